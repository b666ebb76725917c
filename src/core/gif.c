/* rtsh — animated GIF files (rtsh/gif.h). */
#include "rtsh/gif.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rtsh/atomic.h"
#include "rtsh/memory.h"
#include "rtsh/srgb.h"

struct gif_anim {
	int w, h, delay;
	uint8_t *buf;
	size_t len, cap;
	bool failed, trailer;
	uint8_t *idx;      /* one frame's palette indices */
	uint8_t pal[768];
};

/* --- the byte buffer --- */

static void put(gif_anim *g, const void *p, size_t n)
{
	if (g->failed)
		return;
	if (g->len + n > g->cap) {
		size_t cap = g->cap ? g->cap : 65536;
		while (cap < g->len + n)
			cap *= 2;
		uint8_t *b = realloc(g->buf, cap);
		if (!b) {
			g->failed = true;
			return;
		}
		g->buf = b;
		g->cap = cap;
	}
	memcpy(g->buf + g->len, p, n);
	g->len += n;
}

static void put8(gif_anim *g, unsigned v)
{
	uint8_t b = (uint8_t)v;
	put(g, &b, 1);
}

static void put16(gif_anim *g, unsigned v)
{
	put8(g, v & 0xff);
	put8(g, (v >> 8) & 0xff);
}

gif_anim *gif_new(int w, int h, int delay_cs)
{
	if (w < 1 || h < 1 || w > 65535 || h > 65535)
		return NULL;
	gif_anim *g = calloc(1, sizeof *g);
	if (!g)
		return NULL;
	g->w = w;
	g->h = h;
	g->delay = delay_cs < 0 ? 0 : delay_cs > 65535 ? 65535 : delay_cs;
	g->idx = malloc((size_t)w * h);
	if (!g->idx) {
		free(g);
		return NULL;
	}
	/* Header and logical screen: no global colour table (each frame has
	 * its own), background 0, square pixels. */
	put(g, "GIF89a", 6);
	put16(g, (unsigned)w);
	put16(g, (unsigned)h);
	put8(g, 0x70); /* colour resolution 8 bits, no global table */
	put8(g, 0);
	put8(g, 0);
	/* NETSCAPE2.0: loop for ever. */
	put(g, "\x21\xff\x0bNETSCAPE2.0\x03\x01\x00\x00\x00", 19);
	if (g->failed) {
		gif_free(g);
		return NULL;
	}
	return g;
}

void gif_free(gif_anim *g)
{
	if (g)
		mem_free_all(g->buf, g->idx, g);
}

/* --- median cut --- */

typedef struct bin {
	uint16_t key;   /* 5 bits a channel: r << 10 | g << 5 | b */
	uint32_t count;
	uint64_t sum[3];
} bin;

typedef struct cbox {
	size_t lo, hi;  /* bins [lo, hi) */
	uint64_t count;
	int axis, range;
} cbox;

/* qsort has no context argument: the axis to sort on, per thread. */
static _Thread_local int sort_axis;

static int cmp_bin(const void *a, const void *b)
{
	const bin *x = a, *y = b;
	int sh = 10 - 5 * sort_axis;
	int u = (x->key >> sh) & 31, v = (y->key >> sh) & 31;
	if (u != v)
		return u - v;
	return (int)x->key - (int)y->key; /* a total order: the same on every libc */
}

static void box_measure(cbox *c, const bin *bins)
{
	int lo[3] = {31, 31, 31}, hi[3] = {0, 0, 0};
	c->count = 0;
	for (size_t i = c->lo; i < c->hi; i++) {
		c->count += bins[i].count;
		for (int a = 0; a < 3; a++) {
			int v = (bins[i].key >> (10 - 5 * a)) & 31;
			lo[a] = v < lo[a] ? v : lo[a];
			hi[a] = v > hi[a] ? v : hi[a];
		}
	}
	c->axis = 0;
	c->range = -1;
	for (int a = 0; a < 3; a++)
		if (hi[a] - lo[a] > c->range) {
			c->range = hi[a] - lo[a];
			c->axis = a;
		}
}

