"""gonio inside Mitsuba 3: IES LM-63 and EULUMDAT luminaires as Mitsuba emitters (docs/MITSUBA.md).

``register()`` registers the emitter plugin ``"gonio"`` for the current Mitsuba variant::

    import mitsuba as mi, gonio.mitsuba
    mi.set_variant("llvm_ad_rgb")
    gonio.mitsuba.register()
    scene = mi.load_dict({..., "lamp": {"type": "gonio", "filename": "lamp.ies",
                                        "to_world": mi.ScalarTransform4f().translate([0, 0, 8])}})

Properties of ``{"type": "gonio", ...}``:

* ``filename`` (string): an IES LM-63 (.ies) or EULUMDAT (.ldt) file, resolved by Mitsuba's file
  resolver;
* ``to_world`` (transform): the luminaire's frame. Its local frame is gonio's photometric frame
  (README "The frame"): nadir (γ = 0°) along local −z, C = 0° along local +x, C = 90° along +y;
* ``scale`` (float, default 1): multiplies the file's candela; 1 cd = 1 unit of Mitsuba radiant
  intensity (W/sr in the RGB variants' white), so 1 lm = 1 unit of Mitsuba power;
* ``shape`` (string): ``"point"`` (default), a point luminaire of intensity I(ω); or
  ``"opening"``, the file's luminous opening emitting L(x, ω) = I(ω) / A_proj(ω);
* ``width``, ``length``, ``height`` (float, metres): override the file's luminous opening with
  the LM-63 sign rules (``length`` along C0–C180 = local x, ``width`` along C90–C270 = local y,
  ``height`` along z; a negative width/length means round, a negative height a sphere);
* ``part`` (integer): which surface of the opening this emitter is; ``luminaire()`` sets it.

A luminous opening must be seen by the camera and hit by rays, so it lives on Mitsuba shapes:
``luminaire(filename, shape="opening", ...)`` builds the shapes (rectangle, disk, the six faces of
a box, a cylinder and its caps, a sphere) each carrying a ``"gonio"`` emitter for its part. The
point luminaire is a plain emitter (``luminaire()`` returns it too).

Sampling: directions by gonio's Havran–Dmitriev–Seidel map of the file (``Sampler.sample`` on
numpy batches, exact pdf); positions on the opening uniformly on its projection in the sampled
direction (``sample_ray``) or uniformly by area (``sample_direction``, ``sample_position``).

JIT variants: the emitter hands Mitsuba's arrays to numpy, which a *symbolic* (recorded) call or
loop cannot do. ``register()`` therefore turns off ``drjit.JitFlag.SymbolicCalls`` and
``drjit.JitFlag.SymbolicLoops`` in ``llvm_*``/``cuda_*`` variants (wavefront mode; pass
``jit_flags=False`` to keep yours). Scalar variants need nothing.
"""

import math
import warnings

import numpy as np

from . import read as _read

__all__ = ["register", "luminaire", "opening", "Opening"]

FEET = 0.3048


# ---------------------------------------------------------------------------------------------
# The luminous opening: geometry in the luminaire's local frame (metres), vectorised in numpy.
# ---------------------------------------------------------------------------------------------


class _Planar:
    """A flat part: centre c, half-axes u ⟂ v (rectangle c ± u ± v, or the ellipse they span),
    normal n = û × v̂; two-sided parts emit on both faces."""

    def __init__(self, c, u, v, round_, two_sided):
        self.c, self.u, self.v = (np.asarray(a, dtype=np.float64) for a in (c, u, v))
        self.round = round_
        self.two_sided = two_sided
        n = np.cross(self.u, self.v)
        self.n = n / np.linalg.norm(n)
        lu, lv = np.linalg.norm(self.u), np.linalg.norm(self.v)
        self.area = (math.pi if round_ else 4.0) * lu * lv
        self.kind = "disk" if round_ else "rectangle"

    def normal(self, x):
        return np.broadcast_to(self.n, x.shape)

    def sample_area(self, s):
        if self.round:
            r = np.sqrt(s[:, 0])
            a = 2.0 * math.pi * s[:, 1]
            p, q = r * np.cos(a), r * np.sin(a)
        else:
            p, q = 2.0 * s[:, 0] - 1.0, 2.0 * s[:, 1] - 1.0
        return self.c + p[:, None] * self.u + q[:, None] * self.v

    def proj(self, w):
        c = w @ self.n
        return self.area * (np.abs(c) if self.two_sided else np.maximum(c, 0.0))

    def sample_proj(self, w, s):
        return self.sample_area(s)  # flat: uniform by area is uniform on the projection

    def mitsuba_matrix(self):
        """Local (x, y, z) of Mitsuba's rectangle [-1, 1]² / unit disk → this part."""
        m = np.eye(4)
        m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = self.u, self.v, self.n, self.c
        return m


