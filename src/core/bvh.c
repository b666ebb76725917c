/* rtsh — binned SAH BVH construction (bvh.h). */
#include "bvh.h"

#include <stdlib.h>
#include <string.h>

#define BINS 16
#define LEAF_MAX 8
#define BALANCED_DEPTH 60
#define COST_TRAVERSE 1.0
#define COST_INTERSECT 1.0

typedef struct builder {
	prim *prims;
	box *bounds;
	vec3 *centroids;
	bvh_node *nodes;
	size_t used;
	int depth;
} builder;

static void swap_items(builder *b, size_t i, size_t j)
{
	prim tp = b->prims[i];
	b->prims[i] = b->prims[j];
	b->prims[j] = tp;
	box tb = b->bounds[i];
	b->bounds[i] = b->bounds[j];
	b->bounds[j] = tb;
	vec3 tc = b->centroids[i];
	b->centroids[i] = b->centroids[j];
	b->centroids[j] = tc;
}

static int bin_of(double c, double lo, double scale)
{
	int k = (int)((c - lo) * scale);
	return k < 0 ? 0 : k >= BINS ? BINS - 1 : k;
}

static void make_leaf(bvh_node *node, size_t begin, size_t end)
{
	node->first_or_right = (uint32_t)begin;
	node->count = (uint16_t)(end - begin);
	node->axis = 0;
}

static void build(builder *b, size_t ni, size_t begin, size_t end, int depth)
{
	bvh_node *node = &b->nodes[ni];
	box nb = box_empty(), cb = box_empty();
	for (size_t i = begin; i < end; i++) {
		nb = box_union(nb, b->bounds[i]);
		cb = box_add(cb, b->centroids[i]);
	}
	node->b = nb;
	if (depth > b->depth)
		b->depth = depth;
	size_t n = end - begin;
	if (n <= 1 || (depth >= BALANCED_DEPTH && n <= LEAF_MAX)) {
		make_leaf(node, begin, end);
		return;
	}

	/* Find the cheapest split over the bins of all three axes. */
	double best_cost = INFINITY;
	int best_axis = -1, best_split = 0;
	vec3 ext = v3_sub(cb.hi, cb.lo);
	/* Past BALANCED_DEPTH only halving by count is used, which bounds the
	 * depth by BALANCED_DEPTH + log2(n) < BVH_MAX_DEPTH. */
	for (int axis = 0; axis < 3 && depth < BALANCED_DEPTH; axis++) {
		double lo = v3_get(cb.lo, axis), e = v3_get(ext, axis);
		if (!(e > 0.0))
			continue;
		double scale = BINS / e;
		size_t count[BINS] = {0};
		box bbox[BINS];
		for (int k = 0; k < BINS; k++)
			bbox[k] = box_empty();
		for (size_t i = begin; i < end; i++) {
			int k = bin_of(v3_get(b->centroids[i], axis), lo, scale);
			count[k]++;
			bbox[k] = box_union(bbox[k], b->bounds[i]);
		}
		/* Sweep from the right to get the area and count right of each split. */
		double right_area[BINS];
		size_t right_count[BINS];
		box acc = box_empty();
		size_t cnt = 0;
		for (int k = BINS - 1; k > 0; k--) {
			acc = box_union(acc, bbox[k]);
			cnt += count[k];
			right_area[k] = box_half_area(acc);
			right_count[k] = cnt;
		}
		acc = box_empty();
		cnt = 0;
		for (int k = 0; k < BINS - 1; k++) {
			acc = box_union(acc, bbox[k]);
			cnt += count[k];
			if (cnt == 0 || right_count[k + 1] == 0)
				continue;
			double cost = box_half_area(acc) * (double)cnt +
			              right_area[k + 1] * (double)right_count[k + 1];
			if (cost < best_cost) {
				best_cost = cost;
				best_axis = axis;
				best_split = k + 1;
			}
		}
	}

	double parent_area = box_half_area(nb);
	double leaf_cost = COST_INTERSECT * (double)n;
	double split_cost = parent_area > 0.0 ? COST_TRAVERSE + COST_INTERSECT * best_cost / parent_area
	                                      : INFINITY;
	if (n <= LEAF_MAX && depth < BALANCED_DEPTH && (best_axis < 0 || leaf_cost <= split_cost)) {
		make_leaf(node, begin, end);
		return;
	}

	size_t mid;
	if (best_axis >= 0) {
		double lo = v3_get(cb.lo, best_axis), scale = BINS / v3_get(ext, best_axis);
		size_t i = begin, j = end;
		while (i < j) {
			if (bin_of(v3_get(b->centroids[i], best_axis), lo, scale) < best_split)
				i++;
			else
				swap_items(b, i, --j);
		}
		mid = i;
	} else {
		mid = begin; /* every centroid is the same point */
	}
	if (mid == begin || mid == end)
		mid = begin + n / 2; /* no useful split: halve by count */

	node->axis = (uint16_t)(best_axis < 0 ? 0 : best_axis);
	node->count = 0;
	size_t left = b->used++;
	build(b, left, begin, mid, depth + 1);
	size_t right = b->used++;
	b->nodes[ni].first_or_right = (uint32_t)right;
	build(b, right, mid, end, depth + 1);
}

bvh *bvh_build(prim *prims, box *bounds, size_t n, rt_error *err)
{
	bvh *t = calloc(1, sizeof *t);
	if (!t) {
		rt_error_set(err, "out of memory building the BVH");
		return NULL;
	}
	if (n == 0)
		return t;
	if (n > UINT32_MAX / 2) {
		free(t);
		rt_error_set(err, "too many objects (%zu); expected at most %u", n, UINT32_MAX / 2);
		return NULL;
	}
	builder b = {prims, bounds, malloc(n * sizeof(vec3)), malloc((2 * n) * sizeof(bvh_node)), 1, 0};
	if (!b.centroids || !b.nodes) {
		free(b.centroids);
		free(b.nodes);
		free(t);
		rt_error_set(err, "out of memory building the BVH");
		return NULL;
	}
	for (size_t i = 0; i < n; i++)
		b.centroids[i] = box_center(bounds[i]);
	build(&b, 0, 0, n, 0);
	free(b.centroids);
	bvh_node *shrunk = realloc(b.nodes, b.used * sizeof(bvh_node));
	t->nodes = shrunk ? shrunk : b.nodes;
	t->nnodes = b.used;
	t->depth = b.depth;
	return t;
}

void bvh_free(bvh *t)
{
	if (!t)
		return;
	free(t->nodes);
	free(t);
}
