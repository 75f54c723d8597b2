"""The pipeline drawing of notebook 00 (the paper's Fig. 1): every step a box, joined in order."""

import matplotlib
import pytest
from matplotlib.patches import FancyArrowPatch, FancyBboxPatch

from meshvae_lib.viewing.pipeline_diagram import DECODER_SIDE, ENCODER_SIDE, PIPELINE_STEPS, pipeline_diagram

matplotlib.use("Agg")


def test_one_box_per_step_and_one_arrow_between_consecutive_steps():
    fig = pipeline_diagram()
    ax = fig.axes[0]
    boxes = [p for p in ax.patches if isinstance(p, FancyBboxPatch)]
    arrows = [p for p in ax.patches if isinstance(p, FancyArrowPatch)]
    assert [b.get_gid() for b in boxes] == [f"step-{k}" for k in range(len(PIPELINE_STEPS))]
    assert len(arrows) == len(PIPELINE_STEPS) - 1
    texts = [t.get_text() for t in ax.texts]
    for step in PIPELINE_STEPS:
        assert step.title in texts and step.paper in texts and step.module in texts
    for eq in ("Eq. (1)", "Eq. (2)", "Eq. (3)", "Eq. (4)"):
        assert eq in texts
    # the encoder side runs along the top row, the decoder side back along the bottom row
    ys = {b.get_gid(): b.get_y() for b in boxes}
    assert len({ys[f"step-{k}"] for k in range(len(ENCODER_SIDE))}) == 1
    assert ys["step-0"] > ys[f"step-{len(PIPELINE_STEPS) - 1}"]
    xs = [b.get_x() for b in boxes]
    assert xs[:len(ENCODER_SIDE)] == sorted(xs[:len(ENCODER_SIDE)])
    assert xs[-len(DECODER_SIDE):] == sorted(xs[-len(DECODER_SIDE):], reverse=True)


def test_every_text_is_readable_at_the_saved_size():
    fig = pipeline_diagram()
    assert min(t.get_fontsize() for t in fig.axes[0].texts) >= 9
    with pytest.raises(ValueError, match="at least 9 points"):
        pipeline_diagram(fontsize=7)


def test_the_notebooks_named_for_collection_io_are_those_that_read_collections():
    from pathlib import Path

    notebooks = Path(__file__).resolve().parents[1] / "notebooks"
    readers = {p.name[:2] for p in notebooks.glob("[0-9][0-9]_*.ipynb")
               if "read_collection" in p.read_text() or "collection_io" in p.read_text()}
    first = ENCODER_SIDE[0]
    assert "collection_io" in first.module
    assert {s.strip() for s in first.notebook.split(",")} - {"00"} == readers   # 00 shows data_synth
