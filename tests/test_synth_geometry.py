"""Geometry of every synthetic collection: closed/manifold templates, no degenerate or inverted
triangles in any frame, edge lengths within bounds of the rest pose, no crossing triangles and no
repeated meshes, the linear floor of issue 24, and the bar's turning rings."""

from __future__ import annotations

import functools

import numpy as np
import pytest
import trimesh
from scipy.sparse.csgraph import connected_components
from scipy.spatial.transform import Rotation

from data_synth import constants as C
from data_synth import list_collections, make_collection
from meshvae_lib.geometry.boundaries import boundary_loops
from meshvae_lib.geometry.topology import edges

NAMES = [n for n, _ in list_collections()]
CLOSED = {"scape", "dyna", "jumping", "hand", "face", "poses"}
#: boundary loops expected of each collection's template
N_LOOPS = {"flag": 1, "bar": 2, **{n: 0 for n in CLOSED}}


@functools.lru_cache(maxsize=None)
def built(name: str, seed: int = 0, resolution: int | None = None):
    """Collections built once per test session (the registry tests share them)."""
    return make_collection(name, seed=seed, resolution=resolution)


@pytest.fixture(scope="module")
def collections():
    return {name: built(name) for name in NAMES}


def rest_per_mesh(col) -> np.ndarray:
    """``(N, V, 3)``: each mesh's own rest pose (a Dyna mesh's body shape in the rest pose)."""
    if "shape_rest" in col.extras:
        idx = [col.extras["shape_names"].index(s) for s in col.labels["shape"]]
        return col.extras["shape_rest"][idx]
    return np.broadcast_to(col.extras["rest"], col.vertices.shape)


def _single_fans(F: np.ndarray, n_vertices: int) -> bool:
    """True if the faces around every vertex are connected through shared edges (one fan)."""
    import scipy.sparse as sp

    n_f = len(F)
    corner_v = F.reshape(-1)
    corner_f = np.repeat(np.arange(n_f), 3)
    # two corners of the same vertex are linked if their faces share an edge through that vertex
    half = np.stack([F, np.roll(F, -1, axis=1)], axis=2).reshape(-1, 2)
    und = np.sort(half, axis=1)
    order = np.lexsort((und[:, 1], und[:, 0]))
    u = und[order]
    same = np.all(u[1:] == u[:-1], axis=1)
    fa = corner_f[order[:-1][same]]
    fb = corner_f[order[1:][same]]
    ends = u[:-1][same]  # each shared edge links its two faces at both of its end vertices
    key_a = np.concatenate([fa * n_vertices + ends[:, 0], fa * n_vertices + ends[:, 1]])
    key_b = np.concatenate([fb * n_vertices + ends[:, 0], fb * n_vertices + ends[:, 1]])
    keys = corner_f * n_vertices + corner_v
    index = {k: i for i, k in enumerate(keys.tolist())}
    ia = np.array([index[k] for k in key_a.tolist()])
    ib = np.array([index[k] for k in key_b.tolist()])
    G = sp.coo_matrix((np.ones(len(ia)), (ia, ib)), shape=(3 * n_f, 3 * n_f))
    _, comp = connected_components(G, directed=False)
    fans_per_vertex = np.zeros(n_vertices, dtype=np.int64)
    np.add.at(fans_per_vertex, corner_v, 0)
    first = np.unique(np.stack([corner_v, comp], 1), axis=0)
    np.add.at(fans_per_vertex, first[:, 0], 1)
    return bool((fans_per_vertex == 1).all())


def _cross(V, F):
    return np.cross(V[..., F[:, 1], :] - V[..., F[:, 0], :], V[..., F[:, 2], :] - V[..., F[:, 0], :])


def edge_face_pairs(F: np.ndarray) -> np.ndarray:
    """``(n_interior_edges, 2)``: the two faces on each side of every interior edge."""
    half = np.sort(np.stack([F, np.roll(F, -1, axis=1)], axis=2).reshape(-1, 2), axis=1)
    face = np.repeat(np.arange(len(F)), 3)
    order = np.lexsort((half[:, 1], half[:, 0]))
    h = half[order]
    same = np.all(h[1:] == h[:-1], axis=1)
    return np.stack([face[order[:-1][same]], face[order[1:][same]]], axis=1)


