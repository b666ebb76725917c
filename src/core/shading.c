/* rtsh — shading helpers shared by the integrators. */
#include "integrators.h"
#include "envmap.h"
#include "warp.h"
#include "rtsh/texture.h"

vec3 world_background(const world *w, vec3 dir, render_mode mode)
{
	if (w->env)
		return envmap_eval(w->env, dir);
	if (w->has_sky) {
		/* The height gradient of the path-tracer seed: horizon at and
		 * below y = 0, zenith straight up. */
		double t = clampd(dir.y / v3_len(dir), 0.0, 1.0);
		return v3_lerp(w->sky_horizon, w->sky_zenith, t);
	}
	return mode == MODE_PATH ? w->ambient : v3(0, 0, 0);
}

vec3 hit_albedo(const mat_lin *m, const hit *h)
{
	if (m->tx && m->tx->tex && h->has_uv) {
		/* the footprint of a pixel at this distance, in u units */
		double du = v3_len(h->dpdu);
		double width = du > 0 ? h->t * texture_pixel_angle() / du : 0;
		vec3 c = texture_lookup(m->tx->tex, h->u, h->v, width);
		return m->tx->tint ? v3_mul(c, m->albedo) : c;
	}
	if (m->checker <= 0.0)
		return m->albedo;
	/* Alternate squares of side 1/checker object units are darkened. */
	double k = m->checker;
	long s = (long)floor(h->local.x * k + 1e-9) + (long)floor(h->local.y * k + 1e-9) +
	         (long)floor(h->local.z * k + 1e-9);
	return (s & 1) ? v3_scale(m->albedo, 0.2) : m->albedo;
}

void bsdf_begin(bsdf *b, const mat_lin *m, const hit *h, vec3 wo)
{
	*b = (bsdf){0};
	b->n = h->front ? h->n : v3_neg(h->n);
	b->wo = wo;
	b->front = h->front;
	b->cos_o = pos(v3_dot(b->n, wo));
	b->family = m->family < MAT_FAMILY_COUNT ? m->family : MAT_PHONG;
}

vec3 whitted_lights(const world *w, const bsdf *b, vec3 p, vec3 (*eval)(const bsdf *b, vec3 wi))
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
		vec3 f = eval(b, ld);
		if (f.x <= 0.0 && f.y <= 0.0 && f.z <= 0.0)
			continue;
		ray sr = {p, ld};
		if (world_occluded(w, &sr, 0.0, dist))
			continue;
		c = v3_add(c, v3_mul(f, v3_scale(lr, RT_PI * ndl)));
	}
	return c;
}

/* Schlick's approximation of the Fresnel reflectance. */
double whitted_schlick(double cos_i, double eta_ratio)
{
	double r0 = (1.0 - eta_ratio) / (1.0 + eta_ratio);
	r0 *= r0;
	double x = 1.0 - cos_i;
	return r0 + (1.0 - r0) * x * x * x * x * x;
}
