/* rtsh — path and number helpers the model and image readers share. */
#ifndef RTSH_READHELP_H
#define RTSH_READHELP_H

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

#endif
