"""Wrong answers to the exercises of notebook 08_exploration: each must make its self-check raise.

Keys are exercise numbers from 1; values map a short description to the code run in place of
the solution (tests/test_exercise_checks.py runs them)."""

WRONG_ANSWERS = {
    1: {
        'strength [1, 1, 1, 1, 0, ...]': 'strength = np.r_[np.ones(4), np.zeros(LATENT - 4)]\n',
        'only the four dimensions of section 4 swept': 'strength = np.r_[np.abs(effects.effect).max(axis=1), np.zeros(LATENT - 4)]\n',
    },
}
