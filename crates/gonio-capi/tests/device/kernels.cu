/* Test kernels over include/gonio_device.h: compiled by NVRTC to PTX for compute_80 and
 * compute_90 and assembled by ptxas in scripts/test-device.sh (no GPU needed), and run on a GPU
 * by scripts/gpu-check.sh (CuPy RawModule). The view is passed by value as a __grid_constant__
 * parameter (CUDA 11.7+, sm_70+): its address is taken without a copy to local memory.
 * SPDX-License-Identifier: MIT OR Apache-2.0 */
#include "gonio_device.h"

#define GONIO_T_INDEX                                                                   \
  long long i = (long long)blockIdx.x * (long long)blockDim.x + (long long)threadIdx.x; \
  if (i >= n) return;

/* Structure-of-arrays sample / pdf / invert / target, the view by value. */
extern "C" __global__ void soa_sample(const __grid_constant__ GonioDeviceView v,
                                      const float *__restrict__ u, const float *__restrict__ w,
                                      float *__restrict__ x, float *__restrict__ y,
                                      float *__restrict__ z, float *__restrict__ pdf, long long n) {
  GONIO_T_INDEX
  float d[3], p;
  gonio_device_sample(&v, u[i], w[i], d, &p);
  x[i] = d[0];
  y[i] = d[1];
  z[i] = d[2];
  pdf[i] = p;
}

/* A BRDF family (gonio_device_brdf_*): sample ω_o for per-lane incident directions, with the
 * pdf at the sample from gonio_device_brdf_pdf and f_r from gonio_device_brdf_eval. */
extern "C" __global__ void brdf_sample(const __grid_constant__ GonioDeviceBrdf b,
                                       const float *__restrict__ wi, const float *__restrict__ u,
                                       const float *__restrict__ w, float *__restrict__ wo,
                                       float *__restrict__ pdf, float *__restrict__ pdf2,
                                       float *__restrict__ f, long long n) {
  GONIO_T_INDEX
  float in[3] = {wi[3 * i], wi[3 * i + 1], wi[3 * i + 2]}, o[3], p, rgb[3];
  gonio_device_brdf_sample(&b, in, u[i], w[i], o, &p);
  pdf2[i] = gonio_device_brdf_pdf(&b, in, o);
  gonio_device_brdf_eval(&b, in, o, rgb);
  wo[3 * i] = o[0];
  wo[3 * i + 1] = o[1];
  wo[3 * i + 2] = o[2];
  pdf[i] = p;
  f[3 * i] = rgb[0];
  f[3 * i + 1] = rgb[1];
  f[3 * i + 2] = rgb[2];
}

/* A kernel NAME writing FN(view, direction) of each direction (x[i], y[i], z[i]) to out[i]. */
#define GONIO_SOA_OF_DIRECTION(NAME, FN)                                                        \
  extern "C" __global__ void NAME(const __grid_constant__ GonioDeviceView v,                     \
                                  const float *__restrict__ x, const float *__restrict__ y,      \
                                  const float *__restrict__ z, float *__restrict__ out,          \
                                  long long n) {                                                 \
    GONIO_T_INDEX                                                                                \
    float d[3] = {x[i], y[i], z[i]};                                                             \
    out[i] = FN(&v, d);                                                                          \
  }

GONIO_SOA_OF_DIRECTION(soa_pdf, gonio_device_pdf)
GONIO_SOA_OF_DIRECTION(soa_target, gonio_device_target)

extern "C" __global__ void soa_invert(const __grid_constant__ GonioDeviceView v,
                                      const float *__restrict__ x, const float *__restrict__ y,
                                      const float *__restrict__ z, float *__restrict__ u,
                                      float *__restrict__ w, long long n) {
  GONIO_T_INDEX
  float d[3] = {x[i], y[i], z[i]}, uv[2];
  gonio_device_invert(&v, d, uv);
  u[i] = uv[0];
  w[i] = uv[1];
}

/* ---- Light tracing (docs/GPU.md): the floor irradiance under a luminaire at the origin. ----
 * The scene of crates/gonio/examples/light_transport.rs: photometric frame (nadir along −z), the
 * floor z = −h cut into nx × ny square patches of side `cell` metres from (x0, y0) (there:
 * h = 3, 12 × 7 patches of 1 m² from (−4, −4)). A direction ω drawn with density pdf(ω) carries
 * the flux I(ω)/pdf(ω) (lumens: I in candela, pdf per sr) to the patch it hits; the patch's mean
 * irradiance (lux) is the mean flux per sample landing in it over its area. The points of the
 * square are iid (a counter hash), sample i of stream `seed`. E (nx·ny doubles) starts at 0. */
GONIO_DEVICE_FN unsigned int gonio_t_hash(unsigned int x) { /* lowbias32 */
  x ^= x >> 16; x *= 0x7feb352du; x ^= x >> 15; x *= 0x846ca68bu; x ^= x >> 16;
  return x;
}

extern "C" __global__ void light_trace_floor(const __grid_constant__ GonioDeviceView v,
                                             unsigned long long n, unsigned int seed, float h,
                                             float x0, float y0, float cell, int nx, int ny,
                                             double *__restrict__ E) {
  unsigned long long i = (unsigned long long)blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  unsigned int a = gonio_t_hash((unsigned int)i ^ gonio_t_hash(seed ^ (unsigned int)(i >> 32)));
  unsigned int b = gonio_t_hash(a ^ 0x9e3779b9u);
  float u = (float)(a >> 8) * 0x1p-24f, w = (float)(b >> 8) * 0x1p-24f; /* [0, 1) */
  float d[3], pdf;
  gonio_device_sample(&v, u, w, d, &pdf);
  if (!(pdf > 0.0f) || !(d[2] < 0.0f)) return;              /* no light, or not downward */
  float t = -h / d[2];                                      /* the ray hits z = −h at t·d */
  int ix = (int)floorf((t * d[0] - x0) / cell), iy = (int)floorf((t * d[1] - y0) / cell);
  if (ix < 0 || ix >= nx || iy < 0 || iy >= ny) return;
  float intensity = gonio_device_target(&v, d);              /* candela: the diagram at ω */
  double flux = (double)intensity / (double)pdf;             /* lumens carried by the sample */
  atomicAdd(&E[iy * nx + ix], flux / ((double)n * (double)cell * (double)cell));
}

/* The deterministic reference: each patch's mean of E(p) = I(ω_p)·cos θ_p / d² by the midpoint
 * rule with k × k points (one thread per patch). */
extern "C" __global__ void floor_reference(const __grid_constant__ GonioDeviceView v, float h,
                                           float x0, float y0, float cell, int nx, int ny, int k,
                                           double *__restrict__ E) {
  int p = blockIdx.x * blockDim.x + threadIdx.x;
  if (p >= nx * ny) return;
  double sum = 0.0;
  for (int a = 0; a < k; a++) {
    for (int b = 0; b < k; b++) {
      double px = x0 + cell * ((p % nx) + (a + 0.5) / k), py = y0 + cell * ((p / nx) + (b + 0.5) / k);
      double d2 = px * px + py * py + (double)h * h, dist = sqrt(d2);
      float dir[3] = {(float)(px / dist), (float)(py / dist), (float)(-h / dist)};
      sum += (double)gonio_device_target(&v, dir) * ((double)h / dist) / d2;
    }
  }
  E[p] = sum / ((double)k * k);
}
