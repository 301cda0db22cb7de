"""Type stubs of the package ``gonio`` (the native module ``gonio._gonio``).

Frame: directions are unit vectors (x, y, z); θ is the polar angle from +z, φ the azimuth from +x
toward +y; densities are per steradian. Photometric files: γ = 0° (nadir) is −z, C = 0° is +x,
θ = 180° − γ, φ = C; values in candela.
"""

import os
from typing import Any, Callable, Literal, Optional, Sequence as _Seq, Tuple, Union

import numpy as np
import numpy.typing as npt

# The progress= option: None, True (a tqdm bar, or lines on stderr) or f(what, fraction).
Progress = Union[None, bool, Callable[[str, float], object]]

__version__: str

Method = Literal["hds", "piecewise-constant", "bilinear", "rejection", "uniform"]
DomainName = Literal["hemisphere", "sphere"]
Format = Literal["ies", "ldt", "json"]
ArrayLike = npt.ArrayLike
F64Array = npt.NDArray[np.float64]

class GonioError(ValueError):
    """Base of every gonio error caused by input."""

class ParseError(GonioError):
    """A file or text could not be read; the message is ``FILE:LINE:COLUMN: message``."""

    file: str
    line: int  # 1-based; 0 when the problem concerns the file as a whole
    column: int  # 1-based; 0 when unknown
    message: str

class DiagramError(GonioError):
    """A diagram was refused (angles, shape or values)."""

class BuildError(GonioError):
    """No sampler of that method for that diagram on that domain."""

class InputError(GonioError):
    """An array or argument is not acceptable; rows are named by their 0-based index."""

class InternalError(RuntimeError):
    """A bug in gonio: a panic caught before it could cross into Python."""

class Diagram:
    """A goniometric diagram: values on a (θ, φ) grid, from a file or from arrays."""

    def __init__(self, theta_deg: ArrayLike, phi_deg: ArrayLike, values: ArrayLike) -> None:
        """``theta_deg`` (N,) strictly increasing in [0°, 180°]; ``phi_deg`` (M,) strictly
        increasing in [0°, 360°); ``values`` (M, N) finite and ≥ 0, ``values[i, j]`` at
        (phi_deg[i], theta_deg[j]). Raises DiagramError."""
    @property
    def theta_deg(self) -> F64Array:
        """Parallels θ in degrees from +z, shape (N,): the shortest decimals that convert back to
        the stored radians (15.0, not 14.999999999999998), as ``to_json`` writes them."""
    @property
    def phi_deg(self) -> F64Array:
        """Meridians φ in degrees from +x toward +y, shape (M,); shortest decimals as ``theta_deg``."""
    @property
    def values(self) -> F64Array:
        """Values, shape (M, N); candela for photometric files."""
    @property
    def flux(self) -> float:
        """∫ of the (θ, φ)-bilinear interpolant over the sphere: value unit × sr (lumens for cd)."""
    @property
    def source(self) -> Literal["ies", "ldt", "json", "example", "arrays"]: ...
    @property
    def name(self) -> str: ...
    @property
    def domain(self) -> DomainName:
        """Default sampler domain: "sphere" for photometric input, else "hemisphere" when θ ≤ 90°."""
    @property
    def warnings(self) -> list[str]:
        """What the reader tolerated, one ``FILE:LINE:COLUMN: warning: ...`` line each."""
    @property
    def header(self) -> Optional[dict[str, Any]]:
        """Every field of an IES/EULUMDAT file (None for other sources)."""
    def intensity(self, directions: ArrayLike) -> F64Array:
        """The (θ, φ)-bilinear interpolant at directions (n, 3): candela for photometric input."""
    def sampler(
        self,
        method: Method = "hds",
        domain: Optional[DomainName] = None,
        *,
        resolution: Optional[int] = None,
        seed: Optional[int] = None,
        tolerance: Optional[float] = None,
    ) -> "Sampler": ...
    def to_json(self) -> str: ...
    def dumps(self, format: Format, luminaire: Optional[str] = None) -> str:
        """JSON, IES LM-63-2019 or EULUMDAT text of the diagram (values must be candela)."""
    def write(self, path: Union[str, os.PathLike[str]], format: Optional[Format] = None) -> None: ...

