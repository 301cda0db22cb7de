"""gonio's HDS map in Dr.Jit operations, over a table blob (docs/TABLES.md).

``Tables(blob)`` reads a float32 table blob (``Sampler.tables(precision="float32")``,
``EnvMap.tables(...)`` or ``gonio tables FILE -o OUT.bin``) once, with numpy, into Dr.Jit arrays
of the current Mitsuba variant (``mi.Float``, ``mi.UInt32``: set the variant first). Its methods
then run the map on Dr.Jit arrays, written only in Dr.Jit operations (``dr.gather``,
``dr.select``, ``dr.while_loop``, arithmetic): no numpy, no ``dr.eval``, no Python branch on an
array's value, so that they trace into Mitsuba's symbolic calls and loops (megakernels), and one
source serves ``scalar_rgb``, ``llvm_ad_rgb`` and ``cuda_ad_rgb`` (in scalar variants, whose Float
is a Python float, the port runs on width-1 arrays of Dr.Jit's scalar backend, so that it computes
in float32 there too; inputs and outputs are the variant's types):

* ``sample(u: Point2f) -> (Vector3f, Float)``: the map M_E ∘ M_D ∘ M_C ∘ M_B and its exact pdf
  per steradian (the disk density times 1/(2T));
* ``pdf(d: Vector3f) -> Float``: the density at unit directions (0 where the map has none);
* ``invert(d: Vector3f) -> Point2f``: the point of the square that ``sample`` maps to d (NaN
  where there is none: below a hemisphere map's horizon, a side without a map, non-finite d);
* ``target(d) -> Float``: a grid target's (θ, φ)-bilinear interpolant (a diagram: candela for a
  photometric file), 0 outside its θ range;
* ``radiance(d) -> Color3f``: an image target's RGB radiance, nearest pixel or bilinear (the
  blob's ``lookup``).

Directions are gonio's frame (θ from +z, φ from +x toward +y); the blob's ``frame`` says what
that is for the data (a photometric file: nadir along −z; an environment map: the image's top row
at +z, its centre column along +x).

What the port is, operation for operation in float32, and where it differs from the library's
float32 map (``crates/gonio/src/mapping/simd/kernels.rs``):

* the same stages and the same operation order (no fused multiply-adds are written; Dr.Jit's
  LLVM backend does not contract them); sin/cos and atan2 are Dr.Jit's own (``dr.sincos``,
  ``dr.atan2``, within a few ulps of the library's series), which is the whole of the difference
  in the continuous results (measured in ``tests/test_drjit_emitters.py`` against the library's
  float32 map on the same points, both variants: directions within 6e-8, the sample's pdf within
  1e-4 relative but for a few in 10⁴ environment-map samples, ≤ 2.2e-4; CUDA: see ``IEEE``);
* searches: the guided searches start from the guide tables' brackets and bisect with a fixed
  number of steps, the bit length of the widest bracket of that guide (computed from the tables at
  load, ≤ ⌈log₂ N⌉ + 1), which finds the same index as the kernels' per-block count; the
  settling steps (entered only where round-off left the index outside its bracket) are bounded
  ``dr.while_loop``s (each bounded by the table's length); searches without a guide (non-uniform
  meridians, the grid target's θ and φ) bisect the whole table in ⌈log₂(len + 1)⌉ steps;
* the radial solve (Halley safeguarded by bisection) is a ``dr.while_loop`` of at most 60 trips,
  the kernels' bound, with their float32 stopping rules (STOP_STEP 2⁻²¹, STOP_CUBIC 2⁻²⁸,
  HALLEY_SMALL 2⁻⁷);
* divisions by a constant divide by an opaque one-element array: Dr.Jit turns ``x / c`` for a
  Python number c into ``x * (1/c)`` (not correctly rounded), which moved ill-conditioned samples;
* the split sphere runs both hemisphere maps as one kernel: their tables are concatenated and each
  lane reads its map's offsets and constants (no divergent calls);
* gathers are not clamped as the kernels' are: every index is in range for a blob that passed the
  writer's checks with φ_0 = 0 (the writer's maps); the one case that would read out of range, an
  azimuth below φ_0 > 0 in a uniform-meridian map, is clamped to the first sector.

The blob's checksum is not recomputed (the writer validated the tables; a reader only reads
them); magic, version, layout, precision (float32 only) and sizes are checked.
"""

import contextlib
import functools
import math
import os
import shutil
import struct
import subprocess
import tempfile

import numpy as np

__all__ = ["Tables", "BrdfTables", "BlobError", "parse", "parse_family", "blob_of", "IEEE"]

IEEE = True
"""The default of ``Tables(..., ieee=None)``: trace the map with ``dr.JitFlag.FastMath`` off (scoped to
the map's own operations), so that CUDA divides and takes square roots correctly rounded, as the
library does (with fast math, CUDA's approximate division and square root move some samples where
the radial solve cancels by up to 4e-3 and their pdf by up to 56 %, measured on an H200; with it off,
ptxas's multiply-add contraction remains: directions within 6e-5, a few pdfs in 1e4 within 3e-3).
LLVM and scalar variants are IEEE either way (the flag only lets them fold a·0 to 0). Costs nothing
measurable in renders (docs/MITSUBA.md)."""

MAGIC = b"GONIOTAB"
_ELEM = {1: "<f4", 2: "<f8", 3: "<u4"}
_MAP_TABLES = ["phi", "beta", "r2", "cum", "wedge_guide", "x", "d", "u", "total", "radius_guide", "inv_dx",
               "radial_guide"]
_GUIDES = {"wedge_guide", "radius_guide", "radial_guide"}

# The float32 constants of the radial solve (crates/gonio/src/mapping/simd/math.rs, `impl Precision for f32`).
STOP_STEP = 4.76837158203125e-7  # 2^-21
STOP_CUBIC = 3.725290298461914e-9  # 2^-28
HALLEY_SMALL = 7.8125e-3  # 2^-7
SOLVE_TRIPS = 60

PI = math.pi
TAU = 2.0 * math.pi
FRAC_PI_2 = 0.5 * math.pi
FRAC_PI_4 = 0.25 * math.pi


def _under_scope(call):
    """A public call of the tables that runs under their float flags (``Tables._scope``)."""

    @functools.wraps(call)
    def scoped(self, *args):
        with self._scope():
            return call(self, *args)

    return scoped


class BlobError(ValueError):
    """A table blob this reader does not take (not a blob, another version, float64 tables, ...)."""


def _bits(n):
    """Steps of a binary descent that reaches any offset in [0, n]: the bit length of n."""
    return int(n).bit_length()


def _head(b):
    """The checks every blob's first bytes must pass (magic, version 1, a 256-byte header, the
    stated size): the stated size and the eight u32 fields at offset 32 (precision, layout,
    frame, target, table count, reserved, maps present, lookup)."""
    if len(b) < 256 or b[:8] != MAGIC:
        raise BlobError("not a gonio table blob (magic GONIOTAB missing)")
    version, header_bytes, total = struct.unpack_from("<IIQ", b, 8)
    if version != 1 or header_bytes != 256:
        raise BlobError(f"table blob version {version} (header {header_bytes} bytes): this reader takes version 1")
    if total != len(b) or total % 64:
        raise BlobError(f"table blob of {len(b)} bytes says it has {total}")
    return total, struct.unpack_from("<8I", b, 32)


def _directory(b, count, total):
    """The blob's tables by id: numpy views of ``b`` (no copy), each entry checked (a known
    element type, 64-byte aligned, inside the ``total`` bytes)."""
    tables = {}
    for k in range(count):
        tid, elem, off, cnt = struct.unpack_from("<IIQQ", b, 256 + 32 * k)
        if elem not in _ELEM or off % 64 or off + cnt * np.dtype(_ELEM[elem]).itemsize > total:
            raise BlobError(f"table blob directory entry {k} (id {tid}) is malformed")
        tables[tid] = np.frombuffer(b, dtype=_ELEM[elem], count=cnt, offset=off)
    return tables


