/* rtsh — tests of the camera's orbit (rtsh/orbit.h), against positions
 * worked out by hand on the circle and the sphere about the pivot, and
 * properties: the distance to the pivot is kept, turns add up, a full turn
 * comes back. */
#include "testutil.h"

#include "rtsh/orbit.h"
#include "rtsh/rtfile.h"

static camera cam(vec3 pos, vec3 dir)
{
	camera c = {pos, dir, 60, false, 0, 0};
	return c;
}

/* Looking at the pivot along +Z from 5 units before it, the camera's
 * right is +X (world.c: right = Y x forward): a yaw of 90 degrees takes it
 * to (5, 0, 0), looking along -X; -90 to (-5, 0, 0). */
static void test_yaw_by_hand(void **state)
{
	(void)state;
	camera c = cam(v3(0, 0, -5), v3(0, 0, 1));
	camera r = orbit_camera(c, v3(0, 0, 0), 90, 0);
	assert_vec_near(r.pos, v3(5, 0, 0), 1e-12);
	assert_vec_near(r.dir, v3(-1, 0, 0), 1e-12);
	camera l = orbit_camera(c, v3(0, 0, 0), -90, 0);
	assert_vec_near(l.pos, v3(-5, 0, 0), 1e-12);
	assert_vec_near(l.dir, v3(1, 0, 0), 1e-12);
	/* About another pivot: the same circle moved. */
	camera m = orbit_camera(cam(v3(1, 2, -2), v3(0, 0, 1)), v3(1, 2, 3), 180, 0);
	assert_vec_near(m.pos, v3(1, 2, 8), 1e-12);
	assert_vec_near(m.dir, v3(0, 0, -1), 1e-12);
}

/* Pitch 30 degrees up: (0, 5 sin 30, -5 cos 30), still looking at the
 * pivot; never past ORBIT_PITCH_LIMIT. */
static void test_pitch_by_hand(void **state)
{
	(void)state;
	camera c = cam(v3(0, 0, -5), v3(0, 0, 1));
	camera u = orbit_camera(c, v3(0, 0, 0), 0, 30);
	assert_vec_near(u.pos, v3(0, 2.5, -5 * cos(deg_to_rad(30))), 1e-12);
	assert_vec_near(u.dir, v3_norm(v3_neg(u.pos)), 1e-12);
	camera top = orbit_camera(c, v3(0, 0, 0), 0, 120);
	double el = rad_to_deg(asin(top.pos.y / v3_len(top.pos)));
	assert_near(el, ORBIT_PITCH_LIMIT, 1e-9);
	assert_vec_near(top.dir, v3_norm(v3_neg(top.pos)), 1e-9);
}

/* Random cameras looking at random pivots: the distance stays, the camera
 * still looks at the pivot, yaws add up, a full turn comes back. */
static void test_properties(void **state)
{
	(void)state;
	test_rng r = {7};
	for (int i = 0; i < 1000; i++) {
		vec3 p = v3(trange(&r, -5, 5), trange(&r, -5, 5), trange(&r, -5, 5));
		vec3 off = v3_scale(tdir(&r), trange(&r, 0.5, 20));
		if (fabs(off.y) > 0.9 * v3_len(off))
			continue; /* near the poles the pitch limit applies */
		camera c = cam(v3_add(p, off), v3_neg(off));
		double a = trange(&r, -180, 180), b = trange(&r, -180, 180);
		double pitch = trange(&r, -20, 20);
		camera o = orbit_camera(c, p, a, pitch);
		assert_near(v3_len(v3_sub(o.pos, p)), v3_len(off), 1e-9 * v3_len(off));
		assert_vec_near(v3_norm(o.dir), v3_norm(v3_sub(p, o.pos)), 1e-9);
		camera ab = orbit_camera(orbit_camera(c, p, a, 0), p, b, 0);
		camera sum = orbit_camera(c, p, a + b, 0);
		assert_vec_near(ab.pos, sum.pos, 1e-9 * (1 + v3_len(off)));
		camera full = c;
		for (int k = 0; k < 4; k++)
			full = orbit_camera(full, p, 90, 0);
		assert_vec_near(full.pos, c.pos, 1e-9 * (1 + v3_len(off)));
	}
}

/* The wheel: a tenth nearer, then back with 1 - 1/0.9. */
static void test_dolly(void **state)
{
	(void)state;
	camera c = cam(v3(1, 2, 13), v3(0, 0, -1));
	camera n = orbit_dolly(c, v3(1, 2, 3), 0.1);
	assert_vec_near(n.pos, v3(1, 2, 12), 1e-12);
	camera f = orbit_dolly(n, v3(1, 2, 3), 1.0 - 1.0 / 0.9);
	assert_vec_near(f.pos, c.pos, 1e-12);
	/* Never onto the pivot. */
	camera z = orbit_dolly(c, v3(1, 2, 3), 5);
	assert_true(v3_len(v3_sub(z.pos, v3(1, 2, 3))) > 0);
}

/* Framing: the box's bounding sphere touches the narrower half angle:
 * distance r / sin(half); the direction stays. */
