/* rtsh — the physically based family of materials (rtsh(5), "Materials"):
 * glTF 2.0's metallic-roughness BSDF (the specification's Appendix B) and
 * the KHR_materials_transmission, _ior, _volume, _clearcoat and _specular
 * extensions.
 *
 *   material = coat over mix(dielectric, metal, metallic)
 *   metal      GGX specular x Schlick's Fresnel with F0 = base colour
 *   dielectric mix(plastic, glass, transmission)
 *   plastic    GGX specular x F + Lambert(base colour) x what the specular
 *              lets through (see pbr_make); F Schlick's with f0 =
 *              min(F0(ior) x specular_color, 1) x specular_factor and f90 =
 *              specular_factor (KHR_materials_specular)
 *   glass      a rough dielectric interface (Walter, Marschner, Li &
 *              Torrance, "Microfacet models for refraction through rough
 *              surfaces", EGSR 2007) with the exact Fresnel reflectance;
 *              the refracted light tinted by the base colour. Thin-walled:
 *              the light goes through without bending (the reflection
 *              mirrored below the surface)
 *   coat       a colourless GGX layer, ior 1.5 (Schlick, F0 = 0.04), of
 *              weight clearcoat; what it lets through, (1 - cc Fc(cos)) at
 *              both ends, lights the rest
 *
 * Every GGX lobe (Trowbridge & Reitz 1975; Walter et al. 2007) has alpha =
 * roughness^2 and the height-correlated Smith masking-shadowing G2 = 1 /
 * (1 + Lambda(o) + Lambda(i)) (Heitz, "Understanding the masking-shadowing
 * function in microfacet-based BRDFs", JCGT 2014), and is sampled by its
 * visible normals (Heitz, "Sampling the GGX distribution of visible
 * normals", JCGT 2018). Lobes whose alpha is below DELTA_ALPHA are perfect
 * mirrors / interfaces. The single-scattering GGX loses energy at high
 * roughness; the metal and the plastic's specular are compensated by
 * Turquin's factor 1 + F0 (1 / E(cos_o) - 1), E the lobe's directional
 * albedo with F = 1 (Turquin, "Practical multiple scattering compensation
 * for microfacet models", 2019), unless multiscatter=0.
 *
 * The sampling picks a lobe in proportion to its estimated albedo, then a
 * direction from it; the weight of a non-delta direction is the whole
 * BSDF's f cos over the whole mixture's pdf (one-sample MIS), so sampling,
 * evaluation and pdf agree by construction. */
#include "integrators.h"
#include "ggx.h"
#include "warp.h"


/* Whitted mode follows mirror and refracted rays below this roughness. */
#define WHITTED_MIRROR_ROUGHNESS 0.2

enum { L_COAT, L_METAL, L_SPEC, L_DIFF, L_GLASS, L_COUNT };

static double avg3(vec3 v)
{
	return (v.x + v.y + v.z) * (1.0 / 3.0);
}

static double pow5(double x)
{
	double x2 = x * x;
	return x2 * x2 * x;
}

/* Schlick's Fresnel for a colour F0 and f90. */
static vec3 schlick3(vec3 f0, double f90, double c)
{
	double k = pow5(1.0 - (c < 1.0 ? c : 1.0));
	return v3_add(f0, v3_scale(v3_sub(v3_splat(f90), f0), k));
}

static double schlick1(double f0, double c)
{
	return f0 + (1.0 - f0) * pow5(1.0 - (c < 1.0 ? c : 1.0));
}

/* --- GGX ----------------------------------------------------------------- */

/* The distribution of normals h (local, z up), a2 = alpha^2. */
static double ggx_d(double a2, double hz)
{
	double k = hz * hz * (a2 - 1.0) + 1.0;
	return a2 / (RT_PI * k * k);
}

