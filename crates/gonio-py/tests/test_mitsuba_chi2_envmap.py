"""Mitsuba 3's own chi-square harness on gonio's environment maps: the float64 map and the float32
environment map (``EnvMap(precision="float32")``) on a generated sky with a one-pixel sun on the
seam and a bright pixel at the pole, and the float64 map on the shared maps
(``../shared/data/envmaps``, or ``GONIO_ENVMAPS``).

The harness and its resolution by convergence are those of ``test_mitsuba_chi2.py`` (its module
documentation); the significance is 1 % with the Šidák correction over the tests of this file,
fixed seeds. Without Mitsuba's ``llvm_ad_rgb`` variant the tests are SKIPPED with the reason.
"""

import os
from pathlib import Path

import numpy as np
import pytest

import gonio
from conftest import SUMMARY
from test_mitsuba_chi2 import _mitsuba, run_harness

ROOT = Path(__file__).resolve().parents[3]
ENVMAPS = Path(os.environ.get("GONIO_ENVMAPS") or ROOT.parent / "shared" / "data" / "envmaps")
SHARED = sorted(ENVMAPS.glob("*.hdr")) if ENVMAPS.is_dir() else []
PRECISIONS = ["float64", "float32"]
N_TESTS = len(PRECISIONS) + max(len(SHARED), 1)


@pytest.fixture(scope="module")
def mitsuba():
    return _mitsuba()


class Directions:
    """An EnvMap seen as a sampler of directions: ``sample(u) -> (d, pdf)``, ``pdf(d)``."""

    def __init__(self, env):
        self.env = env

    def sample(self, u):
        d, p, _ = self.env.sample(u)
        return d, p

    def pdf(self, d):
        return self.env.pdf(d)


def write_pfm(path, img):
    h, w, _ = img.shape
    with open(path, "wb") as f:
        f.write(f"PF\n{w} {h}\n-1.0\n".encode())
        f.write(np.ascontiguousarray(img[::-1], dtype="<f4").tobytes())


@pytest.mark.parametrize("precision", PRECISIONS)
def test_mitsuba_chi2_accepts_a_generated_sky(mitsuba, tmp_path, precision):
    mi, chi2 = mitsuba
    rng = np.random.default_rng(11)
    h, w = 64, 128
    t = (np.arange(h) + 0.5) / h
    img = np.repeat((0.2 + np.cos(np.pi * t) ** 2)[:, None, None], w, axis=1) * np.ones(3)
    img = img * (1 + 0.3 * rng.random((h, w, 1)))
    img[20, 0] = [3000.0, 2000.0, 1000.0]  # a sun on the seam
    img[0, 37] = [800.0, 800.0, 800.0]  # a bright pixel at the pole
    p = tmp_path / "sky.pfm"
    write_pfm(p, img.astype(np.float32))
    env = gonio.EnvMap(p, precision=precision)
    ok, ires, pv, messages = run_harness(mi, chi2, Directions(env), seed=21, test_count=N_TESTS)
    SUMMARY.append(f"{'accepted' if ok else 'REJECTED'}  p = {pv:.4f}  ires = {ires:2d}  envmap ({precision}), generated sky")
    assert ok, messages


@pytest.mark.parametrize("path", [pytest.param(p, id=p.name) for p in SHARED] or [
    pytest.param(None, marks=pytest.mark.skip(reason="SKIPPED: shared envmaps not found (GONIO_ENVMAPS)"),
                 id="no-envmaps")])
def test_mitsuba_chi2_accepts_shared_envmaps(mitsuba, path):
    mi, chi2 = mitsuba
    env = gonio.EnvMap(path)
    ok, ires, pv, messages = run_harness(mi, chi2, Directions(env), seed=31, test_count=N_TESTS)
    SUMMARY.append(f"{'accepted' if ok else 'REJECTED'}  p = {pv:.4f}  ires = {ires:2d}  envmap {path.name}")
    assert ok, messages
