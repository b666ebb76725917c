/* rtsh — rays against a mesh's triangles (mesh.h).
 *
 * The tree is bvh.c's 4-wide BVH, walked here in object space in single
 * precision: the slab tests are those of world.c (the far distance widened
 * by 1 + 2 gamma(3), Ize, "Robust BVH ray traversal", JCGT 2013), four
 * children at a time in SSE. Triangles are tested watertight (Woop, Benthin
 * & Wald, "Watertight ray/triangle intersection", JCGT 2013): the ray is
 * sheared so it runs along +z through the origin, and the three 2D edge
 * functions of the sheared vertices decide the hit; an edge function that
 * rounds to zero is recomputed in double, so a ray through a shared edge or
 * vertex hits exactly one of the triangles meeting there (no cracks).
 */
#include <float.h>
#include <string.h>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "core/bvh.h"
#include "rtsh/mesh.h"


void mesh_ray_make(mesh_ray *r, vec3 o, vec3 d)
{
	r->o[0] = (float)o.x;
	r->o[1] = (float)o.y;
	r->o[2] = (float)o.z;
	r->d[0] = (float)d.x;
	r->d[1] = (float)d.y;
	r->d[2] = (float)d.z;
	float ax = fabsf(r->d[0]), ay = fabsf(r->d[1]), az = fabsf(r->d[2]);
	int kz = ax > ay ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2);
	int kx = (kz + 1) % 3, ky = (kx + 1) % 3;
	if (r->d[kz] < 0.0f) {
		int s = kx;
		kx = ky;
		ky = s;
	}
	r->kx = kx;
	r->ky = ky;
	r->kz = kz;
	r->sx = r->d[kx] / r->d[kz];
	r->sy = r->d[ky] / r->d[kz];
	r->sz = 1.0f / r->d[kz];
}

/* The watertight test of triangle t: t in (tmin, *tmax) sets *tmax and the
 * barycentric weights. */
static inline __attribute__((always_inline)) bool tri_test(const mesh *m, const mesh_ray *r, uint32_t t, float tmin, float *tmax, float b[3])
{
	const uint32_t *i = m->tri[t];
	const float *pa = m->p[i[0]], *pb = m->p[i[1]], *pc = m->p[i[2]];
	int kx = r->kx, ky = r->ky, kz = r->kz;
	float az = pa[kz] - r->o[kz], bz = pb[kz] - r->o[kz], cz = pc[kz] - r->o[kz];
	float ax = pa[kx] - r->o[kx] - r->sx * az, ay = pa[ky] - r->o[ky] - r->sy * az;
	float bx = pb[kx] - r->o[kx] - r->sx * bz, by = pb[ky] - r->o[ky] - r->sy * bz;
	float cx = pc[kx] - r->o[kx] - r->sx * cz, cy = pc[ky] - r->o[ky] - r->sy * cz;
	float u = cx * by - cy * bx, v = ax * cy - ay * cx, w = bx * ay - by * ax;
	if (u == 0.0f || v == 0.0f || w == 0.0f) {
		u = (float)((double)cx * by - (double)cy * bx);
		v = (float)((double)ax * cy - (double)ay * cx);
		w = (float)((double)bx * ay - (double)by * ax);
	}
	if ((u < 0.0f || v < 0.0f || w < 0.0f) && (u > 0.0f || v > 0.0f || w > 0.0f))
		return false;
	float det = u + v + w;
	if (det == 0.0f)
		return false;
	float tt = (u * az + v * bz + w * cz) * r->sz;
	float inv = 1.0f / det;
	float th = tt * inv;
	if (!(th > tmin && th < *tmax))
		return false;
	*tmax = th;
	b[0] = u * inv;
	b[1] = v * inv;
	b[2] = w * inv;
	return true;
}

typedef struct entry {
	uint32_t child, meta;
	float t;
	uint32_t pad;
} entry;

