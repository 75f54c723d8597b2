"""Buffers for the WebGL view: dtypes, layouts, normals, colours, placement and camera framing."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from meshvae_lib.geometry.topology import vertex_normals
from meshvae_lib.viewing.buffers import (
    color_buffer,
    fit_camera,
    index_buffer,
    normal_buffer,
    position_buffer,
    row_offsets,
)


@pytest.fixture
def sphere():
    m = trimesh.creation.icosphere(subdivisions=2)
    return m.vertices, m.faces  # trimesh TrackedArrays on purpose


def test_position_buffer_is_plain_float32_copy(sphere):
    V, _ = sphere
    P = position_buffer(V)
    assert type(P) is np.ndarray  # not trimesh's TrackedArray subclass
    assert P.dtype == np.float32 and P.shape == (len(V), 3) and P.flags.c_contiguous
    np.testing.assert_allclose(P, np.asarray(V), atol=1e-6)
    assert not np.shares_memory(P, np.asarray(V))


@pytest.mark.parametrize("bad", [np.zeros((5, 2)), np.zeros((0, 3)), np.zeros(3)])
def test_position_buffer_rejects_bad_shapes_and_shows_them(bad):
    with pytest.raises(ValueError, match=str(bad.shape).replace("(", r"\(").replace(")", r"\)")):
        position_buffer(bad)


def test_position_buffer_rejects_nan():
    V = np.zeros((4, 3))
    V[2, 1] = np.nan
    with pytest.raises(ValueError, match=r"V: 1 of 12 coordinates are NaN or infinite \(first at index \(2, 1\)\)"):
        position_buffer(V)


def test_index_buffer_flattens_faces_in_order(sphere):
    V, F = sphere
    idx = index_buffer(F, len(V))
    assert idx.dtype == np.uint32 and idx.shape == (3 * len(F),)
    np.testing.assert_array_equal(idx.reshape(-1, 3), np.asarray(F))


def test_index_buffer_rejects_out_of_range_vertex():
    with pytest.raises(ValueError, match="F: vertex index 7 is out of range, there are 5 vertices"):
        index_buffer(np.array([[0, 1, 7]]), 5)


def test_normal_buffer_matches_topology_and_points_outward(sphere):
    V, F = sphere
    N = normal_buffer(V, F)
    assert N.dtype == np.float32 and N.shape == (len(V), 3)
    np.testing.assert_allclose(N, vertex_normals(np.asarray(V), F), atol=1e-6)
    np.testing.assert_allclose(np.linalg.norm(N, axis=1), 1.0, atol=1e-6)
    radial = np.asarray(V) / np.linalg.norm(V, axis=1, keepdims=True)
    # a fine sphere's vertex normals are nearly radial (icosphere level 2: within ~3 degrees)
    assert np.min(np.sum(N * radial, axis=1)) > np.cos(np.radians(5.0))


def test_color_buffer_forms(sphere):
    V, _ = sphere
    n = len(V)
    red = color_buffer("red", n)
    assert red.shape == (n, 3) and red.dtype == np.float32
    np.testing.assert_allclose(red, np.tile([1.0, 0.0, 0.0], (n, 1)))
    np.testing.assert_allclose(color_buffer("#336699", n)[0], [0.2, 0.4, 0.6], atol=1e-6)
    rgba = np.random.default_rng(0).random((n, 4))
    np.testing.assert_allclose(color_buffer(rgba, n), rgba[:, :3], atol=1e-6)
    with pytest.raises(ValueError, match=r"got shape \(7, 3\)"):
        color_buffer(np.zeros((7, 3)), n)
    with pytest.raises(ValueError, match=r"in \[0, 1\]"):
        color_buffer(np.full((n, 3), 2.0), n)
    with pytest.raises(ValueError, match="unknown colour"):
        color_buffer("not-a-colour", n)


def test_row_offsets_separate_meshes_and_keep_relative_pose(sphere):
    V = np.asarray(sphere[0])
    meshes = [V, V + [0.0, 0.3, 0.0], 2.0 * V]
    off = row_offsets(meshes, gap=0.25)
    assert off.shape == (3, 3)
    placed = [m + o for m, o in zip(meshes, off)]
    # consecutive meshes do not overlap along x
    for a, b in zip(placed, placed[1:]):
        assert a[:, 0].max() < b[:, 0].min() + 1e-9
    # one common centre: the y shift of mesh 1 relative to mesh 0 survives
    assert placed[1][:, 1].mean() - placed[0][:, 1].mean() == pytest.approx(0.3, abs=1e-9)
    # equal slots, symmetric about the origin once the common centre is removed
    lo = np.min([m.min(axis=0) for m in meshes], axis=0)
    hi = np.max([m.max(axis=0) for m in meshes], axis=0)
    slots = off[:, 0] + 0.5 * (lo[0] + hi[0])
    np.testing.assert_allclose(np.diff(slots), np.diff(slots)[0], rtol=1e-12)
    assert abs(slots.sum()) < 1e-9


def test_fit_camera_sees_every_point(sphere):
    V = np.asarray(sphere[0])
    pts = np.concatenate([V + [x, 0, 0] for x in (-3.0, 0.0, 3.0)])
    fov, aspect = 40.0, 2.0
    pos, target = fit_camera(pts, fov=fov, aspect=aspect)
    fwd = (target - pos) / np.linalg.norm(target - pos)
    right = np.cross(fwd, [0.0, 1.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    rel = pts - pos
    depth = rel @ fwd
    assert np.all(depth > 0)
    tan_v = np.tan(np.radians(fov) / 2)
    assert np.all(np.abs(rel @ up) / depth <= tan_v * 1.0001)
    assert np.all(np.abs(rel @ right) / depth <= tan_v * aspect * 1.0001)
