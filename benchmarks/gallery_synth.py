"""Render a grid of frames of every synthetic collection to PNG files under build/gallery/.

Usage::

    .venv/bin/python benchmarks/gallery_synth.py [NAME ...] [--frames 12] [--seed 0] [--out DIR]

Each PNG shows evenly spaced meshes of one collection, shaded with a fixed light, every panel
with the same scale so that motions and sizes compare. build/ is not committed.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

# views: (elevation, azimuth) of matplotlib's camera per collection
VIEWS = {"flag": (20, -60), "bar": (25, -70), "hand": (35, -100), "face": (5, -65)}


def shade(V: np.ndarray, F: np.ndarray, light=(0.3, 0.5, 1.0)) -> np.ndarray:
    """Per-face grey levels ``(n_faces,) float64`` from a directional light (two-sided)."""
    n = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    light = np.asarray(light, float) / np.linalg.norm(light)
    return 0.25 + 0.75 * np.abs(n @ light)


def draw_mesh(ax, V, F, center, half, view, color=(0.85, 0.68, 0.55)):
    """Draw mesh ``V (n,3)``, ``F (m,3)`` in matplotlib 3-D axes ``ax`` (y up in the mesh)."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    # mesh coordinates (x, y up, z forward) -> matplotlib (x, -z, y) with z up
    P = np.stack([V[:, 0], -V[:, 2], V[:, 1]], axis=1)
    c = np.array([center[0], -center[2], center[1]])
    tri = P[F]
    g = shade(P, F, light=(0.4, -1.0, 0.8))
    colors = np.clip(np.outer(g, color), 0, 1)
    coll = Poly3DCollection(tri, facecolors=colors, edgecolors="none", linewidths=0)
    ax.add_collection3d(coll)
    for setter, k in ((ax.set_xlim, 0), (ax.set_ylim, 1), (ax.set_zlim, 2)):
        setter(c[k] - half, c[k] + half)
    ax.set_box_aspect((1, 1, 1), zoom=1.45)
    ax.view_init(elev=view[0], azim=view[1])
    ax.set_axis_off()


def render_collection(name: str, out: Path, n_frames: int, seed: int, resolution=None) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from data_synth import make_collection

    col = make_collection(name, seed=seed, resolution=resolution)
    N = len(col.vertices)
    idx = np.unique(np.linspace(0, N - 1, min(n_frames, N)).round().astype(int))
    cols = min(6, len(idx))
    rows = int(np.ceil(len(idx) / cols))
    fig = plt.figure(figsize=(2.6 * cols, 3.0 * rows), dpi=90)
    view = VIEWS.get(name, (8, -75))
    for k, i in enumerate(idx):
        V = col.vertices[i]
        center = 0.5 * (V.min(0) + V.max(0))
        ext = np.max(col.vertices[idx].max(1) - col.vertices[idx].min(1))
        ax = fig.add_subplot(rows, cols, k + 1, projection="3d")
        draw_mesh(ax, V, col.faces, center, 0.55 * ext, view)
        label = ", ".join(f"{c}={col.labels[c][i]}" for c in col.labels if c != "frame")
        ax.set_title(f"{col.names[i]}\n{label}", fontsize=7)
    fig.suptitle(f"{name}: {col.description}  ({N} meshes, {col.vertices.shape[1]} vertices)",
                 fontsize=9)
    fig.tight_layout()
    out.mkdir(parents=True, exist_ok=True)
    path = out / f"{name}.png"
    fig.savefig(path)
    plt.close(fig)
    return path


def main(argv=None) -> int:
    from data_synth import list_collections

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", help="collections (default: all)")
    parser.add_argument("--frames", type=int, default=12)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--resolution", type=int, default=None)
    parser.add_argument("--out", type=Path, default=ROOT / "build" / "gallery")
    args = parser.parse_args(argv)
    names = args.names or [n for n, _ in list_collections()]
    for name in names:
        path = render_collection(name, args.out, args.frames, args.seed, args.resolution)
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
