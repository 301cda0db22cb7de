"""gonio's float32 HDS map on a CUDA device, on CuPy or PyTorch arrays (docs/GPU.md).

``DeviceSampler(tables)`` copies a float32 table blob (docs/TABLES.md: ``Sampler.tables()``,
``EnvMap.tables()``, ``gonio tables FILE -o OUT.bin``) once into device memory and runs the
header-only sampler ``gonio_device.h`` on it, in kernels that NVRTC compiles (through CuPy's
``RawModule``, cached on disk by CuPy) the first time a ``DeviceSampler`` is used:

* ``sample(u)``: points (n, 2) of [0, 1]² → (directions (n, 3), pdf (n,) per steradian);
* ``pdf(directions)``: the density (n,) at unit directions (n, 3) (not renormalised);
* ``invert(directions)``: the points (n, 2) of the square, NaN where there is none (density 0,
  below a hemisphere map's horizon, a non-finite direction);
* ``target(directions)``: a grid target's value (candela for a photometric file), 0 without one;
* ``sample_soa`` / ``pdf_soa`` / ``invert_soa``: the same on separate 1-D arrays (u, v),
  (x, y, z), written into arrays the caller provides (no allocation).

Inputs are float32 device arrays: CuPy arrays, or anything with ``__cuda_array_interface__``
(PyTorch CUDA tensors, Numba device arrays); numpy arrays are copied to the device. Results are
CuPy arrays, or PyTorch tensors sharing their memory when the input was a PyTorch tensor. Kernels
run on CuPy's current stream (``cupy.cuda.Stream``); with PyTorch inputs on another stream,
synchronise first. The header performs the library's float32 map (``Sampler.sample`` etc. on
float32 arrays, what ``Sampler.from_tables(tables)`` computes on the host) operation for
operation, so the results are meant to agree bit for bit, except that the library's ``pdf`` and
``invert`` normalise a direction in float64 first and these do not: pass unit directions
(``scripts/gpu-check.sh`` measures the agreement).

The header is read from ``$GONIO_DEVICE_HEADER`` (a path to ``gonio_device.h``), else from the
package (``gonio/include/gonio_device.h``, where a wheel that ships it has it), else from the
source tree (``crates/gonio-capi/include/gonio_device.h`` beside this file's crate). Its text is
compiled into the module's source, so CuPy's kernel cache follows the header's content.

The blob is validated on the host by the library's reader (``Sampler.from_tables``: every check
of docs/TABLES.md) before any kernel reads it; the view (``GonioDeviceView``) is then built on
the device by a one-thread kernel (``gonio_k_view``, the same fields ``gonio_device_view_init``
fills) and kernels receive a pointer to it.

Requires CuPy (``pip install cupy-cuda12x`` or ``cupy-cuda13x``) and an NVIDIA GPU; importing
this module does not import CuPy (``KERNEL_SOURCE`` and ``header_source()`` work without it).
"""

import os
import pathlib

__all__ = ["DeviceSampler", "KERNEL_SOURCE", "header_path", "header_source", "module_source"]