def parse(data):
    """The blob's header, map slots and target as Python values and numpy views (no copy)."""
    b = bytes(data)
    total, (prec, layout, frame, target, count, _res, maps, lookup) = _head(b)
    if prec != 4:
        raise BlobError(f"table blob of precision {prec} bytes: gonio.drjit reads float32 tables "
                        "(write them with precision='float32' / --precision f32)")
    if layout not in (0, 1, 2) or frame not in (0, 1, 2) or target not in (0, 1, 2):
        raise BlobError(f"table blob layout {layout}, frame {frame}, target {target}: unknown")
    p_lower, inv_2t, target_integral = struct.unpack_from("<3d", b, 64)
    target_a, target_b = struct.unpack_from("<2I", b, 88)
    tables = _directory(b, count, total)
    slots = []
    for s in range(2):
        if not (maps >> s) & 1:
            slots.append(None)
            continue
        o = 96 + 80 * s
        m, n, k_rad, g, g_r = struct.unpack_from("<5I", b, o)
        inv_ub, kappa, guide_scale, radius_scale, edge = struct.unpack_from("<5d", b, o + 32)
        slot = dict(m=m, n=n, K=k_rad, G=g, Gr=g_r, inv_ub=inv_ub, kappa=kappa, guide_scale=guide_scale,
                    radius_scale=radius_scale, edge=edge)
        want = dict(phi=m + 1, beta=m, r2=m + 1, cum=m + 1, wedge_guide=g, x=n, d=m * n, u=m * n, total=m,
                    radius_guide=g_r, inv_dx=n - 1, radial_guide=m * (k_rad + 1))
        for k, name in enumerate(_MAP_TABLES):
            t = tables.get(16 * s + k)
            if t is None or len(t) != want[name]:
                raise BlobError(f"table blob slot {s}: table {name} missing or of the wrong length")
            slot[name] = t
        slots.append(slot)
    if layout in (0, 1) and maps != 1:
        raise BlobError(f"table blob of layout {layout} with maps_present {maps}")
    if layout == 2 and maps not in (1, 2, 3):
        raise BlobError("split table blob without a map")
    out = dict(layout=layout, frame=frame, target=target, lookup=lookup, p_lower=p_lower, inv_2t=inv_2t,
               target_integral=target_integral, slots=slots)
    if target == 1:
        out["grid"] = (tables[32], tables[33], tables[34].reshape(target_b, target_a))
    elif target == 2:
        out["image"] = tables[40].reshape(target_b, target_a, 3)
    return out


def blob_of(obj, path=None, cli_args=()):
    """The float32 blob of a ``gonio.Sampler`` or ``gonio.EnvMap``: ``obj.tables(precision="float32")``,
    or, with a package that predates it, the CLI ``gonio tables path -o … cli_args`` (``$GONIO_BIN``,
    else ``gonio`` on the PATH)."""
    tables = getattr(obj, "tables", None)
    if tables is not None:
        return bytes(tables(precision="float32"))
    exe = os.environ.get("GONIO_BIN") or shutil.which("gonio")
    if path is None or exe is None:
        raise RuntimeError("this gonio package cannot write table blobs (no .tables()) and no gonio CLI was "
                           "found (set GONIO_BIN)")
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "tables.bin")
        subprocess.run([exe, "tables", str(path), "-o", out, "--quiet", *cli_args], check=True,
                       stdout=subprocess.DEVNULL)
        with open(out, "rb") as f:
            return f.read()


class _NS:
    """A namespace of per-map constants: Python numbers, or per-lane arrays in the split layout."""

    def __init__(self, **kw):
        self.__dict__.update(kw)


