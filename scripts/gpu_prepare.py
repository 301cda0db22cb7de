"""Prepares, on this machine, what scripts/gpu-check.sh needs on a GPU machine that has neither
gonio, nor ../shared, nor network (scripts/gpu-prepare.sh runs it; docs/GPU.md):

* .gpudata/  blobs of the contract cases (float32, docs/TABLES.md) and the library's float32
  reference outputs on them (`refs/NAME.npz`: directions and pdf of `Sampler.sample` on
  gpu_common.points(n), `pdf` at those directions, `invert` there where the density is positive,
  NaN elsewhere); the environment maps as .hdr files (their blobs, 11.7 MB each, are rebuilt on
  the GPU machine by the gonio wheel and checked against the checksum recorded here); the timing
  grids 19 × 36 and 181 × 361 (the 1024 × 1024 grid and the 2048 × 1024 image are generated
  there); the light-tracing reference; manifest.json.
* .whl/  the gonio wheel (target/python-wheel), drjit 1.5.0 and mitsuba 3.9.1 for CPython 3.12
  manylinux x86_64 (pip download), mitsuba cut down to what gpu-check uses (cuda_ad_rgb, the
  envmap and bitmap plugins; the full wheel is 62.6 MB, more than the device tool carries).

Usage: python scripts/gpu_prepare.py [--n-ref N] [--no-wheels] [--no-data]
"""

import argparse
import ctypes
import hashlib
import base64
import json
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile
import zipfile

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import gpu_common as gc  # noqa: E402

REPO = pathlib.Path(__file__).resolve().parents[1]
SHARED = pathlib.Path(os.environ.get("GONIO_SHARED", REPO.parent / "shared" / "data"))
DATA = REPO / ".gpudata"
WHL = REPO / ".whl"
CORPUS_FILES = [
    "ies/lm63_2002_lithonia_area_full_h0_360.ies",
    "ldt/isym4_two_lamp_sets_144x73.ldt",
    "ies/lm63_2002_lithonia_type_b_flood_quadrant.ies",
]
MITSUBA = "mitsuba==3.9.1"
DRJIT = "drjit==1.5.0"


def lambert_blob(json_path):
    """The Lambert-sphere blob of a diagram through the C ABI (Python has no layout option)."""
    lib = os.environ.get("GONIO_CAPI_LIB", str(REPO / "target" / "debug" / "libgonio_capi.so"))
    L = ctypes.CDLL(lib)

    class Opts(ctypes.Structure):
        _fields_ = [("tolerance", ctypes.c_double), ("resolution", ctypes.c_size_t),
                    ("seed", ctypes.c_uint64), ("sphere_layout", ctypes.c_int32)]

    diag, samp = ctypes.c_void_p(), ctypes.c_void_p()
    assert L.gonio_diagram_read_path(str(json_path).encode(), 0, ctypes.byref(diag)) == 0
    o = Opts()
    L.gonio_build_options_default(ctypes.byref(o))
    o.sphere_layout = 1  # GONIO_SPHERE_LAYOUT_LAMBERT
    # GONIO_METHOD_HDS 0, GONIO_DOMAIN_SPHERE 2
    assert L.gonio_sampler_build_with(diag, 0, 2, ctypes.byref(o), ctypes.byref(samp)) == 0
    size = ctypes.c_size_t()
    assert L.gonio_sampler_tables(samp, diag, 4, None, 0, ctypes.byref(size)) == 0
    buf = (ctypes.c_uint8 * size.value)()
    assert L.gonio_sampler_tables(samp, diag, 4, buf, size.value, ctypes.byref(size)) == 0
    L.gonio_sampler_free(samp)
    L.gonio_diagram_free(diag)
    return bytes(buf)


