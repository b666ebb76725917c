/* rtsh — rays against a mesh's triangles (mesh.h).
 *
 * The tree is mesh_tree.c's 8-wide BVH, walked in object space in single
 * precision. A node's eight slab tests run at once in one AVX2 register
 * (built twice: for AVX2, and with AVX-512's 32 registers), or two SSE2
 * ones, or one by one in scalar code; the far distances are
 * widened by 1 + 2 gamma(3) (Ize, "Robust BVH ray traversal", JCGT 2013;
 * through the reciprocal of the direction, mesh_walk.h) and so is the
 * nearest hit where the walk prunes, so no box the ray enters is skipped.
 * The walk goes to the nearest child the ray enters and keeps the others
 * on a stack with their entry distances, nearest on top.
 *
 * Triangles are tested watertight (Woop, Benthin & Wald, "Watertight
 * ray/triangle intersection", JCGT 2013): the ray is sheared so it runs
 * along +z through the origin, and the three 2D edge functions of the
 * sheared vertices decide the hit; an edge function that rounds to zero is
 * recomputed in double, so a ray through a shared edge or vertex always
 * hits one of the triangles meeting there (no cracks). A leaf's
 * triangles are laid out in blocks of four (mesh_tri4), tested together
 * in SSE with wt_test's operations in its order, so that the vector and
 * scalar walks find the very same floats; a hit names its triangle by its
 * slot, 4 * block + lane.
 *
 * The walk is written once (mesh_walk.h) and compiled for each vector
 * unit; mesh_intersect, mesh_occluded and their world-ray forms take the
 * best the processor has (mesh_isa_active), through a table of entries.
 * The triangle test's set-up is made at the walk's first leaf: most rays
 * that miss a model never reach one.
 *
 * glTF cut-outs (alphaMode MASK and BLEND, mesh.cuts): where a block finds
 * hits, the lanes in a hole (mesh_cut_hole) are dropped before the nearest
 * is taken, so no ray of any kind stops there; a mesh without them pays one
 * test of the flag where a block finds a hit (callgrind on the bunny: no
 * instruction more).
 */
#include <float.h>
#include <stddef.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define HAVE_AVX2_WALK 1
#endif

#include "core/bvh/bvh.h"
#include "rtsh/mesh.h"

/* The ray o + t d, in floats, made ready for the walk's box tests: written
 * once and inlined into every entry so that the compiler keeps it in
 * registers. */
static inline __attribute__((always_inline)) void ray_node_setup(mesh_ray *r, float ox, float oy, float oz,
                                                                 float dx, float dy, float dz)
{
	r->o[0] = ox;
	r->o[1] = oy;
	r->o[2] = oz;
	r->d[0] = dx;
	r->d[1] = dy;
	r->d[2] = dz;
	r->inv[0] = 1.0f / dx;
	r->inv[1] = 1.0f / dy;
	r->inv[2] = 1.0f / dz;
}

/* The rest, for the triangle tests: the walk makes it at its first leaf
 * (most rays that miss a model never reach one). kz: the axis of the
 * largest |d| (y before x on a tie, z before both), then kx, ky the next
 * two, swapped when d runs down kz so the triangles' winding is kept;
 * written without branches, which random directions would make guesses
 * of. */
static inline __attribute__((always_inline)) void ray_leaf_setup(mesh_ray *r)
{
	float ax = fabsf(r->d[0]), ay = fabsf(r->d[1]), az = fabsf(r->d[2]);
	/* selects as arithmetic and loads: GCC makes branches of ?: here */
	int kxy = !(ax > ay);
#if defined(__SSE2__)
	float axy = _mm_cvtss_f32(_mm_max_ss(_mm_set_ss(ax), _mm_set_ss(ay))); /* ax > ay ? ax : ay */
#else
	float axy = ax > ay ? ax : ay;
#endif
	int zbig = !(axy > az);
	int kz = kxy + zbig * (2 - kxy);
	static const int next[3] = {1, 2, 0};
	int kx = next[kz], ky = next[kx];
	int swap = (kx ^ ky) & -(int)(r->d[kz] < 0.0f);
	kx ^= swap;
	ky ^= swap;
	r->kx = kx;
	r->ky = ky;
	r->kz = kz;
	r->sz = r->inv[kz];
	r->sx = r->d[kx] * r->sz;
	r->sy = r->d[ky] * r->sz;
}

void mesh_ray_make(mesh_ray *r, vec3 o, vec3 d)
{
	ray_node_setup(r, (float)o.x, (float)o.y, (float)o.z, (float)d.x, (float)d.y, (float)d.z);
	ray_leaf_setup(r);
}

/* minps and maxps of one lane: b when either is a NaN */
static inline float lo_of(float a, float b)
{
	return a < b ? a : b;
}

static inline float hi_of(float a, float b)
{
	return a > b ? a : b;
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
	/* The lowest and highest edge function (lo_of and hi_of: minps and
	 * maxps, NaNs and all). An edge function at zero is recomputed in
	 * double; only the lowest or highest needs to be: a float edge function
	 * that is not zero has its exact sign (rounding keeps order), so a zero
	 * between a negative and a positive changes nothing. */
	float lo = lo_of(lo_of(u, v), w), hi = hi_of(hi_of(u, v), w);
	if (lo == 0.0f || hi == 0.0f) {
		u = (float)((double)cx * by - (double)cy * bx);
		v = (float)((double)ax * cy - (double)ay * cx);
		w = (float)((double)bx * ay - (double)by * ax);
		lo = lo_of(lo_of(u, v), w);
		hi = hi_of(hi_of(u, v), w);
	}
	/* some below zero and some above: a miss (a NaN fails below, on its
	 * NaN distance) */
	if (lo < 0.0f && hi > 0.0f)
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

/* The four lanes of block q (block bi of mesh m) one at a time: the nearest
 * hit in (tmin, *best) sets *best and b and returns its lane, else -1. A
 * hit in a cut-out's hole (m->cuts, mesh_cut_hole) is no hit. */
static inline __attribute__((always_inline)) int block_scalar(const mesh *m, uint32_t bi, const mesh_tri4 *q,
                                                              const mesh_ray *r, float tmin, float *best, float b[3])
{
	int kx = r->kx, ky = r->ky, kz = r->kz, found = -1;
	for (int l = 0; l < 4; l++) {
		float t = *best, bb[3];
		if (wt_test(r, q->v[kx][l], q->v[ky][l], q->v[kz][l], q->v[3 + kx][l], q->v[3 + ky][l], q->v[3 + kz][l],
		            q->v[6 + kx][l], q->v[6 + ky][l], q->v[6 + kz][l], tmin, &t, bb) &&
		    !(m->cuts && mesh_cut_hole(m, 4 * bi + (uint32_t)l, bb))) {
			*best = t;
			b[0] = bb[0];
			b[1] = bb[1];
			b[2] = bb[2];
			found = l;
		}
	}
	return found;
}

#if defined(__SSE2__)
/* The ray splatted for the SSE leaf test. */
typedef struct ray4 {
	__m128 ox, oy, oz, sx, sy, sz;
} ray4;

static inline __attribute__((always_inline)) void ray4_make(const mesh_ray *r, ray4 *q)
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
static inline __attribute__((always_inline)) int block_sse(const mesh *m, uint32_t bi, const mesh_tri4 *q,
                                                           const mesh_ray *r, const ray4 *rq, float tmin, float *best,
                                                           float b[3])
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
	/* the lowest and highest edge functions, as wt_test: at zero, the
	 * lane's are recomputed in double */
	__m128 lo = _mm_min_ps(_mm_min_ps(u, v), w), hi = _mm_max_ps(_mm_max_ps(u, v), w);
	unsigned zm = (unsigned)_mm_movemask_ps(_mm_or_ps(_mm_cmpeq_ps(lo, zero), _mm_cmpeq_ps(hi, zero)));
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
		lo = _mm_min_ps(_mm_min_ps(u, v), w);
		hi = _mm_max_ps(_mm_max_ps(u, v), w);
	}
	/* (a NaN lane fails below, on its NaN distance) */
	__m128 neg = _mm_cmplt_ps(lo, zero);
	__m128 pos = _mm_cmpgt_ps(hi, zero);
	/* det is zero only where all three are (same-signed floats do not sum
	 * to zero): there the distance below is 0 * inf, a NaN, and fails as
	 * wt_test's det test does */
	__m128 out = _mm_and_ps(neg, pos); /* the lanes that miss */
	/* no early way out when all four lanes miss here: for rays in random
	 * directions that branch is a coin toss, and the distances below cost
	 * less than its wrong guesses (diffuse rays +4%, bench/README.md) */
	__m128 det = _mm_add_ps(_mm_add_ps(u, v), w);
	__m128 tt = _mm_mul_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(u, az), _mm_mul_ps(v, bz)), _mm_mul_ps(w, cz)), rq->sz);
	__m128 inv = _mm_div_ps(_mm_set1_ps(1.0f), det);
	__m128 th = _mm_mul_ps(tt, inv);
	__m128 ok = _mm_andnot_ps(out, _mm_and_ps(_mm_cmpgt_ps(th, _mm_set1_ps(tmin)), _mm_cmplt_ps(th, _mm_set1_ps(*best))));
	unsigned hm = (unsigned)_mm_movemask_ps(ok);
	if (!hm)
		return -1;
	if (m->cuts) {
		/* a cut-out (glTF alphaMode MASK): the lanes hit in its holes are
		 * no hits; the nearest of the rest is, as block_scalar finds */
		_Alignas(16) float cu[4], cv[4], cw[4], ci[4];
		_mm_store_ps(cu, u);
		_mm_store_ps(cv, v);
		_mm_store_ps(cw, w);
		_mm_store_ps(ci, inv);
		hm = mesh_cut_lanes(m, bi, hm, cu, cv, cw, ci);
		if (!hm)
			return -1;
	}
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