/* Smith's Lambda for a direction of cosine z (either side). */
static double ggx_lambda(double a2, double z)
{
	double z2 = z * z;
	if (z2 >= 1.0)
		return 0.0;
	return 0.5 * (sqrt(1.0 + a2 * (1.0 - z2) / z2) - 1.0);
}

/* A visible normal for wo (local, wo.z > 0), Heitz 2018: the hemisphere
 * configuration stretched to alpha 1, a uniform disc point projected onto
 * the visible half of it, stretched back. */
static vec3 ggx_sample_vndf(double a, vec3 wo, double u1, double u2)
{
	vec3 vh = v3_norm(v3(a * wo.x, a * wo.y, wo.z));
	double l2 = vh.x * vh.x + vh.y * vh.y;
	vec3 t1 = l2 > 0.0 ? v3_scale(v3(-vh.y, vh.x, 0.0), 1.0 / sqrt(l2)) : v3(1, 0, 0);
	vec3 t2 = v3_cross(vh, t1);
	double p1, p2;
	warp_disc(u1, u2, &p1, &p2);
	double s = 0.5 * (1.0 + vh.z);
	p2 = (1.0 - s) * sqrt(pos(1.0 - p1 * p1)) + s * p2;
	vec3 nh = v3_add(v3_add(v3_scale(t1, p1), v3_scale(t2, p2)), v3_scale(vh, sqrt(pos(1.0 - p1 * p1 - p2 * p2))));
	return v3_norm(v3(a * nh.x, a * nh.y, pos(nh.z)));
}

/* --- the bsdf -------------------------------------------------------------- */

static vec3 to_local(const bsdf *b, vec3 v)
{
	return v3(v3_dot(v, b->pb.t), v3_dot(v, b->pb.b), v3_dot(v, b->n));
}

static vec3 to_world(const bsdf *b, vec3 v)
{
	return v3_add(v3_add(v3_scale(b->pb.t, v.x), v3_scale(b->pb.b, v.y)), v3_scale(b->n, v.z));
}

/* The eta of the side below over the side of wo. */
static double eta_of(const bsdf *b)
{
	return b->front ? b->ior : 1.0 / b->ior;
}

static double coat_through(const bsdf *b, double c)
{
	return 1.0 - b->pb.cc * schlick1(0.04, c);
}

