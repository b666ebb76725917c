/* rtsh tests — a tiny terminal emulator for exactly the sequences the frame
 * encoder sends (see src/term/frame.h): it applies a byte stream to a grid
 * of cells so a test can read back what a terminal would show.
 *
 * Colours are kept as the encoder's cell values: 38;2;R;G;B -> 0xRRGGBB,
 * 38;5;N -> N, 30-37/90-97 -> 0..15 (and the same for backgrounds),
 * 39/49 and reset -> EMU_DEFAULT. Anything else fails the test.
 */
#ifndef RTSH_TERMEMU_H
#define RTSH_TERMEMU_H

#include "testutil.h"

#define EMU_DEFAULT 0xff000000u
#define EMU_UNSET 0xfffffffeu /* a cell never written */

typedef struct emu_cell {
	uint32_t ch; /* Unicode code point */
	uint32_t fg, bg;
} emu_cell;

typedef struct emu {
	int cols, rows;
	emu_cell *cell;
	int x, y;    /* cursor, 0-based */
	int sx, sy;  /* saved cursor */
	uint32_t fg, bg, sfg, sbg;
	bool cursor_visible;
	bool sync;   /* inside mode 2026 */
} emu;

static inline void emu_init(emu *e, int cols, int rows)
{
	e->cols = cols;
	e->rows = rows;
	e->cell = malloc(sizeof *e->cell * (size_t)cols * (size_t)rows);
	for (int i = 0; i < cols * rows; i++)
		e->cell[i] = (emu_cell){EMU_UNSET, EMU_UNSET, EMU_UNSET};
	e->x = e->y = e->sx = e->sy = 0;
	e->fg = e->bg = e->sfg = e->sbg = EMU_DEFAULT;
	e->cursor_visible = true;
	e->sync = false;
}

static inline void emu_free(emu *e)
{
	free(e->cell);
}

static inline void emu_put(emu *e, uint32_t ch)
{
	if (e->x >= e->cols || e->y >= e->rows)
		fail_msg("write at %d,%d outside the %dx%d screen", e->y, e->x, e->rows, e->cols);
	e->cell[e->y * e->cols + e->x] = (emu_cell){ch, e->fg, e->bg};
	e->x++;
}

static inline void emu_sgr(emu *e, const int *p, int n)
{
	if (n == 0) {
		e->fg = e->bg = EMU_DEFAULT;
		return;
	}
	for (int i = 0; i < n; i++) {
		int v = p[i];
		if (v == 0) {
			e->fg = e->bg = EMU_DEFAULT;
		} else if ((v == 38 || v == 48) && i + 1 < n && p[i + 1] == 2 && i + 4 < n) {
			uint32_t c = (uint32_t)p[i + 2] << 16 | (uint32_t)p[i + 3] << 8 | (uint32_t)p[i + 4];
			*(v == 38 ? &e->fg : &e->bg) = c;
			i += 4;
		} else if ((v == 38 || v == 48) && i + 2 < n && p[i + 1] == 5) {
			*(v == 38 ? &e->fg : &e->bg) = (uint32_t)p[i + 2];
			i += 2;
		} else if (v >= 30 && v <= 37) {
			e->fg = (uint32_t)(v - 30);
		} else if (v >= 90 && v <= 97) {
			e->fg = (uint32_t)(v - 90 + 8);
		} else if (v >= 40 && v <= 47) {
			e->bg = (uint32_t)(v - 40);
		} else if (v >= 100 && v <= 107) {
			e->bg = (uint32_t)(v - 100 + 8);
		} else if (v == 39) {
			e->fg = EMU_DEFAULT;
		} else if (v == 49) {
			e->bg = EMU_DEFAULT;
		} else {
			fail_msg("unexpected SGR parameter %d", v);
		}
	}
}

