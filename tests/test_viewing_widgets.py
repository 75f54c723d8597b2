"""Widget callbacks without a browser: frame player, latent explorer (sliders, pad, reset, random),
interpolation slider. Each check goes through the widgets' own traits, as a browser would."""

from __future__ import annotations

import time

import numpy as np
import pytest
import trimesh

from meshvae_lib.geometry.topology import vertex_normals
from meshvae_lib.viewing.explorer import LatentExplorer
from meshvae_lib.viewing.widgets import FramePlayer, InterpolationSlider

pytest.importorskip("pythreejs")


@pytest.fixture
def sphere():
    m = trimesh.creation.icosphere(subdivisions=2)
    return np.array(m.vertices), np.array(m.faces)


class LinearDecoder:
    """V(z) = V0 + sum_k z_k B_k; counts calls."""

    def __init__(self, V0, latent_dim, seed=0):
        self.V0 = V0
        self.B = np.random.default_rng(seed).normal(scale=0.05, size=(latent_dim, len(V0), 3))
        self.calls = []

    def __call__(self, z):
        self.calls.append(np.array(z))
        return self.V0 + np.tensordot(z, self.B, axes=1)


# -- frame player ------------------------------------------------------------------------------
def test_frame_player_steps_through_the_sequence(sphere):
    V, F = sphere
    frames = np.stack([V * s for s in np.linspace(1.0, 2.0, 6)])
    p = FramePlayer(frames, F, fps=12, mode="threejs")
    assert p.n_frames == 6 and p.play.max == 5 and p.slider.max == 5 and p.play.interval == 83
    p.slider.value = 3  # what the browser's Play button does through jslink
    np.testing.assert_allclose(p.viewer.positions[0], frames[3], atol=1e-6)
    np.testing.assert_allclose(p.viewer.normals[0], vertex_normals(frames[3], F), atol=1e-6)
    assert p.step(2) == 5
    assert p.step() == 0  # wraps
    np.testing.assert_allclose(p.viewer.positions[0], frames[0], atol=1e-6)
    with pytest.raises(ValueError, match="frame 9 out of range 0..5"):
        p.frame = 9


def test_frame_player_side_by_side_sequences(sphere):
    V, F = sphere
    a = np.stack([V * s for s in (1.0, 1.5, 2.0)])
    b = a + [0.0, 0.1, 0.0]
    p = FramePlayer([a, b], F, titles=["truth", "method"], mode="threejs")
    p.frame = 2
    np.testing.assert_allclose(p.viewer.positions[0], a[2], atol=1e-6)
    np.testing.assert_allclose(p.viewer.positions[1], b[2], atol=1e-6)
    with pytest.raises(ValueError, match="one shape"):
        FramePlayer([a, b[:2]], F, mode="threejs")


# -- latent explorer ---------------------------------------------------------------------------
def test_moving_a_slider_decodes_and_updates_the_buffers(sphere):
    V, F = sphere
    dec = LinearDecoder(V, 8)
    e = LatentExplorer(dec, 8, F, dims=[0, 3, 5], mode="threejs")
    assert e.n_decodes == 1 and set(e.sliders) == {0, 3, 5}
    attr = e.viewer._pos_attrs[0]
    e.sliders[3].value = 1.5
    assert e.n_decodes == 2
    np.testing.assert_allclose(dec.calls[-1], np.eye(8)[3] * 1.5)
    expected = V + 1.5 * dec.B[3]
    assert e.viewer._pos_attrs[0] is attr  # updated in place, not rebuilt
    np.testing.assert_allclose(attr.array, expected, atol=1e-6)
    np.testing.assert_allclose(e.viewer._nrm_attrs[0].array, vertex_normals(expected, F), atol=1e-5)
    assert e.last_update_ms >= 0


