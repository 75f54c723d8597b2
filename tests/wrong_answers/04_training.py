"""Wrong answers to the exercises of notebook 04_training: each must make its self-check raise.

Keys are exercise numbers from 1; values map a short description to the code run in place of
the solution (tests/test_exercise_checks.py runs them)."""

WRONG_ANSWERS = {
    1: {
        'zero tensors with sigma = 1': (
            'x = x_hat = mu = torch.zeros(8, 4)\n'
            'sigma = torch.ones(8, 4)\n'
            'rec_term = kl_term = 0.0\n'
        ),
    },
    3: {
        'a threshold typed in from the text': 'alpha_off = np.full(LATENT, 1e3)\n',
        'sigma = 1/sqrt(2) instead of 0.5 (K / c^2)': (
            "c_paper = decoder_column_norms(model.network, model.encode_meshes(train_V, inference='encoder')).mean(axis=0)\n"
            'alpha_off = model.n_features / c_paper ** 2\n'
        ),
        'column norms at the held-out meshes': (
            "c_paper = decoder_column_norms(model.network, model.encode_meshes(col.vertices[held_out], inference='encoder')).mean(axis=0)\n"
            'alpha_off = 3 * model.n_features / c_paper ** 2\n'
        ),
    },
}
