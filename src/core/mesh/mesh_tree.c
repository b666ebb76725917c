/* rtsh — a mesh's triangle tree (mesh.h).
 *
 * bvh.c builds a binary tree over the triangles with binned SAH and
 * spatial splits (a triangle cut by a split plane goes to both sides, each
 * with the box of its part there: tri_clip), costing a leaf by the blocks
 * of four it needs and a node visit by MESH_TRAVERSE blocks. The tree is
 * then made 8 wide (bvh2_gather) and laid out depth first: each node, then
 * its subtrees in order, and each leaf's triangles as blocks of four
 * (mesh_tri4) in the order the leaves are met, so that a walk reads memory
 * mostly forward.
 */
#include <float.h>
#include <stdlib.h>
#include <string.h>

#include "core/bvh.h"
#include "rtsh/mesh.h"

/* SAH cost of a node visit in block tests: 8-wide nodes cost about two
 * 4-wide ones (measured on the bunny's rays, bench/README.md). */
#define MESH_TRAVERSE 0.75
/* Leaves of at most 4 blocks while a split pays. */
#define MESH_LEAF_MAX 16
/* References spatial splits may add, a share of the triangles. */
#define MESH_SPLIT_BUDGET 0.25

static float down(double v)
{
	float f = (float)v;
	if ((double)f > v)
		f = nextafterf(f, -INFINITY);
	return f;
}

static float up(double v)
{
	float f = (float)v;
	if ((double)f < v)
		f = nextafterf(f, INFINITY);
	return f;
}

static void grow(double lo[3], double hi[3], const double q[3])
{
	for (int i = 0; i < 3; i++) {
		lo[i] = q[i] < lo[i] ? q[i] : lo[i];
		hi[i] = q[i] > hi[i] ? q[i] : hi[i];
	}
}

/* The part of triangle id within [lo, hi] on axis a: its corners there and
 * where its edges cross the two planes, in double, rounded outward and (off
 * axis a) one float step more; then intersected with *bx (what the triangle's
 * reference already held). */
static bool tri_clip(const void *ctx, uint32_t id, int a, float lo, float hi, bvh_fbox *bx)
{
	const mesh *m = ctx;
	const uint32_t *t = m->tri[id];
	double p[3][3];
	for (int k = 0; k < 3; k++)
		for (int c = 0; c < 3; c++)
			p[k][c] = m->p[t[k]][c];
	double blo[3] = {INFINITY, INFINITY, INFINITY}, bhi[3] = {-INFINITY, -INFINITY, -INFINITY};
	for (int k = 0; k < 3; k++) {
		const double *u = p[k], *v = p[(k + 1) % 3];
		if (u[a] >= lo && u[a] <= hi)
			grow(blo, bhi, u);
		for (int s = 0; s < 2; s++) {
			double c = s ? hi : lo;
			if (!((u[a] < c && v[a] > c) || (u[a] > c && v[a] < c)))
				continue;
			double f = (c - u[a]) / (v[a] - u[a]), q[3];
			for (int i = 0; i < 3; i++)
				q[i] = u[i] + (v[i] - u[i]) * f;
			q[a] = c;
			grow(blo, bhi, q);
		}
	}
	if (!(blo[0] <= bhi[0]))
		return false;
	for (int i = 0; i < 3; i++) {
		/* on axis a the bounds are corners' floats or the planes: exact */
		float l = i == a ? down(blo[i]) : nextafterf(down(blo[i]), -INFINITY);
		float h = i == a ? up(bhi[i]) : nextafterf(up(bhi[i]), INFINITY);
		bx->lo[i] = l > bx->lo[i] ? l : bx->lo[i];
		bx->hi[i] = h < bx->hi[i] ? h : bx->hi[i];
		if (!(bx->lo[i] <= bx->hi[i]))
			return false;
	}
	return true;
}

typedef struct emitter_state {
	mesh *m;
	const bvh2 *t;
	uint32_t nodes, blocks;
} emitter_state;

static void empty_child(mesh_node *n, int k)
{
	for (int a = 0; a < 3; a++) {
		n->b[BVH_LO_X + a][k] = INFINITY;
		n->b[BVH_HI_X + a][k] = -INFINITY;
	}
	n->child[k] = MESH_LEAF; /* never entered: no blocks are read */
}

/* The blocks of a leaf of the binary tree; returns its reference. */
static uint32_t emit_leaf(emitter_state *e, uint32_t first, uint32_t count)
{
	mesh *m = e->m;
	uint32_t b0 = e->blocks;
	for (uint32_t j = 0; j < count; j += 4, e->blocks++) {
		mesh_tri4 *q = &m->blk[e->blocks];
		for (uint32_t l = 0; l < 4; l++) {
			uint32_t id = e->t->ids[first + (j + l < count ? j + l : count - 1)];
			const uint32_t *ti = m->tri[id];
			m->btri[e->blocks][l] = id;
			for (int c = 0; c < 3; c++)
				for (int a = 0; a < 3; a++)
					q->v[3 * c + a][l] = m->p[ti[c]][a];
		}
	}
	return MESH_LEAF | (e->blocks - b0 - 1) << MESH_LEAF_SHIFT | b0;
}

