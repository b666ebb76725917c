/* rtsh — tests of key mode without a terminal: the step rule, the
 * selection order, what each key does (keymode_map), the edits it makes
 * through the editor (keymode_apply), the Euler angles of a roll, and a
 * whole session drawing into a pipe: a run of one key is one undo step,
 * frames come, the status line and help bar are drawn. The session part
 * runs a render thread; `make test` runs it under ThreadSanitizer too. */
#include "testutil.h"

#include <fcntl.h>
#include <stdio.h>
#include <poll.h>
#include <time.h>
#include <unistd.h>

#include "rtsh/edit.h"
#include "rtsh/rtfile.h"
#include "rtsh/shape.h"
#include "shell/commands.h"
#include "shell/keymode.h"
#include "shell/options.h"
#include "term/keys.h"

/* The box around the objects but the plane, the light and the camera is
 * x -10..10, y -2..10, z -10..2: its longest side is 20, so step = 0.5. */
static const char scene_text[] = "A 0.3 255,255,255\n"
                                 "C 0,0,-10 0,0,1 70\n"
                                 "L -10,10,-10 0.7 255,255,255\n"
                                 "sp 0,0,0 4 230,60,50\n"
                                 "sp 8,0,0 4 60,200,80\n"
                                 "cu -6,0,0 0,1,0 3,3,3 70,110,235 0.9 0.5 50 0\n"
                                 "pl 0,-2,0 0,1,0 200,200,200\n";

static scene *load(const char *text)
{
	rt_error err;
	scene *s = rt_load_string(text, strlen(text), "k.rt", NULL, &err);
	if (!s)
		fail_msg("%s", err.msg);
	return s;
}

static const km_sel camera_sel = {KM_SEL_CAMERA, 0};

static void test_step_rule(void **state)
{
	(void)state;
	scene *s = load(scene_text);
	assert_near(keymode_step(s), 0.5, 1e-12);
	scene_free(s);
	/* Ten times the scene: ten times the step. */
	s = load("C 0,0,-100 0,0,1 70\nL -100,100,-100 0.7\nsp 0,0,0 40 230,60,50\nsp 80,0,0 40 60,200,80\n");
	assert_near(keymode_step(s), 5.0, 1e-12);
	scene_free(s);
	/* Planes do not count; a scene that is one point steps 1/40. */
	s = load("C 0,0,0 0,0,1 70\npl 0,-2,0 0,1,0 200,200,200\n");
	assert_near(keymode_step(s), 1.0 / 40, 1e-12);
	scene_free(s);
	/* A far camera makes the step larger. */
	s = load("C 0,0,-400 0,0,1 70\nsp 0,0,0 2 255,0,0\n");
	assert_near(keymode_step(s), 401.0 / 40, 1e-12);
	scene_free(s);
}

static void test_selection_order(void **state)
{
	(void)state;
	scene *s = load(scene_text); /* 4 objects, 1 light */
	km_sel sel = camera_sel;
	const km_sel_kind kinds[] = {KM_SEL_OBJECT, KM_SEL_OBJECT, KM_SEL_OBJECT, KM_SEL_OBJECT, KM_SEL_LIGHT,
	                             KM_SEL_CAMERA};
	const size_t idx[] = {0, 1, 2, 3, 0, 0};
	for (int i = 0; i < 6; i++) {
		sel = keymode_select(s, sel, 1);
		assert_int_equal(sel.kind, kinds[i]);
		assert_int_equal(sel.index, idx[i]);
	}
	sel = keymode_select(s, camera_sel, -1);
	assert_int_equal(sel.kind, KM_SEL_LIGHT);
	sel = keymode_select(s, sel, -1);
	assert_int_equal(sel.kind, KM_SEL_OBJECT);
	assert_int_equal(sel.index, 3);
	assert_true(keymode_sel_valid(s, (km_sel){KM_SEL_OBJECT, 3}));
	assert_false(keymode_sel_valid(s, (km_sel){KM_SEL_OBJECT, 4}));
	assert_false(keymode_sel_valid(s, (km_sel){KM_SEL_LIGHT, 1}));
	/* Tab through keymode_map does the same. */
	km_action a = keymode_map('\t', s, camera_sel, 0.5);
	assert_int_equal(a.op, KM_SELECT);
	assert_int_equal(a.sel.kind, KM_SEL_OBJECT);
	assert_int_equal(a.sel.index, 0);
	a = keymode_map(KEYS_BACKTAB, s, camera_sel, 0.5);
	assert_int_equal(a.sel.kind, KM_SEL_LIGHT);
	scene_free(s);
}

static void assert_move(const scene *s, km_sel sel, int key, vec3 d)
{
	km_action a = keymode_map(key, s, sel, 0.5);
	assert_int_equal(a.op, KM_MOVE);
	assert_int_equal(a.sel.kind, sel.kind);
	assert_vec_near(a.d, d, 1e-12);
}

