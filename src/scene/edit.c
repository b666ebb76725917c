/* rtsh — the scene-edit API with undo (edit.h).
 *
 * Every edit is a record that describes the new state of one element; apply()
 * swaps it into the scene, leaving the record holding the old state, that is
 * the inverse edit. Undo and redo are the same operation: apply the record on
 * top of one stack and push it on the other.
 */
#include "rtsh/edit.h"

#include <stdlib.h>
#include <string.h>

#include "rtsh/memory.h"
#include "rtsh/num.h"
#include "rtsh/texture.h"
#include "rtsh/world.h"
#include "scene/rtfile_priv.h"

typedef enum rec_kind {
	REC_OBJECT,        /* replace object idx by u.obj */
	REC_LIGHT,         /* replace light idx by u.li */
	REC_CAMERA,        /* replace camera idx by u.cam */
	REC_AMBIENT,       /* replace (has_ambient, amb) */
	REC_SKY,           /* replace (has_sky, sky) */
	REC_HINTS,         /* replace the hints */
	REC_SELECT,        /* make camera idx active */
	REC_INSERT_OBJECT, /* insert u.obj at idx */
	REC_REMOVE_OBJECT, /* remove object idx */
	REC_INSERT_LIGHT,
	REC_REMOVE_LIGHT,
	REC_INSERT_CAMERA, /* insert u.cam at idx, make camera `active` active */
	REC_REMOVE_CAMERA, /* remove camera idx (keeps the active one in `active`) */
	REC_SCENE,         /* swap the whole scene with u.sc */
} rec_kind;

typedef struct record {
	rec_kind kind;
	uint64_t group;
	char *note;    /* what the step did, for "undone: ..." (editor_note); or NULL */
	size_t idx;
	size_t active;
	bool has;
	union {
		object obj;
		light li;
		camera cam;
		ambient amb;
		sky sk;
		scene_hints hints;
		struct {
			scene *s;
			char *label;
		} sc;
	} u;
} record;

typedef struct stack {
	record *r;
	size_t n, cap;
} stack;

struct editor {
	scene *s;
	char *label;
	uint64_t gen;
	stack undo, redo;
	uint64_t group_seq; /* the last group id handed out */
	uint64_t group;     /* the open group's id while depth > 0 */
	int depth;
	/* What this editor told mem_hold it holds: its scenes' bytes and count. */
	double held;
	long held_scenes;
};

/* Tells the memory estimates (memory.h) what the editor holds now: the
 * current scene and every whole scene in its undo and redo history. */
static void account(editor *ed)
{
	double bytes = (double)scene_bytes(ed->s);
	long n = 1;
	const stack *sts[] = {&ed->undo, &ed->redo};
	for (int k = 0; k < 2; k++)
		for (size_t i = 0; i < sts[k]->n; i++)
			if (sts[k]->r[i].kind == REC_SCENE) {
				bytes += (double)scene_bytes(sts[k]->r[i].u.sc.s);
				n++;
			}
	mem_hold(bytes - ed->held, n - ed->held_scenes);
	ed->held = bytes;
	ed->held_scenes = n;
}

static char *dup_label(const char *label, bool *ok)
{
	if (!label)
		return NULL;
	char *p = strdup(label);
	if (!p)
		*ok = false;
	return p;
}

editor *editor_new(scene *s, const char *label)
{
	editor *ed = calloc(1, sizeof *ed);
	if (!ed)
		return NULL;
	bool ok = true;
	ed->label = dup_label(label, &ok);
	if (!ok) {
		free(ed);
		return NULL;
	}
	ed->s = s;
	ed->gen = 1;
	account(ed);
	return ed;
}

static void record_release(record *r)
{
	free(r->note);
	r->note = NULL;
	if (r->kind == REC_SCENE) {
		scene_free(r->u.sc.s);
		free(r->u.sc.label);
	}
}

static void stack_clear(stack *st)
{
	for (size_t i = 0; i < st->n; i++)
		record_release(&st->r[i]);
	st->n = 0;
}

void editor_free(editor *ed)
{
	if (!ed)
		return;
	mem_hold(-ed->held, -ed->held_scenes);
	stack_clear(&ed->undo);
	stack_clear(&ed->redo);
	free(ed->undo.r);
	free(ed->redo.r);
	scene_free(ed->s);
	free(ed->label);
	free(ed);
}

const scene *editor_scene(const editor *ed)
{
	return ed->s;
}

