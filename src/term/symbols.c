/* rtsh — symbol sets (symbols.h). */
#include "term/symbols.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const symbol_set symbols_table[SYMBOLS_AUTO] = {
	[SYMBOLS_HALF] = {"half", 1, 2, 11},
	[SYMBOLS_QUADRANT] = {"quadrant", 2, 2, 11},
	[SYMBOLS_SEXTANT] = {"sextant", 2, 3, 130},
	[SYMBOLS_OCTANT] = {"octant", 2, 4, 160},
};

static const char *const kind_names[] = {"half", "quadrant", "sextant", "octant", "auto"};

const char *symbols_name(symbols_kind k)
{
	return k >= SYMBOLS_HALF && k <= SYMBOLS_AUTO ? kind_names[k] : "half";
}

bool symbols_parse(const char *s, symbols_kind *k)
{
	for (int i = SYMBOLS_HALF; i <= SYMBOLS_AUTO; i++)
		if (strcmp(s, kind_names[i]) == 0) {
			*k = (symbols_kind)i;
			return true;
		}
	return false;
}

/* Quadrants, mask bit 0 top left, 1 top right, 2 bottom left, 3 bottom
 * right (Unicode's block elements, U+2580..U+259F). */
static const uint16_t quadrant_cp[16] = {
	0x20,   0x2598, 0x259d, 0x2580, 0x2596, 0x258c, 0x259e, 0x259b,
	0x2597, 0x259a, 0x2590, 0x259c, 0x2584, 0x2599, 0x259f, 0x2588,
};

/* The octant patterns that other characters hold, besides the sixteen
 * quadrants (a quadrant is two octants stacked): Unicode 16's U+1CD00
 * block skips them, so an octant's code point is its rank among the
 * patterns not skipped. */
static const struct {
	uint8_t mask;
	uint32_t cp;
} octant_other[] = {
	{0x01, 0x1cea8}, /* LEFT HALF UPPER ONE QUARTER BLOCK */
	{0x02, 0x1ceab}, /* RIGHT HALF UPPER ONE QUARTER BLOCK */
	{0x03, 0x1fb82}, /* UPPER ONE QUARTER BLOCK */
	{0x14, 0x1fbe6}, /* MIDDLE LEFT ONE QUARTER BLOCK */
	{0x28, 0x1fbe7}, /* MIDDLE RIGHT ONE QUARTER BLOCK */
	{0x3f, 0x1fb85}, /* UPPER THREE QUARTERS BLOCK */
	{0x40, 0x1cea3}, /* LEFT HALF LOWER ONE QUARTER BLOCK */
	{0x80, 0x1cea0}, /* RIGHT HALF LOWER ONE QUARTER BLOCK */
	{0xc0, 0x2582},  /* LOWER ONE QUARTER BLOCK */
	{0xfc, 0x2586},  /* LOWER THREE QUARTERS BLOCK */
};
#define N_OCTANT_OTHER (sizeof octant_other / sizeof octant_other[0])

/* The sextant set's glyphs beyond the 64 sextant patterns (ids 64 on):
 * Block Elements (Unicode 1.1: the quadrants, the halves, the lower
 * eighths and U+2594 UPPER ONE EIGHTH BLOCK) and the upper eighth blocks
 * of Symbols for Legacy Computing (Unicode 13, the sextants' own block:
 * U+1FB82..U+1FB86). On the 2x4 canvas a quadrant, a half and a quarter
 * are exact where a sextant row is not (it covers 4/3 sample rows), and
 * an odd eighth shows a mix of the two colours in one row of samples.
 * (The left and right eighths were tried too and gained nothing on the
 * bench's three scenes.) A shape is a quadrant pattern (bit 0 upper
 * left, 1 upper right, 2 lower left, 3 lower right) or one rectangle in
 * eighths of the cell (x0, y0, x1, y1, y down). */
