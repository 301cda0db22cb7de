/* gonio_device.h: header-only sampler of gonio's table blob (docs/TABLES.md, layout version 1)
 * for C99, C++17, CUDA (nvcc and NVRTC) and HIP. See docs/C_API.md and docs/GPU.md.
 * SPDX-License-Identifier: MIT OR Apache-2.0
 *
 * WHAT IT IS
 *   The float32 HDS map of the library (`Float32Map`, crates/gonio/src/mapping/float32.rs) run in
 *   place on the tables of an f32 blob, one point per call: sample, pdf, invert, and the grid
 *   target's value. The arithmetic is the library's vector kernels (mapping/simd/kernels.rs)
 *   operation for operation in IEEE binary32, with the same constants (mapping/simd/math.rs,
 *   `impl Precision for f32`), so that a point gives the library's float32 batch result bit for
 *   bit when no multiply-add is contracted into an FMA (see FLOATING POINT below). Tested by
 *   crates/gonio-capi/examples/device_test.c (scripts/test-c.sh).
 *
 * USE
 *   1. Get an f32 blob: gonio_sampler_tables(sampler, target_or_NULL, 4, buf, cap, &size) or
 *      gonio_envmap_tables(map, 4, ...) from gonio.h, `gonio tables FILE -o OUT.bin`, Python's
 *      Sampler.tables(), or Rust's gonio::mapping::blob::write. Keep it in a buffer aligned to
 *      at least 8 bytes (64 recommended; malloc gives 16, cudaMalloc 256).
 *   2. On the host: GonioDeviceView view; int e = gonio_device_view_init(&view, blob, size);
 *      (0 or a GONIO_DEVICE_E_* code; it validates everything docs/TABLES.md lists).
 *   3. For a GPU: copy the blob's bytes as they are (cudaMemcpy) to a device buffer `dblob`,
 *      then gonio_device_view_rebase(&view, dblob) and pass `view` by value to the kernel
 *      (a plain struct of pointers and scalars, 680 bytes on 64-bit targets).
 *   4. In host or device code: gonio_device_sample / _pdf / _invert / _target on &view.
 *   A tabulated BRDF's family blob (docs/TABLES.md "Families": gonio_brdf_sampler_tables,
 *   Brdf.tables(), `gonio tables BRDF_FILE`) goes through gonio_device_brdf_init (host) and
 *   gonio_device_brdf_rebase, then gonio_device_brdf_sample / _pdf / _eval: the slices blended
 *   for each incident direction, as the library's BrdfSampler (within float32 round-off of its
 *   f64 results; see "BRDF families" below).
 *
 * FRAMES AND UNITS (docs/TABLES.md, "The frames")
 *   Directions dir[3] = (x, y, z) are unit vectors (to f32 round-off: they are not renormalised)
 *   in gonio's axes: θ from +z, φ from +x toward +y. The view's `frame` says what the data's
 *   angles mean there: 0 generic (a diagram given in these axes); 1 photometric (IES, EULUMDAT:
 *   γ = π − θ, nadir along −z; C = φ, C0 along +x, C90 along +y; target in candela, its
 *   integral in lumens); 2 environment map (the image's top row at +z, its centre column along
 *   +x, φ = π − 2π·s for the column fraction s from the left edge). Points of the square are
 *   (u, v) in [0, 1]². Densities are per steradian. The split sphere layout gives u < p_lower to
 *   the lower map (z ≤ 0). A hemisphere view covers z ≥ 0 only: its pdf is 0 below the horizon.
 *
 * FLOATING POINT
 *   On a CUDA device every operation is an explicit round-to-nearest intrinsic (__fadd_rn,
 *   __fmul_rn, __fdiv_rn, __fsqrt_rn, ...): never contracted into an FMA, unaffected by
 *   -use_fast_math (measured on an H200, CUDA 13.0, nvcc and NVRTC, with and without
 *   --use_fast_math: 100 % bit-identical to the host). On a HIP device the operators are used
 *   under `#pragma STDC FP_CONTRACT OFF` (honoured by hipcc's default
 *   -ffp-contract=fast-honor-pragmas, not by -ffp-contract=fast), with hipcc's default correctly
 *   rounded division and square root (not compiled or run here: no HIP toolchain was at hand).
 *   In a .cu file's host code give nvcc -Xcompiler -ffp-contract=off when the host compiler
 *   targets FMA instructions (nvcc's host pass is left without the GCC pragma below). Elsewhere
 *   on the host the operations are plain
 *   float operators, each in its own inline function, and contraction is switched off for this
 *   header's functions: `#pragma STDC FP_CONTRACT OFF` in each body under Clang, `#pragma GCC
 *   optimize("fp-contract=off")` (pushed and popped around the header) under GCC, so that
 *   -march=native in GNU modes (GCC 12) and Clang's default -ffp-contract=on (Clang 14) still
 *   give the library's bits; Clang's -ffp-contract=fast ignores the pragma (do not use it).
 *   Other compilers: compile with their no-contraction option. Never -ffast-math / -Ofast on the host (it reorders and drops
 *   the NaN logic). Subnormal densities are flushed under CUDA's -ftz=true (part of
 *   -use_fast_math); none occurred in the tests. With contraction or flushing the results still
 *   agree with the library's to a few f32 ulps except where the map's inverse CDF jumps over an
 *   unlit gap (a point within round-off of such a gap may land on its other side).
 *
 * LIMITS OF THE PORT
 *   Only f32 blobs (precision 4) are sampled: an f64 blob is refused with GONIO_DEVICE_E_F64.
 *   The image target of an environment map blob is validated and pointed to (view.target_rgb,
 *   W × H RGB floats, row 0 at the top) but not evaluated here. The tables are used in place, so
 *   the host and the device must be little-endian (every CUDA and HIP platform is);
 *   gonio_device_view_init refuses to run on a big-endian host (GONIO_DEVICE_E_ENDIAN).
 *
 * No allocation, no recursion, no exceptions, no libc call beyond <math.h>'s sqrtf, fabsf,
 * floorf, atan2, hypot, fmod on the host (CUDA's builtins on the device), memcpy for bit casts on the host
 * and memcpy/memset/memcmp in the host-only gonio_device_view_init. Every loop states its maximum
 * trip count. The sampling functions read only the blob and the view; any number of threads may
 * use one view at once.
 */

#ifndef GONIO_DEVICE_H
#define GONIO_DEVICE_H

/* ---------------------------------------------------------------------------------------------
 * Qualifiers, fixed-width types, includes.
 * ------------------------------------------------------------------------------------------- */

#if defined(__CUDACC__) || defined(__HIPCC__) || defined(__CUDACC_RTC__)
#define GONIO_DEVICE_FN __host__ __device__ inline
#else
#define GONIO_DEVICE_FN static inline
#endif
/* Host-only functions (the validating view_init; absent under NVRTC). */
#define GONIO_DEVICE_HOST_FN static inline

/* The device pass of nvcc / NVRTC (and of Clang's CUDA): CUDA's explicit-rounding intrinsics,
 * which are never fused. HIP's __fadd_rn & co. are plain operators in HIP's headers (fusable
 * under hipcc's -ffp-contract=fast-honor-pragmas), so HIP's device pass uses the operators under
 * this header's own no-contraction pragma, and __fsqrt_rn for the square root. */
#if defined(__CUDA_ARCH__) && !defined(__HIP__)
#define GONIO_DEVICE_PASS_ 1
#else
#define GONIO_DEVICE_PASS_ 0
#endif
#if defined(__HIP_DEVICE_COMPILE__)
#define GONIO_HIP_DEVICE_PASS_ 1
#else
#define GONIO_HIP_DEVICE_PASS_ 0
#endif

/* GONIO_DEVICE_FAST_MATH (define it before including the header; CUDA device code only): the
 * device's fast arithmetic instead of the bit-exact one: operators the compiler may fuse into
 * FMAs, __fdividef, the hardware __sincosf and atan2f. Results then differ from the library's
 * float32 map within a few f32 ulps in direction and a small relative error in the pdf where it
 * is smooth (docs/GPU.md, "Fast math", gives the measured figures); the host paths and the
 * default device path stay bit for bit the library's. */
#if defined(GONIO_DEVICE_FAST_MATH) && GONIO_DEVICE_PASS_
#define GONIO_DEVICE_FAST_ 1
#else
#define GONIO_DEVICE_FAST_ 0
#endif

#if defined(__clang__) && !GONIO_DEVICE_PASS_
#define GONIO_NO_CONTRACT_ _Pragma("STDC FP_CONTRACT OFF")
#else
#define GONIO_NO_CONTRACT_
#endif

#if defined(__CUDACC_RTC__)
/* NVRTC: no standard headers; its built-in types and math functions only. */
typedef unsigned char gonio_u8;
typedef int gonio_i32;
typedef unsigned int gonio_u32;
typedef unsigned long long gonio_u64;
#else
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <math.h>
typedef uint8_t gonio_u8;
typedef int32_t gonio_i32;
typedef uint32_t gonio_u32;
typedef uint64_t gonio_u64;
#endif

/* GCC contracts a * b + c into an FMA across statements when an FMA instruction is enabled
 * (-march=haswell and later, GNU modes and C++): switched off for this header's functions only. */
#if defined(__GNUC__) && !defined(__clang__) && !defined(__CUDACC__) && !defined(__HIPCC__)
#define GONIO_DEVICE_GCC_OPTIONS_ 1
#pragma GCC push_options
#pragma GCC optimize("fp-contract=off")
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* ---------------------------------------------------------------------------------------------
 * Error codes of gonio_device_view_init (0 = success). Each names the first check that failed,
 * in the order docs/TABLES.md ("What a reader must check") lists them.
 * ------------------------------------------------------------------------------------------- */
enum GonioDeviceError {
  GONIO_DEVICE_OK = 0,
  /* view is NULL, or tables is NULL with bytes > 0. */
  GONIO_DEVICE_E_NULL = 1,
  /* Fewer bytes than the header (256), than total_bytes, or than the directory needs. */
  GONIO_DEVICE_E_TRUNCATED = 2,
  /* Bytes 0-7 are not "GONIOTAB". */
  GONIO_DEVICE_E_MAGIC = 3,
  /* version is not 1. */
  GONIO_DEVICE_E_VERSION = 4,
  /* A header or map-descriptor field out of its range: header_bytes, total_bytes (more bytes
   * given than it states, or not a multiple of 64), layout, frame, target, reserved fields,
   * maps_present/p_lower, inv_2t, a descriptor's counts or scalars, lookup, the target fields;
   * also grids beyond the float32 kernels' 32-bit indices (M or N >= 2^22, M*N or M*(K+1)
   * >= 2^31, a guide of 2^24 entries or more). */
  GONIO_DEVICE_E_HEADER = 5,
  /* The FNV-1a 64 checksum differs: the bytes were changed. */
  GONIO_DEVICE_E_CHECKSUM = 6,
  /* precision is neither 4 nor 8. */
  GONIO_DEVICE_E_PRECISION = 7,
  /* precision is 8: a valid-looking f64 blob, which this header does not sample (write the
   * blob with precision 4). */
  GONIO_DEVICE_E_F64 = 8,
  /* table_count, or a directory entry (id, element type, count, reserved, offset alignment,
   * overlap, end beyond total_bytes). */
  GONIO_DEVICE_E_DIRECTORY = 9,
  /* A table's contents: a non-finite float, a decreasing phi/cum/x/row of u, a negative
   * beta/r2/d/inv_dx/first entry, phi or beta above 2π (+ 1e-6 relative), x beyond the map's
   * disk (1, √2 for the Lambert sphere, + 1e-6 relative), a d whose pdf d·inv_2t would overflow,
   * total != the row's last u, a guide entry beyond its table, an invalid grid target (as
   * Diagram::new) or a negative image pixel. */
  GONIO_DEVICE_E_CONTENT = 10,
  /* The blob's address is not a multiple of 8 (its f64 target tables would be misaligned). */
  GONIO_DEVICE_E_ALIGNMENT = 11,
  /* The host is big-endian: the tables cannot be used in place. */
  GONIO_DEVICE_E_ENDIAN = 12
};

/* Layouts (header field `layout`). */
#define GONIO_DEVICE_LAYOUT_HEMISPHERE 0u
#define GONIO_DEVICE_LAYOUT_LAMBERT 1u
#define GONIO_DEVICE_LAYOUT_SPLIT 2u
/* Targets (header field `target`). */
#define GONIO_DEVICE_TARGET_NONE 0u
#define GONIO_DEVICE_TARGET_GRID 1u
#define GONIO_DEVICE_TARGET_IMAGE 2u

/* One map's tables (a slot of the blob). Pointers are base + the table's offset; lengths are
 * entry counts (every gather clamps its index into [0, len - 1], as the library's kernels). */
typedef struct GonioDeviceMap {
  const float *phi;              /* M + 1 meridian azimuths */
  const float *beta;             /* M sector widths */
  const float *r2;               /* M + 1 squared star radii */
  const float *cum;              /* M + 1 cumulative wedge angles */
  const gonio_u32 *wedge_guide;  /* G */
  const float *x;                /* N parallel radii */
  const float *d;                /* M·N nodal disk densities */
  const float *u;                /* M·N cumulative radial masses */
  const float *total;            /* M row totals */
  const gonio_u32 *radius_guide; /* G_r */
  const float *inv_dx;           /* N − 1 */
  const gonio_u32 *radial_guide; /* M·(K + 1) */
  gonio_u64 offset[12];          /* byte offsets of the twelve tables in the blob */
  gonio_i32 len[12];             /* entries of the twelve tables */
  gonio_i32 m, n, k, wedge_guide_len, radius_guide_len;
  float inv_uniform_beta, kappa, guide_scale, radius_scale, edge;
} GonioDeviceMap;

/* A validated f32 blob: pointers into it and its scalars. Plain data: copy it, pass it to a
 * kernel by value, rebase it onto a copy of the blob (gonio_device_view_rebase). */
typedef struct GonioDeviceView {
  const gonio_u8 *base;       /* the blob */
  gonio_u64 total_bytes;
  gonio_u32 layout;           /* GONIO_DEVICE_LAYOUT_* */
  gonio_u32 frame;            /* 0 generic, 1 photometric, 2 environment map */
  gonio_u32 target;           /* GONIO_DEVICE_TARGET_* */
  gonio_u32 maps_present;     /* bit 0: slot 0 (the map, or the split lower map); bit 1: upper */
  gonio_u32 lookup;           /* image target: 0 nearest, 1 bilinear */
  float p_lower;              /* split layout: probability of the lower map; else 0 */
  float inv_2t;               /* pdf per unit of disk density */
  double target_integral;     /* grid: ∫ value dω over the sphere (lumens if photometric) */
  gonio_u32 target_a;         /* grid: θ nodes N_t; image: width W */
  gonio_u32 target_b;         /* grid: φ nodes M_t; image: height H */
  const double *target_theta; /* grid: N_t θ nodes (radians), else NULL */
  const double *target_phi;   /* grid: M_t φ nodes (radians), else NULL */
  const double *target_values;/* grid: M_t·N_t values, row i = meridian i, else NULL */
  const float *target_rgb;    /* image: W·H·3 linear RGB, row 0 at the top, else NULL */
  gonio_u64 target_offset[3]; /* byte offsets of the target tables (0 when absent) */
  GonioDeviceMap map[2];      /* slot 0, slot 1 (zero when absent) */
} GonioDeviceView;

/* ---------------------------------------------------------------------------------------------
 * f32 vocabulary: IEEE binary32, round to nearest, no contraction.
 * ------------------------------------------------------------------------------------------- */