/* A child waiting on the walk's stack: its reference and entry distance. */
typedef struct entry {
	uint32_t ref;
	float t;
} entry;

/* The deepest stack a walk needs: at most seven children wait per level. */
#define MESH_STACK (7 * BVH_MAX_DEPTH + 8)

/* What the slab tests need of a ray: per axis the byte offset in a node of
 * the row that holds its near planes (by the direction's sign, Williams et
 * al. 2005); the far planes' row is the next one along, or the one before:
 * offset ^ MESH_ROW. The origin is a float already: no rounding to allow
 * for. */
#define MESH_ROW (MESH_WIDTH * sizeof(float))

static inline __attribute__((always_inline)) size_t near_row(const mesh_ray *r, int a)
{
	size_t neg = signbit(r->inv[a]) != 0;
	return (size_t)(MESH_LO(a) + neg) * MESH_ROW;
}

/* Asks for the node or leaf blocks that ref names, to be in the cache when
 * the walk pops it. */
static inline __attribute__((always_inline)) void prefetch_ref(const mesh *m, uint32_t ref)
{
	const char *a = ref & MESH_LEAF ? (const char *)&m->blk[ref & (MESH_MAX_BLOCKS - 1)] : (const char *)m->nodes + ref;
	__builtin_prefetch(a);
	__builtin_prefetch(a + 64);
	__builtin_prefetch(a + 128);
	__builtin_prefetch(a + 192);
}

/* Pushes the children of n in mask hm (at least two) with their entry
 * distances, nearest on top, and returns the nearest, popped. */
static inline __attribute__((always_inline)) uint32_t push_sorted(const mesh_node *n, unsigned hm, const float *tn,
                                                                  entry *stack, int *sp)
{
	int k = __builtin_ctz(hm);
	hm &= hm - 1;
	int k2 = __builtin_ctz(hm);
	hm &= hm - 1;
	if (!hm) {
		if (tn[k2] < tn[k]) {
			int x = k;
			k = k2;
			k2 = x;
		}
		stack[(*sp)++] = (entry){n->child[k2], tn[k2]};
		return n->child[k];
	}
	/* three or more: an insertion sort of the new entries, farthest first */
	int base = *sp, top = base;
	stack[top++] = (entry){n->child[k], tn[k]};
	for (unsigned rest = hm | 1u << k2; rest; rest &= rest - 1) {
		int j = __builtin_ctz(rest);
		entry e = {n->child[j], tn[j]};
		int i = top++;
		while (i > base && stack[i - 1].t < e.t) {
			stack[i] = stack[i - 1];
			i--;
		}
		stack[i] = e;
	}
	*sp = top - 1;
	return stack[top - 1].ref;
}

#ifdef MESH_STATS
_Thread_local unsigned long mesh_stat_nodes, mesh_stat_blocks, mesh_stat_leaves;
#endif

/* The walk for each vector unit: walk_scalar, walk_sse, walk_avx2 and
 * walk_avx512 (the AVX2 code given AVX-512's 32 vector registers, so that
 * the walk keeps the ray in registers through the leaf tests). */
#define WALK walk_scalar
#define WALK_ISA 0
#define WALK_TARGET
#include "mesh_walk.h"

#if defined(__SSE2__)
#define WALK walk_sse
#define WALK_ISA 1
#define WALK_TARGET
#include "mesh_walk.h"
#endif

#if defined(HAVE_AVX2_WALK)
#define AVX2 __attribute__((target("avx2")))
#define AVX512 __attribute__((target("avx2,avx512f,avx512vl")))
#define WALK walk_avx2
#define WALK_ISA 2
#define WALK_TARGET AVX2
#include "mesh_walk.h"
#define WALK walk_avx512
#define WALK_ISA 2
#define WALK_TARGET AVX512
#include "mesh_walk.h"
#endif

/* The walk with the ray's near rows as arguments: from the ray's signs
 * (every ray), or as constants, one inlined copy of the walk per octant of
 * directions chosen by a switch (AVX2 and AVX-512, for coherent rays), so
 * that the three row offsets are immediates and the three registers they
 * held serve the walk. The copies make camera rays 6% faster but rays in
 * random directions 7% slower (the switch guessed wrong, eight copies of
 * the code): bench/README.md. */
#define OCT_CASE(walk, o)                                                                                          \
	case o:                                                                                                    \
		return walk(m, r, leaf_ready, tmin, guard, tmax, tri, b, any, (size_t)(MESH_LO(0) + ((o)&1)) * MESH_ROW, \
		            (size_t)(MESH_LO(1) + ((o) >> 1 & 1)) * MESH_ROW,                                         \
		            (size_t)(MESH_LO(2) + ((o) >> 2 & 1)) * MESH_ROW)
#define WALK_BY_OCTANT(name, walk, target)                                                                          \
	static target inline __attribute__((always_inline)) bool name(const mesh *m, mesh_ray *r, bool leaf_ready,    \
	                                                              float tmin, float guard, float *tmax,          \
	                                                              uint32_t *tri, float b[3], bool any)           \
	{                                                                                                          \
		unsigned o = (unsigned)(signbit(r->inv[0]) != 0) | (unsigned)(signbit(r->inv[1]) != 0) << 1 |      \
		             (unsigned)(signbit(r->inv[2]) != 0) << 2;                                               \
		switch (o) {                                                                                       \
			OCT_CASE(walk, 0);                                                                         \
			OCT_CASE(walk, 1);                                                                         \
			OCT_CASE(walk, 2);                                                                         \
			OCT_CASE(walk, 3);                                                                         \
			OCT_CASE(walk, 4);                                                                         \
			OCT_CASE(walk, 5);                                                                         \
			OCT_CASE(walk, 6);                                                                         \
		default:                                                                                           \
			OCT_CASE(walk, 7);                                                                         \
		}                                                                                                  \
	}
#define WALK_BY_RAY(name, walk, target)                                                                             \
	static target inline __attribute__((always_inline)) bool name(const mesh *m, mesh_ray *r, bool leaf_ready,    \
	                                                              float tmin, float guard, float *tmax,          \
	                                                              uint32_t *tri, float b[3], bool any)           \
	{                                                                                                          \
		return walk(m, r, leaf_ready, tmin, guard, tmax, tri, b, any, near_row(r, 0), near_row(r, 1),       \
		            near_row(r, 2));                                                                         \
	}

/* A world ray on an instance (M: world to model) in the model's floats,
 * ready for the box tests: the single walks (WALK_WORLD) and the packets
 * make it alike. An instance that is not turned (an upright model: M
 * scales and moves only) skips M's zeros, 24 of its 33 operations: the same
 * floats but for the sign of a zero coordinate, on every unit (camera rays
 * +7%, diffuse +2%: bench/README.md). */
static inline __attribute__((always_inline)) bool upright(const double (*M)[4])
{
	return M[0][1] == 0 && M[0][2] == 0 && M[1][0] == 0 && M[1][2] == 0 && M[2][0] == 0 && M[2][1] == 0;
}

