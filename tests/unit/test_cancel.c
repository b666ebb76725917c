/* rtsh — long work stops when its cancel flag is set (issue 31, defect 3:
 * Ctrl-C in the shell): loading a scene with a large model, generating,
 * building a world. The flag is set before the call, or from another thread
 * while the work runs; the call then fails with "stopped", keeps nothing in
 * the caches, and the same call without the flag succeeds after. And a
 * render pass stopped in flight: rendering again gives the picture of a
 * render never stopped, to the byte. */
#include "testutil.h"

#include <pthread.h>
#include <stdatomic.h>
#include <time.h>
#include <unistd.h>

#include "core/envmap.h"
#include "rtsh/generate.h"
#include "rtsh/texture.h"
#include "rtsh/mesh.h"
#include "rtsh/render.h"
#include "rtsh/rtfile.h"
#include "rtsh/world.h"

static char tmpdir[64];
static char rt_path[128], obj_path[128];

/* A model whose normals and tree take long: one polygon of 400000 corners
 * on a circle (a fan whose first corner every triangle shares), and a
 * scene that places it. */
static int setup(void **state)
{
	(void)state;
	snprintf(tmpdir, sizeof tmpdir, "/tmp/rtsh-cancel-XXXXXX");
	if (!mkdtemp(tmpdir))
		return -1;
	snprintf(obj_path, sizeof obj_path, "%s/fan.obj", tmpdir);
	snprintf(rt_path, sizeof rt_path, "%s/fan.rt", tmpdir);
	FILE *f = fopen(obj_path, "w");
	if (!f)
		return -1;
	const int n = 400000;
	for (int i = 0; i < n; i++)
		fprintf(f, "v %.9f %.9f %.9f\n", cos(2 * M_PI * i / n), sin(2 * M_PI * i / n), 0.1 * sin(40.0 * i / n));
	fputc('f', f);
	for (int i = 1; i <= n; i++)
		fprintf(f, " %d", i);
	fputc('\n', f);
	fclose(f);
	f = fopen(rt_path, "w");
	if (!f)
		return -1;
	fprintf(f, "C 0,0,-5 0,0,1 60\nL 2,2,-5 1 255,255,255\nmesh fan.obj 0,0,0 0,1,0 2 200,200,200\n");
	fclose(f);
	return 0;
}

static int teardown(void **state)
{
	(void)state;
	char cmd[128];
	snprintf(cmd, sizeof cmd, "rm -rf %s", tmpdir);
	return system(cmd) == 0 ? 0 : -1;
}

/* Sets *flag after `ms` milliseconds, from its own thread. */
typedef struct later {
	atomic_bool *flag;
	int ms;
} later;

static void *set_later(void *arg)
{
	later *l = arg;
	struct timespec ts = {l->ms / 1000, (long)(l->ms % 1000) * 1000000L};
	nanosleep(&ts, NULL);
	atomic_store(l->flag, true);
	return NULL;
}

static void test_load_stops(void **state)
{
	(void)state;
	atomic_bool cancel;
	rt_error err;
	/* already set: nothing is loaded */
	atomic_init(&cancel, true);
	rt_load_opts lo = {.cancel = &cancel};
	assert_null(rt_load_file(rt_path, &lo, &err));
	assert_non_null(strstr(err.msg, "stopped"));
	/* set from another thread while the model's normals and tree are made
	 * (the reader alone takes a fraction of that) */
	atomic_store(&cancel, false);
	later l = {&cancel, 30};
	pthread_t th;
	assert_int_equal(pthread_create(&th, NULL, set_later, &l), 0);
	scene *s = rt_load_file(rt_path, &lo, &err);
	pthread_join(th, NULL);
	if (s) {
		/* the machine finished the whole load in 30 ms: nothing to check */
		print_message("the load ended before the flag was set\n");
		scene_free(s);
	} else {
		assert_non_null(strstr(err.msg, "stopped"));
	}
	/* nothing half made stays in the cache: the same load without the flag
	 * gives the whole model */
	atomic_store(&cancel, false);
	s = rt_load_file(rt_path, &lo, &err);
	assert_non_null(s);
	assert_int_equal(s->nobjs, 1);
	mesh *m = mesh_cache_get(obj_path, true, s->objs[0].crease, NULL, &err);
	assert_non_null(m);
	/* the fan of a polygon of n corners: n - 2 triangles, less the few whose
	 * corners round to one line in float */
	assert_true(m->ntris <= 400000 - 2 && m->ntris > 399000);
	mesh_cache_put(m);
	scene_free(s);
}

