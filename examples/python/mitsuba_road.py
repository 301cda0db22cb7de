"""A street light over a road in Mitsuba 3: gonio's emitter against what a Mitsuba user does today
(a point light that emits uniformly and is weighted by the profile, the community Python emitter of
mitsuba3 discussion #809), by light tracing (Mitsuba's ``ptracer``), where the emitter's
``sample_ray`` decides the noise.

    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 \\
      .venv/bin/python examples/python/mitsuba_road.py [FILE] [--spp 256] [-o docs/gallery/mitsuba-road.png]

Scene: a road 8 m wide (albedo 0.15) between verges (0.3), a pole 8 m high at the kerb with a 1.5 m
arm; the luminaire (default: the corpus's LEDiL Strada road optic, EULUMDAT) hangs at the arm's end,
C0 along the road, C90 across it toward the road's far side. A driver's camera at 1.5 m looks down
the road. Reference: Mitsuba's ``path`` integrator (next-event estimation toward the point light:
deterministic direct light, no emitter sampling involved) at 256 spp, direct light only
(``max_depth`` 2) for every image.

Printed: RMSE of each light-tracing image against the reference, relative to the reference's mean,
at equal samples per pixel and at equal time (the uniform emitter gets as many more samples as its
cheaper sample_ray buys). Written: the picture (reference | uniform | gonio at equal time).
"""

from typing import Any
import argparse
import math
import os
import pathlib
import time

import numpy as np

from _pictures import save, srgb


