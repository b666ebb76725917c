/* rtsh — tests of the math value types: matrices, inverses, transforms. */
#include "testutil.h"

#include "rtsh/num.h"
#include "rtsh/scene.h"
#include "rtsh/srgb.h"

static void assert_identity(mat4 m, double tol)
{
	for (int i = 0; i < 4; i++)
		for (int j = 0; j < 4; j++)
			assert_near(m.m[i][j], i == j ? 1.0 : 0.0, tol);
}

static mat4 random_affine(test_rng *r)
{
	double sh[6];
	for (int i = 0; i < 6; i++)
		sh[i] = trange(r, -0.4, 0.4);
	mat4 m = m4_translate(v3(trange(r, -10, 10), trange(r, -10, 10), trange(r, -10, 10)));
	m = m4_mul(m, m4_rotate_axis(tdir(r), trange(r, 0, 2 * RT_PI)));
	m = m4_mul(m, m4_shear(sh));
	return m4_mul(m, m4_scale(v3(trange(r, 0.1, 5), trange(r, 0.1, 5), trange(r, 0.1, 5))));
}

static void test_inverse_product_is_identity(void **state)
{
	(void)state;
	test_rng r = {42};
	for (int k = 0; k < 1000; k++) {
		mat4 m = random_affine(&r), inv;
		assert_true(m4_invert(m, &inv));
		assert_identity(m4_mul(m, inv), 1e-12);
		assert_identity(m4_mul(inv, m), 1e-12);
	}
	/* A general (projective) matrix with a hand-checked inverse:
	 * [[2,0,0,0],[0,4,0,0],[0,0,8,0],[1,0,0,1]]^-1 = [[.5,0,0,0],[0,.25,0,0],[0,0,.125,0],[-.5,0,0,1]] */
	mat4 p = {{{2, 0, 0, 0}, {0, 4, 0, 0}, {0, 0, 8, 0}, {1, 0, 0, 1}}}, pinv;
	assert_true(m4_invert(p, &pinv));
	assert_near(pinv.m[0][0], 0.5, 1e-15);
	assert_near(pinv.m[1][1], 0.25, 1e-15);
	assert_near(pinv.m[2][2], 0.125, 1e-15);
	assert_near(pinv.m[3][0], -0.5, 1e-15);
	assert_near(pinv.m[3][3], 1.0, 1e-15);
}

static void test_singular_matrices_are_refused(void **state)
{
	(void)state;
	mat4 out = m4_identity();
	assert_false(m4_invert(m4_scale(v3(1, 0, 1)), &out));
	/* Shearing x by y and y by x with both 1 flattens the xy plane. */
	double sh[6] = {1, 0, 1, 0, 0, 0};
	assert_false(m4_invert(m4_shear(sh), &out));
	mat4 nan = m4_identity();
	nan.m[1][2] = NAN;
	assert_false(m4_invert(nan, &out));
	assert_identity(out, 0); /* untouched */
}

static void test_points_vectors_normals(void **state)
{
	(void)state;
	mat4 t = m4_translate(v3(1, -2, 3));
	assert_vec_near(m4_point(&t, v3(1, 1, 1)), v3(2, -1, 4), 0);
	/* vectors ignore translation */
	assert_vec_near(m4_vector(&t, v3(1, 1, 1)), v3(1, 1, 1), 0);

	mat4 s = m4_scale(v3(2, 3, 4));
	assert_vec_near(m4_point(&s, v3(1, 1, 1)), v3(2, 3, 4), 0);

	/* Quarter turns: x to y about z, y to z about x, z to x about y. */
	mat4 rz = m4_rotate_z(RT_PI / 2), rx = m4_rotate_x(RT_PI / 2), ry = m4_rotate_y(RT_PI / 2);
	assert_vec_near(m4_vector(&rz, v3(1, 0, 0)), v3(0, 1, 0), 1e-15);
	assert_vec_near(m4_vector(&rx, v3(0, 1, 0)), v3(0, 0, 1), 1e-15);
	assert_vec_near(m4_vector(&ry, v3(0, 0, 1)), v3(1, 0, 0), 1e-15);

	/* Each shear component moves one coordinate in proportion to another. */
	const vec3 p = {2, 3, 4};
	const vec3 expect[6] = {{2 + 3, 3, 4}, {2 + 4, 3, 4}, {2, 3 + 2, 4},
	                        {2, 3 + 4, 4}, {2, 3, 4 + 2}, {2, 3, 4 + 3}};
	for (int i = 0; i < 6; i++) {
		double sh[6] = {0};
		sh[i] = 1;
		mat4 m = m4_shear(sh);
		assert_vec_near(m4_point(&m, p), expect[i], 0);
	}

	/* The ellipsoid x^2 + 4y^2 + z^2 = 1 is the unit sphere scaled by
	 * (1, 1/2, 1). At its point (0.6, 0.4, 0) the gradient (2x, 8y, 2z) is
	 * (1.2, 3.2, 0): the normal is (1.2, 3.2, 0) / |(1.2, 3.2, 0)|. The
	 * sphere's own normal there is its local point (0.6, 0.8, 0). */
	xform x;
	assert_true(xf_make(m4_scale(v3(1, 0.5, 1)), &x));
	vec3 local = m4_point(&x.inv, v3(0.6, 0.4, 0));
	assert_vec_near(local, v3(0.6, 0.8, 0), 1e-15);
	vec3 n = v3_norm(m4_normal(&x.inv, local));
	double len = sqrt(1.2 * 1.2 + 3.2 * 3.2);
	assert_vec_near(n, v3(1.2 / len, 3.2 / len, 0), 1e-15);
}

