/* rtsh — an HDR sky: an equirectangular environment, importance-sampled
 * by luminance (envmap.c). Private to the core. */
#ifndef RTSH_ENVMAP_H
#define RTSH_ENVMAP_H

#include "rtsh/world.h"

typedef struct envmap envmap;

/* A sky from image `path` (linear), radiance x strength, turned by
 * rotation_deg about +Y; stops ("stopped") soon after *cancel is set
 * (NULL: never). NULL (err set) on failure. */
envmap *envmap_new(const char *path, double strength, double rotation_deg, const atomic_bool *cancel, rt_error *err);
void envmap_free(envmap *e);
/* The radiance arriving from direction d (any length). */
vec3 envmap_eval(const envmap *e, vec3 d);
/* The density (per steradian) with which envmap_sample picks d. */
double envmap_pdf(const envmap *e, vec3 d);
/* A direction picked in proportion to luminance x solid angle from two
 * numbers in [0,1); its density in *pdf (0: none). */
vec3 envmap_sample(const envmap *e, double u1, double u2, double *pdf);
size_t envmap_memory(const envmap *e);

#endif
