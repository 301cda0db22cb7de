"""The table blob from Python (docs/TABLES.md): Sampler.tables / EnvMap.tables write it, and
Sampler.from_tables reads it back into a sampler that gives the writer's bits in the blob's
precision; a damaged blob raises InputError naming what is wrong."""

import os
import struct

import numpy as np
import pytest

import gonio

ENVMAPS = os.environ.get("GONIO_ENVMAPS", os.path.join(os.path.dirname(__file__), "../../../../shared/data/envmaps"))


def halton(n):
    def rad(i, b):
        f, r = 1.0, 0.0
        while i:
            f /= b
            r += f * (i % b)
            i //= b
        return r

    return np.array([[rad(i + 1, 2), rad(i + 1, 3)] for i in range(n)])


@pytest.mark.parametrize("precision,dtype", [("float32", np.float32), ("float64", np.float64)])
def test_example_round_trips_bit_for_bit(precision, dtype):
    s = gonio.example().sampler()
    blob = s.tables(precision=precision)
    assert blob[:8] == b"GONIOTAB" and len(blob) % 64 == 0
    assert struct.unpack_from("<I", blob, 32)[0] == (4 if precision == "float32" else 8)
    assert struct.unpack_from("<I", blob, 40)[0] == 1  # photometric frame
    back = gonio.Sampler.from_tables(blob)
    assert back.method == "hds" and back.domain == s.domain
    u = halton(5000).astype(dtype)
    da, pa = s.sample(u)
    db, pb = back.sample(u)
    assert np.array_equal(da.view(np.uint8), db.view(np.uint8))
    assert np.array_equal(pa.view(np.uint8), pb.view(np.uint8))
    assert np.array_equal(s.pdf(da).view(np.uint8), back.pdf(da).view(np.uint8))
    assert np.array_equal(s.invert(da).view(np.uint8), back.invert(da).view(np.uint8))
    # The grid target comes back: target_pdf equals the writer's on the sphere.
    d64 = da.astype(np.float64)
    np.testing.assert_allclose(back.target_pdf(d64), s.target_pdf(d64), rtol=1e-9, atol=0)
    # A read-back map writes the same blob again.
    assert back.tables(precision=precision) == blob


def test_envmap_tables_carry_the_image(tmp_path):
    # A small sky written as PFM (little-endian: scale < 0), bottom row first.
    w, h = 8, 4
    rgb = np.linspace(0.1, 3.0, w * h * 3, dtype=np.float32).reshape(h, w, 3)
    p = tmp_path / "sky.pfm"
    with open(p, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
        f.write(rgb[::-1].astype("<f4").tobytes())
    for prec in ("float64", "float32"):
        env = gonio.EnvMap(str(p), precision=prec)
        blob = env.tables()
        assert struct.unpack_from("<I", blob, 40)[0] == 2  # environment-map frame
        assert struct.unpack_from("<II", blob, 88) == (w, h)
        back = gonio.Sampler.from_tables(blob)
        u = halton(2000).astype(np.float32)
        # The writer's float32 map: the sampler's float32 batch (float64 map) or the map itself.
        da, pa = env.sampler().sample(u) if prec == "float64" else env.sample(u)[:2]
        db, pb = back.sample(u)
        assert np.array_equal(da.astype(np.float32).view(np.uint8), db.view(np.uint8))
        assert np.array_equal(pa.astype(np.float32).view(np.uint8), pb.view(np.uint8))
    with pytest.raises(gonio.InputError, match="float64 map"):
        gonio.EnvMap(str(p), precision="float32").tables(precision="float64")


def test_damaged_blobs_are_refused_with_their_reason():
    blob = bytearray(gonio.example().sampler().tables())
    with pytest.raises(gonio.InputError, match="magic"):
        gonio.Sampler.from_tables(b"X" + bytes(blob[1:]))
    with pytest.raises(gonio.InputError, match="bytes, but"):
        gonio.Sampler.from_tables(bytes(blob[:-64]))
    bad = bytearray(blob)
    bad[1000] ^= 0x10
    with pytest.raises(gonio.InputError, match="checksum"):
        gonio.Sampler.from_tables(bytes(bad))
    with pytest.raises(gonio.InputError, match="precision"):
        gonio.example().sampler().tables(precision="float16")
    with pytest.raises(gonio.InputError, match="no tables"):
        gonio.example().sampler("uniform").tables()
