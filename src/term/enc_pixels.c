/* rtsh — the pixel encoders (encoder.h): kitty, sixel and iTerm2 behind the
 * encoder interface.
 *
 * The canvas is the picture area at the terminal's own pixel size (cols x
 * cell_w by rows x cell_h). It is sent in strips of STRIP_ROWS cell rows
 * (sixel: smaller tiles, SIXEL_TILE_W), each a picture of its own placed at
 * its first cell (kitty: its own image id, replaced in place), so that
 * every part of an update stands alone
 * and a slow link carries one strip at a time: a newer picture is never
 * queued behind an older one, the strips still to send simply come from
 * it. A strip whose pixels the terminal already shows is not sent (a hash
 * of its bytes is kept), so an unchanged frame costs nothing.
 *
 * Clearing for kitty deletes the images (they float above the text and
 * would survive a cleared screen); sixel and iTerm2 pictures live in the
 * cells and go with them, so a cleared canvas is sent as background. */
#include <stdlib.h>
#include <string.h>

#include "rtsh/memory.h"
#include "term/encoder.h"
#include "term/pixels.h"

/* Cell rows per strip (kitty, iTerm2: a strip is the picture's width). */
#define STRIP_ROWS 2
/* Sixel sends tiles of one cell row and at most this many pixels across
 * (and never more than the terminal's largest sixel image): a sixel image
 * carries its own palette and cannot be cut, so a tile must be small
 * enough to fit the output scheduler's slice on a slow link (30 KB/s:
 * 2.4 KB a slice). */
#define SIXEL_TILE_W 256
/* The largest sixel image when the terminal does not say (xterm's default
 * maxGraphicSize). */
#define SIXEL_SAFE_MAX 1000

typedef struct pix_enc {
	encoder base;
	pixels_mode mode;
	int w, h;          /* the canvas in pixels */
	uint8_t *rgb;      /* w*h*3, sRGB */
	int nstrips;       /* tiles: nrows x ncols */
	int tile_rows, tile_cols; /* a tile in cells */
	int ncols;         /* tiles across */
	uint8_t *tmp;      /* one tile's pixels when it is narrower than the canvas */
	uint64_t *want;    /* the hash of each strip of the canvas */
	uint64_t *shown;   /* the hash of what the terminal shows there; 0: not known */
	bool *stale;       /* given up by keep_shown: the terminal shows an older picture */
	int next;          /* the strip to look at first (round robin) */
	bool erase;        /* kitty: delete the images before anything else */
	int kitty_used;    /* kitty: image ids used so far (from PIXELS_KITTY_ID) */
} pix_enc;

static void pix_canvas(const encoder_geom *g, int *w, int *h)
{
	*w = g->cols * g->cell_w;
	*h = g->rows * g->cell_h;
}

/* Tile k in pixels. */
static void tile_rect(const pix_enc *e, int k, int *x, int *y, int *w, int *h)
{
	const encoder_geom *g = &e->base.geom;
	int r = k / e->ncols, c = k % e->ncols;
	int rows = g->rows - r * e->tile_rows, cols = g->cols - c * e->tile_cols;
	*x = c * e->tile_cols * g->cell_w;
	*y = r * e->tile_rows * g->cell_h;
	*w = (cols < e->tile_cols ? cols : e->tile_cols) * g->cell_w;
	*h = (rows < e->tile_rows ? rows : e->tile_rows) * g->cell_h;
}

static uint64_t strip_hash(const pix_enc *e, int k)
{
	int x, y, w, h;
	tile_rect(e, k, &x, &y, &w, &h);
	uint64_t v = 0xcbf29ce484222325ULL; /* FNV-1a */
	for (int row = y; row < y + h; row++) {
		const uint8_t *p = e->rgb + ((size_t)row * e->w + x) * 3, *end = p + (size_t)w * 3;
		for (; p < end; p++)
			v = (v ^ *p) * 0x100000001b3ULL;
	}
	return v | 1; /* never 0, which means "not known" */
}

static void pix_close(encoder *b);

