/* rtsh — the bounding volume hierarchy over a world's bounded primitives.
 *
 * Layout (one 64-byte cache line per node): a node holds the boxes of its
 * two children, so one load gives both slab tests (done two at a time in
 * double precision, world.c) and the children are visited nearest first by
 * their actual entry distances. Boxes are stored as floats rounded outward,
 * so each float box contains the exact double-precision bounds of what is
 * below it: the tree can only visit too much, never miss. Leaves are not
 * nodes: a child reference with BVH_LEAF set in `meta` names a run of
 * primitives. Nodes are in depth-first order, node 0 the root.
 */
#ifndef RTSH_BVH_H
#define RTSH_BVH_H

#include <stddef.h>
#include <stdint.h>

#include "rtsh/error.h"
#include "rtsh/world.h"

/* Deepest tree the builder makes: the traversal stacks are this deep. */
#define BVH_MAX_DEPTH 96
/* meta[k]: BVH_LEAF | count for a leaf child, 0 for an inner node. */
#define BVH_LEAF 0x80000000u
#define BVH_MAX_PRIMS (BVH_LEAF - 1)

/* Child boxes: b[BVH_LO_X + axis][k] is the low bound of child k on axis,
 * b[BVH_HI_X + axis][k] its high bound. */
enum { BVH_LO_X = 0, BVH_HI_X = 3 };

typedef struct bvh_node {
	float b[6][2];      /* lo x, lo y, lo z, hi x, hi y, hi z; two children each */
	uint32_t child[2];  /* inner: node index; leaf: first primitive */
	uint32_t meta[2];   /* inner: 0; leaf: BVH_LEAF | primitive count */
} bvh_node;

struct bvh {
	bvh_node *nodes; /* 64-byte aligned; none when the root is a leaf */
	size_t nnodes;
	uint32_t root_meta; /* the root as a child reference: BVH_LEAF | n when */
	uint32_t root;      /* the whole tree is one leaf, else 0 and node 0 */
	int depth;
	size_t leaves;
};

/* Builds the tree over n primitives with world bounds bounds[0..n): binned
 * SAH (Wald, "On fast construction of SAH-based bounding volume hierarchies",
 * 2007). order[i] receives the primitive that goes to place i of tree order
 * (leaves index primitives in that order). NULL (err set) when out of memory
 * or n is too large. */
bvh *bvh_build(const box *bounds, size_t n, uint32_t *order, rt_error *err);
void bvh_free(bvh *t);

/* For the benchmark (bench/bench.c): the rays world_intersect and
 * world_occluded traced in the calling thread since the last reset (a
 * thread-local count, so no cache line is shared between threads), and the
 * bytes a world holds beyond its struct. */
void world_rays_reset(void);
uint64_t world_rays_traced(void);
size_t world_memory(const world *w);

#endif
