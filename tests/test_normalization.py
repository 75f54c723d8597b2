"""FeatureNormalizer: Eq. 3 of the paper, its inverse and its eps case."""

import numpy as np
import pytest

from meshvae_lib.model.normalization import FeatureNormalizer
from meshvae_lib.tolerances import NORMALIZE_EPS
from meshvae_lib.defaults import NORMALIZE_A


def test_range_is_minus_a_to_a_per_component(rng):
    X = rng.normal(size=(40, 7)) * np.arange(1, 8) + np.arange(7) * 10
    Y = FeatureNormalizer().fit_transform(X)
    np.testing.assert_allclose(Y.min(axis=0), -NORMALIZE_A, atol=1e-12)
    np.testing.assert_allclose(Y.max(axis=0), NORMALIZE_A, atol=1e-12)


def test_matches_equation_3_closed_form(rng):
    X = rng.uniform(-3, 5, size=(12, 4))
    a = 0.8
    Y = FeatureNormalizer(a=a).fit_transform(X)
    lo, hi = X.min(0), X.max(0)
    np.testing.assert_allclose(Y, 2 * a * (X - lo) / (hi - lo) - a, rtol=0, atol=1e-12)


def test_round_trip_including_rows_outside_the_training_range(rng):
    X = rng.normal(size=(30, 50))
    norm = FeatureNormalizer().fit(X)
    X_new = rng.normal(size=(5, 50)) * 3
    np.testing.assert_allclose(norm.inverse_transform(norm.transform(X_new)), X_new, rtol=0, atol=1e-12)
    np.testing.assert_allclose(norm.inverse_transform(norm.transform(X[0])), X[0], rtol=0, atol=1e-12)


def test_constant_component_uses_eps(rng):
    X = rng.normal(size=(10, 3))
    X[:, 1] = 2.5
    norm = FeatureNormalizer().fit(X)
    assert norm.min_[1] == pytest.approx(2.5 - NORMALIZE_EPS, abs=1e-15)
    assert norm.max_[1] == pytest.approx(2.5 + NORMALIZE_EPS, abs=1e-15)
    Y = norm.transform(X)
    np.testing.assert_allclose(Y[:, 1], 0.0, atol=1e-9)
    # a decoder output anywhere in [-a, a] maps back within eps of the constant
    back = norm.inverse_transform(np.tile([[0.0, NORMALIZE_A, 0.0]], (1, 1)))
    assert abs(back[0, 1] - 2.5) <= NORMALIZE_EPS * (1 + 1e-9)
    np.testing.assert_allclose(norm.inverse_transform(Y), X, atol=1e-12)


def test_single_training_row_is_all_constant():
    norm = FeatureNormalizer().fit(np.array([[1.0, -2.0]]))
    np.testing.assert_allclose(norm.transform([[1.0, -2.0]]), 0.0, atol=1e-8)


def test_state_dict_round_trip(rng):
    X = rng.normal(size=(8, 6))
    norm = FeatureNormalizer(a=0.7).fit(X)
    copy = FeatureNormalizer.from_state_dict(norm.state_dict())
    np.testing.assert_array_equal(copy.transform(X), norm.transform(X))
    assert copy.a == 0.7


@pytest.mark.parametrize("bad", [np.zeros(3), np.zeros((0, 3)), np.array([[np.nan, 1.0]])])
def test_bad_input_is_refused(bad):
    with pytest.raises(ValueError, match=r"shape|NaN or infinite"):
        FeatureNormalizer().fit(bad)


def test_wrong_width_and_unfitted(rng):
    norm = FeatureNormalizer()
    with pytest.raises(ValueError, match="not fitted"):
        norm.transform(np.zeros((2, 3)))
    norm.fit(rng.normal(size=(4, 3)))
    with pytest.raises(ValueError, match="5 components.*3"):
        norm.transform(np.zeros((2, 5)))
    with pytest.raises(ValueError, match="a must lie"):
        FeatureNormalizer(a=1.0).fit(np.zeros((2, 2)))


def test_shared_scale_keeps_centres_and_gives_every_component_the_largest_width():
    X = np.array([[0.0, 10.0, 5.0], [1.0, 10.5, 5.0], [4.0, 11.0, 5.0]])
    nz = FeatureNormalizer(a=0.3, scale="shared").fit(X)
    np.testing.assert_allclose(nz.max_ - nz.min_, 4.0)  # the widest range, column 0
    np.testing.assert_allclose(0.5 * (nz.min_ + nz.max_), [2.0, 10.5, 5.0])  # each column's midpoint
    Y = nz.transform(X)
    np.testing.assert_allclose(Y[:, 0], [-0.3, -0.15, 0.3])
    np.testing.assert_allclose(Y[:, 1], [-0.075, 0.0, 0.075])  # a barely moving column stays small
    np.testing.assert_allclose(Y[:, 2], 0.0)
    np.testing.assert_allclose(nz.inverse_transform(Y), X, atol=1e-12)
    # squared errors of normalised rows are proportional to squared errors of the raw rows
    d = np.array([0.1, -0.2, 0.3])
    assert np.sum((nz.transform(X[0] + d) - Y[0]) ** 2) == pytest.approx((0.6 / 4.0) ** 2 * np.sum(d ** 2))
    back = FeatureNormalizer.from_state_dict(nz.state_dict())
    assert back.scale == "shared" and "shared" in repr(back)
    np.testing.assert_array_equal(back.transform(X), Y)
    with pytest.raises(ValueError, match="scale"):
        FeatureNormalizer(scale="global").fit(X)
