"""The mesh VAE's one-file checkpoint: ``model.save(path)`` writes it, :func:`load_model` reads it.

A checkpoint is one file written with ``torch.save`` that holds only tensors, numbers, strings,
lists and dicts (it loads with ``weights_only=True``: no code runs when reading it), plus a
checksum of the weights and the reference mesh, so that a corrupted, truncated or foreign file
gives a clear error instead of a broken model.
"""

from __future__ import annotations

import hashlib
import logging
import os
import re
import zipfile
from pathlib import Path

import numpy as np
import torch

from meshvae_lib.model.features import ConditionEncoder, FeatureExtractor
from meshvae_lib.model.meshvae_model import MeshVAEModel
from meshvae_lib.model.normalization import FeatureNormalizer
from meshvae_lib.model.train_config import TrainConfig
from meshvae_lib.model.vae import MeshVAE

__all__ = ["load_model", "write_checkpoint", "CHECKPOINT_FORMAT", "CHECKPOINT_VERSION"]

logger = logging.getLogger(__name__)

#: value of the ``format`` entry of every checkpoint.
CHECKPOINT_FORMAT = "meshvae-checkpoint"
#: bumped when the layout of the checkpoint changes (2: the network config has ``sigma_floor`` and ``output``;
#: version 1 files load with their defaults, 0 and "tanh").
CHECKPOINT_VERSION = 2


def _to_storable(obj):
    """numpy arrays -> tensors, recursively (so that the file loads with weights_only=True)."""
    if isinstance(obj, np.ndarray):
        return torch.from_numpy(np.ascontiguousarray(obj))
    if isinstance(obj, dict):
        return {k: _to_storable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_to_storable(v) for v in obj]
    if isinstance(obj, np.generic):
        return obj.item()
    return obj


def _to_numpy(obj):
    if isinstance(obj, torch.Tensor):
        return obj.numpy()
    if isinstance(obj, dict):
        return {k: _to_numpy(v) for k, v in obj.items()}
    return obj


def _checksum(state_dict: dict, reference: np.ndarray, faces: np.ndarray) -> str:
    h = hashlib.blake2b(digest_size=16)
    for key in sorted(state_dict):
        h.update(key.encode())
        h.update(state_dict[key].detach().cpu().contiguous().numpy().tobytes())
    h.update(np.ascontiguousarray(reference, dtype=np.float64).tobytes())
    h.update(np.ascontiguousarray(faces, dtype=np.int64).tobytes())
    return h.hexdigest()


def write_checkpoint(path, model: MeshVAEModel) -> Path:
    """Write ``model`` to ``path`` as one checkpoint file (what ``model.save(path)`` does). Returns
    the path.

    The file is written next to its destination and renamed, so an interrupted save never leaves a
    half-written checkpoint under the final name.
    """
    model._check_fitted()
    path = Path(path)
    if path.parent and not path.parent.exists():
        path.parent.mkdir(parents=True, exist_ok=True)
    state = {k: v.detach().cpu().clone() for k, v in model.network_.state_dict().items()}
    ext = model.extractor_.state_dict()
    payload = {
        "format": CHECKPOINT_FORMAT,
        "version": CHECKPOINT_VERSION,
        "torch_version": str(torch.__version__),
        "network_config": model.network_.config(),
        "network_state": state,
        "normalizer": _to_storable(model.normalizer_.state_dict()),
        "extractor": _to_storable(ext),
        "conditions": model.conditions_.state_dict(),
        "train_conditions": torch.from_numpy(np.ascontiguousarray(model.train_conditions_, dtype=np.float32)),
        "sigma_object": torch.from_numpy(np.asarray(model.sigma_object_, dtype=np.float64)),
        "train_config": model.train_config_.to_dict(),
        "estimator": {"features": model.features, "labels": list(model.labels),
                      "holdout_every": int(model.holdout_every), "layout": model.layout,
                      "reference_index": int(model.reference_index), "inference": str(model.inference)},
        "holdout_mask": torch.from_numpy(np.asarray(model.holdout_mask_, dtype=bool)),
        "history": [dict(h) for h in getattr(model, "history_", [])],
        "train_seconds": float(getattr(model, "train_seconds_", 0.0)),
        "checksum": _checksum(state, ext["reference"], ext["faces"]),
    }
    tmp = path.with_name(f".{path.name}.tmp-{os.getpid()}")
    try:
        torch.save(payload, tmp)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
    return path


_ZIP_MAGIC = b"PK\x03\x04"


