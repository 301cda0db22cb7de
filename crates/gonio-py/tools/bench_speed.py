"""Sampling 10⁶ points from Python against the Rust batch call for the same points.

    python crates/gonio-py/tools/bench_speed.py [FILE] [--n 1000000] [--runs 15] [--method hds]

In one process, alternately: the library's batch call `gonio::sampler::sample_batch_par` on the
N points into a preallocated buffer, timed inside Rust around that call only
(`gonio._gonio._bench_rust_batch`), and `Sampler.sample(u)` from Python on the same C-ordered
float64 array, timed around the Python call (conversion, allocation of the output arrays,
sampling, scatter into them). Best of R rounds each; both on every rayon thread (set
RAYON_NUM_THREADS to change). Prints both times and their ratio.
"""

import argparse
import os
import pathlib
import time

import gonio

ROOT = pathlib.Path(__file__).resolve().parents[3]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("file", nargs="?", default=None)
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--runs", type=int, default=15)
    ap.add_argument("--method", default="hds")
    a = ap.parse_args()
    corpus = pathlib.Path(os.environ.get("GONIO_CORPUS", ROOT.parent / "shared" / "data" / "photometry"))
    f = a.file or str(corpus / "ldt" / "isym0_fine_1deg_360x181.ldt")
    s = gonio.read(f).sampler(a.method)
    u = gonio.sequence(a.n, "sobol", seed=1)
    rust, py = float("inf"), float("inf")
    for _ in range(a.runs):
        rust = min(rust, gonio._gonio._bench_rust_batch(s, u, 1))
        t = time.perf_counter()
        s.sample(u)
        py = min(py, time.perf_counter() - t)
    print(f"{pathlib.Path(f).name}, method {a.method}: n = {a.n}, best of {a.runs} alternating rounds, "
          f"RAYON_NUM_THREADS={os.environ.get('RAYON_NUM_THREADS', 'all')}, load average {os.getloadavg()[0]:.1f}")
    print(f"  Rust sample_batch_par : {rust * 1e3:8.2f} ms")
    print(f"  Python Sampler.sample : {py * 1e3:8.2f} ms")
    print(f"  ratio Python / Rust   : {py / rust:8.3f}")


if __name__ == "__main__":
    main()
