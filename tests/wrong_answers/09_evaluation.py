"""Wrong answers to the exercises of notebook 09_evaluation: each must make its self-check raise.

Keys are exercise numbers from 1; values map a short description to the code run in place of
the solution (tests/test_exercise_checks.py runs them)."""

WRONG_ANSWERS = {
    1: {
        'the floor copied from the table': (
            "pca_err = rows['jumping']['ours aligned']\n"
            "rimd_over_pca = rows['jumping']['ours rimd'] / pca_err\n"
        ),
        'a floor of zero': (
            'pca_err = 0.0\n'
            "rimd_over_pca = float('inf')\n"
        ),
        'the printed floor, rounded (3.1e-05)': (
            'pca_err = 3.1e-05\n'
            "rimd_over_pca = rows['face']['ours rimd'] / pca_err\n"
        ),
    },
    2: {
        'the quick table reused': (
            't2_longer = t2_quick\n'
            "gain = {'coords': 1.0, 'aligned': 1.0, 'rimd': 1.0}\n"
        ),
        "the default arguments (the quick preset's steps)": (
            'longer = paper.ExperimentSettings.quick(seed=SEED)\n'
            't2_longer = paper.feature_table([COLLECTIONS[0]], settings=longer, cache={})\n'
            "gain = {k: t2_longer.as_dicts()[0][f'ours {k}'] / t2_quick.as_dicts()[0][f'ours {k}'] for k in ('coords', 'aligned', 'rimd')}\n"
        ),
        'the ratio inverted (quick / longer)': (
            'longer = paper.ExperimentSettings.quick(seed=SEED, train_steps=3 * settings.train_steps)\n'
            't2_longer = paper.feature_table([COLLECTIONS[0]], settings=longer, cache={})\n'
            "gain = {k: t2_quick.as_dicts()[0][f'ours {k}'] / t2_longer.as_dicts()[0][f'ours {k}'] for k in ('coords', 'aligned', 'rimd')}\n"
        ),
    },
    3: {
        'the threshold applied to the learned errors': (
            "floor_rel = {name: rows[name]['ours rimd'] for name in rows}\n"
            'informative = [name for name in rows if floor_rel[name] >= 1e-4]\n'
        ),
        'absolute floors, not relative to the diagonal': (
            'floor_rel = {}\n'
            'for name in rows:\n'
            '    coll = paper.load_collection(name, full.settings)\n'
            '    held = holdout_mask(len(coll.vertices), full.settings.holdout_every)\n'
            "    floor_rel[name] = float(pca_baseline(coll.vertices[~held], coll.vertices[held])['mean_vertex_error'])\n"
            'informative = [name for name in rows if floor_rel[name] >= 1e-4]\n'
        ),
        "the table's column copied": (
            "floor_rel = {name: rows[name]['floor / diagonal'] for name in rows}\n"
            "informative = [name for name in rows if rows[name]['informative'] == 'yes']\n"
        ),
    },
}
