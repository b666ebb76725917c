/* rtsh — whatever the editor accepts, the reader accepts (issue 14, 1):
 *   - the issue's repros: three `object 1 scale 1e10,1e10,1e10` (the third
 *     would make a diameter of 1e30), twelve `camera move 1e19,0,0`, a
 *     sphere of diameter 1e20 scaled by 2: refused with the range, and
 *     the scene saves and loads back;
 *   - a property: random sequences of edits with huge, tiny and odd
 *     arguments, each accepted or refused; the result is saved, loaded back
 *     and equal to the editor's scene, every time. */
#include "testutil.h"

#include "rtsh/edit.h"
#include "rtsh/rtfile.h"
#include "rtsh/rules.h"

static scene *load(const char *text)
{
	rt_error err;
	rt_error_clear(&err);
	scene *s = rt_load_string(text, strlen(text), "t.rt", NULL, &err);
	if (!s)
		fail_msg("%s", err.msg);
	return s;
}

/* Saves the editor's scene to memory and loads it back: equal. */
static void expect_round_trip(const editor *ed, const char *when)
{
	char *buf = NULL;
	size_t len = 0;
	FILE *f = open_memstream(&buf, &len);
	assert_non_null(f);
	assert_true(rt_write(editor_scene(ed), f, NULL));
	fclose(f);
	rt_error err;
	rt_error_clear(&err);
	scene *back = rt_load_string(buf, len, "saved.rt", NULL, &err);
	if (!back)
		fail_msg("%s: the saved scene does not load: %s\n%s", when, err.msg, buf);
	if (!scene_equal(back, editor_scene(ed)))
		fail_msg("%s: the saved scene loads back different\n%s", when, buf);
	scene_free(back);
	free(buf);
}

static void test_issue_repros(void **state)
{
	(void)state;
	rt_error err;
	editor *ed = editor_new(load("C 0,0,-5 0,0,1 70\nL 2,0,-10 1 255,255,255\nsp 0,0,0 1 255,0,0\n"), "t");
	assert_true(editor_object_scale(ed, 0, v3_splat(1e10), &err));
	assert_true(editor_object_scale(ed, 0, v3_splat(1e10), &err));
	assert_false(editor_object_scale(ed, 0, v3_splat(1e10), &err));
	assert_non_null(strstr(err.msg, "expected sizes in (0,1e20]"));
	expect_round_trip(ed, "scale 1e10 three times");
	int moved = 0;
	for (int i = 0; i < 12; i++)
		moved += editor_camera_move(ed, v3(1e19, 0, 0), &err);
	assert_int_equal(moved, 10); /* 10 x 1e19 = 1e20 is the last position in range */
	assert_non_null(strstr(err.msg, "camera position"));
	expect_round_trip(ed, "camera move 1e19 twelve times");
	for (int i = 0; i < 12; i++)
		editor_light_move(ed, 0, v3(0, 1e19, 0), &err);
	assert_true(fabs(editor_scene(ed)->lights[0].pos.y) <= RT_NUM_MAX);
	expect_round_trip(ed, "light move 1e19 twelve times");
	assert_true(editor_add_line(ed, "sp 0,0,0 1e20 255,0,0", "add", 0, NULL, &err));
	assert_false(editor_object_scale(ed, 1, v3(2, 2, 2), &err));
	expect_round_trip(ed, "a sphere of 1e20 scaled by 2");
	editor_free(ed);
}

/* object N set KEY=VALUE: the reader's table, scanner and ranges. */
static void test_set_key(void **state)
{
	(void)state;
	rt_error err;
	editor *ed = editor_new(load("sp 0,0,0 1 255,0,0\nto 0,0,0 0,1,0 2 1 0,0,255\n"), "t");
	assert_true(editor_object_set_key(ed, 0, "ior=1.5", &err));
	assert_near(editor_scene(ed)->objs[0].mat.ior, 1.5, 0);
	assert_true(editor_object_set_key(ed, 1, "tube=0.25", &err));
	assert_near(editor_scene(ed)->objs[1].tube, 0.25, 0);
	static const char *const bad[] = {"ior=0.5", "ior=0x1", "ior", "glow=1", "tube=2", "checker=1.5",
	                                  "emit=-1", "fuzz=1e400"};
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
		if (editor_object_set_key(ed, 0, bad[i], &err))
			fail_msg("object 1 set %s was accepted", bad[i]);
	assert_false(editor_object_set_key(ed, 1, "tube=0", &err));
	expect_round_trip(ed, "object set");
	editor_free(ed);
}

