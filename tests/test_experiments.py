"""The paper's experiments (Tables 1, 2, 3, the loss comparison, Sec. 5.2-5.5) on tiny collections.

Each experiment runs end to end on a 40-mesh bent ellipsoid with shape and motion labels, with a
few epochs: the tests check the tables' structure, that the numbers are real (finite, positive,
consistent with the library functions they come from) and that a seed reproduces them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pytest

from meshvae_lib import paper
from meshvae_lib import tolerances as tol
from meshvae_lib.paper import protocol
from meshvae_lib.paper.linear_floor import FLOOR_COLUMNS, NOT_INFORMATIVE, linear_floor
from meshvae_lib.paper.robustness import density_resolutions


@dataclass
class _Collection:
    vertices: np.ndarray
    faces: np.ndarray
    labels: dict = field(default_factory=dict)
    names: list = field(default_factory=list)
    name: str = "ellipsoids"


def _bend(V, a):
    th = a * V[:, 1]
    return np.column_stack([V[:, 0] * np.cos(th) - V[:, 1] * np.sin(th),
                            V[:, 0] * np.sin(th) + V[:, 1] * np.cos(th), V[:, 2]])


def _make(resolution=None):
    import trimesh

    m = trimesh.creation.icosphere(subdivisions=1 if (resolution or 0) < 100 else 2)
    V0 = np.asarray(m.vertices) * [0.3, 1.0, 0.3]
    Vs, shape, motion = [], [], []
    for s in range(4):
        for k in range(10):
            W = V0 * [1 + 0.2 * s, 1, 1 + 0.1 * s]
            Vs.append(_bend(W, 0.8 * np.sin(k / 10 * 2 * np.pi)))
            shape.append(f"s{s}")
            motion.append(f"m{k % 3}")
    return _Collection(np.array(Vs), np.asarray(m.faces, dtype=np.int64),
                       {"shape": np.array(shape), "motion": np.array(motion)})


SETTINGS = paper.ExperimentSettings(resolution=None, max_meshes=None, train_steps=8, min_epochs=3, max_epochs=4,
                                   batch_size=8, latent_dim=8, holdout_every=5, seed=0, embedding_steps=10)


@pytest.fixture(scope="module")
def coll():
    return _make()


@pytest.fixture(scope="module")
def cache():
    return {}


def _finite_positive(xs):
    xs = np.asarray(xs, dtype=float)
    return bool(np.all(np.isfinite(xs)) and np.all(xs > 0))


def test_settings_epochs_and_quick():
    s = paper.ExperimentSettings(train_steps=600, batch_size=32, min_epochs=20, max_epochs=600)
    assert s.epochs_for(120) == 160  # ceil(600 * 32 / 120)
    assert s.epochs_for(10_000) == 20 and s.epochs_for(1) == 600
    q = paper.ExperimentSettings.quick()
    assert q.train_steps < s.train_steps and q.max_meshes <= 40


def test_load_collection_thins_evenly(coll):
    s = paper.ExperimentSettings(max_meshes=7)
    d = paper.load_collection(coll, s)
    idx = np.round(np.linspace(0, 39, 7)).astype(int)
    np.testing.assert_array_equal(d.vertices, coll.vertices[idx])
    np.testing.assert_array_equal(d.labels["shape"], coll.labels["shape"][idx])
    with pytest.raises(ValueError, match="expected a collection"):
        paper.load_collection(3.5, s)


def test_latent_size_table(coll, cache):
    t = paper.latent_size_table([coll], latent_dims=(2, 8), settings=SETTINGS, cache=cache)
    assert t.columns == ["collection [N]", "ours D=2", "ours D=8", *FLOOR_COLUMNS, "paper D=2", "paper D=8"]
    assert len(t.rows) == 1 and t.rows[0][0] == "ellipsoids [40]"
    errs = t.data["errors"]["ellipsoids"]
    assert len(errs) == 2 and _finite_positive(errs)
    # the numbers are the held-out errors of the cached models
    from meshvae_lib.model.evaluation import evaluate_model

    d = paper.load_collection(coll, SETTINGS, cache=cache)
    model = protocol.train_model(d, SETTINGS, cache, latent_dim=8)
    assert evaluate_model(model, d, held_out_only=True, inference="encoder")["mean_vertex_error"] == pytest.approx(errs[1], rel=1e-12)
    md = t.to_markdown()
    assert "| ellipsoids [40] |" in md and md.count("\n|") >= 3
    assert t.plot().axes


def test_latent_size_table_is_deterministic(coll):
    s = dataclasses_replace(SETTINGS, max_epochs=3)
    a = paper.latent_size_table([coll], latent_dims=(4,), settings=s)
    b = paper.latent_size_table([coll], latent_dims=(4,), settings=s)
    assert a.data["errors"] == b.data["errors"]


def dataclasses_replace(obj, **kw):
    import dataclasses

    return dataclasses.replace(obj, **kw)


def test_feature_table(coll, cache):
    t = paper.feature_table([coll], settings=SETTINGS, cache=cache)
    errs = t.data["errors"]["ellipsoids"]
    assert set(errs) == {"coords", "aligned", "rimd"} and _finite_positive(list(errs.values()))
    row = t.as_dicts()[0]
    assert row["RIMD vs coords"] == f"{100 * (1 - errs['rimd'] / errs['coords']):.0f}%"
    assert row["paper rimd"] is None  # no paper number for this collection
    # the linear floor: PCA on the same split, with the same error, in the row and in data
    from meshvae_lib.model.evaluation import pca_baseline
    from meshvae_lib.model.training import holdout_mask

    d = paper.load_collection(coll, SETTINGS, cache=cache)
    held = holdout_mask(len(d.vertices), SETTINGS.holdout_every)
    pca = pca_baseline(d.vertices[~held], d.vertices[held])
    assert row["PCA coords"] == pytest.approx(pca["mean_vertex_error"], rel=1e-12)
    assert t.data["linear_floor"]["ellipsoids"] == linear_floor(d.vertices, SETTINGS.holdout_every)
    assert row["informative"] == ("yes" if row["floor / diagonal"] >= tol.LINEAR_DATA_RTOL else NOT_INFORMATIVE)
    fig = t.plot()
    heights = [p.get_height() for p in fig.axes[0].patches]
    assert heights[-2:] == [row["PCA coords"], row["PCA aligned"]]  # the floor's bars are drawn


def test_robustness_table_reference_and_density(cache):
    t = paper.robustness_table(_make, references=(0, 4), resolutions=(50, 200), settings=SETTINGS, cache=cache)
    runs = t.data["runs"]
    assert [r["n_vertices"] for r in runs] == [42, 162, 42]
    assert runs[2]["reference"] == 3  # index 4 is held out (every 5th): moved to the previous mesh
    assert _finite_positive([r["error"] for r in runs])
    assert t.data["spread"] == pytest.approx(max(r["error"] for r in runs) - min(r["error"] for r in runs))
    first = t.as_dicts()[0]
    assert first["paper base"] == "No. 1" and first["paper error"] == pytest.approx(2.77e-4)
    # every run shows its own collection's floor (the density changes the data, the reference does not)
    assert [r["PCA coords"] for r in t.as_dicts()] == [r["linear_floor"]["pca_coords"] for r in runs]
    assert runs[0]["linear_floor"] == runs[2]["linear_floor"] != runs[1]["linear_floor"]


def test_density_resolutions_stay_inside_data_synth_limits():
    from data_synth.constants import MAX_RESOLUTION, MIN_RESOLUTION

    assert density_resolutions(400) == (400, 320, 500)  # the paper's 0.8x / 1.25x
    quick = density_resolutions(paper.ExperimentSettings.quick().resolution)
    assert quick[0] == 300 and len(set(quick)) == 3
    assert all(MIN_RESOLUTION <= r <= MAX_RESOLUTION for r in quick)
    top = density_resolutions(MAX_RESOLUTION)
    assert all(r <= MAX_RESOLUTION for r in top) and len(set(top)) == 3


def test_loss_table(coll, cache):
    t = paper.loss_table(coll, epoch_factor=2, settings=SETTINGS, cache=cache)
    assert len(t.rows) == 4 and t.column("loss")[2:] == ["PCA on coordinates (linear floor)", "PCA on aligned coordinates"]
    assert t.rows[2][-1] == t.data["linear_floor"]["pca_coords"] and t.rows[3][-1] == t.data["linear_floor"]["pca_aligned"]
    mse_epochs, bce_epochs = t.rows[0][1], t.rows[1][1]
    assert bce_epochs == 2 * mse_epochs == len(t.data["bce_history"])
    assert _finite_positive([t.data["mse_error"], t.data["bce_error"]])
    assert _finite_positive(t.data["bce_history"]) and t.rows[1][3] == min(t.data["bce_history"])
    assert t.plot().axes


def test_embedding_table(coll, cache):
    t = paper.embedding_table(coll, settings=SETTINGS, cache=cache, seeds=(0, 1, 2), hidden=(8,))
    assert t.column("method") == ["sigma_object VAE", "t-SNE", "PCA", "NPE", "sigma_object VAE, exact KL",
                                  "sigma_object VAE, alpha 1e6, no hidden layer"]
    # the VAE row is the seed with the median AUC, the spread column covers every seed
    per_seed = t.data["seed_aucs"]["sigma_object VAE"]
    assert len(per_seed) == 3 and t.rows[0][1] == pytest.approx(sorted(per_seed)[1], abs=1e-12)
    assert t.rows[0][-2] == f"{min(per_seed):.4f}-{max(per_seed):.4f}"
    assert t.data["alpha"] == 1e3 and t.data["hidden"] == (8,)
    again = paper.embedding_table(coll, settings=SETTINGS, seeds=(0, 1, 2), hidden=(8,), compare_exact=False,
                                 compare_paper_defaults=False)
    assert again.data["seed_aucs"]["sigma_object VAE"] == per_seed  # seeded: the same numbers without the cache
    aucs = np.array(t.column("AUC (mean)"), dtype=float)
    assert np.all((aucs > 0) & (aucs <= 1))
    # the table's number is the retrieval AUC of the stored embedding
    from meshvae_lib.applications.retrieval import retrieval_auc

    Y = t.data["embeddings"]["PCA"]
    assert retrieval_auc(Y, t.data["labels"]) == pytest.approx(aucs[2], abs=1e-12)
    assert t.data["embeddings"]["NPE"].shape == (40, 2)
    assert t.rows[0][-1] == pytest.approx(0.5168)
    assert t.data["ours_minus"]["PCA"] == pytest.approx(aucs[0] - aucs[2], abs=1e-12)
    assert t.plot().axes


def test_generation_table(coll, cache):
    t = paper.generation_table(coll, n=4, conditional_collection=coll, condition_column="shape",
                              settings=SETTINGS, cache=cache)
    assert len(t.rows) == 3
    res = t.data["unconditional"]
    assert res.vertices.shape == (4, 42, 3)
    assert t.rows[0][2] == pytest.approx(float(np.median(res.distance)))
    match = t.rows[2][6]
    assert 0.0 <= match <= 1.0


def test_interpolation_table(coll, cache):
    t = paper.interpolation_table(coll, n_steps=4, settings=SETTINGS, cache=cache)
    assert t.column("method") == ["latent (ours)", "linear RIMD", "linear coordinates", "latent, generated ends"]
    seqs = t.data["sequences"]
    a, b = t.data["pair"]
    np.testing.assert_allclose(seqs["linear coordinates"][0], coll.vertices[a], atol=1e-12)
    assert all(s.shape == (4, 42, 3) for s in seqs.values())
    assert all(isinstance(r[1], int) and r[3] >= 0 for r in t.rows)


def test_the_experiments_network_floors_the_deviation_and_train_checks_the_prior_form(coll, cache):
    import torch

    d = paper.load_collection(coll, SETTINGS, cache=cache)
    net = protocol.train_model(d, SETTINGS, cache).network
    assert type(net).__name__ == "MeshVAE" and net.sigma_floor == tol.SIGMA_FLOOR and net.output == "tanh"
    _, s = net.encode(torch.full((2, net.n_features), -1e4))
    assert torch.all(s >= tol.SIGMA_FLOOR)  # the deviation the KL sees is never 0
    with pytest.raises(ValueError, match="prior_form"):
        protocol.train_model(paper.load_collection(_make(), SETTINGS), SETTINGS, None, sigma_object=(0.1,), prior="x")


def test_the_model_cache_is_keyed_by_the_collections_content():
    """Equal collections share a model; other data never gets it, whatever the objects' ids."""
    cache = {}
    a = _make()
    m = protocol.train_model(paper.load_collection(a, SETTINGS, cache=cache), SETTINGS, cache)
    twin = _Collection(a.vertices.copy(), a.faces.copy(), {k: v.copy() for k, v in a.labels.items()})
    assert protocol.train_model(paper.load_collection(twin, SETTINGS, cache=cache), SETTINGS, cache) is m
    del a, twin
    other = _make()
    other.vertices = other.vertices * 1.1  # a new object, perhaps at a freed one's address: other data
    d = paper.load_collection(other, SETTINGS, cache=cache)
    m2 = protocol.train_model(d, SETTINGS, cache)
    fingerprint = paper.collection_fingerprint
    assert m2 is not m and fingerprint(d) != fingerprint(paper.load_collection(_make(), SETTINGS))
    relabelled = _make()
    relabelled.labels["shape"] = relabelled.labels["shape"][::-1].copy()
    assert fingerprint(paper.load_collection(relabelled, SETTINGS)) != fingerprint(paper.load_collection(_make(), SETTINGS))
    # a callable entry is made once and kept alive by its cache entry (its id cannot be reused)
    made = []
    make = lambda res: made.append(res) or _make(res)  # noqa: E731
    first = paper.load_collection(make, SETTINGS, cache=cache)
    assert paper.load_collection(make, SETTINGS, cache=cache) is first and len(made) == 1
    assert any(v[0] is make for v in cache.values() if isinstance(v, tuple))