def test_reset_and_random_decode_once_and_random_is_seeded(sphere):
    V, F = sphere
    dec = LinearDecoder(V, 6)
    z0 = np.full(6, 0.25)
    e = LatentExplorer(dec, 6, F, z0=z0, seed=7, random_scale=1.0, mode="threejs")
    n = e.n_decodes
    z = e.randomize()
    assert e.n_decodes == n + 1  # six sliders moved, one decode
    expected = np.clip(np.random.default_rng(7).standard_normal(6), -3, 3)
    np.testing.assert_allclose(z, expected)
    assert [e.sliders[d].value for d in range(6)] == pytest.approx(list(expected), abs=1e-9)
    e2 = LatentExplorer(LinearDecoder(V, 6), 6, F, z0=z0, seed=7, mode="threejs")
    np.testing.assert_allclose(e2.randomize(), z)
    assert not np.allclose(e.randomize(), z)  # the next draw differs
    e.reset_button.click()
    np.testing.assert_allclose(e.z, z0)
    np.testing.assert_allclose(e.viewer._pos_attrs[0].array, V + np.tensordot(z0, dec.B, axes=1), atol=1e-6)


def test_random_only_touches_slider_dimensions(sphere):
    V, F = sphere
    z0 = np.arange(10, dtype=float) / 10
    e = LatentExplorer(LinearDecoder(V, 10), 10, F, dims=[2, 4], z0=z0, mode="threejs")
    z = e.randomize()
    keep = [d for d in range(10) if d not in (2, 4)]
    np.testing.assert_allclose(z[keep], z0[keep])


def test_pad_click_sets_two_dimensions_with_one_decode(sphere):
    V, F = sphere
    dec = LinearDecoder(V, 4)
    e = LatentExplorer(dec, 4, F, value_range=(-2.0, 2.0), mode="threejs")
    assert e.pad_dims == (0, 1) and e.pad.picker is not None
    n = e.n_decodes
    e.pad.picker.point = (0.5, -1.0, 0.0)  # what the browser's Picker reports on a click
    assert e.n_decodes == n + 1
    np.testing.assert_allclose(e.z[:2], [1.0, -2.0])
    assert e.sliders[0].value == pytest.approx(1.0) and e.sliders[1].value == pytest.approx(-2.0)
    assert e.pad.marker.position[:2] == pytest.approx((0.5, -1.0))
    e.sliders[0].value = -2.0  # the marker follows the slider
    assert e.pad.marker.position[0] == pytest.approx(-1.0)


def test_displacement_colouring_and_reference(sphere):
    V, F = sphere
    dec = LinearDecoder(V, 3)
    e = LatentExplorer(dec, 3, F, reference=V, color_by="displacement", mode="threejs")
    assert e.viewer.n_meshes == 2
    diag = np.linalg.norm(np.ptp(V, axis=0))
    # nothing has moved yet: the scale is 0 .. 1% of the diagonal, not a degenerate one around 0
    assert (e.viewer.mapping.vmin, e.viewer.mapping.vmax) == (0.0, pytest.approx(0.01 * diag))
    e.sliders[1].value = 2.0
    disp = np.linalg.norm(2.0 * dec.B[1], axis=1)
    assert e.viewer.mapping.vmax == pytest.approx(disp.max())
    np.testing.assert_allclose(e.viewer._pos_attrs[0].array, V, atol=1e-6)  # reference stays
    c = e.viewer._color_attrs[1].array
    lum = c.mean(axis=1)
    assert lum[np.argmax(disp)] < lum[np.argmin(disp)]  # YlOrRd: more displacement is darker


def test_explorer_accepts_a_model_and_batched_output(sphere):
    V, F = sphere

    class Model:
        def decode_latent(self, z):
            return np.stack([V * (1 + z[0]), V])  # two meshes per latent vector

    e = LatentExplorer(Model(), 2, F, mode="threejs")
    assert e.viewer.n_meshes == 2
    e.sliders[0].value = 1.0
    np.testing.assert_allclose(e.meshes[0], 2 * V, atol=1e-6)


def test_explorer_validates(sphere):
    V, F = sphere
    dec = LinearDecoder(V, 4)
    with pytest.raises(ValueError, match=r"dims must be distinct indices in 0..3, got \[1, 9\]"):
        LatentExplorer(dec, 4, F, dims=[1, 9], mode="threejs")
    with pytest.raises(ValueError, match=r"z0 must have shape \(4,\)"):
        LatentExplorer(dec, 4, F, z0=np.zeros(3), mode="threejs")
    with pytest.raises(ValueError, match="pad_dims"):
        LatentExplorer(dec, 4, F, dims=[0, 1], pad_dims=(0, 3), mode="threejs")
    with pytest.raises(ValueError, match=r"\(162, 2\)"):
        LatentExplorer(lambda z: V[:, :2], 4, F, mode="threejs")
    with pytest.raises(ValueError, match="callable or have a decode_latent"):
        LatentExplorer(42, 4, F, mode="threejs")