static const struct {
	uint32_t cp;
	uint8_t quad;
	uint8_t x0, y0, x1, y1;
} sextant_extra[] = {
	{0x2598, 1, 0, 0, 0, 0},   {0x259d, 2, 0, 0, 0, 0},   {0x2580, 3, 0, 0, 0, 0},   {0x2596, 4, 0, 0, 0, 0},
	{0x259e, 6, 0, 0, 0, 0},   {0x259b, 7, 0, 0, 0, 0},   {0x2597, 8, 0, 0, 0, 0},   {0x259a, 9, 0, 0, 0, 0},
	{0x259c, 11, 0, 0, 0, 0},  {0x2584, 12, 0, 0, 0, 0},  {0x2599, 13, 0, 0, 0, 0},  {0x259f, 14, 0, 0, 0, 0},
	{0x2581, 0, 0, 7, 8, 8},   {0x2582, 0, 0, 6, 8, 8},   {0x2583, 0, 0, 5, 8, 8},   {0x2585, 0, 0, 3, 8, 8},
	{0x2586, 0, 0, 2, 8, 8},   {0x2587, 0, 0, 1, 8, 8},   {0x2594, 0, 0, 0, 8, 1},   {0x1fb82, 0, 0, 0, 8, 2},
	{0x1fb83, 0, 0, 0, 8, 3},  {0x1fb84, 0, 0, 0, 8, 5},  {0x1fb85, 0, 0, 0, 8, 6},  {0x1fb86, 0, 0, 0, 8, 7},
};
#define N_SEXTANT_EXTRA (sizeof sextant_extra / sizeof sextant_extra[0])

/* The quadrant an octant mask is, or -1: each pair of octant rows equal. */
static int octant_as_quadrant(unsigned m)
{
	unsigned r0 = m & 3, r1 = m >> 2 & 3, r2 = m >> 4 & 3, r3 = m >> 6 & 3;
	if (r0 != r1 || r2 != r3)
		return -1;
	return (int)(r0 | r2 << 2);
}

static bool octant_skipped(unsigned m)
{
	if (octant_as_quadrant(m) >= 0)
		return true;
	for (size_t i = 0; i < N_OCTANT_OTHER; i++)
		if (octant_other[i].mask == m)
			return true;
	return false;
}

uint32_t symbols_codepoint(symbols_kind k, unsigned mask)
{
	switch (k) {
	case SYMBOLS_HALF:
		mask &= 3;
		return mask == 0 ? 0x20 : mask == 1 ? 0x2580 : mask == 2 ? 0x2584 : 0x2588;
	case SYMBOLS_QUADRANT:
		return quadrant_cp[mask & 15];
	case SYMBOLS_SEXTANT:
		if (mask >= 64 && mask < 64 + N_SEXTANT_EXTRA)
			return sextant_extra[mask - 64].cp;
		mask &= 63;
		/* U+1FB00.. run through masks 1..62 but the two columns. */
		if (mask == 0 || mask == 63)
			return mask ? 0x2588 : 0x20;
		if (mask == 21)
			return 0x258c;
		if (mask == 42)
			return 0x2590;
		return 0x1fb00 + mask - 1 - (mask > 21) - (mask > 42);
	case SYMBOLS_OCTANT: {
		mask &= 255;
		int q = octant_as_quadrant(mask);
		if (q >= 0)
			return quadrant_cp[q];
		for (size_t i = 0; i < N_OCTANT_OTHER; i++)
			if (octant_other[i].mask == mask)
				return octant_other[i].cp;
		unsigned rank = 0;
		for (unsigned m = 0; m < mask; m++)
			rank += !octant_skipped(m);
		return 0x1cd00 + rank;
	}
	case SYMBOLS_AUTO:
		break;
	}
	return 0x20;
}

int symbols_utf8(symbols_kind k, unsigned mask, char out[4])
{
	uint32_t c = symbols_codepoint(k, mask);
	if (c < 0x80) {
		out[0] = (char)c;
		return 1;
	}
	if (c < 0x10000) {
		out[0] = (char)(0xe0 | c >> 12);
		out[1] = (char)(0x80 | (c >> 6 & 0x3f));
		out[2] = (char)(0x80 | (c & 0x3f));
		return 3;
	}
	out[0] = (char)(0xf0 | c >> 18);
	out[1] = (char)(0x80 | (c >> 12 & 0x3f));
	out[2] = (char)(0x80 | (c >> 6 & 0x3f));
	out[3] = (char)(0x80 | (c & 0x3f));
	return 4;
}


