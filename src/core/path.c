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
 * Materials are a mix of lobes whose shares never sum above 1 (rtsh(5),
 * "Materials"):
 *   mirror   share `reflective`; tinted by the colour x `metal` with
 *            Schlick's Fresnel; `fuzz` widens it into a Phong lobe
 *   glass    when ior >= 1, the rest: exact dielectric Fresnel, refraction
 *            tinted by the colour, total internal reflection
 *   diffuse  otherwise the rest, split between Lambert (`diffuse` x colour)
 *   specular and a normalised Phong lobe (`specular`, `shininess`), both
 *            scaled down together when diffuse + specular > 1
 * Surfaces are two-sided: the normal is turned to the side the ray came
 * from; glass uses the side to know whether the ray enters or leaves.
 *
 * Point lights follow the Whitted convention (no fall-off): a light of
 * radiance ratio L gives a surface the irradiance pi * L * cos(theta), so a
 * white Lambertian surface facing it sends back exactly L. */
#include "integrators.h"
#include "envmap.h"

#include "emitters.h"
#include "warp.h"

#include <stdlib.h>

/* Cosine-weighted about n, pdf cos / pi: a uniform point of the unit disc
 * lifted onto the hemisphere (Malley's method). */
static vec3 sample_cosine(vec3 n, double u, double v)
{
	double x, y;
	warp_disc(u, v, &x, &y);
	vec3 t, b;
	basis(n, &t, &b);
	return v3_add(v3_add(v3_scale(t, x), v3_scale(b, y)), v3_scale(n, sqrt(pos(1.0 - x * x - y * y))));
}

/* Proportional to cos^e of the angle to axis, pdf (e + 1) / (2 pi) cos^e
 * (Lafortune & Willems, "Using the modified Phong reflectance model for
 * physically based rendering", 1994): u picks the angle, v the azimuth. */
static vec3 sample_phong(vec3 axis, double e, double u, double v)
{
	double cos_a = pow(1.0 - u, 1.0 / (e + 1.0)), c, sn;
	warp_circle(v, &c, &sn);
	double k = sqrt(pos(1.0 - cos_a * cos_a));
	vec3 t, b;
	basis(axis, &t, &b);
	return v3_add(v3_add(v3_scale(t, c * k), v3_scale(b, sn * k)), v3_scale(axis, cos_a));
}

/* The normalised Phong lobe (e + 2) / (2 pi) cos^e a: its albedo is 1 at
 * normal incidence and less elsewhere (Lafortune & Willems 1994). */
static double phong_lobe(double cos_a, double e)
{
	return cos_a > 0.0 ? (e + 2.0) * (0.5 / RT_PI) * pow(cos_a, e) : 0.0;
}

/* Reflectance of a smooth dielectric for unpolarised light, from the
 * Fresnel equations (Born & Wolf, "Principles of Optics", 1.5.2; pbrt 4th
 * ed. 9.3.2). cos_i > 0 on the incident side; eta = eta_t / eta_i. Sets
 * *cos_t for the refracted ray; 1 on total internal reflection. */
static double fresnel_dielectric(double cos_i, double eta, double *cos_t)
{
	double sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
	if (sin2_t >= 1.0) {
		*cos_t = 0.0;
		return 1.0;
	}
	double ct = sqrt(1.0 - sin2_t);
	double rs = (cos_i - eta * ct) / (cos_i + eta * ct);
	double rp = (eta * cos_i - ct) / (eta * cos_i + ct);
	*cos_t = ct;
	return 0.5 * (rs * rs + rp * rp);
}

double fuzz_exponent(double fuzz)
{
	/* A mirror direction perturbed by fuzz times a random point of the unit
	 * ball (the seed's metal) spreads by E[a^2] = 0.4 fuzz^2; the lobe
	 * cos^e a spreads by E[a^2] ~ 2 / (e + 2). Equal when: */
	return 5.0 / (fuzz * fuzz) - 2.0;
}

