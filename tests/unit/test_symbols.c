/* rtsh — tests of the symbol sets (term/symbols.h) and of frames drawn with
 * them: code points from the Unicode names, the two-colour fit against an
 * exhaustive search, and what a terminal shows after the encoder's bytes. */
#include "termemu.h"

#include "term/frame.h"
#include "term/symbols.h"

/* Code points read off the Unicode charts by their names: BLOCK
 * SEXTANT-1 is U+1FB00, BLOCK SEXTANT-23456 U+1FB3B; BLOCK OCTANT-3
 * U+1CD00, OCTANT-23 U+1CD01, OCTANT-123 U+1CD02, OCTANT-4 U+1CD03,
 * OCTANT-2345678 U+1CDE5. Mask bit k is subpixel k+1 of those names. */
static void test_codepoints_by_name(void **state)
{
	(void)state;
	assert_int_equal(symbols_codepoint(SYMBOLS_HALF, 1), 0x2580);
	assert_int_equal(symbols_codepoint(SYMBOLS_HALF, 2), 0x2584);
	assert_int_equal(symbols_codepoint(SYMBOLS_QUADRANT, 6), 0x259e); /* upper right and lower left */
	assert_int_equal(symbols_codepoint(SYMBOLS_QUADRANT, 9), 0x259a); /* upper left and lower right */
	assert_int_equal(symbols_codepoint(SYMBOLS_QUADRANT, 7), 0x259b); /* all but lower right */
	assert_int_equal(symbols_codepoint(SYMBOLS_SEXTANT, 1), 0x1fb00);
	assert_int_equal(symbols_codepoint(SYMBOLS_SEXTANT, 2 | 4 | 8 | 16 | 32), 0x1fb3b);
	assert_int_equal(symbols_codepoint(SYMBOLS_SEXTANT, 1 | 4 | 16), 0x258c);
	assert_int_equal(symbols_codepoint(SYMBOLS_SEXTANT, 2 | 8 | 32), 0x2590);
	assert_int_equal(symbols_codepoint(SYMBOLS_SEXTANT, 1 | 2 | 4 | 8 | 16 | 32), 0x2588);
	/* SEXTANT-1235 (mask 1+2+4+16 = 23): the 23rd mask less the column 21 */
	assert_int_equal(symbols_codepoint(SYMBOLS_SEXTANT, 23), 0x1fb00 + 23 - 2);
	assert_int_equal(symbols_codepoint(SYMBOLS_OCTANT, 4), 0x1cd00);
	assert_int_equal(symbols_codepoint(SYMBOLS_OCTANT, 6), 0x1cd01);
	assert_int_equal(symbols_codepoint(SYMBOLS_OCTANT, 7), 0x1cd02);
	assert_int_equal(symbols_codepoint(SYMBOLS_OCTANT, 8), 0x1cd03);
	assert_int_equal(symbols_codepoint(SYMBOLS_OCTANT, 0xfe), 0x1cde5);
	assert_int_equal(symbols_codepoint(SYMBOLS_OCTANT, 0x0f), 0x2580);
	assert_int_equal(symbols_codepoint(SYMBOLS_OCTANT, 0x55), 0x258c);
	assert_int_equal(symbols_codepoint(SYMBOLS_OCTANT, 0x03), 0x1fb82);
	assert_int_equal(symbols_codepoint(SYMBOLS_OCTANT, 0xc0), 0x2582);
	/* Every octant mask has its own glyph, and the block's 230 are all used. */
	bool used[230] = {false};
	for (unsigned m = 0; m < 256; m++) {
		uint32_t cp = symbols_codepoint(SYMBOLS_OCTANT, m);
		for (unsigned o = 0; o < m; o++)
			assert_true(symbols_codepoint(SYMBOLS_OCTANT, o) != cp);
		if (cp >= 0x1cd00 && cp <= 0x1cde5)
			used[cp - 0x1cd00] = true;
		assert_int_equal(symbols_mask_of(SYMBOLS_OCTANT, cp), (int)m);
	}
	for (int i = 0; i < 230; i++)
		assert_true(used[i]);
	char u[4];
	assert_int_equal(symbols_utf8(SYMBOLS_SEXTANT, 1, u), 4);
	assert_memory_equal(u, "\xf0\x9f\xac\x80", 4); /* U+1FB00 */
}

