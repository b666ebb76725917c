/* rtsh — physics tests of the path tracer (path.c). Every expected value
 * comes from a definition or a law, never from the program's own output:
 *   - white furnace: a convex diffuse sphere of albedo a under a uniform sky
 *     of radiance 1 sends back exactly a;
 *   - a closed scene whose every surface has albedo 1 under a sky of 1 is
 *     radiance 1 everywhere (the rendering equation's solution is L = 1);
 *   - inside a closed diffuse emitter of albedo a and emission E the
 *     radiance is E / (1 - a) (sum of the series E a^k);
 *   - a glass sphere or cube in the furnace neither gains nor loses energy;
 *     inside glass of index n the furnace's radiance is n^2 (Veach 1997, 5.2);
 *   - a mirror sphere shows the sky along the mirrored ray;
 *   - path mode at depth 1 with one point light is Whitted's diffuse term;
 *   - RMS error against a reference falls as 1 / sqrt(samples);
 *   - no material reflects more than it receives; sampling and evaluation of
 *     the smooth lobes describe the same BRDF;
 *   - the image is bit-identical for 1, 2 and 7 threads and any passes. */
#include "testutil.h"

#include "core/integrators.h"
#include "rtsh/render.h"
#include "rtsh/scene.h"
#include "rtsh/world.h"

/* --- scenes ---------------------------------------------------------------- */

static scene *cam_scene(vec3 pos, vec3 dir, double fov)
{
	scene *s = scene_new();
	assert_non_null(s);
	camera c = {pos, dir, fov, false, 0, 0};
	assert_true(scene_add_camera(s, &c, NULL));
	return s;
}

static void set_ambient(scene *s, double ratio, vec3 color)
{
	s->has_ambient = true;
	s->amb = (ambient){ratio, color};
}

/* An object with a plain material: diffuse d, nothing else. */
static object obj(obj_kind k, vec3 pos, vec3 size, vec3 color, double d)
{
	object o = object_make(k, color);
	o.pos = pos;
	o.scale = size;
	o.mat.diffuse = d;
	o.mat.specular = 0;
	o.mat.shininess = 1;
	o.mat.reflective = 0;
	return o;
}

static void add(scene *s, const object *o)
{
	assert_true(scene_add_object(s, o, NULL));
}

static render_settings settings(int w, int h, int samples, int depth, int threads, uint64_t seed)
{
	render_settings set = render_settings_default();
	set.width = w;
	set.height = h;
	set.samples = samples;
	set.depth = depth;
	set.threads = threads;
	set.mode = MODE_PATH;
	set.seed = seed;
	return set;
}

static framebuffer *render_set(const scene *s, const render_settings *set)
{
	world *w = world_build(s, NULL);
	assert_non_null(w);
	framebuffer *fb = render_image(w, set, NULL, NULL, NULL, NULL);
	assert_non_null(fb);
	world_free(w);
	return fb;
}

static framebuffer *render(const scene *s, int w, int h, int samples, int depth)
{
	render_settings set = settings(w, h, samples, depth, 2, 1);
	return render_set(s, &set);
}

static vec3 pixel(const framebuffer *fb, int x, int y)
{
	const float *p = fb->rgb + ((size_t)y * fb->w + x) * 3;
	return v3(p[0], p[1], p[2]);
}

/* --- the projection formula ---------------------------------------------- */

/* The camera looks along +Z from cam; a pixel point (fx, fy) of a w x h
 * image goes in the direction (u, v, 1) with u = (2 fx / w - 1) tan(fov/2)
 * and v = (1 - 2 fy / h) tan(fov/2) h / w (world.h, cam_ray). */
static vec3 pixel_dir(double fov, int w, int h, double fx, double fy)
{
	double t = tan(fov * RT_PI / 360.0);
	return v3_norm(v3((2.0 * fx / w - 1.0) * t, (1.0 - 2.0 * fy / h) * t * h / w, 1.0));
}

/* True when the whole pixel (x, y) sees the sphere (centre c, radius r),
 * with a margin: the distance from c to the ray through each corner is
 * below r (1 - margin). The silhouette is convex, so corners suffice. */
static bool pixel_inside(vec3 cam, double fov, int w, int h, int x, int y, vec3 c, double r,
                         double margin)
{
	for (int k = 0; k < 4; k++) {
		vec3 d = pixel_dir(fov, w, h, x + (k & 1), y + (k >> 1));
		vec3 oc = v3_sub(c, cam);
		double along = v3_dot(oc, d);
		double dist2 = v3_dot(oc, oc) - along * along;
		if (along <= 0.0 || dist2 >= r * r * (1.0 - margin) * (1.0 - margin))
			return false;
	}
	return true;
}

/* The same, with the margin outside: no corner ray comes near the sphere. */
static bool pixel_outside(vec3 cam, double fov, int w, int h, int x, int y, vec3 c, double r)
{
	for (int k = 0; k < 4; k++) {
		vec3 d = pixel_dir(fov, w, h, x + (k & 1), y + (k >> 1));
		vec3 oc = v3_sub(c, cam);
		double along = v3_dot(oc, d);
		if (v3_dot(oc, oc) - along * along <= r * r * 1.1025)
			return false;
	}
	return true;
}

/* Mean (channel x) and count of the pixels well inside the sphere. */
static double mean_inside(const framebuffer *fb, vec3 cam, double fov, vec3 c, double r, int *count)
{
	double sum = 0;
	int n = 0;
	for (int y = 0; y < fb->h; y++)
		for (int x = 0; x < fb->w; x++)
			if (pixel_inside(cam, fov, fb->w, fb->h, x, y, c, r, 0.05)) {
				sum += pixel(fb, x, y).x;
				n++;
			}
	*count = n;
	return n ? sum / n : 0.0;
}