static void pbr_make(bsdf *b, const mat_lin *m, vec3 albedo)
{
	struct bsdf_pbr *p = &b->pb;
	basis(b->n, &p->t, &p->b);
	p->base = albedo;
	double rc = clampd(m->pbr.clearcoat_roughness, 0.0, 1.0);
	b->ior = m->ior >= 1.0 ? m->ior : 1.5;
	pbr_spec sp = pbr_spec_of(m, b->ior);
	p->a = sp.a;
	p->delta = sp.delta;
	p->ms = sp.ms;
	p->f0 = sp.f0;
	p->sf = sp.sf;
	p->ac = rc * rc;
	p->cdelta = p->ac < DELTA_ALPHA;
	double metallic = clampd(m->pbr.metallic, 0.0, 1.0), tr = clampd(m->pbr.transmission, 0.0, 1.0);
	p->wm = metallic;
	p->wp = (1.0 - metallic) * (1.0 - tr);
	p->wt = (1.0 - metallic) * tr;
	p->cc = clampd(m->pbr.clearcoat, 0.0, 1.0);
	p->thin = m->thin;
	p->kms_m = v3_splat(1.0);
	p->kms_p = v3_splat(1.0);
	if (p->ms && !p->delta) {
		double e = pbr_ggx_albedo(p->a, b->cos_o), k = e > 0.0 ? 1.0 / e - 1.0 : 0.0;
		p->kms_m = v3_add(v3_splat(1.0), v3_scale(albedo, k));
		p->kms_p = v3_add(v3_splat(1.0), v3_scale(p->f0, k));
	}
	/* The plastic's Lambert base gets what the specular layer lets
	 * through, (1 - Es(o)) (1 - Es(i)) / (1 - Es_avg): reciprocal, and
	 * energy is conserved exactly (Kulla & Conty, "Revisiting physically
	 * based shading at Imageworks", 2017, the albedo scaling of layers;
	 * glTF's (1 - F(v.h)) gains up to 6% at grazing angles). Es_avg = 2
	 * int Es(mu) mu dmu by the midpoint rule. */
	p->kdiff = 0.0;
	if (p->wp > 0.0) {
		double avg = m->pbr.es_ready ? m->pbr.es_avg : pbr_spec_albedo_avg(&sp);
		p->kdiff = avg < 1.0 ? (1.0 - pbr_spec_albedo(&sp, b->cos_o)) / (1.0 - avg) : 0.0;
	}
	/* lobe choice in proportion to what each sends back from cos_o */
	double co = b->cos_o;
	double pc = p->cc * schlick1(0.04, co), rest = 1.0 - pc;
	vec3 fd = schlick3(p->f0, p->sf, co);
	double w[L_COUNT];
	w[L_COAT] = pc;
	w[L_METAL] = rest * p->wm * avg3(schlick3(albedo, 1.0, co));
	w[L_SPEC] = rest * p->wp * avg3(fd);
	w[L_DIFF] = rest * p->wp * (1.0 - pbr_spec_albedo(&sp, co)) * avg3(albedo);
	w[L_GLASS] = rest * p->wt * (avg3(albedo) > 0.1 ? avg3(albedo) : 0.1);
	double total = 0.0;
	for (int i = 0; i < L_COUNT; i++)
		total += w[i];
	b->total = total;
	for (int i = 0; i < L_COUNT; i++)
		p->pl[i] = total > 0.0 ? w[i] / total : 0.0;
	bool nd_base = !p->delta && (w[L_METAL] > 0.0 || w[L_SPEC] > 0.0 || w[L_GLASS] > 0.0);
	b->smooth = w[L_DIFF] > 0.0 || (w[L_COAT] > 0.0 && !p->cdelta) || nd_base;
	b->through = !p->delta && p->wt > 0.0;
	if (!p->thin)
		b->sigma_in = v3(m->pbr.sigma_a[0], m->pbr.sigma_a[1], m->pbr.sigma_a[2]);
}

