"""Synthesis-based exploration of the shape space (paper Sec. 5.5, Fig. 8).

The paper trains the extended mesh VAE on SCAPE with ``sigma_object = (0.1, 0.1, 0.5, 0.5, 1, ...)``
(``defaults.EXPLORATION_SIGMA_OBJECT``, padded with ones by ``train_config.pad_sigma_object``)
so that the first dimensions capture the dominant deformations, then browses the latent space in
two levels: a grid over dimensions 1-2 in [-2, 2] (the others at 0), and, with dimensions 1-2 fixed
at a chosen point, a grid over dimensions 3-4. It reads off what each dimension controls: height
(standing to squatting), the supporting leg, arm height, facing direction.

Here that reading is measured rather than eyeballed: ``humanoid_regions`` finds feet, hands and the
torso on a rest-pose humanoid, ``measure_humanoid`` turns every mesh into numbers (height, which
foot is lower, hand height, yaw of the torso), and ``dimension_effects`` sweeps each latent
dimension alone and reports its correlation with and its effect on every measurement, in units of
the measurement's spread over the training set.

Latent dimensions are 0-based in the code (the paper's "dimension 1" is index 0).
Conventions of the humanoid: y up, x the character's left, z forward (``data_synth.humanoid``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np

from meshvae_lib import defaults as hp
from meshvae_lib.geometry.alignment import rigid_transform
from meshvae_lib.model.evaluation import per_vertex_error
from meshvae_lib.validation import check_rows, check_vertices

__all__ = [
    "latent_grid",
    "explore",
    "ExplorationGrid",
    "humanoid_regions",
    "measure_humanoid",
    "HUMANOID_MEASUREMENTS",
    "latent_measurement_correlation",
    "dimension_effects",
    "DimensionEffects",
    "dimension_displacement",
    "data_spread",
]

#: names returned by ``measure_humanoid``, in order.
HUMANOID_MEASUREMENTS = ("height", "support", "arm_height", "facing")


def latent_grid(base, dims: Sequence[int] = (0, 1), values_a=None, values_b=None, n: int = 5,
                value_range=hp.EXPLORATION_RANGE) -> np.ndarray:
    """Latent vectors on a 2D grid: ``base`` with dimensions ``dims`` replaced by grid values.

    Parameters
    ----------
    base : (D,) float, the other dimensions' values (the paper: 0 at the first level, the chosen
        point at the second)
    dims : two distinct ints in [0, D)
    values_a, values_b : 1D float arrays, default ``linspace(*value_range, n)``

    Returns
    -------
    Z : (len(values_a), len(values_b), D) float64; ``Z[i, j, dims[0]] = values_a[i]``,
        ``Z[i, j, dims[1]] = values_b[j]``.
    """
    base = np.asarray(base, dtype=np.float64)
    if base.ndim != 1:
        raise ValueError(f"base must be a (D,) latent vector, got {base.shape}")
    d0, d1 = (int(d) for d in dims)
    if d0 == d1 or not (0 <= d0 < base.size and 0 <= d1 < base.size):
        raise ValueError(f"dims must be two distinct indices in [0, {base.size}), got {tuple(dims)}")
    va = np.linspace(*value_range, n) if values_a is None else np.asarray(values_a, dtype=np.float64)
    vb = np.linspace(*value_range, n) if values_b is None else np.asarray(values_b, dtype=np.float64)
    Z = np.broadcast_to(base, (va.size, vb.size, base.size)).copy()
    Z[:, :, d0] = va[:, None]
    Z[:, :, d1] = vb[None, :]
    return Z


@dataclass
class ExplorationGrid:
    """Decoded meshes on a latent grid (one level of the paper's Fig. 8).

    Attributes
    ----------
    dims : (int, int)
    values_a, values_b : (na,), (nb,) float64
    latents : (na, nb, D) float64
    vertices : (na, nb, n_vertices, 3) float64
    """

    dims: tuple
    values_a: np.ndarray
    values_b: np.ndarray
    latents: np.ndarray
    vertices: np.ndarray


def explore(model, dims: Sequence[int] = (0, 1), base=None, n: int = 5,
            value_range=hp.EXPLORATION_RANGE) -> ExplorationGrid:
    """Decode an ``n x n`` grid over two latent dimensions (paper Fig. 8).

    Parameters
    ----------
    model : trained ``MeshVAEModel`` (anything with ``decode_latent((N, D)) -> (N, n, 3)``)
    dims : the two dimensions browsed (0-based: (0, 1) is the paper's first level, (2, 3) its
        second)
    base : (D,) latent values of the other dimensions (default zeros)

    Returns
    -------
    ExplorationGrid
    """
    D = model.latent_dim
    base = np.zeros(D) if base is None else np.asarray(base, dtype=np.float64)
    if base.shape != (D,):
        raise ValueError(f"base must have shape ({D},), got {base.shape}")
    Z = latent_grid(base, dims, n=n, value_range=value_range)
    V = np.asarray(model.decode_latent(Z.reshape(-1, D)), dtype=np.float64)
    V = V.reshape(Z.shape[0], Z.shape[1], -1, 3)
    return ExplorationGrid(tuple(int(d) for d in dims), Z[:, 0, dims[0]].copy(), Z[0, :, dims[1]].copy(), Z, V)


# --------------------------------------------------------------------------------------------
# measurements on a humanoid
# --------------------------------------------------------------------------------------------


def humanoid_regions(V_rest, up: int = 1, left: int = 0, foot_fraction: float = 0.06,
                     hand_fraction: float = 0.025) -> dict:
    """Vertex sets of the feet, hands and torso of a humanoid in a rest pose (A- or T-pose).

    Found geometrically: feet are the vertices within ``foot_fraction`` of the height above the
    lowest point, split by side; hands are the ``hand_fraction`` of all vertices farthest to each
    side; the torso is the central column between 50% and 75% of the height.

    Parameters
    ----------
    V_rest : (n_vertices, 3) float
    up, left : axis indices of "up" and of the character's left

    Returns
    -------
    dict with ``left_foot``, ``right_foot``, ``left_hand``, ``right_hand``, ``torso``: int64 index
    arrays (each non-empty), and ``up``, ``left``, ``forward`` axis indices.
    """
    V = check_vertices(V_rest, "V_rest", batch=False)
    forward = 3 - up - left
    if sorted((up, left, forward)) != [0, 1, 2]:
        raise ValueError(f"up and left must be two distinct axes in 0..2, got up={up}, left={left}")
    h = V[:, up]
    lo, H = h.min(), np.ptp(h)
    c = np.median(V[:, left])
    side = V[:, left] - c
    feet = h <= lo + foot_fraction * H
    k = max(1, int(round(hand_fraction * V.shape[0])))
    order = np.argsort(side)
    torso = (np.abs(side) < 0.1 * H) & (h > lo + 0.5 * H) & (h < lo + 0.75 * H)
    regions = {
        "left_foot": np.flatnonzero(feet & (side > 0)),
        "right_foot": np.flatnonzero(feet & (side < 0)),
        "left_hand": np.sort(order[-k:]),
        "right_hand": np.sort(order[:k]),
        "torso": np.flatnonzero(torso),
    }
    empty = [name for name, idx in regions.items() if idx.size == 0]
    if empty:
        raise ValueError(f"no vertices found for {empty}: is V_rest a humanoid with up={up}, left={left}?")
    regions.update(up=up, left=left, forward=forward)
    regions["rest_torso"] = V[regions["torso"]]
    return regions


def measure_humanoid(V, regions: dict) -> dict:
    """What the paper reads off Fig. 8, as numbers, for every mesh.

    - ``height``: extent along the up axis (standing vs squatting);
    - ``support``: mean height of the right foot minus that of the left foot, over the body
      height: > 0 when the left foot is lower (stands on the left leg);
    - ``arm_height``: mean height of both hands above the lowest point, over the body height;
    - ``facing``: yaw of the torso in degrees (the rotation best aligning the rest torso to the
      mesh's torso, applied to the forward axis, measured about the up axis; > 0 turns left).

    Parameters
    ----------
    V : (n_vertices, 3) or (N, n_vertices, 3) float
    regions : from ``humanoid_regions``

    Returns
    -------
    dict name -> (N,) float64 (floats for a single mesh), names as ``HUMANOID_MEASUREMENTS``.
    """
    V = check_vertices(V, "V")
    single = V.ndim == 2
    Vb = V[None] if single else V
    up, left, fwd = regions["up"], regions["left"], regions["forward"]
    y = Vb[..., up]
    base = y.min(axis=1)
    height = y.max(axis=1) - base
    lf = y[:, regions["left_foot"]].mean(axis=1)
    rf = y[:, regions["right_foot"]].mean(axis=1)
    hands = np.concatenate([regions["left_hand"], regions["right_hand"]])
    arm = (y[:, hands].mean(axis=1) - base) / height
    R, _ = rigid_transform(np.broadcast_to(regions["rest_torso"], (len(Vb),) + regions["rest_torso"].shape),
                           Vb[:, regions["torso"]])
    f = R[:, :, fwd]  # image of the forward axis
    facing = np.degrees(np.arctan2(f[:, left], f[:, fwd]))
    out = {"height": height, "support": (rf - lf) / height, "arm_height": arm, "facing": facing}
    return {k: float(v[0]) for k, v in out.items()} if single else out


# --------------------------------------------------------------------------------------------
# which dimension controls what
# --------------------------------------------------------------------------------------------


def latent_measurement_correlation(Z, measurements: dict) -> tuple[np.ndarray, list]:
    """Pearson correlation of every latent dimension with every measurement.

    Parameters
    ----------
    Z : (N, D) float
    measurements : dict name -> (N,) float

    Returns
    -------
    C : (D, n_measurements) float64 in [-1, 1]; 0 where either side is constant
    names : list of the measurement names (the columns of C)
    """
    Z = check_rows(Z, "Z", single=False)
    names = list(measurements)
    M = np.column_stack([np.asarray(measurements[k], dtype=np.float64) for k in names])
    if M.shape[0] != Z.shape[0]:
        raise ValueError(f"measurements have {M.shape[0]} rows, Z has {Z.shape[0]}")
    Zc = Z - Z.mean(axis=0)
    Mc = M - M.mean(axis=0)
    zs = np.sqrt((Zc**2).sum(axis=0))
    ms = np.sqrt((Mc**2).sum(axis=0))
    denom = np.outer(zs, ms)
    C = np.divide(Zc.T @ Mc, denom, out=np.zeros((Z.shape[1], M.shape[1])), where=denom > 0)
    return np.clip(C, -1.0, 1.0), names


@dataclass
class DimensionEffects:
    """One-at-a-time sweeps of latent dimensions and what they change.

    Attributes
    ----------
    dims : list of int (0-based)
    values : (n_values,) float64, the swept values
    measurements : dict name -> (n_dims, n_values) float64
    correlation : (n_dims, n_measurements) float64, of the swept value with each measurement
    effect : (n_dims, n_measurements) float64, measurement at the top of the range minus at the
        bottom, in units of the measurement's standard deviation over ``reference_std``'s data
    names : list of measurement names
    span : (n_dims, n_measurements) float64, largest minus smallest measurement over the sweep, in
        the same units. Unlike ``effect`` it also sees responses that peak inside the range (a
        dimension that lowers the arms both ways from 0 has a small ``effect`` but a large span).
    """

    dims: list
    values: np.ndarray
    measurements: dict
    correlation: np.ndarray
    effect: np.ndarray
    names: list = field(default_factory=list)
    span: np.ndarray | None = None

    def rows(self) -> list[dict]:
        """One row per dimension: the measurement it changes most, with correlation and effect."""
        out = []
        for i, d in enumerate(self.dims):
            j = int(np.argmax(np.abs(self.effect[i])))
            out.append({"dim": d + 1, "controls": self.names[j], "correlation": float(self.correlation[i, j]),
                        "effect (std)": float(self.effect[i, j]),
                        **{f"corr {n}": float(self.correlation[i, k]) for k, n in enumerate(self.names)}})
        return out

    def to_markdown(self) -> str:
        head = ["dim (1-based)", "controls most", "its correlation", "its change over the range (data std)"]
        head += [f"corr. {n}" for n in self.names]
        lines = ["| " + " | ".join(head) + " |", "|" + " --- |" * len(head)]
        for r in self.rows():
            cells = [str(r["dim"]), r["controls"], f"{r['correlation']:+.2f}", f"{r['effect (std)']:+.2f}"]
            cells += [f"{r[f'corr {n}']:+.2f}" for n in self.names]
            lines.append("| " + " | ".join(cells) + " |")
        return "\n".join(lines)


def dimension_effects(model, measure: Callable[[np.ndarray], dict], dims: Sequence[int] = (0, 1, 2, 3),
                      base=None, n_values: int = 9, value_range=hp.EXPLORATION_RANGE,
                      reference_vertices=None) -> DimensionEffects:
    """Sweep each latent dimension alone over ``value_range`` and measure the decoded meshes.

    Parameters
    ----------
    model : trained ``MeshVAEModel`` (``decode_latent``)
    measure : callable ``(N, n_vertices, 3) -> dict name -> (N,)``, e.g.
        ``lambda V: measure_humanoid(V, regions)``
    dims : 0-based dimensions to sweep
    base : (D,) values of the other dimensions (default zeros)
    reference_vertices : (M, n_vertices, 3) meshes whose measurement spread sets the unit of
        ``effect`` (the training set); default: the sweeps themselves

    Returns
    -------
    DimensionEffects
    """
    D = model.latent_dim
    base = np.zeros(D) if base is None else np.asarray(base, dtype=np.float64)
    dims = [int(d) for d in dims]
    if any(not 0 <= d < D for d in dims):
        raise ValueError(f"dims must lie in [0, {D}), got {dims}")
    values = np.linspace(*value_range, n_values)
    Z = np.broadcast_to(base, (len(dims), n_values, D)).copy()
    for i, d in enumerate(dims):
        Z[i, :, d] = values
    V = np.asarray(model.decode_latent(Z.reshape(-1, D)), dtype=np.float64)
    meas = measure(V.reshape(len(dims) * n_values, -1, 3))
    names = list(meas)
    M = {k: np.asarray(meas[k], dtype=np.float64).reshape(len(dims), n_values) for k in names}
    if reference_vertices is not None:
        ref = measure(np.asarray(reference_vertices, dtype=np.float64))
        std = np.array([np.std(ref[k]) for k in names])
    else:
        std = np.array([np.std(M[k]) for k in names])
    std = np.where(std > 0, std, 1.0)
    corr = np.zeros((len(dims), len(names)))
    eff = np.zeros((len(dims), len(names)))
    for i in range(len(dims)):
        c, _ = latent_measurement_correlation(values[:, None], {k: M[k][i] for k in names})
        corr[i] = c[0]
        eff[i] = np.array([M[k][i, -1] - M[k][i, 0] for k in names]) / std
    span = np.stack([np.ptp(M[k], axis=1) for k in names], axis=1) / std
    return DimensionEffects(dims, values, M, corr, eff, names, span)


def dimension_displacement(model, dims: Sequence[int] | None = None, base=None,
                           value_range=hp.EXPLORATION_RANGE, reference_vertices=None) -> np.ndarray:
    """How far each latent dimension moves the body: the mean vertex distance between the meshes
    decoded at the two ends of ``value_range`` (the others at ``base``), after rigid alignment.

    Parameters
    ----------
    model : trained ``MeshVAEModel`` (``decode_latent``)
    dims : 0-based dimensions (default: all)
    base : (D,) values of the other dimensions (default zeros)
    reference_vertices : (M, n_vertices, 3) meshes whose spread is the unit (the mean vertex
        distance of a mesh to their mean mesh, averaged over them); default: mesh units

    Returns
    -------
    (n_dims,) float64, >= 0.
    """
    D = model.latent_dim
    dims = list(range(D)) if dims is None else [int(d) for d in dims]
    if any(not 0 <= d < D for d in dims):
        raise ValueError(f"dims must lie in [0, {D}), got {dims}")
    base = np.zeros(D) if base is None else np.asarray(base, dtype=np.float64)
    lo, hi = (float(v) for v in value_range)
    Z = np.broadcast_to(base, (len(dims), 2, D)).copy()
    Z[np.arange(len(dims)), 0, dims] = lo
    Z[np.arange(len(dims)), 1, dims] = hi
    V = np.asarray(model.decode_latent(Z.reshape(-1, D)), dtype=np.float64).reshape(len(dims), 2, -1, 3)
    dist = per_vertex_error(V[:, 0], V[:, 1])
    return dist if reference_vertices is None else dist / data_spread(reference_vertices)


def data_spread(reference_vertices) -> float:
    """The unit of :func:`dimension_displacement`: the mean vertex distance of the meshes ``(M, n, 3)``
    to their mean mesh (no alignment), averaged over them; 1.0 where that is 0. Returns a float."""
    R = np.asarray(reference_vertices, dtype=np.float64)
    spread = float(per_vertex_error(R, np.broadcast_to(R.mean(axis=0), R.shape), align=False).mean())
    return spread if spread > 0 else 1.0
