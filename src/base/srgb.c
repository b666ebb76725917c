/* rtsh — sRGB decode and encode (srgb.h). */
#include "rtsh/srgb.h"

#include <math.h>
#include <pthread.h>
#include <string.h>

double srgb_to_linear(double v)
{
	return v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4);
}

/* The 256 whole codes, computed once: a million-object world_build or a
 * large 8-bit texture would otherwise spend its time in pow(). The values
 * are the same bits. */
static double decode_table[256];
static pthread_once_t decode_once = PTHREAD_ONCE_INIT;

static void decode_table_init(void)
{
	for (int i = 0; i < 256; i++)
		decode_table[i] = srgb_to_linear(i / 255.0);
}

const double *srgb8_table(void)
{
	pthread_once(&decode_once, decode_table_init);
	return decode_table;
}

static inline bool whole_code(double code)
{
	return code >= 0.0 && code <= 255.0 && code == (double)(int)code;
}

double srgb8_to_linear(double code)
{
	if (whole_code(code)) {
		pthread_once(&decode_once, decode_table_init);
		return decode_table[(int)code];
	}
	return srgb_to_linear(code / 255.0);
}

vec3 srgb255_to_linear(vec3 c)
{
	/* srgb8_to_linear of each, the table made once for the three */
	if (whole_code(c.x) && whole_code(c.y) && whole_code(c.z)) {
		pthread_once(&decode_once, decode_table_init);
		return v3(decode_table[(int)c.x], decode_table[(int)c.y], decode_table[(int)c.z]);
	}
	return v3(srgb8_to_linear(c.x), srgb8_to_linear(c.y), srgb8_to_linear(c.z));
}

static double srgb_encode(double v)
{
	if (!(v > 0.0))
		return 0.0;
	return 255.0 * (v <= 0.0031308 ? v * 12.92 : 1.055 * pow(v, 1.0 / 2.4) - 0.055);
}

vec3 linear_to_srgb255(vec3 c)
{
	return v3(srgb_encode(c.x), srgb_encode(c.y), srgb_encode(c.z));
}

/* The 8-bit code of a linear value is the sRGB encoding (IEC 61966-2-1)
 * rounded to nearest: code k covers the linear values from
 * threshold[k] = decode((k - 0.5) / 255) up to threshold[k + 1]. A table of
 * buckets gives the code at the start of each bucket, and a step or two up
 * the thresholds finds the code: no pow() per pixel, which matters for every
 * terminal frame. The same comparisons with the same thresholds whatever the
 * buckets, so the same codes.
 *
 * Two tables of buckets: srgb_bucket, 4096 equal steps over [0,1), and, for
 * the runs of linear_to_srgb8_n (every pixel of every picture written),
 * srgb_log_bucket: the doubles of [2^SRGB_LOG_MIN, 1) cut by their exponent
 * and the top SRGB_LOG_BITS bits of their significand, indexed by the
 * double's bits without a multiply or a conversion. A bucket spans a
 * factor of at most 1 + 2^-10 in v, over which the code (255 x the
 * encoding) grows by at most 255 x 1.055 / 2.4 x 2^-10 = 0.11 while the
 * thresholds lie a whole code apart: a bucket holds at most one threshold,
 * so one comparison finds the code (test_math checks every bucket). Values below
 * 2^SRGB_LOG_MIN (darker than code 1 begins, 1.5e-4) take srgb_bucket. */
#define SRGB_BUCKETS 4096
#define SRGB_LOG_MIN (-13)
#define SRGB_LOG_BITS 10
#define SRGB_LOG_BUCKETS ((-SRGB_LOG_MIN) << SRGB_LOG_BITS)

static double srgb_threshold[257];
static uint8_t srgb_bucket[SRGB_BUCKETS];
static uint8_t srgb_log_bucket[SRGB_LOG_BUCKETS];
/* With a gain of 1 the value is a float: the bits of the least float at or
 * above each threshold (k = 1..255; 0 and 256 never read), compared as
 * integers (the order of positive floats' bits is their values'), and the
 * float's own bits give the bucket. */
static uint32_t srgb_threshold_f[257];
static pthread_once_t srgb_once = PTHREAD_ONCE_INIT;

