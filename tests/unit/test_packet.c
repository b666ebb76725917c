/* rtsh — packets of rays (packet.h) against single rays: the same nearest
 * hit to the bit (its distance, its primitive or plane, what the test left,
 * and the whole hit record world_finish makes from it), and the same
 * answer to "is anything in the way", over many packets on several scenes:
 *   - the benchmark grid, the showcase (every shape kind: planes, cylinders,
 *     cones, cubes, discs, rectangles, triangles), the tori, the models of
 *     instances.rt, and the bunny from ../shared when it is there;
 *   - camera packets (4 x 4 pixels), packets of narrow cones from one
 *     origin, shadow packets from the camera hits toward a light;
 *   - a scene of ties: two spheres in one place, cubes sharing a face, two
 *     triangles sharing an edge, a sphere resting on a plane, with rays aimed
 *     exactly at the shared edge, the corners and the point of contact;
 *   - ties that the packet meets in the other order than the single ray:
 *     a sphere and another sphere or a model in two leaves, both at exactly
 *     t = 9 on one ray, whose packets start inside the second one's box;
 *   - a lone model's own packets (mesh_intersect_world_packet) against
 *     its single rays, the slot and barycentrics too, each ray to its own
 *     tmax: the bunny, the fence's cut-outs, spot turned over two planes,
 *     and a model of ties (copies of a triangle in different blocks, a
 *     grid's shared edges and corners); camera packets, rays from the hits
 *     toward the light (the self-hit guard), narrow and wide cones, zero
 *     components, origins apart, short packets;
 * and every vector unit the triangle walk has (mesh_isa_force), as
 * test_world_ray_entry does for single rays. */
#include "testutil.h"

#include <unistd.h>

#include "core/bvh/bvh.h"
#include "core/prim_hit.h"
#include "rtsh/generate.h"
#include "rtsh/mesh.h"
#include "rtsh/packet.h"
#include "rtsh/rtfile.h"
#include "rtsh/world.h"

static long packets, rays_hit;

static void same_double(double a, double b, const char *what)
{
	if (memcmp(&a, &b, sizeof a) != 0)
		fail_msg("%s: packet %.17g, single %.17g", what, a, b);
}

static void same_vec(vec3 a, vec3 b, const char *what)
{
	same_double(a.x, b.x, what);
	same_double(a.y, b.y, what);
	same_double(a.z, b.z, what);
}

/* Two hit records field by field, to the bit (u, v, dpdu, dpdv where the
 * single ray's has them). */
static void same_hit(const hit *hp, const hit *hs)
{
	same_double(hp->t, hs->t, "t");
	same_vec(hp->p, hs->p, "p");
	same_vec(hp->n, hs->n, "n");
	same_vec(hp->local, hs->local, "local");
	assert_int_equal(hp->front, hs->front);
	assert_int_equal(hp->object, hs->object);
	assert_int_equal(hp->mat, hs->mat);
	assert_int_equal(hp->has_uv, hs->has_uv);
	if (hs->has_uv) {
		same_double(hp->u, hs->u, "u");
		same_double(hp->v, hs->v, "v");
		same_vec(hp->dpdu, hs->dpdu, "dpdu");
		same_vec(hp->dpdv, hs->dpdv, "dpdv");
	}
}

/* world_intersect_packet's hit records (the packet's own, made two rays at
 * a time on planes and spheres) against world_intersect_coherent's, for
 * r[0..n) with tmin < t < tmax. */
static void check_records(const world *w, const ray *r, int n, double tmin, double tmax)
{
	hit hp[PACKET_MAX];
	bool fp[PACKET_MAX];
	memset(hp, 0, sizeof hp);
	world_intersect_packet(w, n, r, tmin, tmax, hp, fp);
	for (int i = 0; i < n; i++) {
		hit hs;
		memset(&hs, 0, sizeof hs);
		bool fs = world_intersect_coherent(w, &r[i], tmin, tmax, &hs);
		assert_int_equal(fp[i], fs);
		if (fs)
			same_hit(&hp[i], &hs);
	}
}

/* Packet against single rays for r[0..n): nearest hits, hit records, and
 * shadow queries to a fraction of each hit's distance and to `lamp`. */
static void check_packet(const world *w, const ray *r, int n, vec3 lamp)
{
	trace_hit tp[PACKET_MAX];
	bool fp[PACKET_MAX];
	world_trace_packet(w, n, r, 0.0, INFINITY, tp, fp);
	packets++;
	check_records(w, r, n, 0.0, INFINITY);
	ray sr[PACKET_MAX];
	double smax[PACKET_MAX];
	for (int i = 0; i < n; i++) {
		trace_hit ts;
		bool fs = world_trace_coherent(w, &r[i], 0.0, INFINITY, &ts);
		assert_int_equal(fp[i], fs);
		sr[i] = r[i];
		smax[i] = INFINITY;
		if (!fs)
			continue;
		rays_hit++;
		same_double(tp[i].t, ts.t, "t");
		assert_ptr_equal(tp[i].prim, ts.prim);
		assert_ptr_equal(tp[i].plane, ts.plane);
		if (ts.prim && (ts.prim->tag == PRIM_SHAPE || ts.prim->tag == PRIM_MESH)) /* spheres, triangles leave none */
			same_vec(tp[i].nl, ts.nl, "nl");
		hit hp, hs;
		memset(&hp, 0, sizeof hp);
		memset(&hs, 0, sizeof hs);
		world_finish(w, &r[i], &tp[i], &hp);
		world_finish(w, &r[i], &ts, &hs);
		same_hit(&hp, &hs);
		/* a shadow ray from just off the hit toward the light */
		vec3 p = v3_add(hs.p, v3_scale(hs.n, hs.front ? 1e-6 : -1e-6));
		vec3 to = v3_sub(lamp, p);
		sr[i] = (ray){p, v3_norm(to)};
		smax[i] = v3_len(to);
	}
	/* along the camera rays: up to half, all of and beyond the hit */
	for (int f = 0; f < 3; f++) {
		double tm[PACKET_MAX];
		bool op[PACKET_MAX];
		for (int i = 0; i < n; i++)
			tm[i] = fp[i] ? tp[i].t * (f == 0 ? 0.5 : f == 1 ? 1.0 : 2.0) : INFINITY;
		world_occluded_packet(w, n, r, 0.0, tm, op);
		for (int i = 0; i < n; i++)
			assert_int_equal(op[i], world_occluded(w, &r[i], 0.0, tm[i]));
	}
	bool op[PACKET_MAX];
	world_occluded_packet(w, n, sr, 0.0, smax, op);
	for (int i = 0; i < n; i++)
		assert_int_equal(op[i], world_occluded(w, &sr[i], 0.0, smax[i]));
}

