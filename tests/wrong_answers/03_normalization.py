"""Wrong answers to the exercises of notebook 03_normalization: each must make its self-check raise.

Keys are exercise numbers from 1; values map a short description to the code run in place of
the solution (tests/test_exercise_checks.py runs them)."""

_EQ3 = (
    'a, eps = 0.9, 1e-6\n'
    'lo, hi = X_ex.min(axis=0), X_ex.max(axis=0)\n'
    'const = hi == lo\n'
    'lo, hi = np.where(const, lo - eps, lo), np.where(const, hi + eps, hi)\n'
    'Y_mine = 2 * a * (X_ex - lo) / (hi - lo) - a\n'
)

WRONG_ANSWERS = {
    1: {
        'X_back is the input unchanged': _EQ3 + 'X_back = X_ex.copy()\n',
        'X_back is X': _EQ3 + 'X_back = X.copy()\n',
        'the round trip of Y_mine instead of Y_dec': _EQ3 + 'X_back = (Y_mine + a) * (hi - lo) / (2 * a) + lo\n',
        'without the eps rule': (
            'a = 0.9\n'
            'lo, hi = X_ex.min(axis=0), X_ex.max(axis=0)\n'
            'with np.errstate(invalid="ignore", divide="ignore"):\n'
            '    Y_mine = 2 * a * (X_ex - lo) / (hi - lo) - a\n'
            'X_back = (Y_dec + a) * (hi - lo) / (2 * a) + lo\n'
        ),
        'min-max onto [-1, 1] (a = 1)': (
            'a, eps = 1.0, 1e-6\n'
            'lo, hi = X_ex.min(axis=0), X_ex.max(axis=0)\n'
            'lo, hi = np.where(hi == lo, lo - eps, lo), np.where(hi == lo, hi + eps, hi)\n'
            'Y_mine = 2 * a * (X_ex - lo) / (hi - lo) - a\n'
            'X_back = (Y_dec + a) * (hi - lo) / (2 * a) + lo\n'
        ),
    },
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
    3: {
        "the paper's a = 0.9": 'a_max = 0.9\nmargin_max = (1 - a_max) / (2 * a_max)\n',
        "the PCA start's a = 0.3": 'a_max = 0.3\nmargin_max = (1 - a_max) / (2 * a_max)\n',
        'the lower end of the search': 'a_max = 0.5\nmargin_max = (1 - a_max) / (2 * a_max)\n',
        "exercise 2's margin copied": 'a_max = 0.7\nmargin_max = 1 / 18\n',
    },
}
