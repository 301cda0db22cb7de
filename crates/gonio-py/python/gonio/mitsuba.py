"""gonio inside Mitsuba 3: IES LM-63 and EULUMDAT luminaires and environment maps as Mitsuba
emitters, and tabulated BRDFs as a Mitsuba BSDF (docs/MITSUBA.md).

``register()`` registers the emitter plugins ``"gonio"`` and ``"gonio_envmap"`` and the BSDF
``"gonio_brdf"`` for the current Mitsuba variant::

    import mitsuba as mi, gonio.mitsuba
    mi.set_variant("llvm_ad_rgb")
    gonio.mitsuba.register()
    scene = mi.load_dict({..., "lamp": {"type": "gonio", "filename": "lamp.ies",
                                        "to_world": mi.ScalarTransform4f().translate([0, 0, 8])},
                          "sky": {"type": "gonio_envmap", "filename": "sky.hdr"}})

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

Properties of ``{"type": "gonio_envmap", ...}`` (an environment light, like Mitsuba's ``envmap``):

* ``filename`` (string): a lat-long .hdr, .exr or .pfm image of radiance;
* ``to_world`` (transform): as Mitsuba's ``envmap`` (its local frame Y-up: the image's top row
  along local +y, its centre column along local +z), so the same ``to_world`` places the same
  image the same way; gonio's frame (x, y, z) is that local frame's (y, z, x) (docs/ENVMAPS.md);
* ``scale`` (float, default 1): multiplies the radiance;
* ``weight`` (string, default ``"luminance"``): what the sampling density follows (``luminance``,
  ``red``, ``green``, ``blue``; or 0, 1, 2);
* ``lookup`` (string, default ``"nearest"``): the radiance, the pixel holding the direction or
  ``"bilinear"`` between pixel centres (the interpolant the density follows);
* ``mis_compensation`` (bool, default false): sample the weight minus its mean (for MIS only).

Properties of ``{"type": "gonio_brdf", ...}`` (a measured material; docs/MITSUBA.md):

* ``filename`` (string): a MERL ``.binary``, UTIA ``.bin`` or gonio BRDF JSON table (by content);
* ``scale`` (float, default 1): multiplies f_r;
* ``merl_theta``, ``merl_phi`` (integers, default 46, 90): a MERL file's resampling grid;
* ``theta_o``, ``phi_o``, ``force_resample``: the slices' outgoing grid, as ``Brdf.sampler``;
* ``sampling`` (``"hds"`` default, or ``"cosine"``): the exact blended slice map, or a cosine lobe.

The table's frame is the shading frame (z the normal, x ``si.sh_frame.s``); its incident direction
is ``si.wi``; ``eval`` is f_r·cos θ_o; one-sided (front side only), glossy reflection.

Sampling: directions by gonio's Havran–Dmitriev–Seidel map (the file's diagram, the image's
weight) with the exact pdf, run in Dr.Jit operations over the map's float32 tables
(``gonio.drjit.Tables``, loaded once at scene load); positions on an opening uniformly on its
projection in the sampled direction (``sample_ray``) or uniformly by area (``sample_direction``,
``sample_position``); an environment's rays (``sample_ray``) start on a disk of the scene's
bounding sphere, as Mitsuba's ``envmap``.

Every per-call method is written in Dr.Jit operations (no numpy, no evaluation), so the emitters
trace into Mitsuba's symbolic calls and loops (megakernels) in ``llvm_*``/``cuda_*`` variants and
run as Python scalars in ``scalar_*`` ones; ``register()`` touches no JIT flag.
"""

import math
import os
import warnings
from typing import Any, Dict, Optional, Tuple, Union

import numpy as np

from . import read as _read

