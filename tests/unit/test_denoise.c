/* rtsh — tests of the denoiser (denoise.c). Expected values come from a
 * reference render or from definitions:
 *   - on scenes/cornell.rt, 8 samples denoised are closer to a 4096-sample
 *     reference than 64 samples without
 *     (RMS error in linear radiance, the lamp's pixels left out);
 *   - an edge between two flat regions keeps its width (10%-90% rise);
 *   - a picture without noise (piecewise constant, features agreeing) comes
 *     out unchanged; a constant one too, however noisy its neighbours;
 *   - a flat noisy surface of known noise: the error falls as the mean over
 *     the regression's 9x9 window says (9x);
 *   - an edge in the features: no tap crosses it, each side keeps its own
 *     radiance;
 *   - highlights a few pixels wide on a surface unlike its surroundings:
 *     the error of a two-unknown least-squares fit (trace of the hat
 *     matrix), not the eight-unknown one's;
 *   - an edge pixel's highlight in a glossy metal: 5 x the mean albedo over
 *     the same 64 positions as the albedo;
 *   - a mixed pixel moves towards its window's line by at most 1.345
 *     standard deviations of a pixel mean's noise (Huber's clip);
 *   - the features seen through a mirror are the reflected wall's, at the
 *     distance of the whole path; through glass 1 - F of the wall's albedo
 *     and F of white (Fresnel at normal incidence); the sky's, its colour;
 *   - the result is identical for any thread count; whitted mode is never
 *     touched; the setting parses auto, on and off. */
#include "testutil.h"

#include <errno.h>
#include <sys/stat.h>

#include "rtsh/denoise.h"
#include "rtsh/image.h"
#include "rtsh/render.h"
#include "rtsh/rtfile.h"
#include "rtsh/scene.h"
#include "rtsh/settings.h"
#include "rtsh/world.h"

/* The renders of the quality tests are too slow under ThreadSanitizer;
 * test_threads covers the denoiser's threads there. */
#if defined(__SANITIZE_THREAD__)
#define SKIP_UNDER_TSAN()                                                              \
	do {                                                                           \
		print_message("skipped under TSan: too slow there (test_threads runs)\n"); \
		skip();                                                                \
	} while (0)
#else
#define SKIP_UNDER_TSAN() ((void)0)
#endif

static render_settings path_settings(int w, int h, int samples, int depth, uint64_t seed)
{
	render_settings set = render_settings_default();
	set.width = w;
	set.height = h;
	set.samples = samples;
	set.depth = depth;
	set.threads = 2;
	set.mode = MODE_PATH;
	set.seed = seed;
	set.denoise = DENOISE_OFF;
	return set;
}

static framebuffer *render_with(const world *w, render_settings set, int denoise)
{
	set.denoise = denoise;
	framebuffer *fb = render_image(w, &set, NULL, NULL, NULL, NULL);
	assert_non_null(fb);
	return fb;
}

/* True when any of 4x4 rays through pixel (x, y) meets an emitter. */
static bool sees_lamp(const world *w, int x, int y, int fw, int fh)
{
	for (int j = 0; j < 4; j++)
		for (int i = 0; i < 4; i++) {
			ray r = cam_ray(&w->cam, x + (i + 0.5) / 4, y + (j + 0.5) / 4, fw, fh);
			hit h;
			if (world_intersect(w, &r, 0.0, INFINITY, &h)) {
				vec3 e = w->mats[h.mat].emission;
				if (e.x + e.y + e.z > 0.0)
					return true;
			}
		}
	return false;
}

/* RMS error of a against ref over the pixels where mask is 0. */
static double rms(const framebuffer *a, const framebuffer *ref, const unsigned char *mask)
{
	double sum = 0;
	long n = 0;
	for (int i = 0; i < a->w * a->h; i++) {
		if (mask[i])
			continue;
		for (int k = 0; k < 3; k++) {
			double d = (double)a->rgb[i * 3 + k] - ref->rgb[i * 3 + k];
			sum += d * d;
		}
		n += 3;
	}
	return sqrt(sum / (double)n);
}

/* FNV-1a over bytes, to name the cached reference. */
static uint64_t fnv(uint64_t h, const void *p, size_t n)
{
	const unsigned char *b = p;
	for (size_t i = 0; i < n; i++)
		h = (h ^ b[i]) * 0x100000001b3ULL;
	return h;
}

/* The 4096-sample reference of cornell.rt, cached in build/test-cache under
 * a name that hashes the scene file and a small probe render with the same
 * settings: any change to the renderer that changes its pixels renders the
 * reference again (about 15 s on two cores). */
static framebuffer *cornell_reference(const world *w, render_settings set, const char *scene_path)
{
	uint64_t h = 0xcbf29ce484222325ULL;
	FILE *f = fopen(scene_path, "rb");
	assert_non_null(f);
	char buf[4096];
	size_t n;
	while ((n = fread(buf, 1, sizeof buf, f)) > 0)
		h = fnv(h, buf, n);
	fclose(f);
	render_settings probe = set;
	probe.width = 16;
	probe.height = 9;
	probe.samples = 4;
	framebuffer *pf = render_with(w, probe, DENOISE_OFF);
	h = fnv(h, pf->rgb, (size_t)pf->w * pf->h * 3 * sizeof *pf->rgb);
	h = fnv(h, &set.width, sizeof set.width);
	h = fnv(h, &set.height, sizeof set.height);
	h = fnv(h, &set.samples, sizeof set.samples);
	h = fnv(h, &set.depth, sizeof set.depth);
	h = fnv(h, &set.seed, sizeof set.seed);
	fb_free(pf);
	char path[256];
	snprintf(path, sizeof path, "build/test-cache/cornell-%dx%d-%d-%016llx.pfm", set.width, set.height,
	         set.samples, (unsigned long long)h);
	rt_error err;
	framebuffer *ref = image_read_pfm(path, &err);
	if (ref && ref->w == set.width && ref->h == set.height) {
		print_message("reference: %s (cached)\n", path);
		return ref;
	}
	fb_free(ref);
	ref = render_with(w, set, DENOISE_OFF);
	if (mkdir("build", 0777) == 0 || errno == EEXIST)
		if (mkdir("build/test-cache", 0777) == 0 || errno == EEXIST)
			if (image_write(path, ref, 0.0, &err))
				print_message("reference: %s (rendered and cached)\n", path);
	return ref;
}

/* The test of issue 12: cornell.rt, 8 samples denoised against 64 without,
 * both against 4096 samples with another seed, at 160x90 (at the scene's
 * own depth 12). */
static void test_cornell_rmse(void **state)
{
	(void)state;
	SKIP_UNDER_TSAN();
	rt_error err;
	const char *path = "scenes/cornell.rt";
	scene *s = rt_load_file(path, NULL, &err);
	if (!s) {
		print_message("skipped: %s\n", err.msg);
		skip();
	}
	world *w = world_build(s, &err);
	assert_non_null(w);
	const int W = 160, H = 90, depth = 12;
	framebuffer *ref = cornell_reference(w, path_settings(W, H, 4096, depth, 4242), path);
	unsigned char *mask = calloc((size_t)W * H, 1);
	assert_non_null(mask);
	int lamp = 0;
	for (int y = 0; y < H; y++)
		for (int x = 0; x < W; x++)
			lamp += mask[y * W + x] = sees_lamp(w, x, y, W, H);
	assert_true(lamp > 0 && lamp < W * H / 10);
	framebuffer *raw64 = render_with(w, path_settings(W, H, 64, depth, 1), DENOISE_OFF);
	framebuffer *raw32 = render_with(w, path_settings(W, H, 32, depth, 3), DENOISE_OFF);
	framebuffer *raw8 = render_with(w, path_settings(W, H, 8, depth, 2), DENOISE_OFF);
	framebuffer *dn8 = render_with(w, path_settings(W, H, 8, depth, 2), DENOISE_ON);
	double e64 = rms(raw64, ref, mask), e32 = rms(raw32, ref, mask), e8 = rms(raw8, ref, mask);
	double d8 = rms(dn8, ref, mask);
	print_message("cornell.rt %dx%d, the lamp's %d pixels left out, RMS error against 4096 spp: "
	              "8 spp %.5f, 32 spp %.5f, 64 spp %.5f, 8 spp denoised %.5f (%.2fx the 64 spp error)\n",
	              W, H, lamp, e8, e32, e64, d8, d8 / e64);
	/* Issue 12: 8 samples denoised closer to the reference than 64
	 * without; and, with room, than 32 and under a third of the 8-sample
	 * error. */
	assert_true(d8 < e64);
	assert_true(d8 < e32);
	assert_true(d8 < e8 / 3);
	fb_free(raw32);
	fb_free(dn8);
	fb_free(raw8);
	fb_free(raw64);
	free(mask);
	fb_free(ref);
	world_free(w);
	scene_free(s);
}

/* --- edges ----------------------------------------------------------------- */

static scene *load_text(const char *text)
{
	rt_error err;
	scene *s = rt_load_string(text, strlen(text), "test", NULL, &err);
	if (!s)
		fail_msg("%s", err.msg);
	return s;
}

/* The adaptive tests' world (a light, a floor and two objects), its scene
 * in *s. */
static world *adaptive_world(scene **s)
{
	*s = load_text("C 0,1,-4 0,-0.2,1 60\nA 0.3 200,220,255\nL 2,4,-2 0.7 255,255,255\n"
	               "pl 0,0,0 0,1,0 200,200,200\nsp 0,1,0 2 220,60,50\n"
	               "sp 1.5,0.5,-1 0,1,0 1,1,1 255,255,255 0 0 1 1\n");
	world *w = world_build(*s, NULL);
	assert_non_null(w);
	return w;
}

/* The features of the centre pixel of a 9x9 picture of the scene of text,
 * summed over its samples 0 .. n - 1 (denoise_sample's accumulator). */
static void centre_features(const char *text, int n, double f[DENOISE_ACC])
{
	scene *s = load_text(text);
	world *w = world_build(s, NULL);
	assert_non_null(w);
	memset(f, 0, DENOISE_ACC * sizeof *f);
	for (int k = 0; k < n; k++)
		denoise_sample(w, cam_ray(&w->cam, 4.5, 4.5, 9, 9), k, f);
	world_free(w);
	scene_free(s);
}

/* The mean of the image along rows (vertical = false: a profile across x)
 * or along columns (vertical = true: across y), of the luminance. */
static void profile(const framebuffer *fb, bool vertical, double *p)
{
	int n = vertical ? fb->h : fb->w, m = vertical ? fb->w : fb->h;
	for (int i = 0; i < n; i++) {
		double sum = 0;
		for (int j = 0; j < m; j++) {
			const float *c = fb->rgb + ((size_t)(vertical ? i * fb->w + j : j * fb->w + i)) * 3;
			sum += 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
		}
		p[i] = sum / m;
	}
}

/* The width in pixels of the step of profile p (n values) around index
 * mid: the distance between its 10% and 90% crossings between the plateau
 * means lo (before) and hi (after), linearly interpolated between pixel
 * centres. */
static double edge_width(const double *p, int n, int mid)
{
	double a = 0, b = 0;
	for (int i = mid - 8; i < mid - 4; i++)
		a += p[i] / 4;
	for (int i = mid + 4; i < mid + 8; i++)
		b += p[i] / 4;
	double cross[2];
	const double level[2] = {0.1, 0.9};
	for (int k = 0; k < 2; k++) {
		double t = a + level[k] * (b - a);
		cross[k] = NAN;
		for (int i = mid - 4; i < mid + 4 && i + 1 < n; i++)
			if ((p[i] - t) * (p[i + 1] - t) <= 0 && p[i] != p[i + 1]) {
				cross[k] = i + (t - p[i]) / (p[i + 1] - p[i]);
				break;
			}
	}
	return fabs(cross[1] - cross[0]);
}

/* The RMS difference in luminance from ref over a plateau: rows y0..y1,
 * columns x0..x1 (exclusive). */
static double plateau_noise(const framebuffer *fb, const framebuffer *ref, int x0, int x1, int y0, int y1)
{
	double s2 = 0;
	int n = 0;
	for (int y = y0; y < y1; y++)
		for (int x = x0; x < x1; x++) {
			const float *c = fb->rgb + ((size_t)y * fb->w + x) * 3;
			const float *r = ref->rgb + ((size_t)y * fb->w + x) * 3;
			double d = 0.2126 * (c[0] - r[0]) + 0.7152 * (c[1] - r[1]) + 0.0722 * (c[2] - r[2]);
			s2 += d * d;
			n++;
		}
	return sqrt(s2 / n);
}

/* An edge between two flat regions stays as sharp as in the reference: a
 * change of albedo (two squares side by side, a vertical edge at the middle
 * column boundary) and a shadow (a point light above, cut off by a shelf
 * out of view, a horizontal edge at the middle row boundary). Lit by a lamp
 * and a uniform sky, so the flat regions are noisy at 8 samples. */
