/* rtsh — the key view (keyview.h). */
#include "term/keyview.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "term/screen.h"

void keyview_init(keyview *v, termout *out, frame_palette pal, const keyview_item *bar, size_t nbar)
{
	memset(v, 0, sizeof *v);
	v->out = out;
	v->pal = pal;
	v->bar = bar;
	v->nbar = nbar;
	abuf_init(&v->a);
}

void keyview_free(keyview *v)
{
	termout_set_picture(v->out, NULL);
	encoder_close(v->enc);
	v->enc = NULL;
	abuf_free(&v->a);
}

/* Code points in s (the bars hold single-width characters only). */
static int text_width(const char *s)
{
	int n = 0;
	for (; *s; s++)
		n += ((unsigned char)*s & 0xc0) != 0x80;
	return n;
}

/* The rows the help bar takes: one, or two where one would cut items off
 * and the screen has room (40x16 or more). */
static int bar_rows(const keyview *v, int cols, int rows)
{
	int used = 0;
	for (size_t i = 0; i < v->nbar; i++)
		used += 2 + text_width(v->bar[i].keys) + 1 + text_width(v->bar[i].what);
	return used <= cols - 1 || cols < 40 || rows < 16 ? 1 : 2;
}

void keyview_layout(keyview *v, int cols, int rows, bool help, double aspect)
{
	v->cols = cols;
	v->rows = rows;
	v->help = help;
	v->help_rows = help ? bar_rows(v, cols, rows) : 0;
	v->pic_rows = rows - 1 - v->help_rows;
	termout_set_picture(v->out, NULL);
	encoder_close(v->enc);
	v->enc = NULL;
	v->img_w = v->img_h = 0;
	if (v->pic_rows < 2 || cols < 8) {
		v->pic_rows = 0;
	} else {
		bool whole = v->pal == PALETTE_NONE;
		encoder_geom g = {.cols = cols, .rows = v->pic_rows, .pal = v->pal, .cursor_off = true,
		                  .cell_w = v->cell_w, .cell_h = v->cell_h, .max_w = v->max_w, .max_h = v->max_h};
		const encoder_ops *ops = v->ops && !whole ? v->ops : &encoder_halfblock;
		v->enc = ops->open(&g);
		if (!v->enc && ops != &encoder_halfblock) {
			ops = &encoder_halfblock;
			v->enc = ops->open(&g);
		}
		if (ops == &encoder_halfblock) {
			screen_fit(cols, v->pic_rows, aspect, whole, &v->img_w, &v->img_h);
			v->img_x = (cols - v->img_w) / 2;
			v->img_y = (2 * v->pic_rows - v->img_h) / 2;
			if (whole)
				v->img_y &= ~1;
		} else {
			/* Square pixels on the encoder's canvas (2x4 samples a cell,
			 * or the terminal's pixels), the aspect fitted inside. */
			int cw, ch;
			ops->canvas(&g, &cw, &ch);
			if (!(aspect > 0) || !isfinite(aspect))
				aspect = 16.0 / 9.0;
			v->img_w = cw;
			v->img_h = (int)lround(cw / aspect);
			if (v->img_h > ch) {
				v->img_h = ch;
				v->img_w = (int)lround(ch * aspect);
			}
			v->img_w = v->img_w < 1 ? 1 : v->img_w > cw ? cw : v->img_w;
			v->img_h = v->img_h < 1 ? 1 : v->img_h;
			v->img_x = (cw - v->img_w) / 2;
			v->img_y = (ch - v->img_h) / 2;
		}
		if (!v->enc)
			v->img_w = v->img_h = 0;
		termout_set_picture(v->out, v->enc);
	}
	keyview_repaint(v);
}

void keyview_set_encoder(keyview *v, const encoder_ops *ops, int cell_w, int cell_h, int max_w, int max_h)
{
	v->ops = ops;
	v->cell_w = cell_w;
	v->cell_h = cell_h;
	v->max_w = max_w;
	v->max_h = max_h;
}

void keyview_repaint(keyview *v)
{
	v->repaint = true;
	v->status_shown[0] = '\0';
}

