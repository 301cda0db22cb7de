"""Shared by scripts/gpu_prepare.py (here) and scripts/gpu_check.py (on the GPU machine): the
points of the square, the generated diagrams and image, and the light-tracing scene. numpy only.
"""

import math

import numpy as np

# The points of the contract: 16 corner and edge points, then the R2 sequence (Roberts 2018)
# computed in float64 from the index and rounded to float32 (the same values on any machine).
_EDGE = [
    (0.0, 0.0), (1.0, 1.0), (0.0, 1.0), (1.0, 0.0), (0.5, 0.0), (0.5, 1.0), (0.0, 0.5), (1.0, 0.5),
    (0.25, 0.75), (0.75, 0.25), (1e-7, 0.5), (0.5, 1e-7), (1 - 6e-8, 0.5), (0.5, 1 - 6e-8),
    (0.999, 0.001), (0.001, 0.999),
]


def points(n):
    """(n, 2) float32 points of [0, 1]²: the 16 edge points, then R2."""
    g = 1.32471795724474602596
    a1, a2 = 1.0 / g, 1.0 / (g * g)
    i = np.arange(n, dtype=np.float64)
    u = np.empty((n, 2), dtype=np.float64)
    u[:, 0] = np.mod(0.5 + a1 * i, 1.0)
    u[:, 1] = np.mod(0.5 + a2 * i, 1.0)
    k = min(n, len(_EDGE))
    u[:k] = np.array(_EDGE[:k])
    return np.clip(u.astype(np.float32), 0.0, 1.0)


def library_unit(dirs):
    """The float32 directions that the library's Python `pdf` and `invert` evaluate for float32
    input `dirs` (n, 3): gonio::sampler::normalize in float64 (x·(1/√(x² + y² + z²))), rounded to
    float32. The header does not renormalise: the device is given these. numpy's float64
    operations are correctly rounded, so this is the same on any machine."""
    e = np.asarray(dirs, dtype=np.float32).astype(np.float64)
    ss = e[:, 0] * e[:, 0] + e[:, 1] * e[:, 1] + e[:, 2] * e[:, 2]
    inv = 1.0 / np.sqrt(ss)
    return (e * inv[:, None]).astype(np.float32)


def lobes(n_theta, m_phi):
    """A smooth generated diagram on n_theta parallels over [0°, 180°] and m_phi uniform
    meridians: (theta_deg (N,), phi_deg (M,), values (M, N)), positive everywhere."""
    th = np.linspace(0.0, 180.0, n_theta)
    ph = np.arange(m_phi) * (360.0 / m_phi)
    t, p = np.meshgrid(np.radians(th), np.radians(ph))  # (M, N)
    v = (
        1.0
        + 4.0 * np.exp(-(((t - 1.0) / 0.35) ** 2)) * (1.0 + np.cos(3.0 * p)) / 2.0
        + 3.0 * np.exp(-((t / 0.25) ** 2))
        + 0.5 * np.exp(-(((t - 2.4) / 0.3) ** 2)) * (1.0 + np.sin(2.0 * p))
    )
    return th, ph, v


def env_image(width, height):
    """A generated HDR lat-long image (height, width, 3) float32, row 0 at the top: a sky
    gradient, a small bright sun and a few softer lights."""
    y = (np.arange(height) + 0.5) / height
    x = (np.arange(width) + 0.5) / width
    theta = np.pi * y[:, None]                     # from the top (+z)
    phi = np.pi - 2.0 * np.pi * x[None, :]         # gonio's envmap frame (docs/TABLES.md)
    sky = 0.2 + 0.8 * np.clip(np.cos(theta), 0, 1) + 0.05 * np.sin(3 * phi) ** 2
    def spot(t0, p0, w, amp):
        c = np.sin(theta) * np.sin(t0) * np.cos(phi - p0) + np.cos(theta) * np.cos(t0)
        return amp * np.exp((c - 1.0) / (w * w))
    lum = sky + spot(0.6, 1.0, 0.02, 5e3) + spot(1.2, -2.0, 0.15, 20.0) + spot(2.2, 0.3, 0.3, 3.0)
    img = np.empty((height, width, 3), dtype=np.float32)
    img[..., 0] = lum * 1.0
    img[..., 1] = lum * 0.9 + 0.02 * np.cos(phi)
    img[..., 2] = lum * 0.8 + 0.1 * np.sin(theta)
    return np.clip(img, 0.0, None).astype(np.float32)


def write_pfm(path, img):
    """A colour PFM (little endian; PFM stores the bottom row first)."""
    h, w, _ = img.shape
    with open(path, "wb") as f:
        f.write(f"PF\n{w} {h}\n-1.0\n".encode())
        f.write(np.ascontiguousarray(img[::-1], dtype="<f4").tobytes())


# The light-tracing scene of crates/gonio/examples/light_transport.rs (floor patches only): the
# luminaire at the origin (photometric frame, nadir −z), the floor z = −3 m, 12 × 7 patches of
# 1 m² from (−4, −4).
FLOOR = dict(h=3.0, x0=-4.0, y0=-4.0, cell=1.0, nx=12, ny=7)


def floor_reference(intensity, k=64, floor=FLOOR):
    """Each floor patch's mean irradiance (lux) by the midpoint rule with k × k points:
    E(p) = I(ω_p)·cos θ_p / d², `intensity` a function of unit directions (n, 3) → (n,)."""
    h, x0, y0, c, nx, ny = (floor[k_] for k_ in ("h", "x0", "y0", "cell", "nx", "ny"))
    f = (np.arange(k) + 0.5) / k
    a, b = np.meshgrid(f, f, indexing="ij")
    out = np.zeros(nx * ny)
    for p in range(nx * ny):
        px = x0 + c * ((p % nx) + a.ravel())
        py = y0 + c * ((p // nx) + b.ravel())
        d2 = px * px + py * py + h * h
        dist = np.sqrt(d2)
        dirs = np.stack([px / dist, py / dist, -h / dist * np.ones_like(px)], axis=1)
        out[p] = np.mean(intensity(dirs) * (h / dist) / d2)
    return out


def light_trace(dirs, pdf, intensity_at, floor=FLOOR):
    """The light-tracing estimate of the patches' irradiance from samples (dirs, pdf)."""
    h, x0, y0, c, nx, ny = (floor[k_] for k_ in ("h", "x0", "y0", "cell", "nx", "ny"))
    n = len(pdf)
    d = dirs.astype(np.float64)
    ok = (pdf > 0) & (d[:, 2] < 0)
    t = -h / np.where(ok, d[:, 2], -1.0)
    ix = np.floor((t * d[:, 0] - x0) / c)
    iy = np.floor((t * d[:, 1] - y0) / c)
    ok &= (ix >= 0) & (ix < nx) & (iy >= 0) & (iy < ny)
    flux = intensity_at(d[ok]) / pdf[ok].astype(np.float64)
    idx = (iy[ok] * nx + ix[ok]).astype(np.int64)
    return np.bincount(idx, weights=flux, minlength=nx * ny) / (n * c * c)


def rel_rmse(est, ref):
    return float(math.sqrt(np.mean((est - ref) ** 2)) / np.mean(ref))
