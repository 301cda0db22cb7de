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


def random_sky(path, rng, shape, floor, spike, rgb):
    """A float32 RGB image of ``shape`` (height, width) with values in [floor, floor + 1) from
    ``rng`` and one bright pixel ``spike`` = (row, column) of colour ``rgb``, written as PFM to
    ``path``; returns the image."""
    img = (rng.random((*shape, 3)) + floor).astype(np.float32)
    img[spike] = rgb
    write_pfm(path, img)
    return img


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
    # A missing file is FileNotFoundError, as from read and read_brdf (one family per fault).
    with pytest.raises(FileNotFoundError):
        gonio.EnvMap(tmp_path / "missing.hdr")
    write_pfm(p, np.ones((4, 8, 3), np.float32))
    env = gonio.EnvMap(p)
    with pytest.raises(gonio.InputError):
        env.sample([[1.5, 0.2]])
    with pytest.raises(gonio.InputError):
        gonio.EnvMap(p, lookup="cubic")


def test_frame_matches_mitsuba(tmp_path):
    """docs/ENVMAPS.md "The frame": under to_world = rows (0,0,1), (1,0,0), (0,1,0), Mitsuba 3's
    ``envmap`` and gonio read the same pixel at every Mitsuba texel node off the poles (column
    centre u = (c + 1/2)/W, row r at theta = pi r/(H - 1)): Mitsuba's ``emitter.eval``, gonio's
    ``eval``, and gonio's map to the square and back (``invert`` then ``sample``, which carries
    the radiance of the direction's pixel)."""
    mi = pytest.importorskip("mitsuba")
    mi.set_variant("scalar_rgb")
    w, h = 16, 8
    img = (np.random.default_rng(3).random((h, w, 3)) * 4 + 0.25).astype(np.float32)
    path = str(tmp_path / "img.exr")
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
            si = mi.SurfaceInteraction3f()
            si.wi = mi.Vector3f(-g[0], -g[1], -g[2])
            assert np.allclose(np.array(emitter.eval(si)), img[r, c], rtol=1e-4)  # Mitsuba interpolates in float32
            dirs.append(g)
            want.append(img[r, c])
    assert len(dirs) == w * (h - 2)
    env = gonio.EnvMap(path)
    assert np.allclose(env.eval(dirs), want, rtol=1e-6)
    back, _, rgb = env.sample(env.invert(dirs))
    assert np.allclose(back, dirs, atol=1e-6)
    assert np.allclose(rgb, want, rtol=1e-6)


def test_peers_script_smoke(tmp_path):
    """benches/envmap_peers.py (gonio vs Mitsuba 3's envmap emitter) on a tiny generated map in a
    few seconds: it runs, writes every row, Mitsuba's samples land where gonio's do (same frame),
    and both samplers' pdf agrees with their samples. The full run is in docs/ENVMAPS.md."""
    mi = pytest.importorskip("mitsuba")
    import csv
    import json
    import os
    import subprocess
    import sys
    from pathlib import Path

    script = Path(__file__).resolve().parents[3] / "benches" / "envmap_peers.py"
    mi.set_variant("scalar_rgb")
    w, h = 32, 16
    img = np.full((h, w, 3), 0.05, np.float32)
    img[4, 21] = 2000.0  # one bright pixel off the axes: a wrong frame moves Mitsuba's samples
    path = tmp_path / "tiny.exr"
    mi.Bitmap(img).write(str(path))
    out, checks = tmp_path / "rows.csv", tmp_path / "checks.json"
    args = [sys.executable, str(script), "--maps", str(path), "--reps", "4", "--counts", "16", "64",
            "--ref-k", "2", "--speed-n", "4096", "--repeats", "1", "--csv", str(out),
            "--checks-json", str(checks)]
    r = subprocess.run(args, capture_output=True, text=True, timeout=300, env=dict(os.environ))
    assert r.returncode == 0, r.stderr[-3000:]
    rows = list(csv.DictReader(open(out)))
    # 5 samplers x 2 lookups x 4 surfaces x 2 estimators x 2 point kinds.
    assert len(rows) == 160
    assert {x["sampler"] for x in rows} == {"gonio-hds", "gonio-hds-f32", "latlong", "pbrt-v4-style", "mitsuba"}
    assert "Every sampler in the same run" in r.stdout
    assert all(math.isfinite(float(x["rel_rmse_last"])) for x in rows)
    (c,) = json.load(open(checks))
    # Most of the power is in the bright pixel: both mean directions point at it.
    assert c["len_gonio"] > 0.5 and c["len_mitsuba"] > 0.5, c
    assert c["angle_deg"] < 5.0, c
    assert c["pdf_gonio"] < 1e-9, c
    assert c["pdf_mitsuba"] < 5e-2, c  # Mitsuba recomputes in float32 (7e-4 to 2.7e-2 on the shared maps)


