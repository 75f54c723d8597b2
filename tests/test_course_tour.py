"""Notebook 00's helpers (meshvae_lib.course.tour): the floor's two fits, and the unseen inputs of its
self-checks, on hand-made meshes with known answers."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
import trimesh

from meshvae_lib.course import linear_floor_detail, shuffled_gallery, unseen_surfaces
from meshvae_lib.geometry import boundary_loops, edges
from meshvae_lib.paper import linear_floor

RNG = np.random.default_rng(0)


def _chi(c) -> int:
    return c.vertices.shape[1] - len(edges(c.faces)) + len(c.faces)


def _collection(V, F, n=6):
    Vs = np.stack([V * (1 + 0.1 * k) + 0.01 * RNG.normal(size=V.shape) for k in range(n)])
    return SimpleNamespace(vertices=Vs, faces=np.asarray(F), names=[f"m{k}" for k in range(n)], labels={})


@pytest.fixture(scope="module")
def gallery():
    sphere = trimesh.creation.icosphere(subdivisions=2)
    grid = trimesh.creation.box().subdivide().subdivide()
    # an open disc: the sphere's lower half; an open tube: a cylinder without caps
    lower = sphere.faces[np.all(sphere.vertices[sphere.faces][:, :, 2] < 0.3, axis=1)]
    keep = np.unique(lower)
    disc_V, disc_F = sphere.vertices[keep], np.searchsorted(keep, lower)
    tube = trimesh.creation.cylinder(radius=0.5, height=2.0, sections=16)
    side = tube.faces[np.abs(tube.face_normals[:, 2]) < 0.5]
    keep_t = np.unique(side)
    return {"scape": (_collection(grid.vertices, grid.faces), np.arange(3)),
            "hand": (_collection(sphere.vertices, sphere.faces), np.arange(3)),
            "flag": (_collection(disc_V, disc_F), np.arange(3)),
            "bar": (_collection(tube.vertices[keep_t], np.searchsorted(keep_t, side)), np.arange(3))}


def test_the_unseen_surfaces_have_the_euler_characteristics_their_docstring_gives(gallery):
    for name in ("scape", "hand", "flag", "bar"):
        loops = len(boundary_loops(gallery[name][0].faces))
        assert (_chi(gallery[name][0]), loops) == {"scape": (2, 0), "hand": (2, 0), "flag": (1, 1), "bar": (0, 2)}[name]
    for seed in (0, 1, 2):
        unseen = unseen_surfaces(gallery, seed)
        chi = {name: _chi(c) for name, (c, _) in unseen.items()}
        loops = {name: len(boundary_loops(c.faces)) for name, (c, _) in unseen.items()}
        holes = 3 + seed % 3
        assert chi == {"two_bodies": 4, "holed_hand": 2 - holes, "flag_and_bar": 1}
        assert loops == {"two_bodies": 0, "holed_hand": holes, "flag_and_bar": 3}
        assert sum(chi[n] != 2 - loops[n] for n in chi) == 2, "2 minus the loops is wrong for two of them"
        c = unseen["two_bodies"][0]
        assert c.vertices.shape == (1, 2 * gallery["scape"][0].vertices.shape[1], 3) and c.faces.max() < c.vertices.shape[1]


def test_a_shuffled_gallery_holds_the_same_meshes_with_another_first_one(gallery):
    out = shuffled_gallery(gallery, ["hand", "flag"], seed=3)
    assert set(out) == {"hand", "flag"}
    for name, (c, idx) in out.items():
        old, old_idx = gallery[name]
        assert not np.array_equal(c.vertices[0], old.vertices[0]), "the first mesh changes"
        assert sorted(c.names) == sorted(old.names)
        for k, i in enumerate(idx):   # each shown mesh is found at its new index
            assert np.array_equal(c.vertices[i], old.vertices[old_idx[k]]) and c.names[i] == old.names[old_idx[k]]


def test_the_detailed_floor_is_linear_floor_plus_each_fit():
    V = np.cumsum(RNG.normal(size=(40, 30, 3)), axis=0) * 0.1 + RNG.normal(size=(30, 3))
    V = V + np.sin(V) * 0.3   # not a linear family
    f, detail = linear_floor(V, 4), linear_floor_detail(V, 4)
    assert {k: detail[k] for k in f} == f
    assert detail["relative"] == min(detail["relative_coords"], detail["relative_aligned"])
    assert detail["relative_coords"] != detail["relative_aligned"]
    assert (detail["n_train"], detail["n_held"]) == (30, 10)
    with pytest.raises(ValueError, match="holdout_every"):
        linear_floor_detail(V, 1)
