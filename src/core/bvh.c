/* rtsh — binned SAH BVH construction (bvh.h).
 *
 * The builder works on 32-byte references (a float box rounded outward) and
 * a parallel array of primitive indices, rather than on the primitives, so
 * that partitioning moves little memory; the caller reorders its primitives
 * once at the end from `order`. Each node bins the centroids of its
 * references on all three axes in one pass (Wald, "On fast construction of
 * SAH-based bounding volume hierarchies", 2007; 16 bins per axis, fewer for
 * small nodes), sweeps the bins for the split of least surface area
 * heuristic cost (Goldsmith & Salmon 1987; MacDonald & Booth 1990), and
 * partitions in place, gathering the children's centroid bounds on the way,
 * so every level costs two passes over its references. The boxes are kept
 * as four floats (the fourth unused) so that a box union is one SSE min and
 * one max; a scalar version of each helper serves other machines. The binary
 * tree is then collapsed into 4-wide nodes (collapse, bvh.h).
 */
#include "bvh.h"

#include <stdlib.h>
#include <string.h>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#define BINS 16
#define LEAF_MAX 8
/* Past this depth nodes are halved by count, which bounds the depth by
 * BALANCED_DEPTH + log2(n) < BVH_MAX_DEPTH. */
#define BALANCED_DEPTH 60
/* SAH cost of a node visit, in units of a world-space sphere test (each
 * primitive brings its own cost, bvh_build); measured: 4 gave the fastest
 * renders of 100k and 1M spheres (1 built twice as many nodes). */
#define COST_TRAVERSE 4.0

/* A box of floats. Lane 3 is not part of the box: a reference keeps its
 * primitive's intersection cost in lo[3] (hi[3] = 0), which the centroid
 * lane ignores; bins and node boxes carry whatever min/max made of it. */
typedef struct fbox {
	float lo[4], hi[4];
} fbox;

/* A node of the binary tree, before the collapse to 4-wide nodes. */
typedef struct node2 {
	fbox box[2];
	uint32_t child[2], meta[2];
} node2;

typedef struct builder {
	fbox *refs;    /* the primitives' boxes, rounded outward */
	uint32_t *ids; /* the primitive of each reference */
	node2 *nodes;
	size_t used, cap;
	int depth;
	size_t leaves;
	double trav;    /* SAH cost of a node visit */
	unsigned block; /* primitives tested together (bvh_build_blocks), 1 */
} builder;

/* The SAH cost of testing primitives of summed cost `sum` in a leaf: the
 * sum, or in blocks of b->block (unit costs) the number of blocks. */
static inline double leaf_cost(const builder *b, double sum)
{
	return b->block > 1 ? ceil(sum / b->block) : sum;
}

static fbox fbox_empty(void)
{
	return (fbox){{INFINITY, INFINITY, INFINITY, 0}, {-INFINITY, -INFINITY, -INFINITY, 0}};
}

#if defined(__SSE2__)
/* a = a u b */
static inline void fbox_union(fbox *a, const fbox *b)
{
	_mm_storeu_ps(a->lo, _mm_min_ps(_mm_loadu_ps(a->lo), _mm_loadu_ps(b->lo)));
	_mm_storeu_ps(a->hi, _mm_max_ps(_mm_loadu_ps(a->hi), _mm_loadu_ps(b->hi)));
}

/* c = lo + hi: twice the centroid (the bins only need a consistent scale) */
static inline void centroid2(const fbox *r, float c[4])
{
	_mm_storeu_ps(c, _mm_add_ps(_mm_loadu_ps(r->lo), _mm_loadu_ps(r->hi)));
}

/* a = a u {p} */
static inline void fbox_add_point(fbox *a, const float p[4])
{
	__m128 v = _mm_loadu_ps(p);
	_mm_storeu_ps(a->lo, _mm_min_ps(_mm_loadu_ps(a->lo), v));
	_mm_storeu_ps(a->hi, _mm_max_ps(_mm_loadu_ps(a->hi), v));
}
#else
static inline float fmn(float a, float b) { return a < b ? a : b; }
static inline float fmx(float a, float b) { return a > b ? a : b; }