static void test_frame(void **state)
{
	(void)state;
	camera c = cam(v3(7, 1, 2), v3(0, -1, 1));
	box b = {v3(-1, 0, -1), v3(1, 2, 1)};
	double r = sqrt(3.0);
	camera w = orbit_frame(c, b, 2.0); /* wide: the vertical half angle */
	double hv = atan(tan(deg_to_rad(30)) / 2.0);
	assert_near(v3_len(v3_sub(w.pos, v3(0, 1, 0))), r / sin(hv), 1e-9);
	assert_vec_near(v3_norm(w.dir), v3_norm(c.dir), 1e-12);
	assert_vec_near(v3_norm(v3_sub(v3(0, 1, 0), w.pos)), v3_norm(c.dir), 1e-12);
	camera t = orbit_frame(c, b, 0.5); /* tall: the horizontal one, 30 degrees */
	assert_near(v3_len(v3_sub(t.pos, v3(0, 1, 0))), r / sin(deg_to_rad(30)), 1e-9);
	camera e = orbit_frame(c, box_empty(), 1.0);
	assert_vec_near(e.pos, c.pos, 0);
}

/* Framing a glTF camera (vertical=1: 60 degrees is the height's) and an
 * orthographic one, and the wheel on the latter. By hand: box radius
 * sqrt(3) about (0,1,0). Vertical 60 on a wide image (aspect 2): the
 * vertical half angle 30 is the narrower, distance r / sin 30 = 2r (it was
 * framed as 60 degrees wide: atan(tan 30 / 2), 3.6r). On a tall one (0.5):
 * the horizontal, atan(tan 30 / 2). Orthographic: the half height r on a
 * wide image, 2r on a tall one (its width, h x 0.5, holds r), from 2r in
 * front; the wheel multiplies the half height, the camera stays. */
static void test_frame_kinds(void **state)
{
	(void)state;
	box b = {v3(-1, 0, -1), v3(1, 2, 1)};
	double r = sqrt(3.0);
	camera v = cam(v3(7, 1, 2), v3(0, 0, -1));
	v.vertical = true;
	camera w = orbit_frame(v, b, 2.0);
	assert_near(v3_len(v3_sub(w.pos, v3(0, 1, 0))), 2 * r, 1e-9);
	assert_vec_near(w.pos, v3(0, 1, 2 * r), 1e-9);
	assert_near(w.fov, 60, 0);
	camera t = orbit_frame(v, b, 0.5);
	assert_near(v3_len(v3_sub(t.pos, v3(0, 1, 0))), r / sin(atan(tan(deg_to_rad(30)) / 2)), 1e-9);
	camera o = cam(v3(7, 1, 2), v3(0, 0, -1));
	o.ortho = 5;
	camera ow = orbit_frame(o, b, 2.0);
	assert_near(ow.ortho, r, 1e-12);
	assert_vec_near(ow.pos, v3(0, 1, 2 * r), 1e-9);
	assert_near(orbit_frame(o, b, 0.5).ortho, 2 * r, 1e-12);
	camera n = orbit_dolly(o, v3(1, 2, 3), 0.1);
	assert_near(n.ortho, 4.5, 1e-12);
	assert_vec_near(n.pos, o.pos, 0);
	assert_near(orbit_dolly(n, v3(1, 2, 3), 1.0 - 1.0 / 0.9).ortho, 5, 1e-12);
}

/* The turntable: frame k of n is a yaw of 360 k / n; frame 0 is the
 * camera itself, half a turn is the same for 2 of 4 and 1 of 2. The
 * scene's centre is the box of its bounded objects (the plane left out). */
static void test_turntable(void **state)
{
	(void)state;
	rt_error err;
	const char *text = "C 0,1,-6 0,0,1 60\nsp 0,1,0 2 255,0,0\nsp 4,1,0 2 0,255,0\npl 0,0,0 0,1,0 9,9,9\n";
	scene *s = rt_load_string(text, strlen(text), "t.rt", NULL, &err);
	assert_non_null(s);
	vec3 p = orbit_scene_centre(s);
	assert_vec_near(p, v3(2, 1, 0), 1e-12);
	camera c = scene_camera(s);
	camera f0 = orbit_turntable(c, p, 0, 24);
	assert_vec_near(f0.pos, c.pos, 0);
	assert_vec_near(f0.dir, c.dir, 0);
	camera h1 = orbit_turntable(c, p, 2, 4), h2 = orbit_turntable(c, p, 1, 2);
	assert_vec_near(h1.pos, h2.pos, 0);
	assert_vec_near(h1.pos, v3(2 + 2, 1, 6), 1e-12); /* (0,-6) from p=(2,0) mirrored through it */
	camera q = orbit_turntable(c, p, 6, 24);
	assert_vec_near(q.pos, orbit_camera(c, p, 90, 0).pos, 1e-12);
	scene_free(s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_yaw_by_hand), cmocka_unit_test(test_pitch_by_hand),
		cmocka_unit_test(test_properties),  cmocka_unit_test(test_dolly),
		cmocka_unit_test(test_frame),       cmocka_unit_test(test_turntable),
		cmocka_unit_test(test_frame_kinds),
	};
	return cmocka_run_group_tests_name("orbit", tests, NULL, NULL);
}
