/* rtsh — the kitty graphics protocol (pixels.h).
 *
 * From the protocol's documentation (sw.kovidgoyal.net/kitty/graphics-
 * protocol): an APC sequence \e_G<key=value,...>;<payload>\e\\ per
 * command. The picture goes as one transmit-and-display command (a=T) of
 * 24-bit RGB (f=24) of s x v pixels, compressed with zlib (o=z), in base64
 * chunks of at most 4096 bytes: every chunk but the last has m=1, and only
 * the first carries the other keys. i= names the image and p= its
 * placement, so the next picture replaces this one in place; c= and r=
 * scale it to the cells; C=1 keeps the cursor where it is; q=2 silences
 * the terminal's answers (they would arrive as keys). */
#include "term/pixels.h"

#include <stdlib.h>

#include <zlib.h>

bool pixels_kitty(abuf *out, const uint8_t *rgb, int w, int h, int cols, int rows, int id)
{
	if (w < 1 || h < 1)
		return false;
	size_t n = (size_t)w * (size_t)h * 3;
	uLongf zn = compressBound((uLong)n);
	uint8_t *z = malloc(zn);
	if (!z)
		return false;
	/* Level 5: on the showcase at 1600x900, 264 KB against 369 KB at
	 * level 1 and 240 KB at 9, for about 1.4x and 0.6x level 1's time:
	 * the pixels go over slow links. */
	if (compress2(z, &zn, rgb, (uLong)n, 5) != Z_OK) {
		free(z);
		return false;
	}
	abuf b64;
	abuf_init(&b64);
	pixels_base64(&b64, z, zn);
	free(z);
	if (b64.failed) {
		abuf_free(&b64);
		return false;
	}
	size_t len0 = out->len;
	for (size_t at = 0; at < b64.len || at == 0; at += PIXELS_KITTY_CHUNK) {
		size_t k = b64.len - at < PIXELS_KITTY_CHUNK ? b64.len - at : PIXELS_KITTY_CHUNK;
		bool more = at + k < b64.len;
		abuf_str(out, "\x1b_G");
		if (at == 0) {
			abuf_printf(out, "a=T,f=24,o=z,s=%d,v=%d,i=%d,p=1,C=1,q=2,", w, h, id);
			if (cols > 0 && rows > 0)
				abuf_printf(out, "c=%d,r=%d,", cols, rows);
		}
		else
			abuf_str(out, "q=2,");
		abuf_printf(out, "m=%d;", more ? 1 : 0);
		abuf_add(out, b64.b + at, k);
		abuf_str(out, "\x1b\\");
		if (k == 0)
			break;
	}
	abuf_free(&b64);
	if (out->failed) {
		out->len = len0;
		return false;
	}
	return true;
}

void pixels_kitty_delete(abuf *out, int id)
{
	/* d=I: the image's placements and its data */
	abuf_printf(out, "\x1b_Ga=d,d=I,i=%d,q=2\x1b\\", id);
}
