/* rtsh — real pixels: the terminal graphics protocols that show an image
 * at the terminal's own pixel resolution, and how to find out which one a
 * terminal speaks.
 *
 *   kitty   the kitty graphics protocol (kitty, WezTerm, Konsole, Ghostty):
 *           zlib-compressed RGB (f=24, o=z) in base64 chunks, one image id
 *           replaced in place (enc_kitty.c)
 *   sixel   DEC sixel (xterm -ti vt340, foot, mlterm, WezTerm, Windows
 *           Terminal): at most 256 colours, quantised and encoded by
 *           libsixel (enc_sixel.c)
 *   iterm   the iTerm2 inline image protocol (iTerm2, WezTerm, VS Code):
 *           a PNG made with libpng (enc_iterm.c)
 *
 * Each encoder appends the bytes that draw a w x h sRGB picture (3 bytes a
 * pixel, rows top down) with its top-left corner at the cursor, covering
 * cols x rows character cells (0, 0: at the picture's own pixel size).
 * The caller puts the cursor there first and restores it after (DECSC and
 * DECRC have one slot, so the encoders do not use them).
 *
 * Escape sequences these files send:
 *   \e_G...;<base64>\e\\      kitty graphics: transmit, place, delete, query
 *   \eP...q...\e\\            sixel (libsixel's DCS)
 *   \e]1337;File=...:<b64>\a  iTerm2 inline image
 *   \e7 \e[?25l \e[R;CH ...  each strip of the picture placed at its cell
 *   \e8 \e[?25h              (enc_pixels.c), the cursor saved, hidden while
 *                             the image comes, restored and shown again
 *   \e[c  \e[16t  \e[?2;1;0S  questions: DA1 (sixel is attribute 4),
 *                             the cell size in pixels, XTSMGRAPHICS (the
 *                             largest sixel image)
 *   \e[>q                     XTVERSION: the terminal's name and version
 *                             (answered \eP>|text\e\\)
 */
#ifndef RTSH_PIXELS_H
#define RTSH_PIXELS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "base/abuf.h"

typedef enum pixels_mode {
	PIXELS_OFF,   /* half blocks */
	PIXELS_KITTY,
	PIXELS_SIXEL,
	PIXELS_ITERM,
	PIXELS_AUTO,  /* ask the terminal */
} pixels_mode;

/* "off" "kitty" "sixel" "iterm" "auto". */
const char *pixels_mode_name(pixels_mode m);
/* false when s names no mode. */
bool pixels_mode_parse(const char *s, pixels_mode *m);

/* --- encoders ------------------------------------------------------------ */

/* The first kitty image id rtsh uses (the picture's strips take the ids
 * from here up, PIXELS_KITTY_IDS of them at most). */
#define PIXELS_KITTY_ID 4242
#define PIXELS_KITTY_IDS 256
/* Bytes of base64 in one kitty chunk (the protocol's limit). */
#define PIXELS_KITTY_CHUNK 4096

/* kitty: the picture as image `id` (placement 1), replacing the one of that
 * id shown before, scaled to cols x rows cells; the terminal answers
 * nothing (q=2). Each chunk of at most PIXELS_KITTY_CHUNK base64 bytes is
 * its own escape sequence. False when out of memory (out unchanged). */
bool pixels_kitty(abuf *out, const uint8_t *rgb, int w, int h, int cols, int rows, int id);
/* kitty: deletes image `id` and frees its data in the terminal. */
void pixels_kitty_delete(abuf *out, int id);

/* sixel: the picture in at most 256 colours (libsixel's median-cut
 * quantiser, no dithering: a refining picture must not shimmer). False on
 * failure (out unchanged). */
bool pixels_sixel(abuf *out, const uint8_t *rgb, int w, int h);
/* Whether libsixel can be loaded (it is opened on the first call); if not,
 * false with why ("libsixel cannot be loaded (REASON); expected SONAME
 * installed") when why is not NULL. pixels_sixel is false without it. */
bool pixels_sixel_available(char *why, size_t size);

