"""Latent inference (model.inference) and the linearised RIMD reconstruction it rests on (issue 23)."""

import numpy as np
import pytest
import torch

from geometry_fixtures import strip
from meshvae_lib.geometry.collection import MeshCollection
from meshvae_lib.geometry.reconstruction import RIMDReconstructor
from meshvae_lib.geometry.rimd import RIMDEncoder
from meshvae_lib.model.evaluation import evaluate_model, pca_baseline, per_vertex_error
from meshvae_lib.model.feature_kinds.coords import CoordinateLinearization
from meshvae_lib.model.inference.gauss_newton import gauss_newton_codes, rigid_fields
from meshvae_lib.model.networks import decoder_linearization as decoder_jacobian
from meshvae_lib.model.meshvae_model import MeshVAEModel
from meshvae_lib.model.train_config import TrainConfig
from meshvae_lib.model.vae import MeshVAE

torch.set_num_threads(1)


def _arcs(angles, twist=0.0):
    """A strip rolled into arcs of the given total angles (radians), optionally twisted: RIMD
    features nearly linear in the angle, vertex coordinates not (sines and cosines)."""
    P, F = strip()
    L = P[:, 0].max()
    out = []
    for k, th in enumerate(angles):
        V = P.copy()
        if abs(th) > 1e-9:
            r = L / th
            phi = P[:, 0] / r
            V[:, 0], V[:, 2] = r * np.sin(phi), r * (1 - np.cos(phi))
        a = twist * np.sin(k) * P[:, 0] / L
        y = P[:, 1] - P[:, 1].mean()
        V[:, 1] = P[:, 1].mean() + y * np.cos(a)
        V[:, 2] += y * np.sin(a)
        out.append(V)
    return MeshCollection(np.array(out), F, names=[f"arc{k:02d}" for k in range(len(angles))])


@pytest.fixture(scope="module")
def arcs():
    return _arcs(np.linspace(0.0, 4.0, 21), twist=0.4)


# -- the linearised reconstruction ------------------------------------------------------------------
@pytest.mark.parametrize("layout", ["paper", "compact"])
def test_jvp_matches_central_differences_of_the_reconstruction(arcs, layout):
    V, F = arcs.vertices, arcs.faces
    rec = RIMDReconstructor(V[0], F, layout=layout)
    f = RIMDEncoder(V[0], F, layout=layout).transform(V[13])          # consistent features
    rng = np.random.default_rng(0)
    dF = rng.standard_normal((len(f), 3))
    lin = rec.linearize(f)
    np.testing.assert_array_equal(lin.positions, rec.reconstruct(f, align=False))
    h = 1e-5
    fd = np.stack([(rec.reconstruct(f + h * dF[:, k], align=False) - rec.reconstruct(f - h * dF[:, k], align=False))
                   / (2 * h) for k in range(3)], axis=-1)
    J = lin.jvp(dF)
    assert J.shape == (V.shape[1], 3, 3)
    # first order is exact at consistent features: only the differences' O(h^2) and round-off remain
    assert np.linalg.norm(J - fd) < 1e-5 * np.linalg.norm(fd)
    np.testing.assert_allclose(lin.jvp(dF[:, 0]), J[:, :, 0], rtol=0, atol=1e-12 * np.abs(J).max())


@pytest.mark.parametrize("rotations,noise", [("global", 0.01), ("global", 0.3), ("bfs", 0.3)])
def test_jvp_of_inconsistent_features_follows_the_steps_taken(arcs, rotations, noise):
    """A decoder's output is not consistent: the rotation recovery's sweeps then stop short of the
    least-squares optimum, and the derivative follows the steps actually taken (the walk, each
    sweep), so it matches central differences as closely as at consistent features."""
    V, F = arcs.vertices, arcs.faces
    rec = RIMDReconstructor(V[0], F, rotations=rotations)
    rng = np.random.default_rng(1)
    f = RIMDEncoder(V[0], F).transform(V[9]) + noise * rng.standard_normal(rec.layout.K)
    dF = rng.standard_normal((len(f), 2))
    h = 1e-6
    fd = np.stack([(rec.reconstruct(f + h * dF[:, k], align=False) - rec.reconstruct(f - h * dF[:, k], align=False))
                   / (2 * h) for k in range(2)], axis=-1)
    err = np.linalg.norm(rec.linearize(f).jvp(dF) - fd) / np.linalg.norm(fd)
    assert err < 1e-5