static inline void prepare(const mesh_ray *r, bvh_ray *q)
{
	for (int a = 0; a < 3; a++) {
		float inv = 1.0f / r->d[a];
		bool neg = signbit(inv);
		q->near[a] = (neg ? BVH_HI_X : BVH_LO_X) + a;
		q->far[a] = (neg ? BVH_LO_X : BVH_HI_X) + a;
		float f = r->o[a];
#if defined(__SSE2__)
		q->on[a] = _mm_set1_ps(f);
		q->of[a] = _mm_set1_ps(f);
		q->inv[a] = _mm_set1_ps(inv);
#else
		q->on[a] = f;
		q->of[a] = f;
		q->inv[a] = inv;
#endif
	}
}

bool mesh_intersect(const mesh *m, const mesh_ray *r, float tmin, float *tmax, uint32_t *tri, float b[3])
{
	const bvh *tree = m->tree;
	bvh_ray q;
	prepare(r, &q);
	entry stack[BVH_STACK];
	int sp = 0;
	bool found = false;
	float best = *tmax;
	uint32_t child = tree->root, meta = tree->root_meta;
	for (;;) {
		if (meta) {
			uint32_t count = meta & ~BVH_LEAF;
			for (uint32_t k = 0; k < count; k++)
				if (tri_test(m, r, child + k, tmin, &best, b)) {
					*tri = child + k;
					found = true;
				}
		} else {
			const bvh_node *n = &tree->nodes[child];
			float tn[BVH_WIDTH];
			unsigned hm = bvh_slab4(n, &q, tmin, best, tn);
			if (hm) {
				if (hm & (hm - 1)) {
					int idx[BVH_WIDTH], c = 0;
					for (int k = 0; k < BVH_WIDTH; k++) {
						if (!(hm >> k & 1))
							continue;
						int j = c++;
						while (j > 0 && tn[idx[j - 1]] < tn[k]) {
							idx[j] = idx[j - 1];
							j--;
						}
						idx[j] = k;
					}
					for (int i = 0; i < c; i++)
						stack[sp++] = (entry){n->child[idx[i]], n->meta[idx[i]], tn[idx[i]], 0};
					sp--;
				} else {
					int k = __builtin_ctz(hm);
					stack[sp] = (entry){n->child[k], n->meta[k], 0, 0};
				}
				child = stack[sp].child;
				meta = stack[sp].meta;
				continue;
			}
		}
		while (sp > 0 && stack[sp - 1].t > BVH_SLAB_SLACK * best)
			sp--;
		if (sp == 0)
			break;
		sp--;
		child = stack[sp].child;
		meta = stack[sp].meta;
	}
	/* every hit found was nearer than the last, so b holds the best's */
	if (found)
		*tmax = best;
	return found;
}

bool mesh_occluded(const mesh *m, const mesh_ray *r, float tmin, float tmax)
{
	const bvh *tree = m->tree;
	bvh_ray q;
	prepare(r, &q);
	entry stack[BVH_STACK];
	int sp = 0;
	float b[3];
	uint32_t child = tree->root, meta = tree->root_meta;
	for (;;) {
		if (meta) {
			uint32_t count = meta & ~BVH_LEAF;
			for (uint32_t k = 0; k < count; k++) {
				float t = tmax;
				if (tri_test(m, r, child + k, tmin, &t, b))
					return true;
			}
		} else {
			const bvh_node *n = &tree->nodes[child];
			float tn[BVH_WIDTH];
			unsigned hm = bvh_slab4(n, &q, tmin, tmax, tn);
			if (hm) {
				int k = __builtin_ctz(hm);
				for (unsigned rest = hm & (hm - 1); rest; rest &= rest - 1) {
					int j = __builtin_ctz(rest);
					stack[sp++] = (entry){n->child[j], n->meta[j], tn[j], 0};
				}
				child = n->child[k];
				meta = n->meta[k];
				continue;
			}
		}
		if (sp == 0)
			return false;
		sp--;
		child = stack[sp].child;
		meta = stack[sp].meta;
	}
}

bool mesh_intersect_brute(const mesh *m, const mesh_ray *r, float tmin, float *tmax, uint32_t *tri, float b[3])
{
	bool found = false;
	float bb[3];
	for (uint32_t t = 0; t < m->ntris; t++)
		if (tri_test(m, r, t, tmin, tmax, bb)) {
			*tri = t;
			memcpy(b, bb, sizeof bb);
			found = true;
		}
	return found;
}