def test_batch_equals_single_points(tmp_path):
    """The batches run the sphere map's SIMD kernels (lanes of several points, a scalar tail):
    a batch of 1001 points against 1001 one-point calls, the documented batch round-off
    (directions 1e-15, densities 1e-12 relative), the radiance exactly eval() of the batch
    direction, pdf and invert batches against one-direction calls the same way."""
    rng = np.random.default_rng(3)
    p = tmp_path / "b.pfm"
    img = random_sky(p, rng, (8, 16), 0.1, (2, 5), [100.0, 50.0, 10.0])
    for lookup in ("nearest", "bilinear"):
        env = gonio.EnvMap(p, lookup=lookup)
        u = np.vstack([rng.random((1001, 2)), [[0, 0], [1, 1], [0.5, 0.5]]])
        d, pdf, rgb = env.sample(u)
        one = [env.sample(u[k:k + 1]) for k in range(len(u))]
        d1 = np.vstack([o[0] for o in one])
        p1 = np.concatenate([o[1] for o in one])
        assert np.max(np.abs(d - d1)) <= 1e-15
        assert np.all(np.abs(pdf - p1) <= 1e-12 * p1)
        assert np.array_equal(env.eval(d), rgb)
        q = env.pdf(d)
        q1 = np.concatenate([env.pdf(d[k:k + 1]) for k in range(len(d))])
        assert np.all(np.abs(q - q1) <= 1e-12 * q1)
        assert np.all(np.abs(q - pdf) <= 1e-10 * pdf)
        w = env.invert(d)
        w1 = np.vstack([env.invert(d[k:k + 1]) for k in range(len(d))])
        assert np.max(np.abs(w - w1)) <= 1e-12
        # The round trip inside the square (the corners are on its boundary, where the map folds).
        assert np.allclose(w[:1001], u[:1001], atol=1e-8)


def test_weight_options(tmp_path):
    """weight= chooses what the density follows: a channel by name or index, or the caller's
    (height, width) array; an array equal to the luminance (computed in float32 in the library's
    order) gives the default map bit for bit; bad weights are InputErrors."""
    rng = np.random.default_rng(4)
    p = tmp_path / "w.pfm"
    # A red source: the red weight puts its mass there.
    img = random_sky(p, rng, (8, 16), 0.05, (3, 9), [40.0, 0.1, 0.1])
    u = rng.random((3000, 2))
    lum = (np.float32(0.2126) * img[..., 0] + np.float32(0.7152) * img[..., 1]) + np.float32(0.0722) * img[..., 2]
    default = gonio.EnvMap(p)
    custom = gonio.EnvMap(p, weight=lum)
    assert (default.weight, custom.weight) == ("luminance", "custom")
    d0, p0, _ = default.sample(u)
    d1, p1, _ = custom.sample(u)
    assert np.array_equal(d0, d1) and np.array_equal(p0, p1)
    red, red0 = gonio.EnvMap(p, weight="red"), gonio.EnvMap(p, weight=0)
    assert red.weight == "red" and red0.weight == "red"
    dr_, pr, _ = red.sample(u)
    assert np.array_equal(pr, red0.sample(u)[1])
    # The red map's density over the luminance map's: largest at the red source.
    t, s = math.pi * 3.5 / 8, 9.5 / 16
    ph = math.pi - 2 * math.pi * s
    src = [[math.sin(t) * math.cos(ph), math.sin(t) * math.sin(ph), math.cos(t)]]
    ratio_src = red.pdf(src)[0] / default.pdf(src)[0]
    assert ratio_src > 1.5 and ratio_src > np.max(red.pdf(d0) / default.pdf(d0)) * 0.999
    assert np.allclose(red.pdf(dr_), pr, rtol=1e-10)
    # The custom weight of one bright pixel: its pixel holds most of the mass.
    one = np.full((8, 16), 1e-3)
    one[6, 2] = 1.0
    m = gonio.EnvMap(p, weight=one)
    d, _, _ = m.sample(u)
    rows = np.floor(np.arccos(np.clip(d[:, 2], -1, 1)) / math.pi * 8)
    assert np.mean(rows == 6) > 0.5
    for bad in ("alpha", 3, -1, np.ones((16, 8)), -one, np.where(one > 0.5, np.nan, one), np.full((8, 16), 1e300)):
        with pytest.raises(gonio.InputError):
            gonio.EnvMap(p, weight=bad)
    with pytest.raises(gonio.GonioError, match="black"):
        gonio.EnvMap(p, weight=np.zeros((8, 16)))


