/* rtsh — reading images into linear RGB floats (texture.h).
 *
 * PNG, JPEG, BMP, TGA and Radiance HDR: stb_image (libstb). PPM/PGM (P2, P3,
 * P5, P6, 8 or 16 bits) and PFM (PF colour, Pf grey; the sign of the scale
 * gives the byte order, rows bottom first): our own readers, after the
 * netpbm and PFM format descriptions. XPM: libXpm reads the file; we turn
 * its colour table (#RGB, #RRGGBB, #RRRRGGGGBBBB, None and the common names)
 * into colours and fail on anything else.
 */
#include <errno.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <X11/xpm.h>
#include <stb/stb_image.h>

#include "base/dynlib.h"
#include "base/readhelp.h"
#include "rtsh/filesrc.h"
#include "rtsh/memory.h"
#include "rtsh/srgb.h"
#include "rtsh/texture.h"

/* Images larger than this (in pixels) are refused. */
#define IMAGE_MAX_PIXELS ((size_t)1 << 28)

static const char *ext_of(const char *path)
{
	const char *slash = strrchr(path, '/');
	const char *dot = strrchr(slash ? slash : path, '.');
	return dot ? dot + 1 : "";
}

enum { F_NONE, F_STB, F_PPM, F_PFM, F_XPM };

static int format_of(const char *path)
{
	static const struct {
		const char *ext;
		int f;
	} t[] = {{"png", F_STB}, {"jpg", F_STB}, {"jpeg", F_STB}, {"bmp", F_STB}, {"tga", F_STB},
	         {"hdr", F_STB}, {"ppm", F_PPM}, {"pgm", F_PPM}, {"pnm", F_PPM}, {"pfm", F_PFM},
	         {"xpm", F_XPM}};
	const char *e = ext_of(path);
	for (size_t i = 0; i < sizeof t / sizeof t[0]; i++)
		if (strcasecmp(e, t[i].ext) == 0)
			return t[i].f;
	return F_NONE;
}

bool image_format_known(const char *path)
{
	return format_of(path) != F_NONE;
}

/* 8-bit codes to floats, through a table */
static void codes_to_float(const unsigned char *in, size_t n, int comp, bool srgb, float *out)
{
	float lut[256];
	for (int i = 0; i < 256; i++)
		lut[i] = srgb ? (float)srgb8_to_linear(i) : (float)(i / 255.0);
	for (size_t i = 0; i < n; i++)
		for (int c = 0; c < 3; c++)
			out[3 * i + c] = lut[in[i * (size_t)comp + (comp >= 3 ? c : 0)]];
}

/* Bytes a pixel takes while an image is read and made a texture: the
 * decoder's (up to 3 floats), ours (3 floats) and the mip chain's (4/3 of
 * ours). */
#define IMAGE_BYTES_PER_PIXEL (12.0 + 12.0 + 4.0)

/* --- the previewer's budget (texture.h) --- */

static size_t budget;                       /* 0: none */
static _Thread_local bool budget_off;        /* image_budget_exempt */
static _Thread_local char budget_last[RT_ERROR_MSG_MAX];
static pthread_mutex_t budget_lock = PTHREAD_MUTEX_INITIALIZER;
#define BUDGET_KEEP 32
static char *budget_paths[BUDGET_KEEP];     /* the refused images, to count each once */
static size_t budget_count;
static char budget_first[RT_ERROR_MSG_MAX];

void image_budget_set(size_t pixels)
{
	budget = pixels;
}

void image_budget_exempt(bool on)
{
	budget_off = on;
}

bool image_budget_refused(const rt_error *err)
{
	return err && budget_last[0] && strcmp(err->msg, budget_last) == 0;
}

size_t image_budget_report(char *first, size_t size)
{
	pthread_mutex_lock(&budget_lock);
	size_t n = budget_count;
	if (size)
		snprintf(first, size, "%s", budget_first);
	pthread_mutex_unlock(&budget_lock);
	return n;
}

