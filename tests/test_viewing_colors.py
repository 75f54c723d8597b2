"""Colour mapping: continuous values, errors, categorical labels, colour bar and legend HTML."""

from __future__ import annotations

import matplotlib
import numpy as np
import pytest

from meshvae_lib.viewing.colors import (
    ColorMapping,
    colorbar_html,
    error_colors,
    label_colors,
    legend_html,
    scalar_colors,
)


def test_scalar_colors_ends_match_the_colour_map():
    v = np.array([2.0, 3.0, 4.0])
    C, m = scalar_colors(v, cmap="viridis")
    assert C.shape == (3, 3) and C.dtype == np.float32
    assert (m.vmin, m.vmax) == (2.0, 4.0)
    cmap = matplotlib.colormaps["viridis"]
    np.testing.assert_allclose(C[0], cmap(0.0)[:3], atol=1e-6)
    np.testing.assert_allclose(C[1], cmap(0.5)[:3], atol=1e-6)
    np.testing.assert_allclose(C[2], cmap(1.0)[:3], atol=1e-6)


def test_scalar_colors_clip_and_share_one_range_across_meshes():
    v = np.array([[0.0, 1.0], [2.0, 10.0]])
    C, m = scalar_colors(v, vmin=0.0, vmax=2.0)
    assert C.shape == (2, 2, 3)
    np.testing.assert_allclose(C[1, 1], C[1, 0], atol=1e-6)  # 10 clipped to vmax=2
    C2, m2 = scalar_colors(v)
    assert (m2.vmin, m2.vmax) == (0.0, 10.0)


def test_show_clipped_names_the_ends_that_values_lie_past():
    v = np.array([[-1.0, 1.0], [2.0, 10.0]])
    assert scalar_colors(v, vmin=0.0, vmax=2.0)[1].extend == "neither"           # off by default
    assert scalar_colors(v, vmin=0.0, vmax=2.0, show_clipped=True)[1].extend == "both"
    assert scalar_colors(v, vmin=-1.0, vmax=2.0, show_clipped=True)[1].extend == "max"
    assert scalar_colors(v, vmin=0.0, vmax=10.0, show_clipped=True)[1].extend == "min"
    assert scalar_colors(v, show_clipped=True)[1].extend == "neither"              # the full range clips nothing
    P = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 3.0]])
    assert error_colors(P, np.zeros((2, 3)), vmax=2.0, show_clipped=True)[1].extend == "max"
    assert error_colors(P, np.zeros((2, 3)), vmax=3.0, show_clipped=True)[1].extend == "neither"


def test_constant_values_and_nan_give_finite_colours():
    C, m = scalar_colors(np.full(5, 3.0))
    assert np.all(np.isfinite(C))
    np.testing.assert_allclose(C[0], C[-1])
    C, _ = scalar_colors(np.array([0.0, np.nan, 1.0]))
    np.testing.assert_allclose(C[1], [0.5, 0.5, 0.5])


def test_scalar_colors_validates():
    with pytest.raises(ValueError, match=r"got \(2, 2, 2\)"):
        scalar_colors(np.zeros((2, 2, 2)))
    with pytest.raises(ValueError, match="vmax"):
        scalar_colors(np.arange(3.0), vmin=5.0, vmax=1.0)
    with pytest.raises(ValueError, match="unknown matplotlib colour map"):
        scalar_colors(np.arange(3.0), cmap="no-such-map")


def test_error_colors_distances_and_ordering(rng):
    T = rng.normal(size=(50, 3))
    shift = np.zeros((50, 3))
    shift[:, 0] = np.linspace(0.0, 1.0, 50)
    C, m, e = error_colors(T + shift, T, scale=100.0)
    np.testing.assert_allclose(e, 100.0 * np.linspace(0.0, 1.0, 50), atol=1e-9)
    assert m.vmin == 0.0 and m.vmax == pytest.approx(100.0)
    # YlOrRd darkens with the error: luminance decreases monotonically
    lum = C @ np.array([0.299, 0.587, 0.114], dtype=np.float32)
    assert np.all(np.diff(lum) <= 1e-6) and lum[0] - lum[-1] > 0.5
    # one truth broadcast against two methods
    C2, _, e2 = error_colors(np.stack([T, T + shift]), T, vmax=1.0)
    assert e2.shape == (2, 50) and np.all(e2[0] == 0.0)
    with pytest.raises(ValueError, match="do not broadcast"):
        error_colors(T[:10], T)


def test_label_colors_equal_and_distinct():
    labels = np.array([2, 0, 2, 1, 0, 1])
    C, legend = label_colors(labels, names={0: "arm", 1: "leg", 2: "torso"})
    assert C.shape == (6, 3)
    np.testing.assert_array_equal(C[0], C[2])
    np.testing.assert_array_equal(C[1], C[4])
    distinct = {tuple(c) for c in C}
    assert len(distinct) == 3
    assert [n for n, _ in legend] == ["arm", "leg", "torso"]
    assert all(h.startswith("#") and len(h) == 7 for _, h in legend)


def test_label_colors_many_labels_stay_distinct():
    C, legend = label_colors(np.arange(40))
    assert len({tuple(np.round(c, 4)) for c in C}) == 40
    assert len(legend) == 40


def test_colorbar_and_legend_html():
    m = ColorMapping("viridis", 0.0, 0.25, label="error <%>")
    h = colorbar_html(m, width=200)
    assert "linear-gradient" in h and "width:200px" in h
    assert "<span>0</span>" in h and "<span>0.125</span>" in h and "<span>0.25</span>" in h
    assert "error &lt;%&gt;" in h  # escaped
    assert len(m.stops(5)) == 5 and m.stops(5)[0] == matplotlib.colors.to_hex(matplotlib.colormaps["viridis"](0.0))
    lg = legend_html([("a", "#ff0000"), ("b<", "#00ff00")])
    assert "#ff0000" in lg and "b&lt;" in lg