def test_plots_show_what_the_tables_print(coll, cache):
    """Table 1's figure: the absolute errors the table prints, on a log axis; the bar plots read the
    rows, so a table read back from results.json (no data) plots too."""
    t = paper.latent_size_table([coll], latent_dims=(2, 8), settings=SETTINGS, cache=cache)
    ax = t.plot().axes[0]
    assert ax.get_ylabel() == "held-out per-vertex error (mesh units)" and ax.get_yscale() == "log"
    line, floor = ax.get_lines()
    np.testing.assert_array_equal(line.get_ydata(), t.rows[0][1:3])
    assert list(floor.get_ydata()) == [t.as_dicts()[0]["PCA coords"]] * 2 and floor.get_linestyle() == "--"
    bare = paper.ExperimentTable(t.name, t.title, t.columns, t.rows)
    assert bare.plot().axes[0].get_lines()[0].get_ydata().tolist() == t.rows[0][1:3]
    t3 = paper.ExperimentTable("table3_robustness", "t3", ["base mesh", "points", "error", "paper error"],
                               [["No. 1", 42, 1e-3, 2.77e-4], ["No. 4", 42, 2e-3, None]])
    ax3 = t3.plot().axes[0]
    assert ax3.get_ylabel() == "held-out per-vertex error (mesh units)"
    assert [p.get_height() for p in ax3.patches[:2]] == [1e-3, 2e-3]
    with pytest.raises(ValueError, match="no plot"):
        paper.ExperimentTable("nope", "t", ["a"]).plot()


