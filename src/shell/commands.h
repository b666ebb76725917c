/* rtsh — the command table.
 *
 * Every shell command is one entry: name, aliases, usage, argument counts,
 * what to complete for each argument, one line of help and the handler.
 * Lookup (exact names, aliases and unique prefixes), usage errors, `help`,
 * readline completion and the man page's list all come from this table, so
 * a new command is one entry and one function. The table is in
 * command_table.c, above its handlers; lookup and the argument helpers are
 * in commands.c, below them, and read the table the shell was handed.
 */
#ifndef RTSH_COMMANDS_H
#define RTSH_COMMANDS_H

#include <stdbool.h>
#include <stddef.h>

#include "rtsh/math.h"
#include "shell/shell.h"

/* A handler gets the words after the command name, and `rest`: the text
 * after the name as typed (for `add LINE`). It returns false after
 * shell_fail. */
typedef bool (*cmd_fn)(shell *sh, int argc, char **argv, const char *rest);

#define CMD_MAX_ARGS 32
#define CMD_ANY (-1)

typedef struct command {
	const char *name;
	const char *aliases;   /* space-separated, or NULL */
	const char *usage;     /* the forms, one per line, with the name */
	int min_args, max_args;/* words after the name; CMD_ANY: no limit */
	/* What to complete for the first words after the name: alternatives
	 * separated by '|'; "@file" (any), "@scene" (what load reads),
	 * "@output" (what save writes), "@command", "@setting", "@value" (of the
	 * setting before), "@object", "@light", "@camera" (their numbers),
	 * "@element" (the .rt elements, rtfile.h), "@key" (after "set": the
	 * object keys, rtfile.h) and "@ref" (numbers of the
	 * kind named by the word before). */
	const char *complete[3];
	const char *help;      /* one line */
	cmd_fn run;
} command;

extern const command command_table[];
extern const size_t command_count;

/* The command of the `count` in `table` named `word`, one of its aliases,
 * or the one command whose name or alias starts with `word`; NULL
 * otherwise, with a message saying whether it is unknown or ambiguous. */
const command *command_lookup(const command *table, size_t count, const char *word, char *msg, size_t size);
/* command_lookup in command_table (command_table.c). */
const command *command_find(const char *word, char *msg, size_t size);
/* Hands sh the command table (command_table.c): shell_main and the tests
 * call it after shell_init; command_run, help and the scripts read it from
 * sh. */
void command_table_install(shell *sh);

/* Index of the choice in "a|b|c" that `word` names or is a unique prefix of;
 * -1 when none or more than one. */
int choice_pick(const char *choices, const char *word);
/* "a, b or c" for messages. */
void choice_list(const char *choices, char *buf, size_t size);

/* Splits a command into words: blanks separate, '…' and "…" quote,
 * backslash escapes the next character outside single quotes. Returns the
 * word count (at most max), or -1 with a message on an unclosed quote.
 * Words point into buf (at least strlen(s) + 1 bytes). *rest_at is the
 * offset in s of the text after the first word. */
int split_words(const char *s, char **argv, int max, char *buf, size_t *rest_at, char *msg, size_t size);

/* Argument parsers: on failure they record `WHAT: "WORD" is not ...;
 * expected ...` and return false. */
bool arg_number(shell *sh, const char *what, const char *word, double lo, double hi, double *out);
bool arg_int(shell *sh, const char *what, const char *word, long lo, long hi, long *out);
bool arg_vec(shell *sh, const char *what, const char *word, const char *expect, vec3 *out);
bool arg_color(shell *sh, const char *what, const char *word, vec3 *out);
/* An element number 1..n of `kind` ("object", "light", "camera"), returned
 * 0-based. */
bool arg_index(shell *sh, const char *what, const char *word, const char *kind, size_t n, size_t *out);
/* A number: [+-]digits[.digits][e[+-]digits]; no inf, nan or hex. */
bool parse_number(const char *s, double *out);

/* The handlers (cmd_scene.c, cmd_step.c, cmd_edit.c, commands.c). */
bool cmd_load(shell *sh, int argc, char **argv, const char *rest);
bool cmd_save(shell *sh, int argc, char **argv, const char *rest);
bool cmd_render(shell *sh, int argc, char **argv, const char *rest);
bool cmd_set(shell *sh, int argc, char **argv, const char *rest);
bool cmd_list(shell *sh, int argc, char **argv, const char *rest);
bool cmd_camera(shell *sh, int argc, char **argv, const char *rest);
bool cmd_light(shell *sh, int argc, char **argv, const char *rest);
bool cmd_object(shell *sh, int argc, char **argv, const char *rest);
bool cmd_ambient(shell *sh, int argc, char **argv, const char *rest);
bool cmd_add(shell *sh, int argc, char **argv, const char *rest);
bool cmd_delete(shell *sh, int argc, char **argv, const char *rest);
bool cmd_undo(shell *sh, int argc, char **argv, const char *rest);
bool cmd_redo(shell *sh, int argc, char **argv, const char *rest);
bool cmd_generate(shell *sh, int argc, char **argv, const char *rest);
bool cmd_next(shell *sh, int argc, char **argv, const char *rest);
bool cmd_prev(shell *sh, int argc, char **argv, const char *rest);
bool cmd_view(shell *sh, int argc, char **argv, const char *rest);
bool cmd_turntable(shell *sh, int argc, char **argv, const char *rest);
bool cmd_show(shell *sh, int argc, char **argv, const char *rest);
bool cmd_source(shell *sh, int argc, char **argv, const char *rest);
bool cmd_help(shell *sh, int argc, char **argv, const char *rest);
bool cmd_clear(shell *sh, int argc, char **argv, const char *rest);
bool cmd_quit(shell *sh, int argc, char **argv, const char *rest);

/* Runs one command (no ';'): looks it up in sh's table, checks the
 * argument count and calls the handler. Blank commands succeed. */
bool command_run(shell *sh, const char *text);

#endif