/* Every 4 x 4 block of camera rays of a W x H image (the last blocks of a
 * row or column short: packets of 1 to 16). */
static void camera_packets(const world *w, int W, int H, vec3 lamp)
{
	for (int y0 = 0; y0 < H; y0 += 4)
		for (int x0 = 0; x0 < W; x0 += 4) {
			ray r[PACKET_MAX];
			int n = 0;
			for (int y = y0; y < y0 + 4 && y < H; y++)
				for (int x = x0; x < x0 + 4 && x < W; x++)
					r[n++] = cam_ray(&w->cam, x + 0.5, y + 0.5, W, H);
			check_packet(w, r, n, lamp);
		}
}

/* Narrow cones of rays from random points toward random targets in the
 * box lo..hi. */
static void cone_packets(const world *w, vec3 lo, vec3 hi, int count, uint64_t seed, vec3 lamp)
{
	test_rng g = {seed};
	vec3 ext = v3_sub(hi, lo);
	for (int k = 0; k < count; k++) {
		vec3 o = v3_add(lo, v3(ext.x * (3 * trand(&g) - 1), ext.y * (3 * trand(&g) - 1), ext.z * (3 * trand(&g) - 1)));
		vec3 at = v3_add(lo, v3(ext.x * trand(&g), ext.y * trand(&g), ext.z * trand(&g)));
		double spread = 0.002 + 0.05 * trand(&g);
		int n = 1 + (int)(trand(&g) * PACKET_MAX) % PACKET_MAX;
		ray r[PACKET_MAX];
		for (int i = 0; i < n; i++) {
			vec3 j = v3((trand(&g) - 0.5) * spread, (trand(&g) - 0.5) * spread, (trand(&g) - 0.5) * spread);
			r[i] = (ray){o, v3_norm(v3_add(v3_norm(v3_sub(at, o)), j))};
			if (k % 3 == 2) /* origins a little apart: each ray's own height over the planes */
				r[i].o = v3_add(o, v3_scale(j, 0.1));
		}
		check_packet(w, r, n, lamp);
		check_records(w, r, n, 1e-3, 1e3);
	}
}

/* The scene of text (named name in messages) and its world; the test
 * fails on a load or build error. */
static world *world_of_text(const char *text, const char *name, scene **s)
{
	rt_error err;
	*s = rt_load_string(text, strlen(text), name, NULL, &err);
	if (!*s)
		fail_msg("%s: %s", name, err.msg);
	world *w = world_build(*s, &err);
	if (!w)
		fail_msg("%s: %s", name, err.msg);
	return w;
}

/* The scene at path on every vector unit; false when it is absent. */
static bool check_scene(const char *path, int W, int H, int cones)
{
	if (access(path, R_OK) != 0)
		return false;
	rt_error err;
	scene *s = rt_load_file(path, NULL, &err);
	if (!s)
		fail_msg("%s: %s", path, err.msg);
	world *w = world_build(s, &err);
	if (!w)
		fail_msg("%s: %s", path, err.msg);
	vec3 lamp = w->nlights ? w->lights[0].pos : v3(0, 10, 0);
	for (int isa = MESH_ISA_SCALAR; isa <= MESH_ISA_BEST; isa++) {
		if (!mesh_isa_force((mesh_isa)isa))
			continue;
		camera_packets(w, W, H, lamp);
		box b = w->bounds;
		if (!box_is_empty(b))
			cone_packets(w, b.lo, b.hi, cones, 17 + (uint64_t)isa, lamp);
	}
	assert_true(mesh_isa_force(MESH_ISA_BEST));
	world_free(w);
	scene_free(s);
	return true;
}

static void test_scenes(void **state)
{
	(void)state;
	const char *paths[] = {"scenes/grid.rt",   "scenes/showcase.rt",  "scenes/tori.rt",    "scenes/instances.rt",
	                       "scenes/final.rt",  "scenes/classic42.rt", "scenes/cornell.rt", "scenes/fence.rt",
	                       "scenes/spot.rt"};
	for (size_t i = 0; i < sizeof paths / sizeof *paths; i++) {
		long before = rays_hit;
		assert_true(check_scene(paths[i], 96, 54, 300));
		assert_true(rays_hit - before > 1000);
	}
}

static void test_bunny(void **state)
{
	(void)state;
	const char *path = "../shared/models/stanford-bunny.obj";
	if (access(path, R_OK) != 0) {
		print_message("skipped: %s is absent\n", path);
		skip();
	}
	char text[256];
	snprintf(text, sizeof text, "C 0,0.1,-3.2 0,0,1 40\nL -2,3,-4 0.8 255,255,255\nmesh %s 0,0,0 0,1,0 1 200,200,200\n", path);
	scene *s;
	world *w = world_of_text(text, "bunny", &s);
	for (int isa = MESH_ISA_SCALAR; isa <= MESH_ISA_BEST; isa++)
		if (mesh_isa_force((mesh_isa)isa))
			camera_packets(w, 64, 48, w->lights[0].pos);
	assert_true(mesh_isa_force(MESH_ISA_BEST));
	world_free(w);
	scene_free(s);
}

/* Shadow packets whose rays go apart in a big tree (the 1M-sphere scene's
 * case, where the packet's interval lets through children no ray enters):
 * 4 x 4 blocks of pixels S apart, so that the lit points are far apart,
 * toward each light in turn. Each ray must get its own answer, and be
 * counted once. */
static void shadow_block(const world *w, int W, int H, int S, int x0, int y0, vec3 lamp, long *blocked, long *lit)
{
	ray sr[PACKET_MAX];
	double smax[PACKET_MAX];
	int n = 0;
	for (int j = 0; j < PACKET_MAX; j++) {
		ray r = cam_ray(&w->cam, x0 + S * (j % 4) + 0.5, y0 + S * (j / 4) + 0.5, W, H);
		hit h;
		if (!world_intersect(w, &r, 0.0, INFINITY, &h))
			continue;
		vec3 p = v3_add(h.p, v3_scale(h.n, h.front ? 1e-6 : -1e-6));
		vec3 to = v3_sub(lamp, p);
		sr[n] = (ray){p, v3_norm(to)};
		smax[n++] = v3_len(to);
	}
	bool op[PACKET_MAX];
	world_rays_reset();
	world_occluded_packet(w, n, sr, 0.0, smax, op);
	assert_int_equal(world_rays_traced(), (uint64_t)n);
	for (int i = 0; i < n; i++) {
		assert_int_equal(op[i], world_occluded(w, &sr[i], 0.0, smax[i]));
		*blocked += op[i];
		*lit += !op[i];
	}
}