def random_diagram(rng, n_theta, m_phi, hemisphere):
    th = np.linspace(0.0, 90.0 if hemisphere else 180.0, n_theta)
    ph = np.sort(rng.uniform(0, 360, m_phi)) if m_phi > 1 else np.array([0.0])
    ph = np.unique(np.round(ph, 3))
    v = rng.uniform(0.0, 1.0, (len(ph), n_theta)) ** 2
    v[v < 0.05] = 0.0  # some unlit nodes
    v[:, 0] = v[0, 0]  # one value at the pole
    if not hemisphere:
        v[:, -1] = v[0, -1]
    return th, ph, v


def reference(blob, u):
    """The library's float32 map on the blob: sample (dirs, pdf), and `pdf` (pdf_at) and `invert`
    (inv; NaN where the density is 0) of those directions (which the library normalises first:
    it evaluates gpu_common.library_unit(dirs))."""
    import gonio

    s = gonio.Sampler.from_tables(blob)
    dirs, pdf = s.sample(u)
    pdf_at = s.pdf(dirs)  # evaluated at gpu_common.library_unit(dirs)
    inv = np.full((len(u), 2), np.nan, dtype=np.float32)
    idx = np.nonzero(pdf_at > 0)[0]
    for attempt in range(51):  # the library refuses nothing here; a bound all the same
        if attempt == 50:
            raise RuntimeError("invert: more than 50 rows refused")
        try:
            inv[idx] = s.invert(dirs[idx])
            break
        except gonio.InputError as e:  # a row the reader refuses: drop it, name it
            msg = str(e)
            row = [int(w) for w in msg.replace(",", " ").replace(":", " ").split() if w.isdigit()]
            if not row:
                raise
            print(f"    invert refused row {idx[row[0]]}: {msg[:100]}")
            idx = np.delete(idx, row[0])
    return dict(dirs=dirs, pdf=pdf, pdf_at=pdf_at, inv=inv)


def checksum_field(blob):
    return int.from_bytes(blob[24:32], "little")


