/* rtsh — tests of the renderer: a Phong value computed by hand, shadows,
 * reflections, the sRGB transfer, thread-count invariance, progressive
 * passes, rectangles (rtsh-mpi's tiles), cancelling, image files, and an end-to-end render through the rtsh
 * binary checked against the projection formula. */
#include "testutil.h"

#include <dirent.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "rtsh/image.h"
#include "rtsh/render.h"
#include "rtsh/rtfile.h"
#include "rtsh/scene.h"
#include "rtsh/world.h"
#include "core/integrators.h"

/* The sRGB decoding of an 8-bit code, from IEC 61966-2-1. */
static double srgb_decode(double code)
{
	double c = code / 255.0;
	return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

static scene *base_scene(vec3 cam_pos, vec3 cam_dir, double fov)
{
	scene *s = scene_new();
	camera c = {cam_pos, cam_dir, fov, false, 0, 0};
	assert_true(scene_add_camera(s, &c, NULL));
	return s;
}

static void add_light(scene *s, vec3 pos, double ratio)
{
	light l = {.pos = pos, .ratio = ratio, .color = v3(255, 255, 255)};
	assert_true(scene_add_light(s, &l, NULL));
}

static object sphere(vec3 c, double diameter, vec3 color)
{
	object o = object_make(OBJ_SPHERE, color);
	o.pos = c;
	o.scale = v3_splat(diameter);
	return o;
}

/* Renders s at w x h with the given settings; returns the framebuffer. */
static framebuffer *render(const scene *s, int w, int h, int samples, int depth, int threads,
                           render_mode mode)
{
	world *wd = world_build(s, NULL);
	assert_non_null(wd);
	render_settings set = render_settings_default();
	set.width = w;
	set.height = h;
	set.samples = samples;
	set.depth = depth;
	set.threads = threads;
	set.mode = mode;
	framebuffer *fb = render_image(wd, &set, NULL, NULL, NULL, NULL);
	assert_non_null(fb);
	world_free(wd);
	return fb;
}

static vec3 pixel(const framebuffer *fb, int x, int y)
{
	const float *p = fb->rgb + ((size_t)y * fb->w + x) * 3;
	return v3(p[0], p[1], p[2]);
}

/* The centre pixel of a 101x101 image looks straight down the camera axis
 * ((50 + 0.5) * 2 / 101 - 1 = 0). Camera at z = -5, a sphere of radius 1 at
 * the origin: the hit is (0,0,-1) with normal (0,0,-1), view v = (0,0,-1).
 * Light at (3,0,-5): to the light L = (3,0,-4)/5, N.L = 0.8. The mirror of
 * -L about N is R = (-0.6, 0, -0.8), so R.V = 0.8. Colour 128 grey decodes
 * to a = srgb(128); ambient 0.1 white; diffuse 0.9, specular 0.5,
 * shininess 10; light ratio 0.7 white:
 *   0.1 a + 0.7 * 0.9 * 0.8 a + 0.7 * 0.5 * 0.8^10 */
static void test_phong_by_hand(void **state)
{
	(void)state;
	scene *s = base_scene(v3(0, 0, -5), v3(0, 0, 1), 60);
	s->has_ambient = true;
	s->amb = (ambient){0.1, v3(255, 255, 255)};
	add_light(s, v3(3, 0, -5), 0.7);
	object o = sphere(v3(0, 0, 0), 2, v3(128, 128, 128));
	o.mat.diffuse = 0.9;
	o.mat.specular = 0.5;
	o.mat.shininess = 10;
	assert_true(scene_add_object(s, &o, NULL));
	framebuffer *fb = render(s, 101, 101, 1, 0, 1, MODE_WHITTED);
	double a = srgb_decode(128);
	double expect = 0.1 * a + 0.7 * 0.9 * 0.8 * a + 0.7 * 0.5 * pow(0.8, 10);
	vec3 c = pixel(fb, 50, 50);
	assert_near(c.x, expect, 1e-6);
	assert_near(c.y, expect, 1e-6);
	assert_near(c.z, expect, 1e-6);
	/* the corner pixel sees nothing: black background in whitted mode */
	assert_vec_near(pixel(fb, 0, 0), v3(0, 0, 0), 0);
	fb_free(fb);
	scene_free(s);
}

/* A plane y = 0 lit from straight above by a light at (0,10,0); a sphere of
 * radius 0.5 at (0,2,0) shadows the origin. The camera at (0,1,-5) looks at
 * the origin, passing far below the blocker. Lit: ambient + diffuse (N.L = 1)
 * + specular 0.9 * (R.V)^200 with R = (0,1,0), V = (0,1,-5)/sqrt 26;
 * shadowed: ambient only. */
static void test_shadow(void **state)
{
	(void)state;
	for (int blocked = 0; blocked < 2; blocked++) {
		scene *s = base_scene(v3(0, 1, -5), v3(0, -1, 5), 40);
		s->has_ambient = true;
		s->amb = (ambient){0.2, v3(255, 255, 255)};
		add_light(s, v3(0, 10, 0), 1.0);
		object p = object_make(OBJ_PLANE, v3(255, 255, 255));
		assert_true(scene_add_object(s, &p, NULL));
		if (blocked) {
			object b = sphere(v3(0, 2, 0), 1, v3(255, 0, 0));
			assert_true(scene_add_object(s, &b, NULL));
		}
		framebuffer *fb = render(s, 101, 101, 1, 0, 2, MODE_WHITTED);
		double lit = 0.2 + 0.9 + 0.9 * pow(1 / sqrt(26.0), 200);
		assert_near(pixel(fb, 50, 50).x, blocked ? 0.2 : lit, 1e-6);
		fb_free(fb);
		scene_free(s);
	}
}

/* A mirror sphere facing the camera reflects an emitter behind the camera.
 * Mirror: diffuse 0, specular 0, reflective k; emitter: emit 1 white, so its
 * radiance is 1. Whitted blends local (0 here) and reflected by k; depth 0
 * turns reflections off. */
static void test_reflection(void **state)
{
	(void)state;
	const double ks[] = {1.0, 0.5, 0.25};
	for (int depth = 0; depth <= 1; depth++)
		for (size_t i = 0; i < 3; i++) {
			scene *s = base_scene(v3(0, 0, -5), v3(0, 0, 1), 60);
			object m = sphere(v3(0, 0, 0), 2, v3(255, 255, 255));
			m.mat.diffuse = 0;
			m.mat.specular = 0;
			m.mat.reflective = ks[i];
			object e = sphere(v3(0, 0, -30), 10, v3(255, 255, 255));
			e.mat.emission = 1;
			e.mat.diffuse = 0;
			e.mat.specular = 0;
			assert_true(scene_add_object(s, &m, NULL));
			assert_true(scene_add_object(s, &e, NULL));
			framebuffer *fb = render(s, 101, 101, 1, depth, 1, MODE_WHITTED);
			assert_near(pixel(fb, 50, 50).x, depth ? ks[i] : 0.0, 1e-9);
			fb_free(fb);
			scene_free(s);
		}
}

/* The rays (world_rays_traced: camera, mirror, glass and shadow rays) that
 * Whitted traces for the one camera ray r of s at depth. */
static uint64_t whitted_rays(const scene *s, ray r, int depth)
{
	world *w = world_build(s, NULL);
	assert_non_null(w);
	render_settings set = render_settings_default();
	set.depth = depth;
	set.mode = MODE_WHITTED;
	world_rays_reset();
	vec3 c = whitted_radiance(w, &set, r);
	uint64_t n = world_rays_traced();
	assert_true(c.x == 0.0 && c.y == 0.0 && c.z == 0.0); /* no light, no ambient */
	world_free(w);
	return n;
}

static object mirror_object(obj_kind k, vec3 pos, vec3 dir, double diameter, double reflective)
{
	object o = object_make(k, v3(255, 255, 255));
	o.pos = pos;
	o.dir = dir;
	o.scale = v3_splat(diameter);
	o.mat.diffuse = 0;
	o.mat.specular = 0;
	o.mat.reflective = reflective;
	return o;
}

/* Adaptive tree depth control (whitted.c): between two parallel mirrors of
 * reflective 0.5 a ray shot along their normal bounces back and forth, the
 * k-th mirror ray carrying weight 0.5^k to the camera. Rays of weight below
 * 2^-24 are not traced, so mirror rays k = 1..24 are: 25 rays with the
 * camera's, whatever the depth beyond 24 (the old code traced 1 + depth). No
 * light: no shadow rays. */
static void test_whitted_weight_cutoff(void **state)
{
	(void)state;
	scene *s = base_scene(v3(0, 0, -5), v3(0, 0, 1), 60);
	object a = mirror_object(OBJ_PLANE, v3(0, 0, 1), v3(0, 0, -1), 1, 0.5);
	object b = mirror_object(OBJ_PLANE, v3(0, 0, -1), v3(0, 0, 1), 1, 0.5);
	assert_true(scene_add_object(s, &a, NULL));
	assert_true(scene_add_object(s, &b, NULL));
	ray r = {v3(0, 0, 0), v3(0, 0, 1)};
	assert_int_equal(whitted_rays(s, r, 10), 11);
	assert_int_equal(whitted_rays(s, r, 24), 25);
	assert_int_equal(whitted_rays(s, r, 100), 25);
	assert_int_equal(whitted_rays(s, r, 1000), 25);
	scene_free(s);
}

/* The hard bound (whitted.c, WHITTED_MAX_RAYS 4096): a camera ray at the
 * centre of a glass sphere (diameter 2) inside a mirror sphere (diameter 4,
 * reflective 1) along a diameter. Every ray hits a surface head-on: glass
 * sends a mirror and a refracted ray, each of weight 1/2 (an ior of
 * (1 + sqrt .5) / (1 - sqrt .5) makes Schlick's r0 = 1/2), the mirror one
 * ray of weight 1; none escapes. A ray arriving at the glass with depth d
 * left traces G(d) rays with its own, one arriving at the mirror M(d):
 * G(0) = M(0) = 1, G(d) = 1 + G(d-1) + M(d-1) (inside: back to the glass;
 * outside: on to the mirror), M(d) = 1 + G(d-1); so G(d) = Fib(d+4) - 2:
 * 2582 at depth 14, 4179 at 15, 46366 at 20. Up to depth 20 no ray's weight
 * (at least 2^-20, roughly) is below 2^-24, so the weight rule cuts
 * nothing: the counts are G(d) up to 1 + 4096, then 1 + 4096. */
static void test_whitted_ray_bound(void **state)
{
	(void)state;
	scene *s = base_scene(v3(0, 0, -5), v3(0, 0, 1), 60);
	object g = mirror_object(OBJ_SPHERE, v3(0, 0, 0), v3(0, 1, 0), 2, 0);
	g.mat.ior = (1 + sqrt(0.5)) / (1 - sqrt(0.5));
	object m = mirror_object(OBJ_SPHERE, v3(0, 0, 0), v3(0, 1, 0), 4, 1);
	assert_true(scene_add_object(s, &g, NULL));
	assert_true(scene_add_object(s, &m, NULL));
	ray r = {v3(0, 0, 0), v3(1, 0, 0)};
	assert_int_equal(whitted_rays(s, r, 1), 3);
	assert_int_equal(whitted_rays(s, r, 2), 6);
	assert_int_equal(whitted_rays(s, r, 14), 2582);
	assert_int_equal(whitted_rays(s, r, 15), 1 + 4096);
	assert_int_equal(whitted_rays(s, r, 20), 1 + 4096);
	assert_int_equal(whitted_rays(s, r, 1000), 1 + 4096);
	scene_free(s);
}

/* A scene with every kind of shape, for the invariance tests. */
static scene *busy_scene(void)
{
	scene *s = base_scene(v3(0, 2, -8), v3(0, -0.2, 1), 70);
	s->has_ambient = true;
	s->amb = (ambient){0.2, v3(200, 220, 255)};
	add_light(s, v3(-4, 6, -5), 0.8);
	add_light(s, v3(4, 3, -3), 0.4);
	test_rng r = {11};
	for (int k = 0; k < OBJ_KIND_COUNT * 3; k++) {
		if (obj_kind_flags((obj_kind)(k % OBJ_KIND_COUNT)) & KIND_MODEL)
			continue; /* a model needs a file (test_mesh) */
		object o = object_make((obj_kind)(k % OBJ_KIND_COUNT),
		                       v3(trange(&r, 0, 255), trange(&r, 0, 255), trange(&r, 0, 255)));
		o.pos = v3(trange(&r, -4, 4), trange(&r, 0, 3), trange(&r, -2, 4));
		o.dir = tdir(&r);
		o.scale = v3(trange(&r, 0.5, 2), trange(&r, 0.5, 2), trange(&r, 0.5, 2));
		o.mat.reflective = trange(&r, 0, 0.6);
		if (o.kind == OBJ_TRIANGLE)
			for (int i = 0; i < 3; i++)
				o.tri[i] = v3_add(o.pos, v3(trange(&r, -1, 1), trange(&r, -1, 1), trange(&r, -1, 1)));
		if (o.kind == OBJ_PLANE) {
			o.pos = v3(0, -0.5, 0);
			o.dir = v3(0, 1, 0.1);
		}
		assert_true(scene_add_object(s, &o, NULL));
	}
	return s;
}

static void test_threads_identical(void **state)
{
	(void)state;
	scene *s = busy_scene();
	for (int mode = MODE_WHITTED; mode <= MODE_PATH; mode++) {
		framebuffer *one = render(s, 67, 45, 3, 4, 1, (render_mode)mode);
		const int counts[] = {2, 7};
		for (int i = 0; i < 2; i++) {
			framebuffer *fb = render(s, 67, 45, 3, 4, counts[i], (render_mode)mode);
			assert_memory_equal(one->rgb, fb->rgb, sizeof(float) * 67 * 45 * 3);
			fb_free(fb);
		}
		fb_free(one);
	}
	scene_free(s);
}

/* Four passes of one sample each give exactly the image of one pass of four. */
static void test_progressive_equals_batch(void **state)
{
	(void)state;
	scene *s = busy_scene();
	world *w = world_build(s, NULL);
	render_settings set = render_settings_default();
	set.width = 40;
	set.height = 30;
	set.samples = 4;
	set.threads = 2;
	set.mode = MODE_PATH;
	framebuffer *batch = render_image(w, &set, NULL, NULL, NULL, NULL);
	framebuffer *prog = fb_new(40, 30);
	for (int k = 0; k < 4; k++) {
		render_job job = {.w = w, .set = set, .fb = prog, .sample_begin = k, .sample_end = k + 1};
		assert_int_equal(render_run(&job, NULL), RENDER_DONE);
	}
	assert_int_equal(prog->spp, 4);
	assert_memory_equal(batch->rgb, prog->rgb, sizeof(float) * 40 * 30 * 3);
	/* a first pass ignores whatever the sums hold (a cancelled pass leaves
	 * them half done): garbage in the sums, then passes from 0 */
	for (int i = 0; i < 40 * 30 * 3; i++)
		prog->sum[i] = 1e6 + i;
	prog->spp = 0;
	for (int k = 0; k < 4; k += 2) {
		render_job job = {.w = w, .set = set, .fb = prog, .sample_begin = k, .sample_end = k + 2};
		assert_int_equal(render_run(&job, NULL), RENDER_DONE);
	}
	assert_memory_equal(batch->rgb, prog->rgb, sizeof(float) * 40 * 30 * 3);
	/* a pass that does not follow the samples done is refused */
	render_job bad = {.w = w, .set = set, .fb = prog, .sample_begin = 2, .sample_end = 3};
	rt_error err;
	assert_int_equal(render_run(&bad, &err), RENDER_FAILED);
	fb_free(batch);
	fb_free(prog);
	world_free(w);
	scene_free(s);
}

/* render_rect gives any rectangle of the image (rtsh-mpi's tiles) bit for
 * bit as the whole image holds it, in both modes, edges included. */
static void test_rect_equals_image(void **state)
{
	(void)state;
	/* the busy scene, then textures (their footprints) and an HDR sky */
	static const char textured[] = "C 0,1,-6 0,0,1 60\nL 2,5,-4 0.7 255,255,255\n"
	                               "sky textures/sky.hdr 1 20\n"
	                               "sp -1,1,0 2.5 255,255,255 texture=textures/earth.png\n"
	                               "pl 0,0,0 0,1,0 200,200,200 texture=textures/earth.png\n";
	for (int which = 0; which < 2; which++) {
		rt_error err = {0};
		scene *s = which == 0 ? busy_scene()
		                      : rt_load_string(textured, sizeof textured - 1, "scenes/t.rt", NULL, &err);
		if (!s)
			fail_msg("%s", err.msg);
		world *w = world_build(s, NULL);
		for (int mode = MODE_WHITTED; mode <= MODE_PATH; mode++) {
			render_settings set = render_settings_default();
			set.width = 53;
			set.height = 37;
			set.samples = 3;
			set.threads = 2;
			set.mode = (render_mode)mode;
			framebuffer *fb = render_image(w, &set, NULL, NULL, NULL, NULL);
			const int rects[][4] = {{0, 0, 53, 37}, {0, 0, 1, 1}, {17, 5, 40, 22}, {48, 30, 53, 37}};
			for (size_t r = 0; r < sizeof rects / sizeof rects[0]; r++) {
				const int *q = rects[r];
				int rw = q[2] - q[0], rh = q[3] - q[1];
				float *out = malloc(sizeof(float) * 3 * (size_t)(rw * rh));
				render_rect(w, &set, q[0], q[1], q[2], q[3], out);
				for (int y = 0; y < rh; y++)
					assert_memory_equal(out + (size_t)y * rw * 3,
					                    fb->rgb + ((size_t)(q[1] + y) * 53 + q[0]) * 3,
					                    sizeof(float) * 3 * (size_t)rw);
				free(out);
			}
			fb_free(fb);
		}
		world_free(w);
		scene_free(s);
	}
}

static void test_cancel(void **state)
{
	(void)state;
	scene *s = busy_scene();
	world *w = world_build(s, NULL);
	render_settings set = render_settings_default();
	set.width = 64;
	set.height = 64;
	set.threads = 2;
	atomic_bool cancel;
	atomic_init(&cancel, true);
	rt_error err;
	assert_null(render_image(w, &set, &cancel, NULL, NULL, &err));
	assert_non_null(strstr(err.msg, "stopped"));
	world_free(w);
	scene_free(s);
}

static void test_srgb(void **state)
{
	(void)state;
	/* every code decodes and re-encodes to itself */
	for (int c = 0; c < 256; c++) {
		assert_near(srgb8_to_linear(c), srgb_decode(c), 1e-15);
		assert_int_equal(linear_to_srgb8(srgb_decode(c)), c);
	}
	/* linear 0.5 is code 188 (0.7354 * 255 = 187.5...) and clamping */
	assert_int_equal(linear_to_srgb8(0.5), 188);
	assert_int_equal(linear_to_srgb8(-1), 0);
	assert_int_equal(linear_to_srgb8(7), 255);
	assert_int_equal(linear_to_srgb8(NAN), 0);
	/* for any value, the code is the encoding rounded to nearest (values
	 * within 1e-9 of a rounding boundary may go either way) */
	test_rng r = {3};
	for (int i = 0; i < 200000; i++) {
		double v = i < 100000 ? trand(&r) : trand(&r) * 0.01;
		double e = (v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1 / 2.4) - 0.055) * 255 + 0.5;
		if (fabs(e - floor(e + 0.5)) < 1e-9)
			continue;
		assert_int_equal(linear_to_srgb8(v), (int)floor(e));
	}
	/* the world decodes .rt colours the same way */
	vec3 l = srgb255_to_linear(v3(0, 128, 255));
	assert_near(l.x, 0, 0);
	assert_near(l.y, srgb_decode(128), 1e-15);
	assert_near(l.z, 1, 1e-15);
}