/* Arguments spread over every magnitude, with some odd ones. */
static double wild(test_rng *g)
{
	double u = trand(g);
	if (u < 0.05)
		return 0;
	if (u < 0.08)
		return 1e20;
	double m = pow(10, trange(g, -25, 25));
	return trand(g) < 0.5 ? -m : m;
}

static vec3 wild_vec(test_rng *g)
{
	return v3(wild(g), wild(g), wild(g));
}

static void test_random_edit_sequences(void **state)
{
	(void)state;
	test_rng g = {14};
	int accepted = 0, refused = 0;
	for (int seq = 0; seq < 200; seq++) {
		editor *ed = editor_new(load("A 0.2 255,255,255\nC 0,1,-5 0,0,1 70\nL 2,3,-4 0.7 255,255,255\n"
		                             "sky 10,20,30 200,200,255 1\n"
		                             "sp 0,0,0 1 255,0,0\ncy 1,0,0 0,1,0 1 2 0,255,0\n"
		                             "to 0,1,0 0,0,1 2 0.5 0,0,255\ntr 0,0,0 1,0,0 0,1,0 9,9,9\n"
		                             "pl 0,-1,0 0,1,0 200,200,200\ncu 0,0,3 1,1,0 1,2,3 50,50,50 "
		                             "0.5 0.5 10 0.5 0.1,0,0,0,0,0 twist=30\n"),
		                        "t");
		for (int step = 0; step < 25; step++) {
			rt_error err;
			size_t obj = (size_t)(trand(&g) * 6);
			bool ok;
			switch ((int)(trand(&g) * 11)) {
			case 0:
				ok = editor_object_move(ed, obj, wild_vec(&g), &err);
				break;
			case 1:
				ok = editor_object_scale(ed, obj, v3(fabs(wild(&g)), fabs(wild(&g)), fabs(wild(&g))), &err);
				break;
			case 2:
				ok = editor_object_rotate(ed, obj, wild_vec(&g), &err);
				break;
			case 3:
				ok = editor_object_color(ed, obj, v3(trange(&g, -10, 300), 0, 0), &err);
				break;
			case 4:
				ok = editor_light_move(ed, 0, wild_vec(&g), &err);
				break;
			case 5:
				ok = editor_light_brightness(ed, 0, trange(&g, -0.5, 1.5), &err);
				break;
			case 6:
				ok = editor_camera_move(ed, wild_vec(&g), &err);
				break;
			case 7:
				ok = editor_camera_fov(ed, trange(&g, -20, 200), &err);
				break;
			case 8:
				ok = editor_camera_turn(ed, wild(&g), trange(&g, -100, 100), &err);
				break;
			case 9:
				ok = editor_camera_pos(ed, wild_vec(&g), &err);
				break;
			default:
				ok = editor_set_sky(ed, true, &(sky){.zenith = v3(1, 2, 3), .horizon = v3(4, 5, 6), .strength = wild(&g)}, &err);
				break;
			}
			accepted += ok;
			refused += !ok;
		}
		char when[64];
		snprintf(when, sizeof when, "sequence %d", seq);
		expect_round_trip(ed, when);
		editor_free(ed);
	}
	print_message("%d edits accepted, %d refused; every sequence saved and loaded back equal\n",
	              accepted, refused);
	assert_true(accepted > 1000 && refused > 500);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_issue_repros),
		cmocka_unit_test(test_set_key),
		cmocka_unit_test(test_random_edit_sequences),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
