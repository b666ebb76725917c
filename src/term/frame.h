/* rtsh — the cell frame encoder: half blocks and the other symbol sets.
 *
 * A frame is a grid of character cells; each cell shows two stacked pixels
 * with U+2580 UPPER HALF BLOCK (foreground = upper pixel, background = lower
 * pixel), or whichever of space, U+2584 LOWER HALF BLOCK and U+2588 FULL
 * BLOCK costs fewer bytes for the same two colours. A frame of another
 * symbol set (term/symbols.h: quadrants, sextants, octants) shows a grid of
 * subpixels a cell instead, each cell in two colours: its canvas holds 2x4
 * samples a cell, and each cell takes the glyph and colours of least error
 * (symbols_fit; the sextant set: symbols_fit_cover on the samples), or the
 * complement glyph with the colours swapped when
 * that costs fewer bytes. The encoder keeps the cells the terminal shows
 * and sends only the cells that changed.
 *
 * Every escape sequence this module sends (ESC = \e, CSI = \e[):
 *   \e[?2026h  \e[?2026l   begin / end synchronized update (DEC mode 2026)
 *   \e7  \e8               save / restore the cursor (and its attributes)
 *   \e[?25l  \e[?25h       hide / show the cursor
 *   \e[R;CH  \e[RH         move the cursor to row R, column C (1-based)
 *   \e[NC                  move the cursor N columns right
 *   \e[...m                SGR: 38;2;R;G;B and 48;2;R;G;B (24-bit), 38;5;N
 *                          and 48;5;N (256 colours), 30-37 90-97 40-47
 *                          100-107 (16 colours), 49 (default background),
 *                          and \e[m (reset); several joined by ';'
 * and, in text mode (.ans files, `show`), "\e[m\n" at the end of each row.
 */
#ifndef RTSH_FRAME_H
#define RTSH_FRAME_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "base/abuf.h"
#include "term/symbols.h"

typedef enum frame_palette {
	PALETTE_TRUECOLOR, /* cells hold 0xRRGGBB */
	PALETTE_256,       /* cells hold an xterm index 16..255 (cube and grey ramp) */
	PALETTE_16,        /* cells hold an index 0..15 */
	PALETTE_NONE,      /* cells hold an ASCII character (no colour at all) */
} frame_palette;

/* The terminal's default background (letterbox bars). */
#define FRAME_DEFAULT 0xff000000u

/* Two stacked pixels, quantised for the frame's palette. In PALETTE_NONE a
 * cell is one character: top == bot == its code. In a frame of another
 * symbol set, top is the colour of the subpixels in mask (symbols.h; in
 * the sextant set mask is a glyph id, 64 and up a glyph beyond the
 * sextants, top its ink) and bot the colour of the others; a cell of one colour has mask 0 and
 * top == bot (half blocks: mask is always 1, the upper pixel). */
typedef struct frame_cell {
	uint32_t top, bot;
	uint32_t mask;
} frame_cell;

typedef struct frame {
	int cols, rows;    /* cells */
	int x0, y0;        /* the top-left cell on the screen, 0-based */
	frame_palette pal;
	bool sync;         /* bracket each update with DEC mode 2026 */
	bool cursor_off;   /* leave the cursor hidden after an update (key mode) */
	frame_cell *cur;   /* what the next update shows: cols x rows */
	frame_cell *shown; /* what the terminal shows */
	bool have_shown;   /* false: the next update sends every cell */
	int next_row;      /* where the next frame_update_part starts */
	int tol;           /* truecolor: a shown cell within tol (sRGB levels, each
	                      channel) of the current one is left as it is; 0: exact */
	symbols_kind sym;  /* the symbol set (SYMBOLS_HALF: two pixels a cell) */
	int nsub;          /* subpixels a cell */
	double flat;       /* symbols: a split that gains at most this much squared
	                      error over one colour is not worth its bytes (symbols_fit) */
	double lambda;     /* truecolor: squared error (sRGB levels, summed over a
	                      cell's 8 samples' worth of area) worth a byte (rd_row);
	                      0: every cell its best fit */
	uint8_t *px;       /* the canvas, cols x rows*2 pixels (symbols: cols*2 x
	                      rows*4 samples), sRGB */
	uint8_t *def;      /* 1 where the canvas holds a picture's sample, 0 where
	                      it shows the default background */
	bool cover;        /* cells fitted over the glyphs' shapes on the 2x4 samples
	                      (symbols_fit_cover: the sextant set, whose glyphs
	                      beyond the masks mix samples), else over subpixels */
	symbols_shapes shapes; /* the set's glyphs on the samples, their complements */
	char glyph[256][4]; /* the UTF-8 of each mask's glyph ... */
	uint8_t glyph_len[256]; /* ... and its length */
	abuf out;
} frame;