class Tables:
    """A table blob's map(s) and target as Dr.Jit arrays of the current Mitsuba variant; see the
    module documentation for the methods."""

    def __init__(self, data, mi=None, ieee=None):
        self._bind(mi, ieee)
        b = parse(data)
        self.layout, self.frame, self.target_kind = b["layout"], b["frame"], b["target"]
        self.lookup = "bilinear" if b["lookup"] == 1 else "nearest"
        self.target_integral = b["target_integral"]
        self.inv_2t = float(b["inv_2t"])
        self.p_lower = float(b["p_lower"])
        slots = b["slots"]
        # Split layout: slot 0 the lower map, slot 1 the upper one; the others one map in slot 0.
        self.has_lower = self.layout == 2 and slots[0] is not None
        self.has_upper = self.layout != 2 or slots[1] is not None
        present = [s for s in slots if s is not None]
        self.both = len(present) == 2

        # The tables, concatenated over the present slots (lower first), as arrays of the variant.
        offs = [dict.fromkeys(_MAP_TABLES, 0) for _ in present]
        cat = {}
        for name in _MAP_TABLES:
            parts = [s[name] for s in present]
            if len(parts) == 2:
                offs[1][name] = len(parts[0])
            cat[name] = np.concatenate(parts) if len(parts) == 2 else parts[0]
        self._t = {name: self._array(cat[name], name in _GUIDES) for name in _MAP_TABLES}

        def consts(s, off):
            m, n = s["m"], s["n"]
            rg = s["radial_guide"].astype(np.int64).reshape(m, s["K"] + 1)
            rgn = np.roll(rg, -1, axis=0)  # wedge i's next meridian's row (the last wraps to 0)
            span_rad = int(np.max(np.maximum(rg[:, 1:], rgn[:, 1:]) - np.minimum(rg[:, :-1], rgn[:, :-1])))
            wg = np.minimum(s["wedge_guide"].astype(np.int64), m - 1)
            span_w = int(np.max(np.diff(wg))) if len(wg) > 1 else 0
            span_w = max(span_w, int(m - 1 - wg[-1]))
            rgd = np.minimum(s["radius_guide"].astype(np.int64), n - 2)
            span_r = int(np.max(np.diff(rgd))) if len(rgd) > 1 else 0
            span_r = max(span_r, int(n - 2 - rgd[-1]))
            return dict(
                m=m, n=n, K=s["K"], kmax_w=s["G"] - 1, kmax_r=s["Gr"] - 1, kappa=float(s["kappa"]),
                guide_scale=float(s["guide_scale"]), radius_scale=float(s["radius_scale"]), edge=float(s["edge"]),
                inv_ub=float(s["inv_ub"]), north=max(float(s["d"][0]), 0.0), south=max(float(s["d"][n - 1]), 0.0),
                **{"o_" + k: v for k, v in off.items()},
                steps_w=_bits(span_w), steps_r=_bits(span_r), steps_rad=_bits(span_rad), steps_phi=_bits(m + 1),
            )

        self._consts = [consts(s, o) for s, o in zip(present, offs)]
        self._kappa_div = [self._const(c["kappa"]) for c in self._consts]
        self._p_div = self._const(self.p_lower)
        self._q_div = self._const(1.0 - np.float32(self.p_lower))
        self._tau_div = self._const(np.float32(TAU))
        self._pi_div = self._const(np.float32(PI))
        c0 = self._consts
        # Fixed step counts: the widest over the present maps.
        self.steps = {k: max(c[k] for c in c0) for k in ("steps_w", "steps_r", "steps_rad", "steps_phi")}
        self.any_uniform = any(c["inv_ub"] > 0 for c in c0)
        self.any_general = any(not c["inv_ub"] > 0 for c in c0)
        self.p_lower_below = float(np.nextafter(np.float32(self.p_lower), np.float32(0.0)))

        if "grid" in b:
            th, ph, vals = b["grid"]
            self.grid_shape = (len(ph), len(th))
            # f64 in the blob; float32 here (θ = π rounds to f32(π), which atan2 can return too).
            self._gth = self._array(th.astype(np.float32), False)
            self._gph = self._array(ph.astype(np.float32), False)
            self._gv = self._array(vals.astype(np.float32).ravel(), False)
            self._g_first = float(np.float32(ph[0]))
            self._g_last = float(np.float32(ph[-1]))
            self._g_width = float(np.float32(np.float32(ph[0]) + np.float32(TAU) - np.float32(ph[-1])))
            self._g_width_div = self._const(self._g_width)
        if "image" in b:
            img = b["image"]
            self.height, self.width = img.shape[:2]
            self._rgb = self._array(np.ascontiguousarray(img, dtype=np.float32).ravel(), False)
            # The poles' colours: the mean of the first and last rows (f64 means rounded to f32).
            self._poles = [tuple(float(v) for v in img[r].astype(np.float64).mean(axis=0).astype(np.float32))
                           for r in (0, self.height - 1)]

    # -- arrays and gathers ---------------------------------------------------------------------

    def _bind(self, mi, ieee):
        """The current Mitsuba variant's modules and array types (mi: the module, or None to
        import it)."""
        import drjit as dr

        if mi is None:
            import mitsuba as mi
        if mi.variant() is None:
            raise RuntimeError(f"gonio.drjit.{type(self).__name__}: set a Mitsuba variant first (mi.set_variant)")
        self.dr, self.mi = dr, mi
        self.variant = mi.variant()
        self.ieee = IEEE if ieee is None else bool(ieee)
        self.scalar = not dr.is_array_v(mi.Float)
        if self.scalar:
            # Mitsuba's scalar Float is a Python float (double): the port runs on width-1 arrays of
            # Dr.Jit's scalar backend instead, so that it computes in float32 there too.
            S = dr.scalar
            self.F, self.I, self.U = S.ArrayXf, S.ArrayXi, S.ArrayXu
        else:
            self.F, self.I, self.U = mi.Float, mi.Int32, mi.UInt32

    def _array(self, a, unsigned):
        return self.U(np.ascontiguousarray(a, dtype=np.uint32)) if unsigned else \
            self.F(np.ascontiguousarray(a, dtype=np.float32))

    def _gf(self, table, idx):
        return self.dr.gather(self.F, table, self.U(idx))

    def _gi(self, table, idx):
        return self.I(self.dr.gather(self.U, table, self.U(idx)))

    def _in(self, v):
        """A Mitsuba Float (a Python float in scalar variants) as the port's array."""
        return self.F(v) if self.scalar else v

    def _out(self, v):
        """The port's array as a Mitsuba Float."""
        return v[0] if self.scalar else v

    def _map_f(self, c, name, idx):
        return self._gf(self._t[name], idx + getattr(c, "o_" + name))

    def _map_i(self, c, name, idx):
        return self._gi(self._t[name], idx + getattr(c, "o_" + name))

    def _const(self, v):
        """A divisor constant: an opaque one-element array in JIT variants (Dr.Jit turns a division
        by a Python number into a multiplication by its rounded reciprocal, which is not the
        kernels' correctly rounded division)."""
        a = self.F(float(v))
        if not self.scalar:
            self.dr.make_opaque(a)
        return a

    def _scope(self):
        """Fast math off for the map's operations (``ieee``), the caller's flags restored after."""
        if self.ieee:
            return self.dr.scoped_set_flag(self.dr.JitFlag.FastMath, False)
        return contextlib.nullcontext()

    def _float(self, i):
        return self.F(i)

    def _not(self, m):
        return ~m if self.dr.is_array_v(m) else (not m)

    def _clamp(self, x, lo, hi):
        """``Lane::clamp``: NaN passes through."""
        dr = self.dr
        x = dr.select(x < lo, lo, x)
        return dr.select(x > hi, hi, x)

    def _to_index(self, x, kmax):
        """⌊x⌋ clamped into [0, kmax] (0 for NaN), as the kernels' `to_index`."""
        dr, F = self.dr, self.F
        top = F(kmax)
        v = dr.select(x > 0, x, F(0.0))
        v = dr.select(v < top, v, top)
        return self.I(v)

    def _ctx(self, low):
        """The per-lane constants of the map each lane runs (split layout with both maps: selected
        by `low`, the lanes of the lower map)."""
        c = self._consts
        if len(c) == 1:
            return _NS(kappa_div=self._kappa_div[0], **c[0])
        dr = self.dr
        out = {"kappa_div": self.dr.select(low, self._kappa_div[0], self._kappa_div[1])}
        for k, a in c[0].items():
            bb = c[1][k]
            if a == bb or k.startswith("steps_"):
                out[k] = a
            elif isinstance(a, int):
                out[k] = dr.select(low, self.I(a), self.I(bb))
            else:
                out[k] = dr.select(low, self.F(a), self.F(bb))
        return _NS(**out)

    # -- searches -------------------------------------------------------------------------------

    def _descend(self, lo, hi, w, probe, steps):
        """Per lane the largest j in [lo, hi] with probe(j) ≤ w (lo when none), probe
        non-decreasing, in `steps` fixed steps (enough for every bracket)."""
        dr = self.dr
        top = dr.maximum(hi, lo)
        base = lo
        for p in reversed(range(steps)):
            cand = dr.minimum(base + (1 << p), top)
            base = dr.select(probe(cand) <= w, cand, base)
        return base

    def _guided(self, c, name, guide, scale, x, last, kmax, steps):
        """`guided`: the largest i ≤ last with a_i ≤ x (0 if none), a = table `name`, from the guide
        bracket, then the settling steps (bounded while loops, rarely entered)."""
        dr = self.dr
        k = self._to_index(x * scale, kmax)
        lo = dr.minimum(self._map_i(c, guide, k), last)
        hi = dr.select(kmax > k, dr.minimum(self._map_i(c, guide, dr.minimum(k + 1, kmax)), last), last)
        hi = self.I(hi)
        found = self._descend(lo, hi, x, lambda j: self._map_f(c, name, j), steps)

        def a(j):
            return self._map_f(c, name, j)

        # Settling (the kernels' `settle_guided`): at most `last` steps each way.
        (i,) = dr.while_loop((found,), lambda i: (i > 0) & (a(i) > x), lambda i: (i - 1,),
                             labels=("i",), label="gonio_settle_down")
        (i,) = dr.while_loop((i,), lambda i: (i < last) & (a(i + 1) <= x), lambda i: (i + 1,),
                             labels=("i",), label="gonio_settle_up")
        return i

    def _count_le(self, table, off, length, x, steps):
        """How many of table[off : off + length] (non-decreasing) are ≤ x."""
        dr = self.dr
        base = self.I(0)
        for p in reversed(range(steps)):
            cand = base + (1 << p)
            probe = self._gf(table, dr.minimum(cand, length) - 1 + off)
            base = dr.select((cand <= length) & (probe <= x), cand, base)
        return base

    # -- the kernels' stages --------------------------------------------------------------------

    def _radius_azimuth(self, x, y, z):
        dr = self.dr
        r2 = dr.select(z > 0, (x * x + y * y) / (1.0 + z), 1.0 - z)
        xr = dr.sqrt(self._clamp(r2, 0.0, 2.0))
        phi = dr.atan2(y, x)
        phi = dr.select(phi < 0, phi + TAU, phi)
        phi = dr.select(phi >= TAU, 0.0, phi)
        pole = (x == 0) & (y == 0)
        return xr, dr.select(pole, 0.0, phi)

    def _sectors(self, c, p):
        dr = self.dr
        i = None
        if self.any_uniform:
            iu = self._to_index(p * c.inv_ub, c.m - 1)
            down = p < self._map_f(c, "phi", iu)
            up = self._not(down) & (c.m > iu + 1) & (p >= self._map_f(c, "phi", iu + 1))
            iu = dr.select(down, iu - 1, iu)
            iu = dr.select(up, iu + 1, iu)
            iu = dr.maximum(iu, 0)  # p < φ_0 > 0 only (never with the writer's φ_0 = 0)
            i = iu
        if self.any_general:
            k = self._count_le(self._t["phi"], c.o_phi, c.m + 1, p, self.steps["steps_phi"])
            ig = dr.minimum(dr.maximum(k - 1, 0), c.m - 1)
            i = ig if i is None else dr.select(c.inv_ub > 0, i, ig)
        i1 = i + 1
        i1 = dr.select(i1 == c.m, 0, i1)
        phi0 = self._map_f(c, "phi", i)
        beta = self._map_f(c, "beta", i)
        eps = self._clamp((p - phi0) / beta, 0.0, 1.0)
        return i, i1, eps

    def _cell(self, c, x, y, z):
        """Where the density and the inverse of a direction start: its disk radius, its wedge
        (sectors i, i + 1 and the fraction between them) and its parallel segment j."""
        xr, p = self._radius_azimuth(x, y, z)
        i, i1, e = self._sectors(c, p)
        j = self._guided(c, "x", "radius_guide", c.radius_scale, xr, c.n - 2, c.kmax_r, self.steps["steps_r"])
        return xr, i, i1, e, j

    def _density(self, c, x, y, z):
        dr = self.dr
        n = c.n
        xr, i, i1, eps, j = self._cell(c, x, y, z)
        t = self._clamp((xr - self._map_f(c, "x", j)) * self._map_f(c, "inv_dx", j), 0.0, 1.0)
        a, bb = i * n + j, i1 * n + j
        a0, a1 = self._map_f(c, "d", a), self._map_f(c, "d", a + 1)
        b0, b1 = self._map_f(c, "d", bb), self._map_f(c, "d", bb + 1)
        ra = a0 + t * (a1 - a0)
        rb = b0 + t * (b1 - b0)
        d = dr.maximum((1.0 - eps) * ra + eps * rb, 0.0)
        return dr.select(xr > c.edge, 0.0, d)

    def _invert(self, c, x, y, z):
        dr = self.dr
        n = c.n
        xr, i, i1, e, j = self._cell(c, x, y, z)
        x0, x1 = self._map_f(c, "x", j), self._map_f(c, "x", j + 1)
        idx = self._map_f(c, "inv_dx", j)
        a, bb = i * n + j, i1 * n + j
        da0, da1 = self._map_f(c, "d", a), self._map_f(c, "d", a + 1)
        db0, db1 = self._map_f(c, "d", bb), self._map_f(c, "d", bb + 1)
        ua, ub = self._map_f(c, "u", a), self._map_f(c, "u", bb)
        uan, ubn = self._map_f(c, "total", i), self._map_f(c, "total", i1)
        cum0, cum1 = self._map_f(c, "cum", i), self._map_f(c, "cum", i + 1)
        beta = self._map_f(c, "beta", i)
        r2a, r2b = self._map_f(c, "r2", i), self._map_f(c, "r2", i + 1)
        ome = 1.0 - e
        d0 = ome * da0 + e * db0
        d1 = ome * da1 + e * db1
        k = (d1 - d0) * idx
        tau = self._clamp(xr - x0, 0.0, x1 - x0)
        w = (ome * ua + e * ub) + self._partial_mass(x0, d0, k, tau)
        wn = ome * uan + e * ubn
        rbd = dr.select(wn > 0, dr.sqrt(self._clamp(w / wn, 0.0, 1.0)), 0.0)
        wedge = (beta * e) * (r2a + (0.5 * (r2b - r2a)) * e)
        phib = dr.minimum(cum0 + c.kappa * wedge, cum1)
        return self._disk_to_square(rbd, phib)

    def _disk_to_square(self, r, phi):
        dr = self.dr
        p = dr.select(phi >= 7.0 * FRAC_PI_4, phi - TAU, phi)
        s = r * (4.0 / PI)
        q0 = p < FRAC_PI_4
        q1 = p < 3.0 * FRAC_PI_4
        q2 = p < 5.0 * FRAC_PI_4
        a = dr.select(q0, r, dr.select(q1, -(p - FRAC_PI_2) * s, dr.select(q2, -r, (p - 1.5 * PI) * s)))
        b = dr.select(q0, s * p, dr.select(q1, r, dr.select(q2, (-s) * (p - PI), -r)))
        return self._clamp(0.5 * (a + 1.0), 0.0, 1.0), self._clamp(0.5 * (b + 1.0), 0.0, 1.0)

    @staticmethod
    def _partial_mass(x0, d0, k, tau):
        return tau * ((2.0 * x0) * d0 + tau * ((x0 * k + d0) + (tau * (2.0 / 3.0)) * k))

    def _solve_radius(self, x0, x1, d0, d1, m):
        """`radial::solve_radius`: Halley safeguarded by bisection, at most 60 trips per lane."""
        dr, F = self.dr, self.F
        nt = self._not
        zero = F(0.0)
        h = x1 - x0
        kk = (d1 - d0) / h
        dbar = 0.5 * (d0 + d1)
        early = nt(m > 0) | nt(h > 0) | nt(dbar > 0)
        konst = kk == 0
        active = nt(early) & nt(konst)
        iterated = active
        k = kk
        ka = (d1 - d0) / (h * (x0 + x1))
        ds = (2.0 * m) / (d0 + dr.sqrt(dr.maximum(d0 * d0 + (2.0 * ka) * m, 0.0)))
        g = ds / (x0 + dr.sqrt(x0 * x0 + ds))
        finite = dr.abs(g) < math.inf
        q = m / dbar
        t = q / (dr.sqrt(x0 * x0 + q) + x0)
        res = dr.select(early, x0, dr.select(konst, x0 + dr.minimum(t, h), zero))
        g = dr.select(finite, g, t)
        tau = self._clamp(g, zero, h)
        lo0 = dr.zeros(F, dr.width(h))
        it = dr.zeros(self.I, dr.width(h))
        nan = math.nan

        def cond(tau, lo, hi, active, it):
            return active & (it < SOLVE_TRIPS)

        def body(tau, lo, hi, active, it):
            t = tau
            f = self._partial_mass(x0, d0, k, t) - m
            exact = f == 0
            pos = f > 0
            nlo = dr.select(pos, lo, t)
            nhi = dr.select(pos, t, hi)
            xx = x0 + t
            dd = d0 + k * t
            g1 = (2.0 * xx) * dd
            g2 = 2.0 * (dd + k * xx)
            den = g1 * g1 - (0.5 * f) * g2
            ok = (g1 > 0) & (den > 0)
            # (the division runs on every lane; its result is kept where `ok`)
            nxt = dr.select(ok, t - (f * g1) / dr.select(ok, den, 1.0), nan)
            halley = (nxt > nlo) & (nxt < nhi)
            nxt = dr.select(halley, nxt, 0.5 * (nlo + nhi))
            nxt = dr.select(exact, t, nxt)
            step = dr.abs(nxt - t)
            scale = x0 + nxt
            stop = (step <= STOP_STEP * scale) | ((nhi - nlo) <= STOP_STEP * (x0 + nhi))
            cc = (0.25 * g2) * g2 + (dr.abs(4.0 * k) * g1) * (1.0 / 6.0)
            predicted = cc * ((step * step) * step) <= (STOP_CUBIC * scale) * (g1 * g1)
            stop = stop | exact | (halley & (step <= HALLEY_SMALL * scale) & predicted)
            nlo = dr.select(exact, lo, nlo)
            nhi = dr.select(exact, hi, nhi)
            return (dr.select(active, nxt, t), dr.select(active, nlo, lo), dr.select(active, nhi, hi),
                    active & nt(stop), it + 1)

        tau, _, _, _, _ = dr.while_loop((tau, lo0, h, active, it), cond, body,
                                        labels=("tau", "lo", "hi", "active", "it"), label="gonio_solve_radius")
        return dr.select(iterated, x0 + tau, res)

    # -- the stages of the forward map, shared by one map and a blend of slices ---------------

    def _square_to_disk(self, u, v):
        """M_B: Shirley–Chiu's concentric map of the square onto the B-disk: (r_B, φ_B)."""
        dr = self.dr
        a = 2.0 * u - 1.0
        b = 2.0 * v - 1.0
        big = dr.abs(a) > dr.abs(b)
        r = dr.select(big, a, b)
        num = dr.select(big, b, a)
        den = dr.select(big, a, b)
        q = num / den
        phi = dr.select(big, FRAC_PI_4 * q, FRAC_PI_2 - FRAC_PI_4 * q)
        negr = r < 0
        r = dr.select(negr, -r, r)
        phi = dr.select(negr, phi + PI, phi)
        phi = dr.select(phi < 0, phi + TAU, phi)
        phi = dr.select(phi >= TAU, 0.0, phi)
        origin = (a == 0) & (b == 0)
        return dr.select(origin, 0.0, r), dr.select(origin, 0.0, phi)

    def _wedge_fraction(self, beta, ra, rbb, gamma):
        """M_C's wedge equation: the fraction ε of a sector of width β between squared star
        radii R_a², R_b² that holds the wedge angle γ."""
        dr = self.dr
        aa = (0.5 * beta) * (rbb - ra)
        bb = beta * ra
        cc = dr.maximum(gamma, 0.0)
        dn = bb + dr.sqrt(dr.maximum(bb * bb + (4.0 * aa) * cc, 0.0))
        return dr.select(dn > 0, self._clamp((2.0 * cc) / dn, 0.0, 1.0), 0.0)

    def _settle(self, j, n, w, ut, label):
        """`settle_radial`'s loops on the radial CDF `ut` at level `w` (each entered only where
        its condition holds); the last one steps back over an unlit zone at the map's end."""
        dr = self.dr
        (j,) = dr.while_loop((j,), lambda j: (j > 0) & (ut(j) > w), lambda j: (j - 1,),
                             labels=("j",), label=label + "_down")
        (j,) = dr.while_loop((j,), lambda j: (j + 2 < n) & (ut(j + 1) <= w), lambda j: (j + 1,),
                             labels=("j",), label=label + "_up")
        (j,) = dr.while_loop((j,), lambda j: (j > 0) & (ut(j + 1) <= ut(j)), lambda j: (j - 1,),
                             labels=("j",), label=label + "_edge")
        return j

    def _lift(self, xr, phic, x0, inv_dx, d0, d1):
        """M_E (D-disk radius `xr`, azimuth φ_C → direction) and the disk density there, linear
        on the segment from x0 with end densities d0, d1: (x, y, z, D)."""
        dr = self.dr
        r2 = xr * xr
        s = xr * dr.sqrt(dr.maximum(2.0 - r2, 0.0))
        sp, cp = dr.sincos(phic)
        ox = s * cp
        oy = s * sp
        oz = 1.0 - r2
        up = oz > 0
        rd2 = dr.select(up, (ox * ox + oy * oy) / (1.0 + oz), 1.0 - oz)
        xd = dr.sqrt(dr.minimum(dr.maximum(rd2, 0.0), 2.0))
        t = dr.minimum(dr.maximum((xd - x0) * inv_dx, 0.0), 1.0)
        return ox, oy, oz, dr.maximum(d0 + (d1 - d0) * t, 0.0)

    def _sample_map(self, c, u, v):
        """`sample_block` of one map (per lane `c`): direction (x, y, z) and disk density D."""
        dr = self.dr
        n = c.n
        # Stage 1: M_B (concentric square → disk) and the wedge search.
        rb, pb = self._square_to_disk(u, v)
        wi = self._guided(c, "cum", "wedge_guide", c.guide_scale, pb, c.m - 1, c.kmax_w, self.steps["steps_w"])

        # Stage 2: the wedge equation, then the radial search over the blended CDF.
        beta = self._map_f(c, "beta", wi)
        ra = self._map_f(c, "r2", wi)
        rbb = self._map_f(c, "r2", wi + 1)
        cum = self._map_f(c, "cum", wi)
        phi0 = self._map_f(c, "phi", wi)
        eps = self._wedge_fraction(beta, ra, rbb, (pb - cum) / c.kappa_div)
        phic = phi0 + eps * beta
        w1 = wi + 1
        wn = dr.select(w1 == c.m, 0, w1)
        a_off, b_off = wi * n, wn * n
        ome = 1.0 - eps

        def blend(name, j):
            return ome * self._map_f(c, name, a_off + j) + eps * self._map_f(c, name, b_off + j)

        r2b = rb * rb
        w = r2b * (ome * self._map_f(c, "total", wi) + eps * self._map_f(c, "total", wn))
        kg = c.K
        kk = self._to_index(r2b * kg, kg - 1)
        ga = wi * (kg + 1) + kk
        gb = wn * (kg + 1) + kk
        lo = dr.minimum(self._map_i(c, "radial_guide", ga), self._map_i(c, "radial_guide", gb))
        hi = dr.maximum(self._map_i(c, "radial_guide", ga + 1), self._map_i(c, "radial_guide", gb + 1))
        j = self._descend(lo, hi, w, lambda j: blend("u", j), self.steps["steps_rad"])

        def ut(j):
            return blend("u", j)

        # The settling loops of `settle_radial` (each entered only where its condition holds).
        j = self._settle(j, n, w, ut, "gonio_radial")
        uj = ut(j)

        # Stage 3: the radial solve on segment j.
        d0 = blend("d", j)
        d1 = blend("d", j + 1)
        x0 = self._map_f(c, "x", j)
        x1 = self._map_f(c, "x", j + 1)
        inv_dx = self._map_f(c, "inv_dx", j)
        xr = dr.minimum(self._solve_radius(x0, x1, d0, d1, w - uj), x1)

        # Stage 4: the density at the radius and M_E (disk → sphere).
        ox, oy, oz, od = self._lift(xr, phic, x0, inv_dx, d0, d1)
        up = oz > 0
        pole = (ox == 0) & (oy == 0)
        od = dr.select(pole, dr.select(up, c.north, c.south), od)
        return ox, oy, oz, od

    # -- the public calls -----------------------------------------------------------------------

    @_under_scope
    def sample(self, u):
        """Points u (Point2f, in [0, 1]²) → (unit directions Vector3f, pdf Float per sr)."""
        dr, mi = self.dr, self.mi
        x, y = self._in(u.x), self._in(u.y)
        if self.layout != 2 or not (self.has_lower and self.has_upper):
            c = self._ctx(None)
            ox, oy, oz, od = self._sample_map(c, x, y)
            if self.layout == 2 and self.has_lower:  # the lower map only
                oz = -oz
        else:
            p = self.p_lower
            low = x < p
            uu = dr.select(low, dr.minimum(x / self._p_div, 1.0), self._clamp((x - p) / self._q_div, 0.0, 1.0))
            c = self._ctx(low)
            ox, oy, oz, od = self._sample_map(c, uu, y)
            oz = dr.select(low, -oz, oz)
        o = self._out
        return mi.Vector3f(o(ox), o(oy), o(oz)), o(od * self.inv_2t)

    def _side(self, z):
        """Split layout: the lanes the lower map serves (z < 0; z = 0 too without an upper map)."""
        if not self.has_upper:
            return z <= 0
        return z < 0

    @_under_scope
    def pdf(self, d):
        """The density per steradian at unit directions d (Vector3f)."""
        return self._out(self._pdf(self._in(d.x), self._in(d.y), self._in(d.z)))

    def _pdf(self, x, y, z):
        dr = self.dr
        if self.layout == 0:
            c = self._ctx(None)
            return dr.select(z >= 0, self._density(c, x, y, z) * self.inv_2t, 0.0)
        if self.layout == 1:
            return self._density(self._ctx(None), x, y, z) * self.inv_2t
        low = self._side(z)
        if self.both:
            dens = self._density(self._ctx(low), x, y, dr.select(low, -z, z))
        else:
            dens = self._density(self._ctx(None), x, y, -z if self.has_lower else z)
            dens = dr.select(low if self.has_lower else self._not(low), dens, 0.0)
        return dens * self.inv_2t

    @_under_scope
    def invert(self, d):
        """The points of the square (Point2f) that ``sample`` maps to unit directions d; NaN
        where none does."""
        dr, mi = self.dr, self.mi
        x, y, z = self._in(d.x), self._in(d.y), self._in(d.z)
        nan = math.nan
        ok = dr.isfinite(x) & dr.isfinite(y) & dr.isfinite(z)
        if self.layout != 2:
            u, v = self._invert(self._ctx(None), x, y, z)
            if self.layout == 0:
                ok = ok & (z >= 0)
        else:
            low = self._side(z)
            if self.both:
                u, v = self._invert(self._ctx(low), x, y, dr.select(low, -z, z))
            else:
                u, v = self._invert(self._ctx(None), x, y, -z if self.has_lower else z)
                ok = ok & (low if self.has_lower else self._not(low))
            p = self.p_lower
            if self.has_lower and not self.has_upper:
                ul = u
            else:
                ul = u * p
                ul = dr.select((ul >= p) & (p > 0), self.p_lower_below, ul)
            uh = dr.minimum(p + u * (1.0 - p), 1.0)
            fin = dr.isfinite(u)
            u = dr.select(fin, dr.select(low, ul, uh), nan)
        return mi.Point2f(self._out(dr.select(ok, u, nan)), self._out(dr.select(ok, v, nan)))

    # -- targets --------------------------------------------------------------------------------

    def _angles(self, x, y, z):
        """θ from +z and φ ∈ [0, 2π) from +x toward +y (φ = 0 on the axis)."""
        dr = self.dr
        theta = dr.atan2(dr.sqrt(x * x + y * y), z)
        phi = dr.atan2(y, x)
        phi = dr.select(phi < 0, phi + TAU, phi)
        phi = dr.select(phi >= TAU, 0.0, phi)
        return theta, dr.select((x == 0) & (y == 0), 0.0, phi)

    @_under_scope
    def target(self, d):
        """The grid target's bilinear interpolant at directions d (``Diagram.intensity``)."""
        if self.target_kind != 1:
            raise ValueError("this table blob has no grid target")
        dr = self.dr
        m, n = self.grid_shape
        theta, phi = self._angles(self._in(d.x), self._in(d.y), self._in(d.z))
        th, ph, vals = self._gth, self._gph, self._gv
        t0, t1 = self._gf(th, 0), self._gf(th, n - 1)
        inside = (theta >= t0) & (theta <= t1)
        if n == 1:
            j, t = 0, 0.0
        else:
            k = self._count_le(th, 0, n, theta, _bits(n))
            j = dr.minimum(dr.maximum(k - 1, 0), n - 2)
            tj, tj1 = self._gf(th, j), self._gf(th, j + 1)
            t = self._clamp((theta - tj) / (tj1 - tj), 0.0, 1.0)
        if m == 1:
            i0, i1, e = 0, 0, 0.0
        else:
            first, last = self._g_first, self._g_last
            wrap = (phi >= last) | (phi < first)
            off = dr.select(phi >= last, phi - last, phi + TAU - last)
            k = self._count_le(ph, 0, m, phi, _bits(m))
            i = dr.minimum(dr.maximum(k - 1, 0), m - 2)
            pi0, pi1 = self._gf(ph, i), self._gf(ph, i + 1)
            e_in = self._clamp((phi - pi0) / (pi1 - pi0), 0.0, 1.0)
            e_wr = self._clamp(off / self._g_width_div, 0.0, 1.0)
            i0 = dr.select(wrap, m - 1, i)
            i1 = dr.select(wrap, 0, i + 1)
            e = dr.select(wrap, e_wr, e_in)
        jn = dr.minimum(j + 1, n - 1)

        def row(i):
            return (1.0 - t) * self._gf(vals, i * n + j) + t * self._gf(vals, i * n + jn)

        value = (1.0 - e) * row(i0) + e * row(i1)
        return self._out(dr.select(inside, value, 0.0))

    @_under_scope
    def radiance(self, d):
        """The image target's RGB radiance (Color3f) at unit directions d, by the blob's lookup."""
        if self.target_kind != 2:
            raise ValueError("this table blob has no image target")
        dr, mi = self.dr, self.mi
        w, h = self.width, self.height
        theta, phi = self._angles(self._in(d.x), self._in(d.y), self._in(d.z))
        # phi_to_s: s = ½ − φ/2π (mod 1), s = 1 → 0.
        r = 0.5 - phi / self._tau_div
        s = dr.select(r < 0, r + 1.0, r)
        s = dr.select(s >= 1.0, 0.0, s)
        t = theta / self._pi_div
        if self.lookup == "nearest":
            x = dr.minimum(self._to_index(s * w, w), w - 1)
            y = dr.minimum(self._to_index(t * h, h), h - 1)
            return self._color(self._pixel(y * w + x))
        xs = s * w - 0.5
        x0f = dr.floor(xs)
        bw = xs - x0f
        x0 = self.I(x0f)
        x0 = dr.select(x0 < 0, x0 + w, x0)
        x0 = dr.select(x0 >= w, x0 - w, x0)
        x1 = dr.select(x0 + 1 == w, 0, x0 + 1)
        ys = t * h - 0.5
        top = ys < 0
        bottom = self._not(top) & (ys >= h - 1)
        y0 = self._to_index(ys, h - 1)
        ya = dr.select(top, 0, dr.select(bottom, h - 1, y0))
        yb = dr.select(top, 0, dr.select(bottom, h - 1, dr.minimum(y0 + 1, h - 1)))
        f = dr.select(top, self._clamp((ys + 0.5) * 2.0, 0.0, 1.0),
                      dr.select(bottom, self._clamp((ys - (h - 1)) * 2.0, 0.0, 1.0), ys - self._float(y0)))

        def row(yy):
            p, q = self._pixel(yy * w + x0), self._pixel(yy * w + x1)
            return [a * (1.0 - bw) + b * bw for a, b in zip(p, q)]

        ca = [dr.select(top, pole, a) for pole, a in zip(self._poles[0], row(ya))]
        cb = [dr.select(bottom, pole, b) for pole, b in zip(self._poles[1], row(yb))]
        return self._color([a * (1.0 - f) + b * f for a, b in zip(ca, cb)])

    def _pixel(self, k):
        """The RGB of pixel k (row-major) as three arrays."""
        i = 3 * k
        return [self._gf(self._rgb, i + c) for c in range(3)]

    def _color(self, c):
        return self.mi.Color3f(*(self._out(v) for v in c))