/* render_image_srgb8: the codes its threads write as tiles finish are the
 * sRGB encoding (linear_to_srgb8) of each float of rgb times 2^exposure,
 * for any thread count, and a PPM written from it holds those codes. */
static void test_srgb8_in_tiles(void **state)
{
	(void)state;
	scene *s = base_scene(v3(0, 0, -5), v3(0, 0, 1), 60);
	add_light(s, v3(3, 2, -5), 0.7);
	object o = sphere(v3(0, 0, 0), 2.0, v3(200, 120, 40));
	assert_true(scene_add_object(s, &o, NULL));
	world *wd = world_build(s, NULL);
	assert_non_null(wd);
	render_settings set = render_settings_default();
	set.width = 37; /* not a multiple of the tile */
	set.height = 21;
	set.exposure = 0.5;
	char dir[] = "/tmp/rtsh-test-XXXXXX";
	assert_non_null(mkdtemp(dir));
	char path[256];
	snprintf(path, sizeof path, "%s/a.ppm", dir);
	for (int threads = 1; threads <= 2; threads++) {
		set.threads = threads;
		framebuffer *fb = render_image_srgb8(wd, &set, NULL, NULL, NULL, NULL);
		assert_non_null(fb);
		assert_non_null(fb->srgb8);
		double gain = pow(2.0, 0.5);
		for (int i = 0; i < 37 * 21 * 3; i++)
			assert_int_equal(fb->srgb8[i], linear_to_srgb8(fb->rgb[i] * gain));
		assert_true(image_write(path, fb, 0.5, NULL));
		FILE *f = fopen(path, "rb");
		assert_non_null(f);
		unsigned char buf[64 + 37 * 21 * 3];
		size_t n = fread(buf, 1, sizeof buf, f);
		fclose(f);
		size_t head = strlen("P6\n37 21\n255\n");
		assert_int_equal(n, head + 37 * 21 * 3);
		assert_memory_equal(buf + head, fb->srgb8, 37 * 21 * 3);
		/* another exposure: the file is encoded from rgb, not from these codes */
		assert_true(image_write(path, fb, 0.0, NULL));
		framebuffer *back = image_read_ppm(path, NULL);
		assert_non_null(back);
		for (int i = 0; i < 37 * 21 * 3; i++)
			assert_near(back->rgb[i], srgb_decode(linear_to_srgb8(fb->rgb[i])), 1e-6);
		fb_free(back);
		fb_free(fb);
	}
	unlink(path);
	rmdir(dir);
	world_free(wd);
	scene_free(s);
}