class _CylinderSide:
    """The side of the vertical cylinder of radius r from z = −h/2 to h/2 (normals outward)."""

    kind = "cylinder"
    two_sided = False

    def __init__(self, r, h):
        self.r, self.h = r, h
        self.area = 2.0 * math.pi * r * h

    def normal(self, x):
        n = np.array(x, dtype=np.float64)
        n[:, 2] = 0.0
        return n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)

    def _point(self, phi, s1):
        return np.stack([self.r * np.cos(phi), self.r * np.sin(phi), (s1 - 0.5) * self.h], axis=1)

    def sample_area(self, s):
        return self._point(2.0 * math.pi * s[:, 0], s[:, 1])

    def proj(self, w):
        return 2.0 * self.r * self.h * np.hypot(w[:, 0], w[:, 1])

    def sample_proj(self, w, s):
        # Uniform across the projected width 2r: the offset r·sin α of the point at azimuth
        # φ_ω + α is uniform in [−r, r], α = asin(2 s − 1); height uniform.
        a = np.arcsin(np.clip(2.0 * s[:, 0] - 1.0, -1.0, 1.0))
        return self._point(np.arctan2(w[:, 1], w[:, 0]) + a, s[:, 1])

    def mitsuba_matrix(self):
        """Mitsuba's cylinder (radius 1, z from 0 to 1) → this part."""
        m = np.diag([self.r, self.r, self.h, 1.0])
        m[2, 3] = -0.5 * self.h
        return m


class _Sphere:
    """The sphere of radius r about the photometric centre."""

    kind = "sphere"
    two_sided = False

    def __init__(self, r):
        self.r = r
        self.area = 4.0 * math.pi * r * r

    def normal(self, x):
        return x / np.maximum(np.linalg.norm(x, axis=1, keepdims=True), 1e-300)

    def sample_area(self, s):
        z = 1.0 - 2.0 * s[:, 0]
        rho = np.sqrt(np.maximum(0.0, 1.0 - z * z))
        a = 2.0 * math.pi * s[:, 1]
        return self.r * np.stack([rho * np.cos(a), rho * np.sin(a), z], axis=1)

    def proj(self, w):
        return np.full(len(w), math.pi * self.r * self.r)

    def sample_proj(self, w, s):
        # Uniform on the disk the sphere projects to, lifted onto the visible hemisphere.
        e1 = np.where(np.abs(w[:, :1]) < 0.9, np.array([[1.0, 0.0, 0.0]]), np.array([[0.0, 1.0, 0.0]]))
        e1 = e1 - (e1 * w).sum(1, keepdims=True) * w
        e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
        e2 = np.cross(w, e1)
        rho = np.sqrt(s[:, 0])
        a = 2.0 * math.pi * s[:, 1]
        h = np.sqrt(np.maximum(0.0, 1.0 - rho * rho))
        return self.r * (rho[:, None] * (np.cos(a)[:, None] * e1 + np.sin(a)[:, None] * e2) + h[:, None] * w)

    def mitsuba_matrix(self):
        return np.diag([self.r, self.r, self.r, 1.0])