static inline void fbox_union(fbox *a, const fbox *b)
{
	for (int i = 0; i < 4; i++) {
		a->lo[i] = fmn(a->lo[i], b->lo[i]);
		a->hi[i] = fmx(a->hi[i], b->hi[i]);
	}
}

static inline void centroid2(const fbox *r, float c[4])
{
	for (int i = 0; i < 4; i++)
		c[i] = r->lo[i] + r->hi[i];
}

static inline void fbox_add_point(fbox *a, const float p[4])
{
	for (int i = 0; i < 4; i++) {
		a->lo[i] = fmn(a->lo[i], p[i]);
		a->hi[i] = fmx(a->hi[i], p[i]);
	}
}
#endif

/* Half the surface area, in double (no overflow); 0 when empty. */
static inline double fbox_half_area(const fbox *b)
{
	double e[3];
	for (int i = 0; i < 3; i++) {
		e[i] = (double)b->hi[i] - (double)b->lo[i];
		if (!(e[i] >= 0.0))
			return 0.0;
	}
	return e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
}

/* The nearest floats below and above a double. */
static float float_down(double v)
{
	float f = (float)v;
	return (double)f > v ? nextafterf(f, -INFINITY) : f;
}

static float float_up(double v)
{
	float f = (float)v;
	return (double)f < v ? nextafterf(f, INFINITY) : f;
}

/* Fewer bins for small nodes: most nodes are small, and 16 bins on three
 * axes would cost more to set up and sweep than the binning itself. */
static int bins_for(size_t n)
{
	return n >= BINS ? BINS : n < 4 ? 4 : (int)n;
}

/* The bin of each lane of a (doubled) centroid: (c - lo) * scale, clamped to
 * [0, nbins - 1]; NaN (an infinite box) goes to bin 0. */
static inline void bin_index(const float c[4], const float lo[4], const float scale[4], int nbins, int k[4])
{
#if defined(__SSE2__)
	__m128 v = _mm_mul_ps(_mm_sub_ps(_mm_loadu_ps(c), _mm_loadu_ps(lo)), _mm_loadu_ps(scale));
	/* max(v, 0) is 0 when v is NaN */
	v = _mm_min_ps(_mm_max_ps(v, _mm_setzero_ps()), _mm_set1_ps((float)(nbins - 1)));
	_mm_storeu_si128((__m128i *)k, _mm_cvttps_epi32(v));
#else
	for (int i = 0; i < 4; i++) {
		float v = (c[i] - lo[i]) * scale[i];
		k[i] = !(v > 0.0f) ? 0 : v >= (float)(nbins - 1) ? nbins - 1 : (int)v;
	}
#endif
}

typedef struct split {
	int axis, at; /* bins [0, at) go left */
	double cost;  /* SAH: area-weighted costs, not yet divided by the parent's area */
	double total; /* the cost of testing every primitive of the node */
	fbox lb, rb;  /* the children's boxes */
} split;

/* The binning of one node: the lower corner and scale of the centroid
 * bounds per axis (scale 0 on an axis where all centroids are equal). */
typedef struct binning {
	float lo[4], scale[4];
	int nbins;
	bool usable[3];
} binning;

static bool binning_make(const fbox *cb, size_t n, binning *bn)
{
	bn->nbins = bins_for(n);
	bool any = false;
	for (int a = 0; a < 3; a++) {
		float e = cb->hi[a] - cb->lo[a];
		bn->lo[a] = cb->lo[a];
		bn->usable[a] = e > 0.0f && e < INFINITY;
		bn->scale[a] = bn->usable[a] ? (float)bn->nbins / e : 0.0f;
		any |= bn->usable[a];
	}
	bn->lo[3] = 0.0f;
	bn->scale[3] = 0.0f;
	return any;
}

/* The cheapest binned split of refs[begin, end) with centroid bounds cb;
 * axis -1 when every centroid is the same point. */