static bool over_budget(const char *path, long w, long h, rt_error *err)
{
	rt_error_set(err, "%s: %ldx%ld pixels, over the preview's %zu for an image; drawn untextured", path, w, h,
	             budget);
	snprintf(budget_last, sizeof budget_last, "%s", err ? err->msg : "");
	pthread_mutex_lock(&budget_lock);
	bool seen = false;
	for (size_t i = 0; i < BUDGET_KEEP && budget_paths[i] && !seen; i++)
		seen = strcmp(budget_paths[i], path) == 0;
	if (!seen) {
		if (budget_count == 0)
			snprintf(budget_first, sizeof budget_first, "%s", budget_last);
		if (budget_count < BUDGET_KEEP)
			budget_paths[budget_count] = strdup(path); /* NULL: counted again, no harm */
		budget_count++;
	}
	pthread_mutex_unlock(&budget_lock);
	return false;
}

static bool size_ok(const char *path, long w, long h, rt_error *err)
{
	if (w <= 0 || h <= 0)
		return rt_error_set(err, "%s: the image is %ldx%ld pixels; expected a size of at least 1x1", path, w, h);
	/* the previewer's budget first: an image too large for any use is
	 * skipped by a preview as one over the budget */
	if (budget && !budget_off && (double)w * (double)h > (double)budget)
		return over_budget(path, w, h, err);
	if ((size_t)w * (size_t)h > IMAGE_MAX_PIXELS || w > 1 << 20 || h > 1 << 20)
		return rt_error_set(err, "%s: image too large: %ldx%ld pixels; expected at most 268435456 (2^28, "
		                    "16384x16384) pixels and 1048576 a side", path, w, h);
	/* the decoder's pixels (floats for HDR), ours, and the mip chain's
	 * third more (texture.c) */
	char what[300];
	snprintf(what, sizeof what, "the image %s (%ldx%ld pixels)", path, w, h);
	return mem_check((double)w * (double)h * IMAGE_BYTES_PER_PIXEL, what, err);
}

/* The size a PNG, JPEG, BMP or Radiance HDR header gives, read here: for an
 * image over its own limits stb_image says only "unknown image type" (its
 * PNG reader refuses more than 2^30 decoded bytes, its JPEG reader more
 * than 2^31), and the user needs the size and ours. False when the bytes
 * are none of these or the header is cut short. After the PNG and JFIF
 * specifications and Ward's RGBE format note. */
static uint32_t be16(const unsigned char *p) { return (uint32_t)p[0] << 8 | p[1]; }
static uint32_t be32(const unsigned char *p) { return be16(p) << 16 | be16(p + 2); }
static uint32_t le32(const unsigned char *p) { return (uint32_t)p[3] << 24 | (uint32_t)p[2] << 16 | (uint32_t)p[1] << 8 | p[0]; }

static bool header_size(const unsigned char *b, size_t len, long *w, long *h)
{
	if (len >= 24 && memcmp(b, "\x89PNG\r\n\x1a\n", 8) == 0 && memcmp(b + 12, "IHDR", 4) == 0) {
		*w = (long)be32(b + 16);
		*h = (long)be32(b + 20);
		return true;
	}
	if (len >= 26 && b[0] == 'B' && b[1] == 'M' && le32(b + 14) >= 40) {
		*w = (long)(int32_t)le32(b + 18);
		*h = labs((long)(int32_t)le32(b + 22));
		return true;
	}
	if (len >= 4 && b[0] == 0xff && b[1] == 0xd8) { /* JPEG: the segments up to a frame header */
		size_t i = 2;
		while (i + 4 <= len && b[i] == 0xff) {
			unsigned m = b[i + 1];
			if (m == 0xff) { /* fill byte */
				i++;
				continue;
			}
			size_t seg = be16(b + i + 2);
			if (m >= 0xc0 && m <= 0xcf && m != 0xc4 && m != 0xc8 && m != 0xcc) {
				if (i + 9 > len)
					return false;
				*h = (long)be16(b + i + 5);
				*w = (long)be16(b + i + 7);
				return true;
			}
			i += 2 + seg;
		}
		return false;
	}
	if (len >= 2 && b[0] == '#' && b[1] == '?') { /* Radiance: after the blank line, "-Y H +X W" */
		const unsigned char *e = b + len, *s = b;
		while (s + 1 < e && !(s[0] == '\n' && s[1] == '\n'))
			s++;
		char axis[2][3];
		long a, c;
		char line[96];
		size_t n = s + 2 < e ? (size_t)(e - s - 2) : 0;
		if (n == 0)
			return false;
		n = n < sizeof line - 1 ? n : sizeof line - 1;
		memcpy(line, s + 2, n);
		line[n] = '\0';
		if (sscanf(line, "%2s %ld %2s %ld", axis[0], &a, axis[1], &c) != 4)
			return false;
		bool y_first = axis[0][1] == 'Y';
		*h = y_first ? a : c;
		*w = y_first ? c : a;
		return true;
	}
	return false;
}

