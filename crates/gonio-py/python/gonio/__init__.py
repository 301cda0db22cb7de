"""gonio — importance sampling of goniometric diagrams, numpy-native.

Reads IES LM-63 and EULUMDAT files (``gonio.read``), and samples any diagram through the
Havran–Dmitriev–Seidel mapping or a baseline (``gonio.Sampler``) with the exact pdf of every
sample, its closed-form inverse, and the project's test battery (``gonio.check``).

Frame (README "The frame"): directions are unit vectors (x, y, z); θ is the polar angle from
+z, φ the azimuth from +x toward +y; densities are per steradian. Photometric files: γ = 0°
(nadir) is −z and C = 0° is +x, so θ = 180° − γ and φ = C; values are candela.

Example::

    import gonio
    d = gonio.read("luminaire.ies")
    s = d.sampler()                       # the HDS map on the sphere
    u = gonio.sequence(100_000, "sobol", seed=1)
    directions, pdf = s.sample(u)         # (n, 3), (n,)
"""

from ._gonio import (  # noqa: F401
    __version__,
    Brdf,
    BrdfSampler,
    BuildError,
    Diagram,
    DiagramError,
    EnvMap,
    GonioError,
    InputError,
    InternalError,
    ParseError,
    Sampler,
    analytic_brdf,
    check,
    convert,
    example,
    methods,
    read,
    read_brdf,
    read_bytes,
    read_limit,
    read_mesh,
    sequence,
    set_read_limit,
    texture_uv,
)

__all__ = [
    "Brdf",
    "BrdfSampler",
    "BuildError",
    "Diagram",
    "DiagramError",
    "EnvMap",
    "GonioError",
    "InputError",
    "InternalError",
    "ParseError",
    "Sampler",
    "analytic_brdf",
    "check",
    "convert",
    "example",
    "methods",
    "read",
    "read_brdf",
    "read_bytes",
    "read_limit",
    "read_mesh",
    "sequence",
    "set_read_limit",
    "texture_uv",
]
