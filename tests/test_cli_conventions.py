"""The conventions every ``meshvae`` command follows (``meshvae --help`` and README, "Bring your own meshes"):

- exit status 0 on success, 1 when the command fails on valid input, 2 for bad usage or a bad value;
- results and "wrote ..." lines on stdout, progress, warnings and errors on stderr;
- option choices are the library's constants; a damaged checkpoint is reported as damaged.
"""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import numpy as np
import pytest
from test_cli_vae import _strips

from meshvae_lib import defaults
from meshvae_lib.cli import (COMMANDS, EXIT_FAILURE, EXIT_USAGE, CommandFailed, UsageError, build_parser,
                             exit_status, main, resolve_mesh)
from meshvae_lib.geometry.collection_io import write_collection
from meshvae_lib.geometry.mesh_files import write_mesh

CLI = Path(__file__).resolve().parents[1] / "meshvae_lib" / "cli"


@pytest.fixture(scope="module")
def work(tmp_path_factory):
    """A tiny collection, its features and a tiny trained model (about a second)."""
    root = tmp_path_factory.mktemp("conventions")
    coll = _strips(n=8)
    data = write_collection(root / "strips.npz", coll)
    feats = root / "feats.npz"
    model = root / "m.pt"
    assert main(["features", str(data), "-o", str(feats)]) == 0
    assert main(["train", str(data), "-o", str(model), "--epochs", "2", "--latent", "2", "--no-progress"]) == 0
    return root, data, feats, model, coll


def _valid_runs(root, data, feats, model):
    return {
        "synth": ["synth", "bar", "-o", str(root / "bar.npz"), "--resolution", "300"],
        "features": ["features", str(data), "-o", str(root / "f2.npz"), "--reference", "s03"],
        "reconstruct": ["reconstruct", str(feats), "-o", str(root / "rebuilt.npz")],
        "train": ["train", str(data), "-o", str(root / "m2.pt"), "--epochs", "1", "--latent", "2", "--no-progress"],
        "evaluate": ["evaluate", str(model), str(data), "--json"],
        "generate": ["generate", str(model), "-n", "2", "-o", str(root / "gen.npz")],
        "interpolate": ["interpolate", str(model), "0", "-1", "--data", str(data), "--steps", "3",
                        "-o", str(root / "seq.npz")],
    }


def test_every_command_has_a_valid_run_here():
    assert sorted(_valid_runs(Path("."), "d", "f", "m")) == sorted(COMMANDS)


@pytest.mark.parametrize("command", COMMANDS)
def test_a_valid_run_exits_0_and_prints_its_output_on_stdout(work, command, capsys):
    root, data, feats, model, coll = work
    capsys.readouterr()
    assert main(_valid_runs(root, data, feats, model)[command]) == 0
    out, err = capsys.readouterr()
    assert "error" not in err
    assert "wrote" not in err, err  # "wrote ..." is output, never on stderr
    if command == "evaluate":
        assert out.lstrip().startswith("{") and '"mean_vertex_error"' in out
    else:
        assert out.strip().splitlines()[-1].startswith("wrote "), out


def _bad_values(root, data, feats, model):
    """(argv, message): a bad value for each command, to be reported with exit status 2."""
    return [
        (["synth", "nosuch", "-o", str(root / "x.npz")], "unknown collection 'nosuch'"),
        (["synth", "bar", "-o", str(root / "x.npz"), "--seed", "-1"], "--seed must be non-negative"),
        (["features", str(data), "-o", str(root / "x.npz"), "--reference", "8"],
         "--reference 8 is out of range for 8 meshes"),
        (["features", str(root / "missing"), "-o", str(root / "x.npz")], "no such collection"),
        (["reconstruct", str(feats), "-o", str(root / "x.npz"), "--iterations", "-1"],
         "--iterations must be >= 0"),
        (["reconstruct", str(root / "missing.npz"), "-o", str(root / "x.npz")], "no such feature file"),
        (["train", str(data), "-o", str(root / "x.pt"), "--latent", "0"], "--latent must be >= 1"),
        (["train", str(data), "-o", str(root / "x.pt"), "--labels", "colour"], "colour"),
        (["evaluate", str(model), str(data), "--fit-latent", "-1"], "--fit-latent must be >= 0"),
        (["evaluate", str(model), str(data), "--jobs", "0"], "--jobs must be >= 1"),
        (["evaluate", str(model), str(data), "--jobs", "2", "--inference", "encoder"], "--inference encoder"),
        (["evaluate", str(model), str(data), "--gn-steps", "0"], "--gn-steps must be >= 1"),
        (["evaluate", str(model), str(data), "--chord-steps", "-1"], "--chord-steps must be >= 0"),
        (["evaluate", str(model), str(data), "--gn-steps", "2", "--fit-latent", "1"],
         "--gn-steps: options of the default inference (gauss-newton), which does not combine with --fit-latent"),
        (["evaluate", str(root / "missing.pt"), str(data)], "no checkpoint file at"),
        (["generate", str(model), "-n", "0", "-o", str(root / "x.npz")], "-n must be >= 1"),
        (["generate", str(model), "-o", str(root / "x.npz"), "--condition", "pose=a"], "without labels"),
        (["interpolate", str(model), "0", "1", "--data", str(data), "--steps", "1", "-o", str(root / "x.npz")],
         "--steps must be >= 2"),
        (["interpolate", str(model), "0", "nobody", "--data", str(data), "-o", str(root / "x.npz")],
         "B 'nobody' is neither an index, a mesh name of the collection, nor a mesh file"),
    ]