class Opening:
    """A luminous opening: ``kind`` ("rectangle", "disk", "box", "cylinder", "sphere"), its
    dimensions in metres (``length`` along local x = C0–C180, ``width`` along y = C90–C270,
    ``height`` along z; a disk's or cylinder's diameter in ``length`` and ``width``, a sphere's in
    all three), and its ``parts`` (the surfaces that emit), centred on the photometric centre."""

    def __init__(self, kind, length, width, height):
        self.kind, self.length, self.width, self.height = kind, length, width, height
        a, b, h = 0.5 * length, 0.5 * width, 0.5 * height
        if kind == "rectangle":
            self.parts = [_Planar([0, 0, 0], [a, 0, 0], [0, b, 0], False, True)]
        elif kind == "disk":
            self.parts = [_Planar([0, 0, 0], [a, 0, 0], [0, b, 0], True, True)]
        elif kind == "box":
            self.parts = [
                _Planar([a, 0, 0], [0, b, 0], [0, 0, h], False, False),
                _Planar([-a, 0, 0], [0, 0, h], [0, b, 0], False, False),
                _Planar([0, b, 0], [0, 0, h], [a, 0, 0], False, False),
                _Planar([0, -b, 0], [a, 0, 0], [0, 0, h], False, False),
                _Planar([0, 0, h], [a, 0, 0], [0, b, 0], False, False),
                _Planar([0, 0, -h], [0, b, 0], [a, 0, 0], False, False),
            ]
        elif kind == "cylinder":
            self.parts = [
                _CylinderSide(a, height),
                _Planar([0, 0, h], [a, 0, 0], [0, a, 0], True, False),
                _Planar([0, 0, -h], [0, a, 0], [a, 0, 0], True, False),
            ]
        elif kind == "sphere":
            self.parts = [_Sphere(a)]
        else:
            raise ValueError(f"unknown opening kind {kind!r}")
        self.area = sum(p.area for p in self.parts)

    def projected_area(self, w):
        """A_proj(ω) in m² for local unit directions ``w`` (n, 3)."""
        w = np.asarray(w, dtype=np.float64).reshape(-1, 3)
        return sum(p.proj(w) for p in self.parts)

    def __repr__(self):
        return (f"gonio.mitsuba.Opening({self.kind!r}, length={self.length:g} m, width={self.width:g} m, "
                f"height={self.height:g} m)")


def _from_signed(width, length, height, where):
    """The LM-63 rules on signed dimensions (metres): see ``opening``."""
    w, l, h = width, length, height
    if w == 0 and l == 0 and h == 0:
        return None
    if w < 0 and l == 0:  # LM-63-1995: "-d 0 0" circular, "-d 0 h" cylinder, "-d 0 -d" sphere
        l = w
    if l < 0 and w == 0:
        w = l
    if w > 0 and l > 0 and h == 0:
        return Opening("rectangle", l, w, 0.0)
    if w > 0 and l > 0 and h > 0:
        return Opening("box", l, w, h)
    if w < 0 and l < 0 and h == 0:
        return Opening("disk", -l, -w, 0.0)
    if w < 0 and l < 0 and h > 0 and w == l:
        return Opening("cylinder", -l, -w, h)
    if w < 0 and l < 0 and h < 0 and w == l == h:
        return Opening("sphere", -l, -w, -h)
    raise ValueError(
        f"{where}: luminous opening width {width:g}, length {length:g}, height {height:g} m is a "
        "shape gonio.mitsuba does not model (it models rectangle, box, disk or ellipse, vertical "
        "cylinder, sphere); override it with the width/length/height properties"
    )


def opening(diagram, width=None, length=None, height=None, where="luminaire"):
    """The luminous opening of a photometric ``diagram`` (gonio.Diagram), or None for a point.

    IES LM-63: the width, length, height fields (feet or metres by the units field; width along
    the C90–C270 plane, length along C0–C180), by the LM-63 sign rules: w, l > 0, h = 0 a
    rectangle; w, l, h > 0 a box; w, l < 0 (or w < 0, l = 0 as in LM-63-1995) a disk (an ellipse
    when they differ); that with h > 0 a vertical cylinder; w = l = h < 0 a sphere.
    EULUMDAT: the luminous area's length (diameter) and width (0 = round) in mm, and the
    heights of its sides at C0, C90, C180, C270 (all equal and > 0: a box or cylinder).
    ``width``/``length``/``height`` in metres override the file's with the LM-63 rules."""
    if width is not None or length is not None or height is not None:
        return _from_signed(width or 0.0, length or 0.0, height or 0.0, where)
    h = diagram.header
    if h is None:
        return None
    if h.get("ies") is not None:
        i = h["ies"]
        unit = FEET if i["units_type"] == 1 else 1.0
        return _from_signed(i["width"] * unit, i["length"] * unit, i["height"] * unit, where)
    if h.get("ldt") is not None:
        e = h["ldt"]
        la, wa = (x / 1000.0 for x in e["luminous_area_mm"])
        hs = [x / 1000.0 for x in e["luminous_area_heights_mm"]]
        if la <= 0:
            return None
        hh = hs[0]
        if any(abs(x - hh) > 1e-9 for x in hs):
            warnings.warn(
                f"{where}: EULUMDAT luminous area with unequal side heights {hs} m: modelled flat "
                "(its luminous sides ignored); override it with the width/length/height properties",
                stacklevel=2,
            )
            hh = 0.0
        if wa <= 0:
            return Opening("cylinder" if hh > 0 else "disk", la, la, hh)
        return Opening("box" if hh > 0 else "rectangle", la, wa, hh)
    return None