static void test_image_files(void **state)
{
	(void)state;
	framebuffer *fb = fb_new(5, 3);
	for (int i = 0; i < 5 * 3 * 3; i++)
		fb->rgb[i] = (float)(i * 0.03125);
	char dir[] = "/tmp/rtsh-test-XXXXXX";
	assert_non_null(mkdtemp(dir));
	char path[256];
	snprintf(path, sizeof path, "%s/a.pfm", dir);
	assert_true(image_write(path, fb, 0.0, NULL));
	framebuffer *back = image_read_pfm(path, NULL);
	assert_non_null(back);
	assert_memory_equal(back->rgb, fb->rgb, sizeof(float) * 45); /* exact, row order kept */
	fb_free(back);
	/* a PFM keeps the linear radiance whatever the exposure */
	assert_true(image_write(path, fb, 1.0, NULL));
	back = image_read_pfm(path, NULL);
	assert_memory_equal(back->rgb, fb->rgb, sizeof(float) * 45);
	fb_free(back);
	/* PPM: codes are the sRGB encoding */
	snprintf(path, sizeof path, "%s/a.ppm", dir);
	assert_true(image_write(path, fb, 0.0, NULL));
	back = image_read_ppm(path, NULL);
	assert_non_null(back);
	for (int i = 0; i < 45; i++)
		assert_near(back->rgb[i], srgb_decode(linear_to_srgb8(fb->rgb[i])), 1e-6);
	fb_free(back);
	/* exposure +1 doubles the radiance before the 8-bit encoding */
	assert_true(image_write(path, fb, 1.0, NULL));
	back = image_read_ppm(path, NULL);
	for (int i = 0; i < 45; i++)
		assert_near(back->rgb[i], srgb_decode(linear_to_srgb8(2 * fb->rgb[i])), 1e-6);
	fb_free(back);
	/* PNG: the signature is there */
	snprintf(path, sizeof path, "%s/a.png", dir);
	assert_true(image_write(path, fb, 0.0, NULL));
	FILE *f = fopen(path, "rb");
	unsigned char sig[8];
	assert_int_equal(fread(sig, 1, 8, f), 8);
	fclose(f);
	assert_memory_equal(sig, "\x89PNG\r\n\x1a\n", 8);
	/* an unknown type is refused and leaves the old file alone */
	rt_error err;
	snprintf(path, sizeof path, "%s/a.bmp", dir);
	assert_false(image_write(path, fb, 0.0, &err));
	assert_non_null(strstr(err.msg, "expected .ppm"));
	/* a failed write (folder not writable) keeps the old file */
	snprintf(path, sizeof path, "%s/a.ppm", dir);
	struct stat before, after;
	assert_int_equal(stat(path, &before), 0);
	if (geteuid() != 0) { /* root may write anywhere */
		chmod(dir, 0500);
		assert_false(image_write(path, fb, 0.0, &err));
		chmod(dir, 0700);
		assert_int_equal(stat(path, &after), 0);
		assert_int_equal(before.st_size, after.st_size);
	}
	/* no temporary file is left behind */
	char cmd[512];
	snprintf(cmd, sizeof cmd, "ls -a %s | grep -c tmp > /dev/null", dir);
	assert_int_not_equal(system(cmd), 0);
	snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
	assert_int_equal(system(cmd), 0);
	fb_free(fb);
}

