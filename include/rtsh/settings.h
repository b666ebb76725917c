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
	SETTING_RESOLUTION, /* WxH: render_settings.width and .height */
	SETTING_ENUM,       /* one of `choices`, stored as an int: its index */
} setting_type;

/* setting_def.flags */
enum {
	SETTING_BARE_ON = 1, /* the command line's --NAME alone means --NAME=on */
	SETTING_TERMINAL = 2, /* the terminal's choice (pixels, symbols): the render
	                       * core never reads it, and rtsh-mpi's wire leaves
	                       * it out */
	SETTING_SCENE = 4,    /* kept with the scene: a .rt file's `set NAME VALUE`
	                       * line sets it, `save x.rt` writes it back, and
	                       * loading the scene applies it (under the command
	                       * line's --NAME and the shell's `set`). For how the
	                       * picture is made (resolution, samples, seed,
	                       * exposure...), not for the machine or the terminal
	                       * (threads, pixels, symbols). */
};

/* One setting: adding one is a field in render_settings (render.h) and a
 * row of settings_table (settings.c). `set`, its completion and help, the
 * long option --NAME, the defaults (render_settings_default), rtsh-mpi's
 * wire (src/mpi/wire.c) and, for a SETTING_SCENE row, the .rt reader and
 * writer (scene_hints.kept) all read the row. */
typedef struct setting_def {
	const char *name;
	setting_type type;
	double min, max;  /* inclusive range for numbers (and each of W, H) */
	size_t offset;    /* of the value in render_settings (W for a resolution) */
	const char *help;
	const char *def;  /* the default, as `set` would read it */
	const char *const *choices; /* SETTING_ENUM: the names, in order, NULL-terminated */
	unsigned flags;   /* SETTING_* above */
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
/* A SETTING_SCENE row's value for a scene file: value (as a .rt `set` line
 * or the shell's `set` gives it) checked by the row and written to out as
 * settings_format writes it (a number: the shortest text that reads back to
 * it), zero-padded to size; false (err set as by settings_set) otherwise. */
bool settings_scene_value(const setting_def *def, const char *value, char *out, size_t size, rt_error *err);
/* True for a SETTING_SCENE row whose value scene_hints.kept holds: every
 * one but resolution, samples, depth and mode (the hints' own fields). */
bool settings_kept_slot(const setting_def *def);
/* The number of choices of a SETTING_ENUM (0 for other types). */
int settings_choices(const setting_def *def);
/* The choices joined by sep ("whitted|path"), at most size bytes. */
void settings_choices_text(const setting_def *def, const char *sep, const char *last, char *buf, size_t size);

/* The value of an integer-like setting (INT, ENUM) in s, and setting it. */
int settings_get_int(const render_settings *s, const setting_def *def);
void settings_put_int(render_settings *s, const setting_def *def, int v);

#endif
