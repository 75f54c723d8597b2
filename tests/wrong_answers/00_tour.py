"""Wrong answers to the exercises of notebook 00_tour: each must make its self-check raise.

Keys are exercise numbers from 1; values map a short description to the code run in place of
the solution (tests/test_exercise_checks.py runs them)."""

_CHI = ('chi = {name: c.vertices.shape[1] - len(edges(c.faces)) + len(c.faces) '
        'for name, (c, _) in gallery.items()}\n')
_PAPER = 'paper_counts_fit_genus0 = bool(edges_paper == 3 * n_paper - 6)\n'
_MOVES = ('from meshvae_lib.geometry.alignment import bounding_box_diagonal\n'
          'moves = {name: np.linalg.norm(c.vertices - c.vertices[0], axis=-1).mean(axis=1) / bounding_box_diagonal(c.vertices[0])\n'
          '         for name, (c, _) in gallery.items()}\n')

WRONG_ANSWERS = {
    1: {
        'every collection taken for a closed genus-0 surface': _PAPER + 'chi = {name: 2 for name in gallery}\n',
        'directed edges counted (each edge twice)': _PAPER + (
            'chi = {name: c.vertices.shape[1] - 2 * len(edges(c.faces)) + len(c.faces) for name, (c, _) in gallery.items()}\n'),
        'the paper check without the -6 (|E| = 3n)': 'paper_counts_fit_genus0 = bool(edges_paper == 3 * n_paper)\n' + _CHI,
        'typed constants: True, and chi 2 but for the flag (1) and the bar (0)': (
            'paper_counts_fit_genus0 = True\n'
            'chi = {n: 2 for n in gallery} | {"flag": 1, "bar": 0}\n'),
        "chi copied from an earlier output (the flag's one loop in the list, the bar's two in its title)": _PAPER + (
            'chi = {"scape": 2, "poses": 2, "dyna": 2, "jumping": 2, "flag": 1, "bar": 0, "hand": 2, "face": 2}\n'),
        'chi as 2 minus the boundary loops (one piece of genus 0 assumed)': _PAPER + (
            'chi = {name: 2 - len(boundary_loops(c.faces)) for name, (c, _) in gallery.items()}\n'),
        "the paper check typed from the paper's counts, not from n_paper and edges_paper": (
            'paper_counts_fit_genus0 = (7500 == 3 * 2502 - 6)\n' + _CHI),
        'the planar-graph bound |E| <= 3n - 6 instead of the equality': (
            'paper_counts_fit_genus0 = bool(edges_paper <= 3 * n_paper - 6)\n' + _CHI),
        'only that |F| = 2|E|/3 is a whole number (|E| a multiple of 3)': (
            'paper_counts_fit_genus0 = edges_paper % 3 == 0\n' + _CHI),
        "the paper check copied from an earlier output (the K line's 2502 and 7500)": (
            'paper_counts_fit_genus0 = 7500 == 3 * 2502 - 6 and n_paper > 0\n' + _CHI),
    },
    2: {
        "the first jack's top, as if the twelve jacks were copies": (
            'dist = np.linalg.norm(col.vertices - col.vertices[0], axis=-1)\n'
            'peak = first_argmax(dist[:10].mean(axis=1))\n'
            'busiest = first_argmax(dist.max(axis=0))\n'
        ),
        'the frame the player was set to, copied from an earlier output': (
            'dist = np.linalg.norm(col.vertices - col.vertices[0], axis=-1)\n'
            'peak = M // 2\n'
            'busiest = first_argmax(dist.max(axis=0))\n'
        ),
        "peak copied from an earlier output (the check's printout), busiest computed": (
            'dist = np.linalg.norm(col.vertices - col.vertices[0], axis=-1)\n'
            'peak = 103\n'
            'busiest = first_argmax(dist.max(axis=0))\n'
        ),
        'peak and busiest typed in': 'peak = 103\nbusiest = 1\n',
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
        'the printed answer and percentage, copied from an earlier output': (
            'farthest = ("dyna", 11)\n'
            'how_far = 2.012\n'
        ),
        'farthest copied from an earlier output, how_far computed for that one mesh': _MOVES + (
            'farthest = ("dyna", 11)\n'
            'how_far = float(moves["dyna"][11])\n'
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
