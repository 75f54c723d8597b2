"""A number quoted in a notebook's text is printed in its own section, and the text keeps its budget.

A *section* runs from one markdown heading to the next. Every number with two or more significant
digits in a section's markdown (outside formulas, code spans and links), and in the comments of its
solution cells, must be shown by that section's code cells -- printed in an output, or written in
the code itself (not in a comment) -- with the same value to the digits quoted: ``0.38`` is
supported by a printed ``0.380`` or ``3.8e-01``, not by ``0.384``. A number that cannot be printed
there is cited instead: its sentence says "paper" (the paper is not in the clone) or names where it
was measured (``docs/``). Section, figure, table, equation, notebook, exercise and seed numbers are
references, not quantities, and are skipped, as are years.

The budget (issue 36): no markdown cell over 200 words, no notebook over 2,500 words of markdown,
words counted as runs of word characters (``\\w+``).
"""

from __future__ import annotations

import json
import re
from decimal import Decimal, InvalidOperation
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb"))

MAX_CELL_WORDS = 200
MAX_NOTEBOOK_WORDS = 2500

NUMBER = re.compile(r"(?<![\w.])(\d{1,3}(?:,\d{3})+(?:\.\d+)?|\d+(?:\.\d+)?(?:[eE][-+−]?\d+)?)(?=[x×]\b|[^\w]|$)")
REFERENCE_BEFORE = re.compile(r"(Sec\.|Secs\.|Section|sections?|notebooks?|Figs?\.|Tables?|Eqs?\.|Equations?|cells?"
                              r"|exercises?|steps?|dims?|dimensions?|seeds?|\()\s*$", re.IGNORECASE)
SECTION_LIST = re.compile(r"\b(Secs?\.|Sections?)\s*[\d.]+(?:\s*(?:,|and|–|-|to)\s*[\d.]+)*", re.IGNORECASE)
TITLE_NUMBER = re.compile(r"^(#{1,6}\s*)\d+\s*·", re.MULTILINE)  # a notebook's own number: "# 11 · Bring ..."
YEAR = re.compile(r"^(19|20)\d\d$")
HEADING = re.compile(r"^#{1,6}\s", re.MULTILINE)
WORD = re.compile(r"\w+")


def significant_digits(token: str) -> int:
    mantissa = re.split(r"[eE]", token.replace(",", ""))[0]
    if "." in mantissa:
        return len(mantissa.replace(".", "").lstrip("0"))
    return len(mantissa.lstrip("0").rstrip("0"))


def _value(token: str) -> Decimal | None:
    try:
        return Decimal(token.replace(",", "").replace("−", "-")).normalize()
    except InvalidOperation:
        return None


def _strip_comments(code: str) -> str:
    return "\n".join(line.split("#", 1)[0] if not line.lstrip().startswith(("'", '"')) else line
                     for line in code.splitlines())


def _comments(code: str) -> str:
    return "\n".join(line.split("#", 1)[1] for line in code.splitlines() if "#" in line)


def _solution_comments(code: str) -> str:
    inside, found = False, []
    for line in code.splitlines():
        if "### BEGIN SOLUTION" in line:
            inside = True
        elif "### END SOLUTION" in line:
            inside = False
        elif inside and "#" in line:
            found.append(line.split("#", 1)[1])
    return "\n".join(found)


def sections(nb: dict) -> list[dict]:
    """The notebook cut at its markdown headings: each ``{"title", "markdown", "comments", "shown"}``.

    ``markdown`` is the section's markdown text, ``comments`` the comments of its solution cells,
    ``shown`` the code (without comments) and text outputs of its code cells.
    """
    out = [{"title": "(before the first heading)", "markdown": [], "comments": [], "shown": []}]
    for cell in nb["cells"]:
        src = "".join(cell["source"])
        if cell["cell_type"] == "markdown":
            starts = [m.start() for m in HEADING.finditer(src)]
            cuts = sorted({0, *starts, len(src)})
            for a, b in zip(cuts[:-1], cuts[1:]):
                chunk = src[a:b]
                if a in starts:
                    out.append({"title": chunk.splitlines()[0].strip(), "markdown": [], "comments": [], "shown": []})
                if chunk.strip():
                    out[-1]["markdown"].append(chunk)
        elif cell["cell_type"] == "code":
            out[-1]["comments"].append(_solution_comments(src))
            out[-1]["shown"].append(_strip_comments(src))
            for o in cell.get("outputs", []):
                out[-1]["shown"].append("".join(o.get("text", "")))
                out[-1]["shown"].append("".join(o.get("data", {}).get("text/plain", "")))
    return out


