"""``meshvae train DATA -o model.pt``: train a mesh VAE on a collection and save one checkpoint."""

from __future__ import annotations

import argparse
import dataclasses
import logging
import re

from meshvae_lib.defaults import DECODERS, DEFAULT_ARCHITECTURE, DEFAULT_FEATURE_KIND, DEFAULT_INIT, INIT_MODES, PRIOR_FORMS
from meshvae_lib.defaults import DEFAULT_ALPHA, DEFAULT_BATCH_SIZE, DEFAULT_EPOCHS, DEFAULT_LATENT, DEFAULT_LR, PCA_LATENT_MAX
from meshvae_lib.defaults import MAX_EPOCHS, MAX_NETWORK_PARAMETERS
from meshvae_lib.model.feature_kinds import FEATURE_KINDS
from . import (CommandFailed, UsageError, add_allow_degenerate, add_command, add_output_argument, check_at_least,
               check_at_most, check_number, check_output, check_seed, note, result)

logger = logging.getLogger(__name__)

DESCRIPTION = """\
Train a mesh VAE (Tan et al., CVPR 2018) on a collection of meshes that share one connectivity,
and write everything needed to use it (weights, normaliser, reference mesh, faces, labels) to one
checkpoint file. DATA is an .npz collection or a folder of OBJ/PLY/OFF files (+ labels.csv).
The defaults train a good model for 50-200 meshes; a progress bar shows the epochs.
By default (--init pca) a network without internal layers, with the standard prior and no labels
starts as the PCA of the training features, and early stopping on every 8th training mesh chooses
how many of the --epochs to train (possibly none): on real meshes this generalises far better than
the paper's training (docs/vae.md, "Generalisation on real meshes"). --init random
--no-early-stopping trains as the paper does (random start, a = 0.9, all --epochs); conditional
networks, internal layers and a sigma_object prior always start at random.

examples:
  meshvae train scape.npz -o scape.pt
  meshvae train dyna.npz -o dyna_cond.pt --labels shape motion
  meshvae train scape.npz -o explore.pt --sigma-object 0.1,0.1,0.5,0.5
  meshvae train jumping.npz -o coords.pt --features coords --holdout-every 5
  meshvae train scape.npz -o spiral.pt --architecture spiral --holdout-every 5
"""


def _floats(text: str) -> list[float]:
    try:
        values = [float(v) for v in text.replace(" ", "").split(",") if v]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected comma-separated numbers, got {text!r}") from None
    if not values or any(v <= 0 for v in values):
        raise argparse.ArgumentTypeError(f"expected positive numbers, got {text!r}")
    return values


#: TrainConfig's fields as the command line names them (errors name the option, not the field).
OPTIONS = {"epochs": "--epochs", "batch_size": "--batch-size", "lr": "--lr", "alpha": "--alpha",
           "latent_dim": "--latent", "hidden": "--hidden", "sigma_object": "--sigma-object",
           "prior_form": "--prior-form", "seed": "--seed", "init": "--init", "device": "--device",
           "early_stopping": "--no-early-stopping", "progress": "--no-progress", "architecture": "--architecture"}


def _option_names(text: str, flags: dict | None = None) -> str:
    """A library message with ``TrainConfig.<field>`` (or ``sigma_object``, ...) in the command
    line's words: ``--epochs``; ``flags`` maps the networks' option fields to their flags."""
    names = {**OPTIONS, **(flags or {})}
    text = re.sub(r"TrainConfig\.(\w+)", lambda m: names.get(m.group(1), m.group(0)), text)
    words = ["sigma_object", "latent_dim", "batch_size", "holdout_every", "reference_index", *(flags or {})]
    return re.sub(r"\b(" + "|".join(map(re.escape, words)) + r")\b",
                  lambda m: {"holdout_every": "--holdout-every", "reference_index": "--reference"}.get(
                      m.group(1), names.get(m.group(1), m.group(1))), text)