/* End to end: scenes/basic.rt through the rtsh binary. The sphere of radius
 * 0.5 seen from 5 units away subtends a half-angle asin(0.5/5); on the image
 * plane at distance 1 its outline is a circle of radius tan(asin(0.1)),
 * which is tan(asin 0.1) / tan(35 deg) * W/2 pixels for the 70 degree
 * horizontal FOV. Every other pixel is black (no sky). */
static void test_basic_silhouette(void **state)
{
	(void)state;
	char out[] = "/tmp/rtsh-basic-XXXXXX.pfm";
	int fd = mkstemps(out, 4);
	assert_true(fd >= 0);
	close(fd);
	char cmd[512];
	snprintf(cmd, sizeof cmd, "%s scenes/basic.rt -o %s -r 240x240 -s 1 -q", test_rtsh_bin(), out);
	assert_int_equal(system(cmd), 0);
	framebuffer *fb = image_read_pfm(out, NULL);
	unlink(out);
	assert_non_null(fb);
	assert_int_equal(fb->w, 240);
	double r_px = tan(asin(0.1)) / tan(deg_to_rad(35)) * 120;
	int lit = 0, row = 0;
	for (int y = 0; y < 240; y++)
		for (int x = 0; x < 240; x++) {
			vec3 c = pixel(fb, x, y);
			if (c.x > 0) {
				lit++;
				row += y == 120;
				/* red: only the specular highlight adds green and blue */
				assert_true(c.x >= c.y);
			}
		}
	/* pixel centres inside the circle: the area within 1% */
	assert_near(lit, RT_PI * r_px * r_px, 0.01 * RT_PI * r_px * r_px);
	assert_near(row, 2 * r_px, 2);
	/* the light at (2,0,-10) puts the highlight right of centre */
	int bright_x = 0;
	double best = -1;
	for (int x = 0; x < 240; x++)
		if (pixel(fb, x, 120).y > best) {
			best = pixel(fb, x, 120).y;
			bright_x = x;
		}
	assert_true(bright_x > 120);
	fb_free(fb);
}