def test_samplers_of_an_envmap(tmp_path):
    """EnvMap.sampler(kind): "hds" is the map itself (the same samples and pdf), float32 arrays reach
    its float32 map; the lat-long and pbrt-v4-style peers keep the sampler contract (pdf agrees
    with the sample, the inverse round-trips, the density integrates to 1)."""
    rng = np.random.default_rng(5)
    p = tmp_path / "s.pfm"
    img = random_sky(p, rng, (16, 32), 0.05, (5, 20), [300.0, 200.0, 100.0])
    env = gonio.EnvMap(p)
    u = rng.random((4000, 2))
    d, pdf, _ = env.sample(u)
    hds = env.sampler()
    assert hds.method == "hds" and hds.domain == "sphere"
    dh, ph = hds.sample(u)
    assert np.max(np.abs(dh - d)) <= 1e-15 and np.all(np.abs(ph - pdf) <= 1e-12 * pdf)
    # The float32 map's contract (docs/API.md, "Float32 maps"): its pdf agrees with its samples,
    # its inverse round-trips to 1e-5, and its density stays close to the float64 map's.
    u32 = u.astype(np.float32)
    d32, p32 = hds.sample(u32)
    assert d32.dtype == np.float32 and p32.dtype == np.float32
    assert np.max(np.abs(hds.pdf(d32) / p32 - 1)) < 1e-4
    assert np.max(np.abs(hds.invert(d32) - u32)) < 1e-5
    assert np.max(np.abs(env.pdf(d32.astype(np.float64)) / p32 - 1)) < 1e-3
    # A uniform grid on the sphere to check that each density integrates to 1.
    nt, nph = 400, 800
    th = (np.arange(nt) + 0.5) / nt * math.pi
    phg = (np.arange(nph) + 0.5) / nph * 2 * math.pi
    T, P = np.meshgrid(th, phg, indexing="ij")
    grid = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], -1).reshape(-1, 3)
    dA = (np.sin(T) * (math.pi / nt) * (2 * math.pi / nph)).reshape(-1)
    for kind, res in (("latlong", None), ("pbrt-v4", None), ("pbrt-v4", 16)):
        s = env.sampler(kind) if res is None else env.sampler(kind, resolution=res)
        assert s.method == kind
        dk, pk = s.sample(u)
        assert np.allclose(np.linalg.norm(dk, axis=1), 1.0, atol=1e-12)
        ok = pk > 0
        assert np.all(ok)
        assert np.allclose(s.pdf(dk), pk, rtol=1e-9)
        assert np.allclose(s.invert(dk), u, atol=1e-7)
        assert abs(np.dot(s.pdf(grid), dA) - 1.0) < 5e-3
    for bad in (lambda: env.sampler("mitsuba"), lambda: env.sampler("latlong", resolution=8),
                lambda: env.sampler("pbrt-v4", resolution=0)):
        with pytest.raises(gonio.InputError):
            bad()


