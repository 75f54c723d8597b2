"""The fast paths of the default inference (issue 38): the Jacobian pushed through in blocks equals
the one built column by column, the Cholesky factorisation equals SuperLU's, and meshes fitted in
worker processes equal the serial fit exactly."""

import numpy as np
import pytest
import scipy.sparse as sp
import torch

from geometry_fixtures import strip
from meshvae_lib import tolerances as tol
from meshvae_lib.geometry.collection import MeshCollection
from meshvae_lib.geometry.reconstruction import RIMDReconstructor
from meshvae_lib.geometry.rimd import RIMDEncoder
from meshvae_lib.geometry.spd_factor import SPDFactor, factorize_spd, pinning, spd_backend
from meshvae_lib.model.inference.gauss_newton import GaussNewton, gauss_newton_codes
from meshvae_lib.model.meshvae_model import MeshVAEModel
from meshvae_lib.model.train_config import TrainConfig
from meshvae_lib.workers import map_forked, resolve_jobs

torch.set_num_threads(1)


def _bent(n=14, seed=0):
    """A strip bent and twisted by random amounts: a small collection with nonlinear poses."""
    P, F = strip()
    rng = np.random.default_rng(seed)
    L = P[:, 0].max()
    out = []
    for th, tw in zip(rng.uniform(0.2, 3.0, n), rng.uniform(-0.5, 0.5, n)):
        V = P.copy()
        r = L / th
        phi = P[:, 0] / r
        V[:, 0], V[:, 2] = r * np.sin(phi), r * (1 - np.cos(phi))
        a, y = tw * P[:, 0] / L, P[:, 1] - P[:, 1].mean()
        V[:, 1] = P[:, 1].mean() + y * np.cos(a)
        V[:, 2] += y * np.sin(a)
        out.append(V)
    return MeshCollection(np.array(out), F)


@pytest.fixture(scope="module")
def bent():
    return _bent()


@pytest.mark.parametrize("layout", ["paper", "compact"])
def test_the_jacobian_in_blocks_equals_the_jacobian_column_by_column(bent, layout):
    V, F = bent.vertices, bent.faces
    rec = RIMDReconstructor(V[0], F, layout=layout)
    rng = np.random.default_rng(3)
    f = RIMDEncoder(V[0], F, layout=layout).transform(V[5]) + 0.05 * rng.standard_normal(rec.layout.K)
    lin = rec.linearize(f)                               # inconsistent features: the sweeps run
    d = 2 * tol.JVP_BLOCK + 5                             # three blocks, the last one short
    dF = rng.standard_normal((rec.layout.K, d))
    J = lin.jvp(dF)
    columns = np.stack([lin.jvp(dF[:, k]) for k in range(d)], axis=-1)
    scale = np.abs(columns).max()
    assert scale > 0 and J.shape == columns.shape
    np.testing.assert_allclose(J, columns, rtol=0, atol=1e-10 * scale)
    # and the adjoint, in blocks or not, stays its transpose
    dP = rng.standard_normal((V.shape[1], 3, 3))
    np.testing.assert_allclose(np.einsum("nkd,nke->de", J, dP), dF.T @ lin.vjp(dP), rtol=1e-10,
                               atol=1e-10 * scale * np.abs(dP).max() * V.shape[1])


def test_the_cholesky_factorisation_solves_what_superlu_solves():
    rng = np.random.default_rng(0)
    n = 60
    A = sp.random(n, n, density=0.08, random_state=1)
    M = (A @ A.T + sp.eye(n) * 0.5).tocsr()                   # symmetric positive definite
    B = rng.standard_normal((n, 40))                          # more columns than SuperLU's chunk
    dense = np.linalg.solve(M.toarray(), B)
    fallback = SPDFactor(M, backend="superlu")
    np.testing.assert_allclose(fallback.solve(B), dense, rtol=1e-10, atol=1e-10 * np.abs(dense).max())
    np.testing.assert_allclose(fallback.solve(B[:, 0]), dense[:, 0], rtol=1e-10, atol=1e-10 * np.abs(dense).max())
    assert spd_backend() == "cholmod"                         # the lock installs cholespy
    chol = factorize_spd(M)
    assert chol.backend == "cholmod"
    np.testing.assert_allclose(chol.solve(B), dense, rtol=1e-10, atol=1e-10 * np.abs(dense).max())
    np.testing.assert_allclose(chol.solve(B[:, 3]), dense[:, 3], rtol=1e-10, atol=1e-10 * np.abs(dense).max())
    # a singular Laplacian pinned at one vertex is positive definite
    L = sp.diags([-np.ones(n - 1), 2 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1]).tolil()
    L[0, 0] = L[n - 1, n - 1] = 1.0
    pinned = factorize_spd(L.tocsr() + pinning(n, np.array([0]), 1.0))
    x = pinned.solve(np.r_[1.0, np.zeros(n - 2), -1.0])
    np.testing.assert_allclose(L @ x, np.r_[1.0, np.zeros(n - 2), -1.0], atol=1e-10)
    assert abs(x[0]) < 1e-10           # b sums to zero, so the pin carries nothing: x stays 0 there
    with pytest.raises(ValueError, match=r"shape \(60,\) or \(60, k\)"):
        chol.solve(np.zeros((59, 2)))
    with pytest.raises(ValueError, match="backend"):
        SPDFactor(M, backend="lapack")


