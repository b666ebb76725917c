/* rtsh — binned SAH BVH construction (bvh.h).
 *
 * The builder works on 32-byte references (a float box rounded outward) and
 * a parallel array of primitive indices, rather than on the primitives, so
 * that partitioning moves little memory; the caller reorders its primitives
 * once at the end from the ids. Each node bins the centroids of its
 * references on all three axes in one pass (Wald, "On fast construction of
 * SAH-based bounding volume hierarchies", 2007; 16 bins per axis, fewer for
 * small nodes), sweeps the bins for the split of least surface area
 * heuristic cost (Goldsmith & Salmon 1987; MacDonald & Booth 1990), and
 * partitions in place, gathering the children's centroid bounds on the way,
 * so every level costs two passes over its references. The boxes are kept
 * as four floats (the fourth unused) so that a box union is one SSE min and
 * one max; a scalar version of each helper serves other machines.
 *
 * With a chop function (a mesh's triangles) a node also tries spatial
 * splits where its object split's children overlap (Stich, Friedrich &
 * Dietrich 2009): 16 bins across the node's box, each reference cut into
 * the bins it spans, and a reference cut by the chosen plane goes to both
 * sides unless sending it whole to one side costs less ("unsplitting").
 * The references live in one array with room for split_budget x n more;
 * each node's range is followed by its share of the free room, given to
 * its children in proportion to their sizes, so a subtree never writes
 * outside its own range. When a node's share is used up, it makes object
 * splits only.
 *
 * The binary tree is then made wide: bvh2_gather lists a wide node's
 * children (world.c's trees are 4 wide, a mesh's 8, mesh_tree.c).
 */
#include "core/bvh/bvh.h"
#include "rtsh/memory.h"

#include <pthread.h>
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
/* Spatial splits are tried where the object split's children overlap by
 * more than this share of the root's area (Stich et al.'s alpha). */
#define SPATIAL_ALPHA 1e-2

typedef bvh_fbox fbox;
_Static_assert(sizeof(fbox) == 32, "bin_refs finds a bin by its byte offset: 32 x its index");
typedef bvh2_node node2;

