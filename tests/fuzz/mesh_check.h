/* rtsh — fuzz targets' check of a mesh's tree (fuzz_obj.c, fuzz_ply.c).
 *
 * `raw` as read and `m` the same mesh prepared: rays from each corner of the
 * box (pushed out a little) through points inside it chosen by the input's
 * bytes, traced through the tree with every vector unit the machine has and
 * against every triangle (mesh_intersect_brute). The tree must find a hit
 * exactly when brute force does, at the very same distance: a box that
 * misses part of a triangle (a spatial split cut too tight, a slab test that
 * rounds the wrong way) shows here. Stops the fuzzer (abort) otherwise.
 *
 * Except where the floats cannot tell: a triangle far thinner than single
 * precision resolves at its size (a sliver 1e5 long and 3 wide, found by
 * the fuzzers) gives the watertight test edge functions that are rounding
 * noise and "hits" tens of units off it; the tree, rightly, does not look
 * in boxes beyond the first such hit, while brute force tests them all. So
 * a ray whose hit (the tree's or brute force's) lies off its triangle's box
 * by more than the rounding of the coordinates involved (2^-18 of them) is
 * not compared, and near ties are allowed: the tree's hit may be farther
 * than brute force's by 2^-16 of the distance (two triangles whose
 * distances differ by less than their rounding, in different leaves). */
#ifndef RTSH_FUZZ_MESH_CHECK_H
#define RTSH_FUZZ_MESH_CHECK_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "rtsh/mesh.h"

/* Whether the hit at t lies in the box of corners c, give or take the
 * rounding of coordinates as large as the ones involved. */
static bool hit_on_triangle(const mesh_ray *r, float t, const vec3 c[3])
{
	double big = 0;
	for (int a = 0; a < 3; a++) {
		big = fmax(big, fabs(r->o[a]) + fabs((double)t * r->d[a]));
		for (int k = 0; k < 3; k++)
			big = fmax(big, fabs((&c[k].x)[a]));
	}
	double tol = big * 0x1p-18;
	for (int a = 0; a < 3; a++) {
		double p = r->o[a] + (double)t * r->d[a];
		double lo = fmin(fmin((&c[0].x)[a], (&c[1].x)[a]), (&c[2].x)[a]);
		double hi = fmax(fmax((&c[0].x)[a], (&c[1].x)[a]), (&c[2].x)[a]);
		if (p < lo - tol || p > hi + tol)
			return false;
	}
	return true;
}

static void mesh_check(const mesh *raw, const mesh *m, const uint8_t *data, size_t size)
{
	box b = raw->bounds;
	vec3 c = box_center(b), e = v3_sub(b.hi, b.lo);
	double pad = 0.25 * v3_max_comp(e) + 1e-3;
	for (int k = 0; k < 8; k++) {
		vec3 o = v3(k & 1 ? b.hi.x + pad : b.lo.x - pad, k & 2 ? b.hi.y + pad : b.lo.y - pad,
		            k & 4 ? b.hi.z + pad : b.lo.z - pad);
		/* a target in the box from three of the input's bytes */
		uint8_t q[3] = {0, 0, 0};
		for (int i = 0; i < 3 && size; i++)
			q[i] = data[((size_t)k * 3 + (size_t)i) % size];
		vec3 t = v3(b.lo.x + e.x * q[0] / 255.0, b.lo.y + e.y * q[1] / 255.0, b.lo.z + e.z * q[2] / 255.0);
		if (k == 0)
			t = c;
		vec3 d = v3_sub(t, o);
		if (!(v3_len(d) > 0))
			continue;
		mesh_ray r;
		mesh_ray_make(&r, o, d);
		float tb = INFINITY, bb[3];
		uint32_t kb;
		bool hb = mesh_intersect_brute(raw, &r, 0, &tb, &kb, bb);
		if (hb) {
			vec3 cb[3];
			for (int i = 0; i < 3; i++) {
				const float *p = raw->p[raw->tri[kb][i]];
				cb[i] = v3(p[0], p[1], p[2]);
			}
			if (!hit_on_triangle(&r, tb, cb))
				continue;
		}
		for (int isa = MESH_ISA_SCALAR; isa < MESH_ISA_BEST; isa++) {
			if (!mesh_isa_force((mesh_isa)isa))
				continue;
			float tt = INFINITY, bt[3];
			uint32_t kt;
			bool ht = mesh_intersect(m, &r, 0, &tt, &kt, bt);
			bool occ = mesh_occluded(m, &r, 0, INFINITY);
			vec3 ct[3];
			if (ht) {
				mesh_corners(m, kt, ct);
				if (!hit_on_triangle(&r, tt, ct))
					continue;
			}
			if (ht != hb || occ != hb || (ht && !(tt >= tb && tt <= tb + fabsf(tb) * 0x1p-16f))) {
				fprintf(stderr, "mesh tree (vector unit %d) and brute force disagree: ray %d hit %d/%d occluded %d t %.9g/%.9g\n",
				        isa, k, ht, hb, occ, tt, tb);
				abort();
			}
		}
		mesh_isa_force(MESH_ISA_BEST);
	}
}

#endif
