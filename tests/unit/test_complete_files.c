/* rtsh — tests of file-name completion by type (shell/complete_files.h):
 * load is offered folders and .rt files, save folders, the files it could
 * overwrite and the extensions it writes. */
#include "testutil.h"

#include <sys/stat.h>
#include <unistd.h>

#include "shell/complete_files.h"

typedef struct got {
	char *v[32];
	int n;
} got;

static void collect(void *ctx, const char *s)
{
	got *g = ctx;
	if (g->n < 32)
		g->v[g->n++] = strdup(s);
}

static int by_name(const void *a, const void *b)
{
	return strcmp(*(char *const *)a, *(char *const *)b);
}

/* The candidates, sorted and joined by spaces. */
static void check(const char *text, file_use use, const char *want)
{
	got g = {.n = 0};
	complete_files(text, use, collect, &g);
	qsort(g.v, (size_t)g.n, sizeof g.v[0], by_name);
	char all[2048] = "";
	for (int i = 0; i < g.n; i++) {
		strcat(all, i ? " " : "");
		strcat(all, g.v[i]);
		free(g.v[i]);
	}
	assert_string_equal(all, want);
}

static void touch(const char *dir, const char *name)
{
	char p[512];
	snprintf(p, sizeof p, "%s/%s", dir, name);
	FILE *f = fopen(p, "w");
	assert_non_null(f);
	fclose(f);
}

static void test_by_type(void **state)
{
	(void)state;
	char dir[] = "/tmp/rtsh-complete-XXXXXX";
	assert_non_null(mkdtemp(dir));
	const char *names[] = {"a.rt", "b.png", "c.txt", "d.PPM", ".e.rt", "f.ans", "g.obj"};
	for (size_t i = 0; i < 7; i++)
		touch(dir, names[i]);
	char sub[600], text[600], want[2048];
	snprintf(sub, sizeof sub, "%s/sub", dir);
	assert_int_equal(mkdir(sub, 0700), 0);
	/* load: the folder, the scene and the model; not the image, text or hidden. */
	snprintf(text, sizeof text, "%s/", dir);
	snprintf(want, sizeof want, "%s/a.rt %s/g.obj %s/sub/", dir, dir, dir);
	check(text, FILES_SCENE, want);
	/* Hidden files when asked for. */
	snprintf(text, sizeof text, "%s/.", dir);
	snprintf(want, sizeof want, "%s/.e.rt", dir);
	check(text, FILES_SCENE, want);
	/* save: what it could overwrite (any case of extension), and folders. */
	snprintf(text, sizeof text, "%s/", dir);
	snprintf(want, sizeof want, "%s/a.rt %s/b.png %s/d.PPM %s/f.ans %s/sub/", dir, dir, dir, dir, dir);
	check(text, FILES_OUTPUT, want);
	/* save NAME: NAME with each extension it writes. */
	snprintf(text, sizeof text, "%s/out", dir);
	snprintf(want, sizeof want, "%s/out.ans %s/out.jpeg %s/out.jpg %s/out.pfm %s/out.png %s/out.ppm %s/out.rt",
	         dir, dir, dir, dir, dir, dir, dir);
	check(text, FILES_OUTPUT, want);
	/* A prefix of a file and a folder. */
	snprintf(text, sizeof text, "%s/s", dir);
	snprintf(want, sizeof want, "%s/s.ans %s/s.jpeg %s/s.jpg %s/s.pfm %s/s.png %s/s.ppm %s/s.rt %s/sub/", dir,
	         dir, dir, dir, dir, dir, dir, dir);
	check(text, FILES_OUTPUT, want);
	for (size_t i = 0; i < 6; i++) {
		char p[600];
		snprintf(p, sizeof p, "%s/%s", dir, names[i]);
		unlink(p);
	}
	rmdir(sub);
	rmdir(dir);
	/* The names save accepts are the ones it offers. */
	assert_true(output_name_ok("x.png"));
	assert_true(output_name_ok("x.rt"));
	assert_true(output_name_ok("x.ANS"));
	assert_false(output_name_ok("x.txt"));
	assert_false(output_name_ok("png"));
}

static void test_home(void **state)
{
	(void)state;
	char home[] = "/tmp/rtsh-home-XXXXXX";
	assert_non_null(mkdtemp(home));
	setenv("HOME", home, 1);
	touch(home, "h.rt");
	/* ~/ stays as typed. */
	check("~/", FILES_SCENE, "~/h.rt");
	char p[600];
	snprintf(p, sizeof p, "%s/h.rt", home);
	unlink(p);
	rmdir(home);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_by_type),
		cmocka_unit_test(test_home),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