GONIO_DEVICE_FN float gonio_d_add_(float a, float b) {
#if GONIO_DEVICE_FAST_
  return a + b;
#elif GONIO_DEVICE_PASS_
  return __fadd_rn(a, b);
#else
  GONIO_NO_CONTRACT_
  return a + b;
#endif
}
GONIO_DEVICE_FN float gonio_d_sub_(float a, float b) {
#if GONIO_DEVICE_FAST_
  return a - b;
#elif GONIO_DEVICE_PASS_
  return __fsub_rn(a, b);
#else
  GONIO_NO_CONTRACT_
  return a - b;
#endif
}
GONIO_DEVICE_FN float gonio_d_mul_(float a, float b) {
#if GONIO_DEVICE_FAST_
  return a * b;
#elif GONIO_DEVICE_PASS_
  return __fmul_rn(a, b);
#else
  GONIO_NO_CONTRACT_
  return a * b;
#endif
}
GONIO_DEVICE_FN float gonio_d_div_(float a, float b) {
#if GONIO_DEVICE_FAST_
  return __fdividef(a, b);
#elif GONIO_DEVICE_PASS_
  return __fdiv_rn(a, b);
#else
  GONIO_NO_CONTRACT_
  return a / b;
#endif
}
GONIO_DEVICE_FN float gonio_d_sqrt_(float a) {
#if GONIO_DEVICE_FAST_
  return sqrtf(a);
#elif GONIO_DEVICE_PASS_ || GONIO_HIP_DEVICE_PASS_
  return __fsqrt_rn(a);
#else
  return sqrtf(a);
#endif
}
GONIO_DEVICE_FN float gonio_d_abs_(float a) { return fabsf(a); }
GONIO_DEVICE_FN gonio_u32 gonio_d_bits_(float a) {
#if GONIO_DEVICE_PASS_ || GONIO_HIP_DEVICE_PASS_
  return (gonio_u32)__float_as_uint(a);
#else
  gonio_u32 b;
  memcpy(&b, &a, sizeof b);
  return b;
#endif
}
GONIO_DEVICE_FN float gonio_d_from_bits_(gonio_u32 b) {
#if GONIO_DEVICE_PASS_ || GONIO_HIP_DEVICE_PASS_
  return __uint_as_float(b);
#else
  float a;
  memcpy(&a, &b, sizeof a);
  return a;
#endif
}
GONIO_DEVICE_FN float gonio_d_nan_(void) { return gonio_d_from_bits_(0x7fc00000u); }
GONIO_DEVICE_FN int gonio_d_isnan_(float a) { return a != a; }
GONIO_DEVICE_FN int gonio_d_signbit_(float a) { return (gonio_d_bits_(a) >> 31) != 0u; }
GONIO_DEVICE_FN int gonio_d_finite_(float a) {
  return (gonio_d_bits_(a) & 0x7f800000u) != 0x7f800000u;
}
/* Rust's a.max(b) / a.min(b) as the kernels spell them (b where b > a or a is NaN). */
GONIO_DEVICE_FN float gonio_d_fmax_(float a, float b) { return (b > a || a != a) ? b : a; }
GONIO_DEVICE_FN float gonio_d_fmin_(float a, float b) { return (b < a || a != a) ? b : a; }
/* Lane clamp: NaN passes through. */
GONIO_DEVICE_FN float gonio_d_clamp_(float x, float lo, float hi) {
  x = x < lo ? lo : x;
  return x > hi ? hi : x;
}
GONIO_DEVICE_FN gonio_i32 gonio_d_imin_(gonio_i32 a, gonio_i32 b) { return a < b ? a : b; }
GONIO_DEVICE_FN gonio_i32 gonio_d_imax_(gonio_i32 a, gonio_i32 b) { return a > b ? a : b; }
/* (x as index).min(kmax): NaN and negatives give 0; kmax < 2^24 (exact in f32). */
GONIO_DEVICE_FN gonio_i32 gonio_d_to_index_(float x, gonio_i32 kmax) {
  float top = (float)kmax;
  float v = x > 0.0f ? x : 0.0f;
  v = v < top ? v : top;
  return (gonio_i32)v;
}
GONIO_DEVICE_FN gonio_i32 gonio_d_clampi_(gonio_i32 i, gonio_i32 len) {
  i = i < 0 ? 0 : i;
  return i > len - 1 ? len - 1 : i;
}
GONIO_DEVICE_FN float gonio_d_gf_(const float *t, gonio_i32 len, gonio_i32 i) {
  return t[gonio_d_clampi_(i, len)];
}
GONIO_DEVICE_FN gonio_i32 gonio_d_gu_(const gonio_u32 *t, gonio_i32 len, gonio_i32 i) {
  return (gonio_i32)t[gonio_d_clampi_(i, len)];
}

/* f32 constants: the f64 values of the Rust code rounded to f32 (hex: exact). */
#define GONIO_D_FRAC_PI_4_ (0x1.921fb6p-1f)
#define GONIO_D_FRAC_PI_2_ (0x1.921fb6p+0f)
#define GONIO_D_PI_ (0x1.921fb6p+1f)
#define GONIO_D_TAU_ (0x1.921fb6p+2f)
#define GONIO_D_3PI_4_ (0x1.2d97c8p+1f)
#define GONIO_D_5PI_4_ (0x1.f6a7a2p+1f)
#define GONIO_D_7PI_4_ (0x1.5fdbbep+2f)
#define GONIO_D_3PI_2_ (0x1.2d97c8p+2f)
#define GONIO_D_4_OVER_PI_ (0x1.45f306p+0f)
#define GONIO_D_FRAC_2_PI_ (0x1.45f306p-1f)
#define GONIO_D_TWO_THIRDS_ (0x1.555556p-1f)
#define GONIO_D_ONE_SIXTH_ (0x1.555556p-3f)
/* math.rs, impl Precision for f32. */
#define GONIO_D_PIO2_1_ (0x1.920000p+0f)
#define GONIO_D_PIO2_2_ (0x1.fb4000p-12f)
#define GONIO_D_PIO2_3_ (0x1.4442d2p-24f)
#define GONIO_D_ROUND_MAGIC_ (0x1.800000p+23f)
#define GONIO_D_SIN0_ (-0x1.555556p-3f)
#define GONIO_D_SIN1_ (0x1.111112p-7f)
#define GONIO_D_SIN2_ (-0x1.a01a02p-13f)
#define GONIO_D_SIN3_ (0x1.71de3ap-19f)
#define GONIO_D_COS0_ (0x1.555556p-5f)
#define GONIO_D_COS1_ (-0x1.6c16c2p-10f)
#define GONIO_D_COS2_ (0x1.a01a02p-16f)
#define GONIO_D_COS3_ (-0x1.27e4fcp-22f)
#define GONIO_D_ATAN0_ (-0x1.555556p-2f)
#define GONIO_D_ATAN1_ (0x1.99999ap-3f)
#define GONIO_D_ATAN2_ (-0x1.24924ap-3f)
#define GONIO_D_HALF_PI_LO_ (-0x1.777a5cp-25f)
#define GONIO_D_PI_LO_PART_ (-0x1.777a5cp-24f)
#define GONIO_D_STOP_STEP_ (0x1.000000p-21f)
#define GONIO_D_STOP_CUBIC_ (0x1.000000p-28f)
#define GONIO_D_HALLEY_SMALL_ (0x1.000000p-7f)

/* atan(k/8), k = 0..8: f32 high part and rounded low part. A switch, not a table, so that no
 * global array is needed on the device. */
GONIO_DEVICE_FN float gonio_d_atan_hi_(gonio_i32 k) {
  switch (k) {
  case 1: return 0x1.fd5baap-4f;
  case 2: return 0x1.f5b760p-3f;
  case 3: return 0x1.6f6194p-2f;
  case 4: return 0x1.dac670p-2f;
  case 5: return 0x1.1e00bap-1f;
  case 6: return 0x1.4978fap-1f;
  case 7: return 0x1.700a7cp-1f;
  case 8: return 0x1.921fb6p-1f;
  default: return 0.0f;
  }
}
GONIO_DEVICE_FN float gonio_d_atan_lo_(gonio_i32 k) {
  switch (k) {
  case 1: return -0x1.54f424p-30f;
  case 2: return -0x1.b4dfc8p-29f;
  case 3: return 0x1.e4def0p-30f;
  case 4: return 0x1.586ed4p-28f;
  case 5: return 0x1.7bdfd6p-26f;
  case 6: return 0x1.934f70p-28f;
  case 7: return 0x1.5e118cp-27f;
  case 8: return -0x1.777a5cp-26f;
  default: return 0.0f;
  }
}

/* sin and cos of x in [0, 2π] (kernels.rs sin_cos, f32 reduction and series). */
GONIO_DEVICE_FN void gonio_d_sin_cos_(float x, float *sin_out, float *cos_out) {
#if GONIO_DEVICE_FAST_
  __sincosf(x, sin_out, cos_out);
}
#else
  const float magic = GONIO_D_ROUND_MAGIC_;
  float k = gonio_d_sub_(gonio_d_add_(gonio_d_mul_(x, GONIO_D_FRAC_2_PI_), magic), magic);
  float r = gonio_d_sub_(
      gonio_d_sub_(gonio_d_sub_(x, gonio_d_mul_(k, GONIO_D_PIO2_1_)), gonio_d_mul_(k, GONIO_D_PIO2_2_)),
      gonio_d_mul_(k, GONIO_D_PIO2_3_));
  float z = gonio_d_mul_(r, r);
  float ps = GONIO_D_SIN3_, pc = GONIO_D_COS3_;
  float s, hz, w, c, k4, n, q, s1, c1;
  int q1, q2, q3, swap;
  ps = gonio_d_add_(gonio_d_mul_(ps, z), GONIO_D_SIN2_);
  pc = gonio_d_add_(gonio_d_mul_(pc, z), GONIO_D_COS2_);
  ps = gonio_d_add_(gonio_d_mul_(ps, z), GONIO_D_SIN1_);
  pc = gonio_d_add_(gonio_d_mul_(pc, z), GONIO_D_COS1_);
  ps = gonio_d_add_(gonio_d_mul_(ps, z), GONIO_D_SIN0_);
  pc = gonio_d_add_(gonio_d_mul_(pc, z), GONIO_D_COS0_);
  s = gonio_d_add_(r, gonio_d_mul_(gonio_d_mul_(r, z), ps));
  hz = gonio_d_mul_(0.5f, z);
  w = gonio_d_sub_(1.0f, hz);
  c = gonio_d_add_(w, gonio_d_add_(gonio_d_sub_(gonio_d_sub_(1.0f, w), hz),
                                   gonio_d_mul_(gonio_d_mul_(z, z), pc)));
  k4 = gonio_d_mul_(k, 0.25f);
  n = gonio_d_sub_(gonio_d_add_(k4, magic), magic);
  q = gonio_d_sub_(k, gonio_d_mul_(4.0f, n > k4 ? gonio_d_sub_(n, 1.0f) : n));
  q1 = q == 1.0f;
  q2 = q == 2.0f;
  q3 = q == 3.0f;
  swap = q1 || q3;
  s1 = swap ? c : s;
  c1 = swap ? s : c;
  *sin_out = (q2 || q3) ? -s1 : s1;
  *cos_out = (q1 || q2) ? -c1 : c1;
}
#endif

/* atan2(y, x) in (−π, π] (kernels.rs atan2, f32 series and table). */
GONIO_DEVICE_FN float gonio_d_atan2_(float y, float x) {
#if GONIO_DEVICE_FAST_
  return atan2f(y, x);
}
#else
  const float magic = GONIO_D_ROUND_MAGIC_;
  float ax = gonio_d_abs_(x), ay = gonio_d_abs_(y);
  int swap = ay > ax;
  float num = swap ? ax : ay, den = swap ? ay : ax;
  float t = den > 0.0f ? gonio_d_div_(num, den) : 0.0f;
  float t8 = gonio_d_mul_(t, 8.0f);
  float kf = gonio_d_sub_(gonio_d_add_(t8, magic), magic);
  float c, z, z2, p, a;
  gonio_i32 k;
  kf = kf > t8 ? gonio_d_sub_(kf, 1.0f) : kf;
  c = gonio_d_mul_(kf, 0.125f);
  z = gonio_d_div_(gonio_d_sub_(t, c), gonio_d_add_(1.0f, gonio_d_mul_(t, c)));
  z2 = gonio_d_mul_(z, z);
  p = GONIO_D_ATAN2_;
  p = gonio_d_add_(gonio_d_mul_(p, z2), GONIO_D_ATAN1_);
  p = gonio_d_add_(gonio_d_mul_(p, z2), GONIO_D_ATAN0_);
  k = gonio_d_to_index_(kf, 8);
  a = gonio_d_add_(gonio_d_atan_hi_(k),
                   gonio_d_add_(gonio_d_atan_lo_(k),
                                gonio_d_add_(z, gonio_d_mul_(gonio_d_mul_(z, z2), p))));
  if (swap) a = gonio_d_add_(gonio_d_sub_(GONIO_D_FRAC_PI_2_, a), GONIO_D_HALF_PI_LO_);
  if (gonio_d_signbit_(x)) a = gonio_d_add_(gonio_d_sub_(GONIO_D_PI_, a), GONIO_D_PI_LO_PART_);
  return gonio_d_signbit_(y) ? -a : a;
}
#endif

/* The largest j in [lo, hi] with probe(j) <= w for a non-decreasing probe (lo when none):
 * the kernels' branch-free `descend` for one lane. At most 31 steps (22 for M, N < 2^22). The
 * probe is a table `a` (blend = 0) or the blend (1 − e)·a[oa + j] + e·a[ob + j] (blend = 1). */
GONIO_DEVICE_FN float gonio_d_probe_(const float *a, gonio_i32 len, int blend, float ome,
                                     float e, gonio_i32 oa, gonio_i32 ob, gonio_i32 j) {
  if (!blend) return gonio_d_gf_(a, len, j);
  return gonio_d_add_(gonio_d_mul_(ome, gonio_d_gf_(a, len, oa + j)),
                      gonio_d_mul_(e, gonio_d_gf_(a, len, ob + j)));
}
GONIO_DEVICE_FN gonio_i32 gonio_d_descend_(gonio_i32 lo, gonio_i32 hi, float w, const float *a,
                                           gonio_i32 len, int blend, float ome, float e,
                                           gonio_i32 oa, gonio_i32 ob) {
  gonio_i32 span = gonio_d_imax_(hi - lo, 0);
  gonio_i32 base = lo, top, h;
  if (span == 0) return base;
  top = gonio_d_imax_(hi, lo);
  h = 1;
  while (h <= span / 2) h <<= 1; /* highest power of two <= span: at most 30 steps */
  while (h > 0) {                /* at most 31 steps */
    gonio_i32 cand = gonio_d_imin_(base + h, top);
    if (gonio_d_probe_(a, len, blend, ome, e, oa, ob, cand) <= w) base = cand;
    h >>= 1;
  }
  return base;
}

/* mapping::guided_search: the largest i <= last with a_i <= x (0 if none), non-decreasing a,
 * from the guide's bracket; the settling loops run only when round-off left i outside its
 * bracket (each at most `last` steps). */
GONIO_DEVICE_FN gonio_i32 gonio_d_guided_(const float *a, gonio_i32 alen, const gonio_u32 *guide,
                                          gonio_i32 glen, float scale, float x, gonio_i32 last) {
  gonio_i32 kmax = glen - 1;
  gonio_i32 k = gonio_d_to_index_(gonio_d_mul_(x, scale), kmax);
  gonio_i32 lo = gonio_d_imin_(gonio_d_gu_(guide, glen, k), last);
  gonio_i32 hi = kmax > k ? gonio_d_imin_(gonio_d_gu_(guide, glen, k + 1), last) : last;
  gonio_i32 i = gonio_d_descend_(lo, hi, x, a, alen, 0, 0.0f, 0.0f, 0, 0);
  int down = i > 0 && gonio_d_gf_(a, alen, i) > x;
  int up = last > i && gonio_d_gf_(a, alen, i + 1) <= x;
  if (down || up) {
    while (i > 0 && gonio_d_gf_(a, alen, i) > x) i--;         /* at most `last` steps */
    while (i < last && gonio_d_gf_(a, alen, i + 1) <= x) i++; /* at most `last` steps */
  }
  return i;
}

/* diagram::segment on a non-decreasing float table: the largest k <= len − 2 with a_k <= x
 * (0 when x < a_0 or NaN). Binary search: at most 32 steps. */
GONIO_DEVICE_FN gonio_i32 gonio_d_segment_(const float *a, gonio_i32 len, float x) {
  gonio_i32 lo = 0, n = len; /* partition point: first index with !(a[i] <= x) */
  while (n > 0) {
    gonio_i32 half = n / 2;
    if (a[lo + half] <= x) {
      lo = lo + half + 1;
      n = n - half - 1;
    } else {
      n = half;
    }
  }
  lo = lo > 0 ? lo - 1 : 0;
  return lo < len - 2 ? lo : len - 2;
}

