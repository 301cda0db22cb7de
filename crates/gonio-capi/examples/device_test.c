/* device_test.c: the contract of include/gonio_device.h on the host, against the library.
 * SPDX-License-Identifier: MIT OR Apache-2.0
 *
 * For every case (the built-in example luminaire as a JSON diagram in memory, each photometric
 * file given, random JSON diagrams of a fixed seed, both sphere layouts and the hemisphere
 * domain, each environment map given) it takes the float32 table blob from the C ABI
 * (gonio_sampler_tables / gonio_envmap_tables, precision 4), opens it with
 * gonio_device_view_init, and compares the header's sample, pdf and invert, point by point, with
 * the library's float32 batches (gonio_*_batch_soa_f32, gonio_envmap_f32_*):
 *   - points of the square: Halton (bases 2, 3) plus the square's edges, corners and centre;
 *   - directions: the samples' own, the poles, the seam (φ = 0 and φ = 2π − ε over all θ), the
 *     horizon, random unit vectors; each given to the header as the library reads it (normalised
 *     in double, rounded to float);
 *   - asserts: directions within 1e-6 of the library's, pdfs within 8 f32 ulps (relative),
 *     inverses within 1e-5 where the density is positive, NaN where the library's are NaN; and
 *     counts the results that are bit-identical (printed; with -ffp-contract=off all of them);
 *   - the grid target against gonio_diagram_intensity (relative 1e-6 of the maximum).
 * Then that gonio_device_view_init refuses broken blobs with the documented codes: every length
 * short of the blob, each header byte flipped, a changed table byte (checksum), an f64 blob,
 * changed fields and tables with the checksum made valid again, a misaligned or NULL buffer.
 *
 * Usage: device_test [-n POINTS] [-f FILE_POINTS] [-e ENV_POINTS] [-r RANDOM_DIAGRAMS]
 *                    [--refusals-only] FILES...
 *   POINTS (default 10^6) per case of the example and random diagrams (a quarter for each
 *   random one), FILE_POINTS (default POINTS) per photometric file, ENV_POINTS (default 2^16)
 *   per environment map, RANDOM_DIAGRAMS (default 12).
 *   FILES: .ies / .ldt / .json diagrams and .hdr / .exr / .pfm environment maps. Exit status 0
 *   when every check passes. Build: scripts/test-c.sh (cc -std=c99 -ffp-contract=off ...).
 */
#include "gonio.h"
#include "gonio_device.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define CHECK_PRINT_LIMIT 20
#include "check.h"

static const double PI_D = 3.14159265358979323846;

static uint64_t rng_state = 0x2545f4914f6cdd1dull;
static double rnd(void) { return splitmix64_unit(&rng_state); }
static double gauss(void) {
  double a = rnd(), b = rnd();
  if (a < 1e-300) a = 1e-300;
  return sqrt(-2.0 * log(a)) * cos(2.0 * PI_D * b);
}

static double radical_inverse(uint32_t i, uint32_t base) {
  double inv = 1.0 / base, f = inv, r = 0.0;
  while (i > 0) {
    r += f * (double)(i % base);
    i /= base;
    f *= inv;
  }
  return r;
}

static uint32_t bits_of(float f) {
  uint32_t b;
  memcpy(&b, &f, 4);
  return b;
}
static int same_bits(float a, float b) {
  if (a != a && b != b) return 1; /* NaN == NaN for this count */
  return bits_of(a) == bits_of(b);
}
static int pdf_close(float dev, float lib) {
  double m = fabs((double)dev) > fabs((double)lib) ? fabs((double)dev) : fabs((double)lib);
  if (dev != dev || lib != lib) return (dev != dev) == (lib != lib);
  return fabs((double)dev - (double)lib) <= 8.0 * FLT_EPSILON * m;
}
/* gonio::sampler::normalize, in double, then rounded to float: what the float32 batches of the C
 * ABI read. */
static void lib_normalize(const float in[3], float out[3]) {
  double d[3], ss, inv, big, l;
  int c;
  for (c = 0; c < 3; c++) d[c] = (double)in[c];
  ss = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  if (ss >= 1e-290 && ss <= 1e290) {
    inv = 1.0 / sqrt(ss);
    for (c = 0; c < 3; c++) out[c] = (float)(d[c] * inv);
    return;
  }
  big = fabs(d[0]);
  if (fabs(d[1]) > big) big = fabs(d[1]);
  if (fabs(d[2]) > big) big = fabs(d[2]);
  for (c = 0; c < 3; c++) d[c] /= big;
  l = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  for (c = 0; c < 3; c++) out[c] = (float)(d[c] / l);
}

/* ------------------------------------------------------------------------------------------ */
/* Statistics per input kind. */

typedef struct Stats {
  const char *kind;
  int cases;
  double points, dirs;
  double s_dir_same, s_pdf_same, pdf_same, inv_same, inv_nan_agree;
  double max_dir_err, max_spdf_rel, max_pdf_rel, max_inv_err, max_round_trip;
  double target_points, max_target_rel;
  double dev_seconds, dev_calls;
} Stats;

static Stats stats(const char *kind) {
  Stats s;
  memset(&s, 0, sizeof s);
  s.kind = kind;
  return s;
}

static void print_stats(const Stats *s) {
  if (s->cases == 0) return;
  printf("device_test: %-11s %3d cases, %8.0f points, %8.0f directions: bit-identical sample "
         "dir %.4f%% pdf %.4f%%, pdf %.4f%%, invert %.4f%%; max |dir err| %.3g, max pdf rel "
         "err %.3g (sample) %.3g (pdf), max |invert err| %.3g, max round trip %.3g",
         s->kind, s->cases, s->points, s->dirs, 100.0 * s->s_dir_same / s->points,
         100.0 * s->s_pdf_same / s->points, 100.0 * s->pdf_same / s->dirs,
         100.0 * s->inv_same / s->dirs, s->max_dir_err, s->max_spdf_rel, s->max_pdf_rel,
         s->max_inv_err, s->max_round_trip);
  if (s->target_points > 0)
    printf(", target %.0f points max rel err %.3g", s->target_points, s->max_target_rel);
  printf(", header %.0f ns/call\n", 1e9 * s->dev_seconds / (s->dev_calls > 0 ? s->dev_calls : 1));
}

/* ------------------------------------------------------------------------------------------ */
/* The library's float32 calls for one case: a sampler or a float32 environment map. */

typedef struct Lib {
  const GonioSampler *sampler;
  const GonioEnvMapF32 *env;
} Lib;

static int lib_sample(const Lib *l, const float *u, const float *v, size_t n, float *x, float *y,
                      float *z, float *pdf, float *rgb) {
  if (l->sampler) return gonio_sample_batch_soa_f32(l->sampler, u, v, n, x, y, z, pdf);
  return gonio_envmap_f32_sample_batch(l->env, u, v, n, x, y, z, pdf, rgb);
}
static int lib_pdf(const Lib *l, const float *x, const float *y, const float *z, size_t n,
                   float *pdf) {
  if (l->sampler) return gonio_pdf_batch_soa_f32(l->sampler, x, y, z, n, pdf);
  return gonio_envmap_f32_pdf_batch(l->env, x, y, z, n, pdf);
}
static int lib_invert(const Lib *l, const float *x, const float *y, const float *z, size_t n,
                      float *u, float *v) {
  if (l->sampler) return gonio_invert_batch_soa_f32(l->sampler, x, y, z, n, u, v);
  return gonio_envmap_f32_invert_batch(l->env, x, y, z, n, u, v);
}

