"""The package gives the CLI's results for the same file, method and seed, bit for bit."""

import json
import subprocess

import numpy as np
import pytest

import gonio
from conftest import valid_corpus_files

# A few corpus files of different kinds (IES type C, type B, EULUMDAT, narrow spot), plus the
# built-in example; every method on each.
PICK = ["lm63_2002_lithonia_indx_spot_0p5deg.ies", "lm63_2002_lithonia_type_b_flood_quadrant.ies",
        "isym4_two_lamp_sets_144x73.ldt"]
METHODS = ["hds", "piecewise-constant", "bilinear", "rejection", "uniform"]


def inputs():
    files = {p.name: p for p in valid_corpus_files()}
    out = [pytest.param("example", id="example")]
    out += [pytest.param(files[n], id=n) for n in PICK if n in files]
    return out


def load(inp):
    return gonio.example() if inp == "example" else gonio.read(inp)


def run(bin_, *args):
    return subprocess.run([str(bin_), *map(str, args)], check=True, capture_output=True).stdout


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("inp", inputs())
@pytest.mark.parametrize("sequence", ["random", "sobol"])
def test_sample_pdf_invert_equal_the_cli(gonio_bin, tmp_path, inp, method, sequence):
    n, seed = 3000, 42
    out = tmp_path / "s.f64"
    run(gonio_bin, "sample", inp, "-n", n, "--sequence", sequence, "--seed", seed,
        "--method", method, "--format", "f64", "-o", out)
    cli = np.fromfile(out, dtype="<f8").reshape(n, 6)
    s = load(inp).sampler(method)
    u = gonio.sequence(n, sequence, seed=seed)
    np.testing.assert_array_equal(u, cli[:, :2])
    d, p = s.sample(u)
    np.testing.assert_array_equal(d, cli[:, 2:5])
    np.testing.assert_array_equal(p, cli[:, 5])

    # pdf and invert of the same directions through CSV (shortest round-trip decimals).
    dirs = tmp_path / "d.csv"
    dirs.write_text("x,y,z\n" + "".join(f"{x!r},{y!r},{z!r}\n" for x, y, z in d[:500].tolist()))
    rows = np.array([[float(v) for v in line.split(",")]
                     for line in run(gonio_bin, "pdf", inp, "--directions", dirs, "--method", method)
                     .decode().splitlines()[1:]])
    np.testing.assert_array_equal(s.pdf(d[:500]), rows[:, 3])
    if method != "rejection":
        rows = np.array([[float(v) for v in line.split(",")]
                         for line in run(gonio_bin, "invert", inp, "--directions", dirs, "--method", method)
                         .decode().splitlines()[1:]])
        np.testing.assert_array_equal(s.invert(d[:500]), rows[:, 3:5])


@pytest.mark.parametrize("inp", inputs()[:2])
def test_check_report_equals_the_cli(gonio_bin, inp):
    cli = subprocess.run([str(gonio_bin), "check", str(inp), "--quick", "--seed", "9", "--json"],
                         capture_output=True)
    assert cli.returncode in (0, 1), cli.stderr
    cli_report = json.loads(cli.stdout)
    report = gonio.check(load(inp), "hds", quick=True, seed=9)
    assert report == cli_report
    assert report["passed"] == (cli.returncode == 0)
