/* rtsh — the cell encoders (encoder.h): half blocks, two pixels a cell,
 * and the other symbol sets (term/symbols.h: quadrants, sextants,
 * octants), drawn by the frame module (frame.h), which keeps the cells the
 * terminal shows and sends the changed ones, a few rows per part. A symbol
 * set's canvas holds 2x4 samples a cell. */
#include <stdlib.h>

#include "term/encoder.h"

typedef struct halfblock {
	encoder base;
	frame *fr;
} halfblock;

static void hb_canvas(const encoder_geom *g, int *w, int *h)
{
	*w = g->cols;
	*h = 2 * g->rows;
}

static void sym_canvas(const encoder_geom *g, int *w, int *h)
{
	*w = g->cols * SYMBOLS_SAMPLE_W;
	*h = g->rows * SYMBOLS_SAMPLE_H;
	if (g->pal == PALETTE_NONE)
		hb_canvas(g, w, h); /* no colour: one character a cell, as half blocks */
}

static encoder *cells_open(const encoder_geom *g, const encoder_ops *ops, symbols_kind sym)
{
	halfblock *e = calloc(1, sizeof *e);
	if (!e)
		return NULL;
	e->base.ops = ops;
	e->base.geom = *g;
	e->fr = frame_new_symbols(g->cols, g->rows, g->pal, sym);
	if (!e->fr) {
		free(e);
		return NULL;
	}
	e->fr->x0 = g->x0;
	e->fr->y0 = g->y0;
	e->fr->cursor_off = g->cursor_off;
	if (g->exact)
		e->fr->lambda = 0;
	return &e->base;
}

static void hb_close(encoder *e)
{
	halfblock *h = (halfblock *)e;
	frame_free(h->fr);
	free(h);
}

static void hb_put(encoder *e, const uint8_t *rgb, int w, int h, int ox, int oy)
{
	frame_put_image(((halfblock *)e)->fr, rgb, w, h, ox, oy);
}

static void hb_clear(encoder *e)
{
	frame_clear(((halfblock *)e)->fr);
}

static void hb_invalidate(encoder *e)
{
	frame_invalidate(((halfblock *)e)->fr);
}

static bool hb_update(encoder *e, abuf *out, size_t budget)
{
	return frame_update_part(((halfblock *)e)->fr, out, budget);
}

static bool hb_dirty(const encoder *e)
{
	return frame_dirty(((const halfblock *)e)->fr);
}

static void hb_keep_shown(encoder *e)
{
	frame_keep_shown(((halfblock *)e)->fr);
}

static void hb_set_lossy(encoder *e, int tol)
{
	((halfblock *)e)->fr->tol = tol;
}

static encoder *hb_open(const encoder_geom *g)
{
	return cells_open(g, &encoder_halfblock, SYMBOLS_HALF);
}

static encoder *quadrant_open(const encoder_geom *g)
{
	return cells_open(g, &encoder_quadrant, SYMBOLS_QUADRANT);
}

static encoder *sextant_open(const encoder_geom *g)
{
	return cells_open(g, &encoder_sextant, SYMBOLS_SEXTANT);
}

static encoder *octant_open(const encoder_geom *g)
{
	return cells_open(g, &encoder_octant, SYMBOLS_OCTANT);
}

#define CELL_OPS(NAME, CANVAS, OPEN)                                                              \
	{                                                                                         \
		.name = NAME, .canvas = CANVAS, .open = OPEN, .close = hb_close, .put = hb_put,     \
		.clear = hb_clear, .invalidate = hb_invalidate, .update = hb_update,              \
		.dirty = hb_dirty, .keep_shown = hb_keep_shown, .set_lossy = hb_set_lossy,        \
	}

const encoder_ops encoder_halfblock = CELL_OPS("halfblock", hb_canvas, hb_open);
const encoder_ops encoder_quadrant = CELL_OPS("quadrant", sym_canvas, quadrant_open);
const encoder_ops encoder_sextant = CELL_OPS("sextant", sym_canvas, sextant_open);
const encoder_ops encoder_octant = CELL_OPS("octant", sym_canvas, octant_open);
