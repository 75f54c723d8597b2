"""How the corrected decoder is chosen over the linear one: the lower confidence bound of its gain on
validation meshes, and the report of the choice (``corrected_decoder``)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["CorrectionReport", "checked_scores", "gain_lower_bound"]


def gain_lower_bound(gain: np.ndarray, confidence: float) -> float:
    """The one-sided ``confidence`` lower bound of the mean of ``gain (n >= 2,)`` float (Student's t
    with n - 1 degrees of freedom): ``mean - t_q(n - 1) * std / sqrt(n)``."""
    from scipy.stats import t

    gain = np.asarray(gain, dtype=np.float64).reshape(-1)
    if gain.size < 2:
        raise ValueError(f"need at least 2 gains for a bound, got {gain.size}")
    return float(gain.mean() - t.ppf(confidence, gain.size - 1) * gain.std(ddof=1) / np.sqrt(gain.size))


def checked_scores(score, rows: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """``score(rows, idx)`` (the caller's error of each reconstruction ``rows (M, K)`` of the rows
    ``idx (M,)``), checked: (M,) finite float64, else ValueError showing what came back."""
    e = np.asarray(score(rows, idx), dtype=np.float64)
    if e.shape != (len(idx),) or not np.isfinite(e).all():
        raise ValueError(f"score must return ({len(idx)},) finite errors, got shape {e.shape}"
                         f" with {int((~np.isfinite(e)).sum()) if e.size else 0} non-finite values")
    return e


@dataclass
class CorrectionReport:
    """What :meth:`CorrectedLinearDecoder.fit` measured and chose.

    kept : "corrected" or "linear"; reason : a sentence saying why; linear_validation,
    corrected_validation : mean squared row error of the validation rows (per row, summed over the K
    components) with the linear decoder and with the best corrected one (NaN where none was trained);
    best_step, steps : the Adam step of the best validation error and the steps taken; n_fit,
    n_validation : the rows trained on and set aside; curve : (step, training error, validation
    error of the stopping rows) at every check; linear_score, corrected_score : the mean of ``score``
    over the choosing rows for both decoders, and linear_errors, corrected_errors : their values row
    by row; gain_lower_bound : the lower confidence bound of the mean gain per row
    (:func:`gain_lower_bound`; the correction is kept only where it is above ``min_gain`` times the
    linear decoder's mean error).
    """

    kept: str
    reason: str
    linear_validation: float
    corrected_validation: float
    best_step: int
    steps: int
    n_fit: int
    n_validation: int
    curve: list
    linear_score: float = float("nan")
    corrected_score: float = float("nan")
    gain_lower_bound: float = float("nan")
    linear_errors: list = field(default_factory=list)
    corrected_errors: list = field(default_factory=list)