def _shown_values(text: str) -> set[Decimal]:
    values = set()
    for m in NUMBER.finditer(text.replace("−", "-")):
        v = _value(m.group(1))
        if v is not None:
            values.add(v)
    return values


def _clean_markdown(md: str) -> str:
    md = TITLE_NUMBER.sub(r"\1", md)
    md = re.sub(r"\$\$.*?\$\$", " ", md, flags=re.DOTALL)
    md = re.sub(r"\$[^$]*\$", " ", md)
    md = re.sub(r"`([^`]*)`", lambda c: c.group(1) if "docs/" in c.group(1) else " CODE ", md)
    md = re.sub(r"\]\([^)]*\)", "]", md)
    md = re.sub(r"<[^>]*>", " ", md)
    return SECTION_LIST.sub(" ", md)


def _quoted(text: str):
    """(token, its sentence, context, is a percentage) for each quantity quoted in ``text``."""
    for m in NUMBER.finditer(text):
        token = m.group(1)
        if significant_digits(token) < 2 or YEAR.match(token) or REFERENCE_BEFORE.search(text[max(0, m.start() - 25):m.start()]):
            continue
        start = max(text.rfind(". ", 0, m.start()), text.rfind("\n", 0, m.start()))
        end = min([i for i in (text.find(". ", m.end()), text.find("\n", m.end())) if i >= 0] or [len(text)])
        context = text[max(0, m.start() - 60):m.end() + 30].replace("\n", " ")
        yield token, text[start:end], context, text[m.end():m.end() + 1] == "%"


def _supported(token: str, percent: bool, shown: set[Decimal]) -> bool:
    v = _value(token)
    if v is None:
        return False
    candidates = {v}
    if percent:  # 84% may be printed as 0.84
        candidates.add((v / 100).normalize())
    return bool(candidates & shown)


def unsupported_numbers(nb: dict) -> list[str]:
    """The quoted numbers of a notebook that its own section does not show and that are not cited."""
    bad = []
    for sec in sections(nb):
        shown = _shown_values("\n".join(sec["shown"]))
        texts = [_clean_markdown(md) for md in sec["markdown"]] + [c for c in sec["comments"] if c]
        for text in texts:
            for token, sentence, context, percent in _quoted(text):
                if _supported(token, percent, shown) or "paper" in sentence.lower() or "docs/" in sentence:
                    continue
                bad.append(f"[{sec['title']}] {token}: ...{context}...")
    return bad


def supported_numbers(nb: dict) -> list[tuple[int, str]]:
    """(section index, token) of the quoted numbers that their section shows (not cited ones)."""
    found = []
    for i, sec in enumerate(sections(nb)):
        shown = _shown_values("\n".join(sec["shown"]))
        for md in sec["markdown"]:
            text = _clean_markdown(md)
            for token, sentence, _, percent in _quoted(text):
                if not percent and _supported(token, percent, shown) and "paper" not in sentence.lower() and "docs/" not in sentence:
                    found.append((i, token))
    return found


def markdown_words(nb: dict) -> list[int]:
    """The word count of each markdown cell (runs of word characters)."""
    return [len(WORD.findall("".join(c["source"]))) for c in nb["cells"] if c["cell_type"] == "markdown"]


def _nb(*cells):
    return {"cells": [{"cell_type": kind, "source": [src], **({"outputs": [{"text": out}]} if kind == "code" else {})}
                      for kind, src, out in cells]}


def test_the_scanner_finds_an_unsupported_number_and_accepts_supported_ones():
    nb = _nb(("markdown", "## A\nThe error is 0.213 here, 84% agree, 6.1e-3 of it, Sec. 5.2 and 5.3, $a = 0.95$, in 2018.", None),
             ("code", "print(err)", "error 0.2130, agreement 0.84, 6.10e-03"))
    assert unsupported_numbers(nb) == []
    nb["cells"][0]["source"] = ["## A\nA stretch of 32.5 is far from 1."]
    assert len(unsupported_numbers(nb)) == 1 and "32.5" in unsupported_numbers(nb)[0]