static void test_split_shadows(void **state)
{
	(void)state;
	gen_opts o = {.spheres_only = true};
	rt_error err;
	scene *s = scene_generate(30000, 1, &o, &err);
	if (!s)
		fail_msg("generate: %s", err.msg);
	world *w = world_build(s, &err);
	if (!w)
		fail_msg("world_build: %s", err.msg);
	assert_true(w->tree->nnodes >= 1024); /* a deep tree: 30k spheres */
	assert_true(w->nlights >= 2);
	enum { W = 160, H = 96, S = 3 };
	long blocked = 0, lit = 0, k = 0;
	for (int y0 = 0; y0 + 4 * S <= H; y0 += 2)
		for (int x0 = 0; x0 + 4 * S <= W; x0 += 2, k++)
			shadow_block(w, W, H, S, x0, y0, w->lights[k % (long)w->nlights].pos, &blocked, &lit);
	/* both answers, many times */
	assert_true(blocked > 500 && lit > 500);
	world_free(w);
	scene_free(s);
}

/* Ties: primitives at exactly the same distance, where the single ray keeps
 * the first it meets; the packet must keep the same one. */
static void test_ties(void **state)
{
	(void)state;
	const char *text = "C 0,2,-6 0,-0.2,1 60\n"
	                   "L 3,6,-4 0.8 255,255,255\n"
	                   "pl 0,0,0 0,1,0 200,200,200\n"
	                   "sp 0,1,0 2 255,0,0\n"       /* resting on the plane */
	                   "sp 0,1,0 2 0,255,0\n"       /* the same sphere again */
	                   "sp 3,1,0 1 0,0,255\n"
	                   "cu -3,1,0 0,1,0 1,1,1 255,255,0\n"
	                   "cu -3,2,0 0,1,0 1,1,1 0,255,255\n" /* sharing a face */
	                   "cu -3,1,0 0,1,0 1,1,1 255,0,255\n" /* the same cube */
	                   "tr 1,0,2 2,0,2 1.5,2,2 200,100,50\n"
	                   "tr 2,0,2 1.5,2,2 2.5,2,2 50,100,200\n" /* sharing an edge */
	                   "cy 0,3,0 0,1,0 1 1 100,100,100\n"
	                   "cy 0,3,0 0,1,0 1 1 100,200,100\n";
	scene *s;
	world *w = world_of_text(text, "ties", &s);
	vec3 lamp = w->lights[0].pos;
	camera_packets(w, 160, 90, lamp);
	/* rays aimed exactly at the shared edge, the cubes' corners and shared
	 * face, the contact of sphere and plane, from nearby origins */
	vec3 targets[] = {v3(1.75, 1, 2), v3(2, 0, 2), v3(1.5, 2, 2), v3(-2.5, 1.5, -0.5), v3(-3.5, 1.5, -0.5),
	                  v3(-2.5, 0.5, -0.5), v3(0, 0, 0), v3(0, 1, -1), v3(0, 3.5, -0.5), v3(-3, 1.5, 0)};
	test_rng g = {5};
	for (size_t k = 0; k < sizeof targets / sizeof *targets; k++)
		for (int rep = 0; rep < 40; rep++) {
			ray r[PACKET_MAX];
			vec3 o = v3(-1 + 2 * trand(&g), 2 + trand(&g), -6 - trand(&g));
			for (int i = 0; i < PACKET_MAX; i++) {
				vec3 at = targets[k];
				if (i > 0) /* the others along the edge or face, a little off */
					at = v3_add(at, v3((trand(&g) - 0.5) * 0.01, (trand(&g) - 0.5) * 0.01, 0));
				r[i] = (ray){o, v3_norm(v3_sub(at, o))};
			}
			check_packet(w, r, PACKET_MAX, lamp);
		}
	world_free(w);
	scene_free(s);
}

/* The leaf of w's tree that holds primitive p: the index of its first
 * primitive, or -1 when no leaf holds it. */
static long leaf_of(const world *w, const prim *p)
{
	size_t k = (size_t)(p - w->prims);
	const bvh *t = w->tree;
	if (t->root_meta & BVH_LEAF)
		return k < (t->root_meta & ~BVH_LEAF) ? (long)t->root : -1;
	for (size_t n = 0; n < t->nnodes; n++)
		for (int c = 0; c < BVH_WIDTH; c++) {
			uint32_t m = t->nodes[n].meta[c], first = t->nodes[n].child[c];
			if ((m & BVH_LEAF) && k >= first && k < first + (m & ~BVH_LEAF))
				return (long)first;
		}
	return -1;
}

/* The world's sphere of centre c and radius r (the test fails when there
 * is none). */
static const prim *sphere_at(const world *w, vec3 c, double r)
{
	for (size_t i = 0; i < w->nprims; i++)
		if (w->prims[i].tag == PRIM_SPHERE && v3_len(v3_sub(w->prims[i].u.sph.c, c)) == 0.0 && w->prims[i].u.sph.r == r)
			return &w->prims[i];
	fail_msg("no sphere at %g,%g,%g of radius %g", c.x, c.y, c.z, r);
	return NULL;
}

/* Packets of 2 to PACKET_MAX rays with the tie ray r0 in each lane in
 * turn; the others start inside Y's box (x in [-2, -1.25]), every other one
 * along d: the packet reaches Y's leaf before X's, where the single ray
 * meets X first. Each against the single rays (hits and records). */
static void tie_packets(const world *w, ray r0, vec3 d, test_rng *g)
{
	for (int n = 2; n <= PACKET_MAX; n++)
		for (int j = 0; j < n; j++) {
			ray r[PACKET_MAX];
			for (int i = 0; i < n; i++) {
				vec3 o = v3(-2 + 0.75 * trand(g), -1 + 6 * trand(g), -5 + 6 * trand(g));
				vec3 di = v3(0.5 + trand(g), 1 + 2 * trand(g), -1 - 2 * trand(g));
				r[i] = i == j ? r0 : (ray){o, i % 2 ? d : di};
			}
			check_packet(w, r, n, w->lights[0].pos);
			check_records(w, r, n, 1.0, 100.0);
		}
}

