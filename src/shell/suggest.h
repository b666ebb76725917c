/* rtsh — "did you mean …?": the closest name to a mistyped word among the
 * shell's commands, settings and choices (base/nearest.h measures it).
 */
#ifndef RTSH_SUGGEST_H
#define RTSH_SUGGEST_H

#include <stdbool.h>
#include <stddef.h>

#include "base/nearest.h"

/* The same among choices written "a|b|c"; the choice goes to buf. */
bool suggest_choice(const char *choices, const char *word, char *buf, size_t size);
/* A command name or alias of the command table close to word, into buf;
 * false when none is (command_table.c: the shell's own table). */
bool suggest_command(const char *word, char *buf, size_t size);
/* The same among the `count` commands of `table` (commands.h). */
struct command;
bool suggest_command_in(const struct command *table, size_t count, const char *word, char *buf, size_t size);
/* A setting name of the settings table close to word, or NULL. */
const char *suggest_setting(const char *word);

#endif