/* --- rows handed over as the render finishes them (render_image_rows) --- */

static world *rows_world(void)
{
	scene *s = base_scene(v3(0, 0, -5), v3(0, 0, 1), 60);
	add_light(s, v3(3, 2, -5), 0.7);
	object o = sphere(v3(0, 0, 0), 2.0, v3(200, 120, 40));
	assert_true(scene_add_object(s, &o, NULL));
	world *wd = world_build(s, NULL);
	assert_non_null(wd);
	scene_free(s);
	return wd;
}

typedef struct rows_seen {
	const uint8_t *expect; /* the codes by their definition */
	int next;              /* the row the next call must start at */
	int calls, stop_at;    /* stop_at: the call that returns false (0: none) */
	int slow;              /* the first `slow` calls take 2 ms: the other threads run ahead */
	const uint8_t *lo, *hi; /* the lowest and highest byte of codes handed over */
	atomic_bool *cancel;    /* set at the first call (NULL: none) */
} rows_seen;

static bool rows_check(void *ctx, const framebuffer *fb, int y0, int y1, const uint8_t *codes)
{
	rows_seen *r = ctx;
	r->calls++;
	assert_int_equal(y0, r->next); /* in order, each row once */
	assert_true(y1 > y0 && y1 <= fb->h);
	r->next = y1;
	/* final when handed over */
	size_t row = (size_t)fb->w * 3, n = (size_t)(y1 - y0) * row;
	assert_memory_equal(codes, r->expect + (size_t)y0 * row, n);
	if (!r->lo || codes < r->lo)
		r->lo = codes;
	if (!r->hi || codes + n > r->hi)
		r->hi = codes + n;
	if (r->cancel)
		atomic_store(r->cancel, true);
	if (r->calls <= r->slow)
		nanosleep(&(struct timespec){0, 2000000}, NULL);
	return r->calls != r->stop_at;
}

/* The handover that fails (call stop_at, the first `slow` calls slow) stops
 * the render: no image, no call after it, the message. */
static void handover_stops(const world *wd, const render_settings *set, const uint8_t *expect, int stop_at, int slow)
{
	rows_seen stop = {expect, 0, 0, stop_at, slow, NULL, NULL, NULL};
	rt_error err = {0};
	assert_null(render_image_rows(wd, set, NULL, NULL, NULL, rows_check, &stop, &err));
	assert_int_equal(stop.calls, stop_at);
	assert_non_null(strstr(err.msg, "writing the image stopped the render"));
}

/* Every row once, in order, its codes final when handed over and those of
 * linear_to_srgb8 on render_image's floats x 2^exposure; no float image
 * kept; with 1, 2 and 3 threads. A callback that fails stops the render. */
static void test_rows_while_rendering(void **state)
{
	(void)state;
	world *wd = rows_world();
	render_settings set = render_settings_default();
	set.width = 37; /* not a multiple of the tile either way: 4 bands, the last of 5 rows */
	set.height = 53;
	set.exposure = 0.5;
	size_t n = 37 * 53 * 3;
	framebuffer *ref = render_image(wd, &set, NULL, NULL, NULL, NULL);
	assert_non_null(ref);
	uint8_t *expect = malloc(n);
	assert_non_null(expect);
	double gain = pow(2.0, 0.5);
	for (size_t i = 0; i < n; i++)
		expect[i] = linear_to_srgb8(ref->rgb[i] * gain);
	for (int threads = 1; threads <= 3; threads++) {
		set.threads = threads;
		rows_seen r = {expect, 0, 0, 0, 0, NULL, NULL, NULL};
		framebuffer *fb = render_image_rows(wd, &set, NULL, NULL, NULL, rows_check, &r, NULL);
		assert_non_null(fb);
		assert_int_equal(r.next, 53);
		assert_true(r.calls >= 1 && r.calls <= 4);
		assert_null(fb->rgb);
		fb_free(fb);
		handover_stops(wd, &set, expect, 1, 0); /* a failed handover stops the render */
	}
	free(expect);
	fb_free(ref);
	world_free(wd);
}

/* A tall picture's codes pass through a ring of a few bands, not the whole
 * image's (framebuffer.srgb8_ring): the codes handed over lie within
 * threads + 6 bands of 16 rows; while the first handovers are slow the
 * other threads wait for their slots instead of writing over rows not yet
 * handed over: every row's codes are still linear_to_srgb8 of
 * render_image's floats, in order; with 1, 2 and 3 threads. */