static void test_edges(void **state)
{
	(void)state;
	SKIP_UNDER_TSAN();
	const char *albedo_scene = "C 0,0,-4 0,0,1 40\n"
	                           "A 0.3 255,255,255\n"
	                           "rc -1,0,0 0,0,-1 2,1,2 222,222,222 1 0 1 0\n"
	                           "rc 1,0,0 0,0,-1 2,1,2 60,60,60 1 0 1 0\n"
	                           "rc 0,3,-2 0,-1,0 2,1,2 255,255,255 0 0 1 0 emit=3\n";
	/* The light at (0,5,-1) passes the shelf's edge at z = -0.4, y = 2,
	 * and meets the wall z = 0 at y = 0. */
	const char *shadow_scene = "C 0,0,-4 0,0,1 40\n"
	                           "A 0.3 255,255,255\n"
	                           "L 0,5,-1 0.8 255,255,255\n"
	                           "rc 0,0,0 0,0,-1 6,1,6 222,222,222 1 0 1 0\n"
	                           "rc 0,2,-1.7 0,1,0 6,1,2.6 222,222,222 1 0 1 0\n";
	const struct {
		const char *name, *text;
		bool vertical;
	} cases[] = {{"albedo edge", albedo_scene, false}, {"shadow edge", shadow_scene, true}};
	const int W = 64, H = 36;
	for (size_t c = 0; c < 2; c++) {
		scene *s = load_text(cases[c].text);
		world *w = world_build(s, NULL);
		assert_non_null(w);
		framebuffer *ref = render_with(w, path_settings(W, H, 1024, 5, 7), DENOISE_OFF);
		framebuffer *raw = render_with(w, path_settings(W, H, 8, 5, 8), DENOISE_OFF);
		framebuffer *dn = render_with(w, path_settings(W, H, 8, 5, 8), DENOISE_ON);
		int n = cases[c].vertical ? H : W, mid = n / 2;
		double p[64];
		profile(ref, cases[c].vertical, p);
		double wref = edge_width(p, n, mid);
		profile(raw, cases[c].vertical, p);
		double wraw = edge_width(p, n, mid);
		profile(dn, cases[c].vertical, p);
		double wdn = edge_width(p, n, mid);
		/* the noise of one flat region, away from the edge */
		int x0 = 4, x1 = cases[c].vertical ? W - 4 : mid - 4;
		int y0 = 4, y1 = cases[c].vertical ? mid - 4 : H - 4;
		double nraw = plateau_noise(raw, ref, x0, x1, y0, y1), ndn = plateau_noise(dn, ref, x0, x1, y0, y1);
		print_message("%s: width (10%%-90%%) %.2f px in the 1024-spp reference, %.2f px at 8 spp, "
		              "%.2f px at 8 spp denoised; a flat region's RMS error %.4f -> %.4f\n",
		              cases[c].name, wref, wraw, wdn, nraw, ndn);
		assert_true(wref < 1.5);
		assert_true(wdn <= wref + 0.5);
		assert_true(ndn < 0.5 * nraw);
		fb_free(dn);
		fb_free(raw);
		fb_free(ref);
		world_free(w);
		scene_free(s);
	}
}

/* --- definitions ----------------------------------------------------------- */

/* A framebuffer of w x h with the given features everywhere, spp samples
 * and no noise (the mean of the squares is the square of the mean). */
static framebuffer *flat_fb(int w, int h, int spp)
{
	framebuffer *fb = fb_new(w, h);
	assert_non_null(fb);
	assert_true(denoise_prepare(fb));
	fb->spp = spp;
	for (int i = 0; i < w * h; i++) {
		float *f = fb->feat + (size_t)i * DENOISE_FEATURES;
		f[0] = f[1] = f[2] = 0.5f;
		f[3] = 0;
		f[4] = 0;
		f[5] = -1;
		f[6] = 3;
	}
	return fb;
}

static void set_pixel(framebuffer *fb, int i, float r, float g, float b)
{
	fb->rgb[i * 3] = r;
	fb->rgb[i * 3 + 1] = g;
	fb->rgb[i * 3 + 2] = b;
	double l = 0.2126 * r + 0.7152 * g + 0.0722 * b;
	float *f = fb->feat + (size_t)i * DENOISE_FEATURES;
	f[7] = f[13] = (float)(l * l);
	f[10] = r; /* the even samples are the same as all of them */
	f[11] = g;
	f[12] = b;
}

/* Without noise nothing changes: a constant picture, and a picture of two
 * colours on one surface (a shadow's edge the features do not see) whose
 * samples all agree. */
static void test_no_noise_no_change(void **state)
{
	(void)state;
	const int W = 40, H = 30;
	framebuffer *fb = flat_fb(W, H, 16);
	for (int i = 0; i < W * H; i++)
		set_pixel(fb, i, 0.3f, 0.2f, 0.1f);
	float *out = malloc(sizeof(float) * W * H * 3);
	assert_non_null(out);
	assert_true(denoise_image(fb, out, 2));
	for (int i = 0; i < W * H * 3; i++)
		assert_near(out[i], fb->rgb[i], 1e-6 * fb->rgb[i]);
	for (int y = 0; y < H; y++)
		for (int x = 0; x < W; x++)
			if (x * 3 + y > 50)
				set_pixel(fb, y * W + x, 0.05f, 0.04f, 0.03f);
	assert_true(denoise_image(fb, out, 2));
	for (int i = 0; i < W * H * 3; i++)
		assert_near(out[i], fb->rgb[i], 1e-6 * fb->rgb[i]);
	/* out may be the picture itself */
	float keep = fb->rgb[0];
	assert_true(denoise_image(fb, fb->rgb, 3));
	assert_near(fb->rgb[0], keep, 1e-6 * keep);
	free(out);
	fb_free(fb);
}

/* Fills pixel i of fb with spp grey samples (the same in r, g and b) drawn
 * from mean + sigma * a uniform variable of variance 1, as a render job
 * records them: the mean of all, of the even ones, and of their squares. */
static void noisy_pixel(framebuffer *fb, int i, double mean, double sigma, test_rng *r)
{
	double all = 0, even = 0, sq = 0, sq_even = 0;
	for (int k = 0; k < fb->spp; k++) {
		double v = mean + sigma * sqrt(12.0) * (trand(r) - 0.5);
		all += v;
		sq += v * v;
		if (!(k & 1)) {
			even += v;
			sq_even += v * v;
		}
	}
	int ne = (fb->spp + 1) / 2;
	float *f = fb->feat + (size_t)i * DENOISE_FEATURES;
	for (int c = 0; c < 3; c++) {
		fb->rgb[i * 3 + c] = (float)(all / fb->spp);
		f[10 + c] = (float)(even / ne);
	}
	f[7] = (float)(sq / fb->spp);
	f[13] = (float)(sq_even / ne);
}

/* A flat grey surface, 8 samples of known noise a pixel: away from the
 * border, the regression fits a plane to the 81 pixels of its 9x9 window
 * (the features are all alike, so every weight is one), and the value of
 * a least-squares plane at the centre of a symmetric window is the mean of
 * the window. Its error is therefore the noise of the pixel mean,
 * sigma / sqrt(8), over sqrt(81): 9x smaller than the raw pixels'. */
static void test_flat_noise(void **state)
{
	(void)state;
	const int W = 64, H = 48, SPP = 8;
	const double MEAN = 0.4, SIGMA = 0.2;
	framebuffer *fb = flat_fb(W, H, SPP);
	test_rng r = {27};
	for (int i = 0; i < W * H; i++)
		noisy_pixel(fb, i, MEAN, SIGMA, &r);
	float *out = malloc(sizeof(float) * W * H * 3);
	assert_non_null(out);
	assert_true(denoise_image(fb, out, 2));
	double se_raw = 0, se_dn = 0;
	int n = 0;
	for (int y = 4; y < H - 4; y++)
		for (int x = 4; x < W - 4; x++) {
			int i = y * W + x;
			se_raw += (fb->rgb[i * 3] - MEAN) * (fb->rgb[i * 3] - MEAN);
			se_dn += (out[i * 3] - MEAN) * (out[i * 3] - MEAN);
			n++;
		}
	double raw = sqrt(se_raw / n), dn = sqrt(se_dn / n);
	double expect_raw = SIGMA / sqrt(SPP), expect_dn = expect_raw / 9.0;
	print_message("flat grey, sigma %.2f a sample, 8 samples: RMS error raw %.5f (expected %.5f), "
	              "denoised %.5f (expected %.5f)\n",
	              SIGMA, raw, expect_raw, dn, expect_dn);
	assert_true(fabs(raw / expect_raw - 1.0) < 0.1); /* the synthetic noise is as stated */
	/* Windows overlap, so the interior's 2240 pixels hold far fewer
	 * independent errors: 25% either way. */
	assert_true(dn < 1.25 * expect_dn);
	assert_true(dn > 0.75 * expect_dn);
	free(out);
	fb_free(fb);
}

/* An edge in the features (albedo 0.8 left of x = 32, 0.2 right of it,
 * the same lighting 0.5 everywhere): no tap crosses it (the albedo
 * distance makes its weight zero), so the columns next to it keep their
 * own side's radiance, 0.4 and 0.1, within the filtered noise; a blur
 * across it would pull them towards 0.25. Each side's error is also
 * checked against the flat case's: the edge's pixels see half a window. */
static void test_feature_edge(void **state)
{
	(void)state;
	const int W = 64, H = 48, SPP = 8;
	const double SIGMA = 0.1;
	framebuffer *fb = flat_fb(W, H, SPP);
	test_rng r = {12};
	for (int y = 0; y < H; y++)
		for (int x = 0; x < W; x++) {
			int i = y * W + x;
			float a = x < W / 2 ? 0.8f : 0.2f;
			float *f = fb->feat + (size_t)i * DENOISE_FEATURES;
			f[0] = f[1] = f[2] = a;
			noisy_pixel(fb, i, 0.5 * a, SIGMA * a, &r);
		}
	float *out = malloc(sizeof(float) * W * H * 3);
	assert_non_null(out);
	assert_true(denoise_image(fb, out, 2));
	for (int side = 0; side < 2; side++) {
		int x = side ? W / 2 : W / 2 - 1;
		double truth = side ? 0.1 : 0.4, s = 0, se = 0;
		for (int y = 4; y < H - 4; y++) {
			double v = out[(y * W + x) * 3];
			s += v;
			se += (v - truth) * (v - truth);
		}
		int n = H - 8;
		double mean = s / n, rms = sqrt(se / n);
		/* the raw pixel's noise: SIGMA * albedo / sqrt(8) */
		double noise = SIGMA * (side ? 0.2 : 0.8) / sqrt(SPP);
		print_message("column %d next to the edge: mean %.4f (true %.2f), RMS error %.4f (raw noise %.4f)\n",
		              x, mean, truth, rms, noise);
		assert_true(fabs(mean - truth) < 0.5 * noise);
		assert_true(rms < 0.5 * noise);
	}
	free(out);
	fb_free(fb);
}

/* Highlights a few pixels wide: a flat surface of albedo 0.5 with 12 5x5
 * blocks of albedo 1 (a glossy metal's highlight: so unlike their
 * surroundings that a tap across has a weight of (1 - 9.375 / 16)^16 =
 * 7e-7, none to speak of; SIGMA_A2), 14 pixels apart, whose direct light
 * peaks as a highlight does: 8 at the centre, halved at each step out (4,
 * 2, 1, 0.5 at city-block distance 1 to 4); the radiance is the direct
 * light, with noise 2 a sample (variance 4 / 8 of a pixel's mean), 8
 * samples. Each block's pixel p then has the 25 taps t of its block, of
 * weight w_t = exp_fast(DIRECT_W dd_t^2), dd_t = (d_t - d_p) / (0.5 d_p +
 * 0.05) (the direct light's weight; 1 for every tap before it). A
 * weighted least-squares line in the direct light (what the direct
 * light's fit is: a constant and dd's slope, held back by DIRECT_RIDGE x
 * sum w) gives sum_t h_t y_t at p, h_t = w_t (z0 + z1 dd_t), (z0, z1) =
 * M^-1 (1, 0), M = sum_t w_t (1, dd_t)^T (1, dd_t) plus the ridge; its
 * expected squared error is (sum h_t d_t - d_p)^2 + 4 / 8 sum h_t^2
 * (the radiance is linear in the direct light: the bias is the ridge's).
 * Computed below for the 25 pixels: RMS 0.2925 (with equal weights it
 * is 2 / sqrt(8) x sqrt(2 / 25) = 0.200, and the regression on all the
 * features, a constant, x, y and the direct light, 0.283 then, 0.407
 * now); the raw pixels 0.707. The choice among the candidates by their
 * noisy error estimates adds to it (the blend with the whole fit; and
 * averaged over the pixels of alike direct light, fewer, the estimates
 * are noisier): within 20% of the line (0.324 with the direct light in
 * the regression's weights alone, 0.348 in the choice's too). */
static double exp_fast_def(double x)
{
	double t = 1.0 - x / 16.0;
	t = t > 0 ? t : 0;
	return pow(t, 16);
}

