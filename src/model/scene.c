/* rtsh — the scene model (scene.h). */
#include "rtsh/scene.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rtsh/memory.h"
#include "rtsh/num.h"

static const struct {
	const char *id, *name;
	unsigned flags;
} kind_names[OBJ_KIND_COUNT] = {
#define RT_KIND(e, i, n, desc, f) [OBJ_##e] = {i, n, f},
#include "rtsh/kinds.def"
#undef RT_KIND
};

const char *obj_kind_id(obj_kind k)
{
	return (unsigned)k < OBJ_KIND_COUNT ? kind_names[k].id : "?";
}

const char *obj_kind_name(obj_kind k)
{
	return (unsigned)k < OBJ_KIND_COUNT ? kind_names[k].name : "object";
}

unsigned obj_kind_flags(obj_kind k)
{
	return (unsigned)k < OBJ_KIND_COUNT ? kind_names[k].flags : 0;
}

int obj_kind_from_id(const char *id)
{
	for (int k = 0; k < OBJ_KIND_COUNT; k++)
		if (strcmp(id, kind_names[k].id) == 0)
			return k;
	return -1;
}

material material_default(vec3 color)
{
	return (material){
		.color = color,
		.diffuse = 0.9,
		.specular = 0.9,
		.shininess = 200.0,
		.reflective = 0.0,
		.bumpscale = 1.0,
		.uvscale = {1.0, 1.0},
	};
}

material_pbr material_pbr_absent(void)
{
	return (material_pbr){
		.roughness = -1.0,
		.att_color = {255.0, 255.0, 255.0},
		.specular_factor = 1.0,
		.specular_color = {255.0, 255.0, 255.0},
		.emit_color = {-1.0, -1.0, -1.0},
		.multiscatter = 1,
	};
}

scene *scene_new(void)
{
	scene *s = calloc(1, sizeof(scene));
	if (s) {
		s->hints.depth = -1;
		s->hints.mode = -1;
	}
	return s;
}

void scene_free(scene *s)
{
	if (s)
		mem_free_all(s->cams, s->lights, s->objs, s);
}

size_t scene_bytes(const scene *s)
{
	return s ? sizeof *s + s->cap_cams * sizeof *s->cams + s->cap_lights * sizeof *s->lights +
	               s->cap_objs * sizeof *s->objs
	         : 0;
}

static void *dup_array(const void *p, size_t n, size_t size, bool *ok)
{
	if (n == 0)
		return NULL;
	void *q = malloc(n * size);
	if (!q) {
		*ok = false;
		return NULL;
	}
	memcpy(q, p, n * size);
	return q;
}

scene *scene_clone(const scene *s)
{
	scene *c = malloc(sizeof *c);
	if (!c)
		return NULL;
	*c = *s;
	bool ok = true;
	c->cams = dup_array(s->cams, s->ncams, sizeof *s->cams, &ok);
	c->lights = dup_array(s->lights, s->nlights, sizeof *s->lights, &ok);
	c->objs = dup_array(s->objs, s->nobjs, sizeof *s->objs, &ok);
	c->cap_cams = s->ncams;
	c->cap_lights = s->nlights;
	c->cap_objs = s->nobjs;
	if (!ok) {
		scene_free(c);
		return NULL;
	}
	return c;
}

static bool material_equal(const material *a, const material *b)
{
	return v3_eq(a->color, b->color) && a->diffuse == b->diffuse && a->specular == b->specular &&
	       a->shininess == b->shininess && a->reflective == b->reflective && a->fuzz == b->fuzz &&
	       a->metal == b->metal && a->ior == b->ior && a->emission == b->emission &&
	       a->checker == b->checker && a->texture == b->texture && a->normalmap == b->normalmap &&
	       a->bump == b->bump && a->bumpscale == b->bumpscale && a->uvscale[0] == b->uvscale[0] &&
	       a->uvscale[1] == b->uvscale[1] && a->uvoffset[0] == b->uvoffset[0] &&
	       a->uvoffset[1] == b->uvoffset[1] &&
	       a->pbr == b->pbr;
}

bool object_equal(const object *a, const object *b)
{
	if (a->kind != b->kind || !material_equal(&a->mat, &b->mat))
		return false;
	if ((obj_kind_flags(a->kind) & KIND_VERTICES))
		return v3_eq(a->tri[0], b->tri[0]) && v3_eq(a->tri[1], b->tri[1]) &&
		       v3_eq(a->tri[2], b->tri[2]);
	for (int i = 0; i < 6; i++)
		if (a->shear[i] != b->shear[i])
			return false;
	if (a->file != b->file || a->file_colors != b->file_colors || a->smooth != b->smooth ||
	    a->crease != b->crease || a->node != b->node)
		return false;
	return v3_eq(a->pos, b->pos) && v3_eq(a->dir, b->dir) && a->twist == b->twist &&
	       (!(obj_kind_flags(a->kind) & KIND_TUBE) || a->tube == b->tube) &&
	       v3_eq(a->scale, b->scale);
}

