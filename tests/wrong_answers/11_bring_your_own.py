"""Wrong answers to the exercises of notebook 11_bring_your_own: each must make its self-check raise.

Keys are exercise numbers from 1; values map a short description to the code run in place of
the solution (tests/test_exercise_checks.py runs them)."""

WRONG_ANSWERS = {
    1: {
        'any three meshes of the data': (
            "cond = MeshVAEModel('rimd', config, labels=('motion',), layout='compact').fit(coll)\n"
            'cond_meshes = coll.vertices[:3]\n'
        ),
        'the unconditional model': (
            'cond = model\n'
            'cond_meshes = model.generate(3, seed=SEED)\n'
        ),
        'the meshes of another label value': (
            'value = sorted(set(coll.labels["motion"]))[1]\n'
            "cond = MeshVAEModel('rimd', config, labels=('motion',), layout='compact').fit(coll)\n"
            'cond_meshes = cond.generate(3, seed=SEED, condition={"motion": value})\n'
        ),
        'the label value "bend" copied from an earlier output': (
            "cond = MeshVAEModel('rimd', config, labels=('motion',), layout='compact').fit(coll)\n"
            'cond_meshes = cond.generate(3, seed=SEED, condition={"motion": "bend"})\n'
        ),
        'another config (1 epoch, latent 2, seed 5), trained on meshes 20-59 only': (
            'value = sorted(set(coll.labels["motion"]))[0]\n'
            "cond = MeshVAEModel('rimd', TrainConfig(epochs=1, latent_dim=2, seed=5, device='cpu', progress=False),\n"
            "                    labels=('motion',), layout='compact').fit(coll.subset(np.arange(20, 60)))\n"
            'cond_meshes = cond.generate(3, seed=SEED, condition={"motion": value})\n'
        ),
        'the same config, trained on meshes 20-59 only': (
            'value = sorted(set(coll.labels["motion"]))[0]\n'
            "cond = MeshVAEModel('rimd', config, labels=('motion',), layout='compact').fit(coll.subset(np.arange(20, 60)))\n"
            'cond_meshes = cond.generate(3, seed=SEED, condition={"motion": value})\n'
        ),
        'another seed for the generated meshes': (
            'value = sorted(set(coll.labels["motion"]))[0]\n'
            "cond = MeshVAEModel('rimd', config, labels=('motion',), layout='compact').fit(coll)\n"
            'cond_meshes = cond.generate(3, seed=SEED + 1, condition={"motion": value})\n'
        ),
    },
    2: {
        'err_shuffled = 1.0': (
            'rng = np.random.default_rng(SEED)\n'
            'Vs = coll.vertices[1][rng.permutation(coll.n_vertices)]\n'
            "shuffled = collection.MeshCollection(Vs[None], coll.faces, ['shuffled'], {})\n"
            'err_shuffled = 1.0\n'
        ),
        'the error copied from an earlier output (0.28)': (
            'rng = np.random.default_rng(SEED)\n'
            'Vs = coll.vertices[1][rng.permutation(coll.n_vertices)]\n'
            "shuffled = collection.MeshCollection(Vs[None], coll.faces, ['shuffled'], {})\n"
            'err_shuffled = 0.28\n'
        ),
        'the input unchanged (no permutation)': (
            "shuffled = collection.MeshCollection(coll.vertices[1][None], coll.faces, ['shuffled'], {})\n"
            "err_shuffled = evaluate_model(model, shuffled)['relative_error']\n"
        ),
        'the held-out error copied': (
            'rng = np.random.default_rng(SEED)\n'
            'Vs = coll.vertices[1][rng.permutation(coll.n_vertices)]\n'
            "shuffled = collection.MeshCollection(Vs[None], coll.faces, ['shuffled'], {})\n"
            "err_shuffled = ev['relative_error']\n"
        ),
        'each coordinate column sorted on its own (not a vertex permutation)': (
            'Vs = np.sort(coll.vertices[1], axis=0)\n'
            "shuffled = collection.MeshCollection(Vs[None], coll.faces, ['shuffled'], {})\n"
            "err_shuffled = evaluate_model(model, shuffled)['relative_error']\n"
        ),
        'one independent permutation per coordinate column': (
            'rng = np.random.default_rng(SEED)\n'
            'Vs = np.stack([coll.vertices[1][rng.permutation(coll.n_vertices), k] for k in range(3)], axis=1)\n'
            "shuffled = collection.MeshCollection(Vs[None], coll.faces, ['shuffled'], {})\n"
            "err_shuffled = evaluate_model(model, shuffled)['relative_error']\n"
        ),
    },
    3: {
        'the first 8 training meshes': (
            'chosen = np.flatnonzero(~model.holdout_mask_)[:8]\n'
        ),
        'held-out meshes': (
            'chosen = np.flatnonzero(model.holdout_mask_)[:8]\n'
        ),
        '4 meshes, each twice': (
            'train_idx = np.flatnonzero(~model.holdout_mask_)\n'
            'chosen = train_idx[[0, 0, 16, 16, 31, 31, 47, 47]]\n'
        ),
        "the solution's indices copied from an earlier output": (
            'chosen = np.array([0, 8, 16, 25, 33, 42, 50, 58])\n'
        ),
    },
}
