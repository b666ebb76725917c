/* rtsh — tests of the .rt reader and writer (rtfile.h): every dialect, every
 * element's field errors with line, column and message, the number and
 * lexing traps, strict mode, warnings, and the round trip
 * load(write(s)) == s on the wild corpus and on seeded random scenes.
 * Expected values are read off the input text by hand.
 */
#include "testutil.h"

#include <locale.h>
#include <sys/stat.h>
#include <unistd.h>

#include "rtsh/render.h"
#include "rtsh/rtfile.h"
#include "rtsh/rules.h"
#include "rtsh/settings.h"
#include "scene/rtfile_priv.h"

#define WILD_DIR "../shared/scenes-wild"

/* --- helpers --- */

typedef struct warn_log {
	int n;
	rt_error last;
} warn_log;

static void warn_collect(void *ctx, const rt_error *w)
{
	warn_log *log = ctx;
	log->n++;
	log->last = *w;
}

static scene *load_with(const char *text, size_t len, const char *name, bool strict, warn_log *log,
                        rt_error *err)
{
	rt_warnings w = {warn_collect, log};
	rt_load_opts o = {.strict = strict, .warn = log ? &w : NULL};
	rt_error_clear(err);
	return rt_load_string(text, len, name, &o, err);
}

/* Loads text (lenient, name "t.rt"); fails the test with the message if it
 * does not load. */
static scene *load_ok(const char *text)
{
	rt_error err;
	scene *s = load_with(text, strlen(text), "t.rt", false, NULL, &err);
	if (!s) {
		char buf[700];
		rt_error_format(&err, buf, sizeof buf);
		fail_msg("did not load: %s\n--- text:\n%s", buf, text);
	}
	return s;
}

static scene *load_strict_ok(const char *text)
{
	rt_error err;
	scene *s = load_with(text, strlen(text), "t.rt", true, NULL, &err);
	if (!s) {
		char buf[700];
		rt_error_format(&err, buf, sizeof buf);
		fail_msg("did not load under strict: %s\n--- text:\n%s", buf, text);
	}
	return s;
}

/* Asserts that text fails at line:col with msg in the message. */
static void expect_error_len(const char *text, size_t len, bool strict, int line, int col,
                             const char *msg)
{
	rt_error err;
	scene *s = load_with(text, len, "t.rt", strict, NULL, &err);
	if (s) {
		scene_free(s);
		fail_msg("loaded, expected %d:%d %s\n--- text:\n%s", line, col, msg, text);
	}
	if (err.line != line || err.col != col || !strstr(err.msg, msg) || strcmp(err.file, "t.rt"))
		fail_msg("got %s:%d:%d: %s\nexpected t.rt:%d:%d: ...%s...\n--- text:\n%s", err.file,
		         err.line, err.col, err.msg, line, col, msg, text);
}

static void expect_error(const char *text, int line, int col, const char *msg)
{
	expect_error_len(text, strlen(text), false, line, col, msg);
}

static void expect_strict_error(const char *text, int line, int col, const char *msg)
{
	expect_error_len(text, strlen(text), true, line, col, msg);
}

/* The scene as text (rt_write into memory); the caller frees. */
static char *write_text(const scene *s, size_t *len)
{
	char *buf = NULL;
	size_t n = 0;
	FILE *f = open_memstream(&buf, &n);
	assert_non_null(f);
	rt_error err;
	assert_true(rt_write(s, f, &err));
	assert_int_equal(fclose(f), 0);
	if (len)
		*len = n;
	return buf;
}

/* load(write(s)) is equal to s, and writing that again gives the same text. */
static void assert_round_trip(const scene *s, const char *what)
{
	size_t len;
	char *text = write_text(s, &len);
	rt_error err;
	scene *t = load_with(text, len, "rewrite.rt", false, NULL, &err);
	if (!t) {
		char buf[700];
		rt_error_format(&err, buf, sizeof buf);
		fail_msg("%s: the written scene does not load: %s\n--- text:\n%s", what, buf, text);
	}
	if (!scene_equal(s, t))
		fail_msg("%s: load(write(s)) differs from s\n--- text:\n%s", what, text);
	char *again = write_text(t, NULL);
	if (strcmp(text, again) != 0)
		fail_msg("%s: writing twice gives different text", what);
	free(again);
	free(text);
	scene_free(t);
}

static const char SUBJECT[] = "A 0.2 255,255,255\n"
                              "C -50.0,0,20 0,0,1 70\n"
                              "L -40.0,50.0,0.0 0.6 10,0,255\n"
                              "sp 0.0,0.0,20.6 12.6 10,0,255\n"
                              "pl 0.0,0.0,-10.0 0.0,1.0,0.0 0,0,225\n"
                              "cy 50.0,0.0,20.6 0.0,0.0,1.0 14.2 21.42 10,0,255\n";

static void assert_default_material(const material *m, vec3 color)
{
	assert_true(v3_eq(m->color, color));
	assert_true(m->diffuse == 0.9 && m->specular == 0.9 && m->shininess == 200);
	assert_true(m->reflective == 0 && m->fuzz == 0 && m->metal == 0 && m->ior == 0);
	assert_true(m->emission == 0 && m->checker == 0);
}

/* --- the 42 format --- */

static void test_subject_example(void **state)
{
	(void)state;
	scene *s = load_ok(SUBJECT);
	assert_true(s->has_ambient);
	assert_true(s->amb.ratio == 0.2 && v3_eq(s->amb.color, v3(255, 255, 255)));
	assert_int_equal(s->ncams, 1);
	assert_int_equal(s->cam, 0);
	assert_true(v3_eq(s->cams[0].pos, v3(-50, 0, 20)));
	assert_true(v3_eq(s->cams[0].dir, v3(0, 0, 1)));
	assert_true(s->cams[0].fov == 70);
	assert_int_equal(s->nlights, 1);
	assert_true(v3_eq(s->lights[0].pos, v3(-40, 50, 0)));
	assert_true(s->lights[0].ratio == 0.6 && v3_eq(s->lights[0].color, v3(10, 0, 255)));
	assert_int_equal(s->nobjs, 3);

	const object *sp = &s->objs[0];
	assert_int_equal(sp->kind, OBJ_SPHERE);
	assert_true(v3_eq(sp->pos, v3(0, 0, 20.6)));
	assert_true(v3_eq(sp->dir, v3(0, 1, 0)));
	assert_true(v3_eq(sp->scale, v3(12.6, 12.6, 12.6)));
	assert_true(sp->twist == 0);
	for (int i = 0; i < 6; i++)
		assert_true(sp->shear[i] == 0);
	assert_default_material(&sp->mat, v3(10, 0, 255));

	const object *pl = &s->objs[1];
	assert_int_equal(pl->kind, OBJ_PLANE);
	assert_true(v3_eq(pl->pos, v3(0, 0, -10)));
	assert_true(v3_eq(pl->dir, v3(0, 1, 0)));
	assert_true(v3_eq(pl->scale, v3(1, 1, 1)));
	assert_default_material(&pl->mat, v3(0, 0, 225));

	const object *cy = &s->objs[2];
	assert_int_equal(cy->kind, OBJ_CYLINDER);
	assert_true(v3_eq(cy->pos, v3(50, 0, 20.6)));
	assert_true(v3_eq(cy->dir, v3(0, 0, 1)));
	assert_true(v3_eq(cy->scale, v3(14.2, 21.42, 14.2)));
	assert_default_material(&cy->mat, v3(10, 0, 255));

	/* The subject's own example passes its own rules. */
	scene *t = load_strict_ok(SUBJECT);
	assert_true(scene_equal(s, t));
	scene_free(t);
	scene_free(s);
}

static void test_cone_and_raw_directions(void **state)
{
	(void)state;
	/* Directions are kept as written, not normalised. */
	scene *s = load_ok("C 0,0,0 0,0,2 60\n"
	                   "co 1,2,3 0,-3,0 4 5 6,7,8\n"
	                   "pl 0,0,0 0,5,0 1,1,1\n");
	assert_true(v3_eq(s->cams[0].dir, v3(0, 0, 2)));
	assert_int_equal(s->objs[0].kind, OBJ_CONE);
	assert_true(v3_eq(s->objs[0].pos, v3(1, 2, 3)));
	assert_true(v3_eq(s->objs[0].dir, v3(0, -3, 0)));
	assert_true(v3_eq(s->objs[0].scale, v3(4, 5, 4)));
	assert_default_material(&s->objs[0].mat, v3(6, 7, 8));
	assert_true(v3_eq(s->objs[1].dir, v3(0, 5, 0)));
	assert_false(s->has_ambient);
	assert_int_equal(s->nlights, 0);
	scene_free(s);
}

static void test_light_default_colour(void **state)
{
	(void)state;
	scene *s = load_ok("C 0,0,0 0,0,1 70\nL 1,2,3 0.5\nL 4,5,6 1 7,8,9\n");
	assert_int_equal(s->nlights, 2);
	assert_true(v3_eq(s->lights[0].pos, v3(1, 2, 3)) && s->lights[0].ratio == 0.5);
	assert_true(v3_eq(s->lights[0].color, v3(255, 255, 255)));
	assert_true(v3_eq(s->lights[1].color, v3(7, 8, 9)) && s->lights[1].ratio == 1);
	scene_free(s);
}

/* --- the 2019 variant --- */

static void test_2019_variant(void **state)
{
	(void)state;
	scene *s = load_ok("R 1920 1080\n"
	                   "A 0.2 255,255,255\n"
	                   "c -50,0,20 0,0,1 70\n"
	                   "c 0,0,0 1,0,0 90\n"
	                   "l -40,50,0 0.6 10,0,255\n"
	                   "l 0,0,0 0.3\n"
	                   "sq 0,0,20.6 1,0,0 12.6 10,0,255\n"
	                   "tr 10,20,10 10,10,20 20,10,10 0,0,255\n");
	assert_int_equal(s->hints.width, 1920);
	assert_int_equal(s->hints.height, 1080);
	assert_int_equal(s->ncams, 2);
	assert_true(v3_eq(s->cams[1].pos, v3(0, 0, 0)) && v3_eq(s->cams[1].dir, v3(1, 0, 0)));
	assert_true(s->cams[1].fov == 90);
	assert_int_equal(s->cam, 0);
	assert_int_equal(s->nlights, 2);
	assert_true(v3_eq(s->lights[1].color, v3(255, 255, 255)) && s->lights[1].ratio == 0.3);
	const object *sq = &s->objs[0];
	assert_int_equal(sq->kind, OBJ_RECT);
	assert_true(v3_eq(sq->pos, v3(0, 0, 20.6)) && v3_eq(sq->dir, v3(1, 0, 0)));
	assert_true(v3_eq(sq->scale, v3(12.6, 1, 12.6)));
	assert_default_material(&sq->mat, v3(10, 0, 255));
	const object *tr = &s->objs[1];
	assert_int_equal(tr->kind, OBJ_TRIANGLE);
	assert_true(v3_eq(tr->tri[0], v3(10, 20, 10)));
	assert_true(v3_eq(tr->tri[1], v3(10, 10, 20)));
	assert_true(v3_eq(tr->tri[2], v3(20, 10, 10)));
	assert_default_material(&tr->mat, v3(0, 0, 255));
	scene_free(s);

	/* C and c mix: all are cameras in file order. */
	s = load_ok("c 1,0,0 0,0,1 10\nC 2,0,0 0,0,1 20\nc 3,0,0 0,0,1 30\n");
	assert_int_equal(s->ncams, 3);
	for (int i = 0; i < 3; i++)
		assert_true(s->cams[i].pos.x == i + 1 && s->cams[i].fov == 10 * (i + 1));
	scene_free(s);
}

