"""gonio.EnvMap on tiny generated PFM images; the frame against Mitsuba 3's envmap emitter when
mitsuba is installed (docs/ENVMAPS.md)."""

import math

import numpy as np
import pytest

import gonio


def write_pfm(path, img):
    """img: (h, w, 3) float32, row 0 at the top; PFM stores rows bottom to top, little-endian."""
    h, w, _ = img.shape
    with open(path, "wb") as f:
        f.write(f"PF\n{w} {h}\n-1.0\n".encode())
        f.write(np.ascontiguousarray(img[::-1], dtype="<f4").tobytes())


def test_constant_sky_is_uniform(tmp_path):
    p = tmp_path / "sky.pfm"
    write_pfm(p, np.full((8, 16, 3), 0.5, np.float32))
    env = gonio.EnvMap(p)
    assert (env.width, env.height) == (16, 8)
    u = np.random.default_rng(1).random((1000, 2))
    d, pdf, rgb = env.sample(u)
    assert np.allclose(pdf, 1 / (4 * math.pi), rtol=1e-12)
    assert np.all(rgb == 0.5)
    assert np.allclose(np.linalg.norm(d, axis=1), 1.0)


def test_sample_pdf_invert_eval_agree(tmp_path):
    rng = np.random.default_rng(2)
    img = (rng.random((8, 16, 3)) + 0.1).astype(np.float32)
    p = tmp_path / "r.pfm"
    write_pfm(p, img)
    env = gonio.EnvMap(p)
    u = rng.random((2000, 2))
    d, pdf, rgb = env.sample(u)
    assert np.allclose(env.pdf(d), pdf, rtol=1e-10)
    assert np.allclose(env.invert(d), u, atol=1e-8)
    assert np.array_equal(env.eval(d), rgb)
    # Pixel centres read their pixel: centre column = +x, top row = +z.
    for r in range(8):
        for c in range(16):
            t, s = math.pi * (r + 0.5) / 8, (c + 0.5) / 16
            phi = math.pi - 2 * math.pi * s
            dd = [math.sin(t) * math.cos(phi), math.sin(t) * math.sin(phi), math.cos(t)]
            assert np.allclose(env.eval([dd])[0], img[r, c])


def test_black_map_and_bad_input(tmp_path):
    p = tmp_path / "black.pfm"
    write_pfm(p, np.zeros((4, 8, 3), np.float32))
    with pytest.raises(gonio.GonioError, match="black"):
        gonio.EnvMap(p)
    with pytest.raises(gonio.GonioError):
        gonio.EnvMap(tmp_path / "missing.hdr")
    write_pfm(p, np.ones((4, 8, 3), np.float32))
    env = gonio.EnvMap(p)
    with pytest.raises(gonio.InputError):
        env.sample([[1.5, 0.2]])
    with pytest.raises(gonio.InputError):
        gonio.EnvMap(p, lookup="cubic")


def test_frame_matches_mitsuba(tmp_path):
    mi = pytest.importorskip("mitsuba")
    mi.set_variant("scalar_rgb")
    w, h = 16, 8
    img = (np.random.default_rng(3).random((h, w, 3)) * 4 + 0.25).astype(np.float32)
    path = str(tmp_path / "img.exr")
    mi.Bitmap(img).write(path)
    m = mi.ScalarTransform4f([[0, 0, 1, 0], [1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0, 1]])
    emitter = mi.load_dict({"type": "envmap", "filename": path, "to_world": m})
    env = gonio.EnvMap(path)
    for r in range(1, h - 1):
        theta = math.pi * r / (h - 1)
        for c in range(w):
            u = (c + 0.5) / w
            ml = (math.sin(theta) * math.sin(2 * math.pi * u), math.cos(theta),
                  -math.sin(theta) * math.cos(2 * math.pi * u))
            g = (ml[2], ml[0], ml[1])
            si = mi.SurfaceInteraction3f()
            si.wi = mi.Vector3f(-g[0], -g[1], -g[2])
            assert np.allclose(np.array(emitter.eval(si)), img[r, c], rtol=1e-4)  # Mitsuba interpolates in float32
            assert np.allclose(env.eval([g])[0], img[r, c], rtol=1e-6)
