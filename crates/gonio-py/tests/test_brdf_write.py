"""BRDF writers in Python (issue 41 item 4): ``gonio.analytic_brdf`` (the library's analytic BRDFs
in the MERL, UTIA and JSON layouts) and ``Brdf.write`` (a table to JSON exactly, to MERL and UTIA by
its interpolant), read back by ``gonio.read_brdf``."""

import numpy as np
import pytest

import gonio


def _dir(t, p):
    t, p = np.radians(t), np.radians(p)
    return np.array([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)])


def test_analytic_lambert_in_every_layout(tmp_path):
    albedo = [0.8, 0.5, 0.2]
    wi = _dir(30, 40)
    wo = np.array([_dir(t, p) for t in (0, 20, 50, 70) for p in (0, 130, 250)])
    for fmt, ext in (("json", "json"), ("merl", "binary"), ("utia", "bin")):
        path = gonio.analytic_brdf(tmp_path / f"l.{ext}", "lambert", format=fmt, albedo=albedo)
        b = gonio.read_brdf(path)
        assert b.channels == 3
        # Constant per channel: every layout reads it back exactly (UTIA's encoding to 1e-12).
        assert np.allclose(b.eval(wi, wo), np.array(albedo) / np.pi, rtol=1e-9)


def test_analytic_ggx_json_and_merl_agree(tmp_path):
    j = gonio.read_brdf(gonio.analytic_brdf(tmp_path / "g.json", "ggx", alpha_x=0.4, n_theta=46, n_phi=90))
    m = gonio.read_brdf(gonio.analytic_brdf(tmp_path / "g.binary", "ggx", format="merl", alpha_x=0.4))
    wi = _dir(35, 0)
    wo = np.array([_dir(t, p) for t in (5, 25, 45, 60) for p in (150, 180, 210)])
    fj, fm = j.eval(wi, wo)[:, 0], m.eval(wi, wo)[:, 0]
    # Two resamplings of the same lobe (a 2° × 4° grid; MERL's half-angle cells, resampled to it).
    assert np.all(np.abs(fm / fj - 1) < 0.1), np.abs(fm / fj - 1).max()
    assert j.symmetry == "isotropic" and m.symmetry == "isotropic"
    u = gonio.read_brdf(gonio.analytic_brdf(tmp_path / "a.bin", "ggx", format="utia", alpha_x=0.4, alpha_y=0.2))
    assert u.symmetry == "anisotropic"


def test_brdf_write_round_trips(tmp_path):
    src = gonio.read_brdf(gonio.analytic_brdf(tmp_path / "a.json", "ggx", alpha_x=0.5, alpha_y=0.3,
                                              n_theta=7, n_phi=12))
    back = gonio.read_brdf(src.write(tmp_path / "b.json"))
    for g0, g1 in zip(src.grid, back.grid):
        assert np.allclose(g0, g1, rtol=0, atol=1e-12)
    wi = _dir(40, 10)
    wo = np.array([_dir(t, p) for t in (10, 40, 70) for p in (0, 100, 200, 300)])
    assert np.allclose(src.eval(wi, wo), back.eval(wi, wo), rtol=1e-12)
    # UTIA: the interpolant at UTIA's own nodes, read back at those nodes.
    ut = gonio.read_brdf(src.write(tmp_path / "b.bin", "utia"))
    nodes = np.array([_dir(t, p) for t in (0, 15, 30, 45, 60, 75) for p in (0, 7.5, 90, 352.5)])
    wi_n = _dir(45, 7.5)
    assert np.allclose(ut.eval(wi_n, nodes), src.eval(wi_n, nodes), rtol=1e-9, atol=1e-12)
    # MERL holds isotropic tables only.
    with pytest.raises(gonio.InputError, match="isotropic"):
        src.write(tmp_path / "b.binary", "merl")
    iso = gonio.read_brdf(gonio.analytic_brdf(tmp_path / "i.json", "lambert", n_theta=5, n_phi=4))
    m = gonio.read_brdf(iso.write(tmp_path / "i.binary", "merl"))
    assert np.allclose(m.eval(wi, wo), iso.eval(wi, wo), rtol=1e-9)


def test_writer_errors(tmp_path):
    with pytest.raises(gonio.InputError, match="format"):
        gonio.analytic_brdf(tmp_path / "x", "lambert", format="exr")
    with pytest.raises(gonio.InputError, match="family"):
        gonio.analytic_brdf(tmp_path / "x", "phong")
    with pytest.raises(gonio.InputError, match="alpha"):
        gonio.analytic_brdf(tmp_path / "x", "ggx", alpha_x=0.0)
    with pytest.raises(gonio.InputError, match="isotropic"):
        gonio.analytic_brdf(tmp_path / "x", "ggx", format="merl", alpha_x=0.3, alpha_y=0.1)
    with pytest.raises(gonio.InputError, match="albedo"):
        gonio.analytic_brdf(tmp_path / "x", "lambert", albedo=[1.0, float("nan"), 0.0])
    with pytest.raises(gonio.GonioError):
        gonio.analytic_brdf(tmp_path / "no" / "such" / "dir.json", "lambert")