/* Pixel bytes a file byte may hold, at most (read_stb). */
#define IMAGE_MAX_RATIO 4096.0

static float *read_stb(const char *path, const unsigned char *buf, size_t len, bool srgb, int *w, int *h,
                       rt_error *err)
{
	if (len > INT32_MAX) {
		rt_error_set(err, "%s: the image file is too large", path);
		return NULL;
	}
	int x = 0, y = 0, comp = 0;
	long hw, hh;
	if (!stbi_info_from_memory(buf, (int)len, &x, &y, &comp)) {
		if (!header_size(buf, len, &hw, &hh) || size_ok(path, hw, hh, err))
			rt_error_set(err, "%s: cannot decode the image: %s", path, stbi_failure_reason());
		return NULL;
	}
	if (!size_ok(path, x, y, err))
		return NULL;
	/* No format stb_image reads packs more than ~1,000 pixel bytes into one
	 * file byte (deflate's limit is 1032:1; RLE and JPEG less): a header
	 * that promises far more describes a file cut short, which some of its
	 * readers (PNM, BMP) would pad rather than refuse. */
	if ((double)x * (double)y * 3 > IMAGE_MAX_RATIO * (double)len + 65536.0) {
		rt_error_set(err, "%s: the header says %dx%d pixels, more than its %zu bytes can hold; expected a "
		             "complete image", path, x, y, len);
		return NULL;
	}
	/* decoded first, our floats after: a header that promises more than the
	 * file holds fails in the decoder before the big float buffer exists */
	size_t n;
	float *out = NULL;
	if (stbi_is_hdr_from_memory(buf, (int)len)) {
		float *f = stbi_loadf_from_memory(buf, (int)len, &x, &y, &comp, 3);
		if (!f) {
			rt_error_set(err, "%s: cannot decode the image: %s", path, stbi_failure_reason());
			return NULL;
		}
		n = (size_t)x * (size_t)y * 3; /* the decoder's own size */
		out = malloc(n * sizeof *out);
		if (out)
			memcpy(out, f, n * sizeof *out);
		stbi_image_free(f);
	} else {
		unsigned char *c = stbi_load_from_memory(buf, (int)len, &x, &y, &comp, 3);
		if (!c) {
			rt_error_set(err, "%s: cannot decode the image: %s", path, stbi_failure_reason());
			return NULL;
		}
		n = (size_t)x * (size_t)y * 3;
		out = malloc(n * sizeof *out);
		if (out)
			codes_to_float(c, n / 3, 3, srgb, out);
		stbi_image_free(c);
	}
	if (!out) {
		rt_error_set(err, "%s: out of memory (%dx%d image)", path, x, y);
		return NULL;
	}
	*w = x;
	*h = y;
	return out;
}

/* The alpha channel of a PNG, TGA or BMP (stb_image): codes / 255, linear
 * (never sRGB-decoded), bytes top row first. */
static bool read_stb_alpha(const char *path, const unsigned char *buf, size_t len, unsigned char **alpha, int *w,
                           int *h, rt_error *err)
{
	int x = 0, y = 0, comp = 0;
	long hw, hh;
	if (len <= INT32_MAX && !stbi_info_from_memory(buf, (int)len, &x, &y, &comp) &&
	    header_size(buf, len, &hw, &hh) && !size_ok(path, hw, hh, err))
		return false;
	if (len > INT32_MAX || !stbi_info_from_memory(buf, (int)len, &x, &y, &comp))
		return rt_error_set(err, "%s: cannot decode the image: %s", path,
		                    len > INT32_MAX ? "too large" : stbi_failure_reason());
	if (comp != 2 && comp != 4)
		return true; /* grey or RGB: opaque */
	if (!size_ok(path, x, y, err))
		return false;
	if ((double)x * (double)y * comp > IMAGE_MAX_RATIO * (double)len + 65536.0)
		return rt_error_set(err, "%s: the header says %dx%d pixels, more than its %zu bytes can hold; expected a "
		                    "complete image", path, x, y, len);
	unsigned char *c = stbi_load_from_memory(buf, (int)len, &x, &y, &comp, comp);
	if (!c)
		return rt_error_set(err, "%s: cannot decode the image: %s", path, stbi_failure_reason());
	size_t n = (size_t)x * (size_t)y;
	unsigned char *a = malloc(n);
	if (a)
		for (size_t i = 0; i < n; i++)
			a[i] = c[i * (size_t)comp + (size_t)comp - 1];
	stbi_image_free(c);
	if (!a)
		return rt_error_set(err, "%s: out of memory (%dx%d image)", path, x, y);
	*alpha = a;
	*w = x;
	*h = y;
	return true;
}

