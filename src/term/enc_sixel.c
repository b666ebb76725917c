/* rtsh — sixel (pixels.h), quantised and encoded by libsixel.
 *
 * A sixel image is one DCS sequence: \eP P1;P2;P3 q, a raster attribute
 * "1;1;W;H, colour registers #N;2;R;G;B (percent), then bands six pixels
 * high, \e\\ at the end (VT330/VT340 Programmer Reference Manual, chapter
 * 14). libsixel picks at most 256 colours by median cut and writes the
 * bands; rtsh asks for no dithering, so a picture that refines pass by
 * pass does not shimmer. */
#include "term/pixels.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <sixel/sixel.h>

#include "base/dynlib.h"

/* libsixel, opened on the first sixel picture (base/dynlib.h): a start-up
 * that draws none (a batch render, half blocks, kitty) does not map it
 * (issue 29: 0.2 ms of the process's serial start). */
#ifndef RTSH_SIXEL_SONAME
#define RTSH_SIXEL_SONAME "libsixel.so.1"
#endif

static struct {
	SIXELSTATUS (*output_new)(sixel_output_t **output, sixel_write_function fn_write, void *priv,
	                          sixel_allocator_t *allocator);
	void (*output_unref)(sixel_output_t *output);
	void (*output_set_8bit)(sixel_output_t *output, int availability);
	SIXELSTATUS (*dither_new)(sixel_dither_t **ppdither, int ncolors, sixel_allocator_t *allocator);
	void (*dither_unref)(sixel_dither_t *dither);
	SIXELSTATUS (*dither_initialize)(sixel_dither_t *dither, unsigned char *data, int width, int height,
	                                 int pixelformat, int method_for_largest, int method_for_rep,
	                                 int quality_mode);
	void (*dither_set_diffusion)(sixel_dither_t *dither, int method_for_diffuse);
	SIXELSTATUS (*encode)(unsigned char *pixels, int width, int height, int depth, sixel_dither_t *dither,
	                      sixel_output_t *context);
} sx;
static dynlib_lazy sx_lazy = DYNLIB_LAZY;

static void sx_open(void)
{
	const dynlib_fn fns[] = {
	    {"sixel_output_new", &sx.output_new},
	    {"sixel_output_unref", &sx.output_unref},
	    {"sixel_output_set_8bit_availability", &sx.output_set_8bit},
	    {"sixel_dither_new", &sx.dither_new},
	    {"sixel_dither_unref", &sx.dither_unref},
	    {"sixel_dither_initialize", &sx.dither_initialize},
	    {"sixel_dither_set_diffusion_type", &sx.dither_set_diffusion},
	    {"sixel_encode", &sx.encode},
	};
	sx_lazy.ok = dynlib_open(RTSH_SIXEL_SONAME, fns, sizeof fns / sizeof fns[0], sx_lazy.why, sizeof sx_lazy.why);
}

bool pixels_sixel_available(char *why, size_t size)
{
	pthread_once(&sx_lazy.once, sx_open);
	if (!sx_lazy.ok && why && size)
		snprintf(why, size, "libsixel cannot be loaded (%s); expected %s installed", sx_lazy.why,
		         RTSH_SIXEL_SONAME);
	return sx_lazy.ok;
}

static int sink(char *data, int size, void *priv)
{
	abuf_add(priv, data, (size_t)size);
	return size;
}

bool pixels_sixel(abuf *out, const uint8_t *rgb, int w, int h)
{
	if (w < 1 || h < 1 || !pixels_sixel_available(NULL, 0))
		return false;
	size_t n = (size_t)w * (size_t)h * 3;
	unsigned char *copy = malloc(n); /* libsixel takes a mutable buffer */
	if (!copy)
		return false;
	memcpy(copy, rgb, n);
	size_t len0 = out->len;
	sixel_output_t *o = NULL;
	sixel_dither_t *d = NULL;
	bool ok = !SIXEL_FAILED(sx.output_new(&o, sink, out, NULL)) && !SIXEL_FAILED(sx.dither_new(&d, 256, NULL));
	if (ok) {
		sx.output_set_8bit(o, 0); /* 7-bit ESC P, as over any link */
		ok = !SIXEL_FAILED(sx.dither_initialize(d, copy, w, h, SIXEL_PIXELFORMAT_RGB888, SIXEL_LARGE_AUTO,
		                                        SIXEL_REP_AUTO, SIXEL_QUALITY_AUTO));
	}
	if (ok) {
		sx.dither_set_diffusion(d, SIXEL_DIFFUSE_NONE);
		ok = !SIXEL_FAILED(sx.encode(copy, w, h, 3, d, o));
	}
	if (d)
		sx.dither_unref(d);
	if (o)
		sx.output_unref(o);
	free(copy);
	if (!ok || out->failed) {
		out->len = len0;
		return false;
	}
	return true;
}
