/* rtsh — the shell's state and the helpers its commands share.
 *
 * One `shell` lives for the whole run. Commands (commands.h) read and change
 * it; the scene itself is changed only through the editor (rtsh/edit.h).
 * The shell runs in one of two ways:
 *   - interactive (loop.c): readline, the picture and the status line on
 *     the alternate screen, a background preview; errors are reported and
 *     the shell goes on;
 *   - script (script.c): -c, -f, piped standard input; no picture; the
 *     first error prints "FILE:LINE: message" and stops with status 1.
 */
#ifndef RTSH_SHELL_H
#define RTSH_SHELL_H

#include <signal.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rtsh/edit.h"
#include "rtsh/render.h"
#include "rtsh/rtfile.h"
#include "shell/options.h"
#include "shell/render_service.h"
#include "shell/signals.h"
#include "term/frame.h"
#include "base/abuf.h"
#include "term/evloop.h"
#include "term/screen.h"

#define SHELL_MSG_MAX 1024

/* Settings remembered per scene file for the session (next, prev, load). */
typedef struct scene_memo {
	char *label;
	render_settings set;
} scene_memo;

typedef struct shell {
	const rtsh_options *opt;
	editor *ed;
	render_settings set;

	/* The scene's name and origin, from the editor's label. */
	char *label;           /* copy of editor_label() last seen: a path, or NULL */
	char name[256];        /* for the status line and messages */
	char *dir;             /* the folder next/prev walk through */
	scene_memo *memo;
	size_t nmemo;

	rt_load_opts load_opts;
	rt_warnings warn;

	/* Output. */
	bool interactive;      /* a person types: errors do not stop */
	bool progress;         /* progress bars for full renders (stderr or status line) */
	frame_palette pal;     /* for `show` on standard output */
	screen *scr;           /* NULL: no picture */
	abuf *capture;         /* when set, shell_out/shell_info append here (the pager) */
	abuf *notes;           /* when set, shell_note and load warnings append here (key mode) */
	rsvc *rs;              /* the render service: the preview, key mode, the world cache */
	rsvc_image img;        /* the newest preview image shown */
	uint64_t preview_seq;  /* rsvc_start's number of the preview asked for last */
	uint8_t *srgb;         /* img as sRGB bytes */
	size_t srgb_cap;
	double last_draw;      /* when the picture was last sent */
	double frame_cost;     /* how long the last frame's write() took */
	bool redraw;           /* an image waits to be drawn */

	/* The full-resolution image and what it was rendered from. */
	framebuffer *full;
	uint64_t full_gen;
	render_settings full_set;
	double full_seconds;

	/* Running. */
	bool quit;
	atomic_bool cancel;    /* Ctrl-C: stops a full render */
	char err[SHELL_MSG_MAX];
	char notice[256];      /* said once in the status line (until notice_until) */
	double notice_until;
	bool err_reported;     /* err was printed already (by a nested source) */
	uint64_t saved_gen;    /* the editor's generation when the scene was loaded or saved as .rt */
	uint64_t quit_asked_gen; /* quit asked about unsaved edits at this generation (+1; 0: not asked) */
	bool force;            /* the command word ended in "!" (quit!) */
	int depth;             /* source nesting */
	unsigned hand_set;     /* bit i: settings_table[i] was changed by `set` (answer.c) */
	void (*status_hook)(struct shell *sh); /* redraws the status line (interactive) */
	int wake[2];           /* the interactive loop's wake-up pipe (read, write); -1: none */
	evloop *ev;            /* the interactive loop's event loop (term/evloop.h); NULL: none */
	/* The commands it runs (commands.h): the table is handed down by the
	 * shell's owner (command_table_install), so that lookup, help and the
	 * scripts need not call up into the table's file. */
	const struct command *commands;
	size_t ncommands;
} shell;

/* Records an error message for the command being run; returns false. */
bool shell_fail(shell *sh, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* Prints to standard output (command results). */
void shell_out(shell *sh, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* Prints a confirmation ("saved x.png") to standard output, unless -q. */
void shell_info(shell *sh, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* A message for the status line, shown for a while (said once: the
 * caller's business). */
void shell_notice(shell *sh, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* Prints a note to standard error (warnings, progress text). */
void shell_note(shell *sh, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* Sets up the shell for the options: loads the scene (or the built-in one)
 * and applies the settings; the preview wakes wake_fd (-1: none). False
 * (message printed) when the scene fails. */
bool shell_init(shell *sh, const rtsh_options *o, int wake_fd);
void shell_free(shell *sh);

/* Call before changing the scene or the settings: stops the preview. */
void shell_edit_begin(shell *sh);
/* Call after: notices a new scene (name, settings) and restarts the preview. */
void shell_edit_end(shell *sh);
/* Restarts the preview for the current scene, settings and screen size. */
void shell_refresh(shell *sh);
/* The settings a preview refines with: the shell's, with path mode's own
 * target of samples (PREVIEW_PATH_SAMPLES) when nobody chose any. The
 * shell's preview and key mode's refinement both use it. */
render_settings shell_preview_settings(const shell *sh);
/* Says once, in the status line, that kitty or iTerm2 images asked for in
 * tmux fell back to half blocks. */
void shell_pixels_notice(shell *sh);
/* The status line's text. */
void shell_status_text(shell *sh, char *buf, size_t size);

/* The full-resolution image for the current scene and settings, rendered
 * now if missing or stale (with progress, Ctrl-C stops it); NULL (error
 * recorded) on failure. */
const framebuffer *shell_full_image(shell *sh, bool force);
/* The picture as a frame of cells for `save X.ans` and `show`: the current
 * preview when there is one, else rendered at `cols` columns. */
frame *shell_picture_frame(shell *sh, frame_palette pal, int cols);

/* True when an interactive quit should ask first: edits not saved as .rt,
 * not asked already about these edits, not -q, not from a command file.
 * Marks the question asked (the caller says it). */
bool shell_quit_asks(shell *sh);

/* Replaces the scene (load, next, prev, generate). */
bool shell_replace_scene(shell *sh, scene *s, const char *label);
/* Loads a scene file (the current scene stays on failure). */
bool shell_load(shell *sh, const char *path);

/* --- running commands (script.c) --- */
/* Runs one command line (commands separated by ';'); false on the first
 * error (recorded in sh->err). */
bool shell_run_line(shell *sh, const char *line);
/* Runs text as a command file named `name`; -c uses counts commands
 * instead of lines. Reports the first error as "NAME:LINE: message" and
 * returns false. */
bool shell_run_text(shell *sh, const char *text, const char *name, bool count_commands);
/* The longest command line, in bytes without its newline, that a command
 * file, -c, source, standard input or the prompt may hold (rtsh(1)). */
#define SHELL_LINE_MAX 65536
#define SHELL_LINE_MAX_TEXT "65536"
/* Runs a command file ("-" or "/dev/stdin" = standard input; any other
 * file that is not a regular one is refused unopened). A NUL byte or a line
 * longer than SHELL_LINE_MAX ends it with "FILE:LINE: message". */
bool shell_run_file(shell *sh, const char *path);
/* Prints sh->err for an interactive command (not yet reported). */
void shell_report(shell *sh);

/* The interactive shell (loop.c), full screen when use_screen; wake is the
 * preview's wake-up pipe (read end, write end). Returns the exit status. */
int shell_interactive(shell *sh, bool use_screen, const int wake[2]);

/* ~ and ~/ at the start of a path, expanded with $HOME; a new string. */
char *shell_expand_path(const char *path);

#endif