__all__ = ["register", "prepare", "classes", "luminaire", "opening", "Opening"]

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
        self.area = float((math.pi if round_ else 4.0) * lu * lv)
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

    # Dr.Jit forms (per call: the same formulas on Mitsuba's arrays, `K` = the variant's kit).
    def dr_normal(self, K, x):
        return K.mi.Vector3f(*(float(a) for a in self.n))

    def dr_sample_area(self, K, s):
        dr = K.dr
        if self.round:
            r = dr.sqrt(s.x)
            sn, cs = dr.sincos(2.0 * math.pi * s.y)
            p, q = r * cs, r * sn
        else:
            p, q = 2.0 * s.x - 1.0, 2.0 * s.y - 1.0
        return K.mi.Vector3f(*(float(c) + p * float(a) + q * float(b) for c, a, b in zip(self.c, self.u, self.v)))

    def dr_proj(self, K, w):
        c = K.dot(self.n, w)
        return self.area * (K.dr.abs(c) if self.two_sided else K.dr.maximum(c, 0.0))

    def dr_sample_proj(self, K, w, s):
        return self.dr_sample_area(K, s)

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
        self.r, self.h = float(r), float(h)
        self.area = 2.0 * math.pi * self.r * self.h

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

    def dr_normal(self, K, x):
        dr = K.dr
        rho = dr.sqrt(x.x * x.x + x.y * x.y)
        rho = dr.select(rho > 0, rho, 1.0)
        return K.mi.Vector3f(x.x / rho, x.y / rho, 0.0)

    def _dr_point(self, K, phi, s1):
        sn, cs = K.dr.sincos(phi)
        return K.mi.Vector3f(self.r * cs, self.r * sn, (s1 - 0.5) * self.h)

    def dr_sample_area(self, K, s):
        return self._dr_point(K, 2.0 * math.pi * s.x, s.y)

    def dr_proj(self, K, w):
        return 2.0 * self.r * self.h * K.dr.sqrt(w.x * w.x + w.y * w.y)

    def dr_sample_proj(self, K, w, s):
        dr = K.dr
        a = dr.asin(dr.clip(2.0 * s.x - 1.0, -1.0, 1.0))
        return self._dr_point(K, dr.atan2(w.y, w.x) + a, s.y)

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
        self.r = float(r)
        self.area = 4.0 * math.pi * self.r * self.r

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

    def dr_normal(self, K, x):
        dr = K.dr
        n = dr.norm(x)
        return x / dr.select(n > 0, n, 1.0)

    def dr_sample_area(self, K, s):
        dr = K.dr
        z = 1.0 - 2.0 * s.x
        rho = dr.sqrt(dr.maximum(0.0, 1.0 - z * z))
        sn, cs = dr.sincos(2.0 * math.pi * s.y)
        return K.mi.Vector3f(self.r * rho * cs, self.r * rho * sn, self.r * z)

    def dr_proj(self, K, w):
        return math.pi * self.r * self.r

    def dr_sample_proj(self, K, w, s):
        dr, mi = K.dr, K.mi
        big = dr.abs(w.x) < 0.9
        e1 = mi.Vector3f(dr.select(big, 1.0, 0.0), dr.select(big, 0.0, 1.0), 0.0)
        e1 = e1 - dr.dot(e1, w) * w
        e1 = dr.normalize(e1)
        e2 = dr.cross(w, e1)
        rho = dr.sqrt(s.x)
        sn, cs = dr.sincos(2.0 * math.pi * s.y)
        h = dr.sqrt(dr.maximum(0.0, 1.0 - rho * rho))
        return self.r * (rho * (cs * e1 + sn * e2) + h * w)

    def mitsuba_matrix(self):
        return np.diag([self.r, self.r, self.r, 1.0])


class Opening:
    """A luminous opening: ``kind`` ("rectangle", "disk", "box", "cylinder", "sphere"), its
    dimensions in metres (``length`` along local x = C0–C180, ``width`` along y = C90–C270,
    ``height`` along z; a disk's or cylinder's diameter in ``length`` and ``width``, a sphere's in
    all three), and its ``parts`` (the surfaces that emit), centred on the photometric centre."""

    def __init__(self, kind: str, length: float, width: float, height: float) -> None:
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

    def projected_area(self, w: Any) -> Any:
        """A_proj(ω) in m² for local unit directions ``w`` (n, 3)."""
        w = np.asarray(w, dtype=np.float64).reshape(-1, 3)
        return sum(p.proj(w) for p in self.parts)

    def dr_projected_area(self, K, w):
        """A_proj(ω) for a Dr.Jit Vector3f of local unit directions (per call)."""
        out = None
        for p in self.parts:
            a = p.dr_proj(K, w)
            out = a if out is None else out + a
        return out

    def __repr__(self) -> str:
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


def opening(diagram: Any, width: Optional[float] = None, length: Optional[float] = None,
            height: Optional[float] = None, where: str = "luminaire") -> Optional["Opening"]:
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


