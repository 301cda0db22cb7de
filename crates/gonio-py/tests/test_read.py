"""Reading: the corpus, bytes/str input, header fields, warnings, located errors, writing back."""

import json

import numpy as np
import pytest

import gonio
from conftest import corpus_files, corpus_params

INVALID = [p for p in corpus_files() if p.name.startswith("invalid_")]


@pytest.mark.parametrize("path", corpus_params())
def test_every_corpus_file_reads(path):
    d = gonio.read(path)
    assert d.source == path.suffix.lower()[1:]
    assert d.domain == "sphere"
    n, m = d.theta_deg.shape[0], d.phi_deg.shape[0]
    assert d.values.shape == (m, n)
    assert np.all(np.diff(d.theta_deg) > 0) and np.all(np.diff(d.phi_deg) > 0)
    assert d.theta_deg[0] >= 0 and d.theta_deg[-1] <= 180 and d.phi_deg[-1] < 360
    assert np.all(d.values >= 0) and d.flux > 0
    h = d.header
    assert h["format"] == d.source
    assert h["candela"].shape == h["raw_values"].shape
    np.testing.assert_allclose(h["candela"], h["raw_values"] * h["intensity_scale"], rtol=1e-12)
    assert h["max_intensity_cd"] == pytest.approx(h["candela"].max(), rel=1e-12)
    # Type C: the measured values are kept exactly, so the diagram's maximum is the file's.
    if h["photometric_type"] == "C":
        assert d.values.max() == pytest.approx(h["max_intensity_cd"], rel=1e-12)
    assert ("ies" in h) == (d.source == "ies") and ("ldt" in h) == (d.source == "ldt")
    for w in d.warnings:
        assert w.startswith(str(path) + ":") and ": warning: " in w
    # The same bytes through read_bytes give the same diagram (no TILT file in the corpus).
    b = gonio.read_bytes(path.read_bytes(), d.source, name=path.name)
    np.testing.assert_array_equal(b.values, d.values)
    np.testing.assert_array_equal(b.theta_deg, d.theta_deg)


@pytest.mark.parametrize("path", INVALID or [pytest.param(None, marks=pytest.mark.skip(reason="SKIPPED: corpus not found"))])
def test_invalid_corpus_files_raise_located_errors(path):
    with pytest.raises(gonio.ParseError) as e:
        gonio.read(path)
    err = e.value
    assert isinstance(err, ValueError)
    assert err.file == str(path) and err.line > 0
    assert str(err).startswith(f"{path}:{err.line}:")


def test_ies_text_and_header_fields():
    text = """IESNA:LM-63-2002
[TEST] T1
[MANUFAC] ACME
TILT=NONE
1 1000 1 3 1 1 2 0.5 0.5 0.1
1.0 1.0 100
0 45 90
0
100 80 0
"""
    d = gonio.read_bytes(text, "ies", name="t.ies")
    h = d.header
    assert h["version"] == "LM-63-2002" and h["photometric_type"] == "C"
    assert {k["key"]: k["value"] for k in h["keywords"]} == {"TEST": "T1", "MANUFAC": "ACME"}
    assert h["ies"]["lumens_per_lamp"] == 1000 and h["ies"]["units_type"] == 2
    assert h["symmetry"] == "Rotational" and h["tilt"]["kind"] == "none"
    np.testing.assert_array_equal(h["vertical_angles_deg"], [0, 45, 90])
    # γ = 0 (nadir) is θ = 180°: the diagram lies in θ ∈ [90°, 180°] plus completion.
    assert d.theta_deg[-1] == 180.0
    s = d.sampler()
    # The peak (100 cd at nadir) is straight down, −z.
    np.testing.assert_allclose(d.intensity([[0, 0, -1.0]]), [100.0], rtol=1e-12)
    assert s.pdf([[0, 0, -1.0]])[0] > s.pdf([[1.0, 0, -1.0]])[0]
    assert gonio.read_bytes(text.encode(), "ies").values.tolist() == d.values.tolist()


