"""The package under abuse (issue 25): aliased outputs, races, memory exhaustion, hangs, odd
dtypes and files. Each test here failed before its fix; the slow or process-killing cases run in a
child interpreter with a timeout, so a regression fails the test instead of hanging the suite."""

import os
import subprocess
import sys
import textwrap
import threading

import numpy as np
import pytest

import gonio


def run_child(code, timeout=120):
    """Runs `code` in a fresh interpreter; returns its stdout (fails on a non-zero exit)."""
    r = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)],
        capture_output=True,
        text=True,
        timeout=timeout,
    )
    assert r.returncode == 0, f"exit {r.returncode}\nstdout:\n{r.stdout}\nstderr:\n{r.stderr}"
    return r.stdout


# 1. Aliasing is decided by address range, whatever object owns the memory.


def _buffer_with_points(u, floats):
    """A buffer of ``floats`` float64 values and a view of its first bytes, shaped as the points
    ``u`` and holding them."""
    buf = bytearray(8 * floats)
    ua = np.frombuffer(buf, np.float64, count=u.size).reshape(u.shape)
    ua[:] = u
    return buf, ua


def test_out_sharing_memory_with_the_input_through_another_base_is_refused():
    s = gonio.example().sampler()
    n = 100
    u = gonio.sequence(n, "halton", start=1)
    buf, ua = _buffer_with_points(u, 5 * n)
    da = np.frombuffer(buf, np.float64, count=3 * n).reshape(n, 3)  # a second view, same bytes
    assert ua.base is not da.base and np.shares_memory(ua, da)
    p = np.zeros(n)
    with pytest.raises(gonio.InputError, match=r"out\[0\] \(directions\): shares memory with u"):
        s.sample(ua, out=(da, p))
    np.testing.assert_array_equal(ua, u)  # nothing was written
    # The pdf output overlapping the input, and two outputs overlapping each other.
    pa = np.frombuffer(buf, np.float64, count=n, offset=8 * (2 * n - 1))
    with pytest.raises(gonio.InputError, match=r"out\[1\] \(pdf\): shares memory with u"):
        s.sample(ua, out=(np.zeros((n, 3)), pa))
    other = bytearray(8 * 4 * n)
    d2 = np.frombuffer(other, np.float64, count=3 * n).reshape(n, 3)
    p2 = np.frombuffer(other, np.float64, count=n, offset=8 * 3 * n - 8)
    with pytest.raises(gonio.InputError, match=r"out\[1\] \(pdf\): shares memory with out\[0\]"):
        s.sample(u, out=(d2, p2))
    dirs, _ = s.sample(u)
    dbuf = bytearray(8 * 5 * n)
    dv = np.frombuffer(dbuf, np.float64, count=3 * n).reshape(n, 3)
    dv[:] = dirs
    ov = np.frombuffer(dbuf, np.float64, count=2 * n, offset=8 * (3 * n - 2)).reshape(n, 2)
    with pytest.raises(gonio.InputError, match=r"out: shares memory with directions"):
        s.invert(dv, out=ov)
    with pytest.raises(gonio.InputError, match=r"out: shares memory with directions"):
        s.pdf(dv, out=np.frombuffer(dbuf, np.float64, count=n, offset=8 * 3 * (n - 1)))


def test_out_sharing_memory_through_ctypes_and_shared_memory_is_refused():
    # The same rule whatever owns the memory: two views of one ctypes array, and of one
    # multiprocessing shared-memory block, through different base objects.
    import ctypes
    from multiprocessing import shared_memory

    s = gonio.example().sampler()
    n = 64
    u = gonio.sequence(n, "halton", start=1)

    def views(make):
        ua, da = make()
        assert ua.base is not da.base and np.shares_memory(ua, da)
        ua[:] = u
        with pytest.raises(gonio.InputError, match=r"out\[0\] \(directions\): shares memory with u"):
            s.sample(ua, out=(da, np.zeros(n)))
        np.testing.assert_array_equal(ua, u)  # nothing was written

    raw = (ctypes.c_double * (5 * n))()
    views(lambda: (np.ctypeslib.as_array(raw)[: 2 * n].reshape(n, 2),
                   np.ctypeslib.as_array(ctypes.cast(raw, ctypes.POINTER(ctypes.c_double)),
                                         shape=(3 * n,)).reshape(n, 3)))
    shm = shared_memory.SharedMemory(create=True, size=8 * 5 * n)
    try:
        views(lambda: (np.frombuffer(shm.buf[: 16 * n], np.float64).reshape(n, 2),
                       np.frombuffer(shm.buf[: 24 * n], np.float64).reshape(n, 3)))
    finally:
        shm.close()
        shm.unlink()