def corpus_file() -> pathlib.Path:
    env = os.environ.get("GONIO_CORPUS")
    root = pathlib.Path(env) if env else pathlib.Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "photometry"
    return root / "ldt" / "isym0_ledil_strada_72x181.ldt"


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("file", nargs="?", default=None, help="IES or LDT file (default: the corpus's Strada)")
    p.add_argument("--spp", type=int, default=256, help="light-tracing samples per pixel (256, in passes of 16)")
    p.add_argument("--width", type=int, default=240)
    p.add_argument("--height", type=int, default=135)
    p.add_argument("-o", "--out", default="docs/gallery/mitsuba-road.png")
    a = p.parse_args()

    import drjit as dr
    import mitsuba as mi

    mi.set_variant("llvm_ad_rgb")
    import gonio
    import gonio.mitsuba as gm

    Gonio = gm.register()
    # The uniform-profile peer below runs numpy inside its methods, which a symbolic (recorded)
    # call or loop cannot do: wavefront mode for this comparison (gonio's own emitter needs none).
    dr.set_flag(dr.JitFlag.SymbolicCalls, False)
    dr.set_flag(dr.JitFlag.SymbolicLoops, False)

    class UniformProfile(Gonio):  # type: ignore[valid-type,misc]  # (a class made at run time)
        """The community approach: a point light that samples rays uniformly over the sphere,
        weight 4π·I(ω), and lights points by I(ω)/r² (the same as gonio's)."""

        def sample_ray(self, time: Any, sample1: Any, sample2: Any, sample3: Any, active: Any = True) -> Any:
            u = np.stack(np.broadcast_arrays(np.asarray(sample3.x, np.float64).reshape(-1),
                                             np.asarray(sample3.y, np.float64).reshape(-1)), axis=1)
            z = 1.0 - 2.0 * u[:, 0]
            r = np.sqrt(np.maximum(0.0, 1.0 - z * z))
            phi = 2.0 * math.pi * u[:, 1]
            d = np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)
            w = 4.0 * math.pi * self._intensity(d)
            dw = self._world_dir(d)
            n = len(d)
            def f(x: Any) -> Any:
                return mi.Float(np.ascontiguousarray(x, dtype=np.float32))

            o = np.broadcast_to(self.t, (n, 3))
            ray = mi.Ray3f(mi.Point3f(f(o[:, 0]), f(o[:, 1]), f(o[:, 2])), mi.Vector3f(f(dw[:, 0]), f(dw[:, 1]), f(dw[:, 2])))
            return ray, mi.Color3f(f(w))

    mi.register_emitter("uniform_profile", lambda props: UniformProfile(props))

    PASS = 16
    path = pathlib.Path(a.file) if a.file else corpus_file()
    d = gonio.read(path)
    T = mi.ScalarTransform4f
    head = [-4.0 + 1.5, 0.0, 8.0]  # kerb at x = −4; the arm reaches 1.5 m over the road
    lamp_T = T().translate(head) @ T().rotate([0, 0, 1], -90)  # C0 → −y (along), C90 → +x (across)

    def diffuse(v: Any) -> dict[str, Any]:
        return {"type": "diffuse", "reflectance": {"type": "rgb", "value": v}}

    def scene(emitter_type: str, integrator: str, spp: int, seed: int) -> Any:
        return mi.load_dict({
            "type": "scene",
            "integrator": {"type": integrator, "max_depth": 2},
            "sensor": {
                "type": "perspective", "fov": 60, "fov_axis": "x",
                "to_world": T().look_at(origin=[1.5, -22.0, 1.5], target=[0.0, 8.0, 0.0], up=[0, 0, 1]),
                "film": {"type": "hdrfilm", "width": a.width, "height": a.height, "rfilter": {"type": "box"},
                         "pixel_format": "rgb"},
                "sampler": {"type": "independent", "sample_count": spp, "seed": seed},
            },
            "road": {"type": "rectangle", "to_world": T().scale([4.0, 60.0, 1.0]), "bsdf": diffuse([0.15] * 3)},
            "verge_l": {"type": "rectangle", "to_world": T().translate([-24.0, 0.0, 0.0]) @ T().scale([20.0, 60.0, 1.0]),
                        "bsdf": diffuse([0.2, 0.3, 0.15])},
            "verge_r": {"type": "rectangle", "to_world": T().translate([24.0, 0.0, 0.0]) @ T().scale([20.0, 60.0, 1.0]),
                        "bsdf": diffuse([0.2, 0.3, 0.15])},
            "pole": {"type": "cylinder", "p0": [-4.3, 0.0, 0.0], "p1": [-4.3, 0.0, 8.1], "radius": 0.08,
                     "bsdf": diffuse([0.5] * 3)},
            "arm": {"type": "cylinder", "p0": [-4.3, 0.0, 8.1], "p1": [head[0], 0.0, 8.1], "radius": 0.04,
                    "bsdf": diffuse([0.5] * 3)},
            "lamp": {"type": emitter_type, "filename": str(path), "to_world": lamp_T},
        })

    def render(emitter_type: str, integrator: str, spp: int, seed: int) -> Any:
        sc = scene(emitter_type, integrator, spp, seed)
        t0 = time.perf_counter()
        img = np.array(mi.render(sc, spp=spp, seed=seed), dtype=np.float64)  # type: ignore[arg-type]  # (Mitsuba's stub: UInt32)
        dr.sync_thread()
        return img, time.perf_counter() - t0

    def passes(emitter_type: str, integrator: str, n: int, seed: int) -> Any:
        """Mean of n renders of PASS spp (one wavefront of the whole image each, so memory stays
        small), the total time, and the fastest pass's time."""
        acc, total, best = 0.0, 0.0, float("inf")
        for k in range(n):
            img, t = render(emitter_type, integrator, PASS, seed + k)
            acc, total, best = acc + img / n, total + t, min(best, t)
        return acc, total, best

    ref, t_ref, _ = passes("gonio", "path", 16, 1000)
    ref_spp = 16 * PASS
    mean = ref.mean()

    def rmse(img: Any) -> float:
        return float(np.sqrt(((img - ref) ** 2).mean()) / mean)

    # Warm-up (JIT compilation, the sampler's first use) before any timing.
    render("gonio", "ptracer", PASS, 99)
    render("uniform_profile", "ptracer", PASS, 99)
    n = max(1, a.spp // PASS)
    g, t_g, b_g = passes("gonio", "ptracer", n, 2000)
    u, t_u, b_u = passes("uniform_profile", "ptracer", n, 3000)
    # Equal time: the uniform emitter gets as many passes as gonio's time buys at its own pace
    # (the fastest pass of each, the least disturbed by other work on the machine).
    n_eq = max(1, int(round(n * b_g / b_u)))
    u_eq, t_u_eq, _ = passes("uniform_profile", "ptracer", n_eq, 4000)
    spp, spp_eq = n * PASS, n_eq * PASS
    print(f"{path.name}: flux {d.flux:.1f} lm, {a.width}x{a.height} px, reference: path at {ref_spp} spp ({t_ref:.1f} s)")
    print(f"  ptracer, gonio emitter        {spp:5d} spp  {t_g:6.2f} s ({b_g:.3f} s/pass)  relative RMSE {rmse(g):.4f}")
    print(f"  ptracer, uniform x profile    {spp:5d} spp  {t_u:6.2f} s ({b_u:.3f} s/pass)  relative RMSE {rmse(u):.4f}")
    print(f"  ptracer, uniform, equal time  {spp_eq:5d} spp  {t_u_eq:6.2f} s  relative RMSE {rmse(u_eq):.4f}")
    print(f"  image means / reference mean: gonio {g.mean() / mean:.4f}, uniform {u.mean() / mean:.4f}, "
          f"uniform equal time {u_eq.mean() / mean:.4f}")
    print(f"  RMSE ratio uniform/gonio: equal samples {rmse(u) / rmse(g):.2f}, equal time {rmse(u_eq) / rmse(g):.2f}")

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    def tonemap(img: Any) -> Any:
        x = np.clip(img / (4.0 * mean), 0.0, 1.0)
        return srgb(x)

    fig, axes = plt.subplots(1, 3, figsize=(15, 3.3))
    panels = [(ref, f"reference: path, {ref_spp} spp"),
              (u_eq, f"uniform × profile: ptracer {spp_eq} spp (equal time)\nrel. RMSE {rmse(u_eq):.3f}"),
              (g, f"gonio: ptracer {spp} spp\nrel. RMSE {rmse(g):.3f}")]
    for ax, (img, title) in zip(axes, panels):
        ax.imshow(tonemap(img))
        ax.set_title(title, fontsize=10)
        ax.axis("off")
    save(fig, a.out)


if __name__ == "__main__":
    main()
