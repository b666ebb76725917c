/* rtsh — a small pager for command output longer than the shell's command
 * area (help, list of a large scene): the text fills the screen a page at a
 * time, as `more` shows it.
 *
 * Escape sequences sent: \e[H (home), \e[R;CH (move), \e[K (clear to end of
 * line), \e[2J (clear), \e[7m / \e[m (reverse video for the key line).
 */
#ifndef RTSH_PAGER_H
#define RTSH_PAGER_H

#include <stddef.h>

#include "term/evloop.h"

/* The rows text takes on a terminal `cols` wide, long lines wrapped (escape
 * sequences take no room; a code point takes one column). */
int pager_rows(const char *text, size_t len, int cols);

/* Shows text on the terminal fd_out (through the loop's output scheduler
 * when it has one), reading keys from the event loop l (its input, a
 * terminal, is put in non-canonical mode for the while): Space / PgDn / f a page on,
 * b / PgUp a page back, Enter / Down / j a line on, Up / k a line back,
 * g / Home the top, G / End the end, q / Esc leave; Space on the last page
 * leaves too. Returns when the user leaves, at the end of the input, or when
 * the loop's interrupt hook says so (a signal); the caller redraws its
 * screen. */
void pager_show(evloop *l, int fd_out, const char *text, size_t len, int cols, int rows);

#endif
