"""Latency of one latent-slider move in the LatentExplorer, end to end, on the CPU.

What is timed is the widget callback the kernel runs when a slider moves (``slider.value = v``):
decode z -> mesh, numpy vertex normals, float32 buffers, and the pythreejs attribute hand-off
(traitlets validation and binary serialisation of the position and normal arrays; with no front end
attached the final zmq send is a no-op, a few hundred microseconds for 2 x 36 KB at 3k vertices).

Decoders:
- "MeshVAE+RIMD": a real :class:`meshvae_lib.model.meshvae_model.MeshVAEModel` (RIMD features, latent 128,
  trained for 2 epochs on 12 meshes of the synthetic "scape" collection: latency does not depend on
  how well it is trained) whose ``decode_latent`` runs the network, the inverse feature
  normalisation and :class:`~meshvae_lib.geometry.reconstruction.RIMDReconstructor`;
- "stand-in (linear)": ``V0 + z @ B``, to show the viewer's own share.
If the learning modules or data_synth cannot be imported, only the stand-in runs, and the table
says so. Medians and 90th percentiles over 30 moves after 3 warm-up moves; target < 100 ms.

Run: ``.venv/bin/python benchmarks/bench_viewing.py [--sizes 1000 2500] [--moves 30]``.
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "2")
os.environ.pop("MESHVAE_VIEWER", None)

import numpy as np  # noqa: E402

TARGET_MS = 100.0


def _stats(samples_ms):
    a = np.asarray(samples_ms)
    return float(np.median(a)), float(np.percentile(a, 90))


def _procedural(resolution: int):
    import trimesh

    level = int(np.clip(round(np.log(max(resolution - 2, 12) / 10.0) / np.log(4.0)), 1, 6))
    m = trimesh.creation.icosphere(subdivisions=level)
    return np.array(m.vertices), np.array(m.faces)


def _real_model(resolution: int):
    """(decode, latent_dim, F, V0, label) from a briefly trained MeshVAEModel, or None."""
    try:
        import torch
        from types import SimpleNamespace

        from data_synth.registry import make_collection
        from meshvae_lib.model.meshvae_model import MeshVAEModel
        from meshvae_lib.model.train_config import TrainConfig
    except ImportError as err:
        return None, f"real model unavailable ({err})"
    torch.set_num_threads(2)
    c = make_collection("scape", seed=0, resolution=resolution)
    coll = SimpleNamespace(vertices=c.vertices[:12], faces=c.faces, labels={})
    model = MeshVAEModel(config=TrainConfig(epochs=2, progress=False, device="cpu", seed=0)).fit(coll)
    return (model.decode_latent, model.latent_dim, np.asarray(c.faces), c.vertices[0]), "MeshVAE+RIMD"


def _time_moves(explorer, dim: int, moves: int, warmup: int = 3):
    values = np.linspace(-2.0, 2.0, moves + warmup)
    out = []
    for k, v in enumerate(values):
        t0 = time.perf_counter()
        explorer.sliders[dim].value = float(v)
        dt = 1e3 * (time.perf_counter() - t0)
        if k >= warmup:
            out.append(dt)
    return out


def _parts(decode, latent_dim, viewer, moves):
    """Medians of the three stages separately (decode, normals, buffer hand-off)."""
    from meshvae_lib.geometry.topology import vertex_normals

    rng = np.random.default_rng(0)
    dec, nrm, buf = [], [], []
    for _ in range(moves):
        z = rng.standard_normal(latent_dim)
        t0 = time.perf_counter()
        V = np.asarray(decode(z), dtype=np.float64).reshape(-1, viewer.n_vertices, 3)
        t1 = time.perf_counter()
        N = vertex_normals(V, viewer.F).astype(np.float32)
        t2 = time.perf_counter()
        viewer.set_buffers(V.astype(np.float32), N)
        t3 = time.perf_counter()
        dec.append(1e3 * (t1 - t0)); nrm.append(1e3 * (t2 - t1)); buf.append(1e3 * (t3 - t2))
    return float(np.median(dec)), float(np.median(nrm)), float(np.median(buf))


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sizes", type=int, nargs="+", default=[1000, 2500])
    p.add_argument("--moves", type=int, default=30)
    p.add_argument("--no-real", action="store_true", help="only the stand-in decoder")
    args = p.parse_args(argv)

    from meshvae_lib.viewing.explorer import LatentExplorer

    rows = []
    notes = []
    for res in args.sizes:
        cases = []
        real, label = (None, "skipped (--no-real)") if args.no_real else _real_model(res)
        if real is not None:
            cases.append((label,) + real)
        else:
            notes.append(f"size {res}: {label}; stand-in only")
        if real is not None:
            V0, F = real[3], real[2]
        else:
            V0, F = _procedural(res)
        B = np.random.default_rng(1).normal(scale=0.01, size=(16, len(V0), 3))
        cases.append(("stand-in (linear)", lambda z, V0=V0, B=B: V0 + np.tensordot(z[:16], B, axes=1), 16, F, V0))
        for name, decode, latent_dim, F_, _ in cases:
            ex = LatentExplorer(decode, latent_dim, F_, dims=[0, 1, 2], mode="threejs")
            med, p90 = _stats(_time_moves(ex, 1, args.moves))
            d, n, b = _parts(decode, latent_dim, ex.viewer, min(args.moves, 15))
            rows.append((ex.viewer.n_vertices, len(F_), name, med, p90, d, n, b, "yes" if med < TARGET_MS else "NO"))

    import torch

    print(f"LatentExplorer slider move, end to end (OMP_NUM_THREADS={os.environ['OMP_NUM_THREADS']}, "
          f"torch threads {torch.get_num_threads()}, {os.cpu_count()} CPUs visible, "
          f"load average {os.getloadavg()[0]:.1f}); target < {TARGET_MS:.0f} ms")
    head = f"{'vertices':>8} {'faces':>6}  {'decoder':<18} {'median ms':>9} {'p90 ms':>7}  {'decode':>7} {'normals':>7} {'buffers':>7}  <100ms"
    print(head)
    print("-" * len(head))
    for r in rows:
        print(f"{r[0]:>8} {r[1]:>6}  {r[2]:<18} {r[3]:>9.1f} {r[4]:>7.1f}  {r[5]:>7.1f} {r[6]:>7.2f} {r[7]:>7.2f}  {r[8]}")
    for n in notes:
        print("note:", n)


if __name__ == "__main__":
    main()