static bool light_equal(const light *a, const light *b)
{
	return v3_eq(a->pos, b->pos) && a->ratio == b->ratio && v3_eq(a->color, b->color) && a->kind == b->kind &&
	       a->intensity == b->intensity && v3_eq(a->dir, b->dir) && a->inner == b->inner && a->outer == b->outer &&
	       a->range == b->range;
}

static bool camera_equal(const camera *a, const camera *b)
{
	return v3_eq(a->pos, b->pos) && v3_eq(a->dir, b->dir) && a->fov == b->fov && a->vertical == b->vertical &&
	       a->ortho == b->ortho && a->roll == b->roll;
}

bool scene_equal(const scene *a, const scene *b)
{
	if (a->has_ambient != b->has_ambient || a->ncams != b->ncams || a->cam != b->cam ||
	    a->nlights != b->nlights || a->nobjs != b->nobjs || a->has_sky != b->has_sky)
		return false;
	if (a->has_ambient && (a->amb.ratio != b->amb.ratio || !v3_eq(a->amb.color, b->amb.color)))
		return false;
	if (a->has_sky && (!v3_eq(a->sky.zenith, b->sky.zenith) ||
	                   !v3_eq(a->sky.horizon, b->sky.horizon) ||
	                   a->sky.strength != b->sky.strength || a->sky.file != b->sky.file ||
	                   a->sky.rotation != b->sky.rotation))
		return false;
	if (memcmp(&a->hints, &b->hints, sizeof a->hints) != 0)
		return false;
	for (size_t i = 0; i < a->ncams; i++)
		if (!camera_equal(&a->cams[i], &b->cams[i]))
			return false;
	for (size_t i = 0; i < a->nlights; i++)
		if (!light_equal(&a->lights[i], &b->lights[i]))
			return false;
	for (size_t i = 0; i < a->nobjs; i++)
		if (!object_equal(&a->objs[i], &b->objs[i]))
			return false;
	return true;
}

/* Makes room for one more element of an array that grows by doubling. */
static bool grow(void **arr, size_t *cap, size_t n, size_t size, rt_error *err)
{
	if (n < *cap)
		return true;
	size_t ncap = *cap ? *cap * 2 : 8;
	if (ncap > SIZE_MAX / size)
		return rt_error_set(err, "out of memory; the scene is too large");
	void *p = realloc(*arr, ncap * size);
	if (!p)
		return rt_error_set(err, "out of memory; the scene is too large");
	*arr = p;
	*cap = ncap;
	return true;
}

/* Inserts the element of `size` bytes at index i (past the end: at the end)
 * of the array *arr of *n elements, moving those from i up one place. */
static bool insert_at(void **arr, size_t *cap, size_t *n, size_t i, const void *elem, size_t size, rt_error *err)
{
	if (!grow(arr, cap, *n, size, err))
		return false;
	if (i > *n)
		i = *n;
	char *a = *arr;
	memmove(a + (i + 1) * size, a + i * size, (*n - i) * size);
	memcpy(a + i * size, elem, size);
	(*n)++;
	return true;
}

/* Removes the element at index i (none past the end), moving those after
 * it down one place. */
static void remove_at(void *arr, size_t *n, size_t i, size_t size)
{
	if (i >= *n)
		return;
	char *a = arr;
	memmove(a + i * size, a + (i + 1) * size, (*n - i - 1) * size);
	(*n)--;
}

bool scene_insert_object(scene *s, size_t i, const object *o, rt_error *err)
{
	/* Before the array doubles: what a scene of this size will need. */
	char what[64];
	if (s->nobjs == s->cap_objs && s->nobjs >= 65536 &&
	    (snprintf(what, sizeof what, "a scene of more than %zu objects", s->nobjs),
	     !mem_check((double)s->nobjs * 2 * MEM_PER_OBJECT, what, err)))
		return false;
	return insert_at((void **)&s->objs, &s->cap_objs, &s->nobjs, i, o, sizeof *o, err);
}

bool scene_insert_light(scene *s, size_t i, const light *l, rt_error *err)
{
	return insert_at((void **)&s->lights, &s->cap_lights, &s->nlights, i, l, sizeof *l, err);
}

