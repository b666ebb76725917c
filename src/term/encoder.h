/* rtsh — picture encoders: how an RGB picture becomes bytes for the
 * terminal. Half blocks (enc_halfblock.c) are the first; other protocols
 * (kitty, sixel, iTerm2) are one file each behind the same interface, and
 * one line in encoder_table (encoder.c).
 *
 * An encoder owns a rectangle of character cells on the screen. The front
 * end puts sRGB pictures on its pixel canvas (encoder_put, as often as it
 * likes: a newer picture overtakes one not yet sent) and the output
 * scheduler (out.h) asks for the bytes in parts of about a given size
 * (encoder_update), each part standing alone, so that the bytes in flight
 * to a slow terminal stay bounded. An encoder keeps what the terminal was
 * last sent and sends only what differs from it ("damage").
 */
#ifndef RTSH_ENCODER_H
#define RTSH_ENCODER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "base/abuf.h"
#include "term/frame.h"
#include "term/pixels.h"

/* Where the picture goes and what the terminal is like. */
typedef struct encoder_geom {
	int cols, rows;      /* the picture area in cells */
	int x0, y0;          /* its top-left cell on the screen, 0-based */
	int cell_w, cell_h;  /* a cell in pixels, 0 when not known */
	bool cursor_off;     /* the cursor stays hidden after each part (key mode) */
	int max_w, max_h;    /* the largest image the terminal takes in pixels
	                      * (sixel: XTSMGRAPHICS); 0 when not known */
	frame_palette pal;   /* the colours the terminal takes */
	bool passthrough;    /* pixel encoders: inside tmux, each image sent
	                      * through tmux's passthrough to the terminal
	                      * outside, placed there at the pane's cell
	                      * (pass_x, pass_y) plus its own */
	int pass_x, pass_y;
	bool exact;          /* cell encoders: every cell the best fit of its own
	                      * pixels, no colour kept from a neighbour to save
	                      * bytes (frame.lambda 0) */
} encoder_geom;

typedef struct encoder encoder;

typedef struct encoder_ops {
	const char *name;    /* a pixel encoder's: its value of the `pixels` setting */
	/* The pixel canvas of an area: half blocks give cols x 2*rows. */
	void (*canvas)(const encoder_geom *g, int *w, int *h);
	/* A new encoder, every cell at the default background; NULL when
	 * out of memory or the area is empty. */
	encoder *(*open)(const encoder_geom *g);
	void (*close)(encoder *e);
	/* Puts w x h sRGB pixels (3 bytes each, rows top down) at (ox, oy) of
	 * the canvas; pixels outside keep their value. */
	void (*put)(encoder *e, const uint8_t *rgb, int w, int h, int ox, int oy);
	/* Every pixel to the default background. */
	void (*clear)(encoder *e);
	/* Forgets what the terminal shows (after the screen was cleared). */
	void (*invalidate)(encoder *e);
	/* Appends the next part of the update to out, about `budget` bytes
	 * (SIZE_MAX: all of it); true when more remains to send. */
	bool (*update)(encoder *e, abuf *out, size_t budget);
	/* True when the terminal does not show the newest picture yet. */
	bool (*dirty)(const encoder *e);
	/* Drops the part not yet sent: what the terminal shows stays. */
	void (*keep_shown)(encoder *e);
	/* Lossy damage: parts that moved by at most tol (sRGB levels) need
	 * not be sent; 0: exact. NULL when the encoder is always exact. */
	void (*set_lossy)(encoder *e, int tol);
	/* Pixel encoders: one whole picture of w x h sRGB pixels over cols x
	 * rows cells, for callers that hold no encoder (the batch preview);
	 * false when out of memory. NULL for cell encoders. */
	bool (*picture)(abuf *out, const uint8_t *rgb, int w, int h, int cols, int rows);
} encoder_ops;

/* Every encoder starts with this. */
struct encoder {
	const encoder_ops *ops;
	encoder_geom geom;
};

/* The half-block encoder (term/frame.h underneath), and the other symbol
 * sets' (term/symbols.h): a canvas of 2x4 samples a cell. */
extern const encoder_ops encoder_halfblock, encoder_quadrant, encoder_sextant, encoder_octant;
/* The cell encoder of a symbol set (not SYMBOLS_AUTO). */
const encoder_ops *encoder_symbols(symbols_kind k);
/* Real pixels (term/pixels.h; enc_pixels.c): the canvas is the area at the
 * terminal's pixel size (geom.cell_w, cell_h must be known). */
extern const encoder_ops encoder_kitty, encoder_sixel, encoder_iterm;

/* The encoders by name ("halfblock", ...), NULL-terminated. */
extern const encoder_ops *const encoder_table[];
/* The encoder called name, or NULL. */
const encoder_ops *encoder_find(const char *name);
/* The pixel encoder of a `pixels` value other than off and auto (by its
 * name, pixels.h); NULL when there is none. */
const encoder_ops *encoder_pixels(pixels_mode m);

/* Shorthands for e->ops->... */
static inline void encoder_close(encoder *e)
{
	if (e)
		e->ops->close(e);
}
static inline void encoder_put(encoder *e, const uint8_t *rgb, int w, int h, int ox, int oy)
{
	e->ops->put(e, rgb, w, h, ox, oy);
}
static inline bool encoder_update(encoder *e, abuf *out, size_t budget)
{
	return e->ops->update(e, out, budget);
}
static inline bool encoder_dirty(const encoder *e)
{
	return e->ops->dirty(e);
}

#endif
