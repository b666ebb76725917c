/* rtsh — the Whitted integrator: ambient + direct light per point light,
 * hard shadows, recursive mirror reflection and refraction (Whitted, "An
 * improved illumination model for shaded display", 1980). Each material
 * family shades its own hits (mat_family.whitted): Phong for the seeds'
 * materials (bsdf_phong.c), the same BRDF as in path mode for PBR ones
 * (bsdf_pbr.c).
 *
 * Lights have no distance fall-off, as in miniRT: a light of ratio r and
 * colour c lights a surface facing it with r * c. */
#include "integrators.h"

/* Schlick's approximation of the Fresnel reflectance. */
double whitted_schlick(double cos_i, double eta_ratio)
{
	double r0 = (1.0 - eta_ratio) / (1.0 + eta_ratio);
	r0 *= r0;
	double x = 1.0 - cos_i;
	return r0 + (1.0 - r0) * x * x * x * x * x;
}

static vec3 trace(const world *w, ray r, int depth);

/* first: r is a camera ray (world_intersect_coherent) */
static vec3 trace_at(const world *w, ray r, int depth, bool first)
{
	hit h;
	if (!(first ? world_intersect_coherent : world_intersect)(w, &r, 0.0, INFINITY, &h))
		return world_background(w, r.d, MODE_WHITTED);
	const mat_lin *m = &w->mats[h.mat];
	return mat_families[m->family]->whitted(w, m, &h, r, depth, trace);
}

static vec3 trace(const world *w, ray r, int depth)
{
	return trace_at(w, r, depth, false);
}

vec3 whitted_radiance(const world *w, const render_settings *s, ray r)
{
	return trace_at(w, r, s->depth, true);
}

vec3 whitted_lights(const world *w, const bsdf *b, vec3 p)
{
	vec3 c = v3(0, 0, 0);
	for (size_t i = 0; i < w->nlights; i++) {
		vec3 ld;
		double dist;
		vec3 lr = light_at(&w->lights[i], p, &ld, &dist); /* physical lights fall off */
		if (!(lr.x > 0.0 || lr.y > 0.0 || lr.z > 0.0))
			continue;
		double ndl = v3_dot(b->n, ld);
		if (ndl <= 0.0)
			continue;
		vec3 f = bsdf_eval(b, ld);
		if (f.x <= 0.0 && f.y <= 0.0 && f.z <= 0.0)
			continue;
		ray sr = {p, ld};
		if (world_occluded(w, &sr, 0.0, dist))
			continue;
		c = v3_add(c, v3_mul(f, v3_scale(lr, RT_PI * ndl)));
	}
	return c;
}