bool scene_add_object(scene *s, const object *o, rt_error *err)
{
	return scene_insert_object(s, s->nobjs, o, err);
}

bool scene_add_light(scene *s, const light *l, rt_error *err)
{
	return scene_insert_light(s, s->nlights, l, err);
}

bool scene_add_camera(scene *s, const camera *c, rt_error *err)
{
	return insert_at((void **)&s->cams, &s->cap_cams, &s->ncams, s->ncams, c, sizeof *c, err);
}

void scene_remove_object(scene *s, size_t i)
{
	remove_at(s->objs, &s->nobjs, i, sizeof *s->objs);
}

void scene_remove_light(scene *s, size_t i)
{
	remove_at(s->lights, &s->nlights, i, sizeof *s->lights);
}

camera scene_camera(const scene *s)
{
	if (s->ncams == 0)
		return (camera){v3(0, 0, -5), v3(0, 0, 1), 70.0, false, 0, 0};
	return s->cams[s->cam < s->ncams ? s->cam : 0];
}

object object_make(obj_kind k, vec3 color)
{
	object o;
	memset(&o, 0, sizeof o);
	o.kind = k;
	o.dir = v3(0, 1, 0);
	o.scale = v3(1, 1, 1);
	o.tube = 0.5;
	o.mat = material_default(color);
	o.smooth = 1;
	o.crease = 60;
	o.node = -1;
	if ((obj_kind_flags(k) & KIND_VERTICES)) {
		o.tri[0] = v3(-0.5, -0.5, 0);
		o.tri[1] = v3(0.5, -0.5, 0);
		o.tri[2] = v3(0, 0.5, 0);
	}
	return o;
}

static bool has_shear(const object *o)
{
	for (int i = 0; i < 6; i++)
		if (o->shear[i] != 0.0)
			return true;
	return false;
}

bool object_xform(const object *o, xform *out)
{
	if ((obj_kind_flags(o->kind) & KIND_VERTICES)) {
		*out = xf_identity();
		return true;
	}
	double len = v3_len(o->dir);
	if (!(len > 0.0) || !isfinite(len))
		return false;
	vec3 s = o->scale;
	if ((obj_kind_flags(o->kind) & KIND_UNBOUNDED))
		s = v3(2, 2, 2); /* a plane has no size: object units are world units */
	mat4 m = m4_mul(m4_translate(o->pos), m4_orient(v3_scale(o->dir, 1.0 / len), deg_to_rad(o->twist)));
	if (has_shear(o))
		m = m4_mul(m, m4_shear(o->shear));
	m = m4_mul(m, m4_scale(v3_scale(s, 0.5)));
	return xf_make(m, out);
}

vec3 object_center(const object *o)
{
	if ((obj_kind_flags(o->kind) & KIND_VERTICES))
		return v3_scale(v3_add(v3_add(o->tri[0], o->tri[1]), o->tri[2]), 1.0 / 3.0);
	return o->pos;
}

/* True when object_xform surely succeeds, without building the transform
 * (a million-sphere file spent 13% of its load there): no shear, a finite
 * position, and a direction and sizes (a bounded kind's) within
 * 1e-50..1e50. Then the rotation (m4_orient) has entries of at most 2 and
 * is orthonormal to far better than 1e-3, so the matrix's entries are
 * finite, its determinant (the product of the half sizes, >= 1e-151) and
 * the columns' lengths neither overflow nor underflow, and their ratio is
 * about 1, far from affine_invert's 1e-12 (test_shapes checks the claim
 * against object_xform). Call after object_validate's own checks. */
static bool xform_surely_invertible(const object *o)
{
	const double lo = 1e-50, hi = 1e50;
	if (has_shear(o) || !v3_finite(o->pos))
		return false;
	double len = v3_len(o->dir);
	if (!(len >= lo && len <= hi))
		return false;
	if (obj_kind_flags(o->kind) & KIND_UNBOUNDED)
		return true;
	vec3 s = o->scale;
	return s.x >= lo && s.x <= hi && s.y >= lo && s.y <= hi && s.z >= lo && s.z <= hi;
}

