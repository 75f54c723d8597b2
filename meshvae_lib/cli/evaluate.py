"""``meshvae evaluate model.pt DATA``: per-vertex reconstruction error of a trained model."""

from __future__ import annotations

import argparse
import json

from meshvae_lib.defaults import GAUSS_NEWTON_ITERATIONS
from meshvae_lib.model.inference import INFERENCE_METHODS

from . import UsageError, add_allow_degenerate, add_command, add_model_argument, check_at_least, check_at_most, result

DESCRIPTION = """\
Encode every mesh of DATA, decode it, align it rigidly to the original and report the mean
per-vertex distance (the error of the paper's Table 2), in the mesh's own units. By default a
mesh's code is the encoder's mean refined by a few Gauss-Newton steps on the vertex error
(--inference gauss-newton, docs/vae.md "Inference by Gauss-Newton"); --inference encoder is the
paper's feed-forward encoder alone.
With --held-out only the meshes held out during training are measured: the model recorded each
mesh's identity (its vertex positions), so DATA is the training collection in any order (or any
part of it that holds every held-out mesh); a DATA without them, or with meshes the model was not
trained on, is refused.

examples:
  meshvae evaluate scape.pt scape.npz
  meshvae evaluate scape.pt scape.npz --held-out --json
  meshvae evaluate scape.pt scape.npz --held-out --pca          # + linear PCA on the training meshes
  meshvae evaluate scape.pt held_out.npz --pca train.npz        # PCA fitted on another file
  meshvae evaluate scape.pt scape.npz --held-out --inference encoder  # the paper's encoder
  meshvae evaluate scape.pt scape.npz --held-out --fit-latent 3  # codes fitted by finite differences
  meshvae evaluate scape.pt scape.npz --gn-steps 2 --chord-steps 1  # fewer Jacobians: faster, less accurate

--pca adds the linear floor: PCA on vertex coordinates fitted on the training meshes (by default
the meshes of DATA the model did not hold out; or those of the given file), with all the
directions they span unless --pca-components says otherwise, measured on the same meshes and with
the same error as the model.
"""


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = add_command(subparsers, "evaluate", "per-vertex reconstruction error of a model on a collection", DESCRIPTION, run)
    add_model_argument(p)
    p.add_argument("data", metavar="DATA", help="collection (.npz or folder) with the model's mesh")
    p.add_argument("--held-out", action="store_true",
                   help="only the meshes held out in training, found in DATA by their vertex positions (any order)")
    p.add_argument("--json", action="store_true",
                   help="print JSON (mean_vertex_error, n_meshes, relative_error, per_mesh, names)")
    p.add_argument("--inference", choices=INFERENCE_METHODS, default=None,
                   help="how a mesh's code is found (default: the model's own, normally gauss-newton: the encoder's"
                        " mean, then Gauss-Newton steps on the vertex error with the analytic Jacobian; encoder: the"
                        " paper's feed-forward encoder; finite-difference: Gauss-Newton by forward differences)")
    p.add_argument("--fit-latent", type=int, default=0, metavar="N",
                   help="fit each mesh's latent code with N Gauss-Newton steps by finite differences (the reference"
                        " for --inference gauss-newton; slower: N x (D + 1) decodes per mesh)")
    p.add_argument("--pca", nargs="?", const="", default=None, metavar="TRAIN",
                   help="also report linear PCA on coordinates fitted on the training meshes: those of DATA"
                        " not held out (no value), or all meshes of the collection TRAIN")
    p.add_argument("--pca-components", type=int, default=None, metavar="K",
                   help="principal components of the PCA baseline (default: all the training meshes span)")
    p.add_argument("--jobs", type=int, default=None, metavar="N",
                   help="processes fitting meshes at once with the default inference (default: every available"
                        " core; the codes do not depend on it)")
    p.add_argument("--gn-steps", type=int, default=None, metavar="N",
                   help=f"Jacobians per mesh at most with the default inference (default {GAUSS_NEWTON_ITERATIONS});"
                        " fewer is faster and less accurate (docs/results/inference_speed.md)")
    p.add_argument("--chord-steps", type=int, default=None, metavar="N",
                   help="with the default inference, up to N more steps after each accepted one with the same"
                        " Jacobian (a decode each instead of a Jacobian; default 0)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar while codes are fitted")
    add_allow_degenerate(p)
    return p


def _file(text: str) -> str:
    """A file given on the command line as its messages name it: its name, cut to a readable length."""
    from pathlib import Path

    from meshvae_lib.input_checks import short_name

    return short_name(Path(text).name or text)


def _compatible(model, collection, what: str) -> None:
    """:class:`UsageError` naming ``what`` (DATA's file, or ``--pca FILE``) unless the model fits
    ``collection``."""
    try:
        model.check_compatible(collection)
    except ValueError as exc:
        raise UsageError(f"{what}: {exc}") from None


