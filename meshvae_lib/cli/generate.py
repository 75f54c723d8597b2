"""``meshvae generate model.pt -n N -o OUT``: new meshes decoded from prior samples."""

from __future__ import annotations

import argparse

from . import (UsageError, add_command, add_model_argument, add_output_argument, check_at_least, check_budget,
               check_output, check_seed, result)

DESCRIPTION = """\
Draw N latent vectors from the prior N(0, diag(sigma_object^2)) and decode them into meshes
(paper Sec. 5, "Generation"). --temperature T < 1 scales the prior's deviations down: meshes nearer
the training poses, less varied (docs/vae.md). For a conditional model, --condition COLUMN=VALUE fixes a label
(repeat for several columns); columns left unset take the labels of random training meshes.
OUT ending in .npz gets an .npz collection, any other OUT a folder of OBJ files.

examples:
  meshvae generate scape.pt -n 10 -o generated/
  meshvae generate scape.pt -n 10 -o calmer/ --temperature 0.7
  meshvae generate dyna_cond.pt -n 8 -o running.npz --condition motion=running_on_spot --seed 3
"""


def _condition(text: str) -> tuple[str, str]:
    if "=" not in text:
        raise argparse.ArgumentTypeError(f"expected COLUMN=VALUE, got {text!r}")
    key, value = text.split("=", 1)
    return key.strip(), value.strip()


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = add_command(subparsers, "generate", "generate new meshes from a trained model", DESCRIPTION, run)
    add_model_argument(p)
    p.add_argument("-n", type=int, default=10, metavar="N", help="number of meshes (default 10)")
    add_output_argument(p)
    p.add_argument("--condition", type=_condition, action="append", default=[], metavar="COLUMN=VALUE",
                   help="label value for a conditional model (repeatable)")
    p.add_argument("--seed", type=int, default=0, metavar="S", help="random seed (default 0)")
    p.add_argument("--temperature", type=float, default=1.0, metavar="T",
                   help="scale of the prior's deviations, > 0 and <= 10 (default 1: the paper's prior; lower: nearer"
                        " the training poses)")
    return p


def run(args) -> int:
    import numpy as np

    from meshvae_lib.model.meshvae_model import load_model
    from meshvae_lib.geometry.collection_io import write_collection
    from meshvae_lib.validation import check_positive

    from meshvae_lib.defaults import MAX_TEMPERATURE

    check_at_least(args.n, 1, "-n")
    try:
        check_positive(args.temperature, "--temperature")
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    if args.temperature > MAX_TEMPERATURE:
        raise UsageError(f"--temperature must be <= {MAX_TEMPERATURE:g} (draws at more prior deviations are far outside"
                         f" what the model learned), got {args.temperature:g}")
    check_seed(args.seed)
    check_output(args.output, collection=True)
    model = load_model(args.model)
    check_budget(args.n, len(model.reference_vertices), "-n")
    condition = dict(args.condition)
    if condition and not model.is_conditional:
        raise UsageError("this model was trained without labels; --condition needs a conditional model"
                         " (meshvae train ... --labels COLUMN)")
    V = model.generate(args.n, seed=args.seed, condition=condition or None, temperature=args.temperature)
    labels = {col: np.asarray([val] * args.n) for col, val in condition.items()}
    out = write_collection(args.output, V, model.faces,
                           names=[f"generated_{i:04d}" for i in range(args.n)], labels=labels or None)
    result(f"wrote {args.n} meshes to {out}")
    return 0