# ---------------------------------------------------------------------------------------------
# Mitsuba glue.
# ---------------------------------------------------------------------------------------------

_CLASSES = {}


def register(jit_flags=True):
    """Registers the emitter ``"gonio"`` for Mitsuba's current variant (call after
    ``mi.set_variant``; again after changing variant). In JIT variants ``jit_flags=True`` turns
    off ``dr.JitFlag.SymbolicCalls`` and ``dr.JitFlag.SymbolicLoops`` (the emitter evaluates its
    inputs through numpy, which symbolic recording forbids)."""
    import drjit as dr
    import mitsuba as mi

    variant = mi.variant()
    if variant is None:
        raise RuntimeError("gonio.mitsuba.register(): set a Mitsuba variant first (mi.set_variant)")
    if "rgb" not in variant:
        raise RuntimeError(f"gonio.mitsuba supports the RGB variants (scalar_rgb, llvm_ad_rgb, ...), not {variant}")
    if jit_flags and not variant.startswith("scalar"):
        dr.set_flag(dr.JitFlag.SymbolicCalls, False)
        dr.set_flag(dr.JitFlag.SymbolicLoops, False)
    if variant not in _CLASSES:
        _CLASSES[variant] = _make_class(mi, dr, variant.startswith("scalar"))
    cls = _CLASSES[variant]
    mi.register_emitter("gonio", lambda props: cls(props))
    return cls


def _np(v):
    """A Mitsuba value as float64 (n,); an unset (empty) field reads as one 0."""
    a = np.asarray(v, dtype=np.float64).reshape(-1)
    return a if a.size else np.zeros(1)


def _vec(v):
    x, y, z = np.broadcast_arrays(_np(v.x), _np(v.y), _np(v.z))
    return np.stack([x, y, z], axis=1)


def _pt2(v):
    x, y = np.broadcast_arrays(_np(v.x), _np(v.y))
    return np.stack([x, y], axis=1)


def _mask(a, n):
    return np.broadcast_to(np.asarray(a, dtype=bool).reshape(-1), (n,))


