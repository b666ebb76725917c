/* rtsh — the .rt writer: the scene model back to text that loads to an
 * identical scene (rtsh(5)).
 *
 * Each object is written in the short 42 form when that form loses nothing
 * and in the extended form otherwise; extension keys come from the same
 * table as the reader's (rt_keys), so a new key is written once it has a row.
 * Numbers are printed with the fewest digits (15, 16 or 17) that read back
 * to the same double, always in the "C" locale.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rtsh/image.h"
#include "rtsh/render.h"
#include "rtsh/rtfile.h"
#include "rtsh/settings.h"
#include "rtsh/shape.h"
#include "scene/rtfile_priv.h"

/* A bounded string builder: output is cut at size - 1 bytes, always
 * NUL-terminated. */
typedef struct sbuf {
	char *buf;
	size_t size, len;
} sbuf;

static sbuf sb_make(char *buf, size_t size)
{
	if (size)
		buf[0] = '\0';
	return (sbuf){buf, size, 0};
}

static void sb_put(sbuf *b, const char *s)
{
	if (b->size == 0)
		return;
	size_t n = strlen(s);
	size_t room = b->size - 1 - b->len;
	if (n > room)
		n = room;
	memcpy(b->buf + b->len, s, n);
	b->len += n;
	b->buf[b->len] = '\0';
}

static void sb_num(sbuf *b, double v)
{
	char t[40];
	if (v == floor(v) && fabs(v) < 1e15) { /* whole numbers (colours): exact, and fast */
		snprintf(t, sizeof t, "%s%lld", signbit(v) && v == 0 ? "-" : "", (long long)v);
		sb_put(b, t);
		return;
	}
	for (int prec = 15; prec <= 17; prec++) {
		snprintf(t, sizeof t, "%.*g", prec, v);
		if (strtod(t, NULL) == v)
			break;
	}
	sb_put(b, t);
}

/* " " then the number */
static void sb_field(sbuf *b, double v)
{
	sb_put(b, " ");
	sb_num(b, v);
}

static void sb_vec(sbuf *b, vec3 v)
{
	sb_field(b, v.x);
	sb_put(b, ",");
	sb_num(b, v.y);
	sb_put(b, ",");
	sb_num(b, v.z);
}

static bool base_material_default(const material *m)
{
	material d = material_default(m->color);
	return m->diffuse == d.diffuse && m->specular == d.specular && m->shininess == d.shininess &&
	       m->reflective == d.reflective;
}

static bool has_shear(const object *o)
{
	for (int i = 0; i < 6; i++)
		if (o->shear[i] != 0)
			return true;
	return false;
}

/* The sizes of o's short form f, when f reads back to exactly o: no twist,
 * shear or material beyond the default, a direction only if f has one,
 * and sizes the form can say (shape.h). */
static bool short_form_ok(const object *o, const shape_form *f, double *sizes)
{
	if (!f->id || !f->nfields || o->twist != 0 || has_shear(o) ||
	    (!f->material && !base_material_default(&o->mat)))
		return false;
	if (!strchr(f->types, 'd') && !v3_eq(o->dir, v3(0, 1, 0)))
		return false;
	return f->write(o, sizes);
}

static void fmt_material(sbuf *b, const material *m)
{
	sb_field(b, m->diffuse);
	sb_field(b, m->specular);
	sb_field(b, m->shininess);
	sb_field(b, m->reflective);
}

_Thread_local const char *rt_write_dir = "";

/* A model or texture name as the file being written should say it:
 * relative to its folder when it lies below it, else as stored (and made
 * absolute when a relative name would not be found from the new folder). */
void rt_write_file_name(const char *file, char *out, size_t size)
{
	char abs[4096];
	const char *dir = rt_write_dir ? rt_write_dir : "";
	size_t n = strlen(dir);
	const char *name = file;
	if (n && strncmp(file, dir, n) == 0 && file[n] == '/')
		name = file + n + 1;
	else if (n && file[0] != '/' && realpath(file, abs))
		name = strncmp(abs, dir, n) == 0 && abs[n] == '/' ? abs + n + 1 : abs; /* below it after all */
	bool quote = strpbrk(name, " \t,#\"=") != NULL || strstr(name, "//") != NULL || !name[0]; /* = : not a key */
	snprintf(out, size, "%s%s%s", quote ? "\"" : "", name, quote ? "\"" : "");
}

static void sb_file(sbuf *b, const char *file)
{
	char name[4200];
	rt_write_file_name(file, name, sizeof name);
	sb_put(b, name);
}

/* " NAME=A,B[,C]": a key whose value is a list of numbers. */
static void sb_key_list(sbuf *b, const char *name, const double *v, int n)
{
	sb_put(b, " ");
	sb_put(b, name);
	sb_put(b, "=");
	for (int i = 0; i < n; i++) {
		if (i)
			sb_put(b, ",");
		sb_num(b, v[i]);
	}
}

