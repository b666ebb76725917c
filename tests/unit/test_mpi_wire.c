/* rtsh-mpi's configuration on the wire (src/mpi/wire.h): every field comes
 * back as it went, at the byte offsets and in the byte order the layout in
 * wire.h gives, and damaged or foreign input is refused with a message. */
#include "testutil.h"

#include <math.h>
#include <string.h>

#include "mpi/wire.h"

static job_config sample(test_rng *r)
{
	job_config c;
	memset(&c, 0, sizeof c);
	c.status = (int32_t)trange(r, -1, 3);
	c.verbose = trand(r) < 0.5;
	c.progress = trand(r) < 0.5;
	c.strict = trand(r) < 0.5;
	c.tile = (int32_t)trange(r, 0, 1024);
	c.prefetch = (int32_t)trange(r, -1, 1024);
	c.delay_us = (int32_t)trange(r, 0, 1e7);
	c.set.width = (int32_t)trange(r, 1, RENDER_MAX_DIM);
	c.set.height = (int32_t)trange(r, 1, RENDER_MAX_DIM);
	c.set.samples = (int32_t)trange(r, 1, 1e6);
	c.set.depth = (int32_t)trange(r, 0, 64);
	c.set.threads = (int32_t)trange(r, 0, 256);
	c.set.mode = trand(r) < 0.5 ? MODE_WHITTED : MODE_PATH;
	c.set.seed = (uint64_t)(trand(r) * 4294967296.0) << 32 | (uint64_t)(trand(r) * 4294967296.0);
	c.set.exposure = trange(r, -10, 10);
	c.set.denoise = (int)trange(r, DENOISE_AUTO, DENOISE_OFF + 0.999);
	c.set.pixels = (int)trange(r, 0, 4.999); /* sent by no one (assert_same) */
	c.set.symbols = (int)trange(r, 0, 4.999);
	c.files = (uint64_t)(trand(r) * 1e15);
	return c;
}

static void assert_same(const job_config *a, const job_config *b)
{
	assert_int_equal(a->status, b->status);
	assert_int_equal(a->verbose, b->verbose);
	assert_int_equal(a->progress, b->progress);
	assert_int_equal(a->strict, b->strict);
	assert_int_equal(a->tile, b->tile);
	assert_int_equal(a->prefetch, b->prefetch);
	assert_int_equal(a->delay_us, b->delay_us);
	assert_int_equal(a->set.width, b->set.width);
	assert_int_equal(a->set.height, b->set.height);
	assert_int_equal(a->set.samples, b->set.samples);
	assert_int_equal(a->set.depth, b->set.depth);
	assert_int_equal(a->set.threads, b->set.threads);
	assert_int_equal(a->set.mode, b->set.mode);
	assert_true(a->set.seed == b->set.seed);
	assert_memory_equal(&a->set.exposure, &b->set.exposure, sizeof(double));
	assert_int_equal(a->set.denoise, b->set.denoise);
	/* the terminal's choices do not travel: the receiver has the defaults */
	render_settings def = render_settings_default();
	assert_int_equal(b->set.pixels, def.pixels);
	assert_int_equal(b->set.symbols, def.symbols);
	assert_true(a->files == b->files);
}

static void test_round_trip(void **state)
{
	(void)state;
	test_rng r = {7};
	unsigned char buf[WIRE_CONFIG_SIZE];
	char why[256];
	for (int i = 0; i < 1000; i++) {
		job_config a = sample(&r), b;
		memset(&b, 0xa5, sizeof b);
		wire_put_config(&a, buf);
		if (!wire_get_config(&b, buf, why, sizeof why))
			fail_msg("%d: %s", i, why);
		assert_same(&a, &b);
	}
	/* the defaults, and extremes */
	job_config a, b;
	memset(&a, 0, sizeof a);
	a.status = -1;
	a.set = render_settings_default();
	a.set.seed = UINT64_MAX;
	a.set.exposure = -0.0;
	a.files = UINT64_MAX;
	a.prefetch = -1;
	wire_put_config(&a, buf);
	assert_true(wire_get_config(&b, buf, why, sizeof why));
	assert_same(&a, &b);
	assert_true(signbit(b.set.exposure));
}

/* The bytes, from the layout in wire.h: header 16 bytes, seven i32 (28),
 * then the settings in the settings table's order: width at 44, height 48,
 * samples 52, depth 56, mode 60, threads 64, seed 68, exposure 76,
 * denoise 84 (not the terminal's pixels and symbols); files 88;
 * little-endian. */