/* The whole non-delta BSDF value at local wo, wi. */
static vec3 pbr_f(const bsdf *b, vec3 wo, vec3 wi)
{
	const struct bsdf_pbr *p = &b->pb;
	double co = wo.z, ci = wi.z;
	vec3 f = v3(0, 0, 0);
	if (co <= 0.0 || ci == 0.0)
		return f;
	double att = (1.0 - p->cc * schlick1(0.04, co)) * (1.0 - p->cc * schlick1(0.04, fabs(ci)));
	double a2 = p->a * p->a;
	if (ci > 0.0) {
		vec3 h = v3_norm(v3_add(wo, wi));
		double oh = v3_dot(wo, h);
		if (p->wp > 0.0) {
			vec3 fd = schlick3(p->f0, p->sf, oh);
			pbr_spec sp = {p->a, p->f0, p->sf, p->delta, p->ms};
			f = v3_madd(f, p->base, p->wp * p->kdiff * (1.0 - pbr_spec_albedo(&sp, ci)) * (1.0 / RT_PI));
			if (!p->delta) {
				double spec = ggx_d(a2, h.z) / (4.0 * co * ci * (1.0 + ggx_lambda(a2, co) + ggx_lambda(a2, ci)));
				f = v3_add(f, v3_scale(v3_mul(fd, p->kms_p), p->wp * spec));
			}
		}
		if (!p->delta && (p->wm > 0.0 || p->wt > 0.0)) {
			double spec = ggx_d(a2, h.z) / (4.0 * co * ci * (1.0 + ggx_lambda(a2, co) + ggx_lambda(a2, ci)));
			if (p->wm > 0.0)
				f = v3_add(f, v3_scale(v3_mul(schlick3(p->base, 1.0, oh), p->kms_m), p->wm * spec));
			if (p->wt > 0.0) {
				double ct;
				f = v3_add(f, v3_splat(p->wt * spec * fresnel_dielectric(oh, p->thin ? b->ior : eta_of(b), &ct)));
			}
		}
		f = v3_scale(f, att);
		if (p->cc > 0.0 && !p->cdelta) {
			double ac2 = p->ac * p->ac;
			double spec = ggx_d(ac2, h.z) / (4.0 * co * ci * (1.0 + ggx_lambda(ac2, co) + ggx_lambda(ac2, ci)));
			f = v3_add(f, v3_splat(p->cc * schlick1(0.04, oh) * spec));
		}
		return f;
	}
	if (p->delta || p->wt <= 0.0)
		return f;
	double aci = -ci, ct;
	if (p->thin) {
		/* the reflection mirrored below: wr = (wi.x, wi.y, -wi.z) */
		vec3 h = v3_norm(v3_add(wo, v3(wi.x, wi.y, aci)));
		double oh = v3_dot(wo, h);
		double spec = ggx_d(a2, h.z) / (4.0 * co * aci * (1.0 + ggx_lambda(a2, co) + ggx_lambda(a2, aci)));
		double tf = 1.0 - fresnel_dielectric(oh, b->ior, &ct);
		return v3_scale(p->base, att * p->wt * tf * spec);
	}
	/* Walter et al. 2007, eq. 21, in pbrt 4th ed.'s form (9.7.5) */
	double eta = eta_of(b);
	vec3 h = v3_add(v3_scale(wi, eta), wo);
	double hl = v3_len(h);
	if (!(hl > 0.0))
		return f;
	h = v3_scale(h, 1.0 / hl);
	if (h.z < 0.0)
		h = v3_neg(h);
	double ih = v3_dot(wi, h), oh = v3_dot(wo, h);
	if (ih >= 0.0 || oh <= 0.0)
		return f; /* a microfacet seen from behind */
	double F = fresnel_dielectric(oh, eta, &ct);
	double den = ih + oh / eta;
	double t = ggx_d(a2, h.z) / (1.0 + ggx_lambda(a2, co) + ggx_lambda(a2, aci)) * fabs(ih * oh) /
	           (den * den * aci * co);
	/* radiance: compressed by 1 / eta^2 going through */
	return v3_scale(p->base, att * p->wt * (1.0 - F) * t / (eta * eta));
}