def test_explorer_in_image_mode_has_sliders_but_no_pad_view(sphere):
    V, F = sphere
    e = LatentExplorer(LinearDecoder(V, 3), 3, F, mode="image")
    png = e.viewer._image.png
    e.sliders[2].value = 3.0
    assert e.pad.picker is None and e.viewer._image.png != png


# -- interpolation -----------------------------------------------------------------------------
def test_interpolation_slider_blends_and_keeps_the_ends(sphere):
    V, F = sphere
    A, B = V, V * [2.0, 1.0, 0.5]
    s = InterpolationSlider(A, B, F, mode="threejs")
    assert s.viewer.n_meshes == 3
    s.t = 0.25
    np.testing.assert_allclose(s.viewer.positions[1], 0.75 * A + 0.25 * B, atol=1e-6)
    np.testing.assert_allclose(s.viewer.positions[0], A, atol=1e-6)
    np.testing.assert_allclose(s.viewer.positions[2], B, atol=1e-6)
    with pytest.raises(ValueError, match=r"t must be in \[0, 1\], got 1.5"):
        s.t = 1.5


def test_interpolation_slider_with_a_custom_path(sphere):
    V, F = sphere
    seen = []

    def path(t):
        seen.append(t)
        return V * (1.0 + t)

    s = InterpolationSlider(V, 2 * V, F, interpolate=path, show_ends=False, mode="threejs")
    s.slider.value = 0.5
    assert seen[-1] == 0.5 and s.viewer.n_meshes == 1
    np.testing.assert_allclose(s.viewer.positions[0], 1.5 * V, atol=1e-6)


def test_slow_decoder_switches_sliders_to_update_on_release(sphere, monkeypatch):
    V, F = sphere
    import meshvae_lib.viewing.explorer as explorer

    monkeypatch.setattr(explorer, "LIVE_UPDATE_MAX_MS", 5.0)

    def slow(z):
        time.sleep(0.02)
        return V * (1.0 + 0.1 * z[0])

    e = LatentExplorer(slow, 2, F, mode="threejs")
    assert e.live
    e.sliders[0].value = 0.5
    e.sliders[0].value = 1.0
    assert e.live  # two samples are not enough to judge
    e.sliders[0].value = 1.5
    assert not e.live and all(not s.continuous_update for s in e.sliders.values())
    assert "updates on release" in e.status.value
    fast = LatentExplorer(lambda z: V, 2, F, mode="threejs")
    for v in (0.5, 1.0, 1.5, 2.0):
        fast.sliders[1].value = v
    assert fast.live
    fixed = LatentExplorer(slow, 2, F, continuous_update=True, mode="threejs")
    for v in (0.5, 1.0, 1.5):
        fixed.sliders[0].value = v
    assert fixed.live  # an explicit choice is kept


def test_frame_player_colours_each_frame_on_one_range(sphere):
    V, F = sphere
    frames = np.stack([V * s for s in (1.0, 1.5, 2.0)])
    err = np.stack([np.full(len(V), e) for e in (0.0, 1.0, 4.0)])  # (3 frames, n)
    p = FramePlayer(frames, F, frame_values=err, cmap="viridis", value_label="err", mode="threejs")
    assert (p.viewer.mapping.vmin, p.viewer.mapping.vmax) == (0.0, 4.0)
    c0 = p.viewer._color_attrs[0].array[0].copy()
    p.frame = 2
    c2 = p.viewer._color_attrs[0].array[0]
    assert p.viewer.mapping.vmax == 4.0  # the range stays fixed across frames
    import matplotlib

    np.testing.assert_allclose(c0, matplotlib.colormaps["viridis"](0.0)[:3], atol=1e-6)
    np.testing.assert_allclose(c2, matplotlib.colormaps["viridis"](1.0)[:3], atol=1e-6)
    with pytest.raises(ValueError, match=r"frame_values must have shape \(3, 162\)"):
        FramePlayer(frames, F, frame_values=err[:2], mode="threejs")


