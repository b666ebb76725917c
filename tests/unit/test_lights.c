/* rtsh — tests of the direct sampling of flat emitters by solid angle
 * (the shape kinds' light ops, src/core/shapes/light.c), each against
 * formulas derived independently of the sampling code:
 *   - the solid angle of a rectangle seen from a point on its axis,
 *     4 asin(ab / sqrt((a^2 + d^2)(b^2 + d^2))) for half-sides a, b at
 *     distance d; off the axis, the sum over two triangles;
 *   - the solid angle of a triangle by L'Huilier's theorem on the spherical
 *     excess, tan(E/4)^2 = tan(s/2) tan((s-a)/2) tan((s-b)/2) tan((s-c)/2)
 *     with a, b, c the arcs between the vertices and s half their sum;
 *   - the solid angle of a disc from a point on its axis, 2 pi (1 - d /
 *     sqrt(d^2 + R^2));
 *   - the sampled directions are uniform in solid angle: each part of the
 *     shape (quadrants; the four triangles between the midpoints) receives
 *     the share of samples its own solid angle predicts, every sample lies
 *     on the shape, and the density is 1 / (solid angle);
 *   - beyond SOLID_ANGLE_REACH sizes, area sampling: density t^2 / (cos
 *     area). */
#include "testutil.h"

#include "core/emitters.h"
#include "rtsh/scene.h"
#include "rtsh/world.h"

static double arc(vec3 a, vec3 b)
{
	return acos(fmax(-1.0, fmin(1.0, v3_dot(v3_norm(a), v3_norm(b)))));
}

/* L'Huilier: the solid angle of the triangle a, b, c seen from o. */
static double tri_solid_angle(vec3 o, vec3 a, vec3 b, vec3 c)
{
	vec3 pa = v3_sub(a, o), pb = v3_sub(b, o), pc = v3_sub(c, o);
	double x = arc(pb, pc), y = arc(pc, pa), z = arc(pa, pb), s = (x + y + z) / 2;
	double t = tan(s / 2) * tan((s - x) / 2) * tan((s - y) / 2) * tan((s - z) / 2);
	return 4 * atan(sqrt(fmax(0.0, t)));
}

static double quad_solid_angle(vec3 o, vec3 a, vec3 b, vec3 c, vec3 d)
{
	return tri_solid_angle(o, a, b, c) + tri_solid_angle(o, a, c, d);
}

/* A world holding one emissive object o; its emitter. */
static world *one_emitter(object o, const emitter **e)
{
	scene *s = scene_new();
	assert_non_null(s);
	camera c = {v3(0, 0, -10), v3(0, 0, 1), 60, false, 0, 0};
	assert_true(scene_add_camera(s, &c, NULL));
	o.mat.emission = 1;
	assert_true(scene_add_object(s, &o, NULL));
	world *w = world_build(s, NULL);
	assert_non_null(w);
	scene_free(s);
	assert_int_equal(w->nemitters, 1);
	*e = &w->emitters[0];
	return w;
}

/* A rectangle of sides 2a (x) and 2b (z) centred at c, facing -y. */
static object rect(vec3 c, double a, double b)
{
	object o = object_make(OBJ_RECT, v3(255, 255, 255));
	o.pos = c;
	o.dir = v3(0, -1, 0);
	o.scale = v3(2 * a, 1, 2 * b);
	return o;
}

static void test_rect_on_axis(void **state)
{
	(void)state;
	const double a = 0.6, b = 0.35, ds[] = {0.05, 0.3, 0.8, 1.3};
	for (int k = 0; k < 4; k++) {
		const emitter *e;
		world *w = one_emitter(rect(v3(0, 2, 0), a, b), &e);
		double d = ds[k];
		vec3 p = v3(0, 2 - d, 0);
		assert_true(v3_len2(v3_sub(e->l.c, p)) < e->l.reach2);
		double want = 4 * asin(a * b / sqrt((a * a + d * d) * (b * b + d * d)));
		vec3 wi;
		double pdf, t;
		assert_true(emitter_sample(e, p, 0.3, 0.7, &wi, &pdf, &t));
		assert_near(1 / pdf, want, 1e-9 * want);
		assert_near(1 / emitter_pdf(e, p, wi, t), want, 1e-9 * want);
		world_free(w);
	}
}

/* Samples on an n x n grid of (u1, u2) (stratified, so that the shares are
 * exact up to the grid's resolution): every sample on the shape at the
 * distance t along wi; the density 1 / want; the share in each cell of
 * part() as its solid angle predicts. */
