"""How fast the course models are ready: a fresh Python process that loads a cached course model
and builds what its lesson shows live (notebook 08: a ``LatentExplorer``), timed from the process
start, as an instructor's fresh kernel would be. Median of ``--repeat`` runs; the models must be
cached (``make models``).

    .venv/bin/python benchmarks/bench_course_models.py [--repeat 5]
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

SNIPPETS = {
    "generation-body": "m = course_model('generation-body'); m.generate(1, seed=0)",
    "exploration-body": (
        "from meshvae_lib.viewing import LatentExplorer\n"
        "spec = get_spec('exploration-body'); m = course_model('exploration-body')\n"
        "e = LatentExplorer(m, m.latent_dim, spec.make_collection().faces, dims=range(6), pad_dims=(0, 1))"
    ),
    "conditional-bodies": "m = course_model('conditional-bodies'); m.generate(1, seed=0, condition={'motion': 'squat'})",
}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeat", type=int, default=5)
    args = p.parse_args(argv)
    sys.path.insert(0, str(ROOT))
    from meshvae_lib.course import models as cm

    for name, body in SNIPPETS.items():
        if not cm.is_cached(name):
            print(f"{name}: not cached (run `make models`), skipped")
            continue
        code = ("from meshvae_lib.course.models import course_model, get_spec\n"
                "from meshvae_lib.model.threads import configure_threads\nconfigure_threads(2)\n" + body)
        times = []
        for _ in range(args.repeat):
            start = time.perf_counter()
            subprocess.run([sys.executable, "-c", code], cwd=ROOT, check=True)
            times.append(time.perf_counter() - start)
        print(f"{name:20s} ready in {statistics.median(times):.2f} s from a fresh process "
              f"(median of {args.repeat}; min {min(times):.2f}, max {max(times):.2f})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
