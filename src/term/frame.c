/* rtsh — the half-block frame encoder (frame.h).
 *
 * Per row, the cells that changed are grouped in runs (a gap of up to
 * GAP_FILL unchanged cells is sent again rather than skipped, as a cursor
 * move costs about as much). Within a run, each cell has one or two ways to
 * be drawn (space or full block for one colour; upper or lower half block
 * for two), and a Viterbi pass over the run picks the ways that need the
 * fewest SGR bytes, given that a space keeps the foreground and a full
 * block keeps the background of the cell before.
 */
#include "term/frame.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rtsh/image.h"
#include "rtsh/memory.h"

#define UNKNOWN 0xffffffffu /* SGR state not known */
#define GAP_FILL 3
/* A run of changed cells is drawn in pieces of at most this many cells, so
 * that a part (frame_update_part) ends close to its budget; the SGR state
 * and the cursor carry over, so a piece costs no byte more. */
#define RUN_MAX 16

frame *frame_new(int cols, int rows, frame_palette pal)
{
	return frame_new_symbols(cols, rows, pal, SYMBOLS_HALF);
}

frame *frame_new_symbols(int cols, int rows, frame_palette pal, symbols_kind sym)
{
	if (cols < 1 || rows < 1 || sym < SYMBOLS_HALF || sym >= SYMBOLS_AUTO)
		return NULL;
	if (pal == PALETTE_NONE)
		sym = SYMBOLS_HALF;
	frame *f = calloc(1, sizeof *f);
	if (!f)
		return NULL;
	size_t n = (size_t)cols * (size_t)rows;
	f->cols = cols;
	f->rows = rows;
	f->pal = pal;
	f->sync = true;
	f->sym = sym;
	f->nsub = symbols_table[sym].w * symbols_table[sym].h;
	f->lambda = FRAME_LAMBDA;
	for (unsigned m = 0; m < (unsigned)symbols_count(sym); m++)
		f->glyph_len[m] = (uint8_t)symbols_utf8(sym, m, f->glyph[m]);
	symbols_shapes_init(&f->shapes, sym);
	f->cover = sym == SYMBOLS_SEXTANT;
	f->cur = calloc(n, sizeof *f->cur);
	f->shown = calloc(n, sizeof *f->shown);
	size_t ns = n * (sym == SYMBOLS_HALF ? 2 : SYMBOLS_SAMPLE_W * SYMBOLS_SAMPLE_H);
	f->px = calloc(ns, 3);
	f->def = calloc(ns, 1);
	abuf_init(&f->out);
	if (!f->cur || !f->shown || !f->px || !f->def) {
		frame_free(f);
		return NULL;
	}
	frame_clear(f);
	return f;
}

void frame_free(frame *f)
{
	if (!f)
		return;
	abuf_free(&f->out);
	mem_free_all(f->cur, f->shown, f->px, f->def, f);
}

void frame_invalidate(frame *f)
{
	f->have_shown = false;
}

void frame_clear(frame *f)
{
	frame_cell blank = {FRAME_DEFAULT, FRAME_DEFAULT, f->sym == SYMBOLS_HALF};
	if (f->pal == PALETTE_NONE)
		blank = (frame_cell){' ', ' ', 1};
	for (size_t i = 0; i < (size_t)f->cols * (size_t)f->rows; i++)
		f->cur[i] = blank;
	if (f->def)
		memset(f->def, 0,
		       (size_t)f->cols * f->rows * (f->sym == SYMBOLS_HALF ? 2 : SYMBOLS_SAMPLE_W * SYMBOLS_SAMPLE_H));
}

/* --- palettes --- */

static const uint8_t xterm16[16][3] = {
	{0, 0, 0},       {205, 0, 0},   {0, 205, 0},   {205, 205, 0},
	{0, 0, 238},     {205, 0, 205}, {0, 205, 205}, {229, 229, 229},
	{127, 127, 127}, {255, 0, 0},   {0, 255, 0},   {255, 255, 0},
	{92, 92, 255},   {255, 0, 255}, {0, 255, 255}, {255, 255, 255},
};
static const uint8_t cube_level[6] = {0, 95, 135, 175, 215, 255};

void palette_rgb(unsigned index, uint8_t rgb[3])
{
	if (index < 16) {
		memcpy(rgb, xterm16[index], 3);
	} else if (index < 232) {
		unsigned c = index - 16;
		rgb[0] = cube_level[c / 36];
		rgb[1] = cube_level[c / 6 % 6];
		rgb[2] = cube_level[c % 6];
	} else {
		rgb[0] = rgb[1] = rgb[2] = (uint8_t)(8 + 10 * (index > 255 ? 23 : index - 232));
	}
}

/* The cube level nearest to v (the levels are not evenly spaced). */
static int cube_nearest(int v)
{
	int best = 0;
	for (int i = 1; i < 6; i++)
		if (abs(v - cube_level[i]) < abs(v - cube_level[best]))
			best = i;
	return best;
}

static int dist2(int r, int g, int b, const uint8_t c[3])
{
	int dr = r - c[0], dg = g - c[1], db = b - c[2];
	return dr * dr + dg * dg + db * db;
}