static double highlight_line_rms(int B)
{
	const double W = 1.0, RIDGE_D = 1e-2, VAR = 4.0 / 8.0; /* DIRECT_W, DIRECT_RIDGE, the pixel's noise */
	double se = 0;
	for (int p = 0; p < B * B; p++) {
		double dp = 8.0 / (1 << (abs(p % B - B / 2) + abs(p / B - B / 2)));
		double sc = 1.0 / (0.5 * dp + 0.05), m00 = 0, m01 = 0, m11 = 0;
		for (int t = 0; t < B * B; t++) {
			double dd = (8.0 / (1 << (abs(t % B - B / 2) + abs(t / B - B / 2))) - dp) * sc;
			double w = exp_fast_def(W * dd * dd);
			m00 += w;
			m01 += w * dd;
			m11 += w * dd * dd;
		}
		m11 += RIDGE_D * m00;
		double det = m00 * m11 - m01 * m01, z0 = m11 / det, z1 = -m01 / det;
		double fit = 0, var = 0;
		for (int t = 0; t < B * B; t++) {
			double dt = 8.0 / (1 << (abs(t % B - B / 2) + abs(t / B - B / 2))), dd = (dt - dp) * sc;
			double h = exp_fast_def(W * dd * dd) * (z0 + z1 * dd);
			fit += h * dt;
			var += h * h * VAR;
		}
		se += (fit - dp) * (fit - dp) + var;
	}
	return sqrt(se / (B * B));
}

static void test_highlight_blocks(void **state)
{
	(void)state;
	const int W = 72, H = 62, SPP = 8, B = 5, GAP = 14, NB = 12;
	const double SIG = 2.0, LO = 0.1;
	framebuffer *fb = flat_fb(W, H, SPP);
	test_rng r = {5};
	for (int y = 0; y < H; y++)
		for (int x = 0; x < W; x++) {
			int i = y * W + x;
			float *f = fb->feat + (size_t)i * DENOISE_FEATURES;
			int bx = (x - 10) % GAP, by = (y - 10) % GAP;
			bool hi = x >= 10 && x < 10 + 3 * GAP + B && bx < B && y >= 10 && y < 10 + 2 * GAP + B && by < B;
			double d = LO;
			if (hi) {
				/* the peak: 8 at the centre, halved at each step out */
				int off = abs(bx - B / 2) + abs(by - B / 2);
				d = 8.0 / (1 << off);
				f[0] = f[1] = f[2] = 1.0f;
			}
			f[14] = (float)d;
			noisy_pixel(fb, i, d, hi ? SIG : 0.05, &r);
		}
	float *out = malloc(sizeof(float) * W * H * 3);
	assert_non_null(out);
	assert_true(denoise_image(fb, out, 2));
	double se_dn = 0, se_raw = 0;
	int n = 0;
	for (int i = 0; i < W * H; i++) {
		const float *f = fb->feat + (size_t)i * DENOISE_FEATURES;
		if (f[0] != 1.0f)
			continue;
		se_dn += (out[i * 3] - f[14]) * (out[i * 3] - f[14]);
		se_raw += (fb->rgb[i * 3] - f[14]) * (fb->rgb[i * 3] - f[14]);
		n++;
	}
	assert_int_equal(n, NB * B * B);
	double dn = sqrt(se_dn / n), raw = sqrt(se_raw / n), want = highlight_line_rms(B);
	print_message("highlight blocks: RMS error raw %.4f (expected %.4f), denoised %.4f (expected %.4f, "
	              "the weighted line in the direct light)\n",
	              raw, SIG / sqrt(SPP), dn, want);
	assert_near(want, 0.2925, 1e-4);
	assert_true(dn < 1.2 * want);
	free(out);
	fb_free(fb);
}

/* A rough metal reflecting the horizon: one surface (albedo 0.5, the same
 * normal and depth everywhere), vertical stripes every 12 columns of a
 * dark band 3 wide (direct light over albedo 0.1, radiance 0.3), with 2
 * columns each side of a mid tone (0.55, 0.9), in a bright rest (1, 1):
 * the radiance is no line in the direct light. Noise 0.5 a sample, 8
 * samples. At a band pixel a tap of the mid tone is 0.45 / (0.5 x 0.1 +
 * 0.05) = 4.5 off in the direct-light regressor, of the rest 9: DIRECT_W
 * x 4.5^2 = 20.25 >= 16, so exp_fast gives them no weight at all, the
 * fits are over the band's own taps, whose radiance is a constant plus
 * noise: every candidate is unbiased, and the band's mean comes out 0.3
 * but for noise (the band's 288 pixels' mean of 8 samples each: 0.5 /
 * sqrt(8 x 288) = 0.010). Without that weight all 81 taps count alike: at
 * the band's centre 18 of the rest, 36 of the mid tone, 27 of the band,
 * whose least-squares line in the direct light (mean direct light 40.5 /
 * 81 = 0.5, radiance 58.5 / 81 = 0.7222, slope 7.38 / 8.91 = 0.8283) is
 * 0.7222 - 0.4 x 0.8283 = 0.391 at the band: 0.09 too bright, and the
 * fits' estimated error (0.09^2 + a little noise) beats the raw pixel's
 * (0.5^2 / 8), so the fits were taken (the old code: 0.359). */
static void test_direct_weight_band(void **state)
{
	(void)state;
	const int W = 48, H = 24, SPP = 8;
	framebuffer *fb = flat_fb(W, H, SPP);
	test_rng r = {11};
	for (int y = 0; y < H; y++)
		for (int x = 0; x < W; x++) {
			int i = y * W + x, o = abs(x % 12 - 6);
			float *f = fb->feat + (size_t)i * DENOISE_FEATURES;
			double d = o <= 1 ? 0.1 : o <= 3 ? 0.55 : 1.0, v = o <= 1 ? 0.3 : o <= 3 ? 0.9 : 1.0;
			f[14] = (float)(d * 0.5); /* over the albedo 0.5: d */
			noisy_pixel(fb, i, v, 0.5, &r);
		}
	float *out = malloc(sizeof(float) * W * H * 3);
	assert_non_null(out);
	assert_true(denoise_image(fb, out, 2));
	double s = 0;
	int n = 0;
	for (int y = 0; y < H; y++)
		for (int x = 0; x < W; x++)
			if (abs(x % 12 - 6) <= 1) {
				s += out[(y * W + x) * 3];
				n++;
			}
	assert_int_equal(n, 288);
	print_message("the dark band's mean: %.4f (true 0.3; one line over all the taps 0.391)\n", s / n);
	assert_true(fabs(s / n - 0.3) < 0.03);
	free(out);
	fb_free(fb);
}

/* A 3x3 block whose samples all agree, 1 at the centre and 0.2 around it,
 * in a surface of radiance 1 with noise 0.5 a sample, 8 samples; `mark`
 * sets a pixel's features (in the block or not). Asserts the denoised
 * centre keeps its value, 1. */
static void check_peak_kept(unsigned seed, void (*mark)(float *f, bool block))
{
	const int W = 40, H = 32, X = 20, Y = 16, SPP = 8;
	framebuffer *fb = flat_fb(W, H, SPP);
	test_rng r = {seed};
	for (int y = 0; y < H; y++)
		for (int x = 0; x < W; x++) {
			int i = y * W + x;
			bool block = abs(x - X) <= 1 && abs(y - Y) <= 1;
			mark(fb->feat + (size_t)i * DENOISE_FEATURES, block);
			if (block) {
				float v = x == X && y == Y ? 1.0f : 0.2f;
				set_pixel(fb, i, v, v, v);
			} else {
				noisy_pixel(fb, i, 1.0, 0.5, &r);
			}
		}
	float *out = malloc(sizeof(float) * W * H * 3);
	assert_non_null(out);
	assert_true(denoise_image(fb, out, 2));
	int c = Y * W + X;
	print_message("the block's centre: %.4f (its samples 1; the block's mean %.4f)\n", out[c * 3], 2.6 / 9);
	for (int k = 0; k < 3; k++)
		assert_near(out[c * 3 + k], 1.0, 1e-5);
	free(out);
	fb_free(fb);
}

/* A highlight's peak that no feature explains, in a noisy surface: a 3x3
 * block of albedo 1 (so unlike the surface's 0.2 that no regression tap
 * crosses) whose samples all agree, 1 at its centre and 0.2 around it, in
 * a surface of radiance 1 with noise 0.5 a sample (8 samples). At the
 * centre both regressions are the block's mean (the taps are the block's
 * 9, all of weight one, symmetric about it: no slope), (1 + 8 x 0.2) / 9 =
 * 0.2889, and their estimated error is 0.711^2, while the raw pixel's is 0
 * (its halves agree and have no noise) and exact. Averaged over the 9x9
 * pixels around it alike, the surface's 72 raw estimates (0.5^2 / 8 each
 * on average, 2.25 in all) outweigh the block's fits' (0.57) and the
 * surface's fits' (about 8 / 81 of its raw ones, 0.22), and the centre took
 * the fits' 0.2889; weighted by how alike the albedo is (the surface's by
 * exp(-0.25 x 3 x 0.8^2 / 0.08) = exp(-6), as exp_fast has it (1 - 6/16)^16
 * = 5.4e-4), they count for 0.001, and it keeps its value, 1. */
static void albedo_mark(float *f, bool block)
{
	f[0] = f[1] = f[2] = block ? 1.0f : 0.2f;
}

static void test_pick_own_surface(void **state)
{
	(void)state;
	check_peak_kept(31, albedo_mark);
}

/* The same peak told apart by its direct light alone: a 3x3 block of the
 * surface's albedo (0.5) and direct light 0.1 (over the albedo) in a
 * surface of direct light 1, whose samples all agree, 1 at the centre
 * and 0.2 around it (radiance); the surface 1 with noise 0.5 a sample, 8
 * samples. From the block's pixels a surface pixel is (1 - 0.1) / (0.5 x
 * 0.1 + 0.05) = 9 off in the direct-light regressor: in the regression
 * DIRECT_W x 81 >= 16 and in the choice's average PICK_SCALE x DIRECT_W x
 * 81 = 20.25 >= 16, no weight in either (exp_fast). So at the centre the
 * fits are the block's 9 taps' mean, (1 + 8 x 0.2) / 9 = 0.2889, their
 * estimated error 0.711^2, and only the block's estimates are averaged:
 * the raw pixels' are 0 (their halves agree, no noise), and it keeps its
 * value, 1. Without the direct light in the choice's weights all 81
 * estimates count alike, the surface's 72 raw ones (0.5^2 / 8 each on
 * average, 2.25) outweigh the fits' (0.57 of the block's, about 0.22 of
 * the surface's: test_pick_own_surface), and the centre took 0.2889. */
static void direct_mark(float *f, bool block)
{
	f[14] = block ? 0.05f : 0.5f; /* over the albedo 0.5: 0.1 and 1 */
}

static void test_pick_direct_light(void **state)
{
	(void)state;
	check_peak_kept(37, direct_mark);
}

/* The same picture for 1, 2, 3 and 7 threads, byte for byte, with 1, 3
 * and 8 samples. */
static void test_threads(void **state)
{
	(void)state;
	scene *s = load_text("C 0,1,-4 0,-0.2,1 60\nA 0.5 200,220,255\n"
	                     "pl 0,0,0 0,1,0 200,200,200\nsp 0,1,0 2 220,60,50\n"
	                     "sp 1.5,0.5,-1 0,1,0 1,1,1 255,255,255 0 0 1 1\n");
	world *w = world_build(s, NULL);
	assert_non_null(w);
	/* 1 sample (no halves), 3 (halves of one and two samples) and 8 */
	const int spps[] = {1, 3, 8};
	for (int s_i = 0; s_i < 3; s_i++) {
		render_settings set = path_settings(53, 31, spps[s_i], 4, 3);
		framebuffer *fb = fb_new(53, 31);
		assert_non_null(fb);
		assert_true(denoise_prepare(fb));
		render_job job = {.w = w, .set = set, .fb = fb, .sample_begin = 0, .sample_end = spps[s_i]};
		assert_int_equal(render_run(&job, NULL), RENDER_DONE);
		size_t n = (size_t)fb->w * fb->h * 3;
		float *one = malloc(n * sizeof *one), *many = malloc(n * sizeof *many);
		assert_non_null(one);
		assert_non_null(many);
		assert_true(denoise_image(fb, one, 1));
		const int threads[] = {2, 3, 7};
		for (int k = 0; k < 3; k++) {
			assert_true(denoise_image(fb, many, threads[k]));
			assert_memory_equal(one, many, n * sizeof *one);
		}
		free(one);
		free(many);
		fb_free(fb);
	}
	world_free(w);
	scene_free(s);
}

/* The features through a mirror are those of the surface seen in it: the
 * camera at the origin looks along +z at a mirror at z = 2; behind the
 * camera a wall at z = -3 faces it. The centre pixel sees the wall's
 * albedo, its normal (0,0,1) and the depth 2 + 5 = 7; without the mirror
 * (a white wall at z = 2) the features are that wall's at depth 2. A white
 * metal of fuzz 0.1 (Phong exponent 5 / 0.1^2 - 2 = 498, at least 200) is
 * looked through as the mirror is (its Schlick tint at normal incidence is
 * its colour, white); one of fuzz 0.5 (exponent 18) shows itself: albedo
 * its tint, white. */
