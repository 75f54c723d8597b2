"""The corrected decoder as a network: the ``"corrected"`` architecture of
:mod:`meshvae_lib.model.networks` (issue 47).

Below the training rank (a latent size D smaller than the directions the training meshes span) the
linear decoder is no longer the optimum of a D-dimensional latent, and a nonlinear map may reach
what D principal directions cannot. :class:`~meshvae_lib.model.corrected_decoder.CorrectedLinearDecoder`
asks that safely: the linear decoder plus a correction that is zero at the start, trained with free
codes and kept only where it lowers the error of validation meshes. This module gives it the
network contract (:class:`~meshvae_lib.model.network_base.Network`), so that the estimator, the
checkpoint, every inference (Gauss-Newton through the decoder's autograd linearisation), generation
and ``meshvae train`` take it by name:

- ``start`` fits the estimator on the normalised training rows (its own validation rows are set
  aside from them) and copies what it learned into buffers and the correction's weights; the
  trainer then skips its epochs (``linear_optimum``: the start is already trained);
- ``decode`` is the estimator's: ``tanh(mean + (s * z + g(z)) u @ basis)`` in float64 (``s`` the
  whitened codes' spreads, ``u`` the first direction's, ``g`` the correction, absent when the
  linear decoder was kept);
- ``encode``'s mean is the estimator's code fit of the rows' pre-activations (the projection,
  refined by L-BFGS through the correction): an auto-decoder has no encoder, and its codes are what
  it was trained with; the default inference then fits the code to the vertices (Gauss-Newton). Its deviation is the linear-Gaussian posterior's of the PCA start
  (:func:`~meshvae_lib.model.posterior.linear_gaussian_sigma`), fixed.

The codes are whitened (unit variance over the training rows), so the prior N(0, I) describes
them and sampling it generates.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import torch
from torch import nn

from meshvae_lib.defaults import CORRECTION_CODE_PRIOR, CORRECTION_FIT_ITERATIONS, CORRECTION_HIDDEN, CORRECTION_MIN_GAIN, SIGMA_MAX
from meshvae_lib.model.corrected_decoder import CorrectedLinearDecoder
from meshvae_lib.model.network_base import Network
from meshvae_lib.model.posterior import linear_gaussian_sigma

__all__ = ["CorrectedVAE", "CorrectedOptions"]


@dataclass(frozen=True)
class CorrectedOptions:
    """The corrected decoder's options (``TrainConfig.network_options``; ``meshvae train`` flags)."""

    correction_hidden: tuple[int, ...] = field(default=tuple(CORRECTION_HIDDEN), metadata={
        "flag": "--correction-hidden", "metavar": "H",
        "help": "the correction network's internal layer sizes"})
    min_gain: float = field(default=CORRECTION_MIN_GAIN, metadata={
        "flag": "--correction-min-gain", "metavar": "G",
        "help": "the correction is kept only if its gain on validation meshes is above this fraction of the"
                " linear decoder's error (one-sided 97.5%% bound)"})

    def __post_init__(self):
        hidden = tuple(self.correction_hidden)
        if not hidden or any(isinstance(h, bool) or int(h) != h or int(h) < 1 for h in hidden):
            raise ValueError(f"correction_hidden must be one or more positive integers, got {self.correction_hidden!r}")
        if not 0.0 <= float(self.min_gain) < 1.0:
            raise ValueError(f"min_gain must lie in [0, 1), got {self.min_gain!r}")


