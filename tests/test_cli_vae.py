"""meshvae train / evaluate / generate / interpolate on a tiny synthetic collection."""

import json

import numpy as np
import pytest
import torch

from geometry_fixtures import strip
from meshvae_lib.cli import main
from meshvae_lib.geometry.collection import MeshCollection
from meshvae_lib.geometry.collection_io import read_collection, write_collection
from meshvae_lib.model.meshvae_model import load_model
from meshvae_lib.geometry.mesh_files import write_mesh

torch.set_num_threads(1)  # tiny models: one thread is faster on the shared 2-core machine


def _strips(n=16, nx=8, ny=3, seed=0):
    rng = np.random.default_rng(seed)
    P, F = strip(nx, ny, length=2.0, width=0.5)
    Vs = []
    for k in range(n):
        V = P.copy()
        V[:, 2] = rng.uniform(-0.4, 0.4) * P[:, 0] ** 2 + rng.uniform(-0.3, 0.3) * P[:, 0] * P[:, 1]
        Vs.append(V)
    labels = {"pose": np.array(["a" if k % 2 else "b" for k in range(n)]), "weight": np.linspace(0, 1, n)}
    return MeshCollection(np.array(Vs), np.array(F), names=[f"s{k:02d}" for k in range(n)], labels=labels)


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    root = tmp_path_factory.mktemp("cli")
    coll = _strips()
    path = write_collection(root / "strips.npz", coll)
    model = root / "m.pt"
    rc = main(["train", str(path), "-o", str(model), "--epochs", "8", "--latent", "4", "--holdout-every", "4",
               "--sigma-object", "0.5", "--seed", "1", "--no-progress"])
    assert rc == 0
    return root, path, model, coll


def test_train_writes_a_loadable_model(data, capsys):
    root, path, model, coll = data
    from meshvae_lib.model.meshvae_model import load_model

    m = load_model(model, read_collection(path))
    assert m.latent_dim == 4 and m.config.epochs == 8 and m.feature_kind.name == "rimd"
    np.testing.assert_array_equal(np.flatnonzero(m.holdout_mask_), [3, 7, 11, 15])
    np.testing.assert_array_equal(m.sigma_object_, [0.5, 1, 1, 1])