/* --- the extended format and keys --- */

static void test_extended_format(void **state)
{
	(void)state;
	scene *s = load_ok(
		"C 0,0,-5 0,0,1 80\n"
		"sp 0,0,0 0,0,1 1,2,3 255,255,100 0.5 0.25 100 0.75 0.1,0,0,0,0,0.2 twist=30 "
		"fuzz=0.5 metal=1 ior=1.5 emit=2 checker=4\n"
		"cu 1,2,3 1,1,0 2,2,2 10,20,30\n"
		"di 0,0,0 0,-1,0 4,1,4 1,2,3 1 0 1 0\n"
		"rc 0,0,0 0,1,0 3,1,2 1,2,3\n"
		"tr 0,0,0 1,0,0 0,1,0 9,9,9 0.1 0.2 3 0.4 emit=5\n"
		"cy 0,0,0 0,1,0 2,3,4 5,6,7\n");
	assert_int_equal(s->nobjs, 6);
	const object *o = &s->objs[0];
	assert_int_equal(o->kind, OBJ_SPHERE);
	assert_true(v3_eq(o->pos, v3(0, 0, 0)) && v3_eq(o->dir, v3(0, 0, 1)));
	assert_true(v3_eq(o->scale, v3(1, 2, 3)));
	assert_true(v3_eq(o->mat.color, v3(255, 255, 100)));
	assert_true(o->mat.diffuse == 0.5 && o->mat.specular == 0.25);
	assert_true(o->mat.shininess == 100 && o->mat.reflective == 0.75);
	const double shear[6] = {0.1, 0, 0, 0, 0, 0.2};
	for (int i = 0; i < 6; i++)
		assert_true(o->shear[i] == shear[i]);
	assert_true(o->twist == 30);
	assert_true(o->mat.fuzz == 0.5 && o->mat.metal == 1 && o->mat.ior == 1.5);
	assert_true(o->mat.emission == 2 && o->mat.checker == 4);

	o = &s->objs[1];
	assert_int_equal(o->kind, OBJ_CUBE);
	assert_true(v3_eq(o->pos, v3(1, 2, 3)) && v3_eq(o->dir, v3(1, 1, 0)));
	assert_true(v3_eq(o->scale, v3(2, 2, 2)));
	assert_default_material(&o->mat, v3(10, 20, 30));

	o = &s->objs[2];
	assert_int_equal(o->kind, OBJ_DISC);
	assert_true(v3_eq(o->dir, v3(0, -1, 0)) && v3_eq(o->scale, v3(4, 1, 4)));
	assert_true(o->mat.diffuse == 1 && o->mat.specular == 0 && o->mat.shininess == 1);
	assert_true(o->mat.reflective == 0);

	o = &s->objs[3];
	assert_int_equal(o->kind, OBJ_RECT);
	assert_true(v3_eq(o->scale, v3(3, 1, 2)));

	o = &s->objs[4];
	assert_int_equal(o->kind, OBJ_TRIANGLE);
	assert_true(v3_eq(o->tri[1], v3(1, 0, 0)));
	assert_true(o->mat.diffuse == 0.1 && o->mat.specular == 0.2 && o->mat.shininess == 3);
	assert_true(o->mat.reflective == 0.4 && o->mat.emission == 5);

	/* An extended cylinder: the scaling is diameter, height, diameter. */
	o = &s->objs[5];
	assert_int_equal(o->kind, OBJ_CYLINDER);
	assert_true(v3_eq(o->scale, v3(2, 3, 4)));
	assert_default_material(&o->mat, v3(5, 6, 7));
	scene_free(s);
}

static void test_key_order_and_defaults(void **state)
{
	(void)state;
	scene *s = load_ok("C 0,0,0 0,0,1 70\n"
	                   "sp 0,0,0 2 255,0,0 checker=8 emit=1e6 ior=10 twist=-45\n"
	                   "pl 0,0,0 0,1,0 1,2,3 ior=1\n");
	const object *o = &s->objs[0];
	assert_true(o->mat.checker == 8 && o->mat.emission == 1e6 && o->mat.ior == 10);
	assert_true(o->twist == -45 && o->mat.fuzz == 0 && o->mat.metal == 0);
	assert_true(v3_eq(o->scale, v3(2, 2, 2)));
	assert_true(s->objs[1].mat.ior == 1);
	scene_free(s);
}

/* --- sky and set --- */

static void test_sky_and_set(void **state)
{
	(void)state;
	scene *s = load_ok("C 0,0,0 0,0,1 70\n"
	                   "sky 100,150,255 255,255,255\n"
	                   "set samples 64\n"
	                   "set depth 0\n"
	                   "set mode path\n"
	                   "set resolution 320x200\n");
	assert_true(s->has_sky);
	assert_true(v3_eq(s->sky.zenith, v3(100, 150, 255)));
	assert_true(v3_eq(s->sky.horizon, v3(255, 255, 255)));
	assert_true(s->sky.strength == 1);
	assert_int_equal(s->hints.samples, 64);
	assert_int_equal(s->hints.depth, 0);
	assert_int_equal(s->hints.mode, MODE_PATH);
	assert_int_equal(s->hints.width, 320);
	assert_int_equal(s->hints.height, 200);
	scene_free(s);

	s = load_ok("C 0,0,0 0,0,1 70\nsky 0,0,0 1,1,1 2.5\nset mode whitted\n");
	assert_true(s->sky.strength == 2.5);
	assert_int_equal(s->hints.mode, MODE_WHITTED);
	/* Unset hints stay unset. */
	assert_int_equal(s->hints.samples, 0);
	assert_int_equal(s->hints.depth, -1);
	assert_int_equal(s->hints.width, 0);
	scene_free(s);
}

/* --- the other settings kept with the scene (SETTING_SCENE rows) --- */

#define KCAM "C 0,0,0 0,0,1 70\n"

/* The settings a scene's text gives over the defaults. */
static render_settings applied(const scene *s)
{
	render_settings r = render_settings_default();
	render_settings_apply_hints(&r, &s->hints);
	return r;
}

static void test_kept_settings(void **state)
{
	(void)state;
	/* Values read off the text; the four older ones beside them. */
	const char text[] = KCAM "set samples 4\nset denoise off\nset seed 42\nset exposure -1.5\n";
	scene *s = load_ok(text);
	render_settings r = applied(s);
	assert_int_equal(r.samples, 4);
	assert_int_equal(r.seed, 42);
	assert_true(r.exposure == -1.5);
	assert_int_equal(r.denoise, DENOISE_OFF);
	assert_int_equal(r.threads, 0); /* untouched: the default */
	/* Written back after the older ones, in the table's order. */
	char *out = write_text(s, NULL);
	assert_non_null(strstr(out, "set samples 4\nset seed 42\nset exposure -1.5\nset denoise off\n"));
	free(out);
	assert_round_trip(s, "kept settings");
	scene_free(s);
	/* The largest seed, and an exposure that needs more than %g's digits. */
	s = load_ok(KCAM "set seed 18446744073709551615\nset exposure 0.1234567891234\n");
	r = applied(s);
	assert_true(r.seed == UINT64_MAX);
	assert_true(r.exposure == 0.1234567891234);
	out = write_text(s, NULL);
	assert_non_null(strstr(out, "set seed 18446744073709551615\nset exposure 0.1234567891234\n"));
	free(out);
	assert_round_trip(s, "a long seed and exposure");
	scene_free(s);
	/* The longest text a kept value takes (scene.h's SCENE_KEPT_LEN). */
	s = load_ok(KCAM "set exposure -0.00012345678901234567\n");
	assert_true(applied(s).exposure == -0.00012345678901234567);
	assert_round_trip(s, "the longest exposure");
	scene_free(s);
	/* A repeat with the same value is ignored (lenient); another fails. */
	s = load_ok(KCAM "set seed 5\nset seed 5\n");
	assert_int_equal(applied(s).seed, 5);
	scene_free(s);
	expect_error(KCAM "set seed 5\nset seed 6\n", 3, 1, "set: a second set seed line; expected only one "
	                                                    "(the first is on line 2)");
}

/* Each kept row of the table: a value other than its default (its maximum,
 * its last choice) loads, writes back as it was written and reloads. */
static void test_kept_settings_each_row(void **state)
{
	(void)state;
	int rows = 0;
	for (size_t i = 0; i < settings_count; i++) {
		const setting_def *d = &settings_table[i];
		if (!(d->flags & SETTING_SCENE))
			continue;
		char value[64], line[128], text[256], got[64];
		switch (d->type) {
		case SETTING_INT:
		case SETTING_DOUBLE:
			snprintf(value, sizeof value, "%.0f", d->max);
			break;
		case SETTING_U64:
			snprintf(value, sizeof value, "123456789012345");
			break;
		case SETTING_RESOLUTION:
			snprintf(value, sizeof value, "320x200");
			break;
		case SETTING_ENUM:
			snprintf(value, sizeof value, "%s", d->choices[settings_choices(d) - 1]);
			break;
		}
		snprintf(line, sizeof line, "set %s %s\n", d->name, value);
		snprintf(text, sizeof text, KCAM "%s", line);
		scene *s = load_ok(text);
		render_settings r = applied(s);
		settings_format(&r, d, got, sizeof got);
		assert_string_equal(got, value);
		/* (a resolution is written as the R line it has always been) */
		const char *want = d->type == SETTING_RESOLUTION ? "R 320 200\n" : line;
		char *out = write_text(s, NULL);
		if (!strstr(out, want))
			fail_msg("%s is not written back as \"%s\":\n%s", d->name, want, out);
		free(out);
		assert_round_trip(s, d->name);
		scene_free(s);
		rows++;
	}
	assert_true(rows >= 7); /* resolution samples depth mode seed exposure denoise */
}