static void test_movement_keys(void **state)
{
	(void)state;
	scene *s = load(scene_text); /* the camera looks along +z: right is +x */
	const km_sel obj = {KM_SEL_OBJECT, 0};
	for (int k = 0; k < 2; k++) {
		km_sel sel = k ? obj : camera_sel;
		assert_move(s, sel, KEYS_UP, v3(0, 0, 0.5));
		assert_move(s, sel, 'w', v3(0, 0, 0.5));
		assert_move(s, sel, KEYS_DOWN, v3(0, 0, -0.5));
		assert_move(s, sel, 's', v3(0, 0, -0.5));
		assert_move(s, sel, KEYS_LEFT, v3(-0.5, 0, 0));
		assert_move(s, sel, 'a', v3(-0.5, 0, 0));
		assert_move(s, sel, KEYS_RIGHT, v3(0.5, 0, 0));
		assert_move(s, sel, 'D', v3(0.5, 0, 0));
		assert_move(s, sel, 'r', v3(0, 0.5, 0));
		assert_move(s, sel, 'f', v3(0, -0.5, 0));
	}
	scene_free(s);
	/* The camera looks 45 degrees down: it flies along its view; an object
	 * slides level with the floor. */
	s = load("C 0,10,-10 0,-1,1 70\nsp 0,0,0 2 255,0,0\n");
	double h = 0.5 / sqrt(2.0);
	assert_move(s, camera_sel, KEYS_UP, v3(0, -h, h));
	assert_move(s, obj, KEYS_UP, v3(0, 0, 0.5));
	assert_move(s, obj, 'R', v3(0, 0.5, 0));
	scene_free(s);
	/* Straight down: forward for an object is the camera's up. */
	s = load("C 0,10,0 0,-1,0 70\nsp 0,0,0 2 255,0,0\n");
	km_action a = keymode_map(KEYS_UP, s, obj, 1.0);
	assert_near(v3_len(a.d), 1.0, 1e-12);
	assert_near(a.d.y, 0.0, 1e-12);
	scene_free(s);
}

static void test_other_keys(void **state)
{
	(void)state;
	scene *s = load(scene_text);
	const km_sel obj = {KM_SEL_OBJECT, 2};
	struct {
		int key;
		km_op op;
		double a, b;
		int n;
	} cases[] = {
		{'j', KM_TURN, -KEYMODE_TURN_DEG, 0, 0},
		{KEYS_SHIFT_LEFT, KM_TURN, -KEYMODE_TURN_DEG, 0, 0},
		{'l', KM_TURN, KEYMODE_TURN_DEG, 0, 0},
		{KEYS_SHIFT_RIGHT, KM_TURN, KEYMODE_TURN_DEG, 0, 0},
		{'i', KM_TURN, 0, KEYMODE_TURN_DEG, 0},
		{KEYS_SHIFT_UP, KM_TURN, 0, KEYMODE_TURN_DEG, 0},
		{'k', KM_TURN, 0, -KEYMODE_TURN_DEG, 0},
		{KEYS_SHIFT_DOWN, KM_TURN, 0, -KEYMODE_TURN_DEG, 0},
		{'+', KM_SCALE, KEYMODE_SCALE, 0, 0},
		{'=', KM_SCALE, KEYMODE_SCALE, 0, 0},
		{'-', KM_SCALE, 1 / KEYMODE_SCALE, 0, 0},
		{',', KM_SAMPLES, 0, 0, -1},
		{'.', KM_SAMPLES, 0, 0, 1},
		{'<', KM_DEPTH, 0, 0, -1},
		{'>', KM_DEPTH, 0, 0, 1},
		{KEYS_PAGE_UP, KM_SCENE, 0, 0, -1},
		{KEYS_PAGE_DOWN, KM_SCENE, 0, 0, 1},
		{'m', KM_MODE, 0, 0, 0},
		{' ', KM_STOP, 0, 0, 0},
		{'u', KM_UNDO, 0, 0, 0},
		{'U', KM_REDO, 0, 0, 0},
		{12, KM_REDRAW, 0, 0, 0},
		{KEYS_F(5), KM_REDRAW, 0, 0, 0},
		{'?', KM_HELP, 0, 0, 0},
		{KEYS_F(1), KM_HELP, 0, 0, 0},
		{KEYS_ESC, KM_QUIT, 0, 0, 0},
		{'q', KM_QUIT, 0, 0, 0},
		{'x', KM_NONE, 0, 0, 0},
		{KEYS_OTHER, KM_NONE, 0, 0, 0},
		{KEYS_HOME, KM_NONE, 0, 0, 0},
	};
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		km_action a = keymode_map(cases[i].key, s, obj, 0.5);
		if (a.op != cases[i].op)
			fail_msg("key %d: op %d, expected %d", cases[i].key, a.op, cases[i].op);
		assert_near(a.a, cases[i].a, 1e-12);
		assert_near(a.b, cases[i].b, 1e-12);
		assert_int_equal(a.n, cases[i].n);
		assert_int_equal(a.sel.index, 2);
	}
	/* [ and ] turn about the vertical; { and } roll about the line of
	 * sight (here +z: a roll about Z). */
	assert_vec_near(keymode_map('[', s, obj, 0.5).d, v3(0, KEYMODE_ROTATE_DEG, 0), 1e-12);
	assert_vec_near(keymode_map(']', s, obj, 0.5).d, v3(0, -KEYMODE_ROTATE_DEG, 0), 1e-12);
	assert_vec_near(keymode_map('{', s, obj, 0.5).d, v3(0, 0, KEYMODE_ROTATE_DEG), 1e-9);
	assert_vec_near(keymode_map('}', s, obj, 0.5).d, v3(0, 0, -KEYMODE_ROTATE_DEG), 1e-9);
	assert_true(keymode_is_edit(KM_MOVE) && keymode_is_edit(KM_TURN) && keymode_is_edit(KM_ROTATE) &&
	            keymode_is_edit(KM_SCALE));
	assert_false(keymode_is_edit(KM_SELECT) || keymode_is_edit(KM_UNDO) || keymode_is_edit(KM_SCENE));
	scene_free(s);
}

