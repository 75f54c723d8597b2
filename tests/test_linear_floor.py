"""The linear floor under the experiments' tables (meshvae_lib.paper.linear_floor).

Hand-made collections with a known answer: meshes in a 3-dimensional affine span (PCA reproduces the
held-out ones to round-off: linear data); rigid copies of one mesh (linear too: a rotated mesh is
linear in the rotation matrix's 9 entries, so 12 directions span every rigid copy); a chain turned
at a few hinges (linear as well: its points are sums of the segments' (cos, sin), 2 directions per
hinge, fewer than the training meshes); and the same chain with more hinges than the training meshes
span (non-linear for this data set: informative).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from meshvae_lib import paper
from meshvae_lib import tolerances as tol
from meshvae_lib.model.evaluation import pca_baseline
from meshvae_lib.model.training import holdout_mask
from meshvae_lib.paper.linear_floor import NOT_INFORMATIVE, floor_cells, informative_rows, linear_floor

RNG = np.random.default_rng(0)
BASE = RNG.normal(size=(60, 3))


def _affine_span(n=30):
    fields = RNG.normal(size=(3, 60, 3))
    return BASE + np.einsum("nk,kvd->nvd", RNG.normal(size=(n, 3)), fields)


def _rigid(n=30):
    R = Rotation.from_rotvec(RNG.normal(scale=1.5, size=(n, 3))).as_matrix()
    return np.einsum("nij,vj->nvi", R, BASE) + RNG.normal(size=(n, 1, 3))


def _hinged_strip(n=40, hinges=12, points=3):
    """A strip of ``points`` points per segment turned at ``hinges`` joints by independent angles up to
    80 degrees (a chain: its points are linear in the 2 * hinges numbers cos, sin of the segments)."""
    x = np.linspace(0, 1, points * (hinges + 1))
    out = []
    for _ in range(n):
        angles = RNG.uniform(-1.4, 1.4, size=hinges)
        seg = np.repeat(np.concatenate([[0.0], np.cumsum(angles)]), points)
        d = np.column_stack([np.cos(seg), np.sin(seg), np.zeros_like(seg)]) * (x[1] - x[0])
        P = np.cumsum(d, axis=0)
        out.append(np.concatenate([P, P + [0, 0, 0.05]]))
    return np.array(out)


def test_affine_span_is_linear_data():
    V = _affine_span()
    f = linear_floor(V, 5)
    assert f["relative"] < 1e-12 and not f["informative"] and f["n_components"] == 3
    assert floor_cells(f)[-1] == NOT_INFORMATIVE


def test_a_chain_is_linear_until_its_hinges_outnumber_the_training_meshes():
    few = linear_floor(_hinged_strip(hinges=12), 4)  # 24 directions < 30 training meshes
    assert few["n_components"] == 24 and few["relative"] < 1e-12 and not few["informative"]


def test_the_floor_is_pca_baseline_on_the_experiments_split():
    V = _hinged_strip(hinges=40)  # 80 directions > 30 training meshes
    f = linear_floor(V, 4)
    held = holdout_mask(len(V), 4)
    coords = pca_baseline(V[~held], V[held])
    aligned = pca_baseline(V[~held], V[held], aligned=True)
    assert f["pca_coords"] == coords["mean_vertex_error"] and f["pca_aligned"] == aligned["mean_vertex_error"]
    assert f["relative"] == min(coords["relative_error"], aligned["relative_error"])
    assert f["informative"] and f["relative"] > 100 * tol.LINEAR_DATA_RTOL


def test_rigid_copies_are_linear_data():
    """Large rotations alone do not make data non-linear: R @ x is linear in R's entries."""
    f = linear_floor(_rigid(), 5)
    assert f["n_components"] == 12 and max(f["pca_coords"], f["pca_aligned"]) < 1e-10
    assert not f["informative"]


def test_bad_splits_are_refused():
    V = _affine_span(6)
    with pytest.raises(ValueError, match="holdout_every must be >= 2, got 0"):
        linear_floor(V, 0)
    with pytest.raises(ValueError, match="2 meshes with every 2th held out leave 1 training and 1"):
        linear_floor(V[:2], 2)
    assert linear_floor(V[:3], 3)["n_components"] == 1  # 2 training meshes, 1 held out: enough


def test_informative_rows_keeps_the_informative_ones():
    t = paper.ExperimentTable("t", "t", ["collection [N]", "informative"],
                              [["a", "yes"], ["b", NOT_INFORMATIVE], ["c", "yes"]])
    assert [r["collection [N]"] for r in informative_rows(t)] == ["a", "c"]
