/* rtsh — images, textures, texture coordinates, normal maps and the HDR sky
 * (texture.h, surface.c, envmap.c). Expected values come from the image
 * bytes written here, from the layout rtsh(5) documents, or from physics
 * (the furnace). */
#include "testutil.h"
#include "tmpdir.h"

#include <unistd.h>

#include "core/envmap.h"
#include "core/integrators.h"
#include "rtsh/render.h"
#include "rtsh/rtfile.h"
#include "rtsh/texture.h"
#include "rtsh/world.h"

static double srgb(int code)
{
	double v = code / 255.0;
	return v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4);
}

/* An 8x8 P6 image: the bottom-left 2x2 texels red, the rest blue. */
static const char *corner_ppm(void)
{
	unsigned char buf[64 + 8 * 8 * 3];
	int n = sprintf((char *)buf, "P6\n8 8\n255\n");
	for (int y = 0; y < 8; y++)
		for (int x = 0; x < 8; x++) {
			bool corner = x < 2 && y >= 6;
			buf[n++] = corner ? 255 : 0;
			buf[n++] = 0;
			buf[n++] = corner ? 0 : 255;
		}
	return tmp_write("corner.ppm", buf, (size_t)n);
}

static void test_ppm_pfm_xpm(void **state)
{
	(void)state;
	int w, h;
	rt_error err = {0};
	float *p = image_load_rgb(corner_ppm(), true, &w, &h, &err);
	assert_non_null(p);
	assert_int_equal(w, 8);
	assert_int_equal(h, 8);
	/* top row first: texel (0,7) is the bottom-left one */
	assert_near(p[3 * (7 * 8 + 0)], srgb(255), 1e-6);
	assert_near(p[3 * (0 * 8 + 0) + 2], srgb(255), 1e-6);
	free(p);
	/* PFM rows run bottom to top; scale < 0: little-endian */
	float pf[2 * 1 * 3 + 0] = {0.25f, 0.5f, 2.0f, 7.0f, 8.0f, 9.0f};
	unsigned char buf[64];
	int n = sprintf((char *)buf, "PF\n1 2\n-1.0\n");
	memcpy(buf + n, pf, sizeof pf);
	p = image_load_rgb(tmp_write("a.pfm", buf, (size_t)n + sizeof pf), true, &w, &h, &err);
	assert_non_null(p);
	assert_int_equal(h, 2);
	assert_near(p[0], 7.0, 0); /* the file's second row is the image's top */
	assert_near(p[3], 0.25, 0);
	free(p);
	const char *xpm = "/* XPM */\nstatic char *x[] = {\n\"2 1 2 1\",\n\"a c #FF0000\",\n\"b c None\",\n\"ab\"};\n";
	p = image_load_rgb(tmp_write("a.xpm", xpm, strlen(xpm)), false, &w, &h, &err);
	assert_non_null(p);
	assert_near(p[0], 1, 0);
	assert_near(p[3], 0, 0);
	free(p);
	/* bad images */
	static const struct {
		const char *name, *data, *want;
	} bad[] = {
		{"z.ppm", "P6 0 4 255\n", "is 0x4 pixels"},
		{"t.ppm", "P6 4 4 255\nabc", "ends early"},
		{"h.ppm", "P6 2 2 255", "ends after the header"},
		{"c.png", "\x89PNG\r\n\x1a\ngarbage", "cannot decode"},
		{"c.xpm", "/* XPM */\nstatic char *x[] = {\n\"1 1 1 1\",\n\"a c #GG0000\",\n\"a\"};\n", "XPM colour 1"},
		{"u.gif2", "x", "unknown image format"},
	};
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
		const char *path = tmp_write(bad[i].name, bad[i].data, strlen(bad[i].data));
		p = image_load_rgb(path, true, &w, &h, &err);
		assert_null(p);
		if (!strstr(err.msg, bad[i].want) || !strstr(err.msg, bad[i].name))
			fail_msg("%s: \"%s\", expected \"%s\"", bad[i].name, err.msg, bad[i].want);
	}
}

/* A distant checkerboard must not shimmer: a footprint of many texels
 * returns their average. */
/* Headers that promise more pixels than their file holds are refused, not
 * padded: a binary PPM under a name stb_image reads (found by fuzz_texture:
 * 30 bytes promising 426 x 436,637 pixels became a 2 GB image), and a PNG
 * whose header says 16000 x 16000 with no pixel data after it (more than
 * 4,096 pixel bytes a file byte, which no format packs). */
