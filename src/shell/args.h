/* rtsh — the command line, parsed by getopt_long (GNU rules: `-s4` and
 * `-s 4`, `--samples=4` and `--samples 4`, bundled flags such as `-qi`,
 * unique prefixes of long options, options before or after the scene, and
 * `--` to end the options).
 *
 * Every entry of the settings table (rtsh/settings.h) is also a long
 * option: `--exposure=1.5` means `set exposure 1.5`. The short forms -r -s
 * -d -t -m name the settings resolution, samples, depth, threads and mode.
 *
 * A leaf: it needs only the settings table, so other programs (rtsh-mpi)
 * can parse "the same options as rtsh" with args_parse(ARGS_BATCH).
 */
#ifndef RTSH_ARGS_H
#define RTSH_ARGS_H

#include <stdio.h>

#include "rtsh/render.h"
#include "shell/options.h"

typedef enum args_kind {
	ARGS_RTSH,  /* every option of rtsh */
	ARGS_BATCH, /* the batch options only: no -c, -f, -i (SCENE -o OUT required) */
} args_kind;

/* Parses argv into o (zeroed first); prog names the program in messages.
 * Returns -1 to go on, or an exit status: 0 after --help or --version
 * (printed on standard output), 2 after a usage error (printed on standard
 * error as "PROG: what is wrong" and a hint to --help). */
int args_parse(int argc, char **argv, args_kind kind, const char *prog, rtsh_options *o);

/* The usage text, with one line per setting from the table. */
void args_usage(FILE *f, args_kind kind, const char *prog);

/* Applies the command line's settings over s (after the scene's hints).
 * They were validated when parsed, so this cannot fail. */
void options_apply_settings(const rtsh_options *o, render_settings *s);

#endif