static void test_features_through_mirror(void **state)
{
	(void)state;
	const char *texts[4] = {
		"C 0,0,0 0,0,1 10\npl 0,0,2 0,0,-1 1,1,1 255,255,255 0 0 1 1\n"
		"pl 0,0,-3 0,0,1 1,1,1 180,100,50 1 0 1 0\n",
		"C 0,0,0 0,0,1 10\npl 0,0,2 0,0,-1 1,1,1 255,255,255 1 0 1 0\n",
		"C 0,0,0 0,0,1 10\npl 0,0,2 0,0,-1 1,1,1 255,255,255 0 0 1 1 metal=1 fuzz=0.1\n"
		"pl 0,0,-3 0,0,1 1,1,1 180,100,50 1 0 1 0\n",
		"C 0,0,0 0,0,1 10\npl 0,0,2 0,0,-1 1,1,1 255,255,255 0 0 1 1 metal=1 fuzz=0.5\n"
		"pl 0,0,-3 0,0,1 1,1,1 180,100,50 1 0 1 0\n",
	};
	vec3 wall = srgb255_to_linear(v3(180, 100, 50));
	vec3 albedo[4] = {wall, v3(1, 1, 1), wall, v3(1, 1, 1)};
	const double normal_z[4] = {1, -1, 1, -1}, depth[4] = {7, 2, 7, 2};
	for (int c = 0; c < 4; c++) {
		double f[DENOISE_ACC];
		centre_features(texts[c], 1, f);
		assert_near(f[0], albedo[c].x, 1e-5);
		assert_near(f[1], albedo[c].y, 1e-5);
		assert_near(f[2], albedo[c].z, 1e-5);
		assert_near(f[5], normal_z[c], 1e-3);
		assert_near(f[6], depth[c], 1e-3);
	}
}

/* Glass looked through: a clear glass plane (ior 1.5) at z = 2 facing the
 * camera at the origin, an orange Lambertian wall behind it at z = 4. At
 * normal incidence the glass reflects F = ((1.5 - 1) / (1.5 + 1))^2 = 0.04
 * of the light (Fresnel) and passes the rest, so the centre pixel's albedo
 * feature is 0.96 x the wall's plus 0.04 of a white reflection; the normal
 * and depth are the wall's (the refracted ray goes straight on). */
static void test_features_through_glass(void **state)
{
	(void)state;
	double f[DENOISE_ACC];
	centre_features("C 0,0,0 0,0,1 10\npl 0,0,2 0,0,-1 1,1,1 255,255,255 0 0 1 0 ior=1.5\n"
	                "pl 0,0,4 0,0,-1 1,1,1 180,100,50 1 0 1 0\n",
	                1, f);
	vec3 wall = srgb255_to_linear(v3(180, 100, 50));
	const double F = 0.04;
	assert_near(f[0], (1 - F) * wall.x + F, 1e-4);
	assert_near(f[1], (1 - F) * wall.y + F, 1e-4);
	assert_near(f[2], (1 - F) * wall.z + F, 1e-4);
	assert_near(f[5], -1.0, 1e-3);
	assert_near(f[6], 4.0, 1e-3);
}

/* A clear glass sphere (ior 1.5, radius 1, centre (0, 0, 4)) in front of
 * the wall of test_features_through_glass, now at z = 8: the centre ray
 * enters it at z = 3 and leaves at z = 5, both at normal incidence, where
 * F = ((1.5 - 1) / (1.5 + 1))^2 = 0.04 either way. Entering, F joins the
 * albedo as a white reflection's (0.04) and the rest goes on tinted 0.96;
 * leaving, F is reflected back inside the sphere and is no surface's
 * albedo: the wall's tint is 0.96 x 0.96 = 0.9216 and the albedo
 * 0.9216 x the wall's + 0.04 (the old code added the inner reflection as
 * white too: + 0.96 x 0.04 = 0.0384 more). The normal and depth are the
 * wall's: -z and 8. */
static void test_features_through_glass_sphere(void **state)
{
	(void)state;
	double f[DENOISE_ACC];
	centre_features("C 0,0,0 0,0,1 10\nsp 0,0,4 0,1,0 1,1,1 255,255,255 0 0 1 0 ior=1.5\n"
	                "pl 0,0,8 0,0,-1 1,1,1 180,100,50 1 0 1 0\n",
	                1, f);
	vec3 wall = srgb255_to_linear(v3(180, 100, 50));
	const double F = 0.04, T = (1 - F) * (1 - F);
	print_message("through the sphere: %.6f %.6f %.6f (want %.6f %.6f %.6f)\n", f[0], f[1], f[2], T * wall.x + F,
	              T * wall.y + F, T * wall.z + F);
	assert_near(f[0], T * wall.x + F, 1e-4);
	assert_near(f[1], T * wall.y + F, 1e-4);
	assert_near(f[2], T * wall.z + F, 1e-4);
	assert_near(f[5], -1.0, 1e-3);
	assert_near(f[6], 8.0, 1e-3);
}

/* The sky's albedo feature is its colour in that direction: a uniform sky
 * of radiance 0.5 seen directly gives 0.5; through the clear glass plane
 * of test_features_through_glass, with nothing behind, 0.96 x 0.5 of the
 * sky and 0.04 of a white reflection: 0.52; in a white mirror plane at
 * z = 2 (the ray comes back along -z to the open sky) 0.5. Its depth: 0
 * seen directly; through the glass or in the mirror the distance to the
 * last surface the ray left, the plane's 2 (the sky there is that
 * surface's light, not the open sky's: the filter must not mix them). */
static void test_sky_feature(void **state)
{
	(void)state;
	const char *texts[3] = {
		"C 0,0,0 0,0,1 10\nsky 255,255,255 255,255,255 0.5\n",
		"C 0,0,0 0,0,1 10\nsky 255,255,255 255,255,255 0.5\npl 0,0,2 0,0,-1 1,1,1 255,255,255 0 0 1 0 ior=1.5\n",
		"C 0,0,0 0,0,1 10\nsky 255,255,255 255,255,255 0.5\npl 0,0,2 0,0,-1 1,1,1 255,255,255 0 0 1 1\n",
	};
	const double want[3] = {0.5, 0.96 * 0.5 + 0.04, 0.5}, depth[3] = {0.0, 2.0, 2.0};
	for (int c = 0; c < 3; c++) {
		double f[DENOISE_ACC];
		centre_features(texts[c], 1, f);
		for (int k = 0; k < 3; k++)
			assert_near(f[k], want[c], 1e-4);
		assert_near(f[6], depth[c], 1e-6);
	}
}

/* The sky seen through glass has the glass's normal where the ray entered
 * it: a clear glass sphere (ior 1.5) of diameter 2 centred at (0.5, 0, 4),
 * nothing behind it. The centre ray (0, 0, 1) meets it where
 * (0 - 0.5)^2 + (z - 4)^2 = 1, z = 4 - sqrt(0.75), and its outward normal
 * there is ((0, 0, z) - (0.5, 0, 4)) / 1 = (-0.5, 0, -sqrt(0.75)); the
 * refracted ray meets the back face at 32 degrees from its normal (below
 * the critical 41.8) and leaves to the sky. The old code gave the sky no
 * normal, (0, 0, 0). The same sphere before a wall keeps the wall's normal
 * (0, 0, -1): only the sky takes the glass's. */
static void test_sky_through_glass_normal(void **state)
{
	(void)state;
	double f[DENOISE_ACC];
	centre_features("C 0,0,0 0,0,1 10\nsp 0.5,0,4 0,1,0 2,2,2 255,255,255 0 0 1 0 ior=1.5\n", 1, f);
	print_message("sky through the sphere: normal %.6f %.6f %.6f (want -0.5 0 %.6f)\n", f[3], f[4], f[5],
	              -sqrt(0.75));
	assert_near(f[3], -0.5, 1e-6);
	assert_near(f[4], 0.0, 1e-6);
	assert_near(f[5], -sqrt(0.75), 1e-6);
	centre_features("C 0,0,0 0,0,1 10\nsp 0.5,0,4 0,1,0 2,2,2 255,255,255 0 0 1 0 ior=1.5\n"
	                "pl 0,0,8 0,0,-1 1,1,1 255,255,255 1 0 1 0\n",
	                1, f);
	assert_near(f[3], 0.0, 1e-6);
	assert_near(f[4], 0.0, 1e-6);
	assert_near(f[5], -1.0, 1e-6);
}

/* Glass's reflection in the direct-light feature: the clear glass plane of
 * test_features_through_glass (ior 1.5, at z = 2 facing the camera) under a
 * uniform sky of radiance 0.5, nothing behind it. The refracted ray meets
 * only the sky (no direct light there); the glass reflects F = 0.04 at
 * normal incidence, and its mirror direction (-z, back past the camera)
 * sees the open sky: 0.04 x 0.5 = 0.02 a sample (the old code: 0). No sky
 * and no ambient: 0. A white wall behind the camera at z = -1 facing it:
 * the reflection meets the wall, which sees along its normal (+z) only the
 * glass, no sky: 0. */
static void test_glass_reflection_feature(void **state)
{
	(void)state;
	const char *glass = "C 0,0,0 0,0,1 10\npl 0,0,2 0,0,-1 1,1,1 255,255,255 0 0 1 0 ior=1.5\n";
	const char *extra[3] = {"sky 255,255,255 255,255,255 0.5\n", "A 0 255,255,255\n",
	                        "sky 255,255,255 255,255,255 0.5\npl 0,0,-1 0,0,1 1,1,1 255,255,255 1 0 1 0\n"};
	const double want[3] = {0.02, 0.0, 0.0};
	for (int c = 0; c < 3; c++) {
		char text[512];
		snprintf(text, sizeof text, "%s%s", glass, extra[c]);
		double f[DENOISE_ACC];
		centre_features(text, DENOISE_FEATURE_SAMPLES, f);
		print_message("glass reflection, case %d: %.6f (want %.6f)\n", c, f[7] / DENOISE_FEATURE_SAMPLES, want[c]);
		assert_near(f[7] / DENOISE_FEATURE_SAMPLES, want[c], 1e-6);
	}
}

/* The direct-light feature (acc[7]): a white Lambertian wall at z = 2
 * facing the camera at the origin, a point light of ratio 0.5 at (0, 1, 0).
 * The centre pixel's ray meets the wall at (0, 0, 2); the light is seen
 * from there along (0, 1, -2) / sqrt 5, at cos 2 / sqrt 5 to the normal:
 * albedo 1 / pi x (pi x 0.5) x cos = 0.5 x 2 / sqrt 5 (rtsh(5): a white
 * Lambertian surface facing a light sends back ratio x colour). A small
 * sphere at (0, 0.5, 1), between the two and off the camera ray, puts the
 * point in its shadow: 0. */
static void test_direct_feature(void **state)
{
	(void)state;
	const char *texts[2] = {
		"C 0,0,0 0,0,1 10\nL 0,1,0 0.5 255,255,255\npl 0,0,2 0,0,-1 1,1,1 255,255,255 1 0 1 0\n",
		"C 0,0,0 0,0,1 10\nL 0,1,0 0.5 255,255,255\npl 0,0,2 0,0,-1 1,1,1 255,255,255 1 0 1 0\n"
		"sp 0,0.5,1 0.2 255,255,255\n",
	};
	const double want[2] = {0.5 * 2.0 / sqrt(5.0), 0.0};
	for (int c = 0; c < 2; c++) {
		double f[DENOISE_ACC];
		centre_features(texts[c], 1, f);
		assert_near(f[7], want[c], 1e-4);
		assert_near(f[6], 2.0, 1e-4); /* the wall, not the sphere */
		/* sample 0 is even: its albedo is also the even samples' */
		assert_near(f[10], f[0], 1e-12);
	}
}

/* The sky's part of the direct-light feature: the first
 * DENOISE_FEATURE_SAMPLES samples of a pixel take ENV_DIRS each of one set
 * of 32 cosine-distributed directions, so their mean is that set's
 * estimate of the light the sky sends through the surface. A white
 * Lambertian wall at z = 2 faces the camera at the origin, no lamp:
 * - a uniform sky of radiance 0.5: every direction sees 0.5, and a white
 *   Lambertian surface sends back albedo / pi x pi x 0.5 = 0.5, exactly;
 * - a sky black at the horizon and white at the zenith, radiance
 *   max(0, d.y): the cosine-weighted mean of max(0, y) over the hemisphere
 *   about -z is half the mean of |y| over the unit disc (Malley's method:
 *   the tangent coordinates are uniform on the disc), 1/2 x 4 / (3 pi) =
 *   2 / (3 pi), to the set's quadrature error (32 points: 0.01);
 * - the uniform sky with an infinite white floor at y = -0.5: the
 *   directions below the horizon (half of them) meet the floor, which sees
 *   the sky along its normal (+y): albedo 1 x 0.5 each, and the sky 0.5
 *   in the others: 0.5 in all, exactly (blocked and nothing more: 0.25);
 * - no sky and no ambient: 0, and no shadow ray is traced;
 * - a white metal of fuzz 0.3 instead of the wall (Phong exponent
 *   5 / 0.3^2 - 2 = 53.6: not looked through) under the uniform sky: the
 *   directions are drawn from its lobe about the mirror direction, here
 *   the normal, each weighed by f cos / pdf = (n + 2) / (n + 1) cos, whose
 *   mean over the lobe is 1 (the lobe's mean cosine is (n + 1) / (n + 2)),
 *   times the tint 1 (white): 0.5, to the set's quadrature (0.01). Fixed
 *   cosine-distributed directions would put one or two of the 32 in a lobe
 *   some 10 degrees wide;
 * - the zenith sky max(0, d.y) with the white floor: 2 / (3 pi) from the
 *   directions above the horizon as without it, and the half below (the
 *   cosine-weighted share of the directions with y < 0 is 1/2) meets the
 *   floor, which sees radiance 1 along +y: 2 / (3 pi) + 0.5, to 0.01;
 * - the uniform sky, the floor and a white roof at y = 0.5: every
 *   direction meets the floor or the roof, and each of those sees the
 *   other along its normal, no sky: 0, exactly (without the normal's
 *   shadow ray: 0.5). */
