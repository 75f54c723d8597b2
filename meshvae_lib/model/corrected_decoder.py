"""A decoder whose nonlinearity can only help: the linear (PCA) decoder plus a correction that is zero
at the start, kept only where it lowers the error of validation rows (issue 47).

Below the training rank the linear decoder is no longer the optimum of a D-dimensional latent: rows
that lie on a curved set of dimension d <= D (a body whose joints turn) are reached by a nonlinear
map of D numbers but not by any D principal directions. The question is whether a network can learn
that map from a few hundred meshes without memorising them. This estimator asks it safely:

- the rows' principal directions: ``mean (K,)``, an orthonormal ``basis (r, K)`` and the coefficient
  spreads ``scale (r,)``; the linear decoder is ``y = mean + (scale[:D] * z) @ basis[:D]`` with
  whitened codes ``z (D,)`` (PCA with D directions, the linear floor of the same capacity);
- the corrected decoder adds ``g(z) @ basis``, a small fully connected network ``g : R^D -> R^r``
  whose last layer starts at zero, so that training starts at the linear optimum;
- training is the auto-decoder's (every training row has a free code, trained with ``g`` by Adam,
  with a Gaussian penalty on the codes and weight decay on ``g``), and it is steered by validation
  rows set aside from the training rows: their codes are fitted to them with ``g`` frozen (as
  held-out meshes' codes are), and the network of the best error on half of them is kept;
- the other half chooses: unless the corrected decoder's error there (in the measure the caller
  gives, e.g. the vertex error) gains over the linear decoder's by more than ``min_gain`` of it with
  the ``confidence`` of a one-sided t bound, the estimator returns the linear decoder,
  refitted on all rows. So a few lucky rows do not choose the correction, and where it is kept its
  gain was measured on rows that neither trained nor stopped it.

Rows are vertex coordinates (``output="linear"``) or normalised RIMD rows (``output="tanh"``).
"""

from __future__ import annotations

import logging

import numpy as np

from meshvae_lib.defaults import (CORRECTION_CHECK_EVERY, CORRECTION_CODE_PRIOR, CORRECTION_CONFIDENCE, CORRECTION_FIT_ITERATIONS,
                                  CORRECTION_HIDDEN, CORRECTION_LR, CORRECTION_MAX_STEPS, CORRECTION_MIN_CHOICE_ROWS, CORRECTION_MIN_GAIN,
                                  CORRECTION_PATIENCE, CORRECTION_RANK, CORRECTION_VALIDATION_EVERY,
                                  CORRECTION_WEIGHT_DECAY)
from meshvae_lib.model.correction_choice import CorrectionReport, checked_scores, gain_lower_bound
from meshvae_lib.model.gram_pca import principal_directions
from meshvae_lib.model.threads import torch_threads
from meshvae_lib.tolerances import CODE_FIT_CHANGE_TOL, CODE_FIT_GRAD_TOL, TANH_ROW_CLIP
from meshvae_lib.validation import check_is_fitted

__all__ = ["CorrectedLinearDecoder"]

log = logging.getLogger(__name__)