static void fmt_keys(sbuf *b, const object *o, bool short_form)
{
	for (size_t i = 0; i < rt_nkeys; i++) {
		const rt_key *k = &rt_keys[i];
		if (!rt_key_applies(k, o->kind))
			continue;
		if (k->type == RT_KEY_FILE) {
			const char *f = *(const char *const *)(const void *)((const char *)o + k->offset);
			if (!f)
				continue;
			sb_put(b, " ");
			sb_put(b, k->name);
			sb_put(b, "=");
			sb_file(b, f);
			continue;
		}
		if (k->type == RT_KEY_RGB) {
			double c[3];
			rt_key_get_n(k, o, c, 3);
			if (c[0] == k->def && c[1] == k->def && c[2] == k->def)
				continue;
			sb_key_list(b, k->name, c, 3);
			continue;
		}
		if (k->type == RT_KEY_PAIR) {
			const double *uv = (const double *)(const void *)((const char *)o + k->offset);
			if (uv[0] == k->def && uv[1] == k->def)
				continue;
			sb_key_list(b, k->name, uv, 2);
			continue;
		}
		double v = rt_key_get(k, o);
		if (v == k->def || !rt_key_applies(k, o->kind) || (short_form && k->in_short))
			continue;
		sb_put(b, " ");
		sb_put(b, k->name);
		sb_put(b, "=");
		sb_num(b, v);
	}
}

static void fmt_object(sbuf *b, const object *o, bool extended)
{
	const material *m = &o->mat;
	const shape_kind *d = o->kind < OBJ_KIND_COUNT ? shape_kinds[o->kind] : NULL;
	double sizes[4];
	const shape_form *f = NULL;
	if (obj_kind_flags(o->kind) & KIND_MODEL) {
		sb_put(b, obj_kind_id(o->kind));
		sb_put(b, " ");
		sb_file(b, o->file ? o->file : "");
		sb_vec(b, o->pos);
		sb_vec(b, o->dir);
		if (o->scale.x == o->scale.y && o->scale.y == o->scale.z)
			sb_field(b, o->scale.x);
		else
			sb_vec(b, o->scale);
		if (!o->file_colors) {
			sb_vec(b, m->color);
			if (!base_material_default(m))
				fmt_material(b, m);
		}
	} else if (obj_kind_flags(o->kind) & KIND_VERTICES) {
		sb_put(b, d->form.id);
		for (int i = 0; i < 3; i++)
			sb_vec(b, o->tri[i]);
		sb_vec(b, m->color);
		if (!base_material_default(m))
			fmt_material(b, m);
	} else if (!extended &&
	           (short_form_ok(o, f = &d->form, sizes) || short_form_ok(o, f = &d->alias, sizes))) {
		sb_put(b, f->id);
		size_t ns = 0;
		for (int i = 0; i < f->nfields; i++) {
			if (f->types[i] == 'p')
				sb_vec(b, o->pos);
			else if (f->types[i] == 'd')
				sb_vec(b, o->dir);
			else
				sb_field(b, sizes[ns++]);
		}
		sb_vec(b, m->color);
		if (f->material && !base_material_default(m))
			fmt_material(b, m);
	} else {
		f = NULL;
		sb_put(b, d->form.extended ? d->form.id : d->alias.id);
		sb_vec(b, o->pos);
		sb_vec(b, o->dir);
		sb_vec(b, o->scale);
		sb_vec(b, m->color);
		fmt_material(b, m);
		if (has_shear(o)) {
			sb_put(b, " ");
			for (int i = 0; i < 6; i++) {
				if (i)
					sb_put(b, ",");
				sb_num(b, o->shear[i]);
			}
		}
	}
	fmt_keys(b, o, f != NULL);
}

static void fmt_light(sbuf *b, const light *l)
{
	sb_put(b, "L");
	sb_vec(b, l->pos);
	sb_field(b, l->ratio);
	sb_vec(b, l->color);
	if (l->kind == LIGHT_MINIRT)
		return;
	sb_put(b, l->kind == LIGHT_SUN ? " lux=" : " cd=");
	sb_num(b, l->intensity);
	if (l->kind != LIGHT_POINT) {
		sb_put(b, " dir=");
		sb_num(b, l->dir.x);
		sb_put(b, ",");
		sb_num(b, l->dir.y);
		sb_put(b, ",");
		sb_num(b, l->dir.z);
	}
	if (l->kind == LIGHT_SPOT) {
		sb_put(b, " cone=");
		sb_num(b, l->inner);
		sb_put(b, ",");
		sb_num(b, l->outer);
	}
	if (l->kind != LIGHT_SUN && l->range > 0) {
		sb_put(b, " range=");
		sb_num(b, l->range);
	}
}

static void fmt_camera(sbuf *b, const camera *c, const char *id)
{
	sb_put(b, id);
	sb_vec(b, c->pos);
	sb_vec(b, c->dir);
	sb_field(b, c->fov);
	if (c->vertical)
		sb_put(b, " vertical=1");
	if (c->ortho > 0) {
		sb_put(b, " ortho=");
		sb_num(b, c->ortho);
	}
	if (c->roll != 0) {
		sb_put(b, " roll=");
		sb_num(b, c->roll);
	}
}