/* A tie that the packet meets in the other order than the single ray: the
 * packet must still keep the single ray's primitive. test_ties' ties lie in
 * one leaf, which both walks read in the same order; here they lie in two.
 *
 * Ray 0 goes from o0 = (-9,-18,18) along d = (1,2,-2) to P = (0,0,0) at
 * t = 9. Both spheres pass through P, and their centres lie ahead of it:
 * X at (4,0,-3), radius 5 (|(4,0,-3)| = 5, (4,0,-3) . d = 10 > 0) and Y at
 * (1,2,-2), radius 3 (|(1,2,-2)| = 3, . d = 9 > 0). With oc = o0 - c, every
 * step of sphere_hit is exact in integers:
 *   X: oc = (-13,-18,21), b = -91, c = 934 - 25 = 909, a = 9,
 *      disc = 8281 - 8181 = 100, q = 101, t = c / q = 909 / 101 = 9;
 *   Y: oc = (-10,-20,20), b = -90, c = 900 - 9 = 891,
 *      disc = 8100 - 8019 = 81, q = 99, t = 891 / 99 = 9.
 * The boxes: X's [-1,9] x [-5,5] x [-8,2], Y's [-2,4] x [-1,5] x [-5,1].
 * Ray 0 enters X's box at t = max(-1+9, (-5+18)/2, (2-18)/-2) = 8 and Y's at
 * max(-2+9, (-1+18)/2, (1-18)/-2) = 8.5: alone it meets X first and keeps
 * it (Y at the same t is not nearer).
 * The other rays of the packet start inside Y's box with x <= -1.25, before
 * X's box's low x, and d.x <= 1.5: the packet's interval bound is 0 for Y's
 * box (on every axis some ray starts past its near plane) and about
 * 0.25 / 1.5 for X's (on x every origin is before -1), so the packet meets
 * Y first. Without the test at the next double above ray 0's distance
 * (next_up2 in leaf_spheres) it would not offer X at all, and without the
 * tie flag (offer) it would keep Y: both give ray 0 Y's hit record instead
 * of X's (both checked to fail so). */
static void test_ties_across_leaves(void **state)
{
	(void)state;
	scene *s;
	/* Y first, so that the scene's order does not favour X; four smaller
	 * spheres inside each, of its centre, so that the tree splits the two
	 * apart (a node of more than 4 spheres is split, and each sphere's
	 * centroid goes with its own) */
	world *w = world_of_text("C 0,0,30 0,0,-1 60\nL 3,6,20 0.8 255,255,255\n"
	                         "sp 1,2,-2 6 255,0,0\nsp 4,0,-3 10 0,0,255\n"
	                         "sp 1,2,-2 1 255,255,0\nsp 1,2,-2 2 255,255,0\nsp 1,2,-2 3 255,255,0\n"
	                         "sp 1,2,-2 4 255,255,0\n"
	                         "sp 4,0,-3 2 0,255,255\nsp 4,0,-3 4 0,255,255\nsp 4,0,-3 6 0,255,255\n"
	                         "sp 4,0,-3 8 0,255,255\n",
	                         "ties across leaves", &s);
	const vec3 o0 = v3(-9, -18, 18), d = v3(1, 2, -2);
	const ray r0 = {o0, d};
	const prim *px = sphere_at(w, v3(4, 0, -3), 5), *py = sphere_at(w, v3(1, 2, -2), 3);
	/* the tie itself: each sphere alone at exactly t = 9 */
	double t = 0;
	assert_true(sphere_hit(px, &r0, 0.0, INFINITY, &t));
	same_double(t, 9.0, "X alone");
	assert_true(sphere_hit(py, &r0, 0.0, INFINITY, &t));
	same_double(t, 9.0, "Y alone");
	/* in two leaves (in one, both walks would read them in one order) */
	long lx = leaf_of(w, px), ly = leaf_of(w, py);
	assert_true(lx >= 0 && ly >= 0);
	assert_true(lx != ly);
	/* the single ray keeps X, whose box it enters first */
	trace_hit ts;
	assert_true(world_trace_coherent(w, &r0, 0.0, INFINITY, &ts));
	same_double(ts.t, 9.0, "single t");
	assert_ptr_equal(ts.prim, px);
	test_rng g = {71};
	long before = packets;
	tie_packets(w, r0, d, &g);
	assert_true(packets - before == PACKET_MAX * (PACKET_MAX + 1) / 2 - 1);
	world_free(w);
	scene_free(s);
}

/* Rays from a sphere's centre, which lies on zeros: origins equal as
 * doubles (one origin for the packet) whose zeros differ in sign from ray
 * to ray. There b = (o - c) . d is a zero whose sign the ray's own origin
 * gives, and sphere_hit's q takes it: the packet must not use the first
 * ray's. */
static void test_signed_zero_origins(void **state)
{
	(void)state;
	scene *s;
	world *w = world_of_text("C 0,2,-6 0,-0.2,1 60\nL 3,6,-4 0.8 255,255,255\nsp 0,0,0 2 255,0,0\n"
	                         "sp 0,1,0 1 0,255,0\nsp 3,0,0 1 0,0,255\n",
	                         "zeros", &s);
	test_rng g = {41};
	long before = rays_hit;
	for (int k = 0; k < 400; k++) {
		/* one octant a packet; the centre (0,0,0) or (0,1,0) */
		vec3 sg = v3(k & 1 ? -1 : 1, k & 2 ? -1 : 1, k & 4 ? -1 : 1);
		double cy = k & 8 ? 1.0 : 0.0;
		ray r[PACKET_MAX];
		for (int i = 0; i < PACKET_MAX; i++) {
			unsigned z = (unsigned)(trand(&g) * 8);
			r[i].o = v3(z & 1 ? -0.0 : 0.0, cy == 0.0 && z & 2 ? -0.0 : cy, z & 4 ? -0.0 : 0.0);
			r[i].d = v3_norm(v3(sg.x * (0.1 + trand(&g)), sg.y * (0.1 + trand(&g)), sg.z * (0.1 + trand(&g))));
		}
		check_packet(w, r, PACKET_MAX, w->lights[0].pos);
	}
	assert_true(rays_hit - before > 5000);
	world_free(w);
	scene_free(s);
}

/* Packets at the edges of the interval set-up (packet_prepare): origins
 * equal to the first ray's (a zero of either sign among them) and one
 * ulp off it; a direction component that is 0, -0, of the other sign, or
 * so small or large that its inverse is not a finite non-zero float, in one
 * ray of an otherwise coherent packet; components of one sign spread over
 * many magnitudes. Each packet must give the single rays' answers. */