static void test_env_feature(void **state)
{
	(void)state;
	const char *cam = "C 0,0,0 0,0,1 10\n", *lambert = "pl 0,0,2 0,0,-1 1,1,1 255,255,255 1 0 1 0\n";
	const char *ground = "pl 0,-0.5,0 0,1,0 1,1,1 255,255,255 1 0 1 0\n";
	const char *surface[7] = {lambert, lambert, lambert, lambert,
	                          "pl 0,0,2 0,0,-1 1,1,1 255,255,255 0 0 1 1 metal=1 fuzz=0.3\n", lambert, lambert};
	const char *extra[7] = {
		"sky 255,255,255 255,255,255 0.5\n",
		"sky 255,255,255 0,0,0 1\n",
		"sky 255,255,255 255,255,255 0.5\n",
		"A 0 255,255,255\n",
		"sky 255,255,255 255,255,255 0.5\n",
		"sky 255,255,255 0,0,0 1\n",
		"sky 255,255,255 255,255,255 0.5\npl 0,0.5,0 0,-1,0 1,1,1 255,255,255 1 0 1 0\n",
	};
	const bool floored[7] = {false, false, true, false, false, true, true};
	const double want[7] = {0.5, 2.0 / (3.0 * M_PI), 0.5, 0.0, 0.5, 2.0 / (3.0 * M_PI) + 0.5, 0.0};
	const double tol[7] = {1e-9, 0.01, 1e-9, 0.0, 0.01, 0.01, 0.0};
	for (int c = 0; c < 7; c++) {
		char text[512];
		snprintf(text, sizeof text, "%s%s%s%s", cam, surface[c], extra[c], floored[c] ? ground : "");
		double f[DENOISE_ACC];
		centre_features(text, DENOISE_FEATURE_SAMPLES, f);
		print_message("sky feature, case %d: %.6f (want %.6f)\n", c, f[7] / DENOISE_FEATURE_SAMPLES, want[c]);
		assert_near(f[7] / DENOISE_FEATURE_SAMPLES, want[c], tol[c]);
		assert_near(f[6] / DENOISE_FEATURE_SAMPLES, 2.0, 1e-9);
	}
}

/* A lamp seen through a glossy lobe: a white metal of fuzz 0.05 (Phong
 * exponent 5 / 0.05^2 - 2 = 1998, looked through as a mirror is,
 * test_features_through_mirror) at z = 2 facing the camera at the origin, a
 * lamp of radiance 5 (a sphere of radius 2.5 at z = -5, behind the camera):
 * the reflected centre ray meets the lamp at z = -2.5. Through the fuzz the
 * lamp is blurred, so the features are the metal's own: albedo white,
 * normal -z, depth 2. Through a perfect mirror the lamp is sharp: its
 * emission is the albedo (far from any surface's), depth 2 + 4.5 = 6.5.
 * The glossy metal's direct light then holds the lamp as its lobe sees it:
 * the lamp covers 20.9 degrees about the mirror direction (sin = 2.5 / 7);
 * the lobe sends all but cos(20.9 deg)^1999 (nothing) of its directions
 * there, each with the weight f cos / pdf of a white metal, between 1 and
 * (n + 2) / (n + 1) = 1.0005 times the tint 1 (the cosine within a degree
 * or two of the normal): 5, to 1 %. 32 points on the lamp weighed by the
 * lobe instead are too far apart for a lobe a degree or two wide. */
static void test_lamp_through_glossy(void **state)
{
	(void)state;
	const char *texts[2] = {
		"C 0,0,0 0,0,1 10\npl 0,0,2 0,0,-1 1,1,1 255,255,255 0 0 1 1 metal=1 fuzz=0.05\n"
		"sp 0,0,-5 0,1,0 5,5,5 255,255,255 0 0 1 0 emit=5\n",
		"C 0,0,0 0,0,1 10\npl 0,0,2 0,0,-1 1,1,1 255,255,255 0 0 1 1\n"
		"sp 0,0,-5 0,1,0 5,5,5 255,255,255 0 0 1 0 emit=5\n",
	};
	const double albedo[2] = {1, 5}, normal_z[2] = {-1, 1}, depth[2] = {2, 6.5};
	for (int c = 0; c < 2; c++) {
		double f[DENOISE_ACC];
		centre_features(texts[c], 1, f);
		for (int k = 0; k < 3; k++)
			assert_near(f[k], albedo[c], 1e-5);
		assert_near(f[5], normal_z[c], 1e-3);
		assert_near(f[6], depth[c], 1e-3);
		if (c == 0) {
			centre_features(texts[c], DENOISE_FEATURE_SAMPLES, f);
			assert_near(f[7] / DENOISE_FEATURE_SAMPLES, 5.0, 0.05);
		}
	}
}

/* An edge pixel's highlight in a glossy metal is a mean over the same 64
 * camera positions as its albedo: a checkered white metal of fuzz 0.05
 * (looked through, test_lamp_through_glossy) at z = 2.5 facing the camera
 * at the origin, and behind the camera a lamp of radiance 5 that fills its
 * lobe about every mirror direction of the centre pixel, no sky. At each
 * position the metal's features are its own (the lamp is blurred by the
 * lobe) and its direct light is the lamp through the lobe, 5 x the
 * metal's tint there (its colour at normal incidence, to 1%,
 * test_lamp_through_glossy): so over any positions the direct light is 5
 * x the brightness of the mean albedo over the same positions. The centre
 * pixel of 9 at 10 degrees (0.049 units wide there) straddles the
 * checker's corner at the origin, a quarter of a pixel off its centre
 * (its features vary), so its albedo is the mean over 64 positions; the
 * direct light of the first 8 alone would be off by their share of each
 * square. */
static void test_edge_direct_feature(void **state)
{
	(void)state;
	scene *s = load_text("C 0.012,0.007,0 0,0,1 10\nA 0 255,255,255\n"
	                     "pl 0,0,2.5 0,0,-1 1,1,1 255,255,255 0 0 1 1 metal=1 fuzz=0.05 checker=1\n"
	                     "sp 0,0,-5 0,1,0 5,5,5 255,255,255 0 0 1 0 emit=5\n");
	world *w = world_build(s, NULL);
	assert_non_null(w);
	render_settings set = path_settings(9, 9, 8, 3, 5);
	framebuffer *fb = fb_new(9, 9);
	assert_true(fb && denoise_prepare(fb));
	render_job job = {.w = w, .set = set, .fb = fb, .sample_begin = 0, .sample_end = 8};
	assert_int_equal(render_run(&job, NULL), RENDER_DONE);
	const float *f = fb->feat + (size_t)(4 * 9 + 4) * DENOISE_FEATURES;
	double a = 0.2126 * f[0] + 0.7152 * f[1] + 0.0722 * f[2];
	double a2 = (double)f[0] * f[0] + (double)f[1] * f[1] + (double)f[2] * f[2];
	assert_true(f[8] - a2 > 1e-3); /* an edge: its albedo varies */
	print_message("edge pixel: mean albedo brightness %.4f, direct light %.4f (expected %.4f)\n", a, f[14], 5 * a);
	assert_near(f[14], 5 * a, 0.01 * 5 * a);
	fb_free(fb);
	world_free(w);
	scene_free(s);
}

/* A pixel whose features say it is a mix of two surfaces but whose
 * samples all agree (all of them fell on one side: noise variance 0) still
 * gets the mix its features say: the mixed-pixel step's limit takes the
 * noise of its 3x3 window as a floor. Left of x = 16 albedo 0.8 and
 * radiance 0.4, right of it 0.2 and 0.1 (lighting 0.5), each sample
 * uniformly noisy (sd 0.3); the pixel (16, 12) has the features of half of
 * each (albedo 0.5 and its spread) and 8 samples of exactly 0.4. The step
 * fits its window's outputs linearly in the albedo by least squares (the
 * only feature that varies; a ridge of 1e-3 of the taps), so its value is
 * that line at 0.5: computed here from the outputs of its 8 neighbours
 * (which the step leaves as they are) and the pixel's own value before the
 * step (the same picture with its albedo's spread taken away, so that it
 * is no mixed pixel). With a variance of 0 the old limit kept that value. */
/* The picture of test_mixed_pixel_agreeing_samples, its neighbours'
 * samples of standard deviation sigma: the output (red) of the mixed pixel
 * (16, 12) with the mixed-pixel step (*after), without it (*before: its
 * albedo's spread taken away), the window's least-squares line at its
 * albedo 0.5 (*line), and the step's floor of the noise, the mean over the
 * 3x3 window of each pixel's variance of its mean in radiance (*var):
 * (mean of the squares - square of the mean) / (n - 1) a pixel, from the
 * picture's own sums (the centre's 0). */
static void mixed_pixel_case(double sigma, double *after, double *before, double *line, double *var)
{
	const int W = 32, H = 24, X = 16, Y = 12, SPP = 8;
	float *out[2];
	double vsum = 0;
	for (int pass = 0; pass < 2; pass++) {
		framebuffer *fb = flat_fb(W, H, SPP);
		test_rng r = {7};
		for (int y = 0; y < H; y++)
			for (int x = 0; x < W; x++) {
				int i = y * W + x;
				float *f = fb->feat + (size_t)i * DENOISE_FEATURES;
				float a = x < X ? 0.8f : 0.2f;
				if (x == X && y == Y) {
					a = 0.5f;
					set_pixel(fb, i, 0.4f, 0.4f, 0.4f);
				} else {
					noisy_pixel(fb, i, 0.5 * a, sigma, &r);
				}
				f[0] = f[1] = f[2] = a;
				/* the mean squared albedo: the mixed pixel's of half 0.8,
				 * half 0.2 (features_vary), unless taken away */
				f[8] = x == X && y == Y && pass == 0 ? 1.5f * (0.64f + 0.04f) : 3 * a * a;
				f[9] = f[6] * f[6];
				if (pass == 0 && abs(x - X) <= 1 && abs(y - Y) <= 1) {
					double m = fb->rgb[i * 3], q = (double)f[7] - m * m;
					vsum += (q > 0 ? q : 0) / (SPP - 1);
				}
			}
		out[pass] = malloc(sizeof(float) * W * H * 3);
		assert_non_null(out[pass]);
		assert_true(denoise_image(fb, out[pass], 2));
		fb_free(fb);
	}
	/* the least-squares line through the window's (albedo, output) */
	double sa = 0, sr = 0, saa = 0, sar = 0;
	int n = 0;
	for (int dy = -1; dy <= 1; dy++)
		for (int dx = -1; dx <= 1; dx++) {
			int x = X + dx, i = (Y + dy) * W + x;
			double a = dx == 0 && dy == 0 ? 0.5 : x < X ? 0.8 : 0.2;
			double v = dx == 0 && dy == 0 ? out[1][i * 3] : out[0][i * 3];
			sa += a;
			sr += v;
			saa += a * a;
			sar += a * v;
			n++;
		}
	double slope = (sar - sa * sr / n) / (saa - sa * sa / n);
	int c = Y * W + X;
	*line = sr / n + slope * (0.5 - sa / n);
	*after = out[0][c * 3];
	*before = out[1][c * 3];
	*var = vsum / 9;
	free(out[0]);
	free(out[1]);
}

static void test_mixed_pixel_agreeing_samples(void **state)
{
	(void)state;
	double after, before, line, var;
	mixed_pixel_case(0.3, &after, &before, &line, &var);
	print_message("mixed pixel, samples all 0.4: before the step %.4f, after %.4f (the window's line at 0.5: "
	              "%.4f)\n",
	              before, after, line);
	assert_true(fabs(before - line) > 0.05);
	assert_near(after, line, 0.01);
}

/* The same picture with quieter neighbours (sd 0.09 a sample): the line
 * now lies further from the pixel than 1.345 standard deviations of the
 * noise of a pixel's mean (the window's, the pixel's own being 0), and the
 * step moves it by exactly that much towards the line, Huber's clip; the
 * old limit, 3 standard deviations, let it go all the way. */
