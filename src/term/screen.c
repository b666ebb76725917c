/* rtsh — the full-screen layout (screen.h). */
#define _XOPEN_SOURCE 700 /* wcwidth */
#include "term/screen.h"

#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <wchar.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include "base/abuf.h"

#define ENTER_SEQ "\x1b[?1049h"
/* Every mode rtsh (or readline) may have set, back to the terminal's
 * default: synchronized output, scroll region, attributes, cursor shown,
 * bracketed paste, mouse reporting (1000 1002 1003 1006), cursor keys and
 * keypad in normal mode (DECCKM, DECKPNM), then the main screen. */
#define RESTORE_SEQ "\x1b[?2026l\x1b[r\x1b[m\x1b[?25h\x1b[?2004l\x1b[?1000l\x1b[?1002l\x1b[?1003l\x1b[?1006l" \
                    "\x1b[?1l\x1b>\x1b[?1049l"

/* What the signal-time restore needs, set by screen_enter and
 * screen_keypad (the handlers live in shell/signals.c). */
static volatile sig_atomic_t restore_fd = -1;
static volatile sig_atomic_t keypad_on;
/* kitty images were shown: they float over the text, so every way out and
 * every full clear deletes them. */
static volatile sig_atomic_t kitty_shown;
#define KITTY_DELETE_ALL "\x1b_Ga=d,d=A,q=2\x1b\\"
static char keypad_on_seq[64], keypad_off_seq[64];

static void put_raw(int fd, const char *s, size_t n)
{
	while (n > 0) {
		ssize_t w = write(fd, s, n);
		if (w < 0 && errno == EINTR)
			continue;
		if (w <= 0)
			return;
		s += w;
		n -= (size_t)w;
	}
}

void screen_restore_async(void)
{
	int fd = restore_fd;
	if (fd < 0)
		return;
	if (keypad_on && keypad_off_seq[0])
		put_raw(fd, keypad_off_seq, strlen(keypad_off_seq));
	if (kitty_shown)
		put_raw(fd, KITTY_DELETE_ALL, sizeof KITTY_DELETE_ALL - 1);
	put_raw(fd, RESTORE_SEQ, sizeof RESTORE_SEQ - 1);
}

void screen_reenter_async(void)
{
	int fd = restore_fd;
	if (fd < 0)
		return;
	put_raw(fd, ENTER_SEQ, sizeof ENTER_SEQ - 1);
	if (keypad_on && keypad_on_seq[0])
		put_raw(fd, keypad_on_seq, strlen(keypad_on_seq));
}

void screen_keypad(int fd, const char *on_seq, const char *off_seq, bool on)
{
	if (on) {
		snprintf(keypad_on_seq, sizeof keypad_on_seq, "%s", on_seq ? on_seq : "");
		snprintf(keypad_off_seq, sizeof keypad_off_seq, "%s", off_seq ? off_seq : "");
		put_raw(fd, keypad_on_seq, strlen(keypad_on_seq));
		keypad_on = 1;
	} else {
		keypad_on = 0;
		put_raw(fd, keypad_off_seq, strlen(keypad_off_seq));
	}
}

void screen_fit(int cols, int rows, double aspect, bool whole_cells, int *w, int *h)
{
	int cw = cols, ch = 2 * rows;
	if (!(aspect > 0) || !isfinite(aspect))
		aspect = 16.0 / 9.0;
	if ((double)cw / ch > aspect) {
		*h = ch;
		*w = (int)lround(ch * aspect);
	} else {
		*w = cw;
		*h = (int)lround(cw / aspect);
	}
	if (whole_cells)
		*h &= ~1;
	*w = *w < 1 ? 1 : *w > cw ? cw : *w;
	*h = *h < (whole_cells ? 2 : 1) ? (whole_cells ? 2 : 1) : *h > ch ? ch : *h;
}