const char *editor_label(const editor *ed)
{
	return ed->label;
}

uint64_t editor_generation(const editor *ed)
{
	return ed->gen;
}

size_t editor_undo_count(const editor *ed)
{
	size_t n = 0;
	for (size_t i = 0; i < ed->undo.n; i++)
		n += i == 0 || ed->undo.r[i].group != ed->undo.r[i - 1].group;
	return n;
}

size_t editor_redo_count(const editor *ed)
{
	size_t n = 0;
	for (size_t i = 0; i < ed->redo.n; i++)
		n += i == 0 || ed->redo.r[i].group != ed->redo.r[i - 1].group;
	return n;
}

void editor_group_begin(editor *ed)
{
	if (ed->depth++ == 0)
		ed->group = ++ed->group_seq;
}

void editor_group_end(editor *ed)
{
	if (ed->depth > 0)
		ed->depth--;
}

static bool object_check(const object *o, rt_error *err)
{
	return object_rules(o, err);
}

/* --- applying records --- */

static bool insert_camera(scene *s, size_t i, const camera *c, rt_error *err)
{
	if (!scene_add_camera(s, c, err))
		return false;
	if (i < s->ncams - 1) {
		memmove(&s->cams[i + 1], &s->cams[i], (s->ncams - 1 - i) * sizeof *s->cams);
		s->cams[i] = *c;
	}
	return true;
}

static void remove_camera(scene *s, size_t i)
{
	memmove(&s->cams[i], &s->cams[i + 1], (s->ncams - i - 1) * sizeof *s->cams);
	s->ncams--;
	if (s->cam > i)
		s->cam--;
	else if (s->cam == i)
		s->cam = 0;
}

/* Applies r to the scene and turns r into its inverse. Only inserting can
 * fail (out of memory), leaving both unchanged. */
static bool apply(editor *ed, record *r, rt_error *err)
{
	scene *s = ed->s;
	switch (r->kind) {
	case REC_OBJECT: {
		object t = s->objs[r->idx];
		s->objs[r->idx] = r->u.obj;
		r->u.obj = t;
		break;
	}
	case REC_LIGHT: {
		light t = s->lights[r->idx];
		s->lights[r->idx] = r->u.li;
		r->u.li = t;
		break;
	}
	case REC_CAMERA: {
		camera t = s->cams[r->idx];
		s->cams[r->idx] = r->u.cam;
		r->u.cam = t;
		break;
	}
	case REC_AMBIENT: {
		ambient t = s->amb;
		bool h = s->has_ambient;
		s->amb = r->u.amb;
		s->has_ambient = r->has;
		r->u.amb = t;
		r->has = h;
		break;
	}
	case REC_SKY: {
		sky t = s->sky;
		bool h = s->has_sky;
		s->sky = r->u.sk;
		s->has_sky = r->has;
		r->u.sk = t;
		r->has = h;
		break;
	}
	case REC_HINTS: {
		scene_hints t = s->hints;
		s->hints = r->u.hints;
		r->u.hints = t;
		break;
	}
	case REC_SELECT: {
		size_t t = s->cam;
		s->cam = r->idx;
		r->idx = t;
		break;
	}
	case REC_INSERT_OBJECT:
		if (!scene_insert_object(s, r->idx, &r->u.obj, err))
			return false;
		r->kind = REC_REMOVE_OBJECT;
		break;
	case REC_REMOVE_OBJECT:
		r->u.obj = s->objs[r->idx];
		scene_remove_object(s, r->idx);
		r->kind = REC_INSERT_OBJECT;
		break;
	case REC_INSERT_LIGHT:
		if (!scene_insert_light(s, r->idx, &r->u.li, err))
			return false;
		r->kind = REC_REMOVE_LIGHT;
		break;
	case REC_REMOVE_LIGHT:
		r->u.li = s->lights[r->idx];
		scene_remove_light(s, r->idx);
		r->kind = REC_INSERT_LIGHT;
		break;
	case REC_INSERT_CAMERA: {
		size_t was = s->cam;
		if (!insert_camera(s, r->idx, &r->u.cam, err))
			return false;
		s->cam = r->active;
		r->active = was;
		r->kind = REC_REMOVE_CAMERA;
		break;
	}
	case REC_REMOVE_CAMERA: {
		size_t was = s->cam;
		r->u.cam = s->cams[r->idx];
		remove_camera(s, r->idx);
		r->active = was;
		r->kind = REC_INSERT_CAMERA;
		break;
	}
	case REC_SCENE: {
		scene *t = ed->s;
		char *l = ed->label;
		ed->s = r->u.sc.s;
		ed->label = r->u.sc.label;
		r->u.sc.s = t;
		r->u.sc.label = l;
		break;
	}
	}
	ed->gen++;
	return true;
}

