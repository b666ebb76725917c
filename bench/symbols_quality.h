/* rtsh bench — what a terminal shows of a stream of cell glyphs, as pixels,
 * and how far that is from a picture (PSNR, SSIM). Used by bench.c's
 * symbols rows for rtsh's own output and chafa's alike.
 *
 * The decoder is a small terminal of its own, written from the standards
 * and not from rtsh's encoder: it knows cursor moves (CUP, CUF, CR, LF,
 * DECSC/DECRC), REP (CSI N b), SGR colours (24-bit, 256, 16, reverse
 * video, defaults), and draws each glyph from its shape in the Unicode
 * charts as rectangles inked in the foreground colour: the block elements
 * (U+2580..U+259F: halves, eighths, quadrants, shades as a uniform mix),
 * the sextants (U+1FB00..U+1FB3B), the octants (U+1CD00..U+1CDE5), the
 * upper and right eighth blocks of Symbols for Legacy Computing
 * (U+1FB82..U+1FB8B: UPPER ONE QUARTER, THREE EIGHTHS, FIVE EIGHTHS, THREE
 * QUARTERS, SEVEN EIGHTHS BLOCK, then RIGHT the same) and the quarter
 * blocks that octants borrow (U+1FBE6 U+1FBE7 U+1CEA0 U+1CEA3 U+1CEA8
 * U+1CEAB). The picture it gives is sampled on a
 * grid of 2x4 pixels a cell: each pixel the area-weighted mix of ink and
 * paper over it. Any other character counts as unknown (drawn as paper).
 *
 * SSIM is Wang, Bovik, Sheikh and Simoncelli's (IEEE TIP 2004): an 11x11
 * Gaussian window of sigma 1.5, K1 = 0.01, K2 = 0.03, L = 255, on luma
 * (Rec. 601 weights), the mean over the windows that fit the picture.
 */
#ifndef RTSH_BENCH_SYMBOLS_QUALITY_H
#define RTSH_BENCH_SYMBOLS_QUALITY_H

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define SQ_W 2 /* decoded pixels a cell across */
#define SQ_H 4 /* and down */

typedef struct sq_rect {
	float x0, y0, x1, y1; /* in the cell, 0..1, y down */
} sq_rect;

/* The ink of code point cp as rectangles (at most 8) and a uniform
 * coverage for shades; returns the rectangle count, -1 when unknown. */
