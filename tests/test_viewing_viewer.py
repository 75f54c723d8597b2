"""MeshViewer without a browser: the scene's buffers, in-place updates, colours, fallback modes."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from meshvae_lib.geometry.topology import vertex_normals
from meshvae_lib.viewing.viewer import MeshViewer, as_mesh_stack

pytest.importorskip("pythreejs")


@pytest.fixture
def sphere():
    m = trimesh.creation.icosphere(subdivisions=2)
    return np.array(m.vertices), np.array(m.faces)


def test_scene_holds_float32_buffers_of_every_mesh(sphere):
    V, F = sphere
    W = V * [1.5, 1.0, 0.8]
    v = MeshViewer([V, W], F, titles=["a", "b"], mode="threejs")
    assert v.mode == "threejs" and v.n_meshes == 2 and v.n_vertices == len(V)
    for attr, ref in zip(v._pos_attrs, (V, W)):
        assert attr.array.dtype == np.float32
        np.testing.assert_allclose(attr.array, ref, atol=1e-6)
    for attr, ref in zip(v._nrm_attrs, (V, W)):
        np.testing.assert_allclose(attr.array, vertex_normals(ref, F), atol=1e-6)
    idx = v._meshes[0].geometry.attributes["index"]
    assert idx is v._meshes[1].geometry.attributes["index"]  # one index buffer shared
    np.testing.assert_array_equal(idx.array.reshape(-1, 3), F)
    # side by side along x, one camera for both
    assert v._meshes[0].position[0] < v._meshes[1].position[0]
    assert v.renderer.camera is v.camera and v.controls.controlling is v.camera


def test_update_replaces_buffers_in_place_without_rebuilding(sphere):
    V, F = sphere
    v = MeshViewer([V, V], F, mode="threejs")
    scene_children = v.scene.children
    geoms = [m.geometry for m in v._meshes]
    pos_attrs = list(v._pos_attrs)
    W = V * [1.0, 2.0, 1.0]
    v.update([W, V])
    assert v.scene.children is scene_children
    assert [m.geometry for m in v._meshes] == geoms
    assert all(a is b for a, b in zip(v._pos_attrs, pos_attrs))
    np.testing.assert_allclose(v._pos_attrs[0].array, W, atol=1e-6)
    np.testing.assert_allclose(v._nrm_attrs[0].array, vertex_normals(W, F), atol=1e-6)
    np.testing.assert_allclose(v._pos_attrs[1].array, V, atol=1e-6)
    # one mesh only
    v.update(2 * V, index=1)
    np.testing.assert_allclose(v._pos_attrs[1].array, 2 * V, atol=1e-6)
    np.testing.assert_allclose(v._pos_attrs[0].array, W, atol=1e-6)
    assert v.n_updates == 2 and v.last_update_ms >= 0


def test_update_validates(sphere):
    V, F = sphere
    v = MeshViewer([V, V], F, mode="threejs")
    with pytest.raises(ValueError, match="expected 2 mesh"):
        v.update(V)
    with pytest.raises(ValueError, match="expected meshes with 162 vertices, got 10"):
        v.update([V[:10], V[:10]])
    with pytest.raises(ValueError, match="index 5 out of range"):
        v.update(V, index=5)


def test_constructor_validates(sphere):
    V, F = sphere
    with pytest.raises(ValueError, match="same vertex count"):
        MeshViewer([V, V[:5]], F, mode="threejs")
    with pytest.raises(ValueError, match="1 titles for 2 meshes"):
        MeshViewer([V, V], F, titles=["x"], mode="threejs")
    with pytest.raises(ValueError, match="F: vertex index .* is out of range"):
        MeshViewer(V[:5], F, mode="threejs")
    with pytest.raises(ValueError, match=r"values must have shape \(162,\) or \(1, 162\)"):
        MeshViewer(V, F, values=np.zeros(3), mode="threejs")


def test_values_colour_all_meshes_on_one_scale_with_a_colour_bar(sphere):
    V, F = sphere
    vals = np.stack([np.zeros(len(V)), np.linspace(0, 2, len(V))])
    v = MeshViewer([V, V], F, values=vals, value_label="err", mode="threejs")
    assert v.mapping.vmin == 0.0 and v.mapping.vmax == 2.0
    c0, c1 = v._color_attrs[0].array, v._color_attrs[1].array
    np.testing.assert_allclose(c0, np.broadcast_to(c1[0], c0.shape), atol=1e-6)  # all zero error
    assert "linear-gradient" in v._caption.value and "err" in v._caption.value
    v.set_colors(labels=(V[:, 0] > 0).astype(int))
    assert v.mapping is None and len(v.legend) == 2
    assert len({tuple(c) for c in v._color_attrs[0].array}) == 2
    assert "meshvae-legend" in v._caption.value
    v.set_colors()
    assert v._caption.value == ""


def test_text_repr_is_short_and_deterministic(sphere):
    V, F = sphere
    v = MeshViewer([V, V], F, mode="threejs")
    bundle = v._repr_mimebundle_()
    assert bundle["text/plain"] == "MeshViewer(2 meshes x 162 vertices, mode='threejs')"
    assert "application/vnd.jupyter.widget-view+json" in bundle


@pytest.mark.parametrize("mode", ["image", "static"])
def test_fallback_modes_render_and_update(sphere, mode):
    V, F = sphere
    v = MeshViewer([V, V], F, values=[V[:, 0], V[:, 1]], mode=mode)
    assert v.mode == mode
    png0 = v._image.png
    assert png0[:4] == b"\x89PNG"
    v.update([V, V * [2.0, 1.0, 1.0]])
    assert v._image.png != png0 and v._image.n_renders == 2
    np.testing.assert_allclose(v.positions[1][:, 0], 2 * V[:, 0], atol=1e-6)
    if mode == "image":
        assert v.widget.value == v._image.png
    else:
        assert v.widget is None and "image/png" in v._repr_mimebundle_()


def test_as_mesh_stack_forms(sphere):
    V, _ = sphere
    assert as_mesh_stack(V).shape == (1, len(V), 3)
    assert as_mesh_stack([V, V]).shape == (2, len(V), 3)
    assert as_mesh_stack(np.stack([V, V, V])).shape == (3, len(V), 3)
    with pytest.raises(ValueError, match=r"\(2, 3, 4\)"):
        as_mesh_stack(np.zeros((2, 3, 4)))


def test_snapshot_png_in_display_data_and_current_figure(sphere):
    V, F = sphere
    v = MeshViewer([V, V], F, titles=["a", "b"], mode="threejs")
    bundle = v._repr_mimebundle_()
    assert bundle["image/png"][:4] == b"\x89PNG"
    assert "image/png" not in MeshViewer(V, F, mode="threejs", snapshot=False)._repr_mimebundle_()
    v.update([V, V * [3.0, 1.0, 1.0]])
    fig = v.figure(size=1.5, dpi=40)
    assert [ax.get_title() for ax in fig.axes] == ["a", "b"]
    spans = [ax.collections[0].get_datalim(ax.transData).width for ax in fig.axes]
    assert spans[1] > 2.0 * spans[0]  # the figure shows the updated, stretched mesh


def test_colour_list_with_default_entries(sphere):
    V, F = sphere
    red = np.tile([1.0, 0.0, 0.0], (len(V), 1))
    v = MeshViewer([V, V], F, colors=[None, red], mode="threejs")
    from matplotlib.colors import to_rgb

    from meshvae_lib.viewing.colors import DEFAULT_MESH_COLOR

    np.testing.assert_allclose(v._color_attrs[0].array[0], to_rgb(DEFAULT_MESH_COLOR), atol=1e-6)
    np.testing.assert_allclose(v._color_attrs[1].array, red, atol=1e-6)


def test_the_snapshot_takes_the_panel_size_asked_for(sphere):
    V, F = sphere

    def png_size(png):
        return int.from_bytes(png[16:20], "big"), int.from_bytes(png[20:24], "big")   # IHDR width, height

    big = MeshViewer([V, V, V], F, mode="threejs", snapshot_size=2.6, snapshot_dpi=90)._repr_mimebundle_()["image/png"]
    w, h = png_size(big)
    assert w >= 3 * 2.6 * 90 - 20 and h >= 2.6 * 90, f"3 panels of 2.6 inches at 90 dpi, got {w}x{h} px"
    small = png_size(MeshViewer([V, V, V], F, mode="threejs").snapshot_png())
    assert small[0] < w and small[1] < h, "the default snapshot is the smaller one"
    with pytest.raises(ValueError, match="snapshot_size"):
        MeshViewer(V, F, mode="threejs", snapshot_size=0)
