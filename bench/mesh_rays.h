/* rtsh — the rays of the triangle rows of `make bench`, shared by bench.c
 * and the Embree harness (embree_mesh.c) so that both trace the same ones:
 * a camera that frames the model's bounding box (the model in its own
 * coordinates), one primary ray per pixel centre, and from each primary
 * hit one diffuse (cosine-distributed) secondary ray about the geometric
 * normal turned toward the camera, its direction a hash of the pixel. */
#ifndef RTSH_BENCH_MESH_RAYS_H
#define RTSH_BENCH_MESH_RAYS_H

#include <stdint.h>

#include "rtsh/world.h"

static inline camera bench_mesh_camera(box b)
{
	vec3 c = box_center(b), e = v3_sub(b.hi, b.lo);
	double r = 0.5 * v3_len(e), fov = 40;
	vec3 dir = v3_norm(v3(-0.45, -0.3, -1));
	double dist = 0.8 * r / sin(atan(tan(fov * RT_PI / 360) * 9.0 / 16.0));
	return (camera){v3_sub(c, v3_scale(dir, dist)), dir, fov, false, 0, 0};
}

static inline uint64_t bench_mix(uint64_t z)
{
	z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
	z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
	return z ^ (z >> 31);
}

/* A cosine-distributed direction about the unit normal n for pixel i. */
static inline vec3 bench_diffuse_dir(vec3 n, uint64_t i)
{
	uint64_t a = bench_mix(i * 2 + 1), b = bench_mix(i * 2 + 2);
	double u1 = (double)(a >> 11) * 0x1.0p-53, u2 = (double)(b >> 11) * 0x1.0p-53;
	double r = sqrt(u1), phi = 2 * RT_PI * u2;
	vec3 t = fabs(n.x) > 0.5 ? v3(0, 1, 0) : v3(1, 0, 0);
	vec3 tu = v3_norm(v3_cross(t, n)), tv = v3_cross(n, tu);
	return v3_norm(v3_add(v3_add(v3_scale(tu, r * cos(phi)), v3_scale(tv, r * sin(phi))), v3_scale(n, sqrt(1 - u1))));
}

#endif