def _small_mesh(text: str, args, collection) -> str:
    """A network's complaint that the mesh is too small to down-sample, in the command line's words:
    the spiral network's down-sampling is fixed (SpiralNet++'s settings), so the remedy is another
    ``--architecture``."""
    if "down-sampl" not in text:
        return text
    from meshvae_lib.model.networks import ARCHITECTURE_NAMES

    others = " or ".join(a for a in ARCHITECTURE_NAMES if a != args.architecture)
    return (f"--architecture {args.architecture}: the mesh has {collection.n_vertices} vertices ({len(collection.faces)}"
            f" faces), too few for its fixed {text.split('too few for ', 1)[-1].split(';')[0]};"
            f" use --architecture {others}")


def _check_device(text: str) -> None:
    """:class:`UsageError` unless ``--device`` names a device this machine has ("auto", "cpu",
    "cuda", "cuda:1", "mps")."""
    if text == "auto":
        return
    import torch

    from meshvae_lib.input_checks import short_name

    try:
        dev = torch.device(text)
    except (RuntimeError, ValueError, TypeError) as exc:
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise UsageError(f"--device {short_name(repr(text))} is not a device (auto, cpu, cuda, cuda:0, mps):"
                         f" {short_name(reason, 120)}") from None
    if dev.type == "cuda":
        count = torch.cuda.device_count() if torch.cuda.is_available() else 0
        if count == 0:
            raise UsageError(f"--device {text}: this machine has no CUDA GPU that PyTorch can use"
                             " (use --device cpu, or auto)")
        if dev.index is not None and dev.index >= count:
            raise UsageError(f"--device {text}: this machine has {count} CUDA GPU(s), cuda:0..cuda:{count - 1}")
    elif dev.type == "mps":
        if not (getattr(torch.backends, "mps", None) and torch.backends.mps.is_available()):
            raise UsageError(f"--device {text}: Apple's MPS is not available here (use --device cpu, or auto)")
    elif dev.type != "cpu":
        raise UsageError(f"--device {text}: devices of type {dev.type!r} are not supported (auto, cpu, cuda, mps)")


# -- the networks' flags --------------------------------------------------------------------------
# They come from the registered network classes (their ``description``, ``Options`` dataclass and
# declared members), which import torch: the train command's parser adds them when it parses, so
# that the other commands and ``meshvae --help`` start without torch.


def _flag(f: dataclasses.Field) -> str:
    """The command line's name of an ``Options`` field: its ``metadata["flag"]`` or ``--field-name``."""
    return f.metadata.get("flag", "--" + f.name.replace("_", "-"))


def _option_flags() -> dict:
    """flag -> (the architectures whose ``Options`` have it, its dataclass field), every registered network."""
    from meshvae_lib.model.networks import ARCHITECTURES, network_class

    flags: dict = {}
    for name in ARCHITECTURES:
        for f in dataclasses.fields(network_class(name).Options):
            owners, _ = flags.get(_flag(f), ((), f))
            flags[_flag(f)] = (owners + (name,), f)
    return flags


def _add_network_arguments(p: argparse.ArgumentParser) -> None:
    """``--architecture`` (every registered network, with its description) and each network's
    options as flags (default None: the network's own default)."""
    from meshvae_lib.model.networks import ARCHITECTURES, network_class

    p.add_argument("--architecture", choices=tuple(ARCHITECTURES), default=DEFAULT_ARCHITECTURE,
                   help=f"the network (default {DEFAULT_ARCHITECTURE}): " + "; ".join(
                       f"{name}: {network_class(name).description}" for name in ARCHITECTURES))
    group = p.add_argument_group("the networks' options", "each network's own options (default: the network's)")
    for flag, (owners, f) in _option_flags().items():
        default = f.default if f.default is not dataclasses.MISSING else f.default_factory()
        kwargs = {"dest": "network_" + f.name, "default": None}
        if isinstance(default, (tuple, list)):       # a sequence: one or more values of its items' type
            kwargs.update(nargs="+", type=type(default[0]) if default else int)
            default = " ".join(map(str, default))
        else:
            kwargs.update(type=type(default))
        if "choices" in f.metadata:
            kwargs["choices"] = f.metadata["choices"]
        else:
            kwargs["metavar"] = f.metadata.get("metavar", f.name.upper())
        group.add_argument(flag, help=f"{' and '.join(owners)}: {f.metadata.get('help', f.name)} (default {default})",
                           **kwargs)


class _TrainParser(argparse.ArgumentParser):
    """The train command's parser: the networks' flags are added on its first parse (or help)."""

    def parse_known_args(self, args=None, namespace=None):
        if not any(a.dest == "architecture" for a in self._actions):
            _add_network_arguments(self)
        return super().parse_known_args(args, namespace)