RESULTS = __import__("pathlib").Path(__file__).resolve().parents[1] / "docs" / "results" / "results.json"


def test_the_committed_full_results_are_current():
    """docs/results holds a full `make experiments` run (notebook 09 shows it). When the experiments'
    definitions (any module of meshvae_lib/paper, or the default settings) change, it is stale: rerun
    `make experiments` and commit docs/results."""
    res = paper.read_results(RESULTS)
    assert res.provenance["preset"] == "full" and res.settings == paper.ExperimentSettings()
    assert res.is_current(), "the experiments changed after docs/results was recorded: run `make experiments`"
    assert {"table1", "table2", "table3", "loss"} <= set(res.tables)
    for key in ("commit", "versions", "machine"):
        assert res.provenance.get(key), key


def test_definition_fingerprint_and_read_results(tmp_path):
    import json

    s = paper.ExperimentSettings()
    fp = paper.definition_fingerprint(s)
    assert fp == paper.definition_fingerprint(paper.ExperimentSettings()) and len(fp) == 64
    assert paper.definition_fingerprint(paper.ExperimentSettings(train_steps=301)) != fp
    # it covers the source of every module of meshvae_lib/paper, by relative path in sorted order
    import dataclasses
    import hashlib
    from pathlib import Path

    root = Path(paper.__file__).parent
    rels = sorted(p.relative_to(root).as_posix() for p in root.rglob("*.py"))
    assert {"__init__.py", "settings.py", "tables.py", "protocol.py", "plots.py", "loss.py"} <= set(rels)
    h = hashlib.sha256()
    for rel in rels:
        h.update(f"{rel}\0".encode() + (root / rel).read_bytes())
    h.update(json.dumps(dataclasses.asdict(s), sort_keys=True).encode())
    assert fp == h.hexdigest()
    table = {"name": "table1", "title": "t", "columns": ["a", "b"], "rows": [["x", 1.5]], "notes": [], "seconds": 2.0}
    raw = {"settings": __import__("dataclasses").asdict(s), "seconds": 3.0, "done": True, "failed": [],
           "tables": {"table1": table}, "provenance": {"definition_fingerprint": fp}}
    path = tmp_path / "results.json"
    path.write_text(json.dumps(raw))
    res = paper.read_results(path)
    assert res.is_current() and res.tables["table1"].as_dicts() == [{"a": "x", "b": 1.5}]
    path.write_text(json.dumps({**raw, "provenance": {"definition_fingerprint": "0" * 64}}))
    assert not paper.read_results(path).is_current()
    path.write_text(json.dumps({**raw, "done": False}))
    with pytest.raises(ValueError, match="unfinished"):
        paper.read_results(path)
    path.write_text(json.dumps({"tables": {}}))
    with pytest.raises(ValueError, match="lacks"):
        paper.read_results(path)
    with pytest.raises(FileNotFoundError, match="make experiments"):
        paper.read_results(tmp_path / "nope.json")


