#!/usr/bin/env python3
"""Render times of gonio's Dr.Jit emitters against Mitsuba's own (docs/MITSUBA.md): the
``"gonio"`` point luminaire against Mitsuba's ``point``, and ``"gonio_envmap"`` against
Mitsuba's ``envmap`` (same image), with the ``path`` and ``ptracer`` integrators, Mitsuba's
default (symbolic) JIT flags, in one run. Scenes: a floor and a wall under the luminaire 2 m up;
a diffuse ball on a floor under the environment. ``max_depth`` 3. Each row: the first render
(tracing, compiling, rendering) and the best of REPEATS renders after it (kernels cached), seconds.

    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 \\
      .venv/bin/python benches/mitsuba_drjit.py [--size 512] [--spp 64] [--repeats 3]
      [--file LAMP.ies|.ldt] [--envmap SKY.hdr] [--variant llvm_ad_rgb]

The defaults (--size 128, --spp 16) make a quick run; the figures of docs/MITSUBA.md are
--size 512 --spp 64.
"""

import argparse
import os
import pathlib
import time


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--size", type=int, default=128, help="image width and height (pixels)")
    p.add_argument("--spp", type=int, default=16)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--file", default=None, help="IES/LDT file (default: the corpus's LEDiL Strada road optic)")
    p.add_argument("--envmap", default=None, help="lat-long .hdr/.exr (default: the shared studio.hdr)")
    p.add_argument("--variant", default="llvm_ad_rgb")
    p.add_argument("--fast-math", action="store_true",
                   help="gonio's map with Dr.Jit's fast math (gonio.drjit.IEEE = False; CUDA's approximate division)")
    a = p.parse_args()

    import drjit as dr
    import mitsuba as mi

    mi.set_variant(a.variant)
    import gonio.drjit
    import gonio.mitsuba as gm

    gonio.drjit.IEEE = not a.fast_math
    gm.register()
    here = pathlib.Path(__file__).resolve().parents[1]
    corpus = pathlib.Path(os.environ.get("GONIO_CORPUS") or here.parent / "shared" / "data" / "photometry")
    envs = pathlib.Path(os.environ.get("GONIO_ENVMAPS") or here.parent / "shared" / "data" / "envmaps")
    lamp_file = a.file or str(corpus / "ldt" / "isym0_ledil_strada_72x181.ldt")
    env_file = a.envmap or str(envs / "studio.hdr")
    T = mi.ScalarTransform4f

    def sensor(origin):
        return {"type": "perspective", "fov": 50,
                "to_world": T().look_at(origin=origin, target=[0, 0, 0], up=[0, 0, 1]),
                "film": {"type": "hdrfilm", "width": a.size, "height": a.size, "rfilter": {"type": "box"}},
                "sampler": {"type": "independent", "sample_count": a.spp}}

    def lamp_scene(lamp, integrator):
        return mi.load_dict({
            "type": "scene", "integrator": {"type": integrator, "max_depth": 3}, "sensor": sensor([0, -4, 3]),
            "floor": {"type": "rectangle", "to_world": T().scale([5, 5, 1]), "bsdf": {"type": "diffuse"}},
            "wall": {"type": "rectangle", "to_world": T().translate([0, 3, 0]) @ T().rotate([1, 0, 0], 90)
                     @ T().scale([5, 5, 1]), "bsdf": {"type": "diffuse"}},
            "lamp": lamp,
        })

    def env_scene(env, integrator):
        return gm.prepare(mi.load_dict({
            "type": "scene", "integrator": {"type": integrator, "max_depth": 3}, "sensor": sensor([0, -5, 1.5]),
            "ball": {"type": "sphere", "bsdf": {"type": "diffuse"}},
            "floor": {"type": "rectangle", "to_world": T().translate([0, 0, -1]) @ T().scale(4),
                      "bsdf": {"type": "diffuse"}},
            "env": env,
        }))

    def timed(sc, seed):
        t0 = time.perf_counter()
        img = mi.render(sc, seed=seed)
        dr.eval(img)
        dr.sync_thread()
        return time.perf_counter() - t0

    def measure(sc):
        first = timed(sc, 0)
        return first, min(timed(sc, k + 1) for k in range(a.repeats))

    point = {"type": "point", "position": [0, 0, 2], "intensity": {"type": "rgb", "value": [100.0] * 3}}
    gonio_lamp = {"type": "gonio", "filename": lamp_file, "to_world": T().translate([0, 0, 2])}
    env_mi = {"type": "envmap", "filename": env_file}
    env_g = {"type": "gonio_envmap", "filename": env_file}
    print(f"Mitsuba {mi.__version__}, {a.variant}, {a.size} x {a.size} px, {a.spp} spp, max_depth 3, "
          f"symbolic calls {dr.flag(dr.JitFlag.SymbolicCalls)}, symbolic loops {dr.flag(dr.JitFlag.SymbolicLoops)}, "
          f"gonio map {'fast math' if a.fast_math else 'IEEE'}; "
          f"best of {a.repeats} after the first render, seconds")
    print(f"luminaire: {lamp_file}\nenvironment: {env_file}\n")
    print("| scene | integrator | Mitsuba first / best | gonio first / best | gonio / Mitsuba (best) |")
    print("|---|---|---|---|---|")
    for title, mk, ours, theirs in (("point luminaire", lamp_scene, gonio_lamp, point),
                                    ("environment map", env_scene, env_g, env_mi)):
        for integrator in ("path", "ptracer"):
            m1, mb = measure(mk(theirs, integrator))
            g1, gb = measure(mk(ours, integrator))
            print(f"| {title} | {integrator} | {m1:.3f} / {mb:.3f} | {g1:.3f} / {gb:.3f} | {gb / mb:.2f} |", flush=True)


if __name__ == "__main__":
    main()
