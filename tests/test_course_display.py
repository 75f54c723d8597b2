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


def test_real_feature_table_prints_the_recorded_kinds_the_floor_and_the_verdict():
    from meshvae_lib.course.display import real_feature_table

    rows = [{"collection": "a/3", "coords_default": 0.03, "aligned_default": 0.02, "default": 0.01, "paper_path": 0.5,
             "pca_coords": 0.04, "pca_aligned": 0.02, "floor_relative": 5e-3, "informative": True},
            {"collection": "b", "coords_default": 2e-5, "aligned_default": 1.6e-5, "default": 7.5e-5, "paper_path": None,
             "pca_coords": 1.5e-5, "pca_aligned": 1.2e-5, "floor_relative": 5.2e-6, "informative": False}]
    lines = real_feature_table(rows).splitlines()
    assert len(lines) == 3 and lines[0].split()[:4] == ["collection", "coords", "aligned", "RIMD"]
    assert lines[1].split() == ["a/3", "3.00e-02", "2.00e-02", "1.00e-02", "5.00e-01", "4.00e-02", "2.00e-02", "5.0e-03",
                                "0.25", "yes"]
    assert lines[2].split() == ["b", "2.00e-05", "1.60e-05", "7.50e-05", "-", "1.50e-05", "1.20e-05", "5.2e-06", "5.00",
                                "linear", "data:", "not", "informative"]


def test_span_ceiling_table_prints_the_recorded_errors_and_their_ratios_to_pca():
    from meshvae_lib.course.display import span_ceiling_table

    rows = [{"collection": "a", "n_meshes": 40, "pca_coords": 0.002, "feature_projection": 0.03, "vertex_optimal": 0.004,
             "default": 0.005, "vertex_optimal_below_pca": 9},
            {"collection": "b/3", "n_meshes": 12, "pca_coords": 0.02, "feature_projection": 0.07, "vertex_optimal": 0.015,
             "default": 0.014, "vertex_optimal_below_pca": 10}]
    lines = span_ceiling_table(rows).splitlines()
    assert len(lines) == 3 and lines[0].split()[:3] == ["collection", "meshes", "PCA"]
    assert lines[1].split() == ["a", "40", "2.00e-03", "3.00e-02", "4.00e-03", "5.00e-03", "|", "15.00", "2.00", "2.50",
                                "|", "9", "of", "40"]
    assert lines[2].split() == ["b/3", "12", "2.00e-02", "7.00e-02", "1.50e-02", "1.40e-02", "|", "3.50", "0.75", "0.70",
                                "|", "10", "of", "12"]