def test_converged_feature_table_trains_each_model_until_its_validation_error_stops_improving(coll):
    """With ``converge`` every model's epochs come from early stopping (at most ``converge_epochs``),
    its validation curve is kept, and a curve is 'flat' only when patience, not the limit, stopped it."""
    import dataclasses

    s = dataclasses.replace(SETTINGS, converge=True, converge_epochs=40, patience=10)
    t = paper.feature_table([coll], settings=s, cache={})
    assert t.name == "table2_features_converged" and "stops improving" in t.title
    curves = t.data["validation_curves"]["ellipsoids"]
    assert set(curves) == {"coords", "aligned", "rimd"}
    for kind, c in curves.items():
        assert c["epochs"][0] == 0 and c["epochs"] == sorted(c["epochs"]) and c["epochs"][-1] <= 40
        assert len(c["val_mse"]) == len(c["epochs"]) and np.all(np.isfinite(c["val_mse"]))
        best = c["epochs"][int(np.argmin(c["val_mse"]))]
        assert c["chosen"] == best, kind  # the model is retrained for the best epoch
        assert c["flat"] == (c["epochs"][-1] - best >= 10 and c["epochs"][-1] < 40)
    assert any("trained until its validation MSE" in n for n in t.notes)
    from meshvae_lib.paper.plots import plot_validation_curves

    assert len(plot_validation_curves(t).axes) == 1 and t.plot().axes


