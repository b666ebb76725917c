/* rtsh — what the terminal can do: the colour depth of the picture. */
#ifndef RTSH_CAPS_H
#define RTSH_CAPS_H

#include <stdbool.h>
#include <termios.h>

#include "term/frame.h"

/* The colour output asked for on the command line (--color). */
typedef enum color_mode {
	COLOR_AUTO,
	COLOR_TRUECOLOR,
	COLOR_256,
	COLOR_16,
	COLOR_NONE,
} color_mode;

/* The palette for output on fd. A forced --color wins (even when fd is not
 * a terminal); `auto` gives PALETTE_NONE when fd is not a terminal, NO_COLOR
 * is set and not empty, or TERM is unset or "dumb"; then truecolor when
 * COLORTERM is "truecolor" or "24bit" or terminfo has the RGB or Tc flag;
 * then 256 or 16 colours by terminfo's `colors`. */
frame_palette caps_palette(color_mode mode, int fd);
/* Inside tmux ($TMUX set) with `auto`, before terminfo: tmux answers no
 * XTGETTCAP from a pane (3.3a to 3.6b), but its client's terminal features
 * say RGB when that terminal has truecolor: caps_palette asks `tmux
 * display-message -p '#{client_termfeatures}'` (at most 0.5 s, once) and
 * takes truecolor when the list holds RGB. True when the comma-separated
 * list `features` (tmux's answer, a newline may end it) holds RGB. */
bool caps_features_rgb(const char *features);

/* True when fd is a terminal that can show the full-screen shell: TERM is
 * set and not "dumb". */
bool caps_screen_ok(int fd);

/* Sets the terminal on fd to pass keys one at a time with no echo (ICANON
 * and ECHO off; Ctrl-C and Ctrl-Z still signal), a read returning once vmin
 * bytes are in (0: at once), applied `when` (TCSANOW, TCSADRAIN). *saved
 * gets the modes to restore; false, nothing changed, when fd is not a
 * terminal. */
bool caps_raw_modes(int fd, cc_t vmin, int when, struct termios *saved);

#endif