static void test_kept_settings_errors(void **state)
{
	(void)state;
	/* The row's own range and message, at the value's column. */
	expect_error(KCAM "set exposure 30\n", 2, 14, "set exposure \"30\" is not valid; expected a number in -20..20");
	expect_error(KCAM "set seed -1\n", 2, 10, "set seed \"-1\" is not valid; expected a whole number in 0..18446744073709551615");
	expect_error(KCAM "set denoise xyz\n", 2, 13, "set denoise \"xyz\" is not valid; expected auto, on or off");
	expect_error(KCAM "set denoise onn\n", 2, 13,
	             "set denoise \"onn\" is not valid; did you mean \"on\"? (expected auto, on or off)");
	/* A typo of a name: the nearest kept one. */
	expect_error(KCAM "set seeed 3\n", 2, 5, "set key \"seeed\" is unknown; did you mean \"seed\"?");
	expect_error(KCAM "set exposur 1\n", 2, 5, "did you mean \"exposure\"?");
	/* A setting of the machine or the terminal is not the scene's. */
	expect_error(KCAM "set threads 2\n", 2, 5, "set key \"threads\" is not kept with a scene");
	expect_error(KCAM "set pixels kitty\n", 2, 5, "set key \"pixels\" is not kept with a scene");
	/* 42's strict mode allows no set line at all. */
	expect_strict_error("A 0.2 255,255,255\nC 0,0,0 0,0,1 70\nL 0,0,0 0.5 255,255,255\nset seed 1\n", 4, 1,
	                    "strict mode does not allow the element \"set\"");
}

#undef KCAM

/* --- numbers --- */

static void test_numbers_accepted(void **state)
{
	(void)state;
	scene *s = load_ok("A .5 00,-0,127.5\n"
	                   "C 1.,+2,-0 0,0,1 +60\n"
	                   "sp 0,0,0 1e3 1E1,2e+1,3e-0\n"
	                   "L 0,0,0 1e-400\n");
	assert_true(s->amb.ratio == 0.5);
	assert_true(v3_eq(s->amb.color, v3(0, 0, 127.5)));
	assert_true(v3_eq(s->cams[0].pos, v3(1, 2, 0)));
	assert_true(s->cams[0].fov == 60);
	assert_true(v3_eq(s->objs[0].scale, v3_splat(1000)));
	assert_true(v3_eq(s->objs[0].mat.color, v3(10, 20, 3)));
	assert_true(s->lights[0].ratio == 0);
	scene_free(s);
}

static void test_number_traps(void **state)
{
	(void)state;
	static const char *const bad[] = {"nan", "NaN", "inf", "-inf", "infinity", "0x10", "1.2.3",
	                                  "--1", "+-1", "12abc", "1e", "e3", ".", "-", "+", "1..",
	                                  "1e+", "0,5", "1_0", "٣"};
	char text[128];
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
		snprintf(text, sizeof text, "A %s 255,255,255\nC 0,0,0 0,0,1 70\n", bad[i]);
		expect_error(text, 1, 3, "is not a number; expected a number in [0,1]");
	}
	static const char *const big[] = {"1e400", "-1e400", "1e21", "-100000000000000000000000"};
	for (size_t i = 0; i < sizeof big / sizeof big[0]; i++) {
		snprintf(text, sizeof text, "C 0,0,0 0,0,1 70\nL 0,%s,0 1\n", big[i]);
		expect_error(text, 2, 3, "is out of range; expected a magnitude up to 1e20");
	}
	/* The bound itself is fine, and coordinates near -2^31 occur in the wild. */
	scene *s = load_ok("C 0,0,0 0,0,1 70\nL -2147483648.0,1e20,-1e20 1\n");
	assert_true(v3_eq(s->lights[0].pos, v3(-2147483648.0, 1e20, -1e20)));
	scene_free(s);
	/* Components: empty ones and separators other than commas. */
	expect_error("A 0.2 1,,2\nC 0,0,0 0,0,1 70\n", 1, 7, "has an empty component");
	expect_error("A 0.2 1,2,\nC 0,0,0 0,0,1 70\n", 1, 7, "has an empty component");
	/* A blank before a comma joins the fields: "0.2 ,1,2" is one field. */
	expect_error("A 0.2 ,1,2\nC 0,0,0 0,0,1 70\n", 1, 11, "ambient: too few fields");
	expect_error("A 0.2 1;2;3\nC 0,0,0 0,0,1 70\n", 1, 7, "is not a vector; expected R,G,B");
	expect_error("A 0.2 1,2,3,4\nC 0,0,0 0,0,1 70\n", 1, 7, "has 4 components; expected R,G,B");
	expect_error("A 0.2 1,x,3\nC 0,0,0 0,0,1 70\n", 1, 7,
	             "colour \"1,x,3\" has a component that is not a number");
	/* Tuples the one-pass split does not take, each with the full pass's
	 * message: the third part holding a comma, an empty part before a
	 * fourth, a component out of range after good ones. */
	expect_error("A 0.2 1,2,3,\nC 0,0,0 0,0,1 70\n", 1, 7, "has an empty component");
	expect_error("A 0.2 1,2,3,x\nC 0,0,0 0,0,1 70\n", 1, 7, "has 4 components; expected R,G,B");
	expect_error("A 0.2 1,,2,3\nC 0,0,0 0,0,1 70\n", 1, 7, "has an empty component");
	expect_error("C 0,0,0 0,0,1 70\nL 1,2,3e21 1\n", 2, 3, "is out of range; expected a magnitude up to 1e20");
	expect_error("A 0.2 1,2,256\nC 0,0,0 0,0,1 70\n", 1, 7, "has a component that is out of range");
	/* and the values the one pass reads: strtod's */
	scene *t = load_ok("C 0.5,-0,1e-3 0,0,1 70\nL +2.25,.5,7. 1\n");
	assert_true(t->cams[0].pos.x == 0.5 && t->cams[0].pos.y == 0 && signbit(t->cams[0].pos.y) &&
	            t->cams[0].pos.z == strtod("1e-3", NULL));
	assert_true(v3_eq(t->lights[0].pos, v3(2.25, 0.5, 7.0)));
	scene_free(t);
	/* Whole numbers where they are required. */
	expect_error("R 10.5 10\nC 0,0,0 0,0,1 70\n", 1, 3,
	             "resolution width \"10.5\" is not a whole number; expected a whole number");
	expect_error("C 0,0,0 0,0,1 70\nset samples 1.5\n", 2, 13, "is not a whole number");
}

/* --- lexing --- */

static void test_line_ends_blanks_comments(void **state)
{
	(void)state;
	scene *ref = load_ok(SUBJECT);
	static const char *const variants[] = {
		/* CRLF */
		"A 0.2 255,255,255\r\nC -50.0,0,20 0,0,1 70\r\nL -40.0,50.0,0.0 0.6 10,0,255\r\n"
		"sp 0.0,0.0,20.6 12.6 10,0,255\r\npl 0.0,0.0,-10.0 0.0,1.0,0.0 0,0,225\r\n"
		"cy 50.0,0.0,20.6 0.0,0.0,1.0 14.2 21.42 10,0,255\r\n",
		/* CR only, no final line end */
		"A 0.2 255,255,255\rC -50.0,0,20 0,0,1 70\rL -40.0,50.0,0.0 0.6 10,0,255\r"
		"sp 0.0,0.0,20.6 12.6 10,0,255\rpl 0.0,0.0,-10.0 0.0,1.0,0.0 0,0,225\r"
		"cy 50.0,0.0,20.6 0.0,0.0,1.0 14.2 21.42 10,0,255",
		/* tabs, mixed blanks, comments of both kinds, blank lines */
		"# a scene\n\n\tA\t0.2\t\t255,255,255 # ambient\n"
		"C  -50.0,0,20 \t 0,0,1   70// camera\n"
		"// a light\nL -40.0,50.0,0.0 0.6 10,0,255#trailing\n"
		"   \t\nsp 0.0,0.0,20.6 12.6 10,0,255\t\n"
		"pl 0.0,0.0,-10.0 0.0,1.0,0.0 0,0,225\n"
		"cy 50.0,0.0,20.6 0.0,0.0,1.0 14.2 21.42 10,0,255",
		/* blanks beside commas join a vector */
		"A 0.2 255, 255, 255\nC -50.0 ,0 , 20 0,\t0,1 70\nL -40.0,50.0,0.0 0.6 10,0,255\n"
		"sp 0.0,0.0,20.6 12.6 10 ,0,255\npl 0.0,0.0,-10.0 0.0,1.0,0.0 0,0,225\n"
		"cy 50.0,0.0,20.6 0.0,0.0,1.0 14.2 21.42 10,0,255\n",
	};
	for (size_t i = 0; i < sizeof variants / sizeof variants[0]; i++) {
		scene *s = load_ok(variants[i]);
		if (!scene_equal(ref, s))
			fail_msg("variant %zu differs from the plain file", i);
		scene_free(s);
	}
	scene_free(ref);
	/* Line numbers count every kind of line end; columns count bytes. */
	expect_error("A 0.2 255,255,255\rC 0,0,0 0,0,1 70\rsp 0,0,0 -1 255,0,0", 3, 10,
	             "sphere diameter \"-1\" is not positive");
	expect_error("A 0.2 255,255,255\r\nC 0,0,0 0,0,1 70\r\n\r\nsp 0,0,0 -1 255,0,0\r\n", 4, 10,
	             "sphere diameter \"-1\" is not positive");
	expect_error("C 0,0,0 0,0,1 70\n\tsp\t0,0,0  -1 255,0,0\n", 2, 12, "sphere diameter");
	/* "1, 2, 3" is one field at the column of "1". */
	expect_error("C 0,0,0 0,0,1 70\nsp 1, 2, 3 -1 255,0,0\n", 2, 12,
	             "sphere diameter \"-1\" is not positive");
	expect_error("C 0,0,0 0,0,1 70\nsp 1, x, 3 1 255,0,0\n", 2, 4, "sphere center \"1,x,3\"");
}

static void test_control_bytes_and_empty(void **state)
{
	(void)state;
	static const char nul[] = "C 0,0,0 0,0,1 70\nA 0.\0 1,1,1\n";
	expect_error_len(nul, sizeof nul - 1, false, 2, 5, "a NUL byte");
	expect_error("C 0,0,0 0,0,1 70\nsp 0,0,0 1 2\x01,0,0\n", 2, 13, "control character 0x01");
	/* Even in a comment. */
	expect_error("C 0,0,0 0,0,1 70 # \x1b[31m\n", 1, 20, "control character 0x1B");
	expect_error("C 0,0,0 0,0,1 70\x0c\n", 1, 17, "control character 0x0C");
	/* Whole-file errors have no line. */
	expect_error("", 0, 0, "no elements; expected");
	expect_error("# only a comment\n\n   \t\r\n// and another\n", 0, 0, "no elements");
	expect_error("\n\n\n", 0, 0, "no elements");
}

