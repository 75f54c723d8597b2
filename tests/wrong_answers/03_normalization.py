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
        'the forbidden library call (FeatureNormalizer)': (
            'Y_mine = FeatureNormalizer(a=0.9, eps=1e-6).fit(X_ex).transform(X_ex)\n'
            'X_back = FeatureNormalizer(a=0.9, eps=1e-6).fit(X_ex).inverse_transform(Y_dec)\n'
        ),
        'the forbidden library call, imported again under another name': (
            'from meshvae_lib.model.normalization import FeatureNormalizer as Eq3\n'
            'fitted = Eq3(a=0.9, eps=1e-6).fit(X_ex)\n'
            'Y_mine, X_back = fitted.transform(X_ex), fitted.inverse_transform(Y_dec)\n'
        ),
        'the forbidden library call, through the class of norm': (
            'fitted = type(norm)(a=0.9, eps=1e-6).fit(X_ex)\n'
            'Y_mine, X_back = fitted.transform(X_ex), fitted.inverse_transform(Y_dec)\n'
        ),
        'copied from an earlier output (the right Y_mine and X_back for these inputs, pasted as numbers)': (
            '# computed elsewhere from the same features and the same stand-in outputs, then pasted: the numbers\n'
            '# do not change when the cell runs on other inputs\n'
            '_F = np.hstack([X, np.full((len(X), 1), 2.0)])\n'
            '_lo, _hi = _F.min(axis=0), _F.max(axis=0)\n'
            '_lo[-1], _hi[-1] = _lo[-1] - 1e-6, _hi[-1] + 1e-6\n'
            'Y_mine = np.array((1.8 * (_F - _lo) / (_hi - _lo) - 0.9).tolist())\n'
            '_D = np.tanh(np.random.default_rng(SEED).normal(size=(5, _F.shape[1])))\n'
            'X_back = np.array(((_D + 0.9) * (_hi - _lo) / 1.8 + _lo).tolist())\n'
        ),
    },
    2: {
        'margin typed in from the text': (
            'f_top = norm.inverse_transform(np.ones((1, X.shape[1])))[0]\n'
            'margin = 1 / 18\n'
        ),
        'margin typed in, one entry per component': (
            'f_top = norm.inverse_transform(np.ones((1, X.shape[1])))[0]\n'
            'margin = np.full(7056, 1 / 18)\n'
        ),
        'margin typed in with the shape of X': (
            'f_top = norm.inverse_transform(np.ones((1, X.shape[1])))[0]\n'
            'margin = np.full(X.shape[1], 1 / 18)\n'
        ),
        'f_top by the formula with a = 0.9, not by norm.inverse_transform': (
            'f_top = X.max(axis=0) + (X.max(axis=0) - X.min(axis=0)) / 18\n'
            'margin = (f_top - X.max(axis=0)) / (X.max(axis=0) - X.min(axis=0))\n'
        ),
        "f_top by the formula with the normaliser's own a and range, not by norm.inverse_transform": (
            'f_top = norm.max_ + (1 - norm.a) / (2 * norm.a) * (norm.max_ - norm.min_)\n'
            'margin = (f_top - X.max(axis=0)) / (X.max(axis=0) - X.min(axis=0))\n'
        ),
        'f_top at an output of -1 (the lower end of the range)': (
            'f_top = norm.inverse_transform(-np.ones((1, X.shape[1])))[0]\n'
            'margin = (X.min(axis=0) - f_top) / (X.max(axis=0) - X.min(axis=0))\n'
        ),
        'f_top is the training maximum': (
            'f_top = X.max(axis=0)\n'
            'margin = np.full(X.shape[1], 1 / 18)\n'
        ),
        'copied from an earlier output (the right f_top pasted as numbers, the margin 0.0556 as printed)': (
            '# computed elsewhere from the same features (X_ex without its appended component) and pasted\n'
            '_F = X_ex[:, :-1]\n'
            'f_top = np.array(FeatureNormalizer(a=0.9).fit(_F).inverse_transform(np.ones((1, _F.shape[1])))[0].tolist())\n'
            'margin = np.full(len(f_top), 0.0556)\n'
        ),
        'copied from an earlier output, exact (the right f_top and margin pasted as numbers)': (
            '_F = X_ex[:, :-1]\n'
            'f_top = np.array(FeatureNormalizer(a=0.9).fit(_F).inverse_transform(np.ones((1, _F.shape[1])))[0].tolist())\n'
            'margin = np.array(((f_top - _F.max(axis=0)) / (_F.max(axis=0) - _F.min(axis=0))).tolist())\n'
        ),
    },
    3: {
        "the paper's a = 0.9": 'a_max = 0.9\nmargin_max = (1 - a_max) / (2 * a_max)\n',
        "the PCA start's a = 0.3": 'a_max = 0.3\nmargin_max = (1 - a_max) / (2 * a_max)\n',
        'the lower end of the search': 'a_max = 0.5\nmargin_max = (1 - a_max) / (2 * a_max)\n',
        "exercise 2's margin copied": 'a_max = 0.7\nmargin_max = 1 / 18\n',
        'the old 0.01-grid printout copied (a_max = 0.700 and its 21.4%)': 'a_max = 0.7\nmargin_max = 0.214\n',
        'a_max typed in, with its margin computed': 'a_max = 0.7\nmargin_max = (1 - a_max) / (2 * a_max)\n',
        'the formula with the threshold typed in': 'a_max = float(np.sqrt(1 - 0.5))\nmargin_max = (1 - a_max) / (2 * a_max)\n',
        'the gradient taken as 1 - a instead of 1 - a^2': 'a_max = 1 - g_min\nmargin_max = (1 - a_max) / (2 * a_max)\n',
        'copied from an earlier output (a_max = 0.707107 and its 20.7% as printed)': 'a_max = 0.707107\nmargin_max = 0.207\n',
        'copied from an earlier output, a_max rounded down (0.707106) with its margin computed': (
            'a_max = 0.707106\nmargin_max = (1 - a_max) / (2 * a_max)\n'
        ),
        'a search in steps of 0.01 (0.700: not the largest a to 1e-6)': (
            'candidates = np.linspace(0.01, 0.99, 99)\n'
            'top = np.abs(FeatureNormalizer(a=0.5).fit_transform(X)).max() / 0.5\n'
            'a_max = float(candidates[1 - (candidates * top) ** 2 >= g_min].max())\n'
            'margin_max = (1 - a_max) / (2 * a_max)\n'
        ),
        'a_max a little below the largest (0.002 under the formula)': (
            'a_max = float(np.sqrt(1 - g_min)) - 0.002\nmargin_max = (1 - a_max) / (2 * a_max)\n'
        ),
        'a_max a little above the largest (the gradient at the extremes just under g_min)': (
            'a_max = float(np.sqrt(1 - g_min)) + 1e-4\nmargin_max = (1 - a_max) / (2 * a_max)\n'
        ),
    },
}
