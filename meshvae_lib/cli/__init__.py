"""The ``meshvae`` command line: one sub-command per module in this package.

Each sub-command lives in ``meshvae_lib/cli/<name>.py`` and defines ``add_parser(subparsers)``, which
adds its parser and sets ``func`` (called with the parsed namespace, returns an exit code).
"""

from __future__ import annotations

import argparse
import importlib
import logging
import os
import sys

#: sub-commands, in the order ``meshvae --help`` lists them.
COMMANDS = (
    "synth",
    "features",
    "reconstruct",
    "train",
    "evaluate",
    "generate",
    "interpolate",
)


def add_allow_degenerate(parser: argparse.ArgumentParser) -> None:
    """The ``--allow-degenerate`` flag of every command that reads meshes (``read_collection``)."""
    parser.add_argument("--allow-degenerate", action="store_true",
                        help="accept zero-area faces (they get the fallback cotangent weight)")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="meshvae",
        description="Mesh variational autoencoders (Tan et al., CVPR 2018): RIMD features, "
        "reconstruction, training and applications on your own deforming meshes.",
    )
    from meshvae_lib import __version__

    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress details")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMANDS:
        try:
            module = importlib.import_module(f"{__name__}.{name}")
        except ModuleNotFoundError as exc:  # a sub-command not written yet
            if exc.name != f"{__name__}.{name}":
                raise
            continue
        module.add_parser(subparsers)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(
        level=logging.INFO if args.verbose else logging.WARNING,
        format="%(levelname)s %(name)s: %(message)s",
    )
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    from meshvae_lib.model.threads import ENV_VAR, configure_threads

    try:
        if os.environ.get(ENV_VAR, "").strip():  # only then, so that commands without torch stay fast
            configure_threads()
        return int(args.func(args) or 0)
    except (ValueError, FileNotFoundError, OSError) as exc:
        # Errors from bad input are the user's to fix: one clear line, no traceback.
        print(f"meshvae {args.command}: error: {exc}", file=sys.stderr)
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
