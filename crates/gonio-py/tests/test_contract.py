"""The sampler contract through the package: round trip, pdf agreement, shapes, dtypes, memory
orders, bad input → exception, thread independence, panic safety, the GIL released."""

import os
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import gonio

METHODS = ["hds", "piecewise-constant", "bilinear", "rejection", "uniform"]
INVERTIBLE = ["hds", "piecewise-constant", "bilinear", "uniform"]


def hemisphere_diagram():
    theta = np.linspace(0.0, 90.0, 10)
    phi = np.arange(0.0, 360.0, 45.0)
    t, p = np.meshgrid(np.radians(theta), np.radians(phi))
    values = 1.0 + np.cos(t) ** 4 * (1.5 + np.cos(p))
    return gonio.Diagram(theta, phi, values)


@pytest.fixture(scope="module", params=["example", "hemisphere"])
def diagram(request):
    return gonio.example() if request.param == "example" else hemisphere_diagram()


def test_import_and_version():
    assert isinstance(gonio.__version__, str) and gonio.__version__
    assert gonio.methods() == METHODS
    assert issubclass(gonio.ParseError, gonio.GonioError)
    assert issubclass(gonio.GonioError, ValueError)
    assert issubclass(gonio.InternalError, RuntimeError)


def test_diagram_from_arrays_round_trips_its_grid():
    d = hemisphere_diagram()
    assert d.theta_deg.shape == (10,) and d.phi_deg.shape == (8,)
    assert d.values.shape == (8, 10)
    np.testing.assert_allclose(d.theta_deg, np.linspace(0.0, 90.0, 10), rtol=0, atol=1e-12)
    assert d.domain == "hemisphere" and d.source == "arrays"
    assert d.flux > 0.0 and d.header is None and d.warnings == []


@pytest.mark.parametrize("method", METHODS)
def test_sample_shapes_pdf_agreement_and_unit_length(diagram, method):
    s = diagram.sampler(method)
    u = gonio.sequence(20_000, "sobol", seed=7)
    dirs, pdf = s.sample(u)
    assert dirs.shape == (20_000, 3) and pdf.shape == (20_000,)
    assert dirs.dtype == np.float64 and pdf.dtype == np.float64
    np.testing.assert_allclose(np.linalg.norm(dirs, axis=1), 1.0, rtol=0, atol=1e-12)
    assert np.all(pdf > 0.0)
    np.testing.assert_allclose(s.pdf(dirs), pdf, rtol=1e-9, atol=0)
    if s.domain == "hemisphere":
        assert np.all(dirs[:, 2] >= 0.0)


@pytest.mark.parametrize("method", INVERTIBLE)
def test_invert_round_trips(diagram, method):
    s = diagram.sampler(method)
    u = gonio.sequence(20_000, "random", seed=3)
    dirs, pdf = s.sample(u)
    back = s.invert(dirs)
    assert back.shape == (20_000, 2)
    # Away from the measure-zero seams every implementation documents, the inverse is exact to
    # round-off; compare where the density is positive.
    ok = pdf > 0
    err = np.abs(back[ok] - u[ok]).max(axis=1)
    assert np.quantile(err, 0.999) < 1e-9, err.max()


def test_ratio_bound_holds_on_samples(diagram):
    s = diagram.sampler("hds")
    lo, hi = s.ratio_bound
    assert 0.0 < lo <= 1.0 <= hi
    dirs, pdf = s.sample(gonio.sequence(50_000, "halton"))
    t = s.target_pdf(dirs)
    pos = t > 0
    r = pdf[pos] / t[pos]
    assert r.min() >= lo * (1 - 1e-9) and r.max() <= hi * (1 + 1e-9)


def test_baselines_claim_no_bound_and_target_power_is_flux(diagram):
    for m in ["bilinear", "uniform"]:
        s = diagram.sampler(m)
        assert s.ratio_bound is None
        assert s.target_power == pytest.approx(diagram.flux, rel=1e-12)
    assert diagram.sampler().memory_bytes > 0


def test_dtypes_and_memory_orders_give_the_same_result():
    s = gonio.example().sampler()
    u = gonio.sequence(5_000, "random", seed=11)
    ref_d, ref_p = s.sample(u)
    variants = [
        np.asfortranarray(u),
        np.ascontiguousarray(u),
        np.concatenate([u, np.zeros_like(u)], axis=1)[:, :2],  # strided view
        u.tolist(),
    ]
    for v in variants:
        d, p = s.sample(v)
        np.testing.assert_array_equal(d, ref_d)
        np.testing.assert_array_equal(p, ref_p)
    # Other real dtypes are read as float64 and give float64.
    d16, p16 = s.sample(u.astype(np.float16))
    assert d16.dtype == np.float64 and p16.dtype == np.float64
    np.testing.assert_array_equal(d16, s.sample(u.astype(np.float16).astype(np.float64))[0])


