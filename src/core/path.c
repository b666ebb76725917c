/* rtsh — the path-tracing integrator: a Monte-Carlo estimate of the
 * rendering equation (Kajiya, "The rendering equation", SIGGRAPH 1986).
 *
 * One path per camera sample. At every vertex the path adds the emission it
 * finds, adds next-event estimation toward every point light (a shadow ray
 * each; point lights cannot be hit by a path, so nothing is counted twice)
 * and toward one emissive sphere, rectangle, disc or triangle (whose light
 * the path can also find: the two estimates are weighed by multiple
 * importance sampling), then picks one lobe of the material and continues
 * in a direction sampled from it. Russian roulette ends paths after the
 * third bounce without bias (Arvo & Kirk, "Particle transport and image
 * synthesis", 1990).
 *
 * Materials are of a family (material.c: the seeds' Phong lobes in
 * bsdf_phong.c, glTF's metallic-roughness model in bsdf_pbr.c) that gives
 * the bsdf's value, density and samples. Surfaces are two-sided: the normal
 * is turned to the side the ray came from; glass uses the side to know
 * whether the ray enters or leaves. A rough transmission sees the lights
 * below the surface too, and a PBR volume absorbs along the path inside it
 * (Beer-Lambert).
 *
 * Point lights follow the Whitted convention (no fall-off): a light of
 * radiance ratio L gives a surface the irradiance pi * L * cos(theta), so a
 * white Lambertian surface facing it sends back exactly L. */
#include "integrators.h"
#include "envmap.h"

#include "emitters.h"
#include "warp.h"

#include <stdlib.h>

/* Next-event estimation: the light the point lights send to the vertex
 * through its smooth lobes. */
static vec3 direct_light(const world *w, const bsdf *b, vec3 p, vec3 pdn)
{
	vec3 sum = v3(0, 0, 0);
	for (size_t i = 0; i < w->nlights; i++) {
		const light_lin *l = &w->lights[i];
		vec3 o = p, wi;
		double dist;
		vec3 lr = light_at(l, o, &wi, &dist); /* physical lights fall off */
		if (!(lr.x > 0.0 || lr.y > 0.0 || lr.z > 0.0))
			continue;
		double c = v3_dot(b->n, wi);
		if (c <= 0.0) {
			/* a light below the surface, seen through a rough transmission */
			if (!b->through)
				continue;
			o = pdn;
			lr = light_at(l, o, &wi, &dist);
			c = -v3_dot(b->n, wi);
			if (!(lr.x > 0.0 || lr.y > 0.0 || lr.z > 0.0) || c <= 0.0)
				continue;
		}
		vec3 f = bsdf_eval(b, wi);
		if (f.x <= 0.0 && f.y <= 0.0 && f.z <= 0.0)
			continue;
		ray sr = {o, wi};
		if (world_occluded(w, &sr, 0.0, dist))
			continue;
		/* f x irradiance, the irradiance being pi L cos (see above) */
		sum = v3_add(sum, v3_mul(f, v3_scale(lr, RT_PI * c)));
	}
	return sum;
}

/* The power heuristic weight of a technique of density a against one of b. */
static double power_weight(double a, double b)
{
	return a * a / (a * a + b * b);
}

/* The part of next-event estimation both kinds of light share: the bsdf
 * toward wi in *f and the cosine in *cos_i, false when either is nothing
 * or something stands between p and distance tmax along wi. Below the
 * surface, through a rough transmission only, from the other side (pdn;
 * the direction from p is kept: the two points are a rounding error
 * apart). */
static inline bool unoccluded_eval(const world *w, const bsdf *b, vec3 p, vec3 pdn, vec3 wi, double tmax,
                                   vec3 *f, double *cos_i)
{
	double c = v3_dot(b->n, wi);
	if (c <= 0.0) {
		if (!b->through)
			return false;
		c = -c;
		p = pdn;
	}
	*f = bsdf_eval(b, wi);
	if (f->x <= 0.0 && f->y <= 0.0 && f->z <= 0.0)
		return false;
	ray sr = {p, wi};
	if (world_occluded(w, &sr, 0.0, tmax))
		return false;
	*cos_i = c;
	return true;
}