uint8_t palette_256(uint8_t r, uint8_t g, uint8_t b)
{
	/* The cube is a grid: its nearest point is the nearest level per channel. */
	int cube = 16 + 36 * cube_nearest(r) + 6 * cube_nearest(g) + cube_nearest(b);
	/* The nearest grey (v,v,v) is at the mean; the ramp's nearest level to
	 * the mean is then the nearest ramp colour. */
	double mean = (r + g + b) / 3.0;
	int k = (int)lround((mean - 8) / 10);
	k = k < 0 ? 0 : k > 23 ? 23 : k;
	int grey = 232 + k;
	uint8_t cc[3], gc[3];
	palette_rgb((unsigned)cube, cc);
	palette_rgb((unsigned)grey, gc);
	return (uint8_t)(dist2(r, g, b, gc) < dist2(r, g, b, cc) ? grey : cube);
}

uint8_t palette_16(uint8_t r, uint8_t g, uint8_t b)
{
	int best = 0;
	for (int i = 1; i < 16; i++)
		if (dist2(r, g, b, xterm16[i]) < dist2(r, g, b, xterm16[best]))
			best = i;
	return (uint8_t)best;
}

uint32_t palette_quantize(frame_palette pal, uint8_t r, uint8_t g, uint8_t b)
{
	switch (pal) {
	case PALETTE_TRUECOLOR:
		return (uint32_t)r << 16 | (uint32_t)g << 8 | b;
	case PALETTE_256:
		return palette_256(r, g, b);
	case PALETTE_16:
		return palette_16(r, g, b);
	case PALETTE_NONE:
		break;
	}
	uint8_t c[3] = {r, g, b};
	return (uint32_t)frame_ascii(c, c);
}

char frame_ascii(const uint8_t top[3], const uint8_t bot[3])
{
	static const char ramp[] = " .:-=+*#%@";
	/* Rec. 709 luma weights on the sRGB codes, 0..255 for both pixels. */
	double y = (0.2126 * (top[0] + bot[0]) + 0.7152 * (top[1] + bot[1]) + 0.0722 * (top[2] + bot[2])) / 2;
	int i = (int)(y * 10 / 256);
	return ramp[i < 0 ? 0 : i > 9 ? 9 : i];
}

void frame_srgb_from_linear(const float *rgb, size_t npix, double exposure, uint8_t *out)
{
	double k = exp2(exposure);
	for (size_t i = 0; i < npix * 3; i++)
		out[i] = linear_to_srgb8(rgb[i] * k);
}

/* Fits cell (cx, cy) of a symbol frame to its canvas samples. */
static void fit_cell(frame *f, int cx, int cy)
{
	enum { SW = SYMBOLS_SAMPLE_W, SH = SYMBOLS_SAMPLE_H };
	size_t cw = (size_t)f->cols * SW;
	size_t at = (size_t)cy * SH * cw + (size_t)cx * SW;
	const uint8_t *px = f->px + at * 3, *def = f->def + at;
	int ndef = 0;
	for (int y = 0; y < SH; y++)
		for (int x = 0; x < SW; x++)
			ndef += def[y * cw + x] != 0;
	frame_cell *c = &f->cur[(size_t)cy * f->cols + cx];
	if (ndef == 0) {
		*c = (frame_cell){FRAME_DEFAULT, FRAME_DEFAULT, 0};
		return;
	}
	float sub[8][3];
	uint8_t a[3], b[3];
	unsigned mask;
	if (ndef < SW * SH) {
		/* The edge of a letterboxed picture: the subpixels mostly covered
		 * show the mean of its samples there, the rest the default
		 * background (which only a background colour can show). */
		const symbol_set *set = &symbols_table[f->sym];
		uint8_t cov[SH][SW][3];
		for (int y = 0; y < SH; y++)
			for (int x = 0; x < SW; x++)
				memset(cov[y][x], def[y * cw + x] ? 255 : 0, 3);
		symbols_subpixels(f->sym, &cov[0][0][0], SW * 3, sub);
		mask = 0;
		for (int i = 0; i < set->w * set->h; i++)
			if (sub[i][0] > 127.5f)
				mask |= 1u << i;
		double acc[3] = {0, 0, 0};
		for (int y = 0; y < SH; y++)
			for (int x = 0; x < SW; x++)
				if (def[y * cw + x])
					for (int ch = 0; ch < 3; ch++)
						acc[ch] += px[(y * cw + x) * 3 + ch];
		for (int ch = 0; ch < 3; ch++)
			a[ch] = (uint8_t)(acc[ch] / ndef + 0.5);
		*c = (frame_cell){palette_quantize(f->pal, a[0], a[1], a[2]), FRAME_DEFAULT, mask};
		if (mask == 0)
			*c = (frame_cell){FRAME_DEFAULT, FRAME_DEFAULT, 0};
		else if (mask == (1u << f->nsub) - 1)
			*c = (frame_cell){c->top, c->top, 0};
		return;
	}
	if (f->cover) {
		for (int i = 0; i < SW * SH; i++)
			for (int ch = 0; ch < 3; ch++)
				sub[i][ch] = px[((size_t)(i / SW) * cw + (size_t)(i % SW)) * 3 + ch];
		symbols_fit_cover(&f->shapes, (const float(*)[3])sub, f->flat, &mask, a, b);
	} else {
		symbols_subpixels(f->sym, px, cw * 3, sub);
		symbols_fit((const float(*)[3])sub, f->nsub, f->flat, &mask, a, b);
	}
	uint32_t qa = palette_quantize(f->pal, a[0], a[1], a[2]);
	uint32_t qb = palette_quantize(f->pal, b[0], b[1], b[2]);
	if (mask == 0 || qa == qb)
		*c = (frame_cell){qa, qa, 0};
	else
		*c = (frame_cell){qa, qb, mask};
}

