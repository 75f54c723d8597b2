"""Wrong answers to the exercises of notebook 06_conditional_vae: each must make its self-check raise.

Keys are exercise numbers from 1; values map a short description to the code run in place of
the solution (tests/test_exercise_checks.py runs them)."""

_ENCODED = (
    'Zc = cond.encode_meshes(coll, inference="encoder")\n'
    'Zp = plain.encode_meshes(coll.vertices, inference="encoder")\n'
)

#: the solution of exercise 3 with one of the pair or the motion written in (format with the three expressions)
_BISECTION = (
    'from meshvae_lib.model import per_vertex_error\n'
    'z0 = np.zeros((1, cond.latent_dim))\n'
    'c_a, c_b = (cond.condition_vector({{"shape": s, "motion": {motion}}}) for s in ({a}, {b}))\n'
    'V_a, V_b = cond.decode_latent(z0, conditions=c_a), cond.decode_latent(z0, conditions=c_b)\n'
    'lo, hi = 0.0, 1.0\n'
    'for _ in range(30):\n'
    '    w_mid = (lo + hi) / 2\n'
    '    V_w = cond.decode_latent(z0, conditions=(1 - w_mid) * c_a + w_mid * c_b)\n'
    '    lo, hi = (w_mid, hi) if per_vertex_error(V_w, V_a).mean() < per_vertex_error(V_w, V_b).mean() else (lo, w_mid)\n'
)

#: the solution of exercise 3 with the lesson's pair written in instead of SHAPE_A, SHAPE_B, BLEND_MOTION
_BISECTION_WRITTEN_IN = _BISECTION.format(motion='"walk"', a='"female_heavy"', b='"male_tall_slim"')

WRONG_ANSWERS = {
    1: {
        'the overall mean copied for every motion': 'per_motion = np.full(len(motions), 0.99)\n',
        'the plain model (chance)': (
            'per_motion = generation.condition_agreement(plain, coll, "motion", n=N_PER_LABEL, seed=SEED, '
            'conditioned=False, dataset_features=X)\n'),
        'the shape column instead of the motion': (
            'per_motion = generation.condition_agreement(cond, coll, "shape", n=N_PER_LABEL, seed=SEED, dataset_features=X)\n'),
        "copied from an earlier output (section 5's data meshes, 0.79)": 'per_motion = np.full(len(motions), 0.79)\n',
        'copied from an earlier output (the seven shares the solution shows)': (
            'per_motion = np.array([1.0, 1.0, 1.0, 1.0, 1.0, 0.9, 1.0])\n'),
        "the lesson's seed and number of draws written in instead of SEED and N_PER_LABEL": (
            'per_motion = generation.condition_agreement(cond, coll, "motion", n=10, seed=0, dataset_features=X)\n'),
        "the lesson's number of draws written in instead of N_PER_LABEL": (
            'per_motion = generation.condition_agreement(cond, coll, "motion", n=10, seed=SEED, dataset_features=X)\n'),
        "seed 0 written in instead of SEED": (
            'per_motion = generation.condition_agreement(cond, coll, "motion", n=N_PER_LABEL, seed=0, dataset_features=X)\n'),
        'every motion obeyed, ones typed': 'per_motion = np.ones(len(motions))\n',
        "the collection built again instead of coll": (
            'per_motion = generation.condition_agreement(cond, get_spec(COND).make_collection(), "motion", n=N_PER_LABEL,'
            ' seed=SEED, dataset_features=X)\n'),
    },
    2: {
        'each mesh is its own nearest neighbour': (
            _ENCODED
            + 'share_cond = float(np.mean(coll.labels[COLUMN][generation.nearest_neighbors(Zc, Zc)[0]] == coll.labels[COLUMN]))\n'
            'share_plain = float(np.mean(coll.labels[COLUMN][generation.nearest_neighbors(Zp, Zp)[0]] == coll.labels[COLUMN]))\n'),
        'the two models swapped': (
            _ENCODED
            + 'share_plain = float(np.mean(coll.labels[COLUMN][generation.nearest_neighbors(Zc, Zc, exclude_self=True)[0]] == coll.labels[COLUMN]))\n'
            'share_cond = float(np.mean(coll.labels[COLUMN][generation.nearest_neighbors(Zp, Zp, exclude_self=True)[0]] == coll.labels[COLUMN]))\n'),
        'chance for both': 'share_cond = share_plain = 1 / len(shapes)\n',
        'copied from an earlier output (the shares 0.15 and 0.55 the solution shows)': 'share_cond, share_plain = 0.15, 0.55\n',
        'copied from an earlier output, to full precision (32 and 115 of 210 meshes)': (
            'share_cond, share_plain = 32 / 210, 115 / 210\n'),
        '"shape" written in instead of COLUMN': (
            _ENCODED
            + 'share_cond = float(np.mean(coll.labels["shape"][generation.nearest_neighbors(Zc, Zc, exclude_self=True)[0]] == coll.labels["shape"]))\n'
            'share_plain = float(np.mean(coll.labels["shape"][generation.nearest_neighbors(Zp, Zp, exclude_self=True)[0]] == coll.labels["shape"]))\n'),
    },
    3: {
        'the naive guess w = 0.5': 'w_mid = 0.5\n',
        'the mirrored weight': 'w_mid = 1 - 0.466\n',
        'the other body': 'w_mid = 1.0\n',
        'copied from an earlier output (w = 0.466 the solution shows)': 'w_mid = 0.466\n',
        "the lesson's pair and motion written in instead of SHAPE_A, SHAPE_B, BLEND_MOTION": _BISECTION_WRITTEN_IN,
        '"walk" written in instead of BLEND_MOTION': _BISECTION.format(a="SHAPE_A", b="SHAPE_B", motion='"walk"'),
        "the lesson's pair written in instead of SHAPE_A, SHAPE_B": _BISECTION.format(
            a='"female_heavy"', b='"male_tall_slim"', motion="BLEND_MOTION"),
    },
}
