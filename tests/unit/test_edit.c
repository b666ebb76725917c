/* rtsh — tests of the scene-edit API: every edit undoes to the scene_equal
 * state before it and redoes to the one after; invalid edits change
 * nothing; camera verbs against hand-computed values. */
#include "testutil.h"

#include "rtsh/edit.h"
#include "rtsh/memory.h"
#include "rtsh/rtfile.h"

static const char basic[] = "A 0.1 255,255,255\n"
                            "C 0,0,-5 0,0,1 70\n"
                            "L 2,0,-10 1 255,255,255\n"
                            "L 0,5,0 0.5 255,0,0\n"
                            "sp 0,0,0 1 255,0,0\n"
                            "pl 0,-1,0 0,1,0 200,200,200\n"
                            "cy 2,0,0 0,1,0 1 2 0,0,255\n";

static editor *new_editor(void)
{
	rt_error err;
	scene *s = rt_load_string(basic, sizeof basic - 1, "basic.rt", NULL, &err);
	if (!s)
		fail_msg("%s", err.msg);
	editor *ed = editor_new(s, "basic.rt");
	assert_non_null(ed);
	return ed;
}

#define MAX_STEPS 64

static void test_undo_redo_restore_every_state(void **state)
{
	(void)state;
	editor *ed = new_editor();
	scene *snap[MAX_STEPS];
	int n = 0;
	rt_error err;
	snap[n++] = scene_clone(editor_scene(ed));
#define STEP(call)                                                    \
	do {                                                          \
		if (!(call))                                          \
			fail_msg("%s failed: %s", #call, err.msg);    \
		snap[n++] = scene_clone(editor_scene(ed));            \
	} while (0)
	STEP(editor_object_move(ed, 0, v3(1, 0, 0), &err));
	STEP(editor_object_rotate(ed, 2, v3(30, 45, 60), &err));
	STEP(editor_object_scale(ed, 0, v3(2, 1, 0.5), &err));
	STEP(editor_object_color(ed, 1, v3(1, 2, 3), &err));
	STEP(editor_light_pos(ed, 1, v3(-1, -2, -3), &err));
	STEP(editor_light_move(ed, 0, v3(1, 1, 1), &err));
	STEP(editor_light_brightness(ed, 0, 0.25, &err));
	STEP(editor_light_color(ed, 1, v3(0, 255, 0), &err));
	STEP(editor_camera_move(ed, v3(0, 0, 1), &err));
	STEP(editor_camera_turn(ed, 10, -5, &err));
	STEP(editor_camera_fov(ed, 90, &err));
	STEP(editor_camera_lookat(ed, v3(0, 0, 0), &err));
	STEP(editor_set_ambient(ed, &(ambient){0.5, v3(10, 20, 30)}, &err));
	object o = object_make(OBJ_CUBE, v3(9, 9, 9));
	STEP(editor_insert_object(ed, 1, &o, &err));
	STEP(editor_delete_object(ed, 0, &err));
	STEP(editor_delete_light(ed, 1, &err));
	STEP(editor_add_camera(ed, &(camera){v3(1, 2, 3), v3(0, 0, 1), 40, false, 0, 0}, &err));
	STEP(editor_select_camera(ed, 1, &err));
	STEP(editor_delete_camera(ed, 0, &err));
	STEP(editor_add_line(ed, "sp 1,1,1 0.5 0,255,0", "add", 0, NULL, &err));
	STEP(editor_add_line(ed, "C 0,0,-9 0,0,1 60", "add", 0, NULL, &err));
	STEP(editor_add_line(ed, "A 0.3 255,0,0", "add", 0, NULL, &err));
	STEP(editor_add_line(ed, "R 320 200", "add", 0, NULL, &err));
	STEP(editor_add_line(ed, "l 1,2,3 0.7 10,20,30", "add", 0, NULL, &err));
	const char *otext = "C 0,0,0 0,0,1 50\nsp 0,0,5 1 1,2,3\n";
	scene *other = rt_load_string(otext, strlen(otext), "other.rt", NULL, &err);
	assert_non_null(other);
	STEP(editor_replace(ed, other, "other.rt", &err));
	assert_string_equal(editor_label(ed), "other.rt");
	STEP(editor_object_move(ed, 0, v3(0, 1, 0), &err));
#undef STEP
	assert_int_equal(editor_undo_count(ed), (size_t)(n - 1));
	/* Each state differs from the one before (the test would prove nothing). */
	for (int i = 1; i < n; i++)
		assert_false(scene_equal(snap[i], snap[i - 1]));
	uint64_t g = editor_generation(ed);
	for (int i = n - 2; i >= 0; i--) {
		assert_true(editor_undo(ed, &err));
		assert_true(scene_equal(editor_scene(ed), snap[i]));
	}
	assert_true(editor_generation(ed) > g);
	assert_string_equal(editor_label(ed), "basic.rt");
	assert_false(editor_undo(ed, &err));
	assert_string_equal(err.msg, "nothing to undo");
	for (int i = 1; i < n; i++) {
		assert_true(editor_redo(ed, &err));
		assert_true(scene_equal(editor_scene(ed), snap[i]));
	}
	assert_false(editor_redo(ed, &err));
	/* A new edit after undo forgets the redo history. */
	assert_true(editor_undo(ed, &err));
	assert_true(editor_object_move(ed, 0, v3(5, 0, 0), &err));
	assert_int_equal(editor_redo_count(ed), 0);
	for (int i = 0; i < n; i++)
		scene_free(snap[i]);
	editor_free(ed);
}

static void test_invalid_edits_change_nothing(void **state)
{
	(void)state;
	editor *ed = new_editor();
	scene *before = scene_clone(editor_scene(ed));
	uint64_t g = editor_generation(ed);
	rt_error err;
	assert_false(editor_light_brightness(ed, 0, 1.5, &err));
	assert_false(editor_light_color(ed, 0, v3(256, 0, 0), &err));
	assert_false(editor_object_scale(ed, 0, v3(-1, 1, 1), &err));
	assert_false(editor_object_move(ed, 3, v3(1, 0, 0), &err));
	assert_string_equal(err.msg, "there is no object 4; expected 1..3");
	/* fov 0 and 180 are clamped as in files (issue 14: one rule, rules.h) */
	assert_false(editor_camera_fov(ed, 180.5, &err));
	assert_false(editor_camera_fov(ed, -1, &err));
	assert_false(editor_camera_dir(ed, v3(0, 0, 0), &err));
	assert_false(editor_camera_lookat(ed, v3(0, 0, -5), &err));
	assert_false(editor_delete_light(ed, 2, &err));
	assert_false(editor_delete_camera(ed, 0, &err)); /* the only one */
	assert_false(editor_set_ambient(ed, &(ambient){2, v3(0, 0, 0)}, &err));
	assert_false(editor_add_line(ed, "sp 1,1,1 zero 0,255,0", "add", 0, NULL, &err));
	assert_false(editor_add_line(ed, "", "add", 0, NULL, &err));
	assert_false(editor_select_camera(ed, 1, &err));
	assert_true(scene_equal(editor_scene(ed), before));
	assert_int_equal(editor_generation(ed), g);
	assert_int_equal(editor_undo_count(ed), 0);
	scene_free(before);
	editor_free(ed);
}

/* Camera verbs by hand: the camera at 0,0,-5 looks along +Z, so its right
 * axis is +X (cross(up, forward) = cross(Y, Z) = X) and its up axis is +Y. */
static void test_camera_verbs_by_hand(void **state)
{
	(void)state;
	editor *ed = new_editor();
	rt_error err;
	assert_true(editor_camera_move(ed, v3(1, 2, 3), &err));
	camera c = scene_camera(editor_scene(ed));
	assert_vec_near(c.pos, v3(1, 2, -2), 1e-12);
	assert_true(editor_camera_turn(ed, 90, 0, &err)); /* yaw right: +Z turns to +X */
	c = scene_camera(editor_scene(ed));
	assert_vec_near(c.dir, v3(1, 0, 0), 1e-12);
	assert_true(editor_camera_turn(ed, 0, 30, &err)); /* pitch up 30 degrees */
	c = scene_camera(editor_scene(ed));
	assert_vec_near(c.dir, v3(cos(RT_PI / 6), sin(RT_PI / 6), 0), 1e-12);
	/* Now forward is (cos30, sin30, 0): moving forward 2 goes along it. */
	assert_true(editor_camera_move(ed, v3(0, 0, 2), &err));
	c = scene_camera(editor_scene(ed));
	assert_vec_near(c.pos, v3(1 + 2 * cos(RT_PI / 6), 2 + 1, -2), 1e-12);
	assert_true(editor_camera_lookat(ed, v3(1, 2, 10), &err)); /* from x=1+1.73, y=3, z=-2 */
	c = scene_camera(editor_scene(ed));
	vec3 want = v3_norm(v3(-2 * cos(RT_PI / 6), -1, 12));
	assert_vec_near(c.dir, want, 1e-12);
	editor_free(ed);
}

/* Pitching up 60 then 60 degrees more stops at 89 degrees above the horizon
 * (elevation asin(y) = 89 deg, heading kept along +Z); yaw then turns about
 * the vertical, keeping the elevation. A camera loaded straight down comes
 * back up towards the top of its picture (+Z, see cam_view_make). */
static void test_camera_pitch_stops_short_of_vertical(void **state)
{
	(void)state;
	editor *ed = new_editor();
	rt_error err;
	double e = deg_to_rad(89.0);
	assert_true(editor_camera_turn(ed, 0, 60, &err));
	assert_true(editor_camera_turn(ed, 0, 60, &err));
	camera c = scene_camera(editor_scene(ed));
	assert_vec_near(c.dir, v3(0, sin(e), cos(e)), 1e-12);
	assert_true(editor_camera_turn(ed, 90, 0, &err));
	c = scene_camera(editor_scene(ed));
	assert_vec_near(c.dir, v3(cos(e), sin(e), 0), 1e-12);
	assert_true(editor_camera_dir(ed, v3(0, -3, 0), &err));
	assert_true(editor_camera_turn(ed, 0, 90 - 30, &err));
	c = scene_camera(editor_scene(ed));
	assert_vec_near(c.dir, v3(0, -sin(RT_PI / 6), cos(RT_PI / 6)), 1e-12);
	editor_free(ed);
}

static void test_groups_and_limits(void **state)
{
	(void)state;
	editor *ed = new_editor();
	rt_error err;
	scene *before = scene_clone(editor_scene(ed));
	editor_group_begin(ed);
	for (int i = 0; i < 5; i++)
		assert_true(editor_object_move(ed, 0, v3(0.1, 0, 0), &err));
	editor_group_end(ed);
	assert_int_equal(editor_undo_count(ed), 1);
	assert_true(editor_undo(ed, &err));
	assert_true(scene_equal(editor_scene(ed), before));
	assert_true(editor_redo(ed, &err));
	assert_near(editor_scene(ed)->objs[0].pos.x, 0.5, 1e-12);
	for (int i = 0; i < EDITOR_MAX_UNDO + 10; i++)
		assert_true(editor_object_move(ed, 1, v3(0, 0, 0.001), &err));
	assert_int_equal(editor_undo_count(ed), EDITOR_MAX_UNDO);
	/* Whole scenes: only EDITOR_MAX_SCENES are kept. */
	for (int i = 0; i < EDITOR_MAX_SCENES + 3; i++)
		assert_true(editor_replace(ed, scene_clone(before), "x", &err));
	size_t scenes = 0;
	while (editor_undo(ed, &err))
		scenes += editor_scene(ed)->nobjs == 3;
	assert_true(scenes <= EDITOR_MAX_SCENES + 1);
	scene_free(before);
	editor_free(ed);
}

/* Edits of a big scene record one element, not the scene: 1000 edits of a
 * 200000-object scene change the scene in place (the same scene and the
 * same object array, never copied) and keep 1000 undo records of one
 * object each, no whole scene (the memory estimate holds one scene, the
 * current one, and its bytes do not grow); 1000 undos return to the start.
 * Counted, not timed, so that it holds under the sanitizers too. */
static void test_big_scene_edits_are_cheap(void **state)
{
	(void)state;
	scene *s = scene_new();
	rt_error err;
	assert_true(scene_add_camera(s, &(camera){v3(0, 0, -5), v3(0, 0, 1), 70, false, 0, 0}, &err));
	object o = object_make(OBJ_SPHERE, v3(255, 0, 0));
	for (int i = 0; i < 200000; i++) {
		o.pos = v3(i, 0, 0);
		assert_true(scene_add_object(s, &o, &err));
	}
	long scenes0;
	double bytes0 = mem_held(&scenes0);
	editor *ed = editor_new(s, NULL);
	long scenes;
	double bytes = mem_held(&scenes);
	assert_int_equal(scenes, scenes0 + 1);
	const object *objs = editor_scene(ed)->objs;
	for (int i = 0; i < 1000; i++) {
		assert_true(editor_object_move(ed, (size_t)i * 199, v3(0, 1, 0), &err));
		assert_ptr_equal(editor_scene(ed), s);
		assert_ptr_equal(editor_scene(ed)->objs, objs);
	}
	assert_int_equal(editor_undo_count(ed), 1000);
	assert_near(editor_scene(ed)->objs[199].pos.y, 1, 0);
	assert_near(mem_held(&scenes), bytes, 0);
	assert_int_equal(scenes, scenes0 + 1);
	for (int i = 0; i < 1000; i++) {
		assert_true(editor_undo(ed, &err));
		assert_ptr_equal(editor_scene(ed)->objs, objs);
	}
	assert_int_equal(editor_undo_count(ed), 0);
	assert_near(editor_scene(ed)->objs[199].pos.y, 0, 0);
	assert_near(mem_held(&scenes), bytes, 0);
	assert_int_equal(scenes, scenes0 + 1);
	editor_free(ed);
	assert_near(mem_held(&scenes), bytes0, 0);
	assert_int_equal(scenes, scenes0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_undo_redo_restore_every_state),
		cmocka_unit_test(test_invalid_edits_change_nothing),
		cmocka_unit_test(test_camera_verbs_by_hand),
		cmocka_unit_test(test_camera_pitch_stops_short_of_vertical),
		cmocka_unit_test(test_groups_and_limits),
		cmocka_unit_test(test_big_scene_edits_are_cheap),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