def prepare_data(n_ref):
    import gonio

    if DATA.exists():
        shutil.rmtree(DATA)
    (DATA / "blobs").mkdir(parents=True)
    (DATA / "refs").mkdir()
    (DATA / "envmaps").mkdir()
    u = gc.points(n_ref)
    manifest = {"n_ref": n_ref, "contract": [], "timing": [], "light": None}
    tmp = pathlib.Path(tempfile.mkdtemp())
    ex_json = tmp / "example.json"
    gonio.example().write(str(ex_json))
    rng = np.random.default_rng(20261204)
    cases = [("example_split", lambda: gonio.Sampler(gonio.example()).tables(), "split sphere")]
    try:
        lb = lambert_blob(ex_json)
        cases.append(("example_lambert", lambda: lb, "Lambert sphere"))
    except Exception as e:  # noqa: BLE001
        print(f"  SKIPPED the Lambert example (C ABI library: {e})")
    for rel in CORPUS_FILES:
        p = SHARED / "photometry" / rel
        if p.is_file():
            cases.append((p.stem, (lambda p=p: gonio.read(str(p)).sampler().tables()), "corpus, sphere"))
        else:
            print(f"  SKIPPED corpus file {p} (absent)")
    th, ph, v = random_diagram(rng, 25, 24, False)
    cases.append(("random_sphere_25x24", lambda: gonio.Diagram(th, ph, v).sampler(domain="sphere").tables(), "random, split sphere"))
    th2, ph2, v2 = random_diagram(rng, 10, 13, True)
    cases.append(("random_hemisphere_10x13", lambda: gonio.Diagram(th2, ph2, v2).sampler(domain="hemisphere").tables(), "random, hemisphere"))
    for name, make, what in cases:
        blob = make()
        (DATA / "blobs" / f"{name}.bin").write_bytes(blob)
        np.savez(DATA / "refs" / f"{name}.npz", **reference(blob, u))
        manifest["contract"].append(dict(name=name, kind=what, blob=f"blobs/{name}.bin",
                                         checksum=checksum_field(blob), bytes=len(blob)))
        print(f"  {name}: blob {len(blob)} bytes, reference on {n_ref} points")
    for hdr in sorted((SHARED / "envmaps").glob("*.hdr")):
        blob = gonio.EnvMap(str(hdr), precision="float32").tables()
        shutil.copy(hdr, DATA / "envmaps" / hdr.name)
        name = f"envmap_{hdr.stem}"
        np.savez(DATA / "refs" / f"{name}.npz", **reference(blob, u))
        manifest["contract"].append(dict(name=name, kind="environment map", blob=None,
                                         build=dict(envmap=f"envmaps/{hdr.name}"),
                                         checksum=checksum_field(blob), bytes=len(blob)))
        print(f"  {name}: blob {len(blob)} bytes (rebuilt on the GPU machine), reference on {n_ref} points")
    # Timing cases: generated grids (sphere, split) and a generated 2048 × 1024 image.
    for n_t, m_p in [(19, 36), (181, 361), (1024, 1024)]:
        name = f"grid_{n_t}x{m_p}"
        th, ph, v = gc.lobes(n_t, m_p)
        entry = dict(name=name, grid=[n_t, m_p], build=dict(lobes=[n_t, m_p]))
        blob = gonio.Diagram(th, ph, v).sampler(domain="sphere").tables()
        entry["checksum"] = checksum_field(blob)
        entry["bytes"] = len(blob)
        if len(blob) < 2_000_000:
            (DATA / "blobs" / f"{name}.bin").write_bytes(blob)
            entry["blob"] = f"blobs/{name}.bin"
        else:
            entry["blob"] = None
        manifest["timing"].append(entry)
        print(f"  {name}: blob {len(blob)} bytes" + (" (shipped)" if entry["blob"] else " (generated there)"))
    img = gc.env_image(2048, 1024)
    pfm = tmp / "env_2048x1024.pfm"
    gc.write_pfm(pfm, img)
    e = gonio.EnvMap(str(pfm), precision="float32")
    blob = e.tables()
    manifest["timing"].append(dict(name="envmap_2048x1024", grid=[e.height, e.width], blob=None,
                                   build=dict(env_image=[2048, 1024]), checksum=checksum_field(blob),
                                   bytes=len(blob)))
    print(f"  envmap_2048x1024: {e.width} x {e.height}, blob {len(blob)} bytes (generated there)")
    # Light tracing: the example luminaire's floor patches, reference and a host estimate.
    ex = gonio.example()
    ref = gc.floor_reference(ex.intensity, k=64)
    s = gonio.Sampler.from_tables((DATA / "blobs" / "example_split.bin").read_bytes())
    n_lt = 1 << 22
    uu = np.random.default_rng(7).random((n_lt, 2), dtype=np.float32)
    d, p = s.sample(uu)
    est = gc.light_trace(d, p, ex.intensity)
    err = gc.rel_rmse(est, ref)
    manifest["light"] = dict(blob="blobs/example_split.bin", k=64, floor=gc.FLOOR,
                             reference=ref.tolist(), host_rel_rmse_2p22=err)
    print(f"  light tracing (example, floor 12 x 7 patches): mean E {ref.mean():.4g} lx, host "
          f"estimate with 2^22 float32 samples: relative RMSE {err:.2e}")
    (DATA / "manifest.json").write_text(json.dumps(manifest, indent=1))
    shutil.rmtree(tmp)


def _record_line(name, data):
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{name},sha256={digest},{len(data)}"


KEEP_PLUGINS = {"envmap.so", "bitmap.so", "d65.so", "regular.so", "uniform.so", "irregular.so", "srgb.so", "constant.so"}
DROP_PREFIXES = ("mitsuba/include/", "mitsuba/cmake/", "mitsuba/pkgconfig/", "mitsuba/data/",
                 "share/", "mitsuba/mitsuba_stubs/")


