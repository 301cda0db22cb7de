"""gonio.read_brdf / Brdf / BrdfSampler on small generated gonio BRDF JSON tables (docs/BRDF.md):
exact pdf of every sample, the inverse round trip, the weight f·cos θ_o / pdf, the errors, and
agreement with `gonio brdf sample`."""

import csv
import io
import json
import math
import subprocess

import numpy as np
import pytest

import gonio

THETA_I = np.arange(0.0, 91.0, 15.0)  # 7 incident polar nodes
THETA_O = np.arange(0.0, 91.0, 5.0)  # 19 outgoing polar nodes
DPHI = np.arange(0.0, 360.0, 10.0)  # 36 relative azimuths
RHO = np.array([0.2, 0.5, 0.8])


def lobe(ti, to, dp):
    """A glossy lobe around the mirror direction (θ_o = θ_i, Δφ = 180°) on a diffuse base (1/sr)."""
    ti, to, dp = np.radians(ti), np.radians(to), np.radians(dp)
    cos_mirror = np.cos(ti) * np.cos(to) - np.sin(ti) * np.sin(to) * np.cos(dp)
    return 1.0 / math.pi + 4.0 * np.clip(cos_mirror, 0.0, None) ** 20


def write_table(path, channels=3, fn=None, symmetry="isotropic"):
    """Writes an isotropic gonio BRDF JSON table of `fn` (default: RHO/π per channel × lobe)."""
    ti, to, dp = np.meshgrid(THETA_I, THETA_O, DPHI, indexing="ij")
    base = lobe(ti, to, dp) if fn is None else fn(ti, to, dp)
    scale = RHO[:channels] if channels == 3 else np.array([1.0])
    values = scale[:, None, None, None, None] * base[None, :, None, :, :]  # (C, Ti, Pi, To, Po)
    doc = {
        "format": "gonio-brdf",
        "version": 1,
        "symmetry": symmetry,
        "channels": channels,
        "theta_i_deg": THETA_I.tolist(),
        "phi_i_deg": [0.0],
        "theta_o_deg": THETA_O.tolist(),
        "phi_o_deg": DPHI.tolist(),
        "values": values.ravel().tolist(),
    }
    path.write_text(json.dumps(doc))
    return path


def direction(theta_deg, phi_deg):
    t, p = math.radians(theta_deg), math.radians(phi_deg)
    return np.array([math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)])


@pytest.fixture(scope="module")
def table(tmp_path_factory):
    return write_table(tmp_path_factory.mktemp("brdf") / "lobe.json")


@pytest.fixture(scope="module")
def brdf(table):
    return gonio.read_brdf(table)


@pytest.fixture(scope="module")
def sampler(brdf):
    return brdf.sampler()


def test_read_and_eval_at_nodes(brdf):
    assert brdf.channels == 3 and brdf.symmetry == "isotropic"
    ti, pi, to, po = brdf.grid
    assert np.allclose(np.degrees(ti), THETA_I) and np.allclose(np.degrees(to), THETA_O)
    assert np.allclose(np.degrees(pi), [0.0]) and np.allclose(np.degrees(po), DPHI)
    # At grid nodes the interpolant is the tabulated value; wi azimuth 40° turns Δφ.
    wi = direction(30, 40)
    wo = np.array([direction(t, 40 + p) for t in (0, 25, 45) for p in (0, 90, 180, 270)])
    want = np.array([lobe(30, t, p) for t in (0, 25, 45) for p in (0, 90, 180, 270)])
    f = brdf.eval(wi, wo)
    assert f.shape == (12, 3)
    assert np.allclose(f, want[:, None] * RHO[None, :], rtol=1e-12)
    # Not unit vectors: normalised. Below the horizon: 0.
    assert np.allclose(brdf.eval(2 * wi, 3 * wo), f, rtol=1e-12)
    assert np.all(brdf.eval(wi, [[0.0, 0.3, -1.0]]) == 0.0)


@pytest.mark.parametrize("theta", [0.0, 20.0, 52.0, 80.0])
def test_sample_pdf_weight_invert(brdf, sampler, theta):
    rng = np.random.default_rng(7)
    wi = direction(theta, 33.0)
    u = rng.random((4000, 2))
    wo, pdf, weight = sampler.sample(wi, u)
    assert wo.shape == (4000, 3) and pdf.shape == (4000,) and weight.shape == (4000, 3)
    assert np.allclose(np.linalg.norm(wo, axis=1), 1.0, atol=1e-12)
    assert np.all(wo[:, 2] >= 0.0) and np.all(pdf > 0.0)
    # The exact density of the map that produced each sample.
    assert np.allclose(sampler.pdf(wi, wo), pdf, rtol=1e-10, atol=0.0)
    # weight = f·cos θ_o / pdf per channel.
    f = brdf.eval(wi, wo)
    assert np.allclose(weight, f * wo[:, 2:3] / pdf[:, None], rtol=1e-12, atol=0.0)
    # The inverse round trip.
    back = sampler.invert(wi, wo)
    assert back.shape == (4000, 2)
    assert np.max(np.abs(back - u)) < 1e-10