static void test_mixed_pixel_huber_clip(void **state)
{
	(void)state;
	double after, before, line, var;
	mixed_pixel_case(0.09, &after, &before, &line, &var);
	double sd = sqrt(var), lim = 1.345 * sd;
	double expect = before + (line < before ? -lim : lim);
	print_message("mixed pixel, neighbours sd 0.09: before the step %.4f, after %.4f; the line at 0.5 %.4f, "
	              "the noise's sd %.4f: clipped at %.4f\n",
	              before, after, line, sd, expect);
	/* the clip acts under the rule, and would not at 3 sd */
	assert_true(fabs(line - before) > lim + 0.005);
	assert_true(fabs(line - before) < 3 * sd - 0.005);
	assert_near(after, expect, 1e-4);
}

/* An edge that none of the first DENOISE_FEATURE_SAMPLES camera positions
 * meets, but that covers a corner of the pixel (DENOISE_PROBE_INSET inside
 * it), makes the pixel an edge pixel: its features are the mean over all
 * DENOISE_EDGE_SAMPLES positions. The centre pixel of 9 at 10 degrees
 * looks at a white plane at z = 5; a black triangle at z = 2.5 covers the
 * half-plane beyond a straight edge, placed from the positions themselves
 * (render_sample_ray and the corners' cam_ray, where their rays cross
 * z = 2.5): across the direction u (of 72 tried) along which a corner and
 * one of the 64 positions lie farthest beyond the first eight, half-way.
 * So the first eight all see the plane, and the pixel's albedo must be the
 * plane's less the share covered: the positions beyond the edge, counted.
 * Before the corners were looked at it was the plane's alone. */
static void test_probe_edge(void **state)
{
	(void)state;
	const char *plane = "C 0,0,0 0,0,1 10\nA 0.5 255,255,255\npl 0,0,5 0,0,-1 255,255,255\n";
	render_settings set = path_settings(9, 9, 8, 2, 5);
	scene *s0 = load_text(plane);
	world *w0 = world_build(s0, NULL);
	assert_non_null(w0);
	/* the 64 positions, then the 4 corners */
	double px[DENOISE_EDGE_SAMPLES + 4], py[DENOISE_EDGE_SAMPLES + 4];
	for (int k = 0; k < DENOISE_EDGE_SAMPLES + 4; k++) {
		int c = k - DENOISE_EDGE_SAMPLES;
		double u = c & 1 ? 1 - DENOISE_PROBE_INSET : DENOISE_PROBE_INSET;
		double v = c & 2 ? 1 - DENOISE_PROBE_INSET : DENOISE_PROBE_INSET;
		ray r = c < 0 ? render_sample_ray(w0, &set, 4, 4, 9, 9, k) : cam_ray(&w0->cam, 4 + u, 4 + v, 9, 9);
		px[k] = r.o.x + (2.5 - r.o.z) / r.d.z * r.d.x;
		py[k] = r.o.y + (2.5 - r.o.z) / r.d.z * r.d.y;
	}
	world_free(w0);
	scene_free(s0);
	double best_gap = 0, ux = 1, uy = 0, d0 = 0;
	for (int a = 0; a < 72; a++) {
		double cx = cos(a * (2 * M_PI / 72)), cy = sin(a * (2 * M_PI / 72));
		double hi8 = -INFINITY, hi64 = -INFINITY, hic = -INFINITY;
		for (int k = 0; k < DENOISE_EDGE_SAMPLES + 4; k++) {
			double d = px[k] * cx + py[k] * cy;
			if (k < DENOISE_FEATURE_SAMPLES)
				hi8 = fmax(hi8, d);
			else if (k < DENOISE_EDGE_SAMPLES)
				hi64 = fmax(hi64, d);
			else
				hic = fmax(hic, d);
		}
		double gap = fmin(hi64, hic) - hi8;
		if (gap > best_gap) {
			best_gap = gap;
			ux = cx;
			uy = cy;
			d0 = hi8 + 0.5 * gap;
		}
	}
	assert_true(best_gap > 0);
	int covered = 0;
	for (int k = 0; k < DENOISE_EDGE_SAMPLES; k++)
		covered += px[k] * ux + py[k] * uy > d0;
	/* the edge through d0 u along (-uy, ux), the third corner beyond it;
	 * moved back by 1 (text_all) it covers the whole pixel */
	char text[512], text_all[512];
	for (int m = 0; m < 2; m++) {
		double e = m == 0 ? d0 : d0 - 1;
		snprintf(m == 0 ? text : text_all, sizeof text, "%str %.9f,%.9f,2.5 %.9f,%.9f,2.5 %.9f,%.9f,2.5 0,0,0\n",
		         plane, e * ux - 10 * uy, e * uy + 10 * ux, e * ux + 10 * uy, e * uy - 10 * ux, (e + 20) * ux,
		         (e + 20) * uy);
	}
	/* the two surfaces' albedos, each seen alone */
	double fp[DENOISE_ACC], ft[DENOISE_ACC];
	centre_features(plane, 1, fp);
	centre_features(text_all, 1, ft);
	scene *s = load_text(text);
	world *w = world_build(s, NULL);
	assert_non_null(w);
	framebuffer *fb = fb_new(9, 9);
	assert_true(fb && denoise_prepare(fb));
	render_job job = {.w = w, .set = set, .fb = fb, .sample_begin = 0, .sample_end = 8};
	assert_int_equal(render_run(&job, NULL), RENDER_DONE);
	const float *f = fb->feat + (size_t)(4 * 9 + 4) * DENOISE_FEATURES;
	double share = (double)covered / DENOISE_EDGE_SAMPLES, expect = fp[0] * (1 - share) + ft[0] * share;
	print_message("edge across (%.3f, %.3f), %d of %d positions beyond it; albedo %.4f plane, %.4f triangle: "
	              "%.5f, expected %.5f\n",
	              ux, uy, covered, DENOISE_EDGE_SAMPLES, fp[0], ft[0], f[0], expect);
	assert_true(covered > 0 && covered < DENOISE_EDGE_SAMPLES);
	assert_true(fabs(fp[0] - ft[0]) > 0.25);
	assert_near(f[0], expect, 1e-5);
	fb_free(fb);
	world_free(w);
	scene_free(s);
}

/* Features recorded in passes equal those of one pass, and mean the first
 * DENOISE_FEATURE_SAMPLES samples; the mean square covers every sample. */
static void test_features_in_passes(void **state)
{
	(void)state;
	scene *s = load_text("C 0,1,-4 0,-0.2,1 60\nA 0.5 200,220,255\n"
	                     "pl 0,0,0 0,1,0 200,200,200\nsp 0,1,0 2 220,60,50\n");
	world *w = world_build(s, NULL);
	assert_non_null(w);
	render_settings set = path_settings(17, 11, 20, 3, 5);
	framebuffer *a = fb_new(17, 11), *b = fb_new(17, 11);
	assert_true(a && b && denoise_prepare(a) && denoise_prepare(b));
	render_job job = {.w = w, .set = set, .fb = a, .sample_begin = 0, .sample_end = 20};
	assert_int_equal(render_run(&job, NULL), RENDER_DONE);
	const int cut[] = {0, 1, 3, 9, 20};
	job.fb = b;
	for (int k = 0; k + 1 < 5; k++) {
		job.sample_begin = cut[k];
		job.sample_end = cut[k + 1];
		assert_int_equal(render_run(&job, NULL), RENDER_DONE);
	}
	for (int i = 0; i < 17 * 11 * DENOISE_FEATURES; i++)
		assert_near(a->feat[i], b->feat[i], 1e-5 * (1 + fabsf(a->feat[i])));
	fb_free(a);
	fb_free(b);
	world_free(w);
	scene_free(s);
}

/* The adaptive budget's rule (denoise_allocate), derived by hand. Every
 * pixel's noise gets a thousandth of the mean noise added (f), and the
 * pixels get clamp(l (sigma + f), first, cap) samples, l such that they
 * sum to mean x n; the pairs above first are rounded by their running sum.
 * (a) sigma 0, 1, 2, 3, 0.5, 10, first 4, mean 8, cap 32: f = 16.5 / 6 /
 * 1000 = 0.00275; pixels 0, 1 and 4 stay at 4 (l (1 + f) < 4), so
 * 12 + l (2 + 3 + 10 + 3f) = 48, l = 36 / 15.00825 = 2.39868: 4.80396,
 * 7.20264 and 23.99340 samples, pairs above 4: 0.40198, 1.60132, 9.99670;
 * running sums 0, 0, 0.40198, 2.00330, 2.00330, 12 round to 0, 0, 0, 2,
 * 2, 12: samples 4, 4, 4, 8, 4, 24 (48 in all).
 * (b) sigma 100, 1, 1, 1, first 4, mean 8, cap 16: pixel 0 is clamped to
 * 16; the other three share 32 - 16 equally, 5.333 each, 0.667 pairs:
 * running sums 6, 6.667, 7.333, 8 round to 6, 7, 7, 8: 16, 6, 4, 6.
 * (c) no noise anywhere: every pixel the mean, 8. */
static void test_allocate_rule(void **state)
{
	(void)state;
	uint16_t out[6];
	const float a[6] = {0, 1, 2, 3, 0.5f, 10};
	denoise_allocate(a, 6, 4, 8, 32, out);
	const uint16_t ea[6] = {4, 4, 4, 8, 4, 24};
	assert_memory_equal(out, ea, sizeof ea);
	const float b[4] = {100, 1, 1, 1};
	denoise_allocate(b, 4, 4, 8, 16, out);
	const uint16_t eb[4] = {16, 6, 4, 6};
	assert_memory_equal(out, eb, sizeof eb);
	const float c[5] = {0};
	denoise_allocate(c, 5, 4, 8, 32, out);
	for (int i = 0; i < 5; i++)
		assert_int_equal(out[i], 8);
	/* a larger map: the total, evenness and the bounds */
	enum { N = 1000 };
	static float big[N];
	static uint16_t nb[N];
	for (int i = 0; i < N; i++)
		big[i] = (float)((i * 7919) % 101) * (i % 13 == 0 ? 50.0f : 1.0f);
	denoise_allocate(big, N, 4, 8, 64, nb);
	long total = 0;
	for (int i = 0; i < N; i++) {
		assert_true(nb[i] >= 4 && nb[i] <= 64 && nb[i] % 2 == 0);
		total += nb[i];
	}
	assert_int_equal(total, 8 * N);
}

/* A pixel of DENOISE_OWN_TIMES (4) times the mean samples or more chooses
 * by its own error estimates. A flat grey surface (radiance 0.4, 8 samples
 * of noise 0.2 a pixel, mean 8) holds three pixels of brightness 0.7 whose
 * halves agree (samples of variance 0.01): P1 and P2 (P2's features vary:
 * a mixed pixel) of 32 samples, P3 of 30. At each, the fit is about the
 * window's mean, 0.4 + 0.3 / 81, off by 0.3: its own cross-half estimate
 * about 0.3^2 = 0.09; the raw pixel's about -0.01 / 16 (its halves agree;
 * less their noise). So P1 and P2 keep 0.7 (the albedo 0.5 divided out
 * and in again: exactly), and no mixed step moves P2. Averaged over the
 * window, as P3's (30 < 32) still are, 80 raw estimates of about
 * 0.2^2 / 8 (sum 0.4) lose to the fit's (0.09 and 80 of about
 * 0.2^2 / 8 / 81): P3 comes out near 0.4. Before the rule P1 and P2 did
 * too. */
static void test_own_estimates(void **state)
{
	(void)state;
	const int W = 48, H = 24, SPP = 8, Y = 12;
	const int px[3] = {8, 24, 40}, own[3] = {32, 32, 30};
	framebuffer *fb = flat_fb(W, H, SPP);
	fb->pixel_spp = malloc((size_t)W * H * sizeof *fb->pixel_spp);
	assert_non_null(fb->pixel_spp);
	test_rng r = {11};
	for (int i = 0; i < W * H; i++) {
		fb->pixel_spp[i] = SPP;
		noisy_pixel(fb, i, 0.4, 0.2, &r);
	}
	for (int k = 0; k < 3; k++) {
		int i = Y * W + px[k];
		fb->pixel_spp[i] = (uint16_t)own[k];
		set_pixel(fb, i, 0.7f, 0.7f, 0.7f);
		float *f = fb->feat + (size_t)i * DENOISE_FEATURES;
		f[7] = f[13] = 0.49f + 0.01f;
		if (k == 1) { /* mixed: its albedo varies inside it */
			f[8] = 3 * 0.25f + 0.1f;
			f[9] = f[6] * f[6];
		}
	}
	float *out = malloc(sizeof(float) * W * H * 3);
	assert_non_null(out);
	assert_true(denoise_image(fb, out, 2));
	for (int k = 0; k < 3; k++)
		print_message("pixel %d, %d samples: %.5f\n", k + 1, own[k], out[(Y * W + px[k]) * 3]);
	for (int c = 0; c < 3; c++) {
		assert_float_equal(out[(Y * W + px[0]) * 3 + c], 0.7f, 1e-6);
		assert_float_equal(out[(Y * W + px[1]) * 3 + c], 0.7f, 1e-6);
		assert_true(fabs(out[(Y * W + px[2]) * 3 + c] - (0.4 + 0.3 / 81)) < 0.05);
	}
	free(out);
	fb_free(fb);
}