/* --- white furnace --------------------------------------------------------- */

/* A 1 255,255,255: the sky is radiance 1 in every direction. A convex
 * sphere of diffuse 0.5 white sees only the sky, so every path that hits it
 * carries back 0.5 x 1. Pixels that miss see the sky: 1. */
static void test_white_furnace(void **state)
{
	(void)state;
	const vec3 cam = v3(0, 0, -4);
	const double fov = 40;
	scene *s = cam_scene(cam, v3(0, 0, 1), fov);
	set_ambient(s, 1, v3(255, 255, 255));
	object o = obj(OBJ_SPHERE, v3(0, 0, 0), v3_splat(2), v3(255, 255, 255), 0.5);
	add(s, &o);
	framebuffer *fb = render(s, 32, 32, 256, 5);
	int n = 0, outside = 0;
	double mean = mean_inside(fb, cam, fov, v3(0, 0, 0), 1, &n);
	print_message("furnace: %d sphere pixels, mean %.6f (expected 0.5)\n", n, mean);
	assert_true(n > 100);
	assert_near(mean, 0.5, 0.005);
	for (int y = 0; y < 32; y++)
		for (int x = 0; x < 32; x++) {
			vec3 c = pixel(fb, x, y);
			if (pixel_inside(cam, fov, 32, 32, x, y, v3(0, 0, 0), 1, 0.05)) {
				assert_near(c.x, 0.5, 0.01);
				assert_near(c.y, 0.5, 0.01);
				assert_near(c.z, 0.5, 0.01);
			} else if (pixel_outside(cam, fov, 32, 32, x, y, v3(0, 0, 0), 1)) {
				assert_near(c.x, 1.0, 1e-6);
				outside++;
			}
		}
	assert_true(outside > 100);
	fb_free(fb);
	scene_free(s);
}

/* Surfaces of albedo 1 (white Lambert, a white mirror, clear glass) in any
 * arrangement, even facing each other, under a sky of 1: L = 1 solves the
 * rendering equation everywhere, so every pixel converges to 1 — also
 * through many bounces, where Russian roulette must stay unbiased. */
static void test_furnace_albedo_one(void **state)
{
	(void)state;
	scene *s = cam_scene(v3(0, 0.5, -5), v3(0, -0.1, 1), 60);
	set_ambient(s, 1, v3(255, 255, 255));
	object a = obj(OBJ_SPHERE, v3(-0.9, 0, 0), v3_splat(1.6), v3(255, 255, 255), 1);
	object b = obj(OBJ_CUBE, v3(0.9, 0, 0.2), v3(1.5, 1.5, 1.5), v3(255, 255, 255), 0);
	b.mat.reflective = 1;
	b.dir = v3(0.3, 1, 0.2);
	object g = obj(OBJ_SPHERE, v3(0, 0.9, -1), v3_splat(1), v3(255, 255, 255), 0);
	g.mat.ior = 1.5;
	object c = obj(OBJ_CYLINDER, v3(0, -0.9, 0), v3(4, 0.3, 4), v3(255, 255, 255), 1);
	add(s, &a);
	add(s, &b);
	add(s, &g);
	add(s, &c);
	framebuffer *fb = render(s, 24, 24, 128, 1000);
	double sum = 0;
	for (int y = 0; y < 24; y++)
		for (int x = 0; x < 24; x++) {
			vec3 p = pixel(fb, x, y);
			sum += p.x + p.y + p.z;
			assert_near(p.x, 1.0, 0.2); /* 128 samples per pixel */
		}
	print_message("albedo-1 furnace: mean %.5f (expected 1)\n", sum / (24 * 24 * 3));
	assert_near(sum / (24 * 24 * 3), 1.0, 0.01);
	fb_free(fb);
	scene_free(s);
}

/* The camera inside a closed sphere, cube or cylinder of diffuse albedo
 * a = 0.5 that emits E = 1 (emit 1, white): L = E + a L, so every pixel is
 * E / (1 - a) = 2. The rays start inside the shape and see only its inner
 * side (the seed's "cube as a room" that one-sided shading got wrong). */
static void test_inside_emitter(void **state)
{
	(void)state;
	const obj_kind kinds[] = {OBJ_SPHERE, OBJ_CUBE, OBJ_CYLINDER};
	for (int k = 0; k < 3; k++) {
		scene *s = cam_scene(v3(0.3, -0.2, 0.1), v3(0.2, 0.1, 1), 90);
		object o = obj(kinds[k], v3(0, 0, 0), v3_splat(4), v3(255, 255, 255), 0.5);
		o.dir = v3(0.1, 1, 0.2);
		o.mat.emission = 1;
		add(s, &o);
		framebuffer *fb = render(s, 16, 16, 256, 1000);
		double sum = 0;
		for (int y = 0; y < 16; y++)
			for (int x = 0; x < 16; x++)
				sum += pixel(fb, x, y).x;
		print_message("inside an emitter (%s): mean %.5f (expected 2)\n", obj_kind_name(kinds[k]),
		              sum / 256);
		assert_near(sum / 256, 2.0, 0.02);
		fb_free(fb);
		scene_free(s);
	}
}

/* Clear glass (ior 1.5) reflects F and refracts 1 - F of what falls on it:
 * in the furnace a glass sphere and a glass cube (where total internal
 * reflection traps rays for a while) stay at radiance 1. */