/* The Euler angles of a rotation about an axis turn every direction as the
 * rotation itself does (object_rotate's order: X, then Y, then Z). */
static void test_axis_euler(void **state)
{
	(void)state;
	test_rng rng = {7};
	for (int i = 0; i < 500; i++) {
		vec3 axis = tdir(&rng), v = tdir(&rng);
		double deg = trange(&rng, -180, 180);
		if (i % 50 == 0)
			axis = v3(0, i % 100 ? 1 : -1, 0); /* gimbal lock: a turn about Y by 90 */
		if (i % 50 == 0)
			deg = 90;
		vec3 e = keymode_axis_euler(axis, deg);
		mat4 q = m4_mul(m4_rotate_z(deg_to_rad(e.z)), m4_mul(m4_rotate_y(deg_to_rad(e.y)), m4_rotate_x(deg_to_rad(e.x))));
		mat4 r = m4_rotate_axis(axis, deg_to_rad(deg));
		assert_vec_near(m4_vector(&q, v), m4_vector(&r, v), 1e-9);
	}
}

static void test_apply(void **state)
{
	(void)state;
	editor *ed = editor_new(load(scene_text), NULL);
	const scene *s;
	rt_error err;
	const km_sel obj = {KM_SEL_OBJECT, 0}, lamp = {KM_SEL_LIGHT, 0}, cube = {KM_SEL_OBJECT, 2};
	/* Object: two steps right, then undo one. */
	for (int i = 0; i < 2; i++) {
		km_action a = keymode_map(KEYS_RIGHT, editor_scene(ed), obj, 0.5);
		assert_true(keymode_apply(ed, &a, &err));
	}
	s = editor_scene(ed);
	assert_vec_near(s->objs[0].pos, v3(1, 0, 0), 1e-12);
	assert_true(editor_undo(ed, &err));
	assert_vec_near(editor_scene(ed)->objs[0].pos, v3(0.5, 0, 0), 1e-12);
	/* Camera: forward, up. */
	km_action a = keymode_map(KEYS_UP, editor_scene(ed), camera_sel, 0.5);
	assert_true(keymode_apply(ed, &a, &err));
	a = keymode_map('r', editor_scene(ed), camera_sel, 0.5);
	assert_true(keymode_apply(ed, &a, &err));
	assert_vec_near(scene_camera(editor_scene(ed)).pos, v3(0, 0.5, -9.5), 1e-12);
	/* Light: moves; brightness in steps of 0.05, up to 1 and no further. */
	a = keymode_map(KEYS_LEFT, editor_scene(ed), lamp, 0.5);
	assert_true(keymode_apply(ed, &a, &err));
	assert_vec_near(editor_scene(ed)->lights[0].pos, v3(-10.5, 10, -10), 1e-12);
	a = keymode_map('+', editor_scene(ed), lamp, 0.5);
	for (int i = 0; i < 10; i++)
		assert_true(keymode_apply(ed, &a, &err));
	assert_near(editor_scene(ed)->lights[0].ratio, 1.0, 1e-12);
	uint64_t gen = editor_generation(ed);
	assert_true(keymode_apply(ed, &a, &err));
	assert_int_equal(editor_generation(ed), gen); /* nothing to change: no edit */
	a = keymode_map('-', editor_scene(ed), lamp, 0.5);
	assert_true(keymode_apply(ed, &a, &err));
	assert_near(editor_scene(ed)->lights[0].ratio, 0.95, 1e-12);
	/* Objects grow and shrink by 1.1. */
	a = keymode_map('+', editor_scene(ed), cube, 0.5);
	assert_true(keymode_apply(ed, &a, &err));
	assert_vec_near(editor_scene(ed)->objs[2].scale, v3(3.3, 3.3, 3.3), 1e-12);
	/* The camera zooms: + narrows the field of view by 5 degrees. */
	a = keymode_map('+', editor_scene(ed), camera_sel, 0.5);
	assert_true(keymode_apply(ed, &a, &err));
	assert_near(scene_camera(editor_scene(ed)).fov, 65, 1e-12);
	/* An orthographic camera has no field of view (the fov would change and
	 * the picture not): + shows a height 1.1 times smaller, - 1.1 larger,
	 * and its fov stays as written. */
	{
		editor *oe = editor_new(load("A 0.3 255,255,255\nC 0,0,-10 0,0,1 70 ortho=2\nsp 0,0,0 1 255,0,0\n"), "o.rt");
		assert_non_null(oe);
		km_action z = keymode_map('+', editor_scene(oe), camera_sel, 0.5);
		assert_true(keymode_apply(oe, &z, &err));
		assert_near(scene_camera(editor_scene(oe)).ortho, 2 / 1.1, 1e-12);
		assert_near(scene_camera(editor_scene(oe)).fov, 70, 0);
		z = keymode_map('-', editor_scene(oe), camera_sel, 0.5);
		assert_true(keymode_apply(oe, &z, &err));
		z = keymode_map('-', editor_scene(oe), camera_sel, 0.5);
		assert_true(keymode_apply(oe, &z, &err));
		assert_near(scene_camera(editor_scene(oe)).ortho, 2 * 1.1, 1e-12);
		assert_near(scene_camera(editor_scene(oe)).fov, 70, 0);
		/* the shell's camera fov is refused there, and says why */
		assert_false(editor_camera_fov(oe, 30, &err));
		assert_non_null(strstr(err.msg, "orthographic"));
		assert_near(scene_camera(editor_scene(oe)).fov, 70, 0);
		editor_free(oe);
	}
	/* ] turns the cube's front to the right: -15 degrees about Y, a twist
	 * for an upright cube. */
	a = keymode_map(']', editor_scene(ed), cube, 0.5);
	assert_true(keymode_apply(ed, &a, &err));
	s = editor_scene(ed);
	assert_vec_near(v3_norm(s->objs[2].dir), v3(0, 1, 0), 1e-9);
	assert_near(fmod(s->objs[2].twist + 360.0, 360.0), 345.0, 1e-9);
	/* } rolls the cube clockwise on the screen: its up axis leans right. */
	a = keymode_map('}', editor_scene(ed), cube, 0.5);
	assert_true(keymode_apply(ed, &a, &err));
	vec3 d = v3_norm(editor_scene(ed)->objs[2].dir);
	assert_vec_near(d, v3(sin(deg_to_rad(15)), cos(deg_to_rad(15)), 0), 1e-9);
	/* Only objects rotate. */
	a = keymode_map('[', editor_scene(ed), camera_sel, 0.5);
	assert_false(keymode_apply(ed, &a, &err));
	assert_string_equal(err.msg, "only objects rotate; press Tab to select one");
	/* A selection that is gone is refused. */
	a = keymode_map(KEYS_UP, editor_scene(ed), (km_sel){KM_SEL_OBJECT, 9}, 0.5);
	assert_false(keymode_apply(ed, &a, &err));
	editor_free(ed);
}