/* A sextant row covers 4/3 sample rows: rows of 0, 60, 120, 240 give
 * (3*0 + 60)/4, (60 + 120)/2 and (120 + 3*240)/4. */
static void test_subpixel_areas(void **state)
{
	(void)state;
	uint8_t s[4][2][3];
	const uint8_t rows[4] = {0, 60, 120, 240};
	for (int y = 0; y < 4; y++)
		for (int x = 0; x < 2; x++)
			memset(s[y][x], rows[y], 3);
	float sub[8][3];
	symbols_subpixels(SYMBOLS_SEXTANT, &s[0][0][0], 6, sub);
	assert_near(sub[0][0], 15, 1e-4);
	assert_near(sub[1][1], 15, 1e-4);
	assert_near(sub[2][2], 90, 1e-4);
	assert_near(sub[5][0], 210, 1e-4);
	symbols_subpixels(SYMBOLS_QUADRANT, &s[0][0][0], 6, sub);
	assert_near(sub[0][0], 30, 1e-4);
	assert_near(sub[3][0], 180, 1e-4);
	symbols_subpixels(SYMBOLS_OCTANT, &s[0][0][0], 6, sub);
	assert_near(sub[6][0], 240, 1e-4);
}

/* The least squared error over every mask, each side at its mean. */
static double brute_best(const float sub[][3], int n)
{
	double best = INFINITY;
	for (unsigned m = 0; m < 1u << n; m++) {
		double mean[2][3] = {{0}}, k[2] = {0, 0};
		for (int i = 0; i < n; i++)
			for (int c = 0; c < 3; c++)
				mean[m >> i & 1][c] += sub[i][c];
		for (int i = 0; i < n; i++)
			k[m >> i & 1]++;
		double e = 0;
		for (int i = 0; i < n; i++)
			for (int c = 0; c < 3; c++) {
				int side = m >> i & 1;
				double d = sub[i][c] - mean[side][c] / k[side];
				e += d * d;
			}
		best = e < best ? e : best;
	}
	return best;
}

static void test_fit_by_hand(void **state)
{
	(void)state;
	/* Red left column, blue right: the mask is a column, no error. */
	float sub[8][3];
	for (int i = 0; i < 6; i++) {
		sub[i][0] = i % 2 == 0 ? 255 : 0;
		sub[i][1] = 0;
		sub[i][2] = i % 2 == 0 ? 0 : 255;
	}
	unsigned mask;
	uint8_t a[3], b[3];
	assert_near(symbols_fit((const float(*)[3])sub, 6, 0, &mask, a, b), 0, 1e-9);
	assert_true(mask == 21 || mask == 42);
	const uint8_t *red = mask == 21 ? a : b;
	assert_int_equal(red[0], 255);
	assert_int_equal(red[2], 0);
	/* Five black and one grey 30: one colour has 3 * (5*5^2 + 25^2) = 2250
	 * squared error, the split none; flat = 2250 keeps one colour. */
	for (int i = 0; i < 6; i++)
		for (int c = 0; c < 3; c++)
			sub[i][c] = i == 4 ? 30 : 0;
	assert_near(symbols_fit((const float(*)[3])sub, 6, 2250, &mask, a, b), 2250, 1e-6);
	assert_int_equal(mask, 0);
	assert_int_equal(a[0], 5);
	assert_int_equal(b[1], 5);
	assert_near(symbols_fit((const float(*)[3])sub, 6, 2249, &mask, a, b), 0, 1e-6);
	assert_true(mask == 16 || mask == 63 - 16);
	/* Random cells: the fit's error is the exhaustive search's. */
	test_rng r = {99};
	for (int t = 0; t < 300; t++) {
		int n = t % 3 == 0 ? 4 : t % 3 == 1 ? 6 : 8;
		for (int i = 0; i < n; i++)
			for (int c = 0; c < 3; c++)
				sub[i][c] = (float)(trand(&r) * 255);
		double e = symbols_fit((const float(*)[3])sub, n, 0, &mask, a, b);
		assert_near(e, brute_best((const float(*)[3])sub, n), 1e-3 * (1 + e));
	}
}

