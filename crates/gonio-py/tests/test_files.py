"""The one file reader (issue 36, item 5): Python opens files through the library's reader, with
the same size limit per kind and the same messages as the CLI and the C ABI, one exception family
per fault, and never blocks on a FIFO."""

import os

import numpy as np
import pytest

import gonio


def write_pfm(path, w, h):
    r = np.arange(h, dtype=np.float32)[:, None]
    c = np.arange(w, dtype=np.float32)[None, :]
    v = 0.1 + (r * 7 + c * 3) / (w + h)
    img = np.stack([v, 0.5 * v, 0.25 * v], axis=-1).astype("<f4")
    with open(path, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
        f.write(img.tobytes())


def test_a_200_mb_sky_opens(tmp_path):
    p = tmp_path / "sky.pfm"
    write_pfm(p, 4096, 4096)
    assert os.path.getsize(p) > 200_000_000
    env = gonio.EnvMap(str(p), precision="float32")
    d, pdf, rgb = env.sample(np.array([[0.3, 0.6]], dtype=np.float32))
    assert pdf[0] > 0


def test_the_image_limit_is_the_library_s_message(tmp_path):
    big = tmp_path / "big.pfm"
    with open(big, "wb") as f:
        f.truncate((4 << 30) + 1)
    want = (f"{big}: the file has 4294967297 bytes, more than the limit of 4294967296 bytes for image "
            "files (4096 MiB; settable); not read")
    with pytest.raises(gonio.ParseError) as e:
        gonio.EnvMap(str(big))
    assert str(e.value) == want


def test_limits_are_settable_and_shared(tmp_path):
    assert gonio.read_limit("image") == 4 << 30
    assert gonio.read_limit("photometry") == 64 << 20
    p = tmp_path / "sky.pfm"
    write_pfm(p, 8, 4)
    gonio.set_read_limit("image", 100)
    try:
        with pytest.raises(gonio.ParseError, match="more than the limit of 100 bytes for image files"):
            gonio.EnvMap(str(p))
    finally:
        gonio.set_read_limit("image", 0)
    assert gonio.read_limit("image") == 4 << 30
    gonio.EnvMap(str(p))
    with pytest.raises(gonio.InputError, match="kind"):
        gonio.read_limit("video")


def test_one_exception_family_per_fault(tmp_path):
    # A missing file is FileNotFoundError everywhere, the path named once.
    for call in (gonio.read, gonio.read_brdf, gonio.EnvMap):
        name = str(tmp_path / ("missing" + {gonio.read: ".ies", gonio.read_brdf: ".binary"}.get(call, ".hdr")))
        with pytest.raises(FileNotFoundError) as e:
            call(name)
        assert str(e.value).count(name) == 1, str(e.value)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs on this platform")
def test_a_fifo_is_refused_without_blocking(tmp_path):
    for name in ("sky.hdr", "lamp.ies", "m.binary"):
        p = tmp_path / name
        os.mkfifo(p)
        call = {"sky.hdr": gonio.EnvMap, "lamp.ies": gonio.read, "m.binary": gonio.read_brdf}[name]
        with pytest.raises(OSError, match="FIFO"):
            call(str(p))
    with pytest.raises(OSError, match="character device"):
        gonio.EnvMap("/dev/zero")