static split find_split(const builder *b, size_t begin, size_t end, const fbox *cb)
{
	split best = {.axis = -1, .cost = INFINITY};
	binning bn;
	if (!binning_make(cb, end - begin, &bn))
		return best;
	int nbins = bn.nbins;
	/* per bin: the box and the summed cost (every cost is >= 1, so a
	 * bin is empty when its cost is 0; float sums are exact to 2^24) */
	fbox bbox[3][BINS];
	float bcost[3][BINS];
	for (int a = 0; a < 3; a++)
		for (int k = 0; k < nbins; k++) {
			bbox[a][k] = fbox_empty();
			bcost[a][k] = 0.0f;
		}
	for (size_t i = begin; i < end; i++) {
		const fbox *r = &b->refs[i];
		float c[4];
		int k[4];
		centroid2(r, c);
		bin_index(c, bn.lo, bn.scale, nbins, k);
		for (int a = 0; a < 3; a++) {
			bcost[a][k[a]] += r->lo[3];
			fbox_union(&bbox[a][k[a]], r);
		}
	}
	best.total = 0.0;
	for (int k = 0; k < nbins; k++)
		best.total += bcost[0][k];
	best.total = leaf_cost(b, best.total);
	for (int a = 0; a < 3; a++) {
		if (!bn.usable[a])
			continue;
		/* right-to-left sweep: the area and cost right of each split */
		double right_area[BINS], right_cost[BINS];
		fbox acc = fbox_empty();
		double sum = 0.0;
		for (int k = nbins - 1; k > 0; k--) {
			fbox_union(&acc, &bbox[a][k]);
			sum += bcost[a][k];
			right_area[k] = sum > 0.0 ? fbox_half_area(&acc) : 0.0;
			right_cost[k] = sum;
		}
		acc = fbox_empty();
		sum = 0.0;
		for (int k = 0; k < nbins - 1; k++) {
			fbox_union(&acc, &bbox[a][k]);
			sum += bcost[a][k];
			if (sum == 0.0 || right_cost[k + 1] == 0.0)
				continue;
			double cost = fbox_half_area(&acc) * leaf_cost(b, sum) +
			              right_area[k + 1] * leaf_cost(b, right_cost[k + 1]);
			if (cost < best.cost) {
				best.cost = cost;
				best.axis = a;
				best.at = k + 1;
			}
		}
	}
	if (best.axis >= 0) {
		best.lb = best.rb = fbox_empty();
		for (int k = 0; k < nbins; k++)
			fbox_union(k < best.at ? &best.lb : &best.rb, &bbox[best.axis][k]);
	}
	return best;
}

static inline void swap_refs(builder *b, size_t i, size_t j)
{
	fbox t = b->refs[i];
	b->refs[i] = b->refs[j];
	b->refs[j] = t;
	uint32_t id = b->ids[i];
	b->ids[i] = b->ids[j];
	b->ids[j] = id;
}

/* Partitions by the split, returning the middle; *lcb, *rcb: the children's
 * centroid bounds. The bins are computed exactly as find_split did. */
static size_t partition(builder *b, size_t begin, size_t end, const fbox *cb, const split *s, fbox *lcb,
                        fbox *rcb)
{
	binning bn;
	binning_make(cb, end - begin, &bn);
	int a = s->axis;
	*lcb = *rcb = fbox_empty();
	size_t i = begin, j = end;
	while (i < j) {
		float c[4];
		int k[4];
		centroid2(&b->refs[i], c);
		bin_index(c, bn.lo, bn.scale, bn.nbins, k);
		if (k[a] < s->at) {
			fbox_add_point(lcb, c);
			i++;
		} else {
			fbox_add_point(rcb, c);
			swap_refs(b, i, --j);
		}
	}
	return i;
}

/* The box and centroid bounds of refs[begin, end). */
static void bounds_of(const builder *b, size_t begin, size_t end, fbox *bb, fbox *cb)
{
	*bb = *cb = fbox_empty();
	for (size_t i = begin; i < end; i++) {
		float c[4];
		centroid2(&b->refs[i], c);
		fbox_union(bb, &b->refs[i]);
		fbox_add_point(cb, c);
	}
}

/* Builds the subtree over refs[begin, end) (box bb, centroid bounds cb) and
 * returns its reference in *child, *meta. */