def test_from_encodings_picks_the_dimensions_the_data_uses(sphere):
    V, F = sphere
    rng = np.random.default_rng(3)
    Z = rng.normal(scale=0.01, size=(40, 16)) + 0.5  # mostly collapsed dimensions around 0.5
    Z[:, 7] = rng.normal(loc=1.0, scale=2.0, size=40)
    Z[:, 2] = rng.normal(loc=-1.0, scale=0.5, size=40)
    dec = LinearDecoder(V, 16)
    e = LatentExplorer.from_encodings(dec, Z, F, n_dims=3, seed=1, mode="threejs")
    assert e.dims[:2] == [7, 2]
    np.testing.assert_allclose(e.z0, Z.mean(axis=0))
    lo, hi = e.ranges[7]
    assert lo == pytest.approx(Z[:, 7].mean() - 3 * Z[:, 7].std()) and hi == pytest.approx(Z[:, 7].mean() + 3 * Z[:, 7].std())
    assert (e.sliders[7].min, e.sliders[7].max) == pytest.approx((lo, hi))
    assert e.sliders[2].max - e.sliders[2].min < e.sliders[7].max - e.sliders[7].min
    # random draws follow the data: centred on its mean, scaled by its spread, inside the ranges
    draws = np.array([e.randomize()[[7, 2]] for _ in range(200)])
    assert abs(draws[:, 0].mean() - Z[:, 7].mean()) < 0.5
    assert draws[:, 0].std() > 3 * draws[:, 1].std()
    assert np.all((draws[:, 0] >= lo - 1e-12) & (draws[:, 0] <= hi + 1e-12))
    with pytest.raises(ValueError, match=r"n_meshes >= 2"):
        LatentExplorer.from_encodings(dec, Z[:1], F, mode="threejs")
    with pytest.raises(ValueError, match=r"n_dims must be in 1..16, got 0"):
        LatentExplorer.from_encodings(dec, Z, F, n_dims=0, mode="threejs")


def test_per_slider_ranges_are_validated(sphere):
    V, F = sphere
    dec = LinearDecoder(V, 3)
    e = LatentExplorer(dec, 3, F, dims=[0, 1], value_range=[[-1, 1], [0, 5]], mode="threejs")
    assert (e.sliders[1].min, e.sliders[1].max) == (0.0, 5.0)
    e.pad.pick(1.0, 1.0)
    np.testing.assert_allclose(e.z[:2], [1.0, 5.0])
    with pytest.raises(ValueError, match="low < high"):
        LatentExplorer(dec, 3, F, dims=[0, 1], value_range=[[-1, 1], [2, 2]], mode="threejs")
    with pytest.raises(ValueError, match="random_scale"):
        LatentExplorer(dec, 3, F, dims=[0, 1], random_scale=[1.0, 2.0, 3.0], mode="threejs")


# -- what a page without widgets shows ----------------------------------------------------------
def _png_size(png: bytes) -> tuple[int, int]:
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    return int.from_bytes(png[16:20], "big"), int.from_bytes(png[20:24], "big")   # IHDR width, height


def test_a_static_page_shows_a_strip_of_the_players_frames(sphere, monkeypatch):
    from meshvae_lib.viewing import render

    V, F = sphere
    frames = np.stack([V * s for s in np.linspace(1.0, 2.0, 11)])
    p = FramePlayer([frames, frames + 0.1], F, titles=["a", "b"], mode="threejs")
    shown = []
    real = render.render_mesh_grid
    monkeypatch.setattr(render, "render_mesh_grid", lambda meshes, *a, **kw: shown.append((meshes, kw)) or real(meshes, *a, **kw))
    png = p._repr_mimebundle_()["image/png"]
    meshes, kw = shown[0]
    assert kw["titles"][:6] == ["a frame 0", "a frame 2", "a frame 4", "a frame 6", "a frame 8", "a frame 10"]
    np.testing.assert_array_equal(meshes[5], frames[10])            # first and last frames included
    np.testing.assert_array_equal(meshes[6], frames[0] + 0.1)       # one row per sequence
    w, h = _png_size(png)
    assert w >= 6 * 150 and h > w / 6, f"a readable strip of six panels, got {w}x{h} px"
    assert p.frame == 0 and len(FramePlayer(frames[:2], F, mode="threejs")._static_frames()) == 2


