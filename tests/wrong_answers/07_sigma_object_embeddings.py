"""Wrong answers to the exercises of notebook 07_sigma_object_embeddings: each must make its self-check raise.

Keys are exercise numbers from 1; values map a short description to the code run in place of
the solution (tests/test_exercise_checks.py runs them)."""

WRONG_ANSWERS = {
    1: {
        "the check's own expression": 'gap = exact - sibling\n',
        'the total split evenly': 'gap = torch.full((3,), (exact - sibling) / 3)\n',
        'without the -1 (mu^2 / s^2 only)': 'gap = (0.5 * mu**2 / s_obj**2)[0]\n',
        'the terms copied from an earlier output': 'gap = torch.tensor([12.375, 0.375, 0.0])\n',
        'the per-dimension difference of kl_divergence (the library, not the terms)':
            'gap = torch.stack([kl_divergence(mu[:, i:i + 1], sigma[:, i:i + 1], s_obj[i:i + 1])\n'
            '                   - kl_divergence(mu[:, i:i + 1], sigma[:, i:i + 1], s_obj[i:i + 1], form="sibling")\n'
            '                   for i in range(mu.shape[1])])\n',
    },
    2: {
        'only pair (1, 2) right': "pair_auc = np.r_[curves['σ_object VAE (ours)'].auc['mean'], np.full(LATENT // 2 - 1, 0.5)]\n",
        'overlapping pairs (1, 2), (2, 3), ...': 'pair_auc = np.array([ret.retrieval_auc(Z[SHOWN_SEED][:, i:i + 2], labels) for i in range(LATENT // 2)])\n',
        'the pairs of the exact-KL model instead of seed 0':
            "Zx = ablations['exact KL (alpha 1e3, hidden 256)'].encode_meshes(coll.vertices, inference='encoder')\n"
            'pair_auc = np.array([ret.retrieval_auc(Zx[:, i:i + 2], labels) for i in range(0, LATENT - 1, 2)])\n',
        "the pairs of seed 0 typed in (not in terms of SHOWN_SEED)":
            'pair_auc = np.array([ret.retrieval_auc(Z[0][:, i:i + 2], labels) for i in range(0, LATENT - 1, 2)])\n',
        'the AUCs copied from an earlier output': 'pair_auc = np.r_[0.543, np.full(LATENT // 2 - 1, 0.245)]\n',
    },
    3: {
        "seed 0's dimensions 1-2 (the map of section 3)":
            'choice = (SHOWN_SEED, 0, 1)\nbest_auc = seed_auc[SHOWN_SEED]\n',
        "PCA's AUC typed in for a latent map": 'choice = (SEEDS[0], 0, 1)\nbest_auc = pca_auc\n',
        'dimensions counted from 1 (the AUC of dims 1-2 stored as (1, 2))':
            's_best = max(SEEDS, key=seed_auc.get)\nchoice = (s_best, 1, 2)\nbest_auc = seed_auc[s_best]\n',
        'the same dimension twice': 's_best = max(SEEDS, key=seed_auc.get)\nchoice = (s_best, 0, 0)\n'
                                    'best_auc = ret.retrieval_auc(Z[s_best][:, [0, 0]], labels)\n',
        "no search: the best seed's dimensions 1-2, from seed_auc":
            's = max(SEEDS, key=seed_auc.get)\nchoice = (s, 0, 1)\nbest_auc = seed_auc[s]\n',
        'the best map copied from an earlier output': 'choice = (1, 0, 1)\nbest_auc = 0.561\n',
        'a pair outside the first 12 dimensions':
            's = max(SEEDS, key=seed_auc.get)\nchoice = (s, 0, 100)\nbest_auc = ret.retrieval_auc(Z[s][:, [0, 100]], labels)\n',
    },
}
