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
        'the error copied from an earlier output (the 2 regions line printed by the solution, 2.8e-04)': (
            'two = MeshVAEModel("rimd", TrainConfig(architecture="local-parts", latent_dim=LATENT, network_options={"n_regions": 2},\n'
            '                                       seed=SEED, device="cpu", progress=False), holdout_every=HOLDOUT_EVERY).fit(coll)\n'
            'err_two = 2.8e-04\n'
        ),
        'the model stored under another name than two (the exercise names it)': (
            'm2 = MeshVAEModel("rimd", TrainConfig(architecture="local-parts", latent_dim=LATENT, network_options={"n_regions": 2},\n'
            '                                      seed=SEED, device="cpu", progress=False), holdout_every=HOLDOUT_EVERY).fit(coll)\n'
            "err_two = evaluate_model(m2, coll, indices=held)['mean_vertex_error']\n"
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
        'pasted vertices of the two meshes (region 0 of a on the rest of b, nothing decoded)': (
            'hand_mixed = train[b].copy()\n'
            'hand_mixed[net.vertex_region.numpy() == 0] = train[a][net.vertex_region.numpy() == 0]\n'
        ),
        'copied from an earlier output (the right mesh for this pair, pasted as numbers)': (
            '# the numbers do not change when the cell runs on another pair: the right mesh of meshes 0 and the\n'
            '# farthest from it, computed elsewhere and pasted in\n'
            'hand_mixed = np.array(local.decode_latent(np.where(net.latent_region.numpy() == 0, codes[0],\n'
            '                      codes[int(np.argmax(np.linalg.norm(codes - codes[0], axis=1)))])).tolist())\n'
        ),
        'the mixed mesh of section 5 copied': (
            'hand_mixed = mixed.copy()\n'
        ),
        'region 0 from a pasted onto the decoded mesh b': (
            'hand_mixed = local.decode_latent(codes[b])\n'
            'hand_mixed[net.vertex_region.numpy() == 0] = local.decode_latent(codes[a])[net.vertex_region.numpy() == 0]\n'
        ),
        'the forbidden library call (parts_code builds the mix)': (
            'hand_mixed = local.decode_latent(parts_code(codes, net.latent_region.numpy(), [[a] + [b] * (REGIONS - 1)]))[0]\n'
        ),
        'the forbidden library call, imported again under another name': (
            'from meshvae_lib.applications.generation import parts_code as mix_by_regions\n'
            'hand_mixed = local.decode_latent(mix_by_regions(codes, net.latent_region.numpy(), [[a] + [b] * (REGIONS - 1)]))[0]\n'
        ),
    },
}