static void test_generate_stops(void **state)
{
	(void)state;
	atomic_bool cancel;
	atomic_init(&cancel, true);
	rt_error err;
	assert_null(scene_generate(1000000, 7, &(gen_opts){.cancel = &cancel}, &err));
	assert_string_equal(err.msg, "stopped");
	atomic_store(&cancel, false);
	scene *s = scene_generate(1000, 7, &(gen_opts){.cancel = &cancel}, &err);
	assert_non_null(s);
	scene_free(s);
}

static void test_world_build_stops(void **state)
{
	(void)state;
	rt_error err;
	scene *s = scene_generate(300000, 3, NULL, &err);
	assert_non_null(s);
	atomic_bool cancel;
	atomic_init(&cancel, true);
	assert_null(world_build_cancel(s, &cancel, &err));
	assert_string_equal(err.msg, "stopped");
	/* from another thread, during the build */
	atomic_store(&cancel, false);
	later l = {&cancel, 20};
	pthread_t th;
	assert_int_equal(pthread_create(&th, NULL, set_later, &l), 0);
	world *w = world_build_cancel(s, &cancel, &err);
	pthread_join(th, NULL);
	if (w) {
		print_message("the build ended before the flag was set\n");
		world_release(w);
	} else {
		assert_string_equal(err.msg, "stopped");
	}
	w = world_build_cancel(s, NULL, &err);
	assert_non_null(w);
	assert_int_equal(w->nprims + w->nplanes, s->nobjs);
	world_release(w);
	scene_free(s);
}

/* The readers stop in the middle of a file (issue 31, defect 3: they ran to
 * their end before the flag was looked at). Each file below is valid up to
 * a fault in its last element: with the flag set before the read, the
 * reader stops before it gets there, so the error is "stopped", not the
 * fault (a reader that runs to its end reports the fault). */
static char *tmp_file(const char *name)
{
	static char path[8][160];
	static int k;
	char *p = path[k++ % 8];
	snprintf(p, sizeof path[0], "%s/%s", tmpdir, name);
	return p;
}

static void expect_stopped_mesh(const char *path)
{
	atomic_bool cancel;
	atomic_init(&cancel, true);
	rt_error err;
	assert_null(mesh_cache_get(path, true, 60, &cancel, &err));
	if (strcmp(err.msg, "stopped") != 0)
		fail_msg("%s: \"%s\", expected \"stopped\"", path, err.msg);
	/* without the flag the fault is found: the file is read to its end */
	assert_null(mesh_cache_get(path, true, 60, NULL, &err));
	assert_null(strstr(err.msg, "stopped"));
}

