/* rtsh — meshes and textures in the world (surface.h).
 *
 * Texture coordinates: each shape kind gives its own (shape_kind.uv, in
 * src/core/shapes/; rtsh(5), "Texture coordinates"), the triangle's are the
 * barycentric weights of its 2nd and 3rd vertex and a mesh's the file's vt;
 * then u x uvscale + uvoffset.
 *
 * Normal maps are tangent space (red along +u, green along +v, blue the
 * normal; 8-bit codes c read as 2c/255 - 1, so 127 and 128 are both flat).
 * Bump maps displace the surface by bumpscale x the map's luminance along
 * the normal and shade with the normal of the displaced surface (Blinn,
 * "Simulation of wrinkled surfaces", 1978), by central differences of one
 * texel.
 */
#include "surface.h"
#include "ggx.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rtsh/mesh.h"
#include "rtsh/shape.h"
#include "rtsh/texture.h"

static bool hold_texture(world *w, const char *path, bool srgb, const struct texture **out, rt_error *err)
{
	*out = NULL;
	if (!path)
		return true;
	texture **t = realloc(w->texs, (w->ntexs + 1) * sizeof *t);
	if (!t)
		return rt_error_set(err, "out of memory loading textures");
	w->texs = t;
	texture *tx = texture_cache_get(path, srgb, w->cancel, err);
	if (!tx)
		return image_budget_refused(err); /* the previewer's budget: untextured */
	w->texs[w->ntexs++] = tx;
	*out = tx;
	return true;
}

/* hold_texture for a model's own material k: a failure names the model
 * and the material (rtsh(5), "Meshes"). */
static bool hold_model_texture(world *w, const mesh *me, uint32_t k, const char *what, const char *path, bool srgb,
                               const struct texture **out, rt_error *err)
{
	if (hold_texture(w, path, srgb, out, err))
		return true;
	char why[RT_ERROR_MSG_MAX], mat[96];
	rt_error_format(err, why, sizeof why);
	if (strcmp(why, "stopped") == 0)
		return false;
	const char *name = me->mats[k].name;
	if (name && name[0])
		snprintf(mat, sizeof mat, "\"%.80s\"", name);
	else
		snprintf(mat, sizeof mat, "%u", k + 1);
	return rt_error_set(err, "%s: the %s of material %s: %s", me->path ? me->path : "the model", what, mat, why);
}

bool surf_begin(world *w, const scene *s, rt_error *err)
{
	size_t n = 0, ntx = 0;
	for (size_t i = 0; i < s->nobjs; i++) {
		const material *om = &s->objs[i].mat;
		n += (obj_kind_flags(s->objs[i].kind) & KIND_MODEL) != 0;
		ntx += om->texture || om->normalmap || om->bump;
	}
	w->mtex = NULL;
	w->nmtex = 0;
	if (ntx && !(w->mtex = calloc(ntx, sizeof *w->mtex)))
		return rt_error_set(err, "out of memory preparing the textures");
	if (n == 0)
		return true;
	w->insts = calloc(n, sizeof *w->insts);
	w->meshes = calloc(n, sizeof *w->meshes);
	if (!w->insts || !w->meshes)
		return rt_error_set(err, "out of memory preparing %zu meshes", n);
	size_t extra = 0;
	for (size_t i = 0; i < s->nobjs; i++) {
		const object *o = &s->objs[i];
		if (!(obj_kind_flags(o->kind) & KIND_MODEL))
			continue;
		mesh *m = mesh_cache_get_node(o->file ? o->file : "", o->node, o->smooth != 0, o->crease, w->cancel, err);
		if (!m) {
			char msg[RT_ERROR_MSG_MAX];
			rt_error_format(err, msg, sizeof msg);
			return rt_error_set(err, "object %zu (mesh): %s", i + 1, msg);
		}
		/* the same mesh for every instance: hold it once */
		w->insts[w->ninsts].mesh = m;
		w->insts[w->ninsts++].mat_base = UINT32_MAX;
		size_t k = 0;
		while (k < w->nmeshes && w->meshes[k] != m)
			k++;
		if (k < w->nmeshes)
			mesh_cache_put(m);
		else
			w->meshes[w->nmeshes++] = m;
		if (o->file_colors)
			extra += m->nmats;
	}
	/* each of a model's own materials may have textures */
	if (extra) {
		mat_tex *t = realloc(w->mtex, (ntx + extra) * sizeof *t);
		if (!t)
			return rt_error_set(err, "out of memory preparing the textures");
		w->mtex = t;
	}
	w->ninsts = 0; /* surf_make_inst counts them again */
	if (extra) {
		mat_lin *mats = realloc(w->mats, (s->nobjs + extra) * sizeof *mats);
		if (!mats)
			return rt_error_set(err, "out of memory preparing the meshes' materials");
		w->mats = mats;
	}
	return true;
}