static void query_size(screen *s)
{
	struct winsize ws;
	if (ioctl(s->fd, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0 && ws.ws_row > 0) {
		s->cols = ws.ws_col;
		s->rows = ws.ws_row;
		if (ws.ws_xpixel > 0 && ws.ws_ypixel > 0) {
			s->cell_w = ws.ws_xpixel / ws.ws_col;
			s->cell_h = ws.ws_ypixel / ws.ws_row;
		}
	} else {
		s->cols = 80;
		s->rows = 24;
	}
}

/* Picture rows, status row and scroll region for the current size. */
static void compute_layout(screen *s)
{
	int region = s->rows / 5;
	region = region < 3 ? 3 : region > 10 ? 10 : region;
	int avail = s->rows - 1 - region;
	if (avail < 3 || s->cols < 8) {
		s->pic_rows = 0;
		s->status_row = s->rows >= 3 ? 0 : -1;
		s->region_top = s->status_row + 1;
		s->img_w = s->img_h = 0;
		return;
	}
	/* Rows the picture needs at full width; the rest goes to the region. */
	int need = (int)ceil(s->cols / s->aspect / 2.0);
	s->pic_rows = need < avail ? need : avail;
	s->status_row = s->pic_rows;
	s->region_top = s->pic_rows + 1;
	if (s->pix_ops) {
		/* Real pixels: the picture area at the terminal's pixel size. */
		int cw = s->cols * s->cell_w, ch = s->pic_rows * s->cell_h;
		s->img_w = cw;
		s->img_h = (int)lround(cw / s->aspect);
		if (s->img_h > ch) {
			s->img_h = ch;
			s->img_w = (int)lround(ch * s->aspect);
		}
		s->img_w = s->img_w < 1 ? 1 : s->img_w > cw ? cw : s->img_w;
		s->img_h = s->img_h < 1 ? 1 : s->img_h;
		s->img_x = (cw - s->img_w) / 2;
		s->img_y = (ch - s->img_h) / 2;
		return;
	}
	screen_fit(s->cols, s->pic_rows, s->aspect, s->pal == PALETTE_NONE, &s->img_w, &s->img_h);
	s->img_x = (s->cols - s->img_w) / 2;
	s->img_y = (2 * s->pic_rows - s->img_h) / 2;
	if (s->pal == PALETTE_NONE)
		s->img_y &= ~1;
	else if (s->sym != SYMBOLS_HALF) {
		/* 2x4 samples a cell: the half blocks' canvas, twice as fine */
		s->img_w *= 2;
		s->img_h *= 2;
		s->img_x *= 2;
		s->img_y *= 2;
	}
}

static void put(screen *s, const abuf *a)
{
	if (a->failed)
		return;
	if (s->out)
		termout_text(s->out, a->b, a->len);
	else
		write_all(s->fd, a->b, a->len);
}

static bool tmux_passthrough(screen *s);

/* A new picture encoder for the layout (none when there is no room). */
static void open_encoder(screen *s)
{
	if (kitty_shown && s->enc) {
		/* The old layout's images go with it (kitty's float over text). */
		abuf a;
		abuf_init(&a);
		abuf_str(&a, KITTY_DELETE_ALL);
		put(s, &a);
		abuf_free(&a);
	}
	encoder_close(s->enc);
	s->enc = NULL;
	if (s->pic_rows > 0) {
		encoder_geom g = {.cols = s->cols, .rows = s->pic_rows, .pal = s->pal,
		                  .cell_w = s->cell_w, .cell_h = s->cell_h};
		const pixels_caps *caps = s->out ? termout_pixels(s->out) : NULL;
		if (caps && s->pix_ops == &encoder_sixel) { /* XTSMGRAPHICS' answer */
			g.max_w = caps->sixel_w;
			g.max_h = caps->sixel_h;
		}
		/* Inside tmux, images that tmux does not draw itself (all but its
		 * own sixel) go through its passthrough, placed at the pane's
		 * place outside (asked again: a split or a resize moves it). */
		if (s->pix_ops && s->tmux_pass > 0) {
			s->tmux_pass = 0;
			tmux_passthrough(s);
		}
		if (s->pix_ops && s->tmux_pass > 0 && !(s->pix_ops == &encoder_sixel && caps && caps->sixel)) {
			g.passthrough = true;
			g.pass_x = s->pass_x;
			g.pass_y = s->pass_y;
		}
		if (s->pix_ops)
			s->enc = s->pix_ops->open(&g);
		if (s->pix_ops == &encoder_kitty)
			kitty_shown = 1;
		if (!s->enc)
			s->enc = encoder_symbols(s->pix_ops ? SYMBOLS_HALF : s->sym)->open(&g);
	}
	if (s->out)
		termout_set_picture(s->out, s->enc);
}

static void draw_status(screen *s, abuf *a)
{
	if (s->status_row < 0)
		return;
	abuf_printf(a, "\x1b" "7\x1b[%dH\x1b[7m", s->status_row + 1);
	screen_fit_text(a, s->status, s->cols);
	abuf_str(a, "\x1b[m\x1b" "8");
}

void screen_fit_text(abuf *a, const char *text, int cols)
{
	/* Columns by wcwidth (a CJK character or an emoji takes two, a
	 * combining mark none), in the locale's encoding; a byte that is not a
	 * character there counts one column. */
	int width = 0;
	const char *p = text;
	size_t left = strlen(text);
	mbstate_t st;
	memset(&st, 0, sizeof st);
	while (left > 0) {
		wchar_t wc;
		size_t n = mbrtowc(&wc, p, left, &st);
		int w = 1;
		if (n == (size_t)-1 || n == (size_t)-2 || n == 0) {
			n = 1;
			memset(&st, 0, sizeof st);
		} else {
			w = wcwidth(wc);
			if (w < 0)
				w = 1;
		}
		if (width + w > cols)
			break;
		abuf_add(a, p, n);
		p += n;
		left -= n;
		width += w;
	}
	for (; width < cols; width++)
		abuf_char(a, ' ');
}

/* The command area's text kept for a new layout: at most LOG_KEEP bytes,
 * trimmed at a line's start. */
#define LOG_KEEP 8192

void screen_log(screen *s, const char *text, size_t n)
{
	abuf_add(&s->log, text, n);
	if (s->log.failed) {
		abuf_free(&s->log);
		abuf_init(&s->log);
		return;
	}
	if (s->log.len <= LOG_KEEP)
		return;
	size_t cut = s->log.len - LOG_KEEP;
	const char *nl = memchr(s->log.b + cut, '\n', s->log.len - cut);
	cut = nl ? (size_t)(nl + 1 - s->log.b) : s->log.len;
	memmove(s->log.b, s->log.b + cut, s->log.len - cut);
	s->log.len -= cut;
}

void screen_log_clear(screen *s)
{
	abuf_reset(&s->log);
}

/* The last lines of the command area's text, each ended by "\r\n" from
 * the region's bottom row: the region scrolls them up into place and the
 * cursor ends on the bottom row, where the prompt goes. A line wider than
 * the screen wraps and pushes the oldest ones out. */
static void replay_log(screen *s, abuf *a)
{
	int room = s->rows - s->region_top - 1;
	if (room <= 0 || s->log.len == 0)
		return;
	const char *b = s->log.b;
	size_t end = s->log.len;
	if (b[end - 1] == '\n')
		end--; /* the last line's end */
	size_t start = end;
	for (int lines = 0; start > 0; start--) {
		if (b[start - 1] == '\n' && ++lines == room)
			break;
	}
	for (size_t i = start; i < end; i++) {
		if (b[i] == '\n')
			abuf_str(a, "\r\n");
		else if (b[i] != '\r')
			abuf_char(a, b[i]);
	}
	abuf_str(a, "\r\n");
}

/* Clears the screen, sets the scroll region, draws the status line and puts
 * the cursor on the last row, under the command area's last lines. */
static void redraw_chrome(screen *s)
{
	abuf a;
	abuf_init(&a);
	abuf_str(&a, "\x1b[r\x1b[m\x1b[2J");
	if (s->region_top < s->rows)
		abuf_printf(&a, "\x1b[%d;%dr", s->region_top + 1, s->rows);
	abuf_printf(&a, "\x1b[%dH", s->rows);
	draw_status(s, &a);
	if (s->region_top < s->rows)
		replay_log(s, &a);
	put(s, &a);
	abuf_free(&a);
	if (s->enc)
		s->enc->ops->invalidate(s->enc);
	if (s->out)
		termout_set_picture(s->out, s->enc); /* back after screen_clear_all */
}

bool screen_layout(screen *s, double aspect, bool force)
{
	int oc = s->cols, orow = s->rows, opic = s->pic_rows, ow = s->img_w, oh = s->img_h;
	double oa = s->aspect;
	query_size(s);
	s->aspect = aspect > 0 && isfinite(aspect) ? aspect : 16.0 / 9.0;
	compute_layout(s);
	bool changed = oc != s->cols || orow != s->rows || opic != s->pic_rows;
	if (!changed && !force && s->enc && oa != s->aspect) {
		/* Only the image's shape changed: the next frame update erases
		 * the old picture; the prompt's lines stay. */
		s->enc->ops->clear(s->enc);
	} else if (changed || force || !s->enc) {
		if (!s->enc || s->enc->geom.cols != s->cols || s->enc->geom.rows != s->pic_rows ||
		    (!s->pix_ops && s->enc->ops != encoder_symbols(s->sym)) ||
		    s->enc->geom.pal != s->pal || s->enc->geom.cell_w != s->cell_w ||
		    s->enc->geom.cell_h != s->cell_h)
			open_encoder(s);
		if (s->enc)
			s->enc->ops->clear(s->enc);
		redraw_chrome(s);
	}
	return ow != s->img_w || oh != s->img_h;
}

bool screen_enter(screen *s, int fd, frame_palette pal, double aspect)
{
	memset(s, 0, sizeof *s);
	s->fd = fd;
	s->pal = pal;
	if (!isatty(fd))
		return false;
	s->out = termout_new(fd);
	if (!s->out)
		return false;
	restore_fd = fd;
	write_all(fd, ENTER_SEQ, sizeof ENTER_SEQ - 1);
	s->active = true;
	screen_layout(s, aspect, true);
	return true;
}

void screen_resume(screen *s)
{
	if (!s->active)
		return;
	screen_layout(s, s->aspect, true);
}

void screen_leave(screen *s)
{
	if (!s->active)
		return;
	screen_restore_async();
	restore_fd = -1;
	s->active = false;
	encoder_close(s->enc);
	s->enc = NULL;
	termout_free(s->out);
	s->out = NULL;
	abuf_free(&s->log);
}

void screen_drop_images(screen *s)
{
	if (!kitty_shown)
		return;
	if (s->out)
		termout_text(s->out, KITTY_DELETE_ALL, sizeof KITTY_DELETE_ALL - 1);
	else
		write_all(s->fd, KITTY_DELETE_ALL, sizeof KITTY_DELETE_ALL - 1);
	if (s->enc)
		s->enc->ops->invalidate(s->enc);
}

void screen_clear_all(screen *s)
{
	static const char seq[] = "\x1b[r\x1b[2J";
	screen_drop_images(s);
	if (s->out) {
		/* No picture goes out until screen_layout gives the screen back. */
		termout_set_picture(s->out, NULL);
		termout_text(s->out, seq, sizeof seq - 1);
	} else {
		write_all(s->fd, seq, sizeof seq - 1);
	}
}

void screen_clear_commands(screen *s)
{
	if (!s->active)
		return;
	abuf a;
	abuf_init(&a);
	for (int r = s->region_top; r < s->rows; r++)
		abuf_printf(&a, "\x1b[%dH\x1b[K", r + 1);
	put(s, &a);
	abuf_free(&a);
}

void screen_set_palette(screen *s, frame_palette pal)
{
	if (pal == s->pal)
		return;
	s->pal = pal;
	if (s->active)
		screen_layout(s, s->aspect, true);
}

/* Inside tmux: whether the pane lets images through (asked once). */
static bool tmux_passthrough(screen *s)
{
	if (s->tmux_pass == 0) {
		pixels_caps pc = {.tmux = true};
		pixels_tmux_query(&pc);
		s->tmux_pass = pc.passthrough ? 1 : -1;
		s->pass_x = pc.pane_x;
		s->pass_y = pc.pane_y;
	}
	return s->tmux_pass > 0;
}

bool screen_set_pixels(screen *s, int mode)
{
	s->pixels = mode;
	const pixels_caps *c = s->out ? termout_pixels(s->out) : NULL;
	if (mode == PIXELS_AUTO) {
		/* What the terminal answered, and what the environment says
		 * (iTerm2 has no query of its own). */
		pixels_caps all = {0};
		if (c)
			all = *c;
		pixels_caps_env(&all, getenv("TERM_PROGRAM"), getenv("LC_TERMINAL"), getenv("TMUX"));
		mode = pixels_choose(&all);
		/* tmux with passthrough inside kitty (the server started there
		 * keeps KITTY_WINDOW_ID): kitty's images through tmux. */
		const char *kw = getenv("KITTY_WINDOW_ID");
		if (mode == PIXELS_OFF && all.tmux && kw && *kw && tmux_passthrough(s))
			mode = PIXELS_KITTY;
	}
	/* libsixel is opened here, on first use (enc_sixel.c) */
	s->sixel_missing = mode == PIXELS_SIXEL && !pixels_sixel_available(NULL, 0);
	if (s->sixel_missing)
		mode = PIXELS_OFF;
	const char *tm = getenv("TMUX");
	bool in_tmux = tm && *tm;
	if (in_tmux && mode != PIXELS_OFF && !(mode == PIXELS_SIXEL && c && c->sixel) && !tmux_passthrough(s))
		mode = PIXELS_OFF; /* tmux would drop the images: a blank picture */
	bool cell = false;
	if (in_tmux && mode != PIXELS_OFF && c && c->cell_w > 0 && s->cell_w > 0 &&
	    (abs(c->cell_w - s->cell_w) > 1 || abs(c->cell_h - s->cell_h) > 1))
		/* The cell size tmux's pane has (TIOCGWINSZ) is not the one the
		 * terminal answered (CSI 16 t): the images would not cover
		 * their cells. */
		mode = PIXELS_OFF;
	if (c && c->cell_w > 0 && c->cell_h > 0 && (c->cell_w != s->cell_w || c->cell_h != s->cell_h)) {
		s->cell_w = c->cell_w;
		s->cell_h = c->cell_h;
		cell = true;
	}
	const encoder_ops *ops = encoder_pixels((pixels_mode)mode); /* by name, encoder.c's table */
	if (s->cell_w <= 0 || s->cell_h <= 0)
		ops = NULL;
	if (ops == s->pix_ops && !(ops && cell))
		return false;
	s->pix_ops = ops;
	if (s->active) {
		if (kitty_shown)
			screen_clear_all(s);
		encoder_close(s->enc);
		s->enc = NULL;
		screen_layout(s, s->aspect, true);
	}
	return true;
}

bool screen_set_symbols(screen *s, int kind)
{
	s->symbols = kind;
	symbols_kind k = kind >= SYMBOLS_HALF && kind <= SYMBOLS_AUTO ? (symbols_kind)kind : SYMBOLS_AUTO;
	if (k == SYMBOLS_AUTO) {
		const pixels_caps *c = s->out ? termout_pixels(s->out) : NULL;
		k = symbols_choose(getenv("TERM_PROGRAM"), c && c->version[0] ? c->version : NULL,
		                   getenv("VTE_VERSION"), getenv("TMUX") && *getenv("TMUX"));
	}
	if (k == s->sym)
		return false;
	s->sym = k;
	if (s->active && !s->pix_ops) {
		encoder_close(s->enc);
		s->enc = NULL;
		screen_layout(s, s->aspect, true);
	}
	return true;
}

void screen_status(screen *s, const char *text)
{
	snprintf(s->status, sizeof s->status, "%s", text);
	if (!s->active)
		return;
	abuf a;
	abuf_init(&a);
	draw_status(s, &a);
	put(s, &a);
	abuf_free(&a);
}

void screen_picture(screen *s, const uint8_t *rgb, int w, int h)
{
	if (!s->active || !s->enc || w != s->img_w || h != s->img_h)
		return;
	encoder_put(s->enc, rgb, w, h, s->img_x, s->img_y);
	if (s->out)
		termout_picture_new(s->out);
}
