"""Two pictures for docs/MITSUBA.md, rendered with gonio's Mitsuba 3 emitters (``path``, Mitsuba's
default symbolic JIT flags):

* ``mitsuba-road-openings.png``: a road at night under four street lights (the corpus's AEL
  roadway luminaire, IES, a 0.378 m square luminous opening by its header) on 8 m poles every
  30 m, each merged into the scene as its opening (``gonio.mitsuba.luminaire(..., shape="opening")``):
  the road is lit by the file's candela and the openings shine toward the camera with the
  luminance I(ω)/A_proj(ω). The road is slightly glossy (``roughplastic``), so it also mirrors them.
* ``mitsuba-envmap-balls.png``: a glossy ball (rough aluminium, GGX α = 0.2) and a diffuse ball
  (0.7) on a diffuse floor under the shared studio.hdr, lit by Mitsuba's ``envmap`` (left) and by
  ``gonio_envmap`` (right, ``lookup="bilinear"``), the same image and ``to_world``, equal spp.

    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 \\
      .venv/bin/python examples/python/mitsuba_gallery.py [--spp 128] [--out-dir docs/gallery]
      [--only road|envmap]

The luminaire file is looked up in $GONIO_CORPUS (default ../shared/data/photometry), the map in
$GONIO_ENVMAPS (default ../shared/data/envmaps).
"""

from typing import Any
import argparse
import os
import pathlib
import time

import numpy as np