static void test_long_lines(void **state)
{
	(void)state;
	size_t n = 10u << 20;
	size_t cap = n + 256;
	char *text = malloc(cap);
	assert_non_null(text);

	/* A 10 MB comment line. */
	size_t k = (size_t)snprintf(text, cap, "C 0,0,0 0,0,1 70\n#");
	memset(text + k, 'x', n);
	k += n;
	k += (size_t)snprintf(text + k, cap - k, "\nsp 0,0,0 1 255,0,0\n");
	rt_error err;
	scene *s = load_with(text, k, "t.rt", false, NULL, &err);
	assert_non_null(s);
	assert_int_equal(s->nobjs, 1);
	scene_free(s);

	/* A 10 MB number: 0000...0002. */
	k = (size_t)snprintf(text, cap, "C 0,0,0 0,0,1 70\nsp 0,0,0 ");
	memset(text + k, '0', n);
	k += n;
	k += (size_t)snprintf(text + k, cap - k, "2 255,0,0\n");
	s = load_with(text, k, "t.rt", false, NULL, &err);
	assert_non_null(s);
	assert_true(v3_eq(s->objs[0].scale, v3_splat(2)));
	scene_free(s);

	/* A 10 MB bad token: the message quotes its start and still says
	 * what was expected. */
	k = (size_t)snprintf(text, cap, "C 0,0,0 0,0,1 70\nsp 0,0,0 ");
	memset(text + k, 'z', n);
	k += n;
	k += (size_t)snprintf(text + k, cap - k, " 255,0,0\n");
	s = load_with(text, k, "t.rt", false, NULL, &err);
	assert_null(s);
	assert_int_equal(err.line, 2);
	assert_int_equal(err.col, 10);
	assert_non_null(strstr(err.msg, "sphere diameter \"zzzzzzzzzz"));
	assert_non_null(strstr(err.msg, "...\" is not a number; expected a number > 0"));
	free(text);
}

static void test_many_lines(void **state)
{
	(void)state;
	size_t n = 20000, cap = n * 40 + 64, k = 0;
	char *text = malloc(cap);
	assert_non_null(text);
	k += (size_t)snprintf(text, cap, "C 0,0,-10 0,0,1 70\n");
	for (size_t i = 0; i < n; i++)
		k += (size_t)snprintf(text + k, cap - k, "sp %zu,0,0 1.5 1,2,3\n", i);
	rt_error err;
	scene *s = load_with(text, k, "t.rt", false, NULL, &err);
	assert_non_null(s);
	assert_int_equal(s->nobjs, n);
	assert_true(v3_eq(s->objs[n - 1].pos, v3((double)(n - 1), 0, 0)));
	scene_free(s);
	free(text);
}

/* --- field errors, element by element --- */

typedef struct err_case {
	const char *text;
	int line, col;
	const char *msg;
} err_case;

#define CAM "C 0,0,0 0,0,1 70\n"