def _chosen_meshes(args, model, collection):
    """The meshes of DATA to measure (indices; with ``--held-out`` the model's held-out meshes, found by
    their vertex positions in any order) and the training meshes of ``--pca`` ((N, n, 3) float64, or
    None without ``--pca``); :class:`UsageError` saying why when DATA does not hold them."""
    import numpy as np

    from meshvae_lib.geometry.collection_io import read_collection
    from meshvae_lib.model.evaluation import training_split_of

    data = _file(args.data)
    V = np.asarray(collection.vertices, dtype=np.float64)
    split = None
    if args.held_out or args.pca == "":
        if args.held_out and model.mesh_fingerprints_ is None:
            raise UsageError(f"{_file(args.model)} was written by an older version that did not record which"
                             " meshes it held out: --held-out cannot find them; retrain it")
        try:
            split = training_split_of(model, V)
        except ValueError as exc:
            hint = "" if args.held_out else "; or give the training meshes: --pca TRAIN"
            raise UsageError(f"{'--held-out' if args.held_out else '--pca'}: {data}: {exc}{hint}") from None
    indices = split[1] if args.held_out else np.arange(len(collection))
    if args.pca is None:
        return indices, None
    if args.pca:
        train = read_collection(args.pca, allow_degenerate=args.allow_degenerate)
        _compatible(model, train, f"--pca {_file(args.pca)}")
        return indices, np.asarray(train.vertices, dtype=np.float64)
    n_train = int((~np.asarray(model.holdout_mask_, dtype=bool)).sum())
    if len(split[0]) != n_train:
        raise UsageError(f"--pca: {data} holds {len(split[0])} of the model's {n_train} training meshes; PCA must be"
                         " fitted on all of them: give the training collection as DATA, or the training meshes: --pca TRAIN")
    return indices, V[split[0]]


def run(args) -> int:
    from meshvae_lib.model.meshvae_model import load_model
    from meshvae_lib.model.evaluation import evaluate_model
    from meshvae_lib.geometry.collection_io import read_collection

    import numpy as np

    from meshvae_lib.defaults import MAX_SOLVER_STEPS

    check_at_least(args.fit_latent, 0, "--fit-latent")
    check_at_most(args.fit_latent, MAX_SOLVER_STEPS, "--fit-latent", "Gauss-Newton steps per mesh")
    if args.pca_components is not None:
        check_at_least(args.pca_components, 1, "--pca-components")
    inference = args.inference
    # the default inference's options: (flag, GaussNewton keyword, value, least value, budget of the most)
    given = [option for option in (("--jobs", "n_jobs", args.jobs, 1, None),
                                   ("--gn-steps", "iterations", args.gn_steps, 1, "Gauss-Newton steps per mesh"),
                                   ("--chord-steps", "chord_steps", args.chord_steps, 0, "chord steps per Jacobian"))
             if option[2] is not None]
    gn_options = {name: value for _, name, value, _, _ in given}
    if given:
        if args.fit_latent or inference not in (None, "gauss-newton"):
            raise UsageError(f"{', '.join(flag for flag, *_ in given)}: options of the default inference (gauss-newton),"
                             " which does not combine"
                             f" with {'--fit-latent' if args.fit_latent else '--inference ' + str(inference)}")
        for flag, _, value, least, budget in given:
            check_at_least(value, least, flag)
            if budget:
                check_at_most(value, MAX_SOLVER_STEPS, flag, budget)
        from meshvae_lib.model.inference.gauss_newton import GaussNewton

        inference = GaussNewton(**gn_options)
    collection = read_collection(args.data, allow_degenerate=args.allow_degenerate)
    model = load_model(args.model)
    _compatible(model, collection, _file(args.data))
    if args.fit_latent and args.inference not in (None, "finite-difference"):
        raise UsageError(f"--fit-latent fits by finite differences; it does not combine with --inference {args.inference}")
    indices, V_train = _chosen_meshes(args, model, collection)
    pca = None
    if V_train is not None:  # the linear floor first: a bad --pca-components is found before the work
        from meshvae_lib.model.evaluation import pca_baseline

        V_eval = np.asarray(collection.vertices, dtype=np.float64)[indices]
        rank = min(len(V_train) - 1, 3 * collection.n_vertices)
        if args.pca_components is not None and args.pca_components > rank:
            raise UsageError(f"--pca-components must be <= {rank} (what {len(V_train)} training meshes span),"
                             f" got {args.pca_components}")
        try:
            pca = pca_baseline(V_train, V_eval, n_components=args.pca_components)
        except ValueError as exc:
            raise UsageError(str(exc).replace("n_components", "--pca-components")) from None
    res = evaluate_model(model, collection, indices=indices, fit_iterations=args.fit_latent,
                         inference=inference, progress=not args.no_progress)
    if pca is not None:
        res["pca"] = pca
    if args.json:
        result(json.dumps(res, indent=2))
    else:
        worst = max(range(res["n_meshes"]), key=lambda i: res["per_mesh"][i])
        result(f"mean per-vertex error: {res['mean_vertex_error']:.6g} over {res['n_meshes']} meshes"
               f" ({100 * res['relative_error']:.3g}% of the bounding-box diagonal; features {res['features']}"
               + f"; inference {res['inference']}"
               + (f", {args.fit_latent} steps" if args.fit_latent else "")
               + (f" ({res['inference_description']})" if {"iterations", "chord_steps"} & set(gn_options) else "")
               + f"; {res['seconds_per_mesh']:.2g} s per mesh)")
        result(f"worst: {res['names'][worst]} ({res['per_mesh'][worst]:.6g})")
        if "pca" in res:
            pca = res["pca"]
            result(f"linear PCA on coordinates ({pca['n_components']} components, fitted on the training meshes):"
                   f" {pca['mean_vertex_error']:.6g} ({100 * pca['relative_error']:.3f}% of the diagonal);"
                   f" model / PCA = {res['mean_vertex_error'] / max(pca['mean_vertex_error'], 1e-300):.3g}")
    return 0