static void test_transform_composition(void **state)
{
	(void)state;
	xform a, b;
	assert_true(xf_make(m4_scale(v3(2, 2, 2)), &a));
	assert_true(xf_make(m4_translate(v3(1, 0, 0)), &b));
	/* scale first, then translate: (1,1,1) -> (2,2,2) -> (3,2,2) */
	xform ab = xf_then(a, b);
	assert_vec_near(m4_point(&ab.m, v3(1, 1, 1)), v3(3, 2, 2), 0);
	assert_vec_near(m4_point(&ab.inv, v3(3, 2, 2)), v3(1, 1, 1), 0);
	/* the box of a unit cube turned 45 degrees about y */
	xform r;
	assert_true(xf_make(m4_rotate_y(RT_PI / 4), &r));
	box bb = xf_box(&r, (box){v3(-1, -1, -1), v3(1, 1, 1)});
	assert_near(bb.hi.x, sqrt(2.0), 1e-12);
	assert_near(bb.lo.z, -sqrt(2.0), 1e-12);
	assert_near(bb.hi.y, 1.0, 1e-12);
}

static void test_orient(void **state)
{
	(void)state;
	test_rng r = {7};
	for (int k = 0; k < 500; k++) {
		vec3 d = tdir(&r);
		double tw = trange(&r, -RT_PI, RT_PI);
		mat4 m = m4_orient(d, tw);
		/* +Y goes to d, and the matrix is a rotation: M M^T = I, det +1 */
		assert_vec_near(m4_vector(&m, v3(0, 1, 0)), d, 1e-12);
		mat4 mmt = m4_mul(m, m4_transpose(m));
		assert_identity(mmt, 1e-12);
		vec3 c0 = v3(m.m[0][0], m.m[1][0], m.m[2][0]), c1 = v3(m.m[0][1], m.m[1][1], m.m[2][1]),
		     c2 = v3(m.m[0][2], m.m[1][2], m.m[2][2]);
		assert_near(v3_dot(v3_cross(c0, c1), c2), 1.0, 1e-12);
	}
	/* straight down: a half turn about x */
	mat4 down = m4_orient(v3(0, -1, 0), 0);
	assert_vec_near(m4_vector(&down, v3(0, 1, 0)), v3(0, -1, 0), 1e-15);
	/* +Y unchanged by the shortest arc, and a twist of 90 degrees turns
	 * x to -z (a right-handed turn about y). */
	mat4 up = m4_orient(v3(0, 1, 0), RT_PI / 2);
	assert_vec_near(m4_vector(&up, v3(1, 0, 0)), v3(0, 0, -1), 1e-15);
}

/* Rotating an object composes a world rotation with its orientation, and the
 * (dir, twist) it keeps rebuild exactly that orientation. */
