"""Wrong answers to the exercises of notebook 10_local_parts: each must make its self-check raise.

Keys are exercise numbers from 1; values map a short description to the code run in place of
the solution (tests/test_exercise_checks.py runs them)."""

WRONG_ANSWERS = {
    1: {
        'the local model with its default regions': (
            'two = local\n'
            "err_two = evaluate_model(two, coll, indices=held)['mean_vertex_error']\n"
        ),
        'two regions but the latent size left at its default for 2 regions (16)': (
            'two = MeshVAEModel("rimd", TrainConfig(architecture="local-parts", latent_dim=16, network_options={"n_regions": 2},\n'
            '                                       seed=SEED, device="cpu", progress=False), holdout_every=HOLDOUT_EVERY).fit(coll)\n'
            "err_two = evaluate_model(two, coll, indices=held)['mean_vertex_error']\n"
        ),
        'the error copied from the local model': (
            'two = MeshVAEModel("rimd", TrainConfig(architecture="local-parts", latent_dim=LATENT, network_options={"n_regions": 2},\n'
            '                                       seed=SEED, device="cpu", progress=False), holdout_every=HOLDOUT_EVERY).fit(coll)\n'
            "err_two = errors['local parts']\n"
        ),
        'measured on every mesh, training ones included': (
            'two = MeshVAEModel("rimd", TrainConfig(architecture="local-parts", latent_dim=LATENT, network_options={"n_regions": 2},\n'
            '                                       seed=SEED, device="cpu", progress=False), holdout_every=HOLDOUT_EVERY).fit(coll)\n'
            "err_two = evaluate_model(two, coll, held_out_only=False)['mean_vertex_error']\n"
        ),
    },
    2: {
        'mesh b unchanged': (
            'hand_mixed = local.decode_latent(codes[b])\n'
        ),
        'the regions swapped (region 0 from b, the rest from a)': (
            'mine = codes[a].copy()\n'
            'dims0 = net.latent_region.numpy() == 0\n'
            'mine[dims0] = codes[b][dims0]\n'
            'hand_mixed = local.decode_latent(mine)\n'
        ),
        'the codes averaged': (
            'hand_mixed = local.decode_latent((codes[a] + codes[b]) / 2)\n'
        ),
    },
}