def test_converged_tables_1_and_3_keep_a_curve_per_model(coll):
    import dataclasses

    s = dataclasses.replace(SETTINGS, converge=True, converge_epochs=30, patience=5)
    t1 = paper.latent_size_table([coll], latent_dims=(4, 8), settings=s, cache={})
    assert t1.name == "table1_latent_size_converged"
    assert set(t1.data["validation_curves"]["ellipsoids"]) == {"D=4", "D=8"}
    t3 = paper.robustness_table(_make, references=(0, 4), resolutions=(50,), settings=s, cache={})
    assert t3.name == "table3_robustness_converged" and len(t3.data["validation_curves"]) == 2
    for t in (t1, t3):
        for kinds in t.data["validation_curves"].values():
            for c in kinds.values():
                assert c["chosen"] == c["epochs"][int(np.argmin(c["val_mse"]))] and c["epochs"][-1] <= 30
        assert any("trained until its validation MSE" in n for n in t.notes) and t.plot().axes


def test_noise_diversity_table_measures_noise_and_the_floor(monkeypatch):
    """The knobs' table on a tiny SCAPE-like body: the noise column is sqrt(8/pi) x the level (the mean
    length of a 3D Gaussian step), the ratios are the errors over PCA's, PCA's error grows with the
    noise on the held-out meshes, and levels out of range are refused with their value."""
    s = paper.ExperimentSettings.quick(max_meshes=20, train_steps=4, min_epochs=2, max_epochs=2, latent_dim=4)
    t = paper.noise_diversity_table(diversities=(1.0,), noise_levels=(0.0, 3e-3), settings=s, cache={})
    rows = t.as_dicts()
    assert [(r["diversity"], r["noise"]) for r in rows] == [(1.0, 0.0), (1.0, 3e-3)]
    for r in rows:
        assert r["noise / diagonal"] == pytest.approx(np.sqrt(8 / np.pi) * r["noise"], rel=1e-12)
        assert r["rimd / PCA"] == pytest.approx(r["ours rimd"] / r["PCA coords"], rel=1e-12)
        assert r["coords / PCA"] == pytest.approx(r["ours coords"] / r["PCA coords"], rel=1e-12)
        assert _finite_positive([r["ours coords"], r["ours rimd"], r["ours rimd, Gauss-Newton"]])
    assert rows[1]["PCA coords"] > rows[0]["PCA coords"]
    with pytest.raises(ValueError, match="noise levels must lie in \\[0, 0.1\\), got -0.1"):
        paper.noise_diversity_table(noise_levels=(-0.1,), settings=s)
    with pytest.raises(ValueError, match="diversities must lie in \\[0, 2\\], got 3"):
        paper.noise_diversity_table(diversities=(3,), settings=s)
