"""Wrong answers to the exercises of notebook 01_deformation_gradients: each must make its self-check raise.

Keys are exercise numbers from 1; values map a short description to the code run in place of
the solution (tests/test_exercise_checks.py runs them)."""

WRONG_ANSWERS = {
    1: {
        'the mesh is never rotated': (
            'Q = so3_exp(np.array([0.3, -1.2, 2.0]))\n'
            'T_before = op(V1)\n'
            'T_after = Q @ T_before\n'
            'rigid_err = 0.0\n'
        ),
        'the mesh is moved but not measured': (
            'Q = so3_exp(np.array([0.3, -1.2, 2.0]))\n'
            'V_moved = V1 @ Q.T + np.array([1.0, 2.0, 3.0])\n'
            'T_before = op(V1)\n'
            'T_after = Q @ T_before\n'
            'rigid_err = 0.0\n'
        ),
        'rigid_err typed in from the failure message': (
            'Q = so3_exp(np.array([0.3, -1.2, 2.0]))\n'
            'V_moved = V1 @ Q.T + np.array([1.0, 2.0, 3.0])\n'
            'T_before, T_after = op(V1), op(V_moved)\n'
            'rigid_err = 1e-13\n'
        ),
    },
    2: {
        'library weights typed in from the printout': (
            'c_equilateral, c_square_diagonal = 2 / np.tan(np.pi / 3), 2 / np.tan(np.pi / 2)\n'
            'P_eq = np.array([[0.0, 0, 0], [1, 0, 0], [0.5, np.sqrt(3) / 2, 0], [0.5, -np.sqrt(3) / 2, 0]])\n'
            'P_sq = np.array([[0.0, 0, 0], [1, 1, 0], [0, 1, 0], [1, 0, 0]])\n'
            'pair = np.array([[0, 1, 2], [1, 0, 3]])\n'
            'lib_eq, lib_sq = 1.1547, 0.0\n'
        ),
        'the square is never built': (
            'c_equilateral, c_square_diagonal = 2 / np.tan(np.pi / 3), 2 / np.tan(np.pi / 2)\n'
            'P_eq = np.array([[0.0, 0, 0], [1, 0, 0], [0.5, np.sqrt(3) / 2, 0], [0.5, -np.sqrt(3) / 2, 0]])\n'
            'P_sq = P_eq.copy()\n'
            'pair = np.array([[0, 1, 2], [1, 0, 3]])\n'
            'lib_eq = float(cotangent_weights(P_eq, pair, clamp=False)[edge_index(edges(pair), 0, 1)])\n'
            'lib_sq = 0.0\n'
        ),
    },
    3: {
        "section 2's obtuse pair reused (not negative enough)": (
            'P3, T3 = P.copy(), T2.copy()\n'
            'c_neg = float(cotangent_weights(P3, T3, clamp=False)[edge_index(edges(T3), 0, 1)])\n'
        ),
        'the clamped weight instead of the raw one': (
            'P3 = np.array([[0.0, 0, 0], [2.0, 0, 0], [1.0, 0.05, 0], [1.0, -0.05, 0]])\n'
            'T3 = np.array([[0, 1, 2], [1, 0, 3]])\n'
            'c_neg = float(cotangent_weights(P3, T3)[edge_index(edges(T3), 0, 1)])\n'
        ),
        'a folded pair: both apexes on the same side of the edge': (
            'P3 = np.array([[0.0, 0, 0], [2.0, 0, 0], [1.0, 0.05, 0], [1.0, 0.1, 0]])\n'
            'T3 = np.array([[0, 1, 2], [1, 0, 3]])\n'
            'c_neg = float(cotangent_weights(P3, T3, clamp=False)[edge_index(edges(T3), 0, 1)])\n'
        ),
        'a folded pair whose faces are listed so that their normals agree': (
            'P3 = np.array([[0.0, 0, 0], [2.0, 0, 0], [1.0, 0.05, 0], [1.0, 0.1, 0]])\n'
            'T3 = np.array([[0, 1, 2], [0, 1, 3]])\n'
            'c_neg = float(cotangent_weights(P3, T3, clamp=False)[edge_index(edges(T3), 0, 1)])\n'
        ),
        'a weight below -5 typed in for a pair that does not have it': (
            'P3, T3 = P.copy(), T2.copy()\n'
            'c_neg = -19.95\n'
        ),
    },
}