/* radial::partial_mass. */
GONIO_DEVICE_FN float gonio_d_partial_mass_(float x0, float d0, float k, float tau) {
  return gonio_d_mul_(
      tau, gonio_d_add_(
               gonio_d_mul_(gonio_d_mul_(2.0f, x0), d0),
               gonio_d_mul_(tau, gonio_d_add_(gonio_d_add_(gonio_d_mul_(x0, k), d0),
                                              gonio_d_mul_(gonio_d_mul_(tau, GONIO_D_TWO_THIRDS_),
                                                           k)))));
}

/* radial::solve_radius: Halley safeguarded by bisection, at most 60 iterations. */
GONIO_DEVICE_FN float gonio_d_solve_radius_(float x0, float x1, float d0, float d1, float m) {
  float h = gonio_d_sub_(x1, x0);
  float kk = gonio_d_div_(gonio_d_sub_(d1, d0), h);
  float dbar = gonio_d_mul_(0.5f, gonio_d_add_(d0, d1));
  int early = !(m > 0.0f) || !(h > 0.0f) || !(dbar > 0.0f);
  int konst = kk == 0.0f;
  int active = !early && !konst;
  int iterated = active;
  float k = kk, hi = h, lo = 0.0f;
  float ka = gonio_d_div_(gonio_d_sub_(d1, d0), gonio_d_mul_(h, gonio_d_add_(x0, x1)));
  float ds = gonio_d_div_(
      gonio_d_mul_(2.0f, m),
      gonio_d_add_(d0, gonio_d_sqrt_(gonio_d_fmax_(
                           gonio_d_add_(gonio_d_mul_(d0, d0), gonio_d_mul_(gonio_d_mul_(2.0f, ka), m)),
                           0.0f))));
  float g = gonio_d_div_(ds, gonio_d_add_(x0, gonio_d_sqrt_(gonio_d_add_(gonio_d_mul_(x0, x0), ds))));
  int finite = gonio_d_finite_(g);
  float res = x0, tau;
  int it;
  if (!early && (konst || !finite)) {
    float q = gonio_d_div_(m, dbar);
    float t = gonio_d_div_(q, gonio_d_add_(gonio_d_sqrt_(gonio_d_add_(gonio_d_mul_(x0, x0), q)), x0));
    res = konst ? gonio_d_add_(x0, gonio_d_fmin_(t, h)) : 0.0f;
    g = finite ? g : t;
  }
  tau = gonio_d_clamp_(g, 0.0f, h);
  for (it = 0; it < 60 && active; it++) { /* at most 60 iterations */
    float t = tau;
    float f = gonio_d_sub_(gonio_d_partial_mass_(x0, d0, k, t), m);
    int exact = f == 0.0f;
    int pos = f > 0.0f;
    float nlo = pos ? lo : t, nhi = pos ? t : hi;
    float xx = gonio_d_add_(x0, t);
    float dd = gonio_d_add_(d0, gonio_d_mul_(k, t));
    float g1 = gonio_d_mul_(gonio_d_mul_(2.0f, xx), dd);
    float g2 = gonio_d_mul_(2.0f, gonio_d_add_(dd, gonio_d_mul_(k, xx)));
    float den = gonio_d_sub_(gonio_d_mul_(g1, g1), gonio_d_mul_(gonio_d_mul_(0.5f, f), g2));
    float next = (g1 > 0.0f && den > 0.0f)
                     ? gonio_d_sub_(t, gonio_d_div_(gonio_d_mul_(f, g1), den))
                     : gonio_d_nan_();
    int halley = next > nlo && next < nhi;
    float step, scale, cc;
    int stop, predicted;
    next = halley ? next : gonio_d_mul_(0.5f, gonio_d_add_(nlo, nhi));
    next = exact ? t : next;
    step = gonio_d_abs_(gonio_d_sub_(next, t));
    scale = gonio_d_add_(x0, next);
    stop = step <= gonio_d_mul_(GONIO_D_STOP_STEP_, scale) ||
           gonio_d_sub_(nhi, nlo) <= gonio_d_mul_(GONIO_D_STOP_STEP_, gonio_d_add_(x0, nhi));
    cc = gonio_d_add_(gonio_d_mul_(gonio_d_mul_(0.25f, g2), g2),
                      gonio_d_mul_(gonio_d_mul_(gonio_d_abs_(gonio_d_mul_(4.0f, k)), g1),
                                   GONIO_D_ONE_SIXTH_));
    predicted = gonio_d_mul_(cc, gonio_d_mul_(gonio_d_mul_(step, step), step)) <=
                gonio_d_mul_(gonio_d_mul_(GONIO_D_STOP_CUBIC_, scale), gonio_d_mul_(g1, g1));
    stop = (stop || exact) ||
           (halley && step <= gonio_d_mul_(GONIO_D_HALLEY_SMALL_, scale) && predicted);
    if (exact) {
      nlo = lo;
      nhi = hi;
    }
    tau = next;
    lo = nlo;
    hi = nhi;
    active = !stop;
  }
  return iterated ? gonio_d_add_(x0, tau) : res;
}

/* concentric::disk_to_square. */
GONIO_DEVICE_FN void gonio_d_disk_to_square_(float r, float phi, float uv[2]) {
  float p = phi >= GONIO_D_7PI_4_ ? gonio_d_sub_(phi, GONIO_D_TAU_) : phi;
  float s = gonio_d_mul_(r, GONIO_D_4_OVER_PI_);
  int q0 = p < GONIO_D_FRAC_PI_4_, q1 = p < GONIO_D_3PI_4_, q2 = p < GONIO_D_5PI_4_;
  float a, b;
  if (q0) {
    a = r;
    b = gonio_d_mul_(s, p);
  } else if (q1) {
    a = gonio_d_mul_(-gonio_d_sub_(p, GONIO_D_FRAC_PI_2_), s);
    b = r;
  } else if (q2) {
    a = -r;
    b = gonio_d_mul_(-s, gonio_d_sub_(p, GONIO_D_PI_));
  } else {
    a = gonio_d_mul_(gonio_d_sub_(p, GONIO_D_3PI_2_), s);
    b = -r;
  }
  uv[0] = gonio_d_clamp_(gonio_d_mul_(0.5f, gonio_d_add_(a, 1.0f)), 0.0f, 1.0f);
  uv[1] = gonio_d_clamp_(gonio_d_mul_(0.5f, gonio_d_add_(b, 1.0f)), 0.0f, 1.0f);
}

/* Table indices of GonioDeviceMap.len / offset. */
enum {
  GONIO_D_PHI_ = 0, GONIO_D_BETA_, GONIO_D_R2_, GONIO_D_CUM_, GONIO_D_WGUIDE_, GONIO_D_X_,
  GONIO_D_D_, GONIO_D_U_, GONIO_D_TOTAL_, GONIO_D_RGUIDE_, GONIO_D_INVDX_, GONIO_D_RADGUIDE_
};

/* HdsCore::sample on one map (sample_block's four stages): direction and disk density D. */
GONIO_DEVICE_FN void gonio_d_map_sample_(const GonioDeviceMap *c, float u, float v, float o[4]) {
  const gonio_i32 *L = c->len;
  const gonio_i32 n = c->n;
  float a, b, r, num, den, q, phi, rb, pb;
  float beta, ra, rbb, cum, phi0, gamma, aa, bb, cc, eps, phic, ome, r2b, w, uj, uj1;
  float d0, d1, x0, x1, inv_dx, xr, north, south, r2, s, sp, cp, ox, oy, oz, rd2, xd, t, od;
  gonio_i32 wi, wn, a_off, b_off, kk, ga, gb, lo, hi, j;
  int big, up;
  /* Stage 1: M_B (square to disk) and the wedge search. */
  a = gonio_d_sub_(gonio_d_mul_(2.0f, u), 1.0f);
  b = gonio_d_sub_(gonio_d_mul_(2.0f, v), 1.0f);
  big = gonio_d_abs_(a) > gonio_d_abs_(b);
  r = big ? a : b;
  num = big ? b : a;
  den = big ? a : b;
  q = gonio_d_div_(num, den);
  phi = big ? gonio_d_mul_(GONIO_D_FRAC_PI_4_, q)
            : gonio_d_sub_(GONIO_D_FRAC_PI_2_, gonio_d_mul_(GONIO_D_FRAC_PI_4_, q));
  if (r < 0.0f) {
    r = -r;
    phi = gonio_d_add_(phi, GONIO_D_PI_);
  }
  phi = phi < 0.0f ? gonio_d_add_(phi, GONIO_D_TAU_) : phi;
  phi = phi >= GONIO_D_TAU_ ? 0.0f : phi;
  if (a == 0.0f && b == 0.0f) {
    rb = 0.0f;
    pb = 0.0f;
  } else {
    rb = r;
    pb = phi;
  }
  wi = gonio_d_guided_(c->cum, L[GONIO_D_CUM_], c->wedge_guide, L[GONIO_D_WGUIDE_], c->guide_scale,
                       pb, c->m - 1);
  /* Stage 2: the wedge equation, then the radial search over the blended CDF. */
  beta = gonio_d_gf_(c->beta, L[GONIO_D_BETA_], wi);
  ra = gonio_d_gf_(c->r2, L[GONIO_D_R2_], wi);
  rbb = gonio_d_gf_(c->r2, L[GONIO_D_R2_], wi + 1);
  cum = gonio_d_gf_(c->cum, L[GONIO_D_CUM_], wi);
  phi0 = gonio_d_gf_(c->phi, L[GONIO_D_PHI_], wi);
  gamma = gonio_d_div_(gonio_d_sub_(pb, cum), c->kappa);
  aa = gonio_d_mul_(gonio_d_mul_(0.5f, beta), gonio_d_sub_(rbb, ra));
  bb = gonio_d_mul_(beta, ra);
  cc = gonio_d_fmax_(gamma, 0.0f);
  den = gonio_d_add_(bb, gonio_d_sqrt_(gonio_d_fmax_(
                             gonio_d_add_(gonio_d_mul_(bb, bb), gonio_d_mul_(gonio_d_mul_(4.0f, aa), cc)),
                             0.0f)));
  eps = den > 0.0f ? gonio_d_clamp_(gonio_d_div_(gonio_d_mul_(2.0f, cc), den), 0.0f, 1.0f) : 0.0f;
  phic = gonio_d_add_(phi0, gonio_d_mul_(eps, beta));
  wn = wi + 1 == c->m ? 0 : wi + 1;
  a_off = wi * n;
  b_off = wn * n;
  ome = gonio_d_sub_(1.0f, eps);
  r2b = gonio_d_mul_(rb, rb);
  w = gonio_d_mul_(r2b, gonio_d_add_(gonio_d_mul_(ome, gonio_d_gf_(c->total, L[GONIO_D_TOTAL_], wi)),
                                     gonio_d_mul_(eps, gonio_d_gf_(c->total, L[GONIO_D_TOTAL_], wn))));
  kk = gonio_d_to_index_(gonio_d_mul_(r2b, (float)c->k), c->k - 1);
  ga = wi * (c->k + 1) + kk;
  gb = wn * (c->k + 1) + kk;
  lo = gonio_d_imin_(gonio_d_gu_(c->radial_guide, L[GONIO_D_RADGUIDE_], ga),
                     gonio_d_gu_(c->radial_guide, L[GONIO_D_RADGUIDE_], gb));
  hi = gonio_d_imax_(gonio_d_gu_(c->radial_guide, L[GONIO_D_RADGUIDE_], ga + 1),
                     gonio_d_gu_(c->radial_guide, L[GONIO_D_RADGUIDE_], gb + 1));
  j = gonio_d_descend_(lo, hi, w, c->u, L[GONIO_D_U_], 1, ome, eps, a_off, b_off);
  uj = gonio_d_probe_(c->u, L[GONIO_D_U_], 1, ome, eps, a_off, b_off, j);
  uj1 = gonio_d_probe_(c->u, L[GONIO_D_U_], 1, ome, eps, a_off, b_off, j + 1);
  if ((j > 0 && uj > w) || (n > j + 2 && uj1 <= w) || (j > 0 && uj1 <= uj)) {
    /* The scalar search's settling loops (rare), each at most N steps. */
    const float *U = c->u;
    const gonio_i32 UL = L[GONIO_D_U_];
#define GONIO_D_UT_(jj) gonio_d_probe_(U, UL, 1, ome, eps, a_off, b_off, (jj))
    uj = GONIO_D_UT_(j);
    uj1 = GONIO_D_UT_(j + 1);
    if (j > 0 && uj > w) {
      while (j > 0 && GONIO_D_UT_(j) > w) j--;
      uj = GONIO_D_UT_(j);
      uj1 = GONIO_D_UT_(j + 1);
    }
    if (j + 2 < n && uj1 <= w) {
      while (j + 2 < n && GONIO_D_UT_(j + 1) <= w) j++;
      uj = GONIO_D_UT_(j);
      uj1 = GONIO_D_UT_(j + 1);
    }
    /* The square's edge before an unlit zone at the end of the map. */
    if (j > 0 && uj1 <= uj) {
      while (j > 0 && GONIO_D_UT_(j + 1) <= GONIO_D_UT_(j)) j--;
      uj = GONIO_D_UT_(j);
    }
#undef GONIO_D_UT_
  }
  /* Stage 3: the radial solve on segment j. */
  d0 = gonio_d_probe_(c->d, L[GONIO_D_D_], 1, ome, eps, a_off, b_off, j);
  d1 = gonio_d_probe_(c->d, L[GONIO_D_D_], 1, ome, eps, a_off, b_off, j + 1);
  x0 = gonio_d_gf_(c->x, L[GONIO_D_X_], j);
  x1 = gonio_d_gf_(c->x, L[GONIO_D_X_], j + 1);
  inv_dx = gonio_d_gf_(c->inv_dx, L[GONIO_D_INVDX_], j);
  xr = gonio_d_fmin_(gonio_d_solve_radius_(x0, x1, d0, d1, gonio_d_sub_(w, uj)), x1);
  /* Stage 4: M_E (disk to sphere) and the density there. */
  north = gonio_d_fmax_(c->d[0], 0.0f);
  south = gonio_d_fmax_(c->d[n - 1], 0.0f);
  r2 = gonio_d_mul_(xr, xr);
  s = gonio_d_mul_(xr, gonio_d_sqrt_(gonio_d_fmax_(gonio_d_sub_(2.0f, r2), 0.0f)));
  gonio_d_sin_cos_(phic, &sp, &cp);
  ox = gonio_d_mul_(s, cp);
  oy = gonio_d_mul_(s, sp);
  oz = gonio_d_sub_(1.0f, r2);
  up = oz > 0.0f;
  rd2 = up ? gonio_d_div_(gonio_d_add_(gonio_d_mul_(ox, ox), gonio_d_mul_(oy, oy)), gonio_d_add_(1.0f, oz))
           : gonio_d_sub_(1.0f, oz);
  xd = gonio_d_sqrt_(gonio_d_fmin_(gonio_d_fmax_(rd2, 0.0f), 2.0f));
  t = gonio_d_fmin_(gonio_d_fmax_(gonio_d_mul_(gonio_d_sub_(xd, x0), inv_dx), 0.0f), 1.0f);
  od = gonio_d_fmax_(gonio_d_add_(d0, gonio_d_mul_(gonio_d_sub_(d1, d0), t)), 0.0f);
  if (ox == 0.0f && oy == 0.0f) od = up ? north : south;
  o[0] = ox;
  o[1] = oy;
  o[2] = oz;
  o[3] = od;
}

/* Disk radius and azimuth of a direction (lift::sphere_to_disk_radius / _azimuth). */
GONIO_DEVICE_FN void gonio_d_radius_azimuth_(float x, float y, float z, float *xr, float *phi) {
  float r2 = z > 0.0f ? gonio_d_div_(gonio_d_add_(gonio_d_mul_(x, x), gonio_d_mul_(y, y)), gonio_d_add_(1.0f, z))
                      : gonio_d_sub_(1.0f, z);
  float p;
  *xr = gonio_d_sqrt_(gonio_d_clamp_(r2, 0.0f, 2.0f));
  p = gonio_d_atan2_(y, x);
  p = p < 0.0f ? gonio_d_add_(p, GONIO_D_TAU_) : p;
  p = p >= GONIO_D_TAU_ ? 0.0f : p;
  *phi = (x == 0.0f && y == 0.0f) ? 0.0f : p;
}

