/* rtsh — saving a scene the way the user wrote it.
 *
 * rt_write (rtfile.h) writes a scene from scratch. The writer here starts
 * from the text the scene was loaded from and changes only what the scene
 * no longer agrees with:
 *   - a line whose element is unchanged is copied byte for byte (comments,
 *     blank lines, spacing, number spellings, line ends);
 *   - an edited element is rewritten on its own line, in the form it was
 *     written in (the 42 short form or the extended one, `L` or `l`, `C` or
 *     `c`, `R` or `set resolution`), keeping the line's indentation and its
 *     trailing comment;
 *   - a deleted element's line is dropped (with the ignored repeats of a
 *     changed A, C, R, sky or set line, which would now conflict);
 *   - a new element is written where it falls in its list: before the line
 *     of the element that follows it, or at the end of the file;
 *   - scene hints (R, set lines) follow s->hints the same way.
 * Elements are matched between the text and the scene by a longest common
 * subsequence, so deleting, adding or editing any one element touches one
 * line. The result is checked by loading it back: when it does not load to
 * exactly s, the scene is written from scratch by rt_write instead.
 */
#ifndef RTSH_RTKEEP_H
#define RTSH_RTKEEP_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include "rtsh/error.h"
#include "rtsh/scene.h"

/* Writes s to f keeping src[0..len) (NULL: no source, plain rt_write). */
bool rt_write_keeping(const scene *s, const char *src, size_t len, FILE *f, rt_error *err);
/* The same to path, atomically. */
bool rt_save_keeping(const scene *s, const char *src, size_t len, const char *path, rt_error *err);
/* The file the source text came from, for this thread (NULL: none): model
 * and texture names in its lines are relative to its folder. */
extern _Thread_local const char *rt_keep_source;
/* The text rt_write_keeping writes, in a new buffer (*out_len bytes, NUL
 * after them); NULL when out of memory or when it falls back to rt_write. */
char *rt_keep_text(const scene *s, const char *src, size_t len, size_t *out_len);

#endif