static void test_turns(void **state)
{
	(void)state;
	editor *ed = editor_new(load(scene_text), NULL);
	rt_error err;
	/* 30 turns of 3 degrees to the right: looking along +x. */
	km_action a = keymode_map('l', editor_scene(ed), camera_sel, 0.5);
	for (int i = 0; i < 30; i++)
		assert_true(keymode_apply(ed, &a, &err));
	assert_vec_near(v3_norm(scene_camera(editor_scene(ed)).dir), v3(1, 0, 0), 1e-9);
	/* Pitching up stops 89 degrees above the horizon, and the heading stays. */
	a = keymode_map('i', editor_scene(ed), camera_sel, 0.5);
	for (int i = 0; i < 40; i++)
		assert_true(keymode_apply(ed, &a, &err));
	vec3 d = v3_norm(scene_camera(editor_scene(ed)).dir);
	assert_near(rad_to_deg(asin(d.y)), 89.0, 1e-9);
	assert_near(d.z, 0.0, 1e-9);
	assert_true(d.x > 0);
	/* Turning while looking up still turns about the vertical. */
	a = keymode_map('j', editor_scene(ed), camera_sel, 0.5);
	assert_true(keymode_apply(ed, &a, &err));
	d = v3_norm(scene_camera(editor_scene(ed)).dir);
	assert_near(rad_to_deg(asin(d.y)), 89.0, 1e-9);
	assert_near(rad_to_deg(atan2(d.x, d.z)), 87.0, 1e-9);
	editor_free(ed);
}

/* --- a whole session, drawing into a pipe --- */

typedef struct session {
	char path[64];
	int wake[2], out; /* frames go to a file (a pipe would fill up) */
	rtsh_options opt;
	shell sh;
	termout *o; /* unpaced: whole updates at once */
	keymode *km;
	char *text; /* everything drawn */
	size_t len, cap;
} session;

static double seconds(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)t.tv_sec + t.tv_nsec * 1e-9;
}

static void drain_output(session *ss)
{
	char buf[65536];
	ssize_t n;
	while ((n = pread(ss->out, buf, sizeof buf, (off_t)ss->len)) > 0) {
		if (ss->len + (size_t)n + 1 > ss->cap) {
			ss->cap = (ss->len + (size_t)n + 1) * 2;
			ss->text = realloc(ss->text, ss->cap);
			assert_non_null(ss->text);
		}
		memcpy(ss->text + ss->len, buf, (size_t)n);
		ss->len += (size_t)n;
		ss->text[ss->len] = '\0';
	}
}