def _network_options(args, network) -> tuple[dict, dict]:
    """``TrainConfig.network_options`` from the flags given, and the map from the networks' option
    fields to their flags; UsageError for a flag of another network's."""
    flags, options = _option_flags(), {}
    for flag, (owners, f) in flags.items():
        value = vars(args)["network_" + f.name]
        if value is None:
            continue
        if network.architecture not in owners:
            raise UsageError(f"{flag} is the {' and '.join(owners)} network's, not {network.architecture}'s")
        options[f.name] = value
    return options, {f.name: flag for flag, (_, f) in flags.items()}


def _network_choices(args, network) -> tuple[int, ...]:
    """Check the network (``--architecture``'s class) against ``--features``, ``--hidden`` and
    ``--labels`` (setting its default feature kind when none is given); returns the internal layer sizes."""
    from meshvae_lib.model.networks import ARCHITECTURES, network_class
    from meshvae_lib.model.train_config import default_hidden

    if args.features is None:
        args.features = network.kinds[0] if network.kinds else DEFAULT_FEATURE_KIND
    if network.kinds and args.features not in network.kinds:
        raise UsageError(f"--architecture {args.architecture} works on --features {' or '.join(network.kinds)},"
                         f" not {args.features}")
    if args.labels and not network.conditional:
        raise UsageError(f"--architecture {args.architecture} is unconditional: no --labels")
    if network.takes_hidden:
        return tuple(args.hidden) if args.hidden is not None else default_hidden(args.features, args.init)
    if args.hidden:
        takers = [name for name in ARCHITECTURES if network_class(name).takes_hidden]
        raise UsageError(f"--hidden is the {' and '.join(takers)} network's; --architecture {args.architecture}"
                         " has its own layers")
    return ()


def _decoder_architecture(args, n_train: int) -> str:
    """The architecture ``--decoder`` picks for ``n_train`` training meshes: "corrected" when asked,
    or by default where the linear start is no longer the optimum (a ``--latent`` below the training
    rank, n_train - 1) and the mesh VAE would start at its PCA (no other ``--architecture``, no
    ``--init random``, ``--hidden``, ``--labels``, ``--sigma-object`` or ``--no-early-stopping``);
    else ``--architecture``."""
    if args.decoder == "corrected":
        return "corrected"
    linear_start = (args.architecture == DEFAULT_ARCHITECTURE and args.init == "pca" and not args.hidden
                    and not args.labels and args.sigma_object is None and not args.no_early_stopping)
    if args.decoder == "auto" and linear_start and args.latent is not None and args.latent < n_train - 1:
        return "corrected"
    return args.architecture


def _check_decoder(args) -> None:
    """``--decoder`` against ``--architecture`` (UsageError where they contradict); ``--decoder
    corrected`` sets the architecture."""
    if args.decoder != "auto" and args.architecture not in (DEFAULT_ARCHITECTURE, "corrected"):
        raise UsageError(f"--decoder {args.decoder} chooses the mesh VAE's decoder; --architecture {args.architecture}"
                         " has its own")
    if args.decoder == "linear" and args.architecture == "corrected":
        raise UsageError("--decoder linear contradicts --architecture corrected")
    if args.decoder == "corrected":
        args.architecture = "corrected"