/* A new frame of cols x rows cells, all default background; NULL when out
 * of memory or a size is < 1. */
frame *frame_new(int cols, int rows, frame_palette pal);
/* The same with symbol set sym (not SYMBOLS_AUTO; PALETTE_NONE takes half
 * blocks, one character a cell). */
frame *frame_new_symbols(int cols, int rows, frame_palette pal, symbols_kind sym);
/* frame.lambda's default: measured on three scenes (bench symbols rows,
 * bench/README.md), 5 keeps the PSNR within 0.25 dB of the best fit's and
 * sends 0.4-0.8x its bytes. */
#define FRAME_LAMBDA 5.0
void frame_free(frame *f);
/* Forgets what the terminal shows (after the screen was cleared). */
void frame_invalidate(frame *f);

/* Sets every cell to the default background. */
void frame_clear(frame *f);
/* Puts an image of w x h sRGB pixels (3 bytes each, rows top to bottom) at
 * pixel (ox, oy) of the frame's cols x 2*rows pixel canvas (other symbol
 * sets: cols*2 x rows*4); pixels outside the image keep their value. */
void frame_put_image(frame *f, const uint8_t *rgb, int w, int h, int ox, int oy);

/* The update that turns what the terminal shows into the current cells, as
 * one buffer for one write(); empty (len 0) when nothing changed. The
 * current cells then count as shown. */
const abuf *frame_update(frame *f);
/* Appends to out the next part of the update: rows with changes, from the
 * row after the last part's (round robin, so that every row gets its turn
 * while the picture keeps changing), until about `budget` bytes are out
 * (whole rows; at least one). Each part stands alone (cursor saved and
 * restored, attributes reset, its own synchronized-update bracket) and the
 * rows it holds count as shown. True when cells that differ remain. */
bool frame_update_part(frame *f, abuf *out, size_t budget);
/* True when some cell differs from what the terminal shows. */
bool frame_dirty(const frame *f);
/* Takes what the terminal shows as the current cells (the changes not yet
 * sent are dropped). */
void frame_keep_shown(frame *f);
/* The current cells as ANSI text for a file or a pipe: every row, each
 * ended by "\e[m\n" (PALETTE_NONE: plain text lines). */
void frame_text(const frame *f, abuf *out);

/* --- colour --- */
/* The cell value of an sRGB colour in a palette (PALETTE_NONE: see
 * frame_ascii). */
uint32_t palette_quantize(frame_palette pal, uint8_t r, uint8_t g, uint8_t b);
/* The nearest xterm colour (squared RGB distance) among the 6x6x6 cube
 * (16..231: levels 0,95,135,175,215,255) and the grey ramp (232..255:
 * 8,18,...,238); the cube wins a tie. */
uint8_t palette_256(uint8_t r, uint8_t g, uint8_t b);
/* The nearest of the 16 xterm default colours. */
uint8_t palette_16(uint8_t r, uint8_t g, uint8_t b);
/* The RGB value of an xterm palette index 0..255. */
void palette_rgb(unsigned index, uint8_t rgb[3]);
/* The character for a cell of two pixels with no colour: " .:-=+*#%@" by
 * mean luminance. */
char frame_ascii(const uint8_t top[3], const uint8_t bot[3]);

/* Linear-light floats (3 per pixel) to sRGB bytes, radiance x 2^exposure. */
void frame_srgb_from_linear(const float *rgb, size_t npix, double exposure, uint8_t *out);

#endif
