"""A fuzz harness over the package's entry points (issue 25): random shapes, dtypes, memory
layouts, aliasing between inputs and outputs, and values (NaN, ±inf, huge, tiny, out of range)
for Sampler.sample/pdf/target_pdf/invert, Diagram(...), Diagram.intensity, sequence and
read_bytes. It runs in a child interpreter for a bounded time (GONIO_FUZZ_SECONDS, default 15 s,
fixed seed), so that an abort or a hang fails the test instead of killing the suite.

Every call must either return or raise an ordinary exception of the package's contract
(GonioError and its subclasses, TypeError, OverflowError, MemoryError, OSError); a
PanicException (a BaseException), an InternalError, an abort or a hang fails. A call that
succeeds with an aliased `out=` must give the same numbers as the same call without aliasing.
"""

import os
import subprocess
import sys
import textwrap

HARNESS = r"""
import sys, time, traceback
import numpy as np
import gonio

SECONDS = float(sys.argv[1])
rng = np.random.default_rng(25)
ALLOWED = (gonio.GonioError, TypeError, OverflowError, MemoryError, OSError)

theta = np.array([0.0, 30.0, 60.0, 90.0, 120.0, 180.0])
phi = np.array([0.0, 90.0, 180.0, 270.0])
base = gonio.Diagram(theta, phi, 1.0 + rng.random((4, 6)))
samplers = [base.sampler(m) for m in gonio.methods()] + [gonio.example().sampler()]

SPECIAL = [np.nan, np.inf, -np.inf, 0.0, -0.0, 1.0, 1e300, -1e300, 5e-324, 1e-310, 2.0, -1.0]
DTYPES = [np.float64, np.float32, np.float16, np.int32, np.uint8, np.int64, bool,
          np.complex128, "datetime64[s]", "U8", object]


def values(shape):
    a = rng.random(shape)
    if rng.random() < 0.5:
        mask = rng.random(shape) < 0.1
        a[mask] = rng.choice(SPECIAL, size=int(mask.sum()))
    return a


def as_dtype(a):
    dt = DTYPES[rng.integers(len(DTYPES))]
    try:
        if dt == "datetime64[s]":
            return np.zeros(a.shape, dtype=dt)
        with np.errstate(all="ignore"):
            return a.astype(dt)
    except Exception:
        return a


def layout(a):
    k = rng.integers(6)
    if k == 0:
        return np.asfortranarray(a)
    if k == 1 and a.ndim == 2:  # a strided view
        wide = np.zeros((a.shape[0], 2 * a.shape[1]), dtype=a.dtype)
        wide[:, ::2] = a
        return wide[:, ::2]
    if k == 2:
        return a.tolist()
    if k == 3 and a.size:  # a broadcast view of one row
        return np.broadcast_to(a[:1], a.shape)
    if k == 4:  # a read-only array
        b = a.copy()
        b.flags.writeable = False
        return b
    return a


def shape(k):
    n = int(rng.choice([0, 1, 2, 7, 100, 5000]))
    r = rng.random()
    if r < 0.05:
        return (n,)
    if r < 0.1:
        return (n, k + 1)
    if r < 0.12:
        return (n, k, 1)
    return (n, k)


def aliased(n, k_in, k_outs):
    # One buffer holding the input and the outputs at random offsets (overlapping or not).
    total = n * (k_in + sum(k_outs)) + 8
    buf = bytearray(8 * total)
    def view(k, off):
        off = min(off, total - n * k)
        return np.frombuffer(buf, np.float64, count=n * k, offset=8 * off).reshape((n, k) if k > 1 else (n,))
    u = view(k_in, 0)
    offs = [int(rng.integers(0, total)) for _ in k_outs]
    return u, [view(k, o) for k, o in zip(k_outs, offs)]


calls = 0
t_end = time.perf_counter() + SECONDS
try:
    while time.perf_counter() < t_end:
        calls += 1
        s = samplers[rng.integers(len(samplers))]
        op = rng.integers(9)
        try:
            if op == 0:  # sample, maybe with (aliased) outputs
                if rng.random() < 0.4:
                    n = int(rng.choice([1, 3, 50]))
                    u, (d, p) = aliased(n, 2, [3, 1])
                    u[:] = rng.random((n, 2))
                    ref = s.sample(u.copy())
                    try:
                        got = s.sample(u, out=(d, p))
                    except gonio.InputError:
                        pass  # overlap, alignment: refused before anything is written
                    else:
                        assert np.array_equal(got[0], ref[0]) and np.array_equal(got[1], ref[1], equal_nan=True), "aliased result differs"
                else:
                    s.sample(layout(as_dtype(values(shape(2)))))
            elif op == 1:
                s.pdf(layout(as_dtype(values(shape(3)) * 2 - 1)))
            elif op == 2:
                s.target_pdf(layout(as_dtype(values(shape(3)) * 2 - 1)))
            elif op == 3:
                if rng.random() < 0.4:
                    n = int(rng.choice([1, 3, 50]))
                    d, (o,) = aliased(n, 3, [2])
                    d[:] = rng.random((n, 3)) * 2 - 1
                    try:
                        ref = s.invert(d.copy())
                    except gonio.InputError:
                        ref = None
                    try:
                        got = s.invert(d, out=o)
                    except gonio.InputError:
                        pass
                    else:
                        assert ref is not None and np.array_equal(got, ref), "aliased invert differs"
                else:
                    s.invert(layout(as_dtype(values(shape(3)) * 2 - 1)))
            elif op == 4:
                base.intensity(layout(as_dtype(values(shape(3)) * 2 - 1)))
            elif op == 5:
                m, n = int(rng.integers(0, 5)), int(rng.integers(0, 5))
                t = np.sort(values((n,)) * 180)
                f = np.sort(values((m,)) * 360)
                v = layout(as_dtype(values((m, n)) * float(rng.choice([1, 1e300, 1e-300]))))
                d = gonio.Diagram(layout(t), layout(f), v)
                d.sampler(str(rng.choice(gonio.methods())))
            elif op == 6:
                n = int(rng.choice([0, 1, 10, 1000]))
                start = int(rng.choice([0, 1, 2**36, 2**63, 2**64 - 2000]))
                gonio.sequence(n, str(rng.choice(["halton", "sobol", "random", "RANDOM", "x"])),
                               seed=int(rng.integers(0, 2**63)), start=start)
            elif op == 7:
                data = rng.integers(0, 256, int(rng.choice([0, 1, 10, 300]))).astype(np.uint8).tobytes()
                if rng.random() < 0.5:
                    data = b"IESNA:LM-63-2002\nTILT=NONE\n" + data
                gonio.read_bytes(data, str(rng.choice(["ies", "ldt", "json"])))
            else:
                s.invert(np.full((int(rng.choice([0, 1, 10])), 3), rng.choice(SPECIAL)))
        except gonio.InternalError:
            raise
        except ALLOWED:
            pass
except BaseException:
    traceback.print_exc()
    print("FAILED after", calls, "calls")
    sys.exit(1)
print("ok", calls, "calls")
"""


def test_fuzz_entry_points():
    seconds = os.environ.get("GONIO_FUZZ_SECONDS", "15")
    r = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(HARNESS), seconds],
        capture_output=True,
        text=True,
        timeout=float(seconds) + 120,
    )
    assert r.returncode == 0, f"exit {r.returncode}\n{r.stdout}\n{r.stderr}"
    assert r.stdout.startswith("ok"), r.stdout
    calls = int(r.stdout.split()[1])
    assert calls > 100, r.stdout