static void build(builder *b, size_t begin, size_t end, const fbox *bb, const fbox *cb, int depth,
                  uint32_t *child, uint32_t *meta)
{
	size_t n = end - begin;
	if (depth > b->depth)
		b->depth = depth;
	bool leaf = n <= 1 || (depth >= BALANCED_DEPTH && n <= LEAF_MAX);
	if (!leaf && n <= LEAF_MAX) {
		/* A split costs at least a node visit: a node that costs no more
		 * to test whole is a leaf without binning (most small nodes). */
		double total = 0.0;
		for (size_t i = begin; i < end; i++)
			total += b->refs[i].lo[3];
		leaf = leaf_cost(b, total) <= b->trav;
	}
	split s = {.axis = -1};
	if (!leaf && depth < BALANCED_DEPTH)
		s = find_split(b, begin, end, cb);
	if (!leaf && n <= LEAF_MAX && depth < BALANCED_DEPTH) {
		double area = fbox_half_area(bb);
		double split_cost = area > 0.0 && s.axis >= 0 ? b->trav + s.cost / area : INFINITY;
		leaf = s.total <= split_cost;
	}
	if (leaf) {
		*child = (uint32_t)begin;
		*meta = BVH_LEAF | (uint32_t)n;
		b->leaves++;
		return;
	}

	size_t mid = begin;
	fbox lb, rb, lcb, rcb;
	if (s.axis >= 0) {
		mid = partition(b, begin, end, cb, &s, &lcb, &rcb);
		lb = s.lb;
		rb = s.rb;
	}
	if (mid == begin || mid == end) {
		/* no useful split (equal centroids, or past BALANCED_DEPTH): halve */
		mid = begin + n / 2;
		bounds_of(b, begin, mid, &lb, &lcb);
		bounds_of(b, mid, end, &rb, &rcb);
	}
	size_t ni = b->used++;
	node2 *node = &b->nodes[ni];
	node->box[0] = lb;
	node->box[1] = rb;
	uint32_t c0, m0, c1, m1;
	build(b, begin, mid, &lb, &lcb, depth + 1, &c0, &m0);
	build(b, mid, end, &rb, &rcb, depth + 1, &c1, &m1);
	node = &b->nodes[ni];
	node->child[0] = c0;
	node->meta[0] = m0;
	node->child[1] = c1;
	node->meta[1] = m1;
	*child = (uint32_t)ni;
	*meta = 0;
}

/* A child of a 4-wide node being collected from the binary tree. */
typedef struct slot {
	fbox box;
	uint32_t child, meta;
} slot;

/* Makes the 4-wide node for binary node n2 (and, depth first, the nodes
 * below it) in out[*used ...]; returns its index. */
static uint32_t collapse(const builder *b, uint32_t n2, bvh_node *out, size_t *used)
{
	const node2 *src = &b->nodes[n2];
	slot s[BVH_WIDTH] = {{src->box[0], src->child[0], src->meta[0]}, {src->box[1], src->child[1], src->meta[1]}};
	int cnt = 2;
	while (cnt < BVH_WIDTH) {
		/* open the inner child of largest area (the likeliest to be hit) */
		int best = -1;
		double best_area = -1.0;
		for (int i = 0; i < cnt; i++)
			if (s[i].meta == 0 && fbox_half_area(&s[i].box) > best_area) {
				best_area = fbox_half_area(&s[i].box);
				best = i;
			}
		if (best < 0)
			break;
		const node2 *c = &b->nodes[s[best].child];
		s[best] = (slot){c->box[0], c->child[0], c->meta[0]};
		s[cnt++] = (slot){c->box[1], c->child[1], c->meta[1]};
	}
	uint32_t ni = (uint32_t)(*used)++;
	for (int k = 0; k < BVH_WIDTH; k++) {
		fbox fb = k < cnt ? s[k].box : fbox_empty();
		for (int a = 0; a < 3; a++) {
			out[ni].b[BVH_LO_X + a][k] = fb.lo[a];
			out[ni].b[BVH_HI_X + a][k] = fb.hi[a];
		}
		if (k >= cnt) {
			out[ni].child[k] = 0;
			out[ni].meta[k] = BVH_LEAF; /* empty: its empty box is never entered */
		} else {
			out[ni].meta[k] = s[k].meta;
			out[ni].child[k] = s[k].meta ? s[k].child : collapse(b, s[k].child, out, used);
		}
	}
	return ni;
}

