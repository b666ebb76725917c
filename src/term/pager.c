/* rtsh — the pager (pager.h). */
#include "term/pager.h"

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include "base/abuf.h"
#include "term/caps.h"
#include "term/out.h"

/* Seconds the rest of an escape sequence may take over a slow link. */
#define PAGER_ESC_WAIT 0.3

/* One display row: a slice of the text. */
typedef struct slice {
	const char *p;
	size_t n;
	int indent; /* blanks before it: a wrapped line's hanging indent */
} slice;

/* Length of the escape sequence at p (CSI ... final byte), or 0. */
static size_t escape_len(const char *p, const char *end)
{
	if (p + 1 >= end || p[0] != '\x1b' || p[1] != '[')
		return 0;
	const char *q = p + 2;
	while (q < end && !(*q >= 0x40 && *q <= 0x7e))
		q++;
	return q < end ? (size_t)(q - p) + 1 : (size_t)(end - p);
}

/* The hanging indent of the line at p: the column where its last column
 * of text starts (after a run of two blanks: a table's description), else
 * its own leading blanks; 0 when that leaves fewer than 20 columns. */
static int hang_of(const char *p, const char *end, int cols)
{
	int width = 0, lead = 0, hang = 0, blanks = 0;
	bool text = false;
	for (; p < end && *p != '\n'; p++) {
		size_t e = escape_len(p, end);
		if (e) {
			p += e - 1;
			continue;
		}
		if (((unsigned char)*p & 0xc0) == 0x80)
			continue;
		if (*p == ' ') {
			blanks++;
			lead += !text;
		} else {
			if (text && blanks >= 2)
				hang = width;
			text = true;
			blanks = 0;
		}
		width++;
	}
	if (!hang)
		hang = lead;
	return hang <= cols - 20 ? hang : 0;
}

/* Splits text into display rows of at most cols columns, a long line
 * broken after the last blank that fits (a word wider than the row is cut
 * at the width), its further rows indented by hang_of; returns the count
 * and, when out is not NULL, fills it. */
static int split(const char *text, size_t len, int cols, slice *out)
{
	int n = 0;
	const char *p = text, *end = text + len;
	if (cols < 1)
		cols = 1;
	bool more = false; /* the row goes on the line of the row before */
	int hang = 0;
	while (p < end) {
		const char *start = p, *blank = NULL;
		if (!more)
			hang = hang_of(p, end, cols);
		int indent = more ? hang : 0, width = indent;
		while (p < end && *p != '\n') {
			size_t e = escape_len(p, end);
			if (e) {
				p += e;
				continue;
			}
			bool lead = ((unsigned char)*p & 0xc0) != 0x80;
			if (lead && width == cols) {
				if (*p != ' ' && blank) /* the word goes to the next row */
					p = blank;
				break;
			}
			if (*p == ' ' && width > 0)
				blank = p;
			width += lead;
			p++;
		}
		if (out)
			out[n] = (slice){start, (size_t)(p - start), indent};
		n++;
		more = p < end && *p != '\n';
		if (p < end && *p == '\n')
			p++;
		else if (p < end && *p == ' ')
			p++; /* the blank the row broke at */
	}
	return n;
}

char *pager_wrap(const char *text, size_t len, int cols, size_t *out_len)
{
	int rows = split(text, len, cols, NULL);
	slice *sl = malloc((size_t)(rows ? rows : 1) * sizeof *sl);
	abuf a;
	abuf_init(&a);
	if (!sl)
		return NULL;
	split(text, len, cols, sl);
	for (int i = 0; i < rows; i++) {
		for (int k = 0; k < sl[i].indent; k++)
			abuf_char(&a, ' ');
		abuf_add(&a, sl[i].p, sl[i].n);
		abuf_char(&a, '\n');
	}
	free(sl);
	/* a text that did not end its last line: nor does the wrapped one */
	if (rows && len && text[len - 1] != '\n' && a.len)
		a.len--;
	if (a.failed) {
		abuf_free(&a);
		return NULL;
	}
	abuf_char(&a, '\0');
	if (a.failed) {
		abuf_free(&a);
		return NULL;
	}
	*out_len = a.len - 1;
	return a.b;
}

int pager_split(const char *text, size_t len, int cols, size_t *off, size_t *n, int max)
{
	int rows = split(text, len, cols, NULL);
	slice *sl = malloc((size_t)(rows ? rows : 1) * sizeof *sl);
	if (!sl)
		return -1;
	split(text, len, cols, sl);
	for (int i = 0; i < rows && i < max; i++) {
		off[i] = (size_t)(sl[i].p - text);
		n[i] = sl[i].n;
	}
	free(sl);
	return rows;
}

int pager_rows(const char *text, size_t len, int cols)
{
	return split(text, len, cols, NULL);
}