static int param_len(frame_palette pal, uint32_t v, bool bg);

/* The squared error (sRGB levels, summed over the cell's samples) of
 * showing subpixels sub[n] as a where mask has them, b elsewhere. */
static double cell_error(const float sub[][3], int n, uint32_t mask, uint32_t a, uint32_t b)
{
	double e = 0;
	for (int i = 0; i < n; i++) {
		uint32_t v = mask >> i & 1 ? a : b;
		for (int c = 0; c < 3; c++) {
			double d = sub[i][c] - (double)(v >> (16 - 8 * c) & 255);
			e += d * d;
		}
	}
	return e * (SYMBOLS_SAMPLE_W * SYMBOLS_SAMPLE_H) / n;
}

/* Bytes of the colours of a cell (a, and b when two) that the SGR state
 * (fg, bg) does not hold, and of its glyph: about what the update sends. */
static int cell_bytes(const frame *f, uint32_t a, uint32_t b, bool two, uint32_t fg, uint32_t bg)
{
	int n = 4, k = 0;
	if (a != fg && a != bg)
		n += param_len(f->pal, a, false), k++;
	if (two && b != fg && b != bg && b != a)
		n += param_len(f->pal, b, true), k++;
	return n + (k ? 2 + k : 0);
}

static int colour_dist2(uint32_t a, uint32_t b)
{
	int d = 0;
	for (int sh = 0; sh < 24; sh += 8) {
		int e = (int)(a >> sh & 255) - (int)(b >> sh & 255);
		d += e * e;
	}
	return d;
}

static uint32_t rgb_of(const float c[3])
{
	uint32_t v = 0;
	for (int ch = 0; ch < 3; ch++) {
		long r = lroundf(c[ch]);
		v = v << 8 | (uint32_t)(r < 0 ? 0 : r > 255 ? 255 : r);
	}
	return v;
}

/* Rate and distortion along row cy of a truecolor symbol frame: a cell may
 * keep a colour of the cell before it (its SGR state), or take one colour,
 * when that costs less than f->lambda squared error (sRGB levels over its
 * samples) a byte saved. The row is walked left to right, as an update
 * sends it. */
static void rd_row(frame *f, int cy)
{
	enum { SW = SYMBOLS_SAMPLE_W, SH = SYMBOLS_SAMPLE_H };
	size_t cw = (size_t)f->cols * SW;
	uint32_t fg = UINT32_MAX, bg = UINT32_MAX; /* not known */
	int n = f->nsub;
	bool half = f->sym == SYMBOLS_HALF;
	for (int cx = 0; cx < f->cols; cx++) {
		frame_cell *c = &f->cur[(size_t)cy * f->cols + cx];
		float sub[8][3];
		bool whole = true;
		if (half) {
			/* the cell's two pixels */
			for (int k = 0; k < 2; k++) {
				size_t i = (size_t)(2 * cy + k) * f->cols + cx;
				whole &= f->def[i] != 0;
				for (int ch = 0; ch < 3; ch++)
					sub[k][ch] = f->px[i * 3 + ch];
			}
		} else {
			size_t at = (size_t)cy * SH * cw + (size_t)cx * SW;
			for (int y = 0; y < SH && whole; y++)
				for (int x = 0; x < SW; x++)
					whole &= f->def[at + y * cw + x] != 0;
			if (whole)
				symbols_subpixels(f->sym, f->px + at * 3, cw * 3, sub);
		}
		if (!whole || c->top == FRAME_DEFAULT || c->bot == FRAME_DEFAULT) {
			fg = c->top;
			bg = c->bot;
			continue;
		}
		/* the fit, and its cost */
		frame_cell best = *c;
		bool two = c->mask != 0 && c->top != c->bot;
		double best_j = cell_error((const float(*)[3])sub, n, c->mask, c->top, c->bot) +
		                f->lambda * cell_bytes(f, c->top, c->bot, two, fg, bg);
		frame_cell cand[7];
		int nc = 0;
		float mean[3] = {0, 0, 0};
		for (int i = 0; i < n; i++)
			for (int ch = 0; ch < 3; ch++)
				mean[ch] += sub[i][ch] / (float)n;
		uint32_t m = rgb_of(mean);
		cand[nc++] = (frame_cell){m, m, 0};
		/* one colour of the state for the whole cell */
		if (fg != UINT32_MAX && fg != FRAME_DEFAULT)
			cand[nc++] = (frame_cell){fg, fg, 0};
		if (bg != UINT32_MAX && bg != FRAME_DEFAULT && bg != fg)
			cand[nc++] = (frame_cell){bg, bg, 0};
		if (fg != UINT32_MAX && bg != UINT32_MAX && fg != FRAME_DEFAULT && bg != FRAME_DEFAULT) {
			/* both colours of the state: each subpixel the nearer */
			uint32_t mask = 0;
			for (int i = 0; i < n; i++)
				if (cell_error((const float(*)[3])sub + i, 1, 1, fg, fg) <
				    cell_error((const float(*)[3])sub + i, 1, 1, bg, bg))
					mask |= 1u << i;
			cand[nc++] = fg == bg ? (frame_cell){fg, fg, 0} : (frame_cell){fg, bg, mask};
		}
		/* one colour of the state for the fit's nearer colour, the other
		 * the mean of the subpixels left to it */
		for (int k = 0; k < 2 && two; k++) {
			uint32_t x = k ? bg : fg;
			if (x == UINT32_MAX || x == FRAME_DEFAULT)
				continue;
			uint32_t mask = 0;
			float rest[3] = {0, 0, 0};
			int nr = 0;
			/* x stands for the fit's colour nearer to it */
			uint32_t other = colour_dist2(x, c->top) < colour_dist2(x, c->bot) ? c->bot : c->top;
			for (int i = 0; i < n; i++) {
				if (cell_error((const float(*)[3])sub + i, 1, 1, x, x) <=
				    cell_error((const float(*)[3])sub + i, 1, 1, other, other)) {
					mask |= 1u << i;
				} else {
					for (int ch = 0; ch < 3; ch++)
						rest[ch] += sub[i][ch];
					nr++;
				}
			}
			if (nr == 0) {
				cand[nc++] = (frame_cell){x, x, 0};
				continue;
			}
			for (int ch = 0; ch < 3; ch++)
				rest[ch] /= (float)nr;
			uint32_t r = rgb_of(rest);
			cand[nc++] = mask && r != x ? (frame_cell){x, r, mask} : (frame_cell){r, r, 0};
		}
		for (int k = 0; k < nc; k++) {
			bool t = cand[k].mask != 0;
			double j = cell_error((const float(*)[3])sub, n, cand[k].mask, cand[k].top, cand[k].bot) +
			           f->lambda * cell_bytes(f, cand[k].top, cand[k].bot, t, fg, bg);
			if (j < best_j) {
				best_j = j;
				best = cand[k];
			}
		}
		if (half) /* as half blocks hold a cell: mask 1, top over bottom */
			best = (frame_cell){best.mask & 1 ? best.top : best.bot, best.mask & 2 ? best.top : best.bot, 1};
		*c = best;
		if (best.mask == 0 || best.top == best.bot) {
			if (best.top != fg && best.top != bg)
				bg = best.top;
		} else {
			fg = best.top;
			bg = best.bot;
		}
	}
}

