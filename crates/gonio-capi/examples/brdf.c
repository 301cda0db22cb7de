/* gonio C example for tabulated BRDFs (issue 26): writes a small analytic BRDF table (Lambert plus
 * a Phong lobe around the mirror direction) as a gonio BRDF JSON file, reads it back from the
 * path and from memory, samples it with every method at incident directions on and between the
 * tabulated slices, and checks that
 *   - pdf(wi, sample(wi, u)) equals the sample's pdf (batch and single calls),
 *   - invert(wi, sample(wi, u)) == u (every method but ggx-fit, whose inverse holds only above
 *     the horizon and is not checked here),
 *   - the mean weight of the HDS samples equals the albedo ∫ f·cos θ_o dω_o of the table (by a
 *     midpoint quadrature through gonio_brdf_eval_batch) within 1 %,
 * and exercises the error paths (a bad method, a NaN in a batch, a missing file).
 *
 * Build (see scripts/test-c.sh and docs/C_API.md):
 *   cc -std=c11 -Wall -Wextra -I crates/gonio-capi/include brdf.c \
 *      target/release/libgonio_capi.a -lpthread -ldl -lm -o brdf
 * Run:  ./brdf DIR        (writes DIR/brdf_example.json; exit status 0 when every check passes)
 */
#include "gonio.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

static const double PI = 3.14159265358979323846;

static uint64_t rng_state = 0x243f6a8885a308d3ull;
static double next_unit(void) { return splitmix64_unit(&rng_state); }

/* The analytic BRDF (1/sr) at incident polar angle ti (azimuth 0) and outgoing (to, dphi). */
static double analytic(double ti, double to, double dphi) {
    double c = cos(ti) * cos(to) - sin(ti) * sin(to) * cos(dphi); /* cos to the mirror direction */
    double lobe = c > 0.0 ? 0.5 * 22.0 / (2.0 * PI) * pow(c, 20.0) : 0.0;
    return 0.2 / PI + lobe;
}

#define NT 10 /* θ nodes 0°, 10°, …, 90° */
#define NP 24 /* Δφ nodes 0°, 15°, …, 345° */

/* The JSON text of the table (malloc'ed; the caller frees it). */
static char *table_json(void) {
    size_t cap = 64 * NT * NT * NP + 4096, len = 0;
    char *s = malloc(cap);
    int i, j, k;
    if (!s) return NULL;
    len += (size_t)sprintf(s + len,
                           "{\"format\": \"gonio-brdf\", \"version\": 1, \"symmetry\": "
                           "\"isotropic\", \"channels\": 1,\n \"theta_i_deg\": [");
    for (i = 0; i < NT; i++) len += (size_t)sprintf(s + len, "%s%d", i ? ", " : "", 10 * i);
    len += (size_t)sprintf(s + len, "], \"phi_i_deg\": [0],\n \"theta_o_deg\": [");
    for (i = 0; i < NT; i++) len += (size_t)sprintf(s + len, "%s%d", i ? ", " : "", 10 * i);
    len += (size_t)sprintf(s + len, "], \"phi_o_deg\": [");
    for (k = 0; k < NP; k++) len += (size_t)sprintf(s + len, "%s%d", k ? ", " : "", 15 * k);
    len += (size_t)sprintf(s + len, "],\n \"values\": [");
    for (i = 0; i < NT; i++)
        for (j = 0; j < NT; j++)
            for (k = 0; k < NP; k++) {
                double v = analytic(10.0 * i * PI / 180.0, 10.0 * j * PI / 180.0,
                                    15.0 * k * PI / 180.0);
                len += (size_t)sprintf(s + len, "%s%.17g", (i || j || k) ? ", " : "", v);
            }
    sprintf(s + len, "]}\n");
    return s;
}

