"""pythreejs and ipywidgets are imported only by meshvae_lib.viewing, and only when used."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _loaded_after(code: str) -> set[str]:
    probe = code + "\nimport sys\nprint(' '.join(sorted(m for m in sys.modules if m.split('.')[0] in " \
                   "('pythreejs', 'ipywidgets', 'matplotlib', 'torch'))))"
    out = subprocess.run([sys.executable, "-c", probe], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    return {m.split(".")[0] for m in out.stdout.split()}


def test_importing_the_viewing_package_loads_nothing_heavy():
    assert _loaded_after("import meshvae_lib.viewing") == set()


TETRA = "import numpy as np\nV = np.array([[0,0,0],[1,0,0],[0,1,0],[0,0,1.]]); F = np.array([[0,2,1],[0,1,3],[0,3,2],[1,2,3]])\n"


def test_static_rendering_needs_only_matplotlib():
    code = TETRA + ("from meshvae_lib.viewing import render_mesh_grid, scalar_colors, resolve_mode, MeshViewer\n"
                    "render_mesh_grid([V, V], F, colors=scalar_colors(V[:, 0])[0])\n"
                    "assert resolve_mode() == 'static'\nMeshViewer(V, F)\n")
    assert _loaded_after(code) == {"matplotlib"}


def test_widget_view_loads_pythreejs_but_not_torch():
    code = TETRA + "from meshvae_lib.viewing import MeshViewer\nMeshViewer(V, F, mode='threejs')\n"
    loaded = _loaded_after(code)
    assert loaded >= {"pythreejs", "ipywidgets"}
    assert "torch" not in loaded


def test_no_module_outside_viewing_imports_widget_packages():
    pattern = re.compile(r"^\s*(import|from)\s+(pythreejs|ipywidgets)\b", re.M)
    offenders = [
        str(p.relative_to(ROOT))
        for p in (ROOT / "meshvae_lib").rglob("*.py")
        if "viewing" not in p.parts and pattern.search(p.read_text(encoding="utf-8"))
    ]
    assert offenders == [], f"pythreejs/ipywidgets imported outside meshvae_lib.viewing: {offenders}"


@pytest.mark.parametrize("name", ["MeshViewer", "FramePlayer", "LatentExplorer", "InterpolationSlider",
                                  "render_mesh", "render_mesh_grid", "ImageView", "label_colors"])
def test_lazy_names_resolve(name):
    import meshvae_lib.viewing as viewing

    assert getattr(viewing, name).__name__ == name
    assert name in dir(viewing)


def test_unknown_name_is_an_attribute_error():
    import meshvae_lib.viewing as viewing

    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        viewing.nope