class CorrectedVAE(Network):
    """The linear (PCA) decoder of ``latent_dim`` whitened codes plus a correction network, kept only
    where it helps on validation meshes (module docstring).

    Parameters
    ----------
    n_features : int, K.
    latent_dim : int, D.
    rank : int, r, the principal directions the decoder writes into (r <= D when the linear decoder
        was kept; up to ``CORRECTION_RANK`` otherwise).
    correction_hidden : sequence of int, the correction's internal layers.
    corrected : bool, whether the correction was kept (False: the linear decoder, no correction module).
    sigma_max : float, the deviation head's bound (the deviations are fixed below it).
    code_prior, fit_iterations : the code fit's penalty and L-BFGS iterations (the estimator's).
    choice : str, why the correction was kept or not (the estimator's report).

    Buffers (zeros until :meth:`start` fills them or a checkpoint is loaded): ``row_mean (K,)``,
    ``row_basis (r, K)`` and ``row_scale (r,)`` float64, the pre-activations' principal directions;
    ``unit ()`` and ``spread ()`` float64, the first direction's spread and the training rows' mean
    squared distance from their mean; ``code_sigma (D,)`` float32, the posterior deviations.
    """

    architecture = "corrected"
    description = ("the linear (PCA) decoder plus a correction network that starts at zero, kept only where it"
                   " lowers the error of validation meshes (for latent sizes below the training rank)")
    Options = CorrectedOptions
    outputs = ("tanh",)
    pca_start = True
    trains_in_start = True
    linear_optimum = ("the corrected decoder is trained in its start: the correction with free codes, its steps"
                      " chosen on validation meshes, and kept only where it beats the linear decoder on others")

    def __init__(self, n_features: int, latent_dim: int, rank: int, correction_hidden=tuple(CORRECTION_HIDDEN),
                 corrected: bool = False, sigma_max: float = SIGMA_MAX, code_prior: float = CORRECTION_CODE_PRIOR,
                 fit_iterations: int = CORRECTION_FIT_ITERATIONS, choice: str = ""):
        super().__init__()
        for name, value in (("n_features", n_features), ("latent_dim", latent_dim), ("rank", rank)):
            if int(value) < 1:
                raise ValueError(f"{name} must be a positive integer, got {value}")
        self.n_features, self.latent_dim, self.rank = int(n_features), int(latent_dim), int(rank)
        self.correction_hidden = tuple(int(h) for h in correction_hidden)
        self.corrected, self.sigma_max = bool(corrected), float(sigma_max)
        self.code_prior, self.fit_iterations, self.choice = float(code_prior), int(fit_iterations), str(choice)
        self.register_buffer("row_mean", torch.zeros(self.n_features, dtype=torch.float64))
        self.register_buffer("row_basis", torch.zeros(self.rank, self.n_features, dtype=torch.float64))
        self.register_buffer("row_scale", torch.zeros(self.rank, dtype=torch.float64))
        self.register_buffer("unit", torch.ones((), dtype=torch.float64))
        self.register_buffer("spread", torch.ones((), dtype=torch.float64))
        self.register_buffer("code_sigma", torch.ones(self.latent_dim))
        self.correction = self._estimator_shell()._network(self.latent_dim, self.rank) if self.corrected else None

    # -- configuration -------------------------------------------------------------------------
    def config(self) -> dict:
        """Constructor arguments, enough to rebuild the network: ``CorrectedVAE(**net.config())``."""
        return {"n_features": self.n_features, "latent_dim": self.latent_dim, "rank": self.rank,
                "correction_hidden": list(self.correction_hidden), "corrected": self.corrected,
                "sigma_max": self.sigma_max, "code_prior": self.code_prior, "fit_iterations": self.fit_iterations,
                "choice": self.choice}

    @classmethod
    def check_config(cls, config) -> None:
        """ValueError for what the corrected decoder does not train: a random start, internal layers
        of the mesh VAE, a sigma_object prior, or an epoch count (early stopping on or off: its
        training stops on validation meshes by itself)."""
        if config.init != "pca":
            raise ValueError("TrainConfig.init: the corrected decoder starts at the linear optimum (pca);"
                             " a random start is the mesh-vae architecture's")
        if config.hidden:
            raise ValueError("TrainConfig.hidden: the corrected decoder has its own layers (correction_hidden)")
        if config.sigma_object is not None:
            raise ValueError("TrainConfig.sigma_object: the corrected decoder is trained with the standard prior")
        if config.early_stopping is not None:
            raise ValueError("TrainConfig.early_stopping: the corrected decoder chooses its training steps on"
                             " validation meshes itself (leave it at its default)")

    @classmethod
    def weights_estimate(cls, n_features: int, config) -> int:
        """The buffers (K (r + 1)) plus the correction's weights, r = ``CORRECTION_RANK``."""
        from meshvae_lib.defaults import CORRECTION_RANK, DEFAULT_LATENT

        sizes = [config.latent_dim or DEFAULT_LATENT, *cls.options(config).correction_hidden, CORRECTION_RANK]
        return n_features * (CORRECTION_RANK + 1) + sum(a * b for a, b in zip(sizes, sizes[1:]))

    @classmethod
    def start(cls, x: torch.Tensor, n_conditions: int, config, mesh=None) -> "CorrectedVAE":
        """Fit the corrected decoder on the normalised training rows ``x (N, K)`` float32
        (N >= latent_dim + 2) with ``config``'s latent size, seed and options, and return it as a
        network (eval mode). The mesh is not needed."""
        if n_conditions:
            raise ValueError("the corrected decoder is unconditional: no condition inputs")
        config = config.resolve(x.shape[0], n_conditions)
        options = cls.options(config)
        estimator = CorrectedLinearDecoder(int(config.latent_dim), hidden=tuple(options.correction_hidden),
                                           min_gain=float(options.min_gain), output="tanh", seed=int(config.seed))
        estimator.fit(x.detach().double().cpu().numpy())
        return cls.from_estimator(estimator, config.alpha)

    @classmethod
    def from_estimator(cls, estimator: CorrectedLinearDecoder, alpha: float) -> "CorrectedVAE":
        """The network of a fitted tanh-output ``estimator``; ``alpha`` (Eq. 4's weight) sets the fixed
        posterior deviations, those of the PCA start's linear-Gaussian model."""
        if estimator.output != "tanh":
            raise ValueError(f"the network decodes through a tanh; the estimator's output is {estimator.output!r}")
        report = estimator.report_
        net = cls(estimator.n_features_in_, estimator.latent_dim, len(estimator.scale_), estimator.hidden,
                  corrected=estimator.correction_ is not None, code_prior=estimator.code_prior,
                  fit_iterations=estimator.fit_iterations, choice=f"{report.kept}: {report.reason}")
        D, d = net.latent_dim, min(net.latent_dim, net.rank)
        sigma = np.ones(D)
        sigma[:d] = linear_gaussian_sigma(estimator.scale_[:d], alpha, net.n_features)
        with torch.no_grad():
            for name, value in (("row_mean", estimator.mean_), ("row_basis", estimator.basis_),
                                ("row_scale", estimator.scale_), ("unit", estimator._unit),
                                ("spread", estimator.spread_), ("code_sigma", sigma)):
                getattr(net, name).copy_(torch.as_tensor(np.asarray(value)))
            if net.corrected:
                net.correction.load_state_dict(estimator.correction_.state_dict())
        return net.eval()

    def describe(self) -> str:
        """The network in a few words (for summaries)."""
        layers = " -> ".join(map(str, self.correction_hidden))
        kept = f"a correction ({layers}) kept" if self.corrected else "no correction (the linear decoder kept)"
        return f"linear decoder of {min(self.latent_dim, self.rank)} principal directions, {kept}"

    def used_latent_dims(self) -> np.ndarray:
        """Every latent dimension with the correction (it reads them all); without it, those with a
        principal direction."""
        return np.arange(self.latent_dim if self.corrected else min(self.latent_dim, self.rank))

    # -- the estimator's arithmetic ------------------------------------------------------------
    def _estimator_shell(self) -> CorrectedLinearDecoder:
        return CorrectedLinearDecoder(self.latent_dim, hidden=self.correction_hidden, code_prior=self.code_prior,
                                      fit_iterations=self.fit_iterations, output="tanh")

    def estimator(self) -> CorrectedLinearDecoder:
        """A :class:`CorrectedLinearDecoder` holding this network's decoder (sharing its correction
        module), for its code fit: its ``_codes`` are this network's encoder means (it has no
        ``report_``: the choice is this network's ``choice``)."""
        est = self._estimator_shell()
        est.mean_, est.basis_, est.scale_ = (t.detach().cpu().numpy() for t in (self.row_mean, self.row_basis,
                                                                               self.row_scale))
        est._unit, est.spread_, est.n_features_in_ = float(self.unit), float(self.spread), self.n_features
        est.correction_ = self.correction
        return est

    # -- the four steps ------------------------------------------------------------------------
    def encode(self, x: torch.Tensor, c: torch.Tensor | None = None) -> tuple[torch.Tensor, torch.Tensor]:
        """x (B, K) float32 normalised rows -> (mu (B, D), sigma (B, D)) float32: mu the code fit of
        their pre-activations (the estimator's ``codes(x, through_output=False)``: the projection,
        refined through the correction; rows beyond [-1, 1] are clipped), sigma the fixed deviations.
        The fit through the tanh is left to the inference (Gauss-Newton on the vertices, the
        default): it would double the time per mesh (measured on pcow/3, latent 16)."""
        x = self.with_condition(x, c, self.n_features, "features")
        with torch.enable_grad():
            z = self.estimator()._codes(x.detach().double().cpu().numpy(), through_output=False)
        mu = torch.as_tensor(z, dtype=x.dtype, device=x.device)
        return mu, self.code_sigma.to(x.dtype).expand(x.shape[0], self.latent_dim)

    def decode(self, z: torch.Tensor, c: torch.Tensor | None = None) -> torch.Tensor:
        """z (B, D) -> rows (B, K) in (-1, 1), in z's dtype (computed in float64)."""
        z = self.with_condition(z, c, self.latent_dim, "latent vectors")
        s = self.row_scale[: min(self.latent_dim, self.rank)] / self.unit
        coeff = CorrectedLinearDecoder._decode_coeff(self.correction, z.double(), s, self.rank)
        return torch.tanh(self.row_mean + (coeff * self.unit) @ self.row_basis).to(z.dtype)