/* Angular::sector: sector i, next meridian i1 and ε of an azimuth. */
GONIO_DEVICE_FN void gonio_d_sectors_(const GonioDeviceMap *c, float p, gonio_i32 *i_out,
                                      gonio_i32 *i1_out, float *eps) {
  const gonio_i32 *L = c->len;
  const gonio_i32 m = c->m;
  gonio_i32 i, i1;
  if (c->inv_uniform_beta > 0.0f) {
    int down, up;
    i = gonio_d_to_index_(gonio_d_mul_(p, c->inv_uniform_beta), m - 1);
    down = p < gonio_d_gf_(c->phi, L[GONIO_D_PHI_], i);
    up = !down && m > i + 1 && p >= gonio_d_gf_(c->phi, L[GONIO_D_PHI_], i + 1);
    i = down ? i - 1 : i;
    i = up ? i + 1 : i;
  } else {
    i = gonio_d_segment_(c->phi, L[GONIO_D_PHI_], p);
  }
  i1 = i + 1 == m ? 0 : i + 1;
  *eps = gonio_d_clamp_(gonio_d_div_(gonio_d_sub_(p, gonio_d_gf_(c->phi, L[GONIO_D_PHI_], i)),
                                     gonio_d_gf_(c->beta, L[GONIO_D_BETA_], i)),
                        0.0f, 1.0f);
  *i_out = i;
  *i1_out = i1;
}

/* HdsCore::density: the disk density D at a direction (density_block). */
GONIO_DEVICE_FN float gonio_d_map_density_(const GonioDeviceMap *c, float x, float y, float z) {
  const gonio_i32 *L = c->len;
  const gonio_i32 n = c->n;
  float xr, p, eps, t, a0, a1, b0, b1, ra, rb, d;
  gonio_i32 i, i1, j, a, b;
  gonio_d_radius_azimuth_(x, y, z, &xr, &p);
  gonio_d_sectors_(c, p, &i, &i1, &eps);
  j = gonio_d_guided_(c->x, L[GONIO_D_X_], c->radius_guide, L[GONIO_D_RGUIDE_], c->radius_scale, xr,
                      n - 2);
  t = gonio_d_clamp_(gonio_d_mul_(gonio_d_sub_(xr, gonio_d_gf_(c->x, L[GONIO_D_X_], j)),
                                  gonio_d_gf_(c->inv_dx, L[GONIO_D_INVDX_], j)),
                     0.0f, 1.0f);
  a = i * n + j;
  b = i1 * n + j;
  a0 = gonio_d_gf_(c->d, L[GONIO_D_D_], a);
  a1 = gonio_d_gf_(c->d, L[GONIO_D_D_], a + 1);
  b0 = gonio_d_gf_(c->d, L[GONIO_D_D_], b);
  b1 = gonio_d_gf_(c->d, L[GONIO_D_D_], b + 1);
  ra = gonio_d_add_(a0, gonio_d_mul_(t, gonio_d_sub_(a1, a0)));
  rb = gonio_d_add_(b0, gonio_d_mul_(t, gonio_d_sub_(b1, b0)));
  d = gonio_d_fmax_(gonio_d_add_(gonio_d_mul_(gonio_d_sub_(1.0f, eps), ra), gonio_d_mul_(eps, rb)), 0.0f);
  return xr > c->edge ? 0.0f : d;
}

/* HdsCore::invert: the point of the square of a direction (invert_block). */
GONIO_DEVICE_FN void gonio_d_map_invert_(const GonioDeviceMap *c, float x, float y, float z,
                                         float uv[2]) {
  const gonio_i32 *L = c->len;
  const gonio_i32 n = c->n;
  float xr, p, e, x0, x1, idx, da0, da1, db0, db1, ua, ub, uan, ubn, cum0, cum1, beta, r2a, r2b;
  float ome, d0, d1, k, tau, w, wn, rbd, wedge, phib;
  gonio_i32 i, i1, j, a, b;
  gonio_d_radius_azimuth_(x, y, z, &xr, &p);
  gonio_d_sectors_(c, p, &i, &i1, &e);
  j = gonio_d_guided_(c->x, L[GONIO_D_X_], c->radius_guide, L[GONIO_D_RGUIDE_], c->radius_scale, xr,
                      n - 2);
  x0 = gonio_d_gf_(c->x, L[GONIO_D_X_], j);
  x1 = gonio_d_gf_(c->x, L[GONIO_D_X_], j + 1);
  idx = gonio_d_gf_(c->inv_dx, L[GONIO_D_INVDX_], j);
  a = i * n + j;
  b = i1 * n + j;
  da0 = gonio_d_gf_(c->d, L[GONIO_D_D_], a);
  da1 = gonio_d_gf_(c->d, L[GONIO_D_D_], a + 1);
  db0 = gonio_d_gf_(c->d, L[GONIO_D_D_], b);
  db1 = gonio_d_gf_(c->d, L[GONIO_D_D_], b + 1);
  ua = gonio_d_gf_(c->u, L[GONIO_D_U_], a);
  ub = gonio_d_gf_(c->u, L[GONIO_D_U_], b);
  uan = gonio_d_gf_(c->total, L[GONIO_D_TOTAL_], i);
  ubn = gonio_d_gf_(c->total, L[GONIO_D_TOTAL_], i1);
  cum0 = gonio_d_gf_(c->cum, L[GONIO_D_CUM_], i);
  cum1 = gonio_d_gf_(c->cum, L[GONIO_D_CUM_], i + 1);
  beta = gonio_d_gf_(c->beta, L[GONIO_D_BETA_], i);
  r2a = gonio_d_gf_(c->r2, L[GONIO_D_R2_], i);
  r2b = gonio_d_gf_(c->r2, L[GONIO_D_R2_], i + 1);
  ome = gonio_d_sub_(1.0f, e);
  d0 = gonio_d_add_(gonio_d_mul_(ome, da0), gonio_d_mul_(e, db0));
  d1 = gonio_d_add_(gonio_d_mul_(ome, da1), gonio_d_mul_(e, db1));
  k = gonio_d_mul_(gonio_d_sub_(d1, d0), idx);
  tau = gonio_d_clamp_(gonio_d_sub_(xr, x0), 0.0f, gonio_d_sub_(x1, x0));
  w = gonio_d_add_(gonio_d_add_(gonio_d_mul_(ome, ua), gonio_d_mul_(e, ub)),
                   gonio_d_partial_mass_(x0, d0, k, tau));
  wn = gonio_d_add_(gonio_d_mul_(ome, uan), gonio_d_mul_(e, ubn));
  rbd = wn > 0.0f ? gonio_d_sqrt_(gonio_d_clamp_(gonio_d_div_(w, wn), 0.0f, 1.0f)) : 0.0f;
  wedge = gonio_d_mul_(gonio_d_mul_(beta, e),
                       gonio_d_add_(r2a, gonio_d_mul_(gonio_d_mul_(0.5f, gonio_d_sub_(r2b, r2a)), e)));
  phib = gonio_d_fmin_(gonio_d_add_(cum0, gonio_d_mul_(c->kappa, wedge)), cum1);
  gonio_d_disk_to_square_(rbd, phib, uv);
}

/* ---------------------------------------------------------------------------------------------
 * The layouts (float32.rs Maps::sample / pdf / invert, split.rs SplitRule).
 * ------------------------------------------------------------------------------------------- */

/* Maps (u, v) in [0, 1]² to a unit direction dir[3] (gonio's axes, see FRAMES) and its density
 * *pdf per steradian (gonio_device_pdf at dir to within the float32 map's bound, docs/API.md
 * "Float32 maps"). Equal bit for bit to the library's float32 sample batch
 * (gonio_sample_batch_soa_f32, gonio_envmap_f32_sample_batch). u, v outside [0, 1] or NaN give
 * an unspecified direction, never an out-of-bounds read. Loops: the searches' (⌈log2 N⌉ + 1
 * steps, settling within the table), the radial solve's (at most 60 iterations). */
GONIO_DEVICE_FN void gonio_device_sample(const GonioDeviceView *v, float u, float w, float dir[3],
                                         float *pdf) {
  float o[4];
  if (v->layout != GONIO_DEVICE_LAYOUT_SPLIT) {
    gonio_d_map_sample_(&v->map[0], u, w, o);
  } else {
    int has_lower = (v->maps_present & 1u) != 0u, has_upper = (v->maps_present & 2u) != 0u;
    int lower;
    float uu;
    if (has_lower && has_upper) {
      float p = v->p_lower;
      if (u < p) {
        lower = 1;
        uu = gonio_d_div_(u, p);
        uu = uu < 1.0f ? uu : 1.0f; /* Rust's (u / p).min(1): NaN gives 1 */
      } else {
        lower = 0;
        uu = gonio_d_clamp_(gonio_d_div_(gonio_d_sub_(u, p), gonio_d_sub_(1.0f, p)), 0.0f, 1.0f);
      }
    } else {
      lower = has_lower;
      uu = u;
    }
    if ((lower && has_lower) || (!lower && has_upper)) {
      gonio_d_map_sample_(&v->map[lower ? 0 : 1], uu, w, o);
    } else {
      o[0] = 0.0f;
      o[1] = 0.0f;
      o[2] = 1.0f;
      o[3] = 0.0f;
    }
    if (lower) o[2] = -o[2];
  }
  dir[0] = o[0];
  dir[1] = o[1];
  dir[2] = o[2];
  *pdf = gonio_d_mul_(o[3], v->inv_2t);
}

/* The density (per steradian) of gonio_device_sample at a unit direction dir[3]; 0 below the
 * horizon of a hemisphere view, beyond the map's edge and where the map has no light. Equal bit
 * for bit to the library's float32 pdf batch at the same f32 direction. */
GONIO_DEVICE_FN float gonio_device_pdf(const GonioDeviceView *v, const float dir[3]) {
  float x = dir[0], y = dir[1], z = dir[2], d;
  if (v->layout == GONIO_DEVICE_LAYOUT_HEMISPHERE) {
    d = gonio_d_map_density_(&v->map[0], x, y, z);
    return z >= 0.0f ? gonio_d_mul_(d, v->inv_2t) : 0.0f;
  }
  if (v->layout == GONIO_DEVICE_LAYOUT_LAMBERT) {
    d = gonio_d_map_density_(&v->map[0], x, y, z);
  } else {
    int has_upper = (v->maps_present & 2u) != 0u;
    int lower = z < 0.0f || (z == 0.0f && !has_upper);
    int slot = lower ? 0 : 1;
    if (v->maps_present & (1u << slot))
      d = gonio_d_map_density_(&v->map[slot], x, y, lower ? -z : z);
    else
      d = 0.0f;
  }
  return gonio_d_mul_(d, v->inv_2t);
}

/* The point uv[2] of the square that gonio_device_sample maps to the unit direction dir[3]:
 * returns 0, or nonzero with uv = (NaN, NaN) where there is none (the density is 0 there, below
 * a hemisphere's horizon, a non-finite direction), as the library's float32 invert batch
 * followed by NaN wherever its pdf is 0 (invert_soa_nonzero, gonio_invert_batch_soa_f32). */
GONIO_DEVICE_FN int gonio_device_invert(const GonioDeviceView *v, const float dir[3], float uv[2]) {
  float x = dir[0], y = dir[1], z = dir[2];
  int ok;
  if (v->layout != GONIO_DEVICE_LAYOUT_SPLIT) {
    gonio_d_map_invert_(&v->map[0], x, y, z, uv);
  } else {
    int has_upper = (v->maps_present & 2u) != 0u;
    int lower = z < 0.0f || (z == 0.0f && !has_upper);
    int slot = lower ? 0 : 1;
    if (v->maps_present & (1u << slot)) {
      float w, p = v->p_lower;
      gonio_d_map_invert_(&v->map[slot], x, y, lower ? -z : z, uv);
      w = uv[0];
      if (!gonio_d_finite_(w)) {
        uv[0] = gonio_d_nan_();
      } else if (lower && !has_upper) {
        uv[0] = w;
      } else if (lower) {
        float uu = gonio_d_mul_(w, p);
        /* Rounding must not carry a lower-map point across the seam u = P_lower. */
        uv[0] = (uu >= p && p > 0.0f) ? gonio_d_from_bits_(gonio_d_bits_(p) - 1u) : uu;
      } else {
        float uu = gonio_d_add_(p, gonio_d_mul_(w, gonio_d_sub_(1.0f, p)));
        uv[0] = uu < 1.0f ? uu : 1.0f;
      }
    } else {
      uv[0] = gonio_d_nan_();
      uv[1] = gonio_d_nan_();
    }
  }
  ok = (v->layout != GONIO_DEVICE_LAYOUT_HEMISPHERE || z >= 0.0f) && gonio_d_finite_(x) &&
       gonio_d_finite_(y) && gonio_d_finite_(z);
  if (!ok || gonio_device_pdf(v, dir) == 0.0f) {
    uv[0] = gonio_d_nan_();
    uv[1] = gonio_d_nan_();
  }
  return (gonio_d_isnan_(uv[0]) || gonio_d_isnan_(uv[1])) ? 1 : 0;
}

/* The grid target's value at a direction dir[3] (any non-zero length): the diagram interpolated
 * bilinearly in (θ, φ) (Diagram::interpolate: periodic in φ, 0 outside [θ_0, θ_{N−1}]) with
 * θ = atan2(hypot(x, y), z), φ = atan2(y, x) in [0, 2π) (0 at the poles), in the diagram's
 * units (candela for a photometric blob; frame as FRAMES). Computed in double from the blob's
 * f64 target tables (the diagram exactly) and rounded to float once; it agrees with the
 * library's gonio_diagram_intensity to double round-off (libm's atan2/hypot on the host, CUDA's
 * on the device). 0 when the view has no grid target. Loops: two binary searches, at most
 * ⌈log2 N_t⌉ + 1 and ⌈log2 M_t⌉ + 1 steps. */
GONIO_DEVICE_FN float gonio_device_target(const GonioDeviceView *v, const float dir[3]) {
  const double tau = 6.283185307179586;
  const double *th, *ph, *val;
  double x, y, z, theta, phi, t, e, r0, r1;
  gonio_i32 n, m, j, jn, i0, i1;
  if (v->target != GONIO_DEVICE_TARGET_GRID) return 0.0f;
  th = v->target_theta;
  ph = v->target_phi;
  val = v->target_values;
  n = (gonio_i32)v->target_a;
  m = (gonio_i32)v->target_b;
  x = (double)dir[0];
  y = (double)dir[1];
  z = (double)dir[2];
  theta = atan2(hypot(x, y), z);
  if (x == 0.0 && y == 0.0) {
    phi = 0.0;
  } else {
    phi = atan2(y, x);
    if (phi < 0.0) phi += tau;
    if (phi >= tau) phi = 0.0;
  }
  if (!(theta >= th[0] && theta <= th[n - 1])) return 0.0f;
  {
    /* segment(thetas, theta): the largest j <= n − 2 with θ_j <= θ. */
    gonio_i32 lo = 0, cnt = n;
    while (cnt > 0) { /* at most ⌈log2 N_t⌉ + 1 steps */
      gonio_i32 half = cnt / 2;
      if (th[lo + half] <= theta) {
        lo += half + 1;
        cnt -= half + 1;
      } else {
        cnt = half;
      }
    }
    j = lo > 0 ? lo - 1 : 0;
    j = j < n - 2 ? j : n - 2;
    if (n == 1) j = 0;
  }
  if (n == 1) {
    t = 0.0;
  } else {
    t = (theta - th[j]) / (th[j + 1] - th[j]);
    t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
  }
  /* meridian_weights(phis, phi) */
  {
    double p = fmod(phi, tau);
    if (p < 0.0) p += tau;
    if (m == 1) {
      i0 = 0;
      i1 = 0;
      e = 0.0;
    } else if (p >= ph[m - 1] || p < ph[0]) {
      double width = ph[0] + tau - ph[m - 1];
      double off = p >= ph[m - 1] ? p - ph[m - 1] : p + tau - ph[m - 1];
      i0 = m - 1;
      i1 = 0;
      e = off / width;
      e = e < 0.0 ? 0.0 : (e > 1.0 ? 1.0 : e);
    } else {
      gonio_i32 lo = 0, cnt = m;
      while (cnt > 0) { /* at most ⌈log2 M_t⌉ + 1 steps */
        gonio_i32 half = cnt / 2;
        if (ph[lo + half] <= p) {
          lo += half + 1;
          cnt -= half + 1;
        } else {
          cnt = half;
        }
      }
      i0 = lo > 0 ? lo - 1 : 0;
      i0 = i0 < m - 2 ? i0 : m - 2;
      i1 = i0 + 1;
      e = (p - ph[i0]) / (ph[i1] - ph[i0]);
      e = e < 0.0 ? 0.0 : (e > 1.0 ? 1.0 : e);
    }
  }
  jn = j + 1 < n - 1 ? j + 1 : n - 1;
  r0 = (1.0 - t) * val[i0 * n + j] + t * val[i0 * n + jn];
  r1 = (1.0 - t) * val[i1 * n + j] + t * val[i1 * n + jn];
  return (float)((1.0 - e) * r0 + e * r1);
}