def test_evaluate_json_and_text(data, capsys):
    root, path, model, coll = data
    capsys.readouterr()
    assert main(["evaluate", str(model), str(path), "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["n_meshes"] == 16 and res["mean_vertex_error"] >= 0
    assert res["mean_vertex_error"] == pytest.approx(np.mean(res["per_mesh"]), rel=1e-12)
    assert main(["evaluate", str(model), str(path), "--held-out", "--json"]) == 0
    every_core = json.loads(capsys.readouterr().out)
    assert every_core["n_meshes"] == 4
    assert main(["evaluate", str(model), str(path), "--held-out", "--json", "--jobs", "1"]) == 0
    one = json.loads(capsys.readouterr().out)
    assert one["per_mesh"] == every_core["per_mesh"] and one["inference"] == "gauss-newton"   # the same codes
    assert main(["evaluate", str(model), str(path)]) == 0
    assert "mean per-vertex error" in capsys.readouterr().out


def test_generate_to_npz_and_folder(data):
    root, path, model, coll = data
    assert main(["generate", str(model), "-n", "3", "-o", str(root / "gen.npz"), "--seed", "2"]) == 0
    gen = read_collection(root / "gen.npz")
    assert gen.vertices.shape == (3, coll.n_vertices, 3)
    np.testing.assert_array_equal(gen.faces, coll.faces)
    assert main(["generate", str(model), "-n", "2", "-o", str(root / "gen_dir"), "--seed", "2"]) == 0
    objs = sorted(p.name for p in (root / "gen_dir").glob("*.obj"))
    assert len(objs) == 2
    # same seed, same meshes, in either format
    np.testing.assert_allclose(read_collection(root / "gen_dir").vertices, gen.vertices[:2], atol=1e-9)
    # a temperature: the library's draws at that temperature, not the default ones
    assert main(["generate", str(model), "-n", "3", "-o", str(root / "cool.npz"), "--seed", "2", "--temperature", "0.5"]) == 0
    cool = read_collection(root / "cool.npz").vertices
    np.testing.assert_allclose(cool, load_model(model).generate(3, seed=2, temperature=0.5), atol=1e-9)
    assert not np.allclose(cool, gen.vertices, atol=1e-6)
    for bad in ("0", "-1", "inf", "nan"):
        assert main(["generate", str(model), "-n", "1", "-o", str(root / "bad.npz"), "--temperature", bad]) == 2


def test_interpolate_indices_and_files(data):
    root, path, model, coll = data
    assert main(["interpolate", str(model), "0", "5", "--data", str(path), "--steps", "4",
                 "-o", str(root / "seq.npz")]) == 0
    seq = read_collection(root / "seq.npz")
    assert seq.vertices.shape == (4, coll.n_vertices, 3)
    write_mesh(root / "a.obj", coll.vertices[0], coll.faces)
    write_mesh(root / "b.obj", coll.vertices[5], coll.faces)
    assert main(["interpolate", str(model), str(root / "a.obj"), str(root / "b.obj"), "--steps", "4",
                 "-o", str(root / "seq2.npz")]) == 0
    np.testing.assert_allclose(read_collection(root / "seq2.npz").vertices, seq.vertices, atol=1e-6)


def test_conditional_train_and_generate(data, tmp_path):
    root, path, model, coll = data
    cmodel = tmp_path / "c.pt"
    assert main(["train", str(path), "-o", str(cmodel), "--features", "aligned", "--epochs", "3",
                 "--latent", "2", "--labels", "pose", "weight", "--no-progress"]) == 0
    assert main(["generate", str(cmodel), "-n", "2", "-o", str(tmp_path / "g.npz"),
                 "--condition", "pose=a", "--condition", "weight=0.5"]) == 0
    assert main(["interpolate", str(cmodel), "1", "2", "--data", str(path), "--steps", "3",
                 "-o", str(tmp_path / "s.npz")]) == 0


def test_user_errors_exit_2_with_a_message(data, tmp_path, capsys):
    root, path, model, coll = data
    capsys.readouterr()
    bad = tmp_path / "bad.pt"
    bad.write_bytes(b"not a checkpoint at all")
    assert main(["evaluate", str(bad), str(path)]) == 2
    assert "checkpoint" in capsys.readouterr().err
    assert main(["generate", str(model), "-n", "2", "-o", str(tmp_path / "x.npz"), "--condition", "pose=a"]) == 2
    assert "without labels" in capsys.readouterr().err
    assert main(["interpolate", str(model), "0", "99", "--data", str(path), "-o", str(tmp_path / "y.npz")]) == 2
    assert "B 99 is out of range for 16 meshes" in capsys.readouterr().err
    assert main(["interpolate", str(model), "0", "1", "-o", str(tmp_path / "y.npz")]) == 2
    assert "--data" in capsys.readouterr().err
    other = write_collection(tmp_path / "other.npz", _strips(n=3, nx=6))
    assert main(["evaluate", str(model), str(other)]) == 2
    assert "vertices" in capsys.readouterr().err
    assert main(["train", str(path), "-o", str(tmp_path / "z.pt"), "--labels", "colour", "--epochs", "1",
                 "--no-progress"]) == 2
    assert "colour" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exc:
        main(["train", str(path), "-o", str(tmp_path / "z.pt"), "--sigma-object", "0,-1"])
    assert exc.value.code == 2 and "positive numbers" in capsys.readouterr().err


def test_help_texts_describe_the_commands(capsys):
    for cmd in ("train", "evaluate", "generate", "interpolate"):
        with pytest.raises(SystemExit):
            main([cmd, "--help"])
        out = capsys.readouterr().out
        assert "examples:" in out and len(out) > 400


def test_evaluate_reports_the_pca_baseline(data, capsys):
    root, path, model, coll = data
    from meshvae_lib.model.evaluation import pca_baseline

    capsys.readouterr()
    assert main(["evaluate", str(model), str(path), "--held-out", "--pca", "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    mask = np.zeros(16, bool)
    mask[3::4] = True
    expected = pca_baseline(coll.vertices[~mask], coll.vertices[mask])
    assert res["pca"]["n_components"] == expected["n_components"] == 2  # the strips span two modes
    assert res["pca"]["mean_vertex_error"] == pytest.approx(expected["mean_vertex_error"], rel=1e-9)
    # PCA fitted on another file, evaluated on every mesh of DATA
    train = write_collection(root / "train_part.npz", MeshCollection(coll.vertices[~mask], coll.faces))
    assert main(["evaluate", str(model), str(path), "--pca", str(train), "--pca-components", "1"]) == 0
    out = capsys.readouterr().out
    assert "linear PCA on coordinates (1 components" in out and "model / PCA" in out
    # without a file, DATA must be the training collection with held-out meshes
    other = write_collection(root / "few.npz", MeshCollection(coll.vertices[:5], coll.faces))
    assert main(["evaluate", str(model), str(other), "--pca"]) == 2
    assert "--pca TRAIN" in capsys.readouterr().err


def test_evaluate_with_codes_fitted_to_the_vertices(data, capsys):
    root, path, model, coll = data
    capsys.readouterr()
    assert main(["evaluate", str(model), str(path), "--held-out", "--json", "--inference", "encoder"]) == 0
    plain = json.loads(capsys.readouterr().out)
    assert plain["inference"] == "encoder"
    assert main(["evaluate", str(model), str(path), "--held-out", "--fit-latent", "2", "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["fit_iterations"] == 2 and res["inference"] == "finite-difference"
    assert res["mean_vertex_error"] <= plain["mean_vertex_error"] + 1e-12
    # the default: Gauss-Newton from the encoder's means, never worse than them
    assert main(["evaluate", str(model), str(path), "--held-out", "--json"]) == 0
    default = json.loads(capsys.readouterr().out)
    assert default["inference"] == "gauss-newton"
    assert all(d <= p * (1 + 1e-6) + 1e-12 for d, p in zip(default["per_mesh"], plain["per_mesh"]))
    assert main(["evaluate", str(model), str(path), "--fit-latent", "2", "--inference", "encoder"]) == 2
    assert "does not combine" in capsys.readouterr().err
    # fewer Gauss-Newton steps: the same first steps, so never better per mesh; the default's count
    # gives the default's errors exactly; a chord step after each accepted one never loses
    runs = {}
    for extra in ([], ["--gn-steps", "4"], ["--gn-steps", "1"], ["--gn-steps", "1", "--chord-steps", "2"]):
        assert main(["evaluate", str(model), str(path), "--held-out", "--json", "--jobs", "1"] + extra) == 0
        runs[" ".join(extra)] = json.loads(capsys.readouterr().out)
    assert runs["--gn-steps 4"]["per_mesh"] == runs[""]["per_mesh"]
    assert runs["--gn-steps 1"]["inference_description"] == "encoder + Gauss-Newton, 1 step"
    assert runs["--gn-steps 1 --chord-steps 2"]["inference_description"] == "encoder + Gauss-Newton, 1 step (+2 chord each)"
    one, chord = runs["--gn-steps 1"]["per_mesh"], runs["--gn-steps 1 --chord-steps 2"]["per_mesh"]
    assert all(d <= o * (1 + 1e-9) for d, o in zip(runs[""]["per_mesh"], one))
    assert all(c <= o * (1 + 1e-9) for c, o in zip(chord, one))
    assert sum(one) > sum(runs[""]["per_mesh"]) * (1 + 1e-6)    # the later steps do lower the error here
    assert main(["evaluate", str(model), str(path), "--held-out", "--gn-steps", "1", "--chord-steps", "1"]) == 0
    assert "(encoder + Gauss-Newton, 1 step (+1 chord each))" in capsys.readouterr().out
    assert main(["evaluate", str(model), str(path), "--fit-latent", "-1"]) == 2
    assert "--fit-latent must be >= 0" in capsys.readouterr().err


def test_train_and_evaluate_accept_degenerate_faces_only_when_asked(tmp_path, capsys):
    coll = _strips(n=8)
    V = coll.vertices.copy()
    V[5, 1] = 0.5 * (V[5, 0] + V[5, 3])  # face 0 = [0, 3, 1] of mesh 5 collapses to a segment
    path = write_collection(tmp_path / "flat.npz", MeshCollection(V, coll.faces, names=coll.names, labels={}))
    out = tmp_path / "m.pt"
    args = ["train", str(path), "-o", str(out), "--epochs", "2", "--latent", "3", "--no-progress"]
    capsys.readouterr()
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "zero-area" in err and "--allow-degenerate" in err
    assert main(args + ["--allow-degenerate"]) == 0 and out.exists()
    assert main(["evaluate", str(out), str(path)]) == 2
    assert "zero-area" in capsys.readouterr().err
    assert main(["evaluate", str(out), str(path), "--allow-degenerate", "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["n_meshes"] == 8 and np.isfinite(res["mean_vertex_error"])


def test_train_a_spiral_network_from_the_command_line(tmp_path, capsys):
    """--architecture spiral: coordinates by default, its own epochs, evaluated by Gauss-Newton; the
    options it cannot take are refused before any data is read."""
    coll = _strips(n=10, nx=40, ny=20)                       # 800 vertices: four levels of 4 fit
    path = write_collection(tmp_path / "s.npz", coll)
    out = tmp_path / "spiral.pt"
    assert main(["train", str(path), "-o", str(out), "--architecture", "spiral", "--epochs", "2", "--latent", "2",
                 "--holdout-every", "5", "--no-progress"]) == 0
    text = capsys.readouterr()
    assert "network spiral, features coords" in text.err + text.out and "held-out per-vertex error" in text.out
    m = load_model(out, coll)
    assert type(m.network).__name__ == "SpiralVAE" and m.feature_kind.name == "coords" and m.latent_dim == 2
    assert m.config.epochs == 2 and m.config.loss == "l1"
    for bad, why in ((["--features", "rimd"], "works on --features coords or aligned"),
                     (["--hidden", "8"], "--hidden"), (["--labels", "pose"], "unconditional")):
        capsys.readouterr()
        assert main(["train", str(path), "-o", str(tmp_path / "x.pt"), "--architecture", "spiral", *bad]) == 2
        assert why in capsys.readouterr().err
    small = write_collection(tmp_path / "small.npz", _strips(n=6))
    assert main(["train", str(small), "-o", str(tmp_path / "y.pt"), "--architecture", "spiral", "--epochs", "1",
                 "--no-progress"]) == 2
    err = capsys.readouterr().err  # the remedy is an option that exists
    assert "too few for its fixed down-sampling" in err and "use --architecture mesh-vae or local-parts" in err
    # its options are flags (from its Options dataclass) and reach the network
    assert main(["train", str(path), "-o", str(tmp_path / "small.pt"), "--architecture", "spiral", "--epochs", "1",
                 "--latent", "2", "--channels", "8", "4", "--factors", "4", "4", "--spiral-length", "5",
                 "--no-progress"]) == 0
    net = load_model(tmp_path / "small.pt", coll).network
    assert (net.channels, net.spiral_length, len(net.level_sizes)) == ([8, 4], 5, 3)
    capsys.readouterr()
    assert main(["train", str(path), "-o", str(tmp_path / "z.pt"), "--channels", "8"]) == 2
    assert "--channels is the spiral network's, not mesh-vae's" in capsys.readouterr().err
    assert main(["train", str(path), "-o", str(tmp_path / "z.pt"), "--architecture", "spiral", "--spiral-length", "0"]) == 2
    assert "--spiral-length" in capsys.readouterr().err and not (tmp_path / "z.pt").exists()


def test_train_a_local_parts_network_from_the_command_line(tmp_path, capsys):
    """--architecture local-parts with --regions and --region-method; its options are refused for the
    other networks, and a latent size that does not split into the regions before any data is read."""
    coll = _strips(n=10)
    path = write_collection(tmp_path / "s.npz", coll)
    out = tmp_path / "parts.pt"
    assert main(["train", str(path), "-o", str(out), "--architecture", "local-parts", "--regions", "2", "--latent", "4",
                 "--region-method", "kmeans", "--holdout-every", "5", "--no-progress"]) == 0
    text = capsys.readouterr()
    assert "network local-parts, features rimd" in text.err + text.out and "held-out per-vertex error" in text.out
    m = load_model(out, coll)
    assert type(m.network).__name__ == "LocalPartsVAE" and m.network.n_regions == 2 and m.latent_dim == 4
    assert sorted(set(m.network.vertex_region.tolist())) == [0, 1]
    for bad, why in ((["--architecture", "local-parts", "--regions", "3", "--latent", "4"], "not a multiple of --regions 3"),
                     (["--regions", "2"], "local-parts network's"),
                     (["--architecture", "local-parts", "--regions", "0"], "--regions")):
        capsys.readouterr()
        assert main(["train", str(tmp_path / "missing.npz"), "-o", str(tmp_path / "x.pt"), *bad]) == 2
        assert why in capsys.readouterr().err