def fold_angles_deg(V: np.ndarray, F: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """Angle (degrees) between the normals of the two faces at every interior edge,
    ``(..., n_interior_edges)``.

    On a smooth surface it is small (a few tens of degrees on these meshes at rest). A triangle
    that is inverted (folded over its neighbour) or a crease pinched flat turns its normal
    against the neighbour's, which pushes the angle towards 180 degrees, whatever rigid
    rotation the limb or the cloth made.
    """
    n = _cross(V, F)
    n = n / np.linalg.norm(n, axis=-1, keepdims=True)
    cos = np.sum(n[..., pairs[:, 0], :] * n[..., pairs[:, 1], :], axis=-1)
    return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))


@pytest.mark.parametrize("name", NAMES)
def test_template_topology(collections, name):
    col = collections[name]
    V0, F = col.extras["rest"], col.faces
    assert F.dtype == np.int64 and F.min() == 0 and F.max() == V0.shape[0] - 1
    assert col.vertices.dtype == np.float64 and np.isfinite(col.vertices).all()
    # every vertex used, one connected piece
    A = trimesh.Trimesh(V0, F, process=False)
    n_comp, _ = connected_components(A.edges_sparse, directed=False)
    assert n_comp == 1
    assert len(np.unique(F)) == len(V0)
    # edge-manifold: no edge has more than two faces, orientation consistent
    assert A.is_winding_consistent
    loops = boundary_loops(F)
    assert len(loops) == N_LOOPS[name], f"{name}: {len(loops)} boundary loops"
    if name in CLOSED:
        assert A.is_watertight
        assert A.euler_number == 2  # a sphere-like closed surface
        assert A.volume > 0  # counter-clockwise seen from outside
    # vertex-manifold: the faces around every vertex form one fan; then V - E + F equals
    # 2 - (number of boundary loops) for these genus-0 surfaces, and a pinched vertex breaks it
    assert len(V0) - len(edges(F)) + len(F) == 2 - len(loops)
    assert _single_fans(F, len(V0))
    assert fold_angles_deg(V0, F, edge_face_pairs(F)).max() < C.MAX_TEMPLATE_FOLD_DEG
    ang = np.degrees(A.face_angles)
    assert ang.min() > C.MIN_TEMPLATE_ANGLE_DEG, f"{name}: smallest angle {ang.min():.1f}"


@pytest.mark.parametrize("name", NAMES)
def test_no_degenerate_or_inverted_triangles(collections, name):
    col = collections[name]
    F = col.faces
    rest = rest_per_mesh(col)
    area0 = np.linalg.norm(_cross(rest, F), axis=-1)
    ratio = np.linalg.norm(_cross(col.vertices, F), axis=-1) / area0
    assert ratio.min() > C.MIN_AREA_RATIO, f"{name}: area ratio {ratio.min():.4f}"
    assert ratio.max() < C.MAX_AREA_RATIO, f"{name}: area ratio {ratio.max():.2f}"
    pairs = edge_face_pairs(F)
    fold = fold_angles_deg(col.vertices, F, pairs)
    assert fold.max() < C.MAX_FOLD_ANGLE_DEG, f"{name}: two neighbouring triangles at {fold.max():.0f} deg"
    if name in CLOSED:  # and the surface as a whole keeps its outward orientation
        vol = np.einsum("nfi,nfi->nf", col.vertices[:, F[:, 0]],
                        np.cross(col.vertices[:, F[:, 1]], col.vertices[:, F[:, 2]])).sum(1) / 6
        assert (vol > 0.5 * vol[0]).all()