/* A glTF material (mesh_gltf.c) in the PBR family: its factors are
 * linear already. Thin-walled without KHR_materials_volume (thickness 0);
 * the volume's attenuation in the file's units. */
static void gltf_material(const mesh_mat *mm, mat_lin *l)
{
	l->family = MAT_PBR;
	l->ior = mm->ior >= 1.0f ? mm->ior : 1.5;
	l->thin = mm->thickness <= 0.0f;
	l->pbr.roughness = mm->roughness;
	l->pbr.metallic = mm->metallic;
	l->pbr.transmission = mm->transmission;
	l->pbr.clearcoat = mm->clearcoat;
	l->pbr.clearcoat_roughness = mm->clearcoat_roughness;
	l->pbr.specular_factor = mm->specular;
	for (int k = 0; k < 3; k++) {
		l->pbr.specular_color[k] = mm->specular_color[k];
		float a = mm->att_color[k];
		l->pbr.sigma_a[k] = mm->att_dist > 0.0f ? (a > 0.0f ? -logf(a) / mm->att_dist : 1e30f) : 0.0f;
	}
	/* the union held the object's Phong fields: the rest of the PBR block
	 * is set here, not left to their bytes */
	l->pbr.single = false; /* multiscatter's default */
	pbr_lin_finish(l);     /* es_avg, es_ready */
	l->emission = v3(0, 0, 0);
}

bool surf_material(world *w, const object *o, uint32_t i, rt_error *err)
{
	mat_lin *m = &w->mats[i];
	const material *om = &o->mat;
	m->tx = NULL;
	/* no texture and no model: nothing to hold (a million spheres) */
	if (!surf_material_needed(o))
		return true;
	mat_tex own = {.tint = true, .bumpscale = om->bumpscale, .uvs = {om->uvscale[0] ? om->uvscale[0] : 1,
	               om->uvscale[1] ? om->uvscale[1] : 1}, .uvo = {om->uvoffset[0], om->uvoffset[1]}};
	if (!hold_texture(w, om->texture, true, &own.tex, err) || !hold_texture(w, om->normalmap, false, &own.nmap, err) ||
	    !hold_texture(w, om->bump, false, &own.bump, err))
		return false;
	if (own.tex || own.nmap || own.bump) {
		w->mtex[w->nmtex] = own;
		m->tx = &w->mtex[w->nmtex++];
	}
	if (!(obj_kind_flags(o->kind) & KIND_MODEL) || !o->file_colors)
		return true;
	/* the model's own materials, after the object's: its keys (fuzz,
	 * metal, ...) and textures apply unless the file has its own */
	const mesh *me = w->insts[w->ninsts].mesh;
	if (!me || me->nmats == 0)
		return true;
	w->insts[w->ninsts].mat_base = (uint32_t)w->nmats;
	for (uint32_t k = 0; k < me->nmats; k++) {
		const mesh_mat *mm = &me->mats[k];
		mat_lin l = w->mats[i];
		if (mm->gltf)
			gltf_material(mm, &l);
		l.albedo = v3(mm->kd[0], mm->kd[1], mm->kd[2]);
		vec3 ke = v3(mm->ke[0], mm->ke[1], mm->ke[2]);
		if (v3_max_comp(ke) > 0)
			l.emission = ke;
		l.light = -1;
		mat_tex t = own;
		if (mm->map_kd) {
			if (!hold_model_texture(w, me, k, "colour texture", mm->map_kd, true, &t.tex, err))
				return false;
			t.tint = mm->gltf; /* glTF: texture x baseColorFactor */
		} else if (mm->tex_kd) { /* embedded in the model: the mesh holds it */
			t.tex = mm->tex_kd;
			t.tint = mm->gltf;
		}
		if (mm->gltf && (mm->map_kd || mm->tex_kd)) /* KHR_texture_transform, then the object's */
			for (int a = 0; a < 2; a++) {
				t.uvo[a] += mm->uvo[a] * t.uvs[a];
				t.uvx[a] = mm->uvx[a] * t.uvs[a];
				t.uvs[a] *= mm->uvs[a];
			}
		if (mm->map_norm && !hold_model_texture(w, me, k, "normal map", mm->map_norm, false, &t.nmap, err))
			return false;
		if (!mm->map_norm && mm->tex_norm)
			t.nmap = mm->tex_norm;
		if (mm->gltf && mm->map_mr &&
		    !hold_model_texture(w, me, k, "metallic-roughness texture", mm->map_mr, false, &t.mr, err))
			return false;
		if (mm->gltf && !mm->map_mr && mm->tex_mr)
			t.mr = mm->tex_mr;
		if (mm->gltf && mm->map_emit && !hold_model_texture(w, me, k, "emissive texture", mm->map_emit, true, &t.emit, err))
			return false;
		if (mm->gltf && !mm->map_emit && mm->tex_emit)
			t.emit = mm->tex_emit;
		if (mm->map_bump) {
			if (!hold_model_texture(w, me, k, "bump map", mm->map_bump, false, &t.bump, err))
				return false;
			/* an MTL -bm is in model units: roughly right for scenes */
			t.bumpscale = mm->bump_scale * 0.01;
		}
		l.tx = NULL;
		if (t.tex || t.nmap || t.bump || t.mr || t.emit) {
			w->mtex[w->nmtex] = t;
			l.tx = &w->mtex[w->nmtex++];
		}
		w->mats[w->nmats++] = l;
	}
	return true;
}

