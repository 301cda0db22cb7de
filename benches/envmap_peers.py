#!/usr/bin/env python3
"""gonio.EnvMap against Mitsuba 3's own `envmap` emitter, side by side in one run (docs/ENVMAPS.md).

For each map (default: the three shared maps, ../shared/data/envmaps/{studio,sunset,night}.hdr) the
script loads the same image file twice:

* gonio: ``gonio.EnvMap(path)`` (the HDS sphere map of the luminance; ``sample``, ``pdf``);
* Mitsuba 3: ``mi.load_dict({"type": "envmap", "filename": path, "to_world": M})`` with
  M = rows (0,0,1), (1,0,0), (0,1,0), so that its world directions are gonio's frame
  (docs/ENVMAPS.md, "The frame"); ``sample_direction`` and ``pdf_direction`` on batches
  (variant ``llvm_ad_rgb`` when libLLVM is found, else ``scalar_rgb``, point by point).

and measures

1. **speed**: time per sample and per pdf of one vectorised batch (numpy in, numpy out, median of
   ``--repeats`` after a warm-up that also compiles Mitsuba's kernels), on one thread (gonio's
   batches on a one-thread rayon pool, ``RAYON_NUM_THREADS=1``; Mitsuba with
   ``dr.set_thread_count(1)``), and Mitsuba also on all threads (Dr.Jit's pool);
2. **direct illumination RMSE** as ``crates/gonio/examples/envmaps.rs`` computes it: a diffuse and
   a normalised-Phong (e = 200) surface, normals +z and (1, 0.3, 0.4)/|.|, light sampling alone
   and MIS (balance heuristic, one light and one BSDF sample per count), luminance radiance read by
   gonio's lookup (``nearest`` and ``bilinear``, the same integrand for both samplers), against a
   midpoint-rule reference (k x k points per pixel), ``--reps`` replicates at N = 64 ... 4096,
   iid and Owen-scrambled Sobol' points (``gonio.sequence``, the same points fed to both samplers,
   seeds as in the Rust example); slope = least-squares fit of log RMSE on log N; equal time =
   each sampler's RMSE at gonio's time budget for 4096 samples, from its one-thread cost per sample
   and its slope. The cost: ``sample`` with the radiance of the sample (gonio.EnvMap.sample and
   Mitsuba's ``sample_direction`` return it; the samplers of ``EnvMap.sampler`` pay one radiance
   lookup more), and for MIS the light pdf and the radiance of the BSDF sample's direction.

Samplers (``--no-peers``: the first and the last only): gonio's map (``gonio.EnvMap``, float64),
the float32 environment map (``gonio.EnvMap(path, precision="float32")``: the float32 map alone,
the precision Mitsuba works in, with the radiance in ``sample``), the
lat-long piecewise-constant and pbrt-v4-style peers (``EnvMap.sampler("latlong" | "pbrt-v4")``)
and Mitsuba 3's ``envmap``. The tables compare gonio with Mitsuba, then every sampler side by side
with the counts of the issue's targets.

Run (about 2-4 minutes on one core):

    bash scripts/test-python.sh -k envmap    # once: .venv with gonio, mitsuba and libllvm19
    .venv/bin/python benches/envmap_peers.py [--csv docs/experiments/envmap_peers.csv]

(libLLVM >= 16 is looked up where Debian's libllvm19 puts it, or set DRJIT_LIBLLVM_PATH.)

Options: ``--maps FILE...``, ``--reps``, ``--counts``, ``--ref-k`` (smaller values for a quick run;
the pytest suite runs it on a tiny generated map); ``--speed-only`` (the checks and the speed table
alone: ``--speed-only --repeats 7``).
"""

import argparse
import csv
import math
import os
import sys
import time

import numpy as np