/* The same view over a copy of the blob at `device_tables` (a device buffer holding the same
 * bytes): every pointer recomputed from its offset. Reads nothing at either address. */
GONIO_DEVICE_FN void gonio_device_view_rebase(GonioDeviceView *view, const void *device_tables) {
  const gonio_u8 *b = (const gonio_u8 *)device_tables;
  int s;
  view->base = b;
  for (s = 0; s < 2; s++) { /* 2 slots */
    GonioDeviceMap *c = &view->map[s];
    if (!(view->maps_present & (1u << s))) continue;
    c->phi = (const float *)(const void *)(b + c->offset[GONIO_D_PHI_]);
    c->beta = (const float *)(const void *)(b + c->offset[GONIO_D_BETA_]);
    c->r2 = (const float *)(const void *)(b + c->offset[GONIO_D_R2_]);
    c->cum = (const float *)(const void *)(b + c->offset[GONIO_D_CUM_]);
    c->wedge_guide = (const gonio_u32 *)(const void *)(b + c->offset[GONIO_D_WGUIDE_]);
    c->x = (const float *)(const void *)(b + c->offset[GONIO_D_X_]);
    c->d = (const float *)(const void *)(b + c->offset[GONIO_D_D_]);
    c->u = (const float *)(const void *)(b + c->offset[GONIO_D_U_]);
    c->total = (const float *)(const void *)(b + c->offset[GONIO_D_TOTAL_]);
    c->radius_guide = (const gonio_u32 *)(const void *)(b + c->offset[GONIO_D_RGUIDE_]);
    c->inv_dx = (const float *)(const void *)(b + c->offset[GONIO_D_INVDX_]);
    c->radial_guide = (const gonio_u32 *)(const void *)(b + c->offset[GONIO_D_RADGUIDE_]);
  }
  if (view->target == GONIO_DEVICE_TARGET_GRID) {
    view->target_theta = (const double *)(const void *)(b + view->target_offset[0]);
    view->target_phi = (const double *)(const void *)(b + view->target_offset[1]);
    view->target_values = (const double *)(const void *)(b + view->target_offset[2]);
  } else if (view->target == GONIO_DEVICE_TARGET_IMAGE) {
    view->target_rgb = (const float *)(const void *)(b + view->target_offset[0]);
  }
}

/* ---------------------------------------------------------------------------------------------
 * BRDF families (layout 3, docs/TABLES.md "Families"): a tabulated BRDF's incident slices on
 * their shared grid, blended per incident direction as the library's BrdfSampler does
 * (crates/gonio/src/mapping/blend.rs), and the table's multilinear interpolant.
 *
 * Contract: the library's f64 BrdfSampler within float32 round-off, not bit for bit (the blend
 * has no float32 twin in the library): tested against gonio_brdf_sample / _pdf / _invert /
 * gonio_brdf_eval by device_test.c (ω_o within 1e-4 where the pdf is ≥ 0.01/sr, the library's
 * inverse of ω_o within 1e-5 of (u, v), the pdf at ω_o and f_r within the bounds printed there).
 * Plain float operators (an FMA contraction changes results by round-off only).
 * ------------------------------------------------------------------------------------------- */

/* A validated f32 family blob (gonio_device_brdf_init): pointers into it and its counts. Plain
 * data: pass it to a kernel by value after gonio_device_brdf_rebase. */
typedef struct GonioDeviceBrdf {
  const gonio_u8 *base;
  gonio_u64 total_bytes;
  GonioDeviceMap grid;   /* the shared grid (phi, beta, x, radius_guide, inv_dx, m, n, ...) and
                          * the stacked per-slice tables (r2, cum, d, u, total; len = all slices) */
  const float *slice;    /* 4 per slice: 1/(2T_s), κ_s, edge_s, 0 (all 0: no map) */
  const double *theta_i, *phi_i, *theta_o, *phi_o, *values; /* radians; f_r channel-major */
  gonio_u64 offset[17];  /* byte offsets: the 12 map tables, slice, θ_i, φ_i, θ_o, φ_o (values 17th below) */
  gonio_u64 values_offset;
  gonio_i32 slices, a, b, anisotropic, channels, n_to, n_po, slice_len;
} GonioDeviceBrdf;

#define GONIO_D_BRDF_PARTS_ 4

/* The largest j ≤ len − 2 with (float)a[j] <= x on an increasing double table (0 when x < a_0
 * or NaN): binary search, at most 32 steps. */
GONIO_DEVICE_FN gonio_i32 gonio_d_segment64_(const double *a, gonio_i32 len, float x) {
  gonio_i32 lo = 0, n = len;
  while (n > 0) {
    gonio_i32 half = n / 2;
    if ((float)a[lo + half] <= x) {
      lo = lo + half + 1;
      n = n - half - 1;
    } else {
      n = half;
    }
  }
  lo = lo > 0 ? lo - 1 : 0;
  return lo < len - 2 ? lo : len - 2;
}

/* brdf::clamped: linear weights of x on an increasing grid, clamped to its ends. */
GONIO_DEVICE_FN void gonio_d_clamped64_(const double *a, gonio_i32 len, float x, gonio_i32 *j0,
                                        gonio_i32 *j1, float *t) {
  gonio_i32 j;
  if (len == 1 || !(x > (float)a[0])) {
    *j0 = 0; *j1 = 0; *t = 0.0f;
    return;
  }
  if (x >= (float)a[len - 1]) {
    *j0 = len - 1; *j1 = len - 1; *t = 0.0f;
    return;
  }
  j = gonio_d_segment64_(a, len, x);
  *j0 = j;
  *j1 = j + 1;
  *t = (x - (float)a[j]) / ((float)a[j + 1] - (float)a[j]);
}

/* brdf::periodic: linear weights of an azimuth on a periodic grid in [0, 2π). */
GONIO_DEVICE_FN void gonio_d_periodic64_(const double *a, gonio_i32 len, float x, gonio_i32 *i0,
                                         gonio_i32 *i1, float *t) {
  float first, last;
  gonio_i32 i;
  x = x - GONIO_D_TAU_ * floorf(x / GONIO_D_TAU_);
  if (x >= GONIO_D_TAU_) x -= GONIO_D_TAU_;
  if (x < 0.0f) x += GONIO_D_TAU_;
  if (len == 1) {
    *i0 = 0; *i1 = 0; *t = 0.0f;
    return;
  }
  first = (float)a[0];
  last = (float)a[len - 1];
  if (x < first || x >= last) {
    float xx = x < first ? x + GONIO_D_TAU_ : x;
    *i0 = len - 1;
    *i1 = 0;
    *t = gonio_d_clamp_((xx - last) / (first + GONIO_D_TAU_ - last), 0.0f, 1.0f);
    return;
  }
  i = gonio_d_segment64_(a, len, x);
  *i0 = i;
  *i1 = i + 1;
  *t = (x - (float)a[i]) / ((float)a[i + 1] - (float)a[i]);
}

/* spherical(): θ from +z, φ in [0, 2π) from +x toward +y (0 on the axis). */
GONIO_DEVICE_FN void gonio_d_angles_(float x, float y, float z, float *theta, float *phi) {
  float p;
  *theta = gonio_d_atan2_(gonio_d_sqrt_(x * x + y * y), z);
  p = gonio_d_atan2_(y, x);
  p = p < 0.0f ? p + GONIO_D_TAU_ : p;
  p = p >= GONIO_D_TAU_ ? 0.0f : p;
  *phi = (x == 0.0f && y == 0.0f) ? 0.0f : p;
}

/* The blend for ω_i = (θ_i, φ_i): up to four slices with weights (empty slices dropped, the rest
 * renormalised), c_k = 2·w_k/(2T_k) and κ = Σ w_k κ_k. Returns the number of parts (0: every
 * neighbouring slice is empty). */
typedef struct GonioDBlend_ {
  gonio_i32 s[GONIO_D_BRDF_PARTS_];
  float w[GONIO_D_BRDF_PARTS_], c[GONIO_D_BRDF_PARTS_];
  gonio_i32 len;
  float kappa;
} GonioDBlend_;

GONIO_DEVICE_FN gonio_i32 gonio_d_brdf_blend_(const GonioDeviceBrdf *b, float ti, float pi,
                                              GonioDBlend_ *o) {
  gonio_i32 a0, a1, q0 = 0, q1 = 0, k, n = 0;
  float ta, tq = 0.0f, sum = 0.0f;
  gonio_d_clamped64_(b->theta_i, b->a, ti, &a0, &a1, &ta);
  if (b->anisotropic) gonio_d_periodic64_(b->phi_i, b->b, pi, &q0, &q1, &tq);
  o->kappa = 0.0f;
  for (k = 0; k < 4; k++) { /* 4 steps */
    gonio_i32 a = (k & 2) ? a1 : a0, q = (k & 1) ? q1 : q0, s, j;
    float w = ((k & 2) ? ta : 1.0f - ta) * ((k & 1) ? tq : 1.0f - tq);
    int merged = 0;
    s = a * b->b + q;
    if (!(w > 0.0f) || !(gonio_d_gf_(b->slice, b->slice_len, 4 * s) > 0.0f)) continue;
    for (j = 0; j < n; j++) /* at most 3 steps */
      if (o->s[j] == s) {
        o->w[j] += w;
        merged = 1;
      }
    if (!merged) {
      o->s[n] = s;
      o->w[n] = w;
      n++;
    }
  }
  for (k = 0; k < n; k++) sum += o->w[k];
  for (k = 0; k < n; k++) {
    float inv2t = gonio_d_gf_(b->slice, b->slice_len, 4 * o->s[k]);
    o->w[k] = o->w[k] / sum;
    o->c[k] = 2.0f * o->w[k] * inv2t;
    o->kappa += o->w[k] * gonio_d_gf_(b->slice, b->slice_len, 4 * o->s[k] + 1);
  }
  o->len = n;
  return n;
}

/* Σ w_k t[s_k·stride + i] (which = 0) or Σ c_k (1 − e)·t[s_k·stride + ia] + c_k e·t[s_k·stride + ib]. */
GONIO_DEVICE_FN float gonio_d_bsum_w_(const GonioDBlend_ *p, const float *t, gonio_i32 len,
                                      gonio_i32 stride, gonio_i32 i) {
  float acc = 0.0f;
  gonio_i32 k;
  for (k = 0; k < p->len; k++) acc += p->w[k] * gonio_d_gf_(t, len, p->s[k] * stride + i);
  return acc;
}
GONIO_DEVICE_FN float gonio_d_bsum_c_(const GonioDBlend_ *p, const float *t, gonio_i32 len,
                                      gonio_i32 stride, gonio_i32 ia, gonio_i32 ib, float e) {
  float acc = 0.0f;
  gonio_i32 k;
  for (k = 0; k < p->len; k++) {
    gonio_i32 o = p->s[k] * stride;
    acc += p->c[k] * (1.0f - e) * gonio_d_gf_(t, len, o + ia);
    acc += p->c[k] * e * gonio_d_gf_(t, len, o + ib);
  }
  return acc;
}

/* The blended map at (u, v): direction in the slice frame and the blended disk density. */
GONIO_DEVICE_FN void gonio_d_brdf_map_(const GonioDeviceBrdf *bf, const GonioDBlend_ *p, float u,
                                       float v, float o[4]) {
  const GonioDeviceMap *c = &bf->grid;
  const gonio_i32 *L = c->len;
  const gonio_i32 m = c->m, n = c->n, mn = c->m * c->n;
  float a, b, r, q, phi, rb, pb, beta, ra, rbb, g0, gam, aa, bb, cc, den, eps, phic, w, uj;
  float d0, d1, x0, x1, inv_dx, xr, r2, s, sp, cp, ox, oy, oz, rd2, xd, t;
  gonio_i32 wi, wn, j, h, base, top;
  int big;
  a = 2.0f * u - 1.0f;
  b = 2.0f * v - 1.0f;
  big = gonio_d_abs_(a) > gonio_d_abs_(b);
  r = big ? a : b;
  q = (big ? b : a) / (big ? a : b);
  phi = big ? GONIO_D_FRAC_PI_4_ * q : GONIO_D_FRAC_PI_2_ - GONIO_D_FRAC_PI_4_ * q;
  if (r < 0.0f) {
    r = -r;
    phi += GONIO_D_PI_;
  }
  phi = phi < 0.0f ? phi + GONIO_D_TAU_ : phi;
  phi = phi >= GONIO_D_TAU_ ? 0.0f : phi;
  rb = (a == 0.0f && b == 0.0f) ? 0.0f : r;
  pb = (a == 0.0f && b == 0.0f) ? 0.0f : phi;
  /* The wedge: the largest i <= M − 1 with the blended Γ_i <= φ_B (Γ_0 = 0): ⌈log2 M⌉ steps. */
  base = 0;
  top = m - 1;
  h = 1;
  while (h <= top / 2) h <<= 1;
  while (h > 0) { /* at most 23 steps (M < 2^22) */
    gonio_i32 cand = gonio_d_imin_(base + h, top);
    if (gonio_d_bsum_w_(p, c->cum, L[GONIO_D_CUM_], m + 1, cand) <= pb) base = cand;
    h >>= 1;
  }
  wi = base;
  beta = gonio_d_gf_(c->beta, L[GONIO_D_BETA_], wi);
  ra = gonio_d_bsum_w_(p, c->r2, L[GONIO_D_R2_], m + 1, wi);
  rbb = gonio_d_bsum_w_(p, c->r2, L[GONIO_D_R2_], m + 1, wi + 1);
  g0 = gonio_d_bsum_w_(p, c->cum, L[GONIO_D_CUM_], m + 1, wi);
  gam = (pb - g0) / p->kappa;
  aa = 0.5f * beta * (rbb - ra);
  bb = beta * ra;
  cc = gonio_d_fmax_(gam, 0.0f);
  den = bb + gonio_d_sqrt_(gonio_d_fmax_(bb * bb + 4.0f * aa * cc, 0.0f));
  eps = den > 0.0f ? gonio_d_clamp_(2.0f * cc / den, 0.0f, 1.0f) : 0.0f;
  phic = gonio_d_gf_(c->phi, L[GONIO_D_PHI_], wi) + eps * beta;
  wn = wi + 1 == m ? 0 : wi + 1;
#define GONIO_D_BU_(jj) gonio_d_bsum_c_(p, c->u, L[GONIO_D_U_], mn, wi * n + (jj), wn * n + (jj), eps)
#define GONIO_D_BD_(jj) gonio_d_bsum_c_(p, c->d, L[GONIO_D_D_], mn, wi * n + (jj), wn * n + (jj), eps)
  w = rb * rb * GONIO_D_BU_(n - 1);
  /* The radial segment: the largest j <= N − 2 with the blended U(j) <= w, then the settling
   * loops of the single map (each at most N steps). */
  base = 0;
  top = n - 2;
  h = 1;
  while (h <= top / 2) h <<= 1;
  while (h > 0) { /* at most 23 steps */
    gonio_i32 cand = gonio_d_imin_(base + h, top);
    if (GONIO_D_BU_(cand) <= w) base = cand;
    h >>= 1;
  }
  j = base;
  while (j > 0 && GONIO_D_BU_(j) > w) j--;
  while (j + 2 < n && GONIO_D_BU_(j + 1) <= w) j++;
  while (j > 0 && GONIO_D_BU_(j + 1) <= GONIO_D_BU_(j)) j--;
  uj = GONIO_D_BU_(j);
  d0 = GONIO_D_BD_(j);
  d1 = GONIO_D_BD_(j + 1);
#undef GONIO_D_BU_
#undef GONIO_D_BD_
  x0 = gonio_d_gf_(c->x, L[GONIO_D_X_], j);
  x1 = gonio_d_gf_(c->x, L[GONIO_D_X_], j + 1);
  inv_dx = gonio_d_gf_(c->inv_dx, L[GONIO_D_INVDX_], j);
  xr = gonio_d_fmin_(gonio_d_solve_radius_(x0, x1, d0, d1, w - uj), x1);
  r2 = xr * xr;
  s = xr * gonio_d_sqrt_(gonio_d_fmax_(2.0f - r2, 0.0f));
  gonio_d_sin_cos_(phic, &sp, &cp);
  ox = s * cp;
  oy = s * sp;
  oz = 1.0f - r2;
  rd2 = oz > 0.0f ? (ox * ox + oy * oy) / (1.0f + oz) : 1.0f - oz;
  xd = gonio_d_sqrt_(gonio_d_fmin_(gonio_d_fmax_(rd2, 0.0f), 2.0f));
  t = gonio_d_fmin_(gonio_d_fmax_((xd - x0) * inv_dx, 0.0f), 1.0f);
  o[0] = ox;
  o[1] = oy;
  o[2] = oz;
  o[3] = gonio_d_fmax_(d0 + (d1 - d0) * t, 0.0f);
}