static int sq_glyph(uint32_t cp, sq_rect r[8], float *shade)
{
	*shade = 0;
	int n = 0;
	if (cp == ' ')
		return 0;
	if (cp >= 0x2581 && cp <= 0x2588) { /* lower k eighths, U+2588 the full block */
		float k = (float)(cp - 0x2580);
		r[n++] = (sq_rect){0, 1 - k / 8, 1, 1};
		return n;
	}
	if (cp >= 0x2589 && cp <= 0x258f) { /* left 7/8 .. 1/8 */
		float k = (float)(0x2590 - cp);
		r[n++] = (sq_rect){0, 0, k / 8, 1};
		return n;
	}
	switch (cp) {
	case 0x2580: r[n++] = (sq_rect){0, 0, 1, 0.5f}; return n;
	case 0x2590: r[n++] = (sq_rect){0.5f, 0, 1, 1}; return n;
	case 0x2594: r[n++] = (sq_rect){0, 0, 1, 0.125f}; return n;
	case 0x2595: r[n++] = (sq_rect){0.875f, 0, 1, 1}; return n;
	case 0x2591: *shade = 0.25f; return 0;
	case 0x2592: *shade = 0.5f; return 0;
	case 0x2593: *shade = 0.75f; return 0;
	case 0x1fb82: r[n++] = (sq_rect){0, 0, 1, 0.25f}; return n;     /* upper one quarter */
	case 0x1fb83: r[n++] = (sq_rect){0, 0, 1, 0.375f}; return n;    /* upper three eighths */
	case 0x1fb84: r[n++] = (sq_rect){0, 0, 1, 0.625f}; return n;    /* upper five eighths */
	case 0x1fb85: r[n++] = (sq_rect){0, 0, 1, 0.75f}; return n;     /* upper three quarters */
	case 0x1fb86: r[n++] = (sq_rect){0, 0, 1, 0.875f}; return n;    /* upper seven eighths */
	case 0x1fb87: r[n++] = (sq_rect){0.75f, 0, 1, 1}; return n;     /* right one quarter */
	case 0x1fb88: r[n++] = (sq_rect){0.625f, 0, 1, 1}; return n;    /* right three eighths */
	case 0x1fb89: r[n++] = (sq_rect){0.375f, 0, 1, 1}; return n;    /* right five eighths */
	case 0x1fb8a: r[n++] = (sq_rect){0.25f, 0, 1, 1}; return n;     /* right three quarters */
	case 0x1fb8b: r[n++] = (sq_rect){0.125f, 0, 1, 1}; return n;    /* right seven eighths */
	case 0x1fbe6: r[n++] = (sq_rect){0, 0.25f, 0.5f, 0.75f}; return n; /* middle left one quarter */
	case 0x1fbe7: r[n++] = (sq_rect){0.5f, 0.25f, 1, 0.75f}; return n; /* middle right one quarter */
	case 0x1cea8: r[n++] = (sq_rect){0, 0, 0.5f, 0.25f}; return n;  /* left half upper one quarter */
	case 0x1ceab: r[n++] = (sq_rect){0.5f, 0, 1, 0.25f}; return n;  /* right half upper one quarter */
	case 0x1cea3: r[n++] = (sq_rect){0, 0.75f, 0.5f, 1}; return n;  /* left half lower one quarter */
	case 0x1cea0: r[n++] = (sq_rect){0.5f, 0.75f, 1, 1}; return n;  /* right half lower one quarter */
	default: break;
	}
	if (cp >= 0x2596 && cp <= 0x259f) {
		/* QUADRANT LOWER LEFT, LOWER RIGHT, UPPER LEFT, UPPER LEFT AND
		 * LOWER LEFT AND LOWER RIGHT, UPPER LEFT AND LOWER RIGHT, UPPER
		 * LEFT AND UPPER RIGHT AND LOWER LEFT, UPPER LEFT AND UPPER RIGHT
		 * AND LOWER RIGHT, UPPER RIGHT, UPPER RIGHT AND LOWER LEFT, UPPER
		 * RIGHT AND LOWER LEFT AND LOWER RIGHT (bits: UL 1, UR 2, LL 4, LR 8) */
		static const uint8_t q[10] = {4, 8, 1, 1 | 4 | 8, 1 | 8, 1 | 2 | 4, 1 | 2 | 8, 2, 2 | 4, 2 | 4 | 8};
		unsigned m = q[cp - 0x2596];
		for (int i = 0; i < 4; i++)
			if (m >> i & 1)
				r[n++] = (sq_rect){(i & 1) * 0.5f, (i >> 1) * 0.5f, (i & 1) * 0.5f + 0.5f, (i >> 1) * 0.5f + 0.5f};
		return n;
	}
	if (cp >= 0x1fb00 && cp <= 0x1fb3b) {
		/* BLOCK SEXTANT-<digits>: the sextants 1..6 (row by row, left
		 * first) in ascending order of their binary number, leaving out
		 * the two columns (135 and 246, the half blocks). */
		unsigned idx = cp - 0x1fb00, m = 0;
		for (unsigned v = 1, k = 0; v < 63; v++) {
			if (v == (1 | 4 | 16) || v == (2 | 8 | 32))
				continue;
			if (k++ == idx) {
				m = v;
				break;
			}
		}
		for (int i = 0; i < 6; i++)
			if (m >> i & 1)
				r[n++] = (sq_rect){(i & 1) * 0.5f, (float)(i >> 1) / 3, (i & 1) * 0.5f + 0.5f,
				                   (float)((i >> 1) + 1) / 3};
		return n;
	}
	if (cp >= 0x1cd00 && cp <= 0x1cde5) {
		/* BLOCK OCTANT-<digits>: the patterns of octants 1..8 in
		 * ascending order, leaving out those that other characters
		 * draw: a pattern whose row pairs (12/34, 56/78) are equal
		 * (the quadrants, halves, space and full block), and the ten
		 * quarter-block patterns listed above and in U+2582, U+2586. */
		static const uint8_t other[] = {0x01, 0x02, 0x03, 0x14, 0x28, 0x3f, 0x40, 0x80, 0xc0, 0xfc};
		unsigned idx = cp - 0x1cd00, m = 0;
		for (unsigned v = 0, k = 0; v < 256; v++) {
			bool skip = (v & 3) == (v >> 2 & 3) && (v >> 4 & 3) == (v >> 6 & 3);
			for (size_t j = 0; j < sizeof other; j++)
				skip |= v == other[j];
			if (skip)
				continue;
			if (k++ == idx) {
				m = v;
				break;
			}
		}
		for (int i = 0; i < 8; i++)
			if (m >> i & 1)
				r[n++] = (sq_rect){(i & 1) * 0.5f, (float)(i >> 1) / 4, (i & 1) * 0.5f + 0.5f,
				                   (float)((i >> 1) + 1) / 4};
		return n;
	}
	return -1;
}

