"""Wrong answers to the exercises of notebook 06_conditional_vae: each must make its self-check raise.

Keys are exercise numbers from 1; values map a short description to the code run in place of
the solution (tests/test_exercise_checks.py runs them)."""

_ENCODED = (
    'Zc = cond.encode_meshes(coll, inference="encoder")\n'
    'Zp = plain.encode_meshes(coll.vertices, inference="encoder")\n'
)

WRONG_ANSWERS = {
    1: {
        'the overall mean copied for every motion': 'per_motion = np.full(len(motions), 0.99)\n',
        'the plain model (chance)': (
            'per_motion = generation.condition_agreement(plain, coll, "motion", n=N_PER_LABEL, seed=SEED, '
            'conditioned=False, dataset_features=X)\n'),
        'the shape column instead of the motion': (
            'per_motion = generation.condition_agreement(cond, coll, "shape", n=N_PER_LABEL, seed=SEED, dataset_features=X)\n'),
        "copied from an earlier output (section 5's data meshes, 0.79)": 'per_motion = np.full(len(motions), 0.79)\n',
    },
    2: {
        'each mesh is its own nearest neighbour': (
            _ENCODED
            + 'share_cond = float(np.mean(coll.labels["shape"][generation.nearest_neighbors(Zc, Zc)[0]] == coll.labels["shape"]))\n'
            'share_plain = float(np.mean(coll.labels["shape"][generation.nearest_neighbors(Zp, Zp)[0]] == coll.labels["shape"]))\n'),
        'the two models swapped': (
            _ENCODED
            + 'share_plain = float(np.mean(coll.labels["shape"][generation.nearest_neighbors(Zc, Zc, exclude_self=True)[0]] == coll.labels["shape"]))\n'
            'share_cond = float(np.mean(coll.labels["shape"][generation.nearest_neighbors(Zp, Zp, exclude_self=True)[0]] == coll.labels["shape"]))\n'),
        'chance for both': 'share_cond = share_plain = 1 / len(shapes)\n',
        'copied from an earlier output (the shares 0.15 and 0.55 the check once printed)': 'share_cond, share_plain = 0.15, 0.55\n',
    },
    3: {
        'the naive guess w = 0.5': 'w_mid = 0.5\n',
        'the mirrored weight': 'w_mid = 1 - 0.466\n',
        'the other body': 'w_mid = 1.0\n',
    },
}
