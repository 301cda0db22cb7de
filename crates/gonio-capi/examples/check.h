/* check.h: what the C examples share. SPDX-License-Identifier: MIT OR Apache-2.0
 *
 * CHECK(cond, fmt, ...) counts a failed condition in `failures` and prints it with its place
 * (the first CHECK_PRINT_LIMIT of them: define it before including this file to change it);
 * splitmix64_unit(&state) is a deterministic generator of numbers in [0, 1) (53 bits), the
 * points of the unit square the examples sample. C99 and C++. */
#ifndef GONIO_EXAMPLES_CHECK_H
#define GONIO_EXAMPLES_CHECK_H

#include <stdint.h>
#include <stdio.h>

#ifndef CHECK_PRINT_LIMIT
#define CHECK_PRINT_LIMIT 1000000
#endif

static int failures = 0;

#define CHECK(cond, ...)                                          \
    do {                                                          \
        if (!(cond)) {                                            \
            if (failures < CHECK_PRINT_LIMIT) {                   \
                fprintf(stderr, "FAIL %s:%d: ", __FILE__, __LINE__); \
                fprintf(stderr, __VA_ARGS__);                     \
                fprintf(stderr, "\n");                            \
            }                                                     \
            failures++;                                           \
        }                                                         \
    } while (0)

static double splitmix64_unit(uint64_t *state) {
    uint64_t z = (*state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return (double)(z >> 11) * (1.0 / 9007199254740992.0);
}

#endif
