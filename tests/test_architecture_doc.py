"""docs/ARCHITECTURE.md lists the library as it is: its generated part matches the code."""

from pathlib import Path

import pytest

from meshvae_lib.course.architecture import BEGIN, END, architecture_markdown, module_summary, update_architecture

ROOT = Path(__file__).resolve().parents[1]


def test_the_architecture_page_matches_the_code():
    assert not update_architecture(ROOT / "docs" / "ARCHITECTURE.md", check=True), (
        "docs/ARCHITECTURE.md is stale: run `python -m meshvae_lib.course architecture`")


def test_every_module_and_folder_is_listed():
    text = architecture_markdown()
    lib = ROOT / "meshvae_lib"
    for path in lib.rglob("*.py"):
        if path.name in ("__init__.py", "__main__.py"):
            continue
        dotted = ".".join(path.relative_to(ROOT).with_suffix("").parts)
        assert f"`{dotted}`" in text, f"{dotted} missing from the generated tables"
    for folder in (p for p in lib.iterdir() if p.is_dir() and not p.name.startswith(("_", "."))):
        assert f"├── {folder.name}/" in text, f"folder {folder.name}/ missing from the tree"


def test_module_summary_reads_the_docstring_and_all(tmp_path):
    mod = tmp_path / "m.py"
    mod.write_text('"""Deformation gradients (paper Eq. 1, with a normal term). More text.\n\nBody."""\n'
                   '__all__ = ["b", "a"]\ndef a(): pass\ndef b(): pass\ndef _c(): pass\n')
    assert module_summary(mod) == ("Deformation gradients (paper Eq. 1, with a normal term).", ["b", "a"])
    mod.write_text('"""Constants."""\nX = 1\nY_Z = 2\nlower = 3\n')
    assert module_summary(mod) == ("Constants.", ["X", "Y_Z"])
    page = tmp_path / "page.md"
    page.write_text("# Title\n\nno markers\n")
    with pytest.raises(ValueError, match="no generated part"):
        update_architecture(page)
    page.write_text(f"# Title\n{BEGIN}\nold\n{END}\ntail\n")
    assert update_architecture(page) and not update_architecture(page, check=True)
    assert page.read_text().startswith(f"# Title\n{BEGIN}\n```") and page.read_text().endswith(f"{END}\ntail\n")