/* One element's line into buf, its numbers in the "C" locale: the object o
 * (ext: in the extended form), else the light l, else the camera c. */
static void format_one(char *buf, size_t size, const object *o, bool ext, const light *l, const camera *c)
{
	rt_numloc loc;
	rt_numloc_enter(&loc);
	sbuf b = sb_make(buf, size);
	if (o)
		fmt_object(&b, o, ext);
	else if (l)
		fmt_light(&b, l);
	else
		fmt_camera(&b, c, "C");
	rt_numloc_leave(&loc);
}

void rt_format_object(const object *o, char *buf, size_t size)
{
	format_one(buf, size, o, false, NULL, NULL);
}

void rt_format_object_extended(const object *o, char *buf, size_t size)
{
	format_one(buf, size, o, true, NULL, NULL);
}

void rt_format_light(const light *l, char *buf, size_t size)
{
	format_one(buf, size, NULL, false, l, NULL);
}

void rt_format_camera(const camera *c, char *buf, size_t size)
{
	format_one(buf, size, NULL, false, NULL, c);
}

/* Longer than any line the formatters make. */
#define LINE_MAX_LEN 2048

static void put_line(FILE *f, sbuf *b)
{
	fputs(b->buf, f);
	fputc('\n', f);
	*b = sb_make(b->buf, b->size);
}

static void write_scene(const scene *s, FILE *f)
{
	char line[LINE_MAX_LEN];
	sbuf b = sb_make(line, sizeof line);
	fputs("# rtsh scene (the format is described in rtsh(5))\n", f);
	const scene_hints *h = &s->hints;
	if (h->width > 0 && h->height > 0)
		fprintf(f, "R %d %d\n", h->width, h->height);
	if (h->samples > 0)
		fprintf(f, "set samples %d\n", h->samples);
	if (h->depth >= 0)
		fprintf(f, "set depth %d\n", h->depth);
	if (h->mode >= 0 && h->mode < MODE_COUNT)
		fprintf(f, "set mode %s\n", render_mode_name((render_mode)h->mode));
	for (size_t i = 0; i < settings_count; i++) /* the other kept settings, in the table's order */
		if (settings_kept_slot(&settings_table[i]) && h->kept[i][0])
			fprintf(f, "set %s %s\n", settings_table[i].name, h->kept[i]);
	if (s->has_ambient) {
		sb_put(&b, "A");
		sb_field(&b, s->amb.ratio);
		sb_vec(&b, s->amb.color);
		put_line(f, &b);
	}
	for (size_t i = 0; i < s->ncams; i++) {
		fmt_camera(&b, &s->cams[i], i == 0 ? "C" : "c");
		put_line(f, &b);
	}
	for (size_t i = 0; i < s->nlights; i++) {
		fmt_light(&b, &s->lights[i]);
		put_line(f, &b);
	}
	if (s->has_sky && s->sky.file) {
		sb_put(&b, "sky ");
		sb_file(&b, s->sky.file);
		if (s->sky.strength != 1 || s->sky.rotation != 0)
			sb_field(&b, s->sky.strength);
		if (s->sky.rotation != 0)
			sb_field(&b, s->sky.rotation);
		put_line(f, &b);
	} else if (s->has_sky) {
		sb_put(&b, "sky");
		sb_vec(&b, s->sky.zenith);
		sb_vec(&b, s->sky.horizon);
		if (s->sky.strength != 1)
			sb_field(&b, s->sky.strength);
		put_line(f, &b);
	}
	for (size_t i = 0; i < s->nobjs; i++) {
		fmt_object(&b, &s->objs[i], false);
		put_line(f, &b);
	}
}

bool rt_write(const scene *s, FILE *f, rt_error *err)
{
	rt_numloc loc;
	rt_numloc_enter(&loc);
	errno = 0;
	write_scene(s, f);
	rt_numloc_leave(&loc);
	if (fflush(f) != 0 || ferror(f))
		return rt_error_set(err, "cannot write the scene: %s",
		                    errno ? strerror(errno) : "write error");
	return true;
}

typedef struct save_ctx {
	const scene *s;
} save_ctx;

static bool save_writer(FILE *f, void *ctx, rt_error *err)
{
	const save_ctx *c = ctx;
	return rt_write(c->s, f, err);
}

bool rt_save_in_folder(const char *path, bool no_dot, file_writer_fn write, void *ctx, rt_error *err)
{
	char dir[4096] = "";
	const char *slash = strrchr(path, '/');
	if (slash) {
		size_t n = slash == path ? 1 : (size_t)(slash - path);
		if (n < sizeof dir) {
			memcpy(dir, path, n);
			dir[n] = '\0';
		}
	}
	const char *old = rt_write_dir;
	rt_write_dir = no_dot && strcmp(dir, ".") == 0 ? "" : dir;
	bool ok = file_write_atomic(path, write, ctx, err);
	rt_write_dir = old;
	return ok;
}

bool rt_save(const scene *s, const char *path, rt_error *err)
{
	save_ctx c = {s};
	/* file names below the new file's folder are written relative to it */
	return rt_save_in_folder(path, true, save_writer, &c, err);
}