/* Shapes read off the Unicode charts by name, written here apart from
 * the encoder's tables: in eighths of the cell (x0, y0, x1, y1, y down).
 * Block Elements: U+2580 UPPER HALF, U+2581..U+2587 LOWER ONE EIGHTH ..
 * SEVEN EIGHTHS, U+2588 FULL, U+258C LEFT HALF, U+2590 RIGHT HALF, U+2594
 * UPPER ONE EIGHTH BLOCK; Symbols for Legacy Computing: U+1FB82 UPPER ONE
 * QUARTER, U+1FB83 UPPER THREE EIGHTHS, U+1FB84 UPPER FIVE EIGHTHS,
 * U+1FB85 UPPER THREE QUARTERS, U+1FB86 UPPER SEVEN EIGHTHS BLOCK. */
static const struct {
	uint32_t cp;
	int x0, y0, x1, y1;
} chart_rects[] = {
	{0x2580, 0, 0, 8, 4},  {0x2581, 0, 7, 8, 8},  {0x2582, 0, 6, 8, 8},  {0x2583, 0, 5, 8, 8},
	{0x2584, 0, 4, 8, 8},  {0x2585, 0, 3, 8, 8},  {0x2586, 0, 2, 8, 8},  {0x2587, 0, 1, 8, 8},
	{0x2588, 0, 0, 8, 8},  {0x258c, 0, 0, 4, 8},  {0x2590, 4, 0, 8, 8},  {0x2594, 0, 0, 8, 1},
	{0x1fb82, 0, 0, 8, 2}, {0x1fb83, 0, 0, 8, 3}, {0x1fb84, 0, 0, 8, 5}, {0x1fb85, 0, 0, 8, 6},
	{0x1fb86, 0, 0, 8, 7},
};
/* QUADRANT UPPER LEFT U+2598, UPPER RIGHT U+259D, LOWER LEFT U+2596, LOWER
 * RIGHT U+2597, and the combinations by their names (UL 1, UR 2, LL 4, LR 8). */
static const struct {
	uint32_t cp;
	unsigned q;
} chart_quads[] = {
	{0x2596, 4},         {0x2597, 8},         {0x2598, 1},         {0x2599, 1 | 4 | 8}, {0x259a, 1 | 8},
	{0x259b, 1 | 2 | 4}, {0x259c, 1 | 2 | 8}, {0x259d, 2},         {0x259e, 2 | 4},     {0x259f, 2 | 4 | 8},
};

/* The share of each of the 2x4 samples (rows top down) that the chart's
 * glyph cp inks; false when cp is none of the glyphs above, a sextant
 * (BLOCK SEXTANT-n..: the patterns of sextants 1..6, row by row, left
 * first, in ascending order, the two columns left out) or a space. */
static bool chart_cover(uint32_t cp, double cov[8])
{
	/* each glyph as up to 6 rectangles in 24ths (a sextant row is 8/24) */
	int r[6][4], n = 0;
	bool known = cp == ' ';
	for (size_t i = 0; i < sizeof chart_rects / sizeof chart_rects[0]; i++)
		if (chart_rects[i].cp == cp) {
			r[n][0] = chart_rects[i].x0 * 3, r[n][1] = chart_rects[i].y0 * 3;
			r[n][2] = chart_rects[i].x1 * 3, r[n][3] = chart_rects[i].y1 * 3;
			n++, known = true;
		}
	for (size_t i = 0; i < sizeof chart_quads / sizeof chart_quads[0]; i++)
		if (chart_quads[i].cp == cp) {
			for (int k = 0; k < 4; k++)
				if (chart_quads[i].q >> k & 1) {
					r[n][0] = (k & 1) * 12, r[n][1] = (k >> 1) * 12;
					r[n][2] = r[n][0] + 12, r[n][3] = r[n][1] + 12;
					n++;
				}
			known = true;
		}
	if (cp >= 0x1fb00 && cp <= 0x1fb3b) {
		unsigned want = cp - 0x1fb00, k = 0, pat = 0;
		for (unsigned v = 1; v < 63; v++)
			if (v != 21 && v != 42 && k++ == want)
				pat = v;
		for (int i = 0; i < 6; i++)
			if (pat >> i & 1) {
				r[n][0] = (i % 2) * 12, r[n][1] = (i / 2) * 8;
				r[n][2] = r[n][0] + 12, r[n][3] = r[n][1] + 8;
				n++;
			}
		known = true;
	}
	for (int i = 0; i < 8; i++) {
		/* sample i: x in [12 (i%2), 12 (i%2) + 12), y in [6 (i/2), +6) */
		int sx = 12 * (i % 2), sy = 6 * (i / 2);
		double a = 0;
		for (int k = 0; k < n; k++) {
			int w = (r[k][2] < sx + 12 ? r[k][2] : sx + 12) - (r[k][0] > sx ? r[k][0] : sx);
			int h = (r[k][3] < sy + 6 ? r[k][3] : sy + 6) - (r[k][1] > sy ? r[k][1] : sy);
			if (w > 0 && h > 0)
				a += w * h;
		}
		cov[i] = a / 72;
	}
	return known;
}

