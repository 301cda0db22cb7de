"""How fine must Mitsuba's chi-square harness integrate the pdf over its cells (``ires``)?

    python crates/gonio-py/tools/mitsuba_ires.py [FILE ...] [--samples 1000000] [--res 101]

For each file (default: every corpus file), tabulates the harness's expected counts
(``ChiSquareTest.tabulate_pdf``, SphericalDomain, ``res`` rows) at ires = 4, 8, 16, 32, 64 and
prints, for each ires, the chi²-distance of its table from the next finer one,
Σ (E_ires − E_2ires)² / E_2ires over cells with E_2ires > 0, in units of chi² at ``samples`` samples.
This is about the bias the quadrature adds to the statistic; it must be small against the
statistic's standard deviation √(2·dof) (≈ 200 for res = 101) for the test to mean anything.
"""

import argparse
import pathlib
import sys
import time

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "tests"))
from conftest import valid_corpus_files  # noqa: E402

import gonio  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("files", nargs="*", type=pathlib.Path)
    ap.add_argument("--samples", type=int, default=1_000_000)
    ap.add_argument("--res", type=int, default=101)
    ap.add_argument("--ires", type=int, nargs="*", default=[4, 8, 16, 32, 64])
    a = ap.parse_args()
    import mitsuba as mi

    mi.set_variant("llvm_ad_rgb")
    from mitsuba import chi2

    files = a.files or valid_corpus_files()
    print(f"samples = {a.samples}, res = {a.res}; chi2 distance of ires to the next finer ires")
    print("file".ljust(52) + "".join(f"{i:>10}" for i in a.ires[:-1]) + "   seconds at each ires")
    for f in files:
        s = gonio.read(f).sampler("hds")

        def pdf_func(p):
            d = np.stack([np.asarray(p.x), np.asarray(p.y), np.asarray(p.z)], axis=1)
            return mi.Float(s.pdf(d))

        tables, secs = [], []
        for ires in a.ires:
            t = chi2.ChiSquareTest(chi2.SphericalDomain(), None, pdf_func, sample_count=a.samples,
                                   res=a.res, ires=ires)
            t0 = time.perf_counter()
            t.tabulate_pdf()
            secs.append(time.perf_counter() - t0)
            tables.append(np.asarray(t.pdf, dtype=np.float64))
        dist = []
        for e, fine in zip(tables[:-1], tables[1:]):
            pos = fine > 0
            dist.append(float(np.sum((e[pos] - fine[pos]) ** 2 / fine[pos])))
        print(f.name[:51].ljust(52) + "".join(f"{x:10.3g}" for x in dist) + "   " + " ".join(f"{x:.1f}" for x in secs), flush=True)


if __name__ == "__main__":
    main()
