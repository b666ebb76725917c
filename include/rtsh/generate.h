/* rtsh — the random scene generator (the miniRT seed's stress-test scenes). */
#ifndef RTSH_GENERATE_H
#define RTSH_GENERATE_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rtsh/error.h"
#include "rtsh/scene.h"

typedef struct gen_opts {
	bool spheres_only; /* only spheres, all inside one fixed region (benchmarks) */
	const atomic_bool *cancel; /* when set, generating stops: NULL, err "stopped" */
} gen_opts;

/* A new scene of n random objects (n >= 1) with 2-4 coloured lights, an
 * ambient light, a ground plane and a camera that frames them. The same
 * (n, seed, opts) always gives the identical scene, on every machine.
 * opts may be NULL. NULL (err set) when out of memory or n is too large. */
scene *scene_generate(size_t n, uint64_t seed, const gen_opts *opts, rt_error *err);

#define GENERATE_MAX 10000000

#endif