def register(jit_flags: bool = True) -> Any:
    """Registers the emitters ``"gonio"`` and ``"gonio_envmap"`` and the BSDF ``"gonio_brdf"`` for
    Mitsuba's current variant (call after ``mi.set_variant``; again after changing variant).
    Returns the ``"gonio"`` class (``classes()`` returns all three).

    ``jit_flags`` is accepted for compatibility and does nothing: the emitters are written in
    Dr.Jit operations (``gonio.drjit``) and run inside Mitsuba's symbolic calls and loops, so no
    JIT flag is touched (versions before this one turned off ``dr.JitFlag.SymbolicCalls`` and
    ``SymbolicLoops``)."""
    import drjit as dr
    import mitsuba as mi

    del jit_flags  # does nothing (see above)
    variant = mi.variant()
    if variant is None:
        raise RuntimeError("gonio.mitsuba.register(): set a Mitsuba variant first (mi.set_variant)")
    if "rgb" not in variant:
        raise RuntimeError(f"gonio.mitsuba supports the RGB variants (scalar_rgb, llvm_ad_rgb, ...), not {variant}")
    if variant not in _CLASSES:
        _CLASSES[variant] = _make_classes(mi, dr, variant.startswith("scalar")) + \
            (_make_bsdf(mi, dr, variant.startswith("scalar")),)
    lum, env, brdf = _CLASSES[variant]
    mi.register_emitter("gonio", lambda props: lum(props))
    mi.register_emitter("gonio_envmap", lambda props: env(props))
    mi.register_bsdf("gonio_brdf", lambda props: brdf(props))
    return lum


DEFAULT_RADIUS = 1e5
"""gonio_envmap's bounding-sphere radius (metres) before ``prepare(scene)``: large enough for the
shadow rays of next-event estimation in any ordinary scene; light tracing needs ``prepare``."""


def prepare(scene: Any) -> Any:
    """Tells each ``gonio_envmap`` emitter of ``scene`` the scene's bounding sphere (what Mitsuba's
    ``envmap`` learns from ``set_scene``, which Mitsuba does not call on Python emitters). Needed
    for light tracing (``ptracer``, ``scene.sample_emitter_ray``): its rays start on a disk of that
    sphere. Path tracing works without it. Returns ``scene``."""
    for e in scene.emitters():
        if getattr(e, "is_gonio_envmap", False):
            e.set_scene(scene)
    return scene


def classes() -> Tuple[Any, Any, Any]:
    """The (``"gonio"``, ``"gonio_envmap"``, ``"gonio_brdf"``) classes of the current variant
    (registers them)."""
    import mitsuba as mi

    register()
    return _CLASSES[mi.variant()]


class _Kit:
    """What the per-call code needs: the variant's modules and small helpers on Python-float
    matrices (load-time constants, so that the kernels hold them as literals)."""

    def __init__(self, mi, dr, scalar):
        self.mi, self.dr, self.scalar = mi, dr, scalar

    @staticmethod
    def _row(r, x, y, z):
        out = None
        for c, v in zip(r, (x, y, z)):
            if c == 0.0:
                continue
            t = v if c == 1.0 else (-v if c == -1.0 else c * v)
            out = t if out is None else out + t
        return 0.0 if out is None else out

    def lin(self, m, v):
        """The 3 × 3 matrix m (Python floats) times the vector v."""
        return self.mi.Vector3f(*(self._row(r, v.x, v.y, v.z) for r in m))

    def dot(self, n, v):
        """A constant vector n (Python floats) dot v."""
        return self._row(n, v.x, v.y, v.z)

    def full(self, like, value):
        """A Float of `like`'s width holding `value` (a Python float in scalar variants)."""
        if self.scalar:
            return float(value)
        return self.dr.full(self.mi.Float, value, self.dr.width(like))

    def safe_div(self, a, b):
        """a / b where b ≠ 0, else 0 (no division by zero, in Python floats either)."""
        ok = b != 0
        return self.dr.select(ok, a / self.dr.select(ok, b, 1.0), 0.0)


def _mat(m):
    return [[float(v) for v in row] for row in np.asarray(m, dtype=np.float64)]


def _resolve(mi, name):
    resolver = mi.file_resolver() if hasattr(mi, "file_resolver") else mi.Thread.thread().file_resolver()
    return str(resolver.resolve(str(name)))


def _file_and_scale(mi, props, plugin, kinds):
    """A plugin's two common properties: the required ``filename`` (resolved by Mitsuba's file
    resolver; ``kinds`` words what it may be) and ``scale`` (default 1, finite and >= 0)."""
    name = props.get("filename", None)
    if name is None:
        raise ValueError(f'{plugin}: the property "filename" ({kinds}) is required')
    path = _resolve(mi, name)
    scale = float(props.get("scale", 1.0))
    if not (scale >= 0.0 and math.isfinite(scale)):
        raise ValueError(f"{plugin} {path}: scale must be finite and >= 0, not {scale}")
    return path, scale