class CorrectedLinearDecoder:
    """The linear decoder of ``latent_dim`` principal directions plus a correction network that is
    zero at the start, kept only where it helps on validation rows (see the module's docstring).

    Parameters
    ----------
    latent_dim : int, D >= 1.
    hidden : tuple of int, the correction network's internal layers (SiLU after each).
    weight_decay : float >= 0, AdamW's decay of the correction's weights.
    code_prior : float >= 0, weight of the Gaussian penalty ``mean |z|^2 / D`` on the codes (the rows'
        error is measured relative to their total variance, so the two are comparable).
    lr : float > 0, Adam's step for the codes and the network.
    max_steps, check_every, patience : at most ``max_steps`` full-batch steps; the validation error is
        measured every ``check_every`` steps, and training stops after ``patience`` checks without a
        new best.
    validation_every : every k-th training row (from the ``k // 2``-th) is set aside for validation;
        alternately, those rows stop training (their error picks the best step) or choose between
        the corrected and the linear decoder (so that the choice is not biased by the pick).
    min_gain, confidence : the corrected decoder is kept only if the one-sided ``confidence`` lower
        bound of its mean gain per choosing row (Student's t) is above ``min_gain`` times the linear
        decoder's mean error there (a few lucky rows do not choose it).
    rank : the most principal directions the correction writes into (r).
    fit_iterations : L-BFGS iterations when codes are fitted to rows.
    output : "linear" (rows are the decoder's output: vertex coordinates) or "tanh" (rows in (-1, 1)
        are ``tanh`` of the decoder's output, as the mesh VAE's normalised RIMD rows: the principal
        directions and the correction live in the pre-activations ``atanh(x)``, and codes are fitted
        to the rows through the tanh).
    seed : int, the network's initialisation and nothing else (training is full-batch).

    Attributes (after ``fit``)
    --------------------------
    mean_ : (K,) float64; basis_ : (r, K) float64, orthonormal rows; scale_ : (r,) float64; spread_ :
    float, the training rows' mean squared distance from their mean;
    correction_ : the torch module g (None when the linear decoder was kept); report_ :
    :class:`CorrectionReport`; n_features_in_ : K.
    """

    def __init__(self, latent_dim: int, hidden=CORRECTION_HIDDEN, weight_decay: float = CORRECTION_WEIGHT_DECAY,
                 code_prior: float = CORRECTION_CODE_PRIOR, lr: float = CORRECTION_LR,
                 max_steps: int = CORRECTION_MAX_STEPS, check_every: int = CORRECTION_CHECK_EVERY,
                 patience: int = CORRECTION_PATIENCE, validation_every: int = CORRECTION_VALIDATION_EVERY,
                 min_gain: float = CORRECTION_MIN_GAIN, confidence: float = CORRECTION_CONFIDENCE, rank: int = CORRECTION_RANK,
                 fit_iterations: int = CORRECTION_FIT_ITERATIONS, output: str = "linear", seed: int = 0):
        self.latent_dim, self.hidden, self.weight_decay, self.code_prior = latent_dim, hidden, weight_decay, code_prior
        self.lr, self.max_steps, self.check_every, self.patience = lr, max_steps, check_every, patience
        self.validation_every, self.min_gain, self.confidence = validation_every, min_gain, confidence
        self.rank, self.fit_iterations, self.output, self.seed = rank, fit_iterations, output, seed

    # -- checks ------------------------------------------------------------------------------------
    def _check_params(self) -> None:
        for name in ("latent_dim", "max_steps", "check_every", "patience", "rank", "fit_iterations"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 1:
                raise ValueError(f"{name} must be a positive integer, got {v!r}")
        if isinstance(self.validation_every, bool) or not isinstance(self.validation_every, (int, np.integer)) \
                or self.validation_every < 2:
            raise ValueError(f"validation_every must be an integer >= 2, got {self.validation_every!r}")
        if any(isinstance(h, bool) or not isinstance(h, (int, np.integer)) or h < 1 for h in tuple(self.hidden)):
            raise ValueError(f"hidden must be positive integers, got {self.hidden!r}")
        if not 0.5 <= float(self.confidence) < 1.0:
            raise ValueError(f"confidence must lie in [0.5, 1), got {self.confidence!r}")
        for name in ("weight_decay", "code_prior"):
            v = getattr(self, name)
            if not 0.0 <= float(v) < float("inf"):
                raise ValueError(f"{name} must be finite and >= 0, got {v!r}")
        if not 0.0 < float(self.lr) < float("inf"):
            raise ValueError(f"lr must be positive, got {self.lr!r}")
        if self.output not in ("linear", "tanh"):
            raise ValueError(f"output must be 'linear' or 'tanh', got {self.output!r}")
        if not 0.0 <= float(self.min_gain) < 1.0:
            raise ValueError(f"min_gain must lie in [0, 1), got {self.min_gain!r}")

    def _rows(self, Y, what: str = "Y", training: bool = False) -> np.ndarray:
        """``Y`` as float64 (M, K), checked: finite, and training rows of a tanh output within [-1, 1]
        (held-out rows, normalised with the training range, may lie beyond: they are clipped)."""
        Y = np.asarray(Y, dtype=np.float64)
        if Y.ndim != 2 or Y.shape[0] < 1 or Y.shape[1] < 1:
            raise ValueError(f"{what} must be (n_rows, n_features), got shape {Y.shape}")
        if not np.isfinite(Y).all():
            raise ValueError(f"{what} has {int((~np.isfinite(Y)).sum())} non-finite values")
        if training and self.output == "tanh" and np.abs(Y).max() > 1.0:
            raise ValueError(f"{what}: training rows of a tanh output must lie in [-1, 1], got a value of {np.abs(Y).max():.6g}")
        return Y

    # -- fitting -----------------------------------------------------------------------------------
    def fit(self, X, score=None) -> "CorrectedLinearDecoder":
        """Fit on training rows ``X (N, K)`` float (N >= latent_dim + 2; with ``output="tanh"`` in
        (-1, 1)). Returns self.

        score : None (the squared row error), or ``score(rows (M, K), index (M,) int) -> (M,)``: the
            error of each reconstruction ``rows`` of training row ``X[index]`` in the measure that
            matters (e.g. the vertex error). Training follows the pre-activations' squared error; the
            choice between the corrected and the linear decoder follows ``score``.
        """
        self._check_params()
        X = self._rows(X, training=True)
        n, D = len(X), int(self.latent_dim)
        if n < D + 2:
            raise ValueError(f"need at least latent_dim + 2 = {D + 2} training rows, got {n}")
        self.n_features_in_, self.spread_ = X.shape[1], self._spread(X)
        Y = self._pre(X)
        k = int(self.validation_every)
        val = np.zeros(n, dtype=bool)
        val[k // 2::k] = True
        # the validation rows, alternately: those that stop training (and pick the best step) and
        # those that choose between the corrected and the linear decoder (unbiased by that pick)
        stop, choose = np.zeros(n, dtype=bool), np.zeros(n, dtype=bool)
        stop[np.flatnonzero(val)[0::2]] = True
        choose[np.flatnonzero(val)[1::2]] = True
        n_fit, n_val = int((~val).sum()), int(val.sum())
        none = dict(linear_validation=float("nan"), corrected_validation=float("nan"), best_step=0, steps=0)
        if n_fit < D + 2 or choose.sum() < CORRECTION_MIN_CHOICE_ROWS:
            self._keep_linear(Y, CorrectionReport(
                "linear", f"too few rows ({n}) to set every {k}-th aside for validation", **none,
                n_fit=n, n_validation=0, curve=[]))
            return self
        mean, basis, scale = principal_directions(Y[~val], max(int(self.rank), D))
        r = len(scale)
        if r <= D:
            self._keep_linear(Y, CorrectionReport(
                "linear", f"the training rows span {r} <= latent_dim = {D} directions: the linear decoder is exact",
                **none, n_fit=n_fit, n_validation=n_val, curve=[]))
            return self
        unit = float(scale[0])
        C_fit = (Y[~val] - mean) @ basis.T / unit  # (n_fit, r) coefficients
        Yv = Y[stop] - mean
        C_val = Yv @ basis.T / unit
        out_val = float(np.mean(np.sum(Yv * Yv, axis=1) - np.sum((C_val * unit) ** 2, axis=1)))
        energy = float(np.mean(np.sum(C_fit ** 2, axis=1)))
        linear_val = float(np.mean(np.sum(C_val[:, D:] ** 2, axis=1))) * unit ** 2 + out_val

        with torch_threads(1):  # thousands of small steps: one thread (see torch_threads)
            net, best, best_step, best_state, step, curve = self._train(C_fit, C_val, scale, unit, energy, out_val)
        report = dict(linear_validation=linear_val, corrected_validation=float(best), best_step=best_step,
                      steps=step, n_fit=n_fit, n_validation=n_val, curve=curve)
        if best_state is None:
            self._keep_linear(Y, CorrectionReport("linear", "no validation check was reached", **report))
            return self
        net.load_state_dict(best_state)
        net.eval()
        idx = np.flatnonzero(choose)
        self.mean_, self.basis_, self.scale_, self._unit, self.correction_ = mean, basis, scale, unit, None
        linear_rows = self._decode(self._codes(X[choose]))
        self.correction_ = net
        corrected_rows = self._decode(self._codes(X[choose]))
        if score is None:
            e_lin = np.sum((linear_rows - X[choose]) ** 2, axis=1)
            e_cor = np.sum((corrected_rows - X[choose]) ** 2, axis=1)
        else:
            e_lin, e_cor = (checked_scores(score, rows, idx) for rows in (linear_rows, corrected_rows))
        gain = e_lin - e_cor
        bound = gain_lower_bound(gain, float(self.confidence))
        report.update(linear_score=float(e_lin.mean()), corrected_score=float(e_cor.mean()), gain_lower_bound=bound,
                      linear_errors=e_lin.tolist(), corrected_errors=e_cor.tolist())
        if bound > float(self.min_gain) * e_lin.mean():
            self.report_ = CorrectionReport("corrected", f"validation error {e_cor.mean():.4g} against the linear "
                f"decoder's {e_lin.mean():.4g} ({len(gain)} meshes; the gain's lower bound {bound:.3g} > "
                f"{float(self.min_gain):.3g} x the linear error)", **report)
        else:
            self._keep_linear(Y, CorrectionReport("linear", f"the correction's validation error {e_cor.mean():.4g} "
                f"against the linear decoder's {e_lin.mean():.4g} ({len(gain)} meshes): the gain's lower bound "
                f"{bound:.3g} is not above {float(self.min_gain):.3g} x the linear error", **report))
        log.info("corrected decoder (latent %d): kept the %s decoder (%s)", D, self.report_.kept, self.report_.reason)
        return self

    def fit_linear(self, X) -> "CorrectedLinearDecoder":
        """Fit the linear decoder alone (what :meth:`fit` falls back to) on rows ``X (N, K)``: the
        linear floor of the same capacity, with codes fitted as :meth:`codes` fits them. Returns self."""
        self._check_params()
        X = self._rows(X, training=True)
        self.n_features_in_, self.spread_ = X.shape[1], self._spread(X)
        self._keep_linear(self._pre(X), CorrectionReport(
            "linear", "fit_linear: no correction trained", float("nan"), float("nan"), 0, 0, len(X), 0, []))
        return self

    def _train(self, C_fit: np.ndarray, C_val: np.ndarray, scale: np.ndarray, unit: float, energy: float,
               out_val: float):
        """Adam on the free codes of coefficient rows ``C_fit (n_fit, r)`` and the correction, with
        early stopping on the stopping rows ``C_val (n_stop, r)``. Returns the network, the best
        validation error, its step and state (None if no check was reached), the steps and the curve."""
        import torch

        D, r = int(self.latent_dim), C_fit.shape[1]
        s = torch.tensor(scale[:D] / unit, dtype=torch.float64)
        with torch.random.fork_rng(devices=[]):  # the seed sets this network, not the caller's RNG
            torch.manual_seed(int(self.seed))
            net = self._network(D, r)
        Ct = torch.tensor(C_fit)
        Z = torch.tensor(C_fit[:, :D] / (scale[:D] / unit), requires_grad=True)
        opt = torch.optim.AdamW([{"params": net.parameters(), "weight_decay": float(self.weight_decay)},
                                 {"params": [Z], "weight_decay": 0.0}], lr=float(self.lr))
        Cv = torch.tensor(C_val)
        best, best_step, best_state, since, curve, step = np.inf, 0, None, 0, [], 0
        while step < int(self.max_steps):
            opt.zero_grad()
            err = torch.sum((Ct - self._decode_coeff(net, Z, s, r)) ** 2, dim=1).mean() / energy
            loss = err + float(self.code_prior) * torch.mean(Z * Z)
            loss.backward()
            opt.step()
            step += 1
            if step % int(self.check_every) == 0:
                zv = self._fit_coeff_codes(net, Cv, s, r, energy)
                with torch.no_grad():
                    v = float(torch.sum((Cv - self._decode_coeff(net, zv, s, r)) ** 2, dim=1).mean()) * unit ** 2
                curve.append((step, float(err.detach()) * energy * unit ** 2, v + out_val))
                if v + out_val < best:
                    best, best_step, since = v + out_val, step, 0
                    best_state = {key: t.detach().clone() for key, t in net.state_dict().items()}
                else:
                    since += 1
                    if since >= int(self.patience):
                        break
        return net, best, best_step, best_state, step, curve

    @staticmethod
    def _spread(X: np.ndarray) -> float:
        """The training rows' mean squared distance from their mean (1 where they are all equal): the
        unit of a tanh output's code fit, so that a row's code does not depend on the rows beside it."""
        return float(np.mean(np.sum((X - X.mean(0)) ** 2, axis=1))) or 1.0

    def _pre(self, X: np.ndarray) -> np.ndarray:
        """The rows' pre-activations: ``atanh`` of rows clipped into (-1, 1) for a tanh output."""
        return np.arctanh(np.clip(X, -TANH_ROW_CLIP, TANH_ROW_CLIP)) if self.output == "tanh" else X

    def _keep_linear(self, Y: np.ndarray, report: CorrectionReport) -> None:
        self.mean_, self.basis_, self.scale_ = principal_directions(Y, int(self.latent_dim))
        self.correction_ = None
        self._unit = float(self.scale_[0])
        self.report_ = report

    def _network(self, D: int, r: int):
        from torch import nn

        layers, width = [], D
        for h in tuple(self.hidden):
            layers += [nn.Linear(width, int(h)), nn.SiLU()]
            width = int(h)
        last = nn.Linear(width, r)
        nn.init.zeros_(last.weight)
        nn.init.zeros_(last.bias)
        return nn.Sequential(*layers, last).double()

    @staticmethod
    def _decode_coeff(net, Z, s, r: int):
        """Coefficients (in units of the first direction's spread) of codes ``Z (M, D)``."""
        import torch

        lin = torch.nn.functional.pad(Z[:, : len(s)] * s, (0, r - len(s)))
        return lin if net is None else lin + net(Z)

    def _fit_coeff_codes(self, net, C, s, r: int, energy: float):
        """Codes ``(M, D)`` of coefficient rows ``C (M, r)`` (pre-activations): the projection, then
        L-BFGS on their error plus the code penalty through the correction (all rows at once; the
        objective is a sum of one term per row)."""
        import torch

        D = len(s)
        z = (C[:, :D] / s).clone().requires_grad_(True)
        if net is None:
            return z.detach()
        opt = torch.optim.LBFGS([z], lr=1.0, max_iter=int(self.fit_iterations), line_search_fn="strong_wolfe",
                                tolerance_grad=CODE_FIT_GRAD_TOL, tolerance_change=CODE_FIT_CHANGE_TOL)

        def closure():
            opt.zero_grad()
            loss = torch.sum((C - self._decode_coeff(net, z, s, r)) ** 2) / energy \
                + float(self.code_prior) * torch.sum(z * z) / D
            loss.backward()
            return loss

        opt.step(closure)
        return z.detach()

    def _codes(self, X: np.ndarray, through_output: bool = True) -> np.ndarray:
        """:meth:`codes` without the checks."""
        import torch

        D, r, unit = int(self.latent_dim), len(self.scale_), self._unit
        d = min(D, r)
        s = torch.tensor(self.scale_[:d] / unit)
        energy = float(np.sum((self.scale_ / unit) ** 2))
        C = torch.tensor((self._pre(X) - self.mean_) @ self.basis_.T / unit)
        with torch_threads(1):  # a small problem (see torch_threads)
            z = self._fit_coeff_codes(self.correction_, C, s, r, energy)
        if self.output == "tanh" and through_output:  # the pre-activations' fit starts the rows' own fit
            z = self._fit_output_codes(z, torch.tensor(X), s, r)
        return torch.nn.functional.pad(z, (0, D - z.shape[1])).numpy()

    def _fit_output_codes(self, z0, X, s, r: int):
        """Codes that fit rows ``X (M, K)`` through the tanh: L-BFGS on ``|tanh(decoded) - X|^2``
        relative to the training rows' spread (``spread_``), from ``z0``, plus the code penalty where the correction is
        kept (the linear decoder's fit is plain least squares, as its projection is for coordinates)."""
        import torch

        mean, basis = torch.tensor(self.mean_), torch.tensor(self.basis_ * self._unit)
        D = z0.shape[1]
        prior = 0.0 if self.correction_ is None else float(self.code_prior)  # the linear decoder: least squares
        spread = self.spread_
        z = z0.clone().requires_grad_(True)
        opt = torch.optim.LBFGS([z], lr=1.0, max_iter=int(self.fit_iterations), line_search_fn="strong_wolfe",
                                tolerance_grad=CODE_FIT_GRAD_TOL, tolerance_change=CODE_FIT_CHANGE_TOL)

        def closure():
            opt.zero_grad()
            rows = torch.tanh(mean + self._decode_coeff(self.correction_, z, s, r) @ basis)
            loss = torch.sum((rows - X) ** 2) / spread + prior * torch.sum(z * z) / D
            loss.backward()
            return loss

        opt.step(closure)
        return z.detach()

    # -- use ---------------------------------------------------------------------------------------
    @property
    def kept_(self) -> str:
        """"corrected" or "linear": which decoder ``fit`` returned."""
        check_is_fitted(self, "report_")
        return self.report_.kept

    def codes(self, X, through_output: bool = True) -> np.ndarray:
        """Whitened codes ``(M, D)`` float64 of rows ``X (M, K)``: the projection of their
        pre-activations onto the D principal directions, refined through the correction where it was
        kept, and for a tanh output (unless ``through_output`` is False) fitted to the rows themselves
        through the tanh (held-out rows beyond [-1, 1] are clipped to ``TANH_ROW_CLIP`` for the projection only)."""
        check_is_fitted(self, "report_")
        X = self._rows(X, "X")
        if X.shape[1] != self.n_features_in_:
            raise ValueError(f"rows must have {self.n_features_in_} components, got {X.shape[1]}")
        return self._codes(X, through_output)

    def decode(self, Z) -> np.ndarray:
        """Rows ``(M, K)`` float64 of codes ``Z (M, D)`` (through the tanh for a tanh output)."""
        check_is_fitted(self, "report_")
        Z = self._rows(Z, "Z")
        D = int(self.latent_dim)
        if Z.shape[1] != D:
            raise ValueError(f"codes must have {D} components, got {Z.shape[1]}")
        return self._decode(Z)

    def _decode(self, Z: np.ndarray) -> np.ndarray:
        """:meth:`decode` without the checks."""
        import torch

        s = torch.tensor(self.scale_[: min(int(self.latent_dim), len(self.scale_))] / self._unit)
        with torch.no_grad():
            c = self._decode_coeff(self.correction_, torch.tensor(Z), s, len(self.scale_)).numpy()
        Y = self.mean_ + (c * self._unit) @ self.basis_
        return np.tanh(Y) if self.output == "tanh" else Y

    def reconstruct(self, X) -> np.ndarray:
        """``decode(codes(X))``: rows ``(M, K)`` float64."""
        return self.decode(self.codes(X))
