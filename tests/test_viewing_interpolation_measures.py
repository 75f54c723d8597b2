"""The measures of notebook 05's interpolations, drawn step by step."""

import matplotlib
import numpy as np
import pytest

from meshvae_lib.viewing.interpolation_measures import interpolation_measures_figure

matplotlib.use("Agg")

T = np.linspace(0, 1, 5)
EDGE = {"latent": np.array([0, .02, .03, .02, 0]), "rimd": np.array([0, .02, .03, .02, 0]),
        "coords": np.array([0, .05, .07, .05, 0])}
CROSS = {"latent": np.array([8, 8, 7, 7, 7]), "rimd": np.array([8, 8, 7, 7, 7]), "coords": np.array([8, 8, 9, 7, 7])}


def test_one_line_per_method_the_end_line_and_the_highlight():
    import matplotlib.pyplot as plt

    fig = interpolation_measures_figure(T, EDGE, CROSS, end_counts=(8, 7), highlight="latent")
    left, right = fig.axes
    assert [l.get_label() for l in left.get_lines()] == list(EDGE)
    assert [t.get_text() for t in left.get_legend().get_texts()] == list(EDGE)
    assert len(right.get_lines()) == len(CROSS) + 1                       # the dotted line of the ends
    end = right.get_lines()[-1]
    assert end.get_linestyle() == ":" and np.allclose(end.get_ydata(), 8)
    assert any("end meshes: 8, 7" in t.get_text() for t in right.texts)
    latent = left.get_lines()[0]
    assert latent.get_linestyle() == "--" and latent.get_marker() == "s" and latent.get_zorder() > left.get_lines()[1].get_zorder()
    assert left.get_ylim()[0] == 0 and right.get_ylim()[0] == 0 and right.get_ylim()[1] > 9
    assert left.get_ylabel() == "edge-length distortion" and right.get_ylabel() == "crossing triangle pairs"
    assert min(left.xaxis.label.get_fontsize(), right.title.get_fontsize()) >= 9
    plt.close(fig)


def test_mismatched_inputs_are_refused():
    with pytest.raises(ValueError, match="same methods"):
        interpolation_measures_figure(T, EDGE, {"latent": CROSS["latent"]})
    with pytest.raises(ValueError, match="one value per step"):
        interpolation_measures_figure(T[:3], EDGE, CROSS)
