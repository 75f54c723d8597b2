"""Wrong answers to the exercises of notebook 09_evaluation: each must make its self-check raise.

Keys are exercise numbers from 1; values map a short description to the code run in place of
the solution (tests/test_exercise_checks.py runs them)."""

_PCA_BY_HAND = (
    'X = V_train.reshape(len(V_train), -1)\n'
    'mean = X.mean(axis=0)\n'
)

WRONG_ANSWERS = {
    1: {
        'copied from an earlier output (the mean floor printed in section 2, 1.1e-02, typed in for every mesh)': (
            'floor_mine = np.full(len(V_test), 1.1e-02)\n'
        ),
        "copied from an earlier output, exact (section 2's per-mesh floor pasted as numbers)": (
            "floor_mine = np.array([float(e) for e in floor['per_mesh']])\n"
        ),
        'every direction the training meshes span, not D': _PCA_BY_HAND + (
            'directions = np.linalg.svd(X - mean, full_matrices=False)[2]\n'
            'Y = V_test.reshape(len(V_test), -1) - mean\n'
            'floor_mine = per_vertex_error((mean + Y @ directions.T @ directions).reshape(V_test.shape), V_test)\n'
        ),
        'the coordinates not centred on their mean': _PCA_BY_HAND + (
            'directions = np.linalg.svd(X, full_matrices=False)[2][:D]\n'
            'Y = V_test.reshape(len(V_test), -1)\n'
            'floor_mine = per_vertex_error((Y @ directions.T @ directions).reshape(V_test.shape), V_test)\n'
        ),
        'no rigid alignment before measuring': _PCA_BY_HAND + (
            'directions = np.linalg.svd(X - mean, full_matrices=False)[2][:D]\n'
            'Y = V_test.reshape(len(V_test), -1) - mean\n'
            'projected = (mean + Y @ directions.T @ directions).reshape(V_test.shape)\n'
            'floor_mine = np.linalg.norm(projected - V_test, axis=-1).mean(axis=1)\n'
        ),
        'the forbidden library call (pca_baseline)': (
            "floor_mine = np.array(pca_baseline(V_train, V_test, n_components=D)['per_mesh'])\n"
        ),
        'the forbidden library call, imported again under another name (CoordinatePCA)': (
            'from meshvae_lib.model.evaluation import CoordinatePCA as Linear\n'
            'floor_mine = per_vertex_error(Linear(D).fit(V_train).reconstruct(V_test), V_test)\n'
        ),
        'the library PCA through a course helper (column_reconstructions, the fresh reader\'s bypass)': (
            'floor_mine = per_vertex_error(np.stack([column_reconstructions(m, V_train, D)["PCA on coordinates (floor)"]'
            ' for m in V_test]), V_test)\n'
        ),
        'the library PCA in one region (regional_pca_baseline, the fresh reader\'s bypass)': (
            'from meshvae_lib.model import regional_pca_baseline\n'
            'floor_mine = np.array(regional_pca_baseline(V_train, V_test, np.zeros(V_train.shape[1], int), D)["per_mesh"])\n'
        ),
        "scikit-learn's PCA": (
            'from sklearn.decomposition import PCA\n'
            'p = PCA(D, svd_solver="full").fit(V_train.reshape(len(V_train), -1))\n'
            'Y = p.inverse_transform(p.transform(V_test.reshape(len(V_test), -1)))\n'
            'floor_mine = per_vertex_error(Y.reshape(V_test.shape), V_test)\n'
        ),
        "scikit-learn's IncrementalPCA (one exact SVD at its default batch; the fresh reader's bypass)": (
            'from sklearn.decomposition import IncrementalPCA\n'
            'p = IncrementalPCA(D).fit(V_train.reshape(len(V_train), -1))\n'
            'Y = p.inverse_transform(p.transform(V_test.reshape(len(V_test), -1)))\n'
            'floor_mine = per_vertex_error(Y.reshape(V_test.shape), V_test)\n'
        ),
        "scikit-learn's TruncatedSVD on the centred rows (the fresh reader's bypass)": _PCA_BY_HAND + (
            'from sklearn.decomposition import TruncatedSVD\n'
            'directions = TruncatedSVD(D, algorithm="arpack").fit(X - mean).components_\n'
            'Y = V_test.reshape(len(V_test), -1) - mean\n'
            'floor_mine = per_vertex_error((mean + Y @ directions.T @ directions).reshape(V_test.shape), V_test)\n'
        ),
    },
    2: {
        'copied from an earlier output (the means printed in section 2 typed in for every mesh)': (
            'err_encoder = np.full(len(meshes), 1.2e-02)\n'
            'err_gn = np.full(len(meshes), 1.6e-03)\n'
        ),
        "copied from an earlier output, exact (section 2's per-mesh errors pasted as numbers)": (
            "err_encoder = np.array([float(e) for e in row['RIMD, encoder']['per_mesh']])\n"
            "err_gn = np.array([float(e) for e in row['RIMD, gauss-newton']['per_mesh']])\n"
        ),
        'no rigid alignment before measuring': (
            "err_encoder = np.linalg.norm(model.reconstruct(meshes, inference='encoder') - meshes, axis=-1).mean(axis=1)\n"
            "err_gn = np.linalg.norm(model.reconstruct(meshes, inference='gauss-newton') - meshes, axis=-1).mean(axis=1)\n"
        ),
        'the encoder for both': (
            "rec_encoder = rigid_align(model.reconstruct(meshes, inference='encoder'), meshes)\n"
            'err_encoder = np.linalg.norm(rec_encoder - meshes, axis=-1).mean(axis=1)\n'
            'err_gn = err_encoder.copy()\n'
        ),
        'the root mean square distance, not the mean': (
            "rec_encoder = rigid_align(model.reconstruct(meshes, inference='encoder'), meshes)\n"
            "rec_gn = rigid_align(model.reconstruct(meshes, inference='gauss-newton'), meshes)\n"
            'err_encoder = np.sqrt(((rec_encoder - meshes) ** 2).sum(axis=-1).mean(axis=1))\n'
            'err_gn = np.sqrt(((rec_gn - meshes) ** 2).sum(axis=-1).mean(axis=1))\n'
        ),
        'the forbidden library call (evaluate_model)': (
            "err_encoder = np.array(evaluate_model(model, coll, indices=held, inference='encoder')['per_mesh'])\n"
            "err_gn = np.array(evaluate_model(model, coll, indices=held, inference='gauss-newton')['per_mesh'])\n"
        ),
        'the forbidden library call (per_vertex_error)': (
            "err_encoder = per_vertex_error(model.reconstruct(meshes, inference='encoder'), meshes)\n"
            "err_gn = per_vertex_error(model.reconstruct(meshes, inference='gauss-newton'), meshes)\n"
        ),
        'the forbidden library call, reached through a module that imported it (per_vertex_error)': (
            'from meshvae_lib.applications import exploration\n'
            "err_encoder = exploration.per_vertex_error(model.reconstruct(meshes, inference='encoder'), meshes)\n"
            "err_gn = exploration.per_vertex_error(model.reconstruct(meshes, inference='gauss-newton'), meshes)\n"
        ),
    },
}
