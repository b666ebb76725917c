/* rtsh — the value rules shared by the reader and the editor (rules.h). */
#include "rtsh/rules.h"

#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>

#include "scene/rtfile_priv.h"

static bool within(double v) { return fabs(v) <= RT_NUM_MAX; }
static bool vec_within(vec3 v) { return within(v.x) && within(v.y) && within(v.z); }

static bool out_of_range(rt_error *err, const char *what, vec3 v)
{
	return rt_error_set(err, "%s %g,%g,%g is out of range; expected numbers within +-" RT_NUM_MAX_TEXT,
	                    what, v.x, v.y, v.z);
}

bool fov_rule(double *fov, bool *clamped, rt_error *err)
{
	*clamped = false;
	if (!(*fov >= 0 && *fov <= 180))
		return rt_error_set(err, "camera field of view %g is out of range; expected degrees in "
		                         "[0,180] (the ends are clamped to %g and %g)",
		                    *fov, RT_FOV_MIN, RT_FOV_MAX);
	if (*fov < RT_FOV_MIN || *fov > RT_FOV_MAX) {
		*fov = *fov < RT_FOV_MIN ? RT_FOV_MIN : RT_FOV_MAX;
		*clamped = true;
	}
	return true;
}

bool color_validate(vec3 c, const char *what, rt_error *err)
{
	if (!(c.x >= 0 && c.x <= 255 && c.y >= 0 && c.y <= 255 && c.z >= 0 && c.z <= 255))
		return rt_error_set(err, "%s %g,%g,%g is out of range; expected R,G,B with each in 0..255",
		                    what, c.x, c.y, c.z);
	return true;
}

bool light_validate(const light *l, rt_error *err)
{
	if (!v3_finite(l->pos))
		return rt_error_set(err, "light position is not finite; expected numbers");
	if (!vec_within(l->pos))
		return out_of_range(err, "light position", l->pos);
	if (!(l->ratio >= 0 && l->ratio <= 1))
		return rt_error_set(err, "light brightness %g is out of range; expected 0..1", l->ratio);
	return color_validate(l->color, "light colour", err);
}

bool camera_validate(const camera *c, rt_error *err)
{
	if (!v3_finite(c->pos))
		return rt_error_set(err, "camera position is not finite; expected numbers");
	if (!vec_within(c->pos))
		return out_of_range(err, "camera position", c->pos);
	if (!v3_finite(c->dir) || !(v3_len(c->dir) > 0))
		return rt_error_set(err, "camera direction is the zero vector; expected a non-zero direction");
	if (!vec_within(c->dir))
		return out_of_range(err, "camera direction", c->dir);
	if (!(c->fov >= RT_FOV_MIN && c->fov <= RT_FOV_MAX))
		return rt_error_set(err, "camera field of view %g is out of range; expected degrees "
		                         "in [0,180] (the ends are clamped to %g and %g)",
		                    c->fov, RT_FOV_MIN, RT_FOV_MAX);
	return true;
}

bool ambient_validate(const ambient *a, rt_error *err)
{
	if (!(a->ratio >= 0 && a->ratio <= 1))
		return rt_error_set(err, "ambient brightness %g is out of range; expected 0..1", a->ratio);
	return color_validate(a->color, "ambient colour", err);
}

bool sky_validate(const sky *k, rt_error *err)
{
	if (!color_validate(k->zenith, "sky zenith colour", err) ||
	    !color_validate(k->horizon, "sky horizon colour", err))
		return false;
	if (!(k->strength >= 0 && k->strength <= RT_NUM_MAX))
		return rt_error_set(err, "sky strength %g is out of range; expected a number in [0," RT_NUM_MAX_TEXT "]",
		                    k->strength);
	return true;
}

/* The numeric keys (in table order) that apply to each kind: object_rules
 * checks those of its object's kind instead of asking every key of the
 * table (a million loaded spheres asked 30 keys each). Not made (the full
 * loop instead) if the table outgrows RULE_KEYS_MAX. */