static void test_object_rotate(void **state)
{
	(void)state;
	test_rng r = {99};
	for (int k = 0; k < 300; k++) {
		object o = object_make(OBJ_CUBE, v3(255, 255, 255));
		o.dir = v3_scale(tdir(&r), trange(&r, 0.5, 3)); /* as written: any length */
		o.twist = trange(&r, -180, 180);
		o.pos = v3(1, 2, 3);
		vec3 deg = v3(trange(&r, -180, 180), trange(&r, -180, 180), trange(&r, -180, 180));
		mat4 before = m4_orient(v3_norm(o.dir), deg_to_rad(o.twist));
		mat4 q = m4_mul(m4_rotate_z(deg_to_rad(deg.z)),
		                m4_mul(m4_rotate_y(deg_to_rad(deg.y)), m4_rotate_x(deg_to_rad(deg.x))));
		assert_true(object_rotate(&o, deg, NULL));
		mat4 after = m4_orient(v3_norm(o.dir), deg_to_rad(o.twist));
		mat4 expect = m4_mul(q, before);
		for (int i = 0; i < 3; i++)
			for (int j = 0; j < 3; j++)
				assert_near(after.m[i][j], expect.m[i][j], 1e-9);
		assert_vec_near(o.pos, v3(1, 2, 3), 0); /* about its own centre */
	}
	/* 90 degrees about z turns an upright cylinder's axis to -x. */
	object c = object_make(OBJ_CYLINDER, v3(1, 1, 1));
	assert_true(object_rotate(&c, v3(0, 0, 90), NULL));
	assert_vec_near(c.dir, v3(-1, 0, 0), 1e-15);
}

static void test_object_xform_sizes(void **state)
{
	(void)state;
	/* scale = diameters: a sphere of scale (2,4,6) reaches 1, 2, 3 from its
	 * centre along x, y, z. */
	object o = object_make(OBJ_SPHERE, v3(1, 1, 1));
	o.scale = v3(2, 4, 6);
	o.pos = v3(10, 0, 0);
	xform x;
	assert_true(object_xform(&o, &x));
	assert_vec_near(m4_point(&x.m, v3(1, 0, 0)), v3(11, 0, 0), 1e-15);
	assert_vec_near(m4_point(&x.m, v3(0, 1, 0)), v3(10, 2, 0), 1e-15);
	assert_vec_near(m4_point(&x.m, v3(0, 0, 1)), v3(10, 0, 3), 1e-15);
	/* a cylinder along x of diameter 2, height 4: its cap centre (local y=1)
	 * is 2 along x */
	object c = object_make(OBJ_CYLINDER, v3(1, 1, 1));
	c.dir = v3(3, 0, 0);
	c.scale = v3(2, 4, 2);
	assert_true(object_xform(&c, &x));
	assert_vec_near(m4_point(&x.m, v3(0, 1, 0)), v3(2, 0, 0), 1e-15);
	/* a shear that flattens is reported */
	object bad = object_make(OBJ_CUBE, v3(1, 1, 1));
	bad.shear[0] = 1;
	bad.shear[2] = 1;
	rt_error err;
	assert_false(object_validate(&bad, &err));
	assert_non_null(strstr(err.msg, "not invertible"));
}

/* Sums in the decimals written (issue 31, friction 7): the exact decimal
 * sums, worked by hand, against the plain double sums that drift. */
static void test_add_decimal(void **state)
{
	(void)state;
	double x = 0.1, plain = 0.1;
	for (int i = 0; i < 500; i++) {
		x = num_add_decimal(x, 0.001);
		plain += 0.001;
	}
	assert_true(x == 0.6);
	assert_true(plain != 0.6); /* what the test guards against */
	x = 0;
	for (int i = 0; i < 2000; i++)
		x = num_add_decimal(x, -0.001);
	assert_true(x == -2.0);
	assert_true(num_add_decimal(0.1, 0.2) == 0.3);
	assert_true(num_add_decimal(1e20, 0.5) == 1e20 + 0.5);      /* beyond a double's decimals: the sum */
	assert_true(num_add_decimal(1.0 / 3.0, 0.1) == 1.0 / 3.0 + 0.1); /* 17 digits: the sum */
	assert_true(num_add_decimal(0.123456789012, 1) == 1.123456789012);
	assert_false(signbit(num_add_decimal(-0.001, 0.001))); /* 0, not -0 */
}

/* num_scan reads a decimal to the double strtod gives (correctly rounded,
 * C library): its exact short path (at most 15 digits, |exponent| <= 22)
 * and its strtod path agree with strtod on random decimals of 1 to 20
 * digits, either side of the point, with exponents, signs and zeros; and
 * the values worked by hand. */
