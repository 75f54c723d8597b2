"""A number quoted in a notebook's text is visible in that notebook.

Every number with two or more significant digits in a markdown cell (outside formulas, code spans
and links) must appear in the same notebook's code or outputs -- so a claim can be checked against
the stored run --, or be marked as the paper's (its sentence says "paper"; the paper itself is not in
the clone), or cite where it was measured (``docs/``). Section, figure, table, equation, notebook, exercise and seed numbers are
references, not quantities, and are skipped, as are years.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb"))

NUMBER = re.compile(r"(?<![\w.])(\d{1,3}(?:,\d{3})+|\d+\.\d+|\d+)(?![\w])")
REFERENCE_BEFORE = re.compile(r"(Sec\.|Secs\.|Section|sections?|notebooks?|Figs?\.|Tables?|Eqs?\.|Equations?|cells?"
                              r"|exercises?|steps?|dims?|dimensions?|seeds?|\()\s*$", re.IGNORECASE)
SECTION_LIST = re.compile(r"\b(Secs?\.|Sections?)\s*[\d.]+(?:\s*(?:,|and|–|-|to)\s*[\d.]+)*", re.IGNORECASE)
YEAR = re.compile(r"^(19|20)\d\d$")


def significant_digits(token: str) -> int:
    t = token.replace(",", "")
    if "." in t:
        return len(t.replace(".", "").lstrip("0"))
    return len(t.lstrip("0").rstrip("0"))


def _visible_text(nb: dict) -> str:
    parts = []
    for cell in nb["cells"]:
        if cell["cell_type"] != "code":
            continue
        parts.append("".join(cell["source"]))
        for out in cell.get("outputs", []):
            parts.append("".join(out.get("text", "")))
            parts.append("".join(out.get("data", {}).get("text/plain", "")))
    return "\n".join(parts).replace(",", "")


def _forms(token: str, percent: bool) -> set[str]:
    t = token.replace(",", "")
    v = float(t)
    forms = {t, f"{v:g}", f"{v:.1e}", f"{v:.2e}"}
    if percent:  # 84% may be printed as 0.84
        forms |= {f"{v / 100:g}", f"{v / 100:.2f}", f"{v / 100:.3f}"}
    return forms


def _appears(forms: set[str], text: str) -> bool:
    return any(re.search(r"(?<![\d.])" + re.escape(f) + r"(?![\d])", text) for f in forms)


def unsupported_numbers(nb: dict) -> list[str]:
    """The quoted numbers of a notebook that are neither visible in it nor the paper's."""
    visible = _visible_text(nb)
    bad = []
    for cell in nb["cells"]:
        if cell["cell_type"] != "markdown":
            continue
        raw = "".join(cell["source"])
        md = re.sub(r"\$\$.*?\$\$", " ", raw, flags=re.DOTALL)
        md = re.sub(r"\$[^$]*\$", " ", md)
        md = re.sub(r"`([^`]*)`", lambda c: c.group(1) if "docs/" in c.group(1) else " CODE ", md)
        md = re.sub(r"\]\([^)]*\)", "]", md)
        md = SECTION_LIST.sub(" ", md)
        for m in NUMBER.finditer(md):
            token = m.group(1)
            if significant_digits(token) < 2 or YEAR.match(token) or REFERENCE_BEFORE.search(md[max(0, m.start() - 25):m.start()]):
                continue
            start = max(md.rfind(". ", 0, m.start()), md.rfind("\n", 0, m.start()))
            end = min([i for i in (md.find(". ", m.end()), md.find("\n", m.end())) if i >= 0] or [len(md)])
            sentence = md[start:end]
            forms = _forms(token, md[m.end():m.end() + 1] == "%")
            if _appears(forms, visible) or "paper" in sentence.lower() or "docs/" in sentence:
                continue
            bad.append(f"{token}: ...{md[max(0, m.start() - 60):m.end() + 30]}...".replace("\n", " "))
    return bad


def test_the_scanner_finds_an_unsupported_number_and_accepts_supported_ones():
    nb = {"cells": [
        {"cell_type": "markdown", "source": ["The error is 0.213 here, 84% agree, Sec. 5.2 and 5.3, $a = 0.95$, in 2018."]},
        {"cell_type": "code", "source": ["print(err)"], "outputs": [{"text": "error 0.213, agreement 0.84"}]},
    ]}
    assert unsupported_numbers(nb) == []
    nb["cells"][0]["source"] = ["A stretch of 32.5 is far from 1."]
    assert len(unsupported_numbers(nb)) == 1 and unsupported_numbers(nb)[0].startswith("32.5")


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_every_quoted_number_is_in_the_outputs_or_the_papers(path):
    bad = unsupported_numbers(json.loads(path.read_text()))
    assert not bad, f"{path.stem}: numbers in the text that the notebook does not show:\n" + "\n".join(bad)