/* The mixture density of the non-delta lobes at local wi. */
static double pbr_pdf_local(const bsdf *b, vec3 wo, vec3 wi)
{
	const struct bsdf_pbr *p = &b->pb;
	double co = wo.z, ci = wi.z, pdf = 0.0;
	if (co <= 0.0 || ci == 0.0)
		return 0.0;
	double a2 = p->a * p->a;
	if (ci > 0.0) {
		vec3 h = v3_norm(v3_add(wo, wi));
		pdf += p->pl[L_DIFF] * ci / RT_PI;
		double base_p = p->pl[L_METAL] + p->pl[L_SPEC];
		if (!p->delta && (base_p > 0.0 || p->pl[L_GLASS] > 0.0)) {
			/* the visible normals' density / (4 o.h) = G1(o) D / (4 cos_o) */
			double r = ggx_d(a2, h.z) / (4.0 * co * (1.0 + ggx_lambda(a2, co)));
			double ct, oh = v3_dot(wo, h);
			double fr = p->pl[L_GLASS] > 0.0 ? fresnel_dielectric(oh, p->thin ? b->ior : eta_of(b), &ct) : 0.0;
			pdf += (base_p + p->pl[L_GLASS] * fr) * r;
		}
		if (p->pl[L_COAT] > 0.0 && !p->cdelta) {
			double ac2 = p->ac * p->ac;
			pdf += p->pl[L_COAT] * ggx_d(ac2, h.z) / (4.0 * co * (1.0 + ggx_lambda(ac2, co)));
		}
		return pdf;
	}
	if (p->delta || p->pl[L_GLASS] <= 0.0)
		return 0.0;
	double aci = -ci, ct;
	if (p->thin) {
		vec3 h = v3_norm(v3_add(wo, v3(wi.x, wi.y, aci)));
		double oh = v3_dot(wo, h);
		double r = ggx_d(a2, h.z) / (4.0 * co * (1.0 + ggx_lambda(a2, co)));
		return p->pl[L_GLASS] * (1.0 - fresnel_dielectric(oh, b->ior, &ct)) * r;
	}
	double eta = eta_of(b);
	vec3 h = v3_add(v3_scale(wi, eta), wo);
	double hl = v3_len(h);
	if (!(hl > 0.0))
		return 0.0;
	h = v3_scale(h, 1.0 / hl);
	if (h.z < 0.0)
		h = v3_neg(h);
	double ih = v3_dot(wi, h), oh = v3_dot(wo, h);
	if (ih >= 0.0 || oh <= 0.0)
		return 0.0;
	double F = fresnel_dielectric(oh, eta, &ct);
	double den = ih + oh / eta;
	/* visible normals' density x |dh / dwi| = |i.h| / (i.h + o.h / eta)^2 */
	double dv = ggx_d(a2, h.z) * oh / (co * (1.0 + ggx_lambda(a2, co)));
	return p->pl[L_GLASS] * (1.0 - F) * dv * fabs(ih) / (den * den);
}

static vec3 pbr_eval(const bsdf *b, vec3 wi)
{
	return pbr_f(b, to_local(b, b->wo), to_local(b, wi));
}

static double pbr_pdf(const bsdf *b, vec3 wi)
{
	return pbr_pdf_local(b, to_local(b, b->wo), to_local(b, wi));
}

static bool pbr_has_choice(const bsdf *b)
{
	(void)b;
	return true;
}

/* A perfect lobe's sample: its value over its choice probability. */
static bool delta_out(bsdf_sample *out, vec3 wi, vec3 weight)
{
	out->wi = wi;
	out->weight = weight;
	out->delta = true;
	return true;
}

