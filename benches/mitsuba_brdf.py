#!/usr/bin/env python3
"""Measured materials inside the renderer (docs/BRDF.md, issue 39 item 3): ``"gonio_brdf"`` on a
sphere under each shared environment map, ``path`` with MIS (``max_depth`` 3), in one run:

* **speed at equal spp**: the render time of ``gonio_brdf`` (a GGX conductor table, α = --alpha,
  Mitsuba's separable Smith masking, F = (0.9, 0.6, 0.3), 2° × 4° grid) against Mitsuba's
  ``roughconductor`` of the same α and colour, and against ``gonio_brdf`` with
  ``sampling="cosine"`` (the same table sampled by a cosine lobe: what a renderer that reads MERL
  does); the best of --repeats renders after a first one that traces and compiles, the renders
  interleaved;
* **quality**: the RMSE at equal spp and at equal time (each method gets the spp that
  roughconductor's time at --spp buys it) against a converged reference (``roughconductor`` at
  --ref-spp: the table is that BRDF), relative to the reference's mean, root of the mean over
  --rmse-seeds renders.

    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 \\
      .venv/bin/python benches/mitsuba_brdf.py [--size 128] [--spp 16] [--ref-spp 1024]
      [--repeats 3] [--rmse-seeds 4] [--alpha 0.2] [--variant llvm_ad_rgb]
"""

import argparse
import os
import pathlib
import sys
import tempfile
import time

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--size", type=int, default=128)
    p.add_argument("--spp", type=int, default=16)
    p.add_argument("--ref-spp", type=int, default=1024)
    p.add_argument("--pass-spp", type=int, default=256)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--rmse-seeds", type=int, default=4)
    p.add_argument("--alpha", type=float, default=0.2)
    p.add_argument("--variant", default="llvm_ad_rgb")
    a = p.parse_args()

    import mitsuba as mi

    mi.set_variant(a.variant)
    import gonio.mitsuba as gm

    gm.register()
    sys.path.insert(0, str(ROOT / "crates" / "gonio-py" / "tests"))
    from test_drjit_brdf import SPECULAR, ggx_table

    envdir = pathlib.Path(os.environ.get("GONIO_ENVMAPS") or ROOT.parent / "shared" / "data" / "envmaps")
    maps = sorted(envdir.glob("*.hdr"))
    tmp = tempfile.mkdtemp(prefix="gonio-brdf-bench-")
    table = ggx_table(pathlib.Path(tmp) / "ggx.json", a.alpha, a.alpha, 46, 90)
    bsdfs = {
        "roughconductor": {"type": "roughconductor", "distribution": "ggx", "alpha": a.alpha,
                           "specular_reflectance": {"type": "rgb", "value": SPECULAR}},
        "gonio_brdf": {"type": "gonio_brdf", "filename": str(table)},
        "gonio_brdf cosine": {"type": "gonio_brdf", "filename": str(table), "sampling": "cosine"},
    }

    def scene(env, bsdf, spp):
        return mi.load_dict({
            "type": "scene", "integrator": {"type": "path", "max_depth": 3},
            "sensor": {"type": "perspective", "fov": 30,
                       "to_world": mi.ScalarTransform4f().look_at(origin=[0, -5, 1.5], target=[0, 0, 0],
                                                                  up=[0, 0, 1]),
                       "film": {"type": "hdrfilm", "width": a.size, "height": a.size, "rfilter": {"type": "box"}},
                       "sampler": {"type": "independent", "sample_count": spp}},
            "ball": {"type": "sphere", "bsdf": bsdf},
            "sky": {"type": "envmap", "filename": str(env)}})

    def render(s, seed, spp=None):
        img = mi.render(s, seed=seed, spp=spp or 0)
        return np.array(img, dtype=np.float64)

    print(f"# gonio_brdf bench: {a.size}² px, path max_depth 3, GGX α = {a.alpha}, variant {a.variant}, "
          f"{os.cpu_count()} CPUs")
    print("| map | method | ms at %d spp | × roughconductor | RMSE at equal spp | spp at equal time | "
          "RMSE at equal time |" % a.spp)
    print("|---|---|---|---|---|---|---|")
    for env in maps:
        scenes = {k: scene(env, b, a.spp) for k, b in bsdfs.items()}
        for s in scenes.values():
            render(s, 0)  # trace and compile
        times = {k: [] for k in scenes}
        for _ in range(a.repeats):
            for k, s in scenes.items():
                t0 = time.perf_counter()
                render(s, 1)
                times[k].append(time.perf_counter() - t0)
        best = {k: min(v) for k, v in times.items()}
        ref_scene = scene(env, bsdfs["roughconductor"], a.pass_spp)
        passes = max(1, a.ref_spp // a.pass_spp)
        ref = sum(render(ref_scene, 1000 + k) for k in range(passes)) / passes
        scale = ref.mean()

        def rmse(s, spp):
            errs = [np.mean((render(s, 100 + k, spp) - ref) ** 2) for k in range(a.rmse_seeds)]
            return float(np.sqrt(np.mean(errs)) / scale)

        for k, s in scenes.items():
            eq_spp = max(1, int(round(a.spp * best["roughconductor"] / best[k])))
            print(f"| {env.name} | {k} | {1e3 * best[k]:.1f} | {best[k] / best['roughconductor']:.2f} | "
                  f"{rmse(s, a.spp):.4f} | {eq_spp} | {rmse(s, eq_spp):.4f} |", flush=True)


if __name__ == "__main__":
    main()