_TABLES = {}
_TABLES_MAX = 8


def _cached(cache, key, make):
    """`cache[key]`, made by `make()` on a miss; the oldest entry goes beyond _TABLES_MAX."""
    hit = cache.get(key)
    if hit is None:
        hit = cache[key] = make()
        while len(cache) > _TABLES_MAX:
            cache.pop(next(iter(cache)))
    return hit


def _luminaire_tables(mi, path):
    """(diagram, sampler, gonio.drjit.Tables) of a photometric file for the current variant, cached
    by (variant, path, modification time); the least recently made entry goes beyond 8."""
    from . import drjit as gdr

    def make():
        diagram = _read(path)
        sampler = diagram.sampler("hds", "sphere")
        tables = gdr.Tables(gdr.blob_of(sampler, path), mi)
        if tables.target_kind != 1:
            raise ValueError(f"gonio emitter {path}: the table blob has no grid target")
        return diagram, sampler, tables

    return _cached(_TABLES, (mi.variant(), path, os.path.getmtime(path)), make)


def _make_classes(mi, dr, scalar):
    from . import drjit as gdr
    from . import EnvMap

    K = _Kit(mi, dr, scalar)

    class GonioEmitter(mi.Emitter):
        """Mitsuba emitter "gonio": see the module gonio.mitsuba."""

        def __init__(self, props):
            super().__init__(props)
            path, self.scale = _file_and_scale(mi, props, "gonio emitter", "an .ies or .ldt file")
            self.filename = path
            # The diagram, its map and the map's tables on the device: shared by the emitters of one
            # file (an opening's parts) through a small cache.
            self.diagram, self.sampler, self.tables = _luminaire_tables(mi, path)
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
            self._R, self._Rinv, self._t = _mat(self.R), _mat(self.R_inv), [float(v) for v in self.t]

        def _ptr(self):
            return self if scalar else mi.EmitterPtr(self)

        # -- numpy helpers (kept for subclasses written against earlier versions) -----------------

        def _local_dir(self, w):
            d = w @ self.R_inv.T
            return d / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-300)

        def _world_dir(self, d):
            w = d @ self.R.T
            return w / np.maximum(np.linalg.norm(w, axis=1, keepdims=True), 1e-300)

        def _intensity(self, d):
            """scale × I(d) in cd at local unit directions d (numpy, float64)."""
            ok = np.isfinite(d).all(axis=1) & ((d * d).sum(axis=1) > 0.5)
            out = np.zeros(len(d))
            if ok.any():
                out[ok] = self.scale * self.diagram.intensity(d[ok])
            return out

        # -- Dr.Jit helpers (per call) -----------------------------------------------------------

        def _dr_local(self, w):
            """World vector → local unit direction (NaN for a zero vector)."""
            return dr.normalize(K.lin(self._Rinv, w))

        def _dr_world(self, d):
            return dr.normalize(K.lin(self._R, d))

        def _dr_local_point(self, p):
            return K.lin(self._Rinv, mi.Vector3f(p.x - self._t[0], p.y - self._t[1], p.z - self._t[2]))

        def _dr_world_point(self, x):
            v = K.lin(self._R, x)
            return mi.Point3f(v.x + self._t[0], v.y + self._t[1], v.z + self._t[2])

        def _dr_intensity(self, d):
            """scale × I(d) at local unit directions d (0 where d is not finite)."""
            i = self.tables.target(d)
            ok = dr.isfinite(d.x) & dr.isfinite(d.y) & dr.isfinite(d.z)
            return dr.select(ok, self.scale * i, 0.0)

        def _dr_radiance(self, x, d):
            """L(x, ω) of this part at local points x toward local unit directions d."""
            a = self.opening.dr_projected_area(K, d)
            i = self._dr_intensity(d)
            ok = a > 1e-9 * self.opening.area
            L = dr.select(ok, i / dr.select(ok, a, 1.0), 0.0)
            if not self.part.two_sided:
                L = dr.select(dr.dot(self.part.dr_normal(K, x), d) > 0.0, L, 0.0)
            return L

        # -- Mitsuba's interface ---------------------------------------------------------------

        def sample_ray(self, time, sample1, sample2, sample3, active=True):
            u = mi.Point2f(dr.clip(sample3.x, 0.0, 1.0), dr.clip(sample3.y, 0.0, 1.0))
            d, pdf = self.tables.sample(u)
            w = K.safe_div(self._dr_intensity(d), dr.select(pdf > 0, pdf, 0.0))
            dw = self._dr_world(d)
            if self.opening is None:
                o = mi.Point3f(*self._t)
            else:
                pp = self.part.dr_proj(K, d)
                a = self.opening.dr_projected_area(K, d)
                w = dr.select(a > 0, w * K.safe_div(pp, a), 0.0)
                o = self._dr_world_point(self.part.dr_sample_proj(K, d, sample2))
                # leave the emitting surface
                big = dr.maximum(dr.maximum(dr.abs(o.x), dr.abs(o.y)), dr.abs(o.z))
                o = o + dw * (1e-5 * (1.0 + big))
            w = dr.select(active, w, 0.0)
            return mi.Ray3f(o, dw, time), mi.Color3f(w)

        def sample_direction(self, it, sample, active=True):
            if self.opening is None:
                x = mi.Point3f(*self._t)
                nrm = mi.Vector3f(0.0, 0.0, 0.0)
            else:
                xl = self.part.dr_sample_area(K, sample)
                x = self._dr_world_point(xl)
                nrm = K.lin(self._R, self.part.dr_normal(K, xl))
            dv = x - it.p
            dist = dr.norm(dv)
            ok = dist > 0
            dist_s = dr.select(ok, dist, 1.0)
            dn = dv / dist_s
            dl = self._dr_local(-dn)
            if self.opening is None:
                w = self._dr_intensity(dl) / (dist_s * dist_s)
                pdf = K.full(dist, 1.0)
                delta = True
            else:
                c = dr.abs(dr.dot(nrm, dn))
                ok = ok & (c > 0)
                pdf = dr.select(ok, dist_s * dist_s / (dr.select(ok, c, 1.0) * self.part.area), 0.0)
                L = self._dr_radiance(xl, dl)
                w = dr.select(ok, L / dr.select(ok, pdf, 1.0), 0.0)
                delta = False
            w = dr.select(ok & active, w, 0.0)
            ds = mi.DirectionSample3f()
            ds.p, ds.n, ds.uv, ds.time = x, mi.Normal3f(nrm), mi.Point2f(sample), it.time
            ds.pdf = pdf
            ds.delta = mi.Bool(delta) if scalar else dr.full(mi.Bool, delta, dr.width(dist))
            ds.d, ds.dist, ds.emitter = dn, dist, self._ptr()
            return ds, mi.Color3f(w)

        def pdf_direction(self, it, ds, active=True):
            if self.opening is None:
                return K.full(ds.dist, 0.0)
            c = dr.abs(dr.dot(ds.n, ds.d))
            ok = (c > 0) & active
            return dr.select(ok, ds.dist * ds.dist / (dr.select(ok, c, 1.0) * self.part.area), 0.0)

        def eval_direction(self, it, ds, active=True):
            dl = self._dr_local(-ds.d)
            if self.opening is None:
                w = K.safe_div(self._dr_intensity(dl), ds.dist * ds.dist)
            else:
                w = self._dr_radiance(self._dr_local_point(ds.p), dl)
            return mi.Color3f(dr.select(active, w, 0.0))

        def eval(self, si, active=True):
            if self.opening is None:
                return mi.Color3f(K.full(si.t, 0.0))
            wo = si.to_world(si.wi)
            L = self._dr_radiance(self._dr_local_point(si.p), self._dr_local(wo))
            return mi.Color3f(dr.select(active, L, 0.0))

        def sample_position(self, time, sample, active=True):
            ps = mi.PositionSample3f()
            ps.uv, ps.time = mi.Point2f(sample), time
            if self.opening is None:
                ps.p = mi.Point3f(*self._t)
                ps.n = mi.Normal3f(0.0, 0.0, 0.0)
                ps.pdf = K.full(sample.x, 1.0)
                ps.delta = mi.Bool(True) if scalar else dr.full(mi.Bool, True, dr.width(sample.x))
                return ps, dr.select(active, K.full(sample.x, 1.0), 0.0)
            xl = self.part.dr_sample_area(K, sample)
            ps.p = self._dr_world_point(xl)
            ps.n = mi.Normal3f(K.lin(self._R, self.part.dr_normal(K, xl)))
            a = self.part.area
            ps.pdf = K.full(sample.x, 1.0 / a)
            ps.delta = mi.Bool(False) if scalar else dr.full(mi.Bool, False, dr.width(sample.x))
            return ps, dr.select(active, K.full(sample.x, a), 0.0)

        def pdf_position(self, ps, active=True):
            return K.full(ps.pdf, 1.0 if self.opening is None else 1.0 / self.part.area)

        def sample_wavelengths(self, si, sample, active=True):
            # Called by the particle tracer's direct view of the emitter, with si.wi the world
            # direction toward the sensor: the radiance there (white).
            dl = self._dr_local(si.wi)
            if self.opening is None:
                L = self._dr_intensity(dl)
            else:
                L = self._dr_radiance(self._dr_local_point(si.p), dl)
            return mi.Color0f(), mi.Color3f(dr.select(active, L, 0.0))

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

    # gonio's frame (x, y, z) is Mitsuba's envmap local frame (y, z, x) (docs/ENVMAPS.md).
    P = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])
    ray_eps = float(mi.math.RayEpsilon)

    class GonioEnvMapEmitter(mi.Emitter):
        """Mitsuba emitter "gonio_envmap": see the module gonio.mitsuba."""

        is_gonio_envmap = True

        def __init__(self, props):
            super().__init__(props)
            path, self.scale = _file_and_scale(mi, props, "gonio_envmap emitter", ".hdr, .exr or .pfm")
            self.filename = path
            weight = props.get("weight", "luminance")
            weight = {0: "red", 1: "green", 2: "blue"}.get(weight, weight) if isinstance(weight, int) else str(weight)
            if weight not in ("luminance", "red", "green", "blue"):
                raise ValueError(f"gonio_envmap {path}: weight must be luminance, red, green or blue, not {weight!r}")
            lookup = str(props.get("lookup", "nearest"))
            if lookup not in ("nearest", "bilinear"):
                raise ValueError(f"gonio_envmap {path}: lookup must be nearest or bilinear, not {lookup!r}")
            mis = bool(props.get("mis_compensation", False))
            self.weight, self.lookup, self.mis_compensation = weight, lookup, mis
            self.env = EnvMap(path, lookup=lookup, mis_compensation=mis, weight=weight, precision="float32")
            for msg in self.env.warnings:
                warnings.warn(f"gonio_envmap {path}: {msg}", stacklevel=2)
            cli = ["--weight", weight, "--lookup", lookup] + (["--mis-compensation"] if mis else [])
            self.tables = gdr.Tables(gdr.blob_of(self.env, path, cli), mi)
            if self.tables.target_kind != 2:
                raise ValueError(f"gonio_envmap {path}: the table blob has no image target")
            m = np.array(props.get("to_world", mi.ScalarTransform4f()).matrix, dtype=np.float64)
            self.to_world_matrix = m
            W = m[:3, :3] @ P  # gonio → world
            self._W, self._Winv = _mat(W), _mat(np.linalg.inv(W))
            self.m_flags = mi.EmitterFlags.Infinite | mi.EmitterFlags.SpatiallyVarying
            # Mitsuba does not call set_scene on Python emitters: until gonio.mitsuba.prepare(scene)
            # does, a sphere of radius DEFAULT_RADIUS about the origin stands for the scene's.
            self.scene_attached = False
            self._set_sphere([0.0, 0.0, 0.0], DEFAULT_RADIUS)

        def _set_sphere(self, center, radius):
            self._center = [float(c) for c in center]
            self._radius = float(radius)
            if not scalar:
                self._radius_v = mi.Float(self._radius)
                self._center_v = mi.Point3f(*self._center)
                dr.make_opaque(self._radius_v, self._center_v)
            else:
                self._radius_v, self._center_v = self._radius, mi.Point3f(*self._center)

        def set_scene(self, scene):
            """The scene's bounding sphere, as Mitsuba's envmap (called by gonio.mitsuba.prepare)."""
            self.scene_attached = True
            bbox = scene.bbox()
            if bbox.valid():
                bs = bbox.bounding_sphere()
                self._set_sphere(list(bs.center), max(ray_eps, float(bs.radius) * (1.0 + ray_eps)))
            else:
                self._set_sphere([0.0, 0.0, 0.0], ray_eps)

        def _ptr(self):
            return self if scalar else mi.EmitterPtr(self)

        def _gonio(self, w):
            """World vector → gonio's unit direction."""
            return dr.normalize(K.lin(self._Winv, w))

        def _world(self, g):
            return dr.normalize(K.lin(self._W, g))

        def _radiance(self, g):
            return self.tables.radiance(g) * self.scale

        def sample_direction(self, it, sample, active=True):
            g, pdf = self.tables.sample(sample)
            d = self._world(g)
            radius = dr.maximum(self._radius_v, dr.norm(it.p - self._center_v))
            dist = 2.0 * radius
            ok = active & (pdf > 0)
            ds = mi.DirectionSample3f()
            ds.p, ds.n, ds.uv, ds.time = it.p + d * dist, mi.Normal3f(-d), mi.Point2f(sample), it.time
            ds.pdf = dr.select(ok, pdf, 0.0)
            ds.delta = mi.Bool(False) if scalar else dr.full(mi.Bool, False, dr.width(pdf))
            ds.d, ds.dist, ds.emitter = d, dist, self._ptr()
            w = self._radiance(g) / dr.select(ok, pdf, 1.0)
            return ds, dr.select(ok, w, 0.0)

        def pdf_direction(self, it, ds, active=True):
            return dr.select(active, self.tables.pdf(self._gonio(ds.d)), 0.0)

        def eval(self, si, active=True):
            return dr.select(active, self._radiance(self._gonio(-si.wi)), 0.0)

        def eval_direction(self, it, ds, active=True):
            return dr.select(active, self._radiance(self._gonio(ds.d)), 0.0)

        def sample_ray(self, time, sample1, sample2, sample3, active=True):
            offset = mi.warp.square_to_uniform_disk_concentric(sample2)
            g, pdf = self.tables.sample(sample3)
            d = self._world(g)  # toward the environment; the ray runs the other way
            ok = active & (pdf > 0)
            perp = mi.Frame3f(d).to_world(mi.Vector3f(offset.x, offset.y, 0.0))
            origin = self._center_v + (perp + d) * self._radius_v
            w = self._radiance(g) * (math.pi * self._radius_v * self._radius_v / dr.select(ok, pdf, 1.0))
            return mi.Ray3f(origin, -d, time), dr.select(ok, w, 0.0)

        def sample_wavelengths(self, si, sample, active=True):
            # The particle tracer's direct view: si.wi points from the emitter toward the sensor.
            return mi.Color0f(), dr.select(active, self._radiance(self._gonio(-si.wi)), 0.0)

        def pdf_wavelengths(self, wavelengths, active=True):
            return mi.Color3f(1.0)

        def sample_position(self, time, sample, active=True):
            if scalar:
                raise NotImplementedError("gonio_envmap: sample_position (an infinite emitter has no position)")
            return dr.zeros(mi.PositionSample3f, dr.width(sample.x)), dr.full(mi.Float, math.nan, dr.width(sample.x))

        def pdf_position(self, ps, active=True):
            return K.full(ps.pdf, 0.0)

        def bbox(self):
            return mi.ScalarBoundingBox3f()

        def traverse(self, callback):
            pass

        def parameters_changed(self, keys=None):
            pass

        def to_string(self):
            return (f"GonioEnvMapEmitter[filename={self.filename!r}, {self.tables.width} x {self.tables.height}, "
                    f"weight={self.weight}, lookup={self.lookup}, mis_compensation={self.mis_compensation}, "
                    f"scale={self.scale:g}, bsphere=({self._center}, {self._radius:g})]")

    return GonioEmitter, GonioEnvMapEmitter