# ---------------------------------------------------------------------------------------------
# Families (layout 3): a tabulated BRDF's slices, blended per lane.
# ---------------------------------------------------------------------------------------------

_STACKED = {"r2", "cum", "wedge_guide", "d", "u", "total", "radial_guide"}


def parse_family(data):
    """A family blob's (docs/TABLES.md, "Families") header, shared grid, stacked tables, incident
    grid and BRDF table as Python values and numpy views (no copy). float32 tables only."""
    b = bytes(data)
    total, (prec, layout, frame, target, count, _res, maps, _lookup) = _head(b)
    if layout != 3 or target != 3:
        raise BlobError(f"table blob of layout {layout}, target {target}: not a BRDF family (layout 3); "
                        "write one with Brdf.tables() or `gonio tables BRDF_FILE`")
    if prec != 4:
        raise BlobError(f"family blob of precision {prec} bytes: gonio.drjit reads float32 tables")
    tables = _directory(b, count, total)
    m, n, k_rad, g, g_r = struct.unpack_from("<5I", b, 96)
    inv_ub, _kappa, guide_scale, radius_scale, _edge = struct.unpack_from("<5d", b, 128)
    a, bb, aniso, channels, n_to, n_po = struct.unpack_from("<6I", b, 176)
    s = a * bb
    out = dict(m=m, n=n, K=k_rad, G=g, Gr=g_r, inv_ub=inv_ub, guide_scale=guide_scale,
               radius_scale=radius_scale, A=a, B=bb, anisotropic=bool(aniso), channels=channels, S=s)
    one = dict(phi=m + 1, beta=m, r2=m + 1, cum=m + 1, wedge_guide=g, x=n, d=m * n, u=m * n, total=m,
               radius_guide=g_r, inv_dx=n - 1, radial_guide=m * (k_rad + 1))
    for k, name in enumerate(_MAP_TABLES):
        t = tables.get(k)
        want = one[name] * (s if name in _STACKED else 1)
        if t is None or len(t) != want:
            raise BlobError(f"family blob: table {name} missing or of the wrong length")
        out[name] = t
    need = {64: 4 * s, 65: a, 66: bb, 48: n_to, 49: n_po, 50: channels * s * n_to * n_po}
    for tid, cnt in need.items():
        if tid not in tables or len(tables[tid]) != cnt:
            raise BlobError(f"family blob: table id {tid} missing or of the wrong length")
    out["slice"] = tables[64].reshape(s, 4)
    out["theta_i"], out["phi_i"] = tables[65], tables[66]
    out["theta_o"], out["phi_o"] = tables[48], tables[49]
    out["values"] = tables[50]
    return out