/* Ticks the session for `secs` seconds, as keymode_run's loop does. */
static long run_for(session *ss, double secs)
{
	long frames = 0;
	double end = seconds() + secs;
	while (seconds() < end) {
		frames += keymode_tick(ss->km);
		drain_output(ss);
		struct pollfd p = {ss->wake[0], POLLIN, 0};
		poll(&p, 1, 5);
		char buf[64];
		while (read(ss->wake[0], buf, sizeof buf) > 0)
			;
	}
	return frames;
}

static void session_open(session *ss)
{
	memset(ss, 0, sizeof *ss);
	snprintf(ss->path, sizeof ss->path, "/tmp/rtsh-keymode-XXXXXX.rt");
	int fd = mkstemps(ss->path, 3);
	assert_true(fd >= 0);
	assert_int_equal(write(fd, scene_text, sizeof scene_text - 1), (ssize_t)(sizeof scene_text - 1));
	close(fd);
	assert_int_equal(pipe(ss->wake), 0);
	FILE *f = tmpfile();
	assert_non_null(f);
	ss->out = dup(fileno(f));
	fclose(f);
	for (int i = 0; i < 2; i++)
		fcntl(ss->wake[i], F_SETFL, O_NONBLOCK);
	ss->opt.scene = ss->path;
	ss->opt.quiet = true;
	assert_true(shell_init(&ss->sh, &ss->opt, ss->wake[1]));
	command_table_install(&ss->sh);
	ss->sh.wake[0] = ss->wake[0];
	ss->sh.wake[1] = ss->wake[1];
	ss->sh.set.threads = 2;
	ss->o = termout_new(ss->out);
	assert_non_null(ss->o);
	ss->km = keymode_new(&ss->sh, ss->o, PALETTE_TRUECOLOR, 160, 48);
	assert_non_null(ss->km);
}

static void session_close(session *ss)
{
	keymode_free(ss->km);
	termout_free(ss->o);
	shell_free(&ss->sh);
	for (int i = 0; i < 2; i++)
		close(ss->wake[i]);
	close(ss->out);
	unlink(ss->path);
	free(ss->text);
}

static void test_session(void **state)
{
	(void)state;
	session ss;
	session_open(&ss);
	assert_true(run_for(&ss, 0.5) >= 1);
	assert_non_null(strstr(ss.text, " view │ "));
	assert_non_null(strstr(ss.text, "\x1b[1mEsc\x1b[22m back")); /* the help bar */
	assert_null(strstr(ss.text, "\x1b[?1049")); /* never leaves the alternate screen */
	editor *ed = ss.sh.ed;
	size_t undo0 = editor_undo_count(ed);
	/* Tab selects object 1; keys without a pause between them are one
	 * undo step, whichever keys they are (issue 31, friction 4). */
	keymode_key(ss.km, '\t');
	for (int i = 0; i < 3; i++)
		keymode_key(ss.km, KEYS_RIGHT);
	assert_vec_near(editor_scene(ed)->objs[0].pos, v3(1.5, 0, 0), 1e-12);
	assert_true(run_for(&ss, 0.1) >= 1);
	assert_non_null(strstr(ss.text, "object 1 sphere"));
	keymode_key(ss.km, KEYS_UP); /* another key, no pause: the same step */
	keymode_key(ss.km, KEYS_RIGHT);
	assert_int_equal(keymode_edits(ss.km), 5);
	assert_vec_near(editor_scene(ed)->objs[0].pos, v3(2.0, 0, 0.5), 1e-12);
	/* A pause in typing ends the step; the keys after it are the next. */
	run_for(&ss, KEYMODE_STEP_PAUSE + 0.1);
	keymode_key(ss.km, KEYS_LEFT);
	keymode_key(ss.km, KEYS_DOWN);
	assert_vec_near(editor_scene(ed)->objs[0].pos, v3(1.5, 0, 0), 1e-12);
	keymode_key(ss.km, 'u'); /* takes back the keys after the pause */
	assert_vec_near(editor_scene(ed)->objs[0].pos, v3(2.0, 0, 0.5), 1e-12);
	keymode_key(ss.km, 'u'); /* and the five before it */
	assert_vec_near(editor_scene(ed)->objs[0].pos, v3(0, 0, 0), 1e-12);
	keymode_key(ss.km, 'U'); /* redo */
	assert_vec_near(editor_scene(ed)->objs[0].pos, v3(2.0, 0, 0.5), 1e-12);
	assert_int_equal(editor_undo_count(ed), undo0 + 1);
	/* 300 presses of different keys in one burst: one step. */
	size_t undo1 = editor_undo_count(ed);
	for (int i = 0; i < 300; i++)
		keymode_key(ss.km, i % 3 == 0 ? KEYS_RIGHT : i % 3 == 1 ? KEYS_UP : ']');
	assert_int_equal(editor_undo_count(ed), undo1 + 1);
	/* Settings keys change the shell's settings. */
	int samples = ss.sh.set.samples;
	keymode_key(ss.km, '.');
	assert_int_equal(ss.sh.set.samples, samples * 2);
	keymode_key(ss.km, 'm');
	assert_int_equal(ss.sh.set.mode, MODE_PATH);
	keymode_key(ss.km, '>');
	assert_int_equal(ss.sh.set.depth, 6);
	/* A key held down (30 repeats a second): frames keep coming, as the
	 * pixel ratio adapts when they are too slow (under TSan, say). */
	long frames = 0;
	for (int i = 0; i < 45; i++) {
		keymode_key(ss.km, 'l');
		frames += run_for(&ss, 1.0 / 30);
	}
	assert_true(frames >= 3);
	/* More samples than take a moment; Space stops them. */
	for (int i = 0; i < 12; i++)
		keymode_key(ss.km, '.');
	run_for(&ss, 0.3);
	keymode_key(ss.km, ' ');
	run_for(&ss, 0.1);
	assert_non_null(strstr(ss.text, "spp stopped"));
	keymode_key(ss.km, ' ');
	run_for(&ss, 0.1);
	assert_non_null(strstr(ss.text, "nothing to stop"));
	assert_false(keymode_done(ss.km));
	keymode_key(ss.km, 'q');
	assert_true(keymode_done(ss.km));
	session_close(&ss);
}