static double now(void) { return (double)clock() / CLOCKS_PER_SEC; }

/* The blob of a case (malloc'ed, so aligned for any type), or NULL. */
static unsigned char *sampler_blob(const GonioSampler *s, const GonioDiagram *target,
                                   uint32_t precision, size_t *size) {
  unsigned char *b;
  if (gonio_sampler_tables(s, target, precision, NULL, 0, size) != GONIO_OK) return NULL;
  b = (unsigned char *)malloc(*size);
  if (!b) return NULL;
  if (gonio_sampler_tables(s, target, precision, (uint8_t *)b, *size, size) != GONIO_OK) {
    free(b);
    return NULL;
  }
  return b;
}

/* An array of n floats; stops the test when memory runs out. */
static float *floats(size_t n) {
  float *p = (float *)malloc((n ? n : 1) * sizeof *p);
  if (!p) {
    fprintf(stderr, "device_test: out of memory (%lu floats)\n", (unsigned long)n);
    exit(1);
  }
  return p;
}

/* Compares the header with the library on n points of the square and on directions. */
static void compare(const char *name, const Lib *lib, const GonioDeviceView *view,
                    const GonioDiagram *target, size_t n, Stats *st) {
  size_t n_edge = 257, n_halton, nd, i, k = 0, d, n_rand, n_seam = 1025;
  float *u, *v, *x, *y, *z, *pdf, *rgb, *dx, *dy, *dz, *lp, *lu, *lv;
  double t0, max_target = 0.0;
  if (n < 4 * n_edge + 1) n = 4 * n_edge + 1;
  /* One allocation for the points u, v and the library's x, y, z, pdf (n each) and rgb (3n). */
  u = floats(9 * n);
  v = u + n;
  x = v + n; y = x + n; z = y + n;
  pdf = z + n;
  rgb = pdf + n;
  n_halton = n - 4 * n_edge - 1;
  /* Points: the centre, the four edges (corners included), Halton. */
  u[k] = 0.5f;
  v[k++] = 0.5f;
  for (i = 0; i < n_edge; i++) {
    float t = (float)((double)i / (double)(n_edge - 1));
    u[k] = 0.0f; v[k++] = t;
    u[k] = 1.0f; v[k++] = t;
    u[k] = t; v[k++] = 0.0f;
    u[k] = t; v[k++] = 1.0f;
  }
  for (i = 0; i < n_halton; i++) {
    u[k] = (float)radical_inverse((uint32_t)(i + 1), 2);
    v[k++] = (float)radical_inverse((uint32_t)(i + 1), 3);
  }
  CHECK(lib_sample(lib, u, v, n, x, y, z, pdf, rgb) == GONIO_OK, "%s: sample batch: %s", name,
        gonio_last_error_message());
  t0 = now();
  for (i = 0; i < n; i++) {
    float dir[3], p, e;
    int c, same = 1;
    gonio_device_sample(view, u[i], v[i], dir, &p);
    {
      float ld[3];
      ld[0] = x[i]; ld[1] = y[i]; ld[2] = z[i];
      for (c = 0; c < 3; c++) {
        same &= same_bits(dir[c], ld[c]);
        e = (float)fabs((double)dir[c] - (double)ld[c]);
        CHECK(e <= 1e-6f, "%s: sample(%.9g, %.9g) direction %d: %.9g, library %.9g", name,
              u[i], v[i], c, dir[c], ld[c]);
        if (e > st->max_dir_err) st->max_dir_err = e;
      }
    }
    st->s_dir_same += same;
    st->s_pdf_same += same_bits(p, pdf[i]);
    if (!pdf_close(p, pdf[i])) {
      CHECK(0, "%s: sample(%.9g, %.9g) pdf %.9g, library %.9g", name, u[i], v[i], p, pdf[i]);
    } else if (pdf[i] > 0.0f) {
      double r = fabs((double)p - (double)pdf[i]) / pdf[i];
      if (r > st->max_spdf_rel) st->max_spdf_rel = r;
    }
  }
  st->dev_seconds += now() - t0;
  st->dev_calls += (double)n;
  /* Directions: the samples', poles, seam, horizon, random. */
  n_rand = n / 4;
  nd = n + 6 + 4 * n_seam + 64 + n_rand;
  /* One allocation for the directions dx, dy, dz and the library's pdf, u, v (nd each). */
  dx = floats(6 * nd);
  dy = dx + nd; dz = dy + nd;
  lp = dz + nd; lu = lp + nd; lv = lu + nd;
  memcpy(dx, x, n * sizeof *x);
  memcpy(dy, y, n * sizeof *y);
  memcpy(dz, z, n * sizeof *z);
  d = n;
  {
    static const float poles[6][3] = {{0, 0, 1}, {0, 0, -1}, {-0.0f, 0, 1},
                                      {0, -0.0f, -1}, {1, 0, -0.0f}, {0, 1, 0}};
    for (i = 0; i < 6; i++) {
      dx[d] = poles[i][0]; dy[d] = poles[i][1]; dz[d++] = poles[i][2];
    }
  }
  for (i = 0; i < n_seam; i++) {
    double th = PI_D * (double)i / (double)(n_seam - 1), st_ = sin(th), ct = cos(th);
    double eps[3] = {1e-7, 1e-5, 1e-3};
    int e;
    dx[d] = (float)st_; dy[d] = 0.0f; dz[d++] = (float)ct;
    for (e = 0; e < 3; e++) {
      dx[d] = (float)(st_ * cos(-eps[e]));
      dy[d] = (float)(st_ * sin(-eps[e]));
      dz[d++] = (float)ct;
    }
  }
  for (i = 0; i < 64; i++) {
    double ph = 2.0 * PI_D * (double)i / 64.0;
    dx[d] = (float)cos(ph); dy[d] = (float)sin(ph); dz[d++] = (i % 2) ? 0.0f : -0.0f;
  }
  for (i = 0; i < n_rand; i++) {
    double g[3], l;
    do {
      g[0] = gauss(); g[1] = gauss(); g[2] = gauss();
      l = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    } while (l < 1e-6);
    dx[d] = (float)(g[0] / l); dy[d] = (float)(g[1] / l); dz[d++] = (float)(g[2] / l);
  }
  nd = d;
  CHECK(lib_pdf(lib, dx, dy, dz, nd, lp) == GONIO_OK, "%s: pdf batch: %s", name,
        gonio_last_error_message());
  CHECK(lib_invert(lib, dx, dy, dz, nd, lu, lv) == GONIO_OK, "%s: invert batch: %s", name,
        gonio_last_error_message());
  t0 = now();
  for (i = 0; i < nd; i++) {
    float raw[3], dir[3], p, uv[2];
    int r;
    raw[0] = dx[i]; raw[1] = dy[i]; raw[2] = dz[i];
    lib_normalize(raw, dir);
    p = gonio_device_pdf(view, dir);
    st->pdf_same += same_bits(p, lp[i]);
    if (!pdf_close(p, lp[i])) {
      CHECK(0, "%s: pdf(%.9g, %.9g, %.9g) = %.9g, library %.9g", name, dir[0], dir[1], dir[2], p,
            lp[i]);
    } else if (lp[i] > 0.0f) {
      double rr = fabs((double)p - (double)lp[i]) / lp[i];
      if (rr > st->max_pdf_rel) st->max_pdf_rel = rr;
    }
    r = gonio_device_invert(view, dir, uv);
    CHECK(r == (uv[0] != uv[0] || uv[1] != uv[1]), "%s: invert's status %d with uv (%g, %g)", name,
          r, uv[0], uv[1]);
    st->inv_same += same_bits(uv[0], lu[i]) && same_bits(uv[1], lv[i]);
    {
      int nan_d = uv[0] != uv[0], nan_l = lu[i] != lu[i];
      int nan_dv = uv[1] != uv[1], nan_lv = lv[i] != lv[i];
      if (nan_d != nan_l || nan_dv != nan_lv) {
        CHECK(0, "%s: invert(%.9g, %.9g, %.9g) = (%.9g, %.9g), library (%.9g, %.9g)", name, dir[0],
              dir[1], dir[2], uv[0], uv[1], lu[i], lv[i]);
      } else {
        st->inv_nan_agree += 1;
        if (!nan_d && !nan_dv && lp[i] > 0.0f) {
          double e = fabs((double)uv[0] - lu[i]), e2 = fabs((double)uv[1] - lv[i]);
          if (e2 > e) e = e2;
          CHECK(e <= 1e-5, "%s: invert(%.9g, %.9g, %.9g) = (%.9g, %.9g), library (%.9g, %.9g)",
                name, dir[0], dir[1], dir[2], uv[0], uv[1], lu[i], lv[i]);
          if (e > st->max_inv_err) st->max_inv_err = e;
        }
      }
    }
    /* Round trip of the Halton samples' directions (information: the float32 map's contract;
     * the square's edges are left out, where several points share a direction). */
    if (i >= n - n_halton && i < n && lp[i] > 0.0f && uv[0] == uv[0]) {
      double e = fabs((double)uv[0] - u[i]), e2 = fabs((double)uv[1] - v[i]);
      if (e2 > e) e = e2;
      if (e > st->max_round_trip) st->max_round_trip = e;
    }
  }
  st->dev_seconds += now() - t0;
  st->dev_calls += 2.0 * (double)nd;
  /* The grid target, on every 8th direction. */
  if (target) {
    double mx = 0.0;
    CHECK(gonio_diagram_max_intensity(target, &mx) == GONIO_OK, "max intensity");
    for (i = 0; i < nd; i += 8) {
      float raw[3], dir[3], t;
      double want = 0.0, rel;
      raw[0] = dx[i]; raw[1] = dy[i]; raw[2] = dz[i];
      lib_normalize(raw, dir);
      t = gonio_device_target(view, dir);
      CHECK(gonio_diagram_intensity(target, dir[0], dir[1], dir[2], &want) == GONIO_OK,
            "intensity: %s", gonio_last_error_message());
      rel = fabs((double)t - want) / mx;
      CHECK(rel <= 1e-6, "%s: target(%.9g, %.9g, %.9g) = %.9g, library %.17g", name, dir[0],
            dir[1], dir[2], t, want);
      if (rel > max_target) max_target = rel;
      st->target_points += 1;
    }
    if (max_target > st->max_target_rel) st->max_target_rel = max_target;
  } else {
    float dir[3] = {0.0f, 0.0f, 1.0f};
    CHECK(gonio_device_target(view, dir) == 0.0f, "%s: target without a grid", name);
  }
  st->cases++;
  st->points += (double)n;
  st->dirs += (double)nd;
  free(u);
  free(dx);
}