/* Next-event estimation toward one emitter picked uniformly: a direction
 * from the emitter's solid angle (spheres: the uniform cone they subtend)
 * or area (flat shapes), the emission if nothing is in between, weighted
 * against the chance that the bsdf would have picked the same direction.
 * A vertex on object `self` skips it: a flat or convex surface cannot light
 * itself, and sampling it from just off its surface would only add noise. */
static vec3 emitter_light(const world *w, const bsdf *b, vec3 p, vec3 pdn, uint32_t self, sampler *g)
{
	/* u1 picks the emitter, and its place in the emitter's share is a
	 * fresh uniform number */
	double u1, u2;
	samp_2d(g, &u1, &u2);
	double n = (double)w->nemitters, kd = floor(u1 * n);
	size_t k = kd < n ? (size_t)kd : w->nemitters - 1;
	u1 = u1 * n - (double)k;
	const emitter *e = &w->emitters[k];
	if (e->object == self)
		return v3(0, 0, 0);
	vec3 wi;
	double pdf, t;
	if (!emitter_sample(e, p, u1, u2, &wi, &pdf, &t))
		return v3(0, 0, 0);
	/* nothing may stand between: an any-hit query that stops just short
	 * of the emitter's surface (of a model's triangle, whose
	 * single-precision test may find it a little nearer than t, shorter) */
	vec3 f;
	double cos_i;
	if (!unoccluded_eval(w, b, p, pdn, wi, t * (1.0 - (e->object == UINT32_MAX ? 1e-5 : 1e-7)), &f, &cos_i))
		return v3(0, 0, 0);
	double pdf_l = pdf / (double)w->nemitters;
	double weight = power_weight(pdf_l, bsdf_pdf(b, wi));
	return v3_mul(f, v3_scale(w->mats[e->mat].emission, cos_i * weight / pdf_l));
}

/* Next-event estimation toward the sky from p (pdn below the surface, for a
 * rough transmission): a direction picked by the sky's luminance
 * (envmap_sample), weighted by the power heuristic against the bsdf's own
 * sampling. */
static vec3 sky_light(const world *w, const bsdf *b, vec3 p, vec3 pdn, sampler *g)
{
	const envmap *e = w->env;
	double u1, u2, pdf;
	samp_2d(g, &u1, &u2);
	vec3 wi = envmap_sample(e, u1, u2, &pdf);
	if (!(pdf > 0))
		return v3(0, 0, 0);
	vec3 f;
	double cos_i;
	if (!unoccluded_eval(w, b, p, pdn, wi, INFINITY, &f, &cos_i))
		return v3(0, 0, 0);
	double wt = power_weight(pdf, bsdf_pdf(b, wi));
	return v3_mul(f, v3_scale(envmap_eval(e, wi), cos_i * wt / pdf));
}

vec3 path_radiance(const world *w, const render_settings *s, ray r, sampler *g)
{
	hit h;
	bool found = world_intersect_coherent(w, &r, 0.0, INFINITY, &h);
	return path_radiance_first(w, s, r, g, found, &h);
}