/* The keys the output scheduler held while it awaited an answer reach the
 * key decoder (keymode_run's loop, keymode_late_keys); with none held,
 * nothing, and no null source handed to memcpy: under UBSan `view` stopped
 * at once there (issue 31, defect 6). */
static void test_late_keys(void **state)
{
	(void)state;
	session ss;
	session_open(&ss);
	run_for(&ss, 0.1);
	abuf pend;
	abuf_init(&pend);
	keymode_late_keys(ss.km, &pend); /* none held: none taken */
	assert_int_equal(pend.len, 0);
	assert_false(pend.failed);
	abuf_str(&pend, "ab");
	keymode_late_keys(ss.km, &pend);
	assert_int_equal(pend.len, 2);
	assert_string_equal(pend.b, "ab");
	abuf_free(&pend);
	/* the append buffer itself: adding nothing from nowhere is nothing */
	abuf a;
	abuf_init(&a);
	abuf_add(&a, NULL, 0);
	assert_int_equal(a.len, 0);
	assert_false(a.failed);
	abuf_add(&a, "xy", 2);
	abuf_add(&a, NULL, 0);
	assert_int_equal(a.len, 2);
	assert_string_equal(a.b, "xy");
	abuf_free(&a);
	session_close(&ss);
}

/* Ticks until the output after `from` holds `want` (at most `secs`). */
static bool run_until(session *ss, size_t from, const char *want, double secs)
{
	double end = seconds() + secs;
	while (seconds() < end) {
		run_for(ss, 0.05);
		if (ss->len > from && strstr(ss->text + from, want))
			return true;
	}
	return false;
}

/* Path mode's refine passes are denoised as the shell's previews are (the
 * status line says so), and not with `set denoise off`. */
static void test_path_denoised(void **state)
{
	(void)state;
	session ss;
	session_open(&ss);
	ss.sh.set.samples = 4;
	ss.sh.set.depth = 3;
	/* chosen, as `set samples 4` marks them (else path mode refines to
	 * the preview's own 64) */
	rt_error err;
	const setting_def *def = settings_find("samples", &err);
	assert_non_null(def);
	ss.sh.hand_set |= 1u << (def - settings_table);
	run_for(&ss, 0.2);
	keymode_key(ss.km, 'm');
	assert_int_equal(ss.sh.set.mode, MODE_PATH);
	assert_true(run_until(&ss, 0, "4/4 spp │ denoised", 20.0));
	ss.sh.set.denoise = DENOISE_OFF;
	keymode_key(ss.km, 'm');
	run_for(&ss, 0.2);
	size_t from = ss.len;
	keymode_key(ss.km, 'm');
	assert_int_equal(ss.sh.set.mode, MODE_PATH);
	assert_true(run_until(&ss, from, "4/4 spp", 20.0));
	assert_null(strstr(ss.text + from, "denoised"));
	session_close(&ss);
}

/* The words of a list of key names ("Up Down, w s"): commas after a name
 * go, a lone comma is a key. */
static int key_words(const char *names, char words[][32], int max)
{
	int n = 0;
	char buf[256];
	snprintf(buf, sizeof buf, "%s", names);
	for (char *save = NULL, *t = strtok_r(buf, " ", &save); t && n < max; t = strtok_r(NULL, " ", &save)) {
		size_t len = strlen(t);
		if (len > 1 && t[len - 1] == ',')
			t[--len] = '\0';
		snprintf(words[n++], 32, "%s", t);
	}
	return n;
}

