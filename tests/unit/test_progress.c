/* rtsh — tests of the progress text (shell/progress.h), against values
 * worked out by hand. */
#include "testutil.h"

#include "shell/progress.h"

static void test_text(void **state)
{
	(void)state;
	char buf[256];
	/* 640x360 at 64 spp, a quarter done in 2 s: 16 spp; 6 s left;
	 * 0.25 * 640 * 360 * 64 = 3686400 camera rays in 2 s = 1.8 Mrays/s. */
	progress_state p = {640, 360, 64, 25, 100, 2.0};
	progress_text(&p, 20, buf, sizeof buf);
	assert_string_equal(buf, "[#####...............] 25% 16/64 spp 2.0 s, 6.0 s left 1.8 Mrays/s");
	/* Nothing done yet: no estimate and no speed. */
	p = (progress_state){100, 100, 1, 0, 40, 0.05};
	progress_text(&p, 20, buf, sizeof buf);
	assert_string_equal(buf, "[....................] 0% 0/1 spp 50 ms");
	/* Done: no time left; 100x100x1 rays in 0.5 s = 0.02 Mrays/s. */
	p = (progress_state){100, 100, 1, 40, 40, 0.5};
	progress_text(&p, 20, buf, sizeof buf);
	assert_string_equal(buf, "[####################] 100% 1/1 spp 500 ms 0.0 Mrays/s");
	/* Long renders: minutes. 10% in 30 s leaves 270 s = 4m30s. */
	p = (progress_state){1920, 1080, 1000, 1, 10, 30.0};
	progress_text(&p, 20, buf, sizeof buf);
	assert_string_equal(buf, "[##..................] 10% 100/1000 spp 30 s, 4m30s left 6.9 Mrays/s");
	/* Without a bar, and with a short one (a quarter of 8 is 2). */
	progress_text(&p, 0, buf, sizeof buf);
	assert_string_equal(buf, "10% 100/1000 spp 30 s, 4m30s left 6.9 Mrays/s");
	p.done = 25;
	p.total = 100;
	progress_text(&p, 8, buf, sizeof buf);
	assert_string_equal(buf, "[##......] 25% 250/1000 spp 30 s, 1m30s left 17.3 Mrays/s");
}

static void test_duration(void **state)
{
	(void)state;
	char b[32];
	progress_duration(0.0123, b, sizeof b);
	assert_string_equal(b, "12 ms");
	progress_duration(3.25, b, sizeof b);
	assert_string_equal(b, "3.2 s");
	progress_duration(59.4, b, sizeof b);
	assert_string_equal(b, "59 s");
	progress_duration(125, b, sizeof b);
	assert_string_equal(b, "2m05s");
	progress_duration(-1, b, sizeof b);
	assert_string_equal(b, "0 ms");
}

/* Batch mode's and rtsh-mpi's output: the same text with a bar of 30, after
 * a carriage return, padded to 78 columns (a shorter line covers a longer). */
static void test_print(void **state)
{
	(void)state;
	char out[256] = "";
	FILE *f = fmemopen(out, sizeof out, "w");
	assert_non_null(f);
	progress_state p = {100, 100, 4, 1, 2, 1.0}; /* half done in 1 s: 1 s left */
	progress_print(f, &p);
	fclose(f);
	const char *want = "[###############...............] 50% 2/4 spp 1.0 s, 1.0 s left 0.0 Mrays/s";
	assert_int_equal(out[0], '\r');
	assert_memory_equal(out + 1, want, strlen(want));
	assert_int_equal(strlen(out), 1 + 78);
	for (size_t i = 1 + strlen(want); i < strlen(out); i++)
		assert_int_equal(out[i], ' ');
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_text),
		cmocka_unit_test(test_duration),
		cmocka_unit_test(test_print),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
