"""What the picture-making examples share: the sRGB transfer curve and writing a figure."""

import pathlib
from typing import Any

import numpy as np


def srgb(x: "np.typing.NDArray[np.floating]") -> "np.typing.NDArray[np.floating]":
    """Linear values clipped to [0, 1] and encoded with the sRGB transfer curve."""
    x = np.clip(x, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def save(fig: Any, path: str) -> None:
    """Lays out `fig`, writes it to `path` (its folder made if missing) and says so."""
    fig.tight_layout()
    out = pathlib.Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=100, bbox_inches="tight")
    print(f"wrote {out}")
