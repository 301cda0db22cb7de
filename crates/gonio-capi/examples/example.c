/* gonio C example: read photometric files, sample them with every method, check that
 * pdf(sample(u)) equals the sample's pdf and that invert(sample(u)) == u, and exercise the error
 * paths (NULL pointers, a missing file, a malformed file, bad enumeration values); then sample,
 * evaluate and invert an environment map built in memory (check_envmap) and build it with options
 * (check_envmap_options).
 *
 * Build (see scripts/test-c.sh and docs/C_API.md):
 *   cc -std=c11 -Wall -Wextra -I crates/gonio-capi/include example.c \
 *      target/release/libgonio_capi.a -lpthread -ldl -lm -o example
 * Run:  ./example FILE.ies [FILE.ldt ...]      exit status 0 when every check passes.
 */
#include "gonio.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

static uint64_t rng_state = 0x9e3779b97f4a7c15ull;
static double next_unit(void) { return splitmix64_unit(&rng_state); }

#define N 2048
/* Largest accepted |pdf(sample(u)) - pdf| / pdf and max |invert(sample(u)) - u| (the tolerance of
 * the library's own round-trip check). */
#define PDF_REL_TOL 1e-9
#define ROUND_TRIP_TOL 1e-8

static void check_sampler(const char *path, const GonioSampler *s) {
    static double u[2 * N], dirs[3 * N], pdfs[N], pdf_again[N], uv[2 * N];
    static double su[N], sv[N], x[N], y[N], z[N], spdf[N];
    static float uf[2 * N], dirsf[3 * N], pdfsf[N];
    const char *method = gonio_sampler_method(s);
    for (int i = 0; i < 2 * N; i++) u[i] = next_unit();

    /* Batch, array of structs, double. */
    CHECK(gonio_sample_batch(s, u, N, dirs, pdfs) == GONIO_OK, "%s", gonio_last_error_message());
    CHECK(gonio_pdf_batch(s, dirs, N, pdf_again) == GONIO_OK, "%s", gonio_last_error_message());
    int has_inverse = gonio_invert_batch(s, dirs, N, uv) == GONIO_OK;
    if (!has_inverse)
        CHECK(strcmp(method, "rejection") == 0, "%s: invert failed: %s", method,
              gonio_last_error_message());
    double worst_pdf = 0, worst_uv = 0;
    int tested = 0;
    for (int i = 0; i < N; i++) {
        const double *d = dirs + 3 * i;
        double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        CHECK(fabs(len - 1.0) < 1e-12, "%s: sample %d is not a unit vector (%g)", method, i, len);
        double e = fabs(pdf_again[i] - pdfs[i]) / (pdfs[i] > 0 ? pdfs[i] : 1.0);
        if (e > worst_pdf) worst_pdf = e;
        if (has_inverse && pdfs[i] > 0) {
            double du = fabs(uv[2 * i] - u[2 * i]), dv = fabs(uv[2 * i + 1] - u[2 * i + 1]);
            double m = du > dv ? du : dv;
            if (!(m <= worst_uv)) worst_uv = m; /* NaN counts as worst */
            tested++;
        }
    }
    CHECK(worst_pdf <= PDF_REL_TOL, "%s: pdf(sample(u)) differs by %g (relative)", method,
          worst_pdf);
    CHECK(!has_inverse || worst_uv <= ROUND_TRIP_TOL, "%s: round trip off by %g", method,
          worst_uv);

    /* One point at a time agrees with the batch. */
    GonioSample one;
    CHECK(gonio_sample(s, u[0], u[1], &one) == GONIO_OK, "%s", gonio_last_error_message());
    /* The batch path may use SIMD and FMA: equal up to round-off, not bit for bit. */
    CHECK(fabs(one.direction[0] - dirs[0]) <= 1e-14 && fabs(one.direction[1] - dirs[1]) <= 1e-14 &&
              fabs(one.direction[2] - dirs[2]) <= 1e-14 && fabs(one.pdf - pdfs[0]) <= 1e-13 * pdfs[0],
          "%s: gonio_sample differs from the batch", method);
    double p1;
    CHECK(gonio_pdf(s, dirs[0], dirs[1], dirs[2], &p1) == GONIO_OK &&
              fabs(p1 - pdf_again[0]) <= 1e-13 * pdf_again[0],
          "%s: gonio_pdf differs from the batch", method);

    /* Structure of arrays, double: the same numbers. */
    for (int i = 0; i < N; i++) {
        su[i] = u[2 * i];
        sv[i] = u[2 * i + 1];
    }
    CHECK(gonio_sample_batch_soa(s, su, sv, N, x, y, z, spdf) == GONIO_OK, "%s",
          gonio_last_error_message());
    int same = 1;
    for (int i = 0; i < N; i++)
        same &= x[i] == dirs[3 * i] && y[i] == dirs[3 * i + 1] && z[i] == dirs[3 * i + 2] &&
                spdf[i] == pdfs[i];
    CHECK(same, "%s: SoA and AoS batches differ", method);

    /* Float: the double results rounded; for hds its float32 map (f32 tables and arithmetic), which
       stays within 1e-6 in direction and 1e-4 relative in pdf of the double map (docs/API.md,
       "Float32 maps"; measured 1.6e-7 and 3.2e-5). */
    for (int i = 0; i < 2 * N; i++) uf[i] = (float)u[i];
    CHECK(gonio_sample_batch_f32(s, uf, N, dirsf, pdfsf) == GONIO_OK, "%s",
          gonio_last_error_message());
    GonioSample fs;
    int is_hds = strcmp(method, "hds") == 0;
    CHECK(gonio_sample(s, (double)uf[0], (double)uf[1], &fs) == GONIO_OK &&
              fabs(dirsf[0] - fs.direction[0]) <= (is_hds ? 1e-6 : 1e-7) &&
              fabs(pdfsf[0] - fs.pdf) <= (is_hds ? 1e-4 : 1e-6) * fs.pdf,
          "%s: the float batch is not the rounded double result", method);

    double lo, hi;
    int st = gonio_sampler_ratio_bound(s, &lo, &hi);
    if (st == GONIO_OK)
        printf("  %-18s pdf(sample(u)) rel. error %.1e, round trip %.1e (%d points), "
               "pdf/target in [%.4f, %.4f]\n",
               method, worst_pdf, worst_uv, tested, lo, hi);
    else
        printf("  %-18s pdf(sample(u)) rel. error %.1e, round trip %.1e (%d points), no bound\n",
               method, worst_pdf, worst_uv, tested);
    (void)path;
}

