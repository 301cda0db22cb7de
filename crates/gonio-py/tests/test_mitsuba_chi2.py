"""A peer's test suite: Mitsuba 3's own chi-square harness (``mitsuba.chi2.ChiSquareTest`` with
``SphericalDomain``) on gonio's samplers, driven through this package, for every corpus file and
for random diagrams.

The harness compares a histogram of ``SAMPLES`` samples over a 2·RES × RES grid in (φ, cos θ)
with the expected counts it integrates from ``pdf`` over each cell by an ires × ires trapezoid
rule. Mitsuba's default integration (``ires=4`` in 3.9; 8 in older releases) under-resolves beams
narrower than a cell: a cell of the default 101 rows spans Δcos θ = 2/101 (11.4° at the poles),
and a spot of 0.5°–10° lies inside one or two rows of cells at the nadir, where a handful of
quadrature points see all or none of the beam. The expected counts are then wrong by far more than
the statistical noise and the test is meaningless.

The resolution is therefore chosen per diagram by convergence (docs/PYTHON.md, "Mitsuba's
chi-square harness"): starting from ires = 8, the expected-count table at ires is compared with
the one at 2·ires; the chi² distance d = Σ (E_ires − E_2ires)² / E_2ires is about the bias that
the coarser table would add to the statistic, and the finer one's bias is at least 10× smaller
(measured: 13–50× per doubling). The finer table is used as soon as d / 10 ≤ 0.1·√(2·K), a tenth
of the statistic's standard deviation (K = cells expecting ≥ 5 samples ≈ the degrees of freedom);
else ires doubles again, up to 64. A table that gives no weight to a cell the samples reach (a
feature narrower than the quadrature spacing, e.g. the 0.02° step of a file with near-duplicate
angles) is not converged either; if one remains at ires = 64 the harness rejects, and the test
fails (issue 11: such a cell was once a sample of the square's edge, u = 0 exactly from Mitsuba's
float32 generator, landing inside an unlit zone where the density is zero all around). The histogram is made once by ``tabulate_histogram``. Every table is computed by the harness's own
``tabulate_pdf``; the test then runs the harness's ``run`` on the chosen one.

Significance: each test runs at the 1 % level with the Šidák correction over all of them
(``test_count``), so the whole set has a 1 % false-alarm rate; the seeds are fixed.

Mitsuba needs its ``llvm_ad_rgb`` variant (the scalar variants cannot run the harness) and so
libLLVM; without either, these tests are SKIPPED with the reason and the rest of the suite runs.
"""

import numpy as np
import pytest

import gonio
from conftest import SUMMARY, valid_corpus_files

SAMPLES = 1_000_000
RES = 101
IRES_START, IRES_MAX = 8, 64
RANDOM_DIAGRAMS = 4
METHODS_ON_RANDOM = ["hds", "bilinear"]

FILES = valid_corpus_files()
N_TESTS = len(FILES) + RANDOM_DIAGRAMS * len(METHODS_ON_RANDOM)


def _mitsuba():
    try:
        import mitsuba as mi
    except Exception as e:  # not installed, or no wheel for this platform
        pytest.skip(f"SKIPPED: Mitsuba 3 is not installed ({e}); pip install mitsuba")
    try:
        mi.set_variant("llvm_ad_rgb")
    except Exception as e:
        pytest.skip(
            "SKIPPED: Mitsuba's llvm_ad_rgb variant cannot start (needs libLLVM: apt-get install "
            f"libllvm19, DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1): {e}"
        )
    from mitsuba import chi2

    return mi, chi2


@pytest.fixture(scope="module")
def mitsuba():
    return _mitsuba()


def run_harness(mi, chi2, sampler, seed, test_count=N_TESTS, sample_count=SAMPLES):
    """Runs ChiSquareTest on `sampler` (an object with numpy `sample(u) -> (d, pdf)` and
    `pdf(d)`) through numpy at the resolution chosen by convergence, at the 1 % level Šidák-
    corrected over `test_count` tests; returns (accepted, ires, p-value, messages)."""

    def sample_func(sample):
        u = np.stack([np.asarray(sample.x), np.asarray(sample.y)], axis=1)
        d, _ = sampler.sample(u)
        return mi.Vector3f(d[:, 0], d[:, 1], d[:, 2])

    def pdf_func(p):
        d = np.stack([np.asarray(p.x), np.asarray(p.y), np.asarray(p.z)], axis=1)
        return mi.Float(sampler.pdf(d))

    return converged_chi2(chi2, sample_func, pdf_func, seed, test_count, sample_count)


