"""Illuminance on a floor below a luminaire: light tracing with gonio's samples, drawn next to
the exact illuminance.

    python examples/python/floor_illuminance.py [FILE.ies] [-o floor.png] [-n 1000000] [--height 3]

The luminaire hangs at `--height` metres above an infinite floor, in gonio's frame: nadir (γ = 0°)
is −z, C0 is +x, so the floor is the plane z = −h. Light tracing shoots N directions ω_i with the
exact density p(ω_i) per steradian; each carries the flux I(ω_i) / (N p(ω_i)) lumens, where I is
the luminaire's intensity in candela, and the flux landing in a floor cell divided by the cell's
area is the illuminance E in lux. The exact illuminance at a floor point P at distance r is
E(P) = I(ω) cos β / r² = I(ω) h / r³, with ω the direction of P, averaged over each cell. Without a FILE, the corpus's
area luminaire is used ($GONIO_CORPUS or ../shared/data/photometry), else the built-in example
written to an IES file first.
"""

import argparse
import os
import pathlib
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import gonio  # noqa: E402


def default_file() -> pathlib.Path:
    corpus = os.environ.get("GONIO_CORPUS") or pathlib.Path(__file__).resolve().parents[2] / ".." / "shared" / "data" / "photometry"
    f = pathlib.Path(corpus) / "ies" / "lm63_2002_lithonia_area_full_h0_360.ies"
    if f.is_file():
        return f
    f = pathlib.Path(tempfile.mkdtemp()) / "example.ies"
    gonio.example().write(f)
    return f


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("file", nargs="?", type=pathlib.Path)
    ap.add_argument("-o", "--output", default="floor.png")
    ap.add_argument("-n", "--samples", type=int, default=1_000_000)
    ap.add_argument("--height", type=float, default=3.0, help="mounting height, metres")
    ap.add_argument("--half-width", type=float, default=None, help="half width of the floor shown, metres (default 2.5 h)")
    ap.add_argument("--cells", type=int, default=81, help="cells per side (odd: one row on y = 0)")
    a = ap.parse_args()

    path = a.file or default_file()
    lum = gonio.read(path)
    h, w = a.height, a.half_width or 2.5 * a.height
    edges = np.linspace(-w, w, a.cells + 1)
    cell_area = (edges[1] - edges[0]) ** 2

    # Light tracing: directions with their exact pdf, the flux each carries, where it lands.
    s = lum.sampler()
    d, pdf = s.sample(gonio.sequence(a.samples, "sobol", seed=1))
    flux = lum.intensity(d) / (pdf * a.samples)               # lumens per sample
    down = d[:, 2] < 0
    t = h / -d[down, 2]                                        # ray parameter to z = -h
    x, y = d[down, 0] * t, d[down, 1] * t
    traced, _, _ = np.histogram2d(x, y, bins=[edges, edges], weights=flux[down])
    traced /= cell_area                                        # lux

    # Exact: E = I(ω) h / r³, averaged over each cell (4 × 4 points) like the traced flux.
    c = 0.5 * (edges[1:] + edges[:-1])
    k = 4
    sub = edges[0] + (np.arange(a.cells * k) + 0.5) * (edges[1] - edges[0]) / k
    X, Y = np.meshgrid(sub, sub, indexing="ij")
    P = np.stack([X.ravel(), Y.ravel(), np.full(X.size, -h)], axis=1)
    r = np.linalg.norm(P, axis=1)
    e = (lum.intensity(P / r[:, None]) * h / r**3).reshape(a.cells, k, a.cells, k)
    exact = e.mean(axis=(1, 3))

    fig, ax = plt.subplots(1, 3, figsize=(15, 4.6), constrained_layout=True)
    vmax = exact.max()
    ext = [-w, w, -w, w]
    for a_, img, title in [(ax[0], traced, f"light tracing, {a.samples:,} gonio samples"),
                           (ax[1], exact, "exact  E = I(ω) h / r³")]:
        im = a_.imshow(img.T, origin="lower", extent=ext, vmin=0, vmax=vmax, cmap="inferno")
        a_.set_title(title)
        a_.set_xlabel("x (m, C0)")
        a_.set_ylabel("y (m, C90)")
    fig.colorbar(im, ax=ax[:2], label="illuminance (lux)", shrink=0.9)
    mid = a.cells // 2
    ax[2].plot(c, traced[:, mid], ".", ms=4, label="light tracing")
    ax[2].plot(c, exact[:, mid], "-", label="exact")
    ax[2].set_title(f"profile along x, y = {round(c[mid], 6) + 0.0:.2f} m")
    ax[2].set_xlabel("x (m)")
    ax[2].set_ylabel("lux")
    ax[2].legend()
    fig.suptitle(f"{path.name}: {lum.flux:.0f} lm, mounted at {h:g} m")
    fig.savefig(a.output, dpi=110)
    rel = np.abs(traced - exact).sum() / exact.sum()
    print(f"{a.output}: floor {2 * w:g} m × {2 * w:g} m, relative L1 difference traced vs exact = {rel:.4f}")


if __name__ == "__main__":
    main()
