"""gonio.read_mesh (issue 36: one loader for every input kind, a 60 MB PLY through Python): a
binary PLY of about 60 MB generated here (not committed) reads through the one file reader with
its counts and values; OBJ and ASCII PLY; the mesh size limit and a missing file give the
documented exceptions; the arrays go to texture_uv."""

import numpy as np
import pytest

import gonio


def _binary_ply(path, vertices, faces):
    head = (f"ply\nformat binary_little_endian 1.0\nelement vertex {len(vertices)}\n"
            "property float x\nproperty float y\nproperty float z\n"
            f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n").encode()
    rec = np.zeros(len(faces), dtype=[("n", "u1"), ("i", "<i4", 3)])
    rec["n"] = 3
    rec["i"] = faces
    with open(path, "wb") as f:
        f.write(head)
        f.write(np.ascontiguousarray(vertices, dtype="<f4").tobytes())
        f.write(rec.tobytes())


def test_a_60_mb_ply_reads(tmp_path):
    rng = np.random.default_rng(3)
    n = 2_400_000
    v = rng.standard_normal((n, 3)).astype(np.float32)
    f = rng.integers(0, n, size=(n, 3), dtype=np.int64)
    path = tmp_path / "big.ply"
    _binary_ply(path, v, f)
    size = path.stat().st_size
    assert size > 60e6
    m = gonio.read_mesh(path)
    assert m["vertices"].shape == (n, 3) and m["faces"].shape == (n, 3)
    assert m["faces"].dtype == np.uint32
    assert np.array_equal(m["vertices"], v.astype(np.float64))
    assert np.array_equal(m["faces"], f)
    assert m["normals"].shape == (0, 3)


def test_obj_and_ascii_ply_and_texture_uv(tmp_path):
    obj = tmp_path / "oct.obj"
    obj.write_text("v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n"
                   "f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n")
    m = gonio.read_mesh(obj)
    assert m["vertices"].shape == (6, 3) and m["faces"].shape == (8, 3)
    uv = gonio.texture_uv(m["vertices"], m["faces"])
    assert uv["uvs"].shape[1] == 2
    ply = tmp_path / "quad.ply"
    ply.write_text("ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                   "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                   "0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n")
    q = gonio.read_mesh(ply)
    assert q["faces"].shape == (2, 3) and any("triangulated" in w for w in q["warnings"])


def test_refusals(tmp_path):
    with pytest.raises(FileNotFoundError):
        gonio.read_mesh(tmp_path / "missing.ply")
    bad = tmp_path / "bad.obj"
    bad.write_text("v 1 2\nf 1 2 3\n")
    with pytest.raises(gonio.InputError, match="bad.obj"):
        gonio.read_mesh(bad)
    big = tmp_path / "big.obj"
    big.write_bytes(b"v 0 0 0\n" * 100)
    gonio.set_read_limit("mesh", 99)
    try:
        with pytest.raises(gonio.GonioError, match="limit"):
            gonio.read_mesh(big)
    finally:
        gonio.set_read_limit("mesh", 0)