static inline __attribute__((always_inline)) void world_ray_floats(const double (*M)[4], bool up, const ray *wr,
                                                                   float o[3], float d[3])
{
	double px = wr->o.x, py = wr->o.y, pz = wr->o.z, vx = wr->d.x, vy = wr->d.y, vz = wr->d.z;
	if (up) {
		o[0] = (float)(M[0][0] * px + M[0][3]);
		o[1] = (float)(M[1][1] * py + M[1][3]);
		o[2] = (float)(M[2][2] * pz + M[2][3]);
		d[0] = (float)(M[0][0] * vx);
		d[1] = (float)(M[1][1] * vy);
		d[2] = (float)(M[2][2] * vz);
	} else {
		o[0] = (float)(M[0][0] * px + M[0][1] * py + M[0][2] * pz + M[0][3]);
		o[1] = (float)(M[1][0] * px + M[1][1] * py + M[1][2] * pz + M[1][3]);
		o[2] = (float)(M[2][0] * px + M[2][1] * py + M[2][2] * pz + M[2][3]);
		d[0] = (float)(M[0][0] * vx + M[0][1] * vy + M[0][2] * vz);
		d[1] = (float)(M[1][0] * vx + M[1][1] * vy + M[1][2] * vz);
		d[2] = (float)(M[2][0] * vx + M[2][1] * vy + M[2][2] * vz);
	}
}

static inline __attribute__((always_inline)) void world_ray_setup(const double (*M)[4], const ray *wr, mesh_ray *r)
{
	float o[3], d[3];
	world_ray_floats(M, upright(M), wr, o, d);
	ray_node_setup(r, o[0], o[1], o[2], d[0], d[1], d[2]);
}

/* A world ray on an instance for the walk `walk` (world_ray_setup). */
#define WALK_WORLD(name, walk, target)                                                                              \
	static target inline __attribute__((always_inline)) bool name(const mesh *m, const double (*M)[4],          \
	                                                                     const ray *wr, double tmin, double tmax, \
	                                                                     double *t, uint32_t *slot, float b[3],   \
	                                                                     bool any)                                \
	{                                                                                                             \
		mesh_ray r;                                                                                           \
		world_ray_setup(M, wr, &r);                                                                           \
		float ft = tmax < 3e38 ? (float)tmax : INFINITY;                                                      \
		if (!walk(m, &r, false, (float)tmin, m->eps, &ft, slot, b, any) || !((double)ft < tmax))              \
			return false;                                                                                 \
		*t = ft;                                                                                              \
		return true;                                                                                          \
	}

/* The entries of one vector unit's walk: a mesh_ray in the model's
 * coordinates (mesh_intersect, mesh_occluded), or a world ray and an
 * instance's world-to-model matrix M (mesh_intersect_world, ..._occluded_
 * world): M takes it into the model's coordinates in double, then it is
 * rounded to floats. The triangles are then tested from tmin raised past
 * the model's rounding (m->eps in the model's units, made the ray's at the
 * first leaf); the boxes from the caller's tmin, which is no larger (they
 * are visited a little more, never less). */
#define WALK_ENTRIES(isa, walk0, target)                                                                            \
	WALK_BY_RAY(isa##_walk, walk0, target)                                                                       \
	static target __attribute__((noinline)) bool isa##_hit(const mesh *m, const mesh_ray *r, float tmin,           \
	                                                       float *tmax, uint32_t *tri, float b[3])                \
	{                                                                                                             \
		mesh_ray lr = *r;                                                                                     \
		return isa##_walk(m, &lr, true, tmin, 0, tmax, tri, b, false);                                              \
	}                                                                                                             \
	static target __attribute__((noinline)) bool isa##_any(const mesh *m, const mesh_ray *r, float tmin,           \
	                                                       float tmax)                                            \
	{                                                                                                             \
		uint32_t tri;                                                                                         \
		float b[3];                                                                                           \
		mesh_ray lr = *r;                                                                                     \
		return isa##_walk(m, &lr, true, tmin, 0, &tmax, &tri, b, true);                                             \
	}                                                                                                             \
	WALK_WORLD(isa##_world, isa##_walk, target)                                                                        \
	static target __attribute__((noinline)) bool isa##_hit_world(const mesh *m, const double (*M)[4],             \
	                                                             const ray *wr, double tmin, double tmax,         \
	                                                             double *t, uint32_t *slot, float b[3])           \
	{                                                                                                             \
		return isa##_world(m, M, wr, tmin, tmax, t, slot, b, false);                                          \
	}                                                                                                             \
	static target __attribute__((noinline)) bool isa##_any_world(const mesh *m, const double (*M)[4],             \
	                                                             const ray *wr, double tmin, double tmax)         \
	{                                                                                                             \
		double t;                                                                                             \
		uint32_t slot;                                                                                        \
		float b[3];                                                                                           \
		return isa##_world(m, M, wr, tmin, tmax, &t, &slot, b, true);                                         \
	}

/* The coherent entry (mesh_intersect_world_coherent): the copies of the
 * walk by octant where the vector unit has them. */
