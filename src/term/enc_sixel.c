/* rtsh — sixel (pixels.h), quantised and encoded by libsixel.
 *
 * A sixel image is one DCS sequence: \eP P1;P2;P3 q, a raster attribute
 * "1;1;W;H, colour registers #N;2;R;G;B (percent), then bands six pixels
 * high, \e\\ at the end (VT330/VT340 Programmer Reference Manual, chapter
 * 14). libsixel picks at most 256 colours by median cut and writes the
 * bands; rtsh asks for no dithering, so a picture that refines pass by
 * pass does not shimmer. */
#include "term/pixels.h"

#include <stdlib.h>
#include <string.h>

#include <sixel/sixel.h>

static int sink(char *data, int size, void *priv)
{
	abuf_add(priv, data, (size_t)size);
	return size;
}

bool pixels_sixel(abuf *out, const uint8_t *rgb, int w, int h)
{
	if (w < 1 || h < 1)
		return false;
	size_t n = (size_t)w * (size_t)h * 3;
	unsigned char *copy = malloc(n); /* libsixel takes a mutable buffer */
	if (!copy)
		return false;
	memcpy(copy, rgb, n);
	size_t len0 = out->len;
	sixel_output_t *o = NULL;
	sixel_dither_t *d = NULL;
	bool ok = !SIXEL_FAILED(sixel_output_new(&o, sink, out, NULL)) &&
	          !SIXEL_FAILED(sixel_dither_new(&d, 256, NULL));
	if (ok) {
		sixel_output_set_8bit_availability(o, 0); /* 7-bit ESC P, as over any link */
		ok = !SIXEL_FAILED(sixel_dither_initialize(d, copy, w, h, SIXEL_PIXELFORMAT_RGB888,
		                                           SIXEL_LARGE_AUTO, SIXEL_REP_AUTO,
		                                           SIXEL_QUALITY_AUTO));
	}
	if (ok) {
		sixel_dither_set_diffusion_type(d, SIXEL_DIFFUSE_NONE);
		ok = !SIXEL_FAILED(sixel_encode(copy, w, h, 3, d, o));
	}
	if (d)
		sixel_dither_unref(d);
	if (o)
		sixel_output_unref(o);
	free(copy);
	if (!ok || out->failed) {
		out->len = len0;
		return false;
	}
	return true;
}