static void test_headers_that_promise_too_much(void **state)
{
	(void)state;
	static const unsigned char ppm[] = "P6\n426\n436637  2\n  F\nF\n1\b0%";
	rt_error err = {0};
	int w, h;
	float *p = image_decode_rgb("x.tga", ppm, sizeof ppm - 1, true, &w, &h, &err);
	assert_null(p);
	if (!strstr(err.msg, "ends early"))
		fail_msg("message \"%s\"", err.msg);
	/* PNG: signature, an IHDR of 16000 x 16000 8-bit RGB (its CRC), IEND */
	static const unsigned char png[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 13, 'I', 'H', 'D', 'R',
	                                    0, 0, 0x3e, 0x80, 0, 0, 0x3e, 0x80, 8, 2, 0, 0, 0, 0xce, 0x1c, 0x48, 0x89, 0, 0, 0, 0,
	                                    'I', 'E', 'N', 'D', 0xae, 0x42, 0x60, 0x82};
	p = image_decode_rgb("x.png", png, sizeof png, true, &w, &h, &err);
	assert_null(p);
	if (!strstr(err.msg, "16000x16000 pixels, more than its 45 bytes can hold"))
		fail_msg("message \"%s\"", err.msg);
}

/* An image over the size limit says its size and the limit, in every
 * format: stb_image alone called a 30000 x 30000 RGB PNG or JPEG an
 * "unknown image type" (its own limits are 2^30 and 2^31 decoded bytes).
 * Each header is written here from its format's layout. */
static void test_too_large_says_so(void **state)
{
	(void)state;
	/* 30000 = 0x7530 */
	static const unsigned char png[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 13, 'I', 'H', 'D', 'R',
	                                    0, 0, 0x75, 0x30, 0, 0, 0x75, 0x30, 8, 2, 0, 0, 0, 0, 0, 0, 0};
	/* SOI, then SOF0: length 17, 8 bits, height, width, 3 components */
	static const unsigned char jpg[] = {0xff, 0xd8, 0xff, 0xc0, 0, 17, 8, 0x75, 0x30, 0x75, 0x30, 3,
	                                    1, 0x11, 0, 2, 0x11, 0, 3, 0x11, 0, 0xff, 0xd9};
	/* BITMAPFILEHEADER, then a 40-byte BITMAPINFOHEADER, 24 bits */
	unsigned char bmp[54] = {'B', 'M'};
	bmp[10] = 54;
	bmp[14] = 40;
	bmp[18] = 0x30, bmp[19] = 0x75, bmp[22] = 0x30, bmp[23] = 0x75;
	bmp[26] = 1;
	bmp[28] = 24;
	static const char hdr[] = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 30000 +X 30000\n";
	static const char ppm[] = "P6\n30000 30000\n255\n";
	static const char pfm[] = "PF\n30000 30000\n-1.0\n";
	const struct {
		const char *name;
		const void *b;
		size_t len;
	} c[] = {{"x.png", png, sizeof png}, {"x.jpg", jpg, sizeof jpg}, {"x.bmp", bmp, sizeof bmp},
	         {"x.hdr", hdr, sizeof hdr - 1}, {"x.ppm", ppm, sizeof ppm - 1}, {"x.pfm", pfm, sizeof pfm - 1}};
	for (size_t i = 0; i < sizeof c / sizeof c[0]; i++) {
		rt_error err = {0};
		int w, h;
		float *p = image_decode_rgb(c[i].name, c[i].b, c[i].len, true, &w, &h, &err);
		assert_null(p);
		if (!strstr(err.msg, "image too large: 30000x30000 pixels; expected at most 268435456"))
			fail_msg("%s: message \"%s\"", c[i].name, err.msg);
		unsigned char *a = NULL;
		bool ok = image_decode_alpha(c[i].name, c[i].b, c[i].len, &a, &w, &h, &err);
		assert_null(a);
		if (!ok && !strstr(err.msg, "image too large: 30000x30000 pixels"))
			fail_msg("%s: the alpha reader's message \"%s\"", c[i].name, err.msg);
	}
}

/* The previewer's budget: an image of more pixels than it is refused
 * before decoding, the refusal is known as the budget's (image_budget_refused)
 * and counted once per image; the sky is exempt; at or under the budget,
 * and with none, the image is read. */
