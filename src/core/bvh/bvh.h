/* rtsh — the bounding volume hierarchy over a world's bounded primitives.
 *
 * A 4-wide tree: each node holds the boxes of its (up to) four children,
 * stored as floats rounded outward, so that one 128-byte node (two cache
 * lines) gives the four slab tests, done together in one SSE register each
 * (world.c). A float box contains the exact double-precision bounds of what
 * is below it: the tree can only visit too much, never miss. It is built as
 * a binary SAH tree and then collapsed, each node adopting the children of
 * its largest inner children until it has four (Wald, Benthin & Boulos,
 * "Getting rid of packets", 2008; Dammertz et al., "Shallow bounding volume
 * hierarchies for fast SIMD ray tracing of incoherent rays", 2008).
 * Leaves are not nodes: a child reference with BVH_LEAF in `meta` names a
 * run of primitives. An unused slot has an empty box (lo = +inf,
 * hi = -inf), which no ray enters. Nodes are in depth-first order, node 0
 * the root.
 */
#ifndef RTSH_BVH_H
#define RTSH_BVH_H

#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "rtsh/error.h"
#include "rtsh/math.h"

/* The 4-wide tree (world.h names it; world.c walks it). */
typedef struct bvh bvh;

/* Deepest binary tree the builder makes; the 4-wide tree is no deeper, and
 * a walk holds at most 3 entries per level on its stack. */
#define BVH_MAX_DEPTH 96
#define BVH_STACK (3 * BVH_MAX_DEPTH + 4)
/* meta[k]: BVH_LEAF | count for a leaf child, 0 for an inner node. */
#define BVH_LEAF 0x80000000u
#define BVH_MAX_PRIMS (BVH_LEAF - 1)
#define BVH_WIDTH 4

/* Child boxes: b[BVH_LO_X + axis][k] is the low bound of child k on axis,
 * b[BVH_HI_X + axis][k] its high bound. */
enum { BVH_LO_X = 0, BVH_HI_X = 3 };

typedef struct bvh_node {
	_Alignas(16) float b[6][BVH_WIDTH]; /* lo x, lo y, lo z, hi x, hi y, hi z */
	uint32_t child[BVH_WIDTH];          /* inner: node index; leaf: first primitive */
	uint32_t meta[BVH_WIDTH];           /* inner: 0; leaf: BVH_LEAF | primitive count */
} bvh_node;

/* The slab test's state for one ray: the origin rounded for the near and
 * far planes and the inverse direction, per axis, and the rows of
 * bvh_node.b that hold each axis's near and far planes. Each walker fills
 * it its own way; bvh_slab4 reads it. */
typedef struct bvh_ray {
#if defined(__SSE2__)
	__m128 on[3], of[3], inv[3];
#else
	float on[3], of[3], inv[3];
#endif
	int near[3], far[3];
} bvh_ray;

/* What the slab tests need of a ray, computed once per ray. The tests run in
 * single precision on the nodes' float boxes (see world.h for why) and must
 * never miss a box the exact ray enters:
 *   - each axis reads its near and far planes from the rows of bvh_node.b
 *     chosen by the direction's sign, so no min/max per axis is needed
 *     (Williams et al., "An efficient and robust ray-box intersection
 *     algorithm", 2005);
 *   - the origin is rounded to float in the direction that can only move
 *     the near plane's distance down and the far plane's up;
 *   - the far distance is then scaled by 1 + 2 gamma(3) for the rounding of
 *     the subtraction, the product and the inverse (Ize, "Robust BVH ray
 *     traversal", JCGT 2013), and so is tmax where the walk prunes;
 *   - 0 x inf = NaN (a ray in the plane of a slab) is dropped by the order
 *     of the min/max operands, which keeps the box.
 * On x86-64 the four children are tested at once in SSE registers; the
 * scalar loop is the same test for other machines (GCC 12 vectorises it,
 * but the explicit version measured faster). */