# The kernels, appended to the header's text. Every array is addressed with an element stride, so
# that one kernel serves (n, 2)/(n, 3) arrays (strides 2/3) and separate 1-D arrays (stride 1).
# Pointers and counts are 64-bit parameters (passed from Python as numpy.uint64 / numpy.int64).
KERNEL_SOURCE = r"""
/* The view of a blob that gonio's reader has validated (docs/TABLES.md), built on the device:
 * the fields gonio_device_view_init fills, then gonio_device_view_rebase. No checks. */
GONIO_DEVICE_FN gonio_u32 gonio_cu_rd32(const gonio_u8 *p, gonio_u64 at) {
  p += at;
  return (gonio_u32)p[0] | ((gonio_u32)p[1] << 8) | ((gonio_u32)p[2] << 16) |
         ((gonio_u32)p[3] << 24);
}
GONIO_DEVICE_FN gonio_u64 gonio_cu_rd64(const gonio_u8 *p, gonio_u64 at) {
  return (gonio_u64)gonio_cu_rd32(p, at) | ((gonio_u64)gonio_cu_rd32(p, at + 4) << 32);
}
GONIO_DEVICE_FN double gonio_cu_rdf64(const gonio_u8 *p, gonio_u64 at) {
  gonio_u64 b = gonio_cu_rd64(p, at);
  double d;
  unsigned char *dst = (unsigned char *)&d;
  int i;
  for (i = 0; i < 8; i++) dst[i] = (unsigned char)(b >> (8 * i));
  return d;
}
GONIO_DEVICE_FN void gonio_cu_view_from_blob(const gonio_u8 *p, GonioDeviceView *v) {
  gonio_u32 present, target, e = 0, s, t;
  unsigned char *raw = (unsigned char *)v;
  gonio_u64 i;
  for (i = 0; i < sizeof(GonioDeviceView); i++) raw[i] = 0;
  present = gonio_cu_rd32(p, 56);
  target = gonio_cu_rd32(p, 44);
  for (s = 0; s < 2; s++) {
    GonioDeviceMap *c = &v->map[s];
    gonio_u64 at = 96u + 80u * s;
    if (!(present & (1u << s))) continue;
    c->m = (gonio_i32)gonio_cu_rd32(p, at);
    c->n = (gonio_i32)gonio_cu_rd32(p, at + 4);
    c->k = (gonio_i32)gonio_cu_rd32(p, at + 8);
    c->wedge_guide_len = (gonio_i32)gonio_cu_rd32(p, at + 12);
    c->radius_guide_len = (gonio_i32)gonio_cu_rd32(p, at + 16);
    c->inv_uniform_beta = (float)gonio_cu_rdf64(p, at + 32);
    c->kappa = (float)gonio_cu_rdf64(p, at + 40);
    c->guide_scale = (float)gonio_cu_rdf64(p, at + 48);
    c->radius_scale = (float)gonio_cu_rdf64(p, at + 56);
    c->edge = (float)gonio_cu_rdf64(p, at + 64);
    for (t = 0; t < 12; t++) {
      gonio_u64 d = 256u + 32u * (e + t);
      c->offset[t] = gonio_cu_rd64(p, d + 8);
      c->len[t] = (gonio_i32)gonio_cu_rd64(p, d + 16);
    }
    e += 12;
  }
  if (target == 1u) {
    for (t = 0; t < 3; t++) v->target_offset[t] = gonio_cu_rd64(p, 256u + 32u * (e + t) + 8);
  } else if (target == 2u) {
    v->target_offset[0] = gonio_cu_rd64(p, 256u + 32u * e + 8);
  }
  v->total_bytes = gonio_cu_rd64(p, 16);
  v->layout = gonio_cu_rd32(p, 36);
  v->frame = gonio_cu_rd32(p, 40);
  v->target = target;
  v->maps_present = present;
  v->lookup = gonio_cu_rd32(p, 60);
  v->p_lower = (float)gonio_cu_rdf64(p, 64);
  v->inv_2t = (float)gonio_cu_rdf64(p, 72);
  v->target_integral = gonio_cu_rdf64(p, 80);
  v->target_a = gonio_cu_rd32(p, 88);
  v->target_b = gonio_cu_rd32(p, 92);
  gonio_device_view_rebase(v, p);
}

#if defined(__CUDACC__) || defined(__CUDACC_RTC__)
#define GONIO_CU_INDEX \
  long long i = (long long)blockIdx.x * (long long)blockDim.x + (long long)threadIdx.x; \
  if (i >= n) return;

extern "C" __global__ void gonio_k_view(const gonio_u8 *blob, GonioDeviceView *out) {
  if (blockIdx.x == 0 && threadIdx.x == 0) gonio_cu_view_from_blob(blob, out);
}

extern "C" __global__ void gonio_k_view_size(unsigned long long *out) {
  if (blockIdx.x == 0 && threadIdx.x == 0) *out = sizeof(GonioDeviceView);
}

extern "C" __global__ void gonio_k_sample(const GonioDeviceView *__restrict__ v,
                                          const float *__restrict__ u, const float *__restrict__ w,
                                          long long su, float *__restrict__ x,
                                          float *__restrict__ y, float *__restrict__ z,
                                          long long sd, float *__restrict__ pdf, long long n) {
  GONIO_CU_INDEX
  float d[3], p;
  gonio_device_sample(v, u[i * su], w[i * su], d, &p);
  x[i * sd] = d[0];
  y[i * sd] = d[1];
  z[i * sd] = d[2];
  pdf[i] = p;
}

/* A kernel NAME writing FN(view, direction) of each direction (x, y, z with stride sd) to out. */
#define GONIO_CU_OF_DIRECTION(NAME, FN)                                                          \
  extern "C" __global__ void NAME(const GonioDeviceView *__restrict__ v,                        \
                                  const float *__restrict__ x, const float *__restrict__ y,      \
                                  const float *__restrict__ z, long long sd,                     \
                                  float *__restrict__ out, long long n) {                        \
    GONIO_CU_INDEX                                                                               \
    float d[3] = {x[i * sd], y[i * sd], z[i * sd]};                                              \
    out[i] = FN(v, d);                                                                           \
  }

GONIO_CU_OF_DIRECTION(gonio_k_pdf, gonio_device_pdf)
GONIO_CU_OF_DIRECTION(gonio_k_target, gonio_device_target)

extern "C" __global__ void gonio_k_invert(const GonioDeviceView *__restrict__ v,
                                          const float *__restrict__ x, const float *__restrict__ y,
                                          const float *__restrict__ z, long long sd,
                                          float *__restrict__ u, float *__restrict__ w,
                                          long long su, long long n) {
  GONIO_CU_INDEX
  float d[3] = {x[i * sd], y[i * sd], z[i * sd]}, uv[2];
  gonio_device_invert(v, d, uv);
  u[i * su] = uv[0];
  w[i * su] = uv[1];
}

#endif
"""