def test_normal_turn_detects_an_inverted_triangle(collections):
    """The check above can fail: pushing one vertex through the surface is caught."""
    col = collections["flag"]
    F, rest = col.faces, col.extras["rest"]
    V = rest.copy()
    v = F[len(F) // 2, 0]
    nbrs = np.unique(F[(F == v).any(1)])
    V[v, :2] = 2 * V[nbrs[nbrs != v], :2].mean(0) - V[v, :2]  # reflect through its ring centre
    V[v, :2] += 3 * (V[nbrs[nbrs != v], :2].mean(0) - rest[v, :2])
    assert fold_angles_deg(rest, F, edge_face_pairs(F)).max() < 1e-6
    assert fold_angles_deg(V, F, edge_face_pairs(F)).max() > C.MAX_FOLD_ANGLE_DEG


@pytest.mark.parametrize("name", NAMES)
def test_edge_lengths_stay_near_rest(collections, name):
    col = collections[name]
    E = edges(col.faces)
    rest = rest_per_mesh(col)
    l0 = np.linalg.norm(rest[:, E[:, 0]] - rest[:, E[:, 1]], axis=-1)
    ratio = np.linalg.norm(col.vertices[:, E[:, 0]] - col.vertices[:, E[:, 1]], axis=-1) / l0
    assert ratio.min() > C.MIN_EDGE_RATIO, f"{name}: edge shrank to {ratio.min():.3f}"
    assert ratio.max() < C.MAX_EDGE_RATIO, f"{name}: edge grew to {ratio.max():.2f}"
    # and the meshes really move: the collection is not a copy of its rest pose
    assert np.abs(col.vertices - rest).max() > 0.05 * np.ptp(rest[0], axis=0).max()


def _ring_rotations(col, frame):
    """Rotation of every ring of the bar from the rest pose, ``(n_along,)`` Rotation."""
    n_along, n_around = col.extras["tube_shape"]
    X0 = col.extras["rest"].reshape(n_along, n_around, 3)
    X = col.vertices[frame].reshape(n_along, n_around, 3)
    X0 = X0 - X0.mean(1, keepdims=True)
    X = X - X.mean(1, keepdims=True)
    H = np.einsum("rpi,rpj->rij", X0, X)
    U, _, Vt = np.linalg.svd(H)
    d = np.sign(np.linalg.det(np.einsum("rij,rjk->rki", U, Vt)))
    Vt[:, 2] *= d[:, None]  # a ring is planar: fix the third axis to make a rotation
    return Rotation.from_matrix(np.einsum("rij,rjk->rki", U, Vt))


def test_bar_rings_turn_past_180_degrees_as_their_labels_say(collections):
    """Every ring of the bar is its rest ring turned (a rod: sections keep their shape); the rotation
    accumulated from ring to ring is ``extras["turn_deg"]``, and the most deformed mesh of every
    motion turns past 180 degrees; a pure twist keeps the centre line straight and a pure bend keeps
    the end rings untwisted about it."""
    col = collections["bar"]
    n_along, n_around = col.extras["tube_shape"]
    X0 = col.extras["rest"].reshape(n_along, n_around, 3)
    for motion in ("twist", "bend", "twist_bend"):
        idx = np.nonzero(col.labels["motion"] == motion)[0]
        last = idx[np.argmax(col.extras["turn_deg"][idx])]
        rings = _ring_rotations(col, last)
        X = col.vertices[last].reshape(n_along, n_around, 3)
        # each ring is a rigid copy of its rest ring (to round-off)
        for r in (0, n_along // 2, n_along - 1):
            moved = rings[r].apply(X0[r] - X0[r].mean(0)) + X[r].mean(0)
            assert np.abs(moved - X[r]).max() < 1e-9, f"{motion}: ring {r} is not a rigid copy"
        steps = rings[1:] * rings[:-1].inv()  # ring to ring, each small
        step_angles = steps.magnitude()
        assert step_angles.max() < np.deg2rad(20)
        accumulated = np.rad2deg(step_angles.sum())
        assert accumulated > 180.0, f"{motion}: rings turned only {accumulated:.0f} deg"
        assert abs(accumulated - col.extras["turn_deg"][last]) < 0.01 * accumulated + 1
        centre = X.mean(axis=1)
        straight = np.linalg.norm(np.cross(centre - centre[0], centre[-1] - centre[0]), axis=1).max()
        if motion == "twist":
            assert straight < 1e-9 and col.labels["bend_deg"][last] == 0
        if motion == "bend":
            assert col.labels["twist_deg"][last] == 0 and straight > 0.1


def test_flag_pole_is_scenery_along_the_attached_edge(collections):
    col = collections["flag"]
    (Vp, Fp, _), = col.extras["props"]
    assert Fp.min() == 0 and Fp.max() == len(Vp) - 1
    attached = col.vertices[:, np.isclose(col.extras["rest"][:, 0], 0.0)]        # the sheet's edge x = 0
    axis = np.array([-C.FLAG_POLE_RADIUS, 0.0])
    assert np.allclose(np.linalg.norm(attached[..., [0, 2]] - axis, axis=-1), C.FLAG_POLE_RADIUS)  # on its surface
    assert Vp[:, 1].min() < attached[..., 1].min() and Vp[:, 1].max() > attached[..., 1].max()
    # outward normals: every face normal points away from the pole's axis
    n = np.cross(Vp[Fp[:, 1]] - Vp[Fp[:, 0]], Vp[Fp[:, 2]] - Vp[Fp[:, 0]])
    out = Vp[Fp].mean(axis=1)[:, [0, 2]] - axis
    assert np.all(np.einsum("ij,ij->i", n[:, [0, 2]], out) > 0)


def test_data_synth_normals_agree_with_the_library(collections):
    """data_synth keeps its own vertex normals (it does not import meshvae_lib); they must be the
    library's to rounding."""
    from data_synth.meshing import vertex_normals
    from meshvae_lib.geometry.topology import vertex_normals as library_normals

    for name in ("dyna", "hand", "flag"):
        col = collections[name]
        V = col.vertices[0]
        np.testing.assert_allclose(vertex_normals(V, col.faces), library_normals(V, col.faces), atol=1e-12)


@pytest.mark.parametrize("name", NAMES)
def test_no_crossing_triangles_and_no_repeated_meshes(collections, name):
    from data_synth.quality import duplicate_pairs
    from meshvae_lib.geometry.intersections import self_intersections

    col = collections[name]
    crossing = self_intersections(col.vertices, col.faces)
    assert crossing.max() == 0, f"{name}: crossing triangles in {[col.names[i] for i in np.flatnonzero(crossing)]}"
    pairs = duplicate_pairs(col.vertices)
    assert len(pairs) == 0, f"{name}: {len(pairs)} pairs of identical meshes, e.g. {pairs[:3].tolist()}"


#: collections whose linear floor misses its target (docs/results/synth_floor.md says by how much and
#: why): the face stays below the 1e-4 every collection needs (4e-5 of the diagonal at its default
#: size: rigid alignment takes the head's turn away, the rest is a few dozen smooth directions), and
#: dyna (3e-4) and the hand (3e-4) reach 1e-4 but not the pose collections' 2e-3
BELOW_POSE_TARGET = {"dyna", "hand"}
#: and the poses collection, at full rank: linear blend skinning makes every vertex a linear function
#: of the moving bones' matrices, so its 960 training meshes span the held-out ones (about 200
#: directions; it asks its question at latent sizes far below that: docs/results/nonlinearity.md)
LINEAR = {"face", "poses"}


@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.xfail(n in LINEAR, strict=True,
                                                                          reason="linear data at full rank (issue 24)"))
                                  for n in NAMES])
def test_no_linear_projection_reproduces_a_collection(collections, name):
    """Held-out meshes (every 5th) lie at least FLOOR_TARGET of the diagonal from the span of the
    training meshes (PCA on coordinates and on aligned coordinates), POSE_FLOOR_TARGET for the pose
    collections that reach it; the same floor the experiments' tables print."""
    from meshvae_lib.paper.linear_floor import linear_floor

    floor = linear_floor(collections[name].vertices, 5)["relative"]
    target = C.POSE_FLOOR_TARGET if name in C.POSE_COLLECTIONS and name not in BELOW_POSE_TARGET else C.FLOOR_TARGET
    assert floor >= target, f"{name}: floor {floor:.1e} of the diagonal < {target:.0e}"
