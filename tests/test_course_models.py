"""The course models' registry and cache (meshvae_lib.course.models)."""

from __future__ import annotations

import dataclasses
import logging
from pathlib import Path

import numpy as np
import pytest

from meshvae_lib.course import models as cm
from meshvae_lib.course.commands import main
from meshvae_lib.model.train_config import TrainConfig

NOTEBOOKS = Path(__file__).resolve().parents[1] / "notebooks"

TINY = cm.CourseModelSpec(name="tiny-bar", lesson="test", collection="bar", resolution=300, description="a test model",
                          minutes=0.1, config={"epochs": 3, "latent_dim": 4, "batch_size": 16, "seed": 0})


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv(cm.CACHE_ENV, str(tmp_path / "cache"))
    monkeypatch.setitem(cm.COURSE_MODELS, TINY.name, TINY)
    return tmp_path / "cache"


def test_cache_dir_follows_the_environment(tmp_path, monkeypatch):
    monkeypatch.setenv(cm.CACHE_ENV, str(tmp_path / "a"))
    assert cm.cache_dir() == tmp_path / "a"
    monkeypatch.delenv(cm.CACHE_ENV)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert cm.cache_dir() == tmp_path / "xdg" / "meshvae"
    monkeypatch.delenv("XDG_CACHE_HOME")
    assert cm.cache_dir() == Path.home() / ".cache" / "meshvae"


def test_every_registered_model_is_well_formed():
    assert cm.COURSE_MODELS, "the course has models"
    for name, spec in cm.COURSE_MODELS.items():
        assert spec.name == name
        assert (NOTEBOOKS / f"{spec.lesson}.ipynb").is_file(), spec.lesson
        assert isinstance(spec.train_config(), TrainConfig)  # every config key is a TrainConfig field
        # the sizes: bodies shown in detail (05, 08) at >= 2,000 vertices, the rest >= 1,500
        n_vertices = spec.make_collection().vertices.shape[1]
        assert n_vertices >= (2000 if spec.lesson.startswith(("05", "08")) else 1500), (name, n_vertices)
    with pytest.raises(ValueError, match="generation-body"):
        cm.get_spec("no-such-model")


def test_every_model_is_used_by_its_lesson_and_lessons_05_to_08_use_course_models():
    import re

    sources = {nb.stem: nb.read_text() for nb in NOTEBOOKS.glob("[0-9][0-9]_*.ipynb")}
    for name, spec in cm.COURSE_MODELS.items():
        prefix = name.rsplit("-", 1)[0]
        used = f'\\"{name}\\"' in sources[spec.lesson] or (   # the name as a string in the lesson's code
            name.rsplit("-", 1)[-1].isdigit() and f'course_model(f\\"{prefix}-{{' in sources[spec.lesson])
        assert used, f"{name} is registered for {spec.lesson}, which does not load it"
    for lesson, text in sources.items():
        if lesson[:2] in ("05", "06", "07", "08"):
            assert "course_model(" in text, lesson
            # a mesh VAE built or trained in the lesson (a PCA floor's .fit, e.g. WhitenedPCA, is no training)
            assert not re.search(r"MeshVAEModel\(|train_vae\(|build_model\(", text), f"{lesson} trains a model instead of loading one"


def test_the_key_changes_with_anything_that_determines_the_model(monkeypatch):
    key = cm.model_key(TINY)
    assert key == cm.model_key(dataclasses.replace(TINY)) and len(key) == 64
    assert cm.model_key(dataclasses.replace(TINY, description="other words", minutes=5)) == key
    for change in ({"resolution": 400}, {"data_seed": 1}, {"features": "coords"}, {"holdout_every": 4},
                   {"config": {**TINY.config, "epochs": 4}}, {"config": {**TINY.config, "lr": 1e-4}}):
        assert cm.model_key(dataclasses.replace(TINY, **change)) != key, change
    monkeypatch.setattr(cm, "code_fingerprint", lambda: "other code")
    assert cm.model_key(TINY) != key


def _copy_of_the_code(tmp_path) -> dict:
    """A copy of meshvae_lib and data_synth to edit: package name -> folder."""
    import shutil

    import data_synth
    import meshvae_lib

    roots = {}
    for package in (meshvae_lib, data_synth):
        dest = tmp_path / package.__name__
        shutil.copytree(Path(package.__file__).parent, dest, ignore=shutil.ignore_patterns("__pycache__"))
        roots[package.__name__] = dest
    return roots


