"""Wrong answers to the exercises of notebook 04_training: each must make its self-check raise.

Keys are exercise numbers from 1; values map a short description to the code run in place of
the solution (tests/test_exercise_checks.py runs them)."""

_EX1_RUN = (
    "train_idx = np.flatnonzero(~model.holdout_mask_)[:8]\n"
    "x = torch.as_tensor(model.features_of(col.vertices[train_idx]), dtype=torch.float32)\n"
    "net = model.network.eval()\n"
    "with torch.no_grad():\n"
    "    x_hat, mu, sigma = net(x, generator=torch.Generator().manual_seed(SEED))\n"
    "M, K = x.shape\n"
)

WRONG_ANSWERS = {
    1: {
        'zero tensors with sigma = 1': (
            'x = x_hat = mu = torch.zeros(8, 4)\n'
            'sigma = torch.ones(8, 4)\n'
            'rec_term = kl_term = 0.0\n'
        ),
        'the KL term summed over the 8 meshes instead of averaged': _EX1_RUN + (
            'rec_term = float(ALPHA / (2 * M * K) * ((x_hat - x) ** 2).sum())\n'
            'kl_term = float((0.5 * (sigma ** 2 + mu ** 2 - 1 - torch.log(sigma ** 2)).sum(dim=1)).sum())\n'
        ),
        'the reconstruction term without the 1/2': _EX1_RUN + (
            'rec_term = float(ALPHA * ((x_hat - x) ** 2).mean())\n'
            'kl_term = float((0.5 * (sigma ** 2 + mu ** 2 - 1 - torch.log(sigma ** 2)).sum(dim=1)).mean())\n'
        ),
        "the first 8 meshes of the collection (held-out mesh 4 among them)": (
            "x = torch.as_tensor(model.features_of(col.vertices[:8]), dtype=torch.float32)\n"
            "net = model.network.eval()\n"
            "with torch.no_grad():\n"
            "    x_hat, mu, sigma = net(x, generator=torch.Generator().manual_seed(SEED))\n"
            "rec_term = float(ALPHA / 2 * ((x_hat - x) ** 2).mean())\n"
            "kl_term = float((0.5 * (sigma ** 2 + mu ** 2 - 1 - torch.log(sigma ** 2)).sum(dim=1)).mean())\n"
        ),
    },
    2: {
        "the sweep's alpha 1e4 model, numbers copied from the table": (
            'model_1e3 = sweep[1e4]\n'
            'n_active, mean_sigma = 3, 0.729\n'
        ),
        "the sweep's alpha 1e4 model, counted correctly": (
            'model_1e3 = sweep[1e4]\n'
            "_, s = model_1e3.encode_meshes(train_V, return_sigma=True, inference='encoder')\n"
            'n_active, mean_sigma = int(np.sum(s.mean(axis=0) < 0.5)), float(s.mean())\n'
        ),
        "the library's defaults at alpha 1e3 (PCA start, early stopping)": (
            'model_1e3 = MeshVAEModel(features=FEATURES, holdout_every=HOLDOUT_EVERY, config=TrainConfig(\n'
            '    epochs=EPOCHS, latent_dim=LATENT, alpha=1e3, seed=SEED, progress=False)).fit(col)\n'
            "_, s = model_1e3.encode_meshes(train_V, return_sigma=True, inference='encoder')\n"
            'n_active, mean_sigma = int(np.sum(s.mean(axis=0) < 0.5)), float(s.mean())\n'
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
