"""`meshvae features` and `meshvae reconstruct` end to end."""

import numpy as np
import pytest
from geometry_fixtures import bumpy, tube, twist_bend

from meshvae_lib.geometry.alignment import bounding_box_diagonal, rigid_align
from meshvae_lib.cli import main
from meshvae_lib.geometry.collection_io import read_collection, write_collection
from meshvae_lib.geometry.mesh_files import write_mesh
from meshvae_lib.geometry.rimd import RIMDLayout
from meshvae_lib.geometry.rimd_files import load_features


@pytest.fixture
def data(tmp_path):
    V0, F = tube(8, 10)
    V0 = bumpy(V0, seed=1)
    verts = np.stack([V0, twist_bend(V0, 90, 30), twist_bend(V0, 200, 80), 1.2 * V0])
    folder = tmp_path / "poses"
    write_collection(folder, verts, F, names=["pose1", "pose2", "pose3", "pose10"],
                     labels={"pose": np.array([0, 1, 2, 3])})
    return folder, verts, F


def _errors(P, V):
    return np.linalg.norm(rigid_align(P, V) - V, axis=-1) / bounding_box_diagonal(V)[:, None]


@pytest.mark.parametrize("out_name", ["rebuilt.npz", "rebuilt_folder"])
def test_features_then_reconstruct_round_trip(tmp_path, data, out_name, capsys):
    folder, verts, F = data
    feats = tmp_path / "feats.npz"
    assert main(["features", str(folder), "-o", str(feats)]) == 0
    d = load_features(feats)
    assert d["features"].shape == (4, RIMDLayout(F, verts.shape[1]).K)
    assert d["features"].dtype == np.float64
    np.testing.assert_array_equal(d["reference"], verts[0])
    np.testing.assert_array_equal(d["faces"], F)
    assert d["names"] == ["pose1", "pose2", "pose3", "pose10"]
    assert d["labels"]["pose"].tolist() == [0, 1, 2, 3]
    assert "K = " in capsys.readouterr().out  # "wrote ..." is the command's output: stdout
    out = tmp_path / out_name
    assert main(["reconstruct", str(feats), "-o", str(out)]) == 0
    col = read_collection(out)
    assert col.names == ["pose1", "pose2", "pose3", "pose10"]
    assert col.labels["pose"].tolist() == [0, 1, 2, 3]
    assert _errors(col.vertices, verts).max() < 1e-8


def test_reference_choice_layout_and_paper_method(tmp_path, data):
    folder, verts, F = data
    feats = tmp_path / "f.npz"
    assert main(["features", str(folder), "-o", str(feats), "--reference", "pose2",
                 "--layout", "compact"]) == 0
    d = load_features(feats)
    np.testing.assert_array_equal(d["reference"], verts[1])
    assert d["layout"] == "compact"
    assert main(["features", str(folder), "-o", str(feats), "--reference", "-1"]) == 0
    np.testing.assert_array_equal(load_features(feats)["reference"], verts[3])
    ref = tmp_path / "ref.obj"
    write_mesh(ref, verts[2], F)
    assert main(["features", str(folder), "-o", str(feats), "--reference", str(ref)]) == 0
    np.testing.assert_array_equal(load_features(feats)["reference"], verts[2])
    out = tmp_path / "paper.npz"
    assert main(["reconstruct", str(feats), "-o", str(out), "--method", "paper"]) == 0
    err = _errors(read_collection(out).vertices, verts)
    assert err.mean() < 1e-2


def test_help(capsys):
    for cmd in ("features", "reconstruct"):
        with pytest.raises(SystemExit) as exc:
            main([cmd, "--help"])
        assert exc.value.code == 0
        text = capsys.readouterr().out
        assert "examples:" in text and "-o" in text


def test_bad_input_gives_one_line_errors_and_exit_status_2(tmp_path, data, capsys):
    folder, verts, F = data
    cases = [
        (["features", str(tmp_path / "missing"), "-o", str(tmp_path / "f.npz")], "no such"),
        (["features", str(folder), "-o", str(tmp_path / "f.txt")], "must be an .npz"),
        (["features", str(folder), "-o", str(tmp_path / "f.npz"), "--reference", "9"],
         "out of range"),
        (["features", str(folder), "-o", str(tmp_path / "f.npz"), "--reference", "nobody"],
         "neither an index"),
        (["reconstruct", str(tmp_path / "none.npz"), "-o", str(tmp_path / "o")],
         "no such feature file"),
    ]
    write_collection(tmp_path / "plain.npz", verts, F)
    cases.append((["reconstruct", str(tmp_path / "plain.npz"), "-o", str(tmp_path / "o")],
                  "not a feature file"))
    other = tmp_path / "other.obj"
    Vt, Ft = tube(5, 3)
    write_mesh(other, Vt, Ft)
    cases.append((["features", str(folder), "-o", str(tmp_path / "f.npz"), "--reference",
                   str(other)], "connectivity"))
    for argv, message in cases:
        assert main(argv) == 2, argv
        captured = capsys.readouterr()
        err = captured.err.strip().splitlines()
        assert message in err[-1] and err[-1].startswith(f"meshvae {argv[0]}: error: "), (argv, err)
        assert captured.out == "", argv


@pytest.mark.parametrize("argv", [["--help"], ["synth", "--list"], ["features", "--help"], ["reconstruct", "--help"],
                                  ["evaluate", "--help"], ["generate", "--help"],
                                  ["interpolate", "--help"], ["--version"]])
def test_commands_that_need_no_model_do_not_import_torch(argv):
    """Start-up time: torch's import alone takes seconds on a small machine (benchmarks/bench_cli_startup.py).
    ``train --help`` is the exception: its flags come from the registered networks' ``Options``
    (issue 48), whose modules import torch; the train parser adds them only when it parses, so the
    other commands stay without torch."""
    import subprocess
    import sys

    code = ("import sys\nfrom meshvae_lib.cli import main\ntry:\n    main(%r)\nexcept SystemExit:\n    pass\n"
            "print('TORCH', 'torch' in sys.modules)" % (argv,))
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip().splitlines()[-1] == "TORCH False", out[-500:]


def test_version(capsys):
    from meshvae_lib import __version__

    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0 and capsys.readouterr().out.strip() == f"meshvae {__version__}"


def test_features_and_reconstruct_runs_do_not_import_torch(tmp_path, data):
    """The geometry commands need no model: a real run, not only --help, stays without torch."""
    import subprocess
    import sys

    folder, verts, F = data
    feats, out = tmp_path / "f.npz", tmp_path / "r.npz"
    for argv in (["features", str(folder), "-o", str(feats)], ["reconstruct", str(feats), "-o", str(out)]):
        code = f"import sys\nfrom meshvae_lib.cli import main\nrc = main({argv!r})\nprint('TORCH', rc, 'torch' in sys.modules)"
        res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
        assert res.stdout.strip().splitlines()[-1] == "TORCH 0 False", (argv, res.stdout[-500:], res.stderr[-500:])
