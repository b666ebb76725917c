/* rtsh — the Whitted integrator: ambient + Phong per point light, hard
 * shadows, recursive mirror reflection and refraction (Whitted, "An improved
 * illumination model for shaded display", 1980; Phong 1975).
 *
 * Lights have no distance fall-off, as in miniRT: a light of ratio r and
 * colour c lights a surface facing it with r * c. */
#include "integrators.h"

/* Schlick's approximation of the Fresnel reflectance. */
static double schlick(double cos_i, double eta_ratio)
{
	double r0 = (1.0 - eta_ratio) / (1.0 + eta_ratio);
	r0 *= r0;
	double x = 1.0 - cos_i;
	return r0 + (1.0 - r0) * x * x * x * x * x;
}

/* first: r is a camera ray (world_intersect_coherent) */
static vec3 trace(const world *w, ray r, int depth, bool first)
{
	hit h;
	if (!(first ? world_intersect_coherent : world_intersect)(w, &r, 0.0, INFINITY, &h))
		return world_background(w, r.d, MODE_WHITTED);
	const mat_lin *m = &w->mats[h.mat];
	vec3 n = h.front ? h.n : v3_neg(h.n);
	vec3 albedo = hit_albedo(m, &h);
	vec3 v = v3_neg(r.d);
	vec3 p = offset_point(w, h.p, n);

	vec3 c = v3_add(v3_mul(w->ambient, albedo), m->emission);
	for (size_t i = 0; i < w->nlights; i++) {
		vec3 ld;
		double dist;
		vec3 lr = light_at(&w->lights[i], p, &ld, &dist); /* physical lights fall off */
		if (!(lr.x > 0.0 || lr.y > 0.0 || lr.z > 0.0))
			continue;
		double ndl = v3_dot(n, ld);
		if (ndl <= 0.0)
			continue;
		ray sr = {p, ld};
		if (world_occluded(w, &sr, 0.0, dist))
			continue;
		c = v3_add(c, v3_mul(lr, v3_scale(albedo, m->diffuse * ndl)));
		if (m->specular > 0.0) {
			double rv = v3_dot(v3_reflect(v3_neg(ld), n), v);
			if (rv > 0.0)
				c = v3_add(c, v3_scale(lr, m->specular * pow(rv, m->shininess)));
		}
	}
	if (depth <= 0)
		return c;

	if (m->ior >= 1.0) {
		/* A dielectric: Fresnel-weighted mirror and refracted rays. */
		double eta = h.front ? 1.0 / m->ior : m->ior;
		double cos_i = fmin(v3_dot(v, n), 1.0);
		double sin2_t = eta * eta * (1.0 - cos_i * cos_i);
		vec3 refl_dir = v3_reflect(r.d, n);
		vec3 refl = trace(w, (ray){p, refl_dir}, depth - 1, false);
		if (sin2_t >= 1.0)
			return v3_add(c, refl); /* total internal reflection */
		double kr = schlick(cos_i, h.front ? 1.0 / m->ior : m->ior);
		vec3 tdir = v3_add(v3_scale(r.d, eta), v3_scale(n, eta * cos_i - sqrt(1.0 - sin2_t)));
		vec3 q = offset_point(w, h.p, v3_neg(n));
		vec3 trans = trace(w, (ray){q, v3_norm(tdir)}, depth - 1, false);
		return v3_add(c, v3_add(v3_scale(refl, kr), v3_scale(v3_mul(trans, albedo), 1.0 - kr)));
	}
	if (m->reflective > 0.0) {
		vec3 refl = trace(w, (ray){p, v3_reflect(r.d, n)}, depth - 1, false);
		if (m->metal > 0.0)
			refl = v3_mul(refl, v3_lerp(v3(1, 1, 1), albedo, m->metal));
		c = v3_lerp(c, refl, m->reflective);
	}
	return c;
}

vec3 whitted_radiance(const world *w, const render_settings *s, ray r)
{
	return trace(w, r, s->depth, true);
}
