"""The ``meshvae`` command line: one sub-command per module in this package.

Each sub-command lives in ``meshvae_lib/cli/<name>.py`` and defines ``add_parser(subparsers)``, which
adds its parser (with :func:`add_command`) and sets ``func`` (called with the parsed namespace,
returns an exit code). This module holds what the commands share, importable without numpy or
torch so that ``--help`` stays fast:

- the conventions, applied in one place, :func:`main`: exit status ``EXIT_OK`` (0),
  ``EXIT_FAILURE`` (1: the command failed on valid input, :class:`CommandFailed` or an I/O error
  such as ``cannot write FILE: reason``), ``EXIT_USAGE`` (2: bad usage or a bad value,
  :class:`UsageError`, ``ValueError`` or a missing file) and ``EXIT_INTERRUPTED`` (130: Ctrl-C,
  reported as ``interrupted`` without a traceback); results and "wrote ..." lines go to stdout
  (:func:`result`), progress, warnings and errors to stderr (:func:`note`);
- the checks every command makes before any work: the output can be written
  (:func:`check_output`; outputs are written atomically by the library's writers,
  :mod:`meshvae_lib.atomic`), and sizes that follow from options fit a stated budget
  (:func:`check_budget`, :func:`check_at_most`);
- the shared arguments (:func:`add_model_argument`, :func:`add_output_argument`,
  :func:`add_allow_degenerate`) and the one resolver of a mesh given on the command line as an
  index, a mesh name or a file (:func:`resolve_mesh`, in :mod:`~meshvae_lib.cli.mesh_argument`).
"""

from __future__ import annotations

import argparse
import importlib
import logging
import os
import sys

logger = logging.getLogger(__name__)

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

#: exit status: success.
EXIT_OK = 0
#: exit status: the command failed on valid input (training diverged, an I/O error while writing, ...).
EXIT_FAILURE = 1
#: exit status: bad usage or a bad value, for the user to fix in the command (argparse's own code).
EXIT_USAGE = 2
#: an error message longer than this is cut in the middle (names are cut earlier, where they are
#: formatted; this is the backstop).
MESSAGE_CHARS = 500
#: exit status: interrupted by Ctrl-C (128 + SIGINT, as shells report it).
EXIT_INTERRUPTED = 130
#: exit status: stdout was closed by its reader (``meshvae ... | head``): the command ends quietly,
#: with the status shells report for a command ended by SIGPIPE (128 + 13), as ``cat`` does.
EXIT_BROKEN_PIPE = 141

EPILOG = """\
exit status:
  0  success
  1  the command failed on valid input: e.g. training diverged, or an I/O error while writing
  2  bad usage or a bad value, to fix in the command: an unknown option, a value out of range, a
     missing or unknown file or mesh name, a damaged checkpoint, a model that does not fit the data,
     an output that cannot be written (all checked before any work)
  130  interrupted (Ctrl-C): nothing half-written is left
  141  stdout was closed by its reader (`meshvae ... | head`): the command ends quietly, as `cat`
       does (a full stdout, e.g. /dev/full, is an error: status 1)

outputs are written atomically: a failed write ("cannot write FILE: reason") keeps the old file;
a folder output replaces an existing folder of meshes as a whole (never merged with it).

output: results and "wrote ..." lines go to stdout; progress bars, warnings and errors
(one line: "meshvae COMMAND: error: ...") go to stderr.

Run `meshvae COMMAND --help` for a command's options and examples.
"""


class UsageError(Exception):
    """A bad value in the command (exit status 2). ``ValueError`` and a missing file count too."""


class CommandFailed(Exception):
    """The command failed on valid input (exit status 1), e.g. training diverged."""


#: exceptions that mean "fix the command": a bad value, a file or folder that is not there (or is
#: the wrong kind). Any other OSError is a failure on valid input (a full disk, a permission).
USAGE_ERRORS = (UsageError, ValueError, FileNotFoundError, NotADirectoryError, IsADirectoryError)