# Dr.Jit 1.x needs LLVM >= 16 for the envmap kernels (LLVM 15 aborts: "Cannot select fmaximum").
LLVM_CANDIDATES = [
    "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1",
    *(f"/usr/lib/x86_64-linux-gnu/libLLVM-{v}.so" for v in range(19, 15, -1)),
    "/usr/lib/aarch64-linux-gnu/libLLVM.so.19.1",
    *(f"/usr/lib/aarch64-linux-gnu/libLLVM-{v}.so" for v in range(19, 15, -1)),
]
if not os.environ.get("DRJIT_LIBLLVM_PATH"):
    for _p in LLVM_CANDIDATES:
        if os.path.exists(_p):
            os.environ["DRJIT_LIBLLVM_PATH"] = _p
            break

os.environ.setdefault("RAYON_NUM_THREADS", "1")
import gonio  # noqa: E402 - after RAYON_NUM_THREADS

try:
    import drjit as dr
    import mitsuba as mi
except ImportError:
    print("skipping: mitsuba is not installed (pip install mitsuba)")
    sys.exit(0)

# gonio's batch calls run on rayon's pool; one thread, so that the one-thread costs are one thread's
# (the all-threads rows split a batch over Python threads instead).
os.environ.setdefault("RAYON_NUM_THREADS", "1")
PEER_NAMES = {"hds": "gonio-hds", "latlong": "latlong", "pbrt-v4": "pbrt-v4-style"}

TO_WORLD = [[0, 0, 1, 0], [1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0, 1]]
F32_BELOW_ONE = np.nextafter(np.float32(1), np.float32(0))


def pick_variant(want="auto"):
    if want == "scalar_rgb" or not os.environ.get("DRJIT_LIBLLVM_PATH"):
        if want != "scalar_rgb":
            print("no libLLVM >= 16 found (apt-get install libllvm19); using scalar_rgb (slow)", file=sys.stderr)
        mi.set_variant("scalar_rgb")
        return "scalar_rgb"
    try:
        mi.set_variant("llvm_ad_rgb")
        dr.eval(mi.Float([1.0, 2.0]) * 2)
        return "llvm_ad_rgb"
    except Exception as e:  # noqa: BLE001 - no libLLVM: Dr.Jit raises at first use
        print(f"llvm_ad_rgb unavailable ({e}); using scalar_rgb (slow, point by point)", file=sys.stderr)
        mi.set_variant("scalar_rgb")
        return "scalar_rgb"


class Mitsuba:
    """Mitsuba 3's envmap emitter through its Python API, numpy batches in and out."""

    name = "mitsuba"
    with_radiance = True  # sample_direction evaluates the image at the sample (its weight)

    def __init__(self, path, variant):
        self.variant = variant
        self.vector = variant.startswith("llvm")
        t = mi.ScalarTransform4f(TO_WORLD)
        self.emitter = mi.load_dict({"type": "envmap", "filename": str(path), "to_world": t})

    def sample(self, u):
        u = np.minimum(np.asarray(u, np.float32), F32_BELOW_ONE)
        if not self.vector:
            d = np.empty((len(u), 3))
            p = np.empty(len(u))
            it = mi.Interaction3f()
            for i, (a, b) in enumerate(u):
                ds, _ = self.emitter.sample_direction(it, mi.Point2f(float(a), float(b)))
                d[i] = (ds.d.x, ds.d.y, ds.d.z)
                p[i] = ds.pdf
            return d, p
        n = len(u)
        it = dr.zeros(mi.Interaction3f, n)
        ds, _ = self.emitter.sample_direction(it, mi.Point2f(*(mi.Float(np.ascontiguousarray(u[:, k])) for k in range(2))))
        dr.eval(ds.d, ds.pdf)
        d = np.stack([np.array(ds.d.x), np.array(ds.d.y), np.array(ds.d.z)], axis=1)
        return d.astype(np.float64), np.array(ds.pdf, dtype=np.float64)

    def pdf(self, d):
        d = np.asarray(d, np.float32)
        if not self.vector:
            it = mi.Interaction3f()
            out = np.empty(len(d))
            for i, v in enumerate(d):
                ds = mi.DirectionSample3f()
                ds.d = mi.Vector3f(*map(float, v))
                out[i] = self.emitter.pdf_direction(it, ds)
            return out
        n = len(d)
        it = dr.zeros(mi.Interaction3f, n)
        ds = dr.zeros(mi.DirectionSample3f, n)
        ds.d = mi.Vector3f(*(mi.Float(np.ascontiguousarray(d[:, k])) for k in range(3)))
        p = self.emitter.pdf_direction(it, ds)
        dr.eval(p)
        return np.array(p, dtype=np.float64)

    def threads(self, n):
        if self.vector:
            dr.set_thread_count(n)


