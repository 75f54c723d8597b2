"""Which notebooks keep their widgets' state (issue 36): only those that ask for it, and never stale state."""

from pathlib import Path

import nbformat
import pytest

from meshvae_lib.course import notebooks


class _FakeClient:
    """Stands in for nbclient's NotebookClient: records how it was asked to run, runs nothing."""

    seen: dict = {}

    def __init__(self, nb, **kw):
        _FakeClient.seen = dict(kw, metadata=dict(nb.metadata))

    def execute(self):
        return None


@pytest.fixture
def fake_client(monkeypatch):
    import nbclient

    monkeypatch.setattr(nbclient, "NotebookClient", _FakeClient)
    return _FakeClient


def _write(tmp_path, metadata):
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell("1 + 1")], metadata=metadata)
    path = tmp_path / "nb.ipynb"
    nbformat.write(nb, path)
    return path


STALE = {"application/vnd.jupyter.widget-state+json": {"state": {"old-model": {}}, "version_major": 2, "version_minor": 0}}


def test_stale_state_is_dropped_unless_the_notebook_asks_to_keep_it(tmp_path, fake_client):
    path = _write(tmp_path, {"widgets": STALE})
    nb = notebooks.execute_notebook(path)
    assert fake_client.seen["store_widget_state"] is False and "widgets" not in nb.metadata


def test_a_notebook_that_asks_stores_its_state_but_an_explicit_false_wins(tmp_path, fake_client):
    path = _write(tmp_path, {"widgets": STALE, "meshvae": {"store_widget_state": True}})
    notebooks.execute_notebook(path)
    assert fake_client.seen["store_widget_state"] is True
    nb = notebooks.execute_notebook(path, store_widget_state=False)   # the HTML course build
    assert fake_client.seen["store_widget_state"] is False and "widgets" not in nb.metadata


NOTEBOOK_DIR = Path(__file__).resolve().parents[1] / "notebooks"
NOTEBOOKS = sorted(NOTEBOOK_DIR.glob("[0-9][0-9]_*.ipynb"))
STORING = ("00_tour", "05_generation_interpolation", "08_exploration")   # notebooks whose widgets show unrun
VIEW, STATE = "application/vnd.jupyter.widget-view+json", "application/vnd.jupyter.widget-state+json"


def _shown(nb) -> list[str]:
    """The model ids the stored outputs display."""
    return [o["data"][VIEW]["model_id"] for c in nb.cells if c.cell_type == "code"
            for o in c.get("outputs", []) if VIEW in o.get("data", {})]


def _references(value) -> set[str]:
    """The model ids a widget's state refers to (``"IPY_MODEL_<id>"``, nested anywhere)."""
    if isinstance(value, str):
        return {value[len("IPY_MODEL_"):]} if value.startswith("IPY_MODEL_") else set()
    items = value.values() if isinstance(value, dict) else value if isinstance(value, list) else ()
    return set().union(*(_references(v) for v in items))


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_a_committed_notebook_stores_widget_state_exactly_when_it_asks(path):
    nb = nbformat.read(path, as_version=4)
    asks = nb.metadata.get("meshvae", {}).get("store_widget_state", False) is True
    assert asks == (path.stem in STORING), "STORING names the notebooks that ask for their widgets' state"
    assert ("widgets" in nb.metadata) == asks, "state without asking is left over from an earlier run"


@pytest.mark.parametrize("name", STORING)
def test_the_stored_state_is_complete_and_fresh(name):
    """What a page without a kernel renders: each displayed widget and everything it refers to, and
    nothing else (a model that no output leads to, and no jslink between shown widgets, is left from
    another run)."""
    nb = nbformat.read(NOTEBOOK_DIR / f"{name}.ipynb", as_version=4)
    stored = nb.metadata["widgets"][STATE]
    assert stored["version_major"] == 2
    state = stored["state"]
    shown = _shown(nb)
    assert shown and set(shown) <= set(state), "every widget an output shows is in the stored state"
    refs = {model_id: _references(w["state"]) for model_id, w in state.items()}
    assert set().union(*refs.values()) <= set(state), "every model a stored widget refers to is stored too"
    links = {m for m, w in state.items() if w["model_name"] in ("LinkModel", "DirectionalLinkModel")}
    linked = set(shown)
    while True:   # what the shown widgets refer to, and the jslinks between them (nothing refers to a link)
        more = set().union(*(refs[m] for m in linked)) | {m for m in links if refs[m] & linked}
        if more <= linked:
            break
        linked |= more
    assert linked == set(state), f"{len(set(state) - linked)} stored models belong to no output"
    assert all(w["model_name"] and w["model_module"] for w in state.values())


def test_notebook_08_stores_the_sliders_where_its_last_cell_left_them():
    """The explorer's six sliders z[0]..z[5] over [-2, 2], at the z the set_z cell prints."""
    import re

    nb = nbformat.read(NOTEBOOK_DIR / "08_exploration.ipynb", as_version=4)
    state = nb.metadata["widgets"][STATE]["state"]
    (explorer,) = _shown(nb)
    assert "meshvae-latent-explorer" in state[explorer]["state"]["_dom_classes"]
    sliders = {w["state"]["description"]: w["state"] for w in state.values() if w["model_name"] == "FloatSliderModel"}
    assert sorted(sliders) == [f"z[{d}]" for d in range(6)], sorted(sliders)
    assert all((s["min"], s["max"]) == (-2.0, 2.0) for s in sliders.values())
    (cell,) = [c for c in nb.cells if c.cell_type == "code" and "explorer.set_z(" in c.source]
    printed = re.search(r"z\[:2\] = \[([^\]]*)\]", "".join(o.get("text", "") for o in cell.outputs))
    z01 = [float(v) for v in printed.group(1).split()]
    assert [sliders["z[0]"]["value"], sliders["z[1]"]["value"]] == z01, "the sliders the set_z cell moved"
    assert all(sliders[f"z[{d}]"]["value"] == 0.0 for d in range(2, 6))
