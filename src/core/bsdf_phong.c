/* rtsh — the seeds' Phong family of materials (rtsh(5), "Materials"): a
 * mix of lobes whose shares never sum above 1:
 *   mirror   share `reflective`; tinted by the colour x `metal` with
 *            Schlick's Fresnel; `fuzz` widens it into a Phong lobe
 *   glass    when ior >= 1, the rest: exact dielectric Fresnel, refraction
 *            tinted by the colour, total internal reflection
 *   diffuse  otherwise the rest, split between Lambert (`diffuse` x colour)
 *   specular and a normalised Phong lobe (`specular`, `shininess`), both
 *            scaled down together when diffuse + specular > 1
 * In Whitted mode: ambient + Phong per point light, and recursive mirror
 * reflection and refraction (Whitted 1980; Phong 1975). */
#include "integrators.h"
#include "warp.h"

/* Schlick's approximation of the Fresnel reflectance. */
static double schlick(double cos_i, double eta_ratio)
{
	double r0 = (1.0 - eta_ratio) / (1.0 + eta_ratio);
	r0 *= r0;
	double x = 1.0 - cos_i;
	return r0 + (1.0 - r0) * x * x * x * x * x;
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

double fuzz_exponent(double fuzz)
{
	/* A mirror direction perturbed by fuzz times a random point of the unit
	 * ball (the seed's metal) spreads by E[a^2] = 0.4 fuzz^2; the lobe
	 * cos^e a spreads by E[a^2] ~ 2 / (e + 2). Equal when: */
	return 5.0 / (fuzz * fuzz) - 2.0;
}

static void phong_make(bsdf *b, const mat_lin *m, vec3 albedo)
{
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

static vec3 phong_eval(const bsdf *b, vec3 wi)
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

static double phong_bsdf_pdf(const bsdf *b, vec3 wi)
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

static bool phong_sample(const bsdf *b, const double u[3], bsdf_sample *out)
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
	out->pdf = -1.0;
	switch (lobe) {
	case 0: /* Lambert: f cos / pdf = (kd / pi) cos / (cos / pi) */
		out->wi = warp_cosine(b->n, u[1], u[2]);
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

/* Set by whitted.c around the first hit's shading (integrators.h); kept
 * here, beside its reader, so that this file calls nothing of whitted.c. */
_Thread_local whitted_shadows whitted_shadow_hint;

/* Whitted shading: ambient x colour + emission, diffuse and Phong per
 * visible point light, then the mirror or the glass rays. */
static vec3 phong_whitted(const world *w, const mat_lin *m, const hit *hp, ray r, int depth, vec3 weight,
                          whitted_trace_fn trace)
{
	const hit *h = hp; /* read in place: a copy cost 3% of a grid render's instructions */
	/* the first hit's shadow rays may have been traced as packets, and
	 * what they were made from kept (integrators.h) */
	const whitted_shadows *ws = whitted_shadow_hint.h == hp ? &whitted_shadow_hint : NULL;
	const whitted_pre *pre = ws ? ws->pre : NULL;
	vec3 n, p;
	if (pre) {
		n = pre->n;
		p = pre->p;
	} else {
		phong_whitted_frame(w, h, &n, &p);
	}
	vec3 albedo = hit_albedo(m, h);
	vec3 v = v3_neg(r.d);

	vec3 c = v3_add(v3_mul(w->ambient, albedo), m->emission);
	for (size_t i = 0; i < w->nlights; i++) {
		double ndl;
		vec3 lr, ld;
		bool blocked;
		if (pre && i < WHITTED_PRE_LIGHTS) { /* traced as a packet when lit */
			if (!(pre->lit >> i & 1u))
				continue;
			lr = pre->lr[i];
			ld = pre->ld[i];
			ndl = pre->ndl[i];
			blocked = (ws->blocked >> i & 1u) != 0;
		} else {
			ray sr;
			double dist;
			if (!phong_light_ray(w, i, p, n, &sr, &dist, &lr, &ndl))
				continue;
			blocked = ws && i < WHITTED_PACKET_LIGHTS && (ws->known >> i & 1u) ? (ws->blocked >> i & 1u) != 0
			                                                                   : world_occluded(w, &sr, 0.0, dist);
			ld = sr.d;
		}
		if (blocked)
			continue;
		c = v3_add(c, v3_mul(lr, v3_scale(albedo, m->diffuse * ndl)));
		if (m->specular > 0.0) {
			double rv = v3_dot(v3_reflect(v3_neg(ld), n), v);
			/* (pow was 5% of a grid render's time; most highlights
			 * there add less than c's last bit) */
			if (rv > 0.0 && !phong_specular_negligible(c, lr, m->specular, rv, m->shininess))
				c = v3_add(c, v3_scale(lr, m->specular * pow(rv, m->shininess)));
		}
	}
	if (depth <= 0)
		return c;

	if (m->ior >= 1.0) {
		/* A dielectric: Fresnel-weighted mirror and refracted rays. */
		double eta = h->front ? 1.0 / m->ior : m->ior;
		double cos_i = fmin(v3_dot(v, n), 1.0);
		double sin2_t = eta * eta * (1.0 - cos_i * cos_i);
		vec3 refl_dir = v3_reflect(r.d, n);
		if (sin2_t >= 1.0) /* total internal reflection */
			return v3_add(c, trace(w, (ray){p, refl_dir}, depth - 1, weight));
		double kr = schlick(cos_i, h->front ? 1.0 / m->ior : m->ior);
		vec3 refl = trace(w, (ray){p, refl_dir}, depth - 1, v3_scale(weight, kr));
		vec3 tdir = v3_add(v3_scale(r.d, eta), v3_scale(n, eta * cos_i - sqrt(1.0 - sin2_t)));
		vec3 q = offset_point(w, h->p, v3_neg(n));
		vec3 trans = trace(w, (ray){q, v3_norm(tdir)}, depth - 1, v3_mul(weight, v3_scale(albedo, 1.0 - kr)));
		return v3_add(c, v3_add(v3_scale(refl, kr), v3_scale(v3_mul(trans, albedo), 1.0 - kr)));
	}
	if (m->reflective > 0.0) {
		/* (a tint of 1 changes no bit: x * 1.0 is x) */
		vec3 tint = m->metal > 0.0 ? v3_lerp(v3(1, 1, 1), albedo, m->metal) : v3(1, 1, 1);
		vec3 refl = trace(w, (ray){p, v3_reflect(r.d, n)}, depth - 1, v3_mul(weight, v3_scale(tint, m->reflective)));
		c = v3_lerp(c, v3_mul(refl, tint), m->reflective);
	}
	return c;
}

static bool phong_has_choice(const bsdf *b)
{
	return b->p[0] < 1.0; /* a lone Lambert lobe: no choice */
}

/* A surface that is mostly a perfect mirror or glass is looked through. */
/* A metal lobe at least this narrow (Phong exponent: fuzz <= 0.157) is
 * looked through like a perfect mirror by the denoiser's features: what
 * its reflection shows has edges (a checkered floor, a lamp) that the
 * metal's own albedo and normal do not. Chosen on scenes/metal-fuzz.rt
 * (8 samples, 128x96 and 200x120: 10% and 8% less RMS error denoised;
 * exponents 30 and 200 within 1% of each other). */
#define FEATURE_GLOSS_MIN 200

static int phong_features(const bsdf *b, vec3 *albedo, vec3 *tint, vec3 *dir)
{
	*albedo = v3_add(v3_add(b->kd, b->ks), v3_add(b->km, v3_scale(b->kt, b->wg)));
	double mirror = b->nm < 0.0 || b->nm >= FEATURE_GLOSS_MIN ? b->p[2] : 0.0;
	double delta = mirror + b->p[3];
	if (delta < 0.5)
		return 0;
	if (mirror >= b->p[3]) {
		*tint = b->km;
		return 1;
	}
	/* Snell's law in vector form (pbrt 4th ed. 9.3.2). */
	double eta = b->front ? b->ior : 1.0 / b->ior;
	double sin2_t = (1.0 - b->cos_o * b->cos_o) / (eta * eta);
	if (sin2_t >= 1.0) {
		*tint = v3_splat(b->wg);
		return 1;
	}
	*tint = v3_scale(b->kt, b->wg);
	double cos_t = sqrt(1.0 - sin2_t);
	*dir = v3_add(v3_scale(b->wo, -1.0 / eta), v3_scale(b->n, b->cos_o / eta - cos_t));
	return 2;
}

const mat_family mat_phong_family = {
	.name = "phong",
	.make = phong_make,
	.eval = phong_eval,
	.pdf = phong_bsdf_pdf,
	.sample = phong_sample,
	.has_choice = phong_has_choice,
	.features = phong_features,
	.whitted = phong_whitted,
};