typedef int (*part_fn)(vec3 q, const void *ctx);

static void check_uniform(const emitter *e, vec3 p, double want, part_fn part, const void *ctx,
                          const double *share, int nparts)
{
	const int n = 300;
	int count[8] = {0}, total = 0;
	assert_true(v3_len2(v3_sub(e->l.c, p)) < e->l.reach2); /* near: by solid angle */
	for (int i = 0; i < n; i++)
		for (int j = 0; j < n; j++) {
			vec3 wi;
			double pdf, t;
			if (!emitter_sample(e, p, (i + 0.5) / n, (j + 0.5) / n, &wi, &pdf, &t))
				continue;
			assert_near(v3_len(wi), 1, 1e-12);
			assert_near(1 / pdf, want, 1e-9 * want);
			vec3 q = v3_madd(p, wi, t);
			/* on the shape's plane */
			assert_near(v3_dot(v3_sub(q, e->l.c), e->l.n), 0, 1e-9);
			int k = part(q, ctx);
			assert_true(k >= 0 && k < nparts);
			count[k]++;
			total++;
		}
	for (int k = 0; k < nparts; k++)
		assert_near((double)count[k] / total, share[k], 0.004);
}

typedef struct rect_ctx {
	vec3 c;
	double a, b;
} rect_ctx;

static int rect_quadrant(vec3 q, const void *vctx)
{
	const rect_ctx *r = vctx;
	double x = q.x - r->c.x, z = q.z - r->c.z;
	if (fabs(x) > r->a * (1 + 1e-9) || fabs(z) > r->b * (1 + 1e-9))
		return -1; /* off the rectangle */
	return (x > 0) + 2 * (z > 0);
}

static void test_rect_uniform(void **state)
{
	(void)state;
	rect_ctx r = {v3(0.3, 2, -0.2), 0.6, 0.35};
	const vec3 ps[] = {v3(1.1, 1.6, 0.4), v3(0.2, 1.9, -0.1), v3(-0.5, 1.2, 0.5)};
	for (int k = 0; k < 3; k++) {
		const emitter *e;
		world *w = one_emitter(rect(r.c, r.a, r.b), &e);
		vec3 p = ps[k];
		double share[4], total = 0;
		for (int q = 0; q < 4; q++) {
			double x0 = q & 1 ? 0 : -r.a, x1 = q & 1 ? r.a : 0;
			double z0 = q & 2 ? 0 : -r.b, z1 = q & 2 ? r.b : 0;
			vec3 c = r.c;
			share[q] = quad_solid_angle(p, v3(c.x + x0, c.y, c.z + z0), v3(c.x + x1, c.y, c.z + z0),
			                            v3(c.x + x1, c.y, c.z + z1), v3(c.x + x0, c.y, c.z + z1));
			total += share[q];
		}
		for (int q = 0; q < 4; q++)
			share[q] /= total;
		check_uniform(e, p, total, rect_quadrant, &r, share, 4);
		world_free(w);
	}
}

typedef struct tri_ctx {
	vec3 v[3], m[3]; /* vertices, midpoints of the edges v0v1, v1v2, v2v0 */
} tri_ctx;

/* Barycentric coordinates of q in the triangle a, b, c (in its plane). */
static void bary(vec3 q, vec3 a, vec3 b, vec3 c, double *l)
{
	vec3 n = v3_cross(v3_sub(b, a), v3_sub(c, a));
	double nn = v3_len2(n);
	l[0] = v3_dot(v3_cross(v3_sub(c, b), v3_sub(q, b)), n) / nn;
	l[1] = v3_dot(v3_cross(v3_sub(a, c), v3_sub(q, c)), n) / nn;
	l[2] = 1 - l[0] - l[1];
}

static int tri_part(vec3 q, const void *vctx)
{
	const tri_ctx *t = vctx;
	double l[3];
	bary(q, t->v[0], t->v[1], t->v[2], l);
	for (int k = 0; k < 3; k++)
		if (l[k] < -1e-9)
			return -1; /* off the triangle */
	/* the corner triangle at vertex k holds l[k] > 1/2 */
	for (int k = 0; k < 3; k++)
		if (l[k] > 0.5)
			return k;
	return 3; /* the middle one */
}