/* The squared error (sRGB levels) of showing samples x[8] as glyph g of
 * f's shapes in colours a (ink) and b. */
static double cover_error(const frame *f, const float x[8][3], unsigned g, uint32_t a, uint32_t b)
{
	const float *cov = f->shapes.cov[g];
	float va[3], vb[3];
	for (int c = 0; c < 3; c++) {
		va[c] = (float)(a >> (16 - 8 * c) & 255);
		vb[c] = (float)(b >> (16 - 8 * c) & 255) - va[c];
	}
	double e = 0;
	for (int i = 0; i < 8; i++)
		for (int c = 0; c < 3; c++) {
			float d = x[i][c] - va[c] - (1 - cov[i]) * vb[c];
			e += (double)(d * d);
		}
	return e;
}

/* rd_row for frames fitted over the glyphs' shapes (f->cover): the same
 * candidates, each glyph's colours by least squares on its samples. */
static void rd_row_cover(frame *f, int cy)
{
	enum { SW = SYMBOLS_SAMPLE_W, SH = SYMBOLS_SAMPLE_H };
	size_t cw = (size_t)f->cols * SW;
	uint32_t fg = UINT32_MAX, bg = UINT32_MAX; /* not known */
	const symbols_shapes *sh = &f->shapes;
	for (int cx = 0; cx < f->cols; cx++) {
		frame_cell *c = &f->cur[(size_t)cy * f->cols + cx];
		float x[8][3];
		bool whole = true;
		size_t at = (size_t)cy * SH * cw + (size_t)cx * SW;
		for (int i = 0; i < SW * SH; i++) {
			size_t k = at + (size_t)(i / SW) * cw + (size_t)(i % SW);
			whole &= f->def[k] != 0;
			for (int ch = 0; ch < 3; ch++)
				x[i][ch] = f->px[k * 3 + ch];
		}
		if (!whole || c->top == FRAME_DEFAULT || c->bot == FRAME_DEFAULT) {
			fg = c->top;
			bg = c->bot;
			continue;
		}
		frame_cell best = *c;
		bool two = c->mask != 0 && c->top != c->bot;
		double best_j = cover_error(f, (const float(*)[3])x, c->mask, c->top, c->bot) +
		                f->lambda * cell_bytes(f, c->top, c->bot, two, fg, bg);
		frame_cell cand[7];
		int nc = 0;
		float mean[3] = {0, 0, 0};
		for (int i = 0; i < 8; i++)
			for (int ch = 0; ch < 3; ch++)
				mean[ch] += x[i][ch] / 8;
		uint32_t m = rgb_of(mean);
		cand[nc++] = (frame_cell){m, m, 0};
		if (fg != UINT32_MAX && fg != FRAME_DEFAULT)
			cand[nc++] = (frame_cell){fg, fg, 0};
		if (bg != UINT32_MAX && bg != FRAME_DEFAULT && bg != fg)
			cand[nc++] = (frame_cell){bg, bg, 0};
		if (fg != UINT32_MAX && bg != UINT32_MAX && fg != FRAME_DEFAULT && bg != FRAME_DEFAULT && fg != bg) {
			/* both colours of the state: the glyph that shows them best.
			 * With d = fg - bg, sample i shows bg + c_i d, off by
			 * |x_i - bg|^2 - 2 c_i (x_i - bg).d + c_i^2 |d|^2: only the
			 * last two terms differ from glyph to glyph. */
			double p[8], dd = 0, d[3];
			for (int ch = 0; ch < 3; ch++) {
				d[ch] = (double)(fg >> (16 - 8 * ch) & 255) - (double)(bg >> (16 - 8 * ch) & 255);
				dd += d[ch] * d[ch];
			}
			for (int i = 0; i < 8; i++) {
				p[i] = 0;
				for (int ch = 0; ch < 3; ch++)
					p[i] += (x[i][ch] - (double)(bg >> (16 - 8 * ch) & 255)) * d[ch];
			}
			float es[SYMBOLS_COVER_MAX]; /* sum c_i p_i, every glyph at once */
			for (int g = 0; g < SYMBOLS_COVER_MAX; g++)
				es[g] = 0;
			for (int i = 0; i < 8; i++)
				for (int g = 0; g < SYMBOLS_COVER_MAX; g++)
					es[g] += sh->covt[i][g] * (float)p[i];
			unsigned bg_id = 0;
			double be = 0; /* glyph 0, all paper */
			for (int g = 1; g < sh->n && g < SYMBOLS_COVER_MAX; g++) {
				double e = sh->uu[g] * dd - 2 * (double)es[g];
				if (e < be) {
					be = e;
					bg_id = (unsigned)g;
				}
			}
			cand[nc++] = (frame_cell){fg, bg, bg_id};
		}
		/* one colour of the state for the fit's nearer colour, the other
		 * by least squares with the fit's glyph */
		for (int k = 0; k < 2 && two; k++) {
			uint32_t xs = k ? bg : fg;
			if (xs == UINT32_MAX || xs == FRAME_DEFAULT)
				continue;
			/* xs takes the ink when nearer to c->top, else the paper */
			bool ink = colour_dist2(xs, c->top) < colour_dist2(xs, c->bot);
			const float *cov = sh->cov[c->mask];
			double ww = 0, r[3] = {0, 0, 0};
			for (int i = 0; i < 8; i++) {
				double wf = ink ? cov[i] : 1 - cov[i], wo = 1 - wf; /* xs's share, the other's */
				ww += wo * wo;
				for (int ch = 0; ch < 3; ch++)
					r[ch] += wo * (x[i][ch] - wf * (double)(xs >> (16 - 8 * ch) & 255));
			}
			if (ww <= 0)
				continue;
			float o[3];
			for (int ch = 0; ch < 3; ch++)
				o[ch] = (float)(r[ch] / ww);
			uint32_t ov = rgb_of(o);
			if (ov == xs)
				cand[nc++] = (frame_cell){xs, xs, 0};
			else
				cand[nc++] = ink ? (frame_cell){xs, ov, c->mask} : (frame_cell){ov, xs, c->mask};
		}
		for (int k = 0; k < nc; k++) {
			bool t = cand[k].mask != 0 && cand[k].top != cand[k].bot;
			double j = cover_error(f, (const float(*)[3])x, cand[k].mask, cand[k].top, cand[k].bot) +
			           f->lambda * cell_bytes(f, cand[k].top, cand[k].bot, t, fg, bg);
			if (j < best_j) {
				best_j = j;
				best = cand[k];
			}
		}
		*c = best;
		if (best.mask == 0 || best.top == best.bot) {
			if (best.top != fg && best.top != bg)
				bg = best.top;
		} else {
			fg = best.top;
			bg = best.bot;
		}
	}
}

