"""One mesh under every column of a Table 2 row (notebook 09's colour map): the floor is PCA's
projection, and every reconstruction comes back rigidly aligned to the mesh."""

from __future__ import annotations

import numpy as np
import pytest

from meshvae_lib.course.table_row import FLOOR_COLUMN, column_reconstructions
from meshvae_lib.model import pca_baseline, per_vertex_error


def _rotation(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


@pytest.fixture
def meshes():
    rng = np.random.default_rng(0)
    return rng.normal(size=(9, 30, 3))


class _Moved:
    """A stand-in model: its reconstruction is the mesh plus a per-inference change, then moved rigidly."""

    def __init__(self, changes):
        self.changes = changes

    def reconstruct(self, V, inference):
        return (V + self.changes[inference]) @ _rotation(0.7).T + np.array([1.0, -2.0, 0.5])


def test_the_floor_column_is_pcas_projection_measured_as_pca_baseline(meshes):
    train, mesh = meshes[:8], meshes[8]
    for k in (3, 7):
        out = column_reconstructions(mesh, train, k)
        assert list(out) == [FLOOR_COLUMN]
        err = np.linalg.norm(out[FLOOR_COLUMN] - mesh, axis=1).mean()
        assert np.isclose(err, pca_baseline(train, mesh[None], n_components=k)["mean_vertex_error"], rtol=1e-10)
    exact = column_reconstructions(meshes[2], train, 7)[FLOOR_COLUMN]   # a training mesh, every direction kept
    assert np.allclose(exact, meshes[2], atol=1e-9)


def test_each_model_and_inference_comes_back_aligned_in_order(meshes):
    offsets = {"encoder": 0.0, "gauss-newton": 0.0}
    out = column_reconstructions(meshes[8], meshes[:8], 3, models={"m": _Moved(offsets)})
    assert list(out) == [FLOOR_COLUMN, "m, encoder", "m, gauss-newton"]
    for column in ("m, encoder", "m, gauss-newton"):   # a rigid motion is all there was: aligned, nothing is left
        assert out[column].shape == (30, 3) and out[column].dtype == np.float64
        assert np.allclose(out[column], meshes[8], atol=1e-9)
    change = 0.1 * np.random.default_rng(1).normal(size=(30, 3))   # not rigid: alignment leaves it
    bumped = column_reconstructions(meshes[8], meshes[:8], 3, models={"m": _Moved({"encoder": 0.0, "gauss-newton": change})},
                                    inferences=("gauss-newton",))
    assert list(bumped) == [FLOOR_COLUMN, "m, gauss-newton"]
    err = np.linalg.norm(bumped["m, gauss-newton"] - meshes[8], axis=1).mean()
    assert err > 0.05 and np.isclose(err, per_vertex_error(meshes[8] + change, meshes[8]), rtol=1e-9)


def test_shapes_are_checked(meshes):
    with pytest.raises(ValueError):
        column_reconstructions(meshes[:2], meshes[:8], 3)
    with pytest.raises(ValueError):
        column_reconstructions(meshes[8, :20], meshes[:8], 3)
