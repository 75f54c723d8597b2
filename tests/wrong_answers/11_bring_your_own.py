"""Wrong answers to the exercises of notebook 11_bring_your_own: each must make its self-check raise.

Keys are exercise numbers from 1; values map a short description to the code run in place of
the solution (tests/test_exercise_checks.py runs them)."""

WRONG_ANSWERS = {
    1: {
        'any three meshes of the data': (
            'column = next(iter(coll.labels))\n'
            'value = sorted(set(coll.labels[column]))[0]\n'
            "cond = MeshVAEModel('rimd', config, labels=(column,), layout='compact').fit(coll)\n"
            'cond_meshes = coll.vertices[:3]\n'
        ),
        'the unconditional model': (
            'column = next(iter(coll.labels))\n'
            'cond = model\n'
            'cond_meshes = model.generate(3, seed=SEED)\n'
        ),
        'the meshes of another label value': (
            'column = next(iter(coll.labels))\n'
            'value = sorted(set(coll.labels[column]))[1]\n'
            "cond = MeshVAEModel('rimd', config, labels=(column,), layout='compact').fit(coll)\n"
            'cond_meshes = cond.generate(3, seed=SEED, condition={column: value})\n'
        ),
    },
    2: {
        'err_shuffled = 1.0': (
            'rng = np.random.default_rng(SEED)\n'
            'Vs = coll.vertices[1][rng.permutation(coll.n_vertices)]\n'
            "shuffled = collection.MeshCollection(Vs[None], coll.faces, ['shuffled'], {})\n"
            'err_shuffled = 1.0\n'
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
    },
    3: {
        'the first 8 training meshes': (
            'chosen = np.flatnonzero(~model.holdout_mask_)[:8]\n'
        ),
        'held-out meshes': (
            'chosen = np.flatnonzero(model.holdout_mask_)[:8]\n'
        ),
    },
}
