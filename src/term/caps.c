/* rtsh — terminal capabilities (caps.h), from the environment and terminfo. */
#include "term/caps.h"

#include <stdlib.h>
#include <string.h>
#include <term.h>
#include <unistd.h>

static bool env_is(const char *name, const char *a, const char *b)
{
	const char *v = getenv(name);
	return v && (strcmp(v, a) == 0 || (b && strcmp(v, b) == 0));
}

static bool term_usable(void)
{
	const char *t = getenv("TERM");
	return t && *t && strcmp(t, "dumb") != 0;
}

bool caps_screen_ok(int fd)
{
	return isatty(fd) && term_usable();
}

/* The depth terminfo gives for $TERM, or PALETTE_NONE when it does not know
 * the terminal. */
static frame_palette terminfo_palette(int fd)
{
	int status = 0;
	if (setupterm(NULL, fd, &status) != 0)
		return PALETTE_16; /* a terminal with no entry: assume the basic colours */
	frame_palette p = PALETTE_NONE;
	char rgb[] = "RGB", tc[] = "Tc", colors[] = "colors";
	int n = tigetnum(colors);
	if (tigetflag(rgb) > 0 || tigetflag(tc) > 0)
		p = PALETTE_TRUECOLOR;
	else if (n >= 256)
		p = PALETTE_256;
	else if (n >= 8)
		p = PALETTE_16;
	del_curterm(cur_term);
	return p;
}

frame_palette caps_palette(color_mode mode, int fd)
{
	switch (mode) {
	case COLOR_TRUECOLOR:
		return PALETTE_TRUECOLOR;
	case COLOR_256:
		return PALETTE_256;
	case COLOR_16:
		return PALETTE_16;
	case COLOR_NONE:
		return PALETTE_NONE;
	case COLOR_AUTO:
		break;
	}
	const char *nc = getenv("NO_COLOR");
	if (!isatty(fd) || (nc && *nc) || !term_usable())
		return PALETTE_NONE;
	if (env_is("COLORTERM", "truecolor", "24bit"))
		return PALETTE_TRUECOLOR;
	return terminfo_palette(fd);
}
