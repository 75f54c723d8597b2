"""Which notebooks keep their widgets' state (issue 36): only those that ask for it, and never stale state."""

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


def test_notebook_00_asks_for_its_state():
    from pathlib import Path

    nb = nbformat.read(Path(__file__).resolve().parents[1] / "notebooks" / "00_tour.ipynb", as_version=4)
    assert nb.metadata["meshvae"]["store_widget_state"] is True
    state = nb.metadata["widgets"]["application/vnd.jupyter.widget-state+json"]["state"]
    shown = [o["data"]["application/vnd.jupyter.widget-view+json"]["model_id"] for c in nb.cells if c.cell_type == "code"
             for o in c.get("outputs", []) if "application/vnd.jupyter.widget-view+json" in o.get("data", {})]
    assert shown and all(model_id in state for model_id in shown), "the stored state describes the widgets the outputs show"