def test_vjp_is_the_transpose_of_jvp(arcs):
    V, F = arcs.vertices, arcs.faces
    rec = RIMDReconstructor(V[0], F)
    lin = rec.linearize(RIMDEncoder(V[0], F).transform(V[17]))
    rng = np.random.default_rng(2)
    dF = rng.standard_normal((rec.layout.K, 4))
    dP = rng.standard_normal((V.shape[1], 3, 5))
    lhs = np.einsum("nkd,nke->de", lin.jvp(dF), dP)
    rhs = dF.T @ lin.vjp(dP)
    np.testing.assert_allclose(lhs, rhs, rtol=1e-10, atol=1e-10 * np.abs(lhs).max())
    assert lin.vjp(dP[:, :, 0]).shape == (rec.layout.K,)


def test_linearize_refuses_what_it_does_not_linearise(arcs):
    V, F = arcs.vertices, arcs.faces
    f = RIMDEncoder(V[0], F).transform(V[3])
    with pytest.raises(ValueError, match="local-global iterations"):
        RIMDReconstructor(V[0], F, method="paper", iterations=2).linearize(f)
    with pytest.raises(ValueError, match="one feature vector"):
        RIMDReconstructor(V[0], F).linearize(np.stack([f, f]))
    with pytest.raises(ValueError, match="jvp|dF must have shape"):
        RIMDReconstructor(V[0], F).linearize(f).jvp(np.ones(3))


def test_coordinate_linearization_is_the_reshape():
    f = np.arange(12.0)
    lin = CoordinateLinearization(f)
    np.testing.assert_array_equal(lin.positions, f.reshape(4, 3))
    d = np.arange(24.0).reshape(12, 2)
    np.testing.assert_array_equal(lin.jvp(d), d.reshape(4, 3, 2))
    np.testing.assert_array_equal(lin.vjp(lin.jvp(d)), d)


def test_a_kind_without_its_own_linearisation_gets_forward_differences():
    """FeatureKind's default linearize: forward differences of the kind's decoder, against the exact
    derivative of a decoder that is not linear (x -> x + 0.1 x^2 per coordinate)."""
    from meshvae_lib.model.feature_kinds.base import FiniteDifferenceLinearization

    def decode(X):
        return (X + 0.1 * X ** 2).reshape(len(X), -1, 3)

    f = np.linspace(-1.0, 2.0, 12)
    lin = FiniteDifferenceLinearization(decode, f)
    np.testing.assert_array_equal(lin.positions, decode(f[None])[0])
    dF = np.random.default_rng(0).standard_normal((12, 3))
    dF[:, 1] = 0.0                                              # a zero direction has a zero derivative
    exact = ((1.0 + 0.2 * f)[:, None] * dF).reshape(4, 3, 3)
    np.testing.assert_allclose(lin.jvp(dF), exact, rtol=0, atol=1e-5)
    np.testing.assert_array_equal(lin.jvp(dF)[..., 1], 0.0)
    assert lin.jvp(dF[:, 0]).shape == (4, 3)


# -- the network's part ---------------------------------------------------------------------------
@pytest.mark.parametrize("hidden,output,conditions", [((), "tanh", 0), ((), "sigmoid", 2), ((16,), "tanh", 0)])
def test_decoder_jacobian_against_autograd_and_differences(hidden, output, conditions):
    torch.manual_seed(0)
    net = MeshVAE(n_features=30, latent_dim=5, hidden=hidden, n_conditions=conditions, output=output).eval()
    z = np.random.default_rng(3).standard_normal(5)
    c = np.array([1.0, 0.0]) if conditions else None
    rows, J = decoder_jacobian(net, z, c)
    ct = None if c is None else torch.tensor(c[None], dtype=torch.float32)
    with torch.no_grad():
        np.testing.assert_allclose(rows, net.decode(torch.tensor(z[None], dtype=torch.float32), ct)[0].double().numpy(),
                                   atol=1e-6)
    h = 1e-3
    fd = np.stack([(decoder_jacobian(net, z + h * e, c)[0] - decoder_jacobian(net, z - h * e, c)[0]) / (2 * h)
                   for e in np.eye(5)], axis=1)
    np.testing.assert_allclose(J, fd, atol=2e-3 * np.abs(fd).max())


