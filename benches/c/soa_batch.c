/* Cost per point of the C ABI's structure-of-arrays batches on the HDS sphere map of a photometric
 * file: gonio_sample_batch_soa, gonio_pdf_batch_soa, gonio_invert_batch_soa and their _f32 twins,
 * over N points (default 65536) of a regular grid of the square, REP repeats (default 5); prints
 * the best wall time per point. Under callgrind (benches/c/soa_batch.sh) the instruction counts of
 * each call are read with --toggle-collect.
 *
 *   cc -O2 -I crates/gonio-capi/include benches/c/soa_batch.c target/release/libgonio_capi.a \
 *      -lpthread -ldl -lm -o /tmp/soa_batch && /tmp/soa_batch FILE.ies [N] [REP]
 */
#include "gonio.h"
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

static void check(GonioStatus s, const char *what) {
  if (s != GONIO_OK) {
    fprintf(stderr, "%s: %s\n", what, gonio_last_error_message());
    exit(1);
  }
}

int main(int argc, char **argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: %s FILE [N] [REP]\n", argv[0]);
    return 2;
  }
  size_t n = argc > 2 ? (size_t)atol(argv[2]) : 65536;
  int rep = argc > 3 ? atoi(argv[3]) : 5;
  struct GonioDiagram *d = NULL;
  struct GonioSampler *s = NULL;
  check(gonio_diagram_read_path(argv[1], GONIO_FORMAT_AUTO, &d), "read");
  check(gonio_sampler_build(d, GONIO_METHOD_HDS, GONIO_DOMAIN_SPHERE, &s), "build");
  double *u = malloc(n * sizeof *u), *v = malloc(n * sizeof *v);
  double *x = malloc(n * sizeof *x), *y = malloc(n * sizeof *y), *z = malloc(n * sizeof *z);
  double *p = malloc(n * sizeof *p), *iu = malloc(n * sizeof *iu), *iv = malloc(n * sizeof *iv);
  float *u32 = malloc(n * sizeof *u32), *v32 = malloc(n * sizeof *v32);
  float *x32 = malloc(n * sizeof *x32), *y32 = malloc(n * sizeof *y32), *z32 = malloc(n * sizeof *z32);
  float *p32 = malloc(n * sizeof *p32), *iu32 = malloc(n * sizeof *iu32), *iv32 = malloc(n * sizeof *iv32);
  size_t side = 1;
  while (side * side < n) side++;
  for (size_t i = 0; i < n; i++) {
    u[i] = ((double)(i % side) + 0.5) / (double)side;
    v[i] = ((double)(i / side) + 0.5) / (double)side;
    u32[i] = (float)u[i];
    v32[i] = (float)v[i];
  }
  const char *names[6] = {"sample_soa", "pdf_soa", "invert_soa", "sample_soa_f32", "pdf_soa_f32",
                          "invert_soa_f32"};
  double best[6] = {1e30, 1e30, 1e30, 1e30, 1e30, 1e30};
/* Runs CALL, stops on an error, and keeps its best wall time in best[K]. */
#define TIMED(K, CALL)                   \
  do {                                   \
    double t = now();                    \
    check(CALL, names[K]);               \
    t = now() - t;                       \
    if (t < best[K]) best[K] = t;        \
  } while (0)
  for (int r = 0; r < rep; r++) {
    TIMED(0, gonio_sample_batch_soa(s, u, v, n, x, y, z, p));
    TIMED(1, gonio_pdf_batch_soa(s, x, y, z, n, p));
    TIMED(2, gonio_invert_batch_soa(s, x, y, z, n, iu, iv));
    TIMED(3, gonio_sample_batch_soa_f32(s, u32, v32, n, x32, y32, z32, p32));
    TIMED(4, gonio_pdf_batch_soa_f32(s, x32, y32, z32, n, p32));
    TIMED(5, gonio_invert_batch_soa_f32(s, x32, y32, z32, n, iu32, iv32));
  }
  for (int k = 0; k < 6; k++) printf("%-15s %7.2f ns per point\n", names[k], 1e9 * best[k] / n);
  /* A checksum so that nothing is optimised away and two builds can be compared. */
  double sum = 0, sum32 = 0;
  for (size_t i = 0; i < n; i++) {
    sum += x[i] + y[i] + z[i] + p[i] + iu[i] + iv[i];
    sum32 += (double)x32[i] + y32[i] + z32[i] + p32[i] + iu32[i] + iv32[i];
  }
  printf("checksum f64 %.17g f32 %.17g\n", sum, sum32);
  gonio_sampler_free(s);
  gonio_diagram_free(d);
  return 0;
}