/* --- netpbm --- */

typedef struct pnm {
	const unsigned char *s, *end, *start;
	const char *path;
} pnm;

static bool pnm_int(pnm *p, long *v)
{
	p->s = skip_space(p->s, p->end, true, NULL);
	const char *c = (const char *)p->s;
	if (!scan_long(&c, (const char *)p->end, v))
		return false;
	p->s = (const unsigned char *)c;
	return true;
}

static float *read_ppm(const char *path, const unsigned char *buf, size_t len, bool srgb, int *w, int *h,
                       rt_error *err)
{
	pnm p = {buf, buf + len, buf, path};
	if (len < 2 || buf[0] != 'P' || !strchr("2356", buf[1])) {
		rt_error_set(err, "%s: not a PPM/PGM image; expected P2, P3, P5 or P6 first", path);
		return NULL;
	}
	char kind = (char)buf[1];
	p.s += 2;
	long x, y, maxv;
	if (!pnm_int(&p, &x) || !pnm_int(&p, &y) || !pnm_int(&p, &maxv)) {
		rt_error_set(err, "%s: byte %zu: a bad header; expected WIDTH HEIGHT MAXVAL", path,
		             (size_t)(p.s - buf));
		return NULL;
	}
	if (!size_ok(path, x, y, err))
		return NULL;
	if (maxv < 1 || maxv > 65535) {
		rt_error_set(err, "%s: maxval %ld; expected 1..65535", path, maxv);
		return NULL;
	}
	bool color = kind == '3' || kind == '6', binary = kind == '5' || kind == '6';
	int comp = color ? 3 : 1, bps = maxv > 255 ? 2 : 1;
	size_t n = (size_t)x * (size_t)y;
	if (binary) {
		if (p.s >= p.end) {
			rt_error_set(err, "%s: byte %zu: the file ends after the header (truncated?); expected pixel data",
			             path, len);
			return NULL;
		}
		p.s++; /* the one blank after maxval */
		if ((size_t)(p.end - p.s) / ((size_t)comp * (size_t)bps) < n) {
			rt_error_set(err, "%s: byte %zu: the pixel data ends early (truncated?); expected %zu bytes",
			             path, (size_t)(p.end - buf), n * (size_t)comp * (size_t)bps);
			return NULL;
		}
	} else if ((size_t)(p.end - p.s) / 2 < n * (size_t)comp / 2) {
		rt_error_set(err, "%s: the file is too short for a %ldx%ld image (truncated?)", path, x, y);
		return NULL;
	}
	float *out = malloc(n * 3 * sizeof *out);
	if (!out) {
		rt_error_set(err, "%s: out of memory (%ldx%ld image)", path, x, y);
		return NULL;
	}
	for (size_t i = 0; i < n; i++) {
		if (read_poll()) { /* Ctrl-C: every 4096 pixels */
			free(out);
			rt_error_set(err, "stopped");
			return NULL;
		}
		for (int c = 0; c < comp; c++) {
			long v;
			if (binary) {
				v = bps == 2 ? (long)p.s[0] << 8 | p.s[1] : p.s[0];
				p.s += bps;
			} else if (!pnm_int(&p, &v)) {
				free(out);
				rt_error_set(err, "%s: byte %zu: expected pixel value %zu of %zu", path, (size_t)(p.s - buf),
				             i * (size_t)comp + (size_t)c + 1, n * (size_t)comp);
				return NULL;
			}
			double f = (double)(v < 0 ? 0 : v > maxv ? maxv : v) / (double)maxv;
			float lf = srgb ? (float)srgb_to_linear(f) : (float)f;
			if (comp == 1)
				out[3 * i] = out[3 * i + 1] = out[3 * i + 2] = lf;
			else
				out[3 * i + (size_t)c] = lf;
		}
	}
	*w = (int)x;
	*h = (int)y;
	return out;
}