int symbols_count(symbols_kind k)
{
	if (k < SYMBOLS_HALF || k >= SYMBOLS_AUTO)
		return 0;
	int n = 1 << (symbols_table[k].w * symbols_table[k].h);
	return k == SYMBOLS_SEXTANT ? n + (int)N_SEXTANT_EXTRA : n;
}

/* The share of sample (sx, sy) of the 2x4 grid that rectangle r (in
 * units of the cell, y down) covers. */
static double rect_share(double x0, double y0, double x1, double y1, int sx, int sy)
{
	double ax = (double)sx / SYMBOLS_SAMPLE_W, bx = (double)(sx + 1) / SYMBOLS_SAMPLE_W;
	double ay = (double)sy / SYMBOLS_SAMPLE_H, by = (double)(sy + 1) / SYMBOLS_SAMPLE_H;
	double w = fmin(bx, x1) - fmax(ax, x0), h = fmin(by, y1) - fmax(ay, y0);
	return w > 0 && h > 0 ? w * h * SYMBOLS_SAMPLE_W * SYMBOLS_SAMPLE_H : 0;
}

void symbols_cover(symbols_kind k, unsigned id, float cov[8])
{
	for (int i = 0; i < 8; i++)
		cov[i] = 0;
	if (k < SYMBOLS_HALF || k >= SYMBOLS_AUTO || (int)id >= symbols_count(k))
		return;
	const symbol_set *set = &symbols_table[k];
	unsigned n = 1u << (set->w * set->h);
	for (int sy = 0; sy < SYMBOLS_SAMPLE_H; sy++)
		for (int sx = 0; sx < SYMBOLS_SAMPLE_W; sx++) {
			double c = 0;
			if (id < n) {
				for (int j = 0; j < set->h; j++)
					for (int i = 0; i < set->w; i++)
						if (id >> (j * set->w + i) & 1)
							c += rect_share((double)i / set->w, (double)j / set->h,
							                (double)(i + 1) / set->w, (double)(j + 1) / set->h, sx, sy);
			} else {
				unsigned e = id - n;
				if (sextant_extra[e].quad) {
					for (int q = 0; q < 4; q++)
						if (sextant_extra[e].quad >> q & 1)
							c += rect_share((q & 1) * 0.5, (q >> 1) * 0.5, (q & 1) * 0.5 + 0.5,
							                (q >> 1) * 0.5 + 0.5, sx, sy);
				} else {
					c = rect_share(sextant_extra[e].x0 / 8.0, sextant_extra[e].y0 / 8.0,
					               sextant_extra[e].x1 / 8.0, sextant_extra[e].y1 / 8.0, sx, sy);
				}
			}
			cov[sy * SYMBOLS_SAMPLE_W + sx] = (float)c;
		}
}

int symbols_mask_of(symbols_kind k, uint32_t cp)
{
	if (k < SYMBOLS_HALF || k >= SYMBOLS_AUTO)
		return -1;
	unsigned n = (unsigned)symbols_count(k);
	if (k == SYMBOLS_OCTANT && cp >= 0x1cd00 && cp <= 0x1cde5) {
		unsigned rank = 0;
		for (unsigned m = 0; m < n; m++)
			if (!octant_skipped(m) && rank++ == cp - 0x1cd00)
				return (int)m;
	}
	for (unsigned m = 0; m < n; m++)
		if (symbols_codepoint(k, m) == cp)
			return (int)m;
	return -1;
}