static encoder *pix_open_mode(const encoder_geom *g, const encoder_ops *ops, pixels_mode mode)
{
	int w, h;
	pix_canvas(g, &w, &h);
	if (w < 1 || h < 1 || g->cell_h < 1)
		return NULL;
	pix_enc *e = calloc(1, sizeof *e);
	if (!e)
		return NULL;
	e->base.ops = ops;
	e->base.geom = *g;
	e->mode = mode;
	e->w = w;
	e->h = h;
	e->tile_rows = STRIP_ROWS;
	e->tile_cols = g->cols;
	if (mode == PIXELS_SIXEL) {
		int max_w = g->max_w > 0 ? g->max_w : SIXEL_SAFE_MAX;
		max_w = max_w < SIXEL_TILE_W ? max_w : SIXEL_TILE_W;
		e->tile_rows = 1;
		e->tile_cols = max_w / g->cell_w > 0 ? max_w / g->cell_w : 1;
		if (e->tile_cols > g->cols)
			e->tile_cols = g->cols;
	}
	e->ncols = (g->cols + e->tile_cols - 1) / e->tile_cols;
	e->nstrips = (g->rows + e->tile_rows - 1) / e->tile_rows * e->ncols;
	e->rgb = calloc((size_t)w * h * 3, 1);
	e->tmp = e->ncols > 1 ? malloc((size_t)e->tile_cols * g->cell_w * e->tile_rows * g->cell_h * 3) : NULL;
	e->want = calloc((size_t)e->nstrips, sizeof *e->want);
	e->shown = calloc((size_t)e->nstrips, sizeof *e->shown);
	e->stale = calloc((size_t)e->nstrips, sizeof *e->stale);
	if (!e->rgb || !e->want || !e->shown || !e->stale || (e->ncols > 1 && !e->tmp)) {
		pix_close(&e->base);
		return NULL;
	}
	/* The terminal shows the background (the screen was cleared). */
	for (int k = 0; k < e->nstrips; k++)
		e->shown[k] = e->want[k] = strip_hash(e, k);
	return &e->base;
}

static void pix_close(encoder *b)
{
	pix_enc *e = (pix_enc *)b;
	mem_free_all(e->rgb, e->tmp, e->want, e->shown, e->stale, e);
}

static void pix_put(encoder *b, const uint8_t *rgb, int w, int h, int ox, int oy)
{
	pix_enc *e = (pix_enc *)b;
	int x0 = ox < 0 ? 0 : ox, y0 = oy < 0 ? 0 : oy;
	int x1 = ox + w < e->w ? ox + w : e->w, y1 = oy + h < e->h ? oy + h : e->h;
	if (x1 <= x0 || y1 <= y0)
		return;
	for (int y = y0; y < y1; y++)
		memcpy(e->rgb + ((size_t)y * e->w + x0) * 3, rgb + ((size_t)(y - oy) * w + (x0 - ox)) * 3,
		       (size_t)(x1 - x0) * 3);
	int th = e->tile_rows * e->base.geom.cell_h, tw = e->tile_cols * e->base.geom.cell_w;
	for (int k = 0; k < e->nstrips; k++) {
		int r = k / e->ncols, c = k % e->ncols;
		if ((r + 1) * th <= y0 || r * th >= y1 || (c + 1) * tw <= x0 || c * tw >= x1)
			continue;
		e->want[k] = strip_hash(e, k);
		if (e->stale[k]) {
			e->shown[k] = 0;
			e->stale[k] = false;
		}
	}
}

static void pix_clear(encoder *b)
{
	pix_enc *e = (pix_enc *)b;
	memset(e->rgb, 0, (size_t)e->w * e->h * 3);
	for (int k = 0; k < e->nstrips; k++)
		e->want[k] = strip_hash(e, k);
	if (e->mode == PIXELS_KITTY) {
		/* Deleting the images shows the background again. */
		e->erase = e->kitty_used > 0;
		memcpy(e->shown, e->want, (size_t)e->nstrips * sizeof *e->shown);
	}
}

static void pix_invalidate(encoder *b)
{
	pix_enc *e = (pix_enc *)b;
	memset(e->shown, 0, (size_t)e->nstrips * sizeof *e->shown);
	memset(e->stale, 0, (size_t)e->nstrips * sizeof *e->stale);
}

/* Appends tile k, placed at its cell with the cursor saved and restored,
 * and hidden meanwhile: a terminal that draws its cursor while the image's
 * bytes are still coming (xterm, between two reads) puts it on the tile's
 * first cell, and when the cursor leaves, paints that cell again as text,
 * over the image: a cell-sized hole in the terminal's background colour
 * (issue 31, defect 8). */
static bool send_strip(pix_enc *e, int k, abuf *out)
{
	abuf *outer = out;
	const encoder_geom *g = &e->base.geom;
	int x, y, w, h;
	tile_rect(e, k, &x, &y, &w, &h);
	int rows = h / g->cell_h, cols = w / g->cell_w;
	size_t len0 = out->len;
	abuf inner;
	if (g->passthrough) {
		/* Through tmux: the whole strip, its cursor move in the outer
		 * terminal's cells, goes as one passthrough. */
		abuf_init(&inner);
		out = &inner;
	}
	abuf_printf(out, "\x1b" "7\x1b[?25l\x1b[%d;%dH", g->pass_y * g->passthrough + g->y0 + y / g->cell_h + 1,
	            g->pass_x * g->passthrough + g->x0 + x / g->cell_w + 1);
	const uint8_t *p = e->rgb + ((size_t)y * e->w + x) * 3;
	if (w < e->w) { /* a tile narrower than the canvas: its rows together */
		for (int row = 0; row < h; row++)
			memcpy(e->tmp + (size_t)row * w * 3, p + (size_t)row * e->w * 3, (size_t)w * 3);
		p = e->tmp;
	}
	bool ok;
	if (e->mode == PIXELS_KITTY) {
		ok = k < PIXELS_KITTY_IDS && pixels_kitty(out, p, w, h, cols, rows, PIXELS_KITTY_ID + k);
		if (ok && k + 1 > e->kitty_used)
			e->kitty_used = k + 1;
	} else {
		ok = pixels_encode(e->mode, out, p, w, h, cols, rows);
	}
	abuf_str(out, g->cursor_off || g->passthrough ? "\x1b" "8" : "\x1b" "8\x1b[?25h");
	if (g->passthrough) {
		bool good = ok && !inner.failed;
		out = outer;
		if (good)
			pixels_passthrough(out, inner.b, inner.len);
		abuf_free(&inner);
		ok = good;
	}
	if (!ok || out->failed) {
		out->len = len0;
		return false;
	}
	return true;
}