static bool pbr_sample(const bsdf *b, const double u[3], bsdf_sample *out)
{
	const struct bsdf_pbr *p = &b->pb;
	if (!(b->total > 0.0) || b->cos_o <= 0.0)
		return false;
	int lobe = 0;
	double below = 0.0, acc = p->pl[0];
	while (lobe < L_COUNT - 1 && (u[0] >= acc || p->pl[lobe] == 0.0)) {
		below = acc;
		acc += p->pl[++lobe];
	}
	while (lobe > 0 && p->pl[lobe] == 0.0)
		below -= p->pl[--lobe];
	double pk = p->pl[lobe], ur = clampd((u[0] - below) / pk, 0.0, 0.999999999);
	out->radiance_scale = 1.0;
	out->transmit = false;
	out->delta = false;
	out->pdf = -1.0;
	vec3 wo = to_local(b, b->wo);
	double co = wo.z;
	vec3 mirror = v3_sub(v3_scale(b->n, 2.0 * co), b->wo);
	double att_r = coat_through(b, co) * coat_through(b, co);
	vec3 wi;
	switch (lobe) {
	case L_COAT:
		if (p->cdelta)
			return delta_out(out, mirror, v3_splat(p->cc * schlick1(0.04, co) / pk));
		{
			vec3 h = ggx_sample_vndf(p->ac, wo, u[1], u[2]);
			wi = v3_sub(v3_scale(h, 2.0 * v3_dot(wo, h)), wo);
		}
		break;
	case L_METAL:
	case L_SPEC:
		if (p->delta) {
			vec3 F = lobe == L_METAL ? v3_scale(schlick3(p->base, 1.0, co), p->wm)
			                         : v3_scale(schlick3(p->f0, p->sf, co), p->wp);
			return delta_out(out, mirror, v3_scale(F, att_r / pk));
		}
		{
			vec3 h = ggx_sample_vndf(p->a, wo, u[1], u[2]);
			wi = v3_sub(v3_scale(h, 2.0 * v3_dot(wo, h)), wo);
		}
		break;
	case L_DIFF:
		wi = warp_cosine(v3(0, 0, 1), u[1], u[2]);
		break;
	default: { /* glass: reflect with probability F, else go through */
		double eta = p->thin ? b->ior : eta_of(b), ct;
		if (p->delta) {
			double F = fresnel_dielectric(co, eta, &ct);
			if (ur < F)
				return delta_out(out, mirror, v3_splat(p->wt * att_r / pk));
			if (p->thin) {
				out->transmit = true;
				return delta_out(out, v3_neg(b->wo), v3_scale(p->base, p->wt * att_r / pk));
			}
			vec3 t = v3_add(v3_scale(b->wo, -1.0 / eta), v3_scale(b->n, co / eta - ct));
			out->transmit = true;
			out->radiance_scale = 1.0 / (eta * eta);
			double att = coat_through(b, co) * coat_through(b, ct);
			return delta_out(out, v3_norm(t), v3_scale(p->base, p->wt * att / pk));
		}
		vec3 h = ggx_sample_vndf(p->a, wo, u[1], u[2]);
		double oh = v3_dot(wo, h);
		double F = fresnel_dielectric(oh, eta, &ct);
		vec3 wr = v3_sub(v3_scale(h, 2.0 * oh), wo);
		if (ur < F) {
			wi = wr;
		} else if (p->thin) {
			wi = v3(wr.x, wr.y, -wr.z);
			out->transmit = true;
		} else {
			wi = v3_add(v3_scale(wo, -1.0 / eta), v3_scale(h, oh / eta - ct));
			out->transmit = true;
			out->radiance_scale = 1.0 / (eta * eta);
		}
		break;
	}
	}
	if (out->transmit ? wi.z >= 0.0 : wi.z <= 0.0)
		return false; /* below the surface: the lobe's lost energy */
	double pdf = pbr_pdf_local(b, wo, wi);
	if (!(pdf > 0.0))
		return false;
	vec3 f = pbr_f(b, wo, wi);
	out->wi = to_world(b, v3_norm(wi));
	out->pdf = pdf;
	/* radiance_scale is applied by the caller: take it out of f */
	out->weight = v3_scale(f, fabs(wi.z) / (pdf * out->radiance_scale));
	return true;
}

/* The denoiser's view: a perfect mirror metal or perfect glass is looked
 * through; anything else shows its base colour. */
static int pbr_features(const bsdf *b, vec3 *albedo, vec3 *tint, vec3 *dir)
{
	const struct bsdf_pbr *p = &b->pb;
	*albedo = p->base;
	if (!p->delta)
		return 0;
	if (p->wm >= 0.5) {
		*tint = schlick3(p->base, 1.0, b->cos_o);
		return 1;
	}
	if (p->wt >= 0.5) {
		*tint = p->base;
		if (p->thin) {
			*dir = v3_neg(b->wo);
			return 2;
		}
		double eta = eta_of(b), ct;
		if (fresnel_dielectric(b->cos_o, eta, &ct) >= 1.0)
			return 1;
		*dir = v3_add(v3_scale(b->wo, -1.0 / eta), v3_scale(b->n, b->cos_o / eta - ct));
		return 2;
	}
	return 0;
}

/* Whitted: ambient x base colour, the point lights through the same BRDF
 * as in path mode, and below WHITTED_MIRROR_ROUGHNESS the mirror (and
 * refracted) rays weighted by the lobes' Fresnel at cos_o. */