vec3 path_radiance_first(const world *w, const render_settings *s, ray r, sampler *g, bool found, const hit *first)
{
	/* Each bounce has its own dimensions whatever happens at it: the light
	 * (2), the bsdf (3) and Russian roulette (1). */
	const uint32_t dim0 = g->dim;
	vec3 radiance = v3(0, 0, 0), thr = v3(1, 1, 1);
	/* The product of (eta_t / eta_i)^2 over the refractions so far: it
	 * undoes their radiance scaling for Russian roulette (pbrt 4th ed.
	 * 13.1.5). */
	double eta_scale = 1.0;
	/* Absorption per unit along r: inside a PBR volume (Beer-Lambert). */
	vec3 sigma = v3(0, 0, 0);
	/* Where the ray r left and with what density its direction was picked,
	 * when the emitters were also sampled there (0: weigh emission by 1). */
	vec3 from = r.o;
	double from_pdf = 0.0;
	double env_from_pdf = 0.0; /* the same for the HDR sky (envmap.c) */
	for (int bounce = 0;; bounce++) {
		g->dim = dim0 + 6u * (uint32_t)bounce;
		hit h;
		bool met = bounce == 0 ? found : world_intersect(w, &r, 0.0, INFINITY, &h);
		if (bounce == 0 && found)
			h = *first;
		if (!met) {
			vec3 bg = world_background(w, r.d, MODE_PATH);
			if (w->env && env_from_pdf > 0.0) {
				double pe = envmap_pdf(w->env, r.d);
				bg = v3_scale(bg, env_from_pdf * env_from_pdf / (env_from_pdf * env_from_pdf + pe * pe));
			}
			radiance = v3_add(radiance, v3_mul(thr, bg));
			break;
		}
		if (sigma.x > 0.0 || sigma.y > 0.0 || sigma.z > 0.0)
			thr = v3_mul(thr, v3(exp(-sigma.x * h.t), exp(-sigma.y * h.t), exp(-sigma.z * h.t)));
		const mat_lin *m = &w->mats[h.mat];
		if (m->light >= 0 && from_pdf > 0.0) {
			double pdf_l = emitter_pdf(emitter_at(w, m->light, h.p), from, r.d, h.t) /
			               (double)w->nemitters;
			radiance = v3_add(radiance, v3_mul(thr, v3_scale(hit_emission(m, &h),
			                                                 power_weight(from_pdf, pdf_l))));
		} else {
			radiance = v3_add(radiance, v3_mul(thr, hit_emission(m, &h)));
		}
		if (bounce >= s->depth)
			break;
		bsdf b;
		bsdf_make(&b, m, &h, v3_neg(r.d));
		vec3 p = offset_point(w, h.p, b.n);
		vec3 pdn = b.through ? offset_point(w, h.p, v3_neg(b.n)) : p;
		if (b.smooth && w->nlights)
			radiance = v3_add(radiance, v3_mul(thr, direct_light(w, &b, p, pdn)));
		bool sample_emitters = b.smooth && w->nemitters;
		if (sample_emitters)
			radiance = v3_add(radiance, v3_mul(thr, emitter_light(w, &b, p, pdn, h.object, g)));
		if (b.smooth && w->env) {
			/* the sky's two numbers: hashed dimensions of their own, far
			 * from the bounces' */
			g->dim = (1u << 20) + 2u * (uint32_t)bounce;
			radiance = v3_add(radiance, v3_mul(thr, sky_light(w, &b, p, pdn, g)));
		}

		g->dim = dim0 + 6u * (uint32_t)bounce + 2u;
		double u[3];
		u[0] = bsdf_has_choice(&b) ? samp_1d(g) : 0.5; /* a lone lobe: no choice */
		g->dim = dim0 + 6u * (uint32_t)bounce + 3u;
		samp_2d(g, &u[1], &u[2]);
		bsdf_sample bs;
		if (!bsdf_sample_u(&b, u, &bs))
			break;
		thr = v3_mul(thr, v3_scale(bs.weight, bs.radiance_scale));
		eta_scale /= bs.radiance_scale;
		r = (ray){bs.transmit ? offset_point(w, h.p, v3_neg(b.n)) : p, bs.wi};
		if (bs.transmit) /* into the volume below, or out of it */
			sigma = b.front ? b.sigma_in : v3(0, 0, 0);
		from = r.o;
		double spdf = bs.delta || !(sample_emitters || (b.smooth && w->env)) ? 0.0
		              : bs.pdf >= 0.0                                       ? bs.pdf
		                                                                    : bsdf_pdf(&b, bs.wi);
		from_pdf = sample_emitters && !bs.delta ? spdf : 0.0;
		env_from_pdf = b.smooth && w->env && !bs.delta ? spdf : 0.0;

		/* Russian roulette after the third bounce: survive with q, weigh
		 * the survivors by 1 / q. q is the square root of the throughput,
		 * as in Cycles: paths end a little later, which costs 5% more time
		 * on the Cornell box and takes 14% off its noise. */
		if (bounce >= 3) {
			double q = sqrt(max3(thr) * eta_scale);
			q = q < 0.95 ? q : 0.95;
			if (!(q > 0.0) || samp_1d(g) >= q)
				break;
			thr = v3_scale(thr, 1.0 / q);
		}
	}
	return radiance;
}

static vec3 path_camera_first(const world *w, const render_settings *s, ray r, sampler *g, bool found,
                              const hit *h, uint32_t known, uint32_t blocked)
{
	(void)known, (void)blocked;
	return path_radiance_first(w, s, r, g, found, h);
}

/* Path mode samples every pixel and gives the denoiser its features. */
const integrator path_integrator = {path_radiance, path_camera_first, NULL, true, true};