static void test_rows_ring(void **state)
{
	(void)state;
	world *wd = rows_world();
	render_settings set = render_settings_default();
	set.width = 37;
	set.height = 16 * 30 + 5; /* 31 bands, the last of 5 rows */
	size_t row = 37 * 3, n = row * (size_t)set.height;
	framebuffer *ref = render_image(wd, &set, NULL, NULL, NULL, NULL);
	assert_non_null(ref);
	uint8_t *expect = malloc(n);
	assert_non_null(expect);
	for (size_t i = 0; i < n; i++)
		expect[i] = linear_to_srgb8(ref->rgb[i]);
	for (int threads = 1; threads <= 3; threads++) {
		set.threads = threads;
		rows_seen r = {expect, 0, 0, 0, 8, NULL, NULL, NULL};
		framebuffer *fb = render_image_rows(wd, &set, NULL, NULL, NULL, rows_check, &r, NULL);
		assert_non_null(fb);
		assert_int_equal(r.next, set.height);
		assert_int_equal(r.calls, 31); /* a call a band */
		assert_true((size_t)(r.hi - r.lo) <= (size_t)(threads + 6) * 16 * row);
		fb_free(fb);
		/* threads waiting for their slots end when a handover fails, or
		 * when the render is cancelled: no hang, the right message */
		handover_stops(wd, &set, expect, 2, 8);
		atomic_bool cancel = false;
		rows_seen cut = {expect, 0, 0, 0, 8, NULL, NULL, &cancel};
		rt_error err = {0};
		assert_null(render_image_rows(wd, &set, &cancel, NULL, NULL, rows_check, &cut, &err));
		assert_true(cut.calls >= 1 && cut.calls < 31);
		assert_non_null(strstr(err.msg, "render stopped"));
	}
	free(expect);
	fb_free(ref);
	world_free(wd);
}

/* image_write_rendered's make: renders with the rows it is given, counting
 * them; fails by itself when `fail` is set. */
typedef struct make_ctx {
	const world *w;
	const render_settings *set;
	bool fail;
	int rows_calls;
	render_rows_fn rows;
	void *rows_ctx;
} make_ctx;

static bool count_rows(void *ctx, const framebuffer *fb, int y0, int y1, const uint8_t *codes)
{
	make_ctx *m = ctx;
	m->rows_calls++;
	return m->rows(m->rows_ctx, fb, y0, y1, codes);
}

static framebuffer *make_render(void *ctx, render_rows_fn rows, void *rows_ctx, rt_error *err)
{
	make_ctx *m = ctx;
	if (m->fail) {
		rt_error_set(err, "the render failed");
		return NULL;
	}
	if (!rows)
		return render_image_srgb8(m->w, m->set, NULL, NULL, NULL, err);
	m->rows = rows;
	m->rows_ctx = rows_ctx;
	return render_image_rows(m->w, m->set, NULL, NULL, NULL, count_rows, m, err);
}

static unsigned char *slurp(const char *path, size_t *len)
{
	FILE *f = fopen(path, "rb");
	assert_non_null(f);
	fseek(f, 0, SEEK_END);
	long n = ftell(f);
	fseek(f, 0, SEEK_SET);
	unsigned char *b = malloc((size_t)n + 1);
	assert_non_null(b);
	assert_int_equal(fread(b, 1, (size_t)n, f), (size_t)n);
	fclose(f);
	*len = (size_t)n;
	return b;
}

static int temp_files(const char *dir)
{
	DIR *d = opendir(dir);
	assert_non_null(d);
	int k = 0;
	struct dirent *e;
	while ((e = readdir(d)))
		k += strstr(e->d_name, ".tmp.") != NULL;
	closedir(d);
	return k;
}

/* A file written while the picture renders is whole and the same bytes as
 * one written after the render (PPM, PNG, JPEG; 2 threads); the PPM's
 * pixels are linear_to_srgb8 of render_image's floats. A render that fails,
 * or a write that fails half way (the file size limit), leaves the old file
 * as it was and no temporary file. */
static void test_write_rendered(void **state)
{
	(void)state;
	world *wd = rows_world();
	render_settings set = render_settings_default();
	set.width = 320;
	set.height = 180;
	set.exposure = 0.5;
	set.threads = 2;
	char dir[] = "/tmp/rtsh-test-XXXXXX", a[256], b[256];
	assert_non_null(mkdtemp(dir));
	static const char *const ext[] = {"ppm", "png", "jpg"};
	framebuffer *ref = render_image_srgb8(wd, &set, NULL, NULL, NULL, NULL);
	assert_non_null(ref);
	for (int k = 0; k < 3; k++) {
		snprintf(a, sizeof a, "%s/a.%s", dir, ext[k]);
		snprintf(b, sizeof b, "%s/b.%s", dir, ext[k]);
		make_ctx m = {wd, &set, false, 0, NULL, NULL};
		rt_error err = {0};
		assert_true(image_write_rendered(a, 320, 180, 0.5, make_render, &m, &err));
		assert_true(k == 2 ? m.rows_calls == 0 : m.rows_calls >= 1); /* JPEG: after the render */
		assert_true(image_write(b, ref, 0.5, NULL));
		size_t la, lb;
		unsigned char *fa = slurp(a, &la), *fb = slurp(b, &lb);
		assert_int_equal(la, lb);
		assert_memory_equal(fa, fb, la);
		if (k == 0) {
			const char *head = "P6\n320 180\n255\n";
			size_t hn = strlen(head);
			assert_int_equal(la, hn + 320 * 180 * 3);
			assert_memory_equal(fa, head, hn);
			double gain = pow(2.0, 0.5);
			for (size_t i = 0; i < 320 * 180 * 3; i++)
				assert_int_equal(fa[hn + i], linear_to_srgb8(ref->rgb[i] * gain));
		}
		free(fa);
		free(fb);
	}
	/* the old file stays when the render fails */
	snprintf(a, sizeof a, "%s/a.ppm", dir);
	size_t lold;
	unsigned char *old = slurp(a, &lold);
	make_ctx bad = {wd, &set, true, 0, NULL, NULL};
	rt_error err = {0};
	assert_false(image_write_rendered(a, 320, 180, 0.5, make_render, &bad, &err));
	assert_non_null(strstr(err.msg, "the render failed"));
	size_t l2;
	unsigned char *now = slurp(a, &l2);
	assert_int_equal(l2, lold);
	assert_memory_equal(now, old, lold);
	free(now);
	assert_int_equal(temp_files(dir), 0);
	/* and when the disk refuses the rows half way: the render stops early */
	struct rlimit lim, small;
	assert_int_equal(getrlimit(RLIMIT_FSIZE, &lim), 0);
	small = lim;
	small.rlim_cur = 100000; /* the header and six bands of 16 rows (15360 bytes each) */
	void (*was)(int) = signal(SIGXFSZ, SIG_IGN);
	assert_int_equal(setrlimit(RLIMIT_FSIZE, &small), 0);
	make_ctx cut = {wd, &set, false, 0, NULL, NULL};
	memset(&err, 0, sizeof err);
	bool ok = image_write_rendered(a, 320, 180, 0.5, make_render, &cut, &err);
	assert_int_equal(setrlimit(RLIMIT_FSIZE, &lim), 0);
	signal(SIGXFSZ, was);
	assert_false(ok);
	assert_non_null(strstr(err.msg, "write failed"));
	assert_true(cut.rows_calls >= 1 && cut.rows_calls <= 7);
	now = slurp(a, &l2);
	assert_int_equal(l2, lold);
	assert_memory_equal(now, old, lold);
	free(now);
	free(old);
	assert_int_equal(temp_files(dir), 0);
	for (int k = 0; k < 3; k++) {
		snprintf(a, sizeof a, "%s/a.%s", dir, ext[k]);
		snprintf(b, sizeof b, "%s/b.%s", dir, ext[k]);
		unlink(a);
		unlink(b);
	}
	assert_int_equal(rmdir(dir), 0);
	fb_free(ref);
	world_free(wd);
}