static inline void mat3x4_point(const double (*m)[4], vec3 p, vec3 *out)
{
	*out = v3(m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3],
	          m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3],
	          m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3]);
}

static inline vec3 mat3x4_vector(const double (*m)[4], vec3 v)
{
	return v3(m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
	          m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z);
}

/* n by the inverse transpose, given the inverse */
static inline vec3 mat3x4_normal(const double (*inv)[4], vec3 n)
{
	return v3(inv[0][0] * n.x + inv[1][0] * n.y + inv[2][0] * n.z, inv[0][1] * n.x + inv[1][1] * n.y + inv[2][1] * n.z,
	          inv[0][2] * n.x + inv[1][2] * n.y + inv[2][2] * n.z);
}

bool surf_make_inst(world *w, const object *o, uint32_t index, prim *p, box *b, rt_error *err)
{
	const mesh *m = w->insts[w->ninsts].mesh;
	xform x;
	if (!m || !object_xform(o, &x))
		return rt_error_set(err, "object %u (mesh) cannot be placed: its transform is not invertible", index + 1);
	/* the model's box centred on the origin, its longest side 2 */
	vec3 c = box_center(m->bounds), ext = v3_sub(m->bounds.hi, m->bounds.lo);
	double longest = v3_max_comp(ext);
	if (!(longest > 0))
		longest = 1;
	mat4 f = m4_mul(x.m, m4_mul(m4_scale(v3_splat(2.0 / longest)), m4_translate(v3_neg(c))));
	xform fx;
	if (!xf_make(f, &fx))
		return rt_error_set(err, "object %u (mesh) cannot be placed: its transform is not invertible", index + 1);
	prim_inst *in = &w->insts[w->ninsts];
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 4; j++) {
			in->inv[i][j] = fx.inv.m[i][j];
			in->fwd[i][j] = fx.m.m[i][j];
		}
	memset(p, 0, sizeof *p);
	p->tag = PRIM_MESH;
	p->object = index;
	p->u.index = (uint32_t)w->ninsts++;
	*b = xf_box(&fx, m->bounds);
	return true;
}

/* --- textures at the hit --- */

static double luminance(vec3 c)
{
	return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
}