class EnvMap:
    """An environment map (.hdr/.exr/.pfm lat-long image) sampled by the HDS sphere map."""

    def tables(self, precision: Literal["float32", "float64"] = "float32") -> bytes:
        """The map's tables as one blob (docs/TABLES.md) with the RGB image as its target."""

    def __init__(
        self,
        path: str | os.PathLike[str],
        lookup: Literal["nearest", "bilinear"] = "nearest",
        mis_compensation: bool = False,
        weight: Union[Literal["luminance", "red", "green", "blue"], int, ArrayLike, None] = None,
        precision: Literal["float64", "float32"] = "float64",
        *,
        progress: Progress = None,
    ) -> None: ...
    @property
    def precision(self) -> Literal["float64", "float32"]: ...
    @property
    def width(self) -> int: ...
    @property
    def height(self) -> int: ...
    @property
    def power(self) -> float: ...
    @property
    def weight(self) -> Literal["luminance", "red", "green", "blue", "custom"]: ...
    @property
    def lookup(self) -> Literal["nearest", "bilinear"]: ...
    @property
    def memory_bytes(self) -> int: ...
    @property
    def warnings(self) -> list[str]: ...
    def sampler(
        self, kind: Literal["hds", "latlong", "pbrt-v4"] = "hds", *, resolution: int | None = None
    ) -> Sampler: ...
    def sample(
        self, u: ArrayLike
    ) -> tuple[npt.NDArray[np.floating], npt.NDArray[np.floating], npt.NDArray[np.floating]]: ...
    def pdf(self, directions: ArrayLike) -> npt.NDArray[np.floating]: ...
    def eval(self, directions: ArrayLike) -> npt.NDArray[np.floating]: ...
    def invert(self, directions: ArrayLike) -> npt.NDArray[np.floating]: ...

class Brdf:
    """A tabulated BRDF f_r(wi, wo) in 1/sr (1 or 3 channels), from ``read_brdf``. Local frame:
    z the normal, both directions pointing away from the surface (docs/BRDF.md)."""

    @property
    def channels(self) -> int: ...
    @property
    def symmetry(self) -> Literal["isotropic", "anisotropic"]: ...
    @property
    def grid(self) -> Tuple[F64Array, F64Array, F64Array, F64Array]: ...
    def eval(self, wi: ArrayLike, wo: ArrayLike) -> F64Array: ...
    def albedo(self, wi: ArrayLike) -> F64Array: ...
    def sampler(
        self,
        method: Literal["hds", "cosine", "ggx-fit", "piecewise-constant"] = "hds",
        *,
        theta_o: int = 46,
        phi_o: int = 90,
        force_resample: bool = False,
        resolution: int = 128,
    ) -> BrdfSampler: ...
    def write(
        self, path: Union[str, os.PathLike[str]], format: Literal["json", "merl", "utia"] = "json"
    ) -> os.PathLike[str]:
        """Writes the table: JSON exactly, MERL (isotropic) or UTIA by its interpolant."""
    def tables(
        self,
        precision: Literal["float32", "float64"] = "float32",
        *,
        theta_o: int = 46,
        phi_o: int = 90,
        force_resample: bool = False,
    ) -> bytes:
        """The family blob of this table's "hds" sampler (docs/TABLES.md, "Families")."""

class BrdfSampler:
    """Importance sampling of f_r·cos θ_o with the exact pdf (per sr) and inverse; ``wi`` is one
    direction (3,) or one per row (n, 3)."""

    @property
    def method(self) -> str: ...
    @property
    def channels(self) -> int: ...
    @property
    def resampled(self) -> bool: ...
    @property
    def memory_bytes(self) -> int: ...
    def sample(self, wi: ArrayLike, u: ArrayLike) -> Tuple[F64Array, F64Array, F64Array]: ...
    def pdf(self, wi: ArrayLike, wo: ArrayLike) -> F64Array: ...
    def invert(self, wi: ArrayLike, wo: ArrayLike) -> F64Array: ...
    def tables(self, precision: Literal["float32", "float64"] = "float32") -> bytes:
        """The family blob of this "hds" sampler (docs/TABLES.md, "Families")."""

def analytic_brdf(
    path: Union[str, os.PathLike[str]],
    family: Literal["lambert", "ggx"],
    *,
    format: Literal["json", "merl", "utia"] = "json",
    albedo: _Seq[float] = (0.8, 0.8, 0.8),
    alpha_x: float = 0.3,
    alpha_y: Optional[float] = None,
    f0: _Seq[float] = (1.0, 1.0, 1.0),
    n_theta: int = 46,
    n_phi: int = 90,
) -> os.PathLike[str]:
    """Writes the library's analytic BRDF in the MERL, UTIA or gonio BRDF JSON layout; returns path."""

def read_mesh(path: Union[str, os.PathLike[str]]) -> dict[str, Any]:
    """A PLY or OBJ mesh: vertices (n, 3), faces (m, 3) uint32, normals (k, 3), warnings."""

def read_brdf(
    path: Union[str, os.PathLike[str]],
    *,
    merl_theta: int = 46,
    merl_phi: int = 90,
    progress: Progress = None,
) -> Brdf: ...