static void test_preview_budget(void **state)
{
	(void)state;
	unsigned char a[16 + 110];
	int n = sprintf((char *)a, "P5\n10 10\n255\n");
	memset(a + n, 128, 100);
	size_t len100 = (size_t)n + 100;
	unsigned char b[16 + 110];
	int m = sprintf((char *)b, "P5\n10 11\n255\n");
	memset(b + m, 128, 110);
	size_t len110 = (size_t)m + 110;
	rt_error err = {0};
	int w, h;
	image_budget_set(100);
	float *px = image_decode_rgb("a.pgm", a, len100, true, &w, &h, &err);
	assert_non_null(px); /* 100 pixels: at the budget */
	free(px);
	assert_null(image_decode_rgb("b.pgm", b, len110, true, &w, &h, &err));
	assert_true(image_budget_refused(&err));
	if (!strstr(err.msg, "b.pgm: 10x11 pixels, over the preview's 100 for an image"))
		fail_msg("message \"%s\"", err.msg);
	assert_null(image_decode_rgb("b.pgm", b, len110, true, &w, &h, &err)); /* the same image again */
	char first[RT_ERROR_MSG_MAX];
	assert_int_equal(image_budget_report(first, sizeof first), 1);
	assert_string_equal(first, err.msg);
	/* another failure is not the budget's */
	rt_error other = {0};
	assert_null(image_decode_rgb("c.pgm", (const unsigned char *)"P5\n0 1\n255\n", 12, true, &w, &h, &other));
	assert_false(image_budget_refused(&other));
	/* an image over the size limit too: the budget's (a preview skips it) */
	static const unsigned char png[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 13, 'I', 'H', 'D', 'R',
	                                    0, 0, 0x75, 0x30, 0, 0, 0x75, 0x30, 8, 2, 0, 0, 0, 0, 0, 0, 0};
	assert_null(image_decode_rgb("huge.png", png, sizeof png, true, &w, &h, &err));
	assert_true(image_budget_refused(&err));
	assert_int_equal(image_budget_report(first, sizeof first), 2);
	/* the sky is not held to it */
	image_budget_exempt(true);
	px = image_decode_rgb("b.pgm", b, len110, true, &w, &h, &err);
	image_budget_exempt(false);
	assert_non_null(px);
	free(px);
	/* no budget: read */
	image_budget_set(0);
	px = image_decode_rgb("b.pgm", b, len110, true, &w, &h, &err);
	assert_non_null(px);
	free(px);
}

static void test_mipmap_average(void **state)
{
	(void)state;
	int n = 64;
	float *rgb = malloc((size_t)n * n * 3 * sizeof *rgb);
	for (int y = 0; y < n; y++)
		for (int x = 0; x < n; x++)
			for (int c = 0; c < 3; c++)
				rgb[3 * (y * n + x) + c] = (float)((x + y) & 1);
	rt_error err = {0};
	texture *t = texture_make(rgb, n, n, NULL, false, &err);
	assert_non_null(t);
	assert_int_equal(t->nlevels, 7); /* 64, 32, ..., 1 */
	test_rng r = {3};
	for (int i = 0; i < 100; i++) {
		double u = trand(&r), v = trand(&r);
		assert_near(texture_lookup(t, u, v, 0.5).x, 0.5, 1e-6);
	}
	texture_free(t);
}

static scene *load_text(const char *text)
{
	char name[128];
	snprintf(name, sizeof name, "%s/t.rt", tmpdir);
	rt_error err = {0};
	scene *s = rt_load_string(text, strlen(text), name, NULL, &err);
	if (!s) {
		char buf[1024];
		rt_error_format(&err, buf, sizeof buf);
		fail_msg("%s", buf);
	}
	return s;
}

/* rtsh(5): on a rectangle u = (x + 1) / 2, v = (z + 1) / 2 of its own axes,
 * (0,0) the image's bottom-left corner: at the rectangle's -X -Z corner. */
