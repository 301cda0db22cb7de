"""The GPU check of gonio_device.h (scripts/gpu-check.sh runs it; docs/GPU.md): on one CUDA GPU,
with CuPy (NVRTC), from the repository root, with the data of scripts/gpu-prepare.sh in .gpudata/
and (optionally) the wheels of .whl/ on PYTHONPATH (gonio, drjit, mitsuba).

1. Compiles the header's kernels with NVRTC as it ships (defaults: FMA contraction on): gonio.cuda's
   module (view by pointer) and crates/gonio-capi/tests/device/kernels.cu (view by value), plus
   this script's peers (a pbrt-v4-style piecewise-constant 2D sampler, a trivial copy kernel).
2. The contract on the device for every case of .gpudata/manifest.json: directions of `sample`
   within 1e-6 of the library's float32 map, pdf within its bound (8 f32 ulps relative, else the
   conditioning term: the change of the library's pdf over moves of 4 f32 ulps of θ and φ),
   `invert` within 1e-5 where the density is positive; bit-identical fractions. With the gonio
   wheel importable the references are computed here on 2^20 points per case (else the shipped
   2^15-point references are used); the environment maps' blobs are rebuilt here from their .hdr
   (needs gonio) and checked against the checksum recorded by gpu-prepare.
3. Light tracing (kernels.cu): the example luminaire's floor irradiance, 2^24 samples, against the
   midpoint-rule reference computed on the device and the host reference of gpu-prepare.
4. Timing, 2^24 points, best of 7 CUDA-event (device) times, kernels warm: gonio sample / pdf /
   invert on grids 19 × 36, 181 × 361, 1024 × 1024 and a 2048 × 1024 environment map; the
   pbrt-style kernel on the same grids; Mitsuba 3 cuda_ad_rgb MarginalContinuous2D0 sample / eval /
   invert and the envmap emitter's sample_direction / pdf_direction (in a subprocess: Dr.Jit's
   kernel history times, warm); cudaMemcpy device-to-device bandwidth and a trivial kernel.

One table (G points/s) and the contract results are printed and, if $OUT is set, written to
$OUT/gpu-check.txt and $OUT/gpu-check.json. Every part is guarded: a failure prints its reason
and the rest runs. Exit 0 when every contract check that ran passed, 1 otherwise.

Usage: python3 scripts/gpu_check.py [--quick] [--n-time LOG2] [--reps R] [--no-gpu]
       python3 scripts/gpu_check.py --mitsuba-only JSON_OUT [--variant cuda_ad_rgb] (internal)
"""

import argparse
import importlib.util
import json
import math
import os
import pathlib
import platform
import subprocess
import sys
import time
import traceback

import numpy as np

SCRIPTS = pathlib.Path(__file__).resolve().parent
REPO = SCRIPTS.parent
sys.path.insert(0, str(SCRIPTS))
import gpu_common as gc  # noqa: E402

DATA = REPO / ".gpudata"
HEADER = REPO / "crates" / "gonio-capi" / "include" / "gonio_device.h"
KERNELS_CU = REPO / "crates" / "gonio-capi" / "tests" / "device" / "kernels.cu"
CUDA_PY = REPO / "crates" / "gonio-py" / "python" / "gonio" / "cuda.py"
F32_ULP = 2.0 ** -23  # relative spacing of floats in [1, 2)

LOG = []
RESULTS = {"contract": {}, "timing": {}, "light": None, "env": {}, "errors": []}


def say(*a):
    s = " ".join(str(x) for x in a)
    print(s, flush=True)
    LOG.append(s)


def guard(what):
    """Decorator: run, print the reason of any failure, go on."""
    def wrap(fn):
        def run(*a, **k):
            try:
                return fn(*a, **k)
            except Exception as e:  # noqa: BLE001
                say(f"!! {what}: FAILED: {type(e).__name__}: {e}")
                tb = traceback.format_exc().strip().splitlines()
                for line in tb[-6:]:
                    say("   " + line)
                RESULTS["errors"].append(f"{what}: {type(e).__name__}: {e}")
                return None
        return run
    return wrap


# ------------------------------------------------------------------------------------------------
# Peers in CUDA: the pbrt-v4-style piecewise-constant 2D sampler with a lat-long lift, a trivial
# kernel (reads u, v; writes x, y, z, pdf).
# ------------------------------------------------------------------------------------------------