def exit_status(exc: BaseException) -> int:
    """The exit status of a command that raised ``exc``: ``EXIT_USAGE`` or ``EXIT_FAILURE``."""
    if isinstance(exc, CommandFailed):
        return EXIT_FAILURE
    return EXIT_USAGE if isinstance(exc, USAGE_ERRORS) else EXIT_FAILURE


def printable(text: str) -> str:
    """``text`` with control characters (a terminal's escape sequences, carriage returns, a bidi
    override) written as escapes, ``\\x1b``, so that echoing a name cannot act on the terminal; line
    breaks and tabs (columns of ``synth --list``) are kept."""
    if text.isprintable():
        return text
    return "".join(c if c.isprintable() or c in "\n\t" else repr(c)[1:-1] for c in text)


def result(text: str) -> None:
    """A line of the command's output (results, "wrote ..."): stdout, flushed at once, so that a
    full stdout is reported as ``cannot write stdout: reason`` (:class:`~meshvae_lib.atomic.OutputError`,
    exit status 1) and a reader that has gone (``| head``) ends the command quietly
    (``BrokenPipeError``, :data:`EXIT_BROKEN_PIPE`)."""
    try:
        print(printable(text), file=sys.stdout, flush=True)
    except BrokenPipeError:
        raise
    except OSError as exc:
        from meshvae_lib.atomic import OutputError

        raise OutputError("stdout", exc.strerror or str(exc), exc.errno) from None


def note(text: str) -> None:
    """A progress or warning line, not part of the output: stderr."""
    print(printable(text), file=sys.stderr)


# --- shared arguments --------------------------------------------------------------------------


def add_command(subparsers, name: str, help: str, description: str, run) -> argparse.ArgumentParser:
    """A sub-command parser that calls ``run(args)``; its description (with its examples) keeps
    its line breaks."""
    p = subparsers.add_parser(name, help=help, description=description,
                              formatter_class=argparse.RawDescriptionHelpFormatter)
    p.set_defaults(func=run)
    return p


def check_at_least(value: int, minimum: int, option: str, why: str = "") -> None:
    """:class:`UsageError` unless ``value >= minimum`` (``why``: a reason for the message)."""
    if value < minimum:
        raise UsageError(f"{option} must be >= {minimum}{f' ({why})' if why else ''}, got {value}")


def check_at_most(value: int, maximum: int, option: str, why: str = "") -> None:
    """:class:`UsageError` unless ``value <= maximum`` (``why``: the budget, for the message)."""
    if value > maximum:
        raise UsageError(f"{option} must be <= {maximum:,}{f' ({why})' if why else ''}, got {value:,}")


def check_number(value: float, option: str, *, positive: bool = True) -> None:
    """:class:`UsageError` unless ``value`` is a finite number (and > 0 when ``positive``)."""
    import math

    if not math.isfinite(value) or (positive and value <= 0):
        raise UsageError(f"{option} must be a finite number{' > 0' if positive else ''}, got {value}")


def check_seed(value: int, option: str = "--seed") -> None:
    """:class:`UsageError` unless ``value`` is a seed every generator takes: 0 <= value <= ``MAX_SEED``
    (``defaults``)."""
    from meshvae_lib.defaults import MAX_SEED

    check_at_least(value, 0, option)
    check_at_most(value, MAX_SEED, option, "a 64-bit seed")