static void test_readers_stop(void **state)
{
	(void)state;
	const int n = 20000; /* elements: several times the 4096 between polls */
	/* OBJ: n vertices and triangles, then a face with index 0 */
	FILE *f = fopen(tmp_file("bad.obj"), "w");
	assert_non_null(f);
	for (int i = 0; i < n; i++)
		fprintf(f, "v %d %d %d\n", i % 7, i % 11, i % 13);
	for (int i = 1; i + 2 <= n; i += 3)
		fprintf(f, "f %d %d %d\n", i, i + 1, i + 2);
	fprintf(f, "f 1 2 0\n");
	fclose(f);
	expect_stopped_mesh(tmp_file("bad.obj"));
	/* ASCII PLY: the last face's index is past the vertices */
	f = fopen(tmp_file("bad.ply"), "w");
	assert_non_null(f);
	fprintf(f, "ply\nformat ascii 1.0\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\n"
	           "element face %d\nproperty list uchar int vertex_indices\nend_header\n", n, n / 3);
	for (int i = 0; i < n; i++)
		fprintf(f, "%d %d %d\n", i % 7, i % 11, i % 13);
	for (int i = 0; i + 1 < n / 3; i++)
		fprintf(f, "3 %d %d %d\n", 3 * i, 3 * i + 1, 3 * i + 2);
	fprintf(f, "3 0 1 %d\n", n);
	fclose(f);
	expect_stopped_mesh(tmp_file("bad.ply"));
	/* binary PLY: the same */
	f = fopen(tmp_file("badb.ply"), "wb");
	assert_non_null(f);
	fprintf(f, "ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
	           "property float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n", n, n / 3);
	for (int i = 0; i < n; i++) {
		float v[3] = {(float)(i % 7), (float)(i % 11), (float)(i % 13)};
		fwrite(v, sizeof v, 1, f);
	}
	for (int i = 0; i < n / 3; i++) {
		unsigned char c = 3;
		int32_t t[3] = {3 * i, 3 * i + 1, i + 1 < n / 3 ? 3 * i + 2 : n};
		fwrite(&c, 1, 1, f);
		fwrite(t, sizeof t, 1, f);
	}
	fclose(f);
	expect_stopped_mesh(tmp_file("badb.ply"));
	/* .gltf with an external .bin: n positions, then indices whose last is
	 * past them */
	f = fopen(tmp_file("bad.bin"), "wb");
	assert_non_null(f);
	for (int i = 0; i < n; i++) {
		float v[3] = {(float)(i % 7), (float)(i % 11), (float)(i % 13)};
		fwrite(v, sizeof v, 1, f);
	}
	int ni = 3 * (n / 3);
	for (int i = 0; i < ni; i++) {
		uint32_t k = i + 1 < ni ? (uint32_t)i : (uint32_t)n;
		fwrite(&k, 4, 1, f);
	}
	fclose(f);
	f = fopen(tmp_file("bad.gltf"), "w");
	assert_non_null(f);
	fprintf(f, "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
	           "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}],"
	           "\"buffers\":[{\"uri\":\"bad.bin\",\"byteLength\":%d}],"
	           "\"bufferViews\":[{\"buffer\":0,\"byteLength\":%d},{\"buffer\":0,\"byteOffset\":%d,\"byteLength\":%d}],"
	           "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":%d,\"type\":\"VEC3\","
	           "\"min\":[0,0,0],\"max\":[6,10,12]},"
	           "{\"bufferView\":1,\"componentType\":5125,\"count\":%d,\"type\":\"SCALAR\"}]}\n",
	        12 * n + 4 * ni, 12 * n, 12 * n, 4 * ni, n, ni);
	fclose(f);
	expect_stopped_mesh(tmp_file("bad.gltf"));
	/* an ASCII PPM of 100x100 whose last value is not a number */
	f = fopen(tmp_file("bad.ppm"), "w");
	assert_non_null(f);
	fprintf(f, "P3\n100 100\n255\n");
	for (int i = 0; i < 3 * 100 * 100 - 1; i++)
		fprintf(f, "%d\n", i % 256);
	fprintf(f, "x\n");
	fclose(f);
	atomic_bool cancel;
	atomic_init(&cancel, true);
	rt_error err;
	assert_null(texture_cache_get(tmp_file("bad.ppm"), true, &cancel, &err));
	assert_string_equal(err.msg, "stopped");
	assert_null(texture_cache_get(tmp_file("bad.ppm"), true, NULL, &err));
	assert_non_null(strstr(err.msg, "expected pixel value"));
	/* an HDR sky (a valid PPM here) stops in its decoder or, once cached,
	 * in the sky's distribution: envmap_new looks at the flag */
	f = fopen(tmp_file("sky.ppm"), "w");
	assert_non_null(f);
	fprintf(f, "P3\n100 100\n255\n");
	for (int i = 0; i < 3 * 100 * 100; i++)
		fprintf(f, "%d\n", i % 256);
	fclose(f);
	assert_null(envmap_new(tmp_file("sky.ppm"), 1, 0, &cancel, &err)); /* in the decoder */
	assert_string_equal(err.msg, "stopped");
	texture *t = texture_cache_get(tmp_file("sky.ppm"), false, NULL, &err);
	assert_non_null(t); /* now cached: */
	assert_null(envmap_new(tmp_file("sky.ppm"), 1, 0, &cancel, &err)); /* in the distribution */
	assert_string_equal(err.msg, "stopped");
	envmap *e = envmap_new(tmp_file("sky.ppm"), 1, 0, NULL, &err);
	assert_non_null(e);
	envmap_free(e);
	texture_cache_put(t);
}

