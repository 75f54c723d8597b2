"""``meshvae synth``: --list, .npz and folder output, labels, errors as one line."""

from __future__ import annotations

import csv

import numpy as np

from data_synth import list_collections, make_collection
from meshvae_lib.cli import main


def test_list_prints_one_collection_a_line_name_first(capsys):
    assert main(["synth", "--list"]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    names = [n for n, _ in list_collections()]
    assert [line.split()[0] for line in lines] == names
    assert all(len(line.split(None, 1)) == 2 for line in lines)  # and a description


def test_writes_npz_with_labels(tmp_path, capsys):
    out = tmp_path / "bar.npz"
    assert main(["synth", "bar", "-o", str(out), "--seed", "2", "--resolution", "600"]) == 0
    assert "bar" in capsys.readouterr().out
    ref = make_collection("bar", seed=2, resolution=600)
    with np.load(out) as z:
        np.testing.assert_array_equal(z["vertices"], ref.vertices)
        np.testing.assert_array_equal(z["faces"], ref.faces)
        assert list(z["names"]) == ref.names
        for key, value in ref.labels.items():
            np.testing.assert_array_equal(z[f"label_{key}"], value)
            assert len(z[f"label_{key}"]) == len(ref.names)


def test_writes_folder_of_obj_files_and_labels_csv(tmp_path):
    out = tmp_path / "flag"
    assert main(["synth", "flag", "-o", str(out), "--resolution", "400"]) == 0
    ref = make_collection("flag", resolution=400)
    objs = sorted(out.glob("*.obj"))
    assert len(objs) == len(ref.names)
    with open(out / "labels.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == ["name", *ref.labels]
    assert len(rows) == 1 + len(ref.names)
    assert [r[1] for r in rows[1:]] == [str(v) for v in ref.labels["frame"]]
    # the first OBJ holds the first mesh's vertices and the faces (1-based)
    first = [r[0] for r in rows[1:]][0]
    lines = (out / f"{first}.obj").read_text().splitlines()
    v = np.array([[float(x) for x in ln.split()[1:4]] for ln in lines if ln.startswith("v ")])
    f = np.array([[int(x.split("/")[0]) for x in ln.split()[1:4]] for ln in lines if ln.startswith("f ")])
    np.testing.assert_allclose(v, ref.vertices[0], atol=1e-9)
    np.testing.assert_array_equal(f - 1, ref.faces)


def test_bad_input_is_one_line_error_with_exit_status_2(tmp_path, capsys):
    assert main(["synth", "nosuch", "-o", str(tmp_path / "x.npz")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "nosuch" in err and "scape" in err
    assert main(["synth", "bar"]) == 2
    assert "-o" in capsys.readouterr().err
    assert main(["synth", "bar", "-o", str(tmp_path / "x.npz"), "--resolution", "5"]) == 2
    assert "5" in capsys.readouterr().err
    assert main(["synth", "bar", "-o", str(tmp_path / "missing" / "x.npz")]) == 2
    assert "missing" in capsys.readouterr().err
    assert main(["synth", "bar", "-o", str(tmp_path / "x.npz"), "--seed", "-1"]) == 2
    assert "--seed must be non-negative" in capsys.readouterr().err


def test_noise_option_adds_capture_noise_and_rejects_negative_levels(tmp_path, capsys):
    exact, noisy = tmp_path / "exact.npz", tmp_path / "noisy.npz"
    assert main(["synth", "bar", "-o", str(exact)]) == 0
    assert main(["synth", "bar", "-o", str(noisy), "--noise", "1e-3"]) == 0
    a, b = np.load(exact)["vertices"], np.load(noisy)["vertices"]
    diag = np.linalg.norm(a.max(axis=1) - a.min(axis=1), axis=1)
    moved = np.linalg.norm(b - a, axis=2).mean(axis=1) / diag
    np.testing.assert_allclose(moved, np.sqrt(8 / np.pi) * 1e-3, rtol=0.05)
    capsys.readouterr()
    assert main(["synth", "bar", "-o", str(noisy), "--noise", "-1"]) == 2
    assert "--noise must be a finite number >= 0, got -1.0" in capsys.readouterr().err