static const err_case field_errors[] = {
	/* unknown elements, case-sensitive */
	{CAM "xx 1 2\n", 2, 1,
	 "unknown element \"xx\"; expected one of A C c L l R sp pl cy co cu di rc sq tr to mesh sky set"},
	{CAM "SP 0,0,0 1 255,0,0\n", 2, 1, "unknown element \"SP\""},
	{CAM "  fuzz=1\n", 2, 3, "unknown element \"fuzz=1\""},
	/* A */
	{"A 1.5 255,255,255\n" CAM, 1, 3,
	 "ambient ratio \"1.5\" is out of range; expected a number in [0,1]"},
	{"A -0.1 255,255,255\n" CAM, 1, 3, "ambient ratio \"-0.1\" is out of range"},
	{"A 0.2 256,0,0\n" CAM, 1, 7,
	 "ambient colour \"256,0,0\" has a component that is out of range; expected R,G,B each in [0,255]"},
	{"A 0.2 0,-1,0\n" CAM, 1, 7, "ambient colour \"0,-1,0\" has a component that is out of range"},
	{"A 0.2\n" CAM, 1, 6, "ambient: too few fields; expected A RATIO R,G,B"},
	{"A 0.2 1,1,1 1\n" CAM, 1, 13, "ambient: too many fields; expected A RATIO R,G,B"},
	{"A 0.2 255,255,255\nA 0.3 255,255,255\n" CAM, 2, 1,
	 "ambient: a second A line; expected only one (the first is on line 1)"},
	/* C */
	{"C 0,0 0,0,1 70\n", 1, 3, "camera position \"0,0\" has 2 components; expected X,Y,Z"},
	{"C 0,0,0 0,0,0 70\n", 1, 9, "camera direction is the zero vector; expected a non-zero direction"},
	{"C 0,0,0 0,0,1e-200 70\n", 1, 9, "camera direction \"0,0,1e-200\" is too short"},
	{"C 0,0,0 0,0,1 181\n", 1, 15, "camera fov \"181\" is out of range; expected degrees in [0,180]"},
	{"C 0,0,0 0,0,1 -1\n", 1, 15, "camera fov \"-1\" is out of range"},
	{"C 0,0,0 0,0,1\n", 1, 14, "camera: too few fields; expected C POSITION DIRECTION FOV"},
	{"C 0,0,0 0,0,1 70 5\n", 1, 18, "camera: too many fields"},
	{"C 0,0,0 0,0,1 70 fov=1\n", 1, 18, "camera key \"fov=1\" is unknown; expected vertical= ortho="},
	{"C 0,0,0 0,0,1 70 ortho=0\n", 1, 24, "camera ortho= \"0\" is not positive"},
	{"C 0,0,0 0,0,1 70 vertical=1 vertical=1\n", 1, 29, "camera key \"vertical=1\" repeats a key"},
	{CAM "C 0,0,0 0,0,1 60\n", 2, 1, "camera: a second C line; expected only one (the first is on line 1)"},
	{CAM "c 0,0,0 0,0,1 x\n", 2, 15, "camera fov \"x\" is not a number"},
	/* L, l */
	{CAM "L 0,0,0 1.2\n", 2, 9, "light ratio \"1.2\" is out of range; expected a number in [0,1]"},
	{CAM "L 0,0,0\n", 2, 8, "light: too few fields; expected L POSITION RATIO [R,G,B]"},
	{CAM "l 0,0,0 1 1,1,1 1\n", 2, 17, "light: too many fields"},
	{CAM "L 0,0,0 1 1,1,300\n", 2, 11, "light colour \"1,1,300\" has a component that is out of range"},
	/* physical lights */
	{CAM "L 0,0,0 1 lux=3\n", 2, 11, "light: a sun (lux=) without dir=; expected dir=X,Y,Z"},
	{CAM "L 0,0,0 1 cd=3 lux=3 dir=0,-1,0\n", 2, 22, "light: both cd= and lux="},
	{CAM "L 0,0,0 1 range=3\n", 2, 11, "without cd= or lux="},
	{CAM "L 0,0,0 1 cd=-3\n", 2, 14, "light cd= \"-3\" is out of range; expected a number >= 0"},
	{CAM "L 0,0,0 1 cd=3 dir=0,-1,0 cone=20,10\n", 2, 32, "light cone= \"20,10\" has inner >= outer"},
	{CAM "L 0,0,0 1 cd=3 cone=10,20\n", 2, 16, "a spot (cone=) without dir="},
	{CAM "L 0,0,0 1 lux=3 dir=0,-1,0 range=4\n", 2, 28, "cone= or range= on a sun"},
	/* R */
	{"R 0 10\n" CAM, 1, 3, "resolution width \"0\" is out of range; expected a whole number in [1,1e9]"},
	{"R 10 -10\n" CAM, 1, 6, "resolution height \"-10\" is out of range"},
	{"R 10\n" CAM, 1, 5, "resolution: too few fields; expected R WIDTH HEIGHT"},
	{"R 10 10\nR 20 20\n" CAM, 2, 1, "resolution: a second R line"},
	{"R 10 10\n" CAM "set resolution 20x20\n", 3, 1, "a second resolution (R or set resolution) line"},
	/* sp */
	{CAM "sp 0,0,0 -2 255,0,0\n", 2, 10,
	 "sphere diameter \"-2\" is not positive; expected a number > 0"},
	{CAM "sp 0,0 2 255,0,0\n", 2, 4, "sphere center \"0,0\" has 2 components; expected X,Y,Z"},
	{CAM "sp 0,0,0 2 255,0,0 1\n", 2, 20,
	 "sphere: too many fields; expected sp CENTER DIAMETER R,G,B or sp POS ROT SCALE R,G,B "
	 "[DIFFUSE SPECULAR SHININESS REFLECTIVE [SHEAR]]"},
	{CAM "sp 0,0,0 2\n", 2, 11, "sphere: too few fields"},
	{CAM "sp\n", 2, 3, "sphere: too few fields"},
	{CAM "sp 0,0,0 0,1,0 1,1,1 255,0,0 0.5\n", 2, 30,
	 "sphere: 1 of the 4 material fields; expected DIFFUSE SPECULAR SHININESS REFLECTIVE "
	 "together or none of them"},
	{CAM "sp 0,0,0 0,1,0 1,1,1 255,0,0 0.5 0.5 1\n", 2, 30, "sphere: 3 of the 4 material fields"},
	{CAM "sp 0,0,0 0,1,0 1,0,1 255,0,0\n", 2, 16,
	 "sphere scaling \"1,0,1\" has a component that is not positive; expected three numbers > 0"},
	{CAM "sp 0,0,0 0,0,0 1,1,1 255,0,0\n", 2, 10, "sphere rotation is the zero vector"},
	{CAM "sp 0,0,0 0,1,0 1,1,1 255,0,0 2 0.5 10 0\n", 2, 30,
	 "sphere diffuse \"2\" is out of range; expected a number in [0,1]"},
	{CAM "sp 0,0,0 0,1,0 1,1,1 255,0,0 0.5 1.5 10 0\n", 2, 34, "sphere specular \"1.5\" is out of range"},
	{CAM "sp 0,0,0 0,1,0 1,1,1 255,0,0 0.5 0.5 0.5 0\n", 2, 38,
	 "sphere shininess \"0.5\" is out of range; expected a number in [1,500]"},
	{CAM "sp 0,0,0 0,1,0 1,1,1 255,0,0 0.5 0.5 501 0\n", 2, 38, "sphere shininess \"501\" is out of range"},
	{CAM "sp 0,0,0 0,1,0 1,1,1 255,0,0 0.5 0.5 10 -1\n", 2, 41, "sphere reflective \"-1\" is out of range"},
	{CAM "sp 0,0,0 0,1,0 1,1,1 255,0,0 0.9 0.9 200 0 1,0,1,0,0\n", 2, 44,
	 "sphere shear \"1,0,1,0,0\" has 5 components; expected XY,XZ,YX,YZ,ZX,ZY"},
	{CAM "sp 0,0,0 0,1,0 1,1,1 255,0,0 0.9 0.9 200 0 1,0,1,0,0,0\n", 2, 1, "not invertible"},
	{CAM "sp 0,0,0 0,1,0 1,1,1 255,0,0 0.9 0.9 200 0 0,0,0,0,0,0 1\n", 2, 56, "sphere: too many fields"},
	/* pl */
	{CAM "pl 0,0,0 0,0,0 255,0,0\n", 2, 10, "plane normal is the zero vector; expected a non-zero direction"},
	{CAM "pl 0,0,0 0,1,0\n", 2, 15, "plane: too few fields; expected pl POINT NORMAL R,G,B or pl POS ROT SCALE"},
	{CAM "pl 0,0,0 0,1,0 a,b,c\n", 2, 16, "plane colour \"a,b,c\" has a component that is not a number; expected R,G,B"},
	/* cy, co */
	{CAM "cy 0,0,0 0,1,0 2 -1 255,0,0\n", 2, 18, "cylinder height \"-1\" is not positive; expected a number > 0"},
	{CAM "cy 0,0,0 0,1,0 -2 1 255,0,0\n", 2, 16, "cylinder diameter \"-2\" is not positive"},
	{CAM "cy 0,0,0 0,0,0 2 1 255,0,0\n", 2, 10, "cylinder axis is the zero vector"},
	{CAM "cy 0,0,0 0,1,0 2 1\n", 2, 19, "cylinder: too few fields; expected cy CENTER AXIS DIAMETER HEIGHT R,G,B or cy POS"},
	{CAM "co 0,0,0 0,1,0 2 1 255,0,0,0\n", 2, 20, "cone colour \"255,0,0,0\" has 4 components; expected R,G,B"},
	{CAM "co 0,0,0 0,1,0 2 1 255,0,0 9\n", 2, 28, "cone: too many fields"},
	/* cu, di, rc */
	{CAM "cu 0,0,0 0,1,0 1,1,1\n", 2, 21, "cube: too few fields; expected cu POS ROT SCALE R,G,B"},
	{CAM "cu 0,0,0 0,1,0 1 255,0,0\n", 2, 16, "cube scaling \"1\" is not a vector; expected X,Y,Z"},
	{CAM "di 0,0,0 0,1,0 1,1,1 255,0,0 0.9 0.9 200 0 0,0,0,0,0,0 7\n", 2, 56, "disc: too many fields"},
	{CAM "di 0,0,0 0,1,0 1,-1,1 255,0,0\n", 2, 16, "disc scaling \"1,-1,1\" has a component that is not positive"},
	{CAM "rc 0,0,0 0,1,0 1,1,1 300,0,0\n", 2, 22, "rectangle colour \"300,0,0\" has a component that is out of range"},
	/* sq */
	{CAM "sq 0,0,0 0,0,1 -1 255,0,0\n", 2, 16, "square side \"-1\" is not positive; expected a number > 0"},
	{CAM "sq 0,0,0 0,0,0 1 255,0,0\n", 2, 10, "square normal is the zero vector"},
	{CAM "sq 0,0,0 0,0,1 1 255,0,0 0.9 0.9 200 0\n", 2, 26, "square: too many fields; expected sq CENTER NORMAL SIDE R,G,B"},
	/* tr */
	{CAM "tr 0,0,0 1,1,1 2,2,2 255,0,0\n", 2, 4, "triangle: the three points are on one line"},
	{CAM "tr 0,0,0 1,0,0 1,0,0 255,0,0\n", 2, 4, "triangle: the three points are on one line"},
	{CAM "tr 0,0,0 1,0,0 0,1 255,0,0\n", 2, 16, "triangle third point \"0,1\" has 2 components"},
	{CAM "tr 0,0,0 1,0,0 0,1,0 255,0,0 0.5 0.5\n", 2, 30, "triangle: 2 of the 4 material fields"},
	{CAM "tr 0,0,0 1,0,0 0,1,0 255,0,0 0.9 0.9 200 0 0,0,0,0,0,0\n", 2, 44,
	 "triangle: too many fields; expected tr P1 P2 P3 R,G,B [DIFFUSE SPECULAR SHININESS REFLECTIVE]"},
	{CAM "tr 0,0,0 1,0,0 0,1,0 255,0,0 twist=5\n", 2, 30,
	 "triangle key \"twist=5\" does not apply to triangles; expected fuzz= metal= ior= emit= checker="},
	/* key=value */
	{CAM "sp 0,0,0 1 255,0,0 fuzz=2\n", 2, 20, "sphere key \"fuzz=2\" is out of range; expected fuzz in [0,1]"},
	{CAM "sp 0,0,0 1 255,0,0 metal=-0.5\n", 2, 20, "sphere key \"metal=-0.5\" is out of range; expected metal in [0,1]"},
	{CAM "sp 0,0,0 1 255,0,0 foo=1\n", 2, 20,
	 "sphere key \"foo=1\" is unknown; expected twist= fuzz= metal= ior= emit= checker="},
	{CAM "sp 0,0,0 1 255,0,0 Fuzz=1\n", 2, 20, "sphere key \"Fuzz=1\" is unknown"},
	{CAM "sp 0,0,0 1 255,0,0 fuzz=0.1 fuzz=0.2\n", 2, 29,
	 "sphere key \"fuzz=0.2\" repeats a key; expected each key at most once"},
	{CAM "sp 0,0,0 1 255,0,0 ior=0.5\n", 2, 20,
	 "sphere key \"ior=0.5\" is out of range; expected ior 0 (opaque) or a refractive index in [1,10]"},
	{CAM "sp 0,0,0 1 255,0,0 ior=11\n", 2, 20, "sphere key \"ior=11\" is out of range"},
	{CAM "sp 0,0,0 1 255,0,0 checker=2.5\n", 2, 20,
	 "sphere key \"checker=2.5\" is out of range; expected checker a whole number in [0,1000]"},
	{CAM "sp 0,0,0 1 255,0,0 checker=1001\n", 2, 20, "is out of range"},
	{CAM "sp 0,0,0 1 255,0,0 emit=-1\n", 2, 20, "sphere key \"emit=-1\" is out of range; expected emit in [0,1e6]"},
	{CAM "sp 0,0,0 1 255,0,0 emit=1000001\n", 2, 20, "is out of range"},
	{CAM "sp 0,0,0 1 255,0,0 fuzz=\n", 2, 20, "sphere key \"fuzz=\" has a value that is not a number; expected fuzz in [0,1]"},
	{CAM "sp 0,0,0 1 255,0,0 twist=nan\n", 2, 20, "has a value that is not a number; expected twist in degrees"},
	{CAM "sp 0,0,0 1 255,0,0 fuzz=0.1 7\n", 2, 29,
	 "sphere field \"7\" comes after the key=value fields; expected the key=value fields last"},
	{CAM "cy 0,0,0 0,1,0 1 1 255,0,0 =1\n", 2, 28, "cylinder key \"=1\" is unknown"},
	/* sky */
	{CAM "sky 0,0,255 255,255,255 -1\n", 2, 25, "sky strength \"-1\" is out of range; expected a number >= 0"},
	{CAM "sky 0,0,255\n", 2, 12, "sky: too few fields; expected sky ZENITH_R,G,B HORIZON_R,G,B [STRENGTH]"},
	{CAM "sky 0,0,256 0,0,0\n", 2, 5, "sky zenith colour \"0,0,256\" has a component that is out of range"},
	{CAM "sky 0,0,0 0,0,0\nsky 1,1,1 0,0,0\n", 3, 1, "sky: a second sky line"},
	/* set */
	{CAM "set samples 0\n", 2, 13, "set samples \"0\" is out of range; expected a whole number in [1,1000000]"},
	{CAM "set samples 1000001\n", 2, 13, "set samples \"1000001\" is out of range"},
	{CAM "set depth 1001\n", 2, 11, "set depth \"1001\" is out of range; expected a whole number in [0,1000]"},
	{CAM "set mode fast\n", 2, 10, "set mode \"fast\" is unknown; expected whitted or path"},
	{CAM "set resolution 10x\n", 2, 16, "set resolution \"10x\" is not WxH; expected WIDTHxHEIGHT"},
	{CAM "set resolution 0x10\n", 2, 16, "set resolution \"0x10\" has a size that is out of range"},
	{CAM "set resolution 10,10\n", 2, 16, "set resolution \"10,10\" is not WxH"},
	{CAM "set foo 1\n", 2, 5,
	 "set key \"foo\" is unknown; expected one of resolution samples depth mode seed exposure denoise"},
	{CAM "set samples\n", 2, 12, "set: too few fields; expected set NAME VALUE"},
	{CAM "set samples 4 8\n", 2, 15, "set: too many fields"},
	{CAM "set samples 4\nset samples 8\n", 3, 1, "set: a second set samples line"},
};

static void test_field_errors(void **state)
{
	(void)state;
	for (size_t i = 0; i < sizeof field_errors / sizeof field_errors[0]; i++) {
		const err_case *c = &field_errors[i];
		expect_error(c->text, c->line, c->col, c->msg);
	}
}

/* The first error of a file is the one reported. */
static void test_first_error_wins(void **state)
{
	(void)state;
	expect_error(CAM "sp 0,0,0 -1 255,0,0\nsp 0,0,0 -2 255,0,0\nxx\n", 2, 10, "\"-1\"");
	expect_error(CAM "sp 0,0,0 x 999,0,0\n", 2, 10, "sphere diameter \"x\" is not a number");
}

/* --- repeats, the missing camera, warnings --- */

static void test_repeats_and_missing_camera(void **state)
{
	(void)state;
	/* An identical repeat of A or C (as in some wild files) is ignored
	 * with a warning. */
	warn_log log = {0};
	rt_error err;
	const char *text = "A 0.2 1,2,3\nC 0,0,0 0,0,1 70\nC 0,0,0 0,0,1 70\nA 0.2 1,2,3\n";
	scene *s = load_with(text, strlen(text), "t.rt", false, &log, &err);
	assert_non_null(s);
	assert_int_equal(s->ncams, 1);
	assert_int_equal(log.n, 2);
	assert_int_equal(log.last.line, 4);
	assert_int_equal(log.last.col, 1);
	assert_non_null(strstr(log.last.msg, "repeats line 1; ignored"));
	scene_free(s);

	/* No camera: a warning and the default camera; strict: an error. */
	memset(&log, 0, sizeof log);
	text = "A 0.2 255,255,255\nsp 0,0,0 1 255,0,0\n";
	s = load_with(text, strlen(text), "t.rt", false, &log, &err);
	assert_non_null(s);
	assert_int_equal(s->ncams, 1);
	scene *empty = scene_new();
	camera def = scene_camera(empty);
	scene_free(empty);
	assert_true(v3_eq(s->cams[0].pos, def.pos) && v3_eq(s->cams[0].dir, def.dir));
	assert_true(s->cams[0].fov == def.fov);
	assert_int_equal(log.n, 1);
	assert_int_equal(log.last.line, 0);
	assert_non_null(strstr(log.last.msg, "no camera; expected a C line"));
	scene_free(s);
	expect_strict_error("A 0.2 255,255,255\nL 0,0,0 1 255,255,255\n", 0, 0,
	                    "no camera; expected a C line");
}

