"""Wrong answers to the exercises of notebook 02_rimd: each must make its self-check raise.

Keys are exercise numbers from 1; values map a short description to the code run in place of
the solution (tests/test_exercise_checks.py runs them)."""

WRONG_ANSWERS = {
    2: {
        'V_lin is the feature midpoint': (
            'Va, Vb = col.vertices[PAIR[0]], col.vertices[PAIR[1]]\n'
            "V_mid = rec['exact'].reconstruct(0.5 * (enc.transform(Va) + enc.transform(Vb)))\n"
            'V_lin = V_mid.copy()\n'
            'L0 = np.linalg.norm(V0[E[:, 0]] - V0[E[:, 1]], axis=1)\n'
            'stretch_mid = stretch_lin = float(np.mean(np.abs(np.linalg.norm(V_mid[E[:, 0]] - V_mid[E[:, 1]], axis=1) / L0 - 1)))\n'
        ),
        'the two poses of the first attempt': (
            'Va, Vb = col.vertices[poses[0]], col.vertices[poses[2]]\n'
            "V_mid = rec['exact'].reconstruct(0.5 * (enc.transform(Va) + enc.transform(Vb)))\n"
            'V_lin = 0.5 * (Va + rigid_align(Vb, Va))\n'
            'L0 = np.linalg.norm(V0[E[:, 0]] - V0[E[:, 1]], axis=1)\n'
            'stretch_mid, stretch_lin = (float(np.mean(np.abs(np.linalg.norm(X[E[:, 0]] - X[E[:, 1]], axis=1) / L0 - 1))) for X in (V_mid, V_lin))\n'
        ),
        'stretch as the vertex average': (
            'Va, Vb = col.vertices[PAIR[0]], col.vertices[PAIR[1]]\n'
            "V_mid = rec['exact'].reconstruct(0.5 * (enc.transform(Va) + enc.transform(Vb)))\n"
            'V_lin = 0.5 * (Va + rigid_align(Vb, Va))\n'
            'stretch_mid, stretch_lin = (float(vertex_edge_stretch(X, V0, F).mean()) for X in (V_mid, V_lin))\n'
        ),
    },
}