/* ∫ f(wi, wo) cos θ_o dω_o by the midpoint rule on 64 × 128 cells in (cos θ_o, φ_o). */
static double albedo(const GonioBrdf *b, const double wi[3]) {
    enum { M = 64, K = 2 * M };
    static double wo[3 * M * K], f[3 * M * K];
    double sum = 0.0;
    int j, i;
    for (j = 0; j < M; j++)
        for (i = 0; i < K; i++) {
            double z = (j + 0.5) / M, r = sqrt(1.0 - z * z), p = 2.0 * PI * (i + 0.5) / K;
            double *d = wo + 3 * (j * K + i);
            d[0] = r * cos(p);
            d[1] = r * sin(p);
            d[2] = z;
        }
    CHECK(gonio_brdf_eval_batch(b, wi, 1, wo, M * K, f) == GONIO_OK, "eval_batch: %s",
          gonio_last_error_message());
    for (j = 0; j < M * K; j++) sum += f[3 * j] * wo[3 * j + 2];
    return sum * 2.0 * PI / (M * K);
}

#define N 512

static void check_method(const GonioBrdf *b, GonioBrdfMethod method) {
    static const double incident_deg[][2] = {{0, 0}, {30, 0}, {35, 20}, {62, 200}, {85, 90}};
    static double uv[2 * N], wo[3 * N], pdf[N], inv[2 * N];
    static GonioBrdfSample s[N];
    GonioBrdfSampler *sp = NULL;
    size_t a;
    int i;
    GonioStatus st = gonio_brdf_sampler_build(b, method, NULL, &sp);
    CHECK(st == GONIO_OK, "build method %d: %s", method, gonio_last_error_message());
    if (st != GONIO_OK) return;
    for (a = 0; a < sizeof incident_deg / sizeof incident_deg[0]; a++) {
        double t = incident_deg[a][0] * PI / 180.0, p = incident_deg[a][1] * PI / 180.0;
        double wi[3], mean = 0.0, worst_pdf = 0.0, worst_uv = 0.0;
        wi[0] = sin(t) * cos(p);
        wi[1] = sin(t) * sin(p);
        wi[2] = cos(t);
        for (i = 0; i < 2 * N; i++) uv[i] = next_unit();
        st = gonio_brdf_sample_batch(sp, wi, 1, uv, N, s);
        CHECK(st == GONIO_OK, "sample_batch: %s", gonio_last_error_message());
        for (i = 0; i < N; i++) memcpy(wo + 3 * i, s[i].direction, sizeof s[i].direction);
        CHECK(gonio_brdf_pdf_batch(sp, wi, 1, wo, N, pdf) == GONIO_OK, "pdf_batch");
        CHECK(gonio_brdf_invert_batch(sp, wi, 1, wo, N, inv) == GONIO_OK, "invert_batch");
        for (i = 0; i < N; i++) {
            GonioBrdfSample one;
            double e = fabs(pdf[i] - s[i].pdf) / (s[i].pdf + 1e-300);
            if (s[i].pdf > 1e-9 && e > worst_pdf) worst_pdf = e;
            mean += s[i].weight[0];
            if (i % 64 == 0) {
                CHECK(gonio_brdf_sample(sp, wi, uv[2 * i], uv[2 * i + 1], &one) == GONIO_OK &&
                          memcmp(&one, &s[i], sizeof one) == 0,
                      "single sample differs from the batch at #%d", i);
            }
            if (method != GONIO_BRDF_METHOD_GGX_FIT && s[i].pdf > 1e-6) {
                double du = fabs(inv[2 * i] - uv[2 * i]), dv = fabs(inv[2 * i + 1] - uv[2 * i + 1]);
                if (!(du <= worst_uv)) worst_uv = du;
                if (!(dv <= worst_uv)) worst_uv = dv;
            }
        }
        mean /= N;
        CHECK(worst_pdf <= 1e-9, "%s at (%g, %g): pdf differs by %g (relative)",
              gonio_brdf_sampler_method(sp), incident_deg[a][0], incident_deg[a][1], worst_pdf);
        CHECK(worst_uv <= 1e-8, "%s at (%g, %g): invert misses u by %g",
              gonio_brdf_sampler_method(sp), incident_deg[a][0], incident_deg[a][1], worst_uv);
        if (method == GONIO_BRDF_METHOD_HDS) {
            double ref = albedo(b, wi);
            CHECK(fabs(mean - ref) <= 0.01 * ref, "hds at (%g, %g): mean weight %g, albedo %g",
                  incident_deg[a][0], incident_deg[a][1], mean, ref);
            printf("  hds at θ_i = %2g°, φ_i = %3g°: mean weight %.5f, albedo %.5f, "
                   "max pdf error %.1e, max round-trip error %.1e\n",
                   incident_deg[a][0], incident_deg[a][1], mean, ref, worst_pdf, worst_uv);
        }
    }
    gonio_brdf_sampler_free(sp);
}