/* One sampler case: blob, view, rebase, comparison. */
static void sampler_case(const char *name, const GonioDiagram *diag, GonioDomain domain,
                         GonioSphereLayout layout, size_t n, Stats *st) {
  GonioBuildOptions o;
  GonioSampler *s = NULL;
  unsigned char *blob, *copy;
  size_t size = 0;
  GonioDeviceView view, view2;
  Lib lib;
  int e;
  gonio_build_options_default(&o);
  o.sphere_layout = layout;
  if (gonio_sampler_build_with(diag, GONIO_METHOD_HDS, domain, &o, &s) != GONIO_OK) {
    CHECK(0, "%s: build: %s", name, gonio_last_error_message());
    return;
  }
  blob = sampler_blob(s, diag, 4, &size);
  CHECK(blob != NULL, "%s: tables: %s", name, gonio_last_error_message());
  if (!blob) {
    gonio_sampler_free(s);
    return;
  }
  e = gonio_device_view_init(&view, blob, size);
  CHECK(e == GONIO_DEVICE_OK, "%s: view_init: %d", name, e);
  if (e == GONIO_DEVICE_OK) {
    GonioDomain dom;
    gonio_sampler_domain(s, &dom);
    CHECK(dom != GONIO_DOMAIN_HEMISPHERE || view.layout == GONIO_DEVICE_LAYOUT_HEMISPHERE,
          "%s: layout %u", name, view.layout);
    CHECK(view.target == GONIO_DEVICE_TARGET_GRID, "%s: no grid target", name);
    /* Rebase onto a copy (as onto a device buffer) and run from there. */
    copy = (unsigned char *)malloc(size);
    memcpy(copy, blob, size);
    view2 = view;
    gonio_device_view_rebase(&view2, copy);
    {
      int slot = (view.maps_present & 1u) ? 0 : 1;
      CHECK(view2.map[slot].x == (const float *)(const void *)(copy + view.map[slot].offset[5]) &&
                view2.target_values ==
                    (const double *)(const void *)(copy + view.target_offset[2]),
            "%s: rebase", name);
    }
    memset(blob, 0xff, size); /* the first copy is no longer read */
    lib.sampler = s;
    lib.env = NULL;
    compare(name, &lib, &view2, diag, n, st);
    free(copy);
  }
  free(blob);
  gonio_sampler_free(s);
}

static GonioDiagram *read_json(const char *json, const char *name) {
  GonioDiagram *d = NULL;
  if (gonio_diagram_read_memory((const uint8_t *)json, strlen(json), GONIO_FORMAT_JSON, name, &d) !=
      GONIO_OK) {
    CHECK(0, "%s: %s", name, gonio_last_error_message());
    return NULL;
  }
  return d;
}

/* The built-in example luminaire (gonio::synthetic::example_luminaire: 5° × 15° grid, a beam
 * 60° off nadir toward +x, a down-light, a weak up-light), written as a JSON diagram. */
static char *example_json(void) {
  size_t cap = 64 * 1024, len = 0;
  char *s = (char *)malloc(cap);
  int i, j;
  double ax = sin(60.0 * PI_D / 180.0), az = -cos(60.0 * PI_D / 180.0);
  len += (size_t)sprintf(s + len, "{\"theta_deg\": [");
  for (j = 0; j <= 36; j++) len += (size_t)sprintf(s + len, "%s%d", j ? ", " : "", 5 * j);
  len += (size_t)sprintf(s + len, "], \"phi_deg\": [");
  for (i = 0; i < 24; i++) len += (size_t)sprintf(s + len, "%s%d", i ? ", " : "", 15 * i);
  len += (size_t)sprintf(s + len, "], \"values\": [");
  for (i = 0; i < 24; i++) {
    len += (size_t)sprintf(s + len, "%s[", i ? ", " : "");
    for (j = 0; j <= 36; j++) {
      double t = 5.0 * j * PI_D / 180.0, p = 15.0 * i * PI_D / 180.0;
      double dx = sin(t) * cos(p), dz = cos(t);
      double b = dx * ax + dz * az, beam, down, up;
      b = b > 0.0 ? b : 0.0;
      beam = pow(b, 12.0);
      down = -dz > 0.0 ? dz * dz : 0.0;
      up = 0.05 * (dz > 0.0 ? dz : 0.0);
      len += (size_t)sprintf(s + len, "%s%.17g", j ? ", " : "",
                             floor(1200.0 * beam + 400.0 * down + 300.0 * up + 0.5));
    }
    len += (size_t)sprintf(s + len, "]");
  }
  sprintf(s + len, "]}");
  return s;
}