static void test_glass_furnace(void **state)
{
	(void)state;
	const vec3 cam = v3(0, 0, -4);
	const double fov = 40;
	for (int k = 0; k < 2; k++) {
		scene *s = cam_scene(cam, v3(0, 0, 1), fov);
		set_ambient(s, 1, v3(255, 255, 255));
		object g = obj(k ? OBJ_CUBE : OBJ_SPHERE, v3(0, 0, 0), v3_splat(k ? 1.4 : 2),
		               v3(255, 255, 255), 0);
		g.mat.ior = 1.5;
		if (k)
			g.dir = v3(0.4, 1, -0.3);
		add(s, &g);
		framebuffer *fb = render(s, 24, 24, 256, 200);
		int n = 0;
		double mean = mean_inside(fb, cam, fov, v3(0, 0, 0), k ? 0.5 : 1, &n);
		print_message("glass %s in the furnace: mean over it %.5f (expected 1)\n",
		              k ? "cube" : "sphere", mean);
		assert_true(n > 10);
		assert_near(mean, 1.0, 0.01);
		double all = 0;
		for (int i = 0; i < 24 * 24 * 3; i++)
			all += fb->rgb[i];
		assert_near(all / (24 * 24 * 3), 1.0, 0.01);
		fb_free(fb);
		scene_free(s);
	}
}

/* From the centre of a glass sphere every ray meets the surface head-on and
 * leaves (or reflects back through the centre and leaves on the other
 * side): the furnace's radiance 1 becomes n^2 = 2.25 inside (radiance / n^2
 * is invariant along a ray; Veach, thesis 1997, 5.2). */
static void test_radiance_inside_glass(void **state)
{
	(void)state;
	scene *s = cam_scene(v3(0, 0, 0), v3(0, 0, 1), 90);
	set_ambient(s, 1, v3(255, 255, 255));
	object g = obj(OBJ_SPHERE, v3(0, 0, 0), v3_splat(2), v3(255, 255, 255), 0);
	g.mat.ior = 1.5;
	add(s, &g);
	framebuffer *fb = render(s, 8, 8, 16, 100);
	for (int y = 0; y < 8; y++)
		for (int x = 0; x < 8; x++)
			assert_near(pixel(fb, x, y).y, 2.25, 1e-4);
	fb_free(fb);
	scene_free(s);
}

/* --- mirrors and the sky --------------------------------------------------- */