/* frame_put_image for the symbol sets: the samples, then every cell they
 * touch fitted again. */
static void put_symbols(frame *f, const uint8_t *rgb, int w, int h, int ox, int oy)
{
	int cw = f->cols * SYMBOLS_SAMPLE_W, ch = f->rows * SYMBOLS_SAMPLE_H;
	int x0 = ox < 0 ? 0 : ox, y0 = oy < 0 ? 0 : oy;
	int x1 = ox + w < cw ? ox + w : cw, y1 = oy + h < ch ? oy + h : ch;
	if (x1 <= x0 || y1 <= y0)
		return;
	for (int y = y0; y < y1; y++) {
		memcpy(f->px + ((size_t)y * cw + x0) * 3, rgb + ((size_t)(y - oy) * w + (x0 - ox)) * 3,
		       (size_t)(x1 - x0) * 3);
		memset(f->def + (size_t)y * cw + x0, 1, (size_t)(x1 - x0));
	}
	for (int cy = y0 / SYMBOLS_SAMPLE_H; cy <= (y1 - 1) / SYMBOLS_SAMPLE_H; cy++) {
		for (int cx = x0 / SYMBOLS_SAMPLE_W; cx <= (x1 - 1) / SYMBOLS_SAMPLE_W; cx++)
			fit_cell(f, cx, cy);
		if (f->lambda > 0 && f->pal == PALETTE_TRUECOLOR) {
			if (f->cover)
				rd_row_cover(f, cy);
			else
				rd_row(f, cy);
		}
	}
}