/* A random JSON diagram: N parallels in [θ_lo, θ_hi] (endpoints included or not), M meridians
 * (uniform or not, φ_0 = 0 or not), values random, with dark rows and dark caps. */
static char *random_json(int hemisphere) {
  size_t cap = 1 << 20, len = 0;
  char *s = (char *)malloc(cap);
  int n = 2 + (int)(rnd() * 30), m = 1 + (int)(rnd() * 24), i, j;
  double top = hemisphere ? 90.0 : 180.0;
  double th[40], ph[40];
  int uniform = rnd() < 0.5, style = (int)(rnd() * 3), any = 0;
  double lo = rnd() < 0.6 ? 0.0 : rnd() * top * 0.3;
  double hi = rnd() < 0.6 ? top : top - rnd() * top * 0.3;
  for (j = 0; j < n; j++) th[j] = lo + (hi - lo) * (double)j / (double)(n - 1);
  if (rnd() < 0.5)
    for (j = 1; j < n - 1; j++) th[j] += (rnd() - 0.5) * 0.8 * (hi - lo) / (double)(n - 1);
  for (i = 0; i < m; i++) ph[i] = 360.0 * (double)i / (double)m;
  if (!uniform && m > 1)
    for (i = 0; i < m; i++) ph[i] += (rnd() - 0.2) * 0.5 * 360.0 / (double)m;
  if (ph[0] < 0.0) ph[0] = 0.0;
  len += (size_t)sprintf(s + len, "{\"theta_deg\": [");
  for (j = 0; j < n; j++) len += (size_t)sprintf(s + len, "%s%.17g", j ? ", " : "", th[j]);
  len += (size_t)sprintf(s + len, "], \"phi_deg\": [");
  for (i = 0; i < m; i++) len += (size_t)sprintf(s + len, "%s%.17g", i ? ", " : "", ph[i]);
  len += (size_t)sprintf(s + len, "], \"values\": [");
  for (i = 0; i < m; i++) {
    int dark_row = m > 2 && rnd() < 0.15;
    len += (size_t)sprintf(s + len, "%s[", i ? ", " : "");
    for (j = 0; j < n; j++) {
      double val;
      if (style == 0) val = 1000.0 * rnd();
      else if (style == 1) val = (j < n / 3) ? 0.0 : 500.0 * rnd() * rnd();
      else val = rnd() < 0.3 ? 0.0 : pow(rnd(), 4.0) * 1e4;
      if (dark_row) val = 0.0;
      if (val > 0.0) any = 1;
      if (i == m - 1 && j == n - 1 && !any) val = 1.0;
      len += (size_t)sprintf(s + len, "%s%.17g", j ? ", " : "", val);
    }
    len += (size_t)sprintf(s + len, "]");
  }
  sprintf(s + len, "]}");
  return s;
}

static int ends_with(const char *s, const char *suffix) {
  size_t a = strlen(s), b = strlen(suffix);
  return a >= b && strcmp(s + a - b, suffix) == 0;
}
static const char *base_name(const char *p) {
  const char *b = strrchr(p, '/');
  return b ? b + 1 : p;
}

static void envmap_case(const char *path, size_t n, Stats *st) {
  GonioEnvMap *m = NULL;
  GonioEnvMapF32 *f = NULL;
  unsigned char *blob;
  size_t size = 0;
  GonioDeviceView view;
  Lib lib;
  int e;
  if (gonio_envmap_read_path(path, &m) != GONIO_OK) {
    CHECK(0, "%s: %s", path, gonio_last_error_message());
    return;
  }
  CHECK(gonio_envmap_tables(m, 4, NULL, 0, &size) == GONIO_OK, "%s: %s", path,
        gonio_last_error_message());
  blob = (unsigned char *)malloc(size);
  CHECK(gonio_envmap_tables(m, 4, (uint8_t *)blob, size, &size) == GONIO_OK, "%s: %s", path,
        gonio_last_error_message());
  if (gonio_envmap_into_float32(m, &f) != GONIO_OK) { /* consumes m */
    CHECK(0, "%s: into_float32: %s", path, gonio_last_error_message());
    free(blob);
    return;
  }
  e = gonio_device_view_init(&view, blob, size);
  CHECK(e == GONIO_DEVICE_OK, "%s: view_init %d", path, e);
  CHECK(view.frame == 2u && view.target == GONIO_DEVICE_TARGET_IMAGE && view.target_rgb != NULL,
        "%s: frame %u target %u", path, view.frame, view.target);
  if (e == GONIO_DEVICE_OK) {
    lib.sampler = NULL;
    lib.env = f;
    compare(base_name(path), &lib, &view, NULL, n, st);
  }
  gonio_envmap_f32_free(f);
  free(blob);
}

/* ------------------------------------------------------------------------------------------ */
/* Refusals. */

static void put64(unsigned char *b, size_t at, uint64_t v) {
  int k;
  for (k = 0; k < 8; k++) b[at + k] = (unsigned char)(v >> (8 * k));
}
static void put32(unsigned char *b, size_t at, uint32_t v) {
  int k;
  for (k = 0; k < 4; k++) b[at + k] = (unsigned char)(v >> (8 * k));
}
static uint64_t get64(const unsigned char *b, size_t at) {
  uint64_t v = 0;
  int k;
  for (k = 7; k >= 0; k--) v = (v << 8) | b[at + k];
  return v;
}
static uint32_t get32(const unsigned char *b, size_t at) {
  return (uint32_t)b[at] | ((uint32_t)b[at + 1] << 8) | ((uint32_t)b[at + 2] << 16) |
         ((uint32_t)b[at + 3] << 24);
}
static void reseal(unsigned char *b, size_t size) {
  put64(b, 24, gonio_device_checksum(b, size));
}
/* view_init on an exact-size heap copy of the first `len` bytes (valgrind sees any overread). */
static int init_copy(const unsigned char *b, size_t len, GonioDeviceView *v) {
  unsigned char *c = (unsigned char *)malloc(len ? len : 1);
  int e;
  memcpy(c, b, len);
  e = gonio_device_view_init(v, c, len);
  if (e == GONIO_DEVICE_OK) { /* a few calls must stay in bounds */
    float dir[3] = {0.3f, -0.4f, 0.866f}, uv[2], p, out[3];
    int i;
    for (i = 0; i < 64; i++) {
      double len;
      gonio_device_sample(v, (float)(i % 8) / 7.0f, (float)(i / 8) / 7.0f, out, &p);
      len = sqrt((double)out[0] * out[0] + (double)out[1] * out[1] + (double)out[2] * out[2]);
      /* What the library's reader promises of a blob it accepts: unit directions, finite pdfs. */
      CHECK(fabs(len - 1.0) < 1e-5 && p >= 0.0f && p <= FLT_MAX,
            "accepted blob: sample %d gives |dir| = %g, pdf %g", i, len, p);
      p = gonio_device_pdf(v, out);
      CHECK(p >= 0.0f && p <= FLT_MAX, "accepted blob: pdf %g", p);
      (void)gonio_device_invert(v, out, uv);
    }
    (void)gonio_device_invert(v, dir, uv);
    (void)gonio_device_target(v, dir);
  }
  free(c);
  return e;
}

