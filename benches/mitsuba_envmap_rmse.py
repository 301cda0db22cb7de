#!/usr/bin/env python3
"""The sky inside the renderer (docs/MITSUBA.md, issue 37 item 5): ``"gonio_envmap"`` against
Mitsuba's own ``envmap`` (same image, same ``to_world``), ``path`` with MIS (``max_depth`` 3),
a diffuse and a glossy object under each shared map, in one run:

* **equal spp**: the render time of each emitter at --spp (the best of --repeats renders after a
  first one that traces and compiles; the two emitters' renders interleaved, so that a change of
  the machine's load hits both);
* **equal time**: each emitter gets the samples per pixel that Mitsuba's time at --spp buys it
  (spp × t_envmap / t_emitter, at least 1), and its RMSE against a converged reference (Mitsuba's
  ``envmap`` at --ref-spp, in passes of --pass-spp), relative to the reference's mean, the root of
  the mean squared error over --rmse-seeds renders; and, per sample, the RMSE of both at --spp;
* **the references**: the RMSE between the converged reference and a ``gonio_envmap`` render at
  --ref-spp, beside what the two references' noise alone would give (√2 × envmap's RMSE at --spp
  × √(spp / ref-spp)): what exceeds it is the floor below which gonio's error cannot go against
  Mitsuba's picture (Mitsuba puts its image rows on the poles, gonio at pixel centres: the directly
  seen sky and sharp reflections differ by up to half a row's shift).

Scenes (as crates/gonio-py/tests/test_drjit_emitters.py): a unit ball on a floor, the camera
5 m away looking at it, the map seen above the floor. Diffuse: a diffuse ball (0.7) on a diffuse
floor (0.5). Glossy: rough aluminium (``roughconductor``, GGX α = 0.2) on rough plastic (α = 0.15).

    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 \\
      .venv/bin/python benches/mitsuba_envmap_rmse.py [--size 64] [--spp 16] [--ref-spp 1024]
      [--repeats 3] [--rmse-seeds 4] [--maps studio.hdr,sunset.hdr,night.hdr] [--lookup bilinear]
      [--variant llvm_ad_rgb]

Maps: the shared ones ($GONIO_ENVMAPS or ../shared/data/envmaps), or paths.
"""

import argparse
import os
import pathlib
import sys
import time

import numpy as np


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--size", type=int, default=64, help="image width and height (pixels)")
    p.add_argument("--spp", type=int, default=16, help="samples per pixel of the timed renders")
    p.add_argument("--ref-spp", type=int, default=1024, help="samples per pixel of the references")
    p.add_argument("--pass-spp", type=int, default=64, help="the references are rendered in passes of this many spp")
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--rmse-seeds", type=int, default=4, help="renders whose squared errors are averaged")
    p.add_argument("--maps", default="studio.hdr,sunset.hdr,night.hdr")
    p.add_argument("--lookup", default="bilinear", help="gonio_envmap's lookup (Mitsuba's envmap reads bilinearly)")
    p.add_argument("--objects", default="diffuse,glossy")
    p.add_argument("--variant", default="llvm_ad_rgb")
    a = p.parse_args()

    import drjit as dr
    import mitsuba as mi

    mi.set_variant(a.variant)
    import gonio.mitsuba as gm

    gm.register()
    here = pathlib.Path(__file__).resolve().parents[1]
    envs = pathlib.Path(os.environ.get("GONIO_ENVMAPS") or here.parent / "shared" / "data" / "envmaps")

    sys.path.insert(0, str(here / "crates" / "gonio-py" / "tests"))
    from test_drjit_emitters import _ball_scene

    def scene(kind, path, glossy):
        """The ball scene of the test suite (test_drjit_emitters.py) at this run's size and spp."""
        lookup = a.lookup if kind == "gonio_envmap" else None
        return _ball_scene(mi, kind, path, "path", spp=a.spp, res=a.size, lookup=lookup, glossy=glossy)

    def render(sc, seed, spp):
        img = mi.render(sc, seed=seed, spp=spp)
        dr.eval(img)
        dr.sync_thread()
        return img

    def timed(sc, seed):
        t0 = time.perf_counter()
        render(sc, seed, a.spp)
        return time.perf_counter() - t0

    def converged(sc, seed0):
        n = max(1, a.ref_spp // a.pass_spp)
        acc = None
        for k in range(n):
            img = np.array(render(sc, seed0 + k, a.pass_spp), dtype=np.float64)
            acc = img if acc is None else acc + img
        return acc / n

    def rel_rmse(img, ref):
        return float(np.sqrt(np.mean((img - ref) ** 2)) / ref.mean())

    print(f"Mitsuba {mi.__version__}, {a.variant}, {a.size} x {a.size} px, path (MIS), max_depth 3, "
          f"symbolic calls {dr.flag(dr.JitFlag.SymbolicCalls)}, symbolic loops {dr.flag(dr.JitFlag.SymbolicLoops)}; "
          f"times at {a.spp} spp (best of {a.repeats} after the first render), RMSE / mean of the reference "
          f"(Mitsuba's envmap at {a.ref_spp} spp) over {a.rmse_seeds} renders; gonio_envmap lookup {a.lookup}")
    print()
    print("| object | map | time at equal spp: envmap / gonio_envmap (s) | gonio / envmap "
          "| RMSE at equal spp: envmap / gonio_envmap | equal-time spp: envmap / gonio_envmap "
          "| RMSE at equal time: envmap / gonio_envmap | references apart: measured / noise alone |")
    print("|---|---|---|---|---|---|---|---|")
    for obj in a.objects.split(","):
        for name in a.maps.split(","):
            path = pathlib.Path(name) if os.sep in name else envs / name
            sm = scene("envmap", path, obj == "glossy")
            sg = scene("gonio_envmap", path, obj == "glossy")
            timed(sm, 0)
            timed(sg, 0)
            tm, tg = [], []
            for k in range(a.repeats):
                tm.append(timed(sm, k + 1))
                tg.append(timed(sg, k + 1))
            tm, tg = min(tm), min(tg)
            ref = converged(sm, 100_000)
            bias = rel_rmse(converged(sg, 200_000), ref)
            spp_m = a.spp
            spp_g = max(1, int(round(a.spp * tm / tg)))
            def rmse(sc, spp):
                e = [rel_rmse(np.array(render(sc, 1000 + k, spp), dtype=np.float64), ref) for k in range(a.rmse_seeds)]
                return float(np.sqrt(np.mean(np.square(e))))

            rm = rmse(sm, spp_m)
            rg_spp = rmse(sg, a.spp)
            rg = rmse(sg, spp_g) if spp_g != a.spp else rg_spp
            noise = float(np.sqrt(2.0) * rm * np.sqrt(a.spp / (max(1, a.ref_spp // a.pass_spp) * a.pass_spp)))
            print(f"| {obj} | {path.name} | {tm:.3f} / {tg:.3f} | {tg / tm:.2f} | {rm:.4f} / {rg_spp:.4f} "
                  f"| {spp_m} / {spp_g} | {rm:.4f} / {rg:.4f} | {bias:.4f} / {noise:.4f} |", flush=True)


if __name__ == "__main__":
    main()
