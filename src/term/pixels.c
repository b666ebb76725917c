/* rtsh — real pixels: names, base64, PNG in memory, and the questions that
 * find out what the terminal shows (pixels.h). */
#include "term/pixels.h"

#include <errno.h>
#include <stdio.h>
#include <setjmp.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/select.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include <png.h>

#include "rtsh/settings.h"
#include "term/caps.h"

/* The names are the `pixels` setting's choices (settings.c): off, kitty,
 * sixel, iterm, auto, then any other pixel encoder's (encoder.c). */
static const setting_def *pixels_setting(void)
{
	rt_error err;
	return settings_find("pixels", &err);
}

const char *pixels_mode_name(pixels_mode m)
{
	const setting_def *d = pixels_setting();
	return d && (int)m >= 0 && (int)m < settings_choices(d) ? d->choices[m] : "off";
}

bool pixels_mode_parse(const char *s, pixels_mode *m)
{
	const setting_def *d = pixels_setting();
	for (int i = 0; d && i < settings_choices(d); i++)
		if (strcmp(s, d->choices[i]) == 0) {
			*m = (pixels_mode)i;
			return true;
		}
	return false;
}

/* --- base64 (RFC 4648, section 4) ---------------------------------------- */

void pixels_base64(abuf *out, const uint8_t *b, size_t n)
{
	static const char digits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
	size_t need = (n + 2) / 3 * 4;
	/* one growth, then plain stores */
	abuf_add(out, "", 0);
	size_t at = out->len;
	for (size_t k = 0; k < need; k++)
		abuf_char(out, '=');
	if (out->failed)
		return;
	char *o = out->b + at;
	size_t i = 0;
	for (; i + 3 <= n; i += 3, o += 4) {
		uint32_t v = (uint32_t)b[i] << 16 | (uint32_t)b[i + 1] << 8 | b[i + 2];
		o[0] = digits[v >> 18];
		o[1] = digits[(v >> 12) & 63];
		o[2] = digits[(v >> 6) & 63];
		o[3] = digits[v & 63];
	}
	if (i < n) {
		uint32_t v = (uint32_t)b[i] << 16 | (i + 1 < n ? (uint32_t)b[i + 1] << 8 : 0);
		o[0] = digits[v >> 18];
		o[1] = digits[(v >> 12) & 63];
		if (i + 1 < n)
			o[2] = digits[(v >> 6) & 63];
	}
}

/* --- PNG in memory --------------------------------------------------------- */

static void png_sink(png_structp png, png_bytep data, png_size_t n)
{
	abuf_add(png_get_io_ptr(png), (const char *)data, n);
}

static void png_flush_none(png_structp png)
{
	(void)png;
}

/* libpng must not print on the terminal the picture is drawn on: its
 * errors only end the encode (false), its warnings are dropped. */
static void png_error_silent(png_structp png, png_const_charp msg)
{
	(void)msg;
	png_longjmp(png, 1);
}

static void png_warning_silent(png_structp png, png_const_charp msg)
{
	(void)png;
	(void)msg;
}

bool pixels_png(abuf *out, const uint8_t *rgb, int w, int h)
{
	if (w < 1 || h < 1)
		return false;
	png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, png_error_silent, png_warning_silent);
	png_infop info = png ? png_create_info_struct(png) : NULL;
	if (!info) {
		png_destroy_write_struct(&png, NULL);
		return false;
	}
	size_t len0 = out->len;
	if (setjmp(png_jmpbuf(png))) {
		png_destroy_write_struct(&png, &info);
		out->len = len0;
		return false;
	}
	png_set_write_fn(png, out, png_sink, png_flush_none);
	/* Level 5 (as kitty's zlib) and the Paeth filter. */
	png_set_compression_level(png, 5);
	png_set_filter(png, 0, PNG_FILTER_PAETH);
	png_set_IHDR(png, info, (png_uint_32)w, (png_uint_32)h, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
	             PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
	png_write_info(png, info);
	for (int y = 0; y < h; y++)
		png_write_row(png, (png_const_bytep)(rgb + (size_t)y * (size_t)w * 3));
	png_write_end(png, NULL);
	png_destroy_write_struct(&png, &info);
	if (out->failed) {
		out->len = len0;
		return false;
	}
	return true;
}

/* --- questions and answers -------------------------------------------------- */

/* The id of the kitty query's 1x1 image (never shown: t=d, a=q). */
#define QUERY_ID 31