@pytest.mark.parametrize("method", ["hds", "bilinear"])
def test_float32_in_gives_float32_out(method):
    # float32 points in: the float32 batch calls (today the float64 map rounded once), float32 out.
    s = gonio.example().sampler(method)
    u32 = gonio.sequence(5_000, "random", seed=12).astype(np.float32)
    d32, p32 = s.sample(u32)
    assert d32.dtype == np.float32 and p32.dtype == np.float32
    assert d32.shape == (5_000, 3) and d32.flags.c_contiguous
    d64, p64 = s.sample(u32.astype(np.float64))
    if method == "bilinear":
        # The default float32 path: the float64 results of the widened points, rounded once.
        np.testing.assert_array_equal(d32, d64.astype(np.float32))
        np.testing.assert_array_equal(p32, p64.astype(np.float32))
    else:
        # The HDS map's own float32 path (its sphere splits the square in float32, and a float32
        # map may take this call): close to the float64 map, and consistent in itself (below).
        assert np.max(np.abs(d32.astype(np.float64) - d64)) < 1e-4
    assert np.max(np.abs(np.linalg.norm(d32.astype(np.float64), axis=1) - 1)) < 1e-6
    # Any memory order or stride of float32 input gives the same bits.
    for v in [np.asfortranarray(u32), np.concatenate([u32, u32], axis=1)[:, :2]]:
        d, p = s.sample(v)
        np.testing.assert_array_equal(d, d32)
        np.testing.assert_array_equal(p, p32)
    # float32 directions in: float32 pdf and points out.
    q32 = s.pdf(d32)
    assert q32.dtype == np.float32
    # The density at the float32 direction (normalised in float64, rounded): within 1e-5 of the
    # sample's density (the direction moved by at most ~6e-8 rad; the example is smooth).
    np.testing.assert_allclose(q32, p32, rtol=1e-5)
    w32 = s.invert(d32)
    assert w32.dtype == np.float32 and w32.shape == (5_000, 2)
    # The round trip in float32, to the contract's 1e-5.
    assert np.max(np.abs(w32.astype(np.float64) - u32)) < 1e-5
    # Fortran-ordered float32 directions: the same bits.
    f = np.asfortranarray(d32)
    np.testing.assert_array_equal(s.pdf(f), q32)
    np.testing.assert_array_equal(s.invert(f), w32)
    # out= arrays must then be float32.
    dd, pp = np.zeros((5_000, 3), np.float32), np.zeros(5_000, np.float32)
    r = s.sample(u32, out=(dd, pp))
    assert r[0] is dd and r[1] is pp
    np.testing.assert_array_equal(dd, d32)
    with pytest.raises(gonio.InputError, match=r"out\[0\].*float32"):
        s.sample(u32, out=(np.zeros((5_000, 3)), np.zeros(5_000)))
    with pytest.raises(gonio.InputError, match=r"out.*float32"):
        s.pdf(d32, out=np.zeros(5_000))
    # Bad rows are named as in float64.
    bad = u32.copy()
    bad[4_321, 1] = np.float32("nan")
    with pytest.raises(gonio.InputError, match=r"u: row 4321: point"):
        s.sample(bad)
    zero = d32.copy()
    zero[17] = 0
    with pytest.raises(gonio.InputError, match=r"pdf: row 17: direction"):
        s.pdf(zero)


def test_outputs_are_new_arrays():
    s = gonio.example().sampler()
    u = gonio.sequence(100, "halton")
    d1, p1 = s.sample(u)
    d2, p2 = s.sample(u)
    d1[:] = 0.0
    p1[:] = 0.0
    assert np.all(p2 > 0) and not np.shares_memory(d1, d2)
    assert d2.flags.writeable and d2.flags.c_contiguous


@pytest.mark.parametrize("method", INVERTIBLE)
def test_out_arrays_are_written_and_returned(method):
    s = gonio.example().sampler(method)
    u = gonio.sequence(1000, "halton")
    d_new, p_new = s.sample(u)
    d_out, p_out = np.full((1000, 3), np.nan), np.full(1000, np.nan)
    d, p = s.sample(u, out=(d_out, p_out))
    assert d is d_out and p is p_out
    np.testing.assert_array_equal(d_out, d_new)
    np.testing.assert_array_equal(p_out, p_new)
    q = np.full(1000, np.nan)
    assert s.pdf(d_new, out=q) is q
    np.testing.assert_array_equal(q, s.pdf(d_new))
    w = np.full((1000, 2), np.nan)
    assert s.invert(d_new, out=w) is w
    np.testing.assert_array_equal(w, s.invert(d_new))
    # Reused: the second call overwrites the first one's results.
    s.sample(u[::-1].copy(), out=(d_out, p_out))
    np.testing.assert_array_equal(d_out, d_new[::-1])