/* Makes room for one more record. */
static bool stack_reserve(stack *st, rt_error *err)
{
	if (st->n < st->cap)
		return true;
	size_t cap = st->cap ? st->cap * 2 : 16;
	record *p = realloc(st->r, cap * sizeof *p);
	if (!p)
		return rt_error_set(err, "out of memory recording the edit");
	st->r = p;
	st->cap = cap;
	return true;
}

/* Forgets the oldest undo group. */
static void drop_oldest(stack *st)
{
	size_t k = 1;
	while (k < st->n && st->r[k].group == st->r[0].group)
		k++;
	for (size_t i = 0; i < k; i++)
		record_release(&st->r[i]);
	memmove(st->r, st->r + k, (st->n - k) * sizeof *st->r);
	st->n -= k;
}

static size_t scenes_held(const stack *st)
{
	size_t n = 0;
	for (size_t i = 0; i < st->n; i++)
		n += st->r[i].kind == REC_SCENE;
	return n;
}

/* Applies a new edit and records its inverse for undo. */
static bool commit(editor *ed, record *r, rt_error *err)
{
	/* Room first, so that an applied edit is always recorded. */
	if (!stack_reserve(&ed->undo, err))
		return false;
	r->group = ed->depth > 0 ? ed->group : ++ed->group_seq;
	if (!apply(ed, r, err))
		return false;
	stack_clear(&ed->redo);
	ed->undo.r[ed->undo.n++] = *r;
	while (editor_undo_count(ed) > EDITOR_MAX_UNDO || scenes_held(&ed->undo) > EDITOR_MAX_SCENES)
		drop_oldest(&ed->undo);
	account(ed);
	return true;
}

/* The note of the group on top of st, or NULL. */
static const char *top_note(const stack *st)
{
	if (st->n == 0)
		return NULL;
	uint64_t g = st->r[st->n - 1].group;
	for (size_t i = st->n; i > 0 && st->r[i - 1].group == g; i--)
		if (st->r[i - 1].note)
			return st->r[i - 1].note;
	return NULL;
}

bool editor_note(editor *ed, const char *text)
{
	if (ed->undo.n == 0 || top_note(&ed->undo))
		return false;
	record *r = &ed->undo.r[ed->undo.n - 1];
	r->note = strdup(text);
	return r->note != NULL;
}

const char *editor_undo_note(const editor *ed)
{
	return top_note(&ed->undo);
}

const char *editor_redo_note(const editor *ed)
{
	return top_note(&ed->redo);
}

/* Moves one group from `from` to `to`, applying each record. */
static bool replay(editor *ed, stack *from, stack *to, const char *what, rt_error *err)
{
	if (from->n == 0)
		return rt_error_set(err, "nothing to %s", what);
	uint64_t g = from->r[from->n - 1].group;
	while (from->n > 0 && from->r[from->n - 1].group == g) {
		record r = from->r[from->n - 1];
		if (!stack_reserve(to, err) || !apply(ed, &r, err)) {
			account(ed);
			return false;
		}
		from->n--;
		to->r[to->n++] = r;
	}
	account(ed);
	return true;
}

bool editor_undo(editor *ed, rt_error *err)
{
	return replay(ed, &ed->undo, &ed->redo, "undo", err);
}

bool editor_redo(editor *ed, rt_error *err)
{
	return replay(ed, &ed->redo, &ed->undo, "redo", err);
}

/* --- edits --- */

static bool index_ok(size_t i, size_t n, const char *what, rt_error *err)
{
	if (i >= n) {
		if (n == 0)
			return rt_error_set(err, "there is no %s %zu; the scene has no %ss", what, i + 1, what);
		return rt_error_set(err, "there is no %s %zu; expected 1..%zu", what, i + 1, n);
	}
	return true;
}

bool editor_set_object(editor *ed, size_t i, const object *o, rt_error *err)
{
	if (!index_ok(i, ed->s->nobjs, "object", err) || !object_check(o, err))
		return false;
	record r = {.kind = REC_OBJECT, .idx = i, .u.obj = *o};
	return commit(ed, &r, err);
}