static void check_file(const char *path) {
    GonioDiagram *d = NULL;
    if (gonio_diagram_read_path(path, GONIO_FORMAT_AUTO, &d) != GONIO_OK) {
        CHECK(0, "cannot read %s: %s", path, gonio_last_error_message());
        return;
    }
    double flux = 0;
    size_t nw = 0;
    CHECK(gonio_diagram_flux(d, &flux) == GONIO_OK && flux > 0, "flux %g", flux);
    CHECK(gonio_diagram_warning_count(d, &nw) == GONIO_OK, "warning count");
    printf("%s: flux %.6g lm, %zu warnings\n", path, flux, nw);
    for (size_t i = 0; i < nw; i++) {
        const char *w = NULL;
        CHECK(gonio_diagram_warning(d, i, &w) == GONIO_OK && w != NULL, "warning %zu", i);
        printf("  %s\n", w);
    }

    static const GonioMethod methods[] = {GONIO_METHOD_HDS, GONIO_METHOD_PIECEWISE_CONSTANT,
                                          GONIO_METHOD_BILINEAR, GONIO_METHOD_REJECTION,
                                          GONIO_METHOD_UNIFORM};
    for (size_t m = 0; m < sizeof methods / sizeof methods[0]; m++) {
        GonioSampler *s = NULL;
        if (gonio_sampler_build(d, methods[m], GONIO_DOMAIN_AUTO, &s) != GONIO_OK) {
            /* Rejection may refuse a very peaked distribution; that is an answer, not a bug. */
            printf("  method %d not built: %s\n", (int)methods[m], gonio_last_error_message());
            CHECK(methods[m] == GONIO_METHOD_REJECTION, "build failed");
            continue;
        }
        /* The sampler does not borrow the diagram: free the diagram first for the HDS map. */
        check_sampler(path, s);
        gonio_sampler_free(s);
    }
    gonio_diagram_free(d);
}

