/* rtsh — a mesh's triangle tree (mesh.h).
 *
 * bvh.c builds a binary tree over the triangles with binned SAH and
 * spatial splits (a triangle cut by a split plane goes to both sides, each
 * with the box of its part there: tri_chop), costing a leaf by the blocks
 * of four it needs and a node visit by MESH_TRAVERSE blocks. The tree is
 * then made 8 wide (bvh2_gather) and laid out depth first: each node, then
 * its subtrees in order, and each leaf's triangles as blocks of four
 * (mesh_tri4) in the order the leaves are met, so that a walk reads memory
 * mostly forward.
 */
#include <float.h>
#include <stdlib.h>
#include <string.h>

#include "core/bvh/bvh.h"
#include "rtsh/mesh.h"

/* SAH cost of a node visit in block tests: 8-wide nodes cost about two
 * 4-wide ones (measured on the bunny's rays, bench/README.md). */
#define MESH_TRAVERSE 0.75
/* Leaves of at most 4 blocks while a split pays. */
#define MESH_LEAF_MAX 16
/* References spatial splits may add, a share of the triangles. */
#define MESH_SPLIT_BUDGET 0.25

/* A float <= v and a float >= v, and one float step further out: the
 * bounds of a point computed in double. */
static float down(double v)
{
	float f = (float)v;
	if ((double)f > v)
		f -= fabsf(f) * 0x1p-23f + 0x1p-149f;
	return f;
}

static float up(double v)
{
	float f = (float)v;
	if ((double)f < v)
		f += fabsf(f) * 0x1p-23f + 0x1p-149f;
	return f;
}

static inline void grow(double lo[3], double hi[3], const double q[3])
{
	for (int i = 0; i < 3; i++) {
		lo[i] = q[i] < lo[i] ? q[i] : lo[i];
		hi[i] = q[i] > hi[i] ? q[i] : hi[i];
	}
}

/* Where the plane x[a] = c crosses the segment u v (u[a] != v[a]). */
static void cross_at(const double *u, const double *v, int a, double c, double q[3])
{
	double f = (c - u[a]) / (v[a] - u[a]);
	for (int i = 0; i < 3; i++)
		q[i] = u[i] + (v[i] - u[i]) * f;
	q[a] = c;
}

/* The parts of triangle id between consecutive planes pos[0..n] across
 * axis a (bvh.h's chop). Its corners sorted along a, each plane strictly
 * inside the triangle crosses the long edge and one of the short ones
 * (computed once, shared by the parts on both sides); a part is bounded by
 * the crossings of its two planes and the corners between them. The
 * crossings are computed in double, rounded outward and one float step
 * more off axis a (on a they are the planes themselves, and the corners'
 * own floats), then each part is intersected with its box on entry. */
static void tri_chop(const void *ctx, uint32_t id, int a, const float *pos, int n, bvh_fbox *part)
{
	const mesh *m = ctx;
	const uint32_t *t = m->tri[id];
	double c[3][3];
	for (int k = 0; k < 3; k++)
		for (int i = 0; i < 3; i++)
			c[k][i] = m->p[t[k]][i];
	/* sort the corners along a */
	int o0 = 0, o1 = 1, o2 = 2, x;
	if (c[o1][a] < c[o0][a])
		x = o0, o0 = o1, o1 = x;
	if (c[o2][a] < c[o1][a])
		x = o1, o1 = o2, o2 = x;
	if (c[o1][a] < c[o0][a])
		x = o0, o0 = o1, o1 = x;
	const double *v0 = c[o0], *v1 = c[o1], *v2 = c[o2];
	double lo[3], hi[3], q[3];
	for (int i = 0; i < n; i++) {
		double p0 = pos[i], p1 = pos[i + 1];
		for (int j = 0; j < 3; j++) {
			lo[j] = INFINITY;
			hi[j] = -INFINITY;
		}
		for (int k = 0; k < 3; k++)
			if (c[k][a] >= p0 && c[k][a] <= p1)
				grow(lo, hi, c[k]);
		for (int e = 0; e < 2; e++) {
			double pl = e ? p1 : p0;
			if (!(v0[a] < pl && pl < v2[a]))
				continue;
			cross_at(v0, v2, a, pl, q);
			grow(lo, hi, q);
			if (pl < v1[a])
				cross_at(v0, v1, a, pl, q);
			else if (pl > v1[a])
				cross_at(v1, v2, a, pl, q);
			else
				continue; /* the corner v1 itself, counted above */
			grow(lo, hi, q);
		}
		bvh_fbox *bx = &part[i];
		for (int j = 0; j < 3; j++) {
			float l = down(lo[j]), h = up(hi[j]);
			if (j != a) {
				l -= fabsf(l) * 0x1p-23f + 0x1p-149f;
				h += fabsf(h) * 0x1p-23f + 0x1p-149f;
			}
			bx->lo[j] = l > bx->lo[j] ? l : bx->lo[j];
			bx->hi[j] = h < bx->hi[j] ? h : bx->hi[j];
		}
		if (!(lo[0] <= hi[0])) /* nothing of the triangle here */
			for (int j = 0; j < 3; j++) {
				bx->lo[j] = INFINITY;
				bx->hi[j] = -INFINITY;
			}
	}
}

typedef struct emitter_state {
	mesh *m;
	const bvh2 *t;
	uint32_t nodes, blocks;
	bool too_many; /* more nodes than MESH_MAX_NODES */
} emitter_state;

static void empty_child(mesh_node *n, int k)
{
	for (int a = 0; a < 3; a++) {
		n->b[MESH_LO(a)][k] = INFINITY;
		n->b[MESH_HI(a)][k] = -INFINITY;
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
		n->b[MESH_LO(a)][k] = bx->lo[a];
		n->b[MESH_HI(a)][k] = bx->hi[a];
	}
}

/* The wide node for binary node n2 and, depth first, everything below. */
static uint32_t emit_node(emitter_state *e, uint32_t n2)
{
	bvh_slot s[MESH_WIDTH];
	int cnt = bvh2_gather(e->t, n2, MESH_WIDTH, s);
	uint32_t ni = e->nodes++;
	if (ni >= MESH_MAX_NODES)
		e->too_many = true; /* (its offset would read as a leaf: reported when done) */
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
	return (uint32_t)(ni * sizeof(mesh_node));
}

/* Blocks a leaf of `count` references takes. */
static uint32_t blocks_of(uint32_t meta)
{
	return meta ? ((meta & ~BVH_LEAF) + 3) / 4 : 0;
}

bool mesh_build_tree(mesh *m, const atomic_bool *cancel, rt_error *err)
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
	bvh_build_opts o = {.block = 4, .trav = MESH_TRAVERSE, .leaf_max = MESH_LEAF_MAX, .chop = tri_chop, .ctx = m,
	                    .split_budget = MESH_SPLIT_BUDGET, .cancel = cancel};
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
	emitter_state e = {m, &t, 0, 0, false};
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
	if (e.too_many)
		return rt_error_set(err, "%s: too many triangles (%u) for one model's tree", m->path, m->ntris);
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