/* The key table: no key in two places; every row is a line of `help
 * view` (its names, then its text at column 31) and the help bar's items
 * are the table's, Esc first; and the i-th entry of rtsh(1)'s KEY MODE
 * Keys list names every key the i-th row names (the man page is read from
 * the source tree; skipped when it is not there). */
static void test_key_table(void **state)
{
	(void)state;
	scene *s = load(scene_text);
	int codes[256], seen = 0;
	for (size_t i = 0; i < keymode_nkeys; i++)
		for (const km_key *k = keymode_keys[i].keys; k->op != KM_NONE; k++) {
			for (int j = 0; j < seen; j++)
				if (codes[j] == k->key)
					fail_msg("key %d is in the table twice", k->key);
			assert_true(seen < 256);
			codes[seen++] = k->key;
			assert_int_equal(keymode_map(k->key, s, camera_sel, 0.5).op, k->op);
		}
	assert_true(seen >= 40);
	const char *help = keymode_help_text();
	for (size_t i = 0; i < keymode_nkeys; i++) {
		char line[512], first[256];
		snprintf(first, sizeof first, "%.*s", (int)strcspn(keymode_keys[i].what, "\n"), keymode_keys[i].what);
		snprintf(line, sizeof line, "\n  %-29s%s\n", keymode_keys[i].names, first);
		if (!strstr(help, line))
			fail_msg("help view lacks \"%s\"", line + 1);
	}
	keyview_item bar[32];
	size_t nbar = keymode_help_bar(bar, 32);
	assert_int_equal(nbar, 14);
	assert_string_equal(bar[0].keys, "Esc");
	assert_string_equal(bar[0].what, "back");
	assert_string_equal(bar[nbar - 1].what, "hide this");
	scene_free(s);

	FILE *f = fopen("man/rtsh.1", "r");
	if (!f) {
		printf("man/rtsh.1 not found (run from the source tree): the man page check is skipped\n");
		return;
	}
	char ln[512];
	bool in_keys = false, after_tp = false;
	size_t row = 0;
	while (fgets(ln, sizeof ln, f)) {
		if (strncmp(ln, ".SS Keys", 8) == 0) {
			in_keys = true;
			continue;
		}
		if (!in_keys)
			continue;
		if (strncmp(ln, ".SS", 3) == 0 || strncmp(ln, ".SH", 3) == 0)
			break;
		if (strncmp(ln, ".TP", 3) == 0) {
			after_tp = true;
			continue;
		}
		if (!after_tp)
			continue;
		after_tp = false;
		/* The key names: \- is -, quotes go. */
		char man[512];
		size_t m = 0;
		for (const char *p = ln; *p && m + 1 < sizeof man; p++) {
			if (p[0] == '\\' && p[1] == '-')
				continue;
			if (*p != '"')
				man[m++] = *p == '\n' ? ' ' : *p;
		}
		man[m] = '\0';
		assert_true(row < keymode_nkeys);
		char words[16][32];
		int nw = key_words(keymode_keys[row].names, words, 16);
		for (int w = 0; w < nw; w++) {
			char pad[600];
			snprintf(pad, sizeof pad, " %s ", words[w]);
			if (!strstr(man, pad))
				fail_msg("rtsh(1) KEY MODE entry %zu (%s) does not name %s", row + 1, man, words[w]);
		}
		row++;
	}
	fclose(f);
	assert_int_equal(row, keymode_nkeys);
}

/* Issue 9: after an undo the shell releases the render service, and
 * something else may queue a request then (here, one for another scene):
 * the service's kept world is replaced. Key mode holds its own reference,
 * so its selection marks and its renders never use a freed world (ASan
 * would report a use after free), and the picture goes on. */
static void test_undo_then_another_request(void **state)
{
	(void)state;
	session ss;
	session_open(&ss);
	assert_true(run_for(&ss, 0.3) >= 1);
	keymode_key(ss.km, KEYS_UP);
	run_for(&ss, 0.2);
	keymode_key(ss.km, 'u');
	run_for(&ss, 0.3); /* key mode takes the world of the undone scene */
	scene *other = load("C 0,0,-5 0,0,1 70\nL 0,5,-5 0.7\nsp 0,0,0 2 255,255,0\n");
	rsvc_request rq = {
		.s = other,
		.gen = (uint64_t)1 << 40,
		.set = ss.sh.set,
		.w = 32,
		.h = 18,
		.kind = RSVC_REFINE,
	};
	rq.set.samples = 1;
	rsvc_start(ss.sh.rs, &rq);
	for (int i = 0; i < 500 && rsvc_busy(ss.sh.rs); i++)
		usleep(10000);
	assert_false(rsvc_busy(ss.sh.rs));
	rsvc_hold(ss.sh.rs);
	scene_free(other);
	/* The marks of a selected object trace key mode's world; Right moves
	 * it and renders from that world too. */
	size_t before = ss.len;
	keymode_key(ss.km, '\t');
	run_for(&ss, 0.3);
	assert_true(strstr(ss.text + before, "8;2;255;205;0m") != NULL); /* the gold outline */
	keymode_key(ss.km, KEYS_RIGHT);
	assert_true(run_for(&ss, 0.3) >= 1);
	assert_non_null(strstr(ss.text + before, "object 1 sphere"));
	assert_vec_near(editor_scene(ss.sh.ed)->objs[0].pos, v3(0.5, 0, 0), 1e-12);
	session_close(&ss);
}

