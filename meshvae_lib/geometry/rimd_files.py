"""RIMD feature files: the ``.npz`` that ``meshvae features`` writes and ``meshvae reconstruct``
reads.

A feature file holds ``features (N, K) float64`` in one layout of
:class:`~meshvae_lib.geometry.rimd.RIMDLayout`, the ``reference (n, 3) float64`` mesh they are
relative to, its ``faces (F, 3) int64``, ``names (N,)``, the ``layout`` name and one
``label_<column> (N,)`` array per label column, so that the meshes can be rebuilt from the file
alone (:class:`~meshvae_lib.geometry.reconstruction.RIMDReconstructor`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from meshvae_lib.atomic import atomic_file
from meshvae_lib.defaults import DEFAULT_LAYOUT, LAYOUTS
from meshvae_lib.geometry.npz_files import npz_array, npz_names, open_npz
from meshvae_lib.geometry.rimd import RIMDLayout
from meshvae_lib.input_checks import check_numeric, short_name
from meshvae_lib.validation import check_faces, check_finite, check_rows, check_vertices

__all__ = ["FEATURE_FILE_KEYS", "save_features", "load_features"]


#: arrays every feature file holds.
FEATURE_FILE_KEYS = ("features", "reference", "faces", "names", "layout")


def save_features(path, features, reference, faces, names=None, labels=None,
                  layout: str = DEFAULT_LAYOUT) -> None:
    """Write a feature file (``.npz``, uncompressed, float64 kept), atomically: a failed write
    leaves an older file as it was and raises :class:`~meshvae_lib.atomic.OutputError`.

    Parameters
    ----------
    path : str or Path
        Ends in ``.npz``.
    features : (n_meshes, K) float64
    reference : (n_vertices, 3) float64
        The mesh the features are relative to.
    faces : (n_faces, 3) int64
    names : list of str, optional
    labels : dict str -> (n_meshes,) array, optional
        Stored as ``label_<column>``.
    layout : {"paper", "compact"}
    """
    path = Path(path)
    if path.suffix.lower() != ".npz":
        raise ValueError(f"a feature file must end in .npz, got {path}")
    if not path.parent.is_dir():
        raise FileNotFoundError(f"folder does not exist: {path.parent}")
    features = check_rows(features, "features", single=False)
    lay = RIMDLayout(faces, len(reference), layout)
    if features.shape[1] != lay.K:
        raise ValueError(f"features have {features.shape[1]} columns; the {layout!r} layout of "
                         f"this mesh has K = {lay.K}")
    n = features.shape[0]
    names = [f"{k:04d}" for k in range(n)] if names is None else [str(s) for s in names]
    arrays = {
        "features": features,
        "reference": np.asarray(reference, dtype=np.float64),
        "faces": np.asarray(faces, dtype=np.int64),
        "names": np.array(names),
        "layout": np.array(layout),
    }
    for key, val in (labels or {}).items():
        arrays[f"label_{key}"] = np.asarray(val)
    with atomic_file(path) as fh:
        np.savez(fh, **arrays)


def load_features(path) -> dict:
    """Read a feature file written by :func:`save_features` (or ``meshvae features``).

    Returns
    -------
    dict with ``features (N, K) float64``, ``reference (n, 3) float64``, ``faces (F, 3) int64``,
    ``names`` (list of str), ``labels`` (dict), ``layout`` (str).

    Raises
    ------
    FileNotFoundError, ValueError
        Missing file, missing arrays, arrays that are not real numbers (complex, text, Python
        objects: never unpickled), NaN or infinite features, face indices out of range, or a
        feature length that does not match the layout; the message names the file.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no such feature file: {path}")
    data = open_npz(path)
    src = short_name(path.name)
    with data:
        missing = [k for k in ("features", "reference", "faces") if k not in data.files]
        if missing:
            raise ValueError(f"{src}: not a feature file, it lacks {missing} "
                             f"(found {[short_name(f) for f in data.files[:10]]}); make one with `meshvae features`")
        arrays = {k: check_numeric(npz_array(data, k, path), f"{src}: {k!r}")
                  for k in ("features", "reference", "faces")}
        layout = npz_array(data, "layout", path) if "layout" in data.files else np.array(DEFAULT_LAYOUT)
        if layout.dtype.kind not in "US" or layout.shape != ():
            raise ValueError(f"{src}: 'layout' must be one text value, got dtype {layout.dtype} and shape"
                             f" {layout.shape}")
        out = {
            "features": np.asarray(arrays["features"], dtype=np.float64),
            "reference": np.asarray(arrays["reference"], dtype=np.float64),
            "faces": arrays["faces"],
            "layout": str(layout),
            "labels": {k[len("label_"):]: npz_array(data, k, path) for k in data.files
                       if k.startswith("label_")},
        }
        f = out["features"]
        if f.ndim == 1:
            f = out["features"] = f[None]
        out["names"] = (npz_names(data, "names", path) if "names" in data.files
                        else [f"{k:04d}" for k in range(len(f))])
    if out["layout"] not in LAYOUTS:
        raise ValueError(f"{src}: unknown layout {short_name(repr(out['layout']))}; one of {LAYOUTS}")
    out["reference"] = check_vertices(out["reference"], f"{src}: 'reference'", batch=False, finite=True)
    out["faces"] = check_faces(out["faces"], n_vertices=len(out["reference"]), name=f"{src}: 'faces'")
    check_finite(out["features"], f"{src}: 'features'")
    lay = RIMDLayout(out["faces"], len(out["reference"]), out["layout"])
    if f.ndim != 2 or f.shape[1] != lay.K:
        raise ValueError(f"{src}: features have shape {f.shape}, but the {out['layout']!r} "
                         f"layout of its reference mesh needs K = {lay.K}")
    if len(out["names"]) != len(f):
        raise ValueError(f"{src}: {len(out['names'])} names for {len(f)} feature rows")
    return out
