/* rtsh — tests of the writer that keeps the source (rtsh/rtkeep.h): an
 * unedited scene saves to the same bytes; one edit changes exactly its own
 * line, in the form it was written; deletions drop a line, additions add
 * one where they fall in their list. */
#include "testutil.h"

#include <dirent.h>

#include "rtsh/rtfile.h"
#include "rtsh/rtkeep.h"
#include "rtsh/settings.h"
#include "scene/rtfile_priv.h"

static scene *load(const char *text)
{
	rt_error err;
	scene *s = rt_load_string(text, strlen(text), "t.rt", NULL, &err);
	if (!s)
		fail_msg("load: %s", err.msg);
	return s;
}

/* The kept text of s against src; fails when the writer fell back. */
static char *keep(const scene *s, const char *src)
{
	size_t n = 0;
	char *t = rt_keep_text(s, src, strlen(src), &n);
	if (!t)
		fail_msg("the keeping writer fell back to rt_write for:\n%s", src);
	assert_int_equal(strlen(t), n);
	return t;
}

/* Every odd spelling the reader accepts, with comments everywhere. */
static const char wild[] =
	"# a scene written by hand\r\n"
	"\r\n"
	"A   0.20   255,255,255   // dim\r\n"
	"C 0,0,-5  0, 0, 1   70.0\r\n"
	"C 0,0,-5 0,0,1 70\r\n" /* an identical repeat: ignored */
	"l 2,0,-10 1.0\r\n"
	"\tsp 0,0,0 1 255,0,0 # red\r\n"
	"sp 1e0,0,0 2.50 0,255,0\r\n"
	"sp 0,3,0 0,1,0 1,1,1 0,0,255 0.9 0.9 200 0\r\n" /* extended, though short would do */
	"sky 10,20,30 200,200,255 1\r\n"
	"set samples 4\r\n"
	"sp 9,9,9 0 1,2,3\r\n" /* size 0: left out */
	"cy 0,-1,0 0,1,0 1 2 9,9,9 fuzz=0.5";  /* no final line end */

static void test_unedited_is_identical(void **state)
{
	(void)state;
	scene *s = load(wild);
	char *t = keep(s, wild);
	assert_string_equal(t, wild);
	free(t);
	scene_free(s);
}

static void test_every_example_scene(void **state)
{
	(void)state;
	DIR *d = opendir("scenes");
	if (!d) {
		print_message("no scenes/ folder here; skipped\n");
		return;
	}
	int n = 0;
	struct dirent *e;
	while ((e = readdir(d))) {
		size_t len = strlen(e->d_name);
		if (len < 4 || strcmp(e->d_name + len - 3, ".rt") != 0)
			continue;
		char path[512];
		snprintf(path, sizeof path, "scenes/%s", e->d_name);
		FILE *f = fopen(path, "rb");
		assert_non_null(f);
		char *src = malloc(1 << 20);
		size_t got = fread(src, 1, (1 << 20) - 1, f);
		fclose(f);
		src[got] = '\0';
		/* model and texture names are relative to the scene's folder */
		rt_error err;
		scene *s = rt_load_string(src, strlen(src), path, NULL, &err);
		if (!s)
			fail_msg("load: %s", err.msg);
		rt_keep_source = path;
		rt_write_dir = "scenes";
		char *t = keep(s, src);
		rt_keep_source = NULL;
		rt_write_dir = "";
		if (strcmp(t, src) != 0)
			fail_msg("%s does not save to the same bytes", path);
		free(t);
		free(src);
		scene_free(s);
		n++;
	}
	closedir(d);
	assert_true(n >= 5);
}

/* The lines of a text, split at line ends (\r\n kept out). */
static int lines_of(char *t, char **out, int max)
{
	int n = 0;
	for (char *p = t; *p && n < max;) {
		out[n++] = p;
		size_t k = strcspn(p, "\r\n");
		if (!p[k])
			break;
		p[k] = '\0';
		p += k + 1;
		if (*p == '\n')
			p++;
	}
	return n;
}

/* Compares a and b line by line: returns how many lines differ when both
 * have the same count (the differing one in *which), -1 otherwise. */
static int differing(const char *a, const char *b, int *which, char **bline)
{
	char *x = strdup(a), *y = strdup(b), *la[64], *lb[64];
	int na = lines_of(x, la, 64), nb = lines_of(y, lb, 64), diff = 0;
	static char keepb[512];
	if (na != nb) {
		free(x);
		free(y);
		return -1;
	}
	for (int i = 0; i < na; i++)
		if (strcmp(la[i], lb[i]) != 0) {
			diff++;
			*which = i;
			snprintf(keepb, sizeof keepb, "%s", lb[i]);
			*bline = keepb;
		}
	free(x);
	free(y);
	return diff;
}