#define WALK_COHERENT(isa, walk0, target)                                                                           \
	WALK_BY_OCTANT(isa##_walk_o, walk0, target)                                                                  \
	WALK_WORLD(isa##_world_o, isa##_walk_o, target)                                                              \
	static target __attribute__((noinline)) bool isa##_hit_world_coherent(const mesh *m, const double (*M)[4],    \
	                                                                      const ray *wr, double tmin,             \
	                                                                      double tmax, double *t,                 \
	                                                                      uint32_t *slot, float b[3])             \
	{                                                                                                             \
		return isa##_world_o(m, M, wr, tmin, tmax, t, slot, b, false);                                        \
	}

#if defined(HAVE_AVX2_WALK)
/* --- packets (mesh_intersect_world_packet) ---
 *
 * Up to MESH_PACKET_MAX rays whose directions share each axis's sign walk
 * the tree once. A node's eight children are tested against the packet as
 * intervals: per axis, the near distance (b - o) inv of any ray is no less
 * than the lowest corner product of b less the rays' farthest origin and
 * their lowest and highest inverse, and the far one (b - o) (inv S) no
 * more than the highest corner product (rounding to nearest is monotonic,
 * so the bounds hold for each ray's rounded floats). A child that no ray
 * could enter by its own test is skipped for all; the others are visited
 * nearest first for the packet. A leaf is entered by the rays whose own
 * slab test (the single walk's floats) lets them into its box, and each of
 * those meets its blocks with the single ray's block test (block_sse), so
 * a hit is the single ray's floats: distance, slot, barycentrics.
 *
 * The nearest distance does not depend on the order of the walk; which of
 * two triangles at the same distance wins does (the single ray keeps the
 * first it meets, block_sse the first lane in a block). A ray therefore
 * also takes a triangle at exactly its distance so far, from another
 * block, as a tie; a ray with a tie at the end is reported (the caller
 * traces it alone). */

/* A child waiting on the packet's stack: its reference, the packet's entry
 * distance, and where its box is (node `parent`'s column k). */
typedef struct pk_entry {
	uint32_t ref;
	float t;
	uint32_t parent, k;
} pk_entry;

typedef struct mesh_packet {
	/* the rays by component for the leaves' slab tests (lanes past n hold
	 * ray 0 again), and each ray's fl((next float above best) S) */
	_Alignas(32) float ox[MESH_PACKET_MAX], oy[MESH_PACKET_MAX], oz[MESH_PACKET_MAX];
	_Alignas(32) float ix[MESH_PACKET_MAX], iy[MESH_PACKET_MAX], iz[MESH_PACKET_MAX];
	_Alignas(32) float fx[MESH_PACKET_MAX], fy[MESH_PACKET_MAX], fz[MESH_PACKET_MAX];
	_Alignas(32) float bs[MESH_PACKET_MAX];
	_Alignas(32) float dx[MESH_PACKET_MAX], dy[MESH_PACKET_MAX], dz[MESH_PACKET_MAX];
	/* the triangle test's by component (pk_ready): the origin on the
	 * axes kx, ky, kz, the shear constants, tmin, the next float above
	 * the best so far */
	_Alignas(32) float kox[MESH_PACKET_MAX], koy[MESH_PACKET_MAX], koz[MESH_PACKET_MAX];
	_Alignas(32) float ksx[MESH_PACKET_MAX], ksy[MESH_PACKET_MAX], ksz[MESH_PACKET_MAX];
	_Alignas(32) float tmin[MESH_PACKET_MAX], bt[MESH_PACKET_MAX];
	_Alignas(32) int32_t axes[MESH_PACKET_MAX]; /* kx | ky << 2 | kz << 4 */
	float best[MESH_PACKET_MAX];
	uint32_t slot[MESH_PACKET_MAX];
	float b[MESH_PACKET_MAX][3];
	unsigned found, tie;
	bool ready; /* the triangle set-up is made (pk_ready, at the packet's first leaf) */
	bool any;   /* any hit will do (mesh_occluded_world_packet) */
	float tmin0;    /* the query's tmin as a float */
	float eps;      /* the mesh's self-hit guard */
} mesh_packet;

/* The smallest float above t (+inf stays). */
static inline float next_upf(float t)
{
	if (!(t < INFINITY))
		return t;
	if (t == 0.0f)
		return 0x1p-149f;
	uint32_t u;
	memcpy(&u, &t, sizeof u);
	u = u >> 31 ? u - 1 : u + 1; /* a negative one comes nearer zero */
	memcpy(&t, &u, sizeof t);
	return t;
}

/* The rays (a bit each) whose own slab test, the single walk's floats,
 * lets them into column k of node p. */
static AVX2 inline unsigned pk_rays_in(const mesh_packet *s, const mesh_node *p, uint32_t k, float box_tmin, size_t rn0,
                                       size_t rn1, size_t rn2)
{
#define ROW(n, off) ((const float *)((const char *)(n)->b + (off)))
	const __m256 nx = _mm256_set1_ps(ROW(p, rn0)[k]), ny = _mm256_set1_ps(ROW(p, rn1)[k]),
		     nz = _mm256_set1_ps(ROW(p, rn2)[k]);
	const __m256 gx = _mm256_set1_ps(ROW(p, rn0 ^ MESH_ROW)[k]), gy = _mm256_set1_ps(ROW(p, rn1 ^ MESH_ROW)[k]),
		     gz = _mm256_set1_ps(ROW(p, rn2 ^ MESH_ROW)[k]);
#undef ROW
	unsigned m = 0;
	for (int h = 0; h < MESH_PACKET_MAX; h += 8) {
		__m256 ox = _mm256_load_ps(&s->ox[h]), oy = _mm256_load_ps(&s->oy[h]), oz = _mm256_load_ps(&s->oz[h]);
		__m256 t0 = _mm256_max_ps(_mm256_mul_ps(_mm256_sub_ps(nx, ox), _mm256_load_ps(&s->ix[h])),
					  _mm256_set1_ps(box_tmin));
		__m256 t1 = _mm256_min_ps(_mm256_mul_ps(_mm256_sub_ps(gx, ox), _mm256_load_ps(&s->fx[h])),
					  _mm256_load_ps(&s->bs[h]));
		t0 = _mm256_max_ps(_mm256_mul_ps(_mm256_sub_ps(ny, oy), _mm256_load_ps(&s->iy[h])), t0);
		t1 = _mm256_min_ps(_mm256_mul_ps(_mm256_sub_ps(gy, oy), _mm256_load_ps(&s->fy[h])), t1);
		t0 = _mm256_max_ps(_mm256_mul_ps(_mm256_sub_ps(nz, oz), _mm256_load_ps(&s->iz[h])), t0);
		t1 = _mm256_min_ps(_mm256_mul_ps(_mm256_sub_ps(gz, oz), _mm256_load_ps(&s->fz[h])), t1);
		m |= (unsigned)_mm256_movemask_ps(_mm256_cmp_ps(t0, t1, _CMP_LE_OQ)) << h;
	}
	return m;
}

/* Every ray's triangle set-up and tmin by component, as ray_leaf_setup
 * and the single walk's first leaf make them (the same selections and the
 * same operations, eight rays at a time): the origin on the axes kx, ky,
 * kz, the shear constants, the axes themselves. */
static AVX2 inline void pk_ready(mesh_packet *s)
{
	const __m256 mag = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff)), zero = _mm256_setzero_ps();
	const __m256i i0 = _mm256_setzero_si256(), i1 = _mm256_set1_epi32(1), i2 = _mm256_set1_epi32(2);
	for (int h = 0; h < MESH_PACKET_MAX; h += 8) {
		__m256 dx = _mm256_load_ps(&s->dx[h]), dy = _mm256_load_ps(&s->dy[h]), dz = _mm256_load_ps(&s->dz[h]);
		__m256 ax = _mm256_and_ps(dx, mag), ay = _mm256_and_ps(dy, mag), az = _mm256_and_ps(dz, mag);
		/* kz: 2 when !(max(ax, ay) > az), else 1 when !(ax > ay), else 0 */
		__m256i kxy = _mm256_castps_si256(_mm256_cmp_ps(ax, ay, _CMP_NGT_UQ)); /* all ones: kz 1 */
		__m256i zbig = _mm256_castps_si256(_mm256_cmp_ps(_mm256_max_ps(ax, ay), az, _CMP_NGT_UQ));
		__m256i kz = _mm256_blendv_epi8(_mm256_blendv_epi8(i0, i1, kxy), i2, zbig);
		/* kx = next[kz], ky = next[kx] (next: 1, 2, 0), swapped when
		 * d[kz] < 0 */
		__m256i kz0 = _mm256_cmpeq_epi32(kz, i0), kz1 = _mm256_cmpeq_epi32(kz, i1);
		__m256i kx = _mm256_blendv_epi8(_mm256_blendv_epi8(i0, i2, kz1), i1, kz0);
		__m256i ky = _mm256_blendv_epi8(_mm256_blendv_epi8(i1, i0, kz1), i2, kz0);
		__m256 dkz = _mm256_blendv_ps(_mm256_blendv_ps(dz, dy, _mm256_castsi256_ps(kz1)), dx,
					      _mm256_castsi256_ps(kz0));
		__m256i neg = _mm256_castps_si256(_mm256_cmp_ps(dkz, zero, _CMP_LT_OQ));
		__m256i kx2 = _mm256_blendv_epi8(kx, ky, neg), ky2 = _mm256_blendv_epi8(ky, kx, neg);
		/* a component by axis k: x, y or z of each lane */
#define PICK(k, vx, vy, vz)                                                                                            \
	_mm256_blendv_ps(_mm256_blendv_ps(vz, vy, _mm256_castsi256_ps(_mm256_cmpeq_epi32(k, i1))), vx,                 \
			 _mm256_castsi256_ps(_mm256_cmpeq_epi32(k, i0)))
		__m256 ox = _mm256_load_ps(&s->ox[h]), oy = _mm256_load_ps(&s->oy[h]), oz = _mm256_load_ps(&s->oz[h]);
		__m256 sz = PICK(kz, _mm256_load_ps(&s->ix[h]), _mm256_load_ps(&s->iy[h]), _mm256_load_ps(&s->iz[h]));
		_mm256_store_ps(&s->ksz[h], sz);
		_mm256_store_ps(&s->ksx[h], _mm256_mul_ps(PICK(kx2, dx, dy, dz), sz));
		_mm256_store_ps(&s->ksy[h], _mm256_mul_ps(PICK(ky2, dx, dy, dz), sz));
		_mm256_store_ps(&s->kox[h], PICK(kx2, ox, oy, oz));
		_mm256_store_ps(&s->koy[h], PICK(ky2, ox, oy, oz));
		_mm256_store_ps(&s->koz[h], PICK(kz, ox, oy, oz));
#undef PICK
		__m256i axes = _mm256_or_si256(_mm256_or_si256(kx2, _mm256_slli_epi32(ky2, 2)), _mm256_slli_epi32(kz, 4));
		_mm256_store_si256((__m256i *)&s->axes[h], axes);
		/* tmin raised to eps / |d| (tm > g ? tm : g, as maxps) */
		__m256 tm = _mm256_set1_ps(s->tmin0);
		if (s->eps > 0.0f) {
			__m256 dd = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)), _mm256_mul_ps(dz, dz));
			tm = _mm256_max_ps(tm, _mm256_div_ps(_mm256_set1_ps(s->eps), _mm256_sqrt_ps(dd)));
		}
		_mm256_store_ps(&s->tmin[h], tm);
	}
	s->ready = 1;
}

/* Ray i's pick in one block (block_sse's answer: distance th, slot, its
 * barycentrics): nearer than its best, it is the new best; at exactly its
 * best, from another block, a tie (at the query's tmax with nothing found:
 * no hit, as for the single ray). */