static void test_fov_clamp_warning(void **state)
{
	(void)state;
	warn_log log = {0};
	rt_error err;
	const char *text = "C 0,0,0 0,0,1 0\nc 0,0,0 0,0,1 180\nc 0,0,0 0,0,1 0.005\n";
	scene *s = load_with(text, strlen(text), "t.rt", false, &log, &err);
	assert_non_null(s);
	assert_true(s->cams[0].fov == 0.01);
	assert_true(s->cams[1].fov == 179.99);
	assert_true(s->cams[2].fov == 0.01);
	assert_int_equal(log.n, 3);
	assert_int_equal(log.last.line, 3);
	assert_int_equal(log.last.col, 15);
	assert_string_equal(log.last.file, "t.rt");
	assert_non_null(strstr(log.last.msg, "camera fov \"0.005\" is clamped to 0.01 degrees"));
	scene_free(s);

	/* The clamp applies under strict too, where 0 and 180 are allowed. */
	memset(&log, 0, sizeof log);
	text = "A 0 0,0,0\nC 0,0,0 0,0,1 180\nL 0,0,0 0 0,0,0\n";
	s = load_with(text, strlen(text), "t.rt", true, &log, &err);
	assert_non_null(s);
	assert_true(s->cams[0].fov == 179.99);
	assert_int_equal(log.n, 1);
	assert_non_null(strstr(log.last.msg, "clamped to 179.99"));
	scene_free(s);
}

static void test_zero_size_left_out(void **state)
{
	(void)state;
	/* A 42-form size of exactly 0 (the wild corpus has a cylinder of
	 * height 0) loads with a warning and the object left out. */
	warn_log log = {0};
	rt_error err;
	const char *text = CAM "cy 0,0,0 0,1,0 2 0 255,0,0\nsp 0,0,0 1 1,2,3\n";
	scene *s = load_with(text, strlen(text), "t.rt", false, &log, &err);
	assert_non_null(s);
	assert_int_equal(s->nobjs, 1);
	assert_int_equal(s->objs[0].kind, OBJ_SPHERE);
	assert_int_equal(log.n, 1);
	assert_int_equal(log.last.line, 2);
	assert_int_equal(log.last.col, 18);
	assert_non_null(strstr(log.last.msg, "cylinder height \"0\" is zero"));
	scene_free(s);
	/* Its other fields are still checked. */
	expect_error(CAM "sp 0,0,0 0 255,0,256\n", 2, 12, "sphere colour");
	/* Strict mode: an error. */
	expect_strict_error("A 0 0,0,0\nC 0,0,0 0,0,1 70\nL 0,0,0 0 0,0,0\nsp 0,0,0 0 0,0,0\n", 4, 10,
	                    "sphere diameter \"0\" is not positive");
}

/* --- strict mode --- */

static void test_strict_rules(void **state)
{
	(void)state;
	rt_error err;
	scene *s = load_with(SUBJECT, strlen(SUBJECT), "scene.txt", true, NULL, &err);
	assert_null(s);
	assert_int_equal(err.line, 0);
	assert_non_null(strstr(err.msg, "does not end in .rt"));
	/* The same text under another name is fine. */
	s = load_with(SUBJECT, strlen(SUBJECT), "dir/x.rt", true, NULL, &err);
	assert_non_null(s);
	scene_free(s);

#define AC "A 0.2 255,255,255\nC 0,0,0 0,0,1 70\n"
#define ACL AC "L 0,0,0 0.5 255,255,255\n"
	expect_strict_error("C 0,0,0 0,0,1 70\nL 0,0,0 0.5 255,255,255\n", 0, 0,
	                    "no ambient light; expected an A line");
	expect_strict_error(AC, 0, 0, "no light; expected an L line");
	expect_strict_error(ACL "L 1,0,0 0.5 255,255,255\n", 4, 1, "light: a second L line; expected exactly one");
	expect_strict_error(AC "L 0,0,0 0.5\n", 3, 12, "light: too few fields; expected L POSITION RATIO R,G,B");
	expect_strict_error(ACL "C 0,0,0 0,0,1 70\n", 4, 1, "camera: a second C line");
	expect_strict_error("A 0.2 255,255,255\nA 0.2 255,255,255\nC 0,0,0 0,0,1 70\n", 2, 1,
	                    "ambient: a second A line");
	expect_strict_error(ACL "c 0,0,0 0,0,1 70\n", 4, 1,
	                    "strict mode does not allow the element \"c\"; expected one of A C L sp pl cy");
	static const char *const ids[] = {"l", "R", "co", "cu", "di", "rc", "sq", "tr", "sky", "set"};
	char text[256];
	for (size_t i = 0; i < sizeof ids / sizeof ids[0]; i++) {
		snprintf(text, sizeof text, ACL "%s 1 2 3\n", ids[i]);
		expect_strict_error(text, 4, 1, "strict mode does not allow the element");
	}
	expect_strict_error(ACL "sp 0,0,0 0,1,0 1,1,1 255,0,0\n", 4, 1,
	                    "sphere: the extended form is not allowed in strict mode; expected sp CENTER "
	                    "DIAMETER R,G,B");
	expect_strict_error(ACL "pl 0,0,0 0,1,0 1,1,1 255,0,0\n", 4, 1, "plane: the extended form");
	expect_strict_error(ACL "sp 0,0,0 1 255,0,0 1\n", 4, 20,
	                    "sphere: too many fields; expected sp CENTER DIAMETER R,G,B");
	expect_strict_error(ACL "sp 0,0,0 1 255,0,0 fuzz=0.5\n", 4, 20,
	                    "sphere key \"fuzz=0.5\" is not allowed in strict mode");
	/* Directions: components in [-1,1], unit length within 0.01. */
	expect_strict_error("A 0.2 255,255,255\nC 0,0,0 0,0,2 70\n", 2, 9,
	                    "camera direction \"0,0,2\" has a component outside [-1,1]");
	expect_strict_error("A 0.2 255,255,255\nC 0,0,0 0.5,0.5,0 70\n", 2, 9,
	                    "camera direction \"0.5,0.5,0\" is not a unit vector (length 0.7071)");
	expect_strict_error(ACL "pl 0,0,0 0,0.9,0 255,0,0\n", 4, 10, "plane normal");
	expect_strict_error(ACL "cy 0,0,0 1,1,1 1 1 255,0,0\n", 4, 10, "cylinder axis");
	/* Colours: whole numbers. */
	expect_strict_error(ACL "sp 0,0,0 1 127.5,0,0\n", 4, 12,
	                    "sphere colour \"127.5,0,0\" has a component that is not a whole number; "
	                    "expected R,G,B whole numbers in [0,255]");
	expect_strict_error("A 0.2 255,255,255.5\n", 1, 7, "not a whole number");
	/* What strict accepts: nearly unit directions, the subject's blanks. */
	s = load_strict_ok(ACL "pl 0,0,0 0.577,0.577,0.577 255,0,0\n"
	                       "cy 0,0,0 -0.6, 0.8, 0 1 1 1,2,3\n");
	assert_true(v3_eq(s->objs[0].dir, v3(0.577, 0.577, 0.577)));
	assert_true(v3_eq(s->objs[1].dir, v3(-0.6, 0.8, 0)));
	scene_free(s);
#undef ACL
#undef AC
}

/* --- the writer --- */

static void test_format_lines(void **state)
{
	(void)state;
	scene *s = load_ok(SUBJECT);
	char buf[512];
	rt_format_object(&s->objs[0], buf, sizeof buf);
	assert_string_equal(buf, "sp 0,0,20.6 12.6 10,0,255");
	rt_format_object(&s->objs[1], buf, sizeof buf);
	assert_string_equal(buf, "pl 0,0,-10 0,1,0 0,0,225");
	rt_format_object(&s->objs[2], buf, sizeof buf);
	assert_string_equal(buf, "cy 50,0,20.6 0,0,1 14.2 21.42 10,0,255");
	rt_format_light(&s->lights[0], buf, sizeof buf);
	assert_string_equal(buf, "L -40,50,0 0.6 10,0,255");
	rt_format_camera(&s->cams[0], buf, sizeof buf);
	assert_string_equal(buf, "C -50,0,20 0,0,1 70");
	/* A small buffer cuts the line and terminates it. */
	rt_format_object(&s->objs[0], buf, 8);
	assert_string_equal(buf, "sp 0,0,");
	scene_free(s);

	s = load_ok(CAM
	            "sp 0,0,0 0,0,1 1,2,3 255,255,100 0.5 0.25 100 0.75 0.1,0,0,0,0,0.2 twist=30 "
	            "fuzz=0.5 metal=1 ior=1.5 emit=2 checker=4\n"
	            "cu 1,2,3 1,1,0 2,2,2 10,20,30\n"
	            "tr 10,20,10 10,10,20 20,10,10 0,0,255\n"
	            "tr 0,0,0 1,0,0 0,1,0 9,9,9 0.1 0.2 3 0.4 emit=5\n"
	            "sq 0,0,20.6 1,0,0 12.6 10,0,255\n"
	            "rc 0,0,0 0,1,0 3,1,2 1,2,3\n"
	            "sp 0,0,0 2 255,0,0 fuzz=0.25\n"
	            "sp 0,0,0 0,1,0 1,1,2 1,2,3\n"
	            "co 1,2,3 0,-3,0 4 5 6,7,8 twist=90\n"
	            "sp 0.1,0,0 1 0,0,0\n");
	static const char *const want[] = {
		"sp 0,0,0 0,0,1 1,2,3 255,255,100 0.5 0.25 100 0.75 0.1,0,0,0,0,0.2 twist=30 fuzz=0.5 "
		"metal=1 ior=1.5 emit=2 checker=4",
		"cu 1,2,3 1,1,0 2,2,2 10,20,30 0.9 0.9 200 0",
		"tr 10,20,10 10,10,20 20,10,10 0,0,255",
		"tr 0,0,0 1,0,0 0,1,0 9,9,9 0.1 0.2 3 0.4 emit=5",
		"sq 0,0,20.6 1,0,0 12.6 10,0,255",
		"rc 0,0,0 0,1,0 3,1,2 1,2,3 0.9 0.9 200 0",
		"sp 0,0,0 2 255,0,0 fuzz=0.25",
		"sp 0,0,0 0,1,0 1,1,2 1,2,3 0.9 0.9 200 0",
		"co 1,2,3 0,-3,0 4,5,4 6,7,8 0.9 0.9 200 0 twist=90",
		"sp 0.1,0,0 1 0,0,0",
	};
	assert_int_equal(s->nobjs, sizeof want / sizeof want[0]);
	for (size_t i = 0; i < s->nobjs; i++) {
		rt_format_object(&s->objs[i], buf, sizeof buf);
		assert_string_equal(buf, want[i]);
	}
	/* The fewest digits that read back exactly. */
	s->objs[9].pos = v3(1.0 / 3.0, 0.1 + 0.2, -0.0);
	rt_format_object(&s->objs[9], buf, sizeof buf);
	assert_string_equal(buf, "sp 0.3333333333333333,0.30000000000000004,-0 1 0,0,0");
	scene_free(s);
}

