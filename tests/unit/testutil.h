/* rtsh — helpers shared by the cmocka tests. */
#ifndef RTSH_TESTUTIL_H
#define RTSH_TESTUTIL_H

/* clang-format off */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>
/* clang-format on */

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rtsh/math.h"

/* Fails the test unless |a - b| <= tol, printing both values. */
#define assert_near(a, b, tol)                                                                  \
	do {                                                                                    \
		double a_ = (a), b_ = (b);                                                      \
		if (!(fabs(a_ - b_) <= (tol)))                                                  \
			fail_msg("%s = %.12g, expected %.12g (tolerance %g)", #a, a_, b_, (double)(tol)); \
	} while (0)

#define assert_vec_near(v, w, tol)                \
	do {                                      \
		vec3 v_ = (v), w_ = (w);          \
		assert_near(v_.x, w_.x, tol);     \
		assert_near(v_.y, w_.y, tol);     \
		assert_near(v_.z, w_.z, tol);     \
	} while (0)

/* A small deterministic generator for property tests (splitmix64). */
typedef struct test_rng {
	uint64_t s;
} test_rng;

static inline double trand(test_rng *r)
{
	uint64_t z = (r->s += 0x9e3779b97f4a7c15ULL);
	z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
	z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
	z ^= z >> 31;
	return (double)(z >> 11) * 0x1.0p-53;
}

/* Uniform in [lo, hi). */
static inline double trange(test_rng *r, double lo, double hi)
{
	return lo + (hi - lo) * trand(r);
}

/* A uniformly distributed unit vector. */
static inline vec3 tdir(test_rng *r)
{
	double z = trange(r, -1, 1), phi = trange(r, 0, 2 * RT_PI), s = sqrt(1 - z * z);
	return v3(s * cos(phi), s * sin(phi), z);
}

/* The rtsh binary under test: $RTSH_BIN, else ./rtsh. */
static inline const char *test_rtsh_bin(void)
{
	const char *b = getenv("RTSH_BIN");
	return b && *b ? b : "./rtsh";
}

#endif
