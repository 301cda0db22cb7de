"""Mitsuba 3's chi-square harness (``mitsuba.chi2.ChiSquareTest``, ``SphericalDomain``) on the
tabulated-BRDF samplers at several incident directions (issue 26): the HDS map of the slice
blended between tabulated incident directions, and cosine sampling, on a glossy table written by
``test_brdf.write_table``. The incident directions lie between the table's slices (15° apart), so
the map under test is a blend, not a tabulated slice.

The harness, its convergence-chosen integration resolution and its statistics are those of
``test_mitsuba_chi2.run_harness``: each test at the 1 % level with the Šidák correction over this
file's tests (a 1 % false-alarm rate for the file), fixed seeds. One more test shows the harness
has power here: the samples of the blended map at θ_i = 37° against the pdf of the map at θ_i =
45° (the neighbouring tabulated slice: what a random choice between slices would sample) are
rejected. Skipped, with the reason, without Mitsuba's llvm_ad_rgb variant.
"""

import numpy as np
import pytest

import gonio
from conftest import SUMMARY
from test_brdf import direction, write_table
from test_mitsuba_chi2 import mitsuba, run_harness  # noqa: F401 (the fixture)

SAMPLES = 400_000
CASES = [("hds", 0.0, 0.0), ("hds", 22.0, 30.0), ("hds", 37.0, 200.0), ("hds", 68.0, 95.0),
         ("hds", 83.0, 10.0), ("cosine", 37.0, 200.0)]
N_TESTS = len(CASES)


@pytest.fixture(scope="module")
def brdf(tmp_path_factory):
    return gonio.read_brdf(write_table(tmp_path_factory.mktemp("brdf_chi2") / "lobe.json"))


class AtIncident:
    """A BRDF sampler at one incident direction, in the harness's sample/pdf form."""

    def __init__(self, sampler, wi, wi_pdf=None):
        self.s, self.wi = sampler, wi
        self.wi_pdf = wi if wi_pdf is None else wi_pdf

    def sample(self, u):
        d, pdf, _ = self.s.sample(self.wi, u)
        return d, pdf

    def pdf(self, d):
        return self.s.pdf(self.wi_pdf, d)


@pytest.mark.parametrize("method,theta_i,phi_i", CASES)
def test_mitsuba_chi2_accepts_brdf_sampler(mitsuba, brdf, method, theta_i, phi_i):
    mi, chi2 = mitsuba
    s = AtIncident(brdf.sampler(method), direction(theta_i, phi_i))
    ok, ires, p, messages = run_harness(mi, chi2, s, seed=11, test_count=N_TESTS,
                                        sample_count=SAMPLES)
    SUMMARY.append(f"{'accepted' if ok else 'REJECTED'}  p = {p:.4f}  ires = {ires:2d}  brdf "
                   f"{method} θ_i = {theta_i}°, φ_i = {phi_i}°")
    assert ok, messages


def test_mitsuba_chi2_rejects_the_neighbouring_slice(mitsuba, brdf):
    mi, chi2 = mitsuba
    s = AtIncident(brdf.sampler("hds"), direction(37.0, 200.0), wi_pdf=direction(45.0, 200.0))
    ok, _, p, messages = run_harness(mi, chi2, s, seed=12, test_count=1, sample_count=SAMPLES)
    SUMMARY.append(f"{'accepted' if ok else 'rejected (as it must)'}  p = {p:.2e}  brdf: the "
                   "blend at θ_i = 37° against the slice at 45°")
    assert not ok, messages
