/* rtsh — private interface between the renderer and its integrators. */
#ifndef RTSH_INTEGRATORS_H
#define RTSH_INTEGRATORS_H

#include "rtsh/render.h"
#include "sampler.h"

/* Radiance arriving along r (unit direction) by ambient + Phong + hard
 * shadows + mirror reflection / refraction up to s->depth (whitted.c). */
vec3 whitted_radiance(const world *w, const render_settings *s, ray r);
/* A Monte-Carlo estimate of the radiance along r (path.c); g is the sample's
 * own random stream. */
vec3 path_radiance(const world *w, const render_settings *s, ray r, rng *g);

/* What a ray that leaves the scene sees: the sky if the scene has one, else
 * black (whitted) or the ambient colour as a uniform sky (path). */
vec3 world_background(const world *w, vec3 dir, render_mode mode);

/* The surface colour at a hit (the checker texture applied). */
vec3 hit_albedo(const mat_lin *m, const hit *h);

/* A point just off the surface on the side of n, for spawning rays. */
static inline vec3 offset_point(const world *w, vec3 p, vec3 n)
{
	double e = w->eps + 1e-12 * v3_max_abs(p);
	return v3_madd(p, n, e);
}

#endif