def test_a_notebooks_own_number_in_its_title_is_not_a_quantity_but_the_same_number_later_is():
    nb = _nb(("markdown", "# 11 · Bring your own meshes\nIt takes 11 minutes.", None), ("code", "x", "nothing"))
    bad = unsupported_numbers(nb)
    assert len(bad) == 1 and "11 minutes" in bad[0]


def test_a_number_printed_in_another_section_does_not_count():
    nb = _nb(("markdown", "## One\nThe error is 0.213.", None),
             ("code", "x = 1", "nothing"),
             ("markdown", "## Two\nMore.", None),
             ("code", "print(err)", "error 0.213"))
    assert len(unsupported_numbers(nb)) == 1 and "[## One] 0.213" in unsupported_numbers(nb)[0]


def test_rounded_or_scientific_numbers_must_match_the_digits_printed():
    def bad(md, out):
        return unsupported_numbers(_nb(("markdown", "## S\n" + md, None), ("code", "x", out)))
    assert bad("It is 1.6 to 1.8e-04.", "floors 2e-04 2e-04") and len(bad("It is 1.6 to 1.8e-04.", "floors 2e-04 2e-04")) == 2
    assert bad("It is 0.38x.", "ratio 0.384")
    assert not bad("It is 0.38x and 2.9e-5.", "ratio 0.380, floor 2.90e-05")


def test_a_comment_supports_nothing_and_solution_comments_are_checked():
    nb = _nb(("markdown", "## Exercises\nSolve it.", None),
             ("code", "### BEGIN SOLUTION\nans = f()  # about 0.0270, against 0.0268\n### END SOLUTION", "0.0270"))
    bad = unsupported_numbers(nb)
    assert len(bad) == 1 and "0.0268" in bad[0]


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_changing_one_printed_digit_is_caught(path):
    """Mutation: every number a section supports becomes unsupported when its printed digits change."""
    nb = json.loads(path.read_text())
    found = supported_numbers(nb)
    if not found:
        pytest.skip(f"{path.stem} quotes no printed number")
    before = len(unsupported_numbers(nb))
    for index, token in found[:5]:
        mutated = json.loads(path.read_text())
        value = _value(token)
        secs = sections(mutated)
        # change the last digit of every shown occurrence of the value inside its section's cells
        target = secs[index]
        section_cells = _cells_of_section(mutated, index)
        for cell in section_cells:
            for o in cell.get("outputs", []):
                for key, holder in (("text", o), ("text/plain", o.get("data", {}))):
                    if key in holder:
                        holder[key] = _bump_digits(holder[key], value)
            cell["source"] = [_bump_digits("".join(cell["source"]), value)]
        after = unsupported_numbers(mutated)
        assert len(after) > before, f"{path.stem} [{target['title']}]: {token} still counted as shown after its digits changed"


def _cells_of_section(nb: dict, index: int) -> list[dict]:
    count, cells = 0, []
    for cell in nb["cells"]:
        if cell["cell_type"] == "markdown":
            count += len(HEADING.findall("".join(cell["source"])))
        elif count == index:
            cells.append(cell)
    return cells


def _bump_digits(text, value: Decimal):
    if isinstance(text, list):
        text = "".join(text)

    def bump(m):
        v = _value(m.group(1))
        if v != value:
            return m.group(0)
        s = m.group(1)
        digits = [i for i, ch in enumerate(s.split("e")[0].split("E")[0]) if ch.isdigit()]
        i = digits[-1]
        return s[:i] + str((int(s[i]) + 1) % 10) + s[i + 1:]
    return NUMBER.sub(bump, text.replace("−", "-"))


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_every_quoted_number_is_shown_in_its_section_or_cited(path):
    bad = unsupported_numbers(json.loads(path.read_text()))
    assert not bad, f"{path.stem}: numbers in the text that their section does not show:\n" + "\n".join(bad)


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_the_markdown_keeps_its_word_budget(path):
    words = markdown_words(json.loads(path.read_text()))
    long_cells = [w for w in words if w > MAX_CELL_WORDS]
    assert not long_cells and sum(words) <= MAX_NOTEBOOK_WORDS, (
        f"{path.stem}: {sum(words)} words of markdown (at most {MAX_NOTEBOOK_WORDS}), "
        f"cells over {MAX_CELL_WORDS} words: {long_cells}")