void bsdf_make(bsdf *b, const mat_lin *m, const hit *h, vec3 wo)
{
	*b = (bsdf){0};
	b->n = h->front ? h->n : v3_neg(h->n);
	b->wo = wo;
	b->front = h->front;
	b->cos_o = pos(v3_dot(b->n, wo));
	vec3 albedo = hit_albedo(m, h);
	double mirror = clampd(m->reflective, 0.0, 1.0), rest = 1.0 - mirror;
	double w[4] = {0, 0, 0, 0};
	if (m->ior >= 1.0) {
		b->wg = rest;
		b->kt = albedo;
		b->ior = m->ior;
		w[3] = rest;
	} else {
		double d = clampd(m->diffuse, 0.0, 1.0), s = clampd(m->specular, 0.0, 1.0);
		double k = d + s > 1.0 ? rest / (d + s) : rest;
		b->kd = v3_scale(albedo, d * k);
		b->ks = v3_splat(s * k);
		b->ns = pos(m->shininess);
		w[0] = max3(b->kd);
		w[1] = s * k;
	}
	if (mirror > 0.0) {
		/* Schlick's Fresnel for a conductor whose normal-incidence
		 * reflectance is the tint (Schlick, "An inexpensive BRDF model for
		 * physically-based rendering", 1994). */
		vec3 f0 = v3_lerp(v3_splat(1.0), albedo, clampd(m->metal, 0.0, 1.0));
		double x = 1.0 - b->cos_o, x5 = x * x * x * x * x;
		b->km = v3_scale(v3_add(f0, v3_scale(v3_sub(v3_splat(1.0), f0), x5)), mirror);
		b->nm = m->fuzz > 0.0 ? fuzz_exponent(m->fuzz < 1.0 ? m->fuzz : 1.0) : -1.0;
		w[2] = max3(b->km);
	} else {
		b->nm = -1.0;
	}
	b->total = w[0] + w[1] + w[2] + w[3];
	if (b->total > 0.0)
		for (int i = 0; i < 4; i++)
			b->p[i] = w[i] / b->total;
	b->smooth = w[0] > 0.0 || w[1] > 0.0 || (w[2] > 0.0 && b->nm >= 0.0);
}

vec3 bsdf_eval(const bsdf *b, vec3 wi)
{
	double c = v3_dot(b->n, wi);
	if (c <= 0.0 || !b->smooth)
		return v3(0, 0, 0);
	vec3 f = v3_scale(b->kd, 1.0 / RT_PI);
	vec3 r = v3_sub(v3_scale(b->n, 2.0 * b->cos_o), b->wo); /* wo mirrored */
	double cos_r = v3_dot(wi, r);
	if (b->p[1] > 0.0)
		f = v3_madd(f, b->ks, phong_lobe(cos_r, b->ns));
	if (b->p[2] > 0.0 && b->nm >= 0.0)
		f = v3_madd(f, b->km, phong_lobe(cos_r, b->nm));
	return f;
}

/* The density of sample_phong's directions. */
static double phong_pdf(double cos_a, double e)
{
	return cos_a > 0.0 ? (e + 1.0) * (0.5 / RT_PI) * pow(cos_a, e) : 0.0;
}

double bsdf_pdf(const bsdf *b, vec3 wi)
{
	double c = v3_dot(b->n, wi);
	if (c <= 0.0 || !b->smooth)
		return 0.0;
	double pdf = b->p[0] * c / RT_PI;
	vec3 r = v3_sub(v3_scale(b->n, 2.0 * b->cos_o), b->wo);
	double cos_r = v3_dot(wi, r);
	if (b->p[1] > 0.0)
		pdf += b->p[1] * phong_pdf(cos_r, b->ns);
	if (b->p[2] > 0.0 && b->nm >= 0.0)
		pdf += b->p[2] * phong_pdf(cos_r, b->nm);
	return pdf;
}

bool bsdf_sample_dir(const bsdf *b, rng *g, bsdf_sample *out)
{
	double u[3] = {rng_next(g), rng_next(g), rng_next(g)};
	return bsdf_sample_u(b, u, out);
}