def test_rigid_fields_span_the_rigid_motions():
    P = np.random.default_rng(4).standard_normal((30, 3))
    Q = rigid_fields(P)
    np.testing.assert_allclose(Q.T @ Q, np.eye(6), atol=1e-12)
    # a small rotation plus a translation lies in the span
    w, t = np.array([0.01, -0.02, 0.015]), np.array([0.3, 0.1, -0.2])
    motion = np.cross(w, P - P.mean(0)) + t
    m = motion.ravel()
    assert np.linalg.norm(m - Q @ (Q.T @ m)) < 1e-12 * np.linalg.norm(m)


# -- inference end to end --------------------------------------------------------------------------
@pytest.fixture(scope="module")
def arc_model(arcs):
    return MeshVAEModel("rimd", TrainConfig(progress=False, latent_dim=8, seed=0), holdout_every=4).fit(arcs)


def test_gauss_newton_never_raises_the_error_and_beats_the_encoder(arcs, arc_model):
    held = np.flatnonzero(arc_model.holdout_mask_)
    V = arcs.vertices[held]
    z_enc = arc_model.encode_meshes(V, inference="encoder")
    z_gn, report = gauss_newton_codes(arc_model, V, z_enc, iterations=4)
    e_enc = per_vertex_error(arc_model.decode_latent(z_enc), V)
    e_gn = per_vertex_error(arc_model.decode_latent(z_gn), V)
    assert np.all(e_gn <= e_enc * (1 + 1e-6) + 1e-12)
    assert np.mean(e_gn) < 0.5 * np.mean(e_enc)
    np.testing.assert_allclose(report.initial_error, e_enc, rtol=1e-4)
    np.testing.assert_allclose(report.final_error, e_gn, rtol=1e-4)
    assert np.all(report.iterations >= 1) and np.all(report.decodes >= report.iterations)
    # the model's default is this strategy
    np.testing.assert_array_equal(arc_model.encode_meshes(V), z_gn)


def test_gauss_newton_does_not_depend_on_the_scale_of_the_latent_axes(arcs, arc_model):
    """Marquardt's damping (each direction in proportion to its own curvature) makes the fit
    invariant to rescaling the latent axes, which changes no decoded mesh: a direction that moves
    the vertices little is not frozen by the others. (Damping by a multiple of the mean curvature
    fails this: about twice the error on the rescaled model, measured.)"""
    held = np.flatnonzero(arc_model.holdout_mask_)
    V = arcs.vertices[held]
    D = arc_model.latent_dim
    s = np.logspace(-1.5, 1.5, D)                 # axis k of the copy is axis k of the model times s_k
    scaled = MeshVAEModel.from_state_dict(arc_model.state_dict())
    net = scaled.network
    with torch.no_grad():
        st = torch.as_tensor(s, dtype=torch.float32)
        net.encoder_head.weight[:D] *= st[:, None]
        net.encoder_head.bias[:D] *= st
        net.decoder_head.weight[:, :D] /= st[None, :]
    z = arc_model.encode_meshes(V, inference="encoder")
    np.testing.assert_allclose(scaled.decode_latent(z * s), arc_model.decode_latent(z), atol=1e-5)
    z0, report0 = gauss_newton_codes(arc_model, V, z, iterations=4)
    z1, report1 = gauss_newton_codes(scaled, V, z * s, iterations=4)
    assert np.mean(report0.final_error) < 0.5 * np.mean(report0.initial_error)
    np.testing.assert_allclose(report1.final_error, report0.final_error, rtol=0.02)
    np.testing.assert_allclose(z1 / s, z0, atol=1e-3 * np.abs(z0).max())


