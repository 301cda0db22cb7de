"""The luminous opening in Mitsuba 3: a street light seen from below by a camera, with the luminance
gonio's emitter gives its opening, L = I(ω)/A_proj(ω), next to the same luminaire as a point.

    DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 \\
      .venv/bin/python examples/python/mitsuba_opening.py [FILE] [-o docs/gallery/mitsuba-opening.png]

Default FILE: the corpus's AEL roadway luminaire (IES, a 0.378 m square opening by its header) on an
8 m pole over a road (albedo 0.15), C0 along the road. The camera stands on the road 16 m along it at
1.5 m, looking at the luminaire. Printed: the luminance of the opening toward the camera, from the
render (its brightest pixel, partly covered) and from
the file (I(ω)/A_proj(ω)), in cd/m².
"""

from typing import Any
import argparse
import os
import pathlib

import numpy as np

from _pictures import save, srgb


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("file", nargs="?", default=None)
    p.add_argument("-o", "--out", default="docs/gallery/mitsuba-opening.png")
    p.add_argument("--spp", type=int, default=64)
    a = p.parse_args()

    import mitsuba as mi

    mi.set_variant("llvm_ad_rgb")
    import gonio
    import gonio.mitsuba as gm

    gm.register()
    root = os.environ.get("GONIO_CORPUS") or pathlib.Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "photometry"
    f = pathlib.Path(a.file) if a.file else pathlib.Path(root) / "ies" / "lm63_2002_ael_asa_roadway_h0_180.ies"
    d = gonio.read(f)
    T = mi.ScalarTransform4f
    head = np.array([-2.5, 0.0, 8.0])
    lamp_T = T().translate(head.tolist()) @ T().rotate([0, 0, 1], 90)  # C0 → +y (along the road)
    eye = np.array([0.5, -16.0, 1.5])

    def diffuse(v: Any) -> dict[str, Any]:
        return {"type": "diffuse", "reflectance": {"type": "rgb", "value": v}}

    def scene(shape: str) -> Any:
        return mi.load_dict({
            "type": "scene",
            "integrator": {"type": "path", "max_depth": 3},
            "sensor": {"type": "perspective", "fov": 60,
                       "to_world": T().look_at(origin=eye.tolist(), target=[-1.0, 0.0, 3.5], up=[0, 0, 1]),
                       "film": {"type": "hdrfilm", "width": 320, "height": 240},
                       "sampler": {"type": "independent", "sample_count": a.spp}},
            "road": {"type": "rectangle", "to_world": T().scale([4.0, 40.0, 1.0]), "bsdf": diffuse([0.15] * 3)},
            "verge": {"type": "rectangle", "to_world": T().translate([0, 0, -0.01]) @ T().scale([40.0, 40.0, 1.0]),
                      "bsdf": diffuse([0.2, 0.3, 0.15])},
            "pole": {"type": "cylinder", "p0": [-4.3, 0.0, 0.0], "p1": [-4.3, 0.0, 8.25], "radius": 0.08,
                     "bsdf": diffuse([0.5] * 3)},
            "arm": {"type": "cylinder", "p0": [-4.3, 0.0, 8.25], "p1": [head[0], 0.0, 8.25], "radius": 0.05,
                    "bsdf": diffuse([0.5] * 3)},
            **gm.luminaire(f, to_world=lamp_T, shape=shape),
        })

    imgs = {s: np.array(mi.render(scene(s)), dtype=np.float64) for s in ("point", "opening")}
    o = gm.opening(d)
    assert o is not None, "the file has a luminous opening"
    w_world = (eye - head) / np.linalg.norm(eye - head)
    M = np.array(lamp_T.matrix, dtype=np.float64)
    wl = M[:3, :3].T @ w_world
    want = d.intensity(wl[None])[0] / o.projected_area(wl[None])[0]
    got = imgs["opening"][:, :, 0].max()
    # The flat opening, seen 21° above its plane from 17.6 m, is about 3 pixels tall here: no
    # pixel is wholly inside it, so the brightest is below the luminance (the tests check it on
    # pixels that see only the opening).
    print(f"{f.name}: {o}; luminance toward the camera: file {want:.4g} cd/m², brightest pixel {got:.4g} cd/m²")

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    low = imgs["point"][2 * imgs["point"].shape[0] // 3:, :, 0]
    road = np.median(low[low > 0])  # the lit road in the lower third

    def tonemap(img: Any) -> Any:
        x = np.clip(img / (8.0 * road), 0.0, 1.0)
        return srgb(x)

    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for ax, (k, title) in zip(axes, [("point", "shape = \"point\": the luminaire is invisible"),
                                     ("opening", f"shape = \"opening\": {want:.3g} cd/m² toward the camera")]):
        ax.imshow(tonemap(imgs[k]))
        ax.set_title(title, fontsize=10)
        ax.axis("off")
    save(fig, a.out)


if __name__ == "__main__":
    main()
