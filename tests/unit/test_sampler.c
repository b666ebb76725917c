/* rtsh — tests of the sample values (core/sampler.h), each against a
 * definition:
 *   - Sobol's second dimension equals the textbook construction from its
 *     direction numbers (primitive polynomial x + 1);
 *   - every pixel's first 2^k two-dimensional points form a (0,k,2)-net:
 *     exactly one point in each elementary interval of area 2^-k, for the
 *     pixel position and for the later pairs of dimensions; the first 2^k
 *     one-dimensional values fall one in each interval of length 2^-k;
 *   - stratified pixel positions: the fraction of a pixel that a random
 *     straight edge covers, estimated with N = 2^k samples, errs far less
 *     than independent samples would (RMS sqrt(a(1-a)/N)): at most 1/3 of
 *     that at N = 64 and 1/4 at N >= 256, measured on the sampler and on
 *     rendered pictures against the exact area of the clipped pixel;
 *   - the warps keep the unit disc and the circle exactly. */
#include "testutil.h"

#include "core/sampler.h"
#include "core/warp.h"
#include "rtsh/render.h"
#include "rtsh/scene.h"
#include "rtsh/world.h"

static void test_sobol_definition(void **state)
{
	(void)state;
	/* direction numbers v_j = m_j / 2^j with m_1 = 1 and, for the
	 * polynomial x + 1, m_j = 2 m_{j-1} xor m_{j-1} (Bratley & Fox 1988) */
	uint32_t v[32];
	v[0] = 1u << 31;
	for (int j = 1; j < 32; j++)
		v[j] = v[j - 1] ^ (v[j - 1] >> 1);
	test_rng r = {9};
	for (int n = 0; n < 100000; n++) {
		uint32_t i = n < 4096 ? (uint32_t)n : (uint32_t)(trand(&r) * 0x1.0p32);
		uint32_t x = 0;
		for (int j = 0; j < 32; j++)
			if (i >> j & 1)
				x ^= v[j];
		if (sobol_dim1(i) != x)
			fail_msg("index %u: %08x, expected %08x", i, sobol_dim1(i), x);
	}
}

/* Exactly one of the first 2^k points of each pair of dimensions in every
 * elementary interval [a 2^-i, (a+1) 2^-i) x [b 2^-(k-i), (b+1) 2^-(k-i)). */
static void test_nets(void **state)
{
	(void)state;
	static int count[1 << 12];
	for (int k = 0; k <= 12; k += 3)
		for (uint64_t pixel = 0; pixel < 6; pixel++)
			for (uint32_t dim = 0; dim < 2 * SAMPLER_DIMS; dim += 14) {
				uint32_t n = 1u << k;
				for (int i = 0; i <= k; i++) {
					memset(count, 0, sizeof count);
					for (uint32_t s = 0; s < n; s++) {
						sampler sp = sampler_for(3, pixel * 7919, s);
						sp.dim = dim;
						double u, v;
						samp_2d(&sp, &u, &v);
						assert_true(u >= 0 && u < 1 && v >= 0 && v < 1);
						int a = (int)(u * (1 << i)), b = (int)(v * (1 << (k - i)));
						count[a << (k - i) | b]++;
					}
					if (dim >= SAMPLER_DIMS)
						continue; /* hashed random numbers past the table */
					for (uint32_t c = 0; c < n; c++)
						if (count[c] != 1)
							fail_msg("k %d dims %u,%u pixel %u: interval %u holds %d points", k,
							         dim, dim + 1, (unsigned)pixel, c, count[c]);
				}
				memset(count, 0, sizeof count);
				for (uint32_t s = 0; s < n; s++) {
					sampler sp = sampler_for(3, pixel * 7919, s);
					sp.dim = dim;
					count[(int)(samp_1d(&sp) * n)]++;
				}
				if (dim < SAMPLER_DIMS)
					for (uint32_t c = 0; c < n; c++)
						assert_int_equal(count[c], 1);
			}
}

/* The area of the unit square [0,1]^2 where the affine function with values
 * g[0..3] at the corners (0,0), (1,0), (1,1), (0,1) is negative: the square
 * clipped by the line g = 0 (Sutherland & Hodgman), then the shoelace
 * formula. */