bool editor_set_light(editor *ed, size_t i, const light *l, rt_error *err)
{
	if (!index_ok(i, ed->s->nlights, "light", err) || !light_validate(l, err))
		return false;
	record r = {.kind = REC_LIGHT, .idx = i, .u.li = *l};
	return commit(ed, &r, err);
}

bool editor_set_camera(editor *ed, size_t i, const camera *c, rt_error *err)
{
	if (!camera_validate(c, err))
		return false;
	if (ed->s->ncams == 0 && i == 0)
		return editor_add_camera(ed, c, err);
	if (!index_ok(i, ed->s->ncams, "camera", err))
		return false;
	record r = {.kind = REC_CAMERA, .idx = i, .u.cam = *c};
	return commit(ed, &r, err);
}

bool editor_set_ambient(editor *ed, const ambient *a, rt_error *err)
{
	if (!ambient_validate(a, err))
		return false;
	record r = {.kind = REC_AMBIENT, .has = true, .u.amb = *a};
	return commit(ed, &r, err);
}

bool editor_set_sky(editor *ed, bool has, const sky *sk, rt_error *err)
{
	record r = {.kind = REC_SKY, .has = has};
	if (has) {
		if (!sky_validate(sk, err))
			return false;
		r.u.sk = *sk;
	} else {
		r.u.sk = ed->s->sky;
	}
	return commit(ed, &r, err);
}

bool editor_select_camera(editor *ed, size_t i, rt_error *err)
{
	if (!index_ok(i, ed->s->ncams, "camera", err))
		return false;
	record r = {.kind = REC_SELECT, .idx = i};
	return commit(ed, &r, err);
}

bool editor_insert_object(editor *ed, size_t i, const object *o, rt_error *err)
{
	if (i > ed->s->nobjs)
		i = ed->s->nobjs;
	if (!object_check(o, err))
		return false;
	record r = {.kind = REC_INSERT_OBJECT, .idx = i, .u.obj = *o};
	return commit(ed, &r, err);
}

bool editor_insert_light(editor *ed, size_t i, const light *l, rt_error *err)
{
	if (i > ed->s->nlights)
		i = ed->s->nlights;
	if (!light_validate(l, err))
		return false;
	record r = {.kind = REC_INSERT_LIGHT, .idx = i, .u.li = *l};
	return commit(ed, &r, err);
}

bool editor_add_camera(editor *ed, const camera *c, rt_error *err)
{
	if (!camera_validate(c, err))
		return false;
	record r = {.kind = REC_INSERT_CAMERA, .idx = ed->s->ncams, .active = ed->s->cam, .u.cam = *c};
	return commit(ed, &r, err);
}

bool editor_delete_object(editor *ed, size_t i, rt_error *err)
{
	if (!index_ok(i, ed->s->nobjs, "object", err))
		return false;
	record r = {.kind = REC_REMOVE_OBJECT, .idx = i};
	return commit(ed, &r, err);
}

bool editor_delete_light(editor *ed, size_t i, rt_error *err)
{
	if (!index_ok(i, ed->s->nlights, "light", err))
		return false;
	record r = {.kind = REC_REMOVE_LIGHT, .idx = i};
	return commit(ed, &r, err);
}

bool editor_delete_camera(editor *ed, size_t i, rt_error *err)
{
	if (!index_ok(i, ed->s->ncams, "camera", err))
		return false;
	if (ed->s->ncams == 1)
		return rt_error_set(err, "camera %zu is the only camera; a scene needs one", i + 1);
	record r = {.kind = REC_REMOVE_CAMERA, .idx = i};
	return commit(ed, &r, err);
}

bool editor_replace(editor *ed, scene *s, const char *label, rt_error *err)
{
	bool ok = true;
	record r = {.kind = REC_SCENE, .u.sc = {s, dup_label(label, &ok)}};
	if (!ok || !commit(ed, &r, err)) {
		if (!ok)
			rt_error_set(err, "out of memory");
		scene_free(s);
		free(r.u.sc.label);
		return false;
	}
	return true;
}

/* The first word of a .rt line. */
static void first_word(const char *line, char *buf, size_t size)
{
	while (*line == ' ' || *line == '\t')
		line++;
	size_t n = 0;
	while (line[n] && line[n] != ' ' && line[n] != '\t' && n + 1 < size) {
		buf[n] = line[n];
		n++;
	}
	buf[n] = '\0';
}