/* xterm's colour of palette index i (16 colours, the 6x6x6 cube, greys). */
static void sq_palette(unsigned i, uint8_t c[3])
{
	static const uint8_t x16[16][3] = {
		{0, 0, 0},       {205, 0, 0},   {0, 205, 0},   {205, 205, 0},   {0, 0, 238},    {205, 0, 205},
		{0, 205, 205},   {229, 229, 229}, {127, 127, 127}, {255, 0, 0}, {0, 255, 0},    {255, 255, 0},
		{92, 92, 255},   {255, 0, 255}, {0, 255, 255}, {255, 255, 255},
	};
	static const uint8_t lv[6] = {0, 95, 135, 175, 215, 255};
	if (i < 16) {
		memcpy(c, x16[i], 3);
	} else if (i < 232) {
		c[0] = lv[(i - 16) / 36];
		c[1] = lv[(i - 16) / 6 % 6];
		c[2] = lv[(i - 16) % 6];
	} else {
		c[0] = c[1] = c[2] = (uint8_t)(8 + 10 * (i - 232));
	}
}

typedef struct sq_cell {
	uint32_t ch;
	uint8_t fg[3], bg[3];
} sq_cell;

/* Decodes n bytes of terminal output onto a screen of cols x rows cells
 * (the terminal's default colours: white on black) and samples it as
 * (cols*2) x (rows*4) sRGB pixels in out. Returns how many cells hold a
 * character the decoder does not know (drawn as their background). */