static bool pix_update(encoder *b, abuf *out, size_t budget)
{
	pix_enc *e = (pix_enc *)b;
	size_t start = out->len;
	if (e->erase) {
		abuf del;
		abuf_init(&del);
		for (int k = 0; k < e->kitty_used; k++)
			pixels_kitty_delete(e->base.geom.passthrough ? &del : out, PIXELS_KITTY_ID + k);
		if (e->base.geom.passthrough && !del.failed)
			pixels_passthrough(out, del.b, del.len);
		abuf_free(&del);
		e->kitty_used = 0;
		e->erase = false;
	}
	for (int i = 0; i < e->nstrips; i++) {
		int k = (e->next + i) % e->nstrips;
		if (e->want[k] == e->shown[k])
			continue;
		if (out->len > start && out->len - start >= budget) {
			e->next = k;
			return true;
		}
		if (send_strip(e, k, out))
			e->shown[k] = e->want[k];
		else
			e->shown[k] = e->want[k]; /* out of memory: give this picture up */
		e->next = (k + 1) % e->nstrips;
	}
	return false;
}

static bool pix_dirty(const encoder *b)
{
	const pix_enc *e = (const pix_enc *)b;
	if (e->erase)
		return true;
	for (int k = 0; k < e->nstrips; k++)
		if (e->want[k] != e->shown[k])
			return true;
	return false;
}

static void pix_keep_shown(encoder *b)
{
	pix_enc *e = (pix_enc *)b;
	/* What the terminal shows stays: the strips not sent are given up
	 * until the next picture, which sends them whatever it holds. */
	for (int k = 0; k < e->nstrips; k++)
		if (e->shown[k] != e->want[k]) {
			e->shown[k] = e->want[k];
			e->stale[k] = true;
		}
}

static encoder *kitty_open(const encoder_geom *g)
{
	return pix_open_mode(g, &encoder_kitty, PIXELS_KITTY);
}

static encoder *sixel_open(const encoder_geom *g)
{
	return pix_open_mode(g, &encoder_sixel, PIXELS_SIXEL);
}

static encoder *iterm_open(const encoder_geom *g)
{
	return pix_open_mode(g, &encoder_iterm, PIXELS_ITERM);
}

static bool kitty_picture(abuf *out, const uint8_t *rgb, int w, int h, int cols, int rows)
{
	return pixels_encode(PIXELS_KITTY, out, rgb, w, h, cols, rows);
}

static bool sixel_picture(abuf *out, const uint8_t *rgb, int w, int h, int cols, int rows)
{
	return pixels_encode(PIXELS_SIXEL, out, rgb, w, h, cols, rows);
}

static bool iterm_picture(abuf *out, const uint8_t *rgb, int w, int h, int cols, int rows)
{
	return pixels_encode(PIXELS_ITERM, out, rgb, w, h, cols, rows);
}

#define PIXEL_OPS(NAME, OPEN, PICTURE)                                                             \
	{                                                                                          \
		.name = NAME, .canvas = pix_canvas, .open = OPEN, .close = pix_close, .put = pix_put, \
		.clear = pix_clear, .invalidate = pix_invalidate, .update = pix_update,            \
		.dirty = pix_dirty, .keep_shown = pix_keep_shown, .picture = PICTURE,              \
	}

const encoder_ops encoder_kitty = PIXEL_OPS("kitty", kitty_open, kitty_picture);
const encoder_ops encoder_sixel = PIXEL_OPS("sixel", sixel_open, sixel_picture);
const encoder_ops encoder_iterm = PIXEL_OPS("iterm", iterm_open, iterm_picture);

/* One picture in the given protocol, for callers that hold no encoder
 * (the batch preview). */
bool pixels_encode(pixels_mode m, abuf *out, const uint8_t *rgb, int w, int h, int cols, int rows)
{
	switch (m) {
	case PIXELS_KITTY:
		return pixels_kitty(out, rgb, w, h, cols, rows, PIXELS_KITTY_ID);
	case PIXELS_SIXEL:
		return pixels_sixel(out, rgb, w, h);
	case PIXELS_ITERM:
		return pixels_iterm(out, rgb, w, h, cols, rows);
	default:
		return false;
	}
}
