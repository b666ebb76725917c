/* rtsh-mpi — the job's configuration, field by field (wire.h). */
#include "mpi/wire.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* The fields wire.c sends, in the order render.h declares them: when
 * render_settings gains a field this stops compiling, so that the new field
 * is sent too (add it to the encoder, decoder, test and WIRE_VERSION). */
struct settings_fields {
	int width, height, samples, depth, threads;
	render_mode mode;
	uint64_t seed;
	double exposure;
	int denoise, pixels, symbols;
};
_Static_assert(sizeof(render_settings) == sizeof(struct settings_fields),
               "render_settings changed: send the new field in src/mpi/wire.c");
_Static_assert(sizeof(double) == 8 && sizeof(uint64_t) == 8, "doubles are sent as 64 bits");

static const unsigned char magic[8] = "RTSHMPI";

typedef struct writer {
	unsigned char *p;
} writer;

static void put_u32(writer *w, uint32_t v)
{
	for (int i = 0; i < 4; i++)
		*w->p++ = (unsigned char)(v >> (8 * i));
}

static void put_u64(writer *w, uint64_t v)
{
	for (int i = 0; i < 8; i++)
		*w->p++ = (unsigned char)(v >> (8 * i));
}

static void put_i32(writer *w, int32_t v)
{
	put_u32(w, (uint32_t)v);
}

static void put_f64(writer *w, double v)
{
	uint64_t bits;
	memcpy(&bits, &v, sizeof bits);
	put_u64(w, bits);
}

typedef struct reader {
	const unsigned char *p, *end;
} reader;

static uint32_t get_u32(reader *r)
{
	uint32_t v = 0;
	for (int i = 0; i < 4 && r->p < r->end; i++)
		v |= (uint32_t)*r->p++ << (8 * i);
	return v;
}

static uint64_t get_u64(reader *r)
{
	uint64_t v = 0;
	for (int i = 0; i < 8 && r->p < r->end; i++)
		v |= (uint64_t)*r->p++ << (8 * i);
	return v;
}

static int32_t get_i32(reader *r)
{
	uint32_t u = get_u32(r);
	return u <= INT32_MAX ? (int32_t)u : (int32_t)(u - INT32_MAX - 1) - INT32_MAX - 1;
}

static double get_f64(reader *r)
{
	uint64_t bits = get_u64(r);
	double v;
	memcpy(&v, &bits, sizeof v);
	return v;
}

/* version 2's fields after the header: 7 + 6 + 3 i32, 2 u64, 1 f64 */
#define BODY_V1 (16 * 4 + 2 * 8 + 8)
#define HEADER (8 + 4 + 4)
_Static_assert(HEADER + BODY_V1 <= WIRE_CONFIG_SIZE, "the configuration fits its buffer");

void wire_put_config(const job_config *c, unsigned char buf[WIRE_CONFIG_SIZE])
{
	memset(buf, 0, WIRE_CONFIG_SIZE);
	memcpy(buf, magic, sizeof magic);
	writer w = {buf + sizeof magic};
	put_u32(&w, WIRE_VERSION);
	put_u32(&w, BODY_V1);
	put_i32(&w, c->status);
	put_i32(&w, c->verbose);
	put_i32(&w, c->progress);
	put_i32(&w, c->strict);
	put_i32(&w, c->tile);
	put_i32(&w, c->prefetch);
	put_i32(&w, c->delay_us);
	const render_settings *s = &c->set;
	put_i32(&w, s->width);
	put_i32(&w, s->height);
	put_i32(&w, s->samples);
	put_i32(&w, s->depth);
	put_i32(&w, s->threads);
	put_i32(&w, (int32_t)s->mode);
	put_u64(&w, s->seed);
	put_f64(&w, s->exposure);
	put_i32(&w, s->denoise);
	put_i32(&w, s->pixels);
	put_i32(&w, s->symbols);
	put_u64(&w, c->files);
}

/* Checks lo <= v <= hi, else says so in why. */
static bool in_range(const char *name, long long v, long long lo, long long hi, char *why, size_t n)
{
	if (v >= lo && v <= hi)
		return true;
	snprintf(why, n, "the settings rank 0 sent have %s = %lld; expected %lld..%lld", name, v, lo, hi);
	return false;
}

bool wire_get_config(job_config *c, const unsigned char buf[WIRE_CONFIG_SIZE], char *why,
                     size_t whylen)
{
	if (memcmp(buf, magic, sizeof magic) != 0) {
		snprintf(why, whylen, "the settings rank 0 sent do not begin with \"RTSHMPI\"; "
		                      "expected rtsh-mpi on every rank");
		return false;
	}
	reader r = {buf + sizeof magic, buf + WIRE_CONFIG_SIZE};
	uint32_t version = get_u32(&r), len = get_u32(&r);
	if (version != WIRE_VERSION || len != BODY_V1) {
		snprintf(why, whylen, "rank 0 sent settings of version %u (%u bytes); expected version %d "
		         "(%d bytes): run the same rtsh-mpi on every node", (unsigned)version, (unsigned)len,
		         WIRE_VERSION, BODY_V1);
		return false;
	}
	job_config k;
	memset(&k, 0, sizeof k);
	k.status = get_i32(&r);
	k.verbose = get_i32(&r);
	k.progress = get_i32(&r);
	k.strict = get_i32(&r);
	k.tile = get_i32(&r);
	k.prefetch = get_i32(&r);
	k.delay_us = get_i32(&r);
	render_settings *s = &k.set;
	s->width = get_i32(&r);
	s->height = get_i32(&r);
	s->samples = get_i32(&r);
	s->depth = get_i32(&r);
	s->threads = get_i32(&r);
	int32_t mode = get_i32(&r);
	s->seed = get_u64(&r);
	s->exposure = get_f64(&r);
	s->denoise = get_i32(&r);
	s->pixels = get_i32(&r);
	s->symbols = get_i32(&r);
	k.files = get_u64(&r);
	bool ok = in_range("status", k.status, -1, 255, why, whylen) &&
	          in_range("tile", k.tile, 0, 1024, why, whylen) &&
	          in_range("prefetch", k.prefetch, -1, 1024, why, whylen) &&
	          in_range("delay_us", k.delay_us, 0, 10000000, why, whylen) &&
	          in_range("mode", mode, MODE_WHITTED, MODE_PATH, why, whylen) &&
	          in_range("denoise", s->denoise, DENOISE_AUTO, DENOISE_OFF, why, whylen) &&
	          in_range("threads", s->threads, 0, INT32_MAX, why, whylen) &&
	          in_range("depth", s->depth, 0, INT32_MAX, why, whylen) &&
	          in_range("pixels", s->pixels, 0, INT32_MAX, why, whylen) &&
	          in_range("symbols", s->symbols, 0, INT32_MAX, why, whylen);
	if (ok && k.status < 0) /* a job to render: an image of a size fb_new takes */
		ok = in_range("width", s->width, 1, RENDER_MAX_DIM, why, whylen) &&
		     in_range("height", s->height, 1, RENDER_MAX_DIM, why, whylen) &&
		     in_range("samples", s->samples, 1, INT32_MAX, why, whylen);
	if (ok && !isfinite(s->exposure)) {
		snprintf(why, whylen, "the settings rank 0 sent have exposure = %g; expected a finite number",
		         s->exposure);
		ok = false;
	}
	if (!ok)
		return false;
	s->mode = (render_mode)mode;
	k.verbose = k.verbose != 0;
	k.progress = k.progress != 0;
	k.strict = k.strict != 0;
	*c = k;
	return true;
}