static double srgb_decode(double code)
{
	double c = code / 255.0;
	return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

/* A mirror sphere (reflective 1, metal 0: reflectance 1 at every angle) in a
 * uniform sky of 0.7 x lin(200,220,255) shows exactly that sky; under the
 * `sky` gradient each pixel centre shows the sky along the mirrored ray:
 * strength x (horizon + (zenith - horizon) clamp(dir.y, 0, 1)). */
static void test_mirror_shows_sky(void **state)
{
	(void)state;
	const vec3 cam = v3(0, 0, -4);
	const double fov = 50;
	const int W = 40, H = 30;
	for (int gradient = 0; gradient < 2; gradient++) {
		scene *s = cam_scene(cam, v3(0, 0, 1), fov);
		set_ambient(s, 0.7, v3(200, 220, 255));
		if (gradient) {
			s->has_sky = true;
			s->sky = (sky){.zenith = v3(40, 90, 250), .horizon = v3(250, 240, 200), .strength = 1.5};
		}
		object m = obj(OBJ_SPHERE, v3(0, 0, 0), v3_splat(2), v3(255, 255, 255), 0);
		m.mat.reflective = 1;
		add(s, &m);
		framebuffer *fb = render(s, W, H, 1, 3); /* one sample: the pixel centre */
		int n = 0;
		for (int y = 0; y < H; y++)
			for (int x = 0; x < W; x++) {
				if (!pixel_inside(cam, fov, W, H, x, y, v3(0, 0, 0), 1, 0.02))
					continue;
				vec3 d = pixel_dir(fov, W, H, x + 0.5, y + 0.5);
				/* the hit on the unit sphere: |cam + t d| = 1 */
				double b = v3_dot(cam, d), c = v3_dot(cam, cam) - 1;
				double t = -b - sqrt(b * b - c);
				vec3 nrm = v3_add(cam, v3_scale(d, t));
				vec3 r = v3_sub(d, v3_scale(nrm, 2 * v3_dot(d, nrm)));
				vec3 want;
				if (gradient) {
					double k = fmin(fmax(r.y, 0.0), 1.0);
					vec3 zen = v3(srgb_decode(40), srgb_decode(90), srgb_decode(250));
					vec3 hor = v3(srgb_decode(250), srgb_decode(240), srgb_decode(200));
					want = v3_scale(v3_add(hor, v3_scale(v3_sub(zen, hor), k)), 1.5);
				} else {
					want = v3_scale(v3(srgb_decode(200), srgb_decode(220), 1.0), 0.7);
				}
				assert_vec_near(pixel(fb, x, y), want, 1e-5);
				n++;
			}
		assert_true(n > 200);
		fb_free(fb);
		scene_free(s);
	}
}

/* --- path at depth 1 against Whitted -------------------------------------- */

/* No ambient line: the path tracer's sky is black and Whitted's ambient
 * term is 0. At depth 1 the path tracer's only light is then the next-event
 * estimate at the first hit, (diffuse x albedo / pi) x (pi L cos): Whitted's
 * diffuse term diffuse x albedo x L x cos, shadows included. Specular 0 on
 * every object so that only the diffuse term remains in both. Same seed,
 * same pixel positions: the images agree to rounding. */
static void test_depth1_equals_whitted_diffuse(void **state)
{
	(void)state;
	scene *s = cam_scene(v3(0, 1.5, -6), v3(0, -0.2, 1), 60);
	light l = {v3(-3, 5, -4), 0.8, v3(255, 230, 200), LIGHT_MINIRT, 0, {0, 0, 0}, 0, 0, 0};
	assert_true(scene_add_light(s, &l, NULL));
	object a = obj(OBJ_SPHERE, v3(0, 1, 0), v3_splat(2), v3(200, 120, 60), 0.7);
	object b = obj(OBJ_CUBE, v3(1.8, 0.5, -1), v3(1, 1, 1), v3(60, 200, 120), 0.9);
	b.dir = v3(0.3, 1, 0.1);
	object p = obj(OBJ_PLANE, v3(0, 0, 0), v3(1, 1, 1), v3(230, 230, 230), 0.8);
	add(s, &a);
	add(s, &b);
	add(s, &p);
	world *w = world_build(s, NULL);
	render_settings set = settings(40, 30, 4, 1, 2, 5);
	framebuffer *path = render_image(w, &set, NULL, NULL, NULL, NULL);
	set.mode = MODE_WHITTED;
	set.depth = 0;
	framebuffer *whitted = render_image(w, &set, NULL, NULL, NULL, NULL);
	assert_non_null(path);
	assert_non_null(whitted);
	double lit = 0;
	for (int i = 0; i < 40 * 30 * 3; i++) {
		assert_near(path->rgb[i], whitted->rgb[i], 1e-5 * (1 + whitted->rgb[i]));
		lit += whitted->rgb[i];
	}
	assert_true(lit > 40 * 30 * 3 * 0.05); /* the comparison is not 0 == 0 */
	/* By hand at one point: the sphere's top (0,2,0) faces up, the light is
	 * at (-3,5,-4): cos = 3 / sqrt(34), colour 200,120,60 x 0.7 x 0.8 x
	 * lin(255,230,200). Traced directly through the bsdf and the shading of
	 * a hit, as the integrator does at depth 1. */
	hit h = {.t = 1, .p = v3(0, 2, 0), .n = v3(0, 1, 0), .front = true, .object = 0};
	bsdf bs;
	bsdf_make(&bs, &w->mats[0], &h, v3_norm(v3(0, 1, -1)));
	vec3 wi = v3_norm(v3(-3, 3, -4));
	vec3 f = bsdf_eval(&bs, wi);
	double cos = 3 / sqrt(34.0);
	assert_near(f.x * RT_PI * 0.8 * srgb_decode(255) * cos, srgb_decode(200) * 0.7 * 0.8 * cos, 1e-12);
	assert_near(f.y * RT_PI * 0.8 * srgb_decode(230) * cos,
	            srgb_decode(120) * 0.7 * 0.8 * srgb_decode(230) * cos, 1e-12);
	fb_free(path);
	fb_free(whitted);
	world_free(w);
	scene_free(s);
}

/* A rectangle facing away from the camera is lit like one facing it: the
 * surfaces are two-sided, so flipping the normal changes nothing. */
static void test_two_sided(void **state)
{
	(void)state;
	framebuffer *fb[2];
	for (int k = 0; k < 2; k++) {
		scene *s = cam_scene(v3(0, 0, -3), v3(0, 0, 1), 60);
		set_ambient(s, 0.3, v3(255, 255, 255));
		light l = {v3(1, 1, -4), 0.9, v3(255, 255, 255), LIGHT_MINIRT, 0, {0, 0, 0}, 0, 0, 0};
		assert_true(scene_add_light(s, &l, NULL));
		object r = obj(OBJ_RECT, v3(0, 0, 0), v3(2, 1, 2), v3(180, 180, 180), 0.8);
		r.dir = k ? v3(0, 0, 1) : v3(0, 0, -1);
		add(s, &r);
		fb[k] = render(s, 16, 16, 8, 3);
		scene_free(s);
	}
	/* the centre pixel sees the rectangle lit from the camera's side */
	assert_true(pixel(fb[0], 8, 8).x > 0.3);
	for (int i = 0; i < 16 * 16 * 3; i++)
		assert_near(fb[0]->rgb[i], fb[1]->rgb[i], 1e-6);
	fb_free(fb[0]);
	fb_free(fb[1]);
}

/* --- emitters --------------------------------------------------------------- */

/* Renders a 1x1 image through a very narrow camera at cam looking at the
 * origin, with `samples` paths at depth 1, the emitters sampled directly
 * (and weighed against the paths) or left to the paths alone. */
static double origin_radiance(const scene *s, int samples, bool sample_emitters)
{
	world *w = world_build(s, NULL);
	assert_non_null(w);
	if (!sample_emitters)
		w->nemitters = 0;
	render_settings set = settings(1, 1, samples, 1, 2, 11);
	framebuffer *fb = render_image(w, &set, NULL, NULL, NULL, NULL);
	assert_non_null(fb);
	double v = fb->rgb[1];
	fb_free(fb);
	world_free(w);
	return v;
}

/* A white Lambertian floor of albedo 0.8 under a lamp, no sky. At the
 * origin, facing up (Lambert's formulas for the irradiance E from a
 * uniform emitter of radiance Le; the floor sends back 0.8 E / pi):
 *   a disc of radius R at height h, parallel, centred above:
 *     E = pi Le R^2 / (R^2 + h^2)
 *   a sphere of radius r whose centre is at distance D straight up:
 *     E = pi Le (r / D)^2
 * Both the direct sampling of the emitters (with MIS) and the paths alone
 * must give these. */
static void test_emitter_irradiance(void **state)
{
	(void)state;
	const double le = 2 * srgb_decode(250); /* emit 2, colour 250 grey */
	for (int shape = 0; shape < 2; shape++) {
		scene *s = cam_scene(v3(0, 0.5, -4), v3(0, -0.5, 4), 0.2);
		object floor = obj(OBJ_PLANE, v3(0, 0, 0), v3(1, 1, 1), v3(255, 255, 255), 0.8);
		object lamp = obj(shape ? OBJ_SPHERE : OBJ_DISC, v3(0, shape ? 2 : 1, 0),
		                  v3_splat(1), v3(250, 250, 250), 0);
		lamp.dir = v3(0, -1, 0);
		lamp.mat.emission = 2;
		add(s, &floor);
		add(s, &lamp);
		double want = shape ? 0.8 * le * 0.25 * 0.25 : 0.8 * le * 0.25 / 1.25;
		double mis = origin_radiance(s, 20000, true);
		double paths = origin_radiance(s, 400000, false);
		print_message("%s: expected %.5f, sampled %.5f, paths only %.5f\n", shape ? "sphere" : "disc",
		              want, mis, paths);
		assert_near(mis, want, 0.005 * want);
		assert_near(paths, want, 0.01 * want);
		scene_free(s);
	}
}

/* Sampling the emitters directly changes the noise, not the image: every
 * kind of sampled emitter (sphere, rectangle, disc, triangle), out of the
 * camera's view, over Lambert, Phong and fuzzy-metal lobes, renders to the
 * same means with and without it. */
static void test_emitter_sampling_unbiased(void **state)
{
	(void)state;
	scene *s = cam_scene(v3(0, 3.2, -4.5), v3(0, -0.75, 1), 55);
	object floor = obj(OBJ_PLANE, v3(0, 0, 0), v3(1, 1, 1), v3(220, 220, 220), 0.6);
	floor.mat.specular = 0.3;
	floor.mat.shininess = 20;
	object a = obj(OBJ_SPHERE, v3(-1.2, 0.6, 0.5), v3_splat(1.2), v3(200, 160, 120), 0);
	a.mat.reflective = 1;
	a.mat.metal = 1;
	a.mat.fuzz = 0.4;
	object b = obj(OBJ_CUBE, v3(1.2, 0.5, 0.3), v3(1, 1, 1), v3(120, 180, 220), 0.9);
	b.dir = v3(0.2, 1, 0.1);
	object l1 = obj(OBJ_SPHERE, v3(-3, 3, 2.5), v3_splat(1.6), v3(255, 220, 180), 0);
	l1.mat.emission = 1.5;
	object l2 = obj(OBJ_RECT, v3(1, 3.6, 0), v3(3, 1, 2), v3(200, 220, 255), 0);
	l2.dir = v3(0.2, -1, 0);
	l2.mat.emission = 1;
	object l3 = obj(OBJ_DISC, v3(0, 2.5, 4), v3(2.5, 1, 2.5), v3(255, 255, 255), 0.5);
	l3.dir = v3(0, -0.5, -1);
	l3.mat.emission = 1;
	object l4 = object_make(OBJ_TRIANGLE, v3(255, 180, 120));
	l4.tri[0] = v3(5, 0, 1);
	l4.tri[1] = v3(5.5, 3, 3);
	l4.tri[2] = v3(4.5, 1.5, 4);
	l4.mat.emission = 1;
	object objs[] = {floor, a, b, l1, l2, l3, l4};
	for (size_t i = 0; i < sizeof objs / sizeof objs[0]; i++)
		add(s, &objs[i]);
	double mean[2] = {0, 0}, block_diff = 0;
	framebuffer *fb[2];
	for (int k = 0; k < 2; k++) {
		world *w = world_build(s, NULL);
		assert_non_null(w);
		assert_int_equal(w->nemitters, 4);
		if (k)
			w->nemitters = 0;
		render_settings set = settings(16, 12, k ? 4096 : 1024, 6, 2, 21 + k);
		fb[k] = render_image(w, &set, NULL, NULL, NULL, NULL);
		assert_non_null(fb[k]);
		for (int i = 0; i < 16 * 12 * 3; i++)
			mean[k] += fb[k]->rgb[i] / (16 * 12 * 3);
		world_free(w);
	}
	/* the image mean, and the means of its twelve 4x4 blocks */
	for (int by = 0; by < 3; by++)
		for (int bx = 0; bx < 4; bx++) {
			double m[2] = {0, 0};
			for (int k = 0; k < 2; k++)
				for (int y = by * 4; y < by * 4 + 4; y++)
					for (int x = bx * 4; x < bx * 4 + 4; x++) {
						vec3 c = pixel(fb[k], x, y);
						m[k] += (c.x + c.y + c.z) / 48;
					}
			block_diff = fmax(block_diff, fabs(m[0] - m[1]) / m[1]);
		}
	print_message("image mean: sampled %.5f, paths only %.5f; largest 4x4 block difference %.2f%%\n",
	              mean[0], mean[1], 100 * block_diff);
	assert_true(mean[1] > 0.04);
	assert_near(mean[0], mean[1], 0.015 * mean[1]);
	assert_true(block_diff < 0.08);
	fb_free(fb[0]);
	fb_free(fb[1]);
	scene_free(s);
}

/* --- convergence ----------------------------------------------------------- */

/* Soft light from the sky gradient, a point light, diffuse surfaces and a
 * glossy Phong lobe: noise from every kind of sampling. */
static scene *convergence_scene(void)
{
	scene *s = cam_scene(v3(0, 1.2, -4), v3(0, -0.25, 1), 60);
	s->has_sky = true;
	s->sky = (sky){.zenith = v3(120, 170, 255), .horizon = v3(255, 255, 255), .strength = 1};
	light l = {v3(2, 4, -2), 0.7, v3(255, 255, 255), LIGHT_MINIRT, 0, {0, 0, 0}, 0, 0, 0};
	assert_true(scene_add_light(s, &l, NULL));
	object p = obj(OBJ_PLANE, v3(0, 0, 0), v3(1, 1, 1), v3(200, 200, 200), 0.9);
	object a = obj(OBJ_SPHERE, v3(-0.7, 0.6, 0), v3_splat(1.2), v3(220, 80, 60), 0.8);
	a.mat.specular = 0.2;
	a.mat.shininess = 30;
	object b = obj(OBJ_SPHERE, v3(0.8, 0.5, 0.3), v3_splat(1), v3(220, 200, 160), 0.8);
	add(s, &p);
	add(s, &a);
	add(s, &b);
	return s;
}

static double squared_error(const framebuffer *a, const framebuffer *ref)
{
	double sum = 0;
	size_t n = (size_t)a->w * a->h * 3;
	for (size_t i = 0; i < n; i++) {
		double d = (double)a->rgb[i] - ref->rgb[i];
		sum += d * d;
	}
	return sum / n;
}

/* Monte-Carlo error falls as 1 / sqrt(N): four times the samples, half the
 * RMS error. The reference (4096 samples) uses another seed, so its noise
 * is independent of the images it judges; each RMS error is taken over four
 * renders with different seeds, so that it is itself well measured. */
static void test_convergence(void **state)
{
	(void)state;
	scene *s = convergence_scene();
	world *w = world_build(s, NULL);
	assert_non_null(w);
	render_settings set = settings(16, 16, 4096, 8, 2, 1234567);
	framebuffer *ref = render_image(w, &set, NULL, NULL, NULL, NULL);
	assert_non_null(ref);
	double err[3];
	const int spp[3] = {16, 64, 256};
	for (int i = 0; i < 3; i++) {
		double mse = 0;
		for (uint64_t seed = 1; seed <= 4; seed++) {
			set.samples = spp[i];
			set.seed = seed;
			framebuffer *fb = render_image(w, &set, NULL, NULL, NULL, NULL);
			assert_non_null(fb);
			mse += squared_error(fb, ref) / 4;
			fb_free(fb);
		}
		/* The reference's own noise adds N / 4096 of the error's variance. */
		err[i] = sqrt(mse / (1.0 + spp[i] / 4096.0));
	}
	print_message("rms error: 16 spp %.5f, 64 spp %.5f, 256 spp %.5f (ratios %.3f %.3f)\n", err[0],
	              err[1], err[2], err[1] / err[0], err[2] / err[1]);
	assert_true(err[1] / err[0] > 0.4 && err[1] / err[0] < 0.6);
	assert_true(err[2] / err[1] > 0.4 && err[2] / err[1] < 0.6);
	fb_free(ref);
	world_free(w);
	scene_free(s);
}

/* --- thread counts and passes -------------------------------------------- */

/* Every material at once: Lambert, Phong, metal with fuzz, glass, emission,
 * a checker, a point light and the sky. */
static scene *material_scene(void)
{
	scene *s = cam_scene(v3(0, 1.5, -6), v3(0, -0.2, 1), 70);
	s->has_sky = true;
	s->sky = (sky){.zenith = v3(100, 150, 255), .horizon = v3(255, 250, 240), .strength = 1};
	light l = {v3(-3, 5, -3), 0.8, v3(255, 240, 220), LIGHT_MINIRT, 0, {0, 0, 0}, 0, 0, 0};
	assert_true(scene_add_light(s, &l, NULL));
	object p = obj(OBJ_PLANE, v3(0, 0, 0), v3(2, 2, 2), v3(230, 230, 230), 0.9);
	p.mat.checker = 1;
	object a = obj(OBJ_SPHERE, v3(-2, 0.7, 0), v3_splat(1.4), v3(200, 60, 50), 0.9);
	a.mat.specular = 0.9;
	a.mat.shininess = 200;
	object b = obj(OBJ_SPHERE, v3(0, 0.7, 0), v3_splat(1.4), v3(255, 255, 255), 0);
	b.mat.ior = 1.5;
	object c = obj(OBJ_CUBE, v3(2, 0.6, 0), v3(1.2, 1.2, 1.2), v3(220, 190, 120), 0);
	c.mat.reflective = 1;
	c.mat.metal = 1;
	c.mat.fuzz = 0.2;
	object e = obj(OBJ_DISC, v3(0, 2.5, 1.5), v3(1.5, 1, 1.5), v3(255, 200, 150), 0);
	e.mat.emission = 3;
	e.dir = v3(0, -1, -0.5);
	add(s, &p);
	add(s, &a);
	add(s, &b);
	add(s, &c);
	add(s, &e);
	return s;
}

static void test_threads_bit_identical(void **state)
{
	(void)state;
	scene *s = material_scene();
	world *w = world_build(s, NULL);
	assert_non_null(w);
	render_settings set = settings(37, 23, 6, 12, 1, 3);
	framebuffer *one = render_image(w, &set, NULL, NULL, NULL, NULL);
	assert_non_null(one);
	const int counts[] = {2, 7};
	for (int i = 0; i < 2; i++) {
		set.threads = counts[i];
		framebuffer *fb = render_image(w, &set, NULL, NULL, NULL, NULL);
		assert_non_null(fb);
		assert_memory_equal(one->rgb, fb->rgb, sizeof(float) * 37 * 23 * 3);
		assert_null(fb->sum); /* an image made in one pass keeps no sums */
		fb_free(fb);
	}
	/* passes of 1, 2 and 3 samples on 7 threads: the same image again */
	framebuffer *prog = fb_new(37, 23);
	const int ends[] = {1, 3, 6};
	for (int k = 0; k < 3; k++) {
		render_job job = {.w = w, .set = set, .fb = prog, .sample_begin = prog->spp,
		                  .sample_end = ends[k]};
		assert_int_equal(render_run(&job, NULL), RENDER_DONE);
	}
	assert_memory_equal(one->rgb, prog->rgb, sizeof(float) * 37 * 23 * 3);
	fb_free(prog);
	fb_free(one);
	world_free(w);
	scene_free(s);
}

/* --- energy ---------------------------------------------------------------- */

static mat_lin lin_material(double d, double sp, double sh, double refl, double fuzz, double metal,
                            double ior)
{
	return (mat_lin){.albedo = v3(1, 1, 1), .diffuse = d, .specular = sp, .shininess = sh,
	                 .reflective = refl, .fuzz = fuzz, .metal = metal, .ior = ior};
}

/* A hit at the origin seen from wo = (sin, 0, cos theta = c), above the
 * plane z = 0; front: the outward normal is +Z (the ray arrived from
 * outside), else -Z (it arrived from inside the shape). */
static bsdf bsdf_at(const mat_lin *m, double c, bool front)
{
	hit h = {.t = 1, .p = v3(0, 0, 0), .n = v3(0, 0, front ? 1 : -1), .front = front};
	bsdf b;
	bsdf_make(&b, m, &h, v3(sqrt(1 - c * c), 0, c));
	return b;
}

typedef struct estimate {
	vec3 mean;
	double max_sd; /* the largest standard error of the mean's channels */
} estimate;

/* The directional albedo: the mean of f cos / pdf over n sampled directions
 * (absorbed samples count 0). */
static estimate albedo_of(const bsdf *b, int n, rng *r)
{
	vec3 sum = v3(0, 0, 0), sq = v3(0, 0, 0);
	for (int i = 0; i < n; i++) {
		bsdf_sample smp;
		if (!bsdf_sample_dir(b, r, &smp))
			continue;
		sum = v3_add(sum, smp.weight);
		sq = v3_add(sq, v3_mul(smp.weight, smp.weight));
	}
	estimate e;
	e.mean = v3_scale(sum, 1.0 / n);
	vec3 var = v3_sub(v3_scale(sq, 1.0 / n), v3_mul(e.mean, e.mean));
	e.max_sd = sqrt(fmax(0.0, v3_max_comp(var)) / n);
	return e;
}

/* Every combination of the material fields, seen at grazing to normal
 * incidence from both sides, reflects at most what it receives. */
static void test_energy_bound(void **state)
{
	(void)state;
	rng r = {2024};
	const double d[] = {0, 0.5, 1}, sp[] = {0, 0.5, 1}, sh[] = {1, 20, 500}, refl[] = {0, 0.5, 1};
	const double fuzz[] = {0, 0.3, 1}, metal[] = {0, 1}, ior[] = {0, 1.5};
	const double cosv[] = {1, 0.6, 0.2, 0.02};
	int combos = 0;
	double worst = 0;
	for (int i0 = 0; i0 < 3; i0++)
		for (int i1 = 0; i1 < 3; i1++)
			for (int i2 = 0; i2 < 3; i2++)
				for (int i3 = 0; i3 < 3; i3++)
					for (int i4 = 0; i4 < 3; i4++)
						for (int i5 = 0; i5 < 2; i5++)
							for (int i6 = 0; i6 < 2; i6++)
								for (int i7 = 0; i7 < 4; i7++) {
									mat_lin m = lin_material(d[i0], sp[i1], sh[i2], refl[i3],
									                         fuzz[i4], metal[i5], ior[i6]);
									bsdf b = bsdf_at(&m, cosv[i7], (i7 & 1) == 0);
									estimate e = albedo_of(&b, 1000, &r);
									double top = v3_max_comp(e.mean);
									worst = fmax(worst, top - 5 * e.max_sd);
									if (top > 1 + 5 * e.max_sd + 1e-9)
										fail_msg("d %g s %g sh %g r %g fuzz %g metal %g ior %g "
										         "cos %g: albedo %g",
										         d[i0], sp[i1], sh[i2], refl[i3], fuzz[i4],
										         metal[i5], ior[i6], cosv[i7], top);
									combos++;
								}
	print_message("%d material combinations: largest albedo (less 5 sd) %.4f\n", combos, worst);
}

/* Albedos known exactly from the definitions: Lambert reflects diffuse x
 * colour; the normalised Phong lobe reflects exactly `specular` at normal
 * incidence ((e+2)/(2 pi) integral of cos^(e+1) over the hemisphere = 1); a
 * mirror 1; a metal its colour at normal incidence (Schlick's F0); clear
 * glass F + (1 - F) = 1 at every angle, total internal reflection included. */
static void test_albedo_by_definition(void **state)
{
	(void)state;
	rng r = {77};
	mat_lin lambert = lin_material(0.6, 0, 1, 0, 0, 0, 0);
	lambert.albedo = v3(0.2, 0.5, 0.9);
	for (int k = 0; k < 3; k++) {
		bsdf b = bsdf_at(&lambert, 1.0 - 0.45 * k, k != 1);
		estimate e = albedo_of(&b, 2000, &r);
		assert_vec_near(e.mean, v3(0.12, 0.3, 0.54), 1e-12);
	}
	const double shin[] = {1, 10, 200};
	for (int k = 0; k < 3; k++) {
		mat_lin phong = lin_material(0, 0.8, shin[k], 0, 0, 0, 0);
		bsdf b = bsdf_at(&phong, 1.0, true);
		estimate e = albedo_of(&b, 40000, &r);
		assert_near(e.mean.x, 0.8, 4 * e.max_sd + 1e-9);
	}
	mat_lin mirror = lin_material(0, 0, 1, 1, 0, 0, 0);
	for (int k = 0; k < 4; k++) {
		bsdf b = bsdf_at(&mirror, 1.0 - 0.3 * k, true);
		assert_vec_near(albedo_of(&b, 100, &r).mean, v3(1, 1, 1), 1e-12);
	}
	mat_lin gold = lin_material(0, 0, 1, 1, 0, 1, 0);
	gold.albedo = v3(0.9, 0.6, 0.2);
	bsdf bg = bsdf_at(&gold, 1.0, true);
	assert_vec_near(albedo_of(&bg, 100, &r).mean, gold.albedo, 1e-12);
	mat_lin glass = lin_material(0, 0, 1, 0, 0, 0, 1.5);
	for (int k = 0; k < 8; k++) {
		/* from outside and from inside, beyond the critical angle too */
		bsdf b = bsdf_at(&glass, 1.0 - 0.14 * k, k & 1);
		assert_vec_near(albedo_of(&b, 500, &r).mean, v3(1, 1, 1), 1e-12);
	}
}

/* The Fresnel reflectance the glass lobe picks with: at normal incidence
 * ((n - 1) / (n + 1))^2 = 0.04 for n = 1.5; total internal reflection from
 * inside beyond the critical angle asin(1 / 1.5). */
static void test_fresnel(void **state)
{
	(void)state;
	mat_lin glass = lin_material(0, 0, 1, 0, 0, 0, 1.5);
	rng r = {5};
	for (int inside = 0; inside < 2; inside++) {
		bsdf b = bsdf_at(&glass, 1.0, !inside);
		int refl = 0, n = 100000;
		for (int i = 0; i < n; i++) {
			bsdf_sample smp;
			assert_true(bsdf_sample_dir(&b, &r, &smp));
			refl += !smp.transmit;
			if (smp.transmit) {
				/* head-on: straight through, radiance scaled by (n_i / n_t)^2 */
				assert_vec_near(smp.wi, v3(0, 0, -1), 1e-12);
				assert_near(smp.radiance_scale, inside ? 2.25 : 1 / 2.25, 1e-12);
			}
		}
		assert_near((double)refl / n, 0.04, 0.002);
	}
	double crit = sqrt(1 - 1 / 2.25);
	bsdf tir = bsdf_at(&glass, crit * 0.99, false);
	for (int i = 0; i < 100; i++) {
		bsdf_sample smp;
		assert_true(bsdf_sample_dir(&tir, &r, &smp));
		assert_false(smp.transmit);
	}
	/* Snell: sin t = sin i / 1.5 going in at 60 degrees */
	bsdf in = bsdf_at(&glass, 0.5, true);
	for (int i = 0; i < 200; i++) {
		bsdf_sample smp;
		assert_true(bsdf_sample_dir(&in, &r, &smp));
		if (smp.transmit)
			assert_near(sqrt(smp.wi.x * smp.wi.x + smp.wi.y * smp.wi.y), sqrt(0.75) / 1.5, 1e-12);
	}
}

/* Sampling and evaluation describe the same BRDF: for the smooth lobes
 * (Lambert, Phong, fuzzy metal) the mean sampled weight equals the integral
 * of f cos over the hemisphere, estimated independently with uniformly
 * distributed directions (pdf 1 / (2 pi)). Next-event estimation uses f,
 * the paths use the samples: a mismatch would bias one against the other. */
static void test_sample_matches_eval(void **state)
{
	(void)state;
	rng r = {99};
	mat_lin mats[3] = {
		lin_material(0.7, 0.3, 15, 0, 0, 0, 0),
		lin_material(0.4, 0.5, 4, 0.3, 0.6, 0.5, 0),
		lin_material(0, 0, 1, 1, 0.8, 1, 0),
	};
	mats[1].albedo = v3(0.9, 0.4, 0.2);
	mats[2].albedo = v3(0.8, 0.7, 0.5);
	for (int k = 0; k < 3; k++)
		for (int a = 0; a < 3; a++) {
			bsdf b = bsdf_at(&mats[k], 1.0 - 0.4 * a, true);
			estimate e = albedo_of(&b, 200000, &r);
			vec3 sum = v3(0, 0, 0), sq = v3(0, 0, 0);
			const int n = 200000;
			for (int i = 0; i < n; i++) {
				double z = rng_next(&r), phi = 2 * RT_PI * rng_next(&r), s = sqrt(1 - z * z);
				vec3 wi = v3(s * cos(phi), s * sin(phi), z);
				vec3 v = v3_scale(bsdf_eval(&b, wi), z * 2 * RT_PI);
				sum = v3_add(sum, v);
				sq = v3_add(sq, v3_mul(v, v));
			}
			vec3 mean = v3_scale(sum, 1.0 / n);
			vec3 var = v3_sub(v3_scale(sq, 1.0 / n), v3_mul(mean, mean));
			double sd = sqrt(fmax(0.0, v3_max_comp(var)) / n);
			double tol = 5 * sqrt(sd * sd + e.max_sd * e.max_sd) + 1e-9;
			assert_near(e.mean.x, mean.x, tol);
			assert_near(e.mean.y, mean.y, tol);
			assert_near(e.mean.z, mean.z, tol);
		}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_white_furnace),
		cmocka_unit_test(test_furnace_albedo_one),
		cmocka_unit_test(test_inside_emitter),
		cmocka_unit_test(test_glass_furnace),
		cmocka_unit_test(test_radiance_inside_glass),
		cmocka_unit_test(test_mirror_shows_sky),
		cmocka_unit_test(test_depth1_equals_whitted_diffuse),
		cmocka_unit_test(test_two_sided),
		cmocka_unit_test(test_emitter_irradiance),
		cmocka_unit_test(test_emitter_sampling_unbiased),
		cmocka_unit_test(test_convergence),
		cmocka_unit_test(test_threads_bit_identical),
		cmocka_unit_test(test_energy_bound),
		cmocka_unit_test(test_albedo_by_definition),
		cmocka_unit_test(test_fresnel),
		cmocka_unit_test(test_sample_matches_eval),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
