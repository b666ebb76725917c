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

static vec3 trace(const world *w, ray r, int depth);

static vec3 shade(const world *w, ray r, int depth, bool found, const hit *h)
{
	if (!found)
		return world_background(w, r.d, MODE_WHITTED);
	const mat_lin *m = &w->mats[h->mat];
	return mat_families[m->family]->whitted(w, m, h, r, depth, trace);
}

/* first: r is a camera ray (world_intersect_coherent) */
static vec3 trace_at(const world *w, ray r, int depth, bool first)
{
	hit h;
	bool found = (first ? world_intersect_coherent : world_intersect)(w, &r, 0.0, INFINITY, &h);
	return shade(w, r, depth, found, &h);
}

static vec3 trace(const world *w, ray r, int depth)
{
	return trace_at(w, r, depth, false);
}

vec3 whitted_radiance(const world *w, const render_settings *s, ray r)
{
	return trace_at(w, r, s->depth, true);
}

vec3 whitted_radiance_first(const world *w, const render_settings *s, ray r, bool found, const hit *h)
{
	return shade(w, r, s->depth, found, h);
}

static vec3 whitted_camera(const world *w, const render_settings *s, ray r, sampler *g)
{
	(void)g;
	return whitted_radiance(w, s, r);
}

static vec3 whitted_camera_first(const world *w, const render_settings *s, ray r, sampler *g, bool found,
                                 const hit *h)
{
	(void)g;
	return whitted_radiance_first(w, s, r, found, h);
}

/* Whitted draws no random numbers: one sample is the pixel's centre. */
const integrator whitted_integrator = {whitted_camera, whitted_camera_first, false, false};