/* Every glyph of the sextant set has the shape its chart gives, every one
 * has its own code point, and together they hold the 60 sextants, the
 * quadrants, halves and eighth rows. */
static void test_sextant_set_shapes(void **state)
{
	(void)state;
	int n = symbols_count(SYMBOLS_SEXTANT);
	assert_int_equal(n, 64 + 12 + 12);
	for (int g = 0; g < n; g++) {
		uint32_t cp = symbols_codepoint(SYMBOLS_SEXTANT, (unsigned)g);
		double want[8];
		if (!chart_cover(cp, want))
			fail_msg("sextant glyph %d is U+%04X, not in the chart's table", g, cp);
		float got[8];
		symbols_cover(SYMBOLS_SEXTANT, (unsigned)g, got);
		for (int i = 0; i < 8; i++)
			if (fabs(got[i] - want[i]) > 1e-6)
				fail_msg("U+%04X sample %d: %g inked, the chart %g", cp, i, got[i], want[i]);
		for (int o = 0; o < g; o++)
			assert_true(symbols_codepoint(SYMBOLS_SEXTANT, (unsigned)o) != cp);
		assert_int_equal(symbols_mask_of(SYMBOLS_SEXTANT, cp), g);
	}
	/* LOWER ONE QUARTER BLOCK inks the last sample row; UPPER ONE EIGHTH
	 * BLOCK half of the first; a sextant's middle row 2/3 of rows 1, 2. */
	float c[8];
	symbols_cover(SYMBOLS_SEXTANT, (unsigned)symbols_mask_of(SYMBOLS_SEXTANT, 0x2582), c);
	assert_near(c[6], 1, 1e-6);
	assert_near(c[5], 0, 1e-6);
	symbols_cover(SYMBOLS_SEXTANT, (unsigned)symbols_mask_of(SYMBOLS_SEXTANT, 0x2594), c);
	assert_near(c[1], 0.5, 1e-6);
	symbols_cover(SYMBOLS_SEXTANT, 4 | 8, c);
	assert_near(c[2], 2.0 / 3, 1e-6);
	assert_near(c[5], 2.0 / 3, 1e-6);
	assert_near(c[0], 0, 1e-6);
}

/* The least squared error of showing x[8] with the chart's glyph cov, the
 * two colours from the regression of x on the ink's share (slope = the
 * ink's colour less the paper's), clamped to 0..255: +inf when the glyph
 * has one colour. */
static double brute_glyph(const double cov[8], const float x[8][3])
{
	double mc = 0, vc = 0;
	for (int i = 0; i < 8; i++)
		mc += cov[i] / 8;
	for (int i = 0; i < 8; i++)
		vc += (cov[i] - mc) * (cov[i] - mc);
	if (vc < 1e-9)
		return INFINITY;
	double e = 0;
	for (int ch = 0; ch < 3; ch++) {
		double mx = 0, cx = 0;
		for (int i = 0; i < 8; i++)
			mx += x[i][ch] / 8;
		for (int i = 0; i < 8; i++)
			cx += (cov[i] - mc) * (x[i][ch] - mx);
		double slope = cx / vc, paper = mx - slope * mc, ink = paper + slope;
		paper = paper < 0 ? 0 : paper > 255 ? 255 : paper;
		ink = ink < 0 ? 0 : ink > 255 ? 255 : ink;
		for (int i = 0; i < 8; i++) {
			double d = x[i][ch] - (cov[i] * ink + (1 - cov[i]) * paper);
			e += d * d;
		}
	}
	return e;
}