bool bsdf_sample_u(const bsdf *b, const double u[3], bsdf_sample *out)
{
	if (!(b->total > 0.0))
		return false;
	double u0 = u[0];
	int lobe = 0;
	double below = 0.0, acc = b->p[0];
	while (lobe < 3 && (u0 >= acc || b->p[lobe] == 0.0)) {
		below = acc;
		acc += b->p[++lobe];
	}
	while (lobe > 0 && b->p[lobe] == 0.0) /* u0 past a sum rounded below 1 */
		below -= b->p[--lobe];
	/* Each lobe's f cos / pdf, times 1 / (its choice probability). */
	double inv_p = 1.0 / b->p[lobe];
	vec3 r = v3_sub(v3_scale(b->n, 2.0 * b->cos_o), b->wo);
	out->radiance_scale = 1.0;
	out->transmit = false;
	out->delta = false;
	switch (lobe) {
	case 0: /* Lambert: f cos / pdf = (kd / pi) cos / (cos / pi) */
		out->wi = sample_cosine(b->n, u[1], u[2]);
		out->weight = v3_scale(b->kd, inv_p);
		return true;
	case 1:
	case 2: {
		double e = lobe == 1 ? b->ns : b->nm;
		vec3 k = lobe == 1 ? b->ks : b->km;
		if (e < 0.0) { /* a perfect mirror */
			out->wi = r;
			out->weight = v3_scale(k, inv_p);
			out->delta = true;
			return true;
		}
		out->wi = sample_phong(r, e, u[1], u[2]);
		double c = v3_dot(out->wi, b->n);
		if (c <= 0.0)
			return false; /* below the surface: the lobe's lost energy */
		/* ((e+2)/(2 pi) cos^e a) cos / ((e+1)/(2 pi) cos^e a) */
		out->weight = v3_scale(k, inv_p * (e + 2.0) / (e + 1.0) * c);
		return true;
	}
	default: { /* glass: reflect with probability F, else refract */
		double eta = b->front ? b->ior : 1.0 / b->ior, cos_t;
		double f = fresnel_dielectric(b->cos_o, eta, &cos_t);
		out->delta = true;
		/* u0's place inside the lobe's share: a fresh uniform number */
		if ((u0 - below) * inv_p < f) {
			out->wi = r;
			out->weight = v3_splat(b->wg * inv_p);
			return true;
		}
		/* Snell's law in vector form (pbrt 4th ed. 9.3.2). */
		vec3 t = v3_add(v3_scale(b->wo, -1.0 / eta), v3_scale(b->n, b->cos_o / eta - cos_t));
		out->wi = v3_norm(t);
		out->weight = v3_scale(b->kt, b->wg * inv_p);
		/* Radiance is compressed by (eta_t / eta_i)^2 across the
		 * interface (Veach, thesis 1997, 5.2). */
		out->radiance_scale = 1.0 / (eta * eta);
		out->transmit = true;
		return true;
	}
	}
}

/* Next-event estimation: the light the point lights send to the vertex
 * through its smooth lobes. */
