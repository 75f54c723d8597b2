"""Wrong answers to the exercises of notebook 07_sigma_object_embeddings: each must make its self-check raise.

Keys are exercise numbers from 1; values map a short description to the code run in place of
the solution (tests/test_exercise_checks.py runs them)."""

WRONG_ANSWERS = {
    1: {
        "the check's own expression": 'gap = exact - sibling\n',
        'the total split evenly': 'gap = torch.full((3,), (exact - sibling) / 3)\n',
    },
    2: {
        'only pair (1, 2) right': "pair_auc = np.r_[curves['σ_object VAE (ours)'].auc['mean'], np.full(LATENT // 2 - 1, 0.5)]\n",
        'overlapping pairs (1, 2), (2, 3), ...': 'pair_auc = np.array([ret.retrieval_auc(Z[median_seed][:, i:i + 2], labels) for i in range(LATENT // 2)])\n',
    },
}
