/* rtsh — the command history file, ~/.rtsh_history ($HOME respected).
 * Each line is appended as it is typed, so history survives a crash; the
 * file is trimmed to HISTORY_MAX lines at exit. When the file cannot be
 * written, one warning says so and the shell goes on without it. */
#ifndef RTSH_HISTORY_H
#define RTSH_HISTORY_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#define HISTORY_MAX 1000

typedef struct shell_history {
	char path[4096]; /* "" when there is no $HOME */
	bool writable;
	bool warned;
	FILE *warn;      /* where the warning goes */
} shell_history;

/* The history file's path for $HOME into buf; false when HOME is unset. */
bool history_path(char *buf, size_t size);
/* Reads the file into readline's history and checks it can be written. */
void history_setup(shell_history *h, FILE *warn);
/* Adds a typed line (not blank, not the same as the last one). */
void history_add_line(shell_history *h, const char *line);
/* Trims the file at exit. */
void history_finish(shell_history *h);

#endif