static void test_prepare_edges(void **state)
{
	(void)state;
	rt_error err;
	scene *s = rt_load_file("scenes/grid.rt", NULL, &err);
	if (!s)
		fail_msg("grid: %s", err.msg);
	world *w = world_build(s, &err);
	if (!w)
		fail_msg("grid: %s", err.msg);
	vec3 lamp = w->lights[0].pos;
	static const double odd[] = {0.0, -0.0, 1e-300, -1e-300, 1e-40, -1e-40, 1e300, 1e-30};
	const int nodd = (int)(sizeof odd / sizeof *odd);
	test_rng g = {29};
	long before = rays_hit;
	for (int k = 0; k < 400; k++) {
		/* from above the grid (y = 0 is the ground), origins with zeros */
		vec3 o = v3(k % 3 == 0 ? 0.0 : -0.0, 3 + trand(&g), k % 2 ? 0.0 : -6 + trand(&g));
		vec3 at = v3(-4 + 8 * trand(&g), 0.4, -4 + 8 * trand(&g));
		vec3 d0 = v3_norm(v3_sub(at, o));
		ray r[PACKET_MAX];
		for (int i = 0; i < PACKET_MAX; i++) {
			vec3 d = v3_add(d0, v3((trand(&g) - 0.5) * 0.02, (trand(&g) - 0.5) * 0.02, (trand(&g) - 0.5) * 0.02));
			r[i] = (ray){o, d};
			if (i % 4 == 1) /* the same origin with the other zero */
				r[i].o.x = -r[i].o.x;
			if (k % 4 == 1 && i == 7) /* one ulp off */
				r[i].o.y = nextafter(r[i].o.y, INFINITY);
		}
		int j = 1 + (int)(trand(&g) * (PACKET_MAX - 1));
		switch (k % 5) {
		case 0: /* one odd component in one ray */
			r[j].d.x = odd[k / 5 % nodd];
			break;
		case 1: /* one ray's component of the other sign */
			r[j].d.z = -r[j].d.z;
			break;
		case 2: /* magnitudes spread over the packet, one sign */
			for (int i = 0; i < PACKET_MAX; i++)
				r[i].d.x = copysign(pow(10.0, -30.0 * trand(&g)), d0.x);
			break;
		case 3: /* the same direction throughout */
			for (int i = 0; i < PACKET_MAX; i++)
				r[i].d = d0;
			break;
		default: /* the same odd component in every ray */
			for (int i = 0; i < PACKET_MAX; i++)
				r[i].d.y = -odd[k / 5 % nodd];
		}
		check_packet(w, r, 1 + k % PACKET_MAX, lamp);
		check_packet(w, r, PACKET_MAX, lamp);
	}
	assert_true(rays_hit - before > 5000);
	world_free(w);
	scene_free(s);
}

/* --- a lone model: the triangle tree's own packets --- */

/* The packets mesh_intersect_world_packet traced, and the ties it reported
 * (check_model). */
static long model_traced, model_ties, model_occluded_traced;

/* mesh_intersect_world_packet itself against mesh_intersect_world_coherent
 * ray by ray, on the lone model of w, each ray to its own tmax: the beyond
 * of the single ray's hit, exactly it, or half of it. A ray with a tie is
 * the caller's to trace again: its answer is not compared, but whether it
 * hit at all is (the distance of a tie is the nearest). */
static void check_model(const world *w, const ray *r, int n, int turn)
{
	const prim_inst *in = &w->insts[w->prims[0].u.index];
	double ts[PACKET_MAX], tm[PACKET_MAX] = {0}, t[PACKET_MAX];
	uint32_t ss[PACKET_MAX], slot[PACKET_MAX];
	float bs[PACKET_MAX][3], b[PACKET_MAX][3];
	bool fs[PACKET_MAX];
	for (int i = 0; i < n; i++) {
		fs[i] = mesh_intersect_world_coherent(in->mesh, in->inv, &r[i], 0.0, INFINITY, &ts[i], &ss[i], bs[i]);
		int k = (turn + i) % 4;
		tm[i] = !fs[i] || k == 0 ? INFINITY : k == 1 ? ts[i] : k == 2 ? 0.5 * ts[i] : 2.0 * ts[i];
		if (tm[i] < INFINITY) /* again to that tmax */
			fs[i] = mesh_intersect_world_coherent(in->mesh, in->inv, &r[i], 0.0, tm[i], &ts[i], &ss[i], bs[i]);
	}
	/* shadow packets: whether anything lies on each ray up to its tmax */
	unsigned occ;
	if (mesh_occluded_world_packet(in->mesh, in->inv, n, r, 0.0, tm, &occ)) {
		model_occluded_traced++;
		for (int i = 0; i < n; i++)
			assert_int_equal(occ >> i & 1u, mesh_occluded_world(in->mesh, in->inv, &r[i], 0.0, tm[i]));
	}
	unsigned got, tie;
	/* each its own tmax, or (every other turn, when they are all
	 * the same) one for all */
	bool one = turn % 2 == 0;
	for (int i = 1; i < n && one; i++)
		one = tm[i] == tm[0];
	if (!mesh_intersect_world_packet(in->mesh, in->inv, n, r, 0.0, tm[0], one ? NULL : tm, t, slot, b, &got, &tie))
		return;
	model_traced++;
	for (int i = 0; i < n; i++) {
		assert_int_equal(got >> i & 1u, fs[i]);
		if (!fs[i])
			continue;
		same_double(t[i], ts[i], "model t");
		if (tie >> i & 1u) {
			model_ties++;
			continue;
		}
		assert_int_equal(slot[i], ss[i]);
		for (int k = 0; k < 3; k++)
			if (memcmp(&b[i][k], &bs[i][k], sizeof(float)) != 0)
				fail_msg("model b[%d]: packet %.9g, single %.9g", k, (double)b[i][k], (double)bs[i][k]);
	}
}

/* Packets on the lone model of w (and the planes beside it): camera
 * packets, narrow cones, wide ones (directions of both signs: the single
 * rays' way), and rays with odd components, through check_packet and
 * check_model. */