bool editor_add_line(editor *ed, const char *line, const char *name, int lineno,
                     const rt_load_opts *opts, rt_error *err)
{
	scene *t = scene_new();
	if (!t)
		return rt_error_set(err, "out of memory");
	if (!rt_parse_line(t, line, name, lineno, opts, err)) {
		scene_free(t);
		return false;
	}
	char id[16];
	first_word(line, id, sizeof id);
	bool ok = true;
	size_t before = ed->undo.n;
	editor_group_begin(ed);
	for (size_t i = 0; ok && i < t->nobjs; i++)
		ok = editor_insert_object(ed, ed->s->nobjs, &t->objs[i], err);
	for (size_t i = 0; ok && i < t->nlights; i++)
		ok = editor_insert_light(ed, ed->s->nlights, &t->lights[i], err);
	for (size_t i = 0; ok && i < t->ncams; i++) {
		if (strcmp(id, "C") == 0 && ed->s->ncams > 0)
			ok = editor_set_camera(ed, ed->s->cam, &t->cams[i], err);
		else
			ok = editor_add_camera(ed, &t->cams[i], err);
	}
	if (ok && t->has_ambient) {
		ok = editor_set_ambient(ed, &t->amb, err);
	}
	if (ok && t->has_sky) {
		ok = editor_set_sky(ed, true, &t->sky, err);
	}
	scene_hints h = ed->s->hints, n = t->hints;
	if (n.width > 0 && n.height > 0) {
		h.width = n.width;
		h.height = n.height;
	}
	if (n.samples > 0)
		h.samples = n.samples;
	if (n.depth >= 0)
		h.depth = n.depth;
	if (n.mode >= 0)
		h.mode = n.mode;
	for (size_t i = 0; i < SCENE_KEPT_MAX; i++)
		if (n.kept[i][0])
			memcpy(h.kept[i], n.kept[i], sizeof h.kept[i]);
	if (ok && memcmp(&h, &ed->s->hints, sizeof h) != 0) {
		record r = {.kind = REC_HINTS, .u.hints = h};
		ok = commit(ed, &r, err);
	}
	editor_group_end(ed);
	scene_free(t);
	if (!ok) {
		/* Roll back what this line already did (undoing never needs memory
		 * here: only inserts were made, and removing cannot fail). */
		while (ed->undo.n > before) {
			record *r = &ed->undo.r[--ed->undo.n];
			apply(ed, r, NULL);
			record_release(r);
		}
		account(ed);
		return false;
	}
	return true;
}

/* --- verbs --- */

static bool get_object(editor *ed, size_t i, object *o, rt_error *err)
{
	if (!index_ok(i, ed->s->nobjs, "object", err))
		return false;
	*o = ed->s->objs[i];
	return true;
}

bool editor_object_move(editor *ed, size_t i, vec3 d, rt_error *err)
{
	object o;
	if (!get_object(ed, i, &o, err))
		return false;
	if (!v3_finite(d))
		return rt_error_set(err, "move is not finite; expected numbers");
	object_move(&o, d);
	return editor_set_object(ed, i, &o, err);
}

bool editor_object_rotate(editor *ed, size_t i, vec3 deg, rt_error *err)
{
	object o;
	return get_object(ed, i, &o, err) && object_rotate(&o, deg, err) &&
	       editor_set_object(ed, i, &o, err);
}

bool editor_object_scale(editor *ed, size_t i, vec3 f, rt_error *err)
{
	object o;
	return get_object(ed, i, &o, err) && object_scale(&o, f, err) &&
	       editor_set_object(ed, i, &o, err);
}

bool editor_object_color(editor *ed, size_t i, vec3 rgb, rt_error *err)
{
	object o;
	if (!get_object(ed, i, &o, err))
		return false;
	o.mat.color = rgb;
	return editor_set_object(ed, i, &o, err);
}