KERNEL_NAMES = ("gonio_k_view", "gonio_k_view_size", "gonio_k_sample", "gonio_k_pdf",
                "gonio_k_invert", "gonio_k_target")
# sizeof(GonioDeviceView) on 64-bit targets with the header of this writing; the device's own
# sizeof is what a DeviceSampler allocates (gonio_k_view_size).
VIEW_BYTES = 680
_BLOCK = 256


def header_path():
    """The path of ``gonio_device.h`` this module compiles (see the module's docstring)."""
    env = os.environ.get("GONIO_DEVICE_HEADER")
    here = pathlib.Path(__file__).resolve().parent
    candidates = [pathlib.Path(env)] if env else []
    candidates += [
        here / "include" / "gonio_device.h",
        here.parents[2] / "gonio-capi" / "include" / "gonio_device.h",
    ]
    for c in candidates:
        if c.is_file():
            return c
    raise FileNotFoundError(
        "gonio_device.h not found: set GONIO_DEVICE_HEADER to its path (tried "
        + ", ".join(str(c) for c in candidates)
        + ")"
    )


def header_source():
    """The text of ``gonio_device.h``."""
    return header_path().read_text(encoding="utf-8")


def module_source(header_text=None):
    """The CUDA source NVRTC compiles: the header's text followed by ``KERNEL_SOURCE``."""
    if header_text is None:
        header_text = header_source()
    return header_text + "\n" + KERNEL_SOURCE


_MODULES = {}