def test_adjacent_views_of_one_buffer_are_accepted():
    # The range test is exact: outputs right next to the input in the same buffer are fine.
    s = gonio.example().sampler()
    n = 50
    u = gonio.sequence(n, "sobol", seed=3)
    buf, ua = _buffer_with_points(u, 6 * n)
    da = np.frombuffer(buf, np.float64, count=3 * n, offset=8 * 2 * n).reshape(n, 3)
    pa = np.frombuffer(buf, np.float64, count=n, offset=8 * 5 * n)
    d, p = s.sample(ua, out=(da, pa))
    ref_d, ref_p = s.sample(u)
    np.testing.assert_array_equal(da, ref_d)
    np.testing.assert_array_equal(pa, ref_p)


# 2. No PanicException: a race on numpy's borrow flags, allocation failure, a signal.


def test_reading_an_array_another_thread_writes_is_an_input_error_not_a_panic():
    s = gonio.example().sampler("rejection")
    n = 1 << 17
    u = gonio.sequence(n, "random", seed=1)
    d, p = np.zeros((n, 3)), np.ones(n)
    done = threading.Event()
    errors = []

    def writer():
        try:
            for _ in range(3):
                try:
                    s.sample(u, out=(d, p))
                except gonio.InputError as e:  # the reader holds the array: refused, typed
                    assert "cannot be written" in str(e), e
        except BaseException as e:  # noqa: B902 - what matters is its type
            errors.append(e)
        finally:
            done.set()

    t = threading.Thread(target=writer)
    t.start()
    refused = 0
    readers = [lambda: s.pdf(d), lambda: gonio.Diagram([0, 90], [0], p[:2].reshape(1, 2))]
    try:
        while not done.is_set():
            for reader in readers:
                try:
                    reader()
                except gonio.InputError as e:
                    assert "another call is writing" in str(e), e
                    refused += 1
                except gonio.DiagramError:
                    pass  # values read mid-write may be refused as a diagram: typed too
    finally:
        t.join()
    assert not errors, errors
    # Each writer call holds the output for a while with the GIL released, and this thread
    # retries in a loop meanwhile: the conflict is met (before the fix: PanicException).
    assert refused > 0


def test_memory_exhaustion_is_memory_error_not_an_abort():
    # Address space = what the interpreter uses now + 1 GiB: every request below needs more.
    out = run_child(
        """
        import resource, numpy as np, gonio
        s = gonio.example().sampler()
        s.sample(gonio.sequence(10, "halton"))  # thread pool and tables up
        vm = [int(l.split()[1]) * 1024 for l in open("/proc/self/status") if l.startswith("VmSize")][0]
        resource.setrlimit(resource.RLIMIT_AS, (vm + (1 << 30), resource.RLIM_INFINITY))
        cases = {
            "broadcast points": lambda: s.sample(np.broadcast_to([0.5, 0.5], (10**9, 2))),
            "float32 directions": lambda: s.pdf(np.broadcast_to(np.float32([0, 0, 1]), (10**9, 3))),
            "strided invert": lambda: s.invert(np.broadcast_to([0.0, 0.0, 1.0], (10**9, 3))),
            "sequence 2**27": lambda: gonio.sequence(2**27),
            "diagram values": lambda: gonio.Diagram([0, 90], [0], np.broadcast_to(1.0, (10**9, 2))),
            # Issue 40, item 3: 10^8 faces of 3 vertices (the library's allocations are fallible).
            "texture_uv faces": lambda: gonio.texture_uv(
                [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0]], np.broadcast_to([0, 3, 2], (10**8, 3))),
        }
        for name, f in cases.items():
            try:
                f()
                print(name, "no error")
            except MemoryError as e:
                print(name, "MemoryError")
        """
    )
    lines = out.split("\n")
    for name in ["broadcast points", "float32 directions", "strided invert", "sequence 2**27",
                 "diagram values", "texture_uv faces"]:
        assert f"{name} MemoryError" in lines, out