def luminaire(filename: Union[str, "os.PathLike[str]"], to_world: Any = None, shape: str = "point",
              scale: float = 1.0, width: Optional[float] = None, length: Optional[float] = None,
              height: Optional[float] = None, name: str = "gonio") -> Dict[str, Any]:
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


_BRDF_TABLES = {}


def _brdf_tables(mi, path, merl_theta, merl_phi, theta_o, phi_o, force_resample):
    """gonio.drjit.BrdfTables of a BRDF file for the current variant, cached by the variant, the
    file (path, modification time) and the options; the least recently made entry goes beyond 8."""
    from . import drjit as gdr
    from . import read_brdf

    def make():
        brdf = read_brdf(path, merl_theta=merl_theta, merl_phi=merl_phi)
        blob = brdf.tables("float32", theta_o=theta_o, phi_o=phi_o, force_resample=force_resample)
        return gdr.BrdfTables(blob, mi)

    key = (mi.variant(), path, os.path.getmtime(path), merl_theta, merl_phi, theta_o, phi_o, force_resample)
    return _cached(_BRDF_TABLES, key, make)


def _make_bsdf(mi, dr, scalar):
    K = _Kit(mi, dr, scalar)

    class GonioBrdf(mi.BSDF):
        """Mitsuba BSDF "gonio_brdf": a tabulated BRDF (MERL, UTIA, gonio BRDF JSON) sampled
        exactly through the HDS map of its slices blended for each incident direction (see the
        module gonio.mitsuba and docs/MITSUBA.md)."""

        def __init__(self, props):
            super().__init__(props)
            self.filename, self.scale = _file_and_scale(
                mi, props, "gonio_brdf", "a MERL, UTIA or gonio BRDF JSON file")
            opts = {}
            for k, d in (("merl_theta", 46), ("merl_phi", 90), ("theta_o", 46), ("phi_o", 90)):
                v = props.get(k, d)
                if int(v) != v or int(v) < 1:
                    raise ValueError(f"gonio_brdf {self.filename}: {k} must be a positive integer, not {v}")
                opts[k] = int(v)
            force = bool(props.get("force_resample", False))
            self.sampling = str(props.get("sampling", "hds"))
            if self.sampling not in ("hds", "cosine"):
                raise ValueError(f'gonio_brdf {self.filename}: sampling must be "hds" or "cosine", '
                                 f"not {self.sampling!r}")
            self.tables = _brdf_tables(mi, self.filename, opts["merl_theta"], opts["merl_phi"],
                                       opts["theta_o"], opts["phi_o"], force)
            self.options = dict(opts, force_resample=force)
            flags = mi.BSDFFlags.GlossyReflection | mi.BSDFFlags.FrontSide
            self.m_flags = flags
            self.m_components = [flags]

        def _cos(self, v):
            return v.z

        def sample(self, ctx, si, sample1, sample2, active=True):
            t = self.tables
            bs = mi.BSDFSample3f()
            if self.sampling == "cosine":
                wo = mi.warp.square_to_cosine_hemisphere(sample2)
                pdf = mi.warp.square_to_cosine_hemisphere_pdf(wo)
                ok = True
            else:
                wo, pdf, ok = t.sample_valid(si.wi, sample2)
            cos_i, cos_o = self._cos(si.wi), self._cos(wo)
            enabled = ctx.is_enabled(mi.BSDFFlags.GlossyReflection)
            valid = active & (cos_i > 0) & (cos_o > 0) & (pdf > 0) & ok & enabled
            f = t.eval(si.wi, wo)
            bs.wo = wo
            bs.pdf = dr.select(valid, pdf, 0.0)
            bs.eta = 1.0
            bs.sampled_type = mi.UInt32(+mi.BSDFFlags.GlossyReflection) if not scalar else \
                int(mi.BSDFFlags.GlossyReflection)
            bs.sampled_component = 0 if scalar else mi.UInt32(0)
            k = K.safe_div(cos_o * self.scale, pdf)
            weight = f * k
            return bs, dr.select(valid, weight, 0.0)

        def eval(self, ctx, si, wo, active=True):
            cos_i, cos_o = self._cos(si.wi), self._cos(wo)
            enabled = ctx.is_enabled(mi.BSDFFlags.GlossyReflection)
            valid = active & (cos_i > 0) & (cos_o > 0) & enabled
            f = self.tables.eval(si.wi, wo) * (cos_o * self.scale)
            return dr.select(valid, f, 0.0)

        def pdf(self, ctx, si, wo, active=True):
            cos_i, cos_o = self._cos(si.wi), self._cos(wo)
            enabled = ctx.is_enabled(mi.BSDFFlags.GlossyReflection)
            valid = active & (cos_i > 0) & (cos_o > 0) & enabled
            if self.sampling == "cosine":
                p = mi.warp.square_to_cosine_hemisphere_pdf(wo)
            else:
                p = self.tables.pdf(si.wi, wo)
            return dr.select(valid, p, 0.0)

        def eval_pdf(self, ctx, si, wo, active=True):
            return self.eval(ctx, si, wo, active), self.pdf(ctx, si, wo, active)

        def traverse(self, callback):
            pass

        def parameters_changed(self, keys=None):
            pass

        def to_string(self):
            t = self.tables
            return (f"GonioBrdf[filename={self.filename!r}, {'anisotropic' if t.anisotropic else 'isotropic'}, "
                    f"{t.channels} channel(s), {t.S} slices of {t.m} x {t.n}, scale={self.scale:g}, "
                    f"sampling={self.sampling}, "
                    f"options={self.options}]")

    return GonioBrdf