static void test_corner_lands_where_documented(void **state)
{
	(void)state;
	corner_ppm();
	scene *s = load_text("C 0,5,0 0,-1,0.001 60\nrc 0,0,0 0,1,0 2,1,2 255,255,255 texture=corner.ppm\n"
	                     "sp 5,0,0 1 255,255,255 texture=corner.ppm\n");
	rt_error err = {0};
	world *w = world_build(s, &err);
	assert_non_null(w);
	struct {
		vec3 at;
		bool red;
	} probes[] = {{{-0.8, 0, -0.8}, true}, {{0.8, 0, 0.8}, false}, {{-0.8, 0, 0.8}, false}, {{0.8, 0, -0.8}, false}};
	for (size_t i = 0; i < 4; i++) {
		vec3 o = v3_add(probes[i].at, v3(0, 3, 0));
		hit h;
		assert_true(world_intersect(w, &(ray){o, v3(0, -1, 0)}, 0, INFINITY, &h));
		vec3 c = hit_albedo(&w->mats[h.mat], &h);
		assert_near(c.x, probes[i].red ? 1 : 0, 1e-6);
		assert_near(c.z, probes[i].red ? 0 : 1, 1e-6);
	}
	/* the sphere: (0,0) at the south pole, u = 1/2 (the image's middle)
	 * facing -Z: the bottom row near u = 0 is red, the middle is blue */
	hit h;
	assert_true(world_intersect(w, &(ray){v3(5, -3, 0.05), v3(0, 1, 0)}, 0, INFINITY, &h));
	assert_near(h.v, asin(0.1) / RT_PI, 1e-6); /* 0.05 from the axis on a radius of 0.5 */
	assert_true(world_intersect(w, &(ray){v3(5, 0, -3), v3(0, 0, 1)}, 0, INFINITY, &h));
	assert_near(h.u, 0.5, 1e-9);
	assert_near(h.v, 0.5, 1e-9);
	world_free(w);
	scene_free(s);
}

static framebuffer *render_text(const char *text, render_mode mode, int samples, int threads)
{
	scene *s = load_text(text);
	rt_error err = {0};
	world *w = world_build(s, &err);
	assert_non_null(w);
	render_settings set = render_settings_default();
	set.width = 64;
	set.height = 48;
	set.mode = mode;
	set.samples = samples;
	set.threads = threads;
	set.depth = mode == MODE_PATH ? 40 : 5;
	framebuffer *fb = render_image(w, &set, NULL, NULL, NULL, &err);
	assert_non_null(fb);
	world_free(w);
	scene_free(s);
	return fb;
}

static void test_flat_normal_map_changes_nothing(void **state)
{
	(void)state;
	unsigned char buf[64 + 4 * 4 * 3];
	int n = sprintf((char *)buf, "P6\n4 4\n255\n");
	for (int i = 0; i < 16; i++) {
		buf[n++] = (unsigned char)(i & 1 ? 127 : 128); /* both count as flat */
		buf[n++] = 128;
		buf[n++] = 255;
	}
	tmp_write("flat.ppm", buf, (size_t)n);
	const char *base = "C 0,1,-4 0,-0.2,1 60\nL 2,4,-3 0.8 255,255,255\nA 0.1 255,255,255\n"
	                   "sp 0,0.5,0 0,1,0 1.5,1.4,1.5 200,100,50%s\npl 0,0,0 0,1,0 150,150,150%s\n";
	char a[512], b[512];
	snprintf(a, sizeof a, base, "", "");
	snprintf(b, sizeof b, base, " normalmap=flat.ppm", " normalmap=flat.ppm");
	for (int mode = 0; mode < 2; mode++) {
		framebuffer *fa = render_text(a, (render_mode)mode, 2, 1);
		framebuffer *fb = render_text(b, (render_mode)mode, 2, 1);
		assert_memory_equal(fa->rgb, fb->rgb, (size_t)fa->w * fa->h * 3 * sizeof(float));
		fb_free(fa);
		fb_free(fb);
	}
	/* a tilted normal map does change the picture */
	for (int i = 0; i < 16; i++)
		buf[n - 48 + 3 * i] = 220;
	tmp_write("flat.ppm", buf, (size_t)n);
	framebuffer *fa = render_text(a, MODE_WHITTED, 1, 1), *fb = render_text(b, MODE_WHITTED, 1, 1);
	assert_true(memcmp(fa->rgb, fb->rgb, (size_t)fa->w * fa->h * 3 * sizeof(float)) != 0);
	fb_free(fa);
	fb_free(fb);
}

static const char *uniform_pfm(float value)
{
	unsigned char buf[64 + 8 * 4 * 12];
	int n = sprintf((char *)buf, "PF\n8 4\n-1.0\n");
	for (int i = 0; i < 8 * 4 * 3; i++) {
		memcpy(buf + n, &value, 4);
		n += 4;
	}
	return tmp_write("uniform.pfm", buf, (size_t)n);
}

/* The furnace: a white Lambertian sphere under a uniform sky of radiance
 * L reflects L in every direction (all it receives, albedo 1). */
