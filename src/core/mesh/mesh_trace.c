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
 *
 * A leaf's triangles are laid out in blocks of four (mesh_tri4: each
 * coordinate of each corner a row of four floats, the same floats as the
 * vertices), and the watertight test runs on the four at once in SSE,
 * doing wt_test's operations in its order so that it finds the very same
 * floats; a lane whose edge function is zero falls back to double alone.
 * The tree is built for these blocks (bvh_build_blocks: a leaf costs what
 * its blocks cost), and a hit names its triangle by its slot, 4 * block +
 * lane, whose corners the block holds (mesh_surface reads them there).
 */
#include <float.h>
#include <stdlib.h>
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

/* The watertight test of one triangle, given its corners' coordinates on
 * the ray's axes kx, ky, kz: t in (tmin, *tmax) sets *tmax and the
 * barycentric weights. The SSE leaf test below does the same operations in
 * the same order, four triangles at a time, so both find the same floats. */
static inline __attribute__((always_inline)) bool wt_test(const mesh_ray *r, float pax, float pay, float paz,
                                                          float pbx, float pby, float pbz, float pcx, float pcy,
                                                          float pcz, float tmin, float *tmax, float b[3])
{
	int kx = r->kx, ky = r->ky, kz = r->kz;
	float az = paz - r->o[kz], bz = pbz - r->o[kz], cz = pcz - r->o[kz];
	float ax = pax - r->o[kx] - r->sx * az, ay = pay - r->o[ky] - r->sy * az;
	float bx = pbx - r->o[kx] - r->sx * bz, by = pby - r->o[ky] - r->sy * bz;
	float cx = pcx - r->o[kx] - r->sx * cz, cy = pcy - r->o[ky] - r->sy * cz;
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

/* Triangle t from the indexed vertices (the brute-force reference, on a
 * mesh not prepared). */
static bool tri_test(const mesh *m, const mesh_ray *r, uint32_t t, float tmin, float *tmax, float b[3])
{
	const uint32_t *i = m->tri[t];
	const float *pa = m->p[i[0]], *pb = m->p[i[1]], *pc = m->p[i[2]];
	int kx = r->kx, ky = r->ky, kz = r->kz;
	return wt_test(r, pa[kx], pa[ky], pa[kz], pb[kx], pb[ky], pb[kz], pc[kx], pc[ky], pc[kz], tmin, tmax, b);
}

/* --- the leaf blocks --- */

bool mesh_make_blocks(mesh *m)
{
	bvh *tree = m->tree;
	free(m->blk);
	free(m->bfirst);
	m->blk = NULL;
	m->bfirst = NULL;
	m->nblk = 0;
	/* count the blocks: every leaf starts a new one */
	size_t n = 0;
	if (tree->root_meta)
		n = ((tree->root_meta & ~BVH_LEAF) + 3) / 4;
	else
		for (size_t i = 0; i < tree->nnodes; i++)
			for (int k = 0; k < BVH_WIDTH; k++)
				if (tree->nodes[i].meta[k])
					n += ((tree->nodes[i].meta[k] & ~BVH_LEAF) + 3) / 4;
	if (n > UINT32_MAX)
		return false;
	mesh_tri4 *blk = aligned_alloc(64, (n * sizeof *blk + 63) / 64 * 64 + 64);
	uint32_t *first = malloc((n ? n : 1) * sizeof *first);
	if (!blk || !first) {
		free(blk);
		free(first);
		return false;
	}
	uint32_t next = 0;
	size_t nodes = tree->root_meta ? 1 : tree->nnodes;
	for (size_t i = 0; i < nodes; i++)
		for (int k = 0; k < (tree->root_meta ? 1 : BVH_WIDTH); k++) {
			uint32_t *child = tree->root_meta ? &tree->root : &tree->nodes[i].child[k];
			uint32_t meta = tree->root_meta ? tree->root_meta : tree->nodes[i].meta[k];
			if (!meta)
				continue;
			uint32_t count = meta & ~BVH_LEAF, t0 = *child;
			*child = next;
			for (uint32_t j = 0; j < count; j += 4, next++) {
				first[next] = t0 + j;
				for (int l = 0; l < 4; l++) {
					/* a lane past the end repeats the last triangle */
					const uint32_t *ti = m->tri[t0 + (j + (uint32_t)l < count ? j + (uint32_t)l : count - 1)];
					for (int c = 0; c < 3; c++)
						for (int a = 0; a < 3; a++)
							blk[next].v[3 * c + a][l] = m->p[ti[c]][a];
				}
			}
		}
	m->blk = blk;
	m->bfirst = first;
	m->nblk = next;
	return true;
}

/* Lanes 0..n-1 of block q one at a time: the nearest hit in (tmin, *best)
 * sets *best and b and returns its lane, else -1. */
static inline __attribute__((always_inline)) int block_scalar(const mesh_tri4 *q, uint32_t n, const mesh_ray *r,
                                                              float tmin, float *best, float b[3])
{
	int kx = r->kx, ky = r->ky, kz = r->kz, found = -1;
	for (uint32_t l = 0; l < n && l < 4; l++)
		if (wt_test(r, q->v[kx][l], q->v[ky][l], q->v[kz][l], q->v[3 + kx][l], q->v[3 + ky][l], q->v[3 + kz][l],
		            q->v[6 + kx][l], q->v[6 + ky][l], q->v[6 + kz][l], tmin, best, b))
			found = (int)l;
	return found;
}

#if defined(__SSE2__)
/* The ray splatted for the SSE leaf test. */
typedef struct ray4 {
	__m128 ox, oy, oz, sx, sy, sz;
} ray4;

static inline void ray4_make(const mesh_ray *r, ray4 *q)
{
	q->ox = _mm_set1_ps(r->o[r->kx]);
	q->oy = _mm_set1_ps(r->o[r->ky]);
	q->oz = _mm_set1_ps(r->o[r->kz]);
	q->sx = _mm_set1_ps(r->sx);
	q->sy = _mm_set1_ps(r->sy);
	q->sz = _mm_set1_ps(r->sz);
}

/* block_scalar's test on the four lanes at once (wt_test's operations in
 * its order; an edge function that is zero in some lane is recomputed in
 * double for that lane, as wt_test does). */
static inline __attribute__((always_inline)) int block_sse(const mesh_tri4 *q, uint32_t n, const mesh_ray *r,
                                                           const ray4 *rq, float tmin, float *best, float b[3])
{
	int kx = r->kx, ky = r->ky, kz = r->kz;
	__m128 az = _mm_sub_ps(_mm_load_ps(q->v[kz]), rq->oz);
	__m128 bz = _mm_sub_ps(_mm_load_ps(q->v[3 + kz]), rq->oz);
	__m128 cz = _mm_sub_ps(_mm_load_ps(q->v[6 + kz]), rq->oz);
	__m128 ax = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(q->v[kx]), rq->ox), _mm_mul_ps(rq->sx, az));
	__m128 ay = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(q->v[ky]), rq->oy), _mm_mul_ps(rq->sy, az));
	__m128 bx = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(q->v[3 + kx]), rq->ox), _mm_mul_ps(rq->sx, bz));
	__m128 by = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(q->v[3 + ky]), rq->oy), _mm_mul_ps(rq->sy, bz));
	__m128 cx = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(q->v[6 + kx]), rq->ox), _mm_mul_ps(rq->sx, cz));
	__m128 cy = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(q->v[6 + ky]), rq->oy), _mm_mul_ps(rq->sy, cz));
	__m128 u = _mm_sub_ps(_mm_mul_ps(cx, by), _mm_mul_ps(cy, bx));
	__m128 v = _mm_sub_ps(_mm_mul_ps(ax, cy), _mm_mul_ps(ay, cx));
	__m128 w = _mm_sub_ps(_mm_mul_ps(bx, ay), _mm_mul_ps(by, ax));
	const __m128 zero = _mm_setzero_ps();
	unsigned lanes = (1u << (n < 4 ? n : 4)) - 1;
	unsigned zm = (unsigned)_mm_movemask_ps(
	                  _mm_or_ps(_mm_or_ps(_mm_cmpeq_ps(u, zero), _mm_cmpeq_ps(v, zero)), _mm_cmpeq_ps(w, zero))) &
	              lanes;
	if (zm) {
		_Alignas(16) float fu[4], fv[4], fw[4], fax[4], fay[4], fbx[4], fby[4], fcx[4], fcy[4];
		_mm_store_ps(fu, u);
		_mm_store_ps(fv, v);
		_mm_store_ps(fw, w);
		_mm_store_ps(fax, ax);
		_mm_store_ps(fay, ay);
		_mm_store_ps(fbx, bx);
		_mm_store_ps(fby, by);
		_mm_store_ps(fcx, cx);
		_mm_store_ps(fcy, cy);
		for (; zm; zm &= zm - 1) {
			int l = __builtin_ctz(zm);
			fu[l] = (float)((double)fcx[l] * fby[l] - (double)fcy[l] * fbx[l]);
			fv[l] = (float)((double)fax[l] * fcy[l] - (double)fay[l] * fcx[l]);
			fw[l] = (float)((double)fbx[l] * fay[l] - (double)fby[l] * fax[l]);
		}
		u = _mm_load_ps(fu);
		v = _mm_load_ps(fv);
		w = _mm_load_ps(fw);
	}
	__m128 neg = _mm_or_ps(_mm_or_ps(_mm_cmplt_ps(u, zero), _mm_cmplt_ps(v, zero)), _mm_cmplt_ps(w, zero));
	__m128 pos = _mm_or_ps(_mm_or_ps(_mm_cmpgt_ps(u, zero), _mm_cmpgt_ps(v, zero)), _mm_cmpgt_ps(w, zero));
	__m128 det = _mm_add_ps(_mm_add_ps(u, v), w);
	__m128 ok = _mm_andnot_ps(_mm_and_ps(neg, pos), _mm_cmpneq_ps(det, zero));
	if (!(_mm_movemask_ps(ok) & lanes))
		return -1;
	__m128 tt = _mm_mul_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(u, az), _mm_mul_ps(v, bz)), _mm_mul_ps(w, cz)), rq->sz);
	__m128 inv = _mm_div_ps(_mm_set1_ps(1.0f), det);
	__m128 th = _mm_mul_ps(tt, inv);
	ok = _mm_and_ps(ok, _mm_and_ps(_mm_cmpgt_ps(th, _mm_set1_ps(tmin)), _mm_cmplt_ps(th, _mm_set1_ps(*best))));
	unsigned hm = (unsigned)_mm_movemask_ps(ok) & lanes;
	if (!hm)
		return -1;
	_Alignas(16) float fth[4];
	_mm_store_ps(fth, th);
	/* the nearest, the first lane on a tie: what block_scalar keeps */
	int l = __builtin_ctz(hm);
	for (unsigned rest = hm & (hm - 1); rest; rest &= rest - 1) {
		int j = __builtin_ctz(rest);
		if (fth[j] < fth[l])
			l = j;
	}
	_Alignas(16) float fu[4], fv[4], fw[4], fi[4];
	_mm_store_ps(fu, u);
	_mm_store_ps(fv, v);
	_mm_store_ps(fw, w);
	_mm_store_ps(fi, inv);
	*best = fth[l];
	b[0] = fu[l] * fi[l];
	b[1] = fv[l] * fi[l];
	b[2] = fw[l] * fi[l];
	return l;
}
#endif