static vec3 direct_light(const world *w, const bsdf *b, vec3 p)
{
	vec3 sum = v3(0, 0, 0);
	for (size_t i = 0; i < w->nlights; i++) {
		vec3 wi;
		double dist;
		vec3 lr = light_at(&w->lights[i], p, &wi, &dist); /* physical lights fall off */
		if (!(lr.x > 0.0 || lr.y > 0.0 || lr.z > 0.0))
			continue;
		double c = v3_dot(b->n, wi);
		if (c <= 0.0)
			continue;
		vec3 f = bsdf_eval(b, wi);
		if (f.x <= 0.0 && f.y <= 0.0 && f.z <= 0.0)
			continue;
		ray sr = {p, wi};
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

/* Next-event estimation toward one emitter picked uniformly: a direction
 * from the emitter's solid angle (spheres: the uniform cone they subtend)
 * or area (flat shapes), the emission if nothing is in between, weighted
 * against the chance that the bsdf would have picked the same direction.
 * A vertex on object `self` skips it: a flat or convex surface cannot light
 * itself, and sampling it from just off its surface would only add noise. */
static vec3 emitter_light(const world *w, const bsdf *b, vec3 p, uint32_t self, sampler *g)
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
	double cos_i = v3_dot(b->n, wi);
	if (cos_i <= 0.0)
		return v3(0, 0, 0);
	vec3 f = bsdf_eval(b, wi);
	if (f.x <= 0.0 && f.y <= 0.0 && f.z <= 0.0)
		return v3(0, 0, 0);
	/* Nothing may stand between: an any-hit query that stops just short
	 * of the emitter's surface. */
	ray sr = {p, wi};
	if (world_occluded(w, &sr, 0.0, t * (1.0 - 1e-7)))
		return v3(0, 0, 0);
	double pdf_l = pdf / (double)w->nemitters;
	double weight = power_weight(pdf_l, bsdf_pdf(b, wi));
	return v3_mul(f, v3_scale(w->mats[e->object].emission, cos_i * weight / pdf_l));
}

/* Next-event estimation toward the sky from p: a direction picked by the
 * sky's luminance (envmap_sample), weighted by the power heuristic against
 * the bsdf's own sampling. */
static vec3 sky_light(const world *w, const bsdf *b, vec3 p, sampler *g)
{
	const envmap *e = w->env;
	double u1, u2, pdf;
	samp_2d(g, &u1, &u2);
	vec3 wi = envmap_sample(e, u1, u2, &pdf);
	if (!(pdf > 0))
		return v3(0, 0, 0);
	double cos_i = v3_dot(b->n, wi);
	if (cos_i <= 0)
		return v3(0, 0, 0);
	vec3 f = bsdf_eval(b, wi);
	if (f.x <= 0 && f.y <= 0 && f.z <= 0)
		return v3(0, 0, 0);
	ray sr = {p, wi};
	if (world_occluded(w, &sr, 0.0, INFINITY))
		return v3(0, 0, 0);
	double wt = power_weight(pdf, bsdf_pdf(b, wi));
	return v3_mul(f, v3_scale(envmap_eval(e, wi), cos_i * wt / pdf));
}

vec3 path_radiance(const world *w, const render_settings *s, ray r, sampler *g)
{
	/* Each bounce has its own dimensions whatever happens at it: the light
	 * (2), the bsdf (3) and Russian roulette (1). */
	const uint32_t dim0 = g->dim;
	vec3 radiance = v3(0, 0, 0), thr = v3(1, 1, 1);
	/* The product of (eta_t / eta_i)^2 over the refractions so far: it
	 * undoes their radiance scaling for Russian roulette (pbrt 4th ed.
	 * 13.1.5). */
	double eta_scale = 1.0;
	/* Where the ray r left and with what density its direction was picked,
	 * when the emitters were also sampled there (0: weigh emission by 1). */
	vec3 from = r.o;
	double from_pdf = 0.0;
	double env_from_pdf = 0.0; /* the same for the HDR sky (envmap.c) */
	for (int bounce = 0;; bounce++) {
		g->dim = dim0 + 6u * (uint32_t)bounce;
		hit h;
		if (!(bounce == 0 ? world_intersect_coherent : world_intersect)(w, &r, 0.0, INFINITY, &h)) {
			vec3 bg = world_background(w, r.d, MODE_PATH);
			if (w->env && env_from_pdf > 0.0) {
				double pe = envmap_pdf(w->env, r.d);
				bg = v3_scale(bg, env_from_pdf * env_from_pdf / (env_from_pdf * env_from_pdf + pe * pe));
			}
			radiance = v3_add(radiance, v3_mul(thr, bg));
			break;
		}
		const mat_lin *m = &w->mats[h.mat];
		if (m->light >= 0 && from_pdf > 0.0) {
			double pdf_l = emitter_pdf(&w->emitters[m->light], from, r.d, h.t) /
			               (double)w->nemitters;
			radiance = v3_add(radiance, v3_mul(thr, v3_scale(m->emission,
			                                                 power_weight(from_pdf, pdf_l))));
		} else {
			radiance = v3_add(radiance, v3_mul(thr, m->emission));
		}
		if (bounce >= s->depth)
			break;
		bsdf b;
		bsdf_make(&b, m, &h, v3_neg(r.d));
		vec3 p = offset_point(w, h.p, b.n);
		if (b.smooth && w->nlights)
			radiance = v3_add(radiance, v3_mul(thr, direct_light(w, &b, p)));
		bool sample_emitters = b.smooth && w->nemitters;
		if (sample_emitters)
			radiance = v3_add(radiance, v3_mul(thr, emitter_light(w, &b, p, h.object, g)));
		if (b.smooth && w->env) {
			/* the sky's two numbers: hashed dimensions of their own, far
			 * from the bounces' */
			g->dim = (1u << 20) + 2u * (uint32_t)bounce;
			radiance = v3_add(radiance, v3_mul(thr, sky_light(w, &b, p, g)));
		}

		g->dim = dim0 + 6u * (uint32_t)bounce + 2u;
		double u[3];
		u[0] = b.p[0] < 1.0 ? samp_1d(g) : 0.5; /* a lone Lambert lobe: no choice */
		g->dim = dim0 + 6u * (uint32_t)bounce + 3u;
		samp_2d(g, &u[1], &u[2]);
		bsdf_sample bs;
		if (!bsdf_sample_u(&b, u, &bs))
			break;
		thr = v3_mul(thr, v3_scale(bs.weight, bs.radiance_scale));
		eta_scale /= bs.radiance_scale;
		r = (ray){bs.transmit ? offset_point(w, h.p, v3_neg(b.n)) : p, bs.wi};
		from = r.o;
		from_pdf = sample_emitters && !bs.delta ? bsdf_pdf(&b, bs.wi) : 0.0;
		env_from_pdf = b.smooth && w->env && !bs.delta ? bsdf_pdf(&b, bs.wi) : 0.0;

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