int main(int argc, char **argv) {
    char path[4096];
    char *json;
    FILE *f;
    GonioBrdf *b = NULL, *m = NULL;
    GonioBrdfSampler *sp = NULL;
    GonioBrdfInfo info;
    GonioBrdfSample one;
    GonioBrdfMethod method;
    double wi[6] = {0.0, 0.0, 1.0, 0.0, NAN, 1.0}, uv[2] = {0.5, 0.5}, pdf[2];
    if (argc != 2) {
        fprintf(stderr, "usage: %s DIR\n", argv[0]);
        return 2;
    }
    snprintf(path, sizeof path, "%s/brdf_example.json", argv[1]);
    json = table_json();
    if (!json || !(f = fopen(path, "w"))) {
        fprintf(stderr, "cannot write %s\n", path);
        free(json);
        return 1;
    }
    fputs(json, f);
    fclose(f);

    CHECK(gonio_brdf_read_path(path, NULL, &b) == GONIO_OK, "read %s: %s", path,
          gonio_last_error_message());
    CHECK(gonio_brdf_read_memory((const uint8_t *)json, strlen(json), "table", NULL, &m) ==
              GONIO_OK,
          "read_memory: %s", gonio_last_error_message());
    free(json);
    if (!b || !m) return 1;
    CHECK(gonio_brdf_info(m, &info) == GONIO_OK && info.format == GONIO_BRDF_FORMAT_JSON &&
              info.anisotropic == 0 && info.channels == 1 && info.theta_i == NT &&
              info.phi_i == 1 && info.theta_o == NT && info.phi_o == NP,
          "info");
    gonio_brdf_free(m);

    for (method = GONIO_BRDF_METHOD_HDS; method <= GONIO_BRDF_METHOD_PIECEWISE_CONSTANT; method++) {
        printf("method %d\n", method);
        check_method(b, method);
    }

    /* Error paths: nothing is handed out or written, the message says what and where. */
    CHECK(gonio_brdf_sampler_build(b, 42, NULL, &sp) == GONIO_ERR_INVALID_ARGUMENT && !sp,
          "an unknown method is refused");
    CHECK(gonio_brdf_sampler_build(b, GONIO_BRDF_METHOD_HDS, NULL, &sp) == GONIO_OK, "build");
    pdf[0] = pdf[1] = -1.0;
    CHECK(gonio_brdf_pdf_batch(sp, wi, 2, wi, 2, pdf) == GONIO_ERR_INVALID_ARGUMENT &&
              strncmp(gonio_last_error_message(), "wi #1: ", 7) == 0 && pdf[0] == -1.0,
          "a NaN incident direction stops the batch: %s", gonio_last_error_message());
    uv[1] = 1.5;
    CHECK(gonio_brdf_sample(sp, wi, uv[0], uv[1], &one) == GONIO_ERR_INVALID_ARGUMENT,
          "a point outside the square is refused");
    CHECK(gonio_brdf_sample(sp, NULL, 0.5, 0.5, &one) == GONIO_ERR_NULL_POINTER, "NULL wi");
    gonio_brdf_sampler_free(sp);
    gonio_brdf_free(b);
    b = NULL;
    CHECK(gonio_brdf_read_path("/nonexistent/m.binary", NULL, &b) == GONIO_ERR_IO && !b,
          "a missing file");
    remove(path);

    if (failures) {
        fprintf(stderr, "brdf: %d check(s) failed\n", failures);
        return 1;
    }
    printf("brdf: all checks passed\n");
    return 0;
}
