/* rtsh — the iTerm2 inline image protocol (pixels.h).
 *
 * From iTerm2's documentation (iterm2.com/documentation-images.html): an
 * OSC 1337 sequence \e]1337;File=<args>:<base64 of the file>\a, with
 * inline=1 to show the file rather than download it, size= its length in
 * bytes, width= and height= in cells, preserveAspectRatio=0 to fill them
 * exactly. The file is a PNG made with libpng; doNotMoveCursor=1 (iTerm2
 * 3.5) keeps the cursor put. */
#include "term/pixels.h"

bool pixels_iterm(abuf *out, const uint8_t *rgb, int w, int h, int cols, int rows)
{
	abuf png;
	abuf_init(&png);
	if (!pixels_png(&png, rgb, w, h)) {
		abuf_free(&png);
		return false;
	}
	size_t len0 = out->len;
	abuf_printf(out, "\x1b]1337;File=inline=1;size=%zu;", png.len);
	if (cols > 0 && rows > 0)
		abuf_printf(out, "width=%d;height=%d;preserveAspectRatio=0;", cols, rows);
	abuf_str(out, "doNotMoveCursor=1:");
	pixels_base64(out, (const uint8_t *)png.b, png.len);
	abuf_str(out, "\a");
	abuf_free(&png);
	if (out->failed) {
		out->len = len0;
		return false;
	}
	return true;
}