void pixels_questions(abuf *out)
{
	abuf_printf(out, "\x1b_Gi=%d,s=1,v=1,a=q,t=d,f=24;AAAA\x1b\\", QUERY_ID);
	abuf_str(out, "\x1b[?2;1;0S"); /* XTSMGRAPHICS: read the largest sixel geometry */
	abuf_str(out, "\x1b[16t");     /* the cell size in pixels */
	abuf_str(out, "\x1b[>q");      /* XTVERSION */
}

void pixels_queries(abuf *out)
{
	pixels_questions(out);
	abuf_str(out, "\x1b[c"); /* DA1, the fence */
}

/* Numeric parameters of a CSI sequence in p..end (digits and ';'). */
static int csi_params(const char *p, const char *end, long *v, int max)
{
	int n = 0;
	long cur = 0;
	bool any = false;
	for (; p < end; p++) {
		if (*p >= '0' && *p <= '9') {
			cur = cur * 10 + (*p - '0');
			if (cur > 1000000)
				cur = 1000000;
			any = true;
		} else if (*p == ';') {
			if (n < max)
				v[n++] = any ? cur : 0;
			cur = 0;
			any = false;
		}
	}
	if (n < max)
		v[n++] = any ? cur : 0;
	return n;
}

/* The length of the answer starting at s (s[0] == ESC), filling c, or 0
 * when s starts no complete answer. DA1 is recorded (sixel) but, unless
 * take_da1, not taken: the output scheduler waits for it too. */
static size_t one_answer(pixels_caps *c, const char *s, size_t n, bool take_da1)
{
	if (n >= 3 && s[1] == '_' && s[2] == 'G') {
		/* kitty: \e_G<keys>;<message>\e\\ */
		for (size_t i = 3; i + 1 < n; i++)
			if (s[i] == 0x1b && s[i + 1] == '\\') {
				char id[16];
				int k = snprintf(id, sizeof id, "i=%d;", QUERY_ID);
				for (size_t j = 3; j + (size_t)k + 2 <= i; j++)
					if (memcmp(s + j, id, (size_t)k) == 0 && memcmp(s + j + k, "OK", 2) == 0)
						c->kitty = true;
				return i + 2;
			}
		return 0;
	}
	if (n >= 3 && s[1] == 'P' && s[2] == '>') {
		/* XTVERSION: \eP>|<name and version>\e\\ */
		for (size_t i = 3; i + 1 < n; i++)
			if (s[i] == 0x1b && s[i + 1] == '\\') {
				if (s[3] == '|') {
					size_t k = 0;
					for (size_t j = 4; j < i && k + 1 < sizeof c->version; j++)
						if (s[j] >= 0x20 && s[j] < 0x7f)
							c->version[k++] = s[j];
					c->version[k] = '\0';
				}
				return i + 2;
			}
		return 0;
	}
	if (n < 3 || s[1] != '[')
		return 0;
	/* CSI: parameters, then a final byte in 0x40..0x7e */
	size_t i = 2;
	while (i < n && ((s[i] >= '0' && s[i] <= '9') || s[i] == ';' || s[i] == '?'))
		i++;
	if (i >= n)
		return 0;
	char fin = s[i];
	long v[32];
	bool priv = s[2] == '?';
	int k = csi_params(s + 2 + priv, s + i, v, 32);
	if (fin == 'c' && priv) { /* DA1: \e[?62;4;...c */
		c->da1 = true;
		for (int j = 1; j < k; j++)
			if (v[j] == 4)
				c->sixel = true;
		return take_da1 ? i + 1 : 0;
	}
	if (fin == 'S' && priv) { /* XTSMGRAPHICS: \e[?2;0;W;HS */
		if (k >= 4 && v[0] == 2 && v[1] == 0) {
			c->sixel_w = (int)v[2];
			c->sixel_h = (int)v[3];
		}
		return i + 1;
	}
	if (fin == 't' && !priv && k >= 3 && v[0] == 6) { /* \e[6;H;Wt */
		c->cell_h = (int)v[1];
		c->cell_w = (int)v[2];
		return i + 1;
	}
	return 0;
}

size_t pixels_answer(pixels_caps *c, const char *s, size_t n)
{
	return n > 0 && s[0] == 0x1b ? one_answer(c, s, n, false) : 0;
}

size_t pixels_take_answers(pixels_caps *c, char *buf, size_t n)
{
	size_t r = 0, w = 0, taken = 0;
	while (r < n) {
		size_t k = buf[r] == 0x1b ? one_answer(c, buf + r, n - r, true) : 0;
		if (k) {
			r += k;
			taken += k;
		} else {
			buf[w++] = buf[r++];
		}
	}
	return taken;
}

