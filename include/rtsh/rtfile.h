/* rtsh — reading and writing .rt scene files.
 *
 * One parser for every dialect, mixed freely in one file: the 42 miniRT
 * format, its 2019 variant (R, c, l, sq, tr) and the extended format of the
 * miniRT seed (position rotation scaling colour material [shear]), with
 * optional trailing key=value extensions. See rtsh(5).
 *
 * Errors read "FILE:LINE:COL: what is wrong; expected ...". The parser never
 * crashes or hangs on any input: NUL bytes, huge or non-finite numbers,
 * enormous lines and empty files all give an error.
 */
#ifndef RTSH_RTFILE_H
#define RTSH_RTFILE_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include "rtsh/error.h"
#include "rtsh/scene.h"

/* Reads a whole file into a new NUL-terminated buffer of *len bytes (plus
 * the NUL); NULL with err set ("PATH: cannot open: ..."). */
typedef char *(*rt_read_fn)(void *ctx, const char *path, size_t *len, rt_error *err);

typedef struct rt_load_opts {
	bool strict;               /* the 42 subject's rules (rtsh --strict) */
	const rt_warnings *warn;   /* optional sink for warnings */
	/* Optional: how the scene file and every file it references are read;
	 * NULL reads them from disk. rtsh-mpi records them on rank 0 and serves
	 * them from memory on the other ranks. */
	rt_read_fn read;
	void *read_ctx;
	/* Optional: when set (Ctrl-C in the shell), the load stops soon after,
	 * with the error "stopped", at the next line or in a model's normals or
	 * tree (a model's or an image's decoder runs to its end first). */
	const atomic_bool *cancel;
} rt_load_opts;

/* Reads a file the way the loader does: through opts->read when set, else
 * from disk (at most 1 GiB). opts may be NULL. */
char *rt_read_file(const char *path, const rt_load_opts *opts, size_t *len, rt_error *err);

/* Loads a scene file (at most 1 GiB); NULL with err set on the first
 * problem. opts may be NULL. Non-fatal notes go to opts->warn: a clamped
 * FOV, an A/C/R/sky/set line that repeats the first one exactly (ignored),
 * a 42-form object of size 0 (left out), no camera (the default camera is
 * added; with opts->strict that is an error). A loaded scene has at least
 * one camera and cam == 0. */
scene *rt_load_file(const char *path, const rt_load_opts *opts, rt_error *err);
/* The model viewer's scene for a model file (.obj .ply .gltf .glb .stl):
 * the model on a ground plane, framed by the camera, with a light and a
 * sky (viewer.c). rt_load_file calls it for those extensions. */
scene *rt_load_model(const char *path, const rt_load_opts *opts, rt_error *err);
/* The text of that scene (.rt lines naming the model by its file name,
 * relative to its folder), in a new buffer of *len bytes and a NUL; NULL
 * (err set) when the model cannot be read. `save x.rt` keeps it. */
char *rt_model_text(const char *path, const rt_load_opts *opts, size_t *len, rt_error *err);
/* Loads a scene from memory (text need not be NUL-terminated); `name` is the
 * file name used in messages. */
scene *rt_load_string(const char *text, size_t len, const char *name, const rt_load_opts *opts,
                      rt_error *err);
/* Parses one line (no newline) into s, as the shell's `add LINE` does. The
 * once-only elements replace the existing ones: A the ambient, C the active
 * camera (or adds one if there is none), R, sky and set their values. On
 * error s is unchanged. */
bool rt_parse_line(scene *s, const char *line, const char *name, int lineno,
                   const rt_load_opts *opts, rt_error *err);

/* The i-th element the reader knows, in the order of its messages (A C c L
 * l R, then the shape kinds' identifiers from shape.h, then sky set): its
 * identifier, and in *usage every form it is read in. NULL past the last.
 * `help add` and completion list them from here. */
const char *rt_element(size_t i, const char **usage);

/* The i-th key=value field objects take (the reader's one table of keys):
 * its name, and in *help one line saying what it does and its range. NULL
 * past the last. A new material key is one line of that table
 * (src/scene/keys.c, rt_keys). */
const char *rt_key_info(size_t i, const char **help);

/* Writes the scene as .rt text; load(write(s)) is equal to s (scene_equal). */
bool rt_write(const scene *s, FILE *f, rt_error *err);
/* Writes the scene to path atomically. */
bool rt_save(const scene *s, const char *path, rt_error *err);
/* The one .rt line for an element (no newline), as `list` shows it. */
void rt_format_object(const object *o, char *buf, size_t size);
/* The same in the extended form whatever the short form could say
 * (triangles: their only form). */
void rt_format_object_extended(const object *o, char *buf, size_t size);
void rt_format_light(const light *l, char *buf, size_t size);
void rt_format_camera(const camera *c, char *buf, size_t size);

#endif
