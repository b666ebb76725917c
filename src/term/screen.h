/* rtsh — the full-screen layout: the picture on top, a status line, and a
 * scroll region of a few lines at the bottom for the prompt and the output
 * of commands.
 *
 *   row 0 .. pic_rows-1        the picture (half blocks or another symbol
 *                              set, frame.h; or real pixels, pixels.h)
 *   row status_row             the status line (reverse video)
 *   rows region_top .. rows-1  the scroll region (DECSTBM); the cursor lives
 *                              here, so readline and printf work as usual
 *
 * Escape sequences sent here, besides the frame's (frame.h):
 *   \e[?1049h \e[?1049l   enter / leave the alternate screen
 *   \e[T;Br  \e[r         set / reset the scroll region
 *   \e[2J                 clear the screen
 *   \e[7m                 reverse video (the status line)
 *   \e[K                  clear to the end of the line
 *   \e_Ga=d,d=A,q=2\e\\     kitty: delete the images (when the picture used
 *                         them: before a full clear, a new layout, the way out)
 *
 *   \e[?2026l \e[?25h \e[?2004l \e[?1000l \e[?1002l \e[?1003l \e[?1006l
 *   \e[?1l \e>           on the way out: every mode rtsh or readline may
 *                         have set, back to its default (screen_restore_async)
 *
 * The terminal is restored on every way out: screen_leave on a normal exit;
 * the signal handlers (shell/signals.c) call screen_restore_async, which
 * uses async-signal-safe calls only.
 */
#ifndef RTSH_SCREEN_H
#define RTSH_SCREEN_H

#include <stdbool.h>
#include <stdint.h>

#include "base/abuf.h"
#include "term/encoder.h"
#include "term/frame.h"
#include "term/out.h"

typedef struct screen {
	int fd;
	int cols, rows;
	int pic_rows;      /* 0: no room for a picture */
	int status_row;    /* 0-based */
	int region_top;    /* the scroll region is region_top .. rows-1 */
	frame_palette pal;
	double aspect;     /* width / height of the image */
	int img_w, img_h;  /* the preview's size in pixels (0 when no picture) */
	int img_x, img_y;  /* its place on the encoder's canvas (half blocks:
	                    * cols x 2*pic_rows pixels) */
	encoder *enc;      /* the picture area's encoder */
	int symbols;       /* symbols_kind asked for (screen_set_symbols) */
	symbols_kind sym;  /* the symbol set in use (not SYMBOLS_AUTO) */
	int pixels;        /* pixels_mode asked for (screen_set_pixels) */
	const encoder_ops *pix_ops; /* the pixel encoder in use; NULL: half blocks */
	bool sixel_missing; /* sixel chosen, libsixel not loadable: half blocks (the shell says why) */
	int cell_w, cell_h; /* a cell in pixels (0: not known) */
	int tmux_pass;     /* inside tmux: 0 not asked yet, 1 passthrough on, -1 off */
	int pass_x, pass_y; /* with passthrough: the pane's top-left cell outside */
	termout *out;      /* every byte of the screen goes out through it */
	bool active;
	char status[512];  /* the status line's text */
	abuf log;          /* the command area's recent text (screen_log), drawn
	                    * again after a resize or Ctrl-Z and fg */
} screen;

/* Remembers text shown in the command area (the prompt and the command,
 * its output, its error), so that a new layout (a resize, Ctrl-Z and fg,
 * the pager's or key mode's end) shows the area's last lines again. Only
 * the last few kilobytes are kept. */
void screen_log(screen *s, const char *text, size_t n);
/* Forgets the command area's text (clear). */
void screen_log_clear(screen *s);

/* Enters the alternate screen of fd and lays it out for an image of the
 * given aspect. False when fd is not a terminal. */
bool screen_enter(screen *s, int fd, frame_palette pal, double aspect);
/* Restores the terminal: scroll region, attributes, cursor, main screen.
 * Safe to call twice. */
void screen_leave(screen *s);
/* Reads the terminal size and lays the screen out again for `aspect`;
 * clears it when anything changed (or `force`), redraws the status line and
 * puts the cursor on the last row. True when the image size changed. */
bool screen_layout(screen *s, double aspect, bool force);
/* Clears the whole screen and resets the scroll region (before the pager
 * or key mode takes the screen); no picture goes out until screen_layout
 * gives the screen back. */
void screen_clear_all(screen *s);
/* Clears the command area (the scroll region) and leaves the cursor on
 * its last row. */
void screen_clear_commands(screen *s);
/* Another palette (the terminal said it has truecolor): lays out and
 * clears the screen again. */
void screen_set_palette(screen *s, frame_palette pal);
/* Real pixels (term/pixels.h): mode off, kitty, sixel, iterm or auto (what
 * the terminal said in the start-up probe; half blocks when it said
 * nothing, or the cell size in pixels is not known). Lays the screen out
 * again when the encoder changes; true then. */
bool screen_set_pixels(screen *s, int mode);
/* The cells' glyphs when not in real pixels (term/symbols.h): half,
 * quadrant, sextant, octant or auto (symbols_choose on TERM_PROGRAM,
 * VTE_VERSION and the XTVERSION answer of the start-up probe). Lays the
 * screen out again when the set in use changes; true then. */
bool screen_set_symbols(screen *s, int kind);
/* Deletes the picture's kitty images now, if it showed any (they float
 * over text): before something else draws on the screen (key mode). */
void screen_drop_images(screen *s);
/* text fitted to exactly cols terminal columns (cut on a character, padded
 * with spaces), counted by wcwidth in the current locale: the status line. */
void screen_fit_text(abuf *a, const char *text, int cols);
/* Sets and draws the status line. */
void screen_status(screen *s, const char *text);
/* Puts an sRGB image of img_w x img_h pixels in the picture area
 * (letterboxed); the output scheduler (s->out, termout_pump) sends the
 * cells that changed. */
void screen_picture(screen *s, const uint8_t *rgb, int w, int h);
/* Lays the screen out again and redraws it after the process was stopped
 * and continued (the signal handler entered the alternate screen again). */
void screen_resume(screen *s);

/* --- for signal handlers: async-signal-safe --- */
/* Writes the sequence that gives the terminal back (keypad off when
 * screen_keypad turned it on, every mode reset, main screen); nothing when
 * no screen is entered. */
void screen_restore_async(void);
/* Remembers text shown in the command area (the prompt and the command,
 * its output, its error), so that a new layout (a resize, Ctrl-Z and fg,
 * the pager's or key mode's end) shows the area's last lines again. Only
 * the last few kilobytes are kept. */
void screen_log(screen *s, const char *text, size_t n);
/* Forgets the command area's text (clear). */
void screen_log_clear(screen *s);

/* Enters the alternate screen again, with the keypad mode it had. */
void screen_reenter_async(void);
/* Sends terminfo's keypad transmit string on_seq (on) or off_seq (off) to
 * fd and remembers the state for the two functions above. */
void screen_keypad(int fd, const char *on_seq, const char *off_seq, bool on);

/* The preview size for a picture area of cols x rows cells and an aspect:
 * letterboxed inside cols x 2*rows pixels, both at least 1. */
void screen_fit(int cols, int rows, double aspect, bool whole_cells, int *w, int *h);

#endif
