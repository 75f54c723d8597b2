"""The mesh VAE's one-file checkpoint format: a model's state <-> one file.

:func:`write_checkpoint` (behind ``model.save(path)``) writes the state a model gives
(:meth:`~meshvae_lib.model.meshvae_model.MeshVAEModel.state_dict`), :func:`read_checkpoint` reads it
back (``meshvae_model.load_model`` builds the model from it). A checkpoint is one file written with
``torch.save`` that holds only tensors, numbers, strings, lists and dicts (it loads with
``weights_only=True``: no code runs when reading it), plus a digest of everything else it holds
(:func:`payload_digest`: the weights, the normaliser, the reference mesh, the configuration, the
held-out meshes' fingerprints, the history), so that a corrupted, truncated, edited or foreign file
gives a clear error instead of a broken model. Files of formats 1 to 3 are read too
(:func:`read_checkpoint` upgrades them); their checksum covers only the weights, the reference mesh
and the faces.
"""

from __future__ import annotations

import hashlib
import io
import logging
import re
import zipfile
from pathlib import Path

import numpy as np
import torch

from meshvae_lib.atomic import atomic_file

__all__ = ["write_checkpoint", "read_checkpoint", "payload_digest", "CHECKPOINT_FORMAT", "CHECKPOINT_VERSION"]

logger = logging.getLogger(__name__)

#: value of the ``format`` entry of every checkpoint.
CHECKPOINT_FORMAT = "meshvae-checkpoint"
#: bumped when the layout of the checkpoint changes (2: the network config has ``sigma_floor`` and ``output``;
#: version 1 files load with their defaults, 0 and "tanh"; 3: the network's ``architecture``, the feature
#: kind's state instead of the feature extractor's, the epochs trained and early stopping's record;
#: 4: a ``digest`` of everything stored instead of a ``checksum`` of the weights and the reference
#: mesh, and the fingerprint of every training mesh, ``mesh_fingerprints``).
CHECKPOINT_VERSION = 4


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
    """tensors -> numpy arrays, recursively (the inverse of :func:`_to_storable`)."""
    if isinstance(obj, torch.Tensor):
        return obj.numpy()
    if isinstance(obj, dict):
        return {k: _to_numpy(v) for k, v in obj.items()}
    if isinstance(obj, list):
        return [_to_numpy(v) for v in obj]
    return obj


def _checksum(state_dict: dict, reference: np.ndarray, faces: np.ndarray) -> str:
    h = hashlib.blake2b(digest_size=16)
    for key in sorted(state_dict):
        h.update(key.encode())
        h.update(state_dict[key].detach().cpu().contiguous().numpy().tobytes())
    h.update(np.ascontiguousarray(reference, dtype=np.float64).tobytes())
    h.update(np.ascontiguousarray(faces, dtype=np.int64).tobytes())
    return h.hexdigest()


def _update_digest(h, obj) -> None:
    """Feed ``obj`` (what a checkpoint stores: tensors, dicts, lists, strings, numbers, None) to the
    hash ``h`` in one unambiguous byte form: each value is tagged with its type and its length."""

    def put(tag: bytes, data: bytes) -> None:
        h.update(tag + len(data).to_bytes(8, "little") + data)

    if isinstance(obj, torch.Tensor):
        t = obj.detach().cpu().contiguous()
        put(b"T", f"{t.dtype}{tuple(t.shape)}".encode())
        put(b"B", t.reshape(-1).view(torch.uint8).numpy().tobytes())
    elif isinstance(obj, dict):
        put(b"D", str(len(obj)).encode())
        for key in sorted(obj, key=repr):
            _update_digest(h, key)
            _update_digest(h, obj[key])
    elif isinstance(obj, (list, tuple)):
        put(b"L", str(len(obj)).encode())
        for item in obj:
            _update_digest(h, item)
    elif isinstance(obj, str):
        put(b"S", obj.encode("utf-8", "surrogatepass"))
    elif obj is None or isinstance(obj, bool):
        put(b"N" if obj is None else b"b", str(obj).encode())
    elif isinstance(obj, int):
        put(b"I", str(obj).encode())
    elif isinstance(obj, float):
        put(b"F", obj.hex().encode())
    else:
        raise TypeError(f"a checkpoint stores no {type(obj).__name__}")