static void test_layout(void **state)
{
	(void)state;
	job_config a;
	memset(&a, 0, sizeof a);
	a.status = -1;
	a.tile = 0x0a0b0c0d;
	a.prefetch = -2;
	a.set = render_settings_default();
	a.set.width = 0x1234;
	a.set.mode = MODE_PATH;
	a.set.seed = 0x0102030405060708ull;
	a.set.exposure = 1.5; /* IEEE 754: 0x3ff8000000000000 */
	a.files = 0x1122334455667788ull;
	unsigned char buf[WIRE_CONFIG_SIZE];
	memset(buf, 0xee, sizeof buf);
	wire_put_config(&a, buf);
	static const unsigned char head[16] = {'R', 'T', 'S', 'H', 'M', 'P', 'I', 0, 5, 0, 0, 0, 80, 0, 0, 0};
	assert_memory_equal(buf, head, 16);
	static const unsigned char status[4] = {0xff, 0xff, 0xff, 0xff}, tile[4] = {0x0d, 0x0c, 0x0b, 0x0a},
	                           prefetch[4] = {0xfe, 0xff, 0xff, 0xff}, width[4] = {0x34, 0x12, 0, 0},
	                           mode[4] = {1, 0, 0, 0},
	                           seed[8] = {8, 7, 6, 5, 4, 3, 2, 1},
	                           exposure[8] = {0, 0, 0, 0, 0, 0, 0xf8, 0x3f},
	                           files[8] = {0x88, 0x77, 0x66, 0x55, 0x44, 0x33, 0x22, 0x11};
	assert_memory_equal(buf + 16, status, 4);
	assert_memory_equal(buf + 32, tile, 4);
	assert_memory_equal(buf + 36, prefetch, 4);
	assert_memory_equal(buf + 44, width, 4);
	assert_memory_equal(buf + 60, mode, 4);
	assert_memory_equal(buf + 68, seed, 8);
	assert_memory_equal(buf + 76, exposure, 8);
	assert_memory_equal(buf + 88, files, 8);
	for (int i = 96; i < WIRE_CONFIG_SIZE; i++)
		assert_int_equal(buf[i], 0);
}

/* decode(buf) must fail with a message naming what. */
static void expect_refused(const unsigned char *buf, const char *what)
{
	job_config c;
	memset(&c, 0x5a, sizeof c);
	job_config before = c;
	char why[256] = "";
	assert_false(wire_get_config(&c, buf, why, sizeof why));
	if (!strstr(why, what))
		fail_msg("expected \"%s\" in \"%s\"", what, why);
	assert_memory_equal(&c, &before, sizeof c); /* untouched */
}

static void test_refused(void **state)
{
	(void)state;
	job_config a;
	memset(&a, 0, sizeof a);
	a.status = -1;
	a.set = render_settings_default();
	unsigned char good[WIRE_CONFIG_SIZE], buf[WIRE_CONFIG_SIZE];
	wire_put_config(&a, good);
	memcpy(buf, good, sizeof buf);
	buf[0] = 'X';
	expect_refused(buf, "RTSHMPI");
	memcpy(buf, good, sizeof buf);
	buf[8] = 1; /* version 1 (before `symbols`) */
	expect_refused(buf, "version 1");
	memcpy(buf, good, sizeof buf);
	buf[8] = 2; /* version 2 (mode after threads) */
	expect_refused(buf, "version 2");
	memcpy(buf, good, sizeof buf);
	buf[8] = 3; /* version 3 (with the terminal's pixels and symbols) */
	expect_refused(buf, "version 3");
	memcpy(buf, good, sizeof buf);
	buf[8] = 4; /* version 4 (the farm's one pass of a denoised image) */
	expect_refused(buf, "version 4");
	memcpy(buf, good, sizeof buf);
	buf[60] = 7; /* mode */
	expect_refused(buf, "mode = 7");
	memcpy(buf, good, sizeof buf);
	memset(buf + 44, 0, 4); /* width 0 */
	expect_refused(buf, "width = 0");
	memcpy(buf, good, sizeof buf);
	memset(buf + 76, 0xff, 8); /* exposure NaN */
	expect_refused(buf, "exposure");
	memcpy(buf, good, sizeof buf);
	buf[84] = 9; /* denoise */
	expect_refused(buf, "denoise = 9");
	/* a job that will not render (status >= 0) carries no image size */
	a.status = 1;
	a.set.width = 0;
	wire_put_config(&a, buf);
	job_config b;
	char why[256];
	assert_true(wire_get_config(&b, buf, why, sizeof why));
	assert_int_equal(b.status, 1);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_round_trip),
	    cmocka_unit_test(test_layout),
	    cmocka_unit_test(test_refused),
	};
	return cmocka_run_group_tests_name("mpi_wire", tests, NULL, NULL);
}
