/* rtsh — the command-line options, shared by main.c and the front ends
 * (parsed by shell/args.h). */
#ifndef RTSH_OPTIONS_H
#define RTSH_OPTIONS_H

#include <stdbool.h>

#include "rtsh/render.h"
#include "rtsh/settings.h"
#include "term/caps.h"

/* A setting given on the command line; it wins over the scene file's hints. */
typedef struct option_setting {
	const setting_def *def;
	const char *value;
} option_setting;

#define OPTIONS_MAX_SETTINGS 16
/* --preview: the largest side in cells; --turntable: the most frames. */
#define OPTIONS_MAX_CELLS 1000
#define OPTIONS_MAX_FRAMES 3600

typedef struct rtsh_options {
	const char *scene;     /* SCENE.rt or NULL (the built-in showcase) */
	const char *output;    /* -o OUT: batch render */
	const char *commands;  /* -c 'CMD; CMD' */
	const char *file;      /* -f FILE ("-" = stdin) */
	bool interactive;      /* -i */
	bool quiet;            /* -q */
	bool strict;           /* --strict */
	color_mode color;      /* --color */
	const char *preview;   /* --preview COLSxROWS (shell/preview.h) */
	int preview_cols, preview_rows;
	bool turntable;        /* --turntable [FRAMES] */
	int turntable_frames;  /* FRAMES, 0 when not given */
	option_setting settings[OPTIONS_MAX_SETTINGS];
	int nsettings;
} rtsh_options;

/* The shell: runs -c / -f / stdin commands or the interactive shell.
 * Returns the process exit status. */
int shell_main(const rtsh_options *o);

#endif
