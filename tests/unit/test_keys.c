/* rtsh — tests of key mode's key reader fed by the event loop (term/keys.h,
 * keys_open_fed): bytes given with keys_feed come out as keys, decoded with
 * xterm's terminfo (keypad transmit mode: Up is ESC O A, F1 ESC O P,
 * Shift+Tab ESC [ Z), a lone Esc is Esc after the delay, and a terminal's
 * late status answer is no key. Skipped when terminfo has no xterm. */
#include "testutil.h"

#include <stdlib.h>
#include <time.h>

#include "term/keys.h"

static keys *open_xterm(void)
{
	setenv("TERM", "xterm", 1);
	return keys_open_fed(10);
}

/* The next key, waiting up to a second for ncurses to see the bytes. */
static int next_key(keys *k)
{
	for (int i = 0; i < 1000; i++) {
		int c = keys_next(k);
		if (c != KEYS_NONE)
			return c;
		struct timespec ts = {0, 1000000};
		nanosleep(&ts, NULL);
	}
	return KEYS_NONE;
}

static void test_fed_keys(void **state)
{
	(void)state;
	keys *k = open_xterm();
	if (!k)
		skip(); /* no terminfo entry for xterm here */
	assert_true(keys_feed(k, "a\x1bOA\x1bOP\x1b[Z", 10));
	assert_int_equal(next_key(k), 'a');
	assert_int_equal(next_key(k), KEYS_UP);
	assert_int_equal(next_key(k), KEYS_F(1));
	assert_int_equal(next_key(k), KEYS_BACKTAB);
	assert_int_equal(keys_next(k), KEYS_NONE);
	/* A late answer to a status query: no key (not Esc then "[0n"). */
	assert_true(keys_feed(k, "\x1b[0nq", 5));
	assert_int_equal(next_key(k), KEYS_OTHER);
	assert_int_equal(next_key(k), 'q');
	/* A lone Esc: Esc once the delay passed. */
	assert_true(keys_feed(k, "\x1b", 1));
	assert_int_equal(next_key(k), KEYS_ESC);
	keys_close(k);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_fed_keys),
	};
	return cmocka_run_group_tests_name("keys", tests, NULL, NULL);
}
