/* rtsh-mpi — the job's configuration, field by field (wire.h). */
#include "mpi/wire.h"

#include "rtsh/settings.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

_Static_assert(sizeof(double) == 8 && sizeof(uint64_t) == 8, "doubles are sent as 64 bits");

static const unsigned char magic[8] = "RTSHMPI";

typedef struct writer {
	unsigned char *p, *end;
} writer;

static void put_u32(writer *w, uint32_t v)
{
	for (int i = 0; i < 4 && w->p < w->end; i++)
		*w->p++ = (unsigned char)(v >> (8 * i));
}

static void put_u64(writer *w, uint64_t v)
{
	for (int i = 0; i < 8 && w->p < w->end; i++)
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

/* Checks lo <= v <= hi, else says so in why. */
static bool in_range(const char *name, long long v, long long lo, long long hi, char *why, size_t n)
{
	if (v >= lo && v <= hi)
		return true;
	snprintf(why, n, "the settings rank 0 sent have %s = %lld; expected %lld..%lld", name, v, lo, hi);
	return false;
}

/* The job's own fields: 7 i32 before the settings, a u64 after them. */
#define JOB_BYTES (7 * 4 + 8)
#define HEADER (8 + 4 + 4)

/* The bytes a setting takes on the wire (settings.h, by its type). */
static size_t setting_bytes(const setting_def *d)
{
	return d->type == SETTING_INT || d->type == SETTING_ENUM ? 4 : 8;
}

/* What ranks render with: every row of the settings table but the
 * terminal's choices. */
static bool on_wire(const setting_def *d)
{
	return !(d->flags & SETTING_TERMINAL);
}

/* The bytes after the header: the job's fields and every setting on the
 * wire, in the table's order. */
static size_t body_bytes(void)
{
	size_t n = JOB_BYTES;
	for (size_t i = 0; i < settings_count; i++)
		if (on_wire(&settings_table[i]))
			n += setting_bytes(&settings_table[i]);
	return n;
}

static void put_setting(writer *w, const render_settings *s, const setting_def *d)
{
	const char *at = (const char *)s + d->offset;
	switch (d->type) {
	case SETTING_INT:
	case SETTING_ENUM:
		put_i32(w, settings_get_int(s, d));
		return;
	case SETTING_U64: {
		uint64_t v;
		memcpy(&v, at, sizeof v);
		put_u64(w, v);
		return;
	}
	case SETTING_DOUBLE: {
		double v;
		memcpy(&v, at, sizeof v);
		put_f64(w, v);
		return;
	}
	case SETTING_RESOLUTION:
		put_i32(w, s->width);
		put_i32(w, s->height);
		return;
	}
}

/* Reads a setting into s; false (why says so) when its value is out of the
 * table's range and check is set. */
static bool get_setting(reader *r, render_settings *s, const setting_def *d, bool check, char *why, size_t n)
{
	char *at = (char *)s + d->offset;
	switch (d->type) {
	case SETTING_INT: {
		int32_t v = get_i32(r);
		settings_put_int(s, d, v);
		return !check || in_range(d->name, v, (long long)d->min, (long long)d->max, why, n);
	}
	case SETTING_ENUM: {
		int32_t v = get_i32(r);
		settings_put_int(s, d, v);
		return in_range(d->name, v, 0, settings_choices(d) - 1, why, n);
	}
	case SETTING_U64: {
		uint64_t v = get_u64(r);
		memcpy(at, &v, sizeof v);
		return true;
	}
	case SETTING_DOUBLE: {
		double v = get_f64(r);
		memcpy(at, &v, sizeof v);
		if (!check || (isfinite(v) && v >= d->min && v <= d->max))
			return true;
		snprintf(why, n, "the settings rank 0 sent have %s = %g; expected a number in %g..%g", d->name, v,
		         d->min, d->max);
		return false;
	}
	case SETTING_RESOLUTION:
		s->width = get_i32(r);
		s->height = get_i32(r);
		return !check || (in_range("width", s->width, (long long)d->min, (long long)d->max, why, n) &&
		                  in_range("height", s->height, (long long)d->min, (long long)d->max, why, n));
	}
	return true;
}

void wire_put_config(const job_config *c, unsigned char buf[WIRE_CONFIG_SIZE])
{
	memset(buf, 0, WIRE_CONFIG_SIZE);
	memcpy(buf, magic, sizeof magic);
	writer w = {buf + sizeof magic, buf + WIRE_CONFIG_SIZE};
	put_u32(&w, WIRE_VERSION);
	put_u32(&w, (uint32_t)body_bytes()); /* more than fits: wire_get_config refuses */
	put_i32(&w, c->status);
	put_i32(&w, c->verbose);
	put_i32(&w, c->progress);
	put_i32(&w, c->strict);
	put_i32(&w, c->tile);
	put_i32(&w, c->prefetch);
	put_i32(&w, c->delay_us);
	for (size_t i = 0; i < settings_count; i++)
		if (on_wire(&settings_table[i]))
			put_setting(&w, &c->set, &settings_table[i]);
	put_u64(&w, c->files);
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
	size_t want = body_bytes();
	if (version != WIRE_VERSION || len != want || HEADER + want > WIRE_CONFIG_SIZE) {
		snprintf(why, whylen, "rank 0 sent settings of version %u (%u bytes); expected version %d "
		         "(%zu bytes, at most %d): run the same rtsh-mpi on every node", (unsigned)version,
		         (unsigned)len, WIRE_VERSION, want, WIRE_CONFIG_SIZE - HEADER);
		return false;
	}
	job_config k;
	memset(&k, 0, sizeof k);
	k.set = render_settings_default(); /* the terminal's choices: not sent */
	k.status = get_i32(&r);
	k.verbose = get_i32(&r);
	k.progress = get_i32(&r);
	k.strict = get_i32(&r);
	k.tile = get_i32(&r);
	k.prefetch = get_i32(&r);
	k.delay_us = get_i32(&r);
	bool ok = true;
	/* the settings of a job to render are checked against the table's
	 * ranges; a job that only ends the ranks (status >= 0) uses none */
	for (size_t i = 0; i < settings_count; i++)
		if (on_wire(&settings_table[i]))
			ok = get_setting(&r, &k.set, &settings_table[i], k.status < 0, ok ? why : NULL, ok ? whylen : 0) && ok;
	k.files = get_u64(&r);
	ok = ok && in_range("status", k.status, -1, 255, why, whylen) &&
	     in_range("tile", k.tile, 0, 1024, why, whylen) &&
	     in_range("prefetch", k.prefetch, -1, 1024, why, whylen) &&
	     in_range("delay_us", k.delay_us, 0, 10000000, why, whylen);
	if (!ok)
		return false;
	k.verbose = k.verbose != 0;
	k.progress = k.progress != 0;
	k.strict = k.strict != 0;
	*c = k;
	return true;
}