def test_every_command_has_bad_value_cases():
    assert {argv[0] for argv, _ in _bad_values(Path("."), "d", "f", "m")} == set(COMMANDS)


def test_bad_values_exit_2_with_one_line_on_stderr(work, capsys):
    root, data, feats, model, coll = work
    capsys.readouterr()
    for argv, message in _bad_values(root, data, feats, model):
        assert main(argv) == EXIT_USAGE, argv
        out, err = capsys.readouterr()
        lines = [ln for ln in err.splitlines() if ln.startswith("meshvae ")]
        assert lines and lines[-1].startswith(f"meshvae {argv[0]}: error: ") and message in lines[-1], (argv, err)
        assert out == "", (argv, out)


@pytest.mark.parametrize("argv", [
    ["synth", "bar", "--seed", "x"],
    ["features", "d.npz", "-o", "f.npz", "--layout", "nope"],
    ["reconstruct", "f.npz"],  # -o missing
    ["train", "d.npz", "-o", "m.pt", "--sigma-object", "0,-1"],
    ["evaluate", "m.pt"],  # DATA missing
    ["generate", "m.pt", "-o", "g.npz", "--condition", "no-equals-sign"],
    ["interpolate", "m.pt", "0", "1", "-o", "s.npz", "--steps", "many"],
    ["nosuchcommand"],
])
def test_argparse_errors_exit_2_on_stderr(argv, capsys):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == EXIT_USAGE
    out, err = capsys.readouterr()
    assert out == "" and "error: " in err.strip().splitlines()[-1]


def test_no_command_prints_the_help_on_stderr_and_exits_2(capsys):
    assert main([]) == EXIT_USAGE
    out, err = capsys.readouterr()
    assert out == "" and "usage: meshvae" in err