static inline void bvh_ray_prepare(const ray *r, bvh_ray *q)
{
#if defined(__SSE2__)
	/* the three axes at once, without a branch (ray directions are random
	 * in path mode, and a branch on each sign would be guessed wrong half
	 * the time): [x, y, z, 1] */
	const __m128d one = _mm_set1_pd(1.0);
	__m128 inv = _mm_movelh_ps(_mm_cvtpd_ps(_mm_div_pd(one, _mm_loadu_pd(&r->d.x))),
	                           _mm_cvtpd_ps(_mm_div_sd(one, _mm_load_sd(&r->d.z))));
	__m128 f = _mm_movelh_ps(_mm_cvtpd_ps(_mm_loadu_pd(&r->o.x)), _mm_cvtpd_ps(_mm_load_sd(&r->o.z)));
	/* the rounded origin is within half a step of o: one step |f| 2^-23
	 * (and the smallest subnormal) each way brackets o (overflow to +-inf
	 * only widens the box); the near plane's origin is the one that can
	 * only bring its distance down: f + e along +d, f - e along -d */
	const __m128 sign = _mm_set1_ps(-0.0f);
	__m128 e = _mm_add_ps(_mm_mul_ps(_mm_andnot_ps(sign, f), _mm_set1_ps(0x1p-23f)), _mm_set1_ps(0x1p-149f));
	__m128 es = _mm_xor_ps(e, _mm_and_ps(inv, sign));
	__m128 on = _mm_add_ps(f, es), of = _mm_sub_ps(f, es);
	q->on[0] = _mm_shuffle_ps(on, on, 0x00);
	q->on[1] = _mm_shuffle_ps(on, on, 0x55);
	q->on[2] = _mm_shuffle_ps(on, on, 0xaa);
	q->of[0] = _mm_shuffle_ps(of, of, 0x00);
	q->of[1] = _mm_shuffle_ps(of, of, 0x55);
	q->of[2] = _mm_shuffle_ps(of, of, 0xaa);
	q->inv[0] = _mm_shuffle_ps(inv, inv, 0x00);
	q->inv[1] = _mm_shuffle_ps(inv, inv, 0x55);
	q->inv[2] = _mm_shuffle_ps(inv, inv, 0xaa);
	unsigned neg = (unsigned)_mm_movemask_ps(inv);
	for (int a = 0; a < 3; a++) {
		int n = (int)(neg >> a & 1u);
		q->near[a] = a + 3 * n;
		q->far[a] = a + 3 - 3 * n;
	}
#else
	double o[3] = {r->o.x, r->o.y, r->o.z}, d[3] = {r->d.x, r->d.y, r->d.z};
	for (int a = 0; a < 3; a++) {
		float inv = (float)(1.0 / d[a]);
		bool neg = signbit(inv);
		q->near[a] = (neg ? BVH_HI_X : BVH_LO_X) + a;
		q->far[a] = (neg ? BVH_LO_X : BVH_HI_X) + a;
		float f = (float)o[a], e = fabsf(f) * 0x1p-23f + 0x1p-149f;
		float up = f + e, down = f - e;
		q->on[a] = neg ? down : up;
		q->of[a] = neg ? up : down;
		q->inv[a] = inv;
	}
#endif
}

/* Widens tmax by the rounding of three float operations, so a box the ray
 * grazes is never missed. */
#define BVH_SLAB_SLACK (1.0f + 2.0f * (3.0f * 0x1p-24f) / (1.0f - 3.0f * 0x1p-24f))

/* Slab tests of the four children of n against [tmin, tmax]: bit k of the
 * result is set when child k may be hit, and tn[k] is (about) where the ray
 * enters it. */