static inline void pk_take(mesh_packet *s, int i, uint32_t slot, float th, float b0, float b1, float b2)
{
	if (s->any) {
		/* any hit will do: the ray is done (no leaf lets it in again,
		 * no block finds it a hit, the packet does not wait for it) */
		s->best[i] = th;
		s->bt[i] = -INFINITY;
		s->bs[i] = -INFINITY;
		s->found |= 1u << i;
		return;
	}
	if (th < s->best[i]) {
		s->best[i] = th;
		s->bt[i] = next_upf(th);
		s->bs[i] = s->bt[i] * BVH_SLAB_SLACK;
		s->slot[i] = slot;
		s->b[i][0] = b0;
		s->b[i][1] = b1;
		s->b[i][2] = b2;
		s->found |= 1u << i;
		s->tie &= ~(1u << i);
	} else if (s->found >> i & 1u) {
		s->tie |= 1u << i;
	}
}

/* Ray i meets the blocks of leaf `ref`, with the single ray's block test
 * (its bound the next float above its best, so that a triangle at exactly
 * that distance is seen). */
static AVX2 inline void pk_leaf(const mesh *m, mesh_packet *s, int i, uint32_t ref)
{
	uint32_t first = ref & (MESH_MAX_BLOCKS - 1), nb = ((ref & ~MESH_LEAF) >> MESH_LEAF_SHIFT) + 1;
	mesh_ray r;
	r.o[0] = s->ox[i];
	r.o[1] = s->oy[i];
	r.o[2] = s->oz[i];
	r.kx = s->axes[i] & 3;
	r.ky = s->axes[i] >> 2 & 3;
	r.kz = s->axes[i] >> 4;
	r.sx = s->ksx[i];
	r.sy = s->ksy[i];
	r.sz = s->ksz[i];
	ray4 rq;
	ray4_make(&r, &rq);
	for (uint32_t k = 0; k < nb; k++) {
		float bt = s->bt[i], bb[3];
		int l = block_sse(m, first + k, &m->blk[first + k], &r, &rq, s->tmin[i], &bt, bb);
		if (l >= 0)
			pk_take(s, i, 4 * (first + k) + (uint32_t)l, bt, bb[0], bb[1], bb[2]);
	}
}

/* The rays `in` (ready, with the same axes kx, ky, kz) meet the blocks of
 * leaf `ref` eight at a time: each triangle of a block against eight rays
 * in one register, block_sse's operations in its order lane by lane (the
 * lanes are rays here, not triangles), and per ray the block's pick as
 * block_sse makes it: the nearest of the triangles with tmin < t < bt, the
 * first on a tie. No cut-outs here (pk_leaf has them). */
static AVX2 inline void pk_leaf_rays(const mesh *m, mesh_packet *s, unsigned in, uint32_t ref, int kx, int ky, int kz)
{
	uint32_t first = ref & (MESH_MAX_BLOCKS - 1), nb = ((ref & ~MESH_LEAF) >> MESH_LEAF_SHIFT) + 1;
	const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f), inf = _mm256_set1_ps(INFINITY);
	const __m256i bits = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
	for (int h = 0; h < MESH_PACKET_MAX; h += 8) {
		unsigned hm = in >> h & 0xffu;
		if (!hm)
			continue;
		const __m256 act = _mm256_castsi256_ps(
			_mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32((int)hm), bits), bits));
		const __m256 ox = _mm256_load_ps(&s->kox[h]), oy = _mm256_load_ps(&s->koy[h]), oz = _mm256_load_ps(&s->koz[h]);
		const __m256 sx = _mm256_load_ps(&s->ksx[h]), sy = _mm256_load_ps(&s->ksy[h]), sz = _mm256_load_ps(&s->ksz[h]);
		const __m256 tmin = _mm256_load_ps(&s->tmin[h]);
		for (uint32_t k = 0; k < nb; k++) {
			const mesh_tri4 *q = &m->blk[first + k];
			const __m256 bt = _mm256_load_ps(&s->bt[h]);
			__m256 pick = inf, pu = zero, pv = zero, pw = zero;
			__m256i pl = _mm256_set1_epi32(-1);
			for (int l = 0; l < 4; l++) {
				__m256 az = _mm256_sub_ps(_mm256_set1_ps(q->v[kz][l]), oz);
				__m256 bz = _mm256_sub_ps(_mm256_set1_ps(q->v[3 + kz][l]), oz);
				__m256 cz = _mm256_sub_ps(_mm256_set1_ps(q->v[6 + kz][l]), oz);
				__m256 ax = _mm256_sub_ps(_mm256_sub_ps(_mm256_set1_ps(q->v[kx][l]), ox), _mm256_mul_ps(sx, az));
				__m256 ay = _mm256_sub_ps(_mm256_sub_ps(_mm256_set1_ps(q->v[ky][l]), oy), _mm256_mul_ps(sy, az));
				__m256 bx = _mm256_sub_ps(_mm256_sub_ps(_mm256_set1_ps(q->v[3 + kx][l]), ox), _mm256_mul_ps(sx, bz));
				__m256 by = _mm256_sub_ps(_mm256_sub_ps(_mm256_set1_ps(q->v[3 + ky][l]), oy), _mm256_mul_ps(sy, bz));
				__m256 cx = _mm256_sub_ps(_mm256_sub_ps(_mm256_set1_ps(q->v[6 + kx][l]), ox), _mm256_mul_ps(sx, cz));
				__m256 cy = _mm256_sub_ps(_mm256_sub_ps(_mm256_set1_ps(q->v[6 + ky][l]), oy), _mm256_mul_ps(sy, cz));
				__m256 u = _mm256_sub_ps(_mm256_mul_ps(cx, by), _mm256_mul_ps(cy, bx));
				__m256 v = _mm256_sub_ps(_mm256_mul_ps(ax, cy), _mm256_mul_ps(ay, cx));
				__m256 w = _mm256_sub_ps(_mm256_mul_ps(bx, ay), _mm256_mul_ps(by, ax));
				__m256 lo = _mm256_min_ps(_mm256_min_ps(u, v), w), hi = _mm256_max_ps(_mm256_max_ps(u, v), w);
				unsigned zm = (unsigned)_mm256_movemask_ps(
						      _mm256_or_ps(_mm256_cmp_ps(lo, zero, _CMP_EQ_OQ), _mm256_cmp_ps(hi, zero, _CMP_EQ_OQ))) &
					      hm;
				if (zm) {
					/* an edge function at zero: in double, as wt_test */
					_Alignas(32) float fu[8], fv[8], fw[8], fax[8], fay[8], fbx[8], fby[8], fcx[8], fcy[8];
					_mm256_store_ps(fu, u);
					_mm256_store_ps(fv, v);
					_mm256_store_ps(fw, w);
					_mm256_store_ps(fax, ax);
					_mm256_store_ps(fay, ay);
					_mm256_store_ps(fbx, bx);
					_mm256_store_ps(fby, by);
					_mm256_store_ps(fcx, cx);
					_mm256_store_ps(fcy, cy);
					for (; zm; zm &= zm - 1) {
						int j = __builtin_ctz(zm);
						fu[j] = (float)((double)fcx[j] * fby[j] - (double)fcy[j] * fbx[j]);
						fv[j] = (float)((double)fax[j] * fcy[j] - (double)fay[j] * fcx[j]);
						fw[j] = (float)((double)fbx[j] * fay[j] - (double)fby[j] * fax[j]);
					}
					u = _mm256_load_ps(fu);
					v = _mm256_load_ps(fv);
					w = _mm256_load_ps(fw);
					lo = _mm256_min_ps(_mm256_min_ps(u, v), w);
					hi = _mm256_max_ps(_mm256_max_ps(u, v), w);
				}
				__m256 out = _mm256_and_ps(_mm256_cmp_ps(lo, zero, _CMP_LT_OQ), _mm256_cmp_ps(hi, zero, _CMP_GT_OQ));
				/* no ray of the eight meets it: the next (coherent rays
				 * mostly agree; a NaN lane goes on, to fail on its
				 * distance) */
				if (!_mm256_movemask_ps(_mm256_andnot_ps(out, act)))
					continue;
				__m256 det = _mm256_add_ps(_mm256_add_ps(u, v), w);
				__m256 tt = _mm256_mul_ps(
					_mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(u, az), _mm256_mul_ps(v, bz)), _mm256_mul_ps(w, cz)), sz);
				__m256 inv = _mm256_div_ps(one, det);
				__m256 th = _mm256_mul_ps(tt, inv);
				__m256 ok = _mm256_andnot_ps(out, _mm256_and_ps(_mm256_cmp_ps(th, tmin, _CMP_GT_OQ),
										_mm256_cmp_ps(th, bt, _CMP_LT_OQ)));
				/* the nearest so far in the block, the first on a tie */
				__m256 better = _mm256_and_ps(_mm256_and_ps(ok, act), _mm256_cmp_ps(th, pick, _CMP_LT_OQ));
				if (!_mm256_movemask_ps(better))
					continue;
				pick = _mm256_blendv_ps(pick, th, better);
				pl = _mm256_castps_si256(
					_mm256_blendv_ps(_mm256_castsi256_ps(pl), _mm256_castsi256_ps(_mm256_set1_epi32(l)), better));
				pu = _mm256_blendv_ps(pu, _mm256_mul_ps(u, inv), better);
				pv = _mm256_blendv_ps(pv, _mm256_mul_ps(v, inv), better);
				pw = _mm256_blendv_ps(pw, _mm256_mul_ps(w, inv), better);
			}
			unsigned got = ~(unsigned)_mm256_movemask_ps(_mm256_castsi256_ps(pl)) & hm;
			if (!got)
				continue;
			_Alignas(32) float fp[8], fu[8], fv[8], fw[8];
			_Alignas(32) int32_t fl[8];
			_mm256_store_ps(fp, pick);
			_mm256_store_ps(fu, pu);
			_mm256_store_ps(fv, pv);
			_mm256_store_ps(fw, pw);
			_mm256_store_si256((__m256i *)fl, pl);
			for (; got; got &= got - 1) {
				int j = __builtin_ctz(got);
				pk_take(s, h + j, 4 * (first + k) + (uint32_t)fl[j], fp[j], fu[j], fv[j], fw[j]);
			}
		}
	}
}