static int view_is_zero(const GonioDeviceView *v) {
  const unsigned char *p = (const unsigned char *)v;
  size_t i;
  for (i = 0; i < sizeof *v; i++)
    if (p[i]) return 0;
  return 1;
}

static void refusals(const GonioDiagram *diag) {
  GonioSampler *s = NULL;
  unsigned char *blob, *b64, *w;
  size_t size = 0, size64 = 0, len, at;
  GonioDeviceView v;
  int e, accepted = 0, checked = 0;
  uint32_t m0;
  CHECK(gonio_sampler_build(diag, GONIO_METHOD_HDS, GONIO_DOMAIN_SPHERE, &s) == GONIO_OK, "build");
  blob = sampler_blob(s, diag, 4, &size);
  b64 = sampler_blob(s, NULL, 8, &size64);
  CHECK(blob && b64, "tables: %s", gonio_last_error_message());
  if (!blob || !b64) return;
  w = (unsigned char *)malloc(size + 64);
  CHECK(init_copy(blob, size, &v) == GONIO_DEVICE_OK, "the blob itself");
  /* NULL arguments. */
  CHECK(gonio_device_view_init(NULL, blob, size) == GONIO_DEVICE_E_NULL, "NULL view");
  CHECK(gonio_device_view_init(&v, NULL, size) == GONIO_DEVICE_E_NULL, "NULL tables");
  CHECK(gonio_device_view_init(&v, NULL, 0) == GONIO_DEVICE_E_TRUNCATED, "NULL, 0 bytes");
  /* Every length short of the blob (all below 2048, then every 61st): truncated. */
  for (len = 0; len < size; len += (len < 2048 ? 1 : 61)) {
    e = init_copy(blob, len, &v);
    CHECK(e == GONIO_DEVICE_E_TRUNCATED, "truncated to %zu bytes: %d", len, e);
    CHECK(view_is_zero(&v), "view not zeroed after a failure");
    checked++;
  }
  e = init_copy(blob, size - 1, &v);
  CHECK(e == GONIO_DEVICE_E_TRUNCATED, "truncated by one byte: %d", e);
  /* More bytes than the header states. */
  memcpy(w, blob, size);
  memset(w + size, 0, 64);
  e = init_copy(w, size + 64, &v);
  CHECK(e == GONIO_DEVICE_E_HEADER, "64 bytes too many: %d", e);
  /* Each header byte flipped (all bits, then the lowest), checksum left stale. */
  for (at = 0; at < 256; at++) {
    int f;
    for (f = 0; f < 2; f++) {
      int want;
      memcpy(w, blob, size);
      w[at] ^= f ? 0x01 : 0xff;
      if (at < 8) want = GONIO_DEVICE_E_MAGIC;
      else if (at < 12) want = GONIO_DEVICE_E_VERSION;
      else if (at < 16) want = GONIO_DEVICE_E_HEADER;
      else if (at < 24) want = get64(w, 16) > size ? GONIO_DEVICE_E_TRUNCATED : GONIO_DEVICE_E_HEADER;
      else want = GONIO_DEVICE_E_CHECKSUM;
      e = init_copy(w, size, &v);
      CHECK(e == want, "header byte %zu flipped (^%s): %d, expected %d", at, f ? "0x01" : "0xff", e,
            want);
      checked++;
    }
  }
  /* Each header byte flipped with the checksum made valid again: refused or harmless (run). */
  for (at = 32; at < 256; at++) {
    memcpy(w, blob, size);
    w[at] ^= 0xff;
    reseal(w, size);
    e = init_copy(w, size, &v);
    CHECK(e != GONIO_DEVICE_E_CHECKSUM, "resealed byte %zu: checksum", at);
    if (e == GONIO_DEVICE_OK) accepted++;
    checked++;
  }
  /* A changed table byte: checksum. */
  memcpy(w, blob, size);
  w[size - 100] ^= 0x5a;
  CHECK(init_copy(w, size, &v) == GONIO_DEVICE_E_CHECKSUM, "table byte changed");
  /* An f64 blob. */
  e = init_copy(b64, size64, &v);
  CHECK(e == GONIO_DEVICE_E_F64, "f64 blob: %d", e);
  /* Fields and tables changed, checksum valid. */
  m0 = get32(blob, 96);
#define MUTATE(what, want, stmt)                                          \
  do {                                                                    \
    memcpy(w, blob, size);                                                \
    stmt;                                                                 \
    reseal(w, size);                                                      \
    e = init_copy(w, size, &v);                                           \
    CHECK(e == (want), "%s: %d, expected %d", what, e, (int)(want));      \
    checked++;                                                            \
  } while (0)
  MUTATE("precision 5", GONIO_DEVICE_E_PRECISION, put32(w, 32, 5));
  MUTATE("layout 3", GONIO_DEVICE_E_HEADER, put32(w, 36, 3));
  MUTATE("frame 3", GONIO_DEVICE_E_HEADER, put32(w, 40, 3));
  MUTATE("reserved 52", GONIO_DEVICE_E_HEADER, put32(w, 52, 1));
  MUTATE("table_count + 1", GONIO_DEVICE_E_DIRECTORY, put32(w, 48, get32(w, 48) + 1));
  MUTATE("entry 0 id", GONIO_DEVICE_E_DIRECTORY, put32(w, 256, 7));
  MUTATE("entry 0 elem", GONIO_DEVICE_E_DIRECTORY, put32(w, 260, 2));
  MUTATE("entry 0 offset + 4", GONIO_DEVICE_E_DIRECTORY, put64(w, 264, get64(w, 264) + 4));
  MUTATE("entry 1 offset = entry 0", GONIO_DEVICE_E_DIRECTORY, put64(w, 296, get64(w, 264)));
  MUTATE("entry 0 count", GONIO_DEVICE_E_DIRECTORY, put64(w, 272, get64(w, 272) + 1));
  MUTATE("last entry beyond the end", GONIO_DEVICE_E_DIRECTORY,
         put64(w, 256 + 32 * (get32(w, 48) - 1) + 8, size));
  MUTATE("m = 2^22", GONIO_DEVICE_E_HEADER, put32(w, 96, 1u << 22));
  MUTATE("n = 1", GONIO_DEVICE_E_HEADER, put32(w, 100, 1));
  MUTATE("kappa 0", GONIO_DEVICE_E_HEADER, put64(w, 96 + 40, 0));
  MUTATE("inv_2t not f32", GONIO_DEVICE_E_HEADER, w[72] ^= 1);
  MUTATE("phi[1] NaN", GONIO_DEVICE_E_CONTENT, put32(w, (size_t)get64(w, 256 + 8) + 4, 0x7fc00000u));
  MUTATE("phi decreasing", GONIO_DEVICE_E_CONTENT,
         put32(w, (size_t)get64(w, 256 + 8) + 4 * m0, 0));
  MUTATE("phi[M] > 2pi", GONIO_DEVICE_E_CONTENT,
         put32(w, (size_t)get64(w, 256 + 8) + 4 * m0, 0x40c90ff0u));
  MUTATE("x[N-1] > 1", GONIO_DEVICE_E_CONTENT,
         put32(w, (size_t)get64(w, 256 + 5 * 32 + 8) + 4 * (get32(w, 100) - 1), 0x3f800100u));
  MUTATE("d[0] * inv_2t overflows", GONIO_DEVICE_E_CONTENT,
         (put64(w, 72, 0x4000000000000000ull), /* inv_2t = 2 */
          put32(w, (size_t)get64(w, 256 + 6 * 32 + 8), 0x7f000000u)));
  MUTATE("beta[0] < 0", GONIO_DEVICE_E_CONTENT, put32(w, (size_t)get64(w, 256 + 32 + 8), 0xbf800000u));
  MUTATE("wedge_guide[0] = M", GONIO_DEVICE_E_CONTENT, put32(w, (size_t)get64(w, 256 + 4 * 32 + 8), m0));
  MUTATE("total[0] changed", GONIO_DEVICE_E_CONTENT,
         put32(w, (size_t)get64(w, 256 + 8 * 32 + 8), get32(w, (size_t)get64(w, 256 + 8 * 32 + 8)) + 1));
  MUTATE("radial_guide[0] huge", GONIO_DEVICE_E_CONTENT,
         put32(w, (size_t)get64(w, 256 + 11 * 32 + 8), 0xffffffffu));
#undef MUTATE
  /* Misaligned by 4 bytes. */
  {
    unsigned char *mis = (unsigned char *)malloc(size + 8);
    memcpy(mis + 4, blob, size);
    e = gonio_device_view_init(&v, mis + 4, size);
    CHECK(e == GONIO_DEVICE_E_ALIGNMENT, "misaligned: %d", e);
    free(mis);
  }
  printf("device_test: refusals: %d broken blobs refused with the expected codes (truncations, "
         "header bytes flipped, fields, tables, checksum, f64, alignment); %d of 224 resealed "
         "header-byte flips accepted (values still valid) and run in bounds\n",
         checked, accepted);
  free(w);
  free(blob);
  free(b64);
  gonio_sampler_free(s);
}