from _pictures import srgb


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--spp", type=int, default=128)
    p.add_argument("--out-dir", default="docs/gallery")
    p.add_argument("--only", choices=["road", "envmap"], default=None)
    a = p.parse_args()

    import mitsuba as mi

    mi.set_variant("llvm_ad_rgb")
    import gonio.mitsuba as gm

    gm.register()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    here = pathlib.Path(__file__).resolve().parents[2]
    corpus = pathlib.Path(os.environ.get("GONIO_CORPUS") or here.parent / "shared" / "data" / "photometry")
    envs = pathlib.Path(os.environ.get("GONIO_ENVMAPS") or here.parent / "shared" / "data" / "envmaps")
    out_dir = pathlib.Path(a.out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    T = mi.ScalarTransform4f

    def diffuse(v: Any) -> dict[str, Any]:
        return {"type": "diffuse", "reflectance": {"type": "rgb", "value": v}}

    if a.only in (None, "road"):
        f = corpus / "ies" / "lm63_2002_ael_asa_roadway_h0_180.ies"
        d = {"type": "scene",
             "integrator": {"type": "path", "max_depth": 4},
             "sensor": {"type": "perspective", "fov": 55,
                        "to_world": T().look_at(origin=[1.8, -22.0, 1.5], target=[-0.8, 30.0, 3.0], up=[0, 0, 1]),
                        "film": {"type": "hdrfilm", "width": 480, "height": 270},
                        "sampler": {"type": "independent", "sample_count": a.spp}},
             "road": {"type": "rectangle", "to_world": T().translate([0, 40, 0]) @ T().scale([4.0, 70.0, 1.0]),
                      "bsdf": {"type": "roughplastic", "distribution": "ggx", "alpha": 0.25,
                               "diffuse_reflectance": {"type": "rgb", "value": [0.12] * 3}}},
             "verge": {"type": "rectangle", "to_world": T().translate([0, 40, -0.01]) @ T().scale([40.0, 70.0, 1.0]),
                       "bsdf": diffuse([0.15, 0.25, 0.12])}}
        for k, y in enumerate((0.0, 30.0, 60.0, 90.0)):
            head = [-2.5, y, 8.0]
            d[f"pole{k}"] = {"type": "cylinder", "p0": [-4.3, y, 0.0], "p1": [-4.3, y, 8.25], "radius": 0.08,
                             "bsdf": diffuse([0.5] * 3)}
            d[f"arm{k}"] = {"type": "cylinder", "p0": [-4.3, y, 8.25], "p1": [head[0], y, 8.25], "radius": 0.05,
                            "bsdf": diffuse([0.5] * 3)}
            # C0 along the road (+y), the opening's plane horizontal, facing down
            d.update(gm.luminaire(f, to_world=T().translate(head) @ T().rotate([0, 0, 1], 90), shape="opening",
                                  name=f"lamp{k}"))
        t0 = time.perf_counter()
        img = np.array(mi.render(mi.load_dict(d)), dtype=np.float64)
        print(f"road: {img.shape[1]} x {img.shape[0]} px, {a.spp} spp, {time.perf_counter() - t0:.1f} s")
        lum = img @ np.array([0.2126, 0.7152, 0.0722])
        road = np.median(lum[lum.shape[0] * 3 // 4:, lum.shape[1] // 3: 2 * lum.shape[1] // 3])
        print(f"road: median luminance of the road's near middle {road:.3g} cd/m², brightest pixel {lum.max():.3g} cd/m²")
        fig, ax = plt.subplots(figsize=(4.8, 2.9))
        ax.imshow(srgb(img / (6.0 * road)))
        ax.set_title(f"four AEL roadway luminaires as their openings (gonio, path, {a.spp} spp)", fontsize=8)
        ax.axis("off")
        fig.tight_layout()
        out = out_dir / "mitsuba-road-openings.png"
        fig.savefig(out, dpi=100, bbox_inches="tight")
        plt.close(fig)
        print(f"wrote {out} ({out.stat().st_size // 1024} KB)")

    if a.only in (None, "envmap"):
        env_file = envs / "studio.hdr"
        imgs = {}
        for kind in ("envmap", "gonio_envmap"):
            em = {"type": kind, "filename": str(env_file),
                  "to_world": T().rotate([0, 0, 1], 200) @ T().rotate([1, 0, 0], 90)}
            if kind == "gonio_envmap":
                em["lookup"] = "bilinear"
            sc = mi.load_dict({
                "type": "scene", "integrator": {"type": "path", "max_depth": 6},
                "sensor": {"type": "perspective", "fov": 35,
                           "to_world": T().look_at(origin=[0, -7.5, 2.2], target=[0, 0, 0.1], up=[0, 0, 1]),
                           "film": {"type": "hdrfilm", "width": 288, "height": 216},
                           "sampler": {"type": "independent", "sample_count": a.spp}},
                "glossy": {"type": "sphere", "center": [-1.15, 0, 0], "radius": 1.0,
                           "bsdf": {"type": "roughconductor", "material": "Al", "distribution": "ggx", "alpha": 0.2}},
                "matte": {"type": "sphere", "center": [1.15, 0, 0], "radius": 1.0, "bsdf": diffuse([0.7] * 3)},
                "floor": {"type": "rectangle", "to_world": T().translate([0, 0, -1]) @ T().scale(6),
                          "bsdf": diffuse([0.4] * 3)},
                "env": em,
            })
            t0 = time.perf_counter()
            imgs[kind] = np.array(mi.render(sc, seed=0), dtype=np.float64)  # type: ignore[arg-type]  # (Mitsuba's stub: UInt32)
            print(f"{kind}: {imgs[kind].shape[1]} x {imgs[kind].shape[0]} px, {a.spp} spp, {time.perf_counter() - t0:.1f} s, "
                  f"image mean {imgs[kind].mean():.4f}")
        print(f"gonio_envmap / envmap − 1 (image mean): {imgs['gonio_envmap'].mean() / imgs['envmap'].mean() - 1:+.4f}")
        expo = 1.0 / (7.0 * np.median(imgs["envmap"]))
        fig, axes = plt.subplots(1, 2, figsize=(6.0, 2.5))
        for ax, kind in zip(axes, ("envmap", "gonio_envmap")):
            ax.imshow(srgb(imgs[kind] * expo))
            ax.set_title(f"Mitsuba \"{kind}\"" if kind == "envmap" else "gonio \"gonio_envmap\"", fontsize=8)
            ax.axis("off")
        fig.suptitle(f"studio.hdr, path, {a.spp} spp: rough aluminium (α = 0.2) and a diffuse ball", fontsize=8)
        fig.tight_layout()
        out = out_dir / "mitsuba-envmap-balls.png"
        fig.savefig(out, dpi=100, bbox_inches="tight")
        plt.close(fig)
        print(f"wrote {out} ({out.stat().st_size // 1024} KB)")


if __name__ == "__main__":
    main()
