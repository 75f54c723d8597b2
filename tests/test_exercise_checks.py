"""Every exercise's self-check fails on a trivial answer, and on the wrong answers known to fool it.

For each notebook, :func:`~meshvae_lib.course.notebooks.trivial_answer_notebook` gives the names
each solution binds three trivial answers in turn -- left unchanged (undefined, or the value they
had before the exercise), ``None``, and zeros of the real answer's type and shape --, then runs
each named wrong answer of :data:`WRONG_ANSWERS` in place of the solution; it runs the self-check
on each, then restores the real answer. The notebook is executed once (the course models come
from the cache, as for nbval), and every self-check must raise on every one of them.
"""

from __future__ import annotations

from pathlib import Path

import nbformat
import pytest

from meshvae_lib.course.notebooks import (TRIVIAL_ANSWERS, solution_names, trivial_answer_notebook,
                                          trivial_answer_outcomes)

NOTEBOOK_DIR = Path(__file__).resolve().parents[1] / "notebooks"
NOTEBOOKS = sorted(NOTEBOOK_DIR.glob("[0-9][0-9]_*.ipynb"))

#: (notebook stem, exercise number from 1) -> {name: code run in place of the solution}: one-line
#: wrong answers that self-checks accepted, each of which its self-check must now reject.
WRONG_ANSWERS = {
    ("01_deformation_gradients", 1): {
        "the mesh is never rotated": (
            "Q = so3_exp(np.array([0.3, -1.2, 2.0]))\n"
            "T_before = op(V1)\n"
            "T_after = Q @ T_before\n"
            "rigid_err = 0.0\n"),
        "the mesh is moved but not measured": (
            "Q = so3_exp(np.array([0.3, -1.2, 2.0]))\n"
            "V_moved = V1 @ Q.T + np.array([1.0, 2.0, 3.0])\n"
            "T_before = op(V1)\n"
            "T_after = Q @ T_before\n"
            "rigid_err = 0.0\n"),
    },
    ("01_deformation_gradients", 2): {
        "library weights typed in from the printout": (
            "c_equilateral, c_square_diagonal = 2 / np.tan(np.pi / 3), 2 / np.tan(np.pi / 2)\n"
            "P_eq = np.array([[0.0, 0, 0], [1, 0, 0], [0.5, np.sqrt(3) / 2, 0], [0.5, -np.sqrt(3) / 2, 0]])\n"
            "P_sq = np.array([[0.0, 0, 0], [1, 1, 0], [0, 1, 0], [1, 0, 0]])\n"
            "pair = np.array([[0, 1, 2], [1, 0, 3]])\n"
            "lib_eq, lib_sq = 1.1547, 0.0\n"),
        "the square is never built": (
            "c_equilateral, c_square_diagonal = 2 / np.tan(np.pi / 3), 2 / np.tan(np.pi / 2)\n"
            "P_eq = np.array([[0.0, 0, 0], [1, 0, 0], [0.5, np.sqrt(3) / 2, 0], [0.5, -np.sqrt(3) / 2, 0]])\n"
            "P_sq = P_eq.copy()\n"
            "pair = np.array([[0, 1, 2], [1, 0, 3]])\n"
            "lib_eq = float(cotangent_weights(P_eq, pair, clamp=False)[edge_index(edges(pair), 0, 1)])\n"
            "lib_sq = 0.0\n"),
    },
    ("02_rimd", 2): {
        "V_lin is the feature midpoint": (
            "Va, Vb = col.vertices[PAIR[0]], col.vertices[PAIR[1]]\n"
            "V_mid = rec['exact'].reconstruct(0.5 * (enc.transform(Va) + enc.transform(Vb)))\n"
            "V_lin = V_mid.copy()\n"
            "L0 = np.linalg.norm(V0[E[:, 0]] - V0[E[:, 1]], axis=1)\n"
            "stretch_mid = stretch_lin = float(np.mean(np.abs(np.linalg.norm(V_mid[E[:, 0]] - V_mid[E[:, 1]], axis=1) / L0 - 1)))\n"),
        "the two poses of the first attempt": (
            "Va, Vb = col.vertices[poses[0]], col.vertices[poses[2]]\n"
            "V_mid = rec['exact'].reconstruct(0.5 * (enc.transform(Va) + enc.transform(Vb)))\n"
            "V_lin = 0.5 * (Va + rigid_align(Vb, Va))\n"
            "L0 = np.linalg.norm(V0[E[:, 0]] - V0[E[:, 1]], axis=1)\n"
            "stretch_mid, stretch_lin = (float(np.mean(np.abs(np.linalg.norm(X[E[:, 0]] - X[E[:, 1]], axis=1) / L0 - 1)))"
            " for X in (V_mid, V_lin))\n"),
        "stretch as the vertex average": (
            "Va, Vb = col.vertices[PAIR[0]], col.vertices[PAIR[1]]\n"
            "V_mid = rec['exact'].reconstruct(0.5 * (enc.transform(Va) + enc.transform(Vb)))\n"
            "V_lin = 0.5 * (Va + rigid_align(Vb, Va))\n"
            "stretch_mid, stretch_lin = (float(vertex_edge_stretch(X, V0, F).mean()) for X in (V_mid, V_lin))\n"),
    },
    ("03_normalization", 2): {
        "margin typed in from the text": (
            "f_top = norm.inverse_transform(np.ones((1, X.shape[1])))[0]\n"
            "margin = 1 / 18\n"),
        "f_top is the training maximum": (
            "f_top = X.max(axis=0)\n"
            "margin = np.full(X.shape[1], 1 / 18)\n"),
    },
    ("04_training", 1): {
        "zero tensors with sigma = 1": (
            "x = x_hat = mu = torch.zeros(8, 4)\n"
            "sigma = torch.ones(8, 4)\n"
            "rec_term = kl_term = 0.0\n"),
    },
    ("04_training", 3): {
        "a threshold typed in from the text": "alpha_off = np.full(LATENT, 1e3)\n",
        "sigma = 1/sqrt(2) instead of 0.5 (K / c^2)": (
            "c_paper = decoder_column_norms(model.network, model.encode_meshes(train_V, inference='encoder')).mean(axis=0)\n"
            "alpha_off = model.n_features / c_paper ** 2\n"),
        "column norms at the held-out meshes": (
            "c_paper = decoder_column_norms(model.network, model.encode_meshes(col.vertices[held_out], inference='encoder')).mean(axis=0)\n"
            "alpha_off = 3 * model.n_features / c_paper ** 2\n"),
    },
    ("07_sigma_object_embeddings", 1): {
        "the check's own expression": "gap = exact - sibling\n",
        "the total split evenly": "gap = torch.full((3,), (exact - sibling) / 3)\n",
    },
    ("07_sigma_object_embeddings", 2): {
        "only pair (1, 2) right": (
            "pair_auc = np.r_[curves['σ_object VAE (ours)'].auc['mean'], np.full(LATENT // 2 - 1, 0.5)]\n"),
        "overlapping pairs (1, 2), (2, 3), ...": (
            "pair_auc = np.array([ret.retrieval_auc(Z[median_seed][:, i:i + 2], labels) for i in range(LATENT // 2)])\n"),
    },
    ("08_exploration", 1): {
        "strength [1, 1, 1, 1, 0, ...]": "strength = np.r_[np.ones(4), np.zeros(LATENT - 4)]\n",
        "only the four dimensions of section 4 swept": (
            "strength = np.r_[np.abs(effects.effect).max(axis=1), np.zeros(LATENT - 4)]\n"),
    },
    ("09_evaluation", 1): {
        "the floor copied from the table": (
            "pca_err = rows['jumping']['ours aligned']\n"
            "rimd_over_pca = rows['jumping']['ours rimd'] / pca_err\n"),
        "a floor of zero": "pca_err = 0.0\nrimd_over_pca = float('inf')\n",
    },
    ("09_evaluation", 3): {
        "the threshold applied to the learned errors": (
            "floor_rel = {name: rows[name]['ours rimd'] for name in rows}\n"
            "informative = [name for name in rows if floor_rel[name] >= 1e-4]\n"),
        "absolute floors, not relative to the diagonal": (
            "floor_rel = {}\n"
            "for name in rows:\n"
            "    coll = paper.load_collection(name, full.settings)\n"
            "    held = holdout_mask(len(coll.vertices), full.settings.holdout_every)\n"
            "    floor_rel[name] = float(pca_baseline(coll.vertices[~held], coll.vertices[held])['mean_vertex_error'])\n"
            "informative = [name for name in rows if floor_rel[name] >= 1e-4]\n"),
    },
    ("10_bring_your_own", 1): {
        "any three meshes of the data": (
            "column = next(iter(coll.labels))\n"
            "value = sorted(set(coll.labels[column]))[0]\n"
            "cond = MeshVAEModel('rimd', config, labels=(column,), layout='compact').fit(coll)\n"
            "cond_meshes = coll.vertices[:3]\n"),
    },
    ("10_bring_your_own", 2): {
        "err_shuffled = 1.0": (
            "rng = np.random.default_rng(SEED)\n"
            "Vs = coll.vertices[1][rng.permutation(coll.n_vertices)]\n"
            "shuffled = collection.MeshCollection(Vs[None], coll.faces, ['shuffled'], {})\n"
            "err_shuffled = 1.0\n"),
    },
}