def _module(cp):
    """(RawModule, sizeof(GonioDeviceView)): compiled once per header text and device (CuPy also
    caches the binary on disk)."""
    import numpy as np

    src = module_source()
    key = (hash(src), cp.cuda.Device().id)
    entry = _MODULES.get(key)
    if entry is None:
        mod = cp.RawModule(code=src)  # NVRTC defaults (C++17 on CUDA 12 and 13)
        out = cp.zeros(1, dtype=cp.uint64)
        mod.get_function("gonio_k_view_size")((1,), (1,), (np.uint64(out.data.ptr),))
        entry = (mod, int(cp.asnumpy(out)[0]))
        _MODULES[key] = entry
    return entry


def _import_cupy():
    try:
        import cupy as cp
    except ImportError as e:  # pragma: no cover - depends on the machine
        raise ImportError("gonio.cuda needs CuPy (pip install cupy-cuda12x or cupy-cuda13x)") from e
    return cp


def _is_torch(a):
    return type(a).__module__.split(".")[0] == "torch"


def _as_device(cp, a, cols, what):
    """A float32 CuPy array of shape (n, cols) (zero-copy for device float32 input)."""
    arr = cp.asarray(a)
    if arr.dtype != cp.float32:
        raise TypeError(f"{what}: float32 arrays only (got {arr.dtype})")
    if arr.ndim != 2 or arr.shape[1] != cols:
        raise ValueError(f"{what}: shape (n, {cols}) expected, got {arr.shape}")
    if arr.strides[1] != 4 or arr.strides[0] != 4 * cols:
        arr = cp.ascontiguousarray(arr)
    return arr


def _back(like, arr):
    if _is_torch(like):
        import torch

        return torch.as_tensor(arr, device=like.device)
    return arr


