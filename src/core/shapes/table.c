/* rtsh — the shape table, solver and bounds (shape.h). */
#include "shapes.h"

#include <string.h>

const shape_kind *const shape_kinds[OBJ_KIND_COUNT] = {
#define RT_KIND(e, id, name, desc, flags) [OBJ_##e] = &desc,
#include "rtsh/kinds.def"
#undef RT_KIND
};

const shape_kind *shape_kind_of(obj_kind k)
{
	return (unsigned)k < OBJ_KIND_COUNT ? shape_kinds[k] : NULL;
}

const shape_kind *shape_kind_find(const char *id, obj_kind *k, const shape_form **form)
{
	for (int i = 0; i < OBJ_KIND_COUNT; i++) {
		const shape_kind *d = shape_kinds[i];
		const shape_form *f = d->form.id && strcmp(d->form.id, id) == 0     ? &d->form
		                      : d->alias.id && strcmp(d->alias.id, id) == 0 ? &d->alias
		                                                                    : NULL;
		if (f) {
			*k = (obj_kind)i;
			*form = f;
			return d;
		}
	}
	return NULL;
}

/* A mesh is a model file (mesh.h) placed like a unit shape: in object
 * space the model's box is centred on the origin with its longest side 2,
 * so within the unit cube. Its .rt line (FILE, a size of one or three
 * numbers, a colour that may be left out) is no short or extended form:
 * the reader's `mesh` element reads it, and the world traces its triangles
 * as an instance of the shared mesh (surface.c), not by a unit-shape test. */
const shape_kind mesh_kind = {
	.form = {NULL, "mesh", false, false, true, 0, NULL, {NULL}, "", NULL, NULL},
	.bounds = unit_cube_bounds,
	.cost = 32, /* a ray into its object space and down its own tree */
	.recipe = {.use = false},
};

void shape_uv(obj_kind k, vec3 q, vec3 nl, double tube, double *u, double *v, vec3 *dqdu, vec3 *dqdv)
{
	const shape_kind *d = shape_kind_of(k);
	(d && d->uv ? d->uv : uv_planar)(q, nl, tube, u, v, dqdu, dqdv);
}

box shape_local_bounds(obj_kind k, double tube)
{
	return shape_kinds[k]->bounds(tube);
}

box object_bounds(const object *o)
{
	unsigned f = obj_kind_flags(o->kind);
	if (f & KIND_VERTICES)
		return box_add(box_add(box_point(o->tri[0]), o->tri[1]), o->tri[2]);
	if (f & KIND_UNBOUNDED)
		return shape_local_bounds(o->kind, o->tube);
	xform x;
	if (!object_xform(o, &x))
		return box_empty();
	return xf_box(&x, shape_local_bounds(o->kind, o->tube));
}