def test_map_forked_returns_every_result_in_item_order():
    seen = []
    squares = map_forked(lambda i: i * i, 7, n_jobs=2, on_result=lambda: seen.append(1))
    assert squares == [i * i for i in range(7)] and len(seen) == 7
    assert map_forked(lambda i: i, 0, n_jobs=2) == []
    assert resolve_jobs(8, 3) == 3 and resolve_jobs(1, 10) == 1 and resolve_jobs(None, 1) == 1
    for bad in (0, -1, 1.5, True, "2"):
        with pytest.raises(ValueError, match="n_jobs"):
            resolve_jobs(bad, 4)
    with pytest.raises(ValueError, match="n_jobs"):
        GaussNewton(n_jobs=0)


def test_meshes_fitted_in_worker_processes_equal_the_serial_fit_exactly(bent):
    model = MeshVAEModel("rimd", TrainConfig(progress=False, latent_dim=6, seed=0), holdout_every=3).fit(bent)
    V = bent.vertices[model.holdout_mask_]
    assert len(V) >= 4
    z0 = model.encode_meshes(V, inference="encoder")
    serial, rep1 = gauss_newton_codes(model, V, z0, iterations=3, n_jobs=1)
    parallel, rep2 = gauss_newton_codes(model, V, z0, iterations=3, n_jobs=2)
    np.testing.assert_array_equal(parallel, serial)
    np.testing.assert_array_equal(rep2.final_error, rep1.final_error)
    np.testing.assert_array_equal(rep2.iterations, rep1.iterations)
    assert np.all(rep1.final_error < rep1.initial_error)     # the fit did something worth comparing
    # the strategy's option reaches the fit
    np.testing.assert_array_equal(model.encode_meshes(V, inference=GaussNewton(iterations=3, n_jobs=2)), serial)


def test_chord_steps_only_lower_the_error_and_zero_keeps_the_plain_method(bent):
    from meshvae_lib.model.inference.least_squares import marquardt_fit

    model = MeshVAEModel("rimd", TrainConfig(progress=False, latent_dim=6, seed=0), holdout_every=3).fit(bent)
    V = bent.vertices[model.holdout_mask_]
    z0 = model.encode_meshes(V, inference="encoder")
    plain, _ = gauss_newton_codes(model, V, z0, iterations=2, n_jobs=1)
    zero, _ = gauss_newton_codes(model, V, z0, iterations=2, n_jobs=1, chord_steps=0)
    np.testing.assert_array_equal(zero, plain)
    # after one Jacobian both take the same step; chord steps after it are kept only when they lower
    # the squared error (a nonlinear toy problem: the squares of the parameters, then a linear map)
    A = np.random.default_rng(1).standard_normal((30, 4))
    target = A @ (np.array([0.8, 1.2, 0.5, 1.5]) ** 2)

    class Squares:
        def __init__(self, u):
            self.residual = (target - A @ u ** 2).reshape(10, 3)
            self.sq_error = float(self.residual.ravel() @ self.residual.ravel())

    states = {}

    def state_at(u):
        st = Squares(u)
        states[id(st)] = u.copy()
        return st

    def jacobian_at(state):
        return A * (2 * states[id(state)])

    u0 = np.ones(4)
    plain_fit = marquardt_fit(u0, state_at, jacobian_at, iterations=1)
    chord_fit = marquardt_fit(u0, state_at, jacobian_at, iterations=1, chord_steps=3)
    assert chord_fit.jacobians == plain_fit.jacobians == 1 and chord_fit.decodes > plain_fit.decodes
    assert chord_fit.state.sq_error < 0.5 * plain_fit.state.sq_error < 0.5 * plain_fit.start.sq_error
    assert GaussNewton(iterations=3, chord_steps=1).describe() == "encoder + Gauss-Newton, 3 steps (+1 chord each)"
    # on a linear problem the first Gauss-Newton step is exact: chord steps find nothing to add
    A = np.random.default_rng(0).standard_normal((30, 4))
    b = A @ np.array([1.0, -2.0, 0.5, 3.0])

    class Linear:
        def __init__(self, u):
            self.residual = (b - A @ u).reshape(10, 3)
            self.sq_error = float(self.residual.ravel() @ self.residual.ravel())

    fit = marquardt_fit(np.zeros(4), Linear, lambda state: A, iterations=1, chord_steps=3)
    np.testing.assert_allclose(fit.u, [1.0, -2.0, 0.5, 3.0], atol=1e-2)
    with pytest.raises(ValueError, match="chord_steps"):
        marquardt_fit(np.zeros(4), Linear, lambda state: A, iterations=1, chord_steps=-1)


def test_an_option_a_strategy_does_not_take_is_a_clear_error():
    from meshvae_lib.model.inference import make_inference

    with pytest.raises(ValueError, match=r"inference 'encoder' takes the options \(\), got \['iterations'\]"):
        make_inference("encoder", iterations=2)
    assert make_inference("gauss-newton", iterations=2, n_jobs=1).get_options() == {"iterations": 2, "n_jobs": 1,
                                                                                     "chord_steps": 0}


def test_without_cholespy_the_factorisation_falls_back_to_superlu(monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "cholespy", None)        # an import of it now fails
    assert spd_backend() == "superlu"
    n = 30
    M = (sp.diags([-np.ones(n - 1), 2.5 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1])).tocsr()
    factor = factorize_spd(M)
    assert factor.backend == "superlu"
    b = np.random.default_rng(4).standard_normal((n, 20))
    np.testing.assert_allclose(M @ factor.solve(b), b, atol=1e-12)
