/* rtsh — the key view: how key mode (`view`, shell/keymode.h) looks on the
 * terminal. The picture fills the screen but for a status line (reverse
 * video) and, when shown, a help bar under it (each key in bold and what it
 * does, as many as fit). Every byte goes out through the output scheduler
 * (out.h): the bars as text at once, the picture as its encoder's damage,
 * paced by the terminal's answers like the shell's preview.
 *
 * Escape sequences sent here, besides the encoder's (frame.h):
 *   \e[?2026h \e[?2026l   begin / end synchronized update, around the bars
 *   \e[r                  reset the scroll region (the shell's is restored
 *                         by screen_layout on the way out)
 *   \e[2J                 clear the screen
 *   \e[R;CH               move the cursor
 *   \e[7m  \e[m           reverse video (the status line) / reset
 *   \e[1m  \e[22m         bold on / off (the help bar's keys)
 *   \e[K                  clear to the end of the line
 *   \e[?25l \e[?25h       hide / show the cursor
 *   \e_Ga=d,d=A,q=2\e\\     kitty: delete the images (at a repaint, when the
 *                         picture is in kitty images)
 */
#ifndef RTSH_KEYVIEW_H
#define RTSH_KEYVIEW_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "base/abuf.h"
#include "term/encoder.h"
#include "term/frame.h"
#include "term/out.h"

/* One item of the help bar: keys (single-width characters) and what they
 * do. */
typedef struct keyview_item {
	const char *keys, *what;
} keyview_item;

typedef struct keyview {
	termout *out;              /* borrowed: every byte goes through it */
	frame_palette pal;
	const keyview_item *bar;   /* borrowed */
	size_t nbar;
	int cols, rows;
	bool help;                 /* the help bar is shown */
	int help_rows;             /* its rows: two when one would cut it (a screen of 40x16 or more) */
	int pic_rows;              /* the picture's rows; the status line and help bar follow */
	int img_w, img_h;          /* the picture in pixels (0: no room for one) ... */
	int img_x, img_y;          /* ... and its place on the encoder's canvas */
	const encoder_ops *ops;    /* the picture's encoder (keyview_set_encoder);
	                            * NULL: half blocks */
	int cell_w, cell_h;        /* a cell in pixels, for real pixels (0: not known) */
	int max_w, max_h;          /* the largest sixel image (0: not known) */
	encoder *enc;              /* the picture's */
	bool repaint;              /* clear the screen at the next draw */
	char status_shown[1024];
	abuf a;
} keyview;

/* A key view sending through out in palette pal, with the help bar's
 * items. */
void keyview_init(keyview *v, termout *out, frame_palette pal, const keyview_item *bar, size_t nbar);
/* Stops sending the picture and frees the view (the scheduler keeps no
 * picture: the caller gives it its own back). */
void keyview_free(keyview *v);
/* The encoder of the picture: half blocks (NULL), another symbol set, or
 * real pixels (cell_w x cell_h pixels a cell; max_w, max_h the largest
 * sixel image, 0 when not known), from the next keyview_layout on. */
void keyview_set_encoder(keyview *v, const encoder_ops *ops, int cell_w, int cell_h, int max_w, int max_h);
/* Lays out a terminal of cols x rows cells for a picture of the aspect
 * (width / height), with or without the help bar; the next draw clears
 * the screen. */
void keyview_layout(keyview *v, int cols, int rows, bool help, double aspect);
/* The next draw clears the screen and paints it all. */
void keyview_repaint(keyview *v);
/* Puts the picture (img_w x img_h sRGB pixels) for the scheduler to send;
 * final: not a refinement pass (exact on a slow link). */
void keyview_picture(keyview *v, const uint8_t *rgb, bool final);
/* True when the status line shows other text than `text`. */
bool keyview_status_differs(const keyview *v, const char *text);
/* Sends, as one write, what a repaint needs (the screen cleared, the help
 * bar) and the status line when it changed. */
void keyview_draw(keyview *v, const char *status);
/* Gives the screen back: attributes reset, the cursor shown. */
void keyview_end(keyview *v);
/* A status line that fits: " " and the n fields joined by " │ " (empty
 * fields left out) into buf; while it is wider than cols columns, the field
 * of the lowest drop rank > 0 is left out (1 first; 0: never). What still
 * does not fit is cut where the line is drawn. */
void keyview_fit_status(char *buf, size_t size, const char *const *fields, const int *drop, size_t n, int cols);

#endif