/* Normal and bump maps: h->n from the textures of h's material. */
static void perturb(const world *w, hit *h)
{
	const mat_tex *m = w->mats[h->mat].tx;
	if (!h->has_uv || !m || (!m->nmap && !m->bump))
		return;
	vec3 n = h->n;
	if (m->bump) {
		const texture *t = m->bump;
		double du = 1.0 / t->level[0].w, dv = 1.0 / t->level[0].h;
		double hu = luminance(texture_lookup(t, h->u + du, h->v, 0)) - luminance(texture_lookup(t, h->u - du, h->v, 0));
		double hv = luminance(texture_lookup(t, h->u, h->v + dv, 0)) - luminance(texture_lookup(t, h->u, h->v - dv, 0));
		double k = m->bumpscale;
		vec3 pu = v3_madd(h->dpdu, n, k * hu / (2 * du)), pv = v3_madd(h->dpdv, n, k * hv / (2 * dv));
		vec3 nb = v3_cross(pu, pv);
		double l = v3_len(nb);
		if (l > 0 && (hu != 0 || hv != 0)) {
			nb = v3_scale(nb, 1.0 / l);
			n = v3_dot(nb, n) < 0 ? v3_neg(nb) : nb;
		}
	}
	if (m->nmap) {
		vec3 c = texture_lookup(m->nmap, h->u, h->v, 0);
		double tx = 2 * c.x - 1, ty = 2 * c.y - 1, tz = 2 * c.z - 1;
		const double flat = 1.0 / 255 + 1e-6; /* the codes 127 and 128, as floats */
		if (fabs(tx) <= flat)
			tx = 0;
		if (fabs(ty) <= flat)
			ty = 0;
		if (tx != 0 || ty != 0) {
			vec3 tu = v3_sub(h->dpdu, v3_scale(n, v3_dot(n, h->dpdu)));
			double lt = v3_len(tu);
			if (lt > 0) {
				tu = v3_scale(tu, 1.0 / lt);
				vec3 bv = v3_cross(n, tu);
				if (v3_dot(bv, h->dpdv) < 0)
					bv = v3_neg(bv);
				vec3 nn = v3_add(v3_add(v3_scale(tu, tx), v3_scale(bv, ty)), v3_scale(n, tz));
				double l = v3_len(nn);
				if (l > 0)
					n = v3_scale(nn, 1.0 / l);
			}
		}
	}
	h->n = n;
}

static void apply_uv(const world *w, hit *h, double u, double v, vec3 dpdu, vec3 dpdv)
{
	const mat_tex *m = w->mats[h->mat].tx;
	h->has_uv = true;
	h->u = u * m->uvs[0] + m->uvo[0];
	h->v = v * m->uvs[1] + m->uvo[1];
	if (m->uvx[0] != 0 || m->uvx[1] != 0) { /* a glTF rotation: the inverse map carries the tangents */
		h->u += v * m->uvx[0];
		h->v += u * m->uvx[1];
		double a = m->uvs[0], b = m->uvx[0], c = m->uvx[1], d = m->uvs[1], det = a * d - b * c;
		h->dpdu = v3_scale(v3_sub(v3_scale(dpdu, d), v3_scale(dpdv, c)), 1.0 / det);
		h->dpdv = v3_scale(v3_sub(v3_scale(dpdv, a), v3_scale(dpdu, b)), 1.0 / det);
	} else {
		h->dpdu = v3_scale(dpdu, 1.0 / m->uvs[0]);
		h->dpdv = v3_scale(dpdv, 1.0 / m->uvs[1]);
	}
	perturb(w, h);
}

static bool wants_uv(const world *w, const hit *h)
{
	return surf_wants_uv(w, h->mat);
}

vec3 surf_inst_ng(const world *w, const prim *p, vec3 nl)
{
	const prim_inst *in = &w->insts[p->u.index];
	vec3 c[3];
	mesh_corners(in->mesh, (uint32_t)nl.x, c);
	return mat3x4_normal(in->inv, v3_cross(v3_sub(c[1], c[0]), v3_sub(c[2], c[0])));
}