def _make_class(mi, dr, scalar):
    if scalar:
        def F(a):
            return float(a[0])

        def B(a):
            return bool(a[0])
    else:
        def F(a):
            return mi.Float(np.ascontiguousarray(a, dtype=np.float32))

        def B(a):
            return mi.Bool(np.ascontiguousarray(a, dtype=bool))

    def V3(a):
        return mi.Vector3f(F(a[:, 0]), F(a[:, 1]), F(a[:, 2]))

    def P3(a):
        return mi.Point3f(F(a[:, 0]), F(a[:, 1]), F(a[:, 2]))

    def N3(a):
        return mi.Normal3f(F(a[:, 0]), F(a[:, 1]), F(a[:, 2]))

    def P2(a):
        return mi.Point2f(F(a[:, 0]), F(a[:, 1]))

    def C3(a):
        return mi.Color3f(F(a))

    def _position_sample(p, n, uv, time, pdf, delta):
        ps = mi.PositionSample3f()
        ps.p, ps.n, ps.uv, ps.time, ps.pdf, ps.delta = P3(p), N3(n), P2(uv), time, F(pdf), B(delta)
        return ps

    class GonioEmitter(mi.Emitter):
        """Mitsuba emitter "gonio": see the module gonio.mitsuba."""

        def __init__(self, props):
            super().__init__(props)
            name = props.get("filename", None)
            if name is None:
                raise ValueError('gonio emitter: the property "filename" (an .ies or .ldt file) is required')
            resolver = mi.file_resolver() if hasattr(mi, "file_resolver") else mi.Thread.thread().file_resolver()
            path = str(resolver.resolve(str(name)))
            self.filename = path
            self.diagram = _read(path)
            self.sampler = self.diagram.sampler("hds", "sphere")
            self.scale = float(props.get("scale", 1.0))
            if not (self.scale >= 0.0 and math.isfinite(self.scale)):
                raise ValueError(f"gonio emitter {path}: scale must be finite and >= 0, not {self.scale}")
            m = np.array(props.get("to_world", mi.ScalarTransform4f()).matrix, dtype=np.float64)
            self.to_world_matrix = m
            self.R, self.t = m[:3, :3].copy(), m[:3, 3].copy()
            self.R_inv = np.linalg.inv(self.R)
            self.shape_kind = str(props.get("shape", "point"))
            dims = {k: float(props[k]) if k in props else None for k in ("width", "length", "height")}
            part = int(props.get("part", -1))
            if self.shape_kind == "point":
                self.opening = None
                self.part = None
                self.m_flags = mi.EmitterFlags.DeltaPosition
            elif self.shape_kind == "opening":
                self.opening = opening(self.diagram, where=path, **dims)
                if self.opening is None:
                    raise ValueError(f"{path}: the file gives no luminous opening (a point); set width/length/height")
                if not np.allclose(self.R.T @ self.R, np.eye(3), atol=1e-5):
                    raise ValueError(f"gonio emitter {path}: an opening's to_world must be rigid (rotation and "
                                     "translation); size it with width/length/height")
                if not 0 <= part < len(self.opening.parts):
                    raise ValueError(
                        f"gonio emitter {path}: shape 'opening' lives on the opening's Mitsuba shapes; build "
                        "them with gonio.mitsuba.luminaire(filename, shape='opening', ...)"
                    )
                self.part = self.opening.parts[part]
                self.m_flags = mi.EmitterFlags.Surface
            else:
                raise ValueError(f"gonio emitter {path}: shape must be 'point' or 'opening', not {self.shape_kind!r}")
            self.part_index = part

        def _ptr(self):
            return self if scalar else mi.EmitterPtr(self)

        # -- helpers in numpy ------------------------------------------------------------------

        def _local_dir(self, w):
            d = w @ self.R_inv.T
            return d / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-300)

        def _world_dir(self, d):
            w = d @ self.R.T
            return w / np.maximum(np.linalg.norm(w, axis=1, keepdims=True), 1e-300)

        def _intensity(self, d):
            """scale × I(d) in cd at local unit directions d; 0 for zero (unset) directions."""
            ok = np.isfinite(d).all(axis=1) & ((d * d).sum(axis=1) > 0.5)
            if ok.all():
                return self.scale * self.diagram.intensity(d)
            out = np.zeros(len(d))
            if ok.any():
                out[ok] = self.scale * self.diagram.intensity(d[ok])
            return out

        def _radiance(self, x, d):
            """L(x, ω) of this part at local points x toward local directions d (unit)."""
            a = self.opening.projected_area(d)
            i = self._intensity(d)
            ok = a > 1e-9 * self.opening.area
            L = np.where(ok, i / np.where(ok, a, 1.0), 0.0)
            if not self.part.two_sided:
                L = np.where((self.part.normal(x) * d).sum(1) > 0.0, L, 0.0)
            return L

        # -- Mitsuba's interface ---------------------------------------------------------------

        def sample_ray(self, time, sample1, sample2, sample3, active=True):
            u = _pt2(sample3)
            s2 = _pt2(sample2)
            n = max(len(u), len(s2))
            u, s2 = np.broadcast_to(u, (n, 2)), np.broadcast_to(s2, (n, 2))
            d, pdf = self.sampler.sample(np.ascontiguousarray(np.clip(u, 0.0, 1.0)))
            i = self._intensity(d)
            w = np.where(pdf > 0, i / np.where(pdf > 0, pdf, 1.0), 0.0)
            if self.opening is None:
                o = np.broadcast_to(self.t, (n, 3))
            else:
                pp = self.part.proj(d)
                a = self.opening.projected_area(d)
                w = np.where(a > 0, w * pp / np.where(a > 0, a, 1.0), 0.0)
                x = self.part.sample_proj(d, s2)
                o = x @ self.R.T + self.t
            dw = self._world_dir(d)
            if self.opening is not None:  # leave the emitting surface
                o = o + dw * (1e-5 * (1.0 + np.abs(o).max(axis=1, keepdims=True)))
            w = np.where(_mask(active, n), w, 0.0)
            ray = mi.Ray3f(P3(o), V3(dw), F(np.broadcast_to(_np(time), (n,))))
            return ray, C3(w)

        def sample_direction(self, it, sample, active=True):
            p = _vec(it.p)
            s = _pt2(sample)
            n = max(len(p), len(s))
            p, s = np.broadcast_to(p, (n, 3)), np.broadcast_to(s, (n, 2))
            if self.opening is None:
                x = np.broadcast_to(self.t, (n, 3))
                nrm = np.zeros((n, 3))
            else:
                xl = self.part.sample_area(s)
                x = xl @ self.R.T + self.t
                nrm = self.part.normal(xl) @ self.R.T
            dv = x - p
            dist = np.linalg.norm(dv, axis=1)
            ok = dist > 0
            dist_s = np.where(ok, dist, 1.0)
            dn = dv / dist_s[:, None]
            dl = self._local_dir(-dn)
            if self.opening is None:
                w = self._intensity(dl) / (dist_s * dist_s)
                pdf = np.ones(n)
                delta = np.ones(n, dtype=bool)
            else:
                c = np.abs((nrm * dn).sum(1))
                ok &= c > 0
                pdf = np.where(ok, dist_s * dist_s / (np.where(ok, c, 1.0) * self.part.area), 0.0)
                L = self._radiance(xl, dl)
                w = np.where(ok, L / np.where(ok, pdf, 1.0), 0.0)
                delta = np.zeros(n, dtype=bool)
            w = np.where(ok & _mask(active, n), w, 0.0)
            ds = mi.DirectionSample3f(
                p=P3(x), n=N3(nrm), uv=P2(s), time=F(np.broadcast_to(_np(it.time), (n,))), pdf=F(pdf),
                delta=B(delta), d=V3(dn), dist=F(dist), emitter=self._ptr(),
            )
            return ds, C3(w)

        def pdf_direction(self, it, ds, active=True):
            if self.opening is None:
                return F(np.zeros(len(_np(ds.dist))))
            d = _vec(ds.d)
            nrm = _vec(ds.n)
            dist = _np(ds.dist)
            n = max(len(d), len(nrm), len(dist))
            c = np.abs((np.broadcast_to(nrm, (n, 3)) * np.broadcast_to(d, (n, 3))).sum(1))
            dist = np.broadcast_to(dist, (n,))
            ok = (c > 0) & _mask(active, n)
            return F(np.where(ok, dist * dist / (np.where(ok, c, 1.0) * self.part.area), 0.0))

        def eval_direction(self, it, ds, active=True):
            d = _vec(ds.d)
            dist = _np(ds.dist)
            n = max(len(d), len(dist))
            d, dist = np.broadcast_to(d, (n, 3)), np.broadcast_to(dist, (n,))
            dl = self._local_dir(-d)
            if self.opening is None:
                w = self._intensity(dl) / np.maximum(dist * dist, 1e-300)
            else:
                xl = (np.broadcast_to(_vec(ds.p), (n, 3)) - self.t) @ self.R
                w = self._radiance(xl, dl)
            return C3(np.where(_mask(active, n), w, 0.0))

        def eval(self, si, active=True):
            if self.opening is None:
                return C3(np.zeros(len(_np(si.t))))
            wo = _vec(si.to_world(si.wi))
            xw = _vec(si.p)
            n = max(len(wo), len(xw))
            wo, xw = np.broadcast_to(wo, (n, 3)), np.broadcast_to(xw, (n, 3))
            xl = (xw - self.t) @ self.R
            L = self._radiance(xl, self._local_dir(wo))
            return C3(np.where(_mask(active, n), L, 0.0))

        def sample_position(self, time, sample, active=True):
            s = _pt2(sample)
            n = len(s)
            tt = F(np.broadcast_to(_np(time), (n,)))
            if self.opening is None:
                ps = _position_sample(np.broadcast_to(self.t, (n, 3)), np.zeros((n, 3)), s, tt, np.ones(n),
                                      np.ones(n, dtype=bool))
                return ps, F(np.ones(n))
            xl = self.part.sample_area(s)
            x = xl @ self.R.T + self.t
            nrm = self.part.normal(xl) @ self.R.T
            a = self.part.area
            ps = _position_sample(x, nrm, s, tt, np.full(n, 1.0 / a), np.zeros(n, dtype=bool))
            return ps, F(np.where(_mask(active, n), a, 0.0))

        def pdf_position(self, ps, active=True):
            n = len(_np(ps.pdf))
            return F(np.full(n, 1.0 if self.opening is None else 1.0 / self.part.area))

        def sample_wavelengths(self, si, sample, active=True):
            # Called by the particle tracer's direct view of the emitter, with si.wi the world
            # direction toward the sensor: the radiance there (white).
            wo = _vec(si.wi)
            xw = _vec(si.p)
            n = max(len(wo), len(xw))
            wo, xw = np.broadcast_to(wo, (n, 3)), np.broadcast_to(xw, (n, 3))
            dl = self._local_dir(wo)
            if self.opening is None:
                L = self._intensity(dl)
            else:
                L = self._radiance((xw - self.t) @ self.R, dl)
            return mi.Color0f(), C3(np.where(_mask(active, n), L, 0.0))

        def pdf_wavelengths(self, wavelengths, active=True):
            return mi.Color3f(1.0)

        def bbox(self):
            if self.opening is None:
                return mi.ScalarBoundingBox3f(mi.ScalarPoint3f(*self.t), mi.ScalarPoint3f(*self.t))
            o = self.opening
            half = 0.5 * np.array([o.length, o.width, o.height])
            corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * half
            c = corners @ self.R.T + self.t
            return mi.ScalarBoundingBox3f(mi.ScalarPoint3f(*c.min(0)), mi.ScalarPoint3f(*c.max(0)))

        def traverse(self, callback):
            pass

        def parameters_changed(self, keys=None):
            pass

        def to_string(self):
            what = "point" if self.opening is None else f"{self.opening!r}, part {self.part_index} ({self.part.kind})"
            return (f"GonioEmitter[filename={self.filename!r}, shape={what}, scale={self.scale:g}, "
                    f"flux={self.scale * self.diagram.flux:g} lm]")

    return GonioEmitter