class Gonio:
    """gonio.EnvMap, or one of its ``sampler(kind)``, in the map's precision; its batches run on
    rayon's pool (one thread in this script)."""

    def __init__(self, env, kind=None):
        self.env = env
        # gonio.EnvMap.sample returns the radiance with the sample; a gonio.Sampler does not.
        self.with_radiance = kind is None
        self.dtype = np.float32 if env.precision == "float32" else np.float64
        if kind is None:
            self.name = "gonio-hds" + ("-f32" if self.dtype == np.float32 else "")
            self.s = env
        else:
            self.s = env.sampler(kind)
            self.name = PEER_NAMES[kind]

    def sample(self, u):
        d, p = self.s.sample(np.asarray(u, self.dtype))[:2]
        return d.astype(np.float64, copy=False), p.astype(np.float64, copy=False)

    def pdf(self, d):
        return self.s.pdf(np.asarray(d, self.dtype)).astype(np.float64, copy=False)

    def threads(self, n):
        """One thread only (see the speed loop)."""


def median_time(f, repeats):
    f()  # warm-up (Mitsuba compiles its kernels here)
    ts = []
    for _ in range(repeats):
        t = time.perf_counter()
        f()
        ts.append(time.perf_counter() - t)
    return float(np.median(ts))


def luminance(rgb):
    return 0.2126 * rgb[:, 0] + 0.7152 * rgb[:, 1] + 0.0722 * rgb[:, 2]


def normalize(v):
    v = np.asarray(v, np.float64)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


class Surface:
    """Normal n; diffuse (e = 0) or normalised Phong of exponent e about the mirror r of a view."""

    def __init__(self, n, view, e):
        self.n = normalize(n)
        self.r = normalize(2 * np.dot(view, self.n) * self.n - view)
        self.e = e

    def f_cos(self, d):
        c = d @ self.n
        if self.e == 0:
            v = c / math.pi
        else:
            a = np.maximum(d @ self.r, 0.0)
            v = (self.e + 2) / (2 * math.pi) * a**self.e * c
        return np.where(c > 0, v, 0.0)

    def pdf(self, d):
        if self.e == 0:
            return np.maximum(d @ self.n, 0.0) / math.pi
        return (self.e + 1) / (2 * math.pi) * np.maximum(d @ self.r, 0.0) ** self.e

    def sample(self, u):
        axis, ex = (self.n, 1.0) if self.e == 0 else (self.r, self.e)
        ct = (1 - u[:, 0]) ** (1 / (ex + 1))
        st = np.sqrt(np.maximum(1 - ct * ct, 0))
        p = 2 * math.pi * u[:, 1]
        a = np.array([0.0, 1.0, 0.0]) if abs(axis[0]) > 0.9 else np.array([1.0, 0.0, 0.0])
        t = normalize(np.cross(axis, a))
        b = np.cross(axis, t)
        d = (st * np.cos(p))[:, None] * t + (st * np.sin(p))[:, None] * b + ct[:, None] * axis
        return d, self.pdf(d)


def image_directions(s, t):
    """gonio's frame: theta = pi t from +z, phi = pi - 2 pi s (docs/ENVMAPS.md)."""
    th, ph = math.pi * t, math.pi - 2 * math.pi * s
    return np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th) * np.ones_like(ph)], -1)