/* Every error path answers with a status and a message, never a crash. */
static void check_errors(const char *good_path) {
    GonioDiagram *d = NULL;
    GonioSampler *s = NULL;
    double x;
    GonioSample smp;

    CHECK(gonio_diagram_read_path(NULL, GONIO_FORMAT_AUTO, &d) == GONIO_ERR_NULL_POINTER,
          "NULL path");
    CHECK(strstr(gonio_last_error_message(), "path") != NULL, "message names the argument: %s",
          gonio_last_error_message());
    CHECK(gonio_diagram_read_path(good_path, GONIO_FORMAT_AUTO, NULL) == GONIO_ERR_NULL_POINTER,
          "NULL out");
    CHECK(gonio_diagram_read_path("/nonexistent/lamp.ies", GONIO_FORMAT_AUTO, &d) == GONIO_ERR_IO,
          "missing file");
    CHECK(strstr(gonio_last_error_message(), "/nonexistent/lamp.ies") != NULL, "names the file");
    CHECK(d == NULL, "no handle on failure");
    CHECK(gonio_diagram_read_path(good_path, 42, &d) == GONIO_ERR_INVALID_ARGUMENT, "format 42");

    /* A malformed file in memory: the message is FILE:LINE:COLUMN as the CLI prints it. */
    static const char bad[] = "IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 3 1 1 2 0 0 0\n1 1 100\n"
                              "0 45 x\n0\n10 20 30\n";
    CHECK(gonio_diagram_read_memory((const uint8_t *)bad, sizeof bad - 1, GONIO_FORMAT_IES,
                                    "bad.ies", &d) == GONIO_ERR_PARSE,
          "malformed IES accepted");
    CHECK(strncmp(gonio_last_error_message(), "bad.ies:5:", 10) == 0,
          "located message, got: %s", gonio_last_error_message());
    printf("malformed file: %s\n", gonio_last_error_message());
    CHECK(gonio_diagram_read_memory(NULL, 3, GONIO_FORMAT_IES, NULL, &d) == GONIO_ERR_NULL_POINTER,
          "NULL data");
    CHECK(gonio_diagram_read_memory((const uint8_t *)bad, 3, GONIO_FORMAT_AUTO, NULL, &d) ==
              GONIO_ERR_INVALID_ARGUMENT,
          "AUTO format in memory");

    CHECK(gonio_sampler_build(NULL, GONIO_METHOD_HDS, GONIO_DOMAIN_AUTO, &s) ==
              GONIO_ERR_NULL_POINTER,
          "NULL diagram");
    CHECK(gonio_diagram_read_path(good_path, GONIO_FORMAT_AUTO, &d) == GONIO_OK, "%s",
          gonio_last_error_message());
    CHECK(gonio_sampler_build(d, 99, GONIO_DOMAIN_AUTO, &s) == GONIO_ERR_INVALID_ARGUMENT,
          "method 99");
    CHECK(gonio_sampler_build(d, GONIO_METHOD_HDS, 7, &s) == GONIO_ERR_INVALID_ARGUMENT,
          "domain 7");
    CHECK(gonio_sampler_build(d, GONIO_METHOD_HDS, GONIO_DOMAIN_AUTO, NULL) ==
              GONIO_ERR_NULL_POINTER,
          "NULL out");
    CHECK(gonio_sampler_build(d, GONIO_METHOD_HDS, GONIO_DOMAIN_AUTO, &s) == GONIO_OK, "%s",
          gonio_last_error_message());
    gonio_diagram_free(d); /* the sampler stays valid */

    CHECK(gonio_sample(NULL, 0.5, 0.5, &smp) == GONIO_ERR_NULL_POINTER, "NULL sampler");
    CHECK(gonio_sample(s, 0.5, 0.5, NULL) == GONIO_ERR_NULL_POINTER, "NULL out");
    CHECK(gonio_pdf(s, 0, 0, 0, &x) == GONIO_ERR_INVALID_ARGUMENT, "zero direction");
    CHECK(gonio_pdf(s, NAN, 0, 1, &x) == GONIO_ERR_INVALID_ARGUMENT, "NaN direction");
    CHECK(gonio_invert(s, 0, 0, 1, &x, NULL) == GONIO_ERR_NULL_POINTER, "NULL v");
    CHECK(gonio_sample_batch(s, NULL, 4, &x, &x) == GONIO_ERR_NULL_POINTER, "NULL batch input");
    CHECK(gonio_pdf_batch(s, &x, SIZE_MAX / 2, &x) == GONIO_ERR_INVALID_ARGUMENT, "huge n");
    double dirs[6] = {0, 0, 1, 0, 0, 0}, out[2];
    CHECK(gonio_pdf_batch(s, dirs, 2, out) == GONIO_ERR_INVALID_ARGUMENT, "zero direction #1");
    CHECK(strstr(gonio_last_error_message(), "#1") != NULL, "names the index: %s",
          gonio_last_error_message());
    CHECK(gonio_sampler_method(NULL) == NULL, "method of NULL");
    gonio_sampler_free(s);
    gonio_sampler_free(NULL);
    gonio_diagram_free(NULL);
}

