"""Wrong answers to the exercises of notebook 08_exploration: each must make its self-check raise.

Keys are exercise numbers from 1; values map a short description to the code run in place of
the solution (tests/test_exercise_checks.py runs them)."""

WRONG_ANSWERS = {
    1: {
        'strength [1, 1, 1, 1, 0, ...]': 'strength = np.r_[np.ones(4), np.zeros(LATENT - 4)]\n',
        'only the four dimensions of section 4 swept': 'strength = np.r_[np.abs(effects.effect).max(axis=1), np.zeros(LATENT - 4)]\n',
        'the displacement of section 4 instead of the measurements': 'strength = np.asarray(move, dtype=float).copy()\n',
    },
    2: {
        "the paper's second level, dimensions 3 and 4":
            'level_own = ex.explore(model, dims=(2, 3), base=level1.latents[GRID - 1, 0], n=3)\n',
        'the dimension among 1-4 that moves the body most (not a sigma_object = 1 one)':
            'level_own = ex.explore(model, dims=(2, int(np.argmax(move[:4]))), base=level1.latents[GRID - 1, 0], n=3)\n',
        'a 5 x 5 grid (GRID) instead of 3 x 3':
            'level_own = ex.explore(model, dims=(2, 4 + int(np.argmax(move[4:]))), base=level1.latents[GRID - 1, 0], n=GRID)\n',
        'the strongest dimension counted from 1':
            'level_own = ex.explore(model, dims=(2, 5 + int(np.argmax(move[4:]))), base=level1.latents[GRID - 1, 0], n=3)\n',
    },
    3: {
        'the mean body (z = 0)': 'z_arms = np.zeros(LATENT)\narms_up = float(measure(model.decode_latent(z_arms[None]))["arm_height"][0])\n',
        'the target itself typed in': 'z_arms = np.zeros(LATENT)\narms_up = float(np.percentile(measure(coll.vertices)["arm_height"], 90))\n',
        'a training mesh encoded, with its own arm height':
            'k = int(np.argmax(measure(coll.vertices)["arm_height"]))\nz_arms = np.clip(Z[k], -2, 2)\n'
            'arms_up = float(measure(coll.vertices[k:k + 1])["arm_height"][0])\n',
        'beyond the browsing range': 'z_arms = np.zeros(LATENT)\nz_arms[3] = -6.0\n'
                                     'arms_up = float(measure(model.decode_latent(z_arms[None]))["arm_height"][0])\n',
    },
}