/* The noise that decides a pixel's samples is the mean over its 3x3
 * window, its own included: a 3x3 image of 4 samples a pixel, grey 0.5
 * (brightness 0.5), each pixel's mean squared brightness 0.25 + v 3/4, so
 * that its unbiased variance, (mean square - mean^2) 4/3, is v. v = 1..9
 * row by row: the centre (v 5) gets the root of the mean of all nine,
 * sqrt(45 / 9); the corner (0, 0) of itself and its three neighbours 1, 2,
 * 4, 5: sqrt(12 / 4) (the old rule, its neighbours alone, gave sqrt(11 /
 * 3)). Its own v raised to 1000 raises it: sqrt((40 + 1000) / 9) for the
 * centre, and the corner, a neighbour of it, sqrt((1 + 2 + 4 + 1000) / 4).
 * (A pixel whose first samples met a rare bright path, a firefly, had
 * none of its own: its neighbours got them, and it kept the firefly.) */
static void test_sigma_neighbours(void **state)
{
	(void)state;
	framebuffer *fb = fb_new(3, 3);
	assert_non_null(fb);
	assert_true(denoise_prepare(fb));
	fb->spp = 4;
	for (int i = 0; i < 9; i++) {
		for (int k = 0; k < 3; k++) {
			fb->rgb[i * 3 + k] = 0.5f;
			fb->sum[i * 3 + k] = 2.0; /* 4 samples of 0.5 */
			fb->feat[i * DENOISE_FEATURES + k] = 0.5f; /* albedo */
		}
		fb->feat[i * DENOISE_FEATURES + 6] = 3.0f; /* depth: a surface */
		fb->feat[i * DENOISE_FEATURES + 7] = 0.25f + (float)(i + 1) * 0.75f;
	}
	float sg[9];
	assert_true(denoise_sigma(fb, sg));
	assert_near(sg[4], sqrt(45.0 / 9), 1e-5);
	assert_near(sg[0], sqrt(12.0 / 4), 1e-5);
	fb->feat[4 * DENOISE_FEATURES + 7] = 0.25f + 1000.0f * 0.75f;
	float s2[9];
	assert_true(denoise_sigma(fb, s2));
	assert_near(s2[4], sqrt(1040.0 / 9), 1e-4);
	assert_near(s2[0], sqrt(1007.0 / 4), 1e-4);
	/* A pixel that missed the scene (depth 0) or sees a lamp (albedo 2)
	 * is fixed and its noise, not known, counts for no pixel, not even as
	 * 0: pixel 1 (v 2) missing, the corner's window holds 1, 4 and 5:
	 * sqrt(10 / 3); pixel 3 (v 4) a lamp too, 1 and 5: sqrt(6 / 2); the
	 * centre's 45 - 2 - 4 = 39 over 7. */
	fb->feat[4 * DENOISE_FEATURES + 7] = 0.25f + 5.0f * 0.75f;
	fb->feat[1 * DENOISE_FEATURES + 6] = 0.0f;
	assert_true(denoise_fixed(fb->feat + 1 * DENOISE_FEATURES));
	assert_false(denoise_fixed(fb->feat + 0 * DENOISE_FEATURES));
	assert_true(denoise_sigma(fb, s2));
	assert_near(s2[0], sqrt(10.0 / 3), 1e-5);
	fb->feat[3 * DENOISE_FEATURES + 1] = 2.0f;
	assert_true(denoise_fixed(fb->feat + 3 * DENOISE_FEATURES));
	assert_true(denoise_sigma(fb, s2));
	assert_near(s2[0], sqrt(6.0 / 2), 1e-5);
	assert_near(s2[4], sqrt(39.0 / 7), 1e-5);
	/* pixel 4 a lamp too: the corner has its own noise left, sqrt(1) */
	fb->feat[4 * DENOISE_FEATURES + 1] = 2.0f;
	assert_true(denoise_sigma(fb, s2));
	assert_near(s2[0], 1.0, 1e-5);
	/* The sky seen in a glossy metal: depth 0, but a direct light (the
	 * lamps the lobe sees, feature 14): not fixed, and pixel 1's v 2
	 * counts for the corner again: sqrt((1 + 2) / 2). */
	fb->feat[1 * DENOISE_FEATURES + 14] = 2.0f;
	assert_false(denoise_fixed(fb->feat + 1 * DENOISE_FEATURES));
	assert_true(denoise_sigma(fb, s2));
	assert_near(s2[0], sqrt(3.0 / 2), 1e-5);
	fb_free(fb);
}

/* A small image of surface pixels (depth 3), albedo a[i] in every channel,
 * direct light 0 and 6 samples of grey 0.5 whose variance is 1. */
static framebuffer *reach_image(int w, int h, const float *a)
{
	framebuffer *fb = fb_new(w, h);
	assert_non_null(fb);
	assert_true(denoise_prepare(fb));
	fb->spp = 6;
	for (int i = 0; i < w * h; i++) {
		float *f = fb->feat + i * DENOISE_FEATURES;
		for (int k = 0; k < 3; k++) {
			fb->rgb[i * 3 + k] = 0.5f;
			fb->sum[i * 3 + k] = 3.0; /* 6 samples of 0.5 */
			f[k] = a[i];
			f[3 + k] = k == 2 ? 1.0f : 0.0f; /* normal +z */
		}
		f[6] = 3.0f;
		/* mean square 0.25 + 5/6: variance (0.25 + 5/6 - 0.25) 6/5 = 1 */
		f[7] = 0.25f + 5.0f / 6.0f;
	}
	return fb;
}

/* How much of a pixel's noise the filter passes on (denoise_reach), by
 * hand: the sum over the pixels whose window holds it of its share of
 * their fit, squared.
 * (a) 3x3 alike pixels: every window holds all nine at weight 1, so each
 *     pixel is 1/9 of nine fits: 9 / 81 = 1/9.
 * (b) the centre's albedo 0.9 among 0.1: its squared distance 3 x 0.8^2 /
 *     0.08 = 24 is past the weight's end (16): its fit is itself alone
 *     (reach 1), each other pixel 1/8 of eight fits (8 / 64).
 * (c) 2x1, albedo 0.5, direct light 0.1 and 0.2 (over the albedo d 0.2
 *     and 0.4): pixel 0 weighs pixel 1 by (1 - dd^2 / 16)^16 with dd =
 *     0.2 / (0.5 x 0.2 + 0.05) = 4/3: u = (1 - 1/9)^16 = 0.151901; pixel
 *     1 weighs pixel 0 with dd = 0.2 / 0.25 = 0.8: v = 0.96^16 = 0.520403.
 *     reach 0 = (1 / (1 + u))^2 + (v / (1 + v))^2 = 0.870806, reach 1 =
 *     (u / (1 + u))^2 + (1 / (1 + v))^2 = 0.449986. */
static void test_reach(void **state)
{
	(void)state;
	float r[9];
	const float flat[9] = {0.1f, 0.1f, 0.1f, 0.1f, 0.1f, 0.1f, 0.1f, 0.1f, 0.1f};
	framebuffer *fb = reach_image(3, 3, flat);
	assert_true(denoise_reach(fb, r));
	for (int i = 0; i < 9; i++)
		assert_near(r[i], 1.0 / 9, 1e-6);
	fb_free(fb);
	const float spot[9] = {0.1f, 0.1f, 0.1f, 0.1f, 0.9f, 0.1f, 0.1f, 0.1f, 0.1f};
	fb = reach_image(3, 3, spot);
	assert_true(denoise_reach(fb, r));
	for (int i = 0; i < 9; i++)
		assert_near(r[i], i == 4 ? 1.0 : 1.0 / 8, 1e-6);
	fb_free(fb);
	const float two[2] = {0.5f, 0.5f};
	fb = reach_image(2, 1, two);
	fb->feat[14] = 0.1f;
	fb->feat[DENOISE_FEATURES + 14] = 0.2f;
	assert_true(denoise_reach(fb, r));
	double u = pow(1 - 1.0 / 9, 16), v = pow(0.96, 16);
	assert_near(u, 0.151901, 1e-6);
	assert_near(v, 0.520403, 1e-6);
	assert_near(r[0], 1 / ((1 + u) * (1 + u)) + v * v / ((1 + v) * (1 + v)), 1e-5);
	assert_near(r[1], u * u / ((1 + u) * (1 + u)) + 1 / ((1 + v) * (1 + v)), 1e-5);
	assert_near(r[0], 0.870806, 1e-5);
	assert_near(r[1], 0.449986, 1e-5);
	fb_free(fb);
}

/* The allocation takes the filtered noise: (b)'s image above, every
 * pixel's noise 1 (its 3x3 window's mean variance), 6 samples each and 8
 * on average (72 in all). The eight alike pixels' reach is 1/8, their
 * weight 8^-DENOISE_REACH_POW = 8^-0.375 = 0.45850, the centre's 1: l (1
 * + 8 x 0.45850) = 72 (the thousandth of the mean added is below the
 * rounding), l = 15.424: the centre 15.42 samples, 4.71 pairs above 6,
 * the others 7.07, 0.536 pairs; their running sums 0.536, 1.073, 1.609,
 * 2.146, 6.856, 7.392, 7.928, 8.464, 9 round to 1, 1, 2, 2, 7, 7, 8, 8,
 * 9 pairs: 8 6 8 6 16 6 8 6 8. (Without the reach every pixel got 8.) */
static void test_reach_allocation(void **state)
{
	(void)state;
	assert_true(DENOISE_REACH_POW == 0.375);
	const float spot[9] = {0.1f, 0.1f, 0.1f, 0.1f, 0.9f, 0.1f, 0.1f, 0.1f, 0.1f};
	framebuffer *fb = reach_image(3, 3, spot);
	float sg[9];
	assert_true(denoise_sigma(fb, sg));
	for (int i = 0; i < 9; i++)
		assert_near(sg[i], 1.0, 1e-5);
	assert_int_equal(render_adaptive_counts(fb, 8, 6, NULL), 16);
	const uint16_t want[9] = {8, 6, 8, 6, 16, 6, 8, 6, 8};
	assert_memory_equal(fb->pixel_spp, want, sizeof want);
	fb_free(fb);
}

/* The adaptive pass continues each pixel's own sequence: a first pass of 4
 * samples, then every pixel to 8 through render_job.pixel_end, holds the
 * bits of 8 samples in one pass (the same sums in the same order); pixels
 * ended at 4 and 6 keep their 4 or 6 samples' mean (a 4- or 6-sample render's
 * bits), and their features are still made over the first 8 positions (as
 * the 8-sample render's, to float rounding), the albedo at their radiance
 * samples' own positions (15-20) over their own 4 or 6. */
static void test_adaptive_pass(void **state)
{
	(void)state;
	scene *s = load_text("C 0,1,-4 0,-0.2,1 60\nA 0.5 200,220,255\nL 2,4,-2 0.7 255,255,255\n"
	                     "pl 0,0,0 0,1,0 200,200,200\nsp 0,1,0 2 220,60,50\nsp -1.2,0.4,-1.5 0.4 40,40,240\n");
	world *w = world_build(s, NULL);
	assert_non_null(w);
	enum { W = 19, H = 13, N = W * H };
	render_settings set = path_settings(W, H, 8, 3, 11);
	framebuffer *ref[3];
	const int spp[3] = {4, 6, 8};
	for (int k = 0; k < 3; k++) {
		ref[k] = fb_new(W, H);
		assert_true(ref[k] && denoise_prepare(ref[k]));
		render_job job = {.w = w, .set = set, .fb = ref[k], .sample_begin = 0, .sample_end = spp[k]};
		assert_int_equal(render_run(&job, NULL), RENDER_DONE);
	}
	framebuffer *fb = fb_new(W, H);
	assert_true(fb && denoise_prepare(fb));
	render_job job = {.w = w, .set = set, .fb = fb, .sample_begin = 0, .sample_end = 4};
	assert_int_equal(render_run(&job, NULL), RENDER_DONE);
	uint16_t end[N];
	for (int i = 0; i < N; i++)
		end[i] = (uint16_t)spp[i % 3];
	job.sample_begin = 4;
	job.sample_end = 8;
	job.pixel_end = end;
	assert_int_equal(render_run(&job, NULL), RENDER_DONE);
	for (int i = 0; i < N; i++) {
		const framebuffer *r = ref[i % 3], *r8 = ref[2];
		assert_memory_equal(fb->rgb + i * 3, r->rgb + i * 3, 3 * sizeof *fb->rgb);
		const float *f = fb->feat + (size_t)i * DENOISE_FEATURES;
		const float *f8 = r8->feat + (size_t)i * DENOISE_FEATURES, *fr = r->feat + (size_t)i * DENOISE_FEATURES;
		for (int q = 0; q < DENOISE_FEATURES; q++) {
			/* the features of the 8 positions; of the radiance, and
			 * the albedo at its own positions, of the pixel's samples */
			bool own = q == 7 || (q >= 10 && q <= 13) || (q >= 15 && q <= 20);
			float e = own ? fr[q] : f8[q];
			assert_near(f[q], e, 1e-5 * (1 + fabsf(e)));
		}
	}
	for (int k = 0; k < 3; k++)
		fb_free(ref[k]);
	fb_free(fb);
	world_free(w);
	scene_free(s);
}

