"""Wrong answers to the exercises of notebook 08_exploration: each must make its self-check raise.

Keys are exercise numbers from 1; values map a short description to the code run in place of
the solution (tests/test_exercise_checks.py runs them)."""

_STRONG = '4 + int(np.argmax(move[4:]))'
_PANEL = 'level1.latents[GRID - 1, 0]'

WRONG_ANSWERS = {
    1: {
        'strength [1, 1, 1, 1, 0, ...]': 'strength = np.r_[np.ones(4), np.zeros(LATENT - 4)]\n',
        'only the four dimensions of section 4 swept': 'strength = np.r_[np.abs(effects.effect).max(axis=1), np.zeros(LATENT - 4)]\n',
        'the displacement of section 4 instead of the measurements': 'strength = np.asarray(move, dtype=float).copy()\n',
        'copied from an earlier output (the strengths the solution prints, to one decimal)': (
            'strength = np.array([1.5, 2.2, 1.0, 1.7, 1.1, 0.0, 0.2, 0.7, 0.0, 0.8, 0.5, 0.1, 0.1, 0.1, 1.9, 0.8])\n'
        ),
        'copied from an earlier output, to full precision (computed elsewhere on the course model, then pasted)': (
            '# the numbers do not change when the cell runs on another latent space\n'
            'strength = np.array(np.abs(ex.dimension_effects(course_model(MODEL), measure, dims=range(16),\n'
            '                                                reference_vertices=coll.vertices).effect).max(axis=1).tolist())\n'
        ),
        'the span (largest minus smallest) instead of the change from -2 to +2': (
            'all_effects = ex.dimension_effects(model, measure, dims=range(LATENT), reference_vertices=coll.vertices)\n'
            'strength = np.abs(all_effects.span).max(axis=1)\n'
        ),
        'the largest signed change, not the largest absolute one': (
            'all_effects = ex.dimension_effects(model, measure, dims=range(LATENT), reference_vertices=coll.vertices)\n'
            'strength = all_effects.effect.max(axis=1)\n'
        ),
    },
    2: {
        "the paper's second level, dimensions 3 and 4":
            f'level_own = ex.explore(model, dims=(2, 3), base={_PANEL}, n=3)\n',
        'the dimension among 1-4 that moves the body most (not a sigma_object = 1 one)':
            f'level_own = ex.explore(model, dims=(2, int(np.argmax(move[:4]))), base={_PANEL}, n=3)\n',
        'a 5 x 5 grid (GRID) instead of 3 x 3':
            f'level_own = ex.explore(model, dims=(2, {_STRONG}), base={_PANEL}, n=GRID)\n',
        'the strongest dimension counted from 1':
            f'level_own = ex.explore(model, dims=(2, 5 + int(np.argmax(move[4:]))), base={_PANEL}, n=3)\n',
        'copied from an earlier output (dimension 10 of the figure title "dims 3 and 10", typed in as 9)':
            f'level_own = ex.explore(model, dims=(2, 9), base={_PANEL}, n=3)\n',
        'no base: every other dimension at 0, the centre panel (the reader found it passed)':
            f'level_own = ex.explore(model, dims=(2, {_STRONG}), n=3)\n',
        'the panel typed in (z1 = 2, z2 = -2, the bottom-left panel as its title reads)':
            f'level_own = ex.explore(model, dims=(2, {_STRONG}), base=np.r_[2.0, -2.0, np.zeros(LATENT - 2)], n=3)\n',
        'another value range, [-1, 1]':
            f'level_own = ex.explore(model, dims=(2, {_STRONG}), base={_PANEL}, n=3, value_range=(-1, 1))\n',
        'a base between the panels (z1 = z2 = 0.5)':
            f'level_own = ex.explore(model, dims=(2, {_STRONG}), base=np.r_[0.5, 0.5, np.zeros(LATENT - 2)], n=3)\n',
    },
    3: {
        'the mean body (z = 0)': 'z_arms = np.zeros(LATENT)\narms_up = float(measure(model.decode_latent(z_arms[None]))["arm_height"][0])\n',
        'the target itself typed in': 'z_arms = np.zeros(LATENT)\narms_up = float(np.percentile(measure(coll.vertices)["arm_height"], 90))\n',
        'a training mesh encoded, with its own arm height':
            'k = int(np.argmax(measure(coll.vertices)["arm_height"]))\nz_arms = np.clip(Z[k], -2, 2)\n'
            'arms_up = float(measure(coll.vertices[k:k + 1])["arm_height"][0])\n',
        'beyond the browsing range': 'z_arms = np.zeros(LATENT)\nz_arms[3] = -6.0\n'
                                     'arms_up = float(measure(model.decode_latent(z_arms[None]))["arm_height"][0])\n',
        'copied from an earlier output (z[:4] = [-2, 2, 2, -2] as the solution prints it, its arm height decoded)': (
            'z_arms = np.r_[-2.0, 2.0, 2.0, -2.0, np.zeros(LATENT - 4)]\n'
            'arms_up = float(measure(model.decode_latent(z_arms))["arm_height"])\n'
        ),
        'one dimension typed in (dimension 4 at -2: section 4 says it lowers the arms as it grows)': (
            'z_arms = np.zeros(LATENT)\nz_arms[3] = -2.0\n'
            'arms_up = float(measure(model.decode_latent(z_arms))["arm_height"])\n'
        ),
        'arms_up copied from an earlier output (0.88 as printed)': (
            'z_arms = np.r_[-2.0, 2.0, 2.0, -2.0, np.zeros(LATENT - 4)]\narms_up = 0.88\n'
        ),
    },
}