def test_numpy_api_is_resolved_at_import_not_inside_a_call():
    # rust-numpy looks numpy's C API capsule up lazily, on the first call that makes an array; a
    # failure there (a Ctrl-C while numpy's core loads, or the capsule gone) was a PanicException
    # inside that call. gonio resolves it at import: with the capsule removed after `import
    # gonio`, the first array-making calls still work (before the fix: PanicException).
    out = run_child(
        """
        import numpy as np
        core = np._core if hasattr(np, "_core") else np.core
        mod = core.multiarray
        import gonio
        del mod._ARRAY_API
        s = gonio.example().sampler()
        d, p = s.sample(gonio.sequence(8, "halton"))
        assert d.shape == (8, 3) and np.all(p > 0)
        print("ok", s.pdf(d).shape)
        """
    )
    assert "ok (8,)" in out, out
    # The lookup's own failure is the import's exception, an ImportError, not a PanicException.
    out = run_child(
        """
        import numpy as np
        core = np._core if hasattr(np, "_core") else np.core
        del core.multiarray._ARRAY_API
        try:
            import gonio
            print("imported")
        except ImportError:
            print("ImportError")
        """
    )
    assert out.strip() == "ImportError", out


# 4. Hangs: far starts, FIFOs, Ctrl-C in long calls.


def test_a_far_random_start_is_immediate_and_continues_the_stream():
    out = run_child(
        """
        import numpy as np, gonio
        for start in [2**36, 2**63, 2**64 - 10]:
            a = gonio.sequence(6, "random", seed=4, start=start - 3)
            b = gonio.sequence(3, "random", seed=4, start=start)
            assert np.array_equal(a[3:], b), start
        print("ok")
        """,
        timeout=60,
    )
    assert "ok" in out


def test_ctrl_c_interrupts_a_long_check():
    out = run_child(
        """
        import os, signal, threading, time, gonio
        d = gonio.example()
        threading.Timer(1.0, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
        t = time.perf_counter()
        try:
            gonio.check(d, "uniform", samples=10**12)
            print("finished")
        except KeyboardInterrupt:
            print("interrupted")
        """,
        timeout=120,
    )
    assert "interrupted" in out


def test_ctrl_c_interrupts_a_long_batch():
    # SIGINT is sent 10 ms after a 2^23-point rejection batch starts (seconds of work): the call
    # raises KeyboardInterrupt from inside, leaving the rest of its `out` unwritten (NaN). Before
    # the fix the whole batch ran first.
    out = run_child(
        """
        import os, signal, threading, time, numpy as np, gonio
        s = gonio.example().sampler("rejection")
        n = 2**23
        u = gonio.sequence(n, "random")
        d, p = np.full((n, 3), np.nan), np.full(n, np.nan)
        go = threading.Event()
        def kill():
            go.wait()
            time.sleep(0.01)
            os.kill(os.getpid(), signal.SIGINT)
        threading.Thread(target=kill).start()
        try:
            go.set()
            s.sample(u, out=(d, p))
            print("finished")
        except KeyboardInterrupt:
            print("interrupted, rows left:", int(np.isnan(p).sum()))
        """,
        timeout=300,
    )
    assert "interrupted" in out and "rows left: 0" not in out, out


def test_reading_a_fifo_does_not_block(tmp_path):
    f = tmp_path / "pipe.ies"
    os.mkfifo(f)
    with pytest.raises(OSError, match="not a regular file"):
        gonio.read(f)


# 8. The smaller slips.


@pytest.mark.parametrize(
    "bad, kind",
    [
        (np.array([[0.5 + 0.1j, 0.5]]), "complex"),
        (np.array([["2020-01-01", "2020-01-02"]], dtype="datetime64[D]"), "dates"),
        (np.zeros((1, 2), dtype="m8[s]"), "dates"),
        (np.zeros(1, dtype=[("a", "f8"), ("b", "f8")]).reshape(1, 1), "structured"),
        (np.array([["0.5", "0.5"]]), "text"),
        ([["0.5", "0.5"]], "text"),
        (np.array([[0.5, 0.5]], dtype=object), "object"),
    ],
)
def test_non_real_dtypes_are_refused(bad, kind):
    s = gonio.example().sampler()
    with pytest.raises(gonio.InputError, match=kind):
        s.sample(bad)
    with pytest.raises(gonio.InputError, match=kind):
        gonio.Diagram([0, 90], [0], np.asarray(bad).reshape(1, -1)[:, :2] if kind != "structured"
                      else bad)