def test_parse_errors_carry_file_line_column():
    bad = "IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 3 1 1 2 0.5 0.5 0.1\n1.0 1.0 100\n0 45 x\n0\n100 80 0\n"
    with pytest.raises(gonio.ParseError) as e:
        gonio.read_bytes(bad, "ies", name="bad.ies")
    assert (e.value.file, e.value.line) == ("bad.ies", 5)
    assert e.value.column == 6
    assert str(e.value).startswith("bad.ies:5:6: ")
    with pytest.raises(gonio.ParseError) as e:
        gonio.read_bytes('{"theta_deg": [0, 90],\n "phi_deg": [0], "values": [[1, 2]], "x": 1}', "json", name="d.json")
    assert e.value.line == 2 and str(e.value).startswith("d.json:2:")
    with pytest.raises(gonio.InputError, match="unknown format"):
        gonio.read_bytes(b"", "csv")
    with pytest.raises(gonio.InputError, match="bytes or str"):
        gonio.read_bytes(12, "ies")


def test_read_refuses_unknown_extensions_and_missing_files(tmp_path):
    p = tmp_path / "d.txt"
    p.write_text("{}")
    with pytest.raises(gonio.InputError, match=r"unknown input format `\.txt`"):
        gonio.read(p)
    with pytest.raises(FileNotFoundError):
        gonio.read(tmp_path / "missing.ies")
    with pytest.raises(OSError, match="not a regular file"):
        gonio.read(tmp_path, format="json")


def test_json_round_trip_and_formats(tmp_path):
    d = gonio.example()
    p = tmp_path / "e.json"
    d.write(p)
    back = gonio.read(p)
    np.testing.assert_array_equal(back.values, d.values)
    np.testing.assert_array_equal(back.theta_deg, d.theta_deg)
    assert json.loads(d.to_json())["phi_deg"] == d.phi_deg.tolist()
    for fmt in ["ies", "ldt"]:
        q = tmp_path / f"e.{fmt}"
        d.write(q)
        r = gonio.read(q)
        # The writers keep values bit for bit and angles to the rounding of 180° − (180° − θ).
        np.testing.assert_array_equal(r.values, d.values)
        np.testing.assert_allclose(r.theta_deg, d.theta_deg, rtol=0, atol=1e-9)
        assert r.flux == pytest.approx(d.flux, rel=1e-9)
        assert d.dumps(fmt).encode() == q.read_bytes()
    with pytest.raises(gonio.InputError, match="unknown output format"):
        d.write(tmp_path / "e.csv")


@pytest.mark.parametrize("path", corpus_params()[:3])
def test_convert_matches_write(path, tmp_path):
    out = tmp_path / "x.ldt"
    gonio.convert(path, out)
    d = gonio.read(path)
    assert out.read_bytes() == d.dumps("ldt", luminaire=path.stem).encode()
    np.testing.assert_array_equal(gonio.read(out).values, d.values)


def test_tilt_file_is_resolved_next_to_the_ies_file(tmp_path):
    (tmp_path / "lamp.tlt").write_text("1\n3\n0 45 90\n0.5 0.75 1.0\n")
    ies = """IESNA:LM-63-2002
TILT=lamp.tlt
1 1000 1 3 1 1 2 0.5 0.5 0.1
1.0 1.0 100
0 45 90
0
100 80 0
"""
    (tmp_path / "t.ies").write_text(ies)
    d = gonio.read(tmp_path / "t.ies")
    t = d.header["tilt"]
    assert t["kind"] == "file" and t["file"] == "lamp.tlt" and t["geometry"] == 1
    np.testing.assert_array_equal(t["factors"], [0.5, 0.75, 1.0])
    # The factor at the tilt angle 0° (0.5) is applied to every intensity.
    assert d.header["intensity_scale"] == pytest.approx(0.5)
    np.testing.assert_allclose(d.intensity([[0, 0, -1.0]]), [50.0], rtol=1e-12)
    # Without a directory (read_bytes) the TILT file cannot be had: a located error.
    with pytest.raises(gonio.ParseError, match="lamp.tlt"):
        gonio.read_bytes(ies, "ies", name="t.ies")