def references(env_lookup, w, h, surfaces, k):
    """Midpoint rule, k x k points per pixel, of f_cos * luminance for every surface."""
    nt, nph = h * k, w * k
    s = (np.arange(nph) + 0.5) / nph
    sums = np.zeros(len(surfaces))
    rows = max(1, (1 << 19) // nph)
    for i0 in range(0, nt, rows):
        t = (np.arange(i0, min(nt, i0 + rows)) + 0.5) / nt
        d = image_directions(s[None, :], t[:, None]).reshape(-1, 3)
        st = np.repeat(np.sin(math.pi * t), nph)
        lum = luminance(env_lookup.eval(d)) * st
        for j, sf in enumerate(surfaces):
            sums[j] += np.dot(sf.f_cos(d), lum)
    return sums * (math.pi / nt) * (2 * math.pi / nph)


def slope(counts, rmse):
    x = np.log(np.asarray(counts, float))
    y = np.log(np.maximum(np.asarray(rmse), 1e-300))
    return float(np.polyfit(x, y, 1)[0])


def run_map(path, variant, args, out_rows, speed_rows, check_rows):
    name = os.path.splitext(os.path.basename(path))[0]
    t0 = time.perf_counter()
    g = Gonio(gonio.EnvMap(path))
    t_g = time.perf_counter() - t0
    t0 = time.perf_counter()
    m = Mitsuba(path, variant)
    t_m = time.perf_counter() - t0
    w, h = g.env.width, g.env.height
    print(f"{name}: {w} x {h}; built in {t_g * 1e3:.0f} ms (gonio, with its file read), {t_m * 1e3:.0f} ms "
          "(Mitsuba, with its file read)", file=sys.stderr)
    samplers = [g, m]
    if not args.no_peers:
        samplers[1:1] = [Gonio(gonio.EnvMap(path, precision="float32")), Gonio(g.env, "latlong"),
                         Gonio(g.env, "pbrt-v4")]
    print(f"{name}: bytes per pixel beyond the image: "
          + ", ".join(f"{s.name} {s.env.memory_bytes / (w * h):.2f}" for s in samplers
                      if isinstance(s, Gonio) and s.s is s.env), file=sys.stderr)
    lookups = {"nearest": g.env, "bilinear": gonio.EnvMap(path, lookup="bilinear")}

    # 1. Speed: one batch of n points / directions.
    n = args.speed_n
    u = gonio.sequence(n, "random", 7)
    dirs = g.sample(u)[0]
    # Same frame and self-consistent densities: the mean sampled directions of the two samplers
    # (a wrong frame would rotate Mitsuba's), and pdf(sample(u)) against the sample's pdf.
    means, consistency = {}, {}
    for s in samplers:
        d, p = s.sample(u)
        means[s.name] = d.mean(axis=0)
        ok = p > 0
        consistency[s.name] = float(np.max(np.abs(s.pdf(d[ok]) - p[ok]) / p[ok]))
    a, b = means["gonio-hds"], means["mitsuba"]
    angle = math.degrees(math.acos(np.clip(a @ b / (np.linalg.norm(a) * np.linalg.norm(b)), -1, 1)))
    check_rows.append((name, angle, np.linalg.norm(a), np.linalg.norm(b),
                       consistency["gonio-hds"], consistency["mitsuba"]))
    print(f"{name}: max relative |pdf(sample) - sample's pdf|: "
          + ", ".join(f"{k} {v:.1e}" for k, v in consistency.items()), file=sys.stderr)
    ncores = os.cpu_count() or 1
    cost = {}
    for s in samplers:
        # gonio's batches run on rayon's pool, which this script holds to one thread (for the
        # one-thread costs): Python threads would only queue on it, so gonio is timed on one
        # thread; Mitsuba also on all (Dr.Jit's pool). benches/python_batches.py times gonio's
        # batches on all threads.
        for threads in sorted({1, ncores}) if isinstance(s, Mitsuba) else [1]:
            s.threads(threads)
            ts = median_time(lambda: s.sample(u), args.repeats)
            tp = median_time(lambda: s.pdf(dirs), args.repeats)
            speed_rows.append((name, s.name, threads, ts / n * 1e9, tp / n * 1e9))
            if threads == 1:
                cost[s.name] = (ts / n * 1e9, tp / n * 1e9)
        s.threads(1)
    t_eval = median_time(lambda: lookups["nearest"].eval(dirs), args.repeats) / n * 1e9
    if args.speed_only:
        return

    # 2. RMSE.
    view = normalize([0.3, -0.4, 1.0])
    normals = [np.array([0.0, 0.0, 1.0]), normalize([1.0, 0.3, 0.4])]
    surfaces = [(ni, sname, Surface(nv, view, e)) for ni, nv in enumerate(normals)
                for sname, e in (("diffuse", 0.0), ("glossy", 200.0))]
    counts, reps = args.counts, args.reps
    refs = {}
    for lk, env in lookups.items():
        k = args.ref_k if lk == "nearest" else 2 * args.ref_k
        refs[lk] = references(env, w, h, [sf for _, _, sf in surfaces], k)
    for kind in ("random", "sobol"):
        # Every (count, replicate) point set, concatenated: one batch per sampler.
        sets = [(c, rep) for c in counts for rep in range(reps)]
        p1 = np.concatenate([gonio.sequence(c, kind, 1000 + rep) for c, rep in sets])
        p2 = np.concatenate([gonio.sequence(c, kind, 5000 + rep) for c, rep in sets])
        starts = np.cumsum([0] + [c for c, _ in sets[:-1]])
        lights = {s.name: s.sample(p1) for s in samplers}
        for si, (ni, sname, sf) in enumerate(surfaces):
            db, pb = sf.sample(p2)
            fb = sf.f_cos(db)
            light_pdf_b = {s.name: s.pdf(db) for s in samplers}
            for lk, env in lookups.items():
                refv = refs[lk][si]
                lb = luminance(env.eval(db))
                for mis in (False, True):
                    res = {}
                    for s in samplers:
                        d, pl = lights[s.name]
                        fl = sf.f_cos(d)
                        ll = luminance(env.eval(d))
                        ok = pl > 0
                        wl = np.where(ok, pl / (pl + sf.pdf(d)) if mis else 1.0, 0.0)
                        contrib = np.where(ok, wl * fl * ll / np.where(ok, pl, 1.0), 0.0)
                        if mis:
                            okb = pb > 0
                            qb = light_pdf_b[s.name]
                            contrib = contrib + np.where(okb, fb * lb / np.where(okb, pb + qb, 1.0), 0.0)
                        est = np.add.reduceat(contrib, starts) / np.array([c for c, _ in sets])
                        err = (est - refv) ** 2
                        rmse = [math.sqrt(err[[i for i, (c2, _) in enumerate(sets) if c2 == c]].mean())
                                for c in counts]
                        ts, tp = cost[s.name]
                        # A light sample's radiance: inside `sample` for gonio.EnvMap and for
                        # Mitsuba's sample_direction (its weight), one lookup more for the others;
                        # MIS adds the light pdf and the radiance of the BSDF sample's direction.
                        ns = ts + (0.0 if s.with_radiance else t_eval) + ((tp + t_eval) if mis else 0.0)
                        bias = float(np.mean(est[[i for i, (c2, _) in enumerate(sets) if c2 == counts[-1]]]) - refv)
                        res[s.name] = (ns, rmse, slope(counts, rmse), bias)
                    ns_g = res["gonio-hds"][0]
                    for sname2, (ns, rmse, sl, bias) in res.items():
                        eq = rmse[-1] * (ns_g / ns) ** sl
                        out_rows.append({
                            "map": name, "radiance": lk, "surface": sname, "normal": ni,
                            "estimator": "mis" if mis else "light",
                            "points": "sobol" if kind == "sobol" else "iid", "sampler": sname2,
                            "ns_per_sample": round(ns, 1), **{f"rmse@{c}": f"{r:.4e}" for c, r in zip(counts, rmse)},
                            "slope": round(sl, 3), "rel_rmse_last": rmse[-1] / refv,
                            "rel_rmse_last_equal_time": eq / refv, "rel_bias_last": bias / refv,
                        })


def print_all_samplers(groups, names, last):
    """Every sampler of the run side by side: per case the equal-time RMSE and the slope of each,
    then the counts of the targets (gonio's map at least as good as the best peer at equal time;
    with Sobol' points a steeper slope than every discontinuous peer)."""
    gonios = [n for n in names if n.startswith("gonio")]
    peers = [n for n in names if not n.startswith("gonio")]
    print(f"\n### Every sampler in the same run (relative RMSE at equal time, N = {last} for gonio-hds's time; "
          "slope)\n")
    print("| map | radiance | surface | normal | estimator | points | " + " | ".join(names)
          + " | slopes: " + " / ".join(names) + " |")
    print("|" + "---|" * (7 + len(names)))
    tally = {}
    for k, gr in sorted(groups.items()):
        nrm = "+z" if k[2] == 0 else "(1, 0.3, 0.4)"
        eq = {n: gr[n]["rel_rmse_last_equal_time"] for n in names}
        sl = {n: gr[n]["slope"] for n in names}
        best = min(eq.values())
        cells = " | ".join(("**%.2e**" if eq[n] == best else "%.2e") % eq[n] for n in names)
        print(f"| {k[0]} | {k[1]} | {k[3]} | {nrm} | {k[4]} | {k[5]} | {cells} | "
              + " / ".join(f"{sl[n]:.2f}" for n in names) + " |")
        t = tally.setdefault((k[1], k[4], k[5]), {})
        best_peer = min(eq[p] for p in peers)
        for gname in gonios:
            t.setdefault(gname + " ≤ best peer", [0, 0])
            t[gname + " ≤ best peer"][0] += eq[gname] <= best_peer
            t[gname + " ≤ best peer"][1] += 1
            t.setdefault(gname + " slope steeper than every peer", [0, 0])
            t[gname + " slope steeper than every peer"][0] += all(sl[gname] < sl[p] for p in peers)
            t[gname + " slope steeper than every peer"][1] += 1
    cols = list(next(iter(tally.values())).keys())
    print("\n| radiance | estimator | points | " + " | ".join(cols) + " |")
    print("|" + "---|" * (3 + len(cols)))
    totals = {c: [0, 0] for c in cols}
    for wk, t in sorted(tally.items()):
        for c in cols:
            totals[c][0] += t[c][0]
            totals[c][1] += t[c][1]
        print(f"| {wk[0]} | {wk[1]} | {wk[2]} | " + " | ".join(f"{t[c][0]} of {t[c][1]}" for c in cols) + " |")
    print("| all | | | " + " | ".join(f"{totals[c][0]} of {totals[c][1]}" for c in cols) + " |")


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    shared = os.environ.get("GONIO_ENVMAPS") or os.path.join(here, "..", "..", "..", "shared", "data", "envmaps")
    if not os.path.isdir(shared):
        shared = "/work/shared/data/envmaps"
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--maps", nargs="*", default=[os.path.join(shared, f"{m}.hdr") for m in ("studio", "sunset", "night")])
    ap.add_argument("--reps", type=int, default=32)
    ap.add_argument("--counts", type=int, nargs="*", default=[64, 256, 1024, 4096])
    ap.add_argument("--ref-k", type=int, default=4, help="reference points per pixel side (nearest; bilinear 2x)")
    ap.add_argument("--speed-n", type=int, default=1 << 18)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--variant", choices=["auto", "scalar_rgb"], default="auto",
                    help="Mitsuba variant: llvm_ad_rgb when libLLVM >= 16 is found (auto), or scalar_rgb")
    ap.add_argument("--speed-only", action="store_true",
                    help="only the frame checks and the speed table (part 1; no RMSE)")
    ap.add_argument("--no-peers", action="store_true",
                    help="gonio's float64 map and Mitsuba only (no float32 map, lat-long or pbrt-v4-style rows)")
    ap.add_argument("--csv", help="write every row here")
    ap.add_argument("--checks-json", help="write the frame and pdf checks here (for the smoke test)")
    args = ap.parse_args()
    variant = pick_variant(args.variant)
    print(f"mitsuba {mi.__version__} ({variant}), gonio {gonio.__version__}, {os.cpu_count()} cores", file=sys.stderr)
    rows, speed, checks = [], [], []
    t0 = time.perf_counter()
    for p in args.maps:
        run_map(p, variant, args, rows, speed, checks)
    print(f"ran in {time.perf_counter() - t0:.0f} s", file=sys.stderr)

    print("\n| map | angle between the mean sampled directions | their lengths: gonio / Mitsuba "
          "| max rel. pdf(sample) - sample pdf: gonio / Mitsuba |\n|---|---|---|---|")
    for r in checks:
        print(f"| {r[0]} | {r[1]:.2f}° | {r[2]:.3f} / {r[3]:.3f} | {r[4]:.1e} / {r[5]:.1e} |")
    if args.checks_json:
        import json
        with open(args.checks_json, "w") as f:
            json.dump([dict(zip(["map", "angle_deg", "len_gonio", "len_mitsuba", "pdf_gonio", "pdf_mitsuba"], r))
                       for r in checks], f)
    print("\n| map | sampler | threads | ns per sample | ns per pdf |\n|---|---|---|---|---|")
    for r in speed:
        print(f"| {r[0]} | {r[1]} | {r[2]} | {r[3]:.0f} | {r[4]:.0f} |")
    if args.speed_only:
        return
    last = args.counts[-1]
    print(f"\n| map | radiance | surface | normal | estimator | points | rel. RMSE @{last}: gonio / Mitsuba "
          "| equal time: gonio / Mitsuba | slope: gonio / Mitsuba | rel. bias @%d: gonio / Mitsuba |" % last)
    print("|---|---|---|---|---|---|---|---|---|---|")
    key = lambda r: (r["map"], r["radiance"], r["normal"], r["surface"], r["estimator"], r["points"])  # noqa: E731
    groups = {}
    for r in rows:
        groups.setdefault(key(r), {})[r["sampler"]] = r
    wins = {}
    for k, gr in groups.items():
        a, b = gr["gonio-hds"], gr["mitsuba"]
        nrm = "+z" if k[2] == 0 else "(1, 0.3, 0.4)"
        print(f"| {k[0]} | {k[1]} | {k[3]} | {nrm} | {k[4]} | {k[5]} | {a['rel_rmse_last']:.2e} / {b['rel_rmse_last']:.2e} "
              f"| {a['rel_rmse_last_equal_time']:.2e} / {b['rel_rmse_last_equal_time']:.2e} "
              f"| {a['slope']:.2f} / {b['slope']:.2f} | {a['rel_bias_last']:+.1e} / {b['rel_bias_last']:+.1e} |")
        wk = (k[1], k[4], k[5])
        w = wins.setdefault(wk, [0, 0, 0])
        w[0] += a["rel_rmse_last_equal_time"] <= b["rel_rmse_last_equal_time"]
        w[1] += a["slope"] < b["slope"]
        w[2] += 1
    print("\n| radiance | estimator | points | gonio RMSE ≤ Mitsuba's at equal time | gonio slope steeper |\n|---|---|---|---|---|")
    for wk, (eqt, sl, tot) in sorted(wins.items()):
        print(f"| {wk[0]} | {wk[1]} | {wk[2]} | {eqt} of {tot} | {sl} of {tot} |")
    names = [n for n in ("gonio-hds", "gonio-hds-f32", "latlong", "pbrt-v4-style", "mitsuba")
             if any(n in gr for gr in groups.values())]
    if len(names) > 2:
        print_all_samplers(groups, names, last)
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            wr = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
            wr.writeheader()
            for r in rows:
                wr.writerow({k: (f"{v:.4e}" if isinstance(v, float) and k.startswith("rel_") else v) for k, v in r.items()})


if __name__ == "__main__":
    main()