/* The blended disk density at a direction of the slice frame (upper hemisphere). */
GONIO_DEVICE_FN float gonio_d_brdf_density_(const GonioDeviceBrdf *bf, const GonioDBlend_ *p,
                                            float x, float y, float z) {
  const GonioDeviceMap *c = &bf->grid;
  const gonio_i32 *L = c->len;
  const gonio_i32 n = c->n, mn = c->m * c->n;
  float xr, ph, eps, t, acc = 0.0f;
  gonio_i32 i, i1, j, k;
  gonio_d_radius_azimuth_(x, y, z, &xr, &ph);
  gonio_d_sectors_(c, ph, &i, &i1, &eps);
  j = gonio_d_guided_(c->x, L[GONIO_D_X_], c->radius_guide, L[GONIO_D_RGUIDE_], c->radius_scale, xr,
                      n - 2);
  t = gonio_d_clamp_((xr - gonio_d_gf_(c->x, L[GONIO_D_X_], j)) * gonio_d_gf_(c->inv_dx, L[GONIO_D_INVDX_], j),
                     0.0f, 1.0f);
  for (k = 0; k < p->len; k++) { /* at most 4 steps */
    gonio_i32 o = p->s[k] * mn;
    float a0 = gonio_d_gf_(c->d, L[GONIO_D_D_], o + i * n + j);
    float a1 = gonio_d_gf_(c->d, L[GONIO_D_D_], o + i * n + j + 1);
    float b0 = gonio_d_gf_(c->d, L[GONIO_D_D_], o + i1 * n + j);
    float b1 = gonio_d_gf_(c->d, L[GONIO_D_D_], o + i1 * n + j + 1);
    float row = (1.0f - eps) * (a0 + t * (a1 - a0)) + eps * (b0 + t * (b1 - b0));
    float edge = gonio_d_gf_(bf->slice, bf->slice_len, 4 * p->s[k] + 2);
    acc += xr > edge ? 0.0f : p->c[k] * row;
  }
  return gonio_d_fmax_(acc, 0.0f);
}

/* Samples ω_o for the incident direction wi (unit, local shading frame: z the normal, x the
 * tangent, both directions away from the surface) at (u, v) in [0, 1]²: wo and its exact pdf
 * per steradian (the blend of the slices' maps, as gonio_brdf_sample). Returns 1, or 0 where wi
 * lies below the horizon or every neighbouring slice is empty: then wo is the cosine sample, pdf
 * cos θ_o / π, and the sample carries no weight (the library's zero-weight sample). */
GONIO_DEVICE_FN int gonio_device_brdf_sample(const GonioDeviceBrdf *b, const float wi[3], float u,
                                             float v, float wo[3], float *pdf) {
  GonioDBlend_ p;
  float ti, pi, o[4], sp, cp;
  gonio_d_angles_(wi[0], wi[1], wi[2], &ti, &pi);
  ti = gonio_d_fmin_(ti, GONIO_D_FRAC_PI_2_);
  if (!(wi[2] >= 0.0f) || gonio_d_brdf_blend_(b, ti, pi, &p) == 0) {
    float a = 2.0f * u - 1.0f, bb = 2.0f * v - 1.0f, r, ph, s2, c2;
    int big = gonio_d_abs_(a) > gonio_d_abs_(bb);
    r = big ? a : bb;
    ph = (a == 0.0f && bb == 0.0f) ? 0.0f
         : big ? GONIO_D_FRAC_PI_4_ * (bb / a)
               : GONIO_D_FRAC_PI_2_ - GONIO_D_FRAC_PI_4_ * (a / bb);
    gonio_d_sin_cos_(ph, &s2, &c2);
    wo[0] = r * c2;
    wo[1] = r * s2;
    wo[2] = gonio_d_sqrt_(gonio_d_fmax_(1.0f - r * r, 0.0f));
    *pdf = wo[2] / GONIO_D_PI_;
    return 0;
  }
  gonio_d_brdf_map_(b, &p, u, v, o);
  gonio_d_sin_cos_(pi, &sp, &cp);
  wo[0] = cp * o[0] - sp * o[1];
  wo[1] = sp * o[0] + cp * o[1];
  wo[2] = o[2];
  *pdf = 0.5f * o[3];
  return 1;
}

/* The density of gonio_device_brdf_sample at wo for wi, per steradian (0 below the horizon). */
GONIO_DEVICE_FN float gonio_device_brdf_pdf(const GonioDeviceBrdf *b, const float wi[3],
                                            const float wo[3]) {
  GonioDBlend_ p;
  float ti, pi, sp, cp;
  if (!(wo[2] >= 0.0f)) return 0.0f;
  gonio_d_angles_(wi[0], wi[1], wi[2], &ti, &pi);
  ti = gonio_d_fmin_(ti, GONIO_D_FRAC_PI_2_);
  if (!(wi[2] >= 0.0f) || gonio_d_brdf_blend_(b, ti, pi, &p) == 0) return wo[2] / GONIO_D_PI_;
  gonio_d_sin_cos_(pi, &sp, &cp);
  return 0.5f * gonio_d_brdf_density_(b, &p, cp * wo[0] + sp * wo[1], cp * wo[1] - sp * wo[0], wo[2]);
}

/* f_r(wi, wo) per channel (1/sr; a one-channel table repeats it): the table's multilinear
 * interpolant (docs/BRDF.md), 0 below the horizon or outside the table's θ_o range. */
GONIO_DEVICE_FN void gonio_device_brdf_eval(const GonioDeviceBrdf *b, const float wi[3],
                                            const float wo[3], float f[3]) {
  float ti, pi, to, po, ta, tb, tq = 0.0f, tp, az;
  gonio_i32 a0, a1, b0, b1, q0 = 0, q1 = 0, p0, p1, ch, k;
  const gonio_i32 na = b->slices, nb = b->n_to, np_ = b->n_po;
  f[0] = f[1] = f[2] = 0.0f;
  if (!(wi[2] >= 0.0f && wo[2] >= 0.0f)) return;
  gonio_d_angles_(wi[0], wi[1], wi[2], &ti, &pi);
  gonio_d_angles_(wo[0], wo[1], wo[2], &to, &po);
  if (!(to >= (float)b->theta_o[0] - 1e-6f && to <= (float)b->theta_o[nb - 1] + 1e-6f)) return;
  gonio_d_clamped64_(b->theta_i, b->a, ti, &a0, &a1, &ta);
  gonio_d_clamped64_(b->theta_o, nb, to, &b0, &b1, &tb);
  if (b->anisotropic) {
    gonio_d_periodic64_(b->phi_i, b->b, pi, &q0, &q1, &tq);
    az = po;
  } else {
    az = po - pi;
  }
  gonio_d_periodic64_(b->phi_o, np_, az, &p0, &p1, &tp);
  for (ch = 0; ch < b->channels; ch++) { /* at most 3 steps */
    float acc = 0.0f;
    for (k = 0; k < 4; k++) { /* 4 steps */
      gonio_i32 a = (k & 2) ? a1 : a0, q = (k & 1) ? q1 : q0;
      float wa = (k & 2) ? ta : 1.0f - ta, wq = (k & 1) ? tq : 1.0f - tq;
      const double *row = b->values + ((gonio_u64)(ch * na + a * b->b + q) * (gonio_u64)nb) * (gonio_u64)np_;
      float r0 = (1.0f - tp) * (float)row[b0 * np_ + p0] + tp * (float)row[b0 * np_ + p1];
      float r1 = (1.0f - tp) * (float)row[b1 * np_ + p0] + tp * (float)row[b1 * np_ + p1];
      if (wa * wq == 0.0f) continue;
      acc += wa * wq * ((1.0f - tb) * r0 + tb * r1);
    }
    f[ch] = gonio_d_fmax_(acc, 0.0f);
  }
  if (b->channels == 1) f[1] = f[2] = f[0];
}

/* Points *b at a copy of its blob at `device_tables` (e.g. after cudaMemcpy). */
GONIO_DEVICE_FN void gonio_device_brdf_rebase(GonioDeviceBrdf *b, const void *device_tables) {
  const gonio_u8 *p = (const gonio_u8 *)device_tables;
  GonioDeviceMap *c = &b->grid;
  b->base = p;
  c->phi = (const float *)(const void *)(p + b->offset[GONIO_D_PHI_]);
  c->beta = (const float *)(const void *)(p + b->offset[GONIO_D_BETA_]);
  c->r2 = (const float *)(const void *)(p + b->offset[GONIO_D_R2_]);
  c->cum = (const float *)(const void *)(p + b->offset[GONIO_D_CUM_]);
  c->wedge_guide = (const gonio_u32 *)(const void *)(p + b->offset[GONIO_D_WGUIDE_]);
  c->x = (const float *)(const void *)(p + b->offset[GONIO_D_X_]);
  c->d = (const float *)(const void *)(p + b->offset[GONIO_D_D_]);
  c->u = (const float *)(const void *)(p + b->offset[GONIO_D_U_]);
  c->total = (const float *)(const void *)(p + b->offset[GONIO_D_TOTAL_]);
  c->radius_guide = (const gonio_u32 *)(const void *)(p + b->offset[GONIO_D_RGUIDE_]);
  c->inv_dx = (const float *)(const void *)(p + b->offset[GONIO_D_INVDX_]);
  c->radial_guide = (const gonio_u32 *)(const void *)(p + b->offset[GONIO_D_RADGUIDE_]);
  b->slice = (const float *)(const void *)(p + b->offset[12]);
  b->theta_i = (const double *)(const void *)(p + b->offset[13]);
  b->phi_i = (const double *)(const void *)(p + b->offset[14]);
  b->theta_o = (const double *)(const void *)(p + b->offset[15]);
  b->phi_o = (const double *)(const void *)(p + b->offset[16]);
  b->values = (const double *)(const void *)(p + b->values_offset);
}

/* ---------------------------------------------------------------------------------------------
 * The validating reader (host only): blob::read's checks, in its order.
 * ------------------------------------------------------------------------------------------- */
#if !defined(__CUDACC_RTC__)

GONIO_DEVICE_HOST_FN gonio_u32 gonio_d_rd32_(const gonio_u8 *p, gonio_u64 at) {
  p += at;
  return (gonio_u32)p[0] | ((gonio_u32)p[1] << 8) | ((gonio_u32)p[2] << 16) | ((gonio_u32)p[3] << 24);
}
GONIO_DEVICE_HOST_FN gonio_u64 gonio_d_rd64_(const gonio_u8 *p, gonio_u64 at) {
  return (gonio_u64)gonio_d_rd32_(p, at) | ((gonio_u64)gonio_d_rd32_(p, at + 4) << 32);
}
GONIO_DEVICE_HOST_FN double gonio_d_rdf64_(const gonio_u8 *p, gonio_u64 at) {
  gonio_u64 b = gonio_d_rd64_(p, at);
  double d;
  memcpy(&d, &b, sizeof d);
  return d;
}
GONIO_DEVICE_HOST_FN float gonio_d_rdf32_(const gonio_u8 *p, gonio_u64 at) {
  gonio_u32 b = gonio_d_rd32_(p, at);
  float f;
  memcpy(&f, &b, sizeof f);
  return f;
}
/* The f64 field is 0 with a positive sign (the reader's `!= 0 || is_sign_negative`). */
GONIO_DEVICE_HOST_FN int gonio_d_plus_zero_(const gonio_u8 *p, gonio_u64 at) {
  return gonio_d_rd64_(p, at) == 0u;
}
GONIO_DEVICE_HOST_FN int gonio_d_f64_finite_(double d) { return d - d == 0.0; }
/* d is exactly a float value. */
GONIO_DEVICE_HOST_FN int gonio_d_is_f32_(double d) { return (double)(float)d == d; }

/* FNV-1a 64 of the blob with bytes 24-31 taken as 0. One pass over the bytes. */
GONIO_DEVICE_HOST_FN gonio_u64 gonio_device_checksum(const void *tables, size_t bytes) {
  const gonio_u8 *p = (const gonio_u8 *)tables;
  gonio_u64 h = 0xcbf29ce484222325ull;
  size_t k;
  for (k = 0; k < bytes; k++) { /* `bytes` steps */
    gonio_u8 b = (k >= 24 && k < 32) ? 0 : p[k];
    h ^= (gonio_u64)b;
    h *= 0x100000001b3ull;
  }
  return h;
}

/* A float table of `count` entries at `off` (already within the blob): every entry finite. */
GONIO_DEVICE_HOST_FN int gonio_d_all_finite_(const gonio_u8 *p, gonio_u64 off, gonio_u64 count) {
  gonio_u64 i;
  for (i = 0; i < count; i++) /* `count` steps */
    if (!gonio_d_finite_(gonio_d_rdf32_(p, off + 4 * i))) return 0;
  return 1;
}
GONIO_DEVICE_HOST_FN int gonio_d_all_nonneg_(const gonio_u8 *p, gonio_u64 off, gonio_u64 count) {
  gonio_u64 i;
  for (i = 0; i < count; i++)
    if (gonio_d_rdf32_(p, off + 4 * i) < 0.0f) return 0;
  return 1;
}
GONIO_DEVICE_HOST_FN int gonio_d_nondecreasing_(const gonio_u8 *p, gonio_u64 off, gonio_u64 count) {
  gonio_u64 i;
  for (i = 1; i < count; i++)
    if (gonio_d_rdf32_(p, off + 4 * i) < gonio_d_rdf32_(p, off + 4 * (i - 1))) return 0;
  return 1;
}
GONIO_DEVICE_HOST_FN int gonio_d_all_le_(const gonio_u8 *p, gonio_u64 off, gonio_u64 count,
                                         double max) {
  gonio_u64 i;
  for (i = 0; i < count; i++)
    if ((double)gonio_d_rdf32_(p, off + 4 * i) > max) return 0;
  return 1;
}
GONIO_DEVICE_HOST_FN int gonio_d_guides_le_(const gonio_u8 *p, gonio_u64 off, gonio_u64 count,
                                            gonio_u64 max) {
  gonio_u64 i;
  for (i = 0; i < count; i++)
    if ((gonio_u64)gonio_d_rd32_(p, off + 4 * i) > max) return 0;
  return 1;
}

/* Validates `bytes` bytes at `tables` as an f32 table blob (docs/TABLES.md, every check of
 * "What a reader must check", in its order) and fills *view with pointers into it. Returns
 * GONIO_DEVICE_OK (0) or the GONIO_DEVICE_E_* code of the first failed check; on failure *view
 * is zeroed. Never reads outside [tables, tables + bytes). Time: one pass over the bytes (the
 * checksum) plus one over the tables. Differences from the library's reader: a grid target is
 * checked as Diagram::new checks a diagram that needs no snapping of its angles (what the
 * library writes), without its test that the light integrates to a positive power; grids beyond
 * the float32 kernels' 32-bit indices are refused (GONIO_DEVICE_E_HEADER; the library's float32
 * maps never have them). */
