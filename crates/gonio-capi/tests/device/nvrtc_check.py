"""Device code proven without a device (scripts/test-device.sh).

Compiles, with NVRTC from the pip wheel (ctypes on libnvrtc, no GPU, no CUDA toolkit), the CUDA
sources that include gonio_device.h to PTX for compute_80 and compute_90:

* crates/gonio-capi/tests/device/kernels.cu (structure-of-arrays sample / pdf / invert / target
  with the view by value, the light-tracing kernel of docs/GPU.md and its reference);
* gonio.cuda's module (the header's text followed by gonio/cuda.py's KERNEL_SOURCE);
* the peers of scripts/gpu_check.py (a pbrt-v4-style sampler, a trivial kernel);

then assembles each PTX with ptxas (from the nvcc wheel) for sm_80 / sm_90 with -v and prints,
per kernel, registers per thread, stack frame and spill bytes. Exit 1 on any compile or assembly
error (the log is printed), 0 otherwise. NVRTC's defaults are kept (FMA contraction on: the
header writes every operation as an explicit round-to-nearest intrinsic).

Usage: python nvrtc_check.py [--json OUT.json]
"""

import ctypes
import glob
import json
import os
import pathlib
import re
import subprocess
import sys
import tempfile
import importlib.util

HERE = pathlib.Path(__file__).resolve().parent
REPO = HERE.parents[3]
INCLUDE = REPO / "crates" / "gonio-capi" / "include"
CUDA_PY = REPO / "crates" / "gonio-py" / "python" / "gonio" / "cuda.py"
GPU_CHECK = REPO / "scripts" / "gpu_check.py"
ARCHS = ("80", "90")


def site_dirs():
    import site

    dirs = list(site.getsitepackages()) + [site.getusersitepackages()] + sys.path
    return [d for d in dict.fromkeys(dirs) if d and os.path.isdir(d)]


def find_one(patterns):
    for d in site_dirs():
        for pat in patterns:
            hits = sorted(glob.glob(os.path.join(d, pat)))
            if hits:
                return hits[-1]
    return None


def load_nvrtc():
    lib = find_one(["nvidia/cu13/lib/libnvrtc.so.*", "nvidia/cuda_nvrtc/lib/libnvrtc.so.*"])
    if lib is None:
        raise FileNotFoundError("libnvrtc not found in the nvidia-cuda-nvrtc wheel")
    libdir = os.path.dirname(lib)
    # libnvrtc dlopens its builtins library by name: load it first, globally.
    for b in sorted(glob.glob(os.path.join(libdir, "libnvrtc-builtins.so*"))):
        try:
            ctypes.CDLL(b, mode=ctypes.RTLD_GLOBAL)
            break
        except OSError:
            pass
    return ctypes.CDLL(lib), lib


def find_ptxas():
    p = find_one(["nvidia/cu13/bin/ptxas", "nvidia/cuda_nvcc/bin/ptxas"])
    if p is None:
        raise FileNotFoundError("ptxas not found in the nvidia-cuda-nvcc wheel")
    return p


class Nvrtc:
    def __init__(self):
        self.lib, self.path = load_nvrtc()
        L = self.lib
        L.nvrtcGetErrorString.restype = ctypes.c_char_p
        major, minor = ctypes.c_int(), ctypes.c_int()
        self._ok(L.nvrtcVersion(ctypes.byref(major), ctypes.byref(minor)), "nvrtcVersion")
        self.version = f"{major.value}.{minor.value}"

    def _ok(self, rc, what):
        if rc != 0:
            raise RuntimeError(f"{what}: {self.lib.nvrtcGetErrorString(rc).decode()}")

    def compile(self, source, name, options):
        L = self.lib
        prog = ctypes.c_void_p()
        self._ok(
            L.nvrtcCreateProgram(ctypes.byref(prog), source.encode(), name.encode(), 0, None, None),
            "nvrtcCreateProgram",
        )
        try:
            opts = [o.encode() for o in options]
            arr = (ctypes.c_char_p * len(opts))(*opts)
            rc = L.nvrtcCompileProgram(prog, len(opts), arr)
            size = ctypes.c_size_t()
            L.nvrtcGetProgramLogSize(prog, ctypes.byref(size))
            buf = ctypes.create_string_buffer(size.value)
            L.nvrtcGetProgramLog(prog, buf)
            log = buf.value.decode(errors="replace")
            if rc != 0:
                return None, log
            self._ok(L.nvrtcGetPTXSize(prog, ctypes.byref(size)), "nvrtcGetPTXSize")
            ptx = ctypes.create_string_buffer(size.value)
            self._ok(L.nvrtcGetPTX(prog, ptx), "nvrtcGetPTX")
            return ptx.value.decode(), log
        finally:
            L.nvrtcDestroyProgram(ctypes.byref(prog))


