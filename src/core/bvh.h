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

#include <stddef.h>
#include <stdint.h>

#include "rtsh/error.h"
#include "rtsh/world.h"

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

struct bvh {
	bvh_node *nodes;    /* 64-byte aligned; none when the root is a leaf */
	size_t nnodes;
	uint32_t root;      /* the root as a child reference: node 0, or the */
	uint32_t root_meta; /* one leaf of all primitives (BVH_LEAF | n) */
	int depth;          /* of the binary tree */
	size_t leaves;
};

/* Builds the tree over n primitives with world bounds bounds[0..n) and
 * intersection costs costs[0..n) (relative to a world-space sphere; NULL:
 * all 1): binned SAH (Wald, "On fast construction of SAH-based bounding
 * volume hierarchies", 2007). order[i] receives the primitive that goes to
 * place i of tree order (leaves index primitives in that order). NULL (err
 * set) when out of memory or n is too large. */
bvh *bvh_build(const box *bounds, const float *costs, size_t n, uint32_t *order, rt_error *err);
void bvh_free(bvh *t);

/* For the benchmark (bench/bench.c): the rays world_intersect and
 * world_occluded traced in the calling thread since the last reset (a
 * thread-local count, so no cache line is shared between threads), and the
 * bytes a world holds beyond its struct. */
void world_rays_reset(void);
uint64_t world_rays_traced(void);
size_t world_memory(const world *w);

#endif
