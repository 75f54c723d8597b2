"""data_synth.quality: duplicate meshes, on hand-made collections with a known answer."""

from __future__ import annotations

import numpy as np
import pytest

from data_synth import constants as C
from data_synth.quality import bounding_box_diagonals, duplicate_pairs

RNG = np.random.default_rng(0)


def test_bounding_box_diagonal_by_hand():
    V = np.array([[[0, 0, 0], [3, 4, 0], [1, 1, 12]]], dtype=float)
    assert bounding_box_diagonals(V).tolist() == [13.0]  # sqrt(9 + 16 + 144)


def test_duplicates_found_and_near_misses_kept():
    base = RNG.normal(size=(50, 3))
    diag = bounding_box_diagonals(base[None])[0]
    nudge = np.zeros_like(base)
    nudge[7, 0] = 1.0
    V = np.stack([base,
                  base + nudge * 10 * C.DUPLICATE_MESH_RTOL * diag,   # one vertex moved 10x the tolerance: new
                  base + nudge * 0.1 * C.DUPLICATE_MESH_RTOL * diag,  # within it: a copy of 0
                  base + [1.0, 0, 0],                                  # translated: a new mesh
                  base.copy()])                                         # exact copy of 0 (and of 2)
    assert duplicate_pairs(V).tolist() == [[0, 2], [0, 4], [2, 4]]


def test_duplicates_match_a_naive_loop():
    V = np.repeat(RNG.normal(size=(4, 30, 3)), [3, 1, 2, 1], axis=0)
    naive = [[i, j] for i in range(len(V)) for j in range(i + 1, len(V))
             if max(np.linalg.norm(V[i][k] - V[j][k]) for k in range(V.shape[1]))
             <= C.DUPLICATE_MESH_RTOL * bounding_box_diagonals(V)[i]]
    assert duplicate_pairs(V).tolist() == naive == [[0, 1], [0, 2], [1, 2], [4, 5]]


@pytest.mark.parametrize("bad, match", [(np.zeros((3, 4)), r"vertices must be \(n_meshes, n_vertices, 3\), got \(3, 4\)")])
def test_bad_input_shows_the_value(bad, match):
    with pytest.raises(ValueError, match=match):
        duplicate_pairs(bad)
    with pytest.raises(ValueError, match="rtol must be a finite number >= 0, got -1"):
        duplicate_pairs(np.zeros((2, 3, 3)), rtol=-1)