def test_bad_out_arrays_raise():
    s = gonio.example().sampler()
    u = gonio.sequence(10, "halton")
    d, _ = s.sample(u)
    cases = [
        ((np.zeros((10, 3)), np.zeros(9)), r"out\[1\] \(pdf\): shape \(9,\) where \(10,\)"),
        ((np.zeros((10, 3), np.float32), np.zeros(10)), r"out\[0\].*float64"),
        ((np.zeros((3, 10)).T, np.zeros(10)), r"out\[0\].*C-contiguous"),
        (np.zeros((10, 3)), r"out: expected a tuple"),
    ]
    for out, match in cases:
        with pytest.raises(gonio.InputError, match=match):
            s.sample(u, out=out)
    # Misaligned (a float64 view at a byte offset of 1): refused, never read or written in place.
    mis = np.frombuffer(bytearray(8 * 10 + 1), dtype=np.float64, count=10, offset=1)
    with pytest.raises(gonio.InputError, match=r"out: must be C-contiguous and aligned"):
        s.pdf(d, out=mis)
    ro = np.zeros(10)
    ro.flags.writeable = False
    with pytest.raises(gonio.InputError, match=r"out.*cannot be written"):
        s.pdf(d, out=ro)
    # Overlaps: an output that is the input, and two outputs sharing memory.
    flat = np.zeros(40)
    with pytest.raises(gonio.InputError, match=r"out\[1\].*shares memory with out\[0\]"):
        s.sample(u, out=(flat[:30].reshape(10, 3), flat[25:35]))
    buf = np.zeros(30)
    buf[:] = d.ravel()
    with pytest.raises(gonio.InputError, match=r"out: shares memory with directions"):
        s.pdf(buf.reshape(10, 3), out=buf[5:15])
    with pytest.raises(gonio.InputError, match=r"out: shape \(10, 3\) where \(10, 2\)"):
        s.invert(d, out=np.zeros((10, 3)))


def test_empty_batches():
    s = gonio.example().sampler()
    d, p = s.sample(np.zeros((0, 2)))
    assert d.shape == (0, 3) and p.shape == (0,)
    assert s.pdf(np.zeros((0, 3))).shape == (0,)
    assert s.invert(np.zeros((0, 3))).shape == (0, 2)


def test_pdf_normalises_directions():
    s = gonio.example().sampler()
    # From point 1 on: point 0 of Halton is the corner (0, 0), a pole where round-off rules.
    d, p = s.sample(gonio.sequence(1000, "halton", start=1))
    np.testing.assert_allclose(s.pdf(7.5 * d), s.pdf(d), rtol=1e-12)
    np.testing.assert_allclose(s.pdf(d), p, rtol=1e-9)


@pytest.mark.parametrize(
    "bad, match",
    [
        (np.zeros((4, 3)), r"shape \(n, 2\)"),
        (np.zeros(4), r"shape \(n, 2\)"),
        (np.zeros((2, 2, 2)), r"shape \(n, 2\)"),
        ([[0.1, 0.2], [0.3, 1.5]], r"row 1"),
        ([[0.1, 0.2], [-0.1, 0.5]], r"row 1"),
        ([[0.1, 0.2], [0.3, 0.4], [np.nan, 0.5]], r"row 2"),
        ([["a", "b"]], r"cannot be"),
        (np.array([["x", 0.5]], dtype=object), r"dtype object cannot be converted"),
    ],
)
def test_bad_points_raise(bad, match):
    s = gonio.example().sampler()
    with pytest.raises(gonio.InputError, match=match):
        s.sample(bad)


def test_bad_directions_raise():
    s = gonio.example().sampler()
    with pytest.raises(gonio.InputError, match=r"row 1: .*zero or not finite"):
        s.pdf([[0, 0, 1.0], [0, 0, 0]])
    with pytest.raises(gonio.InputError, match=r"row 0"):
        s.target_pdf([[np.inf, 0, 1.0]])
    with pytest.raises(gonio.InputError, match=r"shape \(n, 3\)"):
        s.pdf(np.zeros((5, 2)))
    with pytest.raises(gonio.InputError, match=r"no inverse"):
        gonio.example().sampler("rejection").invert([[0, 0, 1.0]])
    h = hemisphere_diagram().sampler()
    assert h.domain == "hemisphere"
    with pytest.raises(gonio.InputError, match=r"row 1: .*outside the sampler's domain"):
        h.invert([[0, 0, 1.0], [0, 0, -1.0]])
    assert h.pdf([[0, 0, -1.0]])[0] == 0.0
    # A downlight on the sphere: straight up is in the domain but has density 0, so no point maps
    # to it; the error says so instead of "outside the domain" (issue 16).
    down = gonio.read_bytes("IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 3 1 1 2 0 0 0\n1 1 100\n"
                            "0 45 90\n0\n100 60 0\n", "ies").sampler()
    assert down.domain == "sphere"
    with pytest.raises(gonio.InputError, match=r"row 1: .*density 0: no point of the square"):
        down.invert([[0, 0, -1.0], [0, 0, 1.0]])
    assert down.pdf([[0, 0, 1.0]])[0] == 0.0