#define RULE_KEYS_MAX 128
static uint8_t rule_keys[OBJ_KIND_COUNT][RULE_KEYS_MAX];
static size_t rule_nkeys[OBJ_KIND_COUNT];
static bool rule_keys_made;
static pthread_once_t rule_keys_once = PTHREAD_ONCE_INIT;

static void rule_keys_init(void)
{
	if (rt_nkeys > RULE_KEYS_MAX)
		return;
	for (int kind = 0; kind < OBJ_KIND_COUNT; kind++)
		for (size_t i = 0; i < rt_nkeys; i++)
			if (rt_key_applies(&rt_keys[i], (obj_kind)kind) && rt_keys[i].type == RT_KEY_NUM)
				rule_keys[kind][rule_nkeys[kind]++] = (uint8_t)i;
	rule_keys_made = true;
}

/* Key k's value in o is its default or within its range; false with err
 * set (the object's kind named `name`) when not. */
static bool key_rule(const rt_key *k, const object *o, const char *name, rt_error *err)
{
	double v = rt_key_get(k, o);
	if (v == k->def)
		return true;
	if (!(v >= k->min && v <= k->max) || (k->is_int && v != floor(v)) || (k->extra && !k->extra(v)))
		return rt_error_set(err, "%s %s=%g is out of range; expected %s", name, k->name, v, k->expect);
	return true;
}

bool object_rules(const object *o, rt_error *err)
{
	if (!object_validate(o, err))
		return false;
	const char *name = obj_kind_name(o->kind);
	char what[64];
	if (obj_kind_flags(o->kind) & KIND_VERTICES) {
		for (int i = 0; i < 3; i++)
			if (!vec_within(o->tri[i])) {
				snprintf(what, sizeof what, "%s vertex %d", name, i + 1);
				return out_of_range(err, what, o->tri[i]);
			}
	} else {
		/* the names are made only for a message: a million objects load */
		if (!vec_within(o->pos)) {
			snprintf(what, sizeof what, "%s position", name);
			return out_of_range(err, what, o->pos);
		}
		if (!vec_within(o->dir)) {
			snprintf(what, sizeof what, "%s direction", name);
			return out_of_range(err, what, o->dir);
		}
		if (!vec_within(o->scale))
			return rt_error_set(err, "%s scaling %g,%g,%g is out of range; expected sizes in "
			                         "(0," RT_NUM_MAX_TEXT "]",
			                    name, o->scale.x, o->scale.y, o->scale.z);
		for (int i = 0; i < 6; i++)
			if (!within(o->shear[i]))
				return rt_error_set(err, "%s shear %g is out of range; expected numbers within "
				                         "+-" RT_NUM_MAX_TEXT,
				                    name, o->shear[i]);
	}
	const material *m = &o->mat;
	if (!color_validate(m->color, "object colour", err))
		return false;
	if (!(m->diffuse >= 0 && m->diffuse <= 1 && m->specular >= 0 && m->specular <= 1 &&
	      m->reflective >= 0 && m->reflective <= 1 && m->shininess >= 1 && m->shininess <= 500))
		return rt_error_set(err, "%s material %g %g %g %g is out of range; expected DIFFUSE, "
		                         "SPECULAR and REFLECTIVE in [0,1], SHININESS in [1,500]",
		                    name, m->diffuse, m->specular, m->shininess, m->reflective);
	/* files and U,V pairs are checked where they are read */
	pthread_once(&rule_keys_once, rule_keys_init);
	if (rule_keys_made && (unsigned)o->kind < OBJ_KIND_COUNT) {
		for (size_t i = 0; i < rule_nkeys[o->kind]; i++)
			if (!key_rule(&rt_keys[rule_keys[o->kind][i]], o, name, err))
				return false;
		return true;
	}
	for (size_t i = 0; i < rt_nkeys; i++)
		if (rt_key_applies(&rt_keys[i], o->kind) && rt_keys[i].type == RT_KEY_NUM &&
		    !key_rule(&rt_keys[i], o, name, err))
			return false;
	return true;
}
