/* rtsh — sRGB decode and encode (srgb.h). */
#include "rtsh/srgb.h"

#include <math.h>
#include <pthread.h>

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

double srgb8_to_linear(double code)
{
	if (code >= 0.0 && code <= 255.0 && code == (double)(int)code) {
		pthread_once(&decode_once, decode_table_init);
		return decode_table[(int)code];
	}
	return srgb_to_linear(code / 255.0);
}

vec3 srgb255_to_linear(vec3 c)
{
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
 * buckets over [0,1) gives the code at the start of each bucket, and at most
 * a step or two up the thresholds finds the code: no pow() per pixel, which
 * matters for every terminal frame. */
#define SRGB_BUCKETS 4096

static double srgb_threshold[257];
static uint8_t srgb_bucket[SRGB_BUCKETS];
static pthread_once_t srgb_once = PTHREAD_ONCE_INIT;

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
}

/* The code of v in (0, 1), the tables made. */
static inline uint8_t srgb8_of(double v)
{
	int code = srgb_bucket[(int)(v * SRGB_BUCKETS)];
	while (v >= srgb_threshold[code + 1])
		code++;
	return (uint8_t)code;
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
	for (size_t i = 0; i < n; i++) {
		double v = in[i] * gain; /* linear_to_srgb8(in[i] * gain), inline */
		out[i] = !(v > 0.0) ? 0 : v >= 1.0 ? 255 : srgb8_of(v);
	}
}
