/* Libraries opened on first use (base/dynlib.h): assimp, libXpm, cJSON and
 * libsixel are not linked, so a process maps them only when a model, an XPM
 * image, a glTF or a sixel picture needs them; dynlib_open's answers for a library or a function that is missing.
 * This test binary is linked as rtsh is (LDLIBS_FRONT). */
#include "testutil.h"
#include "tmpdir.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base/dynlib.h"
#include "rtsh/gltf.h"
#include "rtsh/mesh.h"
#include "rtsh/texture.h"
#include "term/pixels.h"

/* Whether a library whose file name holds `name` is mapped in this process. */
static bool mapped(const char *name)
{
	FILE *f = fopen("/proc/self/maps", "r");
	assert_non_null(f);
	char line[4096];
	bool found = false;
	while (!found && fgets(line, sizeof line, f))
		found = strstr(line, name) != NULL;
	fclose(f);
	return found;
}

/* Runs first: nothing has read a model or an XPM image yet. */
static void test_not_mapped_at_start(void **state)
{
	(void)state;
	assert_false(mapped("libassimp"));
	assert_false(mapped("libdraco")); /* (not libstdc++: the sanitizers' runtimes bring it) */
	assert_false(mapped("libXpm"));
	assert_false(mapped("libX11"));
	assert_false(mapped("libcjson"));
	assert_false(mapped("libsixel"));
}

/* An STL (read by assimp) loads assimp; the triangle is the file's. */
static void test_model_loads_assimp(void **state)
{
	(void)state;
	rt_error err = {0};
	mesh *m = mesh_load(tmp_text("t.stl", "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 2 0 0\n"
	                                      "vertex 0 2 0\nendloop\nendfacet\nendsolid t\n"),
	                    &err);
	assert_non_null(m);
	assert_int_equal(m->ntris, 1);
	mesh_free(m);
	assert_true(mapped("libassimp"));
}

/* An XPM texture loads libXpm; its one pixel is #FF0000 (linear 1, 0, 0). */
static void test_xpm_loads_libxpm(void **state)
{
	(void)state;
	rt_error err = {0};
	int w = 0, h = 0;
	const char *xpm = "/* XPM */\nstatic char *x[] = {\n\"1 1 1 1\",\n\"a c #FF0000\",\n\"a\"};\n";
	float *p = image_load_rgb(tmp_text("a.xpm", xpm), false, &w, &h, &err);
	assert_non_null(p);
	assert_int_equal(w, 1);
	assert_int_equal(h, 1);
	assert_true(p[0] == 1.0f && p[1] == 0.0f && p[2] == 0.0f);
	free(p);
	assert_true(mapped("libXpm"));
}

/* A glTF (its JSON read by cJSON) loads cJSON; its one camera stands
 * where its node puts it, (1, 2, 3), mirrored into the scene's frame (X
 * negated, as test_gltf's cameras): (-1, 2, 3). */
static void test_gltf_loads_cjson(void **state)
{
	(void)state;
	const char *g = "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
	                "\"nodes\":[{\"camera\":0,\"translation\":[1,2,3]}],"
	                "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.5,\"znear\":0.1}}]}";
	gltf_info gi;
	rt_error err = {0};
	if (!gltf_parse_info("t.gltf", g, strlen(g), &gi, &err))
		fail_msg("%s", err.msg);
	assert_int_equal(gi.ncams, 1);
	assert_true(gi.cams[0].pos.x == -1 && gi.cams[0].pos.y == 2 && gi.cams[0].pos.z == 3);
	gltf_info_free(&gi);
	assert_true(mapped("libcjson"));
}

/* A sixel picture loads libsixel: a 2x1 picture is one DCS sequence (ESC
 * P ... q, VT340 manual chapter 14) with the raster attributes "1;1;2;1, an
 * RGB colour register (#0;2;...) and ESC \\ at the end. */
static void test_sixel_loads_libsixel(void **state)
{
	(void)state;
	char why[400] = "unset";
	assert_true(pixels_sixel_available(why, sizeof why));
	assert_string_equal(why, "unset"); /* untouched when it loads */
	const uint8_t rgb[6] = {255, 0, 0, 0, 0, 255};
	abuf a;
	abuf_init(&a);
	assert_true(pixels_sixel(&a, rgb, 2, 1));
	abuf_add(&a, "", 1); /* a C string */
	assert_true(a.len > 4);
	assert_memory_equal(a.b, "\x1bP", 2);
	assert_non_null(strchr(a.b, 'q'));
	assert_non_null(strstr(a.b, "\"1;1;2;1"));
	assert_non_null(strstr(a.b, "#0;2;"));
	assert_memory_equal(a.b + a.len - 3, "\x1b\\", 2);
	abuf_free(&a);
	assert_true(mapped("libsixel"));
}

static void test_missing_library(void **state)
{
	(void)state;
	double (*fn)(double) = NULL;
	const dynlib_fn fns[] = {{"cos", &fn}};
	char why[256];
	assert_false(dynlib_open("librtsh-no-such-library.so.0", fns, 1, why, sizeof why));
	assert_non_null(strstr(why, "librtsh-no-such-library.so.0"));
	assert_null(fn);
}

static void test_missing_function(void **state)
{
	(void)state;
	double (*fn)(double) = NULL;
	const dynlib_fn fns[] = {{"rtsh_no_such_function", &fn}};
	char why[256];
	assert_false(dynlib_open("libm.so.6", fns, 1, why, sizeof why));
	assert_non_null(strstr(why, "rtsh_no_such_function"));
}

/* libm's functions through the pointers: sqrt(2.25) = 1.5, cos(0) = 1. */
static void test_functions_called(void **state)
{
	(void)state;
	double (*c)(double) = NULL, (*s)(double) = NULL;
	const dynlib_fn fns[] = {{"cos", &c}, {"sqrt", &s}};
	char why[256] = "unset";
	assert_true(dynlib_open("libm.so.6", fns, 2, why, sizeof why));
	assert_string_equal(why, "");
	assert_non_null(c);
	assert_non_null(s);
	volatile double a = 2.25, z = 0.0;
	assert_true(s(a) == 1.5);
	assert_true(c(z) == 1.0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_not_mapped_at_start), /* first: before any reader ran */
	    cmocka_unit_test(test_model_loads_assimp),
	    cmocka_unit_test(test_xpm_loads_libxpm),
	    cmocka_unit_test(test_gltf_loads_cjson),
	    cmocka_unit_test(test_sixel_loads_libsixel),
	    cmocka_unit_test(test_missing_library),
	    cmocka_unit_test(test_missing_function),
	    cmocka_unit_test(test_functions_called),
	};
	return cmocka_run_group_tests(tests, tmpdir_setup, tmpdir_teardown);
}