def test_bad_arguments_raise():
    d = gonio.example()
    with pytest.raises(gonio.InputError, match="unknown method"):
        d.sampler("nope")
    with pytest.raises(gonio.InputError, match="unknown domain"):
        d.sampler("hds", "torus")
    with pytest.raises(gonio.BuildError, match="hemisphere"):
        d.sampler("bilinear", "hemisphere")
    with pytest.raises(gonio.InputError, match="unknown sequence|halton"):
        gonio.sequence(10, "lattice")
    with pytest.raises(gonio.DiagramError, match="strictly increasing"):
        gonio.Diagram([0, 10, 10], [0], [[1, 1, 1]])
    with pytest.raises(gonio.DiagramError, match="shape"):
        gonio.Diagram([0, 10, 20], [0, 90], [[1, 1, 1]])
    with pytest.raises(gonio.DiagramError):
        gonio.Diagram([0, 10], [0], [[1, -1]])
    with pytest.raises(gonio.DiagramError, match="carries no light"):
        gonio.Diagram([0, 10], [0], [[0, 0]])
    with pytest.raises(TypeError):
        gonio.Sampler("not a diagram")


def test_sequences_match_their_definition():
    h = gonio.sequence(8, "halton")
    np.testing.assert_array_equal(h[:, 0], [0, 0.5, 0.25, 0.75, 0.125, 0.625, 0.375, 0.875])
    np.testing.assert_allclose(h[:4, 1], [0, 1 / 3, 2 / 3, 1 / 9], rtol=0, atol=1e-15)
    a = gonio.sequence(1000, "sobol", seed=5)
    b = gonio.sequence(500, "sobol", seed=5, start=500)
    np.testing.assert_array_equal(a[500:], b)
    assert not np.array_equal(a, gonio.sequence(1000, "sobol", seed=6))
    r = gonio.sequence(100_000, "random", seed=1)
    assert r.min() >= 0.0 and r.max() < 1.0
    # iid uniform: mean 1/2 within 5 standard errors (sd 1/sqrt(12 n)); fixed seed.
    assert np.all(np.abs(r.mean(axis=0) - 0.5) < 5 / np.sqrt(12 * r.shape[0]))


_THREAD_SCRIPT = """
import sys, numpy as np, gonio
s = gonio.example().sampler(sys.argv[1])
u = gonio.sequence(100_000, "random", seed=2)
d, p = s.sample(u)
np.save(sys.argv[2], np.concatenate([d, p[:, None], s.pdf(d)[:, None]], axis=1))
"""


@pytest.mark.parametrize("method", ["hds", "rejection"])
def test_results_do_not_depend_on_the_thread_count(tmp_path, method):
    outs = []
    for threads in ["1", "3"]:
        f = tmp_path / f"out{threads}.npy"
        env = dict(os.environ, RAYON_NUM_THREADS=threads)
        subprocess.run([sys.executable, "-c", _THREAD_SCRIPT, method, str(f)], env=env, check=True)
        outs.append(np.load(f))
    np.testing.assert_array_equal(outs[0], outs[1])


def test_panics_become_internal_error_not_a_crash():
    for detached in (True, False):
        with pytest.raises(gonio.InternalError, match="deliberate panic"):
            gonio._gonio._panic_for_test(detached)
    # The interpreter and the thread pool still work afterwards.
    d, p = gonio.example().sampler().sample(gonio.sequence(10_000, "halton"))
    assert np.all(p > 0)


def test_the_gil_is_released_during_a_batch():
    s = gonio.example().sampler("bilinear")
    u = gonio.sequence(1_000_000, "random", seed=4)
    ticks = []
    stop = threading.Event()
    started = threading.Event()

    def spin():
        started.set()
        while not stop.is_set():
            ticks.append(time.perf_counter())

    t = threading.Thread(target=spin)
    t.start()
    started.wait()
    t0 = time.perf_counter()
    s.sample(u)
    t1 = time.perf_counter()
    stop.set()
    t.join()
    # With the GIL held for the whole call, the other thread could run only at the edges of the
    # call (waiting for the GIL), never in the middle half of it.
    lo, hi = t0 + 0.25 * (t1 - t0), t1 - 0.25 * (t1 - t0)
    during = sum(1 for x in ticks if lo < x < hi)
    assert during > 0, (t1 - t0, len(ticks))