def test_help_documents_the_conventions(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--help"])
    assert exc.value.code == 0
    out = capsys.readouterr().out
    assert "exit status:" in out and "0  success" in out and "1  the command failed on valid input" in out
    assert "2  bad usage or a bad value" in out and "stdout" in out and "stderr" in out
    readme = (CLI.parents[1] / "README.md").read_text()
    assert "exit status 0: success; 1: the command failed on valid input" in readme


def test_a_failure_on_valid_input_exits_1(work, capsys):
    """A training that diverges is not the command's fault: status 1, the library's message."""
    root, data, feats, model, coll = work
    capsys.readouterr()
    assert main(["train", str(data), "-o", str(root / "nan.pt"), "--init", "random", "--no-early-stopping",
                 "--lr", "1e12", "--alpha", "1e30", "--epochs", "20", "--latent", "2", "--no-progress"]) == EXIT_FAILURE
    out, err = capsys.readouterr()
    assert "meshvae train: error: training diverged" in err and "wrote" not in out
    assert not (root / "nan.pt").exists()


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full")
def test_an_io_error_while_writing_exits_1(tmp_path, capsys):
    out = tmp_path / "full.npz"
    out.symlink_to("/dev/full")  # every write fails with ENOSPC
    assert main(["synth", "bar", "-o", str(out), "--resolution", "300"]) == EXIT_FAILURE
    assert "meshvae synth: error: " in capsys.readouterr().err


def test_an_unexpected_error_exits_1_with_one_line(monkeypatch, capsys):
    from meshvae_lib.cli import synth

    def boom(args):
        raise RuntimeError("boom")

    monkeypatch.setattr(synth, "run", boom)
    assert main(["synth", "--list"]) == EXIT_FAILURE
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["meshvae synth: error: RuntimeError: boom (run `meshvae -v synth ...` for the traceback)"]


def test_exit_status_of_each_kind_of_error():
    assert exit_status(UsageError("x")) == exit_status(ValueError("x")) == EXIT_USAGE
    assert exit_status(FileNotFoundError("x")) == exit_status(IsADirectoryError("x")) == EXIT_USAGE
    assert exit_status(CommandFailed("x")) == exit_status(PermissionError("x")) == EXIT_FAILURE
    assert exit_status(OSError(28, "No space left on device")) == exit_status(RuntimeError("x")) == EXIT_FAILURE


# --- damaged checkpoints ---------------------------------------------------------------------


@pytest.mark.parametrize("damage", ["truncated", "zero-filled", "random"])
@pytest.mark.parametrize("command", ["evaluate", "generate"])
def test_a_damaged_checkpoint_is_reported_as_damaged(work, damage, command, capsys):
    root, data, feats, model, coll = work
    good = model.read_bytes()
    bad = root / f"{damage}.pt"
    bad.write_bytes({"truncated": good[: len(good) // 2], "zero-filled": bytes(len(good)),
                     "random": np.random.default_rng(0).bytes(len(good))}[damage])
    argv = ([command, str(bad), str(data)] if command == "evaluate"
            else [command, str(bad), "-n", "2", "-o", str(root / "never.npz")])
    capsys.readouterr()
    assert main(argv) == EXIT_USAGE
    err = capsys.readouterr().err
    assert re.search(r"damaged|corrupted|truncated", err), err
    assert not re.search(r"weights.only", err, re.IGNORECASE), err  # never advise unsafe loading
    assert err.startswith(f"meshvae {command}: error: {bad}") and len(err.strip().splitlines()) == 1


# --- the parsers -------------------------------------------------------------------------------


def _sub_parsers():
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return sub.choices


def test_every_choices_list_is_a_library_constant():
    from meshvae_lib.model.feature_kinds import FEATURE_KINDS
    from meshvae_lib.model.inference import INFERENCE_METHODS
    from meshvae_lib.model.networks import ARCHITECTURE_NAMES

    constants = [v for k, v in vars(defaults).items() if k.isupper() and isinstance(v, tuple)]
    constants += [FEATURE_KINDS, INFERENCE_METHODS, ARCHITECTURE_NAMES]  # the registries' names
    seen = 0
    for name, p in _sub_parsers().items():
        for action in p._actions:
            if action.choices is not None:
                assert any(action.choices is c for c in constants), (name, action.dest, action.choices)
                seen += 1
    assert seen >= 7  # --layout, --method, --rotations, --features, --init, --prior-form, --inference


# --- the mesh resolver -------------------------------------------------------------------------


def test_resolve_mesh_by_index_name_and_file(tmp_path):
    coll = _strips(n=4)
    assert resolve_mesh("1", coll, "--reference").index == 1
    last = resolve_mesh("-1", coll, "--reference")
    assert last.index == 3 and last.name == "s03" and last.describe() == "mesh 's03' (index 3)"
    assert resolve_mesh("s02", coll, "--reference").index == 2
    path = write_mesh(tmp_path / "pose.obj", coll.vertices[2], coll.faces)
    for collection in (coll, None):
        chosen = resolve_mesh(str(path), collection, "A", faces=coll.faces, n_vertices=coll.n_vertices)
        np.testing.assert_allclose(chosen.vertices, coll.vertices[2])
        assert chosen.index is None and chosen.name == "pose" and chosen.describe() == "file pose.obj"
    with pytest.raises(UsageError, match=r"--reference 4 is out of range for 4 meshes"):
        resolve_mesh("4", coll, "--reference")
    with pytest.raises(UsageError, match=r"'nobody' is neither an index"):
        resolve_mesh("nobody", coll, "--reference")
    with pytest.raises(UsageError, match=r"A '0' is not a mesh file \(give --data\)"):
        resolve_mesh("0", None, "A", hint=" (give --data)")
    other = _strips(n=1, nx=6)
    wrong = write_mesh(tmp_path / "other.obj", other.vertices[0], other.faces)
    with pytest.raises(UsageError, match=r"connectivity \(18 vertices, 20 faces\) differs from the model's"):
        resolve_mesh(str(wrong), None, "B", faces=coll.faces, n_vertices=coll.n_vertices, owner="the model's")