static void test_fit_cover(void **state)
{
	(void)state;
	symbols_shapes *sh = malloc(sizeof *sh);
	symbols_shapes_init(sh, SYMBOLS_SEXTANT);
	float x[8][3];
	unsigned id;
	uint8_t a[3], b[3];
	/* The top sample row red, the rest blue: UPPER ONE QUARTER BLOCK (or
	 * LOWER THREE QUARTERS, colours swapped) shows it exactly, which no
	 * sextant does (a sextant row is 4/3 sample rows). */
	for (int i = 0; i < 8; i++) {
		x[i][0] = i < 2 ? 255 : 0;
		x[i][1] = 0;
		x[i][2] = i < 2 ? 0 : 255;
	}
	assert_near(symbols_fit_cover(sh, (const float(*)[3])x, 0, &id, a, b), 0, 1e-6);
	uint32_t cp = symbols_codepoint(SYMBOLS_SEXTANT, id);
	assert_true(cp == 0x1fb82 || cp == 0x2586);
	const uint8_t *red = cp == 0x1fb82 ? a : b;
	assert_int_equal(red[0], 255);
	assert_int_equal(red[2], 0);
	/* Rows of 0, 0, 0, 100: LOWER ONE QUARTER BLOCK of 100 on 0 shows them
	 * exactly (as does LOWER ONE EIGHTH BLOCK of 200, half of the last
	 * row); the samples shown are the cell's. */
	for (int i = 0; i < 8; i++)
		for (int c = 0; c < 3; c++)
			x[i][c] = i >= 6 ? 100 : 0;
	assert_near(symbols_fit_cover(sh, (const float(*)[3])x, 0, &id, a, b), 0, 1e-6);
	double cv[8];
	assert_true(chart_cover(symbols_codepoint(SYMBOLS_SEXTANT, id), cv));
	for (int i = 0; i < 8; i++)
		assert_near(cv[i] * a[1] + (1 - cv[i]) * b[1], x[i][1], 1e-9);
	/* Random cells: the fit's error is the least over the chart's glyphs
	 * (where no colour is clamped, the fit is the exact optimum). */
	test_rng r = {7};
	for (int t = 0; t < 400; t++) {
		for (int i = 0; i < 8; i++)
			for (int c = 0; c < 3; c++)
				x[i][c] = (float)(t % 2 ? trand(&r) * 255 : (i / 2 + (i % 2) * (t % 5)) % 3 * 100 + trand(&r) * 8);
		double best = INFINITY, flat = 0;
		for (int c = 0; c < 3; c++) {
			double m = 0;
			for (int i = 0; i < 8; i++)
				m += x[i][c] / 8;
			for (int i = 0; i < 8; i++)
				flat += (x[i][c] - m) * (x[i][c] - m);
		}
		for (int g = 0; g < symbols_count(SYMBOLS_SEXTANT); g++) {
			double cov[8];
			assert_true(chart_cover(symbols_codepoint(SYMBOLS_SEXTANT, (unsigned)g), cov));
			double e = brute_glyph(cov, (const float(*)[3])x);
			best = e < best ? e : best;
		}
		best = best < flat ? best : flat;
		double e = symbols_fit_cover(sh, (const float(*)[3])x, 0, &id, a, b);
		assert_near(e, best, 1e-3 * (1 + e));
	}
	free(sh);
}

/* What the terminal shows of a symbol frame: every subpixel of every cell
 * in the colour the frame's cell gives it. */
