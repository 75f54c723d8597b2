"""matplotlib renderings and the fallback display modes."""

from __future__ import annotations

import io

import numpy as np
import pytest
import trimesh
from matplotlib.figure import Figure
from PIL import Image

from meshvae_lib.viewing import fallback
from meshvae_lib.viewing.colors import error_colors
from meshvae_lib.viewing.fallback import ImageView, resolve_mode
from meshvae_lib.viewing.render import figure_to_png, render_mesh, render_mesh_grid, shade, view_basis


@pytest.fixture
def sphere():
    m = trimesh.creation.icosphere(subdivisions=2)
    return np.array(m.vertices), np.array(m.faces)


def _png_pixels(png: bytes) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=np.int16)


def _drawn(png: bytes) -> float:
    img = _png_pixels(png)
    return float(np.mean(np.abs(img - 255).max(axis=2) > 10))


@pytest.mark.parametrize("up", ["y", "z"])
def test_view_basis_is_a_rotation(up):
    for view in [(0, 0), (30, 45), (-20, 200), (90, 0)]:
        R = view_basis(view, up)
        np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-12)
        assert np.linalg.det(R) == pytest.approx(1.0, abs=1e-12)
    R = view_basis((0, 0), "y")
    np.testing.assert_allclose(R[2], [0, 0, 1], atol=1e-12)  # front view looks from +z
    np.testing.assert_allclose(R[1], [0, 1, 0], atol=1e-12)  # y is up on screen


def test_shade_range_and_two_sidedness():
    R = view_basis((0, 0))
    n = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0]])
    s = shade(n, R, ambient=0.3, diffuse=0.7)
    assert s[0] == pytest.approx(s[1])  # back faces lit like front faces
    assert np.all((s >= 0.3) & (s <= 1.0 + 1e-12))
    assert s[0] > s[2]  # the light comes mostly from the viewer


def test_render_mesh_draws_every_face_sorted_back_to_front(sphere):
    V, F = sphere
    fig = Figure(figsize=(3, 3), dpi=60)
    ax = fig.add_subplot()
    coll = render_mesh(ax, V, F, view=(0, 0))
    polys = coll.get_paths()
    assert len(polys) == len(F)
    fc = coll.get_facecolors()
    assert fc.shape == (len(F), 4)
    # shading varies across the sphere (not a flat silhouette)
    lum = fc[:, :3].mean(axis=1)
    assert lum.max() - lum.min() > 0.2
    culled = render_mesh(ax, V, F, view=(0, 0), cull_backfaces=True)
    assert len(F) * 0.4 < len(culled.get_paths()) < len(F) * 0.6
    assert ax.get_xlim()[1] - ax.get_xlim()[0] == pytest.approx(2 * 0.55 * 2.0, rel=0.02)