/* ------------------------------------------------------------------------------------------ */


/* ---------------------------------------------------------------------------------------------
 * BRDF families (gonio_device_brdf_*): against the library's f64 BrdfSampler through the C ABI.
 * ------------------------------------------------------------------------------------------- */

/* A gonio BRDF JSON table: GGX (α_x, α_y; separable Smith masking, F = (0.9, 0.6, 0.3)), or
 * Lambert when ax <= 0; nt polar nodes 0…90°, np azimuths (incident ones too when anisotropic). */
static char *brdf_json(double ax, double ay, int nt, int np, int aniso) {
  size_t cap = (size_t)3 * nt * nt * np * (aniso ? np : 1) * 26 + 4096, len = 0;
  char *s = (char *)malloc(cap);
  int c, a, q, b, p, npi = aniso ? np : 1;
  const double F[3] = {0.9, 0.6, 0.3};
  len += (size_t)sprintf(s + len, "{\"format\": \"gonio-brdf\", \"version\": 1, \"symmetry\": \"%s\", "
                         "\"channels\": 3, \"theta_i_deg\": [", aniso ? "anisotropic" : "isotropic");
  for (a = 0; a < nt; a++) len += (size_t)sprintf(s + len, "%s%.17g", a ? ", " : "", 90.0 * a / (nt - 1));
  len += (size_t)sprintf(s + len, "], \"phi_i_deg\": [");
  for (q = 0; q < npi; q++) len += (size_t)sprintf(s + len, "%s%.17g", q ? ", " : "", 360.0 * q / np);
  len += (size_t)sprintf(s + len, "], \"theta_o_deg\": [");
  for (a = 0; a < nt; a++) len += (size_t)sprintf(s + len, "%s%.17g", a ? ", " : "", 90.0 * a / (nt - 1));
  len += (size_t)sprintf(s + len, "], \"phi_o_deg\": [");
  for (p = 0; p < np; p++) len += (size_t)sprintf(s + len, "%s%.17g", p ? ", " : "", 360.0 * p / np);
  len += (size_t)sprintf(s + len, "], \"values\": [");
  for (c = 0; c < 3; c++)
    for (a = 0; a < nt; a++)
      for (q = 0; q < npi; q++)
        for (b = 0; b < nt; b++)
          for (p = 0; p < np; p++) {
            double ti = 0.5 * PI_D * a / (nt - 1), pi = 2.0 * PI_D * q / np;
            double to = 0.5 * PI_D * b / (nt - 1), po = 2.0 * PI_D * p / np + (aniso ? 0.0 : pi);
            double wi[3] = {sin(ti) * cos(pi), sin(ti) * sin(pi), cos(ti)};
            double wo[3] = {sin(to) * cos(po), sin(to) * sin(po), cos(to)};
            double f;
            if (ax <= 0.0) {
              f = (c == 0 ? 0.8 : c == 1 ? 0.5 : 0.2) / PI_D;
            } else {
              double h[3] = {wi[0] + wo[0], wi[1] + wo[1], wi[2] + wo[2]};
              double hl = sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
              double ci = wi[2] > 1e-4 ? wi[2] : 1e-4, co = wo[2] > 1e-4 ? wo[2] : 1e-4, t, d, li, lo;
              h[0] /= hl; h[1] /= hl; h[2] /= hl;
              t = (h[0] / ax) * (h[0] / ax) + (h[1] / ay) * (h[1] / ay) + h[2] * h[2];
              d = 1.0 / (PI_D * ax * ay * t * t);
              li = 0.5 * (-1.0 + sqrt(1.0 + ((wi[0] * ax) * (wi[0] * ax) + (wi[1] * ay) * (wi[1] * ay)) / (ci * ci)));
              lo = 0.5 * (-1.0 + sqrt(1.0 + ((wo[0] * ax) * (wo[0] * ax) + (wo[1] * ay) * (wo[1] * ay)) / (co * co)));
              f = F[c] * d / (1.0 + li) / (1.0 + lo) / (4.0 * ci * co);
            }
            len += (size_t)sprintf(s + len, "%s%.17g", (c | a | q | b | p) ? ", " : "", f);
          }
  sprintf(s + len, "]}");
  return s;
}

/* The float32 family blob of a table's "hds" sampler (malloc'd), its size in *size. */
static unsigned char *brdf_blob(const char *json, const char *name, GonioBrdf **brdf_out,
                                GonioBrdfSampler **s_out, size_t *size) {
  GonioBrdf *brdf = NULL;
  GonioBrdfSampler *s = NULL;
  unsigned char *blob;
  if (gonio_brdf_read_memory((const uint8_t *)json, strlen(json), name, NULL, &brdf) != GONIO_OK ||
      gonio_brdf_sampler_build(brdf, GONIO_BRDF_METHOD_HDS, NULL, &s) != GONIO_OK ||
      gonio_brdf_sampler_tables(s, 4, NULL, 0, size) != GONIO_OK) {
    CHECK(0, "%s: %s", name, gonio_last_error_message());
    gonio_brdf_sampler_free(s);
    gonio_brdf_free(brdf);
    return NULL;
  }
  blob = (unsigned char *)malloc(*size);
  CHECK(gonio_brdf_sampler_tables(s, 4, blob, *size, size) == GONIO_OK, "%s: tables", name);
  *brdf_out = brdf;
  *s_out = s;
  return blob;
}