/* phong_specular_negligible says yes only when the highlight, computed as
 * the shading computes it (pow), leaves c's bits as they are; and it does
 * say yes for dim highlights on a lit surface (else it saves nothing). By
 * hand: rv = 0.5, e = 64 gives 2^-64: on c = 1 a highlight of lr s = 1 adds
 * 2^-64, far below 1's half ulp 2^-53 (yes); on c = 0 anything shows (no);
 * rv = 0.9 at e = 200 is 7e-10 (no). */
static void test_specular_negligible(void **state)
{
	(void)state;
	assert_true(phong_specular_negligible(v3(1, 1, 1), v3(1, 1, 1), 1, 0.5, 64));
	assert_false(phong_specular_negligible(v3(0, 1, 1), v3(1, 1, 1), 1, 0.5, 64));
	assert_false(phong_specular_negligible(v3(1, 1, 1), v3(1, 1, 1), 1, 0.9, 200));
	assert_false(phong_specular_negligible(v3(1, NAN, 1), v3(1, 1, 1), 1, 0.5, 64));
	assert_false(phong_specular_negligible(v3(1, 1, 1), v3(INFINITY, 1, 1), 0, 0.5, 64));
	test_rng r = {29};
	int yes = 0;
	for (int k = 0; k < 200000; k++) {
		/* c and lr over many magnitudes, rv and e around the thresholds */
		vec3 c = v3(pow(2, trange(&r, -40, 10)), pow(2, trange(&r, -40, 10)), pow(2, trange(&r, -40, 10)));
		vec3 lr = v3(pow(2, trange(&r, -30, 20)), pow(2, trange(&r, -30, 20)), pow(2, trange(&r, -30, 20)));
		double sp = trange(&r, 0, 1), rv = trange(&r, 1e-6, 1), e = trange(&r, 1, 500);
		if (k % 4 == 0)
			rv = k % 8 == 0 ? 0.5 : 0.8;
		if (k % 3 == 0)
			e = k % 9 == 0 ? 64 : 200;
		if (!phong_specular_negligible(c, lr, sp, rv, e))
			continue;
		yes++;
		vec3 t = v3_scale(lr, sp * pow(rv, e)), sum = v3_add(c, t);
		if (!v3_eq(sum, c))
			fail_msg("c %.17g,%.17g,%.17g + highlight %.17g,%.17g,%.17g (rv %.17g, e %.17g) is not c", c.x, c.y, c.z,
			         t.x, t.y, t.z, rv, e);
	}
	assert_true(yes > 10000);
}

/* Whitted's packets (render_image: camera rays, then each light's shadow
 * rays, in packets, and shading with what the packets worked out:
 * whitted_pre) give each pixel the bits that the single ray's shading,
 * which works out everything itself (render_sample), gives. Seven lights,
 * more than the WHITTED_PRE_LIGHTS kept a hit: a sun, a spot, one behind
 * the floor, one of ratio 0 (no ray), one inside a sphere (blocked), first,
 * so that lights that reach the picture come past WHITTED_PRE_LIGHTS; and
 * shiny, mirror and glass spheres, whose second hits are single rays. */
static void test_packets_equal_single(void **state)
{
	(void)state;
	scene *s = base_scene(v3(0, 3, -8), v3(0, -0.35, 1), 60);
	s->has_ambient = true;
	s->amb = (ambient){0.15, v3(255, 230, 200)};
	light ls[7] = {
		{.pos = v3(0, -3, 0), .ratio = 0.8, .color = v3(255, 255, 255)}, /* below the floor */
		{.pos = v3(2, 5, 3), .ratio = 0.0, .color = v3(255, 255, 255)},  /* sends nothing */
		{.pos = v3(1.5, 0.8, 1), .ratio = 0.5, .color = v3(60, 255, 60)}, /* inside a sphere */
		{.pos = v3(-5, 6, -4), .ratio = 0.6, .color = v3(255, 255, 255)},
		{.pos = v3(4, 3, -2), .ratio = 0.4, .color = v3(255, 120, 60)},
		{.pos = v3(0, 0, 0), .color = v3(200, 200, 255), .kind = LIGHT_SUN, .intensity = 0.3, .dir = v3(1, -2, 1)},
		{.pos = v3(-2, 6, 0), .color = v3(255, 255, 255), .kind = LIGHT_SPOT, .intensity = 20, .dir = v3(0.2, -1, 0),
		 .inner = 20, .outer = 35},
	};
	for (int i = 0; i < 7; i++)
		assert_true(scene_add_light(s, &ls[i], NULL));
	object p = object_make(OBJ_PLANE, v3(200, 200, 200));
	p.mat.checker = 2;
	assert_true(scene_add_object(s, &p, NULL));
	for (int k = 0; k < 9; k++) {
		object o = sphere(v3(-3 + 1.5 * (k % 5), 0.5 + 0.3 * (k / 5), -1 + 1.5 * (k / 5)), k == 8 ? 2.5 : 1,
		                  v3(50 + 20 * k, 200 - 15 * k, 120));
		o.mat.specular = k % 3 == 0 ? 0.8 : 0;
		o.mat.shininess = 20 + 40 * k;
		o.mat.reflective = k % 4 == 1 ? 0.6 : 0;
		o.mat.ior = k == 6 ? 1.5 : 0;
		if (k == 8)
			o.pos = v3(1.5, 0.8, 1); /* around light 4 */
		assert_true(scene_add_object(s, &o, NULL));
	}
	world *wd = world_build(s, NULL);
	assert_non_null(wd);
	render_settings set = render_settings_default();
	set.width = 67; /* not a multiple of 4: partial blocks too */
	set.height = 41;
	set.samples = 1;
	set.depth = 3;
	set.threads = 1;
	set.mode = MODE_WHITTED;
	framebuffer *fb = render_image(wd, &set, NULL, NULL, NULL, NULL);
	assert_non_null(fb);
	int lit = 0;
	for (int y = 0; y < set.height; y++)
		for (int x = 0; x < set.width; x++) {
			vec3 want = render_sample(wd, &set, x, y, set.width, set.height, 0), got = pixel(fb, x, y);
			if (got.x != (float)want.x || got.y != (float)want.y || got.z != (float)want.z)
				fail_msg("pixel %d,%d: packets %.9g,%.9g,%.9g, single ray %.9g,%.9g,%.9g", x, y, got.x, got.y,
				         got.z, want.x, want.y, want.z);
			lit += want.x > 0.3;
		}
	assert_true(lit > set.width * set.height / 4); /* the lights reach the picture */
	fb_free(fb);
	world_free(wd);
	scene_free(s);
}

