"""One numbering everywhere: every "Fig. N", "Table N" and "Eq. N" in the notebooks, the docs, the
README and the library's docstrings is one of the paper's (the LaTeX source in ``../shared/seed``):

- figures 1 pipeline, 2 generation, 3 conditional generation, 4 interpolation, 5 inter-class
  interpolation, 6 more interpolation, 7 embedding, 8 exploration;
- tables 1 latent size, 2 features, 3 reference mesh and density;
- equations 1 (deformation gradient), 2 (the RIMD feature), 3 (normalisation), 4 (the loss),
  5 (the conditional VAE).

A number outside these ranges fails, and so do the references seen wrong before (the figure
numbers of an older draft, which put the embedding at 8 and the exploration at 9).
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
N_FIGURES, N_TABLES, N_EQUATIONS = 8, 3, 5
REFERENCE = re.compile(r"\b(Figs?\.|Figures?|Tables?|Eqs?\.|Equations?)\s*\(?(\d+)([a-z]?)\)?"
                       r"((?:\s*(?:,|and|-|–|/)\s*\(?\d+\)?)*)")
def _files() -> list[str]:
    files = sorted(ROOT.glob("notebooks/[0-9][0-9]_*.ipynb")) + sorted(ROOT.glob("docs/*.md")) + [ROOT / "README.md"]
    files += sorted(ROOT.glob("meshvae_lib/**/*.py")) + sorted(ROOT.glob("benchmarks/*.py"))
    return [p.relative_to(ROOT).as_posix() for p in files]


def _text(rel: str) -> str:
    path = ROOT / rel
    if path.suffix == ".ipynb":
        return "\n".join("".join(c["source"]) for c in json.loads(path.read_text())["cells"])
    return path.read_text()


def references(text: str) -> list[tuple[str, int, str]]:
    """(kind, number, context) for every reference in text; kind 'F', 'T' or 'E'. Lists such as
    "Tables 1, 2 and 3" or "Eqs. (1)-(4)" give one entry per number."""
    found = []
    for m in REFERENCE.finditer(text):
        kind = m.group(1)[0]
        numbers = [int(m.group(2))] + [int(n) for n in re.findall(r"\d+", m.group(4) or "")]
        context = text[max(0, m.start() - 60): m.end() + 20].replace("\n", " ")
        found += [(kind, n, context) for n in numbers]
    return found


def test_the_parser_reads_lists_and_parentheses():
    got = [(k, n) for k, n, _ in references("Fig. 8a, Tables 1, 2 and 3, Eqs. (1)-(4), Eq. (5), Figure 7")]
    assert got == [("F", 8), ("T", 1), ("T", 2), ("T", 3), ("E", 1), ("E", 4), ("E", 5), ("F", 7)]


@pytest.mark.parametrize("name", _files())
def test_every_reference_is_one_of_the_papers(name):
    text = _text(name)
    limits = {"F": N_FIGURES, "T": N_TABLES, "E": N_EQUATIONS}
    bad = [f"{kind}{n}: ...{ctx}..." for kind, n, ctx in references(text) if not 1 <= n <= limits[kind]]
    assert not bad, f"{name}: references the paper does not have:\n" + "\n".join(bad)
    # the concepts whose numbers an older draft gave: exploration is Fig. 8, embedding Fig. 7
    lowered = text.lower()
    for m in re.finditer(r"fig\.\s*(\d+)", lowered):
        window = lowered[max(0, m.start() - 80): m.end() + 10]
        if "embedding" in window and "explor" not in window and "interpol" not in window:
            assert m.group(1) == "7", f"{name}: the embedding figure is Fig. 7: ...{window}..."