def test_render_mesh_paints_back_to_front(sphere):
    V, F = sphere
    # encode each face's index in its colour; ambient=1 turns shading off so colours survive
    i = np.arange(len(F))
    code = np.stack([(i % 256) / 255.0, (i // 256) / 255.0, np.zeros(len(F))], axis=1)
    ax = Figure().add_subplot()
    coll = render_mesh(ax, V, F, colors=code, view=(0, 0), ambient=1.0)
    fc = coll.get_facecolors()[:, :3]
    drawn = np.rint(fc[:, 0] * 255).astype(int) + 256 * np.rint(fc[:, 1] * 255).astype(int)
    assert sorted(drawn.tolist()) == i.tolist()
    depth = V[F].mean(axis=1)[:, 2]  # front view: the viewer is at +z
    assert np.all(np.diff(depth[drawn]) >= -1e-12)


def test_render_mesh_props_are_depth_sorted_with_the_mesh_and_leave_the_frame(sphere):
    V, F = sphere
    ax = Figure().add_subplot()
    plain = render_mesh(ax, V, F, view=(0, 0))
    xlim = ax.get_xlim()
    # a small red sphere in front of the big one (+z faces the viewer) and far to the right
    prop = (0.2 * V + np.array([5.0, 0.0, 3.0]), F, (1.0, 0.0, 0.0))
    ax2 = Figure().add_subplot()
    both = render_mesh(ax2, V, F, view=(0, 0), ambient=1.0, props=[prop])
    assert len(both.get_paths()) == 2 * len(plain.get_paths())
    assert ax2.get_xlim() == pytest.approx(xlim)          # the frame still fits the mesh alone
    red = np.all(np.isclose(both.get_facecolors()[:, :3], (1.0, 0.0, 0.0)), axis=1)
    assert red.sum() == len(F) and np.all(red[-len(F):])  # the prop is nearer: painted last
    with pytest.raises(ValueError, match=r"props\[0\] must be \(V, F, colour\)"):
        render_mesh(ax2, V, F, props=[(V, F)])
    with pytest.raises(ValueError, match="indices into its"):
        render_mesh(ax2, V, F, props=[(V[:3], F, "red")])


def test_render_mesh_validates(sphere):
    V, F = sphere
    ax = Figure().add_subplot()
    with pytest.raises(ValueError, match=r"\(5, 2\)"):
        render_mesh(ax, np.zeros((5, 2)), F)
    with pytest.raises(ValueError, match="out of range, there are 3 vertices"):
        render_mesh(ax, np.zeros((3, 3)), F)


def test_render_mesh_grid_layout_titles_colorbar_and_png(sphere):
    V, F = sphere
    meshes = np.stack([V, 1.2 * V, V * [1.5, 1, 1]])
    C, m, _ = error_colors(meshes, V)
    fig = render_mesh_grid(meshes, F, titles=["a", "b", "c"], ncols=2, colors=C, colorbar=m, suptitle="t")
    assert isinstance(fig, Figure)
    mesh_axes = [ax for ax in fig.axes if ax.get_title()]
    assert [ax.get_title() for ax in mesh_axes] == ["a", "b", "c"]
    assert len(fig.axes) == 4  # 3 panels + the colour bar
    assert fig.axes[-1]._colorbar.extend == "neither"
    C, m, _ = error_colors(meshes, V, vmax=0.1, show_clipped=True)   # values past the scale: a triangle at its top
    clipped = render_mesh_grid(meshes, F, titles=["a", "b", "c"], ncols=2, colors=C, colorbar=m)
    assert clipped.axes[-1]._colorbar.extend == "max"
    png = figure_to_png(fig)
    assert png[:4] == b"\x89PNG"
    assert 0.15 < _drawn(png) < 0.9
    # same_scale: the bigger mesh spans more of its panel
    spans = [ax.collections[0].get_datalim(ax.transData).width for ax in mesh_axes]
    assert spans[1] > 1.1 * spans[0]


def test_render_mesh_grid_suptitle_stays_above_two_line_titles(sphere):
    V, F = sphere
    fig = render_mesh_grid(np.stack([V] * 6), F, titles=["nearest: male_tall_slim\njumping_jacks"] * 6, ncols=3,
                           size=2.5, suptitle="rows: one | two")
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    sup = fig._suptitle.get_window_extent(renderer)
    titles = [ax.title.get_window_extent(renderer) for ax in fig.axes]
    assert sup.y1 <= fig.bbox.y1 and sup.y0 > max(t.y1 for t in titles), "the suptitle clears every panel title"


def test_render_mesh_grid_validates(sphere):
    V, F = sphere
    with pytest.raises(ValueError, match="vertex counts"):
        render_mesh_grid([V, V[:10]], F)
    with pytest.raises(ValueError, match="2 titles for 1 meshes"):
        render_mesh_grid(V, F, titles=["a", "b"])


# -- fallback ----------------------------------------------------------------------------------
def test_resolve_mode_outside_a_kernel_is_static(monkeypatch):
    monkeypatch.delenv(fallback.ENV_VAR, raising=False)
    assert resolve_mode("auto") == "static"
    assert resolve_mode(None) == "static"


def test_resolve_mode_in_a_kernel_prefers_threejs(monkeypatch):
    monkeypatch.delenv(fallback.ENV_VAR, raising=False)
    monkeypatch.setattr(fallback, "in_kernel", lambda: True)
    assert resolve_mode() == "threejs"
    monkeypatch.setattr(fallback, "_importable", lambda name: name != "pythreejs")
    assert resolve_mode() == "image"


def test_resolve_mode_argument_and_environment(monkeypatch):
    monkeypatch.setenv(fallback.ENV_VAR, "image")
    assert resolve_mode() == "image"
    assert resolve_mode("static") == "static"  # an argument beats the environment
    monkeypatch.setenv(fallback.ENV_VAR, "webgpu")
    with pytest.raises(ValueError, match=r"'webgpu' \(from \$MESHVAE_VIEWER\)"):
        resolve_mode()
    with pytest.raises(ValueError, match="'vr'"):
        resolve_mode("vr")
    monkeypatch.setattr(fallback, "_importable", lambda name: False)
    with pytest.raises(ImportError, match="needs pythreejs"):
        resolve_mode("threejs")


def test_image_view_rerenders_into_its_widget(sphere):
    V, F = sphere
    view = ImageView([V, V], F, mode="image", size=1.5, dpi=50)
    first = view.widget.value
    assert first[:4] == b"\x89PNG" and view.n_renders == 1
    view.update(meshes=[V, V * [1.6, 0.7, 1.0]])
    assert view.n_renders == 2 and view.widget.value == view.png
    assert np.mean(np.abs(_png_pixels(first) - _png_pixels(view.png)) > 10) > 0.01


def test_static_view_is_a_png_and_updates_its_display_handle(sphere):
    V, F = sphere

    class Handle:
        def __init__(self):
            self.updates = []

        def update(self, obj, raw=False):
            self.updates.append(obj)

    view = ImageView([V], F, mode="static", size=1.5, dpi=50)
    assert view.widget is None and view._repr_png_()[:4] == b"\x89PNG"
    view._handle = Handle()
    view.update(meshes=[2 * V])
    assert len(view._handle.updates) == 1 and view._handle.updates[0]["image/png"] == view.png
    with pytest.raises(ValueError, match="'threejs'"):
        ImageView([V], F, mode="threejs")


def test_grid_figure_shows_as_png_without_pyplot(sphere):
    V, F = sphere
    fig = render_mesh_grid(V, F, size=1.0, dpi=40)
    png = fig._repr_png_()
    assert png[:4] == b"\x89PNG"
    assert _png_pixels(png).shape[:2] == (40, 40)


def test_multi_line_titles_clear_the_suptitle_and_the_row_above():
    import trimesh

    from meshvae_lib.viewing.render import render_mesh_grid

    s = trimesh.creation.icosphere(subdivisions=1)
    V, F = np.asarray(s.vertices), np.asarray(s.faces)
    fig = render_mesh_grid([V] * 4, F, titles=["a\nb\nc"] * 4, ncols=2, size=2.6, suptitle="a suptitle")
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    renderer = FigureCanvasAgg(fig).get_renderer()
    fig.draw(renderer)
    sup = fig._suptitle.get_window_extent(renderer)
    axes = fig.axes[:4]
    first_row_titles = [ax.title.get_window_extent(renderer) for ax in axes[:2]]
    assert all(t.y1 <= sup.y0 for t in first_row_titles), "the first row's titles stay under the suptitle"
    second_row_titles = [ax.title.get_window_extent(renderer) for ax in axes[2:]]
    assert all(t.y1 <= ax.get_window_extent(renderer).y0 + 1 for t, ax in zip(second_row_titles, axes[:2])), \
        "the second row's titles stay under the first row's panels"