static void assert_screen_is_symbols(const emu *e, const frame *f)
{
	for (int y = 0; y < f->rows; y++)
		for (int x = 0; x < f->cols; x++) {
			const emu_cell *c = &e->cell[(f->y0 + y) * e->cols + f->x0 + x];
			frame_cell want = f->cur[y * f->cols + x];
			if (f->sym == SYMBOLS_SEXTANT) {
				/* each sample's mix of the colours, the glyph's shape from
				 * the chart's table */
				double cs[8];
				float cw[8];
				if (!chart_cover(c->ch, cs))
					fail_msg("cell %d,%d shows U+%04X, not a sextant set glyph", y, x, c->ch);
				symbols_cover(f->sym, want.mask, cw);
				for (int i = 0; i < 8; i++)
					for (int sh = 0; sh <= 24; sh += 8) { /* byte 3: the default colour */
						double shown = cs[i] * (c->fg >> sh & 255) + (1 - cs[i]) * (c->bg >> sh & 255);
						double expect = cw[i] * (want.top >> sh & 255) + (1 - cw[i]) * (want.bot >> sh & 255);
						if (fabs(shown - expect) > 1e-3)
							fail_msg("cell %d,%d sample %d shows %g, expected %g", y, x, i, shown, expect);
					}
				continue;
			}
			int m = symbols_mask_of(f->sym, c->ch);
			if (m < 0)
				fail_msg("cell %d,%d shows U+%04X, not a %s glyph", y, x, c->ch, symbols_name(f->sym));
			for (int i = 0; i < f->nsub; i++) {
				uint32_t shown = m >> i & 1 ? c->fg : c->bg;
				uint32_t expect = want.mask >> i & 1 ? want.top : want.bot;
				if (shown != expect)
					fail_msg("cell %d,%d subpixel %d shows %08x, expected %08x", y, x, i, shown,
					         expect);
			}
		}
}

static void round_trip(symbols_kind sym, frame_palette pal, bool rd)
{
	const int cols = 23, rows = 7;
	test_rng r = {(uint64_t)sym * 31 + (uint64_t)pal};
	frame *f = frame_new_symbols(cols, rows, pal, sym);
	assert_non_null(f);
	if (!rd)
		f->lambda = 0; /* the best fit, cell by cell */
	f->x0 = 2;
	f->y0 = 1;
	emu e;
	emu_init(&e, cols + 4, rows + 3);
	/* Blocks of colour with edges, an odd place: the letterbox's edges
	 * are partly covered cells. */
	int w = cols * 2 - 3, h = rows * 4 - 5;
	uint8_t *img = malloc((size_t)w * h * 3);
	for (int round = 0; round < 12; round++) {
		for (int y = 0; y < h; y++)
			for (int x = 0; x < w; x++)
				for (int c = 0; c < 3; c++)
					img[((size_t)y * w + x) * 3 + c] =
					    (uint8_t)(((x / (1 + round % 3) + y / 3 + c + round) % 4) * 80 + (int)(trand(&r) * 4));
		frame_put_image(f, img, w, h, 1, 2);
		const abuf *out = frame_update(f);
		emu_feed(&e, out->b, out->len);
		assert_screen_is_symbols(&e, f);
		assert_false(frame_dirty(f));
	}
	/* The cells fully inside the picture hold the best fit. */
	for (int cy = 1; cy < rows - 1; cy++)
		for (int cx = 1; cx < cols - 2; cx++) {
			float sub[8][3];
			size_t cw = (size_t)cols * 2;
			unsigned mask;
			uint8_t a[3], b[3];
			if (f->cover) {
				for (int i = 0; i < 8; i++)
					for (int c = 0; c < 3; c++)
						sub[i][c] = f->px[((size_t)(cy * 4 + i / 2) * cw + (size_t)cx * 2 + i % 2) * 3 + c];
				symbols_fit_cover(&f->shapes, (const float(*)[3])sub, f->flat, &mask, a, b);
			} else {
				symbols_subpixels(sym, f->px + ((size_t)cy * 4 * cw + (size_t)cx * 2) * 3, cw * 3, sub);
				symbols_fit((const float(*)[3])sub, f->nsub, f->flat, &mask, a, b);
			}
			frame_cell c = f->cur[cy * cols + cx];
			if (pal == PALETTE_TRUECOLOR && mask && !rd) {
				assert_true(c.mask == mask);
				assert_int_equal(c.top, (uint32_t)a[0] << 16 | (uint32_t)a[1] << 8 | a[2]);
			}
		}
	free(img);
	emu_free(&e);
	frame_free(f);
}

static void test_round_trips(void **state)
{
	(void)state;
	for (int s = SYMBOLS_QUADRANT; s <= SYMBOLS_OCTANT; s++) {
		round_trip((symbols_kind)s, PALETTE_TRUECOLOR, false);
		round_trip((symbols_kind)s, PALETTE_TRUECOLOR, true);
		round_trip((symbols_kind)s, PALETTE_256, true);
		round_trip((symbols_kind)s, PALETTE_16, true);
	}
}