def _hinged_strips(n=16, hinges=6, amplitude=1.2, seed=0):
    """A strip of 7 units folded at 6 hinges by independent random angles (|angle| <= 1.2 rad).
    The coordinates of a chain of rotations span about 2 directions per hinge and more with their
    products; 12 training meshes do not span them, while the RIMD features of a fold are local."""
    P, F = strip(nx=29, ny=3, length=7.0, width=0.5)
    rng = np.random.default_rng(seed)
    xs = np.linspace(0, 7.0, hinges + 2)[1:-1]
    out = []
    for _ in range(n):
        V = P.copy()
        for xh, th in zip(xs[::-1], rng.uniform(-amplitude, amplitude, hinges)[::-1]):
            m = P[:, 0] > xh + 1e-9
            dx, dz = V[m, 0] - xh, V[m, 2]
            V[m, 0], V[m, 2] = xh + np.cos(th) * dx - np.sin(th) * dz, np.sin(th) * dx + np.cos(th) * dz
        out.append(V)
    return MeshCollection(np.array(out), F)


def test_default_inference_beats_pca_on_coordinates_where_the_shapes_are_not_linear():
    """Held-out error of the default path against PCA on coordinates and on aligned coordinates with
    every direction the 12 training meshes span (same split, same error). Measured: default 0.037
    (0.016 with 8 steps), PCA 0.049 (aligned 0.050), the paper's encoder 0.40."""
    coll = _hinged_strips()
    model = MeshVAEModel("rimd", TrainConfig(progress=False, latent_dim=16, seed=0), holdout_every=4).fit(coll)
    mask = model.holdout_mask_
    default = evaluate_model(model, coll, held_out_only=True)
    encoder = evaluate_model(model, coll, held_out_only=True, inference="encoder")
    assert default["inference"] == "gauss-newton" and encoder["inference"] == "encoder"
    for aligned in (False, True):
        pca = pca_baseline(coll.vertices[~mask], coll.vertices[mask], aligned=aligned)
        assert default["mean_vertex_error"] < pca["mean_vertex_error"] / 1.1, aligned
    assert default["mean_vertex_error"] < 0.25 * encoder["mean_vertex_error"]


def test_gauss_newton_reaches_the_finite_difference_fit(arcs, arc_model):
    held = np.flatnonzero(arc_model.holdout_mask_)
    V = arcs.vertices[held]
    e_gn = per_vertex_error(arc_model.reconstruct(V), V)
    e_fd = per_vertex_error(arc_model.reconstruct(V, inference="finite-difference"), V)
    assert np.mean(e_gn) <= 1.1 * np.mean(e_fd)


def test_inference_for_coordinate_kinds_and_a_conditional_model(arcs):
    labels = {"half": np.array(["a" if k < 10 else "b" for k in range(len(arcs.vertices))])}
    coll = MeshCollection(arcs.vertices, arcs.faces, names=arcs.names, labels=labels)
    for kind, lab in (("aligned", ()), ("rimd", ("half",))):
        m = MeshVAEModel(kind, TrainConfig(progress=False, latent_dim=4, epochs=20, seed=0), labels=lab,
                         holdout_every=4).fit(coll)
        V = coll.vertices[m.holdout_mask_]
        lab_held = {"half": labels["half"][m.holdout_mask_]} if lab else None
        e_enc = per_vertex_error(m.reconstruct(V, labels=lab_held, inference="encoder"), V)
        e_gn = per_vertex_error(m.reconstruct(V, labels=lab_held), V)
        assert np.all(e_gn <= e_enc * (1 + 1e-5) + 1e-12), kind


def test_inference_options_are_checked(arcs, arc_model):
    with pytest.raises(ValueError, match="inference must be one of"):
        arc_model.encode_meshes(arcs.vertices[:2], inference="newton")
    with pytest.raises(ValueError, match="iterations must be an integer >= 1"):
        arc_model.encode_meshes(arcs.vertices[:2], iterations=0)
    mu, sigma = arc_model.encode_meshes(arcs.vertices[:2], inference="encoder", return_sigma=True)
    assert mu.shape == sigma.shape == (2, 8) and np.all(sigma > 0)