static void model_packets(const world *w, int W, int H, int cones, uint64_t seed)
{
	assert_true(w->nprims == 1 && w->prims[0].tag == PRIM_MESH);
	vec3 lamp = w->nlights ? w->lights[0].pos : v3(0, 10, 0);
	camera_packets(w, W, H, lamp);
	int turn = 0;
	for (int y0 = 0; y0 < H; y0 += 4)
		for (int x0 = 0; x0 < W; x0 += 4) {
			ray r[PACKET_MAX];
			int n = 0;
			for (int y = y0; y < y0 + 4 && y < H; y++)
				for (int x = x0; x < x0 + 4 && x < W; x++)
					r[n++] = cam_ray(&w->cam, x + 0.5, y + 0.5, W, H);
			check_model(w, r, n, turn++);
			/* from the hits toward the lamp: rays that start on the
			 * model, where its self-hit guard raises tmin */
			ray sr[PACKET_MAX];
			int m = 0;
			for (int i = 0; i < n; i++) {
				hit h;
				if (world_intersect(w, &r[i], 0.0, INFINITY, &h))
					sr[m++] = (ray){h.p, v3_sub(lamp, h.p)};
			}
			if (m > 0) {
				check_packet(w, sr, m, lamp);
				check_model(w, sr, m, turn);
			}
		}
	box b = w->bounds;
	cone_packets(w, b.lo, b.hi, cones, seed, lamp);
	test_rng g = {seed};
	vec3 ext = v3_sub(b.hi, b.lo);
	for (int k = 0; k < cones; k++) {
		vec3 o = v3_add(b.lo, v3(ext.x * (3 * trand(&g) - 1), ext.y * (3 * trand(&g) - 1), ext.z * (3 * trand(&g) - 1)));
		vec3 at = v3_add(b.lo, v3(ext.x * trand(&g), ext.y * trand(&g), ext.z * trand(&g)));
		vec3 d0 = v3_norm(v3_sub(at, o));
		double spread = k % 3 == 0 ? 2.0 : 0.002 + 0.05 * trand(&g);
		ray r[PACKET_MAX];
		for (int i = 0; i < PACKET_MAX; i++) {
			vec3 j = v3((trand(&g) - 0.5) * spread, (trand(&g) - 0.5) * spread, (trand(&g) - 0.5) * spread);
			r[i] = (ray){o, v3_add(d0, j)};
			if (k % 7 == 1 && i == 3) /* a zero component */
				r[i].d.y = k % 2 ? 0.0 : -0.0;
			if (k % 7 == 2) /* all along one axis */
				r[i].d = v3(0, 0, d0.z < 0 ? -1 : 1);
			if (k % 7 == 3 && i > 0) /* origins apart */
				r[i].o = v3_add(o, v3(0.01 * ext.x * trand(&g), 0.01 * ext.y * trand(&g), 0));
		}
		int n = k % 5 == 4 ? 1 + k % PACKET_MAX : PACKET_MAX;
		check_packet(w, r, n, lamp);
		check_model(w, r, n, k);
	}
}

/* A lone model from text on every vector unit. */
static void check_model_scene(const char *text, int W, int H, int cones)
{
	scene *s;
	world *w = world_of_text(text, "model", &s);
	for (int isa = MESH_ISA_SCALAR; isa <= MESH_ISA_BEST; isa++)
		if (mesh_isa_force((mesh_isa)isa))
			model_packets(w, W, H, cones, 41 + (uint64_t)isa);
	assert_true(mesh_isa_force(MESH_ISA_BEST));
	world_free(w);
	scene_free(s);
}

/* Whether the machine has a vector unit with the triangle packets. */
static bool have_model_packets(void)
{
	bool yes = mesh_isa_force(MESH_ISA_AVX2);
	assert_true(mesh_isa_force(MESH_ISA_BEST));
	return yes;
}

/* A new temporary model file named by path (a mkstemps template ending in
 * ".obj"), open for writing. */
static FILE *open_temp_obj(char *path)
{
	int fd = mkstemps(path, 4);
	assert_true(fd >= 0);
	FILE *f = fdopen(fd, "w");
	assert_non_null(f);
	return f;
}

/* Triangles at exactly the same distance in different blocks and leaves:
 * twelve copies of one triangle, six of another with its corners turned,
 * a grid of quads behind them whose rays meet shared edges and corners, a
 * grid of thin slivers; where a single ray keeps the first it meets, the
 * packet must keep the same one (by tracing the ray again alone). */