bool editor_object_set_key(editor *ed, size_t i, const char *assignment, rt_error *err)
{
	object o;
	if (!get_object(ed, i, &o, err))
		return false;
	const char *eq = strchr(assignment, '=');
	size_t nlen = eq ? (size_t)(eq - assignment) : strlen(assignment);
	const rt_key *k = NULL;
	for (size_t j = 0; j < rt_nkeys && !k; j++)
		if (strlen(rt_keys[j].name) == nlen && strncmp(rt_keys[j].name, assignment, nlen) == 0)
			k = &rt_keys[j];
	if (!k || !eq || !rt_key_applies(k, o.kind)) {
		char list[1024] = "";
		size_t used = 0;
		for (size_t j = 0; j < rt_nkeys; j++)
			if (used < sizeof list && rt_key_applies(&rt_keys[j], o.kind))
				used += (size_t)snprintf(list + used, sizeof list - used, "%s%s=",
				                         used ? " " : "", rt_keys[j].name);
		return rt_error_set(err, "\"%s\" is %s; expected KEY=VALUE with one of %s", assignment,
		                    !eq ? "not KEY=VALUE" : !k ? "an unknown key" : "a key this object does not take",
		                    list);
	}
	if (k->type == RT_KEY_FILE) {
		/* An image file, read now (once, by the cache) so that a bad one
		 * is refused here and not at the next render. */
		const char *name = eq + 1;
		if (!*name)
			return rt_error_set(err, "\"%s\": the file name is empty; expected %s", assignment, k->expect);
		rt_error ferr;
		rt_error_clear(&ferr);
		texture *tx = texture_cache_get(name, strcmp(k->name, "texture") == 0, NULL, &ferr);
		if (!tx) {
			char msg[RT_ERROR_MSG_MAX + RT_ERROR_FILE_MAX + 32];
			rt_error_format(&ferr, msg, sizeof msg);
			return rt_error_set(err, "\"%s\": %s", assignment, msg);
		}
		texture_cache_put(tx);
		const char *kept = rt_intern(name, strlen(name));
		if (!kept)
			return rt_error_set(err, "\"%s\": out of memory", assignment);
		memcpy((char *)&o + k->offset, &kept, sizeof kept);
		return editor_set_object(ed, i, &o, err);
	}
	if (k->type == RT_KEY_PAIR || k->type == RT_KEY_RGB) {
		/* U,V or R,G,B, each in the key's range. */
		int n = k->type == RT_KEY_PAIR ? 2 : 3;
		double c[3];
		const char *p = eq + 1;
		for (int j = 0; j < n; j++) {
			const char *end = j < n - 1 ? strchr(p, ',') : p + strlen(p);
			if (!end || num_scan(p, (size_t)(end - p), RT_NUM_MAX, &c[j]) != NUM_OK || c[j] < k->min ||
			    c[j] > k->max)
				return rt_error_set(err, "\"%s\" is not valid; expected %s", assignment, k->expect);
			p = end + 1;
		}
		if (strcmp(k->name, "uvscale") == 0 && (c[0] == 0 || c[1] == 0))
			return rt_error_set(err, "\"%s\" has a zero component; expected %s", assignment, k->expect);
		if (!rt_key_set_n(k, &o, c, n))
			return rt_error_set(err, "\"%s\": out of memory", assignment);
		return editor_set_object(ed, i, &o, err);
	}
	double v;
	if (num_scan_str(eq + 1, RT_NUM_MAX, &v) != NUM_OK || v < k->min || v > k->max ||
	    (k->is_int && v != floor(v)) || (k->extra && !k->extra(v)))
		return rt_error_set(err, "\"%s\" is out of range; expected %s", assignment, k->expect);
	if (!rt_key_set(k, &o, v))
		return rt_error_set(err, "\"%s\": out of memory", assignment);
	return editor_set_object(ed, i, &o, err);
}

static bool get_light(editor *ed, size_t i, light *l, rt_error *err)
{
	if (!index_ok(i, ed->s->nlights, "light", err))
		return false;
	*l = ed->s->lights[i];
	return true;
}

bool editor_light_pos(editor *ed, size_t i, vec3 p, rt_error *err)
{
	light l;
	if (!get_light(ed, i, &l, err))
		return false;
	l.pos = p;
	return editor_set_light(ed, i, &l, err);
}

bool editor_light_move(editor *ed, size_t i, vec3 d, rt_error *err)
{
	light l;
	if (!get_light(ed, i, &l, err))
		return false;
	/* In the decimals written (num_add_decimal): no drift. */
	l.pos = v3(num_add_decimal(l.pos.x, d.x), num_add_decimal(l.pos.y, d.y), num_add_decimal(l.pos.z, d.z));
	return editor_set_light(ed, i, &l, err);
}

bool editor_light_brightness(editor *ed, size_t i, double ratio, rt_error *err)
{
	light l;
	if (!get_light(ed, i, &l, err))
		return false;
	l.ratio = ratio;
	return editor_set_light(ed, i, &l, err);
}

