/* rtsh — the material families and the bsdf calls the integrators make
 * (integrators.h). A family is one entry of mat_families: its BSDF, pdf,
 * sampling, the denoiser's features and its Whitted shading. The
 * integrators call the functions below and never switch on a family. */
#include "integrators.h"
#include "warp.h"

const mat_family *const mat_families[MAT_FAMILY_COUNT] = {
	[MAT_PHONG] = &mat_phong_family,
	[MAT_PBR] = &mat_pbr_family,
};

void bsdf_make(bsdf *b, const mat_lin *m, const hit *h, vec3 wo)
{
	*b = (bsdf){0};
	b->n = h->front ? h->n : v3_neg(h->n);
	b->wo = wo;
	b->front = h->front;
	b->cos_o = pos(v3_dot(b->n, wo));
	b->family = m->family < MAT_FAMILY_COUNT ? m->family : MAT_PHONG;
	mat_lin tmp;
	m = hit_material(m, h, &tmp);
	mat_families[b->family]->make(b, m, hit_albedo(m, h));
}

vec3 bsdf_eval(const bsdf *b, vec3 wi)
{
	return mat_families[b->family]->eval(b, wi);
}

double bsdf_pdf(const bsdf *b, vec3 wi)
{
	return mat_families[b->family]->pdf(b, wi);
}

bool bsdf_sample_u(const bsdf *b, const double u[3], bsdf_sample *out)
{
	return mat_families[b->family]->sample(b, u, out);
}

bool bsdf_sample_dir(const bsdf *b, rng *g, bsdf_sample *out)
{
	double u[3] = {rng_next(g), rng_next(g), rng_next(g)};
	return bsdf_sample_u(b, u, out);
}

bool bsdf_has_choice(const bsdf *b)
{
	return mat_families[b->family]->has_choice(b);
}

int bsdf_features(const bsdf *b, vec3 *albedo, vec3 *tint, vec3 *dir)
{
	return mat_families[b->family]->features(b, albedo, tint, dir);
}