static inline unsigned bvh_slab4(const bvh_node *n, const bvh_ray *q, float tmin, float tmax, float tn[4])
{
#if defined(__SSE2__)
	__m128 t0 = _mm_set1_ps(tmin), t1 = _mm_set1_ps(tmax);
	for (int a = 0; a < 3; a++) {
		__m128 nb = _mm_load_ps(n->b[q->near[a]]), fb = _mm_load_ps(n->b[q->far[a]]);
		/* max(x, acc) and min(x, acc) return acc when x is NaN */
		t0 = _mm_max_ps(_mm_mul_ps(_mm_sub_ps(nb, q->on[a]), q->inv[a]), t0);
		t1 = _mm_min_ps(_mm_mul_ps(_mm_sub_ps(fb, q->of[a]), q->inv[a]), t1);
	}
	_mm_storeu_ps(tn, t0);
	return (unsigned)_mm_movemask_ps(_mm_cmple_ps(t0, _mm_mul_ps(t1, _mm_set1_ps(BVH_SLAB_SLACK))));
#else
	unsigned m = 0;
	for (int k = 0; k < BVH_WIDTH; k++) {
		float t0 = tmin, t1 = tmax;
		for (int a = 0; a < 3; a++) {
			float tnear = (n->b[q->near[a]][k] - q->on[a]) * q->inv[a];
			float tfar = (n->b[q->far[a]][k] - q->of[a]) * q->inv[a];
			t0 = tnear > t0 ? tnear : t0;
			t1 = tfar < t1 ? tfar : t1;
		}
		tn[k] = t0;
		m |= (unsigned)(t0 <= t1 * BVH_SLAB_SLACK) << k;
	}
	return m;
#endif
}

/* An entry of a walk's stack (world.c's single rays, packet.c's packets): a
 * node or a leaf, as in bvh_node, and where the ray or packet enters its
 * box. */
typedef struct bvh_entry {
	uint32_t child, meta;
	float t;
	uint32_t pad;
} bvh_entry;

/* A nearest-hit walk's step into the children of n that mask m (not 0)
 * says are hit: the nearest is entered now (*child, *meta), the others
 * pushed farthest first, so that the next nearest is on top (an insertion
 * sort of at most BVH_WIDTH; of two at the same distance, the lower index
 * comes first); returns the new stack height. */
static inline int bvh_enter_sorted(const bvh_node *n, unsigned m, const float tn[BVH_WIDTH], bvh_entry *stack,
                                   int sp, uint32_t *child, uint32_t *meta)
{
	int idx[BVH_WIDTH], c = 0;
	for (unsigned b = m; b; b &= b - 1) {
		int k = __builtin_ctz(b), j = c++;
		while (j > 0 && tn[idx[j - 1]] < tn[k]) {
			idx[j] = idx[j - 1];
			j--;
		}
		idx[j] = k;
	}
	for (int i = 0; i < c - 1; i++)
		stack[sp++] = (bvh_entry){n->child[idx[i]], n->meta[idx[i]], tn[idx[i]], 0};
	*child = n->child[idx[c - 1]];
	*meta = n->meta[idx[c - 1]];
	return sp;
}

/* An any-hit walk's step into the children of n that mask m (not 0) says
 * are hit, in index order: the first is entered now (*child, *meta), the
 * others pushed; returns the new stack height. */
static inline int bvh_enter_any(const bvh_node *n, unsigned m, const float tn[BVH_WIDTH], bvh_entry *stack, int sp,
                                uint32_t *child, uint32_t *meta)
{
	int k = __builtin_ctz(m);
	for (unsigned rest = m & (m - 1); rest; rest &= rest - 1) {
		int j = __builtin_ctz(rest);
		stack[sp++] = (bvh_entry){n->child[j], n->meta[j], tn[j], 0};
	}
	*child = n->child[k];
	*meta = n->meta[k];
	return sp;
}

struct bvh {
	bvh_node *nodes;    /* 64-byte aligned; none when there are no primitives */
	size_t nnodes;
	uint32_t root;      /* the root as a child reference: node 0 (a lone */
	uint32_t root_meta; /* leaf gets a node too), or an empty leaf */
	int depth;          /* of the binary tree */
	size_t leaves;
};

/* --- the binary tree the builder makes, before it is made wide --- */

/* A box of floats. Lane 3 is not part of the box: the builder keeps a
 * reference's cost in lo[3] (hi[3] = 0), which min/max carry along. */
