#!/usr/bin/env python3
"""Times the Python package's batch methods (`Sampler.sample`, `pdf`, `invert`), with fresh output
arrays and with `out=` arrays reused, on the side-by-side script's peaky grid (values r**4 + 1e-3,
θ 0..90°, φ 0..360°). Prints ns per point, best of the repeats.

    .venv/bin/maturin build --release --locked -q -m crates/gonio-py/Cargo.toml -o /tmp/wh \\
        --interpreter .venv/bin/python
    .venv/bin/python -m pip install -q --force-reinstall --no-deps /tmp/wh/gonio-*.whl
    OPENBLAS_NUM_THREADS=1 .venv/bin/python benches/python_batches.py [--grid 19x36] [--points 2097152]

`RAYON_NUM_THREADS=1` for one thread. `OPENBLAS_NUM_THREADS=1` keeps numpy's idle BLAS threads off
the cores.
"""
import argparse
import time

import numpy as np

import gonio


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--grid", default="19x36", help="parallels x meridians (default 19x36)")
    p.add_argument("--points", type=int, default=1 << 21, help="points per call (2^21)")
    p.add_argument("--repeats", type=int, default=5, help="best of this many calls (5)")
    a = p.parse_args()
    n, m = (int(x) for x in a.grid.split("x"))
    rng = np.random.default_rng(1)
    theta = np.linspace(0.0, 90.0, n)
    phi = np.linspace(0.0, 360.0, m, endpoint=False)
    s = gonio.Diagram(theta, phi, rng.random((m, n)) ** 4 + 1e-3).sampler("hds")
    u = rng.random((a.points, 2))
    d, pdf = s.sample(u)
    q, w = np.empty(a.points), np.empty((a.points, 2))
    calls = {
        "sample": lambda: s.sample(u),
        "sample out=": lambda: s.sample(u, out=(d, pdf)),
        "pdf": lambda: s.pdf(d),
        "pdf out=": lambda: s.pdf(d, out=q),
        "invert": lambda: s.invert(d),
        "invert out=": lambda: s.invert(d, out=w),
    }
    best = dict.fromkeys(calls, float("inf"))
    for _ in range(a.repeats):
        for k, f in calls.items():
            t = time.perf_counter()
            f()
            best[k] = min(best[k], time.perf_counter() - t)
    print(f"grid {n}x{m}, {a.points} points, best of {a.repeats}; ns per point")
    for k, v in best.items():
        print(f"{k:12s} {v / a.points * 1e9:6.1f}")


if __name__ == "__main__":
    main()
