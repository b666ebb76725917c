/* rtsh — the settings table: one entry per render setting, with its type,
 * range, default and help. The shell's `set`, the command-line options and
 * the `set` lines of a .rt file all read and write settings through it.
 */
#ifndef RTSH_SETTINGS_H
#define RTSH_SETTINGS_H

#include <stdbool.h>
#include <stddef.h>

#include "rtsh/error.h"
#include "rtsh/render.h"

typedef enum setting_type {
	SETTING_INT,
	SETTING_U64,
	SETTING_DOUBLE,
	SETTING_RESOLUTION, /* WxH */
	SETTING_MODE,       /* whitted|path */
	SETTING_DENOISE,    /* auto|on|off (denoise_mode) */
	SETTING_PIXELS,     /* off|kitty|sixel|iterm|auto (pixels_mode) */
	SETTING_SYMBOLS,    /* half|quadrant|sextant|octant|auto (symbols_kind) */
} setting_type;

typedef struct setting_def {
	const char *name;
	setting_type type;
	double min, max; /* inclusive range for numbers (and each of W, H) */
	size_t offset;   /* of the value in render_settings (W for a resolution) */
	const char *help;
} setting_def;

extern const setting_def settings_table[];
extern const size_t settings_count;

/* The entry whose name is `name` or a unique prefix of it; NULL otherwise
 * (err says whether it is unknown or ambiguous). */
const setting_def *settings_find(const char *name, rt_error *err);
/* Parses value for the setting and stores it in s; false (err set:
 * "what is wrong; expected ...") leaves s unchanged. */
bool settings_set(render_settings *s, const setting_def *def, const char *value, rt_error *err);
/* Writes the setting's current value ("64", "1920x1080", "path") to buf. */
void settings_format(const render_settings *s, const setting_def *def, char *buf, size_t size);

#endif