static void test_scan_matches_strtod(void **state)
{
	(void)state;
	double v;
	assert_int_equal(num_scan_str("0.1", 1e9, &v), NUM_OK);
	assert_true(v == 0.1);
	assert_int_equal(num_scan_str("-0", 1e9, &v), NUM_OK);
	assert_true(v == 0 && signbit(v));
	assert_int_equal(num_scan_str("-0.000e30", 1e9, &v), NUM_OK);
	assert_true(v == 0 && signbit(v));
	assert_int_equal(num_scan_str("123456789012345", 1e20, &v), NUM_OK);
	assert_true(v == 123456789012345.0);
	assert_int_equal(num_scan_str("9007199254740993", 1e20, &v), NUM_OK); /* 2^53 + 1: ties to even */
	assert_true(v == 9007199254740992.0);
	assert_int_equal(num_scan_str("1e22", 1e30, &v), NUM_OK);
	assert_true(v == 1e22);
	assert_int_equal(num_scan_str("1e23", 1e30, &v), NUM_OK); /* past the exact powers */
	assert_true(v == 1e23);
	assert_int_equal(num_scan_str("2.5e-3", 1, &v), NUM_OK);
	assert_true(v == 0.0025);
	assert_int_equal(num_scan_str("1e5", 1e4, &v), NUM_BIG);
	assert_int_equal(num_scan_str("1e99999999999", 1e300, &v), NUM_BIG);
	assert_int_equal(num_scan_str("0e99999999999", 1, &v), NUM_OK);
	assert_true(v == 0);
	/* the grammar (num.h): what is refused */
	static const char *const bad[] = {"", ".", "+", "-.", "1e", "1e+", "e5", "1.2.3", "1,5", " 1", "1 ",
	                                  "0x10", "inf", "nan", "1e5x", "--1", "1.5e-", "12345678901234567890x"};
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
		assert_int_not_equal(num_scan_str(bad[i], 1e300, &v), NUM_OK);
	static const char *const good[] = {"1.", ".5", "+.5e-1", "-0.", "00012", "1E3", "12345678901234567890"};
	for (size_t i = 0; i < sizeof good / sizeof good[0]; i++) {
		assert_int_equal(num_scan_str(good[i], 1e300, &v), NUM_OK);
		assert_true(v == strtod(good[i], NULL));
	}
	uint64_t x = 88172645463325252ull; /* xorshift64 (Marsaglia 2003) */
	for (int i = 0; i < 200000; i++) {
		char t[64];
		size_t n = 0;
		x ^= x << 13, x ^= x >> 7, x ^= x << 17;
		uint64_t r = x;
		if (r & 1)
			t[n++] = r & 2 ? '-' : '+';
		r >>= 2;
		int whole = (int)(r % 12), frac = (int)((r >> 4) % 12);
		r >>= 8;
		if (whole == 0 && frac == 0)
			whole = 1;
		for (int k = 0; k < whole; k++, r = r * 6364136223846793005ull + 1442695040888963407ull)
			t[n++] = (char)('0' + (r >> 59) % 10 * (k > 0 || (r >> 40) % 4 != 0));
		if (frac) {
			t[n++] = '.';
			for (int k = 0; k < frac; k++, r = r * 6364136223846793005ull + 1442695040888963407ull)
				t[n++] = (char)('0' + (r >> 59) % 10);
		}
		if ((x >> 60) % 3 == 0)
			n += (size_t)snprintf(t + n, sizeof t - n, "e%d", (int)((x >> 32) % 61) - 30);
		t[n] = '\0';
		double want = strtod(t, NULL);
		assert_int_equal(num_scan_str(t, 1e300, &v), NUM_OK);
		if (memcmp(&v, &want, sizeof v) != 0)
			fail_msg("%s: num_scan %.17g, strtod %.17g", t, v, want);
	}
}

/* The 8-bit code of linear v from the definition: the k whose interval
 * [decode((k - 0.5) / 255), decode((k + 0.5) / 255)) holds v, clamped;
 * found from 255 x the encoding and corrected by those bounds. */
