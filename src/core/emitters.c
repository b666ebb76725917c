/* rtsh — the emissive surfaces the path tracer samples directly (path.c
 * weighs them against its own paths). Each shape kind says how its objects
 * are sampled (shape.h, shape_light_ops; src/core/shapes/); this file only
 * collects them. */
#include "emitters.h"

#include <stdlib.h>

#include "rtsh/mesh.h"
#include "warp.h"

/* The world material of triangle t of instance in (object i). */
static uint32_t tri_mat(const prim_inst *in, size_t i, uint32_t t)
{
	if (in->mat_base == UINT32_MAX)
		return (uint32_t)i;
	return in->mat_base + (in->mesh->tmat ? in->mesh->tmat[t] : 0);
}

/* Walks the emissive triangles of the models: counts them, or (put) adds
 * them to w->emitters material by material, each material's in one run,
 * as the triangle kind samples a triangle. */
static size_t mesh_walk(world *w, const scene *s, bool put)
{
	const shape_kind *tk = shape_kind_of(OBJ_TRIANGLE);
	if (!tk || !tk->light.make)
		return 0;
	size_t total = 0, k = 0;
	/* the model objects in order are the instances (surface.c) */
	for (size_t i = 0; i < s->nobjs && k < w->ninsts; i++) {
		if (!(obj_kind_flags(s->objs[i].kind) & KIND_MODEL))
			continue;
		const prim_inst *in = &w->insts[k++];
		const mesh *m = in->mesh;
		if (!m || !m->blk)
			continue;
		uint32_t nm = in->mat_base == UINT32_MAX ? 1 : (m->nmats ? m->nmats : 1);
		for (uint32_t mi = 0; mi < nm; mi++) {
			uint32_t wm = in->mat_base == UINT32_MAX ? (uint32_t)i : in->mat_base + mi;
			if (wm >= w->nmats || !(max3(w->mats[wm].emission) > 0.0) || (w->mats[wm].tx && w->mats[wm].tx->emit))
				continue; /* an emissive texture: found by the paths */
			/* a glTF cut-out (alphaMode MASK or BLEND): an emitter with holes is
			 * found by the paths too, which pass through its holes
			 * (mesh_cut_hole); a point sampled on the whole triangle could
			 * light through one */
			if (in->mat_base != UINT32_MAX && mi < m->nmats && m->mats[mi].alpha_mode != MESH_ALPHA_OPAQUE)
				continue;
			size_t first = w->nemitters, run = 0;
			uint32_t last = UINT32_MAX;
			/* each triangle once: a leaf's last block repeats its last */
			for (uint32_t slot = 0; slot < 4 * m->nblk; slot++) {
				uint32_t t = mesh_slot_tri(m, slot);
				if (t == last || tri_mat(in, i, t) != wm)
					continue;
				last = t;
				vec3 c[3];
				mesh_corners(m, slot, c);
				object o = object_make(OBJ_TRIANGLE, v3(0, 0, 0));
				const double(*f)[4] = in->fwd;
				for (int j = 0; j < 3; j++)
					o.tri[j] = v3(f[0][0] * c[j].x + f[0][1] * c[j].y + f[0][2] * c[j].z + f[0][3],
					              f[1][0] * c[j].x + f[1][1] * c[j].y + f[1][2] * c[j].z + f[1][3],
					              f[2][0] * c[j].x + f[2][1] * c[j].y + f[2][2] * c[j].z + f[2][3]);
				emitter e = {.object = UINT32_MAX, .kind = OBJ_TRIANGLE, .mat = wm, .run = 1};
				if (!tk->light.make(&o, &e.l))
					continue;
				if (put)
					w->emitters[w->nemitters++] = e;
				run++;
			}
			if (put && run > 0) {
				w->emitters[first].run = (uint32_t)run;
				w->mats[wm].light = (int32_t)first;
			}
			total += run;
		}
	}
	return total;
}

/* A model's emissive triangles are sampled too, MESH_EMITTERS of them in
 * all at most (a lamp made of a few triangles; a model whose every
 * triangle glows is left to the paths, as before). The count, and (put)
 * the emitters added. */
#define MESH_EMITTERS 1024

static size_t mesh_emitters(world *w, const scene *s, bool put)
{
	size_t n = mesh_walk(w, s, false);
	if (n == 0 || n > MESH_EMITTERS)
		return 0;
	if (put)
		mesh_walk(w, s, true);
	return n;
}

const emitter *emitter_at(const world *w, int32_t first, vec3 p)
{
	const emitter *e = &w->emitters[first], *best = e;
	if (e->run <= 1)
		return e;
	double bd = INFINITY;
	for (uint32_t j = 0; j < e->run; j++) {
		const shape_light *x = &w->emitters[(uint32_t)first + j].l;
		/* p's barycentrics in the triangle c + a u + b v; how far outside */
		vec3 d = v3_sub(p, x->c);
		double uu = v3_dot(x->u, x->u), uv = v3_dot(x->u, x->v), vv = v3_dot(x->v, x->v);
		double du = v3_dot(d, x->u), dv = v3_dot(d, x->v), det = uu * vv - uv * uv;
		if (!(det > 0.0))
			continue;
		double a = (vv * du - uv * dv) / det, b = (uu * dv - uv * du) / det;
		double out = fmax(fmax(-a, -b), a + b - 1.0);
		out = fmax(out, 0.0) + fabs(v3_dot(d, x->n)) / sqrt(fmax(uu, vv));
		if (out < bd) {
			bd = out;
			best = &w->emitters[(uint32_t)first + j];
		}
	}
	return best;
}

bool emitters_build(world *w, const scene *s, rt_error *err)
{
	w->emitters = NULL;
	w->nemitters = 0;
	size_t n = 0;
	for (size_t pass = 0; pass < 2; pass++) {
		for (size_t i = 0; i < s->nobjs; i++) {
			const object *o = &s->objs[i];
			if (!(max3(w->mats[i].emission) > 0.0))
				continue;
			const shape_kind *k = shape_kind_of(o->kind);
			emitter e = {.object = (uint32_t)i, .kind = (uint32_t)o->kind, .mat = (uint32_t)i, .run = 1};
			if (!k || !k->light.make || !k->light.make(o, &e.l))
				continue; /* found by the paths only */
			if (pass == 1) {
				w->mats[i].light = (int32_t)w->nemitters;
				w->emitters[w->nemitters++] = e;
			} else {
				n++;
			}
		}
		n += mesh_emitters(w, s, pass == 1);
		if (pass == 0) {
			if (n == 0)
				return true;
			w->emitters = calloc(n, sizeof *w->emitters);
			if (!w->emitters)
				return rt_error_set(err, "out of memory preparing the scene");
		}
	}
	return true;
}
