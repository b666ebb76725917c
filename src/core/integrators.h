/* rtsh — private interface between the renderer and its integrators. */
#ifndef RTSH_INTEGRATORS_H
#define RTSH_INTEGRATORS_H

#include "rtsh/render.h"
#include "sampler.h"

/* The camera ray of sample `sample` of pixel (px, py) of an fw x fh image,
 * and in *sp the sampler the integrator goes on with (camera.c). */
ray camera_sample_ray(const world *w, const render_settings *s, int px, int py, int fw, int fh, int sample,
                      sampler *sp);

/* Radiance arriving along r (unit direction) by ambient + Phong + hard
 * shadows + mirror reflection / refraction up to s->depth (whitted.c). */
vec3 whitted_radiance(const world *w, const render_settings *s, ray r);
/* A Monte-Carlo estimate of the radiance along r (path.c); g gives the
 * camera sample's numbers, from dimension g->dim on. */
vec3 path_radiance(const world *w, const render_settings *s, ray r, sampler *g);

/* The scattering at one path vertex (path.c): the material's lobes, each
 * with its share of the energy (shares sum to at most 1; see rtsh(5),
 * "Materials"), in the frame of the side the ray arrived on. */
typedef struct bsdf {
	vec3 n;        /* unit normal, flipped onto the side of wo */
	vec3 wo;       /* unit direction back along the arriving ray */
	double cos_o;  /* n . wo, >= 0 */
	bool front;    /* wo is on the outward side (glass: entering) */
	vec3 kd;       /* Lambert: share x albedo */
	vec3 ks;       /* normalised Phong about the mirror direction: share */
	double ns;     /* its exponent (shininess) */
	vec3 km;       /* mirror / metal: share x tint (Schlick) */
	double nm;     /* its Phong exponent (from fuzz); < 0 for a perfect mirror */
	vec3 kt;       /* glass transmission tint (reflection is white) */
	double wg;     /* glass share */
	double ior;    /* glass refractive index */
	double p[4];   /* lobe choice probabilities: d, s, m, g (sum 1, or all 0) */
	double total;  /* sum of the lobes' choice weights (0: absorbs everything) */
	bool smooth;   /* some non-delta lobe: point lights are seen through it */
} bsdf;

typedef struct bsdf_sample {
	vec3 wi;       /* the new direction (unit) */
	vec3 weight;   /* f cos / pdf, the lobe choice included (energy) */
	double radiance_scale; /* (eta_i / eta_t)^2 on refraction, else 1 */
	bool transmit; /* wi goes through the surface */
	bool delta;    /* from a perfect mirror or glass lobe */
} bsdf_sample;

/* The bsdf of material m at hit h seen from wo (unit, pointing away). */
void bsdf_make(bsdf *b, const mat_lin *m, const hit *h, vec3 wo);
/* The BSDF value f(wi, wo) of the non-delta lobes (per steradian). */
vec3 bsdf_eval(const bsdf *b, vec3 wi);
/* Samples a lobe and a direction from three uniform numbers: u[0] picks
 * the lobe (and, rescaled, glass's reflection or refraction), u[1], u[2]
 * the direction; false when the path is absorbed. */
bool bsdf_sample_u(const bsdf *b, const double u[3], bsdf_sample *out);
/* The same with three numbers from g. */
bool bsdf_sample_dir(const bsdf *b, rng *g, bsdf_sample *out);
/* The Phong exponent of a mirror lobe of roughness fuzz in (0,1]. */
double fuzz_exponent(double fuzz);

/* The mixed density with which bsdf_sample_dir picks the direction wi
 * through a smooth lobe (per steradian; delta lobes are left out). */
double bsdf_pdf(const bsdf *b, vec3 wi);

/* What a ray that leaves the scene sees: the sky if the scene has one, else
 * black (whitted) or the ambient colour as a uniform sky (path). */
vec3 world_background(const world *w, vec3 dir, render_mode mode);

/* The surface colour at a hit (the checker texture applied). */
vec3 hit_albedo(const mat_lin *m, const hit *h);

/* A point just off the surface on the side of n, for spawning rays. */
static inline vec3 offset_point(const world *w, vec3 p, vec3 n)
{
	double ax = fabs(p.x), ay = fabs(p.y), az = fabs(p.z); /* not fmax: a library call */
	double m = ax > ay ? ax : ay;
	double e = w->eps + 1e-12 * (m > az ? m : az);
	return v3_madd(p, n, e);
}

#endif