static int sq_decode(const char *s, size_t n, int cols, int rows, uint8_t *out)
{
	sq_cell *cell = calloc((size_t)cols * rows, sizeof *cell);
	if (!cell)
		return -1;
	for (int i = 0; i < cols * rows; i++)
		cell[i].ch = ' ';
	const uint8_t def_fg[3] = {255, 255, 255}, def_bg[3] = {0, 0, 0};
	uint8_t fg[3], bg[3];
	memcpy(fg, def_fg, 3);
	memcpy(bg, def_bg, 3);
	bool rev = false;
	int x = 0, y = 0, sx = 0, sy = 0;
	uint32_t last = ' ';
	size_t i = 0;
	while (i < n) {
		unsigned char c = (unsigned char)s[i];
		if (c == 0x1b && i + 1 < n) {
			char k = s[i + 1];
			if (k == '7' || k == '8') {
				if (k == '7')
					sx = x, sy = y;
				else
					x = sx, y = sy;
				i += 2;
				continue;
			}
			if (k != '[') {
				i += 2;
				continue;
			}
			i += 2;
			bool priv = i < n && (s[i] == '?' || s[i] == '>');
			if (priv)
				i++;
			long p[40];
			int np = 0;
			long cur = -1;
			while (i < n && ((s[i] >= '0' && s[i] <= '9') || s[i] == ';' || s[i] == ':')) {
				if (s[i] == ';' || s[i] == ':') {
					if (np < 40)
						p[np++] = cur < 0 ? 0 : cur;
					cur = -1;
				} else {
					cur = (cur < 0 ? 0 : cur * 10) + (s[i] - '0');
				}
				i++;
			}
			if ((cur >= 0 || np > 0) && np < 40)
				p[np++] = cur < 0 ? 0 : cur;
			if (i >= n)
				break;
			char fin = s[i++];
			if (priv)
				continue;
			if (fin == 'H' || fin == 'f') {
				y = (np > 0 && p[0] > 0 ? (int)p[0] : 1) - 1;
				x = (np > 1 && p[1] > 0 ? (int)p[1] : 1) - 1;
			} else if (fin == 'C') {
				x += np > 0 && p[0] > 0 ? (int)p[0] : 1;
			} else if (fin == 'b') {
				for (long r = np > 0 && p[0] > 0 ? p[0] : 1; r > 0; r--) {
					if (x < cols && y < rows && y >= 0) {
						sq_cell *ce = &cell[y * cols + x];
						ce->ch = last;
						memcpy(ce->fg, rev ? bg : fg, 3);
						memcpy(ce->bg, rev ? fg : bg, 3);
					}
					x++;
				}
			} else if (fin == 'm') {
				if (np == 0) {
					memcpy(fg, def_fg, 3), memcpy(bg, def_bg, 3), rev = false;
					continue;
				}
				for (int j = 0; j < np; j++) {
					long v = p[j];
					if (v == 0) {
						memcpy(fg, def_fg, 3), memcpy(bg, def_bg, 3), rev = false;
					} else if ((v == 38 || v == 48) && j + 4 < np && p[j + 1] == 2) {
						uint8_t *t = v == 38 ? fg : bg;
						for (int ch = 0; ch < 3; ch++)
							t[ch] = (uint8_t)p[j + 2 + ch];
						j += 4;
					} else if ((v == 38 || v == 48) && j + 2 < np && p[j + 1] == 5) {
						sq_palette((unsigned)p[j + 2], v == 38 ? fg : bg);
						j += 2;
					} else if (v >= 30 && v <= 37) {
						sq_palette((unsigned)(v - 30), fg);
					} else if (v >= 90 && v <= 97) {
						sq_palette((unsigned)(v - 90 + 8), fg);
					} else if (v >= 40 && v <= 47) {
						sq_palette((unsigned)(v - 40), bg);
					} else if (v >= 100 && v <= 107) {
						sq_palette((unsigned)(v - 100 + 8), bg);
					} else if (v == 39) {
						memcpy(fg, def_fg, 3);
					} else if (v == 49) {
						memcpy(bg, def_bg, 3);
					} else if (v == 7) {
						rev = true;
					} else if (v == 27) {
						rev = false;
					}
				}
			}
			continue;
		}
		if (c == '\n') {
			y++;
			x = 0;
			i++;
			continue;
		}
		if (c == '\r') {
			x = 0;
			i++;
			continue;
		}
		if (c < 0x20) {
			i++;
			continue;
		}
		uint32_t cp;
		int len = c < 0x80 ? 1 : (c & 0xe0) == 0xc0 ? 2 : (c & 0xf0) == 0xe0 ? 3 : 4;
		if (i + (size_t)len > n)
			break;
		cp = len == 1 ? c : len == 2 ? c & 0x1f : len == 3 ? c & 0x0f : c & 0x07;
		for (int k = 1; k < len; k++)
			cp = cp << 6 | ((unsigned char)s[i + k] & 0x3f);
		i += (size_t)len;
		if (x < cols && y < rows && y >= 0) {
			sq_cell *ce = &cell[y * cols + x];
			ce->ch = cp;
			memcpy(ce->fg, rev ? bg : fg, 3);
			memcpy(ce->bg, rev ? fg : bg, 3);
		}
		last = cp;
		x++;
	}
	int unknown = 0;
	int W = cols * SQ_W;
	for (int cy = 0; cy < rows; cy++)
		for (int cx = 0; cx < cols; cx++) {
			const sq_cell *ce = &cell[cy * cols + cx];
			sq_rect r[8];
			float shade;
			int nr = sq_glyph(ce->ch, r, &shade);
			if (nr < 0) {
				unknown++;
				nr = 0;
			}
			for (int py = 0; py < SQ_H; py++)
				for (int px = 0; px < SQ_W; px++) {
					/* the ink's share of this pixel's area */
					float x0 = (float)px / SQ_W, x1 = (float)(px + 1) / SQ_W;
					float y0 = (float)py / SQ_H, y1 = (float)(py + 1) / SQ_H;
					float cov = shade;
					for (int k = 0; k < nr; k++) {
						float w = fminf(x1, r[k].x1) - fmaxf(x0, r[k].x0);
						float h = fminf(y1, r[k].y1) - fmaxf(y0, r[k].y0);
						if (w > 0 && h > 0)
							cov += w * h * SQ_W * SQ_H;
					}
					cov = cov > 1 ? 1 : cov;
					uint8_t *o = out + ((size_t)(cy * SQ_H + py) * W + (size_t)(cx * SQ_W + px)) * 3;
					for (int ch = 0; ch < 3; ch++)
						o[ch] = (uint8_t)lroundf(cov * ce->fg[ch] + (1 - cov) * ce->bg[ch]);
				}
		}
	free(cell);
	return unknown;
}