static void test_one_edit_one_line(void **state)
{
	(void)state;
	scene *s = load(wild);
	int which = -1;
	char *line = NULL;
	/* The first sphere (line 7): indentation and comment stay, short form. */
	s->objs[0].pos = v3(0.5, 0, 0);
	char *t = keep(s, wild);
	assert_int_equal(differing(wild, t, &which, &line), 1);
	assert_int_equal(which, 6);
	assert_string_equal(line, "\tsp 0.5,0,0 1 255,0,0 # red");
	free(t);
	s->objs[0].pos = v3(0, 0, 0);
	/* The extended sphere stays extended. */
	s->objs[2].mat.color = v3(1, 2, 3);
	t = keep(s, wild);
	assert_int_equal(differing(wild, t, &which, &line), 1);
	assert_int_equal(which, 8);
	assert_string_equal(line, "sp 0,3,0 0,1,0 1,1,1 1,2,3 0.9 0.9 200 0");
	free(t);
	s->objs[2].mat.color = v3(0, 0, 255);
	/* A light keeps its 2019 identifier; the ambient its comment. */
	s->lights[0].ratio = 0.5;
	s->amb.ratio = 0.25;
	t = keep(s, wild);
	char *x = strdup(t), *l[64];
	int n = lines_of(x, l, 64);
	assert_int_equal(n, 13);
	assert_string_equal(l[2], "A 0.25 255,255,255   // dim");
	assert_string_equal(l[5], "l 2,0,-10 0.5 255,255,255");
	free(x);
	free(t);
	s->lights[0].ratio = 1;
	s->amb.ratio = 0.2;
	/* An edited C drops its ignored repeat (it would now conflict). */
	s->cams[0].fov = 60;
	t = keep(s, wild);
	x = strdup(t);
	n = lines_of(x, l, 64);
	assert_int_equal(n, 12);
	assert_string_equal(l[3], "C 0,0,-5 0,0,1 60");
	assert_string_equal(l[4], "l 2,0,-10 1.0");
	free(x);
	free(t);
	s->cams[0].fov = 70;
	/* The sky keeps its written strength of 1; a new one is written. */
	s->sky.strength = 2;
	t = keep(s, wild);
	assert_int_equal(differing(wild, t, &which, &line), 1);
	assert_string_equal(line, "sky 10,20,30 200,200,255 2");
	free(t);
	s->sky.strength = 1;
	s->sky.zenith = v3(0, 0, 0);
	t = keep(s, wild);
	assert_int_equal(differing(wild, t, &which, &line), 1);
	assert_string_equal(line, "sky 0,0,0 200,200,255 1");
	free(t);
	scene_free(s);
}

static void test_delete_add_and_hints(void **state)
{
	(void)state;
	const char src[] = "C 0,0,-5 0,0,1 70\n"
	                   "sp 0,0,0 1 255,0,0\n"
	                   "# the second\n"
	                   "sp 2,0,0 1 0,255,0\n"
	                   "sp 4,0,0 1 0,0,255\n";
	scene *s = load(src);
	/* Delete the middle sphere: its line goes, nothing else changes. */
	object mid = s->objs[1];
	scene_remove_object(s, 1);
	char *t = keep(s, src);
	assert_string_equal(t, "C 0,0,-5 0,0,1 70\nsp 0,0,0 1 255,0,0\n# the second\nsp 4,0,0 1 0,0,255\n");
	free(t);
	/* Put it back in the middle: its line comes back where it was. */
	rt_error err;
	assert_true(scene_insert_object(s, 1, &mid, &err));
	t = keep(s, src);
	assert_string_equal(t, src);
	free(t);
	/* A new object between the first and second: before the second's line. */
	object o = object_make(OBJ_SPHERE, v3(7, 7, 7));
	assert_true(scene_insert_object(s, 1, &o, &err));
	t = keep(s, src);
	assert_string_equal(t, "C 0,0,-5 0,0,1 70\nsp 0,0,0 1 255,0,0\n# the second\n"
	                       "sp 0,0,0 1 7,7,7\nsp 2,0,0 1 0,255,0\nsp 4,0,0 1 0,0,255\n");
	free(t);
	scene_remove_object(s, 1);
	/* Appended ones go at the end; so do new settings and a new light. */
	o.pos = v3(0, 9, 0);
	assert_true(scene_add_object(s, &o, &err));
	light li = {v3(1, 2, 3), 0.5, v3(255, 255, 255), LIGHT_MINIRT, 0, {0, 0, 0}, 0, 0, 0};
	assert_true(scene_add_light(s, &li, &err));
	s->hints.samples = 16;
	s->hints.mode = 1;
	t = keep(s, src);
	assert_string_equal(t, "C 0,0,-5 0,0,1 70\nsp 0,0,0 1 255,0,0\n# the second\nsp 2,0,0 1 0,255,0\n"
	                       "sp 4,0,0 1 0,0,255\nset samples 16\nset mode path\nL 1,2,3 0.5 255,255,255\n"
	                       "sp 0,9,0 1 7,7,7\n");
	free(t);
	scene_free(s);
	/* A written setting is rewritten in place, R as R. */
	const char hs[] = "R 640 480\nset samples 8\nC 0,0,-5 0,0,1 70\n";
	s = load(hs);
	s->hints.width = 320;
	s->hints.height = 200;
	s->hints.samples = 9;
	t = keep(s, hs);
	assert_string_equal(t, "R 320 200\nset samples 9\nC 0,0,-5 0,0,1 70\n");
	free(t);
	scene_free(s);
}

