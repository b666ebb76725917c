/* rtsh — helpers the model and image readers share (private to the core). */
#ifndef RTSH_MESH_IO_H
#define RTSH_MESH_IO_H

#include <stdbool.h>
#include <stddef.h>

#include "rtsh/error.h"

/* Largest coordinate a model may hold: beyond it a bounding box, a BVH in
 * float and an eps make no sense. */
#define MESH_COORD_MAX 1e15

/* Reads a whole file (NUL-terminated, *len without the NUL); NULL with err
 * "PATH: cannot read ...: reason" (what = "model", "texture"...). */
char *file_slurp(const char *path, const char *what, size_t *len, rt_error *err);
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