def test_a_code_where_the_decoder_saturates_ends_the_fit_instead_of_failing(arcs, arc_model, tmp_path):
    """Far outside the training meshes every tanh output can saturate: the decoded mesh then no
    longer moves with the code (J = 0; found on notebook 11's bar with 8 training meshes). The fit
    stops at the best code found so far instead of failing on a singular system."""
    from meshvae_lib.model.meshvae_model import load_model

    saturated = load_model(arc_model.save(tmp_path / "arcs.pt"), arcs)
    with torch.no_grad():
        saturated.network_.decoder_head.bias.fill_(50.0)     # tanh(50 + W z) == 1.0 in float64
    V = arcs.vertices[:2]
    z0 = saturated.encode_meshes(V, inference="encoder")
    z, report = gauss_newton_codes(saturated, V, z0, iterations=3)
    np.testing.assert_array_equal(z, z0)
    assert np.all(report.decodes == 1) and np.all(report.iterations == 1)
    # a decoder that ignores the code altogether: nothing to fit
    with torch.no_grad():
        saturated.network_.decoder_head.weight.zero_()
    z, report = gauss_newton_codes(saturated, V, z0, iterations=3)
    np.testing.assert_array_equal(z, z0)


class _LinearState:
    """``P(u) = A u`` against a fixed target ``y``: the state marquardt_fit reads."""

    def __init__(self, A, y, u):
        self.positions = (A @ u).reshape(-1, 3)
        self.residual = y.reshape(-1, 3) - self.positions
        self.sq_error = float(np.sum(self.residual ** 2))
        self.mean_error = float(np.linalg.norm(self.residual, axis=1).mean())


def test_marquardt_fit_solves_a_linear_least_squares_problem():
    """On a linear P(u) = A u the damped steps converge to the least-squares solution (numpy's lstsq),
    whatever the scale of A's columns (Marquardt's scaling), and never raise the error."""
    from meshvae_lib.model.inference.gauss_newton import marquardt_fit

    rng = np.random.default_rng(0)
    A = rng.normal(size=(60, 5)) * np.array([1.0, 1e-3, 10.0, 0.1, 1e2])
    y = A @ rng.normal(size=5) + 0.01 * rng.normal(size=60)   # not in A's range: a non-zero optimum
    u_star = np.linalg.lstsq(A, y, rcond=None)[0]
    fit = marquardt_fit(np.zeros(5), lambda u: _LinearState(A, y, u), lambda s: A, iterations=10)
    assert np.allclose(fit.u, u_star, rtol=1e-5, atol=1e-8 * np.abs(u_star).max())
    assert fit.state.sq_error <= fit.start.sq_error
    assert fit.start.sq_error == pytest.approx(float(y @ y))
    assert 1 <= fit.jacobians <= 10 and fit.decodes >= fit.jacobians + 1


def test_marquardt_fit_stops_where_the_mesh_does_not_move_or_no_step_helps():
    from meshvae_lib import tolerances as tol
    from meshvae_lib.model.inference.gauss_newton import marquardt_fit

    A, y = np.ones((6, 2)), np.arange(6.0)
    # a zero Jacobian: one Jacobian computed, no step tried, the start returned
    fit = marquardt_fit(np.array([0.5, -1.0]), lambda u: _LinearState(A, y, u), lambda s: np.zeros((6, 2)), 4)
    assert (fit.jacobians, fit.decodes) == (1, 1) and np.array_equal(fit.u, [0.5, -1.0])

    # every trial decodes to an infinite error: GN_MAX_TRIES rejected tries, then the start
    def state_at(u):
        s = _LinearState(A, y, u)
        if np.any(u != 0):
            s.sq_error = np.inf
        return s

    fit = marquardt_fit(np.zeros(2), state_at, lambda s: A, 4)
    assert (fit.jacobians, fit.decodes) == (1, 1 + tol.GN_MAX_TRIES)
    assert np.array_equal(fit.u, [0.0, 0.0]) and fit.state is fit.start

    # no parameters: nothing to fit, whatever the iterations; a negative count is refused
    fit = marquardt_fit(np.zeros(0), lambda u: _LinearState(np.zeros((6, 0)), y, u), lambda s: np.zeros((6, 0)), 4)
    assert (fit.jacobians, fit.decodes) == (0, 1)
    with pytest.raises(ValueError, match="iterations"):
        marquardt_fit(np.zeros(2), lambda u: _LinearState(A, y, u), lambda s: A, -1)
