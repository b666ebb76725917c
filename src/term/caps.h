/* rtsh — what the terminal can do: the colour depth of the picture. */
#ifndef RTSH_CAPS_H
#define RTSH_CAPS_H

#include <stdbool.h>

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

/* True when fd is a terminal that can show the full-screen shell: TERM is
 * set and not "dumb". */
bool caps_screen_ok(int fd);

#endif