static vec3 pbr_whitted(const world *w, const mat_lin *m, const hit *h, ray r, int depth, vec3 weight,
                        whitted_trace_fn trace)
{
	bsdf b = {0};
	b.n = h->front ? h->n : v3_neg(h->n);
	b.wo = v3_neg(r.d);
	b.front = h->front;
	b.cos_o = pos(v3_dot(b.n, b.wo));
	b.family = MAT_PBR;
	mat_lin tmp;
	m = hit_material(m, h, &tmp);
	pbr_make(&b, m, hit_albedo(m, h));
	const struct bsdf_pbr *p = &b.pb;
	vec3 pt = offset_point(w, h->p, b.n);
	vec3 c = v3_add(v3_mul(w->ambient, p->base), hit_emission(m, h));
	/* the point lights through the BRDF, Whitted's convention: pi L cos */
	for (size_t i = 0; i < w->nlights; i++) {
		vec3 ld;
		double dist;
		vec3 lr = light_at(&w->lights[i], pt, &ld, &dist);
		double ndl = v3_dot(b.n, ld);
		if (!(lr.x > 0.0 || lr.y > 0.0 || lr.z > 0.0) || ndl <= 0.0)
			continue;
		vec3 f = pbr_eval(&b, ld);
		if (f.x <= 0.0 && f.y <= 0.0 && f.z <= 0.0)
			continue;
		ray sr = {pt, ld};
		if (!world_occluded(w, &sr, 0.0, dist))
			c = v3_add(c, v3_mul(f, v3_scale(lr, RT_PI * ndl)));
	}
	if (depth <= 0)
		return c;
	double co = b.cos_o, ct;
	vec3 mirror = v3_sub(v3_scale(b.n, 2.0 * co), b.wo);
	vec3 kr = v3(0, 0, 0), kt = v3(0, 0, 0);
	vec3 tdir = v3(0, 0, 0);
	double att = coat_through(&b, co);
	if (clampd(m->pbr.roughness, 0, 1) < WHITTED_MIRROR_ROUGHNESS) {
		kr = v3_add(v3_scale(schlick3(p->base, 1.0, co), p->wm), v3_scale(schlick3(p->f0, p->sf, co), p->wp));
		if (p->wt > 0.0) {
			double eta = p->thin ? b.ior : eta_of(&b);
			double F = fresnel_dielectric(co, eta, &ct);
			kr = v3_add(kr, v3_splat(p->wt * F));
			kt = v3_scale(p->base, p->wt * (1.0 - F));
			tdir = p->thin ? v3_neg(b.wo)
			               : v3_norm(v3_add(v3_scale(b.wo, -1.0 / eta), v3_scale(b.n, co / eta - ct)));
		}
		kr = v3_scale(kr, att * att);
		kt = v3_scale(kt, att * att);
	}
	if (clampd(m->pbr.clearcoat_roughness, 0, 1) < WHITTED_MIRROR_ROUGHNESS)
		kr = v3_add(kr, v3_splat(p->cc * schlick1(0.04, co)));
	if (max3(kr) > 0.0)
		c = v3_add(c, v3_mul(kr, trace(w, (ray){pt, mirror}, depth - 1, v3_mul(weight, kr))));
	if (max3(kt) > 0.0)
		c = v3_add(c, v3_mul(kt, trace(w, (ray){offset_point(w, h->p, v3_neg(b.n)), tdir}, depth - 1,
		                               v3_mul(weight, kt))));
	return c;
}

const mat_family mat_pbr_family = {
	.name = "pbr",
	.make = pbr_make,
	.eval = pbr_eval,
	.pdf = pbr_pdf,
	.sample = pbr_sample,
	.has_choice = pbr_has_choice,
	.features = pbr_features,
	.whitted = pbr_whitted,
};
