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
 * and every vector unit the triangle walk has (mesh_isa_force), as
 * test_world_ray_entry does for single rays. */
#include "testutil.h"

#include <unistd.h>

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

/* Packet against single rays for r[0..n): nearest hits, hit records, and
 * shadow queries to a fraction of each hit's distance and to `lamp`. */
static void check_packet(const world *w, const ray *r, int n, vec3 lamp)
{
	trace_hit tp[PACKET_MAX];
	bool fp[PACKET_MAX];
	world_trace_packet(w, n, r, 0.0, INFINITY, tp, fp);
	packets++;
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
		same_vec(hp.p, hs.p, "p");
		same_vec(hp.n, hs.n, "n");
		same_vec(hp.local, hs.local, "local");
		assert_int_equal(hp.front, hs.front);
		assert_int_equal(hp.object, hs.object);
		assert_int_equal(hp.mat, hs.mat);
		assert_int_equal(hp.has_uv, hs.has_uv);
		if (hs.has_uv) {
			same_double(hp.u, hs.u, "u");
			same_double(hp.v, hs.v, "v");
			same_vec(hp.dpdu, hs.dpdu, "dpdu");
			same_vec(hp.dpdv, hs.dpdv, "dpdv");
		}
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
		}
		check_packet(w, r, n, lamp);
	}
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
	const char *paths[] = {"scenes/grid.rt", "scenes/showcase.rt", "scenes/tori.rt", "scenes/instances.rt",
	                       "scenes/final.rt", "scenes/classic42.rt", "scenes/cornell.rt"};
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
	rt_error err;
	scene *s = rt_load_string(text, strlen(text), "bunny", NULL, &err);
	if (!s)
		fail_msg("bunny: %s", err.msg);
	world *w = world_build(s, &err);
	if (!w)
		fail_msg("bunny: %s", err.msg);
	for (int isa = MESH_ISA_SCALAR; isa <= MESH_ISA_BEST; isa++)
		if (mesh_isa_force((mesh_isa)isa))
			camera_packets(w, 64, 48, w->lights[0].pos);
	assert_true(mesh_isa_force(MESH_ISA_BEST));
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
	rt_error err;
	scene *s = rt_load_string(text, strlen(text), "ties", NULL, &err);
	if (!s)
		fail_msg("ties: %s", err.msg);
	world *w = world_build(s, &err);
	if (!w)
		fail_msg("ties: %s", err.msg);
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

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_ties),
		cmocka_unit_test(test_prepare_edges),
		cmocka_unit_test(test_scenes),
		cmocka_unit_test(test_bunny),
	};
	int rc = cmocka_run_group_tests(tests, NULL, NULL);
	printf("packets: %ld, rays that hit: %ld\n", packets, rays_hit);
	return rc;
}