/* iTerm2: the picture as an inline PNG stretched over cols x rows cells.
 * False on failure (out unchanged). */
bool pixels_iterm(abuf *out, const uint8_t *rgb, int w, int h, int cols, int rows);

/* The picture in the given protocol (not PIXELS_OFF/AUTO; enc_pixels.c). */
bool pixels_encode(pixels_mode m, abuf *out, const uint8_t *rgb, int w, int h, int cols, int rows);

/* tmux's passthrough of n bytes: \ePtmux; the bytes with every ESC doubled
 * \e\\ (tmux sends them on to the terminal outside as they are). */
void pixels_passthrough(abuf *out, const char *b, size_t n);
/* Standard base64 (RFC 4648, with padding) of n bytes. */
void pixels_base64(abuf *out, const uint8_t *b, size_t n);
/* A PNG of the picture in memory (libpng, RGB 8-bit); false on failure. */
bool pixels_png(abuf *out, const uint8_t *rgb, int w, int h);

/* --- what the terminal can do -------------------------------------------- */

typedef struct pixels_caps {
	bool kitty;           /* answered the kitty graphics query with OK */
	bool sixel;           /* DA1 lists attribute 4 */
	bool da1;             /* DA1 was answered: every question before it was */
	bool iterm;           /* TERM_PROGRAM / LC_TERMINAL name iTerm2 (or WezTerm) */
	bool tmux;            /* inside tmux (TMUX is set) */
	int sixel_w, sixel_h; /* XTSMGRAPHICS: the largest sixel image; 0 unknown */
	int cell_w, cell_h;   /* a cell in pixels (CSI 16 t or TIOCGWINSZ); 0 unknown */
	bool passthrough;     /* inside tmux: its pane lets escape sequences through
	                       * to the terminal outside (allow-passthrough on) */
	int pane_x, pane_y;   /* ... and the pane's top-left cell there */
	char version[64];     /* XTVERSION's answer ("XTerm(379)", "foot(1.16.2)",
	                       * "tmux 3.3a"); "" unknown */
} pixels_caps;

/* The questions, in the order to send them: the kitty query, XTSMGRAPHICS,
 * CSI 16 t, XTVERSION, then DA1, which every terminal answers and which therefore
 * comes last (when its answer is in, the others were answered or never
 * will be). */
void pixels_queries(abuf *out);
/* The same questions without DA1, for a caller that sends DA1 itself. */
void pixels_questions(abuf *out);
/* The length of the answer to one of the questions at the start of s
 * (kitty's, XTSMGRAPHICS, CSI 16 t, XTVERSION), recorded in c; 0 when s starts none
 * (a DA1 answer is recorded, sixel, but not taken: 0). */
size_t pixels_answer(pixels_caps *c, const char *s, size_t n);
/* Reads the answers in n bytes from the terminal into c, returning how
 * many bytes were answers (anything else, such as keys, the caller keeps:
 * the answers found are removed from buf, the rest moved together). */
size_t pixels_take_answers(pixels_caps *c, char *buf, size_t n);
/* What the environment tells: TERM_PROGRAM / LC_TERMINAL, TMUX. */
void pixels_caps_env(pixels_caps *c, const char *term_program, const char *lc_terminal,
                     const char *tmux);
/* Inside tmux (c->tmux): asks tmux (`tmux display-message`) whether the
 * pane lets escape sequences through to the terminal outside and where
 * the pane is there; fills passthrough, pane_x, pane_y. */
void pixels_tmux_query(pixels_caps *c);
/* The protocol for `auto`: kitty, then sixel, then iTerm2, else off (in
 * tmux: sixel only when tmux itself says it has it, else off). */
pixels_mode pixels_choose(const pixels_caps *c);

/* Asks the terminal on fd (a tty in raw mode; in_fd its input) and waits
 * at most timeout seconds for DA1's answer. Bytes read that are not
 * answers (keys typed meanwhile) are appended to keys. Never blocks
 * longer than the timeout. */
void pixels_probe(int in_fd, int out_fd, double timeout, pixels_caps *c, abuf *keys);

#endif
