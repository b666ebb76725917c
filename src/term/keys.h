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
	KEYS_MOUSE,          /* a mouse event: keys_mouse_event says which */
	KEYS_F1 = 0x110100,  /* KEYS_F1 + n - 1 is Fn */
};
#define KEYS_F(n) (KEYS_F1 + (n) - 1)

typedef struct keys keys;

/* A mouse event of xterm's SGR encoding (mode 1006), \e[<B;X;YM for a
 * press or a motion and \e[<B;X;Ym for a release. */
typedef enum keys_button {
	KEYS_BUTTON_LEFT,
	KEYS_BUTTON_MIDDLE,
	KEYS_BUTTON_RIGHT,
	KEYS_BUTTON_NONE,       /* a motion with no button held */
	KEYS_WHEEL_UP,
	KEYS_WHEEL_DOWN,
	KEYS_BUTTON_OTHER,      /* wheel left/right, buttons 8 to 11 */
} keys_button;

typedef struct keys_mouse {
	keys_button button;
	int x, y;               /* the cell, 1-based, as the terminal counts */
	bool release;           /* the button went up ('m') */
	bool motion;            /* moved with the button held (mode 1002) */
	bool shift, meta, ctrl;
} keys_mouse;

/* Reads one SGR mouse report from the n bytes at s, which follow its
 * "\e[<" (the digits, semicolons and the final M or m); returns the bytes
 * it took, 0 when s does not start one (or it is cut short). */
size_t keys_parse_mouse(const char *s, size_t n, keys_mouse *m);
/* The escape sequences that turn the mouse on (button presses, releases
 * and motion while a button is held, 1002; in the SGR encoding, 1006) and
 * off again. */
#define KEYS_MOUSE_ON "\x1b[?1002h\x1b[?1006h"
#define KEYS_MOUSE_OFF "\x1b[?1006l\x1b[?1002l"

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
/* The mouse event keys_next last returned as KEYS_MOUSE. */
keys_mouse keys_mouse_event(const keys *k);
/* terminfo's keypad transmit on / off strings (smkx, rmkx), "" when none:
 * send the first while reading keys and the second after. */
const char *keys_keypad_on(const keys *k);
const char *keys_keypad_off(const keys *k);
/* Ends ncurses and frees everything; the terminal settings of readline
 * (terminfo's current terminal) are as before keys_open. */
void keys_close(keys *k);

#endif
