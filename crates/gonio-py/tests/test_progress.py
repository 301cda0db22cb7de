"""The progress= option of the long calls (issue 41 item 4): a callable sees (what, fraction)
with fractions in [0, 1], non-decreasing, ending at 1; `check` reports its battery's items as
they run; an exception of the callable ends the call and propagates; True works with and without
tqdm; a value that is neither is a TypeError."""

import sys

import numpy as np
import pytest

import gonio


class Recorder:
    def __init__(self):
        self.calls = []

    def __call__(self, what, fraction):
        self.calls.append((what, fraction))


def _sane(calls):
    fr = [f for _, f in calls]
    assert fr and all(0.0 <= f <= 1.0 for f in fr) and fr == sorted(fr) and fr[-1] == 1.0, calls


def test_check_reports_its_items():
    r = Recorder()
    rep = gonio.check(gonio.example(), quick=True, samples=20000, progress=r)
    assert rep["passed"] in (True, False)
    _sane(r.calls)
    items = {w for w, _ in r.calls}
    assert "chi-square" in items and len(r.calls) >= 3, r.calls


def test_staged_calls(tmp_path):
    path = tmp_path / "sky.pfm"
    data = np.ones((4, 8, 3), dtype="<f4")
    path.write_bytes(b"PF\n8 4\n-1.0\n" + data.tobytes())
    for call in (
        lambda p: gonio.EnvMap(str(path), progress=p),
        lambda p: gonio.read_brdf(gonio.analytic_brdf(tmp_path / "l.json", "lambert", n_theta=5, n_phi=4), progress=p),
        lambda p: gonio.texture_uv([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]],
                                   [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5],
                                    [0, 3, 5]], progress=p),
    ):
        r = Recorder()
        call(r)
        _sane(r.calls)
        assert r.calls[-1][0] == "done"


def test_an_exception_of_the_callable_propagates():
    def boom(what, fraction):
        if fraction > 0.2:
            raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        gonio.check(gonio.example(), quick=True, samples=200000, progress=boom)


def test_true_and_bad_values(capsys, monkeypatch):
    # Without tqdm: one line per stage on stderr.
    monkeypatch.setitem(sys.modules, "tqdm", None)
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)
    gonio.EnvMap.__init__  # noqa: B018 (the class exists)
    gonio.check(gonio.example(), quick=True, samples=20000, progress=True)
    err = capsys.readouterr().err
    assert "gonio check:" in err and "100 %" in err
    with pytest.raises(TypeError, match="progress"):
        gonio.check(gonio.example(), quick=True, progress=42)


def test_true_draws_a_tqdm_bar(capsys):
    pytest.importorskip("tqdm", reason="SKIPPED: tqdm is not installed (requirements-test.txt has it)")
    gonio.check(gonio.example(), quick=True, samples=20000, progress=True)
    err = capsys.readouterr().err
    assert "gonio check" in err and "%" in err