/* The bits of a double, and their index in srgb_log_bucket (for v in
 * [2^SRGB_LOG_MIN, 1)). */
static inline uint64_t bits_of(double v)
{
	uint64_t b;
	memcpy(&b, &v, sizeof b);
	return b;
}

static inline size_t log_bucket_of(double v)
{
	return (size_t)((bits_of(v) >> (52 - SRGB_LOG_BITS)) - ((uint64_t)(1023 + SRGB_LOG_MIN) << SRGB_LOG_BITS));
}

/* The code of v in (0, 1) by srgb_bucket, the tables made. */
static inline uint8_t srgb8_of(double v)
{
	int code = srgb_bucket[(int)(v * SRGB_BUCKETS)];
	while (v >= srgb_threshold[code + 1])
		code++;
	return (uint8_t)code;
}

static void srgb_tables(void)
{
	srgb_threshold[0] = -INFINITY;
	for (int k = 1; k < 256; k++)
		srgb_threshold[k] = srgb8_to_linear(k - 0.5);
	srgb_threshold[256] = INFINITY;
	int code = 0;
	for (int b = 0; b < SRGB_BUCKETS; b++) {
		double v = (double)b / SRGB_BUCKETS;
		while (v >= srgb_threshold[code + 1])
			code++;
		srgb_bucket[b] = (uint8_t)code;
	}
	/* each bucket's first double, exactly: its code by srgb_bucket */
	for (size_t b = 0; b < SRGB_LOG_BUCKETS; b++) {
		uint64_t bits = ((uint64_t)(1023 + SRGB_LOG_MIN) << 52) + ((uint64_t)b << (52 - SRGB_LOG_BITS));
		double v;
		memcpy(&v, &bits, sizeof v);
		srgb_log_bucket[b] = srgb8_of(v);
	}
	for (int k = 1; k < 256; k++) {
		float f = (float)srgb_threshold[k];
		if ((double)f < srgb_threshold[k])
			f = nextafterf(f, INFINITY);
		memcpy(&srgb_threshold_f[k], &f, sizeof f);
	}
	srgb_threshold_f[256] = UINT32_MAX;
}

uint8_t linear_to_srgb8(double v)
{
	if (!(v > 0.0))
		return 0;
	if (v >= 1.0)
		return 255;
	pthread_once(&srgb_once, srgb_tables);
	return srgb8_of(v);
}

void linear_to_srgb8_n(const float *in, double gain, uint8_t *out, size_t n)
{
	pthread_once(&srgb_once, srgb_tables);
	const double low = 0x1p-13;
	_Static_assert(SRGB_LOG_MIN == -13, "low is 2^SRGB_LOG_MIN");
	if (gain == 1.0) {
		/* the floats of [2^-13, 1): their bits less those of 2^-13 below
		 * this; the rest (negative, NaN, dark, bright) as below */
		const uint32_t lo = (uint32_t)(127 + SRGB_LOG_MIN) << 23, span = ((uint32_t)127 << 23) - lo;
		const uint32_t *above = srgb_threshold_f + 1; /* above[k]: code k's upper bound */
		for (size_t i = 0; i < n; i++) {
			uint32_t b;
			memcpy(&b, &in[i], sizeof b);
			if (b - lo < span) {
				size_t code = srgb_log_bucket[(b - lo) >> (23 - SRGB_LOG_BITS)];
				code += b >= above[code];
				out[i] = (uint8_t)code;
			} else {
				double v = in[i];
				out[i] = !(v > 0.0) ? 0 : v >= 1.0 ? 255 : srgb8_of(v);
			}
		}
		return;
	}
	for (size_t i = 0; i < n; i++) {
		double v = in[i] * gain; /* linear_to_srgb8(in[i] * gain), inline */
		if (v >= low && v < 1.0) {
			/* the bucket's first value's code; at most one threshold above it */
			int code = srgb_log_bucket[log_bucket_of(v)];
			code += v >= srgb_threshold[code + 1];
			out[i] = (uint8_t)code;
		} else {
			out[i] = !(v > 0.0) ? 0 : v >= 1.0 ? 255 : srgb8_of(v);
		}
	}
}
