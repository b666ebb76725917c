/* rtsh — what the physically based materials (bsdf_pbr.c) and the world
 * (world.c, mat_lin_make) share: GGX's directional albedo and the plastic's
 * specular layer. Private to the core; depends on nothing but math. */
#ifndef RTSH_GGX_H
#define RTSH_GGX_H

#include "rtsh/world.h"

/* Lobes with alpha below this are perfect (roughness < 0.0316). */
#define DELTA_ALPHA 1e-3

/* E(cos_o, alpha): the directional albedo of single-scattering GGX with
 * F = 1 (bilinear in a table). */
double pbr_ggx_albedo(double alpha, double cos_o);

/* The plastic's specular layer of a PBR material. */
typedef struct pbr_spec {
	double a;   /* GGX alpha */
	vec3 f0;    /* min(F0(ior) x specular_color, 1) x specular_factor */
	double sf;  /* specular_factor (f90) */
	bool delta, ms;
} pbr_spec;

pbr_spec pbr_spec_of(const mat_lin *m, double ior);
/* The share of light it reflects from a direction of cosine mu. */
double pbr_spec_albedo(const pbr_spec *s, double mu);
/* Its average over the hemisphere, 2 int Es(mu) mu dmu. */
double pbr_spec_albedo_avg(const pbr_spec *s);
/* Sets mat_lin.pbr.es_avg (mat_lin_make). */
void pbr_lin_finish(mat_lin *m);

#endif
