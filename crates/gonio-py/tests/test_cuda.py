"""gonio.cuda (docs/GPU.md): gonio_device.h on a CUDA device through CuPy.

The contract, on the device, against the library's float32 map (``Sampler.from_tables`` on the
same blob, float32 arrays): sample's directions within 1e-6 and its pdf within 8 f32 ulps (both
expected bit for bit), ``pdf`` and ``invert`` at the directions the library evaluates (it
normalises in float64 first) within 8 ulps and 1e-5 where the density is positive, NaN where it
is 0. Skipped, with the reason, without CuPy or a GPU; the blob checks and the kernel source run
everywhere. scripts/gpu-check.sh runs the same contract on more inputs, with timings.
"""

import importlib.util
import os
import pathlib

import numpy as np
import pytest

import gonio

REPO = pathlib.Path(__file__).resolve().parents[3]
HEADER = REPO / "crates" / "gonio-capi" / "include" / "gonio_device.h"
if HEADER.is_file():  # the header of this checkout, whether or not the wheel ships one
    os.environ.setdefault("GONIO_DEVICE_HEADER", str(HEADER))


def _cuda_module():
    """gonio.cuda from the installed package, else from the source tree."""
    try:
        from gonio import cuda

        return cuda
    except ImportError:
        src = REPO / "crates" / "gonio-py" / "python" / "gonio" / "cuda.py"
        spec = importlib.util.spec_from_file_location("gonio_cuda_source", src)
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
        return mod


cuda = _cuda_module()


def _cupy_or_skip():
    try:
        import cupy as cp
    except ImportError as e:
        pytest.skip(f"SKIPPED: CuPy is not installed ({e})")
    try:
        if cp.cuda.runtime.getDeviceCount() < 1:
            pytest.skip("SKIPPED: no CUDA device")
    except Exception as e:  # noqa: BLE001 - CUDA driver missing, etc.
        pytest.skip(f"SKIPPED: no usable CUDA device ({type(e).__name__}: {e})")
    return cp


def _points(n):
    g = 1.32471795724474602596
    i = np.arange(n, dtype=np.float64)
    u = np.stack([np.mod(0.5 + i / g, 1.0), np.mod(0.5 + i / (g * g), 1.0)], axis=1)
    u[:4] = [[0, 0], [1, 1], [0, 1], [1, 0]]
    return u.astype(np.float32)


def _unit(d):
    e = d.astype(np.float64)
    inv = 1.0 / np.sqrt(e[:, 0] * e[:, 0] + e[:, 1] * e[:, 1] + e[:, 2] * e[:, 2])
    return (e * inv[:, None]).astype(np.float32)


def _blobs():
    out = [("example", gonio.Sampler(gonio.example()).tables())]
    th = np.linspace(0, 90, 10)
    ph = np.linspace(0, 360, 13)[:-1]
    vals = 1.0 + np.outer(np.cos(np.radians(ph)) ** 2, np.cos(np.radians(th)))
    vals[3:5, 4:] = 0.0
    out.append(("hemisphere", gonio.Diagram(th, ph, vals).sampler(domain="hemisphere").tables()))
    env = sorted((REPO.parent / "shared" / "data" / "envmaps").glob("*.hdr"))
    if env:
        out.append(("envmap", gonio.EnvMap(str(env[0]), precision="float32").tables()))
    return out


BLOBS = _blobs()


def test_header_and_source_found():
    src = cuda.module_source()
    assert "gonio_device_sample" in src and "gonio_k_sample" in src
    assert cuda.header_path().name == "gonio_device.h"


def test_refuses_what_it_cannot_sample():
    f64 = gonio.Sampler(gonio.example()).tables(precision="float64")
    with pytest.raises(ValueError, match="float32"):
        cuda.DeviceSampler(f64)
    with pytest.raises(ValueError, match="not a gonio table blob"):
        cuda.DeviceSampler(b"\0" * 512)
    bad = bytearray(BLOBS[0][1])
    bad[300] ^= 1  # a table byte: the checksum no longer matches
    with pytest.raises(gonio.InputError):
        cuda.DeviceSampler(bytes(bad))


@pytest.mark.parametrize("name,blob", BLOBS, ids=[b[0] for b in BLOBS])
def test_contract_on_the_device(name, blob):
    cp = _cupy_or_skip()
    n = 1 << 16
    u = _points(n)
    host = gonio.Sampler.from_tables(blob)
    dev = cuda.DeviceSampler(blob)
    dirs, pdf = host.sample(u)
    d_dirs, d_pdf = (cp.asnumpy(a) for a in dev.sample(cp.asarray(u)))
    assert np.max(np.abs(d_dirs.astype(np.float64) - dirs)) <= 1e-6
    rel = np.abs(d_pdf.astype(np.float64) - pdf) / np.maximum(pdf.astype(np.float64), 1e-30)
    assert np.mean(rel <= 8 * 2.0**-23) >= 0.999, f"pdf beyond 8 ulps: {np.mean(rel > 8 * 2.0**-23)}"
    unit = _unit(dirs)  # what the library's pdf/invert evaluate
    pdf_at = host.pdf(dirs)
    d_pdf_at = cp.asnumpy(dev.pdf(cp.asarray(unit)))
    rel = np.abs(d_pdf_at.astype(np.float64) - pdf_at) / np.maximum(pdf_at.astype(np.float64), 1e-30)
    assert np.mean(rel <= 8 * 2.0**-23) >= 0.999
    pos = pdf_at > 0
    inv = host.invert(dirs[pos])
    d_inv = cp.asnumpy(dev.invert(cp.asarray(unit)))
    assert np.max(np.abs(d_inv[pos].astype(np.float64) - inv)) <= 1e-5
    assert np.isnan(d_inv[~pos]).all()
    # the structure-of-arrays calls give the same bits
    du, dv = cp.asarray(u[:, 0].copy()), cp.asarray(u[:, 1].copy())
    x, y, z, p = (cp.empty(n, dtype=cp.float32) for _ in range(4))
    dev.sample_soa(du, dv, x, y, z, p)
    soa = np.stack([cp.asnumpy(x), cp.asnumpy(y), cp.asnumpy(z)], axis=1)
    assert np.array_equal(soa.view(np.uint32), d_dirs.view(np.uint32))
    assert np.array_equal(cp.asnumpy(p).view(np.uint32), d_pdf.view(np.uint32))


def test_torch_tensors_in_and_out():
    cp = _cupy_or_skip()
    torch = pytest.importorskip("torch", reason="SKIPPED: PyTorch is not installed")
    if not torch.cuda.is_available():
        pytest.skip("SKIPPED: PyTorch without CUDA")
    dev = cuda.DeviceSampler(BLOBS[0][1])
    u = torch.rand(4096, 2, device="cuda", dtype=torch.float32)
    d, p = dev.sample(u)
    assert isinstance(d, torch.Tensor) and d.shape == (4096, 3) and p.shape == (4096,)
    torch.cuda.synchronize()
    ref_d, ref_p = dev.sample(cp.asarray(u.cpu().numpy()))
    assert np.array_equal(d.cpu().numpy(), cp.asnumpy(ref_d))
    assert np.array_equal(p.cpu().numpy(), cp.asnumpy(ref_p))