static int srgb8_reference(double v)
{
	if (!(v > 0.0))
		return 0;
	if (v >= 1.0)
		return 255;
	double e = v <= 0.0031308 ? v * 12.92 : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
	int k = (int)floor(255.0 * e + 0.5);
	k = k < 0 ? 0 : k > 255 ? 255 : k;
	while (k < 255 && v >= srgb_to_linear((k + 0.5) / 255.0))
		k++;
	while (k > 0 && v < srgb_to_linear((k - 0.5) / 255.0))
		k--;
	return k;
}

static void check_srgb8_n(const float *in, size_t n, double gain)
{
	uint8_t out[64];
	assert_true(n <= 64);
	linear_to_srgb8_n(in, gain, out, n);
	for (size_t i = 0; i < n; i++)
		if (out[i] != srgb8_reference(in[i] * gain))
			fail_msg("linear_to_srgb8_n(%.9g x %.17g) = %d; the definition gives %d", (double)in[i], gain,
			         out[i], srgb8_reference(in[i] * gain));
}

/* linear_to_srgb8_n, whose buckets are cut by the bits of the value: every
 * bucket's first and last float, the floats around every code's lower
 * bound, the edges, and random values and gains, against the definition. */
static void test_srgb8_codes(void **state)
{
	(void)state;
	float in[64];
	size_t n = 0;
	/* floats from 2^-14 to 1: each 1/1024 of a binade's first and last */
	for (uint32_t b = 0; b < 14u * 1024u; b++) {
		uint32_t first = ((uint32_t)(127 - 14) << 23) + (b << 13), last = first + 0x1fff;
		memcpy(&in[n++], &first, sizeof first);
		memcpy(&in[n++], &last, sizeof last);
		if (n == 64) {
			check_srgb8_n(in, n, 1.0);
			n = 0;
		}
	}
	/* around each code's lower bound, in floats (gain 1) and in doubles
	 * (the float 1 times a gain that is the bound's neighbour) */
	for (int k = 1; k < 256; k++) {
		double t = srgb_to_linear((k - 0.5) / 255.0);
		float f = (float)t;
		for (int d = 0; d < 4; d++) {
			f = nextafterf(f, 0.0f);
		}
		for (int d = 0; d < 9; d++, f = nextafterf(f, 2.0f))
			check_srgb8_n(&f, 1, 1.0);
		float one = 1.0f;
		double g = t;
		for (int d = 0; d < 4; d++)
			g = nextafter(g, 0.0);
		for (int d = 0; d < 9; d++, g = nextafter(g, 2.0))
			check_srgb8_n(&one, 1, g);
	}
	float edges[] = {0.0f, -0.0f, -1.0f, NAN, INFINITY, -INFINITY, 1.0f, nextafterf(1.0f, 0.0f), 0x1p-13f,
	                 nextafterf(0x1p-13f, 0.0f), 0x1p-149f, 1e-30f, 2.0f, 1e30f};
	size_t ne = sizeof edges / sizeof edges[0];
	check_srgb8_n(edges, ne, 1.0);
	check_srgb8_n(edges, ne, 0.5);
	check_srgb8_n(edges, ne, 3.7);
	test_rng r = {7};
	for (int round = 0; round < 20000; round++) {
		double gain = exp2(trange(&r, -4.0, 4.0));
		for (int i = 0; i < 64; i++)
			in[i] = (float)(round % 2 ? trange(&r, 0.0, 1.2) : exp2(trange(&r, -16.0, 0.5)));
		check_srgb8_n(in, 64, round % 3 ? gain : 1.0);
	}
}

/* object_validate passes the common objects (no shear, direction and sizes
 * within 1e-50..1e50) without building their transform: each one it passes
 * must have a transform object_xform can make. Random kinds, directions
 * (some within 1e-7..1e-20 of straight down, where the rotation is the
 * least exact), twists, positions, and lengths and sizes from 1e-120 to
 * 1e120 (beyond the bounds, where the transform can fail: those the
 * shortcut must leave to the full check). */