/* A grey ramp of one level a cell, flat cells: the rate-distortion pass
 * keeps the colour before while its error, 24 d^2 (8 samples, 3 channels,
 * d levels off), and the glyph's 4 bytes cost less than the new colour's
 * 20 (\e[48;2;v;v;vm and the glyph), each byte worth lambda = 5: 24 d^2 + 20
 * < 100 for d = 1, not 2. So every other cell sends its colour: a cell
 * costs (17 + 1) / 2 bytes instead of 17 ("\e[48;2;41;41;41m "), and none is
 * off by more than 1 level. */
static void test_rate_distortion_ramp(void **state)
{
	(void)state;
	const int cols = 60, rows = 2;
	uint8_t img[2 * 60 * 4 * 2 * 3];
	for (int y = 0; y < rows * 4; y++)
		for (int x = 0; x < cols * 2; x++)
			memset(img + ((size_t)y * cols * 2 + x) * 3, 40 + x / 2, 3);
	size_t bytes[2];
	for (int rd = 0; rd < 2; rd++) {
		frame *f = frame_new_symbols(cols, rows, PALETTE_TRUECOLOR, SYMBOLS_SEXTANT);
		assert_non_null(f);
		if (!rd)
			f->lambda = 0;
		else
			assert_near(f->lambda, FRAME_LAMBDA, 0);
		frame_put_image(f, img, cols * 2, rows * 4, 0, 0);
		for (int i = 0; i < cols * rows; i++) {
			frame_cell c = f->cur[i];
			int want = 40 + i % cols;
			for (int k = 0; k < 2; k++) {
				int v = (int)((k ? c.bot : c.top) & 255);
				assert_true(abs(v - want) <= (rd ? 1 : 0));
			}
		}
		bytes[rd] = frame_update(f)->len;
		frame_free(f);
	}
	assert_true(bytes[1] * 10 < bytes[0] * 6);
}

static void test_choose(void **state)
{
	(void)state;
	assert_int_equal(symbols_choose(NULL, NULL, NULL, false), SYMBOLS_HALF);
	assert_int_equal(symbols_choose("WezTerm", NULL, NULL, false), SYMBOLS_SEXTANT);
	assert_int_equal(symbols_choose(NULL, "foot(1.16.2)", NULL, false), SYMBOLS_SEXTANT);
	assert_int_equal(symbols_choose(NULL, "XTerm(379)", NULL, false), SYMBOLS_HALF);
	assert_int_equal(symbols_choose("tmux", "tmux 3.3a", NULL, true), SYMBOLS_HALF);
	assert_int_equal(symbols_choose(NULL, NULL, "7200", false), SYMBOLS_SEXTANT);
	/* kitty's octants came with 0.40.0 (its changelog), its sextants and
	 * eighth blocks with 0.19.0; without a version, sextants. */
	assert_int_equal(symbols_choose(NULL, "kitty(0.40.0)", NULL, false), SYMBOLS_OCTANT);
	assert_int_equal(symbols_choose("kitty", "kitty(0.42.1)", NULL, false), SYMBOLS_OCTANT);
	assert_int_equal(symbols_choose(NULL, "kitty(0.39.1)", NULL, false), SYMBOLS_SEXTANT);
	assert_int_equal(symbols_choose(NULL, "kitty(0.18.3)", NULL, false), SYMBOLS_HALF);
	assert_int_equal(symbols_choose("kitty", NULL, NULL, false), SYMBOLS_SEXTANT);
	assert_int_equal(symbols_choose(NULL, "kitty(x)", NULL, false), SYMBOLS_SEXTANT);
	symbols_kind k;
	assert_true(symbols_parse("octant", &k));
	assert_int_equal(k, SYMBOLS_OCTANT);
	assert_false(symbols_parse("braille", &k));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_codepoints_by_name),
		cmocka_unit_test(test_subpixel_areas),
		cmocka_unit_test(test_fit_by_hand),
		cmocka_unit_test(test_sextant_set_shapes),
		cmocka_unit_test(test_fit_cover),
		cmocka_unit_test(test_round_trips),
		cmocka_unit_test(test_rate_distortion_ramp),
		cmocka_unit_test(test_choose),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