GONIO_DEVICE_HOST_FN int gonio_d_view_init_(GonioDeviceView *view, const void *tables,
                                            size_t bytes) {
  const gonio_u8 *p = (const gonio_u8 *)tables;
  const gonio_u64 len = (gonio_u64)bytes;
  gonio_u32 precision, layout, frame, target, table_count, present, lookup, tw, th;
  double p_lower, inv_2t, tint, max_azimuth, max_radius, max_density;
  gonio_u64 total, dir_end, prev_end;
  gonio_u32 slots = 0; /* bit s: slot s present */
  gonio_u64 sm[2][5];  /* m, n, k, g, rg per slot */
  gonio_u64 ids[30], elems[30], counts[30];
  gonio_u32 expect = 0, e, s;
  const gonio_u32 one = 1u;
  unsigned char endian;
  memset(view, 0, sizeof *view);
  if (tables == NULL && bytes > 0) return GONIO_DEVICE_E_NULL;
  memcpy(&endian, &one, 1);
  if (endian != 1) return GONIO_DEVICE_E_ENDIAN;
  /* 1. header, magic, version, header_bytes. */
  if (len < 256) return GONIO_DEVICE_E_TRUNCATED;
  if (memcmp(p, "GONIOTAB", 8) != 0) return GONIO_DEVICE_E_MAGIC;
  if (gonio_d_rd32_(p, 8) != 1u) return GONIO_DEVICE_E_VERSION;
  if (gonio_d_rd32_(p, 12) != 256u) return GONIO_DEVICE_E_HEADER;
  /* 2. total_bytes. */
  total = gonio_d_rd64_(p, 16);
  if (total > len) return GONIO_DEVICE_E_TRUNCATED;
  if (total != len || total % 64u != 0u) return GONIO_DEVICE_E_HEADER;
  /* 3. checksum. */
  if (gonio_d_rd64_(p, 24) != gonio_device_checksum(p, bytes)) return GONIO_DEVICE_E_CHECKSUM;
  /* 4. precision, layout, frame, target, reserved. */
  precision = gonio_d_rd32_(p, 32);
  if (precision == 8u) return GONIO_DEVICE_E_F64;
  if (precision != 4u) return GONIO_DEVICE_E_PRECISION;
  layout = gonio_d_rd32_(p, 36);
  frame = gonio_d_rd32_(p, 40);
  target = gonio_d_rd32_(p, 44);
  if (layout > 2u || frame > 2u || target > 2u) return GONIO_DEVICE_E_HEADER;
  table_count = gonio_d_rd32_(p, 48);
  if (gonio_d_rd32_(p, 52) != 0u) return GONIO_DEVICE_E_HEADER;
  present = gonio_d_rd32_(p, 56);
  lookup = gonio_d_rd32_(p, 60);
  p_lower = gonio_d_rdf64_(p, 64);
  inv_2t = gonio_d_rdf64_(p, 72);
  tint = gonio_d_rdf64_(p, 80);
  tw = gonio_d_rd32_(p, 88);
  th = gonio_d_rd32_(p, 92);
  /* 5. maps_present, p_lower, inv_2t. */
  if (layout != 2u) {
    if (present != 1u || !gonio_d_plus_zero_(p, 64)) return GONIO_DEVICE_E_HEADER;
  } else {
    int ok = (present == 1u && p_lower == 1.0) || (present == 2u && gonio_d_plus_zero_(p, 64)) ||
             (present == 3u && p_lower > 0.0 && p_lower < 1.0);
    if (!ok || !gonio_d_is_f32_(p_lower)) return GONIO_DEVICE_E_HEADER;
  }
  slots = present;
  if (!(gonio_d_f64_finite_(inv_2t) && inv_2t > 0.0) || !gonio_d_is_f32_(inv_2t))
    return GONIO_DEVICE_E_HEADER;
  /* 6. the slots' counts (scalars below, with the tables, as the library's reader). */
  for (s = 0; s < 2; s++) {
    gonio_u64 at = 96u + 80u * s, r;
    if (slots & (1u << s)) {
      gonio_u64 mins[5] = {1, 2, 1, 1, 1};
      for (r = 0; r < 5; r++) {
        sm[s][r] = gonio_d_rd32_(p, at + 4 * r);
        if (sm[s][r] < mins[r]) return GONIO_DEVICE_E_HEADER;
      }
      if (sm[s][0] >= (1u << 22) || sm[s][1] >= (1u << 22)) return GONIO_DEVICE_E_HEADER;
      for (r = 20; r < 32; r++)
        if (p[at + r] != 0) return GONIO_DEVICE_E_HEADER;
      /* The float32 kernels' 32-bit indices (stricter than the library's reader). */
      if (sm[s][0] * sm[s][1] >= (1ull << 31) || sm[s][2] >= (1u << 24) ||
          sm[s][0] * (sm[s][2] + 1) >= (1ull << 31) || sm[s][3] >= (1u << 24) ||
          sm[s][4] >= (1u << 24))
        return GONIO_DEVICE_E_HEADER;
    } else {
      for (r = 0; r < 80; r++)
        if (p[at + r] != 0) return GONIO_DEVICE_E_HEADER;
    }
  }
  /* 7. lookup and the target fields. */
  if (target == 2u ? lookup > 1u : lookup != 0u) return GONIO_DEVICE_E_HEADER;
  if (target == 0u) {
    if (tw != 0u || th != 0u || !gonio_d_plus_zero_(p, 80)) return GONIO_DEVICE_E_HEADER;
  } else if (target == 1u) {
    if (tw == 0u || th == 0u) return GONIO_DEVICE_E_HEADER;
    if (!(gonio_d_f64_finite_(tint) && tint >= 0.0)) return GONIO_DEVICE_E_HEADER;
  } else {
    if (tw == 0u || th == 0u) return GONIO_DEVICE_E_HEADER;
    if (!gonio_d_plus_zero_(p, 80)) return GONIO_DEVICE_E_HEADER;
  }
  /* 8. the directory: expected entries, then each entry, before any table is read. */
  for (s = 0; s < 2; s++) {
    gonio_u64 m, n, k;
    gonio_u32 t;
    if (!(slots & (1u << s))) continue;
    m = sm[s][0];
    n = sm[s][1];
    k = sm[s][2];
    {
      gonio_u64 c[12];
      c[0] = m + 1; c[1] = m; c[2] = m + 1; c[3] = m + 1; c[4] = sm[s][3]; c[5] = n;
      c[6] = m * n; c[7] = m * n; c[8] = m; c[9] = sm[s][4]; c[10] = n - 1; c[11] = m * (k + 1);
      for (t = 0; t < 12; t++) {
        ids[expect] = 16u * s + t;
        elems[expect] = (t == 4 || t == 9 || t == 11) ? 3u : 1u;
        counts[expect] = c[t];
        expect++;
      }
    }
  }
  if (target == 1u) {
    ids[expect] = 32; elems[expect] = 2; counts[expect] = tw; expect++;
    ids[expect] = 33; elems[expect] = 2; counts[expect] = th; expect++;
    ids[expect] = 34; elems[expect] = 2; counts[expect] = (gonio_u64)tw * th; expect++;
  } else if (target == 2u) {
    gonio_u64 px = (gonio_u64)tw * th;
    ids[expect] = 40; elems[expect] = 1;
    /* W·H·3 may overflow 64 bits: no stored count can equal it then. */
    counts[expect] = px > (~0ull) / 3u ? ~0ull : px * 3u;
    expect++;
  }
  if ((gonio_u64)table_count != expect) return GONIO_DEVICE_E_DIRECTORY;
  dir_end = 256u + 32u * (gonio_u64)table_count;
  if (dir_end > len) return GONIO_DEVICE_E_TRUNCATED;
  prev_end = dir_end;
  {
    gonio_u64 offs[30];
    for (e = 0; e < expect; e++) {
      gonio_u64 at = 256u + 32u * e, off, count, size, end;
      if (gonio_d_rd32_(p, at) != ids[e] || gonio_d_rd32_(p, at + 4) != elems[e])
        return GONIO_DEVICE_E_DIRECTORY;
      count = gonio_d_rd64_(p, at + 16);
      off = gonio_d_rd64_(p, at + 8);
      if (count != counts[e] || gonio_d_rd64_(p, at + 24) != 0u) return GONIO_DEVICE_E_DIRECTORY;
      if (off % 64u != 0u || off < prev_end) return GONIO_DEVICE_E_DIRECTORY;
      size = elems[e] == 2u ? 8u : 4u;
      if (count > (~0ull) / size) return GONIO_DEVICE_E_DIRECTORY;
      end = off + count * size;
      if (end < off || end > len) return GONIO_DEVICE_E_DIRECTORY;
      offs[e] = off;
      prev_end = end;
    }
    /* Tables are used in place: the blob's address must suit doubles. */
    if (((size_t)p) % 8u != 0u) return GONIO_DEVICE_E_ALIGNMENT;
    /* 9. the contents, slot by slot, then the target. */
    max_azimuth = 6.283185307179586 * (1.0 + 1e-6);
    max_radius = (layout == 1u ? 1.4142135623730951 : 1.0) * (1.0 + 1e-6);
    max_density = 3.4028234663852886e38 / (inv_2t > 1.0 ? inv_2t : 1.0);
    e = 0;
    for (s = 0; s < 2; s++) {
      GonioDeviceMap *c = &view->map[s];
      gonio_u64 at = 96u + 80u * s, m, n, i, t;
      double sc[5];
      const gonio_u64 *o;
      if (!(slots & (1u << s))) continue;
      for (t = 0; t < 5; t++) {
        sc[t] = gonio_d_rdf64_(p, at + 32 + 8 * t);
        if (!gonio_d_f64_finite_(sc[t]) || sc[t] < 0.0 || (t == 1 && sc[t] <= 0.0) ||
            !gonio_d_is_f32_(sc[t]))
          return GONIO_DEVICE_E_HEADER;
      }
      if (!gonio_d_plus_zero_(p, at + 72)) return GONIO_DEVICE_E_HEADER;
      m = sm[s][0];
      n = sm[s][1];
      o = &offs[e];
      /* phi: in [0, 2π] (+ 1e-6 relative) */
      if (!gonio_d_all_finite_(p, o[0], m + 1) || !gonio_d_nondecreasing_(p, o[0], m + 1) ||
          !gonio_d_all_nonneg_(p, o[0], 1) || !gonio_d_all_le_(p, o[0], m + 1, max_azimuth))
        return GONIO_DEVICE_E_CONTENT;
      /* beta: in [0, 2π]; r2 >= 0 */
      if (!gonio_d_all_finite_(p, o[1], m) || !gonio_d_all_nonneg_(p, o[1], m) ||
          !gonio_d_all_le_(p, o[1], m, max_azimuth))
        return GONIO_DEVICE_E_CONTENT;
      if (!gonio_d_all_finite_(p, o[2], m + 1) || !gonio_d_all_nonneg_(p, o[2], m + 1))
        return GONIO_DEVICE_E_CONTENT;
      /* cum */
      if (!gonio_d_all_finite_(p, o[3], m + 1) || !gonio_d_all_nonneg_(p, o[3], 1) ||
          !gonio_d_nondecreasing_(p, o[3], m + 1))
        return GONIO_DEVICE_E_CONTENT;
      if (!gonio_d_guides_le_(p, o[4], sm[s][3], m - 1)) return GONIO_DEVICE_E_CONTENT;
      /* x: within the map's disk (1, or √2 for the Lambert sphere, + 1e-6 relative) */
      if (!gonio_d_all_finite_(p, o[5], n) || !gonio_d_all_nonneg_(p, o[5], 1) ||
          !gonio_d_nondecreasing_(p, o[5], n) || !gonio_d_all_le_(p, o[5], n, max_radius))
        return GONIO_DEVICE_E_CONTENT;
      /* d: >= 0, and d·inv_2t a finite float */
      if (!gonio_d_all_finite_(p, o[6], m * n) || !gonio_d_all_nonneg_(p, o[6], m * n) ||
          !gonio_d_all_le_(p, o[6], m * n, max_density))
        return GONIO_DEVICE_E_CONTENT;
      /* u: each row from >= 0, non-decreasing */
      if (!gonio_d_all_finite_(p, o[7], m * n)) return GONIO_DEVICE_E_CONTENT;
      for (i = 0; i < m; i++) /* M rows */
        if (!gonio_d_all_nonneg_(p, o[7] + 4 * i * n, 1) ||
            !gonio_d_nondecreasing_(p, o[7] + 4 * i * n, n))
          return GONIO_DEVICE_E_CONTENT;
      /* total */
      if (!gonio_d_all_finite_(p, o[8], m)) return GONIO_DEVICE_E_CONTENT;
      for (i = 0; i < m; i++)
        if (gonio_d_rdf32_(p, o[8] + 4 * i) != gonio_d_rdf32_(p, o[7] + 4 * (i * n + n - 1)))
          return GONIO_DEVICE_E_CONTENT;
      if (!gonio_d_guides_le_(p, o[9], sm[s][4], n - 2)) return GONIO_DEVICE_E_CONTENT;
      if (!gonio_d_all_finite_(p, o[10], n - 1) || !gonio_d_all_nonneg_(p, o[10], n - 1))
        return GONIO_DEVICE_E_CONTENT;
      if (!gonio_d_guides_le_(p, o[11], m * (sm[s][2] + 1), n - 2)) return GONIO_DEVICE_E_CONTENT;
      /* The slot's view. */
      c->m = (gonio_i32)m;
      c->n = (gonio_i32)n;
      c->k = (gonio_i32)sm[s][2];
      c->wedge_guide_len = (gonio_i32)sm[s][3];
      c->radius_guide_len = (gonio_i32)sm[s][4];
      c->inv_uniform_beta = (float)sc[0];
      c->kappa = (float)sc[1];
      c->guide_scale = (float)sc[2];
      c->radius_scale = (float)sc[3];
      c->edge = (float)sc[4];
      for (t = 0; t < 12; t++) {
        c->offset[t] = o[t];
        c->len[t] = (gonio_i32)counts[e + t];
      }
      e += 12;
    }
    if (target == 1u) {
      /* A valid diagram: θ strictly increasing in [0, π] (N_t >= 2), φ strictly increasing in
       * [0, 2π), values finite, >= 0, not all 0, at most 2^26 nodes. */
      const double pi = 3.141592653589793, tau = 6.283185307179586;
      gonio_u64 i, nv = (gonio_u64)tw * th;
      int any = 0;
      if (tw < 2u || nv > (1ull << 26)) return GONIO_DEVICE_E_CONTENT;
      for (i = 0; i < tw; i++) {
        double a = gonio_d_rdf64_(p, offs[e] + 8 * i);
        if (!gonio_d_f64_finite_(a) || a < 0.0 || a > pi) return GONIO_DEVICE_E_CONTENT;
        if (i > 0 && !(a > gonio_d_rdf64_(p, offs[e] + 8 * (i - 1)))) return GONIO_DEVICE_E_CONTENT;
      }
      for (i = 0; i < th; i++) {
        double a = gonio_d_rdf64_(p, offs[e + 1] + 8 * i);
        if (!gonio_d_f64_finite_(a) || a < 0.0 || a >= tau) return GONIO_DEVICE_E_CONTENT;
        if (i > 0 && !(a > gonio_d_rdf64_(p, offs[e + 1] + 8 * (i - 1))))
          return GONIO_DEVICE_E_CONTENT;
      }
      for (i = 0; i < nv; i++) {
        double a = gonio_d_rdf64_(p, offs[e + 2] + 8 * i);
        if (!gonio_d_f64_finite_(a) || a < 0.0) return GONIO_DEVICE_E_CONTENT;
        if (a > 0.0) any = 1;
      }
      if (!any) return GONIO_DEVICE_E_CONTENT;
      view->target_offset[0] = offs[e];
      view->target_offset[1] = offs[e + 1];
      view->target_offset[2] = offs[e + 2];
    } else if (target == 2u) {
      gonio_u64 cnt = (gonio_u64)tw * th * 3u;
      if (!gonio_d_all_finite_(p, offs[e], cnt) || !gonio_d_all_nonneg_(p, offs[e], cnt))
        return GONIO_DEVICE_E_CONTENT;
      view->target_offset[0] = offs[e];
    }
  }
  view->total_bytes = total;
  view->layout = layout;
  view->frame = frame;
  view->target = target;
  view->maps_present = present;
  view->lookup = lookup;
  view->p_lower = (float)p_lower;
  view->inv_2t = (float)inv_2t;
  view->target_integral = tint;
  view->target_a = tw;
  view->target_b = th;
  gonio_device_view_rebase(view, p);
  return GONIO_DEVICE_OK;
}