static double clipped_area(const double g[4])
{
	const double cx[4] = {0, 1, 1, 0}, cy[4] = {0, 0, 1, 1};
	double px[8], py[8];
	int n = 0;
	for (int i = 0; i < 4; i++) {
		int j = (i + 1) & 3;
		if (g[i] < 0) {
			px[n] = cx[i];
			py[n++] = cy[i];
		}
		if ((g[i] < 0) != (g[j] < 0)) {
			double t = g[i] / (g[i] - g[j]);
			px[n] = cx[i] + t * (cx[j] - cx[i]);
			py[n++] = cy[i] + t * (cy[j] - cy[i]);
		}
	}
	double a = 0;
	for (int i = 0; i < n; i++) {
		int j = (i + 1) % n;
		a += px[i] * py[j] - px[j] * py[i];
	}
	return fabs(a) / 2;
}

/* RMS error of the covered fraction, over edges, divided by the RMS of
 * independent sampling's error sqrt(a (1 - a) / N). */
typedef struct edge_stats {
	double sq_err, sq_indep;
	int edges;
} edge_stats;

static double edge_ratio(const edge_stats *e)
{
	return sqrt(e->sq_err / e->sq_indep);
}

/* Random edges through random pixels: the line through a uniform point of
 * the pixel at a uniform angle. mode 0: the renderer's pixel positions; 1:
 * independent uniform positions (the yardstick itself). */
static double sampler_edges(uint32_t n, int mode)
{
	test_rng r = {1234 + n};
	edge_stats e = {0, 0, 0};
	while (e.edges < 4000) {
		double x0 = trand(&r), y0 = trand(&r), t = 2 * RT_PI * trand(&r);
		double nx = cos(t), ny = sin(t), c = nx * x0 + ny * y0;
		double g[4] = {-c, nx - c, nx + ny - c, ny - c};
		double a = clipped_area(g);
		if (!(a > 0 && a < 1))
			continue;
		uint64_t pixel = (uint64_t)(trand(&r) * 0x1.0p53);
		rng ind = {(uint64_t)(trand(&r) * 0x1.0p53)};
		uint32_t in = 0;
		for (uint32_t s = 0; s < n; s++) {
			double u, v;
			if (mode == 0) {
				pixel_offset(17, pixel, s, &u, &v);
			} else {
				u = rng_next(&ind);
				v = rng_next(&ind);
			}
			in += nx * u + ny * v - c < 0;
		}
		double d = (double)in / n - a;
		e.sq_err += d * d;
		e.sq_indep += a * (1 - a) / n;
		e.edges++;
	}
	return edge_ratio(&e);
}

static void test_stratified_pixel_edges(void **state)
{
	(void)state;
	const uint32_t ns[] = {64, 256, 1024};
	for (int i = 0; i < 3; i++) {
		double strat = sampler_edges(ns[i], 0), indep = sampler_edges(ns[i], 1);
		print_message("N = %4u: RMS error / independent RMS: %.3f (independent: %.3f)\n", ns[i],
		              strat, indep);
		/* the yardstick is right: independent samples err by it */
		assert_true(indep > 0.9 && indep < 1.1);
		assert_true(strat <= (ns[i] == 64 ? 1.0 / 3 : 1.0 / 4));
	}
}

/* Through the renderer: a 1x1 picture of a huge emissive triangle
 * (radiance 1) in the plane z = 1 before a camera at the origin, nothing
 * else, depth 0: the pixel's value is the fraction of it the triangle
 * covers. The camera maps pixel coordinates to that plane affinely (it is
 * parallel to the image), so one of the triangle's edges is the line
 * through a uniform point of the pixel at a uniform angle, and the exact
 * fraction is the clipped area. */
static vec3 plane_point(const world *w, double fx, double fy)
{
	ray r = cam_ray(&w->cam, fx, fy, 1, 1);
	return v3_scale(r.d, 1.0 / r.d.z);
}