static bvh *build_tree(const box *bounds, const float *costs, size_t n, unsigned block, double trav,
                       uint32_t *order, rt_error *err)
{
	bvh *t = calloc(1, sizeof *t);
	if (!t) {
		rt_error_set(err, "out of memory building the BVH");
		return NULL;
	}
	t->root_meta = BVH_LEAF; /* an empty leaf */
	if (n == 0)
		return t;
	if (n > BVH_MAX_PRIMS) {
		free(t);
		rt_error_set(err, "too many objects (%zu); expected at most %u", n, BVH_MAX_PRIMS);
		return NULL;
	}
	builder b = {.trav = trav, .block = block};
	b.refs = malloc(n * sizeof *b.refs);
	b.ids = order; /* partitioned along with the references */
	b.cap = n > 1 ? n - 1 : 1; /* a binary tree with leaves folded in: < n inner nodes */
	b.nodes = malloc(b.cap * sizeof *b.nodes);
	if (!b.refs || !b.nodes) {
		free(b.refs);
		free(b.nodes);
		free(t);
		rt_error_set(err, "out of memory building the BVH (%zu objects)", n);
		return NULL;
	}
	fbox bb = fbox_empty(), cb = fbox_empty();
	for (size_t i = 0; i < n; i++) {
		fbox *r = &b.refs[i];
		const box *x = &bounds[i];
		*r = (fbox){{float_down(x->lo.x), float_down(x->lo.y), float_down(x->lo.z), costs ? costs[i] : 1.0f},
		            {float_up(x->hi.x), float_up(x->hi.y), float_up(x->hi.z), 0}};
		b.ids[i] = (uint32_t)i;
		float c[4];
		centroid2(r, c);
		fbox_union(&bb, r);
		fbox_add_point(&cb, c);
	}
	uint32_t root2, meta2;
	build(&b, 0, n, &bb, &cb, 0, &root2, &meta2);
	free(b.refs);
	t->depth = b.depth;
	t->leaves = b.leaves;
	if (meta2) {
		/* one leaf: a root node holding it alone, so that a ray that
		 * misses the box of everything stops at one slab test */
		free(b.nodes);
		bvh_node *one = aligned_alloc(64, (sizeof *one + 63) / 64 * 64);
		if (!one) {
			free(t);
			rt_error_set(err, "out of memory building the BVH (%zu objects)", n);
			return NULL;
		}
		for (int k = 0; k < BVH_WIDTH; k++) {
			fbox fb = k == 0 ? bb : fbox_empty();
			for (int a = 0; a < 3; a++) {
				one->b[BVH_LO_X + a][k] = fb.lo[a];
				one->b[BVH_HI_X + a][k] = fb.hi[a];
			}
			one->child[k] = k == 0 ? root2 : 0;
			one->meta[k] = k == 0 ? meta2 : BVH_LEAF;
		}
		t->nodes = one;
		t->nnodes = 1;
		t->root = 0;
		t->root_meta = 0;
		return t;
	}
	/* each 4-wide node takes at least one binary node */
	size_t bytes = (b.used * sizeof(bvh_node) + 63) / 64 * 64;
	bvh_node *wide = aligned_alloc(64, bytes);
	if (!wide) {
		free(b.nodes);
		free(t);
		rt_error_set(err, "out of memory building the BVH (%zu objects)", n);
		return NULL;
	}
	size_t used = 0;
	t->root = collapse(&b, root2, wide, &used);
	t->root_meta = 0;
	free(b.nodes);
	bytes = (used * sizeof(bvh_node) + 63) / 64 * 64;
	bvh_node *fit = aligned_alloc(64, bytes);
	if (fit) {
		memcpy(fit, wide, used * sizeof *fit);
		free(wide);
		wide = fit;
	}
	t->nodes = wide;
	t->nnodes = used;
	return t;
}

bvh *bvh_build(const box *bounds, const float *costs, size_t n, uint32_t *order, rt_error *err)
{
	return build_tree(bounds, costs, n, 1, COST_TRAVERSE, order, err);
}

bvh *bvh_build_blocks(const box *bounds, size_t n, unsigned block, double trav, uint32_t *order, rt_error *err)
{
	return build_tree(bounds, NULL, n, block, trav, order, err);
}

void bvh_free(bvh *t)
{
	if (!t)
		return;
	free(t->nodes);
	free(t);
}