/* Environment maps: a PFM image built in memory (little-endian RGB floats, rows bottom to top),
 * read with gonio_envmap_read_memory. A constant sky has the uniform density 1/(4 pi) everywhere;
 * a sky with one bright pixel is not uniform, and for both pdf(sample(u)) equals the sample's
 * pdf, invert(sample(u)) == u and the batch agrees with single points. */
#define ENV_W 16
#define ENV_H 8
static size_t env_pfm(unsigned char *buf, int bright) {
    int n = sprintf((char *)buf, "PF\n%d %d\n-1.0\n", ENV_W, ENV_H);
    size_t len = (size_t)n;
    for (int row = 0; row < ENV_H; row++) {
        for (int col = 0; col < ENV_W; col++) {
            for (int c = 0; c < 3; c++) {
                float x = (bright && row == 2 && col == 5) ? 100.0f : 0.25f * (float)(c + 1);
                uint32_t bits;
                memcpy(&bits, &x, sizeof bits);
                for (int k = 0; k < 4; k++) buf[len++] = (unsigned char)(bits >> (8 * k));
            }
        }
    }
    return len;
}

#define ENV_N 64
static void check_envmap(void) {
    static unsigned char buf[64 + ENV_W * ENV_H * 12];
    const double uniform = 1.0 / (4.0 * 3.14159265358979323846);
    for (int bright = 0; bright < 2; bright++) {
        size_t len = env_pfm(buf, bright);
        GonioEnvMap *m = NULL;
        GonioStatus st = gonio_envmap_read_memory(buf, len, "sky.pfm", &m);
        CHECK(st == GONIO_OK, "envmap read: %s", gonio_last_error_message());
        if (st != GONIO_OK) continue;
        double uv[2 * ENV_N], dirs[3 * ENV_N], pdfs[ENV_N];
        float rgbs[3 * ENV_N];
        double max_pdf = 0.0;
        for (int i = 0; i < 2 * ENV_N; i++) uv[i] = next_unit();
        for (int i = 0; i < ENV_N; i++) {
            double d[3], pdf = 0.0, q = 0.0, u = -1.0, v = -1.0;
            float rgb[3], e[3];
            st = gonio_envmap_sample(m, uv[2 * i], uv[2 * i + 1], d, &pdf, rgb);
            CHECK(st == GONIO_OK, "envmap sample: %s", gonio_last_error_message());
            if (!bright)
                CHECK(fabs(pdf - uniform) < 1e-12, "constant sky pdf %.17g != 1/(4 pi)", pdf);
            if (pdf > max_pdf) max_pdf = pdf;
            CHECK(gonio_envmap_pdf(m, d[0], d[1], d[2], &q) == GONIO_OK, "envmap pdf");
            CHECK(fabs(q - pdf) <= 1e-9 * pdf, "envmap pdf %.17g vs sample %.17g", q, pdf);
            CHECK(gonio_envmap_eval(m, d[0], d[1], d[2], e) == GONIO_OK, "envmap eval");
            CHECK(memcmp(e, rgb, sizeof e) == 0, "envmap eval != sample radiance");
            st = gonio_envmap_invert(m, d[0], d[1], d[2], &u, &v);
            CHECK(st == GONIO_OK, "envmap invert: %s", gonio_last_error_message());
            CHECK(fabs(u - uv[2 * i]) < 1e-9 && fabs(v - uv[2 * i + 1]) < 1e-9,
                  "envmap round trip (%.17g, %.17g) -> (%.17g, %.17g)", uv[2 * i], uv[2 * i + 1],
                  u, v);
        }
        if (bright) CHECK(max_pdf > 10.0 * uniform, "bright pixel: max pdf %.17g", max_pdf);
        printf("environment map (%s sky, %dx%d PFM): %d samples, max pdf %.4g (uniform %.4g)\n",
               bright ? "one bright pixel" : "constant", ENV_W, ENV_H, ENV_N, max_pdf, uniform);
        st = gonio_envmap_sample_batch(m, uv, ENV_N, dirs, pdfs, rgbs);
        CHECK(st == GONIO_OK, "envmap batch: %s", gonio_last_error_message());
        for (int i = 0; i < ENV_N; i++) {
            double d[3], pdf;
            float rgb[3];
            float e[3];
            gonio_envmap_sample(m, uv[2 * i], uv[2 * i + 1], d, &pdf, rgb);
            /* The batch path: the one-point results up to its round-off, the radiance of its own
               direction. */
            CHECK(fabs(d[0] - dirs[3 * i]) <= 1e-15 && fabs(d[1] - dirs[3 * i + 1]) <= 1e-15 &&
                      fabs(d[2] - dirs[3 * i + 2]) <= 1e-15 && fabs(pdf - pdfs[i]) <= 1e-12 * pdf,
                  "envmap batch element %d differs", i);
            CHECK(gonio_envmap_eval(m, dirs[3 * i], dirs[3 * i + 1], dirs[3 * i + 2], e) == GONIO_OK &&
                      memcmp(e, rgbs + 3 * i, sizeof e) == 0,
                  "envmap batch element %d: radiance != eval of its direction", i);
        }
        /* Errors: a point outside the square, a NaN in a batch (its index), NULL pointers. */
        {
            double d[3], pdf;
            float rgb[3];
            CHECK(gonio_envmap_sample(m, 1.5, 0.5, d, &pdf, rgb) == GONIO_ERR_INVALID_ARGUMENT,
                  "envmap point outside the square");
            uv[2 * 9] = NAN;
            CHECK(gonio_envmap_sample_batch(m, uv, ENV_N, dirs, pdfs, rgbs) ==
                      GONIO_ERR_INVALID_ARGUMENT,
                  "envmap NaN in batch");
            CHECK(strncmp(gonio_last_error_message(), "point #9: ", 10) == 0, "message: %s",
                  gonio_last_error_message());
            CHECK(gonio_envmap_pdf(m, 0.0, 0.0, 1.0, NULL) == GONIO_ERR_NULL_POINTER,
                  "envmap NULL pdf");
            CHECK(gonio_envmap_pdf(NULL, 0.0, 0.0, 1.0, &pdf) == GONIO_ERR_NULL_POINTER,
                  "envmap NULL map");
        }
        /* The float32 environment map (consumes m): float in and out, the uniform density of the
         * constant sky to float round-off (on the bright one, pdf at a sample agrees with the
         * sample's to its contract), the radiance of each direction, the round trip. */
        {
            GonioEnvMapF32 *f = NULL;
            float u32[ENV_N], v32[ENV_N], x[ENV_N], y[ENV_N], z[ENV_N], p32[ENV_N], q32[ENV_N];
            float c32[3 * ENV_N], e32[3 * ENV_N], iu[ENV_N], iv[ENV_N];
            size_t bytes = 0;
            int i;
            CHECK(gonio_envmap_into_float32(m, &f) == GONIO_OK && f != NULL, "envmap float32: %s",
                  gonio_last_error_message());
            for (i = 0; i < ENV_N; i++) {
                u32[i] = (float)((i + 0.5) / ENV_N);
                v32[i] = (float)fmod(0.618034 * (i + 0.5), 1.0);
            }
            CHECK(gonio_envmap_f32_sample_batch(f, u32, v32, ENV_N, x, y, z, p32, c32) == GONIO_OK,
                  "envmap f32 sample: %s", gonio_last_error_message());
            CHECK(gonio_envmap_f32_pdf_batch(f, x, y, z, ENV_N, q32) == GONIO_OK, "envmap f32 pdf");
            CHECK(gonio_envmap_f32_eval_batch(f, x, y, z, ENV_N, e32) == GONIO_OK, "envmap f32 eval");
            CHECK(gonio_envmap_f32_invert_batch(f, x, y, z, ENV_N, iu, iv) == GONIO_OK,
                  "envmap f32 invert");
            CHECK(memcmp(e32, c32, sizeof e32) == 0, "envmap f32: eval != sample radiance");
            for (i = 0; i < ENV_N; i++) {
                float uni = (float)uniform;
                if (!bright)
                    CHECK(fabsf(p32[i] - uni) <= 5e-7f * uni && fabsf(q32[i] - uni) <= 5e-7f * uni,
                          "envmap f32 pdf %.9g, %.9g vs %.9g", p32[i], q32[i], uni);
                else
                    CHECK(fabsf(q32[i] - p32[i]) <= 1e-3f * p32[i],
                          "envmap f32 pdf %.9g at its sample, %.9g with it", q32[i], p32[i]);
                CHECK(fabsf(iu[i] - u32[i]) < 1e-5f && fabsf(iv[i] - v32[i]) < 1e-5f,
                      "envmap f32 round trip %d", i);
            }
            CHECK(gonio_envmap_f32_memory_bytes(f, &bytes) == GONIO_OK && bytes > 0,
                  "envmap f32 memory");
            gonio_envmap_f32_free(f);
        }
    }
    {
        GonioEnvMap *m = NULL;
        CHECK(gonio_envmap_read_memory((const unsigned char *)"junk", 4, NULL, &m) ==
                      GONIO_ERR_PARSE && m == NULL,
              "envmap junk");
        CHECK(gonio_envmap_read_path("/nonexistent/sky.hdr", &m) == GONIO_ERR_IO && m == NULL,
              "envmap missing file");
        gonio_envmap_free(NULL);
    }
}