bool object_validate(const object *o, rt_error *err)
{
	const char *name = obj_kind_name(o->kind);
	if ((obj_kind_flags(o->kind) & KIND_VERTICES)) {
		for (int i = 0; i < 3; i++)
			if (!v3_finite(o->tri[i]))
				return rt_error_set(err, "triangle vertex %d is not finite; expected numbers", i + 1);
		vec3 n = v3_cross(v3_sub(o->tri[1], o->tri[0]), v3_sub(o->tri[2], o->tri[0]));
		double scale = fmax(v3_len2(v3_sub(o->tri[1], o->tri[0])), v3_len2(v3_sub(o->tri[2], o->tri[0])));
		if (!(v3_len(n) > 1e-12 * scale))
			return rt_error_set(err, "triangle has no area (its vertices are on one line); "
			                         "expected three points not in a line");
		return true;
	}
	if (!v3_finite(o->pos) || !v3_finite(o->dir) || !v3_finite(o->scale) || !isfinite(o->twist))
		return rt_error_set(err, "%s has a number that is not finite; expected finite numbers", name);
	if ((obj_kind_flags(o->kind) & KIND_TUBE) && !(o->tube > 0.0 && o->tube <= 100.0))
		return rt_error_set(err, "%s tube ratio is out of range; expected tube= in (0,100]", name);
	if (!(v3_len(o->dir) > 0.0))
		return rt_error_set(err, "%s direction is the zero vector; expected a non-zero direction", name);
	if (!(obj_kind_flags(o->kind) & KIND_UNBOUNDED) && !(o->scale.x > 0 && o->scale.y > 0 && o->scale.z > 0))
		return rt_error_set(err, "%s scaling has a component <= 0; expected sizes > 0", name);
	if (xform_surely_invertible(o))
		return true;
	xform x;
	if (!object_xform(o, &x)) {
		if (has_shear(o))
			return rt_error_set(err, "%s transform is not invertible (check the shear); "
			                         "expected a shear that keeps the shape solid", name);
		return rt_error_set(err, "%s scaling %g,%g,%g is too small or too uneven to place; "
		                         "expected sizes whose product is far from 0",
		                    name, o->scale.x, o->scale.y, o->scale.z);
	}
	return true;
}

/* p + d in the decimals they are written with (num_add_decimal): many
 * small moves do not drift. */
static vec3 add_decimal(vec3 p, vec3 d)
{
	return v3(num_add_decimal(p.x, d.x), num_add_decimal(p.y, d.y), num_add_decimal(p.z, d.z));
}

void object_move(object *o, vec3 d)
{
	if ((obj_kind_flags(o->kind) & KIND_VERTICES)) {
		for (int i = 0; i < 3; i++)
			o->tri[i] = add_decimal(o->tri[i], d);
		return;
	}
	o->pos = add_decimal(o->pos, d);
}

/* Reads (dir, twist) back from a rotation matrix r = orient(dir, twist). */
static void orient_decompose(const mat4 *r, vec3 *dir, double *twist_deg)
{
	vec3 d = v3(r->m[0][1], r->m[1][1], r->m[2][1]);
	d = v3_norm(d);
	mat4 base = m4_orient(d, 0.0);
	/* base^T r is a rotation about Y by the twist. */
	mat4 t = m4_mul(m4_transpose(base), *r);
	double ang = atan2(t.m[0][2], t.m[0][0]);
	*dir = d;
	*twist_deg = rad_to_deg(ang);
	if (fabs(*twist_deg) < 1e-9)
		*twist_deg = 0.0;
}

bool object_rotate(object *o, vec3 deg, rt_error *err)
{
	mat4 q = m4_mul(m4_rotate_z(deg_to_rad(deg.z)),
	                m4_mul(m4_rotate_y(deg_to_rad(deg.y)), m4_rotate_x(deg_to_rad(deg.x))));
	if (!v3_finite(deg))
		return rt_error_set(err, "rotation angles are not finite; expected degrees");
	if ((obj_kind_flags(o->kind) & KIND_VERTICES)) {
		vec3 c = object_center(o);
		for (int i = 0; i < 3; i++)
			o->tri[i] = v3_add(c, m4_vector(&q, v3_sub(o->tri[i], c)));
		return true;
	}
	double len = v3_len(o->dir);
	mat4 r = m4_mul(q, m4_orient(v3_scale(o->dir, 1.0 / len), deg_to_rad(o->twist)));
	orient_decompose(&r, &o->dir, &o->twist);
	return true;
}

bool object_scale(object *o, vec3 f, rt_error *err)
{
	if (!(f.x > 0 && f.y > 0 && f.z > 0) || !v3_finite(f))
		return rt_error_set(err, "scale factors must be > 0; expected SX,SY,SZ like 2,2,2");
	if ((obj_kind_flags(o->kind) & KIND_VERTICES)) {
		vec3 c = object_center(o);
		for (int i = 0; i < 3; i++)
			o->tri[i] = v3_add(c, v3_mul(v3_sub(o->tri[i], c), f));
		return true;
	}
	o->scale = v3_mul(o->scale, f);
	return true;
}