def _load_error_reason(exc: BaseException) -> str:
    """What went wrong in torch.load, in a few words and without torch's advice to load with
    ``weights_only=False`` (which would run whatever code a damaged or foreign file holds)."""
    text = str(exc)
    if "WeightsUnpickler error:" in text:
        text = text.split("WeightsUnpickler error:", 1)[1]
    lines = [ln.strip() for ln in text.splitlines() if ln.strip()]
    first = lines[0] if lines else ""
    match = re.match(r"Unsupported global: GLOBAL ([\w.]+)", first)
    if match:
        return f"an object of type {match.group(1)}"
    first = first.split(". Please use")[0].split(" Check the documentation")[0]
    if not first or re.search(r"weights.only", first, re.IGNORECASE):
        return type(exc).__name__
    return f"{type(exc).__name__}: {first}"


def load_model(path, collection=None) -> MeshVAEModel:
    """Read a checkpoint written by ``model.save(path)``.

    path : the checkpoint file.
    collection : optional data the model will be used with; a mesh with another vertex count or
        connectivity (or lacking the model's label columns) raises ValueError.

    Raises FileNotFoundError for a missing file and ValueError for a file that is not a mesh VAE
    checkpoint, is corrupted or truncated, or was written by a newer version.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no checkpoint file at {path}")
    with open(path, "rb") as fh:
        head = fh.read(4)
    if head != _ZIP_MAGIC:  # torch.save's format is a zip archive; torch would advise unsafe loading
        raise ValueError(f"{path} is damaged or not a mesh VAE checkpoint: it does not start like one"
                         f" (first bytes {head!r}; zero-filled, overwritten or another kind of file)")
    try:
        payload = torch.load(path, map_location="cpu", weights_only=True)
    except (RuntimeError, EOFError, OSError, ValueError, zipfile.BadZipFile, KeyError, IndexError,
            AttributeError, TypeError, UnicodeDecodeError, ImportError) as exc:
        raise ValueError(f"{path} is damaged (corrupted or truncated) or not a mesh VAE checkpoint: its"
                         f" archive cannot be read ({_load_error_reason(exc)})") from exc
    except Exception as exc:  # the unpickler raises its own error types for damaged or foreign pickles
        if type(exc).__module__.startswith(("pickle", "_pickle")) or "Unpickl" in type(exc).__name__:
            raise ValueError(f"{path} is damaged or not a mesh VAE checkpoint: it holds data a checkpoint never"
                             f" holds ({_load_error_reason(exc)})") from exc
        raise
    if not isinstance(payload, dict) or payload.get("format") != CHECKPOINT_FORMAT:
        raise ValueError(f"{path} is not a mesh VAE checkpoint (no '{CHECKPOINT_FORMAT}' marker)")
    if int(payload.get("version", -1)) > CHECKPOINT_VERSION:
        raise ValueError(f"{path} was written by a newer version (checkpoint format {payload['version']},"
                         f" this library reads up to {CHECKPOINT_VERSION})")
    try:
        ext_state = _to_numpy(payload["extractor"])
        state = payload["network_state"]
        if _checksum(state, ext_state["reference"], ext_state["faces"]) != payload["checksum"]:
            raise ValueError(f"{path} is corrupted: its weights do not match the stored checksum")
        config = TrainConfig(**{**payload["train_config"], "progress": False})
        model = MeshVAEModel(**payload["estimator"], config=config)
        model.train_config_ = config
        net_cfg = dict(payload["network_config"])
        model.network_ = MeshVAE(**net_cfg)
        model.network_.load_state_dict(state)
        model.network_.eval()
        model.normalizer_ = FeatureNormalizer.from_state_dict(_to_numpy(payload["normalizer"]))
        model.extractor_ = FeatureExtractor.from_state_dict(ext_state)
        model.conditions_ = ConditionEncoder.from_state_dict(payload["conditions"])
        model.train_conditions_ = payload["train_conditions"].numpy()
        model.sigma_object_ = payload["sigma_object"].numpy()
        model.holdout_mask_ = payload["holdout_mask"].numpy()
        model.history_ = list(payload["history"])
        model.train_seconds_ = float(payload["train_seconds"])
    except (KeyError, TypeError, RuntimeError) as exc:
        raise ValueError(f"{path} is an incomplete or inconsistent mesh VAE checkpoint: {exc!r}") from exc
    sizes = (model.normalizer_.n_features_in_, model.extractor_.n_features_, model.network_.n_features)
    if len(set(sizes)) != 1 or model.conditions_.n_conditions_ != model.network_.n_conditions:
        raise ValueError(f"{path} is inconsistent: feature lengths {sizes}")
    if collection is not None:
        model.check_compatible(collection)
    return model
