/* rtsh — what world.c asks of meshes and textures (surface.c): mesh
 * instances in the world, texture coordinates per shape, textures in
 * materials, and normal / bump mapping. Private to the core. */
#ifndef RTSH_SURFACE_H
#define RTSH_SURFACE_H

#include "rtsh/mesh.h"
#include "rtsh/world.h"

/* Before the objects are placed: loads the scene's meshes (shared, once per
 * file) and makes room for their instances and sub-materials. */
bool surf_begin(world *w, const scene *s, rt_error *err);
/* After w->mats[i] is set from object i: its textures, and a mesh's own
 * materials (appended to w->mats). */
bool surf_material(world *w, const object *o, uint32_t i, rt_error *err);
/* Whether surf_material has anything to do for o (textures, or a model):
 * when not, it only sets w->mats[i].tx to NULL (a million spheres skip the
 * call). */
static inline bool surf_material_needed(const object *o)
{
	return o->mat.texture || o->mat.normalmap || o->mat.bump || (obj_kind_flags(o->kind) & KIND_MODEL);
}
/* A mesh object's primitive and world bounds. */
bool surf_make_inst(world *w, const object *o, uint32_t i, prim *p, box *b, rt_error *err);
/* Instance tests: the nearest hit stores (triangle, b1, b2) in *nl;
 * coherent: the ray is a camera ray (mesh_intersect_world_coherent).
 * Inline: every ray on a model passes here (a call layer fewer). */
static inline bool surf_inst_hit(const world *w, const prim *p, const ray *r, double tmin, double tmax, double *t,
                                 vec3 *nl, bool coherent)
{
	const prim_inst *in = &w->insts[p->u.index];
	uint32_t slot;
	float b[3];
	if (!(coherent ? mesh_intersect_world_coherent : mesh_intersect_world)(in->mesh, in->inv, r, tmin, tmax, t, &slot,
	                                                                       b))
		return false;
	*nl = v3((double)slot, b[1], b[2]);
	return true;
}

static inline bool surf_inst_occluded(const world *w, const prim *p, const ray *r, double tmin, double tmax)
{
	const prim_inst *in = &w->insts[p->u.index];
	return mesh_occluded_world(in->mesh, in->inv, r, tmin, tmax);
}
void surf_inst_finish(const world *w, const prim *p, const ray *r, vec3 nl, hit *h);
/* The geometric normal of that hit in world space, not unit. */
vec3 surf_inst_ng(const world *w, const prim *p, vec3 nl);
/* Texture coordinates of the unit shape sh at h (its kind's, shape.h), or
 * of a world-space triangle (its vertex, edges), when h's material has a
 * texture; nl is the object-space normal the shape's intersect gave. */
void surf_shape_uv(const world *w, const prim_shape *sh, vec3 nl, hit *h);
/* Whether a hit with material mat needs its texture coordinates (the
 * material has a texture): surf_shape_uv's test, for callers that fill the
 * rest of a hit record themselves (packet.c). */
static inline bool surf_wants_uv(const world *w, uint32_t mat)
{
	return w->mats[mat].tx != NULL;
}
void surf_triangle_uv(const world *w, vec3 v0, vec3 e1, vec3 e2, hit *h);
void surf_free(world *w);
size_t surf_memory(const world *w);

#endif
