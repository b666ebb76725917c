/* rtsh — the command-line options, shared by main.c and the front ends. */
#ifndef RTSH_OPTIONS_H
#define RTSH_OPTIONS_H

#include <stdbool.h>

#include "rtsh/render.h"
#include "rtsh/settings.h"

typedef enum color_mode {
	COLOR_AUTO,
	COLOR_TRUECOLOR,
	COLOR_256,
	COLOR_16,
	COLOR_NONE,
} color_mode;

/* A setting given on the command line; it wins over the scene file's hints. */
typedef struct option_setting {
	const setting_def *def;
	const char *value;
} option_setting;

#define OPTIONS_MAX_SETTINGS 16

typedef struct rtsh_options {
	const char *scene;     /* SCENE.rt or NULL (the built-in showcase) */
	const char *output;    /* -o OUT: batch render */
	const char *commands;  /* -c 'CMD; CMD' */
	const char *file;      /* -f FILE ("-" = stdin) */
	bool interactive;      /* -i */
	bool quiet;            /* -q */
	bool strict;           /* --strict */
	color_mode color;      /* --color */
	option_setting settings[OPTIONS_MAX_SETTINGS];
	int nsettings;
} rtsh_options;

/* Parses argv into o (zeroed by the caller); returns -1 to go on, or an
 * exit status (0 after --help or --version, 2 after a usage error, whose
 * message it has printed). */
int options_parse(int argc, char **argv, rtsh_options *o);
/* Prints "PROG: " fmt (with arg) and the --help hint; returns 2. */
int options_usage_error(const char *fmt, const char *arg);

/* Applies the command line's settings over s (after the scene's hints).
 * They were validated when parsed, so this cannot fail. */
void options_apply_settings(const rtsh_options *o, render_settings *s);

/* The shell: runs -c / -f / stdin commands or the interactive shell.
 * Returns the process exit status. */
int shell_main(const rtsh_options *o);

#endif