static void set_child(mesh_node *n, int k, const bvh_fbox *bx)
{
	for (int a = 0; a < 3; a++) {
		n->b[BVH_LO_X + a][k] = bx->lo[a];
		n->b[BVH_HI_X + a][k] = bx->hi[a];
	}
}

/* The wide node for binary node n2 and, depth first, everything below. */
static uint32_t emit_node(emitter_state *e, uint32_t n2)
{
	bvh_slot s[MESH_WIDTH];
	int cnt = bvh2_gather(e->t, n2, MESH_WIDTH, s);
	uint32_t ni = e->nodes++;
	mesh_node *n = &e->m->nodes[ni];
	for (int k = cnt; k < MESH_WIDTH; k++)
		empty_child(n, k);
	for (int k = 0; k < cnt; k++) {
		uint32_t count = s[k].meta & ~BVH_LEAF;
		if (s[k].meta && count == 0) {
			empty_child(n, k);
			continue;
		}
		set_child(n, k, &s[k].box);
		uint32_t ref = s[k].meta ? emit_leaf(e, s[k].child, count) : emit_node(e, s[k].child);
		e->m->nodes[ni].child[k] = ref; /* (no pointer kept across the recursion) */
	}
	return ni;
}

/* Blocks a leaf of `count` references takes. */
static uint32_t blocks_of(uint32_t meta)
{
	return meta ? ((meta & ~BVH_LEAF) + 3) / 4 : 0;
}

bool mesh_build_tree(mesh *m, rt_error *err)
{
	box *bounds = malloc((size_t)(m->ntris ? m->ntris : 1) * sizeof *bounds);
	if (!bounds)
		return rt_error_set(err, "%s: out of memory building the triangle tree", m->path);
	for (uint32_t t = 0; t < m->ntris; t++) {
		box b = {v3(INFINITY, INFINITY, INFINITY), v3(-INFINITY, -INFINITY, -INFINITY)};
		for (int k = 0; k < 3; k++) {
			const float *p = m->p[m->tri[t][k]];
			b = box_add(b, v3(p[0], p[1], p[2]));
		}
		bounds[t] = b;
	}
	bvh_build_opts o = {.block = 4, .trav = MESH_TRAVERSE, .leaf_max = MESH_LEAF_MAX, .clip = tri_clip, .ctx = m,
	                    .split_budget = MESH_SPLIT_BUDGET};
	bvh2 t;
	rt_error e2 = {0};
	bool ok = bvh2_build(bounds, m->ntris, &o, &t, &e2);
	free(bounds);
	if (!ok)
		return rt_error_set(err, "%s: %s", m->path, e2.msg);
	/* count what the wide tree takes: a node per binary node at most, and
	 * one for a root that is a leaf */
	size_t nblk = blocks_of(t.root_meta);
	for (size_t i = 0; i < t.nnodes; i++)
		nblk += blocks_of(t.nodes[i].meta[0]) + blocks_of(t.nodes[i].meta[1]);
	if (nblk >= MESH_MAX_BLOCKS) {
		bvh2_free(&t);
		return rt_error_set(err, "%s: too many triangles (%u) for one model's tree", m->path, m->ntris);
	}
	size_t nn = t.nnodes + 1;
	m->nodes = aligned_alloc(64, (nn * sizeof *m->nodes + 63) / 64 * 64);
	m->blk = aligned_alloc(64, ((nblk ? nblk : 1) * sizeof *m->blk + 63) / 64 * 64);
	m->btri = malloc((nblk ? nblk : 1) * sizeof *m->btri);
	if (!m->nodes || !m->blk || !m->btri) {
		bvh2_free(&t);
		return rt_error_set(err, "%s: out of memory building the triangle tree", m->path);
	}
	emitter_state e = {m, &t, 0, 0};
	if (t.root_meta) {
		/* one leaf (or none): a root node that holds it alone */
		mesh_node *n = &m->nodes[e.nodes++];
		for (int k = 0; k < MESH_WIDTH; k++)
			empty_child(n, k);
		if (t.root_meta & ~BVH_LEAF) {
			set_child(n, 0, &t.bounds);
			n->child[0] = emit_leaf(&e, t.root, t.root_meta & ~BVH_LEAF);
		}
	} else {
		emit_node(&e, t.root);
	}
	m->nnodes = e.nodes;
	m->nblk = e.blocks;
	m->nrefs = (uint32_t)t.nrefs;
	bvh2_free(&t);
	if (m->nnodes < nn) {
		mesh_node *fit = aligned_alloc(64, (m->nnodes * sizeof *fit + 63) / 64 * 64);
		if (fit) {
			memcpy(fit, m->nodes, m->nnodes * sizeof *fit);
			free(m->nodes);
			m->nodes = fit;
		}
	}
	return true;
}