def test_names_match_in_any_letter_case():
    d = gonio.example()
    assert d.sampler("HDS", "Sphere").method == "hds"
    assert d.sampler(" Bilinear ", "SPHERE").domain == "sphere"
    assert gonio.sequence(2, "SOBOL").shape == (2, 2)
    assert gonio.read_bytes(d.dumps("ies"), "IES").source == "ies"


def test_read_size_is_checked_before_reading(tmp_path):
    big = tmp_path / "big.ies"
    with open(big, "wb") as f:
        f.truncate((64 << 20) + 1)  # sparse: nothing is written, nothing should be read
    with pytest.raises(gonio.ParseError, match=r"more than the limit of 67108864 bytes"):
        gonio.read(big)
    with pytest.raises(gonio.ParseError, match=r"more than the limit"):
        gonio.read_bytes(b" " * ((64 << 20) + 1), "ies")


@pytest.mark.parametrize(
    "data, want",
    [
        (b"\0" * 200, "all NUL"),
        ("IESNA:LM-63-2002\nTILT=NONE\n".encode("utf-32-le"), "UTF-32LE without"),
        ("IESNA:LM-63-2002\nTILT=NONE\n".encode("utf-32"), "UTF-32LE, byte-order mark"),
        ("IESNA:LM-63-2002\nTILT=NONE\n".encode("utf-16-le"), "UTF-16LE without"),
    ],
)
def test_nul_and_utf32_files_are_named(data, want):
    for fmt in ["ies", "ldt"]:
        with pytest.raises(gonio.ParseError, match=want):
            gonio.read_bytes(data, fmt)


def test_tiny_and_huge_numbers_print_in_exponent_form():
    s = gonio.example().sampler()
    with pytest.raises(gonio.InputError) as e:
        s.sample([[1e300, 0.5]])
    assert "(1e300, 0.5)" in str(e.value)
    with pytest.raises(gonio.InputError) as e:
        s.sample([[-5e-324, 0.5]])
    assert "-5e-324" in str(e.value)
    # Finite values whose power overflows: a typed error naming the value (issue 40, item 1).
    with pytest.raises(gonio.BuildError) as e:
        gonio.Diagram([0, 90, 180], [0], [[1e308, 1e308, 1e308]]).sampler()
    assert "overflows" in str(e.value) and "1e308" in str(e.value) and len(str(e.value)) < 400


def test_zero_density_inverse_is_refused_by_every_method():
    # A downlight: straight up has density 0 for every method (issue 25, item 6).
    down = gonio.read_bytes("IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 3 1 1 2 0 0 0\n1 1 100\n"
                            "0 45 90\n0\n100 60 0\n", "ies")
    for m in ["hds", "piecewise-constant", "bilinear"]:
        s = down.sampler(m)
        assert s.pdf([[0, 0, 1.0]])[0] == 0.0
        with pytest.raises(gonio.InputError, match=r"row 0: .*density 0"):
            s.invert([[0, 0, 1.0]])


def test_bilinear_is_scale_free():
    theta, phi = np.arange(0, 181, 15.0), np.arange(0, 360, 30.0)
    t, p = np.meshgrid(np.radians(theta), np.radians(phi))
    v = (1 + 0.8 * np.cos(p - 1)) * (1.2 + np.cos(t))
    u = gonio.sequence(2000, "sobol", seed=2)
    ref_d, ref_p = gonio.Diagram(theta, phi, v).sampler("bilinear").sample(u)
    for scale in [1e200, 1e-300, 1e300]:
        d, pdf = gonio.Diagram(theta, phi, v * scale).sampler("bilinear").sample(u)
        np.testing.assert_allclose(d, ref_d, rtol=0, atol=1e-9)
        np.testing.assert_allclose(pdf, ref_p, rtol=1e-9)