/* A block's camera rays (camera_block_rays, which shares each column's and
 * row's terms for one centred sample through a pinhole) are the rays
 * camera_sample_ray gives pixel by pixel, to the bit: cameras with
 * horizontal and vertical fields of view, a roll, an orthographic one,
 * one and several samples, Whitted and path mode, blocks at the edges of
 * odd image sizes. */
static void test_block_rays_bits(void **state)
{
	(void)state;
	test_rng r = {5};
	const int sizes[][2] = {{37, 21}, {1920, 1080}, {5, 301}, {1, 1}};
	for (int k = 0; k < 400; k++) {
		camera c = {v3(trange(&r, -9, 9), trange(&r, -9, 9), trange(&r, -9, 9)), tdir(&r), trange(&r, 1, 170),
		            k % 3 == 1, k % 7 == 3 ? trange(&r, 0.5, 4) : 0, k % 5 == 2 ? trange(&r, -180, 180) : 0};
		scene *s = scene_new();
		assert_true(scene_add_camera(s, &c, NULL));
		world *wd = world_build(s, NULL);
		assert_non_null(wd);
		render_settings set = render_settings_default();
		const int *sz = sizes[k % 4];
		set.width = sz[0];
		set.height = sz[1];
		set.samples = k % 4 == 3 ? 4 : 1;
		set.mode = k % 6 == 5 ? MODE_PATH : MODE_WHITTED;
		bool sampled = k % 6 == 5;
		int x0 = (int)(trange(&r, 0, 1) * set.width), y0 = (int)(trange(&r, 0, 1) * set.height);
		x0 = x0 >= set.width ? set.width - 1 : x0;
		y0 = y0 >= set.height ? set.height - 1 : y0;
		int x1 = x0 + 4 < set.width ? x0 + 4 : set.width, y1 = y0 + 4 < set.height ? y0 + 4 : set.height;
		ray got[16];
		sampler gs[16];
		camera_block_rays(wd, &set, sampled, x0, y0, x1, y1, set.width, set.height, k % 3, got, gs);
		for (int y = y0, i = 0; y < y1; y++)
			for (int x = x0; x < x1; x++, i++) {
				sampler ws;
				ray want = camera_sample_ray(wd, &set, sampled, x, y, set.width, set.height, k % 3, &ws);
				if (memcmp(&got[i], &want, sizeof want) != 0 || gs[i].key != ws.key || gs[i].index != ws.index ||
				    gs[i].rindex != ws.rindex || gs[i].dim != ws.dim)
					fail_msg("camera %d pixel %d,%d of %dx%d: dir %.17g,%.17g,%.17g, pixel by pixel "
					         "%.17g,%.17g,%.17g",
					         k, x, y, set.width, set.height, got[i].d.x, got[i].d.y, got[i].d.z, want.d.x,
					         want.d.y, want.d.z);
			}
		/* cam_block_rays (what the bench's packet rows and Embree's
		 * harness use) against cam_ray: blocks of 1 to 4 x 1 to 4 pixels,
		 * and 17 x 1 (wider than CAM_BLOCK_MAX: pixel by pixel) */
		int bw = k % 9 == 4 ? 17 : 1 + k % 4, bh = k % 9 == 4 ? 1 : 1 + k / 4 % 4;
		int bx1 = x0 + bw < set.width ? x0 + bw : set.width, by1 = y0 + bh < set.height ? y0 + bh : set.height;
		ray cb[17];
		cam_block_rays(&wd->cam, x0, y0, bx1, by1, set.width, set.height, cb);
		for (int y = y0, i = 0; y < by1; y++)
			for (int x = x0; x < bx1; x++, i++) {
				ray want = cam_ray(&wd->cam, x + 0.5, y + 0.5, set.width, set.height);
				if (memcmp(&cb[i], &want, sizeof want) != 0)
					fail_msg("camera %d, cam_block_rays pixel %d,%d of %dx%d: dir %.17g,%.17g,%.17g, cam_ray "
					         "%.17g,%.17g,%.17g",
					         k, x, y, set.width, set.height, cb[i].d.x, cb[i].d.y, cb[i].d.z, want.d.x, want.d.y,
					         want.d.z);
			}
		world_free(wd);
		scene_free(s);
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_phong_by_hand),
		cmocka_unit_test(test_shadow),
		cmocka_unit_test(test_reflection),
		cmocka_unit_test(test_whitted_weight_cutoff),
		cmocka_unit_test(test_whitted_ray_bound),
		cmocka_unit_test(test_threads_identical),
		cmocka_unit_test(test_progressive_equals_batch),
		cmocka_unit_test(test_rect_equals_image),
		cmocka_unit_test(test_cancel),
		cmocka_unit_test(test_srgb),
		cmocka_unit_test(test_image_files),
		cmocka_unit_test(test_srgb8_in_tiles),
		cmocka_unit_test(test_block_rays_bits),
		cmocka_unit_test(test_packets_equal_single),
		cmocka_unit_test(test_specular_negligible),
		cmocka_unit_test(test_rows_while_rendering),
		cmocka_unit_test(test_rows_ring),
		cmocka_unit_test(test_write_rendered),
		cmocka_unit_test(test_basic_silhouette),
	};
	return cmocka_run_group_tests_name("render", tests, NULL, NULL);
}