PEER_SOURCE = r"""
/* pbrt-v4 PiecewiseConstant1D/2D (util/sampling.h) over an nu × nv image on [0,1]², rows v,
 * tables in float32: func (nv·nu), cdf (nv·(nu+1)) per row normalised; marginal func (nv),
 * marginal cdf (nv+1); mint = the marginal's integral. The lat-long lift: θ = π·v, φ = 2π·u,
 * pdf_ω = pdf_uv / (2π² sin θ). */
__device__ __forceinline__ int pb_find(const float *__restrict__ cdf, int size, float u) {
  /* pbrt's FindInterval(size, cdf[i] <= u): the largest i in [0, size−2] with cdf[i] <= u */
  int first = 1, len = size - 2;
  while (len > 0) {
    int half = len >> 1, middle = first + half;
    if (__ldg(cdf + middle) <= u) { first = middle + 1; len -= half + 1; } else { len = half; }
  }
  int i = first - 1;
  return i < 0 ? 0 : (i > size - 2 ? size - 2 : i);
}

extern "C" __global__ void pbrt_sample(const float *__restrict__ func, const float *__restrict__ cdf,
    const float *__restrict__ mfunc, const float *__restrict__ mcdf, int nu, int nv, float mint,
    const float *__restrict__ u0, const float *__restrict__ u1, float *__restrict__ x,
    float *__restrict__ y, float *__restrict__ z, float *__restrict__ pdf, long long n) {
  long long i = (long long)blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  float a = u0[i], b = u1[i];
  /* marginal (v) */
  int j = pb_find(mcdf, nv + 1, b);
  float c0 = __ldg(mcdf + j), c1 = __ldg(mcdf + j + 1);
  float dv = b - c0;
  if (c1 - c0 > 0.0f) dv /= (c1 - c0);
  float v = fminf((j + dv) / nv, 0x1.fffffep-1f);
  /* conditional (u) in row j */
  const float *rc = cdf + (long long)j * (nu + 1);
  int k = pb_find(rc, nu + 1, a);
  float e0 = __ldg(rc + k), e1 = __ldg(rc + k + 1);
  float du = a - e0;
  if (e1 - e0 > 0.0f) du /= (e1 - e0);
  float uu = fminf((k + du) / nu, 0x1.fffffep-1f);
  float pdf_uv = mint > 0.0f ? __ldg(func + (long long)j * nu + k) / mint : 0.0f;
  float theta = 3.14159265f * v, phi = 6.28318531f * uu, st, ct, sp, cp;
  sincosf(theta, &st, &ct);
  sincosf(phi, &sp, &cp);
  x[i] = st * cp; y[i] = st * sp; z[i] = ct;
  pdf[i] = st > 0.0f ? pdf_uv / (2.0f * 9.8696044f * st) : 0.0f;
}

extern "C" __global__ void pbrt_pdf(const float *__restrict__ func, int nu, int nv, float mint,
    const float *__restrict__ x, const float *__restrict__ y, const float *__restrict__ z,
    float *__restrict__ pdf, long long n) {
  long long i = (long long)blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  float dz = fminf(fmaxf(z[i], -1.0f), 1.0f);
  float theta = acosf(dz), phi = atan2f(y[i], x[i]);
  if (phi < 0.0f) phi += 6.28318531f;
  float st = sinf(theta);
  int k = min((int)(phi * (0.15915494f * nu)), nu - 1), j = min((int)(theta * (0.31830989f * nv)), nv - 1);
  float p = mint > 0.0f ? __ldg(func + (long long)j * nu + k) / mint : 0.0f;
  pdf[i] = st > 0.0f ? p / (2.0f * 9.8696044f * st) : 0.0f;
}

extern "C" __global__ void pbrt_invert(const float *__restrict__ cdf, const float *__restrict__ mcdf,
    int nu, int nv, const float *__restrict__ x, const float *__restrict__ y,
    const float *__restrict__ z, float *__restrict__ u0, float *__restrict__ u1, long long n) {
  long long i = (long long)blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  float dz = fminf(fmaxf(z[i], -1.0f), 1.0f);
  float theta = acosf(dz), phi = atan2f(y[i], x[i]);
  if (phi < 0.0f) phi += 6.28318531f;
  float fu = phi * (0.15915494f * nu), fv = theta * (0.31830989f * nv);
  int k = min((int)fu, nu - 1), j = min((int)fv, nv - 1);
  float c0 = __ldg(mcdf + j), c1 = __ldg(mcdf + j + 1);
  const float *rc = cdf + (long long)j * (nu + 1);
  float e0 = __ldg(rc + k), e1 = __ldg(rc + k + 1);
  u1[i] = c0 + (fv - j) * (c1 - c0);
  u0[i] = e0 + (fu - k) * (e1 - e0);
}

/* Keeps the stream busy for `cycles` SM clocks, so that the host has enqueued the timed work
 * before the start event is reached (no host gap inside the measured interval). */
extern "C" __global__ void spin(long long cycles) {
  long long t0 = clock64();
  while (clock64() - t0 < cycles) {
  }
}

extern "C" __global__ void trivial(const float *__restrict__ u, const float *__restrict__ v,
    float *__restrict__ x, float *__restrict__ y, float *__restrict__ z, float *__restrict__ pdf,
    long long n) {
  long long i = (long long)blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  float a = u[i], b = v[i];
  x[i] = a; y[i] = b; z[i] = a * b; pdf[i] = a + b;
}
"""


def pbrt_tables(image):
    """pbrt-v4 PiecewiseConstant2D tables of a (nv, nu) non-negative image on [0,1]² (float64
    accumulation, float32 tables, pbrt's rules for a zero row)."""
    img = np.abs(np.asarray(image, dtype=np.float64))
    nv, nu = img.shape
    func = img
    row_int = func.sum(axis=1) / nu
    cdf = np.zeros((nv, nu + 1))
    cdf[:, 1:] = np.cumsum(func, axis=1) / nu
    for j in range(nv):
        if row_int[j] > 0:
            cdf[j] /= row_int[j]
        else:
            cdf[j] = np.arange(nu + 1) / nu
    mcdf = np.zeros(nv + 1)
    mcdf[1:] = np.cumsum(row_int) / nv
    mint = mcdf[-1]
    mcdf = mcdf / mint if mint > 0 else np.arange(nv + 1) / nv
    f32 = lambda a: np.ascontiguousarray(a, dtype=np.float32)  # noqa: E731
    return dict(func=f32(func), cdf=f32(cdf), mfunc=f32(row_int), mcdf=f32(mcdf), nu=nu, nv=nv,
                mint=float(mint))


def grid_image(n_theta, m_phi):
    """The lobes diagram as an image for the 2D peers: rows θ (n_theta), columns φ (m_phi),
    the values times sin θ (a density over the lat-long square)."""
    th, ph, v = gc.lobes(n_theta, m_phi)
    img = v.T * np.sin(np.radians(th))[:, None]  # (N, M)
    return np.maximum(img, 1e-6 * img.max()).astype(np.float32)


def env_weight_image(img):
    """Rec. 709 luminance times sin θ of an (H, W, 3) lat-long image (rows from the top)."""
    h = img.shape[0]
    lum = 0.2126 * img[..., 0] + 0.7152 * img[..., 1] + 0.0722 * img[..., 2]
    st = np.sin(np.pi * (np.arange(h) + 0.5) / h)
    return (lum * st[:, None]).astype(np.float32)


# ------------------------------------------------------------------------------------------------
# Mitsuba (in a subprocess: --mitsuba-only)
# ------------------------------------------------------------------------------------------------