static void test_validate_without_transform(void **state)
{
	(void)state;
	test_rng r = {11};
	int passed = 0, shortcut_range = 0;
	for (int k = 0; k < 200000; k++) {
		obj_kind kind = (obj_kind)(k % OBJ_KIND_COUNT);
		if (obj_kind_flags(kind) & (KIND_VERTICES | KIND_MODEL))
			continue;
		object o = object_make(kind, v3(1, 1, 1));
		vec3 d = k % 5 == 0 ? v3(pow(10.0, trange(&r, -20, -7)) * trange(&r, -1, 1), -1,
		                         pow(10.0, trange(&r, -20, -7)) * trange(&r, -1, 1))
		                    : tdir(&r);
		double wide = k % 2 ? 120 : 55;
		o.dir = v3_scale(d, pow(10.0, trange(&r, -wide, wide)));
		o.scale = v3(pow(10.0, trange(&r, -wide, wide)), pow(10.0, trange(&r, -wide, wide)),
		             pow(10.0, trange(&r, -wide, wide)));
		if (k % 3 == 0)
			o.scale = v3(o.scale.x, o.scale.x, o.scale.x);
		o.twist = k % 4 ? trange(&r, -1e6, 1e6) : 0;
		o.pos = v3(trange(&r, -1e300, 1e300), trange(&r, -1, 1), pow(10.0, trange(&r, -300, 300)));
		xform x;
		if (object_validate(&o, NULL)) {
			passed++;
			if (!object_xform(&o, &x))
				fail_msg("kind %d dir %g,%g,%g scale %g,%g,%g twist %g: validated, but no transform", kind,
				         o.dir.x, o.dir.y, o.dir.z, o.scale.x, o.scale.y, o.scale.z, o.twist);
		}
		double len = v3_len(o.dir);
		shortcut_range += len >= 1e-50 && len <= 1e50;
	}
	assert_true(passed > 50000 && shortcut_range > 50000);
}

/* The short decimals num_scan reads in one pass (at most 15 digits, no
 * exponent) and those just beyond (16 digits, leading zeros counted):
 * every length from 1 to 17 digits with the point at every place, signs,
 * leading zeros, against strtod, bit for bit (-0 included). */
static void test_scan_short_decimals(void **state)
{
	(void)state;
	uint64_t r = 99;
	for (int n = 1; n <= 17; n++)
		for (int point = 0; point <= n; point++)
			for (int k = 0; k < 40; k++) {
				char t[40];
				size_t len = 0;
				if (k % 3)
					t[len++] = k % 3 == 1 ? '-' : '+';
				for (int i = 0; i < n; i++) {
					if (i == point && point > 0)
						t[len++] = '.';
					r = r * 6364136223846793005ull + 1442695040888963407ull;
					int digit = (int)((r >> 59) % 10);
					if (k % 4 == 0 && i < n / 2)
						digit = 0; /* leading zeros */
					if (k == 39)
						digit = 0; /* all zeros: 0 or -0 */
					t[len++] = (char)('0' + digit);
				}
				if (point == n && k % 2)
					t[len++] = '.'; /* "12." */
				if (point == 0 && k % 5 == 1) {
					memmove(t + (k % 3 ? 2 : 1), t + (k % 3 ? 1 : 0), len - (k % 3 ? 1 : 0));
					t[k % 3 ? 1 : 0] = '.'; /* ".5", "-.5" */
					len++;
				}
				t[len] = '\0';
				double v, want = strtod(t, NULL);
				assert_int_equal(num_scan_str(t, 1e300, &v), NUM_OK);
				if (memcmp(&v, &want, sizeof v) != 0)
					fail_msg("%s: num_scan %.17g, strtod %.17g", t, v, want);
			}
	double v;
	const char *bad[] = {"-", "+", ".", "-.", "1.2.3", "1-", "--1", "1 ", "0x1"};
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
		assert_int_equal(num_scan_str(bad[i], 1e300, &v), NUM_BAD);
	assert_int_equal(num_scan_str("123456789012345", 1e14, &v), NUM_BIG);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_inverse_product_is_identity),
		cmocka_unit_test(test_add_decimal),
		cmocka_unit_test(test_scan_matches_strtod),
		cmocka_unit_test(test_scan_short_decimals),
		cmocka_unit_test(test_singular_matrices_are_refused),
		cmocka_unit_test(test_points_vectors_normals),
		cmocka_unit_test(test_transform_composition),
		cmocka_unit_test(test_orient),
		cmocka_unit_test(test_object_rotate),
		cmocka_unit_test(test_object_xform_sizes),
		cmocka_unit_test(test_srgb8_codes),
		cmocka_unit_test(test_validate_without_transform),
	};
	return cmocka_run_group_tests_name("math", tests, NULL, NULL);
}
