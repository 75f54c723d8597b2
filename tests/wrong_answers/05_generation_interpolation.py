"""Wrong answers to the exercises of notebook 05_generation_interpolation: each must make its self-check raise.

Keys are exercise numbers from 1; values map a short description to the code run in place of
the solution (tests/test_exercise_checks.py runs them)."""

_ROWS = (
    'ref = model.reference_vertices\n'
    'Xh = rimd_features(ref, held, coll.faces)\n'
    'Xt = rimd_features(ref, train, coll.faces)\n'
    '_, d_held = generation.nearest_neighbors(Xh, Xt)\n'
)

_GEN_PATH = (
    'zg = model.sample_latent(2, seed=1)\n'
    '_, gen_path = itp.LatentPath(model.decode_latent, zg[0], zg[1]).steps(N_STEPS)\n'
)


def _claimed(z_code: str) -> str:
    """z_new from ``z_code``, with the novelty and stretch its decoded mesh really has."""
    return (
        z_code
        + 'ref = model.reference_vertices\n'
        'Xt = rimd_features(ref, train, coll.faces)\n'
        '_, d_train = generation.nearest_neighbors(Xt, Xt, exclude_self=True)\n'
        'V1 = model.decode_latent(np.asarray(z_new, dtype=float))\n'
        '_, d1 = generation.nearest_neighbors(rimd_features(ref, V1[None], coll.faces), Xt)\n'
        'new_novelty = float(d1[0] / np.median(d_train))\n'
        'new_stretch = float(np.ravel(itp.edge_length_distortion(V1, coll.faces, train)[0])[0])\n'
    )


#: the training and held-out meshes named afresh, not through ``train`` and ``held``: a value computed
#: from them is the value printed earlier, pasted, and stays the same when the check runs the cell on other meshes
_PASTED_SETS = (
    '_T = coll.vertices[~model.holdout_mask_]\n'
    '_H = coll.vertices[model.holdout_mask_]\n'
)


WRONG_ANSWERS = {
    1: {
        'the forbidden call (the generated shapes)': 'held_novelty = gen.novelty_ratio()\n',
        'raw distances, not divided': _ROWS + 'held_novelty = d_held\n',
        'the mean instead of the median': (
            _ROWS + '_, d_train = generation.nearest_neighbors(Xt, Xt, exclude_self=True)\n'
            'held_novelty = d_held / np.mean(d_train)\n'),
        'training distances without exclude_self': (
            _ROWS + '_, d_train = generation.nearest_neighbors(Xt, Xt)\n'
            'with np.errstate(divide="ignore", invalid="ignore"):\n'
            '    held_novelty = d_held / np.median(d_train)\n'),
        'copied from an earlier output (the right novelties for these meshes, pasted as numbers)': (
            _PASTED_SETS + '_Xt = rimd_features(model.reference_vertices, _T, coll.faces)\n'
            '_, _dh = generation.nearest_neighbors(rimd_features(model.reference_vertices, _H, coll.faces), _Xt)\n'
            '_, _dt = generation.nearest_neighbors(_Xt, _Xt, exclude_self=True)\n'
            'held_novelty = np.array((_dh / np.median(_dt)).tolist())\n'),
        'the forbidden call on a result built for the held-out meshes': (
            _ROWS + 'from meshvae_lib.applications.generation import GenerationResult\n'
            '_, d_train = generation.nearest_neighbors(Xt, Xt, exclude_self=True)\n'
            'held_novelty = GenerationResult(latents=np.zeros((len(held), 1)), vertices=held, nearest=np.zeros(len(held), int),\n'
            '                                distance=d_held, dataset_nn_distance=d_train).novelty_ratio()\n'),
    },
    2: {
        'the data meshes\' latent path of section 3': 'gen_distortion = imp.edge_distortion["latent (ours)"].copy()\n',
        'the default seed': (
            'zg = model.sample_latent(2)\n'
            '_, gen_path = itp.LatentPath(model.decode_latent, zg[0], zg[1]).steps(N_STEPS)\n'
            'gen_distortion, _ = itp.edge_length_distortion(gen_path, coll.faces, train)\n'),
        'against the held-out meshes': _GEN_PATH + 'gen_distortion, _ = itp.edge_length_distortion(gen_path, coll.faces, held)\n',
        'copied from an earlier output (the right distortions for 7 steps, pasted as numbers)': (
            _PASTED_SETS + 'zg = model.sample_latent(2, seed=1)\n'
            '_, _P = itp.LatentPath(model.decode_latent, zg[0], zg[1]).steps(7)\n'
            'gen_distortion = np.array(itp.edge_length_distortion(_P, coll.faces, _T)[0].tolist())\n'),
    },
    3: {
        'a training mesh\'s own code': _claimed('z_new = model.encode_meshes(train[:1], inference="encoder")[0]\n'),
        'a draw scaled up to push the novelty': _claimed('z_new = 3 * model.sample_latent(1, seed=SEED + 1)[0]\n'),
        'numbers copied from the printout onto another draw': (
            'z_new = model.sample_latent(1, seed=SEED)[0]\n'
            'new_novelty, new_stretch = 1.91, 1.36 * float(np.median(stretch_held))\n'),
        'copied from an earlier output (the solution\'s z_new, novelty and stretch, pasted as numbers)': (
            _PASTED_SETS + '_Xt = rimd_features(model.reference_vertices, _T, coll.faces)\n'
            '_, _dt = generation.nearest_neighbors(_Xt, _Xt, exclude_self=True)\n'
            '_Z = model.sample_latent(200, seed=SEED + 1)\n'
            '_V = model.decode_latent(_Z)\n'
            '_, _dn = generation.nearest_neighbors(rimd_features(model.reference_vertices, _V, coll.faces), _Xt)\n'
            '_nov = _dn / np.median(_dt)\n'
            '_st = itp.edge_length_distortion(_V, coll.faces, _T)[0]\n'
            '_ok = np.flatnonzero((_nov >= 1.5) & (_st <= 1.5 * np.median(stretch_held)))\n'
            '_k = _ok[np.argmax(_nov[_ok])]\n'
            'z_new = np.array(_Z[_k].tolist())\n'
            'new_novelty, new_stretch = float(_nov[_k]), float(_st[_k])\n'),
    },
}
