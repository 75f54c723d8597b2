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
    },
}
