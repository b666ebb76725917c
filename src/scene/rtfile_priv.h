/* rtsh — what the .rt reader and writer share (rtfile_read.c, rtfile_write.c).
 *
 * The trailing key=value fields of objects live in ONE table, rt_keys: the
 * reader parses and range-checks them from it and the writer emits every
 * field whose value differs from the row's default. Adding a material key is
 * adding a row (and documenting it in man/rtsh.5).
 */
#ifndef RTSH_RTFILE_PRIV_H
#define RTSH_RTFILE_PRIV_H

#include <locale.h>
#include <stdbool.h>
#include <stddef.h>

#include "rtsh/atomic.h"
#include "rtsh/rules.h"
#include "rtsh/scene.h"


typedef struct rt_key {
	const char *name;   /* as written before '=' */
	size_t offset;      /* of the field in struct object */
	bool is_int;        /* an int field (else double) */
	bool triangles;     /* allowed on triangles */
	unsigned needs;     /* a KIND_* flag the kind must have (0: any kind) */
	bool in_short;      /* the short form says it already: written in the extended form only */
	double min, max;    /* inclusive range */
	double def;         /* the value that means "absent"; not written */
	bool (*extra)(double v); /* a further rule within [min,max], or NULL */
	const char *expect; /* what a valid value is, for messages */
	const char *help;   /* one line for `help` */
	int type;           /* RT_KEY_NUM (0), RT_KEY_FILE, RT_KEY_PAIR or RT_KEY_RGB */
	bool mesh_only;     /* only on mesh objects */
} rt_key;

/* RT_KEY_FILE: a file name (const char * field, rt_intern'ed, resolved
 * against the .rt file's folder); RT_KEY_PAIR: U,V into double[2];
 * RT_KEY_RGB: R,G,B into a vec3 (min, max per channel; absent when all
 * three equal def). */
enum { RT_KEY_NUM, RT_KEY_FILE, RT_KEY_PAIR, RT_KEY_RGB };
/* An offset with this bit is one into the material's shared PBR block
 * (scene.h, material_pbr), which rt_key_get / rt_key_set copy, change and
 * intern: read and write such keys only through them. */
#define RT_KEY_PBR ((size_t)1 << 24)
/* The folder model and texture names are written relative to (rt_save sets
 * it for the duration of a write; "" = as stored). */
extern _Thread_local const char *rt_write_dir;
/* A model or texture file name as a file written to rt_write_dir says it
 * (relative to it when below it, else as stored, made absolute when a
 * relative name would not be found from there; quoted when needed). */
void rt_write_file_name(const char *file, char *out, size_t size);
/* Writes path atomically through write(ctx) with rt_write_dir the new
 * file's folder ("" when the path names none, and with no_dot for "." too),
 * for rt_save and rt_save_keeping. */
bool rt_save_in_folder(const char *path, bool no_dot, file_writer_fn write, void *ctx, rt_error *err);

extern const rt_key rt_keys[];
extern const size_t rt_nkeys;

/* Whether key k may be given on an object of kind kind. */
bool rt_key_applies(const rt_key *k, obj_kind kind);

/* The key's value in o, as a double. */
double rt_key_get(const rt_key *k, const object *o);
/* Stores v (already checked) in o. */
bool rt_key_set(const rt_key *k, object *o, double v);
/* The n numbers (2 for RT_KEY_PAIR, 3 for RT_KEY_RGB) of a key; setting
 * is false only when out of memory (a new PBR block). */
void rt_key_get_n(const rt_key *k, const object *o, double *v, int n);
bool rt_key_set_n(const rt_key *k, object *o, const double *v, int n);

/* Numbers are read and written in the "C" locale whatever the program's
 * locale is: rt_numloc_enter switches the calling thread, leave restores. */
typedef struct rt_numloc {
	locale_t c, old;
} rt_numloc;
void rt_numloc_enter(rt_numloc *l);
void rt_numloc_leave(rt_numloc *l);

/* True when name ends in ".rt" (strict mode asks for it). */
bool rt_name_is_rt(const char *name);

#endif