static void test_model_ties(void **state)
{
	(void)state;
	char path[] = "/tmp/rtsh-test-packet-XXXXXX.obj";
	FILE *f = open_temp_obj(path);
	int nv = 0;
	/* The copies differ in their texture coordinate only (one vt each), so
	 * that the loader keeps them: exact duplicates are dropped at load, and
	 * these are there to meet the ray at exactly the same distance. Every
	 * corner has a uv (vt 19 for the grid's), else the mesh keeps none and
	 * the copies are duplicates again. */
	for (int c = 0; c < 19; c++)
		fprintf(f, "vt %g 0\n", c / 32.0);
	for (int c = 0; c < 12; c++) { /* the same triangle twelve times */
		fprintf(f, "v -2 -2 0\nv 2 -2 0\nv 0 2 0\nf %d/%d %d/%d %d/%d\n", nv + 1, c + 1, nv + 2, c + 1, nv + 3,
		        c + 1);
		nv += 3;
	}
	for (int c = 0; c < 6; c++) { /* another, its corners turned */
		fprintf(f, "v -2.5 -1 1\nv 2.5 -1.5 1\nv 0 2.5 1\n");
		fprintf(f, "f %d/%d %d/%d %d/%d\n", nv + 1 + c % 3, 13 + c, nv + 1 + (c + 1) % 3, 13 + c,
		        nv + 1 + (c + 2) % 3, 13 + c);
		nv += 3;
	}
	for (int j = 0; j <= 8; j++) /* a grid of 8 x 8 quads at z = 2 */
		for (int i = 0; i <= 8; i++)
			fprintf(f, "v %g %g 2\n", -3 + 0.75 * i, -3 + 0.75 * j);
	for (int j = 0; j < 8; j++)
		for (int i = 0; i < 8; i++) {
			int a = nv + j * 9 + i + 1, b = a + 1, c = a + 9, d = c + 1;
			fprintf(f, "f %d/19 %d/19 %d/19\nf %d/19 %d/19 %d/19\n", a, b, d, a, d, c);
		}
	nv += 81;
	assert_int_equal(fclose(f), 0);
	char text[512];
	snprintf(text, sizeof text, "C 0.1,0.05,-7 0,0,1 50\nL -2,3,-6 0.8 255,255,255\nmesh %s 0,0,1 0,1,0 6 200,200,200\n",
	         path);
	long traced = model_traced, ties = model_ties;
	check_model_scene(text, 96, 64, 300);
	/* the same seen through holes: only the grid and its edges */
	snprintf(text, sizeof text, "C 0,0,-7 0,0,1 70\nL -2,3,-6 0.8 255,255,255\nmesh %s 0,0,1 0,1,0 6 200,200,200\n",
	         path);
	check_model_scene(text, 64, 64, 100);
	/* the model among other objects: the object tree's packets meet it
	 * as a packet of its own (packet.c's leaf_mesh), ties and all */
	snprintf(text, sizeof text,
	         "C 0.1,0.05,-7 0,0,1 50\nL -2,3,-6 0.8 255,255,255\nmesh %s 0,0,1 0,1,0 6 200,200,200\n"
	         "sp 2.5,2.5,-1 0.5 255,0,0\nsp -2.5,-2.5,3 0.5 0,255,0\n",
	         path);
	{
		scene *s2;
		world *w2 = world_of_text(text, "ties", &s2);
		for (int isa = MESH_ISA_SCALAR; isa <= MESH_ISA_BEST; isa++)
			if (mesh_isa_force((mesh_isa)isa)) {
				camera_packets(w2, 96, 64, w2->lights[0].pos);
				cone_packets(w2, w2->bounds.lo, w2->bounds.hi, 300, 7 + (uint64_t)isa, w2->lights[0].pos);
				/* from points spread over a wide square, toward the copies */
				test_rng g = {99 + (uint64_t)isa};
				for (int k = 0; k < 400; k++) {
					ray r[PACKET_MAX];
					vec3 o = v3(-4 + 8 * trand(&g), -4 + 8 * trand(&g), -3 - 4 * trand(&g));
					vec3 at = v3(-1 + 2 * trand(&g), -1 + 2 * trand(&g), 1);
					for (int i = 0; i < PACKET_MAX; i++) {
						vec3 oi = v3_add(o, v3(0.5 * trand(&g), 0.5 * trand(&g), 0));
						r[i] = (ray){oi, v3_sub(v3_add(at, v3(0.3 * trand(&g), 0.3 * trand(&g), 0)), oi)};
					}
					check_packet(w2, r, PACKET_MAX, w2->lights[0].pos);
				}
			}
		assert_true(mesh_isa_force(MESH_ISA_BEST));
		world_free(w2);
		scene_free(s2);
	}
	/* rays exactly through the grid's corners and edges (the model's
	 * coordinates are the world's here: placed at its own centre at its
	 * own size; each ray 8 long in z, so that the shear is exact and the
	 * edge functions there are zeros, recomputed in double) */
	snprintf(text, sizeof text, "C 0,0,-7 0,0,1 70\nmesh %s 0,0,1 0,1,0 6 200,200,200\n", path);
	scene *sc;
	world *w = world_of_text(text, "ties", &sc);
	for (int isa = MESH_ISA_SCALAR; isa <= MESH_ISA_BEST; isa++) {
		if (!mesh_isa_force((mesh_isa)isa))
			continue;
		for (int q = 0; q < 8; q++) {
			double sx = q & 1 ? -1 : 1, sy = q & 2 ? -1 : 1;
			ray r[PACKET_MAX];
			vec3 o = v3(0.25 * (q >> 2), 0.125 * (q >> 2), -6);
			for (int i = 0; i < PACKET_MAX; i++) {
				/* corners and edge midpoints of the grid's outer quads */
				double tx = sx * (2.25 + 0.375 * (i % 3)), ty = sy * (0.75 + 0.375 * (i / 3));
				r[i] = (ray){o, v3(tx - o.x, ty - o.y, 8)};
			}
			check_packet(w, r, PACKET_MAX, v3(0, 0, -10));
			check_model(w, r, PACKET_MAX, q);
		}
	}
	assert_true(mesh_isa_force(MESH_ISA_BEST));
	world_free(w);
	scene_free(sc);
	unlink(path);
	if (have_model_packets()) {
		assert_true(model_traced - traced > 500);
		assert_true(model_ties - ties > 100);
	}
}

/* test_ties_across_leaves with a model for X: the packet meets the model
 * as a packet of its own (leaf_mesh), each ray up to the next double above
 * its distance so far, where the model's triangle at exactly that distance
 * is a tie. The model is two triangles, T1 (-1,-2,0) (3,-2,0) (-1,2,0),
 * which holds P = (0,0,0) inside (x + y < 1), and T2 (3,2,2) (2,2,2)
 * (3,1,2), off every ray 0 reaches, that makes its box [-1,3] x [-2,2] x
 * [0,2]: longest side 4, centre (1,0,1), so that placed there at size 4
 * its coordinates are the world's. Ray 0 (from (-9,-18,18) along (1,2,-2))
 * runs down z, the largest |d| (z before y on a tie): the shear
 * constants -1/2, -1 and 1/2 in magnitude are exact, T1's sheared corners
 * are its own x and y (az = -18 cancels o's x and y), its edge functions
 * integers summing to 2 x its area, 16, and t = (9 x 16) / 16 = 9 exactly in
 * float. Ray 0 enters the model's box at t = max(-1+9, (-2+18)/2,
 * (2-18)/-2) = 8, Y's at 8.5: alone it keeps the model. The others start in
 * Y's box with x <= -1.25, before the model's low x: the packet meets Y
 * first. On every vector unit (the model's own packets where there are
 * some, the generic leaf loop elsewhere): with next_up(9) for bound, which
 * the model's walk rounds back to 9.0f and tests strictly, both missed the
 * tie and gave ray 0 Y (packet.c's model_bound). */
static void test_mesh_tie_across_leaves(void **state)
{
	(void)state;
	char path[] = "/tmp/rtsh-test-packet-XXXXXX.obj";
	FILE *f = open_temp_obj(path);
	/* (x mirrored: model files are right-handed, the scene left-handed) */
	fprintf(f, "v 1 -2 0\nv -3 -2 0\nv 1 2 0\nv -3 2 2\nv -2 2 2\nv -3 1 2\nf 1 2 3\nf 4 5 6\n");
	assert_int_equal(fclose(f), 0);
	char text[512];
	/* Y and four spheres inside it, of its centre: the tree puts the model
	 * in a leaf of its own */
	snprintf(text, sizeof text,
	         "C 0,0,30 0,0,-1 60\nL 3,6,20 0.8 255,255,255\n"
	         "sp 1,2,-2 6 255,0,0\nmesh %s 1,0,1 0,1,0 4 0,0,255\n"
	         "sp 1,2,-2 1 255,255,0\nsp 1,2,-2 2 255,255,0\nsp 1,2,-2 3 255,255,0\nsp 1,2,-2 4 255,255,0\n",
	         path);
	scene *s;
	world *w = world_of_text(text, "mesh tie across leaves", &s);
	unlink(path);
	const vec3 o0 = v3(-9, -18, 18), d = v3(1, 2, -2);
	const ray r0 = {o0, d};
	const prim *py = sphere_at(w, v3(1, 2, -2), 3), *pm = NULL;
	for (size_t i = 0; i < w->nprims; i++)
		if (w->prims[i].tag == PRIM_MESH)
			pm = &w->prims[i];
	assert_non_null(pm);
	const prim_inst *in = &w->insts[pm->u.index];
	long lm = leaf_of(w, pm), ly = leaf_of(w, py);
	assert_true(lm >= 0 && ly >= 0);
	assert_true(lm != ly);
	for (int isa = MESH_ISA_SCALAR; isa <= MESH_ISA_BEST; isa++) {
		if (!mesh_isa_force((mesh_isa)isa))
			continue;
		/* the tie itself: each alone at exactly t = 9 */
		double t = 0;
		uint32_t slot;
		float b[3];
		assert_true(sphere_hit(py, &r0, 0.0, INFINITY, &t));
		same_double(t, 9.0, "Y alone");
		assert_true(mesh_intersect_world_coherent(in->mesh, in->inv, &r0, 0.0, INFINITY, &t, &slot, b));
		same_double(t, 9.0, "the model alone");
		/* the single ray keeps the model, whose box it enters first */
		trace_hit ts;
		assert_true(world_trace_coherent(w, &r0, 0.0, INFINITY, &ts));
		same_double(ts.t, 9.0, "single t");
		assert_ptr_equal(ts.prim, pm);
		test_rng g = {73 + (uint64_t)isa};
		tie_packets(w, r0, d, &g);
	}
	assert_true(mesh_isa_force(MESH_ISA_BEST));
	world_free(w);
	scene_free(s);
}

