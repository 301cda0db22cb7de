#!/usr/bin/env python3
"""The envmap frame correspondence with Mitsuba 3's `envmap` emitter, checked pixel by pixel.

Writes a small random RGB image (16 x 8) as OpenEXR, loads it in Mitsuba 3 (`scalar_rgb`) with
`to_world` = rows (0,0,1), (1,0,0), (0,1,0) (Mitsuba local (x, y, z) = gonio (y, z, x), see
docs/ENVMAPS.md), and for every Mitsuba texel node off the poles (column centre u = (c + 1/2)/W,
row r at theta = pi r/(H - 1)) takes the world direction, then asks

* Mitsuba: `emitter.eval` of a ray arriving from that direction,
* gonio: the radiance of the same direction (`gonio invert` to the square, `gonio sample
  --points` back, which prints r,g,b of its nearest pixel),

and checks that both equal pixel (c, r) of the image. Exits non-zero on a mismatch.

    python3 benches/peers/envmap_mitsuba_frame.py [path/to/gonio]
"""
import csv
import io
import math
import os
import subprocess
import sys
import tempfile

import numpy as np

try:
    import mitsuba as mi
except ImportError:
    print("skipping: mitsuba is not installed (pip install mitsuba)")
    sys.exit(0)

GONIO = sys.argv[1] if len(sys.argv) > 1 else "target/release/gonio"


def run(args):
    return subprocess.run([GONIO, *args, "--quiet"], check=True, capture_output=True, text=True).stdout


def main():
    mi.set_variant("scalar_rgb")
    w, h = 16, 8
    rng = np.random.default_rng(1)
    img = (rng.random((h, w, 3)) * 4 + 0.25).astype(np.float32)
    d = tempfile.mkdtemp()
    path = os.path.join(d, "img.exr")
    mi.Bitmap(img).write(path)
    m = mi.ScalarTransform4f([[0, 0, 1, 0], [1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0, 1]])
    emitter = mi.load_dict({"type": "envmap", "filename": path, "to_world": m})
    dirs, want = [], []
    for r in range(1, h - 1):
        theta = math.pi * r / (h - 1)
        for c in range(w):
            u = (c + 0.5) / w
            ml = (math.sin(theta) * math.sin(2 * math.pi * u), math.cos(theta),
                  -math.sin(theta) * math.cos(2 * math.pi * u))
            g = (ml[2], ml[0], ml[1])
            dirs.append(g)
            want.append(img[r, c])
    bad = 0
    for g, px in zip(dirs, want):
        si = mi.SurfaceInteraction3f()
        si.wi = mi.Vector3f(-g[0], -g[1], -g[2])
        v = np.array(emitter.eval(si))
        if not np.allclose(v, px, rtol=1e-4):  # Mitsuba interpolates in float32
            bad += 1
            print("mitsuba", g, v, px)
    dpath = os.path.join(d, "dirs.csv")
    with open(dpath, "w") as f:
        f.write("x,y,z\n" + "".join(f"{a!r},{b!r},{c!r}\n" for a, b, c in dirs))
    inv = list(csv.DictReader(io.StringIO(run(["invert", path, "--directions", dpath]))))
    upath = os.path.join(d, "uv.csv")
    with open(upath, "w") as f:
        f.write("u,v\n" + "".join(f"{row['u']},{row['v']}\n" for row in inv))
    smp = list(csv.DictReader(io.StringIO(run(["sample", path, "--points", upath]))))
    for row, g, px in zip(smp, dirs, want):
        v = np.array([float(row["r"]), float(row["g"]), float(row["b"])])
        back = np.array([float(row["x"]), float(row["y"]), float(row["z"])])
        if not (np.allclose(v, px, rtol=1e-6) and np.allclose(back, g, atol=1e-6)):
            bad += 1
            print("gonio", g, back, v, px)
    n = len(dirs)
    print(f"{n} Mitsuba texel-node directions: Mitsuba and gonio read the same pixel for {2 * n - bad} of {2 * n} lookups")
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