void symbols_subpixels(symbols_kind k, const uint8_t *s, size_t stride, float sub[8][3])
{
	const symbol_set *set = &symbols_table[k];
	/* Subpixel row j covers sample rows [j*H/h, (j+1)*H/h): each sample
	 * row weighs the length it shares with that span. */
	for (int j = 0; j < set->h; j++) {
		double lo = (double)j * SYMBOLS_SAMPLE_H / set->h, hi = (double)(j + 1) * SYMBOLS_SAMPLE_H / set->h;
		for (int c = 0; c < set->w; c++) {
			double acc[3] = {0, 0, 0};
			for (int r = 0; r < SYMBOLS_SAMPLE_H; r++) {
				double a = r > lo ? r : lo, b = r + 1 < hi ? r + 1 : hi;
				if (b <= a)
					continue;
				/* the samples under this subpixel's columns */
				for (int x = c * SYMBOLS_SAMPLE_W / set->w; x < (c + 1) * SYMBOLS_SAMPLE_W / set->w; x++) {
					const uint8_t *p = s + (size_t)r * stride + (size_t)x * 3;
					for (int ch = 0; ch < 3; ch++)
						acc[ch] += (b - a) * p[ch];
				}
			}
			double area = (hi - lo) * ((double)SYMBOLS_SAMPLE_W / set->w);
			for (int ch = 0; ch < 3; ch++)
				sub[j * set->w + c][ch] = (float)(acc[ch] / area);
		}
	}
}

static uint8_t to_byte(double v)
{
	long r = lround(v);
	return (uint8_t)(r < 0 ? 0 : r > 255 ? 255 : r);
}

double symbols_fit(const float sub[][3], int n, double flat, unsigned *mask, uint8_t a[3], uint8_t b[3])
{
	/* The squared error of a split is sum |p|^2 - |S_a|^2/n_a - |S_b|^2/n_b
	 * (each side at its mean), so the best split has the largest
	 * |S_a|^2/n_a + |S_b|^2/n_b. Walk the splits in Gray-code order, one
	 * subpixel moving sides each step; subpixel n-1 stays in b (a split
	 * and its complement are the same). */
	double tot[3] = {0, 0, 0}, sq = 0;
	for (int i = 0; i < n; i++)
		for (int c = 0; c < 3; c++) {
			tot[c] += sub[i][c];
			sq += (double)sub[i][c] * sub[i][c];
		}
	double flat_score = (tot[0] * tot[0] + tot[1] * tot[1] + tot[2] * tot[2]) / n;
	double sa[3] = {0, 0, 0};
	int na = 0;
	unsigned m = 0, best_m = 0;
	double best = flat_score;
	unsigned steps = 1u << (n - 1);
	for (unsigned g = 1; g < steps; g++) {
		int bit = __builtin_ctz(g); /* the subpixel that moves */
		double sign = (m >> bit & 1) ? -1 : 1;
		m ^= 1u << bit;
		na += (int)sign;
		for (int c = 0; c < 3; c++)
			sa[c] += sign * sub[bit][c];
		if (na == 0)
			continue;
		double sb0 = tot[0] - sa[0], sb1 = tot[1] - sa[1], sb2 = tot[2] - sa[2];
		double score = (sa[0] * sa[0] + sa[1] * sa[1] + sa[2] * sa[2]) / na +
		               (sb0 * sb0 + sb1 * sb1 + sb2 * sb2) / (n - na);
		if (score > best) {
			best = score;
			best_m = m;
		}
	}
	if (best_m == 0 || best - flat_score <= flat) {
		for (int c = 0; c < 3; c++)
			a[c] = b[c] = to_byte(tot[c] / n);
		*mask = 0;
		return sq - flat_score;
	}
	double ma[3] = {0, 0, 0}, mb[3] = {0, 0, 0};
	int ka = 0;
	for (int i = 0; i < n; i++) {
		bool in = best_m >> i & 1;
		ka += in;
		for (int c = 0; c < 3; c++)
			(in ? ma : mb)[c] += sub[i][c];
	}
	for (int c = 0; c < 3; c++) {
		a[c] = to_byte(ma[c] / ka);
		b[c] = to_byte(mb[c] / (n - ka));
	}
	*mask = best_m;
	return sq - best;
}