static void brdf_case(const char *name, double ax, double ay, int nt, int np, int aniso, size_t points) {
  char *json = brdf_json(ax, ay, nt, np, aniso);
  GonioBrdf *brdf = NULL;
  GonioBrdfSampler *s = NULL;
  GonioDeviceBrdf bf;
  size_t size = 0, k, total = 0, pdf_over = 0;
  unsigned char *blob = brdf_blob(json, name, &brdf, &s, &size);
  double worst_dir = 0.0, worst_uv = 0.0, worst_f = 0.0, worst_pdf = 0.0;
  const double inc[6][2] = {{0, 0}, {23, 31}, {47, 200}, {76, 95}, {88, 10}, {37, 333}};
  int e, w;
  free(json);
  if (!blob) return;
  e = gonio_device_brdf_init(&bf, blob, size);
  CHECK(e == GONIO_DEVICE_OK, "%s: gonio_device_brdf_init = %d", name, e);
  if (e != GONIO_DEVICE_OK) goto done;
  for (w = 0; w < 6; w++) {
    double ti = inc[w][0] * PI_D / 180.0, pi = inc[w][1] * PI_D / 180.0;
    double wid[3] = {sin(ti) * cos(pi), sin(ti) * sin(pi), cos(ti)};
    float wif[3] = {(float)wid[0], (float)wid[1], (float)wid[2]};
    for (k = 0; k < points; k++) {
      double u = k < 5 ? (double)(k & 1) : radical_inverse((uint32_t)k, 2);
      double v = k < 5 ? (double)((k >> 1) & 1) : radical_inverse((uint32_t)k, 3);
      GonioBrdfSample ls;
      float wo[3], pdf, pp, f[3];
      double wod[3], back_u = NAN, back_v = NAN, lp = 0.0, lf[3], d = 0.0, fm = 0.0, df = 0.0;
      int c, ok;
      if (k == 4) u = v = 0.5;
      gonio_brdf_sample(s, wid, u, v, &ls);
      ok = gonio_device_brdf_sample(&bf, wif, (float)u, (float)v, wo, &pdf);
      CHECK(ok == 1, "%s: sample at (%g, %g) fell back", name, u, v);
      for (c = 0; c < 3; c++) wod[c] = wo[c];
      if (ls.pdf >= 0.01)
        for (c = 0; c < 3; c++) d = fmax(d, fabs(wod[c] - ls.direction[c]));
      worst_dir = fmax(worst_dir, d);
      CHECK(d <= 1e-4, "%s wi (%g, %g) u (%g, %g): direction off by %g", name, inc[w][0], inc[w][1], u, v, d);
      if (gonio_brdf_invert(s, wid, wod, &back_u, &back_v) == GONIO_OK) {
        double duv = fmax(fabs(back_u - u), fabs(back_v - v));
        worst_uv = fmax(worst_uv, duv);
        CHECK(duv <= 1e-5, "%s wi (%g, %g) u (%g, %g): the library inverts ω_o to (%g, %g)", name,
              inc[w][0], inc[w][1], u, v, back_u, back_v);
      } else {
        CHECK(0, "%s: gonio_brdf_invert: %s", name, gonio_last_error_message());
      }
      /* pdf: the device's sample pdf against the library's pdf at ω_o and the device's pdf(). */
      gonio_brdf_pdf(s, wid, wod, &lp);
      pp = gonio_device_brdf_pdf(&bf, wif, wo);
      {
        double r1 = fabs(pdf - lp) / fmax(lp, 1e-2), r2 = fabs(pp - pdf) / fmax(pdf, 1e-2);
        worst_pdf = fmax(worst_pdf, fmax(r1, r2));
        if (r1 > 1e-3 || r2 > 1e-3) pdf_over++;
      }
      total++;
      /* f_r at the library's direction. */
      gonio_brdf_eval(brdf, wid, ls.direction, lf);
      {
        float lwo[3] = {(float)ls.direction[0], (float)ls.direction[1], (float)ls.direction[2]};
        gonio_device_brdf_eval(&bf, wif, lwo, f);
      }
      for (c = 0; c < 3; c++) {
        fm = fmax(fm, lf[c]);
        df = fmax(df, fabs(f[c] - lf[c]));
      }
      if (fm > 0.0) worst_f = fmax(worst_f, df / fm);
      CHECK(df <= 2e-4 * fm + 1e-30, "%s: f_r off by %g of %g", name, df, fm);
    }
  }
  /* Below the horizon and from below: the documented fallbacks. */
  {
    float below[3] = {0.6f, 0.0f, -0.8f}, up[3] = {0.0f, 0.0f, 1.0f}, wo[3], pdf, f[3];
    CHECK(gonio_device_brdf_pdf(&bf, up, below) == 0.0f, "%s: pdf below the horizon", name);
    CHECK(gonio_device_brdf_sample(&bf, below, 0.3f, 0.6f, wo, &pdf) == 0 && wo[2] >= 0.0f &&
              fabsf(pdf - wo[2] / (float)PI_D) <= 1e-6f,
          "%s: sample from below", name);
    gonio_device_brdf_eval(&bf, below, up, f);
    CHECK(f[0] == 0.0f && f[1] == 0.0f && f[2] == 0.0f, "%s: eval from below", name);
  }
  /* 99.9 % of the pdfs within 1e-3 (relative, floor 0.01/sr): the rest lie where the density is
   * steep (float32's position round-off moves it). */
  CHECK(pdf_over * 1000 <= total, "%s: %zu of %zu pdfs beyond 1e-3", name, pdf_over, total);
  printf("device_test: brdf %-22s %7zu samples: ω_o ≤ %.1e (pdf ≥ 0.01), library's inverse ≤ %.1e, "
         "pdf ≤ %.1e (%zu beyond 1e-3), f_r ≤ %.1e\n",
         name, total, worst_dir, worst_uv, worst_pdf, pdf_over, worst_f);
done:
  free(blob);
  gonio_brdf_sampler_free(s);
  gonio_brdf_free(brdf);
}

/* A family blob refused: every truncation, each header and directory byte flipped (checksum
 * resealed), a table byte changed (checksum), an f64 family, a single-map blob. */