def luminaire(filename, to_world=None, shape="point", scale=1.0, width=None, length=None, height=None,
              name="gonio"):
    """Scene-dict entries for a luminaire: ``{name: {"type": "gonio", ...}}`` for a point;
    for ``shape="opening"`` one Mitsuba shape per part of the opening (``name_0``, ...), each
    carrying its ``"gonio"`` emitter. Merge them into the scene dict (``scene.update(...)``).
    ``to_world`` is a Mitsuba transform (rigid for an opening); the variant must be set."""
    import mitsuba as mi

    T = to_world if to_world is not None else mi.ScalarTransform4f()
    em = {"type": "gonio", "filename": str(filename), "to_world": T, "scale": float(scale)}
    dims = {}
    for k, v in (("width", width), ("length", length), ("height", height)):
        if v is not None:
            dims[k] = float(v)
    em.update(dims)
    if shape == "point":
        return {name: em}
    if shape != "opening":
        raise ValueError(f"shape must be 'point' or 'opening', not {shape!r}")
    o = opening(_read(str(filename)), where=str(filename), **dims)
    if o is None:
        raise ValueError(f"{filename}: the file gives no luminous opening (a point); set width/length/height")
    Tm = np.array(T.matrix, dtype=np.float64)
    out = {}
    for k, part in enumerate(o.parts):
        m = Tm @ part.mitsuba_matrix()
        e = dict(em, shape="opening", part=k)
        out[f"{name}_{k}"] = {
            "type": part.kind,
            "to_world": mi.ScalarTransform4f(m.tolist()),
            "emitter": e,
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.0, 0.0, 0.0]}},
        }
    return out
