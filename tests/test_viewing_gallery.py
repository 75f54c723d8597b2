"""Gallery selection and captions (notebook 00), and the round-off printer of the lessons."""

import numpy as np
import pytest

from meshvae_lib.course.display import roundoff
from meshvae_lib.viewing.gallery import align_on_part, angular_stripes, gallery_indices, mesh_caption


def test_evenly_spaced_without_groups():
    V = np.zeros((11, 4, 3))
    assert gallery_indices(V, 3).tolist() == [0, 5, 10]
    assert gallery_indices(V[:2], 5).tolist() == [0, 1]   # never the same mesh twice


def test_the_most_deformed_mesh_of_each_group_in_order_of_appearance():
    V = np.zeros((6, 2, 3))
    V[:, :, 0] = np.array([0.0, 3.0, 1.0, 0.5, 2.0, 0.1])[:, None]   # distance of each mesh from mesh 0
    groups = np.array(["b", "b", "a", "a", "c", "c"])
    assert gallery_indices(V, 8, groups).tolist() == [1, 2, 4]
    assert gallery_indices(V, 2, groups).tolist() == [1, 2]
    # a score picks the member with the highest one instead of the most deformed
    assert gallery_indices(V, 8, groups, score=-np.arange(6.0)).tolist() == [0, 2, 4]
    with pytest.raises(ValueError, match=r"score must be 6 finite numbers, one per mesh, got shape \(5,\)"):
        gallery_indices(V, 8, groups, score=np.zeros(5))
    with pytest.raises(ValueError, match=r"one label per mesh \(6\), got shape \(5,\)"):
        gallery_indices(V, 2, groups[:5])
    with pytest.raises(ValueError, match="n_panels must be an integer >= 1, got 0"):
        gallery_indices(V, 0)


def test_captions_show_categories_numbers_with_units_and_the_frame_when_little_else():
    labels = {"motion": np.array(["jumping_jacks", "run"]), "frame": np.array([3, 4])}
    assert mesh_caption(labels, 0, "m0") == "jumping jacks\nframe 3"
    labels = {"bend_deg": np.array([30, 45]), "wind_pct": np.array([10, 20])}
    assert mesh_caption(labels, 1, "m1") == "bend 45°\nwind 20%"
    assert mesh_caption({"head_yaw_deg": np.array([-26])}, 0, "m") == "head yaw -26°"
    assert mesh_caption({}, 0, "pose_007") == "pose_007"


def test_stripes_alternate_around_the_axis():
    angles = np.linspace(-np.pi + 0.1, np.pi - 0.1, 8)   # one vertex per band of 8
    rest = np.stack([np.zeros(8), np.cos(angles), np.sin(angles)], axis=1)
    c = angular_stripes(rest, n_stripes=8, colors=((0, 0, 0), (1, 1, 1)))
    assert c[:, 0].tolist() == [0, 1, 0, 1, 0, 1, 0, 1]
    with pytest.raises(ValueError, match="even number >= 2, got 3"):
        angular_stripes(rest, 3)


def test_roundoff_prints_a_bound_below_it_and_digits_above():
    assert roundoff(3e-16) == "< 1e-10" and roundoff(-2e-12, 1e-11) == "< 1e-11"
    assert roundoff(3.24e-4) == "3.2e-04"
    with pytest.raises(ValueError, match="below must be > 0, got 0"):
        roundoff(1.0, 0)


def test_align_on_part_undoes_the_part_s_turn_and_keeps_the_rest_s_own_motion():
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(3)
    ref = rng.normal(size=(40, 3))
    part = np.arange(40) < 25                         # these move rigidly; the others also deform
    turn = Rotation.from_rotvec(np.radians(25.0) * np.array([0.6, 0.8, 0.0]))
    own = np.zeros_like(ref)
    own[~part] = 0.1 * rng.normal(size=((~part).sum(), 3))    # the rest's own motion
    moved = turn.apply(ref + own) + np.array([1.0, -2.0, 0.5])
    aligned, deg = align_on_part(np.stack([moved, ref]), ref, part)
    assert np.allclose(deg, [25.0, 0.0], atol=1e-6)
    assert np.allclose(aligned[0, part], ref[part], atol=1e-9)
    assert np.allclose(aligned[0], ref + own, atol=1e-9)      # the own motion stays, the turn goes
    assert np.allclose(aligned[1], ref, atol=1e-9)
    one, one_deg = align_on_part(moved, ref, part)
    assert one.shape == (40, 3) and np.isclose(one_deg, 25.0, atol=1e-6)
    with pytest.raises(ValueError, match="part must be"):
        align_on_part(moved, ref, np.ones(40))
    with pytest.raises(ValueError, match="part must be"):
        align_on_part(moved, ref, np.arange(40) < 2)