def check_budget(n_meshes: int, n_vertices: int, option: str) -> None:
    """:class:`UsageError` unless ``n_meshes`` meshes of ``n_vertices`` vertices fit in one run's
    budget of ``MAX_OUTPUT_VERTICES`` decoded vertices (``defaults``); the message gives the size,
    the limit and the largest ``option`` that fits."""
    from meshvae_lib.defaults import MAX_OUTPUT_VERTICES

    total = n_meshes * n_vertices
    if total > MAX_OUTPUT_VERTICES:
        most = max(MAX_OUTPUT_VERTICES // max(n_vertices, 1), 1)
        raise UsageError(f"{option} {n_meshes:,} asks for {n_meshes:,} meshes of {n_vertices:,} vertices ="
                         f" {total:,} vertices (about {total * 24 / 2**30:.3g} GiB of float64 positions); the"
                         f" limit is {MAX_OUTPUT_VERTICES:,} vertices per run: {option} <= {most:,} for this"
                         " model (run several times for more)")


def check_output(path, *, collection: bool = False, parents: bool = False):
    """The ``-o`` of a command, checked before any work: :class:`UsageError` unless it can be
    written (``meshvae_lib.atomic.check_writable``). ``collection``: an ``.npz`` file when ``path``
    ends in ``.npz``, else a folder of meshes (an existing one is replaced as a whole, so it must
    hold only meshes and ``labels.csv``); ``parents``: missing parent folders will be created.
    Returns the path as a ``Path``."""
    from pathlib import Path

    from meshvae_lib.atomic import check_writable

    path = Path(path)
    folder = collection and path.suffix.lower() != ".npz"
    outputs = None
    if folder:
        from meshvae_lib.geometry.collection_io import FOLDER_OUTPUTS as outputs
    try:
        return check_writable(path, folder=folder, parents=parents, outputs=outputs)
    except ValueError as exc:
        raise UsageError(str(exc)) from None


def add_model_argument(parser: argparse.ArgumentParser) -> None:
    """The ``MODEL.pt`` positional of every command that reads a checkpoint."""
    parser.add_argument("model", metavar="MODEL.pt", help="checkpoint written by `meshvae train`")


def add_output_argument(parser: argparse.ArgumentParser, metavar: str = "OUT",
                        help: str = ".npz file or folder for OBJ files") -> None:
    """The required ``-o/--output`` of every command that writes something."""
    parser.add_argument("-o", "--output", required=True, metavar=metavar, help=help)


def add_allow_degenerate(parser: argparse.ArgumentParser) -> None:
    """The ``--allow-degenerate`` flag of every command that reads meshes (``read_collection``)."""
    parser.add_argument("--allow-degenerate", action="store_true",
                        help="accept zero-area faces (they get the fallback cotangent weight)")


# --- a mesh named on the command line: meshvae_lib/cli/mesh_argument.py ------------------------

from .mesh_argument import ChosenMesh, resolve_mesh  # noqa: E402  (it needs UsageError)


# --- the command line --------------------------------------------------------------------------


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="meshvae",
        description="Mesh variational autoencoders (Tan et al., CVPR 2018): RIMD features,\n"
        "reconstruction, training and applications on your own deforming meshes.",
        epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    from meshvae_lib import __version__

    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    parser.add_argument("-v", "--verbose", action="store_true",
                        help="log progress details (and show the traceback of an unexpected error)")
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


def run() -> None:
    """The ``meshvae`` console script and ``python -m meshvae_lib.cli``: :func:`main`, then exit with
    its status. After a Ctrl-C has been reported (status 130), further interrupts are ignored: the
    command is over, and a late second one (while the interpreter shuts down) must not turn the
    status into a death by SIGINT or print a traceback; the process then leaves with ``os._exit``
    after the exit handlers, because CPython's own exit would report a death by SIGINT instead."""
    import atexit
    import signal

    try:
        status = main()
    except KeyboardInterrupt:  # a second Ctrl-C while the first was being reported
        print("meshvae: interrupted", file=sys.stderr)
        status = EXIT_INTERRUPTED
    except SystemExit as exc:  # argparse: --help, --version (0), a usage error (2)
        status = exc.code if isinstance(exc.code, int) else (EXIT_OK if exc.code is None else EXIT_USAGE)
    try:  # what is left in stdout's buffer (argparse's --help): a reader that has gone ends quietly
        sys.stdout.flush()
    except BrokenPipeError:
        _quiet_stdout()
        status = EXIT_BROKEN_PIPE
    except OSError as exc:
        _quiet_stdout()
        print(f"meshvae: error: cannot write stdout: {exc.strerror or exc}", file=sys.stderr)
        status = status or EXIT_FAILURE
    if status == EXIT_INTERRUPTED:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        # CPython ends a process by SIGINT (status -2, not 130) whenever a KeyboardInterrupt once escaped
        # an embedded evaluation (PyRun_* called from a C extension), even one handled here: about 1 in
        # 5 Ctrl-Cs during training, measured. The command is over and its writers have cleaned up, so
        # run the exit handlers, flush, and leave with the status without the interpreter's teardown.
        atexit._run_exitfuncs()
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (OSError, ValueError):  # a closed or broken pipe: nothing more can be said
                pass
        os._exit(status)
    sys.exit(status)


def _quiet_stdout() -> None:
    """Point stdout at the null device, so that the interpreter's last flush at exit finds nothing to
    complain about (a reader that has gone, a full disk)."""
    try:
        fd = os.open(os.devnull, os.O_WRONLY)
        os.dup2(fd, sys.stdout.fileno())
        os.close(fd)
    except (OSError, ValueError, AttributeError):  # no real file behind stdout (a test's capture)
        pass


def _message(exc: BaseException, command: str) -> tuple[str, int]:
    """The one-line message and exit status of a command that raised ``exc``."""
    import errno

    status = exit_status(exc)
    expected = isinstance(exc, (*USAGE_ERRORS, CommandFailed, OSError))
    if isinstance(exc, OSError) and exc.errno == errno.ENAMETOOLONG:  # a name given on the command line
        from meshvae_lib.input_checks import short_name

        name = exc.filename if exc.filename is not None else ""
        return f"{short_name(os.path.basename(str(name)) or name)}: the file name is too long for the file system", EXIT_USAGE
    text = str(exc) if expected and str(exc) else f"{type(exc).__name__}: {exc}"
    if len(text) > MESSAGE_CHARS:  # a long name or a library's long text: the start and the end
        text = f"{text[: MESSAGE_CHARS - 200]} ... {text[-150:]}"
    if not expected:
        text += f" (run `meshvae -v {command} ...` for the traceback)"
    return text, status


def main(argv: list[str] | None = None) -> int:
    """Run one command; returns its exit status (argparse errors, ``--help`` and ``--version``
    raise ``SystemExit`` as argparse does: 2 and 0; Ctrl-C returns ``EXIT_INTERRUPTED``)."""
    try:
        return _main(argv)
    except KeyboardInterrupt:  # Ctrl-C before the command started (while parsing, importing)
        print("meshvae: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED


def _main(argv: list[str] | None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(
        level=logging.INFO if args.verbose else logging.WARNING,
        format="%(levelname)s %(name)s: %(message)s",
    )
    if not getattr(args, "func", None):
        parser.print_help(sys.stderr)
        return EXIT_USAGE
    try:
        from meshvae_lib.model.threads import ENV_VAR, configure_threads

        if os.environ.get(ENV_VAR, "").strip():  # only then, so that commands without torch stay fast
            configure_threads()
        return int(args.func(args) or EXIT_OK)
    except KeyboardInterrupt:  # Ctrl-C: the writers leave nothing half-written; no traceback
        print(f"meshvae {args.command}: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:  # stdout's reader has gone (`| head`): nothing more to say, to anyone
        _quiet_stdout()
        return EXIT_BROKEN_PIPE
    except Exception as exc:  # one line on stderr, no traceback; the status says whose fault it is
        text, status = _message(exc, args.command)
        if args.verbose:
            logger.error("traceback of the error below", exc_info=exc)
        print(printable(f"meshvae {args.command}: error: {text}").replace("\n", " "), file=sys.stderr)
        return status


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
