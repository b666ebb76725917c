/* rtsh — symbol sets: the glyphs that split a character cell into a grid
 * of subpixels, each shown in one of the cell's two colours (foreground
 * where the glyph is inked, background elsewhere).
 *
 *   half      1x2  U+2580 U+2584 (Unicode 1.1)
 *   quadrant  2x2  U+2596..U+259F with the halves (Unicode 1.1)
 *   sextant   2x3  U+1FB00..U+1FB3B, "Symbols for Legacy Computing"
 *                  (Unicode 13), with U+258C U+2590 for the two columns;
 *                  and beyond the 64 patterns (ids 64..87) the quadrants,
 *                  halves and eighth rows of U+2580..U+259F and U+1FB82..
 *                  U+1FB86, which follow the 2x4 samples' rows
 *   octant    2x4  U+1CD00..U+1CDE5 (Unicode 16), with the 26 patterns
 *                  that other blocks already hold (the quadrants, U+2582
 *                  U+2586 U+1FB82 U+1FB85 U+1FBE6 U+1FBE7 U+1CEA0 U+1CEA3
 *                  U+1CEA8 U+1CEAB)
 *
 * A mask names the inked subpixels: bit row * w + col of the set's w x h
 * grid, rows top down. Mask 0 is a space and the full mask U+2588.
 *
 * The symbol encoders trace every cell on a 2x4 grid of samples (square
 * pixels when a cell is twice as high as wide, as the half blocks'
 * canvas assumes), and a subpixel's colour is the mean of the samples it
 * covers, weighted by area (a sextant row covers 4/3 sample rows). Each
 * cell then gets the mask and two colours of least squared error
 * (symbols_fit), found by trying every split of its subpixels in two. A
 * cell of the sextant set is fitted on its 8 samples instead, over every
 * glyph's shape (symbols_fit_cover).
 */
#ifndef RTSH_SYMBOLS_H
#define RTSH_SYMBOLS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef enum symbols_kind {
	SYMBOLS_HALF,
	SYMBOLS_QUADRANT,
	SYMBOLS_SEXTANT,
	SYMBOLS_OCTANT,
	SYMBOLS_AUTO, /* what the terminal is known to draw (symbols_choose) */
} symbols_kind;

/* Samples a cell of the symbol encoders' canvas (SYMBOLS_HALF: 1x2). */
#define SYMBOLS_SAMPLE_W 2
#define SYMBOLS_SAMPLE_H 4

typedef struct symbol_set {
	const char *name; /* "half", "quadrant", "sextant", "octant" */
	int w, h;         /* the grid of subpixels */
	int unicode;      /* the Unicode version that has all of its glyphs (x10: 11, 130, 160) */
} symbol_set;

/* The sets by symbols_kind (not SYMBOLS_AUTO). */
extern const symbol_set symbols_table[SYMBOLS_AUTO];

/* "half" "quadrant" "sextant" "octant" "auto". */
const char *symbols_name(symbols_kind k);
/* false when s names no kind. */
bool symbols_parse(const char *s, symbols_kind *k);

/* The code point of the glyph for mask in set k (mask 0: U+0020). */
uint32_t symbols_codepoint(symbols_kind k, unsigned mask);
/* Its UTF-8 in out (no NUL); returns the length, 1..4. */
int symbols_utf8(symbols_kind k, unsigned mask, char out[4]);
/* The mask of code point cp in set k, or -1 when the set has no such
 * glyph (the inverse of symbols_codepoint). */
int symbols_mask_of(symbols_kind k, uint32_t cp);

/* The subpixel colours of one cell of set k (not half) from its
 * SYMBOLS_SAMPLE_W x SYMBOLS_SAMPLE_H samples (sRGB, 3 bytes each, rows
 * top down, `stride` bytes from a row to the next): sub[w*h][3]. */
void symbols_subpixels(symbols_kind k, const uint8_t *samples, size_t stride, float sub[8][3]);

/* The best two-colour fit of n subpixels (n <= 8): the mask of the ones
 * shown in colour a (the others in b), with a and b the means of their
 * subpixels rounded to sRGB bytes. A cell whose best split gains at most
 * `flat` (summed squared error, sRGB levels) over one colour is flat:
 * mask 0 and a == b == the mean. Returns the fit's squared error. */
double symbols_fit(const float sub[][3], int n, double flat, unsigned *mask, uint8_t a[3], uint8_t b[3]);

/* The glyphs of set k: ids 0 .. symbols_count(k)-1. Below 1 << (w*h) an
 * id is a mask of the set's grid; the sextant set has more glyphs beyond
 * its 64 patterns (ids 64 on: the Block Elements' quadrants, halves and
 * eighths, and the eighth blocks of Unicode 13's Symbols for Legacy
 * Computing), each drawn from its shape. */
int symbols_count(symbols_kind k);
/* The share (0..1) of each of a cell's SYMBOLS_SAMPLE_W x SYMBOLS_SAMPLE_H
 * samples (rows top down) that glyph id of set k inks. */
void symbols_cover(symbols_kind k, unsigned id, float cov[8]);

#define SYMBOLS_MAX_GLYPHS 256
#define SYMBOLS_COVER_MAX 88 /* the most glyphs symbols_fit_cover takes */
/* A set's glyph shapes on the sample grid, for symbols_fit_cover. */
typedef struct symbols_shapes {
	int n;                               /* glyphs */
	float cov[SYMBOLS_MAX_GLYPHS][8];    /* symbols_cover */
	double uu[SYMBOLS_MAX_GLYPHS], uv[SYMBOLS_MAX_GLYPHS], vv[SYMBOLS_MAX_GLYPHS];
	short comp[SYMBOLS_MAX_GLYPHS];      /* the glyph inked where this one is not, or -1 */
	float covt[8][SYMBOLS_COVER_MAX];    /* cov by sample, for sums over all glyphs at once
	                                        (sets of at most SYMBOLS_COVER_MAX glyphs; 0 past n) */
	/* The glyphs the fit tries: two colours, and not the complement of
	 * one tried (the same fit, colours swapped); their shapes by sample
	 * and the inverse of their normal equations, [ia -ib; -ib ic]. */
	int nsolve;
	short solve[SYMBOLS_COVER_MAX];
	float scovt[8][SYMBOLS_COVER_MAX];
	double ia[SYMBOLS_COVER_MAX], ib[SYMBOLS_COVER_MAX], ic[SYMBOLS_COVER_MAX];
} symbols_shapes;
void symbols_shapes_init(symbols_shapes *s, symbols_kind k);
/* The best two-colour fit of a cell's 8 samples x (sRGB levels) over every
 * glyph of s (a set of at most SYMBOLS_COVER_MAX glyphs: the sextant set): each sample shown as its ink's share of colour a and the
 * rest of b, a and b by least squares (clamped to 0..255, rounded). A
 * cell whose best glyph gains at most `flat` over one colour is flat
 * (id 0, a == b == the mean). Returns the squared error of the fit. */
double symbols_fit_cover(const symbols_shapes *s, const float x[8][3], double flat, unsigned *id, uint8_t a[3],
                         uint8_t b[3]);

/* The set `auto` picks from what is known of the terminal: the names it
 * gives (TERM_PROGRAM, its XTVERSION answer, VTE_VERSION; NULL: not
 * known) and whether it runs inside tmux (which passes the glyphs on to
 * the terminal outside, not known here). Half blocks when nothing is
 * known. */
symbols_kind symbols_choose(const char *term_program, const char *xtversion, const char *vte_version,
                            bool tmux);

#endif
