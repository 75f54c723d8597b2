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
        'copied from an earlier output (the printed bound < 1e-10 typed in as 0)': (
            'Q = so3_exp(np.array([0.3, -1.2, 2.0]))\n'
            'V_moved = V1 @ Q.T + np.array([1.0, 2.0, 3.0])\n'
            'T_before, T_after = op(V1), op(V_moved)\n'
            'rigid_err = 0.0\n'
        ),
        'Q left out of the difference': (
            'Q = so3_exp(np.array([0.3, -1.2, 2.0]))\n'
            'V_moved = V1 @ Q.T + np.array([1.0, 2.0, 3.0])\n'
            'T_before, T_after = op(V1), op(V_moved)\n'
            'rigid_err = float(np.abs(T_after - T_before).max())\n'
        ),
        'the gradients of Eq. (1) alone (op_pure) instead of the default op': (
            'Q = so3_exp(np.array([0.3, -1.2, 2.0]))\n'
            'V_moved = V1 @ Q.T + np.array([1.0, 2.0, 3.0])\n'
            'T_before, T_after = op_pure(V1), op_pure(V_moved)\n'
            'rigid_err = float(np.abs(T_after - Q @ T_before).max())\n'
        ),
        'Q typed in as a matrix (so3_exp not used in the cell)': (
            'Q = np.array([[-0.6761172459106027, -0.7150638736881626, -0.17762073732630712],\n'
            '              [0.4932248264352887, -0.2601690323114642, -0.8300851433521718],\n'
            '              [0.5473524827477636, -0.6488418383336542, 0.528592024587643]])\n'
            'V_moved = V1 @ Q.T + np.array([1.0, 2.0, 3.0])\n'
            'T_before, T_after = op(V1), op(V_moved)\n'
            'rigid_err = float(np.abs(T_after - Q @ T_before).max())\n'
        ),
    },
    2: {
        'copied from an earlier output (1.1547 and 0 as printed)': 'c_hand = np.array([1.1547, 0.0])\n',
        'the exact values typed in (2 / sqrt(3) and 0)': 'c_hand = np.array([2 / np.sqrt(3), 0.0])\n',
        "the library's weights stored as the hand values (the forbidden call; reader round 3)": (
            'c_hand = np.array([cotangent_weights(X_, pair, clamp=False)[edge_index(edges(pair), 0, 1)] for X_ in pairs])\n'
        ),
        'the library imported again inside the cell (the forbidden call)': (
            'from meshvae_lib.geometry.cotangent import cotangent_weights as _cw\n'
            'c_hand = np.array([_cw(X_, pair, clamp=False)[edge_index(edges(pair), 0, 1)] for X_ in pairs])\n'
        ),
        "the library's corner cotangents summed over the two apexes (reader round 4)": (
            'from meshvae_lib.geometry.cotangent import corner_cotangents\n'
            'c_hand = np.array([corner_cotangents(X_, pair)[0, 2] + corner_cotangents(X_, pair)[1, 2] for X_ in pairs])\n'
        ),
        "the raw weights of a DeformationGradientOperator built on each pair (reader round 4)": (
            'c_hand = np.array([DeformationGradientOperator(X_, pair, clamp=False).weights[edge_index(edges(pair), 0, 1)]\n'
            '                   for X_ in pairs])\n'
        ),
        "the library's weights through the package's top-level export": (
            'import meshvae_lib\n'
            'c_hand = np.array([meshvae_lib.cotangent_weights(X_, pair, clamp=False)[edge_index(edges(pair), 0, 1)]\n'
            '                   for X_ in pairs])\n'
        ),
        'the cotangent of one apex only': (
            'c_hand = np.array([(X_[0] - X_[2]) @ (X_[1] - X_[2]) / np.linalg.norm(np.cross(X_[0] - X_[2], X_[1] - X_[2]))\n'
            '                   for X_ in pairs])\n'
        ),
        "the one-ring figure's apex angles, their cotangents taken by hand (reader round 5)": (
            'from meshvae_lib.viewing.one_ring_figure import _angle\n'
            'c_hand = np.array([1 / np.tan(_angle(X_[2], X_[0], X_[1])) + 1 / np.tan(_angle(X_[3], X_[0], X_[1])) for X_ in pairs])\n'
        ),
        'cosines instead of cotangents': (
            'c_hand = np.array([sum((X_[0] - X_[k]) @ (X_[1] - X_[k]) / np.linalg.norm(X_[0] - X_[k]) / np.linalg.norm(X_[1] - X_[k])\n'
            '                       for k in (2, 3)) for X_ in pairs])\n'
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
        'copied from an earlier output (-19.95 as printed), for a pair that does not have it': (
            'P3, T3 = P.copy(), T2.copy()\n'
            'c_neg = -19.95\n'
        ),
    },
}
