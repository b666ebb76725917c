/* rtsh — the bounding volume hierarchy over a world's bounded primitives. */
#ifndef RTSH_BVH_H
#define RTSH_BVH_H

#include <stddef.h>
#include <stdint.h>

#include "rtsh/error.h"
#include "rtsh/world.h"

#define BVH_MAX_DEPTH 96

/* A node in the flat array. An inner node's left child is the next node;
 * `right` is the index of its right child and `count` is 0. A leaf holds
 * prims[first .. first+count). */
typedef struct bvh_node {
	box b;
	uint32_t first_or_right;
	uint16_t count;
	uint16_t axis;
} bvh_node;

struct bvh {
	bvh_node *nodes;
	size_t nnodes;
	int depth;
};

/* Builds the tree over prims[0..n) with their world bounds, reordering prims
 * (and bounds) into tree order: binned SAH (Wald, "On fast construction of
 * SAH-based bounding volume hierarchies", 2007). NULL when out of memory. */
bvh *bvh_build(prim *prims, box *bounds, size_t n, rt_error *err);
void bvh_free(bvh *t);

#endif
