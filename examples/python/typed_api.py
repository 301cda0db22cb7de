"""The Python API as a type checker sees it: every call here is checked by
``mypy --strict`` against the package's stubs (``gonio/__init__.pyi``, ``py.typed``) and the
annotated ``gonio.mitsuba`` in the test command (scripts/test-python.sh), and the script runs:
a luminaire's map, its table blob read back, an environment map, a BRDF written and sampled, and,
when Mitsuba is installed, a luminaire's scene entries.

    .venv/bin/python examples/python/typed_api.py
"""

import pathlib
import tempfile

import numpy as np
import numpy.typing as npt

import gonio


def luminaire() -> float:
    diagram: gonio.Diagram = gonio.example()
    sampler = gonio.Sampler(diagram, "hds", "sphere")
    u: npt.NDArray[np.float64] = gonio.sequence(1000, "halton")
    dirs, pdf = sampler.sample(u)
    back = sampler.invert(dirs)
    blob: bytes = sampler.tables("float32")
    again = gonio.Sampler.from_tables(blob)
    d32, p32 = again.sample(u.astype(np.float32))
    assert np.allclose(sampler.pdf(dirs), pdf) and np.allclose(back, u, atol=1e-9)
    assert d32.dtype == np.float32 and p32.shape == pdf.shape
    return float(np.mean(sampler.target_pdf(dirs) / pdf))


def sky(tmp: pathlib.Path) -> float:
    path = tmp / "sky.pfm"
    h, w = 8, 16
    data = np.ones((h, w, 3), dtype="<f4")
    data[2, 5] = 40.0
    path.write_bytes(f"PF\n{w} {h}\n-1.0\n".encode() + data[::-1].tobytes())
    env = gonio.EnvMap(str(path))
    dirs, pdf, rgb = env.sample(gonio.sequence(64))
    assert np.allclose(env.pdf(dirs), pdf) and rgb.shape == (64, 3)
    return float(pdf.max())


def brdf(tmp: pathlib.Path) -> float:
    path = gonio.analytic_brdf(tmp / "ggx.json", "ggx", alpha_x=0.3, n_theta=10, n_phi=24)
    table: gonio.Brdf = gonio.read_brdf(path)
    copy = gonio.read_brdf(table.write(tmp / "ggx.binary", "merl"))
    s: gonio.BrdfSampler = copy.sampler("hds")
    wo, pdf, weight = s.sample([0.3, 0.1, 0.95], gonio.sequence(100))
    family: bytes = table.tables("float32")
    assert len(family) % 64 == 0 and weight.shape == (100, copy.channels)
    return float(np.mean(pdf))


def scene_entries(path: str) -> int:
    try:
        import mitsuba as mi
    except ImportError:
        return 0
    import gonio.mitsuba as gm

    mi.set_variant("scalar_rgb")
    gm.register()
    entries = gm.luminaire(path, shape="point", scale=2.0)
    return len(entries)


def main() -> None:
    with tempfile.TemporaryDirectory() as t:
        tmp = pathlib.Path(t)
        ies = tmp / "example.ies"
        gonio.example().write(ies)
        print(f"luminaire: mean target/pdf {luminaire():.4f}")
        print(f"sky: largest pdf {sky(tmp):.4f} per sr")
        print(f"brdf: mean pdf {brdf(tmp):.4f} per sr")
        print(f"mitsuba: {scene_entries(str(ies))} scene entr(y/ies) (0: Mitsuba not installed)")


if __name__ == "__main__":
    main()