/* Packets of which every ray but one passes far from the model (beside
 * the sphere about its box, which lets a packet skip the walk when all its
 * rays pass outside) and the one, in each lane in turn, meets it: the
 * packet must find that ray's hit, the single ray's; and a packet whose
 * rays all pass outside finds nothing. On every vector unit, the model
 * turned (its matrix whole) and far from the camera. */
static void test_model_cull(void **state)
{
	(void)state;
	scene *s;
	world *w = world_of_text("C -9,-6,-15 1,0.6,1.6 30\n"
	                         "mesh scenes/models/spot/spot_triangulated.obj 0.4,0.3,0.2 0.3,1,0.1 1.5 255,255,255\n",
	                         "model", &s);
	assert_true(w->nprims == 1 && w->prims[0].tag == PRIM_MESH);
	const prim_inst *in = &w->insts[w->prims[0].u.index];
	vec3 o = w->cam.pos, c = box_center(w->bounds);
	vec3 d0 = v3_norm(v3_sub(c, o));
	long traced = 0;
	for (int isa = MESH_ISA_SCALAR; isa <= MESH_ISA_BEST; isa++) {
		if (!mesh_isa_force((mesh_isa)isa))
			continue;
		for (int j = -1; j < PACKET_MAX; j++) {
			ray r[PACKET_MAX];
			for (int i = 0; i < PACKET_MAX; i++) {
				/* the others turned away, each axis's sign kept */
				double k = 1.6 + 0.05 * i;
				vec3 d = i % 3 == 0 ? v3(d0.x * k, d0.y, d0.z) : i % 3 == 1 ? v3(d0.x, d0.y * k, d0.z) : v3(d0.x, d0.y, d0.z * k);
				r[i] = (ray){o, i == j ? d0 : v3_norm(d)};
				double t;
				uint32_t slot;
				float b[3];
				assert_int_equal(mesh_intersect_world_coherent(in->mesh, in->inv, &r[i], 0.0, INFINITY, &t, &slot, b),
				                 i == j);
			}
			unsigned got = 1, tie = 1;
			double t[PACKET_MAX];
			uint32_t slot[PACKET_MAX];
			float b[PACKET_MAX][3];
			if (isa >= MESH_ISA_AVX2) {
				assert_true(mesh_intersect_world_packet(in->mesh, in->inv, PACKET_MAX, r, 0.0, INFINITY, NULL, t, slot,
				                                        b, &got, &tie));
				assert_int_equal(got, j < 0 ? 0u : 1u << j);
				assert_int_equal(tie, 0u);
				traced++;
			}
			check_model(w, r, PACKET_MAX, j + 1);
			check_packet(w, r, PACKET_MAX, v3(0, 10, 0));
		}
	}
	assert_true(mesh_isa_force(MESH_ISA_BEST));
	if (have_model_packets())
		assert_true(traced >= 17);
	world_free(w);
	scene_free(s);
}

/* Models alone on every vector unit: the bunny (upright: the matrix's
 * zeros skipped), the cow turned (the whole matrix), the fence's glTF
 * cut-outs (alphaMode MASK), spot over a plane (the planes first). */
static void test_model_packets(void **state)
{
	(void)state;
	long traced = model_traced, occluded = model_occluded_traced;
	const char *bunny = "../shared/models/stanford-bunny.obj";
	char text[512];
	if (access(bunny, R_OK) == 0) {
		snprintf(text, sizeof text, "C 0,0.1,-3.2 0,0,1 40\nL -2,3,-4 0.8 255,255,255\nmesh %s 0,0,0 0,1,0 1 200,200,200\n",
		         bunny);
		check_model_scene(text, 96, 72, 200);
	} else {
		print_message("(%s is absent: the bunny is left out)\n", bunny);
	}
	check_model_scene("C -0.5,0.9,-4.5 0.2,-0.1,1 60\nL -4,5,-3 0.8 255,245,225\n"
	                  "mesh scenes/models/fence/fence.gltf 0,0.5,0 0,1,0 8\n",
	                  128, 72, 200);
	check_model_scene("C -3.4,1.5,-4.0 3.4,-0.8,4.0 40\nL -3,6,-2 0.6 255,250,240\n"
	                  "pl 0,0,0 0,1,0 200,200,200\npl 0,0,3 0,0,-1 100,200,100\n"
	                  "mesh scenes/models/spot/spot_triangulated.obj 0,0.74,0 0.3,1,0.1 1.5 255,255,255 twist=-40\n",
	                  96, 54, 200);
	if (have_model_packets()) {
		assert_true(model_traced - traced > 1000);
		assert_true(model_occluded_traced - occluded > 1000);
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_ties),
		cmocka_unit_test(test_ties_across_leaves),
		cmocka_unit_test(test_signed_zero_origins),
		cmocka_unit_test(test_prepare_edges),
		cmocka_unit_test(test_scenes),
		cmocka_unit_test(test_split_shadows),
		cmocka_unit_test(test_bunny),
		cmocka_unit_test(test_model_ties),
		cmocka_unit_test(test_mesh_tie_across_leaves),
		cmocka_unit_test(test_model_packets),
		cmocka_unit_test(test_model_cull),
	};
	int rc = cmocka_run_group_tests(tests, NULL, NULL);
	printf("packets: %ld, rays that hit: %ld; the model's own packets: %ld, ties among them: %ld; shadow packets: %ld\n",
	       packets, rays_hit, model_traced, model_ties, model_occluded_traced);
	return rc;
}
