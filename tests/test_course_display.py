"""meshvae_lib.course.display.first_argmax: a choice among near-ties made by a stated rule."""

import numpy as np
import pytest

from meshvae_lib.course.display import first_argmax
from meshvae_lib.tolerances import TIE_RTOL


def test_the_earliest_of_values_tied_to_the_last_bits():
    # frames 30 and 90 of notebook 00's jumping jacks: which is larger depends on the BLAS kernels
    a, b = 0.1402245850396264, 0.1402245850396265
    x = np.zeros(120)
    x[30], x[90] = a, b
    assert np.argmax(x) == 90 and first_argmax(x) == 30
    x[30], x[90] = b, a
    assert np.argmax(x) == 30 and first_argmax(x) == 30


def test_a_clear_maximum_wins_wherever_it_is():
    assert first_argmax([1.0, 3.0, 2.0]) == 1
    assert first_argmax([3.0, 3.0 * (1 - 10 * TIE_RTOL)]) == 0
    assert first_argmax([3.0 * (1 - 10 * TIE_RTOL), 3.0]) == 1      # 1e-8 apart: not a tie
    assert first_argmax([1.0, 1.0 + 1e-12], rtol=0) == 1            # rtol 0: np.argmax
    assert first_argmax([-2.0, -1.0 - 1e-12, -1.0]) == 1            # negative values: |max|
    assert first_argmax([0.0, 0.0]) == 0


def test_bad_input_says_what_is_wrong():
    with pytest.raises(ValueError, match=r"non-empty 1-D array, got shape \(0,\)"):
        first_argmax([])
    with pytest.raises(ValueError, match=r"got shape \(2, 2\)"):
        first_argmax(np.zeros((2, 2)))
    with pytest.raises(ValueError, match="finite"):
        first_argmax([1.0, np.nan])
    with pytest.raises(ValueError, match="rtol must be >= 0, got -1"):
        first_argmax([1.0], rtol=-1)


def test_real_inference_table_prints_the_recorded_rows_and_their_ratio():
    from meshvae_lib.course.display import real_inference_table

    rows = [{"collection": "a/3", "paper_path": 0.5, "encoder": 0.25, "default": 0.01, "pca_coords": 0.04,
             "pca_aligned": 0.02},
            {"collection": "b", "paper_path": None, "encoder": 1.0, "default": 3.0, "pca_coords": 1.5, "pca_aligned": 4.0}]
    lines = real_inference_table(rows).splitlines()
    assert len(lines) == 3 and lines[0].split()[:2] == ["collection", "paper"]
    assert lines[1].split() == ["a/3", "5.00e-01", "2.50e-01", "1.00e-02", "4.00e-02", "2.00e-02", "|", "12.50", "6.25",
                                "0.25", "|", "0.50"]
    assert lines[2].split() == ["b", "-", "1.00e+00", "3.00e+00", "1.50e+00", "4.00e+00", "|", "-", "0.67", "2.00",
                                "|", "0.75"]