/* The rays `in` meet the blocks of leaf `ref`: eight at a time when they
 * share their axes and the model has no cut-outs, else one by one. */
static AVX2 inline void pk_leaf_all(const mesh *m, mesh_packet *s, unsigned in, uint32_t ref)
{
	if (!s->ready)
		pk_ready(s);
	/* the rays whose axes are the first's, in vector registers (the
	 * axes were just stored as vectors: a scalar load would wait) */
	int i0 = __builtin_ctz(in);
	__m256i a0 = _mm256_load_si256((const __m256i *)&s->axes[0]), a1 = _mm256_load_si256((const __m256i *)&s->axes[8]);
	__m256i first = _mm256_permutevar8x32_epi32(i0 < 8 ? a0 : a1, _mm256_set1_epi32(i0 & 7));
	unsigned same = (unsigned)_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(a0, first))) |
			(unsigned)_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(a1, first))) << 8;
	if (!m->cuts && (in & (in - 1)) && !(in & ~same)) {
		int ax = _mm256_cvtsi256_si32(first);
		pk_leaf_rays(m, s, in, ref, ax & 3, ax >> 2 & 3, ax >> 4);
		return;
	}
	for (; in; in &= in - 1)
		pk_leaf(m, s, __builtin_ctz(in), ref);
}

/* The highest of the rays' bs: where the packet prunes. */
static AVX2 inline float pk_far(const mesh_packet *s)
{
	__m256 a = _mm256_max_ps(_mm256_load_ps(&s->bs[0]), _mm256_load_ps(&s->bs[8]));
	__m128 b = _mm_max_ps(_mm256_castps256_ps128(a), _mm256_extractf128_ps(a, 1));
	b = _mm_max_ps(b, _mm_movehl_ps(b, b));
	b = _mm_max_ss(b, _mm_shuffle_ps(b, b, 1));
	return _mm_cvtss_f32(b);
}

/* The lowest and highest of eight floats (no NaN among them). */
static AVX2 inline float pk_hmin(__m256 a)
{
	__m128 b = _mm_min_ps(_mm256_castps256_ps128(a), _mm256_extractf128_ps(a, 1));
	b = _mm_min_ps(b, _mm_movehl_ps(b, b));
	return _mm_cvtss_f32(_mm_min_ss(b, _mm_shuffle_ps(b, b, 1)));
}

static AVX2 inline float pk_hmax(__m256 a)
{
	__m128 b = _mm_max_ps(_mm256_castps256_ps128(a), _mm256_extractf128_ps(a, 1));
	b = _mm_max_ps(b, _mm_movehl_ps(b, b));
	return _mm_cvtss_f32(_mm_max_ss(b, _mm_shuffle_ps(b, b, 1)));
}