static double rendered_edges(uint32_t n, int edges)
{
	test_rng r = {77 + n};
	edge_stats e = {0, 0, 0};
	scene *s = scene_new();
	assert_non_null(s);
	camera c = {v3(0, 0, 0), v3(0, 0, 1), 60, false, 0, 0};
	assert_true(scene_add_camera(s, &c, NULL));
	object tri = object_make(OBJ_TRIANGLE, v3(255, 255, 255));
	tri.mat.emission = 1;
	tri.mat.diffuse = 0;
	assert_true(scene_add_object(s, &tri, NULL));
	world *w0 = world_build(s, NULL); /* for the camera's map */
	assert_non_null(w0);
	while (e.edges < edges) {
		double x0 = trand(&r), y0 = trand(&r), t = 2 * RT_PI * trand(&r);
		double nx = -sin(t), ny = cos(t); /* covered: n . (f - f0) > 0 */
		double g[4] = {-(-nx * x0 - ny * y0), -(nx * (1 - x0) - ny * y0),
		               -(nx * (1 - x0) + ny * (1 - y0)), -(-nx * x0 + ny * (1 - y0))};
		double a = clipped_area(g);
		if (!(a > 0 && a < 1))
			continue;
		vec3 p = plane_point(w0, x0, y0);
		vec3 along = v3_sub(plane_point(w0, x0 + cos(t), y0 + sin(t)), p);
		vec3 side = v3_sub(plane_point(w0, x0 + nx, y0 + ny), p);
		s->objs[0].tri[0] = v3_madd(p, along, -1000);
		s->objs[0].tri[1] = v3_madd(p, along, 1000);
		s->objs[0].tri[2] = v3_madd(p, side, 1000);
		world *w = world_build(s, NULL);
		assert_non_null(w);
		render_settings set = render_settings_default();
		set.width = set.height = 1;
		set.samples = (int)n;
		set.depth = 0;
		set.threads = 1;
		set.mode = MODE_PATH;
		set.seed = (uint64_t)(trand(&r) * 0x1.0p53);
		framebuffer *fb = render_image(w, &set, NULL, NULL, NULL, NULL);
		assert_non_null(fb);
		double got = fb->rgb[0];
		e.sq_err += (got - a) * (got - a);
		e.sq_indep += a * (1 - a) / n;
		e.edges++;
		fb_free(fb);
		world_free(w);
	}
	world_free(w0);
	scene_free(s);
	return edge_ratio(&e);
}

static void test_rendered_edges(void **state)
{
	(void)state;
	double r64 = rendered_edges(64, 3000), r256 = rendered_edges(256, 1500);
	print_message("rendered: RMS error / independent RMS %.3f at N = 64, %.3f at N = 256\n", r64,
	              r256);
	assert_true(r64 <= 1.0 / 3);
	assert_true(r256 <= 1.0 / 4);
}

static void test_warps(void **state)
{
	(void)state;
	test_rng r = {5};
	for (int i = 0; i < 100000; i++) {
		double u = trand(&r), v = trand(&r), x, y, c, s;
		warp_circle(u, &c, &s);
		assert_near(c, cos(2 * RT_PI * u), 1e-10);
		assert_near(s, sin(2 * RT_PI * u), 1e-10);
		/* the concentric map: radius max(|a|, |b|) of (a, b) = 2 (u, v) - 1 */
		warp_disc(u, v, &x, &y);
		double a = 2 * u - 1, b = 2 * v - 1;
		assert_near(sqrt(x * x + y * y), fmax(fabs(a), fabs(b)), 1e-10);
	}
	/* equal areas of the square go to equal areas of the disc: the share
	 * of points inside radius 1/2 is 1/4 */
	int in = 0;
	for (uint32_t s = 0; s < 4096; s++) {
		double u, v, x, y;
		pixel_offset(1, 2, s, &u, &v);
		warp_disc(u, v, &x, &y);
		in += x * x + y * y < 0.25;
	}
	assert_int_equal(in, 1024);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_sobol_definition),
		cmocka_unit_test(test_nets),
		cmocka_unit_test(test_stratified_pixel_edges),
		cmocka_unit_test(test_rendered_edges),
		cmocka_unit_test(test_warps),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
