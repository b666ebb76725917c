/* rtsh — the nearest name to a mistyped word (base layer): what "did you
 * mean …?" offers, in the shell (shell/suggest.h) and the .rt reader.
 *
 * Closeness is the optimal-string-alignment distance (Damerau–Levenshtein
 * without overlapping edits): one insertion, deletion, substitution or swap
 * of two neighbouring characters costs 1; case is ignored. A candidate is
 * offered only when it is close for the word's length (distance 1 for words
 * of up to 5 bytes, 2 up to 9, 3 beyond) and strictly closer than the word's
 * own length, so a one-letter typo of a short name is caught and a word
 * unlike every name gets no guess.
 */
#ifndef RTSH_NEAREST_H
#define RTSH_NEAREST_H

#include <stdbool.h>
#include <stddef.h>

/* Words longer than this are not typos of any name. */
#define SUGGEST_MAX_LEN 64

/* The distance between a and b (bytes, case-insensitive). */
size_t suggest_distance(const char *a, const char *b);
/* The candidate nearest to word, or NULL when none is close enough; on a
 * tie the first one wins. */
const char *suggest_closest(const char *word, const char *const *cands, size_t n);

/* The nearest candidate seen so far, for lists of other shapes: start,
 * try each candidate (len bytes of it name it), then ok says whether best
 * is close enough to offer. */
typedef struct nearest {
	const char *word;
	size_t len, d;
	const char *best;  /* NULL: none yet */
	size_t best_len;   /* bytes of best that name it (for "a|b" and "a b" lists) */
} nearest;

nearest nearest_start(const char *word);
void nearest_try(nearest *n, const char *cand, size_t len);
bool nearest_ok(const nearest *n);

#endif