void frame_put_image(frame *f, const uint8_t *rgb, int w, int h, int ox, int oy)
{
	int ph = 2 * f->rows;
	if (f->sym != SYMBOLS_HALF) {
		put_symbols(f, rgb, w, h, ox, oy);
		return;
	}
	if (f->pal == PALETTE_NONE) {
		/* One character per cell: only whole cells of the image count. */
		for (int cy = 0; cy < f->rows; cy++) {
			int y0 = 2 * cy - oy, y1 = y0 + 1;
			if (y0 < 0 || y1 >= h)
				continue;
			for (int cx = 0; cx < f->cols; cx++) {
				int x = cx - ox;
				if (x < 0 || x >= w)
					continue;
				char c = frame_ascii(rgb + ((size_t)y0 * w + x) * 3, rgb + ((size_t)y1 * w + x) * 3);
				f->cur[(size_t)cy * f->cols + cx] = (frame_cell){(uint8_t)c, (uint8_t)c, 1};
			}
		}
		return;
	}
	for (int y = 0; y < h; y++) {
		int py = y + oy;
		if (py < 0 || py >= ph)
			continue;
		for (int x = 0; x < w; x++) {
			int px = x + ox;
			if (px < 0 || px >= f->cols)
				continue;
			const uint8_t *p = rgb + ((size_t)y * w + x) * 3;
			uint32_t v = palette_quantize(f->pal, p[0], p[1], p[2]);
			frame_cell *c = &f->cur[(size_t)(py / 2) * f->cols + px];
			if (py % 2 == 0)
				c->top = v;
			else
				c->bot = v;
			memcpy(f->px + ((size_t)py * f->cols + px) * 3, p, 3);
			f->def[(size_t)py * f->cols + px] = 1;
		}
	}
	if (f->lambda > 0 && f->pal == PALETTE_TRUECOLOR) {
		int y0 = oy < 0 ? 0 : oy, y1 = oy + h < ph ? oy + h : ph;
		for (int cy = y0 / 2; cy < (y1 + 1) / 2; cy++)
			rd_row(f, cy);
	}
}

/* --- SGR --- */

static int digits(unsigned v)
{
	return v >= 100 ? 3 : v >= 10 ? 2 : 1;
}

/* The length of the SGR parameters that set colour v as fg or bg. */
static int param_len(frame_palette pal, uint32_t v, bool bg)
{
	if (v == FRAME_DEFAULT)
		return 2; /* 49 (39 is never needed: the default is only a background) */
	switch (pal) {
	case PALETTE_TRUECOLOR:
		return 7 + digits(v >> 16) + digits(v >> 8 & 255) + digits(v & 255);
	case PALETTE_256:
		return 5 + digits(v);
	case PALETTE_16:
		return bg && v >= 8 ? 3 : 2;
	case PALETTE_NONE:
		break;
	}
	return 0;
}

static void put_param(abuf *a, frame_palette pal, uint32_t v, bool bg)
{
	if (v == FRAME_DEFAULT) {
		abuf_str(a, bg ? "49" : "39");
		return;
	}
	switch (pal) {
	case PALETTE_TRUECOLOR:
		abuf_str(a, bg ? "48;2;" : "38;2;");
		abuf_uint(a, v >> 16);
		abuf_char(a, ';');
		abuf_uint(a, v >> 8 & 255);
		abuf_char(a, ';');
		abuf_uint(a, v & 255);
		return;
	case PALETTE_256:
		abuf_str(a, bg ? "48;5;" : "38;5;");
		abuf_uint(a, v);
		return;
	case PALETTE_16:
		abuf_uint(a, v < 8 ? (bg ? 40 : 30) + v : (bg ? 100 : 90) + v - 8);
		return;
	case PALETTE_NONE:
		return;
	}
}

typedef struct sgr {
	uint32_t fg, bg;
} sgr;

/* A way to draw a cell: the glyph of `mask` (0: a space; the full mask:
 * U+2588) in colours fg on bg. */
typedef struct way {
	uint32_t mask;
	uint32_t fg, bg; /* UNKNOWN: this way keeps the current one */
} way;

/* The one or two ways to draw cell c in frame f; returns how many. */
static int ways_of(const frame *f, frame_cell c, way w[2])
{
	uint32_t full = (1u << f->nsub) - 1;
	short comp = f->shapes.comp[c.mask];
	if (c.top == c.bot || c.mask == 0 || c.mask == full) {
		uint32_t v = c.mask == 0 ? c.bot : c.top;
		int n = 0;
		w[n++] = (way){0, UNKNOWN, v};
		if (v != FRAME_DEFAULT)
			w[n++] = (way){full, v, UNKNOWN};
		return n;
	}
	int n = 0;
	if (c.top != FRAME_DEFAULT)
		w[n++] = (way){c.mask, c.top, c.bot};
	if (c.bot != FRAME_DEFAULT && comp >= 0)
		w[n++] = (way){(uint32_t)comp, c.bot, c.top};
	return n;
}

/* Bytes to go from state s to way w, and the state after. */
static int way_cost(const frame *f, sgr s, way w, sgr *after)
{
	bool set_fg = w.fg != UNKNOWN && w.fg != s.fg;
	bool set_bg = w.bg != UNKNOWN && w.bg != s.bg;
	int n = f->glyph_len[w.mask];
	if (set_fg || set_bg)
		n += 3 + (set_fg ? param_len(f->pal, w.fg, false) : 0) + (set_bg ? param_len(f->pal, w.bg, true) : 0) +
		     (set_fg && set_bg);
	after->fg = w.fg != UNKNOWN ? w.fg : s.fg;
	after->bg = w.bg != UNKNOWN ? w.bg : s.bg;
	return n;
}