static AVX2 __attribute__((noinline)) bool packet_walk(const mesh *m, const double (*M)[4], int n, const ray *wr,
                                                       double tmin, double tmax1, const double *tmax, double *t,
                                                       uint32_t *slot, float (*b)[3], unsigned *found, unsigned *tie,
                                                       bool any)
{
	_Alignas(32) mesh_packet s;
	s.any = any;
	float box_tmin = (float)tmin;
	/* the rays in the model's floats by component, as the single walk
	 * makes them (world_ray_floats: its operations in its order, four rays
	 * at a time), the lanes past n ray 0 again */
	const bool up = upright(M);
	int i = 0;
	{
		_Static_assert(sizeof(ray) == 6 * sizeof(double) && offsetof(ray, d) == 3 * sizeof(double),
			       "ray: six doubles o, d");
		const __m256d m00 = _mm256_set1_pd(M[0][0]), m01 = _mm256_set1_pd(M[0][1]), m02 = _mm256_set1_pd(M[0][2]),
			      m03 = _mm256_set1_pd(M[0][3]);
		const __m256d m10 = _mm256_set1_pd(M[1][0]), m11 = _mm256_set1_pd(M[1][1]), m12 = _mm256_set1_pd(M[1][2]),
			      m13 = _mm256_set1_pd(M[1][3]);
		const __m256d m20 = _mm256_set1_pd(M[2][0]), m21 = _mm256_set1_pd(M[2][1]), m22 = _mm256_set1_pd(M[2][2]),
			      m23 = _mm256_set1_pd(M[2][3]);
		const __m256d huge = _mm256_set1_pd(3e38);
		const __m256i pick = _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6);
		for (; i + 4 <= n; i += 4) {
			/* the four rays' 24 doubles turned into six registers of
			 * one component each (loads and shuffles: gathers are slow) */
			const ray *q4 = &wr[i];
			__m256d a0 = _mm256_loadu_pd(&q4[0].o.x), a1 = _mm256_loadu_pd(&q4[1].o.x);
			__m256d a2 = _mm256_loadu_pd(&q4[2].o.x), a3 = _mm256_loadu_pd(&q4[3].o.x);
			/* a_k: o.x o.y o.z d.x of ray k; c_k: d.y d.z of ray k */
			__m128d c0 = _mm_loadu_pd(&q4[0].d.y), c1 = _mm_loadu_pd(&q4[1].d.y);
			__m128d c2 = _mm_loadu_pd(&q4[2].d.y), c3 = _mm_loadu_pd(&q4[3].d.y);
			__m256d t0 = _mm256_unpacklo_pd(a0, a1); /* ox0 ox1 oz0 oz1 */
			__m256d t1 = _mm256_unpackhi_pd(a0, a1); /* oy0 oy1 dx0 dx1 */
			__m256d t2 = _mm256_unpacklo_pd(a2, a3); /* ox2 ox3 oz2 oz3 */
			__m256d t3 = _mm256_unpackhi_pd(a2, a3); /* oy2 oy3 dx2 dx3 */
			__m256d px = _mm256_permute2f128_pd(t0, t2, 0x20), pz = _mm256_permute2f128_pd(t0, t2, 0x31);
			__m256d py = _mm256_permute2f128_pd(t1, t3, 0x20), vx = _mm256_permute2f128_pd(t1, t3, 0x31);
			__m256d c01 = _mm256_set_m128d(c1, c0), c23 = _mm256_set_m128d(c3, c2); /* dy0 dz0 dy1 dz1 */
			__m256d u0 = _mm256_unpacklo_pd(c01, c23), u1 = _mm256_unpackhi_pd(c01, c23); /* dy0 dy2 dy1 dy3 */
			__m256d vy = _mm256_permute4x64_pd(u0, 0xd8), vz = _mm256_permute4x64_pd(u1, 0xd8);
			__m256d a, bq, c, e, f, g;
			if (up) {
				a = _mm256_add_pd(_mm256_mul_pd(m00, px), m03);
				bq = _mm256_add_pd(_mm256_mul_pd(m11, py), m13);
				c = _mm256_add_pd(_mm256_mul_pd(m22, pz), m23);
				e = _mm256_mul_pd(m00, vx);
				f = _mm256_mul_pd(m11, vy);
				g = _mm256_mul_pd(m22, vz);
			} else {
				a = _mm256_add_pd(_mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(m00, px), _mm256_mul_pd(m01, py)),
								_mm256_mul_pd(m02, pz)),
						  m03);
				bq = _mm256_add_pd(_mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(m10, px), _mm256_mul_pd(m11, py)),
								 _mm256_mul_pd(m12, pz)),
						   m13);
				c = _mm256_add_pd(_mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(m20, px), _mm256_mul_pd(m21, py)),
								_mm256_mul_pd(m22, pz)),
						  m23);
				e = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(m00, vx), _mm256_mul_pd(m01, vy)),
						  _mm256_mul_pd(m02, vz));
				f = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(m10, vx), _mm256_mul_pd(m11, vy)),
						  _mm256_mul_pd(m12, vz));
				g = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(m20, vx), _mm256_mul_pd(m21, vy)),
						  _mm256_mul_pd(m22, vz));
			}
			_mm_store_ps(&s.ox[i], _mm256_cvtpd_ps(a));
			_mm_store_ps(&s.oy[i], _mm256_cvtpd_ps(bq));
			_mm_store_ps(&s.oz[i], _mm256_cvtpd_ps(c));
			_mm_store_ps(&s.dx[i], _mm256_cvtpd_ps(e));
			_mm_store_ps(&s.dy[i], _mm256_cvtpd_ps(f));
			_mm_store_ps(&s.dz[i], _mm256_cvtpd_ps(g));
			if (tmax) {
				/* best: tmax < 3e38 ? (float)tmax : inf */
				__m256d tm = _mm256_loadu_pd(&tmax[i]);
				__m128 lt = _mm256_castps256_ps128(_mm256_permutevar8x32_ps(
					_mm256_castpd_ps(_mm256_cmp_pd(tm, huge, _CMP_LT_OQ)), pick));
				_mm_storeu_ps(&s.best[i], _mm_blendv_ps(_mm_set1_ps(INFINITY), _mm256_cvtpd_ps(tm), lt));
			}
		}
	}
	for (; i < n; i++) {
		float o[3], d[3];
		world_ray_floats(M, up, &wr[i], o, d);
		s.ox[i] = o[0];
		s.oy[i] = o[1];
		s.oz[i] = o[2];
		s.dx[i] = d[0];
		s.dy[i] = d[1];
		s.dz[i] = d[2];
		if (tmax)
			s.best[i] = tmax[i] < 3e38 ? (float)tmax[i] : INFINITY;
	}
	if (tmax) {
		for (i = 0; i < n; i++) {
			s.bt[i] = next_upf(s.best[i]);
			s.bs[i] = s.bt[i] * BVH_SLAB_SLACK;
		}
	} else {
		/* one tmax for all */
		float b1 = tmax1 < 3e38 ? (float)tmax1 : INFINITY, t1 = next_upf(b1);
		const __m256 vb = _mm256_set1_ps(b1), vt = _mm256_set1_ps(t1), vs = _mm256_set1_ps(t1 * BVH_SLAB_SLACK);
		for (i = 0; i < MESH_PACKET_MAX; i += 8) {
			_mm256_store_ps(&s.best[i], vb);
			_mm256_store_ps(&s.bt[i], vt);
			_mm256_store_ps(&s.bs[i], vs);
		}
	}
	for (i = n; i < MESH_PACKET_MAX; i++) {
		s.ox[i] = s.ox[0];
		s.oy[i] = s.oy[0];
		s.oz[i] = s.oz[0];
		s.dx[i] = s.dx[0];
		s.dy[i] = s.dy[0];
		s.dz[i] = s.dz[0];
		s.bs[i] = -INFINITY; /* never enters a leaf, never raises pk_far */
		s.bt[i] = 0.0f;      /* (read by pk_leaf_rays, never used) */
	}
	/* the inverses (1 / d, correctly rounded as ray_node_setup's), the far
	 * ones inv S; the signs each axis shares; per axis the origin to
	 * subtract from the near planes (the farthest along the direction) and
	 * from the far ones (the farthest back), the inverses' and the far
	 * inverses' ranges. The bounds need finite origins and finite, non-zero
	 * inverses (a NaN fails too). Of one sign, the inverses' extremes are
	 * the largest and smallest in magnitude, so an infinite or zero one is
	 * among them; and inv S is monotonic in inv, so the far inverses' range
	 * is the extremes' times S, the same floats as the rays' own. */
	const __m256 one = _mm256_set1_ps(1.0f), slack = _mm256_set1_ps(BVH_SLAB_SLACK), big = _mm256_set1_ps(FLT_MAX);
	const __m256 mag = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
	float *oa[3] = {s.ox, s.oy, s.oz}, *da[3] = {s.dx, s.dy, s.dz}, *ia[3] = {s.ix, s.iy, s.iz},
	      *fa[3] = {s.fx, s.fy, s.fz};
	__m256 on[3], of[3], ilo[3], ihi[3], flo[3], fhi[3];
	size_t rn[3];
	__m256 bad = _mm256_setzero_ps();
	for (int a = 0; a < 3; a++) {
		__m256 olo = _mm256_load_ps(oa[a]), ohi = olo, il = _mm256_set1_ps(INFINITY), ih = _mm256_set1_ps(-INFINITY);
		unsigned negs = 0;
		for (int h = 0; h < MESH_PACKET_MAX; h += 8) {
			__m256 o = _mm256_load_ps(oa[a] + h), inv = _mm256_div_ps(one, _mm256_load_ps(da[a] + h));
			_mm256_store_ps(ia[a] + h, inv);
			_mm256_store_ps(fa[a] + h, _mm256_mul_ps(inv, slack));
			bad = _mm256_or_ps(bad, _mm256_cmp_ps(_mm256_and_ps(o, mag), big, _CMP_NLE_UQ));
			bad = _mm256_or_ps(bad, _mm256_cmp_ps(inv, inv, _CMP_UNORD_Q));
			negs |= (unsigned)_mm256_movemask_ps(inv) << h;
			olo = _mm256_min_ps(olo, o);
			ohi = _mm256_max_ps(ohi, o);
			il = _mm256_min_ps(il, inv);
			ih = _mm256_max_ps(ih, inv);
		}
		if (negs != 0 && negs != 0xffffu)
			return false;
		bool neg = negs != 0;
		float l = pk_hmin(il), hh = pk_hmax(ih), fl = l * BVH_SLAB_SLACK, fh = hh * BVH_SLAB_SLACK;
		if (!(fabsf(l) <= FLT_MAX && fabsf(hh) <= FLT_MAX && l != 0.0f && hh != 0.0f && fabsf(fl) <= FLT_MAX &&
		      fabsf(fh) <= FLT_MAX))
			return false;
		on[a] = _mm256_set1_ps(neg ? pk_hmin(olo) : pk_hmax(ohi));
		of[a] = _mm256_set1_ps(neg ? pk_hmax(ohi) : pk_hmin(olo));
		ilo[a] = _mm256_set1_ps(l);
		ihi[a] = _mm256_set1_ps(hh);
		flo[a] = _mm256_set1_ps(fl);
		fhi[a] = _mm256_set1_ps(fh);
		rn[a] = (size_t)(MESH_LO(a) + neg) * MESH_ROW;
	}
	if (_mm256_movemask_ps(bad))
		return false;
	s.ready = false;
	s.tmin0 = box_tmin;
	s.eps = m->eps;
	const size_t rn0 = rn[0], rn1 = rn[1], rn2 = rn[2];
	s.found = s.tie = 0;
	const __m256 t0_8 = _mm256_set1_ps(box_tmin);
	float far = pk_far(&s);
	pk_entry stack[MESH_STACK];
	int sp = 0;
	uint32_t ref = 0; /* the root node */
	const mesh_node *nodes = m->nodes;
	for (;;) {
		{
			const mesh_node *nd = (const mesh_node *)((const char *)nodes + ref);
			__m256 t0 = t0_8, t1 = _mm256_set1_ps(far);
			for (int a = 0; a < 3; a++) {
				size_t r0 = rn[a];
				__m256 x = _mm256_sub_ps(_mm256_load_ps((const float *)((const char *)nd->b + r0)), on[a]);
				__m256 y = _mm256_sub_ps(_mm256_load_ps((const float *)((const char *)nd->b + (r0 ^ MESH_ROW))),
							 of[a]);
				t0 = _mm256_max_ps(_mm256_min_ps(_mm256_mul_ps(x, ilo[a]), _mm256_mul_ps(x, ihi[a])), t0);
				t1 = _mm256_min_ps(_mm256_max_ps(_mm256_mul_ps(y, flo[a]), _mm256_mul_ps(y, fhi[a])), t1);
			}
			_Alignas(32) float tn[MESH_WIDTH];
			_mm256_store_ps(tn, t0);
			unsigned hm = (unsigned)_mm256_movemask_ps(_mm256_cmp_ps(t0, t1, _CMP_LE_OQ));
			/* the children, farthest first, so the nearest is on top */
			int base = sp;
			for (; hm; hm &= hm - 1) {
				uint32_t k = (uint32_t)__builtin_ctz(hm);
				pk_entry e = {nd->child[k], tn[k], ref, k};
				int j = sp++;
				while (j > base && stack[j - 1].t < e.t) {
					stack[j] = stack[j - 1];
					j--;
				}
				stack[j] = e;
			}
		}
		/* the next entry the packet may still need */
		for (;;) {
			while (sp > 0 && stack[sp - 1].t > far)
				sp--;
			if (sp == 0)
				goto done;
			pk_entry e = stack[--sp];
			if (!(e.ref & MESH_LEAF)) {
				ref = e.ref;
				break;
			}
			unsigned in = pk_rays_in(&s, (const mesh_node *)((const char *)nodes + e.parent), e.k, box_tmin, rn0,
						 rn1, rn2);
			if (in)
				pk_leaf_all(m, &s, in, e.ref);
			far = pk_far(&s);
		}
	}