int gif_quantize(const uint8_t *rgb, size_t n, int max, uint8_t *pal, uint8_t *idx)
{
	if (max < 1)
		max = 1;
	if (max > 256)
		max = 256;
	bin *bins = calloc(32768, sizeof *bins);
	uint16_t *slot = malloc(32768 * sizeof *slot); /* a key's bin after sorting */
	if (!bins || !slot) {
		free(bins);
		free(slot);
		return 0;
	}
	for (size_t i = 0; i < n; i++) {
		const uint8_t *p = rgb + 3 * i;
		unsigned k = (unsigned)(p[0] >> 3) << 10 | (unsigned)(p[1] >> 3) << 5 | (unsigned)(p[2] >> 3);
		bin *b = &bins[k];
		b->key = (uint16_t)k;
		b->count++;
		for (int a = 0; a < 3; a++)
			b->sum[a] += p[a];
	}
	/* The used bins together at the front. */
	size_t used = 0;
	for (size_t k = 0; k < 32768; k++)
		if (bins[k].count)
			bins[used++] = bins[k];
	cbox boxes[256];
	int nb = 0;
	if (used) {
		boxes[0] = (cbox){.lo = 0, .hi = used};
		box_measure(&boxes[0], bins);
		nb = 1;
	}
	/* Split the box with the most pixels (among those of more than one
	 * colour) at its median along its longest side. */
	while (nb < max) {
		int best = -1;
		for (int i = 0; i < nb; i++)
			if (boxes[i].range > 0 && (best < 0 || boxes[i].count > boxes[best].count))
				best = i;
		if (best < 0)
			break;
		cbox *c = &boxes[best];
		sort_axis = c->axis;
		qsort(bins + c->lo, c->hi - c->lo, sizeof *bins, cmp_bin);
		uint64_t half = c->count / 2, acc = 0;
		size_t cut = c->lo;
		while (cut < c->hi - 1 && acc + bins[cut].count <= half)
			acc += bins[cut++].count;
		if (cut == c->lo)
			cut++;
		cbox right = {.lo = cut, .hi = c->hi};
		c->hi = cut;
		box_measure(c, bins);
		box_measure(&right, bins);
		boxes[nb++] = right;
	}
	for (int i = 0; i < nb; i++) {
		uint64_t s[3] = {0, 0, 0}, cnt = 0;
		for (size_t j = boxes[i].lo; j < boxes[i].hi; j++) {
			for (int a = 0; a < 3; a++)
				s[a] += bins[j].sum[a];
			cnt += bins[j].count;
			slot[bins[j].key] = (uint16_t)i;
		}
		for (int a = 0; a < 3; a++)
			pal[3 * i + a] = (uint8_t)(cnt ? (s[a] + cnt / 2) / cnt : 0);
	}
	if (idx)
		for (size_t i = 0; i < n; i++) {
			const uint8_t *p = rgb + 3 * i;
			unsigned k = (unsigned)(p[0] >> 3) << 10 | (unsigned)(p[1] >> 3) << 5 | (unsigned)(p[2] >> 3);
			idx[i] = (uint8_t)slot[k];
		}
	free(bins);
	free(slot);
	return nb > 0 ? nb : 1;
}

/* --- LZW (GIF89a appendix F) --- */

typedef struct lzw {
	gif_anim *g;
	uint8_t block[256]; /* a data sub-block being filled: [0] is its length */
	uint32_t acc;
	int nbits;
} lzw;

static void lzw_byte(lzw *z, uint8_t b)
{
	z->block[1 + z->block[0]++] = b;
	if (z->block[0] == 255) {
		put(z->g, z->block, 256);
		z->block[0] = 0;
	}
}

static void lzw_code(lzw *z, unsigned code, int size)
{
	z->acc |= (uint32_t)code << z->nbits;
	z->nbits += size;
	while (z->nbits >= 8) {
		lzw_byte(z, (uint8_t)(z->acc & 0xff));
		z->acc >>= 8;
		z->nbits -= 8;
	}
}

#define LZW_HASH 8192 /* > 4096 entries: open addressing stays short */

/* Codes of min_size + 1 bits and up to 12 (the string table of prefix code
 * and byte in a hash table), a clear code when the table is full. */
