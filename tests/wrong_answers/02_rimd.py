"""Wrong answers to the exercises of notebook 02_rimd: each must make its self-check raise.

Keys are exercise numbers from 1; values map a short description to the code run in place of
the solution (tests/test_exercise_checks.py runs them)."""

WRONG_ANSWERS = {
    1: {
        'S compared without the factor s': (
            's = 1.5\n'
            'f_scaled = enc.transform(s * V1)\n'
            'rot_change = float(np.abs(f_scaled[lay.rotation_slice] - f1[lay.rotation_slice]).max())\n'
            's_change = float(np.abs(f_scaled[lay.scaling_slice] - f1[lay.scaling_slice]).max())\n'
        ),
        'the reference scaled too': (
            's = 1.5\n'
            'f_scaled = RIMDEncoder(s * V0, F).transform(s * V1)\n'
            'rot_change = float(np.abs(f_scaled[lay.rotation_slice] - f1[lay.rotation_slice]).max())\n'
            's_change = float(np.abs(f_scaled[lay.scaling_slice] - s * f1[lay.scaling_slice]).max())\n'
        ),
        'the mesh shifted by s instead of scaled': (
            's = 1.5\n'
            'f_scaled = enc.transform(V1 + s)\n'
            'rot_change = float(np.abs(f_scaled[lay.rotation_slice] - f1[lay.rotation_slice]).max())\n'
            's_change = float(np.abs(f_scaled[lay.scaling_slice] - s * f1[lay.scaling_slice]).max())\n'
        ),
        'rotation and S changes typed in as zero (reader round 1)': (
            's = 1.5\n'
            'f_scaled = enc.transform(s * V1)\n'
            'rot_change = 0.0\n'
            's_change = 0.0\n'
        ),
        'the bound 1e-10 copied from an earlier output': (
            's = 1.5\n'
            'f_scaled = enc.transform(s * V1)\n'
            'rot_change = s_change = 1e-10\n'
        ),
        'the bound 1e-9 of the solution printout copied (reader round 2)': (
            's = 1.5\n'
            'f_scaled = enc.transform(s * V1)\n'
            'rot_change = s_change = 1e-9\n'
        ),
        'signed differences in the reversed order, f1 minus f_scaled, no abs (reader round 5)': (
            's = 1.5\n'
            'f_scaled = enc.transform(s * V1)\n'
            'rot_change = float((f1[lay.rotation_slice] - f_scaled[lay.rotation_slice]).max())\n'
            's_change = float((s * f1[lay.scaling_slice] - f_scaled[lay.scaling_slice]).max())\n'
        ),
        'rotation change as a signed difference in the reversed order, S change right (reader round 5)': (
            's = 1.5\n'
            'f_scaled = enc.transform(s * V1)\n'
            'rot_change = float((f1[lay.rotation_slice] - f_scaled[lay.rotation_slice]).max())\n'
            's_change = float(np.abs(f_scaled[lay.scaling_slice] - s * f1[lay.scaling_slice]).max())\n'
        ),
        'S change as a signed difference in the reversed order, rotation change right (reader round 5)': (
            's = 1.5\n'
            'f_scaled = enc.transform(s * V1)\n'
            'rot_change = float(np.abs(f_scaled[lay.rotation_slice] - f1[lay.rotation_slice]).max())\n'
            's_change = float((s * f1[lay.scaling_slice] - f_scaled[lay.scaling_slice]).max())\n'
        ),
        'signed differences in the natural order, f_scaled minus f1, no abs': (
            's = 1.5\n'
            'f_scaled = enc.transform(s * V1)\n'
            'rot_change = float((f_scaled[lay.rotation_slice] - f1[lay.rotation_slice]).max())\n'
            's_change = float((f_scaled[lay.scaling_slice] - s * f1[lay.scaling_slice]).max())\n'
        ),
    },
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
        'the poses of PAIR hard-coded (reader round 1)': (
            'Va, Vb = col.vertices[37], col.vertices[55]\n'
            "V_mid = rec['exact'].reconstruct(0.5 * (enc.transform(Va) + enc.transform(Vb)))\n"
            'V_lin = 0.5 * (Va + rigid_align(Vb, Va))\n'
            'L0 = np.linalg.norm(V0[E[:, 0]] - V0[E[:, 1]], axis=1)\n'
            'stretch_mid, stretch_lin = (float(np.mean(np.abs(np.linalg.norm(X[E[:, 0]] - X[E[:, 1]], axis=1) / L0 - 1))) for X in (V_mid, V_lin))\n'
        ),
        'the stretches copied from an earlier output': (
            'Va, Vb = col.vertices[PAIR[0]], col.vertices[PAIR[1]]\n'
            "V_mid = rec['exact'].reconstruct(0.5 * (enc.transform(Va) + enc.transform(Vb)))\n"
            'V_lin = 0.5 * (Va + rigid_align(Vb, Va))\n'
            'stretch_mid, stretch_lin = 0.029, 0.046\n'
        ),
    },
    3: {
        'the angle copied from section 3 (1e-8)': (
            'theta_bad = 1e-8\n'
            'R32 = so3_exp(theta_bad * axis).astype(np.float32)\n'
            'err_textbook = abs(float(np.arccos(np.clip((np.trace(R32) - 1) / 2, -1, 1))) - theta_bad)\n'
            'err_library = abs(float(np.linalg.norm(so3_log(R32))) - theta_bad)\n'
        ),
        'an angle next to pi (3.14159255)': (
            'theta_bad = 3.14159255\n'
            'R32 = so3_exp(theta_bad * axis).astype(np.float32)\n'
            'err_textbook = abs(float(np.arccos(np.clip((np.trace(R32) - 1) / 2, -1, 1))) - theta_bad)\n'
            'err_library = abs(float(np.linalg.norm(so3_log(R32))) - theta_bad)\n'
        ),
        'the errors of section 3 copied from an earlier output': (
            'theta_bad = 1e-8\n'
            'err_textbook, err_library = 1.0e-08, 1e-15\n'
        ),
        'float64 instead of float32': (
            'theta_bad = 2e-4\n'
            'R64 = so3_exp(theta_bad * axis)\n'
            'err_textbook = abs(float(np.arccos(np.clip((np.trace(R64) - 1) / 2, -1, 1))) - theta_bad)\n'
            'err_library = abs(float(np.linalg.norm(so3_log(R64))) - theta_bad)\n'
        ),
        'the textbook error typed as theta_bad, the library error as 0 (reader round 1)': (
            'theta_bad = 2e-4\n'
            'err_textbook = theta_bad\n'
            'err_library = 0.0\n'
        ),
        'the solution printout copied from an earlier output': (
            'theta_bad = 2e-4\n'
            'err_textbook, err_library = 2.0e-04, 1e-9\n'
        ),
        'the library error typed as 1/1000 of the printed textbook error (reader round 2)': (
            'theta_bad = 2e-4\n'
            'R32 = so3_exp(theta_bad * axis).astype(np.float32)\n'
            'err_textbook = abs(float(np.arccos(np.clip((np.trace(R32) - 1) / 2, -1, 1))) - theta_bad)\n'
            'err_library = 2.0e-04 / 1000\n'
        ),
        'so3_log of the float64 matrix, at 2.5e-4 (reader round 4)': (
            'theta_bad = 2.5e-4\n'
            'R32 = so3_exp(theta_bad * axis).astype(np.float32)\n'
            'err_textbook = abs(float(np.arccos(np.clip((np.trace(R32) - 1) / 2, -1, 1))) - theta_bad)\n'
            'err_library = abs(float(np.linalg.norm(so3_log(so3_exp(theta_bad * axis)))) - theta_bad)\n'
        ),
        'so3_log of the float64 matrix, at 1.1e-4 (reader round 4)': (
            'theta_bad = 1.1e-4\n'
            'R32 = so3_exp(theta_bad * axis).astype(np.float32)\n'
            'err_textbook = abs(float(np.arccos(np.clip((np.trace(R32) - 1) / 2, -1, 1))) - theta_bad)\n'
            'err_library = abs(float(np.linalg.norm(so3_log(so3_exp(theta_bad * axis)))) - theta_bad)\n'
        ),
        'the textbook formula in float64 arithmetic on the float32 matrix': (
            'theta_bad = 2e-4\n'
            'R32 = so3_exp(theta_bad * axis).astype(np.float32)\n'
            'err_textbook = abs(float(np.arccos(np.clip((np.trace(R32.astype(np.float64)) - 1) / 2, -1, 1))) - theta_bad)\n'
            'err_library = abs(float(np.linalg.norm(so3_log(R32))) - theta_bad)\n'
        ),
    },
}