def payload_digest(payload: dict) -> str:
    """The digest (blake2b, 32 hex digits) of a checkpoint's payload, every entry but ``digest``
    itself: the stored tensors' dtypes, shapes and bytes, and every string, number, list and dict.
    Any change to what a checkpoint holds changes it."""
    h = hashlib.blake2b(digest_size=16)
    _update_digest(h, {k: v for k, v in payload.items() if k != "digest"})
    return h.hexdigest()


def write_checkpoint(path, state: dict) -> Path:
    """Write a model's ``state`` (:meth:`~meshvae_lib.model.meshvae_model.MeshVAEModel.state_dict`) to
    ``path`` as one checkpoint file (what ``model.save(path)`` does). Returns the path.

    The file is written next to its destination and renamed (:func:`~meshvae_lib.atomic.atomic_file`),
    so an interrupted or failed save never leaves a half-written checkpoint under the final name; a
    failed write raises :class:`~meshvae_lib.atomic.OutputError` (``cannot write FILE: reason``).
    """
    path = Path(path)
    if path.parent and not path.parent.exists():
        path.parent.mkdir(parents=True, exist_ok=True)
    network_state = state["network_state"]
    payload = {
        "format": CHECKPOINT_FORMAT,
        "version": CHECKPOINT_VERSION,
        "torch_version": str(torch.__version__),
        **{k: _to_storable(v) for k, v in state.items() if k != "network_state"},
        "network_state": network_state,
    }
    payload["digest"] = payload_digest(payload)
    buffer = io.BytesIO()  # serialised first: torch reports a failed write as a RuntimeError, not an OSError
    torch.save(payload, buffer)
    with atomic_file(path) as fh:
        fh.write(buffer.getbuffer())
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


def read_checkpoint(path) -> dict:
    """The model state stored in the checkpoint file ``path`` (numpy arrays where
    :func:`write_checkpoint` got them; the network's state as tensors), upgraded to the current
    format. Build the model from it with
    :meth:`~meshvae_lib.model.meshvae_model.MeshVAEModel.from_state_dict` (or call
    :func:`~meshvae_lib.model.meshvae_model.load_model`, which does both).

    Raises FileNotFoundError for a missing file and ValueError for a file that is not a mesh VAE
    checkpoint, is corrupted, truncated or edited (its content does not match its digest), or was
    written by a newer version.
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
        version = int(payload["version"])
        if version >= 4 and payload_digest(payload) != payload["digest"]:
            raise ValueError(f"{path} is corrupted or was edited: what it holds does not match its digest"
                             " (retrain, or use an unedited copy)")
        state = {k: (v if k == "network_state" else _to_numpy(v)) for k, v in payload.items()
                 if k not in ("format", "version", "torch_version", "checksum", "digest")}
        if version < 3:
            state = _upgrade(state)
        if version < 4:
            kind = state["kind"]
            if _checksum(state["network_state"], kind["reference"], kind["faces"]) != payload["checksum"]:
                raise ValueError(f"{path} is corrupted: its weights do not match the stored checksum")
            state.setdefault("mesh_fingerprints", None)
    except (KeyError, TypeError, RuntimeError, AttributeError) as exc:
        raise ValueError(f"{path} is an incomplete or inconsistent mesh VAE checkpoint: {exc!r}") from exc
    return state


def _upgrade(state: dict) -> dict:
    """A state of format 1 or 2 in the layout of format 3: the feature extractor's state becomes the
    feature kind's, the network is the one architecture there was (``"mesh-vae"``; format 1 has no
    ``sigma_floor`` and ``output``: the network's defaults), the normalisation half-width is ``a``,
    and the epochs trained are the last epoch of the history (early stopping's record was not kept)."""
    state = dict(state)
    ext = state.pop("extractor")
    state["kind"] = {"kind": ext["kind"], "reference": ext["reference"], "faces": ext["faces"],
                     "options": {"layout": ext["layout"]}, "n_features": ext["n_features"]}
    state["architecture"] = "mesh-vae"
    config = dict(state["train_config"])
    config["a"] = config.pop("feature_range", None)
    state["train_config"] = config
    history = list(state["history"])
    state["train_epochs"] = int(history[-1]["epoch"]) if history else 0
    state["selection"] = None
    return state
