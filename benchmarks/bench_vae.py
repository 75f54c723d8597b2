"""Speed of mesh VAE training on the CPU: ms per Adam step and epochs per minute.

Prints a table. Random feature rows stand in for RIMD features (the step time depends only on the
sizes). Sizes: K = 6 V + 6 E with E ~ 3 V (the paper's layout), for V = 6,890 (K ~ 165k, a
SMPL/Dyna body) and for the course's default sizes. Each row is the median of several timed runs
after warm-up steps; the machine is shared, so expect some noise.

    .venv/bin/python benchmarks/bench_vae.py [--threads 2] [--repeats 7] [--quick]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np
import torch

from meshvae_lib.model.train_config import TrainConfig
from meshvae_lib.model.training import train_vae
from meshvae_lib.model.inplace_grad import start_step
from meshvae_lib.model.loss import vae_loss
from meshvae_lib.model.vae import MeshVAE


def rimd_k(n_vertices: int) -> int:
    n_edges = 3 * n_vertices  # closed triangle mesh: E ~ 3 V
    return 6 * n_vertices + 6 * n_edges


def time_steps(k: int, batch: int, hidden=(), latent=128, fused=True, steps=5, warmup=2, repeats=5) -> float:
    """Median ms per training step (forward, loss, backward, Adam) at batch ``batch``."""
    gen = torch.Generator().manual_seed(0)
    with torch.random.fork_rng(devices=[]):
        torch.manual_seed(0)
        net = MeshVAE(k, latent, hidden)
    opt = torch.optim.Adam(net.parameters(), lr=1e-3, fused=fused)
    x = torch.rand(batch, k, generator=gen) * 1.8 - 0.9
    net.train()

    def step():
        x_hat, mu, sigma = net(x, generator=gen)
        loss = vae_loss(x_hat, x, mu, sigma)["total"]
        start_step(net)
        loss.backward()
        opt.step()

    for _ in range(warmup):
        step()
    runs = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        for _ in range(steps):
            step()
        runs.append((time.perf_counter() - t0) / steps * 1e3)
    return statistics.median(runs)


def epochs_per_minute(k: int, n_meshes: int = 150, epochs: int = 5, repeats: int = 3) -> float:
    rng = np.random.default_rng(0)
    X = rng.uniform(-0.9, 0.9, size=(n_meshes, k))
    rates = []
    for r in range(repeats):
        res = train_vae(X, config=TrainConfig(epochs=epochs, progress=False, seed=r, device="cpu"))
        rates.append(epochs / res.seconds * 60.0)
    return statistics.median(rates)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--quick", action="store_true", help="fewer sizes and repeats")
    args = ap.parse_args()
    torch.set_num_threads(args.threads)
    print(f"torch {torch.__version__}, {torch.get_num_threads()} threads, batch 32, latent 128\n")

    rows = []
    sizes = [(6890, "SMPL/Dyna body (target <= 250 ms)"), (2502, "paper's 2,502-vertex mesh (K = 60,012)"),
             (1500, "course default (~1.5k vertices)")]
    if args.quick:
        sizes = sizes[:1] + sizes[2:]
    for nv, what in sizes:
        k = rimd_k(nv)
        rows.append((f"{nv} ({what})", k, "none", "fused", time_steps(k, 32, repeats=args.repeats)))
    if not args.quick:
        k = rimd_k(6890)
        rows.append(("6890", k, "none", "default Adam", time_steps(k, 32, fused=False, repeats=3)))
        k = rimd_k(1500)
        rows.append(("1500", k, "1024", "fused", time_steps(k, 32, hidden=(1024,), repeats=3)))
        k = 3 * 1500
        rows.append(("1500 coords (K = 3V)", k, "none", "fused", time_steps(k, 32, repeats=args.repeats)))
        rows.append(("1500 coords (K = 3V)", k, "512", "fused", time_steps(k, 32, hidden=(512,), repeats=args.repeats)))

    print(f"{'vertices':44s} {'K':>8s} {'hidden':>7s} {'optimiser':>13s} {'ms/step':>9s}")
    for name, k, hidden, opt, ms in rows:
        print(f"{name:44s} {k:8d} {hidden:>7s} {opt:>13s} {ms:9.1f}")

    print("\nepochs per minute, 150 meshes, batch 32 (4 steps per epoch), no hidden layer")
    for nv in (6890, 1500):
        k = rimd_k(nv)
        print(f"  {nv:5d} vertices, K = {k:7d}: {epochs_per_minute(k, repeats=1 if args.quick else 3):7.1f} epochs/min")


if __name__ == "__main__":
    main()