static void draw(evloop *l, int fd, const slice *rows, int nrows, int top, int page, int cols)
{
	abuf a;
	abuf_init(&a);
	abuf_str(&a, "\x1b[?25l\x1b[m");
	for (int r = 0; r < page; r++) {
		abuf_printf(&a, "\x1b[%d;1H\x1b[m\x1b[K", r + 1);
		if (top + r < nrows) {
			for (int k = 0; k < rows[top + r].indent; k++)
				abuf_char(&a, ' ');
			abuf_add(&a, rows[top + r].p, rows[top + r].n);
		}
	}
	int last = top + page < nrows ? top + page : nrows;
	char keys[160];
	snprintf(keys, sizeof keys, " lines %d-%d of %d%s  Space next page  b back  Up/Down a line  q quit  "
	         "typing starts a command ",
	         top + 1, last, nrows, last == nrows ? " (end)" : "");
	abuf_printf(&a, "\x1b[%d;1H\x1b[m\x1b[7m", page + 1);
	int w = 0;
	for (const char *k = keys; *k && w < cols; k++, w++)
		abuf_char(&a, *k);
	for (; w < cols; w++)
		abuf_char(&a, ' ');
	abuf_str(&a, "\x1b[m");
	if (!a.failed) {
		if (evloop_out(l))
			termout_text(evloop_out(l), a.b, a.len);
		else
			write_all(fd, a.b, a.len);
	}
	abuf_free(&a);
}

/* Whether key k (evloop_key's) is typed text rather than a key of the
 * pager: a printable character that is not Space or q, nor, while the
 * text is longer than a page (`fits` false), one of the moving letters
 * f b j k g G. */
static bool starts_command(const char *k, bool fits)
{
	unsigned char c = (unsigned char)k[0];
	if (c < 0x20 || c == 0x7f || c == ' ' || c == 'q' || c == 'Q')
		return false;
	if (c >= 0x80)
		return c >= 0xc0; /* a UTF-8 character's first byte */
	return fits || !strchr("fbjkgG", c);
}

bool pager_show(evloop *l, int fd_out, const char *text, size_t len, int cols, int rows, size_t *at)
{
	bool left = true;
	int fd_in = evloop_in_fd(l);
	struct termios saved;
	bool have_tty = caps_raw_modes(fd_in, 1, TCSADRAIN, &saved);
	int nrows = split(text, len, cols, NULL);
	slice *sl = malloc((size_t)(nrows ? nrows : 1) * sizeof *sl);
	if (sl) {
		split(text, len, cols, sl);
		int page = rows > 1 ? rows - 1 : 1;
		int top = 0;
		/* the row that holds offset *at */
		while (top + 1 < nrows && (size_t)(sl[top + 1].p - text) <= *at)
			top++;
		for (;;) {
			int max_top = nrows > page ? nrows - page : 0;
			top = top < 0 ? 0 : top > max_top ? max_top : top;
			if (nrows)
				*at = (size_t)(sl[top].p - text);
			draw(l, fd_out, sl, nrows, top, page, cols);
			char k[16];
			size_t kn = evloop_key(l, k, sizeof k, PAGER_ESC_WAIT);
			if (!kn) {
				left = evloop_eof(l);
				break;
			}
			bool fits = nrows <= page;
			if (starts_command(k, fits)) {
				/* The user began the next command: it is kept whole. */
				evloop_unread(l, kn);
				break;
			}
			if (fits && (strcmp(k, "\r") == 0 || strcmp(k, "\n") == 0))
				break;
			if (strcmp(k, " ") == 0 || strcmp(k, "f") == 0 || strcmp(k, "\x1b[6~") == 0) {
				if (top >= max_top && k[0] == ' ')
					break;
				top += page;
			} else if (strcmp(k, "b") == 0 || strcmp(k, "\x1b[5~") == 0) {
				top -= page;
			} else if (strcmp(k, "\r") == 0 || strcmp(k, "\n") == 0 || strcmp(k, "j") == 0 ||
			           strcmp(k, "\x1b[B") == 0 || strcmp(k, "\x1bOB") == 0) {
				top++;
			} else if (strcmp(k, "k") == 0 || strcmp(k, "\x1b[A") == 0 || strcmp(k, "\x1bOA") == 0) {
				top--;
			} else if (strcmp(k, "g") == 0 || strcmp(k, "\x1b[H") == 0 || strcmp(k, "\x1b[1~") == 0) {
				top = 0;
			} else if (strcmp(k, "G") == 0 || strcmp(k, "\x1b[F") == 0 || strcmp(k, "\x1b[4~") == 0) {
				top = max_top;
			} else if (strcmp(k, "q") == 0 || strcmp(k, "Q") == 0 || strcmp(k, "\x1b") == 0 ||
			           k[0] == 3 /* Ctrl-C when ISIG is off */) {
				break;
			}
		}
		free(sl);
	}
	if (have_tty)
		tcsetattr(fd_in, TCSADRAIN, &saved);
	if (evloop_out(l))
		termout_text(evloop_out(l), "\x1b[?25h", 6);
	else
		write_all(fd_out, "\x1b[?25h", 6);
	return left;
}