class Sampler:
    """A bijective map from [0, 1]² to unit directions with the exact pdf (per steradian)."""

    def __init__(
        self,
        diagram: Diagram,
        method: Method = "hds",
        domain: Optional[DomainName] = None,
        *,
        resolution: Optional[int] = None,
        seed: Optional[int] = None,
        tolerance: Optional[float] = None,
    ) -> None: ...
    @property
    def method(self) -> Union[Method, Literal["latlong", "pbrt-v4"]]: ...
    @property
    def domain(self) -> DomainName: ...
    @property
    def ratio_bound(self) -> Optional[Tuple[float, float]]:
        """Guaranteed (min, max) of pdf / target_pdf, or None when the method claims none."""
    @property
    def memory_bytes(self) -> int: ...
    @property
    def target_power(self) -> float:
        """∫ of the diagram over the domain (unit × sr): intensity = target_power × target_pdf."""
    def tables(self, precision: Literal["float32", "float64"] = "float32") -> bytes:
        """The HDS map's tables as one blob (docs/TABLES.md), with the diagram as its grid target."""
    @staticmethod
    def from_tables(data: bytes) -> "Sampler":
        """The sampler of a validated table blob: samples as the map that wrote it, bit for bit."""
    def sample(
        self, u: ArrayLike, *, out: Optional[Tuple[F64Array, F64Array]] = None
    ) -> Tuple[F64Array, F64Array]:
        """Points (n, 2) in [0, 1]² → (directions (n, 3), pdf (n,) per sr). ``out``: C-contiguous
        float64 arrays (n, 3) and (n,) to write into and return, overlapping neither ``u`` nor
        each other."""
    def pdf(self, directions: ArrayLike, *, out: Optional[F64Array] = None) -> F64Array:
        """Density (n,) per sr of ``sample`` at directions (n, 3); 0 outside the domain. ``out``:
        a C-contiguous float64 array (n,) to write into and return."""
    def target_pdf(self, directions: ArrayLike) -> F64Array:
        """Normalised target density (n,) per sr at directions (n, 3)."""
    def invert(self, directions: ArrayLike, *, out: Optional[F64Array] = None) -> F64Array:
        """Points (n, 2) that ``sample`` maps to directions (n, 3); InputError naming the row for a
        direction outside the domain or of density 0 (no point maps to it). ``out``: a
        C-contiguous float64 array (n, 2) to write into and return."""

def read(path: Union[str, os.PathLike[str]], format: Optional[Format] = None) -> Diagram:
    """Reads a .ies, .ldt or .json file (TILT files resolved next to it)."""

def read_bytes(data: Union[bytes, str], format: Format, name: str = "<bytes>") -> Diagram:
    """Reads a diagram from file contents in an explicit format."""

FileKind = Literal["photometry", "diagram", "tilt", "image", "brdf", "mesh", "tables"]

def read_limit(kind: FileKind) -> int:
    """The size limit in bytes of files of ``kind`` (the same in the CLI, C and Python)."""

def set_read_limit(kind: FileKind, bytes: int) -> None:
    """Sets the size limit of files of ``kind`` for the whole process (0: the default)."""

def example() -> Diagram:
    """The built-in example luminaire (candela, sphere)."""

def sequence(
    n: int, kind: Literal["halton", "sobol", "random"] = "halton", seed: int = 0, start: int = 0
) -> F64Array:
    """Points (n, 2) of [0, 1)²: the CLI's ``--sequence KIND --seed SEED`` points."""

def check(
    diagram: Diagram,
    method: Method = "hds",
    *,
    samples: Optional[int] = None,
    seed: int = 0,
    quick: bool = False,
    progress: Progress = None,
) -> dict[str, Any]:
    """The ``gonio check --json`` report as a dict; ``report["passed"]`` is the verdict."""

def convert(src: Union[str, os.PathLike[str]], dst: Union[str, os.PathLike[str]]) -> None:
    """``gonio convert SRC DST``: JSON ↔ IES LM-63-2019 ↔ EULUMDAT by DST's extension."""

def methods() -> list[Method]: ...

def texture_uv(
    vertices: ArrayLike,
    faces: ArrayLike,
    density: str = "surface",
    weights: Optional[ArrayLike] = None,
    center: Optional[tuple[float, float, float]] = None,
    layout: str = "hds",
    *,
    progress: Progress = None,
) -> dict[str, Any]:
    """One-chart UVs of a closed star-shaped mesh from the inverse map (docs/TEXTURE.md): a dict
    with ``positions``, ``uvs``, ``faces``, ``face_uvs``, ``source_face``, ``center``,
    ``cut_faces``, ``seam``."""