class BrdfTables(Tables):
    """A family blob (``Brdf.tables(precision="float32")``) as Dr.Jit arrays of the current
    Mitsuba variant: the blended slice map of a tabulated BRDF and its interpolant, per lane, in
    Dr.Jit operations only (the rules of ``Tables``). Directions are the local shading frame
    (z the normal, x the tangent), both pointing away from the surface:

    * ``sample(wi, u) -> (wo, pdf)``: ω_o from the map of the slices blended for ω_i (docs/TABLES.md,
      "Families"), and its exact pdf per steradian (Σ w_k pdf_k); ω_i below the horizon, or with
      every neighbouring slice empty, gives the cosine sample with pdf cos θ_o / π and ``valid``
      False (see ``sample_valid``);
    * ``pdf(wi, wo) -> Float``: the density of ``sample`` (0 below the horizon);
    * ``eval(wi, wo) -> Color3f``: the table's multilinear interpolant f_r in 1/sr (0 below the
      horizon, 0 beyond the table's θ_o range).

    What differs from the library's f64 ``BrdfSampler``: float32 arithmetic, and the two searches
    of the blended map (the wedge and the radial segment) bisect their whole tables in fixed steps
    instead of starting from the parts' guide brackets (the same index wherever the blended
    cumulative is strictly increasing; ``tests/test_drjit_brdf.py`` measures the agreement).
    """

    def __init__(self, data, mi=None, ieee=None):
        self._bind(mi, ieee)
        f = parse_family(data)
        self.m, self.n, self.S = f["m"], f["n"], f["S"]
        self.A, self.B = f["A"], f["B"]
        self.anisotropic, self.channels = f["anisotropic"], f["channels"]
        self._t = {name: self._array(f[name], name in _GUIDES) for name in _MAP_TABLES}
        rows = np.asarray(f["slice"], dtype=np.float32)
        present = rows[:, 0] > 0
        if not present.any():
            raise BlobError("family blob without any slice map")
        # Per slice: 2·(1/(2T)) (so c_k = w_k · this), κ, present (1/0).
        self._c2 = self._array(2.0 * rows[:, 0], False)
        self._kap = self._array(rows[:, 1], False)
        self._present = self._array(present.astype(np.float32), False)
        self.edge = float(rows[present, 2].max())
        self.x_last = float(np.float32(f["x"][-1]))
        self.inv_ub = float(f["inv_ub"])
        self.radius_scale = float(f["radius_scale"])
        rgd = np.minimum(f["radius_guide"].astype(np.int64), self.n - 2)
        span_r = int(np.max(np.diff(rgd))) if len(rgd) > 1 else 0
        span_r = max(span_r, int(self.n - 2 - rgd[-1]))
        self.steps = dict(steps_r=_bits(span_r), steps_wedge=_bits(self.m), steps_rad=_bits(self.n),
                          steps_phi=_bits(self.m + 1))
        self._c = _NS(o_phi=0, o_beta=0, o_x=0, o_inv_dx=0, o_radius_guide=0, m=self.m, n=self.n,
                      inv_ub=self.inv_ub, kmax_r=f["Gr"] - 1, radius_scale=self.radius_scale)
        self.any_uniform = self.inv_ub > 0
        self.any_general = not self.any_uniform
        # The incident grid and the table (float32), and their search steps.
        self.theta_i = np.asarray(f["theta_i"], dtype=np.float64)
        self.phi_i = np.asarray(f["phi_i"], dtype=np.float64)
        self._ti = self._array(f["theta_i"], False)
        self._pi = self._array(f["phi_i"], False)
        self._to = self._array(f["theta_o"], False)
        self._po = self._array(f["phi_o"], False)
        self._vals = self._array(f["values"], False)
        self.n_ti, self.n_pi, self.n_to, self.n_po = len(f["theta_i"]), len(f["phi_i"]), len(f["theta_o"]), \
            len(f["phi_o"])
        # Uniform grids (the usual: MERL resampled, analytic and UTIA tables) are searched by their
        # direct index and one correction step each way, as the library's `interval`; the others
        # by bisection.
        self._uniform = {}
        for key, g in (("ti", f["theta_i"]), ("pi", f["phi_i"]), ("to", f["theta_o"]), ("po", f["phi_o"])):
            g32 = np.asarray(g, dtype=np.float32).astype(np.float64)
            if len(g32) >= 2:
                h = (g32[-1] - g32[0]) / (len(g32) - 1)
                dev = np.max(np.abs(g32 - (g32[0] + h * np.arange(len(g32)))))
                if h > 0 and dev <= 1e-3 * h:
                    self._uniform[key] = (float(np.float32(g32[0])), float(np.float32(1.0 / h)))
        self._to_lo = float(np.float32(f["theta_o"][0]))
        self._to_hi = float(np.float32(f["theta_o"][-1]))
        self._tau_div = self._const(np.float32(TAU))
        self._pi_div = self._const(np.float32(PI))

    # -- small helpers -------------------------------------------------------------------------

    def _angles(self, x, y, z):
        """(θ, φ) of a direction as the library's ``spherical``: θ = atan2(√(x² + y²), z), φ in
        [0, 2π), 0 on the axis."""
        dr = self.dr
        th = dr.atan2(dr.sqrt(x * x + y * y), z)
        ph = dr.atan2(y, x)
        ph = dr.select(ph < 0, ph + TAU, ph)
        ph = dr.select(ph >= TAU, 0.0, ph)
        ph = dr.select((x == 0) & (y == 0), 0.0, ph)
        return th, ph

    def _interval(self, key, table, count, x):
        """The largest j ≤ count − 2 with table[j] ≤ x (0 if none): on a uniform grid the direct
        index and one correction step each way, else bisection."""
        dr = self.dr
        if key in self._uniform:
            a0, inv_h = self._uniform[key]
            j = self._to_index((x - a0) * inv_h, count - 2)
            j = dr.select((j > 0) & (x < self._gf(table, j)), j - 1, j)
            j = dr.select((j < count - 2) & (x >= self._gf(table, j + 1)), j + 1, j)
            return j
        k = self._count_le(table, 0, count, x, _bits(count))
        return dr.minimum(dr.maximum(k - 1, 0), count - 2)

    def _clamped(self, table, count, x, key=None):
        """Linear weights of x on the increasing grid `table` (count nodes), clamped to its ends:
        (j0, j1, t), as the library's ``clamped``."""
        dr, I, F = self.dr, self.I, self.F
        if count == 1:
            return I(0), I(0), F(0.0)
        first = self._gf(table, I(0))
        last = self._gf(table, I(count - 1))
        j = self._interval(key, table, count, x)
        a0, a1 = self._gf(table, j), self._gf(table, j + 1)
        t = (x - a0) / (a1 - a0)
        below = ~(x > first)
        above = x >= last
        j0 = dr.select(below, 0, dr.select(above, count - 1, j))
        j1 = dr.select(below, 0, dr.select(above, count - 1, j + 1))
        t = dr.select(below | above, 0.0, t)
        return I(j0), I(j1), t

    def _periodic(self, table, count, x, key=None):
        """Linear weights of azimuth x on the periodic grid `table` ⊂ [0, 2π): (i0, i1, t), as the
        library's ``periodic``."""
        dr, I, F = self.dr, self.I, self.F
        x = x - TAU * dr.floor(x / self._tau_div)
        x = dr.select(x >= TAU, x - TAU, x)
        x = dr.select(x < 0, x + TAU, x)
        if count == 1:
            return I(0), I(0), F(0.0)
        first = self._gf(table, I(0))
        last = self._gf(table, I(count - 1))
        wrap = (x < first) | (x >= last)
        xx = dr.select(x < first, x + TAU, x)
        tw = self._clamp((xx - last) / ((first + TAU) - last), 0.0, 1.0)
        i = self._interval(key, table, count, x)
        a0, a1 = self._gf(table, i), self._gf(table, i + 1)
        ti = (x - a0) / (a1 - a0)
        i0 = dr.select(wrap, count - 1, i)
        i1 = dr.select(wrap, 0, i + 1)
        return I(i0), I(i1), dr.select(wrap, tw, ti)

    # -- the blend ----------------------------------------------------------------------------

    def _weights(self, ti, pi):
        """The slices and weights of ω_i = (θ_i, φ_i): a list of (slice index, weight), weights of
        empty slices 0 and the rest renormalised, and `ok` (some neighbour has a map)."""
        dr = self.dr
        a0, a1, ta = self._clamped(self._ti, self.n_ti, ti, "ti")
        parts = []
        if self.anisotropic:
            q0, q1, tq = self._periodic(self._pi, self.n_pi, pi, "pi")
            for a, wa in ((a0, 1.0 - ta), (a1, ta)):
                for q, wq in ((q0, 1.0 - tq), (q1, tq)):
                    parts.append((a * self.B + q, wa * wq))
        else:
            parts = [(a0, 1.0 - ta), (a1, ta)]
        out, total = [], None
        for s, w in parts:
            w = w * self._gf(self._present, s)
            out.append((s, w))
            total = w if total is None else total + w
        ok = total > 0
        inv = dr.select(ok, 1.0 / dr.select(ok, total, 1.0), 0.0)
        return [(s, w * inv) for s, w in out], ok

    def _blend_consts(self, parts):
        """Per part: (slice, w_k, c_k); and κ = Σ w_k κ_k."""
        out, kappa = [], None
        for s, w in parts:
            c = w * self._gf(self._c2, s)
            k = w * self._gf(self._kap, s)
            kappa = k if kappa is None else kappa + k
            out.append((s, w, c))
        return out, kappa

    def _sum(self, parts, coef, name, idx_of):
        acc = None
        for s, w, c in parts:
            v = (w if coef == "w" else c) * self._gf(self._t[name], idx_of(s))
            acc = v if acc is None else acc + v
        return acc

    def _sample_blend(self, parts, kappa, u, v):
        """The blended map at points (u, v): direction in the slice frame and blended disk
        density D (the pdf is D / 2)."""
        dr = self.dr
        m, n = self.m, self.n
        rb, pb = self._square_to_disk(u, v)

        def gamma(i):
            return self._sum(parts, "w", "cum", lambda s: s * (m + 1) + i)

        def r2(i):
            return self._sum(parts, "w", "r2", lambda s: s * (m + 1) + i)

        # The wedge: the largest i ≤ M − 1 with Γ_i ≤ φ_B (Γ_0 = 0).
        wi = self._descend(self.I(0), self.I(m - 1), pb, gamma, self.steps["steps_wedge"])
        beta = self._gf(self._t["beta"], wi)
        ra, rbb = r2(wi), r2(wi + 1)
        g0 = gamma(wi)
        eps = self._wedge_fraction(beta, ra, rbb, (pb - g0) / kappa)
        phic = self._gf(self._t["phi"], wi) + eps * beta
        w1 = wi + 1
        wn = dr.select(w1 == m, 0, w1)
        ome = 1.0 - eps
        mn = m * n

        def ut(j):
            return self._sum(parts, "c", "u", lambda s: s * mn + wi * n + j) * ome + \
                self._sum(parts, "c", "u", lambda s: s * mn + wn * n + j) * eps

        def dt(j):
            return self._sum(parts, "c", "d", lambda s: s * mn + wi * n + j) * ome + \
                self._sum(parts, "c", "d", lambda s: s * mn + wn * n + j) * eps

        w = (rb * rb) * ut(self.I(n - 1))
        j = self._descend(self.I(0), self.I(n - 2), w, ut, self.steps["steps_rad"])
        j = self._settle(j, n, w, ut, "gonio_brdf_radial")
        uj = ut(j)
        d0, d1 = dt(j), dt(j + 1)
        x0 = self._gf(self._t["x"], j)
        x1 = self._gf(self._t["x"], j + 1)
        inv_dx = self._gf(self._t["inv_dx"], j)
        xr = dr.minimum(self._solve_radius(x0, x1, d0, d1, w - uj), x1)
        return self._lift(xr, phic, x0, inv_dx, d0, d1)

    def _density_blend(self, parts, x, y, z):
        """The blended disk density D at directions of the slice frame (upper hemisphere)."""
        dr = self.dr
        n, mn = self.n, self.m * self.n
        c = self._c
        xr, p = self._radius_azimuth(x, y, z)
        i, i1, eps = self._sectors(c, p)
        j = self._guided(c, "x", "radius_guide", c.radius_scale, xr, n - 2, c.kmax_r, self.steps["steps_r"])
        t = self._clamp((xr - self._gf(self._t["x"], j)) * self._gf(self._t["inv_dx"], j), 0.0, 1.0)

        def row(r):
            a0 = self._sum(parts, "c", "d", lambda s: s * mn + r * n + j)
            a1 = self._sum(parts, "c", "d", lambda s: s * mn + r * n + j + 1)
            return a0 + t * (a1 - a0)

        d = dr.maximum((1.0 - eps) * row(i) + eps * row(i1), 0.0)
        return dr.select(xr > self.edge * (1.0 + 1e-6), 0.0, d)

    # -- the public calls ----------------------------------------------------------------------

    def _incident(self, wi):
        ix, iy, iz = self._in(wi.x), self._in(wi.y), self._in(wi.z)
        ti, pi = self._angles(ix, iy, iz)
        ti = self.dr.minimum(ti, FRAC_PI_2)
        return ix, iy, iz, ti, pi

    def sample(self, wi, u):
        """(wo Vector3f, pdf Float) for incident directions wi and points u of the square."""
        wo, pdf, _ = self.sample_valid(wi, u)
        return wo, pdf

    def sample_valid(self, wi, u):
        """``sample`` and a mask: False where the cosine fallback was used (ω_i below the horizon,
        or every neighbouring slice empty: the library's zero-weight sample)."""
        with self._scope():
            dr, mi = self.dr, self.mi
            ix, iy, iz, ti, pi = self._incident(wi)
            uu, vv = self._in(u.x), self._in(u.y)
            parts, ok = self._weights(ti, pi)
            ok = ok & (iz >= 0)
            parts, kappa = self._blend_consts(parts)
            kappa = dr.select(ok, kappa, 1.0)
            ox, oy, oz, od = self._sample_blend(parts, kappa, uu, vv)
            sp, cp = dr.sincos(pi)
            rx = cp * ox - sp * oy
            ry = sp * ox + cp * oy
            pdf = 0.5 * od
            # The cosine fallback (the concentric map lifted by z = √(1 − r²)).
            a = 2.0 * uu - 1.0
            b = 2.0 * vv - 1.0
            big = dr.abs(a) > dr.abs(b)
            r = dr.select(big, a, b)
            q = dr.select(big, b, a) / dr.select(big, a, b)
            ph = dr.select(big, FRAC_PI_4 * q, FRAC_PI_2 - FRAC_PI_4 * q)
            ph = dr.select((a == 0) & (b == 0), 0.0, ph)
            s2, c2 = dr.sincos(ph)
            cz = dr.sqrt(dr.maximum(1.0 - r * r, 0.0))
            wx = dr.select(ok, rx, r * c2)
            wy = dr.select(ok, ry, r * s2)
            wz = dr.select(ok, oz, cz)
            pdf = dr.select(ok, pdf, cz / self._pi_div)
            out = mi.Vector3f(self._out(wx), self._out(wy), self._out(wz))
            return out, self._out(pdf), (bool(ok[0]) if self.scalar else ok)

    def pdf(self, wi, wo):
        """The density of ``sample`` at wo for wi (per steradian; 0 below the horizon)."""
        with self._scope():
            dr = self.dr
            ix, iy, iz, ti, pi = self._incident(wi)
            x, y, z = self._in(wo.x), self._in(wo.y), self._in(wo.z)
            parts, ok = self._weights(ti, pi)
            ok = ok & (iz >= 0)
            parts, _ = self._blend_consts(parts)
            sp, cp = dr.sincos(pi)
            lx = cp * x + sp * y
            ly = cp * y - sp * x
            d = self._density_blend(parts, lx, ly, z)
            p = dr.select(ok, 0.5 * d, dr.maximum(z, 0.0) / self._pi_div)
            return self._out(dr.select(z >= 0, p, 0.0))

    def eval(self, wi, wo):
        """f_r (Color3f, 1/sr): the table's multilinear interpolant; 0 below the horizon."""
        with self._scope():
            dr, mi = self.dr, self.mi
            ix, iy, iz, ti, pi = self._incident(wi)
            x, y, z = self._in(wo.x), self._in(wo.y), self._in(wo.z)
            to, po = self._angles(x, y, z)
            inside = (iz >= 0) & (z >= 0) & (to >= self._to_lo - 1e-6) & (to <= self._to_hi + 1e-6)
            a0, a1, ta = self._clamped(self._ti, self.n_ti, ti, "ti")
            b0, b1, tb = self._clamped(self._to, self.n_to, to, "to")
            if self.anisotropic:
                q = self._periodic(self._pi, self.n_pi, pi, "pi")
                az = po
            else:
                q = (self.I(0), self.I(0), self.F(0.0))
                az = po - pi
            p0, p1, tp = self._periodic(self._po, self.n_po, az, "po")
            na = self.n_ti * self.n_pi
            nb, npo = self.n_to, self.n_po
            out = []
            for ch in range(self.channels):
                acc = None
                for a, wa in ((a0, 1.0 - ta), (a1, ta)):
                    for qi, wq in ((q[0], 1.0 - q[2]), (q[1], q[2])):
                        inc = a * self.n_pi + qi
                        base = (ch * na + inc) * nb

                        def at(bq, pq):
                            return self._gf(self._vals, (base + bq) * npo + pq)

                        row0 = (1.0 - tp) * at(b0, p0) + tp * at(b0, p1)
                        row1 = (1.0 - tp) * at(b1, p0) + tp * at(b1, p1)
                        v = (wa * wq) * ((1.0 - tb) * row0 + tb * row1)
                        acc = v if acc is None else acc + v
                out.append(dr.select(inside, dr.maximum(acc, 0.0), 0.0))
            if self.channels == 1:
                out = [out[0]] * 3
            return mi.Color3f(*(self._out(c) for c in out))