def mitsuba_only(out_json, variant, log2n, reps):
    res = {"variant": variant, "ops": {}, "errors": []}
    try:
        import drjit as dr
        import mitsuba as mi

        mi.set_variant(variant)
        res["versions"] = f"mitsuba {mi.__version__}, drjit {dr.__version__}"
    except Exception as e:  # noqa: BLE001
        res["errors"].append(f"import/set_variant: {type(e).__name__}: {e}")
        pathlib.Path(out_json).write_text(json.dumps(res))
        return 0
    n = 1 << log2n
    try:
        dr.set_flag(dr.JitFlag.KernelHistory, True)
        have_hist = True
    except Exception:  # noqa: BLE001
        have_hist = False
    rng = np.random.default_rng(5)
    ux = mi.Float(rng.random(n, dtype=np.float32))
    uy = mi.Float(rng.random(n, dtype=np.float32))
    u = mi.Point2f(ux, uy)
    dr.eval(u)
    dr.sync_thread()

    def timed(fn):
        """Best of reps: (kernel ms from Dr.Jit's history, wall ms); one warm-up call first."""
        best_k, best_w = math.inf, math.inf
        for r in range(reps + 1):
            if have_hist:
                dr.kernel_history()  # clears it
            dr.sync_thread()
            t0 = time.perf_counter()
            out = fn()
            dr.eval(out)
            dr.sync_thread()
            w = (time.perf_counter() - t0) * 1e3
            k = math.nan
            if have_hist:
                h = dr.kernel_history()
                ts = [float(e.get("execution_time", 0.0)) for e in h]
                k = sum(ts) if ts else math.nan
            if r > 0:
                best_w = min(best_w, w)
                if k == k:
                    best_k = min(best_k, k)
            del out
        return (best_k if best_k < math.inf else None), best_w

    def record(key, fn):
        try:
            k, w = timed(fn)
            res["ops"][key] = {"kernel_ms": k, "wall_ms": w}
        except Exception as e:  # noqa: BLE001
            res["errors"].append(f"{key}: {type(e).__name__}: {e}")

    for n_t, m_p in [(19, 36), (181, 361), (1024, 1024)]:
        g = f"grid_{n_t}x{m_p}"
        try:
            img = grid_image(n_t, m_p)
            distr = mi.MarginalContinuous2D0(img)
            pos, _ = distr.sample(u)
            dr.eval(pos)
            record(f"{g}/sample", lambda: distr.sample(u))
            record(f"{g}/pdf", lambda: distr.eval(pos))
            record(f"{g}/invert", lambda: distr.invert(pos))
        except Exception as e:  # noqa: BLE001
            res["errors"].append(f"{g}: {type(e).__name__}: {e}")
    try:
        img = gc.env_image(2048, 1024)
        emitter = mi.load_dict({"type": "envmap", "bitmap": mi.Bitmap(img)})
        it = dr.zeros(mi.Interaction3f)
        ds, _ = emitter.sample_direction(it, u)
        dr.eval(ds)
        record("envmap_2048x1024/sample", lambda: emitter.sample_direction(it, u))
        record("envmap_2048x1024/pdf", lambda: emitter.pdf_direction(it, ds))
    except Exception as e:  # noqa: BLE001
        res["errors"].append(f"envmap: {type(e).__name__}: {e}")
    pathlib.Path(out_json).write_text(json.dumps(res))
    return 0


# ------------------------------------------------------------------------------------------------
# The device parts (CuPy)
# ------------------------------------------------------------------------------------------------

def load_cuda_module():
    spec = importlib.util.spec_from_file_location("gonio_cuda_repo", CUDA_PY)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


class Device:
    def __init__(self, cp, reps):
        self.cp = cp
        self.reps = reps
        os.environ.setdefault("GONIO_DEVICE_HEADER", str(HEADER))
        self.gcuda = load_cuda_module()
        header = HEADER.read_text()
        t0 = time.perf_counter()
        self.kmod = cp.RawModule(
            code=KERNELS_CU.read_text().replace('#include "gonio_device.h"', header))
        self.kfun = {k: self.kmod.get_function(k) for k in (
            "soa_sample", "soa_pdf", "soa_invert", "soa_target", "light_trace_floor", "floor_reference")}
        # The header's fast-math mode (GONIO_DEVICE_FAST_MATH, --use_fast_math): timed beside the
        # bit-exact kernels, its accuracy against them measured on the same points.
        self.fmod = None
        try:
            self.fmod = cp.RawModule(
                code="#define GONIO_DEVICE_FAST_MATH 1\n"
                + KERNELS_CU.read_text().replace('#include "gonio_device.h"', header),
                options=("--use_fast_math",))
            self.ffun = {k: self.fmod.get_function(k) for k in ("soa_sample", "soa_pdf", "soa_invert")}
        except Exception as e:  # noqa: BLE001
            say(f"   fast-math kernels not built: {type(e).__name__}: {e}")
        self.pmod = cp.RawModule(code=PEER_SOURCE)
        self.pfun = {k: self.pmod.get_function(k) for k in ("pbrt_sample", "pbrt_pdf", "pbrt_invert", "trivial", "spin")}
        say(f"   kernels.cu and the peers compiled (NVRTC) and loaded in {time.perf_counter() - t0:.1f} s")

    def sampler(self, blob, validate):
        return self.gcuda.DeviceSampler(blob, validate=validate)

    def view_value(self, ds):
        """The sampler's device view as a by-value kernel argument (680 bytes)."""
        raw = self.cp.asnumpy(ds.view).tobytes()
        return np.frombuffer(raw, dtype=np.dtype((np.void, len(raw)))).copy()

    def time_ms(self, fn):
        """Best of reps CUDA-event times (ms) of fn() on the current stream; one warm-up. A
        one-thread spin kernel (~0.2 ms) runs before the start event, so that the launch of fn is
        already queued when the start event is reached."""
        cp = self.cp
        fn()
        cp.cuda.get_current_stream().synchronize()
        best = math.inf
        for _ in range(self.reps):
            a, b = cp.cuda.Event(), cp.cuda.Event()
            self.pfun["spin"]((1,), (1,), (np.int64(400_000),))
            a.record()
            fn()
            b.record()
            b.synchronize()
            best = min(best, cp.cuda.get_elapsed_time(a, b))
        return best


def u64(a, off=0):
    return np.uint64(a.data.ptr + 4 * off)