static float *read_pfm(const char *path, const unsigned char *buf, size_t len, int *w, int *h, rt_error *err)
{
	pnm p = {buf, buf + len, buf, path};
	if (len < 2 || buf[0] != 'P' || (buf[1] != 'F' && buf[1] != 'f')) {
		rt_error_set(err, "%s: not a PFM image; expected PF or Pf first", path);
		return NULL;
	}
	int comp = buf[1] == 'F' ? 3 : 1;
	p.s += 2;
	long x, y;
	double scale;
	if (!pnm_int(&p, &x) || !pnm_int(&p, &y)) {
		rt_error_set(err, "%s: a bad header; expected WIDTH HEIGHT SCALE", path);
		return NULL;
	}
	while (p.s < p.end && (*p.s == ' ' || *p.s == '\n' || *p.s == '\r' || *p.s == '\t'))
		p.s++;
	const char *c = (const char *)p.s;
	if (!scan_double(&c, (const char *)p.end, &scale) || scale == 0 || !isfinite(scale)) {
		rt_error_set(err, "%s: a bad scale; expected a non-zero number (negative: little-endian)", path);
		return NULL;
	}
	p.s = (const unsigned char *)c + 1;
	if (!size_ok(path, x, y, err))
		return NULL;
	size_t n = (size_t)x * (size_t)y;
	if (p.s > p.end || (size_t)(p.end - p.s) / (4 * (size_t)comp) < n) {
		rt_error_set(err, "%s: byte %zu: the pixel data ends early (truncated?); expected %zu bytes", path, len,
		             n * 4 * (size_t)comp);
		return NULL;
	}
	float *out = malloc(n * 3 * sizeof *out);
	if (!out) {
		rt_error_set(err, "%s: out of memory (%ldx%ld image)", path, x, y);
		return NULL;
	}
	bool little = scale < 0;
	for (long row = 0; row < y; row++) {
		if (read_cancelled()) { /* Ctrl-C */
			free(out);
			rt_error_set(err, "stopped");
			return NULL;
		}
		long dst = y - 1 - row; /* the file's rows run bottom to top */
		for (long col = 0; col < x; col++)
			for (int k = 0; k < comp; k++) {
				unsigned char b[4];
				memcpy(b, p.s, 4);
				p.s += 4;
				uint32_t u = little ? (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24
				                    : (uint32_t)b[3] | (uint32_t)b[2] << 8 | (uint32_t)b[1] << 16 | (uint32_t)b[0] << 24;
				float f;
				memcpy(&f, &u, 4);
				if (!isfinite(f))
					f = 0;
				size_t o = 3 * ((size_t)dst * (size_t)x + (size_t)col);
				if (comp == 1)
					out[o] = out[o + 1] = out[o + 2] = f;
				else
					out[o + (size_t)k] = f;
			}
	}
	*w = (int)x;
	*h = (int)y;
	return out;
}

/* --- XPM --- */

static int hexval(char c)
{
	if (c >= '0' && c <= '9')
		return c - '0';
	c = (char)(c | 0x20);
	return c >= 'a' && c <= 'f' ? c - 'a' + 10 : -1;
}

static bool xpm_color(const char *s, float rgb[3], bool srgb)
{
	static const struct {
		const char *name;
		unsigned char c[3];
	} names[] = {{"black", {0, 0, 0}},       {"white", {255, 255, 255}}, {"red", {255, 0, 0}},
	             {"green", {0, 255, 0}},     {"blue", {0, 0, 255}},      {"yellow", {255, 255, 0}},
	             {"cyan", {0, 255, 255}},    {"magenta", {255, 0, 255}}, {"gray", {190, 190, 190}},
	             {"grey", {190, 190, 190}},  {"orange", {255, 165, 0}},  {"brown", {165, 42, 42}}};
	if (!s)
		return false;
	double c[3];
	if (strcasecmp(s, "none") == 0) {
		c[0] = c[1] = c[2] = 0;
	} else if (s[0] == '#') {
		size_t n = strlen(s + 1);
		if (n != 3 && n != 6 && n != 12)
			return false;
		size_t d = n / 3;
		for (int k = 0; k < 3; k++) {
			double v = 0;
			for (size_t i = 0; i < d; i++) {
				int h = hexval(s[1 + k * d + i]);
				if (h < 0)
					return false;
				v = v * 16 + h;
			}
			c[k] = v / (pow(16.0, (double)d) - 1) * 255.0;
		}
	} else {
		size_t i = 0;
		while (i < sizeof names / sizeof names[0] && strcasecmp(names[i].name, s) != 0)
			i++;
		if (i == sizeof names / sizeof names[0])
			return false;
		for (int k = 0; k < 3; k++)
			c[k] = names[i].c[k];
	}
	for (int k = 0; k < 3; k++)
		rgb[k] = srgb ? (float)srgb_to_linear(c[k] / 255.0) : (float)(c[k] / 255.0);
	return true;
}

/* libXpm, opened on the first XPM image (base/dynlib.h): it brings five X11
 * libraries that no other start-up needs. */
#ifndef RTSH_XPM_SONAME
#define RTSH_XPM_SONAME "libXpm.so.4"
#endif

static struct {
	int (*create_from_buffer)(char *buffer, XpmImage *image, XpmInfo *info);
	void (*free_image)(XpmImage *image);
	char *(*error_string)(int errcode);
} xpm;
static dynlib_lazy xpm_lazy = DYNLIB_LAZY;

static void xpm_open(void)
{
	const dynlib_fn fns[] = {
	    {"XpmCreateXpmImageFromBuffer", &xpm.create_from_buffer},
	    {"XpmFreeXpmImage", &xpm.free_image},
	    {"XpmGetErrorString", &xpm.error_string},
	};
	xpm_lazy.ok = dynlib_open(RTSH_XPM_SONAME, fns, sizeof fns / sizeof fns[0], xpm_lazy.why, sizeof xpm_lazy.why);
}

static float *read_xpm(const char *path, const unsigned char *buf, size_t len, bool srgb, int *w, int *h,
                       rt_error *err)
{
	/* the values line ("W H NCOLORS CPP"), checked against the file's size
	 * before libXpm allocates what it promises */
	const unsigned char *q = memchr(buf, '"', len);
	long v[4] = {0, 0, 0, 0};
	const char *vc = q ? (const char *)q + 1 : NULL, *end = (const char *)buf + len;
	for (int k = 0; vc && k < 4; k++) {
		while (vc < end && (*vc == ' ' || *vc == '\t'))
			vc++;
		if (!scan_long(&vc, end, &v[k]))
			vc = NULL;
	}
	if (!vc) {
		rt_error_set(err, "%s: no XPM values line; expected \"WIDTH HEIGHT NCOLORS CHARS_PER_PIXEL\"", path);
		return NULL;
	}
	if (!size_ok(path, v[0], v[1], err))
		return NULL;
	if (v[3] < 1 || v[3] > 8 || v[2] < 1 || (size_t)v[2] > len / ((size_t)v[3] + 4) ||
	    (size_t)v[0] * (size_t)v[1] > len / (size_t)v[3]) {
		rt_error_set(err, "%s: the XPM values line promises %ldx%ld pixels, %ld colours, %ld characters "
		             "per pixel: more than the file holds", path, v[0], v[1], v[2], v[3]);
		return NULL;
	}
	pthread_once(&xpm_lazy.once, xpm_open);
	if (!xpm_lazy.ok) {
		rt_error_set(err, "%s: cannot read the XPM image: libXpm cannot be loaded (%s); expected %s installed",
		             path, xpm_lazy.why, RTSH_XPM_SONAME);
		return NULL;
	}
	char *text = malloc(len + 1);
	if (!text) {
		rt_error_set(err, "%s: out of memory", path);
		return NULL;
	}
	memcpy(text, buf, len);
	text[len] = '\0';
	XpmImage img;
	memset(&img, 0, sizeof img);
	int rc = xpm.create_from_buffer(text, &img, NULL);
	free(text);
	if (rc != XpmSuccess) {
		xpm.free_image(&img); /* what libXpm left allocated (it may leave some) */
		rt_error_set(err, "%s: cannot read the XPM image: %s", path, xpm.error_string(rc));
		return NULL;
	}
	float *out = NULL;
	float(*table)[3] = NULL;
	if (!size_ok(path, (long)img.width, (long)img.height, err))
		goto done;
	if (img.ncolors == 0) {
		rt_error_set(err, "%s: the XPM colour table is empty; expected at least one colour", path);
		goto done;
	}
	table = malloc(img.ncolors * sizeof *table);
	out = malloc((size_t)img.width * img.height * 3 * sizeof *out);
	if (!table || !out) {
		free(out);
		out = NULL;
		rt_error_set(err, "%s: out of memory", path);
		goto done;
	}
	for (unsigned i = 0; i < img.ncolors; i++) {
		const XpmColor *c = &img.colorTable[i];
		const char *spec = c->c_color ? c->c_color : c->g_color ? c->g_color : c->g4_color ? c->g4_color : c->m_color;
		if (!xpm_color(spec, table[i], srgb)) {
			free(out);
			out = NULL;
			rt_error_set(err, "%s: XPM colour %u (\"%s\") is \"%s\"; expected #RGB, #RRGGBB, "
			             "None or a basic colour name", path, i + 1, c->string ? c->string : "",
			             spec ? spec : "(none)");
			goto done;
		}
	}
	for (size_t i = 0; i < (size_t)img.width * img.height; i++) {
		unsigned k = img.data[i];
		if (k >= img.ncolors) {
			free(out);
			out = NULL;
			rt_error_set(err, "%s: XPM pixel %zu uses colour %u of %u", path, i, k + 1, img.ncolors);
			goto done;
		}
		memcpy(&out[3 * i], table[k], sizeof *table);
	}
	*w = (int)img.width;
	*h = (int)img.height;
done:
	free(table);
	xpm.free_image(&img);
	return out;
}

float *image_decode_rgb(const char *path, const unsigned char *buf, size_t len, bool srgb, int *w, int *h,
                        rt_error *err)
{
	int f = format_of(path);
	/* stb_image goes by the content: a binary PNM under another name is
	 * read by our reader, which checks that its pixels are all there */
	if (f == F_STB && len >= 2 && buf[0] == 'P' && (buf[1] == '5' || buf[1] == '6'))
		f = F_PPM;
	switch (f) {
	case F_STB:
		return read_stb(path, buf, len, srgb, w, h, err);
	case F_PPM:
		return read_ppm(path, buf, len, srgb, w, h, err);
	case F_PFM:
		return read_pfm(path, buf, len, w, h, err);
	case F_XPM:
		return read_xpm(path, buf, len, srgb, w, h, err);
	default:
		if (!*ext_of(path))
			rt_error_set(err, "%s: the name has no extension; expected .png .jpg .jpeg .bmp .tga .hdr .ppm "
			             ".pgm .pfm or .xpm", path);
		else
			rt_error_set(err, "%s: unknown image format \".%s\"; expected .png .jpg .jpeg .bmp .tga .hdr "
			             ".ppm .pgm .pfm or .xpm", path, ext_of(path));
		return NULL;
	}
}

float *image_load_netpbm(const char *path, bool pfm, int *w, int *h, rt_error *err)
{
	size_t len;
	char *buf = rt_file_read_disk(path, "image", &len, err);
	if (!buf)
		return NULL;
	const unsigned char *b = (const unsigned char *)buf;
	float *out = pfm ? read_pfm(path, b, len, w, h, err) : read_ppm(path, b, len, true, w, h, err);
	free(buf);
	return out;
}

float *image_load_rgb(const char *path, bool srgb, int *w, int *h, rt_error *err)
{
	if (format_of(path) == F_NONE)
		return image_decode_rgb(path, NULL, 0, srgb, w, h, err);
	size_t len;
	char *buf = rt_file_read(path, "image", &len, err);
	if (!buf)
		return NULL;
	float *out = image_decode_rgb(path, (const unsigned char *)buf, len, srgb, w, h, err);
	free(buf);
	return out;
}

bool image_decode_alpha(const char *path, const unsigned char *buf, size_t len, unsigned char **alpha, int *w, int *h,
                        rt_error *err)
{
	*alpha = NULL;
	*w = *h = 0;
	int f = format_of(path);
	if (f == F_STB && len >= 2 && buf[0] == 'P' && (buf[1] == '5' || buf[1] == '6'))
		f = F_PPM;
	if (f != F_STB || stbi_is_hdr_from_memory(buf, len > INT32_MAX ? 0 : (int)len))
		return true; /* PPM, PFM, XPM, HDR, JPEG (stb says 3): no alpha */
	return read_stb_alpha(path, buf, len, alpha, w, h, err);
}