def test_float32_envmap(tmp_path):
    """EnvMap(precision="float32") keeps only the float32 map: float32 arrays out, the float32 map's
    samples bit for bit (EnvMap().sampler() on float32 points), its contract (pdf agrees with the
    sample, the inverse round-trips to 1e-5), the radiance of its directions, fewer bytes."""
    rng = np.random.default_rng(6)
    p = tmp_path / "f.pfm"
    img = random_sky(p, rng, (32, 64), 0.05, (7, 40), [500.0, 400.0, 300.0])
    e64 = gonio.EnvMap(p)
    e32 = gonio.EnvMap(p, precision="float32", lookup="bilinear")
    assert (e64.precision, e32.precision) == ("float64", "float32")
    assert e32.memory_bytes < 0.7 * e64.memory_bytes
    assert e32.power == e64.power
    u = rng.random((5000, 2))
    d, pdf, rgb = e32.sample(u)
    assert d.dtype == pdf.dtype == rgb.dtype == np.float32
    d2, p2 = e64.sampler().sample(u.astype(np.float32))
    assert np.array_equal(d, d2) and np.array_equal(pdf, p2)
    # pdf and invert are the float32 map's (tests/float32_map.rs proves its contract, with the
    # conditioning term that lets the pdf drift by more than 8 ulps at the steep bright pixel):
    # the same bits as the float32 map reached through EnvMap().sampler().
    hds = e64.sampler()
    assert np.array_equal(e32.pdf(d), hds.pdf(d))
    assert np.array_equal(e32.invert(d), hds.invert(d))
    rel = np.abs(e32.pdf(d) / pdf - 1)
    assert np.median(rel) <= 8 * np.finfo(np.float32).eps
    assert np.max(np.abs(e32.invert(d) - u.astype(np.float32))) < 1e-5
    assert np.array_equal(e32.eval(d), rgb)
    assert np.array_equal(rgb, gonio.EnvMap(p, lookup="bilinear").eval(d.astype(np.float64)).astype(np.float32))
    assert np.max(np.abs(e64.pdf(d.astype(np.float64)) / pdf - 1)) < 1e-3
    bad_dirs = [[0.0, 0.0, 0.0], [np.nan, 0, 1], [np.inf, 0, 0]]
    bad = e32.invert(bad_dirs)
    assert bad.dtype == np.float32 and np.all(np.isnan(bad))
    assert np.array_equal(e32.pdf(bad_dirs), [0, 0, 0]) and np.all(e32.eval(bad_dirs) == 0)
    # Directions are normalised first (as everywhere in the package): a scaled direction reads
    # the same density and radiance.
    assert np.array_equal(e32.pdf(4 * d[:100]), e32.pdf(d[:100]))  # 4×: exact in binary
    with pytest.raises(gonio.InputError, match="float64"):
        e32.sampler()
    with pytest.raises(gonio.InputError):
        gonio.EnvMap(p, precision="half")


def test_batches_do_not_depend_on_the_split(tmp_path):
    """EnvMap batches run on all rayon threads in chunks: a batch of several chunks gives the
    bits of the same rows sent in pieces, for both precisions and every call."""
    rng = np.random.default_rng(8)
    p = tmp_path / "t.pfm"
    img = random_sky(p, rng, (16, 32), 0.05, (3, 7), [400.0, 100.0, 50.0])
    n = 3 * 4096 + 77
    u = rng.random((n, 2))
    for env in (gonio.EnvMap(p), gonio.EnvMap(p, precision="float32", lookup="bilinear")):
        whole = env.sample(u)
        cuts = [0, 1, 4095, 4097, 9000, n]
        parts = [env.sample(u[a:b]) for a, b in zip(cuts, cuts[1:])]
        for k in range(3):
            assert np.array_equal(whole[k], np.concatenate([q[k] for q in parts]))
        d = whole[0]
        for f in (env.pdf, env.eval, env.invert):
            a = f(d)
            b = np.concatenate([f(d[i:j]) for i, j in zip(cuts, cuts[1:])])
            assert np.array_equal(a, b, equal_nan=True)