def wrong_answers_of(stem: str) -> dict[int, dict[str, str]]:
    """The named wrong answers of one notebook, by exercise number."""
    return {exercise: answers for (nb_stem, exercise), answers in WRONG_ANSWERS.items() if nb_stem == stem}


def test_solution_names_are_the_global_bindings():
    src = ("x = 1\n### BEGIN SOLUTION\na, (b, c) = 1, (2, 3)\nfor i in range(2):\n    inner = i\n"
           "total += 1\nwith open('f') as fh:\n    pass\ndef helper():\n    hidden = 1\n"
           "sq = [k * k for k in range(3)]\nf = lambda u: u\nif a:\n    late = 2\nimport os.path\n"
           "### END SOLUTION\ny = 2\n")
    assert solution_names(src) == ["a", "b", "c", "i", "inner", "total", "fh", "helper", "sq", "f", "late"]


def test_the_trivial_answer_notebook_wraps_each_exercise():
    nb = nbformat.v4.new_notebook(cells=[
        nbformat.v4.new_code_cell("start = 5"),
        nbformat.v4.new_code_cell("### BEGIN SOLUTION\nanswer = start * 2\n### END SOLUTION"),
        nbformat.v4.new_markdown_cell("check:"),
        nbformat.v4.new_code_cell("assert answer == 10"),
    ])
    out, exercises = trivial_answer_notebook(nb)
    assert exercises == [(1, ["answer"])]
    assert [c.cell_type for c in out.cells] == ["code", "code", "code", "code", "markdown", "code"]
    assert "assert answer == 10" in out.cells[3].source and "TRIVIAL-ANSWER-OUTCOMES" in out.cells[3].source
    ns, printed = _run_cells(out)
    line = [p for p in printed if "TRIVIAL" in p][-1]
    assert '"unchanged": "NameError"' in line and '"None": "AssertionError"' in line and '"zeros": "AssertionError"' in line
    assert ns["answer"] == 10, "the real answer is restored for the rest of the notebook"


