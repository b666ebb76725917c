/* rtsh — fuzz targets' check of a mesh's tree (fuzz_obj.c, fuzz_ply.c).
 *
 * `raw` as read and `m` the same mesh prepared: rays from each corner of the
 * box (pushed out a little) through points inside it chosen by the input's
 * bytes, traced through the tree with every vector unit the machine has and
 * against every triangle (mesh_intersect_brute). Returns NULL, or which of
 * these the tree broke, written into msg (the fuzz targets then abort):
 *
 * 1. It finds nothing brute force does not: a hit means brute force hits
 *    too, at the same distance or nearer (both run the same test on each
 *    triangle, and brute force keeps the nearest of all).
 * 2. mesh_occluded agrees with mesh_intersect (both visit the same boxes).
 * 3. It misses no triangle the ray truly crosses. Whether the ray crosses a
 *    triangle, and where, is decided apart from the watertight test: signed
 *    volumes in long double, trusted only when each is far above its
 *    rounding. For such a triangle j at exact distance T_j, whose own test
 *    gives t_j (infinite when the float test misses it), the tree's distance
 *    is at most max(t_j, T_j (1 + 2^-20)): either the walk reached j's leaf
 *    (and kept t_j or something nearer) or it culled the box, which its
 *    slab test (widened by 1 + 2 gamma(3)) does only past a hit nearer than
 *    the box's entry, itself no farther than T_j.
 *
 * This replaces a comparison with brute force's distance, which needed
 * tolerances: on a sliver far thinner than single precision resolves at its
 * size (found by the fuzzers: 88 million units long and 1 wide; 6.7e7 by
 * 7,261 seen from 8e7 away) the watertight test's distances are rounding
 * noise (1.6e-5 of the distance apart for two triangles sharing an edge, or
 * "hits" tens of units off the triangle), and the tree rightly skips boxes
 * beyond its first such hit while brute force tests them all. The property
 * above holds whatever the noise, and needs no tolerance beyond the slab
 * test's. */
#ifndef RTSH_FUZZ_MESH_CHECK_H
#define RTSH_FUZZ_MESH_CHECK_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "rtsh/mesh.h"

/* The scalar triple product x . (y cross z) and the sum of its six terms'
 * magnitudes (its rounding is a few units of the last place of that sum). */
static long double triple(const long double x[3], const long double y[3], const long double z[3],
                          long double *mag)
{
	long double t[6] = {x[0] * y[1] * z[2], -x[0] * y[2] * z[1], x[1] * y[2] * z[0],
	                    -x[1] * y[0] * z[2], x[2] * y[0] * z[1], -x[2] * y[1] * z[0]};
	long double s = 0, a = 0;
	for (int i = 0; i < 6; i++)
		s += t[i], a += fabsl(t[i]);
	*mag = a;
	return s;
}

/* Whether the ray (its float origin and direction, as the walk sees them)
 * surely crosses the inside of triangle c, and if so at what distance. */
static bool truly_crosses(const mesh_ray *r, const vec3 c[3], long double *t)
{
	long double p[3][3], d[3] = {r->d[0], r->d[1], r->d[2]};
	for (int k = 0; k < 3; k++)
		for (int a = 0; a < 3; a++)
			p[k][a] = (long double)(float)(&c[k].x)[a] - r->o[a];
	long double m0, m1, m2;
	long double u = triple(d, p[2], p[1], &m0);
	long double v = triple(d, p[0], p[2], &m1);
	long double w = triple(d, p[1], p[0], &m2);
	const long double trust = 0x1p-48L; /* far above long double's 2^-64 */
	if (!(fabsl(u) > trust * m0 && fabsl(v) > trust * m1 && fabsl(w) > trust * m2))
		return false;
	if (!((u > 0 && v > 0 && w > 0) || (u < 0 && v < 0 && w < 0)))
		return false;
	/* the plane through the corners: n . (x - p0) = 0 */
	long double e1[3], e2[3], n[3];
	for (int a = 0; a < 3; a++)
		e1[a] = p[1][a] - p[0][a], e2[a] = p[2][a] - p[0][a];
	n[0] = e1[1] * e2[2] - e1[2] * e2[1];
	n[1] = e1[2] * e2[0] - e1[0] * e2[2];
	n[2] = e1[0] * e2[1] - e1[1] * e2[0];
	long double nd = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
	*t = (n[0] * p[0][0] + n[1] * p[0][1] + n[2] * p[0][2]) / nd;
	return *t > 0;
}

static const char *mesh_check(const mesh *raw, const mesh *m, const uint8_t *data, size_t size, char msg[256])
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
		/* the bound of property 3: the least max(t_j, T_j (1 + 2^-20)) */
		double bound = INFINITY;
		for (uint32_t j = 0; hb && j < raw->ntris; j++) {
			vec3 cj[3];
			for (int i = 0; i < 3; i++) {
				const float *p = raw->p[raw->tri[j][i]];
				cj[i] = v3(p[0], p[1], p[2]);
			}
			long double tj;
			if (!truly_crosses(&r, cj, &tj))
				continue;
			mesh one = *raw; /* triangle j alone, through the same test */
			one.tri = raw->tri + j;
			one.ntris = 1;
			float fj = INFINITY, bj[3];
			uint32_t kj;
			if (!mesh_intersect_brute(&one, &r, 0, &fj, &kj, bj))
				continue;
			bound = fmin(bound, fmax((double)fj, (double)(tj * (1 + 0x1p-20L))));
		}
		for (int isa = MESH_ISA_SCALAR; isa < MESH_ISA_BEST; isa++) {
			if (!mesh_isa_force((mesh_isa)isa))
				continue;
			float tt = INFINITY, bt[3];
			uint32_t kt;
			bool ht = mesh_intersect(m, &r, 0, &tt, &kt, bt);
			bool occ = mesh_occluded(m, &r, 0, INFINITY);
			const char *broken = NULL;
			if (ht && !(hb && tt >= tb))
				broken = "1 (nearer than brute force)";
			else if (occ != ht)
				broken = "2 (occluded disagrees)";
			else if (!(tt <= bound || bound == INFINITY))
				broken = "3 (missed a triangle the ray crosses)";
			if (broken) {
				snprintf(msg, 256, "mesh tree (vector unit %d) breaks property %s: ray %d hit %d/%d occluded %d t %.9g, brute force %.9g, bound %.9g",
				         isa, broken, k, ht, hb, occ, tt, tb, bound);
				mesh_isa_force(MESH_ISA_BEST);
				return msg;
			}
		}
		mesh_isa_force(MESH_ISA_BEST);
	}
	return NULL;
}

#endif
