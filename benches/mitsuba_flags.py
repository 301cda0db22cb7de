#!/usr/bin/env python3
"""What the JIT flags cost that gonio's Mitsuba emitter needs in llvm_ad_rgb (docs/MITSUBA.md):
render times of a floor under a point light, Mitsuba's own ``point`` emitter with the default
(symbolic) flags and with ``SymbolicCalls`` and ``SymbolicLoops`` off (wavefront mode), and
gonio's ``"gonio"`` emitter (which needs them off), for the ``path`` and ``ptracer`` integrators.
Best of REPEATS renders after a warm-up, seconds.

    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 \\
      .venv/bin/python benches/mitsuba_flags.py [FILE] [--res 64] [--spp 16]
"""

import argparse
import os
import pathlib
import time


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("file", nargs="?", default=None)
    p.add_argument("--res", type=int, default=64)
    p.add_argument("--spp", type=int, default=16)
    p.add_argument("--repeats", type=int, default=5)
    a = p.parse_args()

    import drjit as dr
    import mitsuba as mi

    mi.set_variant("llvm_ad_rgb")
    import gonio.mitsuba as gm

    root = os.environ.get("GONIO_CORPUS") or pathlib.Path(__file__).resolve().parents[1] / ".." / "shared" / "data" / "photometry"
    f = a.file or str(pathlib.Path(root) / "ldt" / "isym0_ledil_strada_72x181.ldt")
    T = mi.ScalarTransform4f

    def scene(lamp, integrator):
        return mi.load_dict({
            "type": "scene",
            "integrator": {"type": integrator, "max_depth": 3},
            "sensor": {"type": "perspective", "fov": 60,
                       "to_world": T().look_at(origin=[0, -4, 3], target=[0, 0, 0], up=[0, 0, 1]),
                       "film": {"type": "hdrfilm", "width": a.res, "height": a.res},
                       "sampler": {"type": "independent", "sample_count": a.spp}},
            "floor": {"type": "rectangle", "to_world": T().scale([5, 5, 1]), "bsdf": {"type": "diffuse"}},
            "wall": {"type": "rectangle", "to_world": T().translate([0, 3, 0]) @ T().rotate([1, 0, 0], 90) @ T().scale([5, 5, 1]),
                     "bsdf": {"type": "diffuse"}},
            "lamp": lamp,
        })

    def best(lamp, integrator):
        sc = scene(lamp, integrator)
        mi.render(sc)
        dr.sync_thread()
        ts = []
        for k in range(a.repeats):
            t0 = time.perf_counter()
            mi.render(sc, seed=k + 1)
            dr.sync_thread()
            ts.append(time.perf_counter() - t0)
        return min(ts)

    point = {"type": "point", "position": [0, 0, 2], "intensity": {"type": "rgb", "value": [100.0] * 3}}
    gonio_lamp = {"type": "gonio", "filename": f, "to_world": T().translate([0, 0, 2])}
    rows = []
    for integrator in ("path", "ptracer"):
        dr.set_flag(dr.JitFlag.SymbolicCalls, True)
        dr.set_flag(dr.JitFlag.SymbolicLoops, True)
        t_sym = best(point, integrator)
        dr.set_flag(dr.JitFlag.SymbolicCalls, False)
        dr.set_flag(dr.JitFlag.SymbolicLoops, False)
        t_wave = best(point, integrator)
        gm.register()
        t_gonio = best(gonio_lamp, integrator)
        rows.append((integrator, t_sym, t_wave, t_gonio))
    print(f"{a.res}x{a.res} px, {a.spp} spp, max_depth 3, Mitsuba {mi.__version__}; best of {a.repeats}, seconds")
    print("integrator  point (symbolic)  point (wavefront)  gonio (wavefront)")
    for r in rows:
        print(f"{r[0]:10s}  {r[1]:16.3f}  {r[2]:17.3f}  {r[3]:17.3f}")


if __name__ == "__main__":
    main()
