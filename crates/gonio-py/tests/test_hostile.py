"""Issue 40's reproducers through Python, generated here (the CLI's are in crates/gonio-cli/tests,
the C ABI's in crates/gonio-capi/src/tests_abuse.rs): every one a typed, located error or the right
result, never an infinite value, a hang, or data read wrong in silence."""

import json
import os

import numpy as np
import pytest

import gonio


def _brdf_json(value, bom=False):
    js = dict(format="gonio-brdf", version=1, symmetry="isotropic", channels=3, theta_i_deg=[0, 45, 90],
              phi_i_deg=[0], theta_o_deg=[0, 45, 90], phi_o_deg=[0, 90, 180, 270],
              values=[value] * (3 * 3 * 3 * 4))
    text = json.dumps(js)
    return ("\ufeff" + text).encode("utf-8") if bom else text.encode()


def test_item1_huge_brdf_values_are_refused_by_name(tmp_path):
    p = tmp_path / "huge.json"
    p.write_bytes(_brdf_json(1.7e308))
    with pytest.raises(gonio.GonioError) as e:
        gonio.read_brdf(p)
    assert "1.7e308" in str(e.value) or "1.7e+308" in str(e.value), str(e.value)
    # 1e307 is within the limit: finite albedo and weights.
    p.write_bytes(_brdf_json(1e307))
    b = gonio.read_brdf(p)
    _, pdf, w = b.sampler().sample([0.3, 0.0, 0.95], gonio.sequence(64))
    assert np.all(np.isfinite(w)) and np.all(np.isfinite(b.albedo([[0.3, 0.0, 0.95]])))


def test_item2_envmap_refuses_non_regular_files_at_once(tmp_path):
    # OSError, as every reader words a file that is not a regular one (docs/PYTHON.md).
    with pytest.raises(OSError) as e:
        gonio.EnvMap("/dev/zero")
    assert "/dev/zero" in str(e.value) and "regular" in str(e.value), str(e.value)
    fifo = tmp_path / "sky.hdr"
    os.mkfifo(fifo)
    with pytest.raises(OSError):
        gonio.EnvMap(str(fifo))


def test_item5_pfm_with_crlf_is_refused_not_read_a_byte_off(tmp_path):
    p = tmp_path / "crlf.pfm"
    p.write_bytes(b"PF\n2 2\n-1.0\r\n" + np.full(12, 0.7, "<f4").tobytes())
    try:
        env = gonio.EnvMap(str(p))
    except gonio.GonioError as e:
        assert "\\r\\n" in str(e) or "header" in str(e), str(e)
    else:  # read right, or not at all: never 4.17e-8 in silence
        _, _, rgb = env.sample(gonio.sequence(16))
        assert np.allclose(rgb, 0.7, rtol=1e-6), rgb


def test_item5_ply_nan_normals_and_fractional_indices_are_located(tmp_path):
    head = ("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
            "property float nx\nproperty float ny\nproperty float nz\nelement face 1\n"
            "property list uchar float vertex_indices\nend_header\n")
    p = tmp_path / "nan.ply"
    p.write_text(head + "0 0 0 nan 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n")
    with pytest.raises(gonio.InputError) as e:
        gonio.read_mesh(p)
    assert "nan" in str(e.value).lower() and "nan.ply" in str(e.value), str(e.value)
    p.write_text(head + "0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1.5 2\n")
    with pytest.raises(gonio.InputError) as e:
        gonio.read_mesh(p)
    assert "1.5" in str(e.value), str(e.value)


def test_item6_bom_json_brdf_reads_and_messages_are_printable(tmp_path):
    p = tmp_path / "bom.json"
    p.write_bytes(_brdf_json(0.2, bom=True))
    assert gonio.read_brdf(p).channels == 3
    obj = tmp_path / "ctl.obj"
    obj.write_bytes(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 \x1b[31m\x00\n")
    with pytest.raises(gonio.InputError) as e:
        gonio.read_mesh(obj)
    msg = str(e.value)
    assert "\x1b" not in msg and "\x00" not in msg, repr(msg)
