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

/* The edge functions of the lanes in zm (those a float made zero) again in
 * double, as wt_test does: block_sse and the packet walk's leaf. f holds
 * 9 rows of n lanes: u, v, w, ax, ay, bx, by, cx, cy; u, v and w are
 * rewritten. */
static inline __attribute__((always_inline)) void edges_in_double(unsigned zm, float *f, int n)
{
	const float *ax = f + 3 * n, *ay = f + 4 * n, *bx = f + 5 * n, *by = f + 6 * n, *cx = f + 7 * n,
		    *cy = f + 8 * n;
	for (; zm; zm &= zm - 1) {
		int l = __builtin_ctz(zm);
		f[l] = (float)((double)cx[l] * by[l] - (double)cy[l] * bx[l]);
		f[n + l] = (float)((double)ax[l] * cy[l] - (double)ay[l] * cx[l]);
		f[2 * n + l] = (float)((double)bx[l] * ay[l] - (double)by[l] * ax[l]);
	}
}

/* Where a lane's lowest or highest edge function came out zero (the lanes
 * in zm), u, v and w again by edges_in_double and lo and hi of them, for a
 * unit of N floats of type V with its STORE, LOAD, MIN and MAX: the names
 * u, v, w, ax ... cy, lo, hi and zm are the caller's (block_sse and the
 * packet walk's leaf, as wt_test). */
#define EDGES_IN_DOUBLE(N, V, STORE, LOAD, MIN, MAX)                                                                \
	do {                                                                                                        \
		_Alignas(4 * (N)) float f_[9][N];                                                                   \
		const V e_[9] = {u, v, w, ax, ay, bx, by, cx, cy};                                                   \
		for (int r_ = 0; r_ < 9; r_++)                                                                      \
			STORE(f_[r_], e_[r_]);                                                                      \
		edges_in_double(zm, f_[0], N);                                                                      \
		u = LOAD(f_[0]), v = LOAD(f_[1]), w = LOAD(f_[2]);                                                  \
		lo = MIN(MIN(u, v), w);                                                                             \
		hi = MAX(MAX(u, v), w);                                                                             \
	} while (0)

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
		EDGES_IN_DOUBLE(4, __m128, _mm_store_ps, _mm_load_ps, _mm_min_ps, _mm_max_ps);
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

#define PK(name) pk_avx2_##name
#define PK_TARGET AVX2
#include "mesh_packet_walk.h"
#define PK(name) pk_avx512_##name
#define PK_TARGET AVX512
#include "mesh_packet_walk.h"
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
	mesh_isa isa = mesh_isa_active();
	if (n >= 1 && n <= MESH_PACKET_MAX && isa >= MESH_ISA_AVX2)
		return (isa == MESH_ISA_AVX512 ? pk_avx512_walk : pk_avx2_walk)(m, inv, n, r, tmin, tmax, tmax_each, t, slot,
		                                                                 b, found, tie, false);
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
	mesh_isa isa = mesh_isa_active();
	if (n >= 1 && n <= MESH_PACKET_MAX && isa >= MESH_ISA_AVX2) {
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
		return (isa == MESH_ISA_AVX512 ? pk_avx512_walk : pk_avx2_walk)(m, inv, n, r, tmin, 0.0, tmax, t, slot, b,
		                                                                 occ, &tie, true);
	}
#else
	(void)m, (void)inv, (void)n, (void)r, (void)tmin, (void)tmax, (void)occ;
#endif
	return false;
}
