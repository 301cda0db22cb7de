"""gonio.cuda's device-side view builder against gonio_device_view_init, on the host.

gonio.cuda builds the GonioDeviceView of a validated blob on the device (gonio_cu_view_from_blob
in gonio/cuda.py's KERNEL_SOURCE). This compiles that function as C99 with the system compiler
(`cc`) next to the header's validating gonio_device_view_init and checks, on blobs the library
writes (the split example, a hemisphere diagram, an IES file, an environment map when
../shared has one), that both give the same view byte for byte (sizeof included). Exit 77 when
there is no C compiler or no gonio module. Used by scripts/test-device.sh.
"""

import importlib.util
import pathlib
import shutil
import subprocess
import sys
import tempfile

HERE = pathlib.Path(__file__).resolve().parent
REPO = HERE.parents[3]
INCLUDE = REPO / "crates" / "gonio-capi" / "include"
CUDA_PY = REPO / "crates" / "gonio-py" / "python" / "gonio" / "cuda.py"

C_MAIN = r"""
#include <stdio.h>
#include <stdlib.h>
int main(int argc, char **argv) {
  int bad = 0;
  for (int a = 1; a < argc; a++) {
    FILE *f = fopen(argv[a], "rb");
    if (!f) { printf("cannot open %s\n", argv[a]); return 2; }
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    fseek(f, 0, SEEK_SET);
    void *blob = aligned_alloc(64, ((size_t)size + 63) / 64 * 64);
    if (fread(blob, 1, (size_t)size, f) != (size_t)size) return 2;
    fclose(f);
    GonioDeviceView a1, a2;
    int e = gonio_device_view_init(&a1, blob, (size_t)size);
    if (e != 0) { printf("%s: view_init error %d\n", argv[a], e); bad = 1; continue; }
    memset(&a2, 0xAB, sizeof a2);
    gonio_cu_view_from_blob((const gonio_u8 *)blob, &a2);
    int same = memcmp(&a1, &a2, sizeof a1) == 0;
    printf("%s: sizeof(GonioDeviceView) %zu, device builder %s\n", argv[a], sizeof a1,
           same ? "identical" : "DIFFERENT");
    if (!same || sizeof a1 != %VIEW_BYTES%) bad = 1;
    free(blob);
  }
  return bad;
}
"""


def main():
    cc = shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
    if cc is None:
        print("view_check: SKIPPED: no C compiler")
        return 77
    try:
        import numpy as np
        import gonio
    except ImportError as e:
        print(f"view_check: SKIPPED: {e}")
        return 77
    spec = importlib.util.spec_from_file_location("gonio_cuda_source", CUDA_PY)
    cuda = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(cuda)
    with tempfile.TemporaryDirectory() as tmp:
        t = pathlib.Path(tmp)
        src = t / "view_check.c"
        src.write_text(
            '#include "gonio_device.h"\n'
            + cuda.KERNEL_SOURCE
            + C_MAIN.replace("%VIEW_BYTES%", str(cuda.VIEW_BYTES))
        )
        exe = t / "view_check"
        r = subprocess.run(
            [cc, "-std=c11", "-O1", "-Wall", "-Wextra", "-Werror", "-Wno-unused-function",
             f"-I{INCLUDE}", str(src), "-lm", "-o", str(exe)],
            capture_output=True, text=True,
        )
        if r.returncode != 0:
            print("view_check: FAILED to compile:\n" + r.stdout + r.stderr)
            return 1
        blobs = []
        ex = gonio.example()
        blobs.append(("example_split", gonio.Sampler(ex).tables()))
        th = np.linspace(0, 90, 10)
        ph = np.linspace(0, 360, 13)[:-1]
        vals = 1.0 + np.outer(np.cos(np.radians(ph)) ** 2, np.cos(np.radians(th)))
        blobs.append(("hemisphere", gonio.Diagram(th, ph, vals).sampler(domain="hemisphere").tables()))
        corpus = REPO.parent / "shared" / "data"
        ies = corpus / "photometry" / "ies" / "lm63_2002_lithonia_area_full_h0_360.ies"
        if ies.is_file():
            blobs.append(("ies", gonio.read(str(ies)).sampler().tables()))
        envs = sorted((corpus / "envmaps").glob("*.hdr"))
        if envs:
            blobs.append(("envmap", gonio.EnvMap(str(envs[0]), precision="float32").tables()))
        paths = []
        for name, b in blobs:
            p = t / f"{name}.bin"
            p.write_bytes(b)
            paths.append(str(p))
        r = subprocess.run([str(exe)] + paths, capture_output=True, text=True)
        print(r.stdout.replace(tmp + "/", ""), end="")
        if r.returncode != 0:
            print("view_check: FAILED" + r.stderr)
            return 1
    print("view_check: ok")
    return 0


if __name__ == "__main__":
    sys.exit(main())
