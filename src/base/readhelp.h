/* rtsh — path and number helpers the model and image readers share. */
#ifndef RTSH_READHELP_H
#define RTSH_READHELP_H

#include <stdatomic.h>
#include <stdbool.h>

/* A newly allocated path: rel joined to dir (rel unchanged if absolute or
 * dir is empty or "."); NULL when out of memory. */
char *path_join(const char *dir, const char *rel);
/* The folder part of path ("" when there is none); newly allocated. */
char *path_dir(const char *path);

/* Parses a decimal number (sign, digits, '.', exponent, also inf/nan) at
 * *s, not past end; advances *s. False when there is none. Locale-free. */
bool scan_double(const char **s, const char *end, double *out);
/* A decimal integer (optionally signed). */
bool scan_long(const char **s, const char *end, long *out);

/* The first byte from s on (not past end) that is no blank (' ', '\t',
 * '\r') or line end, each '\n' counted in *lines (when not NULL), and with
 * `comments` not in a '#' comment, which runs to its line's end. */
const unsigned char *skip_space(const unsigned char *s, const unsigned char *end, bool comments, int *lines);

/* Ctrl-C during a read (issue 31, defect 3): the flag the readers on this
 * thread poll, set around a read by the caches (mesh_cache_get,
 * texture_cache_get); NULL: none. Returns the one it replaces. */
const atomic_bool *read_cancel_set(const atomic_bool *cancel);
/* True when this thread's flag is set (checked on every call). */
bool read_cancelled(void);
/* read_cancelled, but the flag is looked at only every 4096th call: for a
 * reader's inner loop (a line, an element, a row). */
bool read_poll(void);

#endif
