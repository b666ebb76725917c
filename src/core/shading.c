/* rtsh — shading helpers shared by the integrators. */
#include "integrators.h"
#include "envmap.h"
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

const mat_lin *hit_material(const mat_lin *m, const hit *h, mat_lin *tmp)
{
	if (m->family != MAT_PBR || !m->tx || !m->tx->mr || !h->has_uv)
		return m;
	double du = v3_len(h->dpdu);
	double width = du > 0 ? h->t * texture_pixel_angle() / du : 0;
	vec3 c = texture_lookup(m->tx->mr, h->u, h->v, width);
	*tmp = *m;
	tmp->pbr.roughness = (float)(m->pbr.roughness * clampd(c.y, 0.0, 1.0));
	tmp->pbr.metallic = (float)(m->pbr.metallic * clampd(c.z, 0.0, 1.0));
	tmp->pbr.es_ready = false; /* the plastic's specular albedo for this roughness: bsdf_pbr.c */
	return tmp;
}

vec3 hit_emission(const mat_lin *m, const hit *h)
{
	if (!m->tx || !m->tx->emit || !h->has_uv)
		return m->emission;
	double du = v3_len(h->dpdu);
	double width = du > 0 ? h->t * texture_pixel_angle() / du : 0;
	return v3_mul(m->emission, texture_lookup(m->tx->emit, h->u, h->v, width));
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