static void brdf_refusals(void) {
  char *json = brdf_json(0.4, 0.2, 4, 6, 1);
  GonioBrdf *brdf = NULL;
  GonioBrdfSampler *s = NULL;
  GonioDeviceBrdf bf;
  size_t size = 0, len, at, refused = 0, tried = 0;
  unsigned char *blob = brdf_blob(json, "refusals", &brdf, &s, &size), *w;
  free(json);
  if (!blob) return;
  CHECK(gonio_device_brdf_init(&bf, blob, size) == GONIO_DEVICE_OK, "a valid family");
  w = (unsigned char *)malloc(size);
  for (len = 0; len < size; len++) {
    memcpy(w, blob, len);
    CHECK(gonio_device_brdf_init(&bf, w, len) != GONIO_DEVICE_OK, "family truncated to %zu", len);
  }
  for (at = 0; at < 256 + 32 * 18; at++) {
    int flip;
    for (flip = 0; flip < 3; flip++) {
      memcpy(w, blob, size);
      w[at] ^= flip == 0 ? 0x01 : flip == 1 ? 0x80 : 0xff;
      reseal(w, size);
      tried++;
      if (gonio_device_brdf_init(&bf, w, size) != GONIO_DEVICE_OK) {
        refused++;
      } else {
        /* Accepted (the flip left valid values): it samples in bounds (valgrind watches). */
        float wi[3] = {0.3f, 0.1f, 0.9486833f}, wo[3], pdf, f[3];
        gonio_device_brdf_sample(&bf, wi, 0.3f, 0.7f, wo, &pdf);
        (void)gonio_device_brdf_pdf(&bf, wi, wo);
        gonio_device_brdf_eval(&bf, wi, wo, f);
      }
    }
  }
  CHECK(refused * 10 > tried * 9, "only %zu of %zu header/directory flips refused", refused, tried);
  memcpy(w, blob, size);
  w[size - 64] ^= 0x10;
  CHECK(gonio_device_brdf_init(&bf, w, size) == GONIO_DEVICE_E_CHECKSUM, "a table byte changed");
  /* Table bytes flipped and resealed: refused or accepted, never a read outside (valgrind). */
  for (at = 256 + 32 * 18; at < size; at += 5) {
    memcpy(w, blob, size);
    w[at] ^= 0xff;
    reseal(w, size);
    (void)gonio_device_brdf_init(&bf, w, size);
  }
  {
    size_t s64 = 0;
    unsigned char *b64;
    gonio_brdf_sampler_tables(s, 8, NULL, 0, &s64);
    b64 = (unsigned char *)malloc(s64);
    gonio_brdf_sampler_tables(s, 8, b64, s64, &s64);
    CHECK(gonio_device_brdf_init(&bf, b64, s64) == GONIO_DEVICE_E_F64, "an f64 family");
    free(b64);
  }
  CHECK(gonio_device_brdf_init(&bf, NULL, 0) == GONIO_DEVICE_E_NULL, "NULL");
  printf("device_test: brdf refusals: %zu of %zu header/directory flips refused, every truncation\n",
         refused, tried);
  free(w);
  free(blob);
  gonio_brdf_sampler_free(s);
  gonio_brdf_free(brdf);
}

int main(int argc, char **argv) {
  size_t n = 1000000, n_env = 65536, n_file = 0;
  int n_random = 12, refusals_only = 0, a, i;
  Stats st_example = stats("example"), st_ies = stats("ies"), st_ldt = stats("ldt"),
        st_json = stats("json-file"), st_random = stats("random-json"),
        st_lambert = stats("lambert"), st_hemi = stats("hemisphere"), st_env = stats("envmap");
  GonioDiagram *example;
  char *json;
  double t0 = (double)time(NULL);
  for (a = 1; a < argc && argv[a][0] == '-'; a++) {
    if (strcmp(argv[a], "-n") == 0 && a + 1 < argc) n = (size_t)atol(argv[++a]);
    else if (strcmp(argv[a], "-e") == 0 && a + 1 < argc) n_env = (size_t)atol(argv[++a]);
    else if (strcmp(argv[a], "-f") == 0 && a + 1 < argc) n_file = (size_t)atol(argv[++a]);
    else if (strcmp(argv[a], "-r") == 0 && a + 1 < argc) n_random = atoi(argv[++a]);
    else if (strcmp(argv[a], "--refusals-only") == 0) refusals_only = 1;
    else {
      fprintf(stderr,
              "usage: %s [-n POINTS] [-f FILE_POINTS] [-e ENV_POINTS] [-r RANDOM] "
              "[--refusals-only] FILES...\n",
              argv[0]);
      return 2;
    }
  }
  if (n_file == 0) n_file = n;
  json = example_json();
  example = read_json(json, "example");
  free(json);
  if (!example) return 1;
  refusals(example);
  brdf_refusals();
  if (refusals_only) {
    gonio_diagram_free(example);
    printf("device_test: %s\n", failures ? "FAILED" : "ok");
    return failures ? 1 : 0;
  }
  /* The example: split and Lambert sphere. */
  sampler_case("example (split)", example, GONIO_DOMAIN_SPHERE, GONIO_SPHERE_LAYOUT_SPLIT, n,
               &st_example);
  sampler_case("example (lambert)", example, GONIO_DOMAIN_SPHERE, GONIO_SPHERE_LAYOUT_LAMBERT, n,
               &st_lambert);
  gonio_diagram_free(example);
  /* Files. */
  for (; a < argc; a++) {
    const char *p = argv[a], *b = base_name(p);
    if (strncmp(b, "invalid_", 8) == 0) continue;
    if (ends_with(p, ".hdr") || ends_with(p, ".exr") || ends_with(p, ".pfm")) {
      envmap_case(p, n_env, &st_env);
    } else {
      GonioDiagram *d = NULL;
      Stats *st = ends_with(p, ".ies") || ends_with(p, ".IES") ? &st_ies
                  : ends_with(p, ".json")                      ? &st_json
                                                               : &st_ldt;
      if (gonio_diagram_read_path(p, GONIO_FORMAT_AUTO, &d) != GONIO_OK) {
        printf("device_test: skipped %s (the library refuses it: %s)\n", b,
               gonio_last_error_message());
        continue;
      }
      sampler_case(b, d, GONIO_DOMAIN_AUTO, GONIO_SPHERE_LAYOUT_SPLIT, n_file, st);
      gonio_diagram_free(d);
    }
  }
  /* Random diagrams: sphere (split, then Lambert) and hemisphere. */
  for (i = 0; i < n_random; i++) {
    int hemi = i % 3 == 2;
    char name[64];
    GonioDiagram *d;
    json = random_json(hemi);
    sprintf(name, "random %d%s", i, hemi ? " (hemisphere)" : "");
    d = read_json(json, name);
    free(json);
    if (!d) continue;
    if (hemi) {
      sampler_case(name, d, GONIO_DOMAIN_HEMISPHERE, GONIO_SPHERE_LAYOUT_SPLIT, n, &st_hemi);
      sampler_case(name, d, GONIO_DOMAIN_SPHERE, GONIO_SPHERE_LAYOUT_SPLIT, n, &st_random);
    } else {
      sampler_case(name, d, GONIO_DOMAIN_SPHERE,
                   i % 3 == 1 ? GONIO_SPHERE_LAYOUT_LAMBERT : GONIO_SPHERE_LAYOUT_SPLIT, n,
                   i % 3 == 1 ? &st_lambert : &st_random);
    }
    gonio_diagram_free(d);
  }
  /* BRDF families: isotropic and anisotropic GGX, Lambert. */
  brdf_case("ggx α 0.3", 0.3, 0.3, 10, 24, 0, n / 50);
  brdf_case("ggx α 0.4 × 0.2 (aniso)", 0.4, 0.2, 10, 24, 1, n / 50);
  brdf_case("lambert", 0.0, 0.0, 6, 8, 0, n / 50);
  print_stats(&st_example);
  print_stats(&st_ies);
  print_stats(&st_ldt);
  print_stats(&st_json);
  print_stats(&st_random);
  print_stats(&st_lambert);
  print_stats(&st_hemi);
  print_stats(&st_env);
  printf("device_test: %s (%d failed checks, %.0f s)\n", failures ? "FAILED" : "ok", failures,
         (double)time(NULL) - t0);
  return failures ? 1 : 0;
}