static void test_write_layout(void **state)
{
	(void)state;
	const char *text = "sp 0,0,0 1 255,0,0\n"
	                   "L 0,5,0 0.5\n"
	                   "sky 100,150,255 255,255,255 2\n"
	                   "c 1,0,-5 0,0,1 60\n"
	                   "set mode path\n"
	                   "A 0.2 255,255,255\n"
	                   "C 0,0,-5 0,0,1 70\n"
	                   "set samples 16\n"
	                   "set resolution 640x480\n"
	                   "set depth 5\n";
	scene *s = load_ok(text);
	char *out = write_text(s, NULL);
	assert_string_equal(out, "# rtsh scene (the format is described in rtsh(5))\n"
	                         "R 640 480\n"
	                         "set samples 16\n"
	                         "set depth 5\n"
	                         "set mode path\n"
	                         "A 0.2 255,255,255\n"
	                         "C 1,0,-5 0,0,1 60\n"
	                         "c 0,0,-5 0,0,1 70\n"
	                         "L 0,5,0 0.5 255,255,255\n"
	                         "sky 100,150,255 255,255,255 2\n"
	                         "sp 0,0,0 1 255,0,0\n");
	free(out);
	assert_round_trip(s, "layout");
	scene_free(s);

	/* A scene with nothing optional. */
	s = load_ok("C 0,0,0 0,0,1 70\n");
	out = write_text(s, NULL);
	assert_string_equal(out, "# rtsh scene (the format is described in rtsh(5))\n"
	                         "C 0,0,0 0,0,1 70\n");
	free(out);
	scene_free(s);
}

static void test_save_and_load_file(void **state)
{
	(void)state;
	char dir[] = "/tmp/rtsh-test-rtfile-XXXXXX";
	assert_non_null(mkdtemp(dir));
	char path[256];
	snprintf(path, sizeof path, "%s/scene.rt", dir);
	scene *s = load_ok(SUBJECT);
	rt_error err;
	assert_true(rt_save(s, path, &err));
	rt_load_opts strict = {.strict = true};
	scene *t = rt_load_file(path, &strict, &err);
	assert_non_null(t);
	assert_true(scene_equal(s, t));
	scene_free(t);

	/* Errors name the file. */
	char missing[300];
	snprintf(missing, sizeof missing, "%s/missing.rt", dir);
	assert_null(rt_load_file(missing, NULL, &err));
	assert_string_equal(err.file, missing);
	assert_int_equal(err.line, 0);
	assert_non_null(strstr(err.msg, "cannot open"));
	assert_null(rt_load_file(dir, NULL, &err));
	assert_non_null(strstr(err.msg, "is a directory"));
	char bad[300];
	snprintf(bad, sizeof bad, "%s/bad.rt", dir);
	FILE *f = fopen(bad, "w");
	assert_non_null(f);
	fputs(CAM "sp 0,0,0 -1 255,0,0\n", f);
	fclose(f);
	assert_null(rt_load_file(bad, NULL, &err));
	assert_string_equal(err.file, bad);
	assert_int_equal(err.line, 2);
	assert_int_equal(err.col, 10);
	char formatted[700];
	rt_error_format(&err, formatted, sizeof formatted);
	char want[400];
	snprintf(want, sizeof want, "%s:2:10: sphere diameter \"-1\" is not positive", bad);
	assert_non_null(strstr(formatted, want));

	unlink(path);
	unlink(bad);
	rmdir(dir);
	scene_free(s);
}

/* --- rt_parse_line (the shell's `add`) --- */

static void test_parse_line(void **state)
{
	(void)state;
	scene *s = load_ok(SUBJECT);
	rt_error err;
	assert_true(rt_parse_line(s, "sp 1,2,3 4 5,6,7", "add", 1, NULL, &err));
	assert_int_equal(s->nobjs, 4);
	assert_true(v3_eq(s->objs[3].pos, v3(1, 2, 3)) && v3_eq(s->objs[3].scale, v3_splat(4)));
	assert_true(rt_parse_line(s, "L 0,0,0 0.5", "add", 1, NULL, &err));
	assert_int_equal(s->nlights, 2);
	/* A and C replace the existing ones; c adds a camera. */
	assert_true(rt_parse_line(s, "A 0.5 1,2,3", "add", 1, NULL, &err));
	assert_true(s->amb.ratio == 0.5 && v3_eq(s->amb.color, v3(1, 2, 3)));
	assert_true(rt_parse_line(s, "C 9,9,9 0,1,0 45", "add", 1, NULL, &err));
	assert_int_equal(s->ncams, 1);
	assert_true(v3_eq(s->cams[0].pos, v3(9, 9, 9)) && s->cams[0].fov == 45);
	assert_true(rt_parse_line(s, "c 1,1,1 0,1,0 50", "add", 1, NULL, &err));
	assert_int_equal(s->ncams, 2);
	assert_true(rt_parse_line(s, "set samples 4", "add", 1, NULL, &err));
	assert_true(rt_parse_line(s, "set samples 8", "add", 1, NULL, &err));
	assert_int_equal(s->hints.samples, 8);

	/* An error leaves the scene as it was. */
	scene *before = scene_clone(s);
	assert_false(rt_parse_line(s, "sp 1,2,3 -4 5,6,7", "add", 7, NULL, &err));
	assert_string_equal(err.file, "add");
	assert_int_equal(err.line, 7);
	assert_int_equal(err.col, 10);
	assert_non_null(strstr(err.msg, "sphere diameter \"-4\" is not positive"));
	assert_false(rt_parse_line(s, "sp 0,0,0 1 255,0,0 fuzz=9", "add", 1, NULL, &err));
	assert_false(rt_parse_line(s, "A 2 1,1,1", "add", 1, NULL, &err));
	assert_false(rt_parse_line(s, "", "add", 1, NULL, &err));
	assert_non_null(strstr(err.msg, "no element"));
	assert_false(rt_parse_line(s, "   # just a comment", "add", 1, NULL, &err));
	assert_false(rt_parse_line(s, "sp 0,0,0 1 255,0,0\nsp 0,0,0 1 255,0,0", "add", 1, NULL, &err));
	assert_non_null(strstr(err.msg, "control character 0x0A"));
	rt_load_opts strict = {.strict = true};
	assert_false(rt_parse_line(s, "co 0,0,0 0,1,0 1 1 1,1,1", "add", 1, &strict, &err));
	assert_true(scene_equal(before, s));
	scene_free(before);
	scene_free(s);
}

/* --- round trips --- */

static vec3 rand_vec(test_rng *r, double lo, double hi)
{
	return v3(trange(r, lo, hi), trange(r, lo, hi), trange(r, lo, hi));
}

/* A colour: usually whole numbers, sometimes not. */
static vec3 rand_color(test_rng *r)
{
	if (trand(r) < 0.7)
		return v3(floor(trange(r, 0, 256)), floor(trange(r, 0, 256)), floor(trange(r, 0, 256)));
	return rand_vec(r, 0, 255);
}

static vec3 rand_dir(test_rng *r)
{
	double u = trand(r);
	if (u < 0.3)
		return v3(0, 1, 0);
	if (u < 0.6)
		return tdir(r);
	return v3_scale(tdir(r), trange(r, 0.1, 10)); /* not normalised */
}

static object rand_object(test_rng *r)
{
	obj_kind k = (obj_kind)(int)trange(r, 0, OBJ_KIND_COUNT);
	if (obj_kind_flags(k) & KIND_MODEL)
		k = OBJ_SPHERE; /* a model needs a file (test_mesh round-trips mesh lines) */
	object o = object_make(k, rand_color(r));
	bool simple = trand(r) < 0.4; /* something a short form can say */
	if (k == OBJ_TRIANGLE) {
		vec3 a = rand_vec(r, -50, 50);
		o.tri[0] = a;
		o.tri[1] = v3_add(a, rand_vec(r, 0.5, 5));
		o.tri[2] = v3_add(a, v3(trange(r, -5, -0.5), trange(r, 0.5, 5), trange(r, -5, 5)));
	} else {
		o.pos = rand_vec(r, -100, 100);
		o.dir = simple && k == OBJ_SPHERE ? v3(0, 1, 0) : rand_dir(r);
		double d = trange(r, 0.01, 20);
		if (simple)
			o.scale = k == OBJ_PLANE ? v3_splat(1) : k == OBJ_RECT ? v3(d, 1, d)
			                                                    : v3(d, k == OBJ_SPHERE ? d : trange(r, 0.1, 9), d);
		else
			o.scale = rand_vec(r, 0.01, 20);
		if (!simple && trand(r) < 0.5)
			o.twist = trange(r, -180, 180);
		if (!simple && trand(r) < 0.3)
			for (int i = 0; i < 6; i++)
				o.shear[i] = trand(r) < 0.5 ? 0 : trange(r, -0.4, 0.4);
	}
	if (!simple || trand(r) < 0.3) {
		o.mat.diffuse = trand(r) < 0.2 ? 1 : trand(r);
		o.mat.specular = trand(r);
		o.mat.shininess = trange(r, 1, 500);
		o.mat.reflective = trand(r) < 0.5 ? 0 : trand(r);
	}
	if (trand(r) < 0.3)
		o.mat.fuzz = trand(r);
	if (trand(r) < 0.2)
		o.mat.metal = trand(r);
	if (trand(r) < 0.2)
		o.mat.ior = trange(r, 1, 3);
	if (trand(r) < 0.2)
		o.mat.emission = trange(r, 0, 50);
	if (trand(r) < 0.2)
		o.mat.checker = (int)trange(r, 1, 20);
	return o;
}