static void emit_way(abuf *a, const frame *f, sgr *s, way w)
{
	frame_palette pal = f->pal;
	bool set_fg = w.fg != UNKNOWN && w.fg != s->fg;
	bool set_bg = w.bg != UNKNOWN && w.bg != s->bg;
	if (set_fg || set_bg) {
		abuf_str(a, "\x1b[");
		if (set_fg)
			put_param(a, pal, w.fg, false);
		if (set_fg && set_bg)
			abuf_char(a, ';');
		if (set_bg)
			put_param(a, pal, w.bg, true);
		abuf_char(a, 'm');
	}
	way_cost(f, *s, w, s);
	abuf_add(a, f->glyph[w.mask], f->glyph_len[w.mask]);
}

typedef struct node {
	int cost;
	sgr st;
	signed char back; /* the way chosen for the cell before */
} node;

/* Draws cells [a, b) of a row, from SGR state *s, with the fewest bytes the
 * Viterbi pass finds. */
static void emit_run(const frame *f, abuf *out, const frame_cell *row, int a, int b, sgr *s)
{
	if (f->pal == PALETTE_NONE) {
		for (int x = a; x < b; x++)
			abuf_char(out, (char)row[x].top);
		return;
	}
	int n = b - a;
	node stack_nodes[2 * 64];
	node *nodes = n <= 64 ? stack_nodes : malloc(sizeof *nodes * 2 * (size_t)n);
	if (!nodes) {
		out->failed = true;
		return;
	}
	way w[2];
	for (int i = 0; i < n; i++) {
		int k = ways_of(f, row[a + i], w);
		for (int o = 0; o < 2; o++) {
			node *nd = &nodes[2 * i + o];
			nd->cost = -1;
			if (o >= k)
				continue;
			if (i == 0) {
				nd->cost = way_cost(f, *s, w[o], &nd->st);
				nd->back = -1;
				continue;
			}
			for (int p = 0; p < 2; p++) {
				const node *pv = &nodes[2 * (i - 1) + p];
				if (pv->cost < 0)
					continue;
				sgr st;
				int c = pv->cost + way_cost(f, pv->st, w[o], &st);
				if (nd->cost < 0 || c < nd->cost) {
					nd->cost = c;
					nd->st = st;
					nd->back = (signed char)p;
				}
			}
		}
	}
	/* Walk back from the cheapest end, then draw forwards. */
	signed char *choice = malloc((size_t)n);
	if (!choice) {
		out->failed = true;
		if (nodes != stack_nodes)
			free(nodes);
		return;
	}
	int o = nodes[2 * (n - 1) + 1].cost >= 0 && nodes[2 * (n - 1) + 1].cost < nodes[2 * (n - 1)].cost;
	for (int i = n - 1; i >= 0; i--) {
		choice[i] = (signed char)o;
		o = nodes[2 * i + o].back;
	}
	for (int i = 0; i < n; i++) {
		ways_of(f, row[a + i], w);
		emit_way(out, f, s, w[(int)choice[i]]);
	}
	free(choice);
	if (nodes != stack_nodes)
		free(nodes);
}

static bool cell_eq(frame_cell a, frame_cell b)
{
	return a.top == b.top && a.bot == b.bot && a.mask == b.mask;
}

static void cursor_to(abuf *a, int row, int col)
{
	abuf_str(a, "\x1b[");
	abuf_uint(a, (unsigned)row + 1);
	if (col > 0) {
		abuf_char(a, ';');
		abuf_uint(a, (unsigned)col + 1);
	}
	abuf_char(a, 'H');
}

/* A value no real cell takes: "the terminal's cell is not known". */
static const frame_cell unknown_cell = {0xfffffffeu, 0xfffffffeu, 0};

static void forget_shown(frame *f)
{
	size_t n = (size_t)f->cols * (size_t)f->rows;
	for (size_t i = 0; i < n; i++)
		f->shown[i] = unknown_cell;
	f->have_shown = true;
}

/* The state of one update as it is built. */
typedef struct update_state {
	abuf *out;
	size_t start;    /* out->len when the update began */
	sgr s;
	int row, col;    /* where the cursor is, in frame cells */
} update_state;

static void update_begin(const frame *f, update_state *u, abuf *out)
{
	u->out = out;
	u->start = out->len;
	u->s = (sgr){UNKNOWN, UNKNOWN};
	u->row = u->col = -1;
	(void)f;
}

/* cell_close for frames fitted over the glyphs' shapes: each sample's
 * mix of the two colours within f->tol, the default background only where
 * both show it alike. */
static bool cover_close(const frame *f, frame_cell a, frame_cell b)
{
	const float *ca = f->shapes.cov[a.mask], *cb = f->shapes.cov[b.mask];
	for (int i = 0; i < SYMBOLS_SAMPLE_W * SYMBOLS_SAMPLE_H; i++) {
		bool da = (ca[i] > 0 && a.top == FRAME_DEFAULT) || (ca[i] < 1 && a.bot == FRAME_DEFAULT);
		bool db = (cb[i] > 0 && b.top == FRAME_DEFAULT) || (cb[i] < 1 && b.bot == FRAME_DEFAULT);
		if (da || db) {
			if (da != db || a.top != b.top || a.bot != b.bot || ca[i] != cb[i])
				return false;
			continue;
		}
		for (int sh = 0; sh < 24; sh += 8) {
			float va = ca[i] * (float)(a.top >> sh & 255) + (1 - ca[i]) * (float)(a.bot >> sh & 255);
			float vb = cb[i] * (float)(b.top >> sh & 255) + (1 - cb[i]) * (float)(b.bot >> sh & 255);
			if (fabsf(va - vb) > (float)f->tol)
				return false;
		}
	}
	return true;
}