void surf_inst_finish(const world *w, const prim *p, const ray *r, vec3 nl, hit *h)
{
	const prim_inst *in = &w->insts[p->u.index];
	const mesh *m = in->mesh;
	uint32_t slot = (uint32_t)nl.x;
	mesh_surf s;
	if (m->tri) {
		float b[3] = {0, (float)nl.y, (float)nl.z};
		b[0] = 1.0f - b[1] - b[2];
		mesh_surface(m, slot, b, &s);
	} else {
		/* flat and without uv (most models): the face's normal from the
		 * corners in its block, and its material */
		const mesh_tri4 *q = &m->blk[slot >> 2];
		uint32_t l = slot & 3;
		double e1x = (double)q->v[3][l] - q->v[0][l], e1y = (double)q->v[4][l] - q->v[1][l],
		       e1z = (double)q->v[5][l] - q->v[2][l];
		double e2x = (double)q->v[6][l] - q->v[0][l], e2y = (double)q->v[7][l] - q->v[1][l],
		       e2z = (double)q->v[8][l] - q->v[2][l];
		s.ng = v3(e1y * e2z - e1z * e2y, e1z * e2x - e1x * e2z, e1x * e2y - e1y * e2x);
		s.mat = m->nmats == 0 ? -1 : m->tmat ? m->tmat[mesh_slot_tri(m, slot)] : 0;
	}
	vec3 ng = v3_norm(mat3x4_normal(in->inv, s.ng));
	/* flat faces: the shading normal is the geometric one */
	vec3 ns = m->n ? v3_norm(mat3x4_normal(in->inv, s.ns)) : ng;
	mat3x4_point(in->inv, h->p, &h->local);
	h->front = v3_dot(ng, r->d) < 0.0;
	h->n = ns;
	h->mat = in->mat_base != UINT32_MAX && s.mat >= 0 ? in->mat_base + (uint32_t)s.mat : p->object;
	h->has_uv = false;
	if (m->uv && wants_uv(w, h))
		apply_uv(w, h, s.u, s.v, mat3x4_vector(in->fwd, s.dpdu), mat3x4_vector(in->fwd, s.dpdv));
	/* smooth meshes: rays leave from the smooth surface (mesh_surf.shift),
	 * unless they may pass through it (glass), where the point moved out
	 * would put the far side's rays in front of the face */
	const mat_lin *ml = &w->mats[h->mat];
	bool through = ml->family == MAT_PBR ? ml->pbr.transmission > 0 || ml->thin : ml->ior != 0;
	if (m->n && !through)
		h->p = v3_add(h->p, mat3x4_vector(in->fwd, s.shift));
}

/* The linear part of the inverse of a 3x4 matrix's linear part. */
static vec3 inv_vector(const double (*m)[4], vec3 v)
{
	double a = m[0][0], b = m[0][1], c = m[0][2], d = m[1][0], e = m[1][1], f = m[1][2], g = m[2][0],
	       hh = m[2][1], i = m[2][2];
	double A = e * i - f * hh, B = -(d * i - f * g), C = d * hh - e * g;
	double det = a * A + b * B + c * C;
	if (det == 0)
		return v3(0, 0, 0);
	double D = -(b * i - c * hh), E = a * i - c * g, F = -(a * hh - b * g);
	double G = b * f - c * e, H = -(a * f - c * d), I = a * e - b * d;
	return v3_scale(v3(A * v.x + D * v.y + G * v.z, B * v.x + E * v.y + H * v.z, C * v.x + F * v.y + I * v.z),
	                1.0 / det);
}

void surf_shape_uv(const world *w, const prim_shape *sh, vec3 nl, hit *h)
{
	h->mat = h->object;
	h->has_uv = false;
	if (!wants_uv(w, h))
		return;
	double u, v;
	vec3 du, dv;
	shape_uv((obj_kind)sh->kind, h->local, nl, sh->tube, &u, &v, &du, &dv);
	apply_uv(w, h, u, v, inv_vector(sh->inv, du), inv_vector(sh->inv, dv));
}

void surf_triangle_uv(const world *w, vec3 v0, vec3 e1, vec3 e2, hit *h)
{
	h->mat = h->object;
	h->has_uv = false;
	if (!wants_uv(w, h))
		return;
	/* p = v0 + u e1 + v e2, solved in the triangle's plane */
	vec3 d = v3_sub(h->p, v0);
	double a = v3_dot(e1, e1), b = v3_dot(e1, e2), c = v3_dot(e2, e2);
	double p = v3_dot(d, e1), q = v3_dot(d, e2), det = a * c - b * b;
	double u = det != 0 ? (c * p - b * q) / det : 0, v = det != 0 ? (a * q - b * p) / det : 0;
	apply_uv(w, h, u, v, e1, e2);
}

void surf_free(world *w)
{
	for (size_t i = 0; i < w->nmeshes; i++)
		mesh_cache_put(w->meshes[i]);
	for (size_t i = 0; i < w->ntexs; i++)
		texture_cache_put(w->texs[i]);
	free(w->meshes);
	free(w->texs);
	free(w->mtex);
	free(w->insts);
}

size_t surf_memory(const world *w)
{
	size_t n = w->ninsts * sizeof *w->insts + w->nmeshes * sizeof *w->meshes + w->nmtex * sizeof *w->mtex;
	for (size_t i = 0; i < w->nmeshes; i++)
		n += mesh_memory(w->meshes[i]);
	return n;
}
