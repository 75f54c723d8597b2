"""Choosing and captioning the meshes of a collection gallery (notebook 00's overview).

Pure functions on arrays and label dictionaries; the figures themselves are drawn by
:func:`~meshvae_lib.viewing.render.render_mesh_grid`.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from meshvae_lib.geometry.alignment import rigid_transform
from meshvae_lib.validation import check_count, check_vertices

__all__ = ["gallery_indices", "mesh_caption", "angular_stripes", "align_on_part", "LABEL_UNITS"]

#: label-name suffixes that hold numbers, and the unit shown after the value in a caption.
LABEL_UNITS = {"_deg": "°", "_pct": "%"}


def gallery_indices(vertices, n_panels: int, groups=None, score=None) -> np.ndarray:
    """Which meshes to show in a gallery of ``n_panels`` panels.

    vertices : (M, n, 3) float, the collection's meshes; n_panels : int >= 1; groups : (M,) labels
    or None; score : (M,) float or None. Without groups: ``n_panels`` evenly spaced indices from the
    first mesh to the last. With groups: for each group in order of first appearance, the member
    with the highest ``score`` -- by default the mesh farthest (mean vertex distance) from the
    collection's first mesh, the most deformed member -- and at most ``n_panels`` of them. Returns
    (P,) int64 indices.
    """
    V = check_vertices(vertices, "vertices", batch=True)
    if len(V) == 0:
        raise ValueError(f"vertices must be (M, n, 3) with M >= 1, got shape {V.shape}")
    n_panels = check_count(n_panels, "n_panels", minimum=1)
    if groups is None:
        return np.unique(np.linspace(0, len(V) - 1, int(n_panels)).round().astype(np.int64))
    groups = np.asarray(groups)
    if groups.shape != (len(V),):
        raise ValueError(f"groups must have one label per mesh ({len(V)}), got shape {groups.shape}")
    if score is None:
        away = np.linalg.norm(V - V[0], axis=-1).mean(axis=1)  # (M,)
    else:
        away = np.asarray(score, dtype=np.float64)
        if away.shape != (len(V),) or not np.isfinite(away).all():
            raise ValueError(f"score must be {len(V)} finite numbers, one per mesh, got shape {away.shape}")
    picks = []
    for g in dict.fromkeys(groups.tolist()):
        members = np.flatnonzero(groups == g)
        picks.append(members[np.argmax(away[members])])
    return np.asarray(picks[: int(n_panels)], dtype=np.int64)


def mesh_caption(labels: Mapping, i: int, name: str) -> str:
    """A short caption for mesh ``i`` from its labels.

    labels : {label name: (M,) values}; i : the mesh index; name : the mesh's name, used when it
    has no label to show. Categorical (string) labels one per line with underscores as spaces;
    numeric labels whose names end in a unit suffix of :data:`LABEL_UNITS` (``bend_deg``) one per
    line, underscores as spaces (``bend 30°``); the frame number when that gives fewer than two lines.
    """
    values = {k: labels[k][i] for k in labels}
    lines = [str(v).replace("_", " ") for v in values.values() if isinstance(v, str)]
    lines += [f"{k[:-len(suffix)].replace('_', ' ')} {v}{unit}" for k, v in values.items()
              for suffix, unit in LABEL_UNITS.items() if k.endswith(suffix)]
    if len(lines) < 2 and "frame" in values:
        lines.append(f"frame {values['frame']}")
    return "\n".join(lines) if lines else str(name)


def angular_stripes(rest, n_stripes: int = 8, colors=((0.75, 0.8, 0.88), (0.85, 0.45, 0.25))) -> np.ndarray:
    """Per-vertex colours in stripes around the x axis of a tube in its rest pose.

    rest : (n, 3) float rest-pose vertices of a shape elongated along x; n_stripes : even int >= 2;
    colors : two RGB triples in [0, 1], alternating. Each vertex gets the colour of the band its
    angle around the axis (through the centroid, in the y-z plane) falls in, so that a twist of
    the tube shows as spiralling stripes. Returns (n, 3) float64.
    """
    rest = check_vertices(rest, "rest", batch=False)
    if int(n_stripes) < 2 or int(n_stripes) % 2:
        raise ValueError(f"n_stripes must be an even number >= 2, got {n_stripes}")
    y, z = rest[:, 1] - rest[:, 1].mean(), rest[:, 2] - rest[:, 2].mean()
    band = np.floor((np.arctan2(z, y) + np.pi) / (2 * np.pi) * int(n_stripes)).astype(int) % 2
    return np.asarray(colors, dtype=np.float64)[band]


def align_on_part(vertices, reference, part) -> tuple[np.ndarray, np.ndarray]:
    """Each mesh moved rigidly so that the vertices ``part`` best fit the reference, and the angle
    of that rotation.

    vertices : (M, n, 3) or (n, 3) float, the meshes; reference : (n, 3) float; part : (n,) bool,
    at least 3 True, the vertices the rigid fit (Kabsch, no scale) uses -- a part that moves
    rigidly (the back of a head) makes the angle that part's turn and leaves the rest's own motion
    in the aligned mesh. Returns ``aligned`` (same shape as ``vertices``, float64: every vertex moved
    by the fit of the part) and ``turn_deg`` ((M,) or () float64, the fitted rotation's angle in
    degrees, in [0, 180]).
    """
    V = check_vertices(vertices, "vertices")
    ref = check_vertices(reference, "reference", batch=False)
    part = np.asarray(part)
    if part.dtype != bool or part.shape != (ref.shape[0],) or part.sum() < 3:
        raise ValueError(f"part must be ({ref.shape[0]},) bool with at least 3 True, got {part.dtype} {part.shape}")
    if V.shape[-2:] != ref.shape:
        raise ValueError(f"vertices {V.shape} and reference {ref.shape} must have the same vertices")
    R, t = rigid_transform(V[..., part, :], ref[part])
    aligned = V @ np.swapaxes(R, -1, -2) + t[..., None, :]
    cos = (np.trace(R, axis1=-2, axis2=-1) - 1.0) / 2.0
    return aligned, np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))
