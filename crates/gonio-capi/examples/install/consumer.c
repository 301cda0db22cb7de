/* consumer.c: a program that finds an installed gonio through CMake (find_package(gonio)) or
 * pkg-config (gonio, gonio-static) and uses it: scripts/test-install.sh builds it against an
 * install made by scripts/install-c.sh, shared and static, and runs it.
 * SPDX-License-Identifier: MIT OR Apache-2.0 */
#include <gonio/gonio.h>
#include <gonio/gonio_device.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

int main(void) {
  static const char json[] =
      "{\"theta_deg\": [0, 30, 60, 90], \"phi_deg\": [0, 90, 180, 270], \"values\": "
      "[[4, 3, 1, 0], [4, 2, 1, 0], [4, 3, 2, 0], [4, 1, 1, 0]]}";
  GonioDiagram *d = NULL;
  GonioSampler *s = NULL;
  GonioSample out;
  GonioDeviceView view;
  unsigned char blob[16384];
  size_t size = 0;
  float dir[3], pdf;
  if (gonio_diagram_read_memory((const uint8_t *)json, strlen(json), GONIO_FORMAT_JSON, "consumer",
                                &d) != GONIO_OK ||
      gonio_sampler_build(d, GONIO_METHOD_HDS, GONIO_DOMAIN_HEMISPHERE, &s) != GONIO_OK ||
      gonio_sample(s, 0.25, 0.75, &out) != GONIO_OK) {
    fprintf(stderr, "consumer: %s\n", gonio_last_error_message());
    return 1;
  }
  /* The header-only sampler on the same map's float32 tables. */
  if (gonio_sampler_tables(s, NULL, 4, blob, sizeof blob, &size) != GONIO_OK ||
      gonio_device_view_init(&view, blob, size) != GONIO_DEVICE_OK) {
    fprintf(stderr, "consumer: tables: %s\n", gonio_last_error_message());
    return 1;
  }
  gonio_device_sample(&view, 0.25f, 0.75f, dir, &pdf);
  printf("consumer: gonio %s: direction (%.6f, %.6f, %.6f), pdf %.6f; device header pdf %.6f\n",
         gonio_version(), out.direction[0], out.direction[1], out.direction[2], out.pdf, pdf);
  gonio_sampler_free(s);
  gonio_diagram_free(d);
  return fabs(out.pdf - pdf) <= 1e-4 * out.pdf ? 0 : 1;
}
