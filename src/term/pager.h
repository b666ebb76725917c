/* rtsh — a small pager for command output longer than the shell's command
 * area (help, list of a large scene): the text fills the screen a page at a
 * time, as `more` shows it.
 *
 * Escape sequences sent: \e[H (home), \e[R;CH (move), \e[K (clear to end of
 * line), \e[2J (clear), \e[7m / \e[m (reverse video for the key line).
 */
#ifndef RTSH_PAGER_H
#define RTSH_PAGER_H

#include <stdbool.h>
#include <stddef.h>

#include "term/evloop.h"

/* The rows text takes on a terminal `cols` wide, long lines wrapped at word
 * boundaries (escape
 * sequences take no room; a code point takes one column). */
int pager_rows(const char *text, size_t len, int cols);
/* The same rows: row i is text[off[i] .. off[i] + n[i]) for the first max
 * of them. A long line breaks after its last blank that fits, a word wider
 * than the row at the width. Returns the count, -1 when out of memory. */
int pager_split(const char *text, size_t len, int cols, size_t *off, size_t *n, int max);
/* The further rows of a wrapped line are indented: under the line's last
 * column of text (after two blanks, as in `help set`'s table) or by its own
 * leading blanks, when 20 columns are left. pager_wrap gives the text as
 * those rows, one a line (malloc'ed, NUL-ended, its length in *out_len;
 * NULL when out of memory): for output short enough not to be paged. */
char *pager_wrap(const char *text, size_t len, int cols, size_t *out_len);

/* Shows text on the terminal fd_out (through the loop's output scheduler
 * when it has one), reading keys from the event loop l (its input, a
 * terminal, is put in non-canonical mode for the while): Space / PgDn / f a page on,
 * b / PgUp a page back, Enter / Down / j a line on, Up / k a line back,
 * g / Home the top, G / End the end, q / Esc leave; Space on the last page
 * leaves too, and Enter when the text fits one page. Any other printable
 * key (the moving letters too when the text fits one page) leaves and is
 * given back to the loop, to begin the next command line: what the user
 * typed is not lost. *at is the offset in text of the first row to show (0: the
 * top), and on return that of the first row shown. Returns true when the
 * user leaves or the input ends, false when the loop's interrupt hook
 * stopped it (a signal): the caller may show it again from *at, as it was
 * (after a stop and a continue) or wrapped for a new window size. The
 * caller redraws its screen after. */
bool pager_show(evloop *l, int fd_out, const char *text, size_t len, int cols, int rows, size_t *at);

#endif