def test_per_row_incident_equals_one_incident(sampler):
    rng = np.random.default_rng(3)
    n = 600
    thetas = np.repeat([10.0, 45.0, 70.0], n // 3)
    wis = np.array([direction(t, 15.0 * k) for k, t in enumerate(thetas)])
    u = rng.random((n, 2))
    wo, pdf, weight = sampler.sample(wis, u)
    for k in (0, 250, 599):
        w1, p1, g1 = sampler.sample(wis[k], u[k : k + 1])
        assert np.array_equal(w1[0], wo[k]) and p1[0] == pdf[k] and np.array_equal(g1[0], weight[k])
    assert np.allclose(sampler.pdf(wis, wo), pdf, rtol=1e-10)
    assert np.max(np.abs(sampler.invert(wis, wo) - u)) < 1e-10


def test_mean_weight_is_the_albedo(tmp_path):
    # A Lambertian table f = ρ/π: ∫ f cos θ_o dω_o = ρ.
    path = write_table(tmp_path / "lambert.json", fn=lambda a, b, c: 0 * a + 1 / math.pi)
    s = gonio.read_brdf(path).sampler()
    u = np.random.default_rng(11).random((20000, 2))
    _, _, weight = s.sample(direction(40, 0), u)
    assert np.allclose(weight.mean(axis=0), RHO, rtol=5e-3)


def test_one_channel(tmp_path):
    b = gonio.read_brdf(write_table(tmp_path / "grey.json", channels=1))
    assert b.channels == 1
    s = b.sampler()
    wo, pdf, weight = s.sample([0.0, 0.0, 1.0], np.random.default_rng(1).random((100, 2)))
    assert weight.shape == (100, 1) and b.eval([0.0, 0.0, 1.0], wo).shape == (100, 1)


@pytest.mark.parametrize("method", ["cosine", "ggx-fit", "piecewise-constant"])
def test_other_methods(brdf, method):
    s = brdf.sampler(method)
    assert s.method == method
    wi = direction(35, 0)
    u = np.random.default_rng(5).random((2000, 2))
    wo, pdf, weight = s.sample(wi, u)
    # GGX VNDF sampling reflects some normals below the horizon (~10 % here): those samples carry
    # pdf 0 and weight 0, as pdf() says there, so pdf agrees with every sample.
    below = wo[:, 2] < 0
    assert np.all(weight[below] == 0.0) and np.all(pdf[below] == 0.0)
    assert np.allclose(s.pdf(wi, wo), pdf, rtol=1e-9, atol=0)
    ok = (pdf > 0) & (wo[:, 2] > 0)
    f = brdf.eval(wi, wo[ok])
    assert np.allclose(weight[ok], f * wo[ok, 2:3] / pdf[ok, None], rtol=1e-12)


def test_invert_below_horizon_is_nan(sampler):
    u = sampler.invert([0.0, 0.0, 1.0], [[0.0, 0.0, 1.0], [1.0, 0.0, -0.5]])
    assert np.all(np.isfinite(u[0])) and np.all(np.isnan(u[1]))
    assert sampler.pdf([0.0, 0.0, 1.0], [[1.0, 0.0, -0.5]])[0] == 0.0


def test_errors(tmp_path, brdf, sampler):
    wi = [0.0, 0.0, 1.0]
    with pytest.raises(gonio.InputError, match=r"u: row 2:"):
        sampler.sample(wi, [[0.1, 0.1], [0.2, 0.2], [math.nan, 0.5]])
    with pytest.raises(gonio.InputError, match=r"u: row 0:.*outside"):
        sampler.sample(wi, [[1.5, 0.1]])
    with pytest.raises(gonio.InputError, match=r"shape \(n, 2\)"):
        sampler.sample(wi, np.zeros((4, 3)))
    with pytest.raises(gonio.InputError, match=r"wo: row 1:"):
        sampler.pdf(wi, [[0.0, 0.0, 1.0], [math.nan, 0.0, 1.0]])
    with pytest.raises(gonio.InputError, match=r"wo: row 0:.*non-zero"):
        brdf.eval(wi, [[0.0, 0.0, 0.0]])
    with pytest.raises(gonio.InputError, match=r"wi: row 0:"):
        sampler.invert([math.inf, 0.0, 1.0], [[0.0, 0.0, 1.0]])
    with pytest.raises(gonio.InputError, match=r"wi: expected shape \(3,\)"):
        sampler.pdf([0.0, 1.0], [[0.0, 0.0, 1.0]])
    with pytest.raises(gonio.InputError, match=r"wi: 2 rows"):
        sampler.pdf([[0.0, 0.0, 1.0]] * 2, [[0.0, 0.0, 1.0]] * 3)
    with pytest.raises(gonio.InputError, match=r"complex"):
        brdf.eval(wi, np.zeros((2, 3), complex))
    with pytest.raises(gonio.InputError, match=r"method"):
        brdf.sampler("rejection")
    with pytest.raises(gonio.BuildError):
        brdf.sampler(theta_o=1, force_resample=True)
    bad = tmp_path / "bad.json"
    bad.write_text('{"format": "gonio-brdf",\n "version": 1, "oops": 3}')
    with pytest.raises(gonio.ParseError) as e:
        gonio.read_brdf(bad)
    assert e.value.line == 2
    short = tmp_path / "short.bin"
    short.write_bytes(b"\x00" * 100)
    with pytest.raises(gonio.GonioError, match="short.bin"):
        gonio.read_brdf(short)
    with pytest.raises(FileNotFoundError, match="missing.json"):
        gonio.read_brdf(tmp_path / "missing.json")
    with pytest.raises(OSError, match="not a regular file"):
        gonio.read_brdf(tmp_path)
    # Empty batches are fine.
    wo, pdf, w = sampler.sample(wi, np.zeros((0, 2)))
    assert wo.shape == (0, 3) and pdf.shape == (0,) and w.shape == (0, 3)


def test_cli_agreement(table, sampler, gonio_bin):
    out = subprocess.run(
        [str(gonio_bin), "brdf", "sample", str(table), "--incident", "30,45"]
        + ["-n", "50", "--seed", "4"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    rows = np.array([[float(x) for x in r] for r in list(csv.reader(io.StringIO(out)))[1:]])
    assert rows.shape == (50, 9)
    wo, pdf, weight = sampler.sample(direction(30, 45), rows[:, :2])
    assert np.allclose(wo, rows[:, 2:5], rtol=0, atol=1e-12)
    assert np.allclose(pdf, rows[:, 5], rtol=1e-12, atol=0)
    assert np.allclose(weight, rows[:, 6:9], rtol=1e-12, atol=0)


def test_batches_split_alike_and_inputs_convert(brdf, sampler):
    # 9000 rows span three rayon tasks of 4096: each row is computed alone, so splitting the
    # batch changes nothing, bit for bit.
    rng = np.random.default_rng(13)
    u = rng.random((9000, 2))
    wis = rng.normal(size=(9000, 3))
    wis[:, 2] = np.abs(wis[:, 2]) + 0.05
    wo, pdf, weight = sampler.sample(wis, u)
    parts = [sampler.sample(wis[a:b], u[a:b]) for a, b in ((0, 10), (10, 5000), (5000, 9000))]
    assert np.array_equal(np.concatenate([p[0] for p in parts]), wo)
    assert np.array_equal(np.concatenate([p[1] for p in parts]), pdf)
    assert np.array_equal(np.concatenate([p[2] for p in parts]), weight)
    # float32, Fortran order, strided views and lists are read as float64.
    wo32 = wo[:50].astype(np.float32)
    wi50, wo50 = wis[:50], wo[:50]
    assert np.array_equal(sampler.pdf(wi50, wo32), sampler.pdf(wi50, wo32.astype(np.float64)))
    assert np.array_equal(sampler.pdf(np.asfortranarray(wi50), wo50), sampler.pdf(wi50, wo50))
    strided = brdf.eval(wis[:100:2], wo[:100:2])
    assert np.array_equal(strided, brdf.eval(wis[:100:2].copy(), wo[:100:2].copy()))
    lists = sampler.invert(wis[0].tolist(), wo[:3].tolist())
    assert np.array_equal(lists, sampler.invert(wis[0], wo[:3]))


def test_fuzz_batches(brdf, sampler):
    # 1500 calls with random shapes, dtypes and values (NaN, ±inf, huge, tiny, zero vectors):
    # each returns or raises an ordinary error of the contract, never InternalError.
    rng = np.random.default_rng(26)
    special = [np.nan, np.inf, -np.inf, 0.0, -0.0, 1.0, 1e300, -1e300, 5e-324, 2.0, -1.0]
    dtypes = [np.float64, np.float32, np.int32, bool, np.complex128, object]
    allowed = (gonio.GonioError, TypeError, OverflowError, MemoryError)
    samplers = [sampler, brdf.sampler("cosine")]

    def arr(k, n):
        shapes = [(n, k), (n,), (k,), (n, k + 1), (1, n, k), (n + 1, k)]
        shape = shapes[0] if rng.random() < 0.8 else shapes[int(rng.integers(len(shapes)))]
        a = rng.random(shape) * 2 - 1
        if k == 2:
            a = (a + 1) / 2
        if a.size and rng.random() < 0.2:
            a.flat[rng.integers(a.size)] = rng.choice(special)
        if rng.random() < 0.3:
            with np.errstate(all="ignore"):
                return a.astype(dtypes[int(rng.integers(len(dtypes)))])
        return a

    calls = returned = 0
    for _ in range(1500):
        s = samplers[int(rng.integers(2))]
        op = int(rng.integers(4))
        n = int(rng.choice([0, 1, 3, 17]))
        wi = arr(3, n) if rng.random() < 0.5 else rng.random(3) * 2 - 1
        try:
            if op == 0:
                r = s.sample(wi, arr(2, n))
                assert np.all(np.isfinite(r[0])) and np.all(r[1] >= 0)
            elif op == 1:
                assert np.all(s.pdf(wi, arr(3, n)) >= 0)
            elif op == 2:
                u = s.invert(wi, arr(3, n))
                ok = ~np.isnan(u[:, 0])
                assert np.all((u[ok] >= 0) & (u[ok] <= 1))
            else:
                assert np.all(brdf.eval(wi, arr(3, n)) >= 0)
            calls += 1
            returned += 1
        except gonio.InternalError:
            raise
        except allowed:
            calls += 1
    assert calls == 1500 and returned > 100, returned


def test_albedo_and_mean_weight(brdf, sampler):
    # The mean luminance weight of HDS samples estimates the (luminance) albedo; the weight's
    # spread is small, so 20 000 iid samples put it within 1 % (seeded).
    lum = np.array([0.2126, 0.7152, 0.0722])
    wis = np.array([direction(t, 20) for t in (0, 40, 70)])
    a = brdf.albedo(wis)
    assert a.shape == (3,) and np.all(a > 0)
    u = np.random.default_rng(17).random((20000, 2))
    for wi, ak in zip(wis, a):
        _, _, weight = sampler.sample(wi, u)
        assert abs((weight @ lum).mean() / ak - 1) < 0.01
    with pytest.raises(gonio.InputError, match=r"wi: row 1:"):
        brdf.albedo([[0.0, 0.0, 1.0], [0.0, 0.0, 0.0]])


def test_utia_and_merl_by_content(tmp_path):
    # A constant UTIA file (raw value 14: f = ((14/140 + 0.055)/1.055)^2.4 · 100 per sr) and a
    # constant MERL file (stored 1.5: f = 1.5 · scale_c), recognised by their sizes and headers.
    utia = tmp_path / "const.bin"
    np.full(3 * 288 * 288, 14.0, "<f8").tofile(utia)
    b = gonio.read_brdf(utia)
    assert b.symmetry == "anisotropic" and b.channels == 3
    f = ((14 / 140 + 0.055) / 1.055) ** 2.4 * 100
    wo = np.array([direction(t, p) for t in (0, 30, 60) for p in (0, 100)])
    assert np.allclose(b.eval(direction(45, 10), wo), f, rtol=1e-12)
    assert np.all(b.eval(direction(45, 10), [direction(80, 0)]) == 0)  # no data beyond 75°
    merl = tmp_path / "const.binary"
    with open(merl, "wb") as fh:
        fh.write(np.array([90, 90, 180], "<i4").tobytes())
        fh.write(np.full(3 * 90 * 90 * 180, 1.5, "<f8").tobytes())
    m = gonio.read_brdf(merl, merl_theta=10, merl_phi=8)
    assert m.symmetry == "isotropic" and len(m.grid[0]) == 10 and len(m.grid[3]) == 8
    scale = np.array([1.0, 1.15, 1.66]) / 1500
    assert np.allclose(m.eval(direction(30, 0), wo), 1.5 * scale, rtol=1e-9)