/* Environment map options: constant custom weights give the uniform density on a sky with a
 * bright pixel; custom weights of the wrong length and an unknown lookup are refused; MIS
 * compensation zeroes the dim sky; a negative pixel gives a warning, read back. */
static void check_envmap_options(void) {
    static unsigned char buf[64 + ENV_W * ENV_H * 12];
    static float cw[ENV_W * ENV_H];
    const double uniform = 1.0 / (4.0 * 3.14159265358979323846);
    GonioEnvOptions o;
    GonioEnvMap *m = NULL;
    size_t len = env_pfm(buf, 1), n = 0;
    const char *text = NULL;
    double d[3], pdf = 0.0;
    float rgb[3];
    CHECK(gonio_envmap_options_default(&o) == GONIO_OK && o.weight == GONIO_ENV_WEIGHT_LUMINANCE &&
              o.lookup == GONIO_ENV_LOOKUP_NEAREST && o.mis_compensation == 0,
          "envmap default options");
    for (int i = 0; i < ENV_W * ENV_H; i++) cw[i] = 2.0f;
    o.weight = GONIO_ENV_WEIGHT_CUSTOM;
    o.custom_weights = cw;
    o.custom_len = ENV_W * ENV_H;
    CHECK(gonio_envmap_read_memory_with(buf, len, "sky.pfm", &o, &m) == GONIO_OK, "custom: %s",
          gonio_last_error_message());
    for (int i = 0; m && i < 16; i++) {
        CHECK(gonio_envmap_sample(m, next_unit(), next_unit(), d, &pdf, rgb) == GONIO_OK,
              "custom sample");
        CHECK(fabs(pdf - uniform) < 1e-12, "custom weights: pdf %.17g != 1/(4 pi)", pdf);
    }
    gonio_envmap_free(m);
    m = NULL;
    o.custom_len = 3;
    CHECK(gonio_envmap_read_memory_with(buf, len, "sky.pfm", &o, &m) ==
                  GONIO_ERR_INVALID_ARGUMENT && m == NULL,
          "custom weights of the wrong length");
    printf("expected error: %s\n", gonio_last_error_message());
    gonio_envmap_options_default(&o);
    o.lookup = 7;
    CHECK(gonio_envmap_read_memory_with(buf, len, "sky.pfm", &o, &m) == GONIO_ERR_INVALID_ARGUMENT,
          "unknown lookup");
    /* MIS compensation of the sky with one bright pixel: the dim rest, below the mean, gets
     * density 0 (the zenith here); the lookup option gives the bilinear radiance. */
    gonio_envmap_options_default(&o);
    o.mis_compensation = 1;
    o.lookup = GONIO_ENV_LOOKUP_BILINEAR;
    CHECK(gonio_envmap_read_memory_with(buf, len, "sky.pfm", &o, &m) == GONIO_OK, "mis: %s",
          gonio_last_error_message());
    CHECK(gonio_envmap_pdf(m, 0.0, 0.0, 1.0, &pdf) == GONIO_OK && pdf == 0.0,
          "MIS-compensated zenith pdf %.17g", pdf);
    CHECK(gonio_envmap_eval(m, 0.3, -0.2, 0.9, rgb) == GONIO_OK && rgb[2] == 0.75f,
          "bilinear eval of the dim sky");
    CHECK(gonio_envmap_warning_count(m, &n) == GONIO_OK && n == 0, "no warning, not %zu", n);
    gonio_envmap_free(m);
    m = NULL;
    /* A negative pixel (the first three floats of the data): weighted as 0, with a warning. */
    len = env_pfm(buf, 0);
    {
        const float neg = -1.0f;
        uint32_t bits;
        size_t at = len - (size_t)ENV_W * ENV_H * 12;
        memcpy(&bits, &neg, sizeof bits);
        for (int k = 0; k < 12; k++) buf[at + k] = (unsigned char)(bits >> (8 * (k % 4)));
    }
    gonio_envmap_options_default(&o);
    CHECK(gonio_envmap_read_memory_with(buf, len, "sky.pfm", &o, &m) == GONIO_OK, "negative: %s",
          gonio_last_error_message());
    CHECK(gonio_envmap_warning_count(m, &n) == GONIO_OK && n == 1, "one warning, not %zu", n);
    CHECK(gonio_envmap_warning(m, 0, &text) == GONIO_OK && text &&
              strncmp(text, "sky.pfm: warning: 1 pixels have a negative luminance", 52) == 0,
          "warning text: %s", text ? text : "(null)");
    printf("envmap warning: %s\n", text ? text : "(null)");
    CHECK(gonio_envmap_warning(m, 1, &text) == GONIO_ERR_INVALID_ARGUMENT, "warning index 1");
    gonio_envmap_free(m);
}

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "usage: %s FILE.ies|FILE.ldt ...\n", argv[0]);
        return 2;
    }
    printf("gonio %s\n", gonio_version());
    for (int i = 1; i < argc; i++) check_file(argv[i]);
    check_errors(argv[1]);
    check_envmap();
    check_envmap_options();
    if (failures) {
        fprintf(stderr, "%d check(s) failed\n", failures);
        return 1;
    }
    printf("C example: all checks passed\n");
    return 0;
}