/* The adaptive pass after a first pass made in one go or in several (the
 * shell's preview: passes as its time allows) gives the same counts and
 * the same raw image: the allocation reads the running sums (rgb and the
 * squared brightness, framebuffer.sum2), never the features' running
 * means in floats, nor rgb (the preview denoises it in place between its
 * passes: done here too). */
static void test_adaptive_after_passes(void **state)
{
	(void)state;
	scene *s;
	world *w = adaptive_world(&s);
	enum { W = 31, H = 19, N = W * H };
	render_settings set = path_settings(W, H, 12, 4, 5);
	int first = render_adaptive_first(12, true);
	assert_int_equal(first, 8);
	framebuffer *fb[2];
	for (int k = 0; k < 2; k++) {
		fb[k] = fb_new(W, H);
		assert_true(fb[k] && denoise_prepare(fb[k]));
		render_job job = {.w = w, .set = set, .fb = fb[k]};
		const int one[] = {0, 8}, several[] = {0, 1, 3, 8};
		const int *cut = k ? several : one, ncut = k ? 4 : 2;
		for (int c = 0; c + 1 < ncut; c++) {
			job.sample_begin = cut[c];
			job.sample_end = cut[c + 1];
			assert_int_equal(render_run(&job, NULL), RENDER_DONE);
			if (k)
				assert_true(denoise_image(fb[k], fb[k]->rgb, 2));
		}
		assert_int_equal(render_adaptive(&job, NULL), RENDER_DONE);
		assert_int_equal(fb[k]->spp, 12);
	}
	assert_memory_equal(fb[0]->pixel_spp, fb[1]->pixel_spp, N * sizeof *fb[0]->pixel_spp);
	assert_memory_equal(fb[0]->rgb, fb[1]->rgb, N * 3 * sizeof *fb[0]->rgb);
	fb_free(fb[0]);
	fb_free(fb[1]);
	world_free(w);
	scene_free(s);
}

/* rtsh-mpi's two passes on rectangles (render_rect_first, the counts from
 * the whole image's first pass, render_rect_adaptive) give each pixel the
 * bits a render job's two passes (render_run, render_adaptive) give it:
 * its mean, sums and features, rectangles of 1 pixel and of sides that do
 * not divide the image included (a pixel with fewer samples than
 * DENOISE_FEATURE_SAMPLES too: 3 samples, 2 first). */
static void test_adaptive_rects(void **state)
{
	(void)state;
	scene *s;
	world *w = adaptive_world(&s);
	enum { W = 29, H = 17, N = W * H };
	const int budgets[] = {3, 12};
	for (int b = 0; b < 2; b++) {
		render_settings set = path_settings(W, H, budgets[b], 4, 3);
		int first = render_adaptive_first(set.samples, true);
		assert_true(first < set.samples);
		framebuffer *job_fb = fb_new(W, H), *rect_fb = fb_new(W, H);
		assert_true(job_fb && rect_fb && denoise_prepare(job_fb) && denoise_prepare(rect_fb));
		render_job job = {.w = w, .set = set, .fb = job_fb, .sample_end = first};
		assert_int_equal(render_run(&job, NULL), RENDER_DONE);
		assert_int_equal(render_adaptive(&job, NULL), RENDER_DONE);
		/* the rectangles cover the image once: 1 x 1, 6 x 5 (not
		 * dividing 29 x 17), and what is left of each row band */
		const int rects[][4] = {{0, 0, 1, 1}, {1, 0, 7, 5}, {7, 0, 29, 5}, {0, 5, 6, 10}, {6, 5, 29, 10},
		                        {0, 10, 29, 17}, {0, 1, 1, 5}};
		enum { NR = sizeof rects / sizeof rects[0] };
		size_t covered = 0;
		for (int pass = 0; pass < 2; pass++) {
			if (pass == 1) {
				rect_fb->spp = first;
				assert_int_equal(render_adaptive_counts(rect_fb, set.samples, first, NULL) >= first, true);
				assert_memory_equal(rect_fb->pixel_spp, job_fb->pixel_spp, N * sizeof *rect_fb->pixel_spp);
			}
			for (int r = 0; r < NR; r++) {
				const int *q = rects[r];
				size_t rw = (size_t)(q[2] - q[0]), n = rw * (size_t)(q[3] - q[1]);
				double *sum = malloc(n * 3 * sizeof *sum);
				float *feat = malloc(n * DENOISE_FEATURES * sizeof *feat), *rgb = malloc(n * 3 * sizeof *rgb);
				uint16_t *end = malloc(n * sizeof *end);
				assert_true(sum && feat && rgb && end);
				for (size_t i = 0; i < n; i++) {
					size_t p = (size_t)(q[1] + (int)(i / rw)) * W + (size_t)q[0] + i % rw;
					if (pass == 1) {
						memcpy(sum + i * 3, rect_fb->sum + p * 3, 3 * sizeof *sum);
						memcpy(feat + i * DENOISE_FEATURES, rect_fb->feat + p * DENOISE_FEATURES,
						       DENOISE_FEATURES * sizeof *feat);
						end[i] = rect_fb->pixel_spp[p];
					}
				}
				if (pass == 0)
					render_rect_first(w, &set, q[0], q[1], q[2], q[3], first, sum, feat);
				else
					render_rect_adaptive(w, &set, q[0], q[1], q[2], q[3], first, end, sum, rgb, feat);
				for (size_t i = 0; i < n; i++) {
					size_t p = (size_t)(q[1] + (int)(i / rw)) * W + (size_t)q[0] + i % rw;
					memcpy(rect_fb->sum + p * 3, sum + i * 3, 3 * sizeof *sum);
					memcpy(rect_fb->feat + p * DENOISE_FEATURES, feat + i * DENOISE_FEATURES,
					       DENOISE_FEATURES * sizeof *feat);
					if (pass == 1)
						memcpy(rect_fb->rgb + p * 3, rgb + i * 3, 3 * sizeof *rgb);
					covered += pass == 0;
				}
				free(sum);
				free(feat);
				free(rgb);
				free(end);
			}
		}
		assert_int_equal(covered, N);
		assert_memory_equal(rect_fb->sum, job_fb->sum, N * 3 * sizeof *rect_fb->sum);
		assert_memory_equal(rect_fb->feat, job_fb->feat, N * DENOISE_FEATURES * sizeof *rect_fb->feat);
		assert_memory_equal(rect_fb->rgb, job_fb->rgb, N * 3 * sizeof *rect_fb->rgb);
		fb_free(job_fb);
		fb_free(rect_fb);
	}
	world_free(w);
	scene_free(s);
}

/* A denoised render (render_image, as save and batch output) of 8 samples
 * spends 8 x W x H in all, but not 8 in each pixel: at least
 * DENOISE_FIRST(8) = 6, even, at most DENOISE_CAP(8) = 128, and 8 where
 * the pixel is fixed (the background above the horizon); the same counts
 * and the same picture for 1, 2 and 7 threads. */
static void test_adaptive_render(void **state)
{
	(void)state;
	scene *s;
	world *w = adaptive_world(&s);
	enum { W = 37, H = 23, N = W * H };
	render_settings set = path_settings(W, H, 8, 4, 7);
	set.threads = 1;
	framebuffer *one = render_with(w, set, DENOISE_ON);
	assert_non_null(one->pixel_spp);
	assert_int_equal(one->spp, 8);
	long total = 0;
	int low = 0, high = 0, fixed = 0;
	assert_int_equal(DENOISE_FIRST(8), 6);
	/* the cap: 16 x 8 = 128; at the most samples an adaptive render
	 * takes, 16 x 4096 = 65536 would not fit a pixel's 16-bit count */
	assert_int_equal(DENOISE_CAP(8), 128);
	assert_int_equal(DENOISE_CAP(RENDER_ADAPTIVE_MAX), 65534);
	for (int i = 0; i < N; i++) {
		int n = one->pixel_spp[i];
		assert_true(n >= 6 && n <= 128 && n % 2 == 0);
		if (denoise_fixed(one->feat + (size_t)i * DENOISE_FEATURES)) {
			assert_int_equal(n, 8);
			fixed++;
		}
		total += n;
		low += n < 8;
		high += n > 8;
	}
	assert_int_equal(total, 8L * N);
	assert_true(low > 0 && high > 0 && fixed > 0);
	const int threads[] = {2, 7};
	for (int k = 0; k < 2; k++) {
		set.threads = threads[k];
		framebuffer *many = render_with(w, set, DENOISE_ON);
		assert_memory_equal(one->pixel_spp, many->pixel_spp, N * sizeof *one->pixel_spp);
		assert_memory_equal(one->rgb, many->rgb, N * 3 * sizeof *one->rgb);
		fb_free(many);
	}
	/* raw renders stay one pass of 8 in every pixel */
	framebuffer *raw = render_with(w, set, DENOISE_OFF);
	assert_null(raw->pixel_spp);
	fb_free(raw);
	fb_free(one);
	world_free(w);
	scene_free(s);
}

/* Whitted images are never touched, whatever the setting; path images only
 * with denoise on (render_image is what save and batch use). */
static void test_modes(void **state)
{
	(void)state;
	scene *s = load_text("C 0,1,-4 0,-0.2,1 60\nA 0.5 200,220,255\nL 2,4,-2 0.7 255,255,255\n"
	                     "pl 0,0,0 0,1,0 200,200,200\nsp 0,1,0 2 220,60,50\n");
	world *w = world_build(s, NULL);
	assert_non_null(w);
	render_settings set = path_settings(24, 16, 4, 3, 9);
	set.mode = MODE_WHITTED;
	framebuffer *off = render_with(w, set, DENOISE_OFF), *on = render_with(w, set, DENOISE_ON);
	assert_null(on->feat);
	assert_memory_equal(off->rgb, on->rgb, sizeof(float) * 24 * 16 * 3);
	fb_free(off);
	fb_free(on);
	set.mode = MODE_PATH;
	off = render_with(w, set, DENOISE_OFF);
	framebuffer *aut = render_with(w, set, DENOISE_AUTO);
	on = render_with(w, set, DENOISE_ON);
	assert_memory_equal(off->rgb, aut->rgb, sizeof(float) * 24 * 16 * 3);
	assert_memory_not_equal(off->rgb, on->rgb, sizeof(float) * 24 * 16 * 3);
	fb_free(off);
	fb_free(aut);
	fb_free(on);
	world_free(w);
	scene_free(s);
}

static void test_setting(void **state)
{
	(void)state;
	render_settings set = render_settings_default();
	assert_int_equal(set.denoise, DENOISE_AUTO);
	rt_error err;
	const setting_def *d = settings_find("denoise", &err);
	assert_non_null(d);
	const char *names[] = {"auto", "on", "off"};
	for (int i = 0; i < 3; i++) {
		assert_true(settings_set(&set, d, names[i], &err));
		assert_int_equal(set.denoise, i);
		char buf[16];
		settings_format(&set, d, buf, sizeof buf);
		assert_string_equal(buf, names[i]);
	}
	assert_false(settings_set(&set, d, "yes", &err));
	assert_string_equal(err.msg, "denoise \"yes\" is not valid; expected auto, on or off");
	assert_int_equal(set.denoise, DENOISE_OFF);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_cornell_rmse),
		cmocka_unit_test(test_edges),
		cmocka_unit_test(test_no_noise_no_change),
		cmocka_unit_test(test_flat_noise),
		cmocka_unit_test(test_feature_edge),
		cmocka_unit_test(test_highlight_blocks),
		cmocka_unit_test(test_direct_weight_band),
		cmocka_unit_test(test_pick_own_surface),
		cmocka_unit_test(test_pick_direct_light),
		cmocka_unit_test(test_threads),
		cmocka_unit_test(test_features_through_mirror),
		cmocka_unit_test(test_features_through_glass),
		cmocka_unit_test(test_sky_feature),
		cmocka_unit_test(test_features_through_glass_sphere),
		cmocka_unit_test(test_glass_reflection_feature),
		cmocka_unit_test(test_sky_through_glass_normal),
		cmocka_unit_test(test_direct_feature),
		cmocka_unit_test(test_env_feature),
		cmocka_unit_test(test_lamp_through_glossy),
		cmocka_unit_test(test_edge_direct_feature),
		cmocka_unit_test(test_probe_edge),
		cmocka_unit_test(test_mixed_pixel_agreeing_samples),
		cmocka_unit_test(test_mixed_pixel_huber_clip),
		cmocka_unit_test(test_features_in_passes),
		cmocka_unit_test(test_allocate_rule),
		cmocka_unit_test(test_sigma_neighbours),
		cmocka_unit_test(test_reach),
		cmocka_unit_test(test_reach_allocation),
		cmocka_unit_test(test_own_estimates),
		cmocka_unit_test(test_adaptive_pass),
		cmocka_unit_test(test_adaptive_render),
		cmocka_unit_test(test_adaptive_after_passes),
		cmocka_unit_test(test_adaptive_rects),
		cmocka_unit_test(test_modes),
		cmocka_unit_test(test_setting),
	};
	return cmocka_run_group_tests_name("denoise", tests, NULL, NULL);
}