def _chosen_decoder(args, n_train: int, network, config, flags: dict):
    """The network class and the config once the training meshes are counted (``n_train``): the
    corrected decoder where :func:`_decoder_architecture` picks it, else unchanged."""
    from meshvae_lib.model.networks import network_class

    chosen = _decoder_architecture(args, n_train)
    if chosen == args.architecture:
        return network, config
    args.architecture = chosen
    try:
        return network_class(chosen), dataclasses.replace(config, architecture=chosen)
    except ValueError as exc:
        raise UsageError(_option_names(str(exc), flags)) from None


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = add_command(subparsers, "train", "train a mesh VAE and save a checkpoint", DESCRIPTION, run)
    p.__class__ = _TrainParser     # the networks' flags on first parse: they import torch
    p.add_argument("data", metavar="DATA", help="collection: .npz file or folder of meshes")
    add_output_argument(p, "MODEL.pt", "checkpoint file to write")
    p.add_argument("--features", choices=FEATURE_KINDS, default=None,
                   help="what the network sees: RIMD features (the paper), or the baselines of Table 2:"
                   f" rigidly aligned or raw vertex coordinates (default: {DEFAULT_FEATURE_KIND}, or the first"
                   " kind a network that reads only some can read)")
    p.add_argument("--latent", type=int, default=None, metavar="D",
                   help=f"latent size (default: the network's; the mesh VAE's {DEFAULT_LATENT}, or with the PCA start"
                        f" one per direction the training meshes span when that is more, up to {PCA_LATENT_MAX})")
    p.add_argument("--epochs", type=int, default=None, metavar="E",
                   help=f"training epochs, the most early stopping may choose (default: the network's, {DEFAULT_EPOCHS} for the mesh VAE)")
    p.add_argument("--init", choices=INIT_MODES, default=DEFAULT_INIT,
                   help="pca (default): start from the PCA of the training features (networks without internal"
                        " layers, standard prior, no labels; docs/vae.md); random: PyTorch's initialisation (the paper)")
    p.add_argument("--decoder", choices=DECODERS, default="auto",
                   help="auto (default): with --latent below the training meshes' rank (training meshes - 1), the"
                        " corrected decoder (the linear decoder plus a correction kept only where it lowers the error"
                        " of validation meshes; docs/results/nonlinearity.md), else the linear decoder; linear: the"
                        " mesh VAE without internal layers at its PCA start; corrected: always the corrected decoder")
    p.add_argument("--no-early-stopping", action="store_true",
                   help="train all --epochs instead of choosing them on every 8th training mesh")
    p.add_argument("--alpha", type=float, default=DEFAULT_ALPHA, metavar="A",
                   help=f"weight of the reconstruction term, Eq. 4 (default {DEFAULT_ALPHA:g})")
    p.add_argument("--hidden", type=int, nargs="*", default=None, metavar="H",
                   help="internal layer sizes, outermost first (default: none; see docs/vae.md)")
    p.add_argument("--batch-size", type=int, default=DEFAULT_BATCH_SIZE, metavar="B", help=f"default {DEFAULT_BATCH_SIZE}")
    p.add_argument("--lr", type=float, default=DEFAULT_LR, help=f"Adam learning rate (default {DEFAULT_LR:g})")
    p.add_argument("--holdout-every", type=int, default=0, metavar="K",
                   help="hold out every K-th mesh (K >= 2) and report its reconstruction error (default: 0, none)")
    p.add_argument("--labels", nargs="+", default=[], metavar="COLUMN",
                   help="label columns to condition on (conditional mesh VAE, Eq. 5)")
    p.add_argument("--sigma-object", type=_floats, default=None, metavar="V1,V2,...",
                   help="prior deviations of the first latent dimensions (Sec. 4.4); the rest are 1")
    p.add_argument("--prior-form", choices=PRIOR_FORMS, default="exact",
                   help="how --sigma-object enters the latent cost: the exact KL (default) or the authors'"
                        " sibling-code formula, which makes the small-sigma dimensions carry the dominant"
                        " variation (for 2D maps and exploration)")
    p.add_argument("--reference", type=int, default=0, metavar="I", help="index of the reference mesh (default 0)")
    p.add_argument("--seed", type=int, default=0, metavar="S", help="random seed (default 0)")
    p.add_argument("--device", default="auto", help="auto (GPU when available), cpu, cuda, ... (default auto)")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    add_allow_degenerate(p)
    return p