def grid_of(n):
    return ((n + 255) // 256,), (256,)


# ------------------------------------------------------------------------------------------------
# Cases: blobs and references
# ------------------------------------------------------------------------------------------------

def import_gonio():
    try:
        import gonio

        return gonio, f"gonio {getattr(gonio, '__version__', '?')} from {pathlib.Path(gonio.__file__).parent}"
    except Exception as e:  # noqa: BLE001
        return None, f"gonio not importable ({type(e).__name__}: {e})"


def case_blob(entry, gonio):
    """The case's blob: shipped, or rebuilt here by gonio; checked against the recorded checksum."""
    if entry.get("blob"):
        blob = (DATA / entry["blob"]).read_bytes()
        origin = "shipped"
    else:
        if gonio is None:
            raise RuntimeError("its blob is built by the gonio wheel, which is not importable here")
        b = entry["build"]
        if "envmap" in b:
            blob = gonio.EnvMap(str(DATA / b["envmap"]), precision="float32").tables()
        elif "lobes" in b:
            th, ph, v = gc.lobes(*b["lobes"])
            blob = gonio.Diagram(th, ph, v).sampler(domain="sphere").tables()
        elif "env_image" in b:
            import tempfile

            w, h = b["env_image"]
            with tempfile.TemporaryDirectory() as t:
                p = os.path.join(t, "env.pfm")
                gc.write_pfm(p, gc.env_image(w, h))
                blob = gonio.EnvMap(p, precision="float32").tables()
        else:
            raise RuntimeError(f"unknown build {b}")
        origin = "built here"
    same = int.from_bytes(blob[24:32], "little") == entry["checksum"]
    return blob, origin, same


def host_reference(gonio, blob, u):
    sys.path.insert(0, str(SCRIPTS))
    import gpu_prepare

    return gpu_prepare.reference(blob, u)


def ulps_rel(a, b):
    """|a − b| / max(|b|, tiny) in units of f32 ulps of b (2^-23 relative)."""
    a = a.astype(np.float64)
    b = b.astype(np.float64)
    return np.abs(a - b) / np.maximum(np.abs(b), 1e-30) / F32_ULP


def conditioning(gonio, blob, dirs, pdf_ref):
    """The contract's conditioning term at each direction: the largest change of the library's
    float32 pdf when θ or φ moves by ±4 f32 ulps (of θ, φ in radians, at least 4 ulps of 1)."""
    s = gonio.Sampler.from_tables(blob)
    d = dirs.astype(np.float64)
    th = np.arccos(np.clip(d[:, 2], -1, 1))
    ph = np.arctan2(d[:, 1], d[:, 0])
    out = np.zeros(len(d))
    for dth, dph in [(1, 0), (-1, 0), (0, 1), (0, -1)]:
        t2 = th + dth * 4 * F32_ULP * np.maximum(np.abs(th), 1.0)
        p2 = ph + dph * 4 * F32_ULP * np.maximum(np.abs(ph), 1.0)
        dd = np.stack([np.sin(t2) * np.cos(p2), np.sin(t2) * np.sin(p2), np.cos(t2)], 1)
        p = s.pdf(dd.astype(np.float32)).astype(np.float64)
        out = np.maximum(out, np.abs(p - pdf_ref.astype(np.float64)))
    return out


@guard("contract")
def contract(dev, manifest, gonio, n_contract):
    cp = dev.cp
    say("")
    say("== Contract: the device against the library's float32 map")
    say(f"   {'':<44} {'':>8} {'sample: direction':>20} {'sample: pdf':>20} {'pdf(direction)':>20} "
        f"{'invert(direction)':>20}")
    say(f"   {'case':<44} {'points':>8} {'max err  bit-id':>20} {'max rel  bit-id':>20} {'max rel  bit-id':>20} "
        f"{'max err  bit-id':>20} {'by value':>8} {'verdict':>7}")
    all_ok = True
    for entry in manifest["contract"]:
        name = entry["name"]
        try:
            blob, origin, same = case_blob(entry, gonio)
            if not same:
                say(f"   {name}: NOTE: the blob {origin} differs from gpu-prepare's (checksum); "
                    + ("references recomputed here" if gonio else "shipped references do not apply"))
                if gonio is None:
                    raise RuntimeError("blob differs and no gonio to recompute references")
            if gonio is not None:
                n = n_contract
                u = gc.points(n)
                ref = host_reference(gonio, blob, u)
            else:
                z = np.load(DATA / "refs" / f"{name}.npz")
                ref = {k: z[k] for k in z.files}
                n = len(ref["pdf"])
                u = gc.points(n)
            ds = dev.sampler(blob, validate=gonio is not None)
            du = cp.asarray(u)
            d_dirs, d_pdf = ds.sample(du)
            d_dirs, d_pdf = cp.asnumpy(d_dirs), cp.asnumpy(d_pdf)
            # the directions the library's pdf/invert evaluated (it normalises in float64 first)
            unit = gc.library_unit(ref["dirs"])
            rdirs = cp.asarray(unit)
            d_pdf_at = cp.asnumpy(ds.pdf(rdirs))
            d_inv = cp.asnumpy(ds.invert(rdirs))
            # by value (kernels.cu), SoA: must equal the pointer kernels bit for bit
            byval = "n/a"
            try:
                vv = dev.view_value(ds)
                uu, vvv = cp.asarray(u[:, 0].copy()), cp.asarray(u[:, 1].copy())
                x, y, zz, p = (cp.empty(n, dtype=cp.float32) for _ in range(4))
                g, b = grid_of(n)
                dev.kfun["soa_sample"](g, b, (vv, u64(uu), u64(vvv), u64(x), u64(y), u64(zz), u64(p), np.int64(n)))
                sv = np.stack([cp.asnumpy(x), cp.asnumpy(y), cp.asnumpy(zz)], 1)
                same_bits = (sv.view(np.uint32) == d_dirs.view(np.uint32)).all() and \
                    (cp.asnumpy(p).view(np.uint32) == d_pdf.view(np.uint32)).all()
                byval = "same" if same_bits else "DIFFERS"
            except Exception as e:  # noqa: BLE001
                byval = f"error ({type(e).__name__})"
                say(f"   {name}: by-value kernels: {type(e).__name__}: {e}")
            # directions
            dir_err = float(np.nanmax(np.abs(d_dirs.astype(np.float64) - ref["dirs"].astype(np.float64))))
            dir_bit = float(np.mean((d_dirs.view(np.uint32) == ref["dirs"].view(np.uint32)).all(axis=1)))
            # pdfs
            def pdf_stats(dev_p, ref_p, dirs_for_cond):
                rel = ulps_rel(dev_p, ref_p)
                bit = float(np.mean(dev_p.view(np.uint32) == ref_p.view(np.uint32)))
                beyond = np.nonzero(rel > 8)[0]
                viol = len(beyond)
                if viol and gonio is not None:
                    cond = conditioning(gonio, blob, dirs_for_cond[beyond], ref_p[beyond])
                    err = np.abs(dev_p[beyond].astype(np.float64) - ref_p[beyond].astype(np.float64))
                    viol = int(np.sum(err > cond + 8 * F32_ULP * np.abs(ref_p[beyond])))
                return float(np.max(rel) * F32_ULP), bit, len(beyond), viol
            s_rel, s_bit, s_beyond, s_viol = pdf_stats(d_pdf, ref["pdf"], ref["dirs"])
            a_rel, a_bit, a_beyond, a_viol = pdf_stats(d_pdf_at, ref["pdf_at"], unit)
            # invert where the density is positive
            pos = np.isfinite(ref["inv"]).all(axis=1)
            inv_err = float(np.max(np.abs(d_inv[pos].astype(np.float64) - ref["inv"][pos]))) if pos.any() else 0.0
            inv_bit = float(np.mean((d_inv[pos].view(np.uint32) == ref["inv"][pos].view(np.uint32)).all(axis=1))) if pos.any() else 1.0
            nan_mismatch = int(np.sum(np.isnan(d_inv[~pos]).sum(axis=1) != 2))
            ok = (dir_err <= 1e-6 and s_viol == 0 and a_viol == 0 and inv_err <= 1e-5 and byval in ("same", "n/a")
                  and not np.isnan(d_inv[pos]).any())
            all_ok &= ok
            pc = lambda f: f"{100 * f:8.4f}%"  # noqa: E731
            label = (name.replace("lm63_2002_lithonia_", "lithonia_") + f" ({origin})")[:44]
            say(f"   {label:<44} {n:>8} {dir_err:>10.2e} {pc(dir_bit)} {s_rel:>10.2e} {pc(s_bit)} "
                f"{a_rel:>10.2e} {pc(a_bit)} {inv_err:>10.2e} {pc(inv_bit)} {byval:>8} {'PASS' if ok else 'FAIL':>7}")
            if s_beyond or a_beyond or nan_mismatch:
                say(f"   {'':<42} pdf beyond 8 ulps: sample {s_beyond} (beyond the bound {s_viol}), "
                    f"pdf(direction) {a_beyond} (beyond the bound {a_viol}); invert: {nan_mismatch} rows where "
                    f"the library has no point and the device has one")
            RESULTS["contract"][name] = dict(points=n, origin=origin, dir_max_err=dir_err, dir_bit_identical=dir_bit,
                                             sample_pdf_max_rel=s_rel, sample_pdf_bit_identical=s_bit,
                                             sample_pdf_beyond_8ulps=s_beyond, sample_pdf_violations=s_viol,
                                             pdf_max_rel=a_rel, pdf_bit_identical=a_bit,
                                             pdf_beyond_8ulps=a_beyond, pdf_violations=a_viol,
                                             invert_max_err=inv_err, invert_bit_identical=inv_bit,
                                             invert_nan_mismatch=nan_mismatch, by_value=byval,
                                             ok=bool(ok))
            del ds
        except Exception as e:  # noqa: BLE001
            all_ok = False
            say(f"   {name}: SKIPPED/FAILED: {type(e).__name__}: {e}")
            RESULTS["contract"][name] = dict(ok=False, error=f"{type(e).__name__}: {e}")
    return all_ok


@guard("light tracing")
def light(dev, manifest, log2n):
    cp = dev.cp
    lt = manifest["light"]
    blob = (DATA / lt["blob"]).read_bytes()
    ds = dev.sampler(blob, validate=False)
    vv = dev.view_value(ds)
    f = lt["floor"]
    nx, ny = f["nx"], f["ny"]
    n = 1 << log2n
    E = cp.zeros(nx * ny, dtype=cp.float64)
    g, b = grid_of(n)
    args = (vv, np.uint64(n), np.uint32(1), np.float32(f["h"]), np.float32(f["x0"]), np.float32(f["y0"]),
            np.float32(f["cell"]), np.int32(nx), np.int32(ny), u64(E))
    t0 = cp.cuda.Event(); t1 = cp.cuda.Event()
    t0.record()
    dev.kfun["light_trace_floor"](g, b, args)
    t1.record(); t1.synchronize()
    ms = cp.cuda.get_elapsed_time(t0, t1)
    est = cp.asnumpy(E)
    R = cp.zeros(nx * ny, dtype=cp.float64)
    dev.kfun["floor_reference"](((nx * ny + 63) // 64,), (64,),
                                (vv, np.float32(f["h"]), np.float32(f["x0"]), np.float32(f["y0"]),
                                 np.float32(f["cell"]), np.int32(nx), np.int32(ny), np.int32(lt["k"]), u64(R)))
    dref = cp.asnumpy(R)
    href = np.array(lt["reference"])
    ref_diff = float(np.max(np.abs(dref - href) / np.maximum(href, 1e-300 + 1e-12 * href.max())))
    err = gc.rel_rmse(est, href)
    expect = lt["host_rel_rmse_2p22"] * math.sqrt((1 << 22) / n)
    ok = err < 3 * expect and ref_diff < 1e-4  # 3x the noise the host run predicts
    say("")
    say(f"== Light tracing (kernels.cu light_trace_floor; the example luminaire, floor z = -3 m, {nx} x {ny} patches of 1 m^2)")
    say(f"   2^{log2n} samples in {ms:.2f} ms ({n / ms / 1e6:.2f} G samples/s incl. target lookup and atomics); mean E "
        f"{est.mean():.4g} lx (reference {href.mean():.4g} lx)")
    say(f"   relative RMSE over the patches {err:.2e} (expected about {expect:.1e} from the host run at 2^22); "
        f"device midpoint reference vs host (gonio Diagram.intensity) max rel diff {ref_diff:.1e}: {'PASS' if ok else 'FAIL'}")
    RESULTS["light"] = dict(samples=n, ms=ms, rel_rmse=err, expected=expect, ref_max_rel_diff=ref_diff, ok=bool(ok))
    return ok


@guard("timing")
def timing(dev, manifest, gonio, log2n):
    cp = dev.cp
    n = 1 << log2n
    g, b = grid_of(n)
    T = RESULTS["timing"]
    rng = cp.random.default_rng(11)
    u = rng.random(n, dtype=cp.float32)
    v = rng.random(n, dtype=cp.float32)
    x, y, z, p, ou, ov = (cp.empty(n, dtype=cp.float32) for _ in range(6))
    gps = lambda ms: n / (ms * 1e-3) / 1e9  # noqa: E731
    # bandwidth: 12 bytes/point copied = 24 bytes/point of traffic (read + write)
    try:
        src = cp.empty(12 * n, dtype=cp.uint8)
        dst = cp.empty(12 * n, dtype=cp.uint8)
        src.fill(1)
        stream = cp.cuda.get_current_stream().ptr
        ms = dev.time_ms(lambda: cp.cuda.runtime.memcpyAsync(dst.data.ptr, src.data.ptr, 12 * n,
                                                             cp.cuda.runtime.memcpyDeviceToDevice, stream))
        bw = 24 * n / (ms * 1e-3)
        T["memcpy"] = dict(ms=ms, gbps=bw / 1e9, floor_gpts=bw / 24 / 1e9)
        del src, dst
    except Exception as e:  # noqa: BLE001
        say(f"   memcpy bandwidth: {type(e).__name__}: {e}")
    try:
        ms = dev.time_ms(lambda: dev.pfun["trivial"](g, b, (u64(u), u64(v), u64(x), u64(y), u64(z), u64(p), np.int64(n))))
        T["trivial"] = dict(ms=ms, gpts=gps(ms))
    except Exception as e:  # noqa: BLE001
        say(f"   trivial kernel: {type(e).__name__}: {e}")
    for entry in manifest["timing"]:
        name = entry["name"]
        row = T.setdefault(name, {})
        try:
            blob, origin, same = case_blob(entry, gonio)
            row["blob"] = f"{origin}, {len(blob) / 1e6:.1f} MB" + ("" if same else ", checksum differs from gpu-prepare's")
            ds = dev.sampler(blob, validate=False)
            row["gonio/sample"] = gps(dev.time_ms(lambda: ds.sample_soa(u, v, x, y, z, p)))
            row["gonio/pdf"] = gps(dev.time_ms(lambda: ds.pdf_soa(x, y, z, p)))
            row["gonio/invert"] = gps(dev.time_ms(lambda: ds.invert_soa(x, y, z, ou, ov)))
            try:
                vv = dev.view_value(ds)
                K = dev.kfun
                row["byvalue/sample"] = gps(dev.time_ms(lambda: K["soa_sample"](g, b, (vv, u64(u), u64(v), u64(x), u64(y), u64(z), u64(p), np.int64(n)))))
                row["byvalue/pdf"] = gps(dev.time_ms(lambda: K["soa_pdf"](g, b, (vv, u64(x), u64(y), u64(z), u64(p), np.int64(n)))))
                row["byvalue/invert"] = gps(dev.time_ms(lambda: K["soa_invert"](g, b, (vv, u64(x), u64(y), u64(z), u64(ou), u64(ov), np.int64(n)))))
            except Exception as e:  # noqa: BLE001
                say(f"   {name}: by-value kernels: {type(e).__name__}: {e}")
            if dev.fmod is not None:
                try:
                    F = dev.ffun
                    row["fast/sample"] = gps(dev.time_ms(lambda: F["soa_sample"](g, b, (vv, u64(u), u64(v), u64(x), u64(y), u64(z), u64(p), np.int64(n)))))
                    row["fast/pdf"] = gps(dev.time_ms(lambda: F["soa_pdf"](g, b, (vv, u64(x), u64(y), u64(z), u64(p), np.int64(n)))))
                    row["fast/invert"] = gps(dev.time_ms(lambda: F["soa_invert"](g, b, (vv, u64(x), u64(y), u64(z), u64(ou), u64(ov), np.int64(n)))))
                    # Accuracy: exact and fast samples of the same points, and the fast pdf and
                    # inverse at the exact directions.
                    K = dev.kfun
                    A = cp.asnumpy
                    K["soa_sample"](g, b, (vv, u64(u), u64(v), u64(x), u64(y), u64(z), u64(p), np.int64(n)))
                    ex = [a.copy() for a in (x, y, z, p)]
                    exh = [A(a) for a in ex]
                    F["soa_sample"](g, b, (vv, u64(u), u64(v), u64(x), u64(y), u64(z), u64(p), np.int64(n)))
                    ddir = float(np.max(np.abs(np.stack([A(x) - exh[0], A(y) - exh[1], A(z) - exh[2]]))))
                    big = exh[3] > 1e-3 * float(np.max(exh[3]))
                    rel = np.abs(A(p) - exh[3])[big] / exh[3][big]
                    F["soa_pdf"](g, b, (vv, u64(ex[0]), u64(ex[1]), u64(ex[2]), u64(p), np.int64(n)))
                    relp = np.abs(A(p) - exh[3])[big] / exh[3][big]
                    F["soa_invert"](g, b, (vv, u64(ex[0]), u64(ex[1]), u64(ex[2]), u64(ou), u64(ov), np.int64(n)))
                    hu, hv, hou, hov = A(u), A(v), A(ou), A(ov)
                    fin = np.isfinite(hou) & np.isfinite(hov) & big
                    dinv = float(np.max(np.maximum(np.abs(hou - hu), np.abs(hov - hv))[fin])) if fin.any() else float("nan")
                    row["fast/accuracy"] = dict(
                        dir=ddir, pdf_p999=float(np.percentile(rel, 99.9)), pdf_max=float(np.max(rel)),
                        pdfdir_p999=float(np.percentile(relp, 99.9)), invert=dinv)
                except Exception as e:  # noqa: BLE001
                    say(f"   {name}: fast-math kernels: {type(e).__name__}: {e}")
            del ds
        except Exception as e:  # noqa: BLE001
            say(f"   {name}: gonio timing SKIPPED: {type(e).__name__}: {e}")
        try:
            if name.startswith("grid_"):
                img = grid_image(*entry["grid"])
            else:
                img = env_weight_image(gc.env_image(2048, 1024))
            t = pbrt_tables(img)
            dt = {k: cp.asarray(t[k]) for k in ("func", "cdf", "mfunc", "mcdf")}
            P = dev.pfun
            nu, nv, mint = np.int32(t["nu"]), np.int32(t["nv"]), np.float32(t["mint"])
            row["pbrt/sample"] = gps(dev.time_ms(lambda: P["pbrt_sample"](g, b, (
                u64(dt["func"]), u64(dt["cdf"]), u64(dt["mfunc"]), u64(dt["mcdf"]), nu, nv, mint,
                u64(u), u64(v), u64(x), u64(y), u64(z), u64(p), np.int64(n)))))
            row["pbrt/pdf"] = gps(dev.time_ms(lambda: P["pbrt_pdf"](g, b, (
                u64(dt["func"]), nu, nv, mint, u64(x), u64(y), u64(z), u64(p), np.int64(n)))))
            row["pbrt/invert"] = gps(dev.time_ms(lambda: P["pbrt_invert"](g, b, (
                u64(dt["cdf"]), u64(dt["mcdf"]), nu, nv, u64(x), u64(y), u64(z), u64(ou), u64(ov), np.int64(n)))))
        except Exception as e:  # noqa: BLE001
            say(f"   {name}: pbrt-style timing SKIPPED: {type(e).__name__}: {e}")


def run_mitsuba(log2n, reps, variant, timeout):
    out = pathlib.Path(os.environ.get("TMPDIR", "/tmp")) / f"gonio-mitsuba-{os.getpid()}.json"
    cmd = [sys.executable, str(pathlib.Path(__file__).resolve()), "--mitsuba-only", str(out),
           "--variant", variant, "--n-time", str(log2n), "--reps", str(reps)]
    try:
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        say(f"   Mitsuba: timed out after {timeout} s")
        return None
    if not out.exists():
        tail = (r.stdout + r.stderr).strip().splitlines()[-8:]
        say(f"   Mitsuba: the subprocess failed (rc {r.returncode}): " + " | ".join(tail))
        return None
    res = json.loads(out.read_text())
    out.unlink()
    for e in res.get("errors", []):
        say(f"   Mitsuba: {e}")
    return res


def table(n, mitsuba):
    T = RESULTS["timing"]
    say("")
    say(f"== Throughput, G points/s (2^{int(math.log2(n))} points, best of the CUDA-event times; "
        f"Mitsuba: Dr.Jit kernel-history time, wall time in brackets)")
    bw = T.get("memcpy")
    triv = T.get("trivial")
    floor = bw["floor_gpts"] if bw else None
    if bw:
        say(f"   cudaMemcpy device-to-device: {bw['gbps']:.0f} GB/s (read + write) -> bandwidth floor "
            f"{bw['floor_gpts']:.2f} G points/s at 24 bytes/point")
    if triv:
        say(f"   trivial kernel (reads u, v; writes x, y, z, pdf): {triv['gpts']:.2f} G points/s")
    ms_ops = (mitsuba or {}).get("ops", {})
    hdr = (f"   {'grid':<18} {'op':<7} {'gonio':>8} {'by value':>8} {'pbrt-v4':>8} {'Mitsuba':>16}   target")
    say(hdr)
    verdicts = []
    for entry in [e for e in RESULTS.get("_timing_entries", [])]:
        name = entry["name"]
        row = T.get(name, {})
        for op in ("sample", "pdf", "invert"):
            gv = row.get(f"gonio/{op}")
            bv = row.get(f"byvalue/{op}")
            pv = row.get(f"pbrt/{op}")
            m = ms_ops.get(f"{name}/{op}")
            mk = mw = None
            if m:
                if m.get("kernel_ms"):
                    mk = n / (m["kernel_ms"] * 1e-3) / 1e9
                if m.get("wall_ms"):
                    mw = n / (m["wall_ms"] * 1e-3) / 1e9
            best = max([a for a in (gv, bv) if a is not None], default=None)
            tgt = []
            mref = mk if mk is not None else mw
            if mref is not None and best is not None:
                need = {"sample": 1.0, "pdf": 1.0, "invert": 0.5}[op]
                okm = best >= need * mref
                tgt.append(f"{'>=' if need == 1 else '>= 0.5 x'} Mitsuba's {'eval' if op == 'pdf' else op}: "
                           f"{'PASS' if okm else 'FAIL'} ({best / mref:.2f}x)")
                verdicts.append(okm)
            elif best is not None:
                tgt.append("Mitsuba: n/a")
            if op == "sample" and name == "grid_19x36" and floor and best is not None:
                okf = best >= 0.5 * floor
                tgt.append(f">= 50 % of the bandwidth floor: {'PASS' if okf else 'FAIL'} ({100 * best / floor:.0f} %)")
                verdicts.append(okf)
            f = lambda a: f"{a:8.2f}" if a is not None else f"{'n/a':>8}"  # noqa: E731
            mstr = (f"{mk:6.2f}" if mk is not None else "   n/a") + (f" [{mw:6.2f}]" if mw is not None else " [  n/a ]")
            label = name.replace("grid_", "").replace("envmap_", "env ")
            say(f"   {label:<18} {op:<7} {f(gv)} {f(bv)} {f(pv)} {mstr:>16}   {'; '.join(tgt)}")
    fast_rows = [(e["name"], T.get(e["name"], {})) for e in RESULTS.get("_timing_entries", [])]
    if any("fast/sample" in r for _, r in fast_rows):
        say("")
        say("   gonio_device.h with GONIO_DEVICE_FAST_MATH (--use_fast_math; not bit-exact), G points/s, and its")
        say("   accuracy against the bit-exact kernels on the same 2^n points (pdf: where > 1e-3 of the peak):")
        say(f"   {'grid':<18} {'sample':>8} {'pdf':>8} {'invert':>8}   {'max|ddir|':>9} {'pdf p99.9':>9} {'pdf max':>9} {'pdf(d) p99.9':>12} {'max|du|':>9}")
        for name, r in fast_rows:
            acc = r.get("fast/accuracy", {})
            f = lambda a: f"{a:8.2f}" if a is not None else f"{'n/a':>8}"  # noqa: E731
            g_ = lambda k, w: f"{acc[k]:{w}.2e}" if k in acc else f"{'n/a':>{w}}"  # noqa: E731
            label = name.replace("grid_", "").replace("envmap_", "env ")
            say(f"   {label:<18} {f(r.get('fast/sample'))} {f(r.get('fast/pdf'))} {f(r.get('fast/invert'))}   "
                f"{g_('dir', 9)} {g_('pdf_p999', 9)} {g_('pdf_max', 9)} {g_('pdfdir_p999', 12)} {g_('invert', 9)}")
    if mitsuba and mitsuba.get("versions"):
        say(f"   Mitsuba: {mitsuba['versions']}, variant {mitsuba['variant']}; MarginalContinuous2D0 on the grid's "
            f"values x sin(theta) (no lift to the sphere); env: envmap emitter sample_direction / pdf_direction")
    say("   gonio: gonio.cuda (view by pointer); by value: kernels.cu (__grid_constant__ view); pbrt-v4: "
        "piecewise-constant 2D with a lat-long lift, this script's CUDA")
    return verdicts


def flush_out():
    """Writes what is known so far to $OUT (again after every stage: a later stage that hangs or
    is killed by the outer timeout leaves the earlier results)."""
    out = os.environ.get("OUT")
    if not out:
        return
    try:
        pathlib.Path(out).mkdir(parents=True, exist_ok=True)
        (pathlib.Path(out) / "gpu-check.txt").write_text("\n".join(LOG) + "\n")
        res = {k: v for k, v in RESULTS.items() if not k.startswith("_")}
        (pathlib.Path(out) / "gpu-check.json").write_text(json.dumps(res, indent=1, default=str))
    except Exception as e:  # noqa: BLE001
        print(f"could not write $OUT: {e}")


def pytest_cuda(timeout):
    """crates/gonio-py/tests/test_cuda.py in a subprocess (when pytest and gonio import)."""
    say("")
    say("== pytest crates/gonio-py/tests/test_cuda.py")
    if importlib.util.find_spec("pytest") is None or importlib.util.find_spec("gonio") is None:
        say("   SKIPPED: pytest or gonio not importable here")
        return
    try:
        r = subprocess.run([sys.executable, "-m", "pytest", "-q", "-rs", "-p", "no:cacheprovider",
                            str(REPO / "crates" / "gonio-py" / "tests" / "test_cuda.py")],
                           capture_output=True, text=True, timeout=timeout, cwd=str(REPO))
        lines = (r.stdout + r.stderr).strip().splitlines()
        for line in lines[-6:]:
            say("   " + line)
        RESULTS["pytest"] = dict(rc=r.returncode, tail=lines[-6:])
    except subprocess.TimeoutExpired:
        say(f"   timed out after {timeout:.0f} s")


def env_info(cp):
    say("== Machine")
    say(f"   {platform.platform()}, Python {platform.python_version()}, numpy {np.__version__}")
    if cp is None:
        return
    try:
        props = cp.cuda.runtime.getDeviceProperties(0)
        name = props["name"].decode() if isinstance(props["name"], bytes) else props["name"]
        rt = cp.cuda.runtime.runtimeGetVersion()
        drv = cp.cuda.runtime.driverGetVersion()
        nvrtc = cp.cuda.nvrtc.getVersion()
        say(f"   GPU {name}, sm_{props['major']}{props['minor']}, {props['totalGlobalMem'] / 2**30:.0f} GiB; "
            f"CUDA driver {drv}, runtime {rt}, NVRTC {nvrtc}; CuPy {cp.__version__}")
        RESULTS["env"] = dict(gpu=name, cc=f"{props['major']}{props['minor']}", driver=drv, runtime=rt,
                              nvrtc=list(nvrtc), cupy=cp.__version__)
    except Exception as e:  # noqa: BLE001
        say(f"   device properties: {type(e).__name__}: {e}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="2^20 timing points, 3 repetitions")
    ap.add_argument("--n-time", type=int, default=24, help="log2 of the timing points")
    ap.add_argument("--n-contract", type=int, default=20, help="log2 of the contract points (with gonio)")
    ap.add_argument("--reps", type=int, default=7)
    ap.add_argument("--no-gpu", action="store_true", help="skip every CuPy part (to test the rest)")
    ap.add_argument("--no-mitsuba", action="store_true")
    ap.add_argument("--no-gonio", action="store_true", help="act as if the gonio wheel were absent")
    ap.add_argument("--no-pytest", action="store_true", help="skip crates/gonio-py/tests/test_cuda.py")
    ap.add_argument("--budget", type=float, default=280.0, help="seconds for the whole run")
    ap.add_argument("--variant", default="cuda_ad_rgb")
    ap.add_argument("--mitsuba-only", metavar="JSON")
    a = ap.parse_args()
    if a.quick:
        a.n_time, a.reps = min(a.n_time, 20), 3
    if a.mitsuba_only:
        return mitsuba_only(a.mitsuba_only, a.variant, a.n_time, a.reps)
    t_start = time.perf_counter()
    cp = None
    if not a.no_gpu:
        try:
            import cupy as cp

            cp.cuda.runtime.getDeviceCount()
        except Exception as e:  # noqa: BLE001
            say(f"!! CuPy / GPU unavailable: {type(e).__name__}: {e}")
            cp = None
    env_info(cp)
    gonio, gmsg = import_gonio() if not a.no_gonio else (None, "gonio not used (--no-gonio)")
    say(f"   {gmsg}")
    spec = importlib.util.find_spec("mitsuba")  # imported only in the Mitsuba subprocess
    say(f"   mitsuba: {pathlib.Path(spec.origin).parent if spec and spec.origin else 'not found'}")
    manifest = json.loads((DATA / "manifest.json").read_text())
    RESULTS["_timing_entries"] = manifest["timing"]
    ok = True
    dev = None
    if cp is not None:
        say("== Compiling (NVRTC through CuPy, default options: FMA contraction on)")
        dev = guard("compile")(lambda: Device(cp, a.reps))()
    if dev is not None:
        try:
            t0 = time.perf_counter()
            ds = dev.sampler((DATA / manifest["contract"][0]["blob"]).read_bytes(), validate=False)
            say(f"   gonio.cuda module compiled (NVRTC) and a DeviceSampler made in {time.perf_counter() - t0:.1f} s")
            del ds
        except Exception as e:  # noqa: BLE001
            say(f"!! gonio.cuda: {type(e).__name__}: {e}")
        r = contract(dev, manifest, gonio, 1 << a.n_contract)
        ok &= bool(r)
        flush_out()
        r = light(dev, manifest, a.n_time)
        ok &= bool(r)
        flush_out()
        timing(dev, manifest, gonio, a.n_time)
        try:
            cp.get_default_memory_pool().free_all_blocks()
        except Exception:  # noqa: BLE001
            pass
    else:
        ok = False
        if gonio is not None:
            say("== (no GPU) building the blobs the device parts would use, to check them")
            for entry in manifest["contract"] + manifest["timing"]:
                try:
                    blob, origin, same = case_blob(entry, gonio)
                    say(f"   {entry['name']}: {origin}, {len(blob)} bytes, checksum "
                        f"{'as recorded' if same else 'DIFFERS from gpu-prepare'}")
                except Exception as e:  # noqa: BLE001
                    say(f"   {entry['name']}: {type(e).__name__}: {e}")
    flush_out()
    left = lambda: a.budget - (time.perf_counter() - t_start)  # noqa: E731
    mitsuba = None
    if not a.no_mitsuba:
        say("")
        say(f"== Mitsuba ({a.variant}) in a subprocess")
        mitsuba = run_mitsuba(a.n_time, a.reps, a.variant, timeout=max(10.0, min(150.0, left() - 25)))
    RESULTS["mitsuba"] = mitsuba
    verdicts = table(1 << a.n_time, mitsuba)

    def summary():
        n_c = sum(1 for c in RESULTS["contract"].values() if c.get("ok"))
        say("")
        say(f"== Summary: contract {n_c}/{len(RESULTS['contract'])} cases PASS; light tracing "
            f"{'PASS' if (RESULTS['light'] or {}).get('ok') else 'FAIL/not run'}; speed targets "
            f"{sum(verdicts)}/{len(verdicts)} met; {len(RESULTS['errors'])} part(s) failed; "
            f"{time.perf_counter() - t_start:.0f} s")
        flush_out()

    summary()
    if cp is not None and not a.no_pytest:
        if left() > 45:
            pytest_cuda(timeout=left() - 10)
        else:
            say(f"== pytest test_cuda.py SKIPPED: {left():.0f} s of the budget left")
        flush_out()
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