def test_a_static_page_shows_the_explorers_slider_extremes(sphere):
    V, F = sphere
    dec = LinearDecoder(V, 5)
    ex = LatentExplorer(dec, 5, F, dims=[0, 1, 2, 3, 4], value_range=(-2, 2), mode="threejs")
    before, n_calls = ex.n_decodes, len(dec.calls)
    w, h = _png_size(ex._repr_mimebundle_()["image/png"])
    zs = np.array(dec.calls[n_calls:])
    assert len(zs) == 12 and ex.n_decodes == before             # 4 dimensions x (low, start, high); no slider moved
    np.testing.assert_array_equal(zs[:3, 0], [-2.0, 0.0, 2.0])
    assert np.count_nonzero(zs[:3, 1:]) == 0 and zs[11, 3] == 2.0
    assert w >= 3 * 150 and h >= 4 * 150, f"a 4 x 3 grid of readable panels, got {w}x{h} px"


def test_the_explorers_static_panels_take_the_size_asked_for(sphere):
    from meshvae_lib.defaults import STATIC_DPI

    V, F = sphere
    ex = LatentExplorer(LinearDecoder(V, 4), 4, F, mode="threejs", static_size=2.5)
    w, h = _png_size(ex.static_png())
    assert w >= 3 * 2.5 * STATIC_DPI - 20 and h >= 4 * 2.5 * STATIC_DPI, f"4 x 3 panels of 2.5 inches, got {w}x{h} px"
    with pytest.raises(ValueError, match="static_size"):
        LatentExplorer(LinearDecoder(V, 4), 4, F, mode="threejs", static_size=0)


def test_a_static_page_shows_the_interpolation_along_t(sphere):
    V, F = sphere
    seen = []
    s = InterpolationSlider(V, 2 * V, F, interpolate=lambda t: seen.append(t) or (1 + t) * V, mode="threejs")
    seen.clear()
    w, h = _png_size(s._repr_mimebundle_()["image/png"])
    np.testing.assert_allclose(seen, np.linspace(0.0, 1.0, 6))      # both ends included
    assert s.t == 0.0 and w >= 6 * 150, f"a readable strip, got {w}x{h} px"


def test_the_sliders_static_strip_takes_the_panel_size_asked_for(sphere):
    from meshvae_lib.defaults import STATIC_DPI

    V, F = sphere
    w, h = _png_size(InterpolationSlider(V, 2 * V, F, mode="threejs", static_size=2.6).static_png())
    assert w >= 6 * 2.6 * STATIC_DPI - 20 and h >= 2.6 * STATIC_DPI, f"6 panels of 2.6 inches, got {w}x{h} px"
    w_default, _ = _png_size(InterpolationSlider(V, 2 * V, F, mode="threejs").static_png())
    assert w_default < w, "the default strip is the smaller one"
    with pytest.raises(ValueError, match="static_size"):
        InterpolationSlider(V, 2 * V, F, mode="threejs", static_size=0)


def test_the_players_static_strip_takes_the_panel_size_asked_for(sphere):
    from meshvae_lib.defaults import STATIC_DPI

    V, F = sphere
    frames = np.stack([V * (1 + 0.1 * k) for k in range(8)])
    w, h = _png_size(FramePlayer(frames, F, mode="threejs", static_size=2.6).static_png())
    assert w >= 6 * 2.6 * STATIC_DPI - 20 and h >= 2.6 * STATIC_DPI, f"6 panels of 2.6 inches, got {w}x{h} px"
    w_default, _ = _png_size(FramePlayer(frames, F, mode="threejs").static_png())
    assert w_default < w, "the default strip is the smaller one"
    with pytest.raises(ValueError, match="static_size"):
        FramePlayer(frames, F, mode="threejs", static_size=0)