void pixels_caps_env(pixels_caps *c, const char *term_program, const char *lc_terminal, const char *tmux)
{
	c->iterm = (term_program && (strcmp(term_program, "iTerm.app") == 0 ||
	                             strcmp(term_program, "WezTerm") == 0)) ||
	           (lc_terminal && strcmp(lc_terminal, "iTerm2") == 0);
	c->tmux = tmux && *tmux;
}

void pixels_tmux_query(pixels_caps *c)
{
	c->passthrough = false;
	if (!c->tmux)
		return;
	/* The pane's own value (set on the pane, its window or globally);
	 * TMUX_PANE names this pane, not the one the client looks at. */
	FILE *p = popen("tmux display-message -p -t \"$TMUX_PANE\" "
	                "'#{allow-passthrough} #{pane_left} #{pane_top}' 2>/dev/null",
	                "r");
	if (!p)
		return;
	char line[128] = "", on[16] = "";
	int x = 0, y = 0;
	if (fgets(line, sizeof line, p) && sscanf(line, "%15s %d %d", on, &x, &y) == 3 &&
	    (strcmp(on, "1") == 0 || strcmp(on, "on") == 0 || strcmp(on, "all") == 0) && x >= 0 && y >= 0) {
		c->passthrough = true;
		c->pane_x = x;
		c->pane_y = y;
	}
	pclose(p);
}

void pixels_passthrough(abuf *out, const char *b, size_t n)
{
	abuf_str(out, "\x1bPtmux;");
	for (size_t i = 0; i < n; i++) {
		if (b[i] == 0x1b)
			abuf_char(out, 0x1b); /* every ESC doubled */
		abuf_char(out, b[i]);
	}
	abuf_str(out, "\x1b\\");
}

pixels_mode pixels_choose(const pixels_caps *c)
{
	if (c->tmux)
		/* tmux answers DA1 itself: attribute 4 when it draws sixel (3.4
		 * built with it); kitty and iTerm2 images would need passthrough,
		 * which tmux turns off by default and cannot place. */
		return c->sixel ? PIXELS_SIXEL : PIXELS_OFF;
	if (c->kitty)
		return PIXELS_KITTY;
	if (c->sixel)
		return PIXELS_SIXEL;
	if (c->iterm)
		return PIXELS_ITERM;
	return PIXELS_OFF;
}

static double mono(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)t.tv_sec + t.tv_nsec * 1e-9;
}

void pixels_probe(int in_fd, int out_fd, double timeout, pixels_caps *c, abuf *keys)
{
	struct winsize ws;
	if (ioctl(out_fd, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0 && ws.ws_row > 0 && ws.ws_xpixel > 0 &&
	    ws.ws_ypixel > 0) {
		c->cell_w = ws.ws_xpixel / ws.ws_col;
		c->cell_h = ws.ws_ypixel / ws.ws_row;
	}
	struct termios saved;
	bool restore = caps_raw_modes(in_fd, 0, TCSANOW, &saved);
	abuf q;
	abuf_init(&q);
	pixels_queries(&q);
	bool sent = !q.failed && write_all(out_fd, q.b, q.len);
	abuf_free(&q);
	char buf[1024];
	size_t have = 0;
	double end = mono() + timeout;
	while (sent && !c->da1) {
		double left = end - mono();
		if (left <= 0)
			break;
		fd_set set;
		FD_ZERO(&set);
		FD_SET(in_fd, &set);
		struct timeval tv = {(time_t)left, (suseconds_t)((left - (double)(time_t)left) * 1e6)};
		int r = select(in_fd + 1, &set, NULL, NULL, &tv);
		if (r < 0 && errno == EINTR)
			continue;
		if (r <= 0)
			break;
		ssize_t got = read(in_fd, buf + have, sizeof buf - have);
		if (got <= 0)
			break;
		have += (size_t)got;
		size_t before = have;
		have -= pixels_take_answers(c, buf, have);
		(void)before;
		/* what is left and starts no answer is keys; keep a partial
		 * escape sequence at the end for the next read */
		size_t keep = 0;
		for (size_t i = have; i-- > 0;)
			if (buf[i] == 0x1b) {
				keep = have - i;
				break;
			}
		if (keep == have && have == sizeof buf)
			keep = 0; /* a runaway sequence: give it up as keys */
		abuf_add(keys, buf, have - keep);
		memmove(buf, buf + have - keep, keep);
		have = keep;
	}
	abuf_add(keys, buf, have);
	if (restore)
		tcsetattr(in_fd, TCSANOW, &saved);
}