typedef struct bvh_fbox {
	float lo[4], hi[4];
} bvh_fbox;

/* A binary node: two children, each an inner node (meta 0, child its
 * index) or a leaf (meta BVH_LEAF | count, child the first of its
 * references in bvh2.ids). */
typedef struct bvh2_node {
	bvh_fbox box[2];
	uint32_t child[2], meta[2];
} bvh2_node;

typedef struct bvh2 {
	bvh2_node *nodes;
	size_t nnodes;
	uint32_t root, root_meta; /* as a child reference */
	bvh_fbox bounds;          /* of everything */
	uint32_t *ids;            /* the primitive of each reference */
	size_t nids;              /* ids' length (spatial splits leave gaps) */
	size_t nrefs;             /* references in leaves: n, more after spatial splits */
	int depth;
	size_t leaves;
} bvh2;

/* How to build. Spatial splits (Stich, Friedrich & Dietrich, "Spatial
 * splits in bounding volume hierarchies", 2009) let one primitive be
 * referenced by several leaves, each with the part of it inside the leaf's
 * box: `chop` cuts primitive id by the planes pos[0..n] across an axis;
 * on entry box[0..n) each hold the reference's box, on return box[i] holds
 * the part of it between pos[i] and pos[i + 1] (lane 3 kept), or an empty
 * box (lo > hi) where there is none. */
typedef struct bvh_build_opts {
	const float *costs; /* per primitive, relative to a sphere; NULL: all 1 */
	unsigned block;     /* > 1: unit-cost primitives tested `block` at a time */
	double trav;        /* SAH cost of a node visit */
	unsigned leaf_max;  /* the largest leaf made while a split pays */
	void (*chop)(const void *ctx, uint32_t id, int axis, const float *pos, int n, bvh_fbox *box);
	const void *ctx;
	double split_budget; /* references allowed beyond n, a fraction of n */
	const atomic_bool *cancel; /* when set, the build stops (NULL: never) */
	int threads;        /* > 1: up to that many threads (bvh_build; not with chop) */
} bvh_build_opts;

/* Builds the binary tree over n primitives of world bounds bounds[0..n)
 * (binned SAH, and spatial splits when o->chop is set). False (err set)
 * when out of memory or n is too large, or "stopped" when o->cancel was
 * set during the build. */
bool bvh2_build(const box *bounds, size_t n, const bvh_build_opts *o, bvh2 *t, rt_error *err);
void bvh2_free(bvh2 *t);

/* A child of a wide node: a box and a child reference of the binary tree. */
typedef struct bvh_slot {
	bvh_fbox box;
	uint32_t child, meta;
} bvh_slot;

/* The up to `width` children of the wide node made for binary node `n`:
 * its two, then the inner child of largest area replaced by its own two,
 * until there are `width` or none is inner (Wald, Benthin & Boulos 2008).
 * Returns how many. */
int bvh2_gather(const bvh2 *t, uint32_t n, int width, bvh_slot *out);

/* Half the surface area of a float box, in double; 0 when empty. */
double bvh_fbox_half_area(const bvh_fbox *b);

/* A reference for bvh_build: primitive box x rounded outward to floats,
 * and its intersection cost relative to a world-space sphere. */
void bvh_ref_set(bvh_fbox *r, const box *x, float cost);

/* Builds the tree over the n primitives of references refs[0, n) (made by
 * bvh_ref_set; reordered by the build, the caller's to free): binned SAH
 * (Wald, "On fast construction of SAH-based bounding volume hierarchies",
 * 2007). order[i] receives the primitive that goes to place i of tree
 * order (leaves index primitives in that order). threads > 1: the two
 * subtrees below a node built at once when each has 4096 references or
 * more (the same tree, to the byte, for any count). NULL (err set) when
 * out of memory or n is too large. */
bvh *bvh_build(bvh_fbox *refs, size_t n, uint32_t *order, int threads, const atomic_bool *cancel, rt_error *err);
void bvh_free(bvh *t);

#endif