def test_the_code_in_the_key_is_the_import_closure_of_training(tmp_path):
    from meshvae_lib.course.closure import import_closure

    roots = _copy_of_the_code(tmp_path)
    closure = import_closure(cm.TRAINING_ENTRY_POINTS, roots)
    # what training imports, the registries' modules (imported by name) included
    for module in ("meshvae_lib.model.training", "meshvae_lib.model.vae", "meshvae_lib.geometry.rimd",
                   "meshvae_lib.model.feature_kinds.rimd", "meshvae_lib.model.feature_kinds.coords",
                   "meshvae_lib.geometry.reconstruction", "data_synth.bodies", "meshvae_lib.validation"):
        assert module in closure, module
    # and nothing that only uses a model
    for module in ("meshvae_lib.viewing.render", "meshvae_lib.paper.protocol", "meshvae_lib.applications.generation",
                   "meshvae_lib.geometry.intersections", "meshvae_lib.model.evaluation", "meshvae_lib.cli"):
        assert module not in closure, module
    before = cm.code_fingerprint(roots)
    assert before == cm.code_fingerprint(roots) and len(before) == 64
    for unrelated in ("meshvae_lib/viewing/render.py", "meshvae_lib/paper/features.py",
                      "meshvae_lib/geometry/intersections.py", "meshvae_lib/model/evaluation.py"):
        path = tmp_path / unrelated
        path.write_text(path.read_text() + "\nPROBE = 1\n")
        assert cm.code_fingerprint(roots) == before, f"editing {unrelated} changed the key"
    for related in ("meshvae_lib/geometry/topology.py", "meshvae_lib/model/feature_kinds/rimd.py",
                    "data_synth/skinning.py"):
        path = tmp_path / related
        original = path.read_text()
        path.write_text(original + "\nPROBE = 1\n")
        assert cm.code_fingerprint(roots) != before, f"editing {related} kept the key"
        path.write_text(original)
    assert cm.code_fingerprint(roots) == cm.code_fingerprint()  # the copy is the installed code


def test_code_fingerprint_ignores_comments_and_docstrings_not_code():
    from meshvae_lib.course.closure import code_without_docstrings

    src = '"""Doc."""\nX = 1  # a comment\n\ndef f(a):\n    """What f does."""\n    return a + X\n'
    same = '"""Other doc."""\n# new comment\nX = 1\n\ndef f(a):\n    return a + X  # still the same code\n'
    other = '"""Doc."""\nX = 2\n\ndef f(a):\n    """What f does."""\n    return a + X\n'
    assert code_without_docstrings(src) == code_without_docstrings(same)
    assert code_without_docstrings(src) != code_without_docstrings(other)
    only_doc = 'def g():\n    """Only a docstring."""\n'
    assert "Pass" in code_without_docstrings(only_doc)   # still a valid tree


def test_course_model_builds_once_then_loads(cache, monkeypatch):
    assert not cm.is_cached(TINY.name)
    first = cm.course_model(TINY.name, progress=False)
    path = cm.cache_path(TINY.name)
    assert path.is_file() and path.parent == cache and cm.is_cached(TINY.name)

    def no_training(*a, **k):
        raise AssertionError("a cached model must not be trained again")

    monkeypatch.setattr(cm, "build_model", no_training)
    again = cm.course_model(TINY.name, progress=False)
    z = np.random.default_rng(0).standard_normal((3, 4))
    np.testing.assert_array_equal(first.decode_latent(z), again.decode_latent(z))
    np.testing.assert_array_equal(first.holdout_mask_, again.holdout_mask_)


@pytest.mark.parametrize("damage", ["truncate", "zeros", "edited"])
def test_a_damaged_entry_is_rebuilt_not_loaded(cache, caplog, damage):
    import torch

    model = cm.course_model(TINY.name, progress=False)
    path = cm.cache_path(TINY.name)
    data = path.read_bytes()
    if damage == "edited":  # a whole archive whose normaliser was scaled: its digest no longer matches
        payload = torch.load(path, weights_only=True)
        payload["normalizer"]["max"] = payload["normalizer"]["max"] * 1.5
        torch.save(payload, path)
    else:
        path.write_bytes(data[: len(data) // 2] if damage == "truncate" else bytes(len(data)))
    with caplog.at_level(logging.WARNING, logger=cm.__name__):
        rebuilt = cm.course_model(TINY.name, progress=False)
    assert "damaged" in caplog.text
    z = np.zeros((1, 4))
    np.testing.assert_array_equal(model.decode_latent(z), rebuilt.decode_latent(z))  # training is seeded
    assert cm.course_model(TINY.name, progress=False) is not None and path.read_bytes()[:4] == b"PK\x03\x04"


def test_a_stale_entry_is_replaced(cache, monkeypatch):
    cm.course_model(TINY.name, progress=False)
    old = cm.cache_path(TINY.name)
    unrelated = cache / "tiny-bar-extra-0123456789abcdef0123.pt"  # another model's name, not an old key
    unrelated.write_bytes(b"x")
    monkeypatch.setattr(cm, "code_fingerprint", lambda: "the library changed")
    new = cm.cache_path(TINY.name)
    assert new != old and not cm.is_cached(TINY.name)
    cm.course_model(TINY.name, progress=False)
    assert new.is_file() and not old.exists() and unrelated.exists()


def test_models_command_lists_and_builds(cache, capsys):
    assert main(["models", "--list", TINY.name]) == 0
    out = capsys.readouterr().out
    assert "tiny-bar" in out and "missing" in out and str(cache) in out
    assert main(["models", TINY.name, "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "tiny-bar: built in" in out and "1 course model(s) ready" in out
    assert main(["models", TINY.name, "--no-progress"]) == 0
    assert "tiny-bar: cached" in capsys.readouterr().out
    assert main(["models", "nope"]) == 1
    assert "unknown course model" in capsys.readouterr().err