void keyview_picture(keyview *v, const uint8_t *rgb, bool final)
{
	if (!v->enc)
		return;
	encoder_put(v->enc, rgb, v->img_w, v->img_h, v->img_x, v->img_y);
	termout_picture_new(v->out);
	termout_picture_final(v->out, final);
}

bool keyview_status_differs(const keyview *v, const char *text)
{
	return strcmp(text, v->status_shown) != 0;
}

/* Appends a line of text at row (0-based), cut to the width. */
static void put_line(abuf *a, int row, int cols, const char *text, bool reverse)
{
	abuf_printf(a, "\x1b[%dH%s", row + 1, reverse ? "\x1b[7m" : "");
	int width = 0, max = reverse ? cols : cols - 1; /* never the last cell of the last row */
	const char *p = text;
	for (; *p && width < max; p++) {
		abuf_char(a, *p);
		if (((unsigned char)p[1] & 0xc0) != 0x80)
			width++;
	}
	while (((unsigned char)*p & 0xc0) == 0x80)
		abuf_char(a, *p++);
	if (reverse)
		for (; width < cols; width++)
			abuf_char(a, ' ');
	abuf_str(a, "\x1b[m");
	if (!reverse)
		abuf_str(a, "\x1b[K");
}

/* The help bar from `row` on, over help_rows rows, its items in order;
 * what does not fit on the last row is left out. */
static void put_help(const keyview *v, abuf *a, int row)
{
	size_t i = 0;
	for (int r = 0; r < v->help_rows; r++) {
		abuf_printf(a, "\x1b[%dH", row + r + 1);
		bool last = r == v->help_rows - 1;
		int used = 0;
		for (; i < v->nbar; i++) {
			int w = 2 + text_width(v->bar[i].keys) + 1 + text_width(v->bar[i].what);
			if (used + w > v->cols - (last ? 1 : 0)) /* never the last cell of the last row */
				break;
			abuf_printf(a, "  \x1b[1m%s\x1b[22m %s", v->bar[i].keys, v->bar[i].what);
			used += w;
		}
		abuf_str(a, "\x1b[K");
	}
}

void keyview_draw(keyview *v, const char *status)
{
	abuf *a = &v->a;
	abuf_reset(a);
	abuf_str(a, "\x1b[?2026h");
	if (v->repaint) {
		abuf_str(a, "\x1b[r\x1b[m\x1b[2J\x1b[?25l");
		if (v->ops == &encoder_kitty)
			abuf_str(a, "\x1b_Ga=d,d=A,q=2\x1b\\"); /* kitty's images float over the text */
		if (v->enc)
			v->enc->ops->invalidate(v->enc);
		v->status_shown[0] = '\0';
		if (v->help)
			put_help(v, a, v->rows - v->help_rows);
		v->repaint = false;
	}
	if (keyview_status_differs(v, status) && v->rows >= 1) {
		put_line(a, v->pic_rows, v->cols, status, true);
		snprintf(v->status_shown, sizeof v->status_shown, "%s", status);
	}
	abuf_str(a, "\x1b[?25l\x1b[?2026l");
	if (!a->failed)
		termout_text(v->out, a->b, a->len);
}

void keyview_fit_status(char *buf, size_t size, const char *const *fields, const int *drop, size_t n, int cols)
{
	bool out[32] = {false};
	if (n > 32)
		n = 32;
	for (;;) {
		size_t len = 0;
		buf[0] = '\0';
		for (size_t i = 0; i < n; i++) {
			if (out[i] || !fields[i][0])
				continue;
			int k = snprintf(buf + len, size - len, "%s%s", len ? " │ " : " ", fields[i]);
			if (k < 0 || (size_t)k >= size - len)
				break;
			len += (size_t)k;
		}
		if (text_width(buf) <= cols)
			return;
		size_t worst = n;
		for (size_t i = 0; i < n; i++)
			if (!out[i] && fields[i][0] && drop[i] > 0 && (worst == n || drop[i] < drop[worst]))
				worst = i;
		if (worst == n)
			return;
		out[worst] = true;
	}
}

void keyview_end(keyview *v)
{
	termout_text(v->out, "\x1b[m\x1b[?25h", 9);
}