class DeviceSampler:
    """A float32 table blob in device memory, sampled by ``gonio_device.h`` (module docstring).

    ``DeviceSampler(tables, validate=True)``: ``tables`` is the blob (bytes-like, float32).
    ``validate=False`` skips the library's host-side reader (``gonio.Sampler.from_tables``)
    and checks only the magic, version and precision: for blobs the library has just written.
    """

    def __init__(self, tables, validate=True):
        import numpy as np

        data = bytes(tables)
        if len(data) < 256 or data[:8] != b"GONIOTAB":
            raise ValueError("not a gonio table blob (docs/TABLES.md)")
        if int.from_bytes(data[8:12], "little") != 1:
            raise ValueError("table blob: layout version 1 expected")
        if int.from_bytes(data[32:36], "little") != 4:
            raise ValueError("table blob: only float32 blobs (precision 4) run on the device")
        if validate:
            try:
                from . import Sampler
            except ImportError:  # this file loaded outside the package (scripts/gpu_check.py)
                from gonio import Sampler

            Sampler.from_tables(data)  # raises InputError naming the field at fault
        cp = _import_cupy()
        self.nbytes = len(data)
        self.layout = int.from_bytes(data[36:40], "little")
        self.frame = int.from_bytes(data[40:44], "little")
        self.target_kind = int.from_bytes(data[44:48], "little")
        self._cp = cp
        self._mod, self.view_bytes = _module(cp)
        self._k = {name: self._mod.get_function(name) for name in KERNEL_NAMES}
        host = np.frombuffer(data, dtype=np.uint8)
        # cudaMalloc's alignment (256 bytes) is more than the blob needs (64).
        self.blob = cp.asarray(host)
        self.view = cp.zeros(self.view_bytes, dtype=cp.uint8)
        self._k["gonio_k_view"]((1,), (1,), (np.uint64(self.blob.data.ptr), np.uint64(self.view.data.ptr)))
        cp.cuda.get_current_stream().synchronize()

    # --- low level: 1-D arrays, caller-provided outputs -----------------------------------------

    def _launch(self, name, n, args):
        import numpy as np

        if n == 0:
            return
        grid = ((n + _BLOCK - 1) // _BLOCK,)
        self._k[name](grid, (_BLOCK,), (np.uint64(self.view.data.ptr),) + args + (np.int64(n),))

    @staticmethod
    def _ptr(a, offset=0):
        import numpy as np

        return np.uint64(a.data.ptr + 4 * offset)

    def sample_soa(self, u, v, x, y, z, pdf):
        """Writes the samples of the points (u[i], v[i]) into x, y, z, pdf (1-D float32 CuPy
        arrays of one length, contiguous)."""
        import numpy as np

        n = u.size
        for a in (u, v, x, y, z, pdf):
            _check_1d(self._cp, a, n)
        p = self._ptr
        self._launch("gonio_k_sample", n, (p(u), p(v), np.int64(1), p(x), p(y), p(z), np.int64(1), p(pdf)))

    def pdf_soa(self, x, y, z, pdf):
        """Writes the densities at the directions (x[i], y[i], z[i]) into pdf."""
        import numpy as np

        n = x.size
        for a in (x, y, z, pdf):
            _check_1d(self._cp, a, n)
        p = self._ptr
        self._launch("gonio_k_pdf", n, (p(x), p(y), p(z), np.int64(1), p(pdf)))

    def invert_soa(self, x, y, z, u, v):
        """Writes the points of the square of the directions (x[i], y[i], z[i]) into u, v (NaN
        where there is none)."""
        import numpy as np

        n = x.size
        for a in (x, y, z, u, v):
            _check_1d(self._cp, a, n)
        p = self._ptr
        self._launch("gonio_k_invert", n, (p(x), p(y), p(z), np.int64(1), p(u), p(v), np.int64(1)))

    # --- arrays of points and directions ---------------------------------------------------------

    def sample(self, u):
        """Points ``u`` (n, 2) float32 → (directions (n, 3), pdf (n,)), float32 on the device."""
        import numpy as np

        cp = self._cp
        a = _as_device(cp, u, 2, "sample")
        n = a.shape[0]
        d = cp.empty((n, 3), dtype=cp.float32)
        pdf = cp.empty((n,), dtype=cp.float32)
        p = self._ptr
        self._launch(
            "gonio_k_sample",
            n,
            (p(a), p(a, 1), np.int64(2), p(d), p(d, 1), p(d, 2), np.int64(3), p(pdf)),
        )
        return _back(u, d), _back(u, pdf)

    def _of_direction(self, name, directions):
        """Kernel ``gonio_k_<name>``: one float32 (n,) of the unit ``directions`` (n, 3)."""
        import numpy as np

        cp = self._cp
        a = _as_device(cp, directions, 3, name)
        n = a.shape[0]
        out = cp.empty((n,), dtype=cp.float32)
        p = self._ptr
        self._launch(f"gonio_k_{name}", n, (p(a), p(a, 1), p(a, 2), np.int64(3), p(out)))
        return _back(directions, out)

    def pdf(self, directions):
        """The density (n,) per steradian at unit ``directions`` (n, 3) float32."""
        return self._of_direction("pdf", directions)

    def invert(self, directions):
        """The points (n, 2) of the square of unit ``directions`` (n, 3); NaN rows where none."""
        import numpy as np

        cp = self._cp
        a = _as_device(cp, directions, 3, "invert")
        n = a.shape[0]
        out = cp.empty((n, 2), dtype=cp.float32)
        p = self._ptr
        self._launch(
            "gonio_k_invert", n, (p(a), p(a, 1), p(a, 2), np.int64(3), p(out), p(out, 1), np.int64(2))
        )
        return _back(directions, out)

    def target(self, directions):
        """The grid target's value (n,) at ``directions`` (n, 3) (candela for a photometric
        blob); 0 without a grid target."""
        return self._of_direction("target", directions)


def _check_1d(cp, a, n):
    if not isinstance(a, cp.ndarray) or a.dtype != cp.float32 or a.ndim != 1 or a.size != n:
        raise ValueError("1-D float32 CuPy arrays of one length expected")
    if a.size > 1 and a.strides[0] != 4:
        raise ValueError("contiguous arrays expected")