static void test_triangle(void **state)
{
	(void)state;
	tri_ctx tc;
	tc.v[0] = v3(-0.5, 2, -0.3);
	tc.v[1] = v3(0.7, 2.2, 0.1);
	tc.v[2] = v3(0.1, 1.7, 0.8);
	for (int k = 0; k < 3; k++)
		tc.m[k] = v3_scale(v3_add(tc.v[k], tc.v[(k + 1) % 3]), 0.5);
	object o = object_make(OBJ_TRIANGLE, v3(255, 255, 255));
	for (int k = 0; k < 3; k++)
		o.tri[k] = tc.v[k];
	const emitter *e;
	world *w = one_emitter(o, &e);
	const vec3 ps[] = {v3(0, 1.5, 0), v3(0.1, 2.4, 0.3), v3(1.2, 0.8, -0.6)};
	for (int k = 0; k < 3; k++) {
		vec3 p = ps[k];
		double want = tri_solid_angle(p, tc.v[0], tc.v[1], tc.v[2]);
		double share[4] = {tri_solid_angle(p, tc.v[0], tc.m[0], tc.m[2]),
		                   tri_solid_angle(p, tc.v[1], tc.m[1], tc.m[0]),
		                   tri_solid_angle(p, tc.v[2], tc.m[2], tc.m[1]),
		                   tri_solid_angle(p, tc.m[0], tc.m[1], tc.m[2])};
		double sum = share[0] + share[1] + share[2] + share[3];
		assert_near(sum, want, 1e-9);
		for (int q = 0; q < 4; q++)
			share[q] /= want;
		check_uniform(e, p, want, tri_part, &tc, share, 4);
	}
	world_free(w);
}

/* A disc is sampled through its square: the samples that land in the disc
 * have the square's density, and their share is the disc's solid angle
 * over the square's. */
static void test_disc_on_axis(void **state)
{
	(void)state;
	const double r = 0.5, ds[] = {0.1, 0.5, 1.3};
	for (int k = 0; k < 3; k++) {
		object o = object_make(OBJ_DISC, v3(255, 255, 255));
		o.pos = v3(0, 2, 0);
		o.dir = v3(0, -1, 0);
		o.scale = v3(2 * r, 1, 2 * r);
		const emitter *e;
		world *w = one_emitter(o, &e);
		double d = ds[k];
		vec3 p = v3(0, 2 - d, 0);
		assert_true(v3_len2(v3_sub(e->l.c, p)) < e->l.reach2);
		double square = 4 * asin(r * r / (r * r + d * d)), disc = 2 * RT_PI * (1 - d / sqrt(d * d + r * r));
		const int n = 400;
		int in = 0;
		for (int i = 0; i < n; i++)
			for (int j = 0; j < n; j++) {
				vec3 wi;
				double pdf, t;
				if (!emitter_sample(e, p, (i + 0.5) / n, (j + 0.5) / n, &wi, &pdf, &t))
					continue;
				assert_near(1 / pdf, square, 1e-9 * square);
				vec3 q = v3_madd(p, wi, t);
				assert_true(q.x * q.x + q.z * q.z <= r * r * (1 + 1e-9));
				in++;
			}
		assert_near((double)in / (n * n), disc / square, 0.002);
		world_free(w);
	}
}

/* Beyond SOLID_ANGLE_REACH sizes: area sampling, density t^2 / (cos A). */
static void test_far_by_area(void **state)
{
	(void)state;
	const emitter *e;
	world *w = one_emitter(rect(v3(0, 2, 0), 0.3, 0.2), &e);
	vec3 p = v3(1, -20, 3), wi;
	double pdf, t;
	assert_false(v3_len2(v3_sub(e->l.c, p)) < e->l.reach2);
	assert_true(emitter_sample(e, p, 0.25, 0.75, &wi, &pdf, &t));
	vec3 q = v3_madd(p, wi, t);
	assert_near(q.y, 2, 1e-9);
	assert_near(q.x, -0.15, 1e-9); /* a = 2 u1 - 1 along x, half-side 0.3 */
	assert_near(q.z, -0.1, 1e-9); /* v = R (0, 0, 0.2) = (0, 0, -0.2) facing -y */
	assert_near(pdf, t * t / (fabs(wi.y) * 0.6 * 0.4), 1e-9 * pdf);
	world_free(w);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_rect_on_axis),
		cmocka_unit_test(test_rect_uniform),
		cmocka_unit_test(test_triangle),
		cmocka_unit_test(test_disc_on_axis),
		cmocka_unit_test(test_far_by_area),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