def _run_cells(nb) -> tuple[dict, list[str]]:
    import contextlib
    import io

    ns, printed = {}, []
    for cell in nb.cells:
        if cell.cell_type == "code":
            buf = io.StringIO()
            with contextlib.redirect_stdout(buf):
                exec(cell.source, ns)
            printed.append(buf.getvalue())
    return ns, printed


def test_the_trivial_answer_notebook_tries_named_wrong_answers():
    nb = nbformat.v4.new_notebook(cells=[
        nbformat.v4.new_code_cell("start = 5"),
        nbformat.v4.new_code_cell("### BEGIN SOLUTION\nanswer = start * 2\n### END SOLUTION"),
        nbformat.v4.new_code_cell("assert answer == 2 * start"),
        nbformat.v4.new_code_cell("### BEGIN SOLUTION\nsquare = answer ** 2\n### END SOLUTION"),
        nbformat.v4.new_code_cell("assert square > 0"),
    ])
    wrong = {1: {"typed in": "answer = 10\nscratch = 1", "tripled": "answer = start * 3", "broken": "answer = nope"},
             2: {"negative": "square = -answer"}}
    out, exercises = trivial_answer_notebook(nb, wrong_answers=wrong)
    assert exercises == [(1, ["answer"]), (3, ["square"])]
    ns, printed = _run_cells(out)
    outcomes = trivial_answer_outcomes(nbformat.v4.new_notebook(cells=[
        nbformat.v4.new_code_cell(outputs=[nbformat.v4.new_output("stream", name="stdout", text=text)]) for text in printed]))
    assert outcomes[0] == {"unchanged": "NameError", "None": "AssertionError", "zeros": "AssertionError",
                           "typed in": "passed", "tripled": "AssertionError",
                           "broken": "the wrong answer itself raised NameError"}
    assert outcomes[1] == {"unchanged": "NameError", "None": "TypeError", "zeros": "AssertionError",
                           "negative": "AssertionError"}
    assert ns["answer"] == 10 and ns["square"] == 100, "the real answers are restored"
    assert "scratch" not in ns, "names a wrong answer adds are removed"
    with pytest.raises(ValueError, match="exercises \\[3\\]"):
        trivial_answer_notebook(nb, wrong_answers={3: {"x": "pass"}})
    with pytest.raises(ValueError, match="trivial answers' names"):
        trivial_answer_notebook(nb, wrong_answers={1: {"None": "answer = None"}})