/* The model viewer's keys: the arrows orbit about the scene's centre (the
 * box of the objects but the plane: x -7.5..10, y and z -2..2, so
 * (1.25, 0, 0)) or the selected object's, Right turning the model right
 * (the camera goes to its left), Up tilting its front up (the camera goes
 * down); Shift+arrows fly as the arrows do elsewhere; f frames; the rest
 * as everywhere. */
static void test_model_keys(void **state)
{
	(void)state;
	scene *s = load(scene_text);
	km_action a = keymode_map_model(KEYS_RIGHT, s, camera_sel, 0.5);
	assert_int_equal(a.op, KM_ORBIT);
	assert_near(a.a, -KEYMODE_ORBIT_DEG, 0);
	assert_near(a.b, 0, 0);
	assert_vec_near(a.d, v3(1.25, 0, 0), 1e-12);
	a = keymode_map_model(KEYS_UP, s, camera_sel, 0.5);
	assert_int_equal(a.op, KM_ORBIT);
	assert_near(a.b, -KEYMODE_ORBIT_DEG, 0);
	km_sel two = {KM_SEL_OBJECT, 1};
	assert_vec_near(keymode_map_model(KEYS_LEFT, s, two, 0.5).d, v3(8, 0, 0), 1e-12);
	assert_int_equal(keymode_map_model(KEYS_SHIFT_UP, s, camera_sel, 0.5).op, KM_MOVE);
	assert_vec_near(keymode_map_model(KEYS_SHIFT_UP, s, camera_sel, 0.5).d, keymode_map(KEYS_UP, s, camera_sel, 0.5).d, 0);
	assert_int_equal(keymode_map_model('f', s, camera_sel, 0.5).op, KM_FRAME);
	assert_int_equal(keymode_map_model('F', s, camera_sel, 0.5).op, KM_MOVE);
	assert_int_equal(keymode_map_model('0', s, camera_sel, 0.5).op, KM_HOME);
	assert_true(keymode_is_edit(KM_ORBIT));
	/* The viewer's help bar names its keys: "up/down" the two keys that
	 * move the camera by one step up (+Y) and one down there (the bar said
	 * "r f", and f frames in the viewer). */
	keyview_item bar[32];
	size_t nbar = keymode_help_bar_model(bar, 32);
	size_t updown = nbar;
	for (size_t i = 0; i < nbar; i++)
		if (strcmp(bar[i].what, "up/down") == 0)
			updown = i;
	assert_true(updown < nbar);
	char up = 0, down = 0;
	assert_int_equal(sscanf(bar[updown].keys, "%c %c", &up, &down), 2);
	km_action k = keymode_map_model((unsigned char)up, s, camera_sel, 0.5);
	assert_int_equal(k.op, KM_MOVE);
	assert_vec_near(k.d, v3(0, 0.5, 0), 1e-12);
	k = keymode_map_model((unsigned char)down, s, camera_sel, 0.5);
	assert_int_equal(k.op, KM_MOVE);
	assert_vec_near(k.d, v3(0, -0.5, 0), 1e-12);
	for (size_t i = 0; i < nbar; i++)
		if (strcmp(bar[i].what, "move") == 0)
			fail_msg("the viewer's bar says the arrows move; they orbit");
	/* Applied: the camera at (0,0,-10) goes to its left on the circle of
	 * radius |(-1.25, 0, -10)| about the centre, by 5 degrees. */
	editor *ed = editor_new(s, "k.rt");
	assert_non_null(ed);
	rt_error err;
	a = keymode_map_model(KEYS_RIGHT, editor_scene(ed), camera_sel, 0.5);
	assert_true(keymode_apply(ed, &a, &err));
	camera c = scene_camera(editor_scene(ed));
	double r = sqrt(1.25 * 1.25 + 100), az = atan2(-1.25, -10) + deg_to_rad(5);
	assert_vec_near(c.pos, v3(1.25 + r * sin(az), 0, r * cos(az)), 1e-9);
	/* it looked along +Z, not at the centre: its heading turns by the same
	 * 5 degrees */
	assert_vec_near(v3_norm(c.dir), v3(sin(deg_to_rad(5)), 0, cos(deg_to_rad(5))), 1e-9);
	editor_free(ed);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_step_rule),     cmocka_unit_test(test_selection_order),
		cmocka_unit_test(test_movement_keys), cmocka_unit_test(test_other_keys),
		cmocka_unit_test(test_axis_euler),    cmocka_unit_test(test_apply),
		cmocka_unit_test(test_turns),         cmocka_unit_test(test_session),
		cmocka_unit_test(test_key_table),
		cmocka_unit_test(test_model_keys),
		cmocka_unit_test(test_undo_then_another_request),
		cmocka_unit_test(test_late_keys),
		cmocka_unit_test(test_path_denoised),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
