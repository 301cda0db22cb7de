"""A picture for docs/BRDF.md and docs/MITSUBA.md: tabulated materials rendered with gonio's Mitsuba
BSDF ``"gonio_brdf"`` (exact sampling of each table's blended slice map, ``path``), four balls
on a diffuse floor under the shared sunset.hdr:

1. a Lambert table (albedo 0.8, 0.5, 0.2) in the **MERL** binary layout;
2. a GGX conductor (α = 0.15, copper-like F) in the **MERL** layout;
3. an anisotropic GGX (α_x = 0.5 along the tangent, α_y = 0.08) in the **UTIA** layout;
4. a GGX table (α = 0.35, gold-like F) in **gonio BRDF JSON**;

with Mitsuba's own ``roughconductor`` of the second and fourth beside them in a second row as the
reference. The tables are the library's analytic BRDFs written in those layouts by
``gonio.analytic_brdf`` (there is no measured file in the shared data); a MERL file from the
database is used the same way (``{"type": "gonio_brdf", "filename": "alum-bronze.binary"}``).

    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 \\
      .venv/bin/python examples/python/mitsuba_brdf_gallery.py [--spp 128] [--out-dir docs/gallery]
"""

import argparse
import os
import pathlib
import tempfile
import time

import numpy as np

from _pictures import srgb


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--spp", type=int, default=128)
    p.add_argument("--out-dir", default="docs/gallery")
    p.add_argument("--width", type=int, default=1024)
    a = p.parse_args()

    import mitsuba as mi

    mi.set_variant("llvm_ad_rgb")
    import gonio
    import gonio.mitsuba as gm

    gm.register()
    root = pathlib.Path(__file__).resolve().parents[2]
    envdir = pathlib.Path(os.environ.get("GONIO_ENVMAPS") or root.parent / "shared" / "data" / "envmaps")
    tmp = pathlib.Path(tempfile.mkdtemp(prefix="gonio-brdf-gallery-"))
    copper, gold = [0.95, 0.64, 0.54], [1.0, 0.78, 0.34]
    files = [
        gonio.analytic_brdf(tmp / "lambert.binary", "lambert", format="merl", albedo=[0.8, 0.5, 0.2]),
        gonio.analytic_brdf(tmp / "copper.binary", "ggx", format="merl", alpha_x=0.15, f0=copper),
        gonio.analytic_brdf(tmp / "brushed.bin", "ggx", format="utia", alpha_x=0.5, alpha_y=0.08,
                            f0=[0.9, 0.9, 0.9]),
        gonio.analytic_brdf(tmp / "gold.json", "ggx", format="json", alpha_x=0.35, f0=gold),
    ]
    balls = {}
    for k, f in enumerate(files):
        balls[f"ball{k}"] = {"type": "sphere", "center": [3.0 * k - 4.5, 0.0, 1.0], "radius": 1.0,
                             "bsdf": {"type": "gonio_brdf", "filename": str(f)}}
    for k, (alpha, col) in ((1, (0.15, copper)), (3, (0.35, gold))):
        balls[f"ref{k}"] = {"type": "sphere", "center": [3.0 * k - 4.5, 3.5, 1.0], "radius": 1.0,
                            "bsdf": {"type": "roughconductor", "distribution": "ggx", "alpha": alpha,
                                     "specular_reflectance": {"type": "rgb", "value": col}}}
    w = a.width
    scene = mi.load_dict({
        "type": "scene", "integrator": {"type": "path", "max_depth": 4},
        "sensor": {"type": "perspective", "fov": 50,
                   "to_world": mi.ScalarTransform4f().look_at(origin=[0, -12, 3.5], target=[0, 1.5, 1.0], up=[0, 0, 1]),
                   "film": {"type": "hdrfilm", "width": w, "height": w // 2},
                   "sampler": {"type": "independent", "sample_count": a.spp}},
        "floor": {"type": "rectangle", "to_world": mi.ScalarTransform4f().scale([20, 20, 1]),
                  "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.15, 0.15, 0.15]}}},
        "sky": {"type": "envmap", "filename": str(envdir / "sunset.hdr"),
                "to_world": mi.ScalarTransform4f().rotate([1, 0, 0], 90)},
        **balls})
    t0 = time.perf_counter()
    img = np.array(mi.render(scene, seed=1))  # type: ignore[arg-type]  # (Mitsuba's stub: UInt32)
    t = time.perf_counter() - t0
    out_dir = pathlib.Path(a.out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    out = out_dir / "mitsuba-brdf-materials.png"
    exposure = 0.3 / max(float(np.mean(img)), 1e-6)
    mi.util.write_bitmap(str(out), srgb(img * exposure).astype(np.float32), write_async=False)  # type: ignore[no-untyped-call]
    print(f"{out}: {w} x {w // 2}, {a.spp} spp, {t:.1f} s")


if __name__ == "__main__":
    main()
