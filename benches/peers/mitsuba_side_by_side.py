#!/usr/bin/env python3
"""Mitsuba 3's MarginalContinuous2D0 against gonio's SIMD batch paths, side by side in one run.

For each grid (parallels x meridians) the script draws random peaky values r**4 + 1e-3 (r uniform
in [0, 1), fixed seed), builds

* Mitsuba's ``MarginalContinuous2D0`` on the same values (float32, ``llvm_ad_rgb`` variant) and
  times ``sample`` and ``invert`` over the same uniform points (best of ``--repeats`` after one
  warm-up that also compiles the kernels), first on one thread (``dr.set_thread_count(1)``), then
  on all threads;
* gonio's HDS map of the same values (written as a native JSON diagram on θ = 0..90°, φ = 0..360°)
  and times its SoA batch paths through ``gonio bench --json --method hds --soa`` (best of 5 after a
  warm-up, one-thread pool, then all threads),

and prints per-sample times and the ratios Mitsuba / gonio (above 1 = gonio faster).

Setup (once):

    python3 -m venv /work/venv-mitsuba && /work/venv-mitsuba/bin/pip install mitsuba numpy
    apt-get install libllvm19      # Dr.Jit's LLVM backend
    cargo build --release -p gonio-cli

Run:

    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 \\
        /work/venv-mitsuba/bin/python benches/peers/mitsuba_side_by_side.py [--json out.json]

What is compared is not identical work: Mitsuba returns a point of the unit square and its density
in float32; gonio returns a unit direction on the hemisphere and its exact density (f64, f32
rounded from f64, or the float32 map's own: ``gonio::mapping::Float32Map``).
A second table therefore also times Mitsuba with the work its caller adds for directions, in the
same Dr.Jit kernel: the lift of the sampled point to a unit direction (θ = (π/2)y, φ = 2πx, two
sincos) with the pdf per steradian (÷ π² sin θ), and, before ``invert``, a direction's mapping back
to the square (atan2, acos). The issue's targets are stated against the first table.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--gonio", default=os.path.join(os.path.dirname(__file__), "../../target/release/gonio"),
                   help="the gonio binary (default: target/release/gonio)")
    p.add_argument("--points", type=int, default=1 << 21, help="points per measurement (2^21)")
    p.add_argument("--repeats", type=int, default=5, help="Mitsuba: best of this many timed runs (gonio: 5)")
    p.add_argument("--grids", default="19x36,181x361,1024x1024", help="NxM,… (parallels x meridians)")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--threads", type=int, default=os.cpu_count(), help="threads of the all-thread run")
    p.add_argument("--json", help="also write the results to this JSON file")
    return p.parse_args()


def best_of(repeats, f):
    f()  # warm-up (and kernel compilation for Mitsuba)
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        f()
        best = min(best, time.perf_counter() - t0)
    return best


def time_mitsuba(values, u, v, repeats, threads):
    import drjit as dr
    import mitsuba as mi

    mi.set_variant("llvm_ad_rgb")
    dist = mi.MarginalContinuous2D0(values.astype(np.float32))
    pts = mi.Point2f(u.astype(np.float32), v.astype(np.float32))
    dr.eval(pts)
    out = {}

    def timed(f):
        """The best wall time of running f's Dr.Jit graph to the end, and f's result."""
        last = []

        def run():
            r = f()
            dr.eval(r)
            dr.sync_thread()
            last[:] = [r]

        return best_of(repeats, run), last[0]

    for label, t in (("one", 1), ("all", threads)):
        dr.set_thread_count(t)
        ts, (s, _) = timed(lambda: dist.sample(pts))
        sampled = mi.Point2f(s)
        dr.eval(sampled)
        ti, _ = timed(lambda: dist.invert(sampled))

        # Like for like: Mitsuba's sample lifted to a unit direction with its pdf per steradian, and
        # a direction mapped back to the square before invert. The grid's columns are φ = 2πx and
        # its rows θ = (π/2)y, so dω = π² sin θ dx dy.
        def sample_dir():
            p, pdf = dist.sample(pts)
            st, ct = dr.sincos(p.y * (dr.pi / 2))
            sp, cp = dr.sincos(p.x * (2 * dr.pi))
            return mi.Vector3f(st * cp, st * sp, ct), pdf / (dr.pi * dr.pi * st)

        tsd, (d, _) = timed(sample_dir)
        dirs = mi.Vector3f(d)
        dr.eval(dirs)

        def invert_dir():
            phi = dr.atan2(dirs.y, dirs.x)
            phi = dr.select(phi < 0, phi + 2 * dr.pi, phi)
            return dist.invert(mi.Point2f(phi / (2 * dr.pi), dr.acos(dirs.z) / (dr.pi / 2)))

        tid, _ = timed(invert_dir)
        n = len(u)
        out[label] = {"sample_ns": ts / n * 1e9, "invert_ns": ti / n * 1e9,
                      "sample_dir_ns": tsd / n * 1e9, "invert_dir_ns": tid / n * 1e9}
    return out


def time_gonio(binary, values, n, m, points, repeats, threads):
    theta = [90.0 * j / (n - 1) for j in range(n)]
    phi = [360.0 * i / m for i in range(m)]
    diagram = {"theta_deg": theta, "phi_deg": phi, "values": values.T.tolist()}
    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
        json.dump(diagram, f)
        path = f.name
    try:
        cmd = [binary, "bench", path, "--json", "--method", "hds", "--soa",
               "--samples", str(points), "--threads", str(threads)]
        r = subprocess.run(cmd, check=True, capture_output=True, text=True)
    finally:
        os.unlink(path)
    report = json.loads(r.stdout)
    return report["soa"], report["machine"]


def main():
    a = parse_args()
    rng = np.random.default_rng(a.seed)
    rows = []
    for g in a.grids.split(","):
        n, m = (int(x) for x in g.split("x"))
        values = rng.random((n, m)) ** 4 + 1e-3  # rows: parallels (θ), columns: meridians (φ)
        u, v = rng.random(a.points), rng.random(a.points)
        mit = time_mitsuba(values, u, v, a.repeats, a.threads)
        gon, machine = time_gonio(a.gonio, values, n, m, a.points, a.repeats, a.threads)
        rows.append({"grid": g, "mitsuba": mit, "gonio": gon})
        print(f"grid {g}: done", file=sys.stderr)

    print(f"machine: {machine.get('cpu_model')}, {machine.get('logical_cores')} logical cores, "
          f"load average {machine.get('load_average')}, gonio backend {rows[0]['gonio']['backend']}")
    print(f"{a.points} points, best of {a.repeats}; ns per sample; ratio = Mitsuba / gonio (> 1: gonio faster)")
    def table(cols):
        """One row per grid and thread count: for each (Mitsuba key, gonio key) pair of `cols`, the
        Mitsuba time (when the key differs from the previous pair's), the gonio time and the ratio."""
        hdr = ["grid", "threads"]
        for i, (mk, gk, mname, gname) in enumerate(cols):
            if i == 0 or mk != cols[i - 1][0]:
                hdr.append(mname)
            hdr += [gname, "ratio"]
        print(" | ".join(hdr))
        for r in rows:
            for label in ("one", "all"):
                mi_, go = r["mitsuba"][label], r["gonio"][label]
                cells = [r["grid"], label]
                for i, (mk, gk, _, _) in enumerate(cols):
                    if i == 0 or mk != cols[i - 1][0]:
                        cells.append(f"{mi_[mk]:.1f}")
                    cells += [f"{go[gk]:.1f}", f"{mi_[mk] / go[gk]:.2f}"]
                print(" | ".join(cells))

    table([("sample_ns", "forward_f64_ns", "mi sample", "gonio f64 fwd"),
           ("sample_ns", "forward_f32_ns", "mi sample", "gonio f32 fwd"),
           ("sample_ns", "forward_float32_ns", "mi sample", "float32 map fwd"),
           ("invert_ns", "inverse_f64_ns", "mi invert", "gonio f64 inv"),
           ("invert_ns", "inverse_f32_ns", "mi invert", "gonio f32 inv"),
           ("invert_ns", "inverse_float32_ns", "mi invert", "float32 map inv")])
    print()
    print("like for like: Mitsuba plus the lift to a unit direction and its pdf per steradian (sample),")
    print("and a direction mapped back to the square first (invert); ratio = Mitsuba / gonio f64")
    table([("sample_dir_ns", "forward_f64_ns", "mi sample+dir", "gonio f64 fwd"),
           ("sample_dir_ns", "forward_float32_ns", "mi sample+dir", "float32 map fwd"),
           ("invert_dir_ns", "inverse_f64_ns", "mi dir+invert", "gonio f64 inv"),
           ("invert_dir_ns", "inverse_float32_ns", "mi dir+invert", "float32 map inv")])
    print("scaling (one thread / all threads): " + ", ".join(
        f"{r['grid']}: Mitsuba sample {r['mitsuba']['one']['sample_ns'] / r['mitsuba']['all']['sample_ns']:.2f}, "
        f"gonio f64 forward {r['gonio']['one']['forward_f64_ns'] / r['gonio']['all']['forward_f64_ns']:.2f}"
        for r in rows))
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"points": a.points, "repeats": a.repeats, "machine": machine, "rows": rows}, f, indent=1)


if __name__ == "__main__":
    main()