def test_every_wrong_answer_names_an_existing_exercise():
    for (stem, exercise), answers in WRONG_ANSWERS.items():
        path = NOTEBOOK_DIR / f"{stem}.ipynb"
        assert path.exists(), stem
        assert answers and not set(answers) & set(TRIVIAL_ANSWERS), (stem, exercise)
        trivial_answer_notebook(nbformat.read(path, as_version=4), wrong_answers={exercise: answers})


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_every_self_check_raises_on_trivial_and_known_wrong_answers(path):
    from nbclient import NotebookClient

    wrong = wrong_answers_of(path.stem)
    nb, exercises = trivial_answer_notebook(nbformat.read(path, as_version=4), wrong_answers=wrong)
    assert len(exercises) >= 2, f"{path.stem} has {len(exercises)} exercise(s)"
    NotebookClient(nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(NOTEBOOK_DIR)}}).execute()
    outcomes = trivial_answer_outcomes(nb)
    assert len(outcomes) == len(exercises)
    accepted = []   # (exercise, solution cell, answer names, answer, outcome)
    for number, ((cell, names), o) in enumerate(zip(exercises, outcomes), start=1):
        for answer in (*TRIVIAL_ANSWERS, *wrong.get(number, {})):
            print(f"{path.stem} exercise {number} (cell {cell}), {answer!r}: {o[answer]}")
            if o[answer] == "passed" or o[answer].startswith("the wrong answer itself"):
                accepted.append((number, cell, names, answer, o[answer]))
    assert not accepted, (f"{path.stem}: self-checks that accept a trivial or wrong answer, or wrong answers that do "
                          f"not run (exercise, cell, answer names, answer, outcome): {accepted}")
