/* rtsh — the keyboard of key mode, read by ncurses.
 *
 * ncurses is used for input only: newterm() on the terminal's input with
 * its output sent to /dev/null, so that it never draws (the picture is the
 * frame encoder's) and never leaves the alternate screen; keys are read
 * from a 1x1 pad, which wgetch() does not refresh. The terminal modes
 * (cbreak, no echo) are set by the caller; keypad transmit mode is sent by
 * the caller too (keys_keypad gives the strings).
 *
 * Keys are plain characters (Tab = 9, Esc = 27, Ctrl-L = 12, ...) or the
 * KEYS_ codes below, which no character takes. This header does not include
 * curses.h (whose `box` would clash with rtsh's), so that key mode and its
 * tests see only these codes.
 */
#ifndef RTSH_KEYS_H
#define RTSH_KEYS_H

#include <stdbool.h>
#include <stddef.h>

enum {
	KEYS_NONE = -1,      /* no key waiting */
	KEYS_ESC = 27,
	KEYS_UP = 0x110000,  /* past every Unicode code point */
	KEYS_DOWN,
	KEYS_LEFT,
	KEYS_RIGHT,
	KEYS_SHIFT_UP,
	KEYS_SHIFT_DOWN,
	KEYS_SHIFT_LEFT,
	KEYS_SHIFT_RIGHT,
	KEYS_PAGE_UP,
	KEYS_PAGE_DOWN,
	KEYS_HOME,
	KEYS_END,
	KEYS_BACKTAB,        /* Shift+Tab */
	KEYS_RESIZE,
	KEYS_OTHER,          /* a function key key mode has no use for */
	KEYS_F1 = 0x110100,  /* KEYS_F1 + n - 1 is Fn */
};
#define KEYS_F(n) (KEYS_F1 + (n) - 1)

typedef struct keys keys;

/* Reads keys from the terminal on in_fd with an Esc delay of esc_ms
 * milliseconds. The process's signal handlers are kept as they were. NULL
 * when ncurses cannot use the terminal (TERM unknown, out of memory). */
keys *keys_open(int in_fd, int esc_ms);
/* The same, but ncurses reads only what keys_feed gives it (the key bytes
 * the event loop, term/evloop.h, read from the terminal with the answers
 * taken out); the terminal's fd is never read here. */
keys *keys_open_fed(int esc_ms);
/* Gives ncurses key bytes (keys_open_fed); false when they could not all
 * be taken (more than a pipe holds unread) or k is not fed. */
bool keys_feed(keys *k, const char *b, size_t n);
/* The next key waiting, or KEYS_NONE; never blocks longer than the Esc
 * delay (to tell Esc from the start of a sequence). */
int keys_next(keys *k);
/* terminfo's keypad transmit on / off strings (smkx, rmkx), "" when none:
 * send the first while reading keys and the second after. */
const char *keys_keypad_on(const keys *k);
const char *keys_keypad_off(const keys *k);
/* Ends ncurses and frees everything; the terminal settings of readline
 * (terminfo's current terminal) are as before keys_open. */
void keys_close(keys *k);

#endif