def load_py(path, name):
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


RE_ENTRY = re.compile(r"Compiling entry function '([^']+)' for '(sm_\d+)'")
RE_STACK = re.compile(r"(\d+) bytes stack frame, (\d+) bytes spill stores, (\d+) bytes spill loads")
RE_REGS = re.compile(r"Used (\d+) registers")


def ptxas_stats(ptxas, ptx, arch, tmp):
    src = os.path.join(tmp, f"k_{arch}.ptx")
    with open(src, "w") as f:
        f.write(ptx)
    out = os.path.join(tmp, f"k_{arch}.cubin")
    r = subprocess.run(
        [ptxas, f"-arch=sm_{arch}", "-v", src, "-o", out], capture_output=True, text=True
    )
    text = r.stdout + r.stderr
    if r.returncode != 0:
        return None, text
    stats, cur = {}, None
    for line in text.splitlines():
        m = RE_ENTRY.search(line)
        if m:
            cur = m.group(1)
            stats[cur] = {}
            continue
        if cur is None:
            continue
        m = RE_STACK.search(line)
        if m:
            stats[cur].update(stack=int(m.group(1)), spill_st=int(m.group(2)), spill_ld=int(m.group(3)))
        m = RE_REGS.search(line)
        if m:
            stats[cur]["regs"] = int(m.group(1))
    return stats, text


def main():
    out_json = None
    if "--json" in sys.argv:
        out_json = sys.argv[sys.argv.index("--json") + 1]
    nv = Nvrtc()
    ptxas = find_ptxas()
    pv = subprocess.run([ptxas, "--version"], capture_output=True, text=True).stdout.strip()
    print(f"NVRTC {nv.version} ({nv.path})")
    print(f"ptxas: {pv.splitlines()[-1] if pv else '?'} ({ptxas})")
    cuda = load_py(CUDA_PY, "gonio_cuda_source")
    units = [
        ("kernels.cu", (HERE / "kernels.cu").read_text(), [f"-I{INCLUDE}"]),
        # The header's fast-math mode (GONIO_DEVICE_FAST_MATH: fusable operators, __fdividef,
        # __sincosf, atan2f) compiles too.
        ("kernels.cu fast-math", (HERE / "kernels.cu").read_text(),
         [f"-I{INCLUDE}", "-DGONIO_DEVICE_FAST_MATH=1", "--use_fast_math"]),
        ("gonio.cuda", cuda.module_source((INCLUDE / "gonio_device.h").read_text()), []),
    ]
    try:  # the peers of scripts/gpu_check.py (pbrt-v4-style sampler, trivial kernel)
        units.append(("gpu_check peers", load_py(GPU_CHECK, "gpu_check_source").PEER_SOURCE, []))
    except ImportError as e:
        print(f"(the peers of scripts/gpu_check.py not compiled: {e})")
    failed = False
    report = {"nvrtc": nv.version, "ptxas": pv, "units": {}}
    with tempfile.TemporaryDirectory() as tmp:
        for name, src, extra in units:
            for arch in ARCHS:
                opts = [f"--gpu-architecture=compute_{arch}"] + extra  # NVRTC's defaults otherwise
                ptx, log = nv.compile(src, name, opts)
                if ptx is None:
                    print(f"FAIL: NVRTC {name} compute_{arch}:\n{log}")
                    failed = True
                    continue
                if log.strip():
                    print(f"NVRTC {name} compute_{arch} log:\n{log.strip()}")
                stats, text = ptxas_stats(ptxas, ptx, arch, tmp)
                if stats is None:
                    print(f"FAIL: ptxas sm_{arch} {name}:\n{text}")
                    failed = True
                    continue
                report["units"][f"{name} sm_{arch}"] = stats
                print(f"== {name}: NVRTC compute_{arch} -> PTX ({len(ptx)} bytes) -> ptxas -arch=sm_{arch} -v")
                print(f"   {'kernel':<22} {'regs':>5} {'stack':>6} {'spill st':>9} {'spill ld':>9}")
                for k, s in stats.items():
                    print(
                        f"   {k:<22} {s.get('regs', '?'):>5} {s.get('stack', '?'):>6} "
                        f"{s.get('spill_st', '?'):>9} {s.get('spill_ld', '?'):>9}"
                    )
    if out_json:
        with open(out_json, "w") as f:
            json.dump(report, f, indent=1)
    if failed:
        print("nvrtc_check: FAILED")
        return 1
    print("nvrtc_check: ok (every unit compiled by NVRTC and assembled by ptxas)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