/* A version "A.B.C" at s as A*1000000 + B*1000 + C; -1 when s holds none. */
static long version_of(const char *s)
{
	int a = 0, b = 0, c = 0;
	if (sscanf(s, "%d.%d.%d", &a, &b, &c) < 2 || a < 0 || b < 0 || c < 0 || b > 999 || c > 999)
		return -1;
	return (long)a * 1000000 + (long)b * 1000 + c;
}

symbols_kind symbols_choose(const char *term_program, const char *xtversion, const char *vte_version, bool tmux)
{
	(void)tmux; /* inside tmux, TERM_PROGRAM and XTVERSION name tmux itself */
	/* Terminals that draw the block elements and the glyphs of the
	 * sextant set (sextants, U+1FB82..U+1FB86) themselves, not from a font
	 * that may lack them: kitty (0.19.0 on), WezTerm (20210814 on), foot,
	 * Ghostty and VTE (GNOME Terminal and its kin, 0.64 on). Octants
	 * (Unicode 16) where a release's notes say the terminal draws them:
	 * kitty 0.40.0 ("Add support for the octant box-drawing characters"),
	 * known from its XTVERSION answer, kitty(0.40.0). */
	if (xtversion && strncmp(xtversion, "kitty(", 6) == 0) {
		long v = version_of(xtversion + 6);
		return v >= 40000 ? SYMBOLS_OCTANT : v >= 19000 || v < 0 ? SYMBOLS_SEXTANT : SYMBOLS_HALF;
	}
	static const char *const programs[] = {"WezTerm", "ghostty", "kitty"};
	for (size_t i = 0; term_program && i < sizeof programs / sizeof programs[0]; i++)
		if (strcmp(term_program, programs[i]) == 0)
			return SYMBOLS_SEXTANT;
	if (xtversion && (strncmp(xtversion, "foot(", 5) == 0 || strncmp(xtversion, "WezTerm ", 8) == 0 ||
	                  strncmp(xtversion, "ghostty ", 8) == 0))
		return SYMBOLS_SEXTANT;
	if (vte_version && atol(vte_version) >= 6400)
		return SYMBOLS_SEXTANT;
	return SYMBOLS_HALF;
}

void symbols_shapes_init(symbols_shapes *s, symbols_kind k)
{
	s->n = symbols_count(k);
	memset(s->covt, 0, sizeof s->covt);
	for (int g = 0; g < s->n; g++) {
		symbols_cover(k, (unsigned)g, s->cov[g]);
		for (int i = 0; g < SYMBOLS_COVER_MAX && i < 8; i++)
			s->covt[i][g] = s->cov[g][i];
		double uu = 0, uv = 0, vv = 0;
		for (int i = 0; i < 8; i++) {
			double u = s->cov[g][i], v = 1 - u;
			uu += u * u;
			uv += u * v;
			vv += v * v;
		}
		s->uu[g] = uu;
		s->uv[g] = uv;
		s->vv[g] = vv;
	}
	/* the complement: inked where g is not (the colours swapped) */
	for (int g = 0; g < s->n; g++) {
		s->comp[g] = -1;
		for (int h = 0; h < s->n && s->comp[g] < 0; h++) {
			bool same = true;
			for (int i = 0; i < 8 && same; i++)
				same = fabsf(s->cov[g][i] + s->cov[h][i] - 1) < 1e-5f;
			if (same)
				s->comp[g] = (short)h;
		}
	}
	/* the inverse of each glyph's normal equations, for the glyphs of two
	 * colours that are not the complement of one before */
	memset(s->scovt, 0, sizeof s->scovt);
	s->nsolve = 0;
	for (int g = 0; g < s->n && s->nsolve < SYMBOLS_COVER_MAX; g++) {
		double det = s->uu[g] * s->vv[g] - s->uv[g] * s->uv[g];
		if (det <= 1e-6 || (s->comp[g] >= 0 && s->comp[g] < g))
			continue;
		int j = s->nsolve++;
		s->solve[j] = (short)g;
		for (int i = 0; i < 8; i++)
			s->scovt[i][j] = s->cov[g][i];
		s->ia[j] = s->vv[g] / det;
		s->ib[j] = s->uv[g] / det;
		s->ic[j] = s->uu[g] / det;
	}
}