static scene *rand_scene(test_rng *r)
{
	scene *s = scene_new();
	assert_non_null(s);
	rt_error err;
	if (trand(r) < 0.8) {
		s->has_ambient = true;
		s->amb = (ambient){trand(r), rand_color(r)};
	}
	int ncams = 1 + (int)trange(r, 0, 3);
	for (int i = 0; i < ncams; i++) {
		camera c = {rand_vec(r, -50, 50), rand_dir(r), trange(r, 1, 179), false, 0, 0};
		assert_true(scene_add_camera(s, &c, &err));
	}
	int nlights = (int)trange(r, 0, 4);
	for (int i = 0; i < nlights; i++) {
		light l = {.pos = rand_vec(r, -50, 50), .ratio = trand(r), .color = rand_color(r)};
		assert_true(scene_add_light(s, &l, &err));
	}
	if (trand(r) < 0.3) {
		s->has_sky = true;
		s->sky = (sky){.zenith = rand_color(r), .horizon = rand_color(r), .strength = trand(r) < 0.5 ? 1 : trange(r, 0, 5)};
	}
	if (trand(r) < 0.3) {
		s->hints.width = 1 + (int)trange(r, 0, 4000);
		s->hints.height = 1 + (int)trange(r, 0, 4000);
	}
	if (trand(r) < 0.3)
		s->hints.samples = 1 + (int)trange(r, 0, 1000);
	if (trand(r) < 0.3)
		s->hints.depth = (int)trange(r, 0, 50);
	if (trand(r) < 0.3)
		s->hints.mode = trand(r) < 0.5 ? MODE_WHITTED : MODE_PATH;
	int nobjs = (int)trange(r, 0, 30);
	for (int i = 0; i < nobjs; i++) {
		object o = rand_object(r);
		if (object_validate(&o, &err))
			assert_true(scene_add_object(s, &o, &err));
	}
	return s;
}

static void test_round_trip_random(void **state)
{
	(void)state;
	test_rng r = {20240611};
	for (int i = 0; i < 300; i++) {
		scene *s = rand_scene(&r);
		char what[32];
		snprintf(what, sizeof what, "random scene %d", i);
		assert_round_trip(s, what);
		scene_free(s);
	}
}

static void test_round_trip_examples(void **state)
{
	(void)state;
	scene *s = load_ok(SUBJECT);
	assert_round_trip(s, "subject");
	scene_free(s);
	s = load_ok("R 100 100\nc 0,0,0 0,0,1 0\nl 0,0,0 0.3\nsq 0,0,0 0,0,1 1 1,2,3\n"
	            "tr 0,0,0 1,0,0 0,1,0 1,2,3\nco 0,0,0 1,1,1 1 2 3,4,5\ndi 0,0,0 0,1,0 1,2,3 4,5,6\n");
	assert_round_trip(s, "2019 and extended");
	scene_free(s);
}

/* The wild corpus: every file loads or fails cleanly, every load round
 * trips, the mandatory42/old2019/extendedA files all load and --strict
 * rejects every invalid one. */
typedef struct variant_count {
	char name[32];
	int total, loaded, strict_failed;
} variant_count;

static void test_wild_corpus(void **state)
{
	(void)state;
	FILE *idx = fopen(WILD_DIR "/INDEX.tsv", "r");
	if (!idx) {
		print_message("skipped: %s not found (run from the repository root with the shared "
		              "folder beside it)\n",
		              WILD_DIR);
		skip();
	}
	variant_count counts[16];
	int nvar = 0, problems = 0;
	char line[4096];
	while (fgets(line, sizeof line, idx)) {
		char *path = strtok(line, "\t\n");
		strtok(NULL, "\t\n");
		strtok(NULL, "\t\n");
		char *variant = strtok(NULL, "\t\n");
		if (!path || !variant || strcmp(path, "path") == 0)
			continue;
		variant_count *v = NULL;
		for (int i = 0; i < nvar; i++)
			if (strcmp(counts[i].name, variant) == 0)
				v = &counts[i];
		if (!v) {
			assert_true(nvar < 16);
			v = &counts[nvar++];
			memset(v, 0, sizeof *v);
			snprintf(v->name, sizeof v->name, "%s", variant);
		}
		char full[1024];
		snprintf(full, sizeof full, "%s/%s", WILD_DIR, path);
		v->total++;
		rt_error err;
		scene *s = rt_load_file(full, NULL, &err);
		if (s) {
			v->loaded++;
			assert_round_trip(s, full);
			scene_free(s);
		} else if (!strstr(err.file, path) || !err.msg[0]) {
			print_message("%s: error without the file name: %s\n", full, err.msg);
			problems++;
		}
		bool must = strcmp(variant, "mandatory42") == 0 || strcmp(variant, "old2019") == 0 ||
		            strcmp(variant, "extendedA") == 0;
		if (must && !s) {
			char buf[700];
			rt_error_format(&err, buf, sizeof buf);
			print_message("must load: %s\n", buf);
			problems++;
		}
		rt_load_opts strict = {.strict = true};
		scene *t = rt_load_file(full, &strict, &err);
		if (!t)
			v->strict_failed++;
		else if (strcmp(variant, "invalid") == 0) {
			print_message("--strict loaded an invalid file: %s\n", full);
			problems++;
		}
		scene_free(t);
	}
	fclose(idx);
	for (int i = 0; i < nvar; i++)
		print_message("wild %-12s %3d files: %3d load, %3d fail; --strict rejects %3d\n",
		              counts[i].name, counts[i].total, counts[i].loaded,
		              counts[i].total - counts[i].loaded, counts[i].strict_failed);
	assert_int_equal(problems, 0);
}

/* Numbers are read and written in the C locale whatever LC_NUMERIC says.
 * Without an installed decimal-comma locale, one is built with localedef. */
static void test_c_locale_numbers(void **state)
{
	(void)state;
	static const char *const locales[] = {"de_DE.UTF-8", "fr_FR.UTF-8", "de_DE", "fr_FR"};
	const char *got = NULL;
	for (size_t i = 0; i < 4 && !got; i++)
		got = setlocale(LC_NUMERIC, locales[i]);
	char dir[] = "/tmp/rtsh-test-locale-XXXXXX", cmd[256];
	bool built = false;
	if (!got && mkdtemp(dir)) {
		built = true;
		snprintf(cmd, sizeof cmd, "localedef -i de_DE -f UTF-8 %s/de_DE.UTF-8 >/dev/null 2>&1",
		         dir);
		if (system(cmd) == 0) {
			setenv("LOCPATH", dir, 1);
			got = setlocale(LC_NUMERIC, "de_DE.UTF-8");
		}
	}
	if (got) {
		char probe[16];
		snprintf(probe, sizeof probe, "%g", 0.5);
		assert_string_equal(probe, "0,5"); /* the locale is in effect */
		scene *s = load_ok("A 0.5 255,255,255\nC 0,0,0 0,0,1 70\nsp 0,0,0 0.25 1,2,3\n");
		assert_true(s->amb.ratio == 0.5);
		char buf[128];
		rt_format_object(&s->objs[0], buf, sizeof buf);
		assert_string_equal(buf, "sp 0,0,0 0.25 1,2,3");
		scene_free(s);
		setlocale(LC_NUMERIC, "C");
	}
	if (built) {
		unsetenv("LOCPATH");
		snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
		assert_int_equal(system(cmd), 0);
	}
	if (!got) {
		print_message("skipped: no locale with a decimal comma (and localedef failed)\n");
		skip();
	}
}

/* object_rules and the numeric keys: for every kind and every numeric key,
 * a value outside the key's range is refused, naming the key, when the
 * key applies to the kind (rt_key_applies), and ignored when it does not
 * (object_rules keeps a list of each kind's keys). */
static void test_object_rules_keys(void **state)
{
	(void)state;
	int refused = 0, ignored = 0;
	for (int kind = 0; kind < OBJ_KIND_COUNT; kind++) {
		object base = object_make((obj_kind)kind, v3(10, 20, 30));
		if (!object_rules(&base, NULL))
			continue; /* a kind whose bare object needs more (a model's file) */
		for (size_t i = 0; i < rt_nkeys; i++) {
			const rt_key *k = &rt_keys[i];
			if (k->type != RT_KEY_NUM)
				continue;
			double bad = k->max + 1;
			if (!(k->max < 1e9) || bad == k->def)
				bad = k->min - 1;
			if (!(k->min > -1e9) || bad == k->def)
				continue;
			object o = base;
			assert_true(rt_key_set(k, &o, bad));
			rt_error err;
			err.msg[0] = '\0';
			bool ok = object_rules(&o, &err);
			if (rt_key_applies(k, (obj_kind)kind)) {
				if (ok || !strstr(err.msg, k->name))
					fail_msg("kind %s key %s=%g: %s", obj_kind_name((obj_kind)kind), k->name, bad,
					         ok ? "accepted" : err.msg);
				refused++;
			} else {
				if (!ok)
					fail_msg("kind %s key %s (not its own)=%g refused: %s", obj_kind_name((obj_kind)kind),
					         k->name, bad, err.msg);
				ignored++;
			}
		}
	}
	assert_true(refused > 20 && ignored > 5);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_subject_example),
		cmocka_unit_test(test_cone_and_raw_directions),
		cmocka_unit_test(test_light_default_colour),
		cmocka_unit_test(test_2019_variant),
		cmocka_unit_test(test_extended_format),
		cmocka_unit_test(test_key_order_and_defaults),
		cmocka_unit_test(test_sky_and_set),
		cmocka_unit_test(test_numbers_accepted),
		cmocka_unit_test(test_number_traps),
		cmocka_unit_test(test_line_ends_blanks_comments),
		cmocka_unit_test(test_control_bytes_and_empty),
		cmocka_unit_test(test_long_lines),
		cmocka_unit_test(test_many_lines),
		cmocka_unit_test(test_field_errors),
		cmocka_unit_test(test_first_error_wins),
		cmocka_unit_test(test_repeats_and_missing_camera),
		cmocka_unit_test(test_fov_clamp_warning),
		cmocka_unit_test(test_zero_size_left_out),
		cmocka_unit_test(test_strict_rules),
		cmocka_unit_test(test_format_lines),
		cmocka_unit_test(test_write_layout),
		cmocka_unit_test(test_save_and_load_file),
		cmocka_unit_test(test_parse_line),
		cmocka_unit_test(test_round_trip_examples),
		cmocka_unit_test(test_round_trip_random),
		cmocka_unit_test(test_kept_settings),
		cmocka_unit_test(test_kept_settings_each_row),
		cmocka_unit_test(test_kept_settings_errors),
		cmocka_unit_test(test_wild_corpus),
		cmocka_unit_test(test_c_locale_numbers),
		cmocka_unit_test(test_object_rules_keys),
	};
	return cmocka_run_group_tests_name("rtfile", tests, NULL, NULL);
}