/* The progress callback of the pass to stop: the first time it hears of
 * some tiles done and some not, it sets the flag (the render is then in
 * flight: its threads are between tiles). */
typedef struct stopper {
	atomic_bool *cancel;
	long done_then, total;
} stopper;

/* A generated scene of n objects (seed) and its world, both checked. */
static world *generated_world(int n, uint64_t seed, scene **s)
{
	rt_error err;
	*s = scene_generate(n, seed, NULL, &err);
	assert_non_null(*s);
	world *w = world_build(*s, &err);
	assert_non_null(w);
	return w;
}

static void stop_in_flight(void *ctx, long done, long total)
{
	stopper *st = ctx;
	if (st->done_then == 0 && done > 0 && done < total) {
		st->done_then = done;
		st->total = total;
		atomic_store(st->cancel, true);
	}
}

/* Passes 0..4 and 4..samples into fb: the second with `cancel` and `progress`. */
static render_status two_passes(const world *w, const render_settings *set, framebuffer *fb, int samples,
                                atomic_bool *cancel, stopper *st)
{
	rt_error err;
	render_job a = {.w = w, .set = *set, .fb = fb, .sample_begin = 0, .sample_end = 4};
	a.set.samples = samples;
	assert_int_equal(render_run(&a, &err), RENDER_DONE);
	render_job b = a;
	b.sample_begin = 4;
	b.sample_end = samples;
	b.cancel = cancel;
	b.progress = st ? stop_in_flight : NULL;
	b.progress_ctx = st;
	return render_run(&b, &err);
}

static void test_render_stops_in_flight(void **state)
{
	(void)state;
	scene *s;
	world *w = generated_world(60, 11, &s);
	render_settings set = render_settings_default();
	set.width = 160;
	set.height = 120; /* 80 tiles */
	set.mode = MODE_PATH;
	set.threads = 2;
	/* The second pass must outlast the first progress report (about
	 * 100 ms): longer and longer until it is stopped in flight. */
	int samples = 8;
	framebuffer *fb = fb_new(set.width, set.height), *ref = fb_new(set.width, set.height);
	assert_non_null(fb);
	assert_non_null(ref);
	atomic_bool cancel;
	stopper st;
	render_status got = RENDER_DONE;
	for (; samples <= 4096; samples *= 2) {
		atomic_init(&cancel, false);
		st = (stopper){&cancel, 0, 0};
		got = two_passes(w, &set, fb, samples, &cancel, &st);
		if (got != RENDER_DONE)
			break;
	}
	assert_int_equal(got, RENDER_CANCELLED);
	assert_true(st.done_then > 0 && st.done_then < st.total);
	print_message("stopped at %ld of %ld tiles of the pass 4..%d\n", st.done_then, st.total, samples);
	/* the cancelled pass mixed two passes' sums: the next starts over */
	assert_int_equal(fb->spp, 0);
	/* rendering again, without the flag, after the stop */
	atomic_store(&cancel, false);
	assert_int_equal(two_passes(w, &set, fb, samples, &cancel, NULL), RENDER_DONE);
	/* a render never stopped, into a framebuffer of its own */
	assert_int_equal(two_passes(w, &set, ref, samples, NULL, NULL), RENDER_DONE);
	assert_int_equal(fb->spp, samples);
	assert_int_equal(ref->spp, samples);
	size_t n = (size_t)set.width * set.height * 3;
	assert_memory_equal(fb->rgb, ref->rgb, n * sizeof *fb->rgb);
	assert_memory_equal(fb->sum, ref->sum, n * sizeof *fb->sum);
	/* and the picture is a picture: not all black */
	double total = 0;
	for (size_t i = 0; i < n; i++)
		total += ref->rgb[i];
	assert_true(total > 0);
	fb_free(fb);
	fb_free(ref);
	world_release(w);
	scene_free(s);
}