def run(args) -> int:
    from meshvae_lib.model.meshvae_model import MeshVAEModel
    from meshvae_lib.model.training import TrainingDiverged, holdout_mask
    from meshvae_lib.model.evaluation import evaluate_model
    from meshvae_lib.geometry.collection_io import read_collection
    from meshvae_lib.model.train_config import TrainConfig

    from meshvae_lib.model.networks import network_class

    # every value is checked before the data is read and any training starts
    if args.latent is not None:
        check_at_least(args.latent, 1, "--latent")
    if args.epochs is not None:
        check_at_least(args.epochs, 1, "--epochs")
        check_at_most(args.epochs, MAX_EPOCHS, "--epochs")
    check_at_least(args.batch_size, 2, "--batch-size")
    check_number(args.lr, "--lr")
    check_number(args.alpha, "--alpha")
    for h in args.hidden or ():
        check_at_least(h, 1, "--hidden")
    if args.holdout_every != 0:
        check_at_least(args.holdout_every, 2, "--holdout-every", "or 0 for none")
    check_seed(args.seed)
    _check_device(args.device)
    check_output(args.output)  # its folder must exist, as for every command's -o
    _check_decoder(args)
    network = network_class(args.architecture)
    hidden = _network_choices(args, network)
    options, flags = _network_options(args, network)
    try:
        config = TrainConfig(architecture=args.architecture, network_options=options, epochs=args.epochs, batch_size=args.batch_size, lr=args.lr, alpha=args.alpha,
                             latent_dim=args.latent, hidden=hidden, sigma_object=args.sigma_object,
                             prior_form=args.prior_form, seed=args.seed, init=args.init,
                             early_stopping=False if args.no_early_stopping else None,
                             device=args.device, progress=not args.no_progress)
    except ValueError as exc:
        raise UsageError(_option_names(str(exc), flags)) from None
    collection = read_collection(args.data, allow_degenerate=args.allow_degenerate)
    if not -len(collection) <= args.reference < len(collection):
        raise UsageError(f"--reference {args.reference} is out of range for {len(collection)} meshes"
                         f" (0..{len(collection) - 1})")
    network, config = _chosen_decoder(args, len(collection) - int(holdout_mask(len(collection), args.holdout_every).sum()),
                                      network, config, flags)
    n_features = (3 * collection.n_vertices if args.features != "rimd"
                  else 6 * collection.n_vertices + 9 * len(collection.faces))  # RIMD: 6V + 6E, E <= 3F/2
    n_params = network.weights_estimate(n_features, config)
    if n_params is not None and n_params > MAX_NETWORK_PARAMETERS:
        raise UsageError(f"the network would have about {n_params:,} weights (K = {n_features:,} features,"
                         f" --hidden {' '.join(map(str, hidden)) or '(none)'}, --latent {args.latent or 'auto'});"
                         f" the limit is {MAX_NETWORK_PARAMETERS:,}: choose smaller --hidden or --latent")
    at_most = "at most " if config.resolved_early_stopping(len(args.labels)) else ""
    epochs = "" if network.trains_in_start else f", hidden {list(hidden)}, {at_most}{config.epochs} epochs"
    note(f"training on {len(collection)} meshes of {collection.n_vertices} vertices, network {args.architecture},"
         f" features {args.features}, latent {args.latent or 'auto'}{epochs}")
    model = MeshVAEModel(features=args.features, config=config, labels=args.labels,
                         holdout_every=args.holdout_every, reference_index=args.reference)
    try:
        model.fit(collection)
    except TrainingDiverged as exc:  # valid input, failed training: not the command's fault
        raise CommandFailed(str(exc)) from exc
    except ValueError as exc:
        raise UsageError(_small_mesh(_option_names(str(exc), flags), args, collection)) from exc
    model.save(args.output)
    last = model.history_[-1]
    if args.architecture == "corrected":
        result(f"decoder: {model.network.describe()} ({model.network.choice})")
    elif model.selection_ is not None and "skipped" in model.selection_:
        result(f"no epoch search, the model is the PCA start: {model.selection_['skipped']}")
    elif model.selection_ is not None:
        result(f"early stopping on {len(model.selection_['validation_rows'])} training meshes chose"
               f" {model.train_epochs_} epochs" + (" (the PCA start itself)" if model.train_epochs_ == 0 else ""))
    result(f"trained in {model.train_seconds_:.1f} s: loss {last['total']:.4g} (reconstruction"
           f" {last['reconstruction']:.4g}, KL {last['kl']:.4g}), K = {model.n_features}, latent {model.latent_dim}")
    if model.holdout_mask_.any():
        res = evaluate_model(model, collection, held_out_only=True, progress=not args.no_progress)
        result(f"held-out per-vertex error: {res['mean_vertex_error']:.6g} over {res['n_meshes']} meshes"
               f" ({100 * res['relative_error']:.3g}% of the bounding-box diagonal)")
    result(f"wrote {args.output}")
    return 0