/* PSNR in dB of b against a (n pixels, RGB bytes); INFINITY when equal. */
static double sq_psnr(const uint8_t *a, const uint8_t *b, size_t n)
{
	double se = 0;
	for (size_t i = 0; i < n * 3; i++) {
		double d = (double)a[i] - b[i];
		se += d * d;
	}
	if (se == 0)
		return INFINITY;
	return 10 * log10(255.0 * 255.0 / (se / ((double)n * 3)));
}

/* Mean SSIM of b against a (w x h, RGB bytes) on luma. */
static double sq_ssim(const uint8_t *a, const uint8_t *b, int w, int h)
{
	enum { R = 5 }; /* 11x11 */
	double g[2 * R + 1], gs = 0;
	for (int i = -R; i <= R; i++)
		gs += g[i + R] = exp(-(double)(i * i) / (2 * 1.5 * 1.5));
	for (int i = 0; i < 2 * R + 1; i++)
		g[i] /= gs;
	double *ya = malloc(sizeof *ya * (size_t)w * h), *yb = malloc(sizeof *yb * (size_t)w * h);
	if (!ya || !yb) {
		free(ya);
		free(yb);
		return NAN;
	}
	for (int i = 0; i < w * h; i++) {
		ya[i] = 0.299 * a[3 * i] + 0.587 * a[3 * i + 1] + 0.114 * a[3 * i + 2];
		yb[i] = 0.299 * b[3 * i] + 0.587 * b[3 * i + 1] + 0.114 * b[3 * i + 2];
	}
	const double c1 = (0.01 * 255) * (0.01 * 255), c2 = (0.03 * 255) * (0.03 * 255);
	double sum = 0;
	long count = 0;
	for (int y = R; y < h - R; y++)
		for (int x = R; x < w - R; x++) {
			double ma = 0, mb = 0, saa = 0, sbb = 0, sab = 0;
			for (int dy = -R; dy <= R; dy++)
				for (int dx = -R; dx <= R; dx++) {
					double wt = g[dy + R] * g[dx + R];
					double va = ya[(y + dy) * w + x + dx], vb = yb[(y + dy) * w + x + dx];
					ma += wt * va;
					mb += wt * vb;
					saa += wt * va * va;
					sbb += wt * vb * vb;
					sab += wt * va * vb;
				}
			double va = saa - ma * ma, vb = sbb - mb * mb, cov = sab - ma * mb;
			sum += (2 * ma * mb + c1) * (2 * cov + c2) / ((ma * ma + mb * mb + c1) * (va + vb + c2));
			count++;
		}
	free(ya);
	free(yb);
	return count ? sum / (double)count : NAN;
}

#endif