done:
	for (unsigned f = s.found; f; f &= f - 1) {
		int j = __builtin_ctz(f);
		t[j] = s.best[j];
		slot[j] = s.slot[j];
		b[j][0] = s.b[j][0];
		b[j][1] = s.b[j][1];
		b[j][2] = s.b[j][2];
		if (!((double)s.best[j] < (tmax ? tmax[j] : tmax1)))
			s.found &= ~(1u << j);
	}
	*found = s.found;
	*tie = s.tie & s.found;
	return true;
}
#endif


typedef struct walker {
	bool (*hit)(const mesh *m, const mesh_ray *r, float tmin, float *tmax, uint32_t *tri, float b[3]);
	bool (*any)(const mesh *m, const mesh_ray *r, float tmin, float tmax);
	bool (*hit_world)(const mesh *m, const double (*M)[4], const ray *wr, double tmin, double tmax, double *t,
	                  uint32_t *slot, float b[3]);
	bool (*any_world)(const mesh *m, const double (*M)[4], const ray *wr, double tmin, double tmax);
	bool (*hit_world_coherent)(const mesh *m, const double (*M)[4], const ray *wr, double tmin, double tmax,
	                           double *t, uint32_t *slot, float b[3]);
} walker;

WALK_ENTRIES(scalar, walk_scalar, )
#if defined(__SSE2__)
WALK_ENTRIES(sse, walk_sse, )
#endif
#if defined(HAVE_AVX2_WALK)
WALK_ENTRIES(avx2, walk_avx2, AVX2)
WALK_ENTRIES(avx512, walk_avx512, AVX512)
WALK_COHERENT(avx2, walk_avx2, AVX2)
WALK_COHERENT(avx512, walk_avx512, AVX512)
#endif

static const walker walkers[MESH_ISA_BEST] = {
	[MESH_ISA_SCALAR] = {scalar_hit, scalar_any, scalar_hit_world, scalar_any_world, scalar_hit_world},
#if defined(__SSE2__)
	[MESH_ISA_SSE2] = {sse_hit, sse_any, sse_hit_world, sse_any_world, sse_hit_world},
#endif
#if defined(HAVE_AVX2_WALK)
	[MESH_ISA_AVX2] = {avx2_hit, avx2_any, avx2_hit_world, avx2_any_world, avx2_hit_world_coherent},
	[MESH_ISA_AVX512] = {avx512_hit, avx512_any, avx512_hit_world, avx512_any_world,
	                          avx512_hit_world_coherent},
#endif
};

/* The vector unit in use: -1 until the first walk asks the processor. */
static atomic_int isa_now = -1;

static mesh_isa isa_best(void)
{
#if defined(HAVE_AVX2_WALK)
	if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl"))
		return MESH_ISA_AVX512;
	if (__builtin_cpu_supports("avx2"))
		return MESH_ISA_AVX2;
#endif
#if defined(__SSE2__)
	return MESH_ISA_SSE2;
#else
	return MESH_ISA_SCALAR;
#endif
}

mesh_isa mesh_isa_active(void)
{
	int isa = atomic_load_explicit(&isa_now, memory_order_relaxed);
	if (isa < 0) {
		isa = (int)isa_best();
		atomic_store_explicit(&isa_now, isa, memory_order_relaxed);
	}
	return (mesh_isa)isa;
}

bool mesh_isa_force(mesh_isa isa)
{
	mesh_isa best = isa_best();
	if (isa == MESH_ISA_BEST)
		isa = best;
	if (isa > best)
		return false;
	atomic_store_explicit(&isa_now, (int)isa, memory_order_relaxed);
	return true;
}

bool mesh_intersect(const mesh *m, const mesh_ray *r, float tmin, float *tmax, uint32_t *tri, float b[3])
{
	return walkers[mesh_isa_active()].hit(m, r, tmin, tmax, tri, b);
}

bool mesh_occluded(const mesh *m, const mesh_ray *r, float tmin, float tmax)
{
	return walkers[mesh_isa_active()].any(m, r, tmin, tmax);
}

bool mesh_intersect_world(const mesh *m, const double (*inv)[4], const ray *r, double tmin, double tmax, double *t,
                          uint32_t *slot, float b[3])
{
	return walkers[mesh_isa_active()].hit_world(m, inv, r, tmin, tmax, t, slot, b);
}

bool mesh_intersect_world_coherent(const mesh *m, const double (*inv)[4], const ray *r, double tmin, double tmax,
                                   double *t, uint32_t *slot, float b[3])
{
	return walkers[mesh_isa_active()].hit_world_coherent(m, inv, r, tmin, tmax, t, slot, b);
}

bool mesh_occluded_world(const mesh *m, const double (*inv)[4], const ray *r, double tmin, double tmax)
{
	return walkers[mesh_isa_active()].any_world(m, inv, r, tmin, tmax);
}

bool mesh_intersect_scalar(const mesh *m, const mesh_ray *r, float tmin, float *tmax, uint32_t *tri, float b[3])
{
	return scalar_hit(m, r, tmin, tmax, tri, b);
}

bool mesh_occluded_scalar(const mesh *m, const mesh_ray *r, float tmin, float tmax)
{
	return scalar_any(m, r, tmin, tmax);
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

bool mesh_intersect_world_packet(const mesh *m, const double (*inv)[4], int n, const ray *r, double tmin,
                                 double tmax, const double *tmax_each, double *t, uint32_t *slot, float (*b)[3],
                                 unsigned *found, unsigned *tie)
{
#if defined(HAVE_AVX2_WALK)
	if (n >= 1 && n <= MESH_PACKET_MAX && mesh_isa_active() >= MESH_ISA_AVX2)
		return packet_walk(m, inv, n, r, tmin, tmax, tmax_each, t, slot, b, found, tie, false);
#else
	(void)m, (void)inv, (void)n, (void)r, (void)tmin, (void)tmax, (void)tmax_each, (void)t, (void)slot, (void)b,
		(void)found, (void)tie;
#endif
	return false;
}

bool mesh_occluded_world_packet(const mesh *m, const double (*inv)[4], int n, const ray *r, double tmin,
                                const double *tmax, unsigned *occ)
{
#if defined(HAVE_AVX2_WALK)
	if (n >= 1 && n <= MESH_PACKET_MAX && mesh_isa_active() >= MESH_ISA_AVX2) {
		double t[MESH_PACKET_MAX];
		uint32_t slot[MESH_PACKET_MAX];
		float b[MESH_PACKET_MAX][3];
		unsigned tie;
		/* (a tmax between 3e38 and FLT_MAX: the single ray's float bound,
		 * inf, lets it find hits it then refuses, and which it meets
		 * first decides: traced alone) */
		for (int i = 0; i < n; i++)
			if (tmax[i] >= 3e38 && tmax[i] < INFINITY)
				return false;
		return packet_walk(m, inv, n, r, tmin, 0.0, tmax, t, slot, b, occ, &tie, true);
	}
#else
	(void)m, (void)inv, (void)n, (void)r, (void)tmin, (void)tmax, (void)occ;
#endif
	return false;
}