typedef struct builder {
	const bvh_build_opts *o;
	fbox *refs;    /* the references' boxes, rounded outward */
	uint32_t *ids; /* the primitive of each reference */
	fbox *tmp;     /* spatial partitions: a node's refs on their way */
	uint32_t *tmp_ids;
	node2 *nodes;
	size_t used, cap;
	int depth;
	size_t leaves, nrefs;
	double trav;    /* SAH cost of a node visit */
	unsigned block; /* primitives tested together (1: each its own cost) */
	unsigned leaf_max;
	double root_area; /* for the spatial splits' overlap test */
	bool stopped;     /* o->cancel was set: the rest became leaves */
	int threads;      /* threads this subtree may use (no spatial splits) */
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

/* Inline in the bins' sweeps, which call it some 90 times a node. The
 * SSE2 version widens two lanes at a time and does the same double
 * operations in the same order (the same result, bit for bit), with the
 * sign test of the three extents in one compare. */
static inline double fbox_half_area(const fbox *b)
{
#if defined(__SSE2__)
	__m128 lo = _mm_loadu_ps(b->lo), hi = _mm_loadu_ps(b->hi);
	/* e0 >= 0, e1 >= 0 and e2 >= 0 (false for NaN), tested on the float
	 * differences: a float difference keeps the sign of the exact one and
	 * is 0 only for equal floats (gradual underflow: no flush to zero is
	 * set anywhere), and inf - inf or a NaN gives NaN in floats as in
	 * doubles, so the test is the doubles' */
	if ((_mm_movemask_ps(_mm_cmpge_ps(_mm_sub_ps(hi, lo), _mm_setzero_ps())) & 7) != 7)
		return 0.0;
	__m128d e01 = _mm_sub_pd(_mm_cvtps_pd(hi), _mm_cvtps_pd(lo));
	__m128d e2x = _mm_sub_pd(_mm_cvtps_pd(_mm_movehl_ps(hi, hi)), _mm_cvtps_pd(_mm_movehl_ps(lo, lo)));
	double e0 = _mm_cvtsd_f64(e01), e1 = _mm_cvtsd_f64(_mm_unpackhi_pd(e01, e01)), e2 = _mm_cvtsd_f64(e2x);
	return e0 * e1 + e1 * e2 + e2 * e0;
#else
	double e0 = (double)b->hi[0] - (double)b->lo[0], e1 = (double)b->hi[1] - (double)b->lo[1],
	       e2 = (double)b->hi[2] - (double)b->lo[2];
	if (!(e0 >= 0.0 && e1 >= 0.0 && e2 >= 0.0))
		return 0.0;
	return e0 * e1 + e1 * e2 + e2 * e0;
#endif
}

double bvh_fbox_half_area(const fbox *b)
{
	return fbox_half_area(b);
}

#if !defined(__SSE2__)
/* The float next to finite f towards -inf (down) or +inf: one step of
 * its bit pattern away from zero or towards it (what nextafterf does, in
 * line: the root pass calls it for most bounds). Zero and infinities are
 * left to nextafterf. */
static inline float float_step(float f, bool down)
{
	if (!(f != 0.0f && f > -INFINITY && f < INFINITY))
		return nextafterf(f, down ? -INFINITY : INFINITY);
	uint32_t u;
	memcpy(&u, &f, sizeof u);
	u = (f > 0.0f) != down ? u + 1 : u - 1;
	memcpy(&f, &u, sizeof f);
	return f;
}

/* The nearest floats below and above a double. */
static inline float float_down(double v)
{
	float f = (float)v;
	return (double)f > v ? float_step(f, true) : f;
}

static inline float float_up(double v)
{
	float f = (float)v;
	return (double)f < v ? float_step(f, false) : f;
}
#endif

#if defined(__SSE2__)
/* The float box lanes of v: float_down of each (down)
 * or float_up, the same floats; lane 3 is 0. (float)v and the conversion
 * here both round to nearest; where the float overshoots, its bit pattern
 * moves one step: down from a positive float or up from a negative one is
 * one less, the other way one more, and from a zero the least subnormal
 * of the direction's sign. NaN never overshoots. */
static inline __m128 float_round3(const vec3 *v, bool down)
{
	__m128d v01 = _mm_loadu_pd(&v->x), v2 = _mm_load_sd(&v->z);
	__m128 f = _mm_movelh_ps(_mm_cvtpd_ps(v01), _mm_cvtpd_ps(v2));
	__m128d b01 = _mm_cvtps_pd(f), b2 = _mm_cvtps_pd(_mm_movehl_ps(f, f));
	__m128d o01 = down ? _mm_cmpgt_pd(b01, v01) : _mm_cmplt_pd(b01, v01);
	__m128d o2 = down ? _mm_cmpgt_pd(b2, v2) : _mm_cmplt_pd(b2, v2);
	/* the 64-bit masks as 32-bit lanes 0-2 (lane 3: 0 against 0, false) */
	__m128i over = _mm_castps_si128(_mm_shuffle_ps(_mm_castpd_ps(o01), _mm_castpd_ps(o2), _MM_SHUFFLE(2, 0, 2, 0)));
	__m128i u = _mm_castps_si128(f);
	__m128i pos = _mm_castps_si128(_mm_cmpgt_ps(f, _mm_setzero_ps())); /* -1 where f > 0 */
	__m128i twice = _mm_add_epi32(pos, pos);
	__m128i step = down ? _mm_add_epi32(_mm_set1_epi32(1), twice) : _mm_sub_epi32(_mm_set1_epi32(-1), twice);
	__m128i zero = _mm_castps_si128(_mm_cmpeq_ps(f, _mm_setzero_ps()));
	__m128i moved = _mm_add_epi32(u, step);
	moved = _mm_or_si128(_mm_and_si128(zero, _mm_set1_epi32(down ? (int)0x80000001u : 1)),
	                     _mm_andnot_si128(zero, moved));
	return _mm_castsi128_ps(_mm_or_si128(_mm_and_si128(over, moved), _mm_andnot_si128(over, u)));
}
#endif

/* A reference: box x rounded outward to floats, the cost in lane 3 of
 * the lower corner. */
static inline void ref_set(fbox *r, const box *x, float cost)
{
#if defined(__SSE2__)
	/* lane 3 of the lower corner: the cost (its bits or'ed onto 0) */
	_mm_storeu_ps(r->lo, _mm_or_ps(float_round3(&x->lo, true), _mm_set_ps(cost, 0, 0, 0)));
	_mm_storeu_ps(r->hi, float_round3(&x->hi, false));
#else
	*r = (fbox){{float_down(x->lo.x), float_down(x->lo.y), float_down(x->lo.z), cost},
	            {float_up(x->hi.x), float_up(x->hi.y), float_up(x->hi.z), 0}};
#endif
}

void bvh_ref_set(bvh_fbox *r, const box *x, float cost)
{
	ref_set(r, x, cost);
}

/* Fewer bins for small nodes: most nodes are small, and 16 bins on three
 * axes would cost more to set up and sweep than the binning itself. */
static int bins_for(size_t n)
{
	return n >= BINS ? BINS : n < 4 ? 4 : (int)n;
}

#if !defined(__SSE2__)
/* The bin of each lane of a (doubled) centroid: (c - lo) * scale, clamped to
 * [0, nbins - 1]; NaN (an infinite box) goes to bin 0. The SSE2 passes do
 * the same in their registers. */
static inline void bin_index(const float c[4], const float lo[4], const float scale[4], int nbins, int k[4])
{
	for (int i = 0; i < 4; i++) {
		float v = (c[i] - lo[i]) * scale[i];
		k[i] = !(v > 0.0f) ? 0 : v >= (float)(nbins - 1) ? nbins - 1 : (int)v;
	}
}
#endif

typedef struct split {
	int axis, at; /* object split: bins [0, at) go left */
	bool spatial; /* a spatial split at the plane `pos` on `axis` */
	float pos;
	double cost;  /* SAH: area-weighted costs, not yet divided by the parent's area */
	double total; /* the cost of testing every primitive of the node */
	double nl, nr; /* spatial: the summed costs on each side */
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

/* Adds refs[0], refs[step], ... (n of them) to the bins of binning bn on
 * each axis: the box, and the summed cost in lane 3 of its upper corner
 * (the references' is 0; the sums are made in the references' order). */
static void bin_refs(const fbox *refs, size_t n, size_t step, const binning *bn, fbox bbox[3][BINS])
{
#if defined(__SSE2__)
	/* the same operations as the loop below, the reference and its bins
	 * in registers */
	__m128 blo = _mm_loadu_ps(bn->lo), bsc = _mm_loadu_ps(bn->scale), zero = _mm_setzero_ps(),
	       top = _mm_set1_ps((float)(bn->nbins - 1));
	/* lane 3 only, and -0 in lanes 0-2: x + -0 is x, -0 and NaN included */
	__m128 lane3 = _mm_castsi128_ps(_mm_set_epi32(-1, 0, 0, 0)), negz = _mm_set_ps(0.0f, -0.0f, -0.0f, -0.0f);
	for (size_t i = 0; i < n; i++, refs += step) {
		__m128 lo = _mm_loadu_ps(refs->lo), hi = _mm_loadu_ps(refs->hi);
		__m128 cost = _mm_or_ps(_mm_and_ps(lo, lane3), negz); /* (-0, -0, -0, cost) */
		__m128 v = _mm_mul_ps(_mm_sub_ps(_mm_add_ps(lo, hi), blo), bsc);
		/* the bins' byte offsets: the indices times sizeof (fbox), 32 */
		__m128i k = _mm_slli_epi32(_mm_cvttps_epi32(_mm_min_ps(_mm_max_ps(v, zero), top)), 5);
		size_t k0 = (uint32_t)_mm_cvtsi128_si32(k), k1 = (uint32_t)_mm_cvtsi128_si32(_mm_shuffle_epi32(k, 1)),
		       k2 = (uint32_t)_mm_cvtsi128_si32(_mm_shuffle_epi32(k, 2));
		fbox *x = (fbox *)((char *)bbox[0] + k0), *y = (fbox *)((char *)bbox[1] + k1),
		     *z = (fbox *)((char *)bbox[2] + k2);
		_mm_storeu_ps(x->lo, _mm_min_ps(_mm_loadu_ps(x->lo), lo));
		_mm_storeu_ps(x->hi, _mm_add_ps(_mm_max_ps(_mm_loadu_ps(x->hi), hi), cost));
		_mm_storeu_ps(y->lo, _mm_min_ps(_mm_loadu_ps(y->lo), lo));
		_mm_storeu_ps(y->hi, _mm_add_ps(_mm_max_ps(_mm_loadu_ps(y->hi), hi), cost));
		_mm_storeu_ps(z->lo, _mm_min_ps(_mm_loadu_ps(z->lo), lo));
		_mm_storeu_ps(z->hi, _mm_add_ps(_mm_max_ps(_mm_loadu_ps(z->hi), hi), cost));
	}
#else
	for (size_t i = 0; i < n; i++) {
		const fbox *r = &refs[i * step];
		float c[4];
		int k[4];
		centroid2(r, c);
		bin_index(c, bn->lo, bn->scale, bn->nbins, k);
		for (int a = 0; a < 3; a++) {
			fbox_union(&bbox[a][k[a]], r); /* lane 3: the sum stays (>= 0) */
			bbox[a][k[a]].hi[3] += r->lo[3];
		}
	}
#endif
}

/* The cost of testing primitives of summed cost sum in a leaf, leaf_cost's
 * for block b->block: inline in the sweeps with a constant block. */
static inline double sweep_cost(unsigned block, double sum)
{
	return block > 1 ? ceil(sum / block) : sum;
}

/* The SAH sweeps of find_split over the bins of bn's usable axes: the
 * cheapest split into *best (axis and bin; best->cost is the cost to beat). */
static inline void sweep_bins(fbox bbox[3][BINS], const binning *bn, unsigned block, split *best)
{
	size_t nbins = (size_t)bn->nbins;
	for (int a = 0; a < 3; a++) {
		if (!bn->usable[a])
			continue;
		/* Only the splits between the first and the last bin that hold a
		 * reference (cost >= 1, so an empty bin's sum is 0) have both
		 * sides: the sweeps run from one to the other. The bins outside
		 * are empty boxes (the union leaves them out) of cost 0, so the
		 * sums and boxes are the ones sweeps over every bin make. A whole
		 * node's centroid bounds put references in its first and last
		 * bins: the loops below usually stop at once. */
		size_t first = 0, last = nbins - 1;
		while (first < last && bbox[a][first].hi[3] == 0.0f)
			first++;
		while (last > first && bbox[a][last].hi[3] == 0.0f)
			last--;
		/* right-to-left sweep: the area and cost right of each split */
		double right_area[BINS], right_cost[BINS];
		fbox acc = fbox_empty();
		double sum = 0.0;
		for (size_t k = last; k > first; k--) {
			fbox_union(&acc, &bbox[a][k]);
			sum += bbox[a][k].hi[3];
			right_area[k] = fbox_half_area(&acc);
			right_cost[k] = sum;
		}
		acc = fbox_empty();
		sum = 0.0;
		for (size_t k = first; k < last; k++) {
			fbox_union(&acc, &bbox[a][k]);
			sum += bbox[a][k].hi[3];
			/* the left term is >= 0: a right term that alone reaches
			 * the best cost cannot win, and its left area is not needed */
			double right = right_area[k + 1] * sweep_cost(block, right_cost[k + 1]);
			if (!(right < best->cost))
				continue;
			double cost = fbox_half_area(&acc) * sweep_cost(block, sum) + right;
			if (cost < best->cost) {
				best->cost = cost;
				best->axis = a;
				best->at = (int)k + 1;
			}
		}
	}
}

/* The cheapest binned split of refs[begin, end) with centroid bounds cb;
 * axis -1 when every centroid is the same point. With step > 1 only
 * refs[begin], refs[begin + step], ... are binned (a large node's sample,
 * build): the split is the sample's, and lb and rb are the sample's boxes,
 * not the children's (the partition gathers those). */
static split find_split(const builder *b, size_t begin, size_t end, const fbox *cb, size_t step)
{
	split best = {.axis = -1, .cost = INFINITY};
	binning bn;
	best.total = 0.0;
	/* only a node that may be a leaf weighs itself whole (build) */
	if (end - begin <= b->leaf_max) {
		for (size_t i = begin; i < end; i++)
			best.total += b->refs[i].lo[3];
		best.total = leaf_cost(b, best.total);
	}
	if (!binning_make(cb, end - begin, &bn))
		return best;
	int nbins = bn.nbins;
	/* per bin: the box and the summed cost in hi[3] (every cost is >= 1,
	 * so a bin is empty when its cost is 0; float sums are exact to 2^24) */
	fbox bbox[3][BINS];
	for (int k = 0; k < nbins; k++)
		bbox[0][k] = bbox[1][k] = bbox[2][k] = fbox_empty();
	bin_refs(b->refs + begin, (end - begin + step - 1) / step, step, &bn, bbox);
	/* the sweeps, made twice: for unit costs leaf_cost is the sum itself */
	if (b->block > 1)
		sweep_bins(bbox, &bn, b->block, &best);
	else
		sweep_bins(bbox, &bn, 1, &best);
	if (best.axis >= 0) {
		best.lb = best.rb = fbox_empty();
		for (int k = 0; k < best.at; k++)
			fbox_union(&best.lb, &bbox[best.axis][k]);
		for (int k = best.at; k < nbins; k++)
			fbox_union(&best.rb, &bbox[best.axis][k]);
		best.lb.hi[3] = best.rb.hi[3] = 0.0f; /* a box's, not the costs' */
	}
	return best;
}

/* The planes between the spatial bins of axis a of box bb: pos[0] = lo,
 * pos[BINS] = hi. */
static void spatial_planes(const fbox *bb, int a, float pos[BINS + 1])
{
	double lo = bb->lo[a], hi = bb->hi[a];
	for (int k = 0; k <= BINS; k++)
		pos[k] = (float)(lo + (hi - lo) * k / BINS);
	pos[0] = bb->lo[a];
	pos[BINS] = bb->hi[a];
}

/* The spatial bin of coordinate x: the last k < BINS with pos[k] <= x (or
 * 0), guessed from the scale and then put right against the planes. */
static inline int spatial_bin(const float pos[BINS + 1], float scale, float x)
{
	float g = (x - pos[0]) * scale;
	int k = g > 0.0f ? (g < (float)(BINS - 1) ? (int)g : BINS - 1) : 0;
	while (k > 0 && pos[k] > x)
		k--;
	while (k < BINS - 1 && pos[k + 1] <= x)
		k++;
	return k;
}

static bool fbox_is_empty(const fbox *x)
{
	return !(x->lo[0] <= x->hi[0] && x->lo[1] <= x->hi[1] && x->lo[2] <= x->hi[2]);
}

/* The parts of reference r (of primitive id) below and above the plane at
 * pos across axis a. */
static void cut(const builder *b, uint32_t id, int a, float pos, const fbox *r, fbox parts[2])
{
	float planes[3] = {r->lo[a], pos, r->hi[a]};
	parts[0] = parts[1] = *r;
	b->o->chop(b->o->ctx, id, a, planes, 2, parts);
}

/* The cheapest spatial split of refs[begin, end) (box bb), if cheaper
 * than best: each reference cut into the bins it spans, counted where
 * it enters and where it leaves. */
static void find_spatial(const builder *b, size_t begin, size_t end, const fbox *bb, split *best)
{
	const bvh_build_opts *o = b->o;
	for (int a = 0; a < 3; a++) {
		if (!(bb->hi[a] > bb->lo[a]))
			continue;
		float pos[BINS + 1];
		spatial_planes(bb, a, pos);
		float scale = (float)BINS / (bb->hi[a] - bb->lo[a]);
		fbox bins[BINS];
		double enter[BINS] = {0}, leave[BINS] = {0};
		for (int k = 0; k < BINS; k++)
			bins[k] = fbox_empty();
		for (size_t i = begin; i < end; i++) {
			const fbox *r = &b->refs[i];
			int k0 = spatial_bin(pos, scale, r->lo[a]), k1 = spatial_bin(pos, scale, r->hi[a]);
			enter[k0] += r->lo[3];
			leave[k1] += r->lo[3];
			if (k0 == k1) {
				fbox_union(&bins[k0], r);
				continue;
			}
			fbox parts[BINS];
			for (int k = k0; k <= k1; k++)
				parts[k - k0] = *r;
			o->chop(o->ctx, b->ids[i], a, &pos[k0], k1 - k0 + 1, parts);
			for (int k = k0; k <= k1; k++)
				fbox_union(&bins[k], &parts[k - k0]);
		}
		double right_area[BINS], right_cost[BINS];
		fbox acc = fbox_empty();
		double sum = 0.0;
		for (int k = BINS - 1; k > 0; k--) {
			fbox_union(&acc, &bins[k]);
			sum += leave[k];
			right_area[k] = fbox_half_area(&acc);
			right_cost[k] = sum;
		}
		acc = fbox_empty();
		sum = 0.0;
		for (int k = 0; k < BINS - 1; k++) {
			fbox_union(&acc, &bins[k]);
			sum += enter[k];
			if (sum == 0.0 || right_cost[k + 1] == 0.0)
				continue;
			double cost = fbox_half_area(&acc) * leaf_cost(b, sum) +
			              right_area[k + 1] * leaf_cost(b, right_cost[k + 1]);
			if (cost < best->cost) {
				best->cost = cost;
				best->axis = a;
				best->spatial = true;
				best->pos = pos[k + 1];
				best->nl = sum;
				best->nr = right_cost[k + 1];
			}
		}
	}
	if (best->spatial) {
		float pos[BINS + 1];
		spatial_planes(bb, best->axis, pos);
		/* the children's boxes again, for the unsplitting tests */
		best->lb = best->rb = fbox_empty();
		for (size_t i = begin; i < end; i++) {
			const fbox *r = &b->refs[i];
			if (r->hi[best->axis] <= best->pos)
				fbox_union(&best->lb, r);
			else if (r->lo[best->axis] >= best->pos)
				fbox_union(&best->rb, r);
			else {
				fbox parts[2];
				cut(b, b->ids[i], best->axis, best->pos, r, parts);
				fbox_union(&best->lb, &parts[0]);
				fbox_union(&best->rb, &parts[1]);
			}
		}
	}
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

#if defined(__SSE2__)
/* Whether doubled centroid c goes right of split bin `at` (1 <= at <
 * nbins) on the axis of bit abit: whether its bin as bin_refs computes it,
 * trunc(clamp((c - lo) x scale, 0, nbins - 1)), is at or more. That is
 * (c - lo) x scale >= at, the same float product compared: below 0 and
 * NaN (bin 0) are left, at nbins - 1 or more (the last bin) right, and in
 * between trunc(v) >= at exactly when v >= at. No bin index is stored
 * and loaded back before the branch. */
static inline bool goes_right(__m128 c, __m128 blo, __m128 bsc, __m128 at, int abit)
{
	return (_mm_movemask_ps(_mm_cmpge_ps(_mm_mul_ps(_mm_sub_ps(c, blo), bsc), at)) & abit) != 0;
}
#endif

/* Partitions by an object split, returning the middle; *lcb, *rcb: the
 * children's centroid bounds, and with `boxes` *lb, *rb their boxes (a
 * split found on a sample, whose bins hold the sample's boxes only). The
 * bins are computed exactly as find_split did. Two-pointer (Hoare): the
 * scan from the left stops at a reference that goes right, the scan from
 * the right at one that goes left, and the two swap, so only misplaced
 * references move (about a quarter of a node's instead of every right
 * one). Each side gets the same references in another order than a
 * one-sided partition: the children's bins, centroid bounds and
 * whole-number cost sums do not depend on the order, and the order within
 * a leaf is set when the leaf is made (sort_ids). Inline with a constant
 * `boxes`: partition and partition_boxes below. */
static inline __attribute__((always_inline)) size_t partition_with(builder *b, size_t begin, size_t end,
                                                                   const fbox *cb, const split *s, fbox *lcb,
                                                                   fbox *rcb, bool boxes, fbox *lb, fbox *rb)
{
	binning bn;
	binning_make(cb, end - begin, &bn);
	int a = s->axis;
	*lcb = *rcb = fbox_empty();
	if (boxes)
		*lb = *rb = fbox_empty();
	size_t i = begin, j = end;
#if defined(__SSE2__)
	/* the bounds in registers; the axis's bin of a centroid in lane a */
	__m128 blo = _mm_loadu_ps(bn.lo), bsc = _mm_loadu_ps(bn.scale), zero = _mm_setzero_ps(),
	       at = _mm_set1_ps((float)s->at);
	__m128 llo = _mm_loadu_ps(lcb->lo), lhi = _mm_loadu_ps(lcb->hi), rlo = llo, rhi = lhi;
	/* the children's boxes (with `boxes`) */
	__m128 blol = llo, bhil = lhi, blor = llo, bhir = lhi;
	int abit = 1 << a;
	for (;;) {
		__m128 ci = zero, cj = zero, loi = zero, hii = zero, loj = zero, hij = zero;
		while (i < j) {
			loi = _mm_loadu_ps(b->refs[i].lo);
			hii = _mm_loadu_ps(b->refs[i].hi);
			ci = _mm_add_ps(loi, hii);
			if (goes_right(ci, blo, bsc, at, abit))
				break;
			llo = _mm_min_ps(llo, ci);
			lhi = _mm_max_ps(lhi, ci);
			if (boxes) {
				blol = _mm_min_ps(blol, loi);
				bhil = _mm_max_ps(bhil, hii);
			}
			i++;
		}
		if (i == j)
			break;
		/* refs[i] goes right */
		rlo = _mm_min_ps(rlo, ci);
		rhi = _mm_max_ps(rhi, ci);
		if (boxes) {
			blor = _mm_min_ps(blor, loi);
			bhir = _mm_max_ps(bhir, hii);
		}
		j--;
		while (i < j) {
			loj = _mm_loadu_ps(b->refs[j].lo);
			hij = _mm_loadu_ps(b->refs[j].hi);
			cj = _mm_add_ps(loj, hij);
			if (!goes_right(cj, blo, bsc, at, abit))
				break;
			rlo = _mm_min_ps(rlo, cj);
			rhi = _mm_max_ps(rhi, cj);
			if (boxes) {
				blor = _mm_min_ps(blor, loj);
				bhir = _mm_max_ps(bhir, hij);
			}
			j--;
		}
		if (i == j)
			break;
		/* refs[j] goes left */
		llo = _mm_min_ps(llo, cj);
		lhi = _mm_max_ps(lhi, cj);
		if (boxes) {
			blol = _mm_min_ps(blol, loj);
			bhil = _mm_max_ps(bhil, hij);
		}
		swap_refs(b, i, j);
		i++;
	}
	_mm_storeu_ps(lcb->lo, llo);
	_mm_storeu_ps(lcb->hi, lhi);
	_mm_storeu_ps(rcb->lo, rlo);
	_mm_storeu_ps(rcb->hi, rhi);
	if (boxes) {
		_mm_storeu_ps(lb->lo, blol);
		_mm_storeu_ps(lb->hi, bhil);
		_mm_storeu_ps(rb->lo, blor);
		_mm_storeu_ps(rb->hi, bhir);
	}
#else
	for (;;) {
		float c[4];
		int k[4];
		while (i < j) {
			centroid2(&b->refs[i], c);
			bin_index(c, bn.lo, bn.scale, bn.nbins, k);
			if (k[a] >= s->at)
				break;
			fbox_add_point(lcb, c);
			if (boxes)
				fbox_union(lb, &b->refs[i]);
			i++;
		}
		if (i == j)
			break;
		fbox_add_point(rcb, c);
		if (boxes)
			fbox_union(rb, &b->refs[i]);
		j--;
		while (i < j) {
			centroid2(&b->refs[j], c);
			bin_index(c, bn.lo, bn.scale, bn.nbins, k);
			if (k[a] < s->at)
				break;
			fbox_add_point(rcb, c);
			if (boxes)
				fbox_union(rb, &b->refs[j]);
			j--;
		}
		if (i == j)
			break;
		fbox_add_point(lcb, c);
		if (boxes)
			fbox_union(lb, &b->refs[j]);
		swap_refs(b, i, j);
		i++;
	}
#endif
	if (boxes) /* boxes, not costs: lane 3 as find_split leaves it */
		lb->hi[3] = rb->hi[3] = 0.0f;
	return i;
}

static size_t partition(builder *b, size_t begin, size_t end, const fbox *cb, const split *s, fbox *lcb,
                        fbox *rcb)
{
	return partition_with(b, begin, end, cb, s, lcb, rcb, false, NULL, NULL);
}

static size_t partition_boxes(builder *b, size_t begin, size_t end, const fbox *cb, const split *s, fbox *lcb,
                              fbox *rcb, fbox *lb, fbox *rb)
{
	return partition_with(b, begin, end, cb, s, lcb, rcb, true, lb, rb);
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

static double area_with(const fbox *a, const fbox *r)
{
	fbox u = *a;
	fbox_union(&u, r);
	return fbox_half_area(&u);
}

/* Partitions refs[begin, end) by spatial split s into tmp: the left
 * references from tmp[0] up, the right ones from tmp[room - 1] down. A
 * reference the plane cuts goes to both sides, or whole to one side where
 * that costs less by the SAH (Stich et al.'s unsplitting), or whole where
 * no room is left. Returns the count on the left in *nl and on the right
 * in *nr. */
static void partition_spatial(builder *b, size_t begin, size_t end, size_t room, const split *s, size_t *nl,
                              size_t *nr)
{
	int a = s->axis;
	size_t l = 0, r = room;
	double al = fbox_half_area(&s->lb), ar = fbox_half_area(&s->rb);
	double cl = leaf_cost(b, s->nl), cr = leaf_cost(b, s->nr);
	double cl1 = leaf_cost(b, s->nl - 1), cr1 = leaf_cost(b, s->nr - 1);
	for (size_t i = begin; i < end; i++) {
		const fbox *ref = &b->refs[i];
		uint32_t id = b->ids[i];
		int side; /* -1 left, 1 right, 0 both */
		if (ref->hi[a] <= s->pos)
			side = -1;
		else if (ref->lo[a] >= s->pos)
			side = 1;
		else {
			double both = al * cl + ar * cr;
			double left = area_with(&s->lb, ref) * cl + ar * cr1;
			double right = al * cl1 + area_with(&s->rb, ref) * cr;
			side = left < both && left <= right ? -1 : right < both ? 1 : 0;
			/* both sides take one more slot than the reference had */
			if (side == 0 && r - l < (end - i) + 1)
				side = left <= right ? -1 : 1;
		}
		if (side == 0) {
			fbox parts[2];
			cut(b, id, a, s->pos, ref, parts);
			bool okl = !fbox_is_empty(&parts[0]), okr = !fbox_is_empty(&parts[1]);
			if (okl && okr) {
				b->tmp[l] = parts[0];
				b->tmp_ids[l++] = id;
				b->tmp[--r] = parts[1];
				b->tmp_ids[r] = id;
				continue;
			}
			side = okl ? -1 : 1;
		}
		if (side < 0) {
			b->tmp[l] = *ref;
			b->tmp_ids[l++] = id;
		} else {
			b->tmp[--r] = *ref;
			b->tmp_ids[r] = id;
		}
	}
	*nl = l;
	*nr = room - r;
}

/* Sifts place r of the max-heap over refs[begin, begin + m) (by primitive
 * index, places 0-based from begin) down to where it belongs. */
static void sift_down(builder *b, size_t begin, size_t r, size_t m)
{
	const uint32_t *id = b->ids + begin;
	for (size_t c; (c = 2 * r + 1) < m; r = c) {
		if (c + 1 < m && id[c + 1] > id[c])
			c++;
		if (id[r] >= id[c])
			break;
		swap_refs(b, begin + r, begin + c);
	}
}

/* Puts refs[begin, end) in ascending order of primitive index, unless
 * they are already (a heap sort: no memory, n log n at worst). The halving
 * below sorts first, so that which references go to which half does not
 * depend on the order the partitions above left them in. */
static void sort_refs(builder *b, size_t begin, size_t end)
{
	const uint32_t *id = b->ids + begin;
	size_t n = end - begin, i = 1;
	while (i < n && id[i - 1] < id[i])
		i++;
	if (i >= n)
		return;
	for (size_t k = n / 2; k-- > 0;)
		sift_down(b, begin, k, n);
	for (size_t m = n - 1; m > 0; m--) {
		swap_refs(b, begin, begin + m);
		sift_down(b, begin, 0, m);
	}
}

/* A leaf's primitive indices in ascending order (insertion sort: a leaf
 * holds at most leaf_max): the walks keep the first of equal distances in
 * leaf order, so coincident primitives in one leaf resolve to the lower
 * index, whatever order the partitions left them in. */
static void sort_leaf(uint32_t *id, size_t n)
{
	for (size_t i = 1; i < n; i++) {
		uint32_t x = id[i];
		size_t j = i;
		for (; j > 0 && id[j - 1] > x; j--)
			id[j] = id[j - 1];
		id[j] = x;
	}
}

/* Builds the subtree over refs[begin, end) (box bb, centroid bounds cb),
 * with refs[end, cap_end) free for its spatial splits, and returns its
 * reference in *child, *meta. */
static void build(builder *b, size_t begin, size_t end, size_t cap_end, const fbox *bb, const fbox *cb, int depth,
                  uint32_t *child, uint32_t *meta);

/* A node's left subtree built by another thread: the same calls with a
 * builder of its own, whose nodes go to a range of the array set apart. */
typedef struct sub_build {
	builder b;
	size_t begin, end, cap_end;
	fbox bb, cb;
	int depth;
	uint32_t child, meta;
} sub_build;

static void *sub_build_run(void *arg)
{
	sub_build *s = arg;
	build(&s->b, s->begin, s->end, s->cap_end, &s->bb, &s->cb, s->depth, &s->child, &s->meta);
	return NULL;
}

/* A node of SAMPLE_MIN references or more (and no spatial splits) finds
 * its split by binning every k-th reference, k = n / SAMPLE_N (about
 * SAMPLE_N of them, fixed by the order the partitions above left: the
 * same for any thread count), and the partition gathers the children's
 * boxes. The top levels' binning passes over every reference are what it
 * saves; the split is the sample's, not the whole node's. */
#ifndef SAMPLE_MIN
#define SAMPLE_MIN 4096
#endif
#ifndef SAMPLE_N
#define SAMPLE_N 1024
#endif

/* Below this many references a subtree is not given to another thread. */
#define PARALLEL_MIN 4096

static void build(builder *b, size_t begin, size_t end, size_t cap_end, const fbox *bb, const fbox *cb, int depth,
                  uint32_t *child, uint32_t *meta)
{
	size_t n = end - begin;
	if (depth > b->depth)
		b->depth = depth;
	bool leaf = n <= 1 || (depth >= BALANCED_DEPTH && n <= b->leaf_max);
	/* large nodes look at the cancel flag: at most about 4096 references
	 * are binned between two looks */
	if (!leaf && n >= 4096 && b->o->cancel && atomic_load_explicit(b->o->cancel, memory_order_relaxed))
		b->stopped = true;
	leaf = leaf || b->stopped;
	if (!leaf && n <= b->leaf_max) {
		/* A split costs at least a node visit: a node that costs no more
		 * to test whole is a leaf without binning (most small nodes). */
		double total = 0.0;
		for (size_t i = begin; i < end; i++)
			total += b->refs[i].lo[3];
		leaf = leaf_cost(b, total) <= b->trav;
	}
	split s = {.axis = -1}, obj = s;
	/* a large node's split from a sample (SAMPLE_MIN) */
	size_t step = !b->o->chop && n >= SAMPLE_MIN ? n / SAMPLE_N : 1;
	if (!leaf && depth < BALANCED_DEPTH) {
		s = obj = find_split(b, begin, end, cb, step);
		if (step > 1 && s.axis < 0) {
			/* the sample's centroids in one bin an axis: all of them */
			step = 1;
			s = obj = find_split(b, begin, end, cb, step);
		}
		if (b->o->chop && cap_end > end) {
			/* a spatial split where the object split's children overlap */
			fbox ov = s.lb;
			for (int a = 0; a < 3; a++) {
				ov.lo[a] = ov.lo[a] > s.rb.lo[a] ? ov.lo[a] : s.rb.lo[a];
				ov.hi[a] = ov.hi[a] < s.rb.hi[a] ? ov.hi[a] : s.rb.hi[a];
			}
			if (s.axis < 0 || fbox_half_area(&ov) > SPATIAL_ALPHA * b->root_area)
				find_spatial(b, begin, end, bb, &s);
		}
	}
	if (!leaf && n <= b->leaf_max && depth < BALANCED_DEPTH) {
		double area = fbox_half_area(bb);
		double split_cost = area > 0.0 && s.axis >= 0 ? b->trav + s.cost / area : INFINITY;
		leaf = s.total <= split_cost;
	}
	if (leaf) {
		if (!b->stopped) /* (a stopped build's tree is thrown away) */
			sort_leaf(b->ids + begin, n);
		*child = (uint32_t)begin;
		*meta = BVH_LEAF | (uint32_t)n;
		b->leaves++;
		b->nrefs += n;
		return;
	}

	size_t mid = begin, lend, rbegin, rend, lcap;
	fbox lb, rb, lcb, rcb;
	size_t nl = 0, nr = 0, room = cap_end - begin;
	if (s.spatial) {
		partition_spatial(b, begin, end, room, &s, &nl, &nr);
		/* every reference whole on one side: the object split instead */
		if (nl == 0 || nr == 0)
			s = obj;
	}
	if (s.spatial) {
		/* the free room left, shared in proportion to the sizes */
		size_t freed = room - nl - nr, lfree = (size_t)((double)freed * (double)nl / (double)(nl + nr));
		lend = begin + nl;
		lcap = lend + lfree;
		rbegin = lcap;
		rend = rbegin + nr;
		memcpy(&b->refs[begin], b->tmp, nl * sizeof *b->refs);
		memcpy(&b->ids[begin], b->tmp_ids, nl * sizeof *b->ids);
		memcpy(&b->refs[rbegin], &b->tmp[room - nr], nr * sizeof *b->refs);
		memcpy(&b->ids[rbegin], &b->tmp_ids[room - nr], nr * sizeof *b->ids);
		bounds_of(b, begin, lend, &lb, &lcb);
		bounds_of(b, rbegin, rend, &rb, &rcb);
	} else {
		if (s.axis >= 0 && step > 1) {
			mid = partition_boxes(b, begin, end, cb, &s, &lcb, &rcb, &lb, &rb);
		} else if (s.axis >= 0) {
			mid = partition(b, begin, end, cb, &s, &lcb, &rcb);
			lb = s.lb;
			rb = s.rb;
		}
		if (mid == begin || mid == end) {
			/* no useful split (equal centroids, or past BALANCED_DEPTH):
			 * halve, the lower primitive indices to the left */
			sort_refs(b, begin, end);
			mid = begin + n / 2;
			bounds_of(b, begin, mid, &lb, &lcb);
			bounds_of(b, mid, end, &rb, &rcb);
		}
		/* the free room after end, shared in proportion: the right
		 * references move up by the left child's share */
		size_t freed = cap_end - end, lfree = (size_t)((double)freed * (double)(mid - begin) / (double)n);
		lend = mid;
		lcap = mid + lfree;
		rbegin = lcap;
		rend = end + lfree;
		if (lfree) {
			memmove(&b->refs[rbegin], &b->refs[mid], (end - mid) * sizeof *b->refs);
			memmove(&b->ids[rbegin], &b->ids[mid], (end - mid) * sizeof *b->ids);
		}
	}
	size_t ni = b->used++;
	node2 *node = &b->nodes[ni];
	node->box[0] = lb;
	node->box[1] = rb;
	uint32_t c0, m0, c1, m1;
	if (b->threads > 1 && !b->o->chop && lend - begin >= PARALLEL_MIN && rend - rbegin >= PARALLEL_MIN) {
		/* The left subtree in another thread. Its nodes take the range
		 * after this one, the right subtree's follow it: a subtree over
		 * m references has at most m - 1 nodes (every node splits its
		 * range in two non-empty ones), so the ranges cannot meet. The
		 * references are partitioned in place within each child's range,
		 * as one thread would: the same tree (node indices aside, which
		 * the wide tree does not keep). */
		sub_build sb = {.b = *b, .begin = begin, .end = lend, .cap_end = lcap, .bb = lb, .cb = lcb,
		                .depth = depth + 1};
		sb.b.threads = b->threads / 2;
		sb.b.depth = 0;
		sb.b.leaves = sb.b.nrefs = 0;
		b->threads -= sb.b.threads;
		b->used = ni + (lend - begin);
		pthread_t th;
		bool spawned = pthread_create(&th, NULL, sub_build_run, &sb) == 0;
		if (!spawned)
			sub_build_run(&sb);
		build(b, rbegin, rend, cap_end, &rb, &rcb, depth + 1, &c1, &m1);
		if (spawned)
			pthread_join(th, NULL);
		b->threads += sb.b.threads;
		c0 = sb.child;
		m0 = sb.meta;
		b->depth = b->depth > sb.b.depth ? b->depth : sb.b.depth;
		b->leaves += sb.b.leaves;
		b->nrefs += sb.b.nrefs;
		b->stopped = b->stopped || sb.b.stopped;
	} else {
		build(b, begin, lend, lcap, &lb, &lcb, depth + 1, &c0, &m0);
		build(b, rbegin, rend, cap_end, &rb, &rcb, depth + 1, &c1, &m1);
	}
	node = &b->nodes[ni];
	node->child[0] = c0;
	node->meta[0] = m0;
	node->child[1] = c1;
	node->meta[1] = m1;
	*child = (uint32_t)ni;
	*meta = 0;
}

void bvh2_free(bvh2 *t)
{
	free(t->nodes);
	free(t->ids);
	memset(t, 0, sizeof *t);
}

/* bvh2_build, from the boxes `bounds` or, when refs is not NULL, from the
 * references refs[0, n) made by bvh_ref_set (used in place: the caller's
 * to free; no spatial splits). */
static bool build_from(const box *bounds, fbox *refs, size_t n, const bvh_build_opts *o, bvh2 *t, rt_error *err)
{
	memset(t, 0, sizeof *t);
	t->root_meta = BVH_LEAF; /* an empty leaf */
	t->bounds = fbox_empty();
	if (n == 0)
		return true;
	double budget = o->chop && o->split_budget > 0 && !refs ? o->split_budget : 0;
	size_t cap = n + (size_t)((double)n * budget);
	if (n > BVH_MAX_PRIMS || cap > BVH_MAX_PRIMS)
		return rt_error_set(err, "too many objects (%zu); expected at most %u", n, BVH_MAX_PRIMS);
	builder b = {.o = o, .trav = o->trav, .block = o->block ? o->block : 1,
	             .leaf_max = o->leaf_max ? o->leaf_max : LEAF_MAX, .threads = o->threads > 1 ? o->threads : 1};
	b.refs = refs ? refs : malloc(cap * sizeof *b.refs);
	b.ids = malloc(cap * sizeof *b.ids);
	/* a binary tree with leaves folded in has fewer inner nodes than leaves,
	 * and a leaf holds at least one reference */
	b.nodes = malloc(cap * sizeof *b.nodes);
	if (cap > n) {
		b.tmp = malloc(cap * sizeof *b.tmp);
		b.tmp_ids = malloc(cap * sizeof *b.tmp_ids);
	}
	if (!b.refs || !b.ids || !b.nodes || (cap > n && (!b.tmp || !b.tmp_ids))) {
		if (!refs)
			free(b.refs);
		free(b.ids);
		free(b.nodes);
		free(b.tmp);
		free(b.tmp_ids);
		return rt_error_set(err, "out of memory building the BVH (%zu objects)", n);
	}
	mem_prefault(b.ids, cap * sizeof *b.ids); /* written whole below */
	fbox bb = fbox_empty(), cb = fbox_empty();
	for (size_t i = 0; i < n; i++) {
		fbox *r = &b.refs[i];
		if (!refs)
			ref_set(r, &bounds[i], o->costs ? o->costs[i] : 1.0f);
		b.ids[i] = (uint32_t)i;
		float c[4];
		centroid2(r, c);
		fbox_union(&bb, r);
		fbox_add_point(&cb, c);
	}
	b.root_area = fbox_half_area(&bb);
	build(&b, 0, n, cap, &bb, &cb, 0, &t->root, &t->root_meta);
	if (!refs)
		free(b.refs);
	if (b.stopped) {
		free(b.tmp);
		free(b.tmp_ids);
		free(b.nodes);
		free(b.ids);
		return rt_error_set(err, "stopped");
	}
	free(b.tmp);
	free(b.tmp_ids);
	t->nodes = b.nodes;
	t->nnodes = b.used;
	t->ids = b.ids;
	t->nids = cap;
	t->nrefs = b.nrefs;
	t->bounds = bb;
	t->depth = b.depth;
	t->leaves = b.leaves;
	if (b.used && b.used < cap) {
		node2 *fit = realloc(b.nodes, b.used * sizeof *fit);
		if (fit)
			t->nodes = fit;
	}
	return true;
}

bool bvh2_build(const box *bounds, size_t n, const bvh_build_opts *o, bvh2 *t, rt_error *err)
{
	return build_from(bounds, NULL, n, o, t, err);
}

int bvh2_gather(const bvh2 *t, uint32_t n2, int width, bvh_slot *s)
{
	const node2 *src = &t->nodes[n2];
	s[0] = (bvh_slot){src->box[0], src->child[0], src->meta[0]};
	s[1] = (bvh_slot){src->box[1], src->child[1], src->meta[1]};
	int cnt = 2;
	while (cnt < width) {
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
		const node2 *c = &t->nodes[s[best].child];
		s[best] = (bvh_slot){c->box[0], c->child[0], c->meta[0]};
		s[cnt++] = (bvh_slot){c->box[1], c->child[1], c->meta[1]};
	}
	return cnt;
}

/* Makes the 4-wide node for binary node n2 (and, depth first, the nodes
 * below it) in out[*used ...]; returns its index. */
static uint32_t collapse(const bvh2 *t, uint32_t n2, bvh_node *out, size_t *used)
{
	bvh_slot s[BVH_WIDTH];
	int cnt = bvh2_gather(t, n2, BVH_WIDTH, s);
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
			out[ni].child[k] = s[k].meta ? s[k].child : collapse(t, s[k].child, out, used);
		}
	}
	return ni;
}

bvh *bvh_build(bvh_fbox *refs, size_t n, uint32_t *order, int threads, const atomic_bool *cancel, rt_error *err)
{
	bvh *t = calloc(1, sizeof *t);
	if (!t) {
		rt_error_set(err, "out of memory building the BVH");
		return NULL;
	}
	bvh_build_opts o = {.block = 1, .trav = COST_TRAVERSE, .cancel = cancel, .threads = threads};
	bvh2 b;
	if (!build_from(NULL, refs, n, &o, &b, err)) {
		free(t);
		return NULL;
	}
	t->root_meta = b.root_meta;
	t->root = b.root;
	t->depth = b.depth;
	t->leaves = b.leaves;
	if (n == 0) {
		bvh2_free(&b);
		return t;
	}
	memcpy(order, b.ids, n * sizeof *order); /* no spatial splits: a permutation */
	if (b.root_meta) {
		/* one leaf: a root node holding it alone, so that a ray that
		 * misses the box of everything stops at one slab test */
		bvh_node *one = aligned_alloc(64, (sizeof *one + 63) / 64 * 64);
		if (!one) {
			bvh2_free(&b);
			free(t);
			rt_error_set(err, "out of memory building the BVH (%zu objects)", n);
			return NULL;
		}
		for (int k = 0; k < BVH_WIDTH; k++) {
			fbox fb = k == 0 ? b.bounds : fbox_empty();
			for (int a = 0; a < 3; a++) {
				one->b[BVH_LO_X + a][k] = fb.lo[a];
				one->b[BVH_HI_X + a][k] = fb.hi[a];
			}
			one->child[k] = k == 0 ? b.root : 0;
			one->meta[k] = k == 0 ? b.root_meta : BVH_LEAF;
		}
		bvh2_free(&b);
		t->nodes = one;
		t->nnodes = 1;
		t->root = 0;
		t->root_meta = 0;
		return t;
	}
	/* each 4-wide node takes at least one binary node */
	size_t bytes = (b.nnodes * sizeof(bvh_node) + 63) / 64 * 64;
	bvh_node *wide = aligned_alloc(64, bytes);
	if (!wide) {
		bvh2_free(&b);
		free(t);
		rt_error_set(err, "out of memory building the BVH (%zu objects)", n);
		return NULL;
	}
	size_t used = 0;
	t->root = collapse(&b, b.root, wide, &used);
	t->root_meta = 0;
	bvh2_free(&b);
	bytes = (used * sizeof(bvh_node) + 63) / 64 * 64;
	bvh_node *fit = mem_alloc_huge(bytes); /* every ray's walk: huge pages spare the TLB */
	if (fit) {
		memcpy(fit, wide, used * sizeof *fit);
		free(wide);
		wide = fit;
	}
	t->nodes = wide;
	t->nnodes = used;
	return t;
}

void bvh_free(bvh *t)
{
	if (!t)
		return;
	free(t->nodes);
	free(t);
}
