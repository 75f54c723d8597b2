"""Wrong answers to the exercises of notebook 03_normalization: each must make its self-check raise.

Keys are exercise numbers from 1; values map a short description to the code run in place of
the solution (tests/test_exercise_checks.py runs them)."""

WRONG_ANSWERS = {
    2: {
        'margin typed in from the text': (
            'f_top = norm.inverse_transform(np.ones((1, X.shape[1])))[0]\n'
            'margin = 1 / 18\n'
        ),
        'f_top is the training maximum': (
            'f_top = X.max(axis=0)\n'
            'margin = np.full(X.shape[1], 1 / 18)\n'
        ),
    },
}
