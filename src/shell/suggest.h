/* rtsh — "did you mean …?": the closest name to a mistyped word.
 *
 * Closeness is the optimal-string-alignment distance (Damerau–Levenshtein
 * without overlapping edits): one insertion, deletion, substitution or swap
 * of two neighbouring characters costs 1; case is ignored. A candidate is
 * offered only when it is close for the word's length (distance 1 for words
 * of up to 5 bytes, 2 up to 9, 3 beyond) and strictly closer than the word's
 * own length, so a one-letter typo of a short name is caught and a word
 * unlike every name gets no guess.
 */
#ifndef RTSH_SUGGEST_H
#define RTSH_SUGGEST_H

#include <stdbool.h>
#include <stddef.h>

/* The distance between a and b (bytes, case-insensitive). */
size_t suggest_distance(const char *a, const char *b);
/* The candidate nearest to word, or NULL when none is close enough; on a
 * tie the first one wins. */
const char *suggest_closest(const char *word, const char *const *cands, size_t n);
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