/* --- the walk --- */

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

/* The nearest hit (any = false) or any hit (any = true) in (tmin, *tmax),
 * with SSE leaf tests or scalar ones. */
static inline __attribute__((always_inline)) bool walk(const mesh *m, const mesh_ray *r, float tmin, float *tmax,
                                                       uint32_t *tri, float b[3], bool any, bool sse)
{
	const bvh *tree = m->tree;
	bvh_ray q;
	prepare(r, &q);
#if defined(__SSE2__)
	ray4 rq;
	if (sse)
		ray4_make(r, &rq);
#else
	(void)sse;
#endif
	entry stack[BVH_STACK];
	int sp = 0;
	bool found = false;
	float best = *tmax;
	uint32_t child = tree->root, meta = tree->root_meta;
	for (;;) {
		if (meta) {
			uint32_t count = meta & ~BVH_LEAF;
			for (uint32_t k = 0; k < count; k += 4) {
				const mesh_tri4 *blk = &m->blk[child + k / 4];
				int l;
#if defined(__SSE2__)
				if (sse)
					l = block_sse(blk, count - k, r, &rq, tmin, &best, b);
				else
#endif
					l = block_scalar(blk, count - k, r, tmin, &best, b);
				if (l >= 0) {
					*tri = 4 * (child + k / 4) + (uint32_t)l;
					found = true;
					if (any)
						goto done;
				}
			}
		} else {
			const bvh_node *n = &tree->nodes[child];
			float tn[BVH_WIDTH];
			unsigned hm = bvh_slab4(n, &q, tmin, best, tn);
			if (hm) {
				if (any) {
					int k = __builtin_ctz(hm);
					for (unsigned rest = hm & (hm - 1); rest; rest &= rest - 1) {
						int j = __builtin_ctz(rest);
						stack[sp++] = (entry){n->child[j], n->meta[j], tn[j], 0};
					}
					child = n->child[k];
					meta = n->meta[k];
					continue;
				}
				/* the nearest child next, the others on the stack */
				int k = __builtin_ctz(hm);
				unsigned rest = hm & (hm - 1);
				if (rest) {
					int k2 = __builtin_ctz(rest);
					rest &= rest - 1;
					if (!rest) {
						if (tn[k2] < tn[k]) {
							int x = k;
							k = k2;
							k2 = x;
						}
						stack[sp++] = (entry){n->child[k2], n->meta[k2], tn[k2], 0};
					} else {
						int idx[BVH_WIDTH], c = 0;
						for (int j = 0; j < BVH_WIDTH; j++) {
							if (!(hm >> j & 1))
								continue;
							int i = c++;
							while (i > 0 && tn[idx[i - 1]] < tn[j]) {
								idx[i] = idx[i - 1];
								i--;
							}
							idx[i] = j;
						}
						for (int i = 0; i < c - 1; i++)
							stack[sp++] = (entry){n->child[idx[i]], n->meta[idx[i]], tn[idx[i]], 0};
						k = idx[c - 1];
					}
				}
				child = n->child[k];
				meta = n->meta[k];
				continue;
			}
		}
		if (!any)
			while (sp > 0 && stack[sp - 1].t > BVH_SLAB_SLACK * best)
				sp--;
		if (sp == 0)
			break;
		sp--;
		child = stack[sp].child;
		meta = stack[sp].meta;
	}
done:
	/* every hit found was nearer than the last, so b holds the best's */
	if (found)
		*tmax = best;
	return found;
}

bool mesh_intersect(const mesh *m, const mesh_ray *r, float tmin, float *tmax, uint32_t *tri, float b[3])
{
	return walk(m, r, tmin, tmax, tri, b, false, true);
}

bool mesh_occluded(const mesh *m, const mesh_ray *r, float tmin, float tmax)
{
	uint32_t tri;
	float b[3];
	return walk(m, r, tmin, &tmax, &tri, b, true, true);
}

bool mesh_intersect_scalar(const mesh *m, const mesh_ray *r, float tmin, float *tmax, uint32_t *tri, float b[3])
{
	return walk(m, r, tmin, tmax, tri, b, false, false);
}

bool mesh_occluded_scalar(const mesh *m, const mesh_ray *r, float tmin, float tmax)
{
	uint32_t tri;
	float b[3];
	return walk(m, r, tmin, &tmax, &tri, b, true, false);
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

void mesh_corners(const mesh *m, uint32_t slot, vec3 c[3])
{
	const mesh_tri4 *q = &m->blk[slot >> 2];
	int l = (int)(slot & 3);
	for (int k = 0; k < 3; k++)
		c[k] = v3(q->v[3 * k][l], q->v[3 * k + 1][l], q->v[3 * k + 2][l]);
}