static void test_uniform_sky_furnace(void **state)
{
	(void)state;
	uniform_pfm(0.5f);
	framebuffer *fb = render_text("C 0,0,-4 0,0,1 40\nsky uniform.pfm 1\nsp 0,0,0 0,1,0 2,2,2 255,255,255 1 0 1 0\n",
	                              MODE_PATH, 64, 2);
	double sum = 0;
	int n = 0;
	for (int y = 0; y < fb->h; y++)
		for (int x = 0; x < fb->w; x++) {
			double dx = x + 0.5 - fb->w / 2.0, dy = y + 0.5 - fb->h / 2.0;
			const float *p = &fb->rgb[3 * (y * fb->w + x)];
			if (dx * dx + dy * dy < 100) { /* well inside the sphere's disc */
				sum += p[0];
				n++;
			} else if (dx * dx + dy * dy > 30 * 30) {
				assert_near(p[0], 0.5, 1e-6); /* the sky itself */
			}
		}
	assert_true(n > 200);
	assert_near(sum / n, 0.5, 0.01);
	fb_free(fb);
}

/* The sky's sampling density is what it says and integrates to 1. */
static void test_sky_pdf(void **state)
{
	(void)state;
	/* a sky with a bright band: importance matters */
	int w = 32, h = 16;
	unsigned char buf[64 + 32 * 16 * 12];
	int n = sprintf((char *)buf, "PF\n%d %d\n-1.0\n", w, h);
	for (int i = 0; i < w * h; i++) {
		float v = (i % w) < 4 ? 50.0f : 0.2f + (float)(i / w) * 0.1f;
		for (int c = 0; c < 3; c++) {
			memcpy(buf + n, &v, 4);
			n += 4;
		}
	}
	rt_error err = {0};
	envmap *e = envmap_new(tmp_write("band.pfm", buf, (size_t)n), 1, 30, NULL, &err);
	assert_non_null(e);
	test_rng r = {11};
	for (int i = 0; i < 2000; i++) {
		double pdf;
		vec3 d = envmap_sample(e, trand(&r), trand(&r), &pdf);
		assert_near(v3_len(d), 1, 1e-9);
		if (pdf > 0)
			assert_near(envmap_pdf(e, d) / pdf, 1, 1e-6);
	}
	double integral = 0;
	int m = 400000;
	for (int i = 0; i < m; i++)
		integral += envmap_pdf(e, tdir(&r));
	integral *= 4 * RT_PI / m;
	assert_near(integral, 1, 0.02);
	envmap_free(e);
}

/* The same picture whatever the thread count (meshes, textures, sky). */
static void test_threads_same_picture(void **state)
{
	(void)state;
	corner_ppm();
	uniform_pfm(0.3f);
	FILE *f = fopen("/dev/null", "r");
	fclose(f);
	char obj[256];
	snprintf(obj, sizeof obj, "%s/tri.obj", tmpdir);
	f = fopen(obj, "w");
	fputs("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvt 1 0\nvt 0 1\nvt 1 1\n"
	      "f 1/1 3/3 2/2\nf 1/1 2/2 4/4\nf 1/1 4/4 3/3\nf 2/2 3/3 4/4\n",
	      f);
	fclose(f);
	const char *text = "C 0,1,-4 0,-0.2,1 60\nsky uniform.pfm 1\nL 2,4,-3 0.8 255,255,255\n"
	                   "mesh tri.obj 0,0.5,0 0.2,1,0 1.5 texture=corner.ppm\n"
	                   "pl 0,0,0 0,1,0 150,150,150 texture=corner.ppm\n";
	for (int mode = 0; mode < 2; mode++) {
		framebuffer *a = render_text(text, (render_mode)mode, 4, 1);
		framebuffer *b = render_text(text, (render_mode)mode, 4, 2);
		assert_memory_equal(a->rgb, b->rgb, (size_t)a->w * a->h * 3 * sizeof(float));
		fb_free(a);
		fb_free(b);
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_ppm_pfm_xpm),
		cmocka_unit_test(test_headers_that_promise_too_much),
		cmocka_unit_test(test_too_large_says_so),
		cmocka_unit_test(test_preview_budget),
		cmocka_unit_test(test_mipmap_average),
		cmocka_unit_test(test_corner_lands_where_documented),
		cmocka_unit_test(test_flat_normal_map_changes_nothing),
		cmocka_unit_test(test_uniform_sky_furnace),
		cmocka_unit_test(test_sky_pdf),
		cmocka_unit_test(test_threads_same_picture),
	};
	return cmocka_run_group_tests(tests, tmpdir_setup, tmpdir_teardown);
}