bool editor_light_color(editor *ed, size_t i, vec3 rgb, rt_error *err)
{
	light l;
	if (!get_light(ed, i, &l, err))
		return false;
	l.color = rgb;
	return editor_set_light(ed, i, &l, err);
}

/* The active camera and its index (a scene without cameras gets the default). */
static size_t active_camera(const editor *ed, camera *c)
{
	*c = scene_camera(ed->s);
	return ed->s->cam < ed->s->ncams ? ed->s->cam : 0;
}

bool editor_camera_pos(editor *ed, vec3 p, rt_error *err)
{
	camera c;
	size_t i = active_camera(ed, &c);
	c.pos = p;
	return editor_set_camera(ed, i, &c, err);
}

bool editor_camera_dir(editor *ed, vec3 d, rt_error *err)
{
	camera c;
	size_t i = active_camera(ed, &c);
	c.dir = d;
	return editor_set_camera(ed, i, &c, err);
}

bool editor_camera_lookat(editor *ed, vec3 target, rt_error *err)
{
	camera c;
	size_t i = active_camera(ed, &c);
	vec3 d = v3_sub(target, c.pos);
	if (!v3_finite(d) || !(v3_len(d) > 0))
		return rt_error_set(err, "the point %g,%g,%g is where the camera is; expected another point",
		                    target.x, target.y, target.z);
	c.dir = v3_norm(d);
	return editor_set_camera(ed, i, &c, err);
}

bool editor_camera_fov(editor *ed, double deg, rt_error *err)
{
	camera c;
	size_t i = active_camera(ed, &c);
	if (c.ortho > 0) /* its fov is unused: a change would not show */
		return rt_error_set(err, "camera %zu is orthographic (ortho=%g, its half height): it has no field of view; "
		                         "expected a perspective camera (key mode's - and + zoom it)",
		                    i + 1, c.ortho);
	bool clamped; /* 0 and 180 as in files: clamped to the renderable ends */
	if (!fov_rule(&deg, &clamped, err))
		return false;
	c.fov = deg;
	return editor_set_camera(ed, i, &c, err);
}

bool editor_camera_move(editor *ed, vec3 d, rt_error *err)
{
	camera c;
	size_t i = active_camera(ed, &c);
	cam_view v = cam_view_make(&c);
	c.pos = v3_add(c.pos, v3_add(v3_scale(v.right, d.x), v3_add(v3_scale(v.up, d.y), v3_scale(v.fwd, d.z))));
	return editor_set_camera(ed, i, &c, err);
}

bool editor_camera_turn(editor *ed, double yaw_deg, double pitch_deg, rt_error *err)
{
	if (!isfinite(yaw_deg) || !isfinite(pitch_deg))
		return rt_error_set(err, "turn angles are not finite; expected degrees");
	camera c;
	size_t i = active_camera(ed, &c);
	/* Yaw turns about the world's vertical and pitch tilts towards the
	 * camera's up, as in a first-person view: the camera has no roll, so
	 * the elevation stays within EDIT_PITCH_LIMIT of the horizon (a camera
	 * loaded beyond it may only come back). */
	vec3 f = v3_norm(c.dir);
	double elev = asin(clampd(f.y, -1.0, 1.0)), lim = deg_to_rad(EDIT_PITCH_LIMIT);
	double ne = elev + deg_to_rad(pitch_deg);
	if (ne > lim)
		ne = fmax(elev, lim);
	if (ne < -lim)
		ne = fmin(elev, -lim);
	double az;
	if (fabs(f.y) > 0.999999) {
		/* Straight up or down: the heading is where the top of the
		 * picture points (looking up) or its bottom (looking down). */
		cam_view v = cam_view_make(&c);
		az = f.y > 0 ? atan2(-v.up.x, -v.up.z) : atan2(v.up.x, v.up.z);
	} else {
		az = atan2(f.x, f.z);
	}
	double na = az + deg_to_rad(yaw_deg);
	vec3 d = v3(cos(ne) * sin(na), sin(ne), cos(ne) * cos(na));
	if (ne == elev && fabs(f.y) > 0.999999)
		d = f; /* vertical, and staying so: a heading means nothing */
	if (v3_eq(d, f) || (ne == elev && yaw_deg == 0.0))
		return true; /* already as far as it goes: no edit */
	c.dir = d;
	return editor_set_camera(ed, i, &c, err);
}