/* True when the terminal's cell b may stay for a: equal, or in truecolor
 * within f->tol in every channel of every subpixel. */
static bool cell_close(const frame *f, frame_cell a, frame_cell b)
{
	if (cell_eq(a, b))
		return true;
	if (f->tol <= 0 || f->pal != PALETTE_TRUECOLOR || b.top == unknown_cell.top)
		return false;
	if (f->cover)
		return cover_close(f, a, b);
	for (int i = 0; i < f->nsub; i++) {
		uint32_t ca = a.mask >> i & 1 ? a.top : a.bot, cb = b.mask >> i & 1 ? b.top : b.bot;
		if (ca == cb)
			continue;
		if (ca == FRAME_DEFAULT || cb == FRAME_DEFAULT)
			return false;
		for (int sh = 0; sh < 24; sh += 8) {
			int d = (int)((ca >> sh) & 0xff) - (int)((cb >> sh) & 0xff);
			if (d > f->tol || d < -f->tol)
				return false;
		}
	}
	return true;
}

/* Appends the changed runs of row y, the cells sent then counting as
 * shown; stops after a run once the update holds budget bytes. True when
 * the row is done. */
static bool update_row(frame *f, update_state *u, int y, size_t budget)
{
	abuf *out = u->out;
	const frame_cell *row = f->cur + (size_t)y * f->cols;
	frame_cell *old = f->shown + (size_t)y * f->cols;
	int x = 0;
	for (;;) {
		while (x < f->cols && cell_close(f, row[x], old[x]))
			x++;
		if (x >= f->cols)
			break;
		/* A run from x: extend over changed cells and short gaps. */
		int end = x + 1;
		for (int k = end; k < f->cols && k - x < RUN_MAX; k++) {
			if (!cell_close(f, row[k], old[k]))
				end = k + 1;
			else if (k - end >= GAP_FILL)
				break;
		}
		if (out->len == u->start) {
			if (f->sync)
				abuf_str(out, "\x1b[?2026h");
			abuf_str(out, "\x1b" "7\x1b[?25l");
		}
		if (u->row == y && u->col < x) {
			abuf_str(out, "\x1b[");
			if (x - u->col > 1)
				abuf_uint(out, (unsigned)(x - u->col));
			abuf_char(out, 'C');
		} else if (u->row != y || u->col != x) {
			cursor_to(out, f->y0 + y, f->x0 + x);
		}
		emit_run(f, out, row, x, end, &u->s);
		memcpy(old + x, row + x, sizeof *row * (size_t)(end - x));
		u->row = y;
		u->col = end;
		x = end;
		if (out->len - u->start >= budget)
			return false; /* the rest of the row in the next part */
	}
	return true;
}

static void update_end(const frame *f, update_state *u)
{
	if (u->out->len > u->start) {
		abuf_str(u->out, f->cursor_off ? "\x1b[m\x1b" "8" : "\x1b[m\x1b" "8\x1b[?25h");
		if (f->sync)
			abuf_str(u->out, "\x1b[?2026l");
	}
}

const abuf *frame_update(frame *f)
{
	abuf *out = &f->out;
	abuf_reset(out);
	if (!f->have_shown)
		forget_shown(f);
	update_state u;
	update_begin(f, &u, out);
	for (int y = 0; y < f->rows; y++)
		update_row(f, &u, y, SIZE_MAX);
	update_end(f, &u);
	f->next_row = 0;
	if (out->failed) {
		abuf_reset(out);
		f->have_shown = false;
	}
	return out;
}

bool frame_dirty(const frame *f)
{
	if (!f->have_shown)
		return true;
	size_t n = (size_t)f->cols * (size_t)f->rows;
	for (size_t i = 0; i < n; i++)
		if (!cell_close(f, f->cur[i], f->shown[i]))
			return true;
	return false;
}

bool frame_update_part(frame *f, abuf *out, size_t budget)
{
	if (!f->have_shown)
		forget_shown(f);
	update_state u;
	update_begin(f, &u, out);
	int y = f->next_row % f->rows;
	for (int i = 0; i < f->rows && out->len - u.start < budget; i++) {
		if (!update_row(f, &u, y, budget))
			break; /* y again next time: its cells sent are shown */
		y = (y + 1) % f->rows;
	}
	f->next_row = y;
	update_end(f, &u);
	if (out->failed) {
		f->have_shown = false;
		return true;
	}
	return frame_dirty(f);
}

void frame_keep_shown(frame *f)
{
	if (!f->have_shown)
		return;
	memcpy(f->cur, f->shown, sizeof *f->cur * (size_t)f->cols * (size_t)f->rows);
}

void frame_text(const frame *f, abuf *out)
{
	for (int y = 0; y < f->rows; y++) {
		sgr s = {UNKNOWN, FRAME_DEFAULT}; /* after a reset */
		emit_run(f, out, f->cur + (size_t)y * f->cols, 0, f->cols, &s);
		abuf_str(out, f->pal == PALETTE_NONE ? "\n" : "\x1b[m\n");
	}
}