static double clamp255(double v)
{
	return v < 0 ? 0 : v > 255 ? 255 : v;
}

double symbols_fit_cover(const symbols_shapes *s, const float x[8][3], double flat, unsigned *id, uint8_t a[3],
                         uint8_t b[3])
{
	/* Glyph g shows sample i as c_i a + (1 - c_i) b (c its ink's share of
	 * the sample): a and b by least squares, per channel the 2x2 normal
	 * equations [uu uv; uv vv] [a b] = [sum c x, sum (1-c) x]; the error
	 * at the optimum is sum x^2 - a sum c x - b sum (1-c) x. */
	float xt[3][8]; /* the channels apart: each sum c x one dot product */
	double tot[3] = {0, 0, 0}, sq = 0;
	for (int i = 0; i < 8; i++)
		for (int c = 0; c < 3; c++) {
			xt[c][i] = x[i][c];
			tot[c] += x[i][c];
			sq += (double)x[i][c] * x[i][c];
		}
	double flat_err = sq - (tot[0] * tot[0] + tot[1] * tot[1] + tot[2] * tot[2]) / 8;
	double best = flat_err, best_a[3] = {0, 0, 0}, best_b[3] = {0, 0, 0};
	int best_g = -1;
	/* sum c x for every glyph tried at once (a loop the compiler
	 * vectorises) */
	enum { NS = 48 }; /* enough for the sextant set's 43 */
	float rus[3][NS];
	int ns = s->nsolve < NS ? s->nsolve : NS;
	for (int c = 0; c < 3; c++) {
		for (int k = 0; k < NS; k++)
			rus[c][k] = 0;
		for (int i = 0; i < 8; i++)
			for (int k = 0; k < NS; k++)
				rus[c][k] += s->scovt[i][k] * xt[c][i];
	}
	/* each glyph's error at its optimum, all at once as well */
	double es[NS];
	for (int k = 0; k < NS; k++)
		es[k] = sq;
	for (int c = 0; c < 3; c++)
		for (int k = 0; k < NS; k++) {
			double ru = rus[c][k], rv = tot[c] - ru;
			double fa = s->ia[k] * ru - s->ib[k] * rv, fb = s->ic[k] * rv - s->ib[k] * ru;
			es[k] -= fa * ru + fb * rv;
		}
	for (int k = 0; k < ns; k++) {
		if (es[k] >= best)
			continue; /* clamping the colours below only adds error */
		int g = s->solve[k];
		const float *cv = s->cov[g];
		double fa[3], fb[3], e = es[k];
		bool clamped = false;
		for (int c = 0; c < 3; c++) {
			double ru = rus[c][k], rv = tot[c] - ru;
			fa[c] = s->ia[k] * ru - s->ib[k] * rv;
			fb[c] = s->ic[k] * rv - s->ib[k] * ru;
			clamped |= fa[c] < 0 || fa[c] > 255 || fb[c] < 0 || fb[c] > 255;
		}
		if (clamped) {
			/* a mix past the ends: the error of the colours clamped */
			e = 0;
			for (int c = 0; c < 3; c++) {
				fa[c] = clamp255(fa[c]);
				fb[c] = clamp255(fb[c]);
				for (int i = 0; i < 8; i++) {
					double d = x[i][c] - (cv[i] * fa[c] + (1 - cv[i]) * fb[c]);
					e += d * d;
				}
			}
			if (e >= best)
				continue;
		}
		best = e;
		best_g = g;
		memcpy(best_a, fa, sizeof fa);
		memcpy(best_b, fb, sizeof fb);
	}
	if (best_g < 0 || flat_err - best <= flat) {
		for (int c = 0; c < 3; c++)
			a[c] = b[c] = to_byte(tot[c] / 8);
		*id = 0;
		return flat_err;
	}
	for (int c = 0; c < 3; c++) {
		a[c] = to_byte(best_a[c]);
		b[c] = to_byte(best_b[c]);
	}
	*id = (unsigned)best_g;
	return best;
}