/* scene_hints.kept[] of the setting called name: the value text, "" unset. */
static char *kept(scene *s, const char *name)
{
	rt_error err;
	const setting_def *d = settings_find(name, &err);
	assert_non_null(d);
	return s->hints.kept[d - settings_table];
}

static void set_kept(scene *s, const char *name, const char *value)
{
	char *k = kept(s, name);
	memset(k, 0, SCENE_KEPT_LEN);
	snprintf(k, SCENE_KEPT_LEN, "%s", value);
}

/* The settings kept with the scene beyond the four: as the others. */
static void test_kept_settings(void **state)
{
	(void)state;
	const char src[] = "set seed 7\nC 0,0,-5 0,0,1 70\n# exposure\nset exposure 0.50\nsp 0,0,0 1 255,0,0\n";
	scene *s = load(src);
	assert_string_equal(kept(s, "seed"), "7");
	assert_string_equal(kept(s, "exposure"), "0.5");
	char *t = keep(s, src);
	assert_string_equal(t, src); /* unedited: 0.50 as it was written */
	free(t);
	/* Changed in place, dropped, added after the other settings. */
	set_kept(s, "seed", "9");
	set_kept(s, "exposure", "");
	set_kept(s, "denoise", "on");
	s->hints.samples = 3;
	t = keep(s, src);
	assert_string_equal(t, "set seed 9\nC 0,0,-5 0,0,1 70\n# exposure\nsp 0,0,0 1 255,0,0\n"
	                       "set samples 3\nset denoise on\n");
	free(t);
	scene_free(s);
}

static void test_default_camera(void **state)
{
	(void)state;
	/* No camera line: the default camera is not written until it moves. */
	const char src[] = "sp 0,0,0 1 255,0,0";
	scene *s = load(src);
	char *t = keep(s, src);
	assert_string_equal(t, src);
	free(t);
	s->cams[0].pos = v3(0, 0, -9);
	t = keep(s, src);
	char want[256], cam[128];
	rt_format_camera(&s->cams[0], cam, sizeof cam);
	snprintf(want, sizeof want, "sp 0,0,0 1 255,0,0\n%s\n", cam);
	assert_string_equal(t, want);
	free(t);
	scene_free(s);
}

/* Lists too long for the table (about 2490 x 2490 cells left between the
 * common head and tail, more than 2^21): a deletion and an edit far apart
 * still touch one line each. */
static void test_long_lists(void **state)
{
	(void)state;
	enum { N = 3000 };
	size_t cap = (size_t)N * 40 + 64;
	char *src = malloc(cap), *want = malloc(cap);
	size_t len = (size_t)snprintf(src, cap, "C 0,0,-5 0,0,1 70\n"), wl = len;
	memcpy(want, src, len);
	for (int i = 0; i < N; i++) {
		char line[64];
		/* "1.0": a rewritten line would read "1", so only the edited one may. */
		int n = snprintf(line, sizeof line, "sp %d,0,0 1.0 %d,0,0\n", i, i % 256);
		memcpy(src + len, line, (size_t)n + 1);
		len += (size_t)n;
		if (i == 10)
			continue; /* deleted */
		if (i == 2500)
			n = snprintf(line, sizeof line, "sp %d,5,0 1 %d,0,0\n", i, i % 256);
		memcpy(want + wl, line, (size_t)n + 1);
		wl += (size_t)n;
	}
	scene *s = load(src);
	s->objs[2500].pos.y = 5;
	scene_remove_object(s, 10);
	char *t = keep(s, src);
	assert_string_equal(t, want);
	free(t);
	scene_free(s);
	free(src);
	free(want);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_unedited_is_identical),
		cmocka_unit_test(test_every_example_scene),
		cmocka_unit_test(test_one_edit_one_line),
		cmocka_unit_test(test_delete_add_and_hints),
		cmocka_unit_test(test_default_camera),
		cmocka_unit_test(test_kept_settings),
		cmocka_unit_test(test_long_lists),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