/* A tile of many samples (set samples 100000 in the shell: seconds of
 * work a tile) stops when the flag is set, not when the tile is done: a
 * one-tile image of 16x16 pixels at 100000 samples (25.6 million, many
 * seconds), the flag set 50 ms in from another thread. The old renderer
 * looked at the flag between tiles only: it finished the tile and said
 * RENDER_DONE. Rendering again after the stop gives the bytes of a render
 * never stopped (at fewer samples, not to wait). */
static void test_render_stops_within_a_tile(void **state)
{
	(void)state;
	rt_error err;
	scene *s;
	world *w = generated_world(5, 3, &s);
	render_settings set = render_settings_default();
	set.width = set.height = RENDER_TILE; /* one tile */
	set.threads = 1;
	framebuffer *fb = fb_new(set.width, set.height), *ref = fb_new(set.width, set.height);
	assert_non_null(fb);
	assert_non_null(ref);
	for (int mode = 0; mode < 2; mode++) {
		set.mode = mode ? MODE_PATH : MODE_WHITTED;
		set.samples = 100000;
		atomic_bool cancel;
		atomic_init(&cancel, false);
		later l = {&cancel, 50};
		pthread_t th;
		assert_int_equal(pthread_create(&th, NULL, set_later, &l), 0);
		render_job job = {.w = w, .set = set, .fb = fb, .sample_begin = 0, .sample_end = set.samples,
		                  .cancel = &cancel};
		render_status got = render_run(&job, &err);
		pthread_join(th, NULL);
		assert_int_equal(got, RENDER_CANCELLED);
		assert_int_equal(fb->spp, 0);
		/* again without the flag, and a render never stopped */
		atomic_store(&cancel, false);
		set.samples = 64;
		job.set = set;
		job.sample_end = set.samples;
		assert_int_equal(render_run(&job, &err), RENDER_DONE);
		render_job fresh = {.w = w, .set = set, .fb = ref, .sample_begin = 0, .sample_end = set.samples};
		assert_int_equal(render_run(&fresh, &err), RENDER_DONE);
		size_t n = (size_t)set.width * set.height * 3;
		assert_memory_equal(fb->rgb, ref->rgb, n * sizeof *fb->rgb);
		assert_memory_equal(fb->sum, ref->sum, n * sizeof *fb->sum);
	}
	fb_free(fb);
	fb_free(ref);
	world_release(w);
	scene_free(s);
}

/* The first progress report comes before any tile is done (done 0 of
 * all), so that a render of many samples says it is rendering at once; the
 * old renderer's first came after the calling thread's first tile. */
typedef struct first_report {
	long calls, first_done, first_total;
} first_report;

static void record_first(void *ctx, long done, long total)
{
	first_report *f = ctx;
	if (f->calls++ == 0) {
		f->first_done = done;
		f->first_total = total;
	}
}

static void test_progress_reported_at_once(void **state)
{
	(void)state;
	rt_error err;
	scene *s;
	world *w = generated_world(5, 3, &s);
	render_settings set = render_settings_default();
	set.width = 4 * RENDER_TILE;
	set.height = 2 * RENDER_TILE; /* 8 tiles */
	set.samples = 2;
	for (int threads = 1; threads <= 2; threads++) {
		set.threads = threads;
		framebuffer *fb = fb_new(set.width, set.height);
		assert_non_null(fb);
		first_report f = {0, -1, -1};
		render_job job = {.w = w, .set = set, .fb = fb, .sample_begin = 0, .sample_end = set.samples,
		                  .progress = record_first, .progress_ctx = &f};
		assert_int_equal(render_run(&job, &err), RENDER_DONE);
		assert_true(f.calls >= 2); /* the first, and the last (8 of 8) */
		assert_int_equal(f.first_done, 0);
		assert_int_equal(f.first_total, 8);
		fb_free(fb);
	}
	world_release(w);
	scene_free(s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_load_stops),
	    cmocka_unit_test(test_generate_stops),
	    cmocka_unit_test(test_world_build_stops),
	    cmocka_unit_test(test_readers_stop),
	    cmocka_unit_test(test_render_stops_in_flight),
	    cmocka_unit_test(test_render_stops_within_a_tile),
	    cmocka_unit_test(test_progress_reported_at_once),
	};
	return cmocka_run_group_tests(tests, setup, teardown);
}
