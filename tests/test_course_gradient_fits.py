"""gradient_fit_stats (notebook 01, Sec. 5): each count measures what its name says, on meshes where the answer is known."""

import numpy as np
import pytest

from geometry_fixtures import icosphere
from meshvae_lib.course.gradient_fits import gradient_fit_stats
from meshvae_lib.geometry import DeformationGradientOperator


def test_a_mirror_image_is_a_reflection_at_every_vertex_and_no_stretch():
    V, F = icosphere(2)
    stats = gradient_fit_stats(DeformationGradientOperator(V, F, normal_term=False), V * [1.0, 1.0, -1.0])
    assert stats["reflections"] == len(V) and abs(stats["max_stretch"] - 1.0) < 1e-9
    assert np.allclose(stats["T"], np.diag([1.0, 1.0, -1.0]), atol=1e-9)


def test_a_smooth_sphere_without_the_normal_term_is_weakest_along_its_normals():
    V, F = icosphere(3)   # nearly flat one-rings: A_i is weak along the normal, everywhere
    pure = gradient_fit_stats(DeformationGradientOperator(V, F, normal_term=False), V, cond_limit=50)
    with_normal = gradient_fit_stats(DeformationGradientOperator(V, F), V, cond_limit=50)
    assert pure["ill"] == pure["ill_along_normal"] == len(V) and pure["median_cond"] > 50
    assert with_normal["ill"] == 0 and with_normal["max_cond"] < 50 and with_normal["reflections"] == 0


def test_negative_raw_weights_make_some_a_i_indefinite_and_clamping_removes_them():
    V, F = icosphere(3)
    flat = V * [1.0, 1.0, 0.1]   # squashed: obtuse triangles, negative raw cotangent weights
    raw = gradient_fit_stats(DeformationGradientOperator(flat, F, clamp=False), flat)
    clamped = gradient_fit_stats(DeformationGradientOperator(flat, F), flat)
    assert raw["indefinite"] > 0 and clamped["indefinite"] == 0


def test_bad_limits_say_what_is_wrong():
    V, F = icosphere(1)
    with pytest.raises(ValueError, match="cond_limit"):
        gradient_fit_stats(DeformationGradientOperator(V, F), V, cond_limit=0.5)