def converged_chi2(chi2, sample_func, pdf_func, seed, test_count, sample_count):
    """Mitsuba's ChiSquareTest of Mitsuba-typed `sample_func`/`pdf_func` over the sphere at the
    integration resolution chosen by convergence (ires doubled from IRES_START until the expected
    histograms of two resolutions agree far within the statistic's spread and every sampled cell
    has quadrature weight, at most IRES_MAX), at the 1 % level Šidák-corrected over `test_count`
    tests; returns (accepted, ires, p-value, messages)."""

    def harness(ires):
        t = chi2.ChiSquareTest(
            domain=chi2.SphericalDomain(),
            sample_func=sample_func,
            pdf_func=pdf_func,
            sample_dim=2,
            sample_count=sample_count,
            res=RES,
            ires=ires,
            seed=seed,
        )
        t.tabulate_pdf()
        return t

    # The histogram of the samples does not depend on ires: made once, by the harness.
    first = harness(IRES_START)
    first.tabulate_histogram()
    hits = np.asarray(first.histogram, dtype=np.float64) > 0
    coarse = first
    log = []
    while True:
        fine = harness(2 * coarse.ires)
        e_c = np.asarray(coarse.pdf, dtype=np.float64)
        e_f = np.asarray(fine.pdf, dtype=np.float64)
        pos = e_f > 0
        d = float(np.sum((e_c[pos] - e_f[pos]) ** 2 / e_f[pos]))
        sd = np.sqrt(2.0 * np.count_nonzero(e_f >= 5))
        # A cell that samples reach but no quadrature point sees holds a feature narrower than the
        # quadrature spacing: not converged either.
        missed = int(np.count_nonzero(hits & ~pos))
        log.append(f"ires {coarse.ires} -> {fine.ires}: chi2 distance {d:.3g} (statistic sd ~ {sd:.0f}), "
                   f"{missed} sampled cells with no quadrature weight")
        if (d / 10 <= 0.1 * sd and missed == 0) or fine.ires >= IRES_MAX:
            break
        coarse = fine
    for attr in ("histogram", "histogram_sum", "pdf_start", "pdf_end"):
        setattr(fine, attr, getattr(first, attr))
    fine.fail = fine.fail or first.fail
    fine.messages = first.messages + fine.messages
    # A sampled cell still without quadrature weight at the finest ires makes the harness reject
    # (it is a failure, not a skip: issue 11 traced the 7 such files to samples of the square's
    # edge landing inside an unlit zone, a sampler bug since fixed in Radial::forward).
    ok = fine.run(significance_level=0.01, test_count=test_count, quiet=True)
    p = fine.p_value
    p = float(p[0]) if hasattr(p, "__len__") else float(p)
    return ok, fine.ires, p, "\n".join(log) + "\n" + fine.messages


def random_diagram(rng, hemisphere):
    """A random diagram: a smooth lobe plus 1–3 narrow spots on a random irregular grid."""
    top = 90.0 if hemisphere else 180.0
    n, m = rng.integers(5, 40), rng.integers(1, 30)
    theta = np.sort(rng.choice(np.arange(1, int(top * 2)) / 2.0, size=n - 2, replace=False))
    theta = np.concatenate([[0.0], theta, [top]])
    phi = np.sort(rng.choice(np.arange(0, 360), size=m, replace=False)).astype(float)
    t, p = np.meshgrid(np.radians(theta), np.radians(phi))
    values = rng.uniform(0.0, 0.2) + np.cos(t / 2) ** rng.integers(1, 8) * (1 + 0.5 * np.cos(p))
    for _ in range(rng.integers(1, 4)):
        j = rng.integers(0, n)
        values[:, j] += rng.uniform(1, 20) * (rng.uniform(size=m) < 0.7)
    values[rng.uniform(size=values.shape) < 0.1] = 0.0
    return gonio.Diagram(theta, phi, values)


@pytest.mark.parametrize("path", [pytest.param(p, id=p.name) for p in FILES] or [
    pytest.param(None, marks=pytest.mark.skip(reason="SKIPPED: photometric corpus not found"), id="no-corpus")])
def test_mitsuba_chi2_accepts_hds_on_corpus_file(mitsuba, path):
    mi, chi2 = mitsuba
    s = gonio.read(path).sampler("hds")
    ok, ires, p, messages = run_harness(mi, chi2, s, seed=1)
    SUMMARY.append(f"{'accepted' if ok else 'REJECTED'}  p = {p:.4f}  ires = {ires:2d}  hds  {path.name}")
    print(f"{path.name}: ires={ires}\n{messages}")
    assert ok, messages


@pytest.mark.parametrize("method", METHODS_ON_RANDOM)
@pytest.mark.parametrize("k", range(RANDOM_DIAGRAMS))
def test_mitsuba_chi2_accepts_random_diagrams(mitsuba, k, method):
    mi, chi2 = mitsuba
    rng = np.random.default_rng(1000 + k)
    d = random_diagram(rng, hemisphere=k % 2 == 0)
    s = d.sampler(method)
    ok, ires, p, messages = run_harness(mi, chi2, s, seed=2 + k)
    SUMMARY.append(f"{'accepted' if ok else 'REJECTED'}  p = {p:.4f}  ires = {ires:2d}  {method}  random diagram {k} ({d.domain})")
    print(f"random diagram {k} ({d.domain}, {method}): ires={ires}\n{messages}")
    assert ok, messages


def test_mitsuba_chi2_rejects_a_wrong_pdf(mitsuba):
    """The harness has power here: the right samples against a pdf that is off by 3 % in one
    half of the sphere are rejected."""
    mi, chi2 = mitsuba
    s = gonio.example().sampler("hds")

    class Skewed:
        def sample(self, u):
            return s.sample(u)

        def pdf(self, d):
            p = s.pdf(d)
            return np.where(d[:, 0] > 0, p * 1.03, p * 0.97)

    ok, _, p, messages = run_harness(mi, chi2, Skewed(), seed=3)
    SUMMARY.append(f"{'accepted' if ok else 'rejected (as it must)'}  p = {p:.2e}  pdf off by ±3 % in one half")
    assert not ok, messages