static void lzw_encode(gif_anim *g, const uint8_t *idx, size_t n, int min_size)
{
	uint32_t *hk = malloc(LZW_HASH * sizeof *hk);
	uint16_t *hv = malloc(LZW_HASH * sizeof *hv);
	if (!hk || !hv) {
		free(hk);
		free(hv);
		g->failed = true;
		return;
	}
	const unsigned clear = 1u << min_size, eoi = clear + 1;
	lzw z = {.g = g};
	int size = min_size + 1;
	unsigned next = eoi + 1;
	memset(hk, 0xff, LZW_HASH * sizeof *hk);
	lzw_code(&z, clear, size);
	unsigned prefix = idx[0];
	for (size_t i = 1; i < n; i++) {
		uint8_t c = idx[i];
		uint32_t key = (uint32_t)prefix << 8 | c;
		uint32_t h = (key * 2654435761u) >> 19;
		bool found = false;
		while (hk[h] != 0xffffffffu) {
			if (hk[h] == key) {
				found = true;
				break;
			}
			h = (h + 1) & (LZW_HASH - 1);
		}
		if (found) {
			prefix = hv[h];
			continue;
		}
		lzw_code(&z, prefix, size);
		/* As the decoder sees it: the code after this one is read with
		 * one more bit once the table reaches the current size. */
		if (next >= (1u << size) && size < 12)
			size++;
		if (next < 4095) {
			hk[h] = key;
			hv[h] = (uint16_t)next++;
		} else {
			lzw_code(&z, clear, size);
			size = min_size + 1;
			next = eoi + 1;
			memset(hk, 0xff, LZW_HASH * sizeof *hk);
		}
		prefix = c;
	}
	lzw_code(&z, prefix, size);
	if (next >= (1u << size) && size < 12)
		size++;
	lzw_code(&z, eoi, size);
	if (z.nbits > 0)
		lzw_byte(&z, (uint8_t)(z.acc & 0xff));
	if (z.block[0])
		put(g, z.block, (size_t)z.block[0] + 1);
	put8(g, 0); /* the block terminator */
	free(hk);
	free(hv);
}

bool gif_add_frame(gif_anim *g, const uint8_t *rgb)
{
	if (g->failed)
		return false;
	if (g->trailer) {
		g->len--; /* the trailer goes after the last frame */
		g->trailer = false;
	}
	size_t n = (size_t)g->w * g->h;
	memset(g->pal, 0, sizeof g->pal);
	int colours = gif_quantize(rgb, n, 256, g->pal, g->idx);
	if (!colours)
		return false;
	int bits = 1; /* the local table holds 2^bits colours, 2..256 */
	while ((1 << bits) < colours)
		bits++;
	int min_size = bits < 2 ? 2 : bits;
	/* Graphic control: no disposal needed (every frame covers the
	 * screen), the delay, no transparency. */
	put(g, "\x21\xf9\x04\x04", 4);
	put16(g, (unsigned)g->delay);
	put(g, "\x00\x00", 2);
	/* Image descriptor with a local colour table. */
	put8(g, 0x2c);
	put16(g, 0);
	put16(g, 0);
	put16(g, (unsigned)g->w);
	put16(g, (unsigned)g->h);
	put8(g, 0x80 | (unsigned)(bits - 1));
	put(g, g->pal, (size_t)3 << bits);
	put8(g, (unsigned)min_size);
	lzw_encode(g, g->idx, n, min_size);
	return !g->failed;
}

bool gif_add_linear(gif_anim *g, const float *rgb, double exposure)
{
	size_t n = (size_t)g->w * g->h * 3;
	uint8_t *px = malloc(n);
	if (!px)
		return false;
	double k = exp2(exposure);
	for (size_t i = 0; i < n; i++)
		px[i] = linear_to_srgb8(rgb[i] * k);
	bool ok = gif_add_frame(g, px);
	free(px);
	return ok;
}

const uint8_t *gif_bytes(gif_anim *g, size_t *len)
{
	if (!g->trailer) {
		put8(g, 0x3b);
		g->trailer = !g->failed;
	}
	*len = g->failed ? 0 : g->len;
	return g->failed ? NULL : g->buf;
}

static bool write_gif(FILE *f, void *ctx, rt_error *err)
{
	gif_anim *g = ctx;
	size_t n;
	const uint8_t *b = gif_bytes(g, &n);
	if (!b)
		return rt_error_set(err, "out of memory for the GIF");
	if (fwrite(b, 1, n, f) != n)
		return rt_error_set(err, "cannot write the GIF");
	return true;
}

bool gif_save(gif_anim *g, const char *path, rt_error *err)
{
	return file_write_atomic(path, write_gif, g, err);
}