def keep_in_mitsuba(n, variants=("cuda_ad_rgb", "scalar_rgb")):
    """Whether gpu-check needs the wheel's file `n`: the Python sources, the shared libraries,
    the `variants`' extension modules and the envmap and bitmap plugins."""
    base = n.split("/")[-1]
    if n.startswith(DROP_PREFIXES) or n == "mitsuba/mitsuba":  # headers, data, the CLI renderer
        return False
    if n.startswith("mitsuba/plugins/"):
        return base in KEEP_PLUGINS
    top_level_variant = (n.count("/") == 1 and base.endswith(".so") and not base.startswith("lib")
                         and not base.startswith("mitsuba_"))
    if top_level_variant:
        return any(base.startswith(v + ".") for v in variants)
    return True


def strip_mitsuba(src, dst):
    """A valid wheel of mitsuba with only what gpu-check uses (RECORD rewritten)."""
    zin = zipfile.ZipFile(src)
    record_name = next(n for n in zin.namelist() if n.endswith(".dist-info/RECORD"))
    kept = [i for i in zin.infolist() if i.filename != record_name and keep_in_mitsuba(i.filename)]
    lines = []
    with zipfile.ZipFile(dst, "w", compression=zipfile.ZIP_DEFLATED, compresslevel=9) as zout:
        for info in kept:
            data = zin.read(info)
            zout.writestr(info, data, compress_type=zipfile.ZIP_DEFLATED, compresslevel=9)
            lines.append(_record_line(info.filename, data))
        lines.append(f"{record_name},,")
        zout.writestr(record_name, "\n".join(lines) + "\n")


def prepare_wheels():
    if WHL.exists():
        shutil.rmtree(WHL)
    WHL.mkdir()
    gw = sorted((REPO / "target" / "python-wheel").glob("gonio-*.whl"))
    if not gw:
        print("  the gonio wheel is missing: build it (maturin build, see scripts/test-python.sh)")
    else:
        shutil.copy(gw[-1], WHL / gw[-1].name)
        print(f"  {gw[-1].name}")
    cache = REPO / "target" / "gpu-wheel-cache"
    cache.mkdir(parents=True, exist_ok=True)
    cmd = [sys.executable, "-m", "pip", "download", "-q", "--disable-pip-version-check",
           "--only-binary=:all:", "--no-deps", "--python-version", "3.12", "--implementation", "cp",
           "--platform", "manylinux_2_28_x86_64", MITSUBA, DRJIT, "-d", str(cache)]
    print("  " + " ".join(cmd[2:]))
    r = subprocess.run(cmd)
    if r.returncode != 0:
        print("  SKIPPED mitsuba/drjit: pip download failed")
        return
    dj = sorted(cache.glob("drjit-1.5.0-cp312-*.whl"))[-1]
    shutil.copy(dj, WHL / dj.name)
    mw = sorted(cache.glob("mitsuba-3.9.1-cp312-*.whl"))[-1]
    strip_mitsuba(mw, WHL / mw.name)
    print(f"  {dj.name}, {mw.name} (cut from {mw.stat().st_size / 1e6:.1f} MB to "
          f"{(WHL / mw.name).stat().st_size / 1e6:.1f} MB)")


def du(p):
    return sum(f.stat().st_size for f in p.rglob("*") if f.is_file()) if p.exists() else 0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n-ref", type=int, default=1 << 15)
    ap.add_argument("--no-wheels", action="store_true")
    ap.add_argument("--no-data", action="store_true")
    a = ap.parse_args()
    if not a.no_data:
        print("== .gpudata")
        prepare_data(a.n_ref)
    if not a.no_wheels:
        print("== .whl")
        prepare_wheels()
    total = du(DATA) + du(WHL)
    print(f"== sizes: .gpudata {du(DATA) / 1e6:.1f} MB, .whl {du(WHL) / 1e6:.1f} MB, "
          f"total {total / 1e6:.1f} MB ({total / 2**20:.1f} MiB; the device tool carries 64 MiB)")
    if total > 60e6:
        print("gpu_prepare: TOO LARGE for the device tool: lower --n-ref")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