/* Applies n bytes to the screen. */
static inline void emu_feed(emu *e, const char *s, size_t n)
{
	size_t i = 0;
	while (i < n) {
		unsigned char c = (unsigned char)s[i];
		if (c == 0x1b) {
			if (i + 1 >= n)
				fail_msg("ESC at the end of the stream");
			char k = s[i + 1];
			if (k == '7') {
				e->sx = e->x, e->sy = e->y, e->sfg = e->fg, e->sbg = e->bg;
				i += 2;
				continue;
			}
			if (k == '8') {
				e->x = e->sx, e->y = e->sy, e->fg = e->sfg, e->bg = e->sbg;
				i += 2;
				continue;
			}
			if (k != '[')
				fail_msg("unexpected ESC %c", k);
			i += 2;
			bool priv = i < n && s[i] == '?';
			if (priv)
				i++;
			int p[32], np = 0, cur = -1;
			while (i < n && ((s[i] >= '0' && s[i] <= '9') || s[i] == ';')) {
				if (s[i] == ';') {
					assert_true(np < 32);
					p[np++] = cur < 0 ? 0 : cur;
					cur = -1;
				} else {
					cur = (cur < 0 ? 0 : cur * 10) + (s[i] - '0');
				}
				i++;
			}
			if (cur >= 0 || np > 0)
				p[np++] = cur < 0 ? 0 : cur;
			if (i >= n)
				fail_msg("unterminated CSI");
			char fin = s[i++];
			if (priv) {
				assert_true(fin == 'h' || fin == 'l');
				assert_int_equal(np, 1);
				if (p[0] == 25)
					e->cursor_visible = fin == 'h';
				else if (p[0] == 2026)
					e->sync = fin == 'h';
				else
					fail_msg("unexpected private mode %d", p[0]);
			} else if (fin == 'H') {
				e->y = (np > 0 && p[0] > 0 ? p[0] : 1) - 1;
				e->x = (np > 1 && p[1] > 0 ? p[1] : 1) - 1;
			} else if (fin == 'C') {
				e->x += np > 0 && p[0] > 0 ? p[0] : 1;
			} else if (fin == 'm') {
				emu_sgr(e, p, np);
			} else {
				fail_msg("unexpected CSI final %c", fin);
			}
			continue;
		}
		if (c == '\n') {
			e->y++;
			e->x = 0;
			i++;
			continue;
		}
		if (c < 0x80) {
			if (c < 0x20)
				fail_msg("unexpected control byte %d", c);
			emu_put(e, c);
			i++;
			continue;
		}
		/* A 4-byte UTF-8 sequence (sextants, octants). */
		if ((c & 0xf8) == 0xf0 && i + 3 < n) {
			uint32_t cp = (uint32_t)(c & 0x07) << 18 | (uint32_t)(s[i + 1] & 0x3f) << 12 |
			              (uint32_t)(s[i + 2] & 0x3f) << 6 | (uint32_t)(s[i + 3] & 0x3f);
			emu_put(e, cp);
			i += 4;
			continue;
		}
		/* A 3-byte UTF-8 sequence (the block characters). */
		if ((c & 0xf0) != 0xe0 || i + 2 >= n)
			fail_msg("unexpected byte 0x%02x", c);
		uint32_t cp = (uint32_t)(c & 0x0f) << 12 | (uint32_t)(s[i + 1] & 0x3f) << 6 | (uint32_t)(s[i + 2] & 0x3f);
		emu_put(e, cp);
		i += 3;
	}
}

/* The two pixels a cell shows: space = background twice, U+2580 fg over bg,
 * U+2584 bg over fg, U+2588 fg twice; ASCII (no colour) = the character. */
static inline void emu_pixels(const emu_cell *c, uint32_t *top, uint32_t *bot, bool ascii)
{
	if (ascii) {
		*top = *bot = c->ch;
		return;
	}
	switch (c->ch) {
	case ' ':
		*top = *bot = c->bg;
		break;
	case 0x2580:
		*top = c->fg, *bot = c->bg;
		break;
	case 0x2584:
		*top = c->bg, *bot = c->fg;
		break;
	case 0x2588:
		*top = *bot = c->fg;
		break;
	default:
		fail_msg("unexpected character U+%04X", c->ch);
	}
}

#endif
