"""Wrong answers to the exercises of notebook 00_tour: each must make its self-check raise.

Keys are exercise numbers from 1; values map a short description to the code run in place of
the solution (tests/test_exercise_checks.py runs them)."""

WRONG_ANSWERS = {
    1: {
        'every collection taken for a closed genus-0 surface': (
            'paper_is_closed_genus0 = (7500 == 3 * 2502 - 6)\n'
            'chi = {name: 2 for name in gallery}\n'
        ),
        'directed edges counted (each edge twice)': (
            'paper_is_closed_genus0 = (7500 == 3 * 2502 - 6)\n'
            'chi = {name: c.vertices.shape[1] - 2 * len(edges(c.faces)) + len(c.faces) for name, (c, _) in gallery.items()}\n'
        ),
        'the paper check without the -6 (|E| = 3n)': (
            'paper_is_closed_genus0 = (7500 == 3 * 2502)\n'
            'chi = {name: c.vertices.shape[1] - len(edges(c.faces)) + len(c.faces) for name, (c, _) in gallery.items()}\n'
        ),
    },
    2: {
        "the first jack's top, as if the twelve jacks were copies": (
            'dist = np.linalg.norm(col.vertices - col.vertices[0], axis=-1)\n'
            'peak = first_argmax(dist[:10].mean(axis=1))\n'
            'busiest = first_argmax(dist.max(axis=0))\n'
        ),
        'the frame the player was set to, copied from the output': (
            'dist = np.linalg.norm(col.vertices - col.vertices[0], axis=-1)\n'
            'peak = M // 2\n'
            'busiest = first_argmax(dist.max(axis=0))\n'
        ),
        'peak by the farthest single vertex instead of the mean': (
            'dist = np.linalg.norm(col.vertices - col.vertices[0], axis=-1)\n'
            'peak = first_argmax(dist.max(axis=1))\n'
            'busiest = first_argmax(dist.max(axis=0))\n'
        ),
        'busiest measured in the middle frame only': (
            'dist = np.linalg.norm(col.vertices - col.vertices[0], axis=-1)\n'
            'peak = first_argmax(dist.mean(axis=1))\n'
            'busiest = int(np.argmax(dist[M // 2]))\n'
        ),
    },
    3: {
        'the measure after rigid alignment (the follow-up question, not the task)': (
            'from meshvae_lib.geometry.alignment import bounding_box_diagonal, rigid_align\n'
            'moves = {name: np.linalg.norm(rigid_align(c.vertices, c.vertices[0]) - c.vertices[0], axis=-1).mean(axis=1)\n'
            '         / bounding_box_diagonal(c.vertices[0]) for name, (c, _) in gallery.items()}\n'
            'name_far = max(moves, key=lambda n: moves[n].max())\n'
            'farthest = (name_far, first_argmax(moves[name_far]))\n'
            'how_far = float(moves[name_far].max())\n'
        ),
        'the printed percentage typed in': (
            'farthest = ("dyna", 11)\n'
            'how_far = 2.012\n'
        ),
        'the largest single-vertex distance instead of the mean': (
            'from meshvae_lib.geometry.alignment import bounding_box_diagonal\n'
            'moves = {name: np.linalg.norm(c.vertices - c.vertices[0], axis=-1).max(axis=1) / bounding_box_diagonal(c.vertices[0])\n'
            '         for name, (c, _) in gallery.items()}\n'
            'name_far = max(moves, key=lambda n: moves[n].max())\n'
            'farthest = (name_far, first_argmax(moves[name_far]))\n'
            'how_far = float(moves[name_far].max())\n'
        ),
    },
}