GONIO_DEVICE_HOST_FN int gonio_device_view_init(GonioDeviceView *view, const void *tables,
                                                size_t bytes) {
  int r;
  if (view == NULL) return GONIO_DEVICE_E_NULL;
  r = gonio_d_view_init_(view, tables, bytes);
  if (r != GONIO_DEVICE_OK) memset(view, 0, sizeof *view);
  return r;
}


/* Validates `bytes` bytes at `tables` as an f32 family blob (docs/TABLES.md, "Families": layout
 * 3, target 3) and fills *b with pointers into it. Returns GONIO_DEVICE_OK or the code of the
 * first failed check (on failure *b is zeroed); never reads outside the bytes. Checks: the
 * header steps 1–3 of gonio_device_view_init (size, magic, version, checksum), precision 4, the
 * fixed family fields, the directory (ids, element types, counts from the header in 64-bit
 * arithmetic, alignment, order, inside the blob) before any table is read, then the contents as
 * the library's read_family: every float finite; each present slice's φ/Γ from 0 to 2π, Γ, x and
 * every row of U non-decreasing, D, R², β, 1/Δx ≥ 0, total = the row's last U, its guides within
 * their tables, 1/(2T) > 0, κ in [0.5, 2]; absent slices all zero; the angle grids strictly
 * increasing in range; the values finite and ≥ 0. */
GONIO_DEVICE_HOST_FN int gonio_d_brdf_init_(GonioDeviceBrdf *bf, const void *tables, size_t bytes) {
  const gonio_u8 *p = (const gonio_u8 *)tables;
  const gonio_u64 len = (gonio_u64)bytes;
  const gonio_u32 one = 1u;
  unsigned char endian;
  gonio_u64 m, n, k, g, rg, a, bb, aniso, ch, nto, npo, s, counts[12], cnt[18], off[18], prev, sl;
  gonio_u32 ids[18], elem[18], table_count, e;
  const int stacked[12] = {0, 0, 1, 1, 1, 0, 1, 1, 1, 0, 0, 1};
  GonioDeviceMap *c = &bf->grid;
  double tau32 = (double)(float)6.283185307179586;
  memset(bf, 0, sizeof *bf);
  if (tables == NULL) return GONIO_DEVICE_E_NULL;
  memcpy(&endian, &one, 1);
  if (endian != 1) return GONIO_DEVICE_E_ENDIAN;
  if (len < 256) return GONIO_DEVICE_E_TRUNCATED;
  if (memcmp(p, "GONIOTAB", 8) != 0) return GONIO_DEVICE_E_MAGIC;
  if (gonio_d_rd32_(p, 8) != 1u) return GONIO_DEVICE_E_VERSION;
  if (gonio_d_rd32_(p, 12) != 256u) return GONIO_DEVICE_E_HEADER;
  if (gonio_d_rd64_(p, 16) > len) return GONIO_DEVICE_E_TRUNCATED;
  if (gonio_d_rd64_(p, 16) != len || len % 64u != 0u) return GONIO_DEVICE_E_HEADER;
  if (gonio_d_rd64_(p, 24) != gonio_device_checksum(p, bytes)) return GONIO_DEVICE_E_CHECKSUM;
  if (gonio_d_rd32_(p, 32) == 8u) return GONIO_DEVICE_E_F64;
  if (gonio_d_rd32_(p, 32) != 4u) return GONIO_DEVICE_E_PRECISION;
  /* The tables are read in place as float, u32 and double: 8-byte alignment. */
  if (((size_t)p) % 8u != 0u) return GONIO_DEVICE_E_ALIGNMENT;
  /* Layout 3, frame 0, target 3, maps_present 1, the fixed values of a family. */
  if (gonio_d_rd32_(p, 36) != 3u || gonio_d_rd32_(p, 40) != 0u || gonio_d_rd32_(p, 44) != 3u ||
      gonio_d_rd32_(p, 52) != 0u || gonio_d_rd32_(p, 56) != 1u || gonio_d_rd32_(p, 60) != 0u ||
      !gonio_d_plus_zero_(p, 64) || gonio_d_rdf64_(p, 72) != 0.5 || !gonio_d_plus_zero_(p, 80) ||
      gonio_d_rd32_(p, 88) != 0u || gonio_d_rd32_(p, 92) != 0u)
    return GONIO_DEVICE_E_HEADER;
  table_count = gonio_d_rd32_(p, 48);
  m = gonio_d_rd32_(p, 96);
  n = gonio_d_rd32_(p, 100);
  k = gonio_d_rd32_(p, 104);
  g = gonio_d_rd32_(p, 108);
  rg = gonio_d_rd32_(p, 112);
  if (m < 1 || n < 2 || k < 1 || g < 1 || rg < 1 || m >= (1u << 22) || n >= (1u << 22) ||
      k >= (1u << 24) || g >= (1u << 24) || rg >= (1u << 24))
    return GONIO_DEVICE_E_HEADER;
  for (e = 116; e < 128; e++)
    if (p[e] != 0) return GONIO_DEVICE_E_HEADER;
  if (!gonio_d_plus_zero_(p, 136) || !gonio_d_plus_zero_(p, 160) || !gonio_d_plus_zero_(p, 168))
    return GONIO_DEVICE_E_HEADER; /* κ, edge, reserved */
  {
    double iub = gonio_d_rdf64_(p, 128), gs = gonio_d_rdf64_(p, 144), rs = gonio_d_rdf64_(p, 152);
    if (!(gonio_d_f64_finite_(iub) && iub >= 0.0 && gonio_d_is_f32_(iub)) ||
        !(gonio_d_f64_finite_(gs) && gs >= 0.0 && gonio_d_is_f32_(gs)) ||
        !(gonio_d_f64_finite_(rs) && rs >= 0.0 && gonio_d_is_f32_(rs)))
      return GONIO_DEVICE_E_HEADER;
    c->inv_uniform_beta = (float)iub;
    c->guide_scale = (float)gs;
    c->radius_scale = (float)rs;
  }
  a = gonio_d_rd32_(p, 176);
  bb = gonio_d_rd32_(p, 180);
  aniso = gonio_d_rd32_(p, 184);
  ch = gonio_d_rd32_(p, 188);
  nto = gonio_d_rd32_(p, 192);
  npo = gonio_d_rd32_(p, 196);
  if (a < 1 || bb < 1 || nto < 1 || npo < 1 || aniso > 1 || (aniso == 0 && bb != 1) ||
      (ch != 1 && ch != 3))
    return GONIO_DEVICE_E_HEADER;
  for (e = 200; e < 256; e++)
    if (p[e] != 0) return GONIO_DEVICE_E_HEADER;
  s = a * bb;
  /* Counts in 64-bit arithmetic: every stacked table and the values below 2^31 entries (the
   * kernels' 32-bit indices). */
  counts[0] = m + 1; counts[1] = m; counts[2] = m + 1; counts[3] = m + 1; counts[4] = g;
  counts[5] = n; counts[6] = m * n; counts[7] = m * n; counts[8] = m; counts[9] = rg;
  counts[10] = n - 1; counts[11] = m * (k + 1);
  for (e = 0; e < 12; e++) { /* 12 steps */
    if (stacked[e] && counts[e] > ((1ull << 31) - 1) / s) return GONIO_DEVICE_E_HEADER;
    cnt[e] = stacked[e] ? counts[e] * s : counts[e];
    ids[e] = e;
    elem[e] = (e == 4 || e == 9 || e == 11) ? 3u : 1u;
  }
  if (s > (1ull << 28) || nto * npo > (1ull << 31) / (ch * s)) return GONIO_DEVICE_E_HEADER;
  ids[12] = 64; elem[12] = 1; cnt[12] = 4 * s;
  ids[13] = 65; elem[13] = 2; cnt[13] = a;
  ids[14] = 66; elem[14] = 2; cnt[14] = bb;
  ids[15] = 48; elem[15] = 2; cnt[15] = nto;
  ids[16] = 49; elem[16] = 2; cnt[16] = npo;
  ids[17] = 50; elem[17] = 2; cnt[17] = ch * s * nto * npo;
  if (table_count != 18u) return GONIO_DEVICE_E_DIRECTORY;
  prev = 256u + 32u * 18u;
  if (prev > len) return GONIO_DEVICE_E_TRUNCATED;
  for (e = 0; e < 18; e++) { /* 18 steps */
    gonio_u64 at = 256u + 32u * e, size = elem[e] == 2u ? 8u : 4u;
    off[e] = gonio_d_rd64_(p, at + 8);
    if (gonio_d_rd32_(p, at) != ids[e] || gonio_d_rd32_(p, at + 4) != elem[e] ||
        gonio_d_rd64_(p, at + 16) != cnt[e] || gonio_d_rd64_(p, at + 24) != 0u ||
        off[e] % 64u != 0u || off[e] < prev || off[e] > len || cnt[e] > (len - off[e]) / size)
      return GONIO_DEVICE_E_DIRECTORY;
    prev = off[e] + cnt[e] * size;
  }
  /* Contents. Floats finite (f32 tables and the f64 grids and values). */
  for (e = 0; e < 13; e++)
    if (elem[e] == 1u && !gonio_d_all_finite_(p, off[e], cnt[e])) return GONIO_DEVICE_E_CONTENT;
  for (e = 13; e < 18; e++) {
    gonio_u64 i;
    for (i = 0; i < cnt[e]; i++) {
      double v = gonio_d_rdf64_(p, off[e] + 8 * i);
      if (!gonio_d_f64_finite_(v)) return GONIO_DEVICE_E_CONTENT;
      if (e == 17 && v < 0.0) return GONIO_DEVICE_E_CONTENT;
      if (e < 17) {
        double hi = (e == 13 || e == 15) ? 1.5707963267948966 * (1.0 + 1e-12) : 6.283185307179586;
        int open = (e == 14 || e == 16);
        if (v < 0.0 || (open ? v >= hi : v > hi)) return GONIO_DEVICE_E_CONTENT;
        if (i > 0 && !(v > gonio_d_rdf64_(p, off[e] + 8 * (i - 1)))) return GONIO_DEVICE_E_CONTENT;
      }
    }
  }
  if (aniso == 0 && gonio_d_rdf64_(p, off[14]) != 0.0) return GONIO_DEVICE_E_CONTENT;
  /* The shared grid. */
  if (gonio_d_rdf32_(p, off[0]) != 0.0f || (double)gonio_d_rdf32_(p, off[0] + 4 * m) != tau32 ||
      !gonio_d_nondecreasing_(p, off[0], m + 1) || !gonio_d_all_nonneg_(p, off[1], m) ||
      !gonio_d_all_le_(p, off[1], m, 6.283185307179586 * (1.0 + 1e-6)) ||
      gonio_d_rdf32_(p, off[5]) < 0.0f || !gonio_d_nondecreasing_(p, off[5], n) ||
      !gonio_d_all_le_(p, off[5], n, 1.0 + 1e-6) || !gonio_d_all_nonneg_(p, off[10], n - 1) ||
      !gonio_d_guides_le_(p, off[9], rg, n - 2))
    return GONIO_DEVICE_E_CONTENT;
  /* Each slice. */
  for (sl = 0; sl < s; sl++) { /* s steps */
    gonio_u64 row = off[12] + 16 * sl, i;
    float inv2t = gonio_d_rdf32_(p, row), kap = gonio_d_rdf32_(p, row + 4);
    float edge = gonio_d_rdf32_(p, row + 8), res = gonio_d_rdf32_(p, row + 12);
    gonio_u64 o_r2 = off[2] + 4 * sl * (m + 1), o_cum = off[3] + 4 * sl * (m + 1);
    gonio_u64 o_wg = off[4] + 4 * sl * g, o_d = off[6] + 4 * sl * m * n, o_u = off[7] + 4 * sl * m * n;
    gonio_u64 o_t = off[8] + 4 * sl * m, o_rg = off[11] + 4 * sl * m * (k + 1);
    if (inv2t == 0.0f && kap == 0.0f && edge == 0.0f && res == 0.0f) {
      /* No map: every part zero. */
      const gonio_u64 o[7] = {o_r2, o_cum, o_wg, o_d, o_u, o_t, o_rg};
      const gonio_u64 l[7] = {m + 1, m + 1, g, m * n, m * n, m, m * (k + 1)};
      gonio_u64 q;
      for (q = 0; q < 7; q++)
        for (i = 0; i < 4 * l[q]; i++)
          if (p[o[q] + i] != 0) return GONIO_DEVICE_E_CONTENT;
      continue;
    }
    if (!(inv2t > 0.0f) || !(kap >= 0.5f && kap <= 2.0f) || !(edge >= 0.0f) || res != 0.0f ||
        !((double)inv2t * 3.4028234663852886e38 > 0.0))
      return GONIO_DEVICE_E_CONTENT;
    if (!gonio_d_all_nonneg_(p, o_r2, m + 1) || gonio_d_rdf32_(p, o_cum) != 0.0f ||
        (double)gonio_d_rdf32_(p, o_cum + 4 * m) != tau32 || !gonio_d_nondecreasing_(p, o_cum, m + 1) ||
        !gonio_d_guides_le_(p, o_wg, g, m - 1) || !gonio_d_all_nonneg_(p, o_d, m * n) ||
        !gonio_d_all_le_(p, o_d, m * n, 3.4028234663852886e38 / ((double)inv2t > 1.0 ? (double)inv2t : 1.0)) ||
        !gonio_d_guides_le_(p, o_rg, m * (k + 1), n - 2))
      return GONIO_DEVICE_E_CONTENT;
    for (i = 0; i < m; i++) { /* m steps */
      gonio_u64 ro = o_u + 4 * i * n;
      if (gonio_d_rdf32_(p, ro) < 0.0f || !gonio_d_nondecreasing_(p, ro, n) ||
          gonio_d_rdf32_(p, o_t + 4 * i) != gonio_d_rdf32_(p, ro + 4 * (n - 1)))
        return GONIO_DEVICE_E_CONTENT;
    }
  }
  bf->total_bytes = len;
  c->m = (gonio_i32)m;
  c->n = (gonio_i32)n;
  c->k = (gonio_i32)k;
  c->wedge_guide_len = (gonio_i32)g;
  c->radius_guide_len = (gonio_i32)rg;
  c->kappa = 1.0f;
  c->edge = 1.0f;
  for (e = 0; e < 12; e++) {
    c->offset[e] = off[e];
    c->len[e] = (gonio_i32)cnt[e];
    bf->offset[e] = off[e];
  }
  for (e = 12; e < 17; e++) bf->offset[e] = off[e];
  bf->values_offset = off[17];
  bf->slices = (gonio_i32)s;
  bf->slice_len = (gonio_i32)(4 * s);
  bf->a = (gonio_i32)a;
  bf->b = (gonio_i32)bb;
  bf->anisotropic = (gonio_i32)aniso;
  bf->channels = (gonio_i32)ch;
  bf->n_to = (gonio_i32)nto;
  bf->n_po = (gonio_i32)npo;
  gonio_device_brdf_rebase(bf, p);
  return GONIO_DEVICE_OK;
}

GONIO_DEVICE_HOST_FN int gonio_device_brdf_init(GonioDeviceBrdf *b, const void *tables, size_t bytes) {
  int r;
  if (b == NULL) return GONIO_DEVICE_E_NULL;
  r = gonio_d_brdf_init_(b, tables, bytes);
  if (r != GONIO_DEVICE_OK) memset(b, 0, sizeof *b);
  return r;
}

#endif /* !__CUDACC_RTC__ */

#ifdef __cplusplus
} /* extern "C" */
#endif

#if defined(GONIO_DEVICE_GCC_OPTIONS_)
#pragma GCC pop_options
#undef GONIO_DEVICE_GCC_OPTIONS_
#endif

#endif /* GONIO_DEVICE_H */
