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

/* SGR mouse reports (xterm's ctlseqs, "SGR (1006)"): button bits 0-1,
 * +4 Shift, +8 Meta, +16 Ctrl, +32 motion, +64 the wheel; M a press or a
 * motion, m a release. */
static void test_mouse_reports(void **state)
{
	(void)state;
	keys_mouse m;
	assert_int_equal(keys_parse_mouse("0;10;5M", 7, &m), 7);
	assert_int_equal(m.button, KEYS_BUTTON_LEFT);
	assert_int_equal(m.x, 10);
	assert_int_equal(m.y, 5);
	assert_false(m.release || m.motion || m.shift);
	assert_int_equal(keys_parse_mouse("32;11;5Mq", 9, &m), 8);
	assert_true(m.motion);
	assert_int_equal(m.button, KEYS_BUTTON_LEFT);
	assert_int_equal(keys_parse_mouse("0;11;5m", 7, &m), 7);
	assert_true(m.release);
	assert_int_equal(keys_parse_mouse("36;200;100M", 11, &m), 11);
	assert_true(m.shift && m.motion);
	assert_int_equal(m.x, 200);
	assert_int_equal(keys_parse_mouse("1;3;4M", 6, &m), 6);
	assert_int_equal(m.button, KEYS_BUTTON_MIDDLE);
	assert_int_equal(keys_parse_mouse("64;3;4M", 7, &m), 7);
	assert_int_equal(m.button, KEYS_WHEEL_UP);
	assert_int_equal(keys_parse_mouse("65;3;4M", 7, &m), 7);
	assert_int_equal(m.button, KEYS_WHEEL_DOWN);
	assert_int_equal(keys_parse_mouse("35;3;4M", 7, &m), 7);
	assert_int_equal(m.button, KEYS_BUTTON_NONE);
	assert_int_equal(keys_parse_mouse("24;3;4M", 7, &m), 7);
	assert_true(m.ctrl && m.meta);
	/* Cut short, or not a report. */
	assert_int_equal(keys_parse_mouse("0;10;5", 6, &m), 0);
	assert_int_equal(keys_parse_mouse("0;10", 4, &m), 0);
	assert_int_equal(keys_parse_mouse("0;a;5M", 6, &m), 0);
	assert_int_equal(keys_parse_mouse("0;10;5X", 7, &m), 0);
	assert_int_equal(keys_parse_mouse(";10;5M", 6, &m), 0);
	assert_int_equal(keys_parse_mouse("0;1234567;5M", 12, &m), 0);
}

/* The reports through ncurses, whatever terminfo says of the mouse
 * (xterm-256color's kmous is \e[<, tmux's \e[M): a report between keys,
 * and a key after a report. */
static void test_fed_mouse(void **state)
{
	(void)state;
	static const char *terms[] = {"xterm-256color", "tmux-256color", "xterm"};
	int tried = 0;
	for (size_t t = 0; t < sizeof terms / sizeof terms[0]; t++) {
		setenv("TERM", terms[t], 1);
		keys *k = keys_open_fed(10);
		if (!k)
			continue;
		tried++;
		assert_true(keys_feed(k, "a\x1b[<0;10;5M\x1b[<32;12;6Mb\x1b[<0;12;6m\x1bOA", 36));
		assert_int_equal(next_key(k), 'a');
		assert_int_equal(next_key(k), KEYS_MOUSE);
		keys_mouse m = keys_mouse_event(k);
		assert_int_equal(m.x, 10);
		assert_int_equal(m.y, 5);
		assert_false(m.motion);
		assert_int_equal(next_key(k), KEYS_MOUSE);
		m = keys_mouse_event(k);
		assert_true(m.motion);
		assert_int_equal(m.x, 12);
		assert_int_equal(next_key(k), 'b');
		assert_int_equal(next_key(k), KEYS_MOUSE);
		assert_true(keys_mouse_event(k).release);
		assert_int_equal(next_key(k), KEYS_UP);
		assert_int_equal(keys_next(k), KEYS_NONE);
		/* An Esc [ that is no report stays what it was. */
		assert_true(keys_feed(k, "\x1b[0n", 4));
		assert_int_equal(next_key(k), KEYS_OTHER);
		keys_close(k);
	}
	if (!tried)
		skip();
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_fed_keys),
		cmocka_unit_test(test_mouse_reports),
		cmocka_unit_test(test_fed_mouse),
	};
	return cmocka_run_group_tests_name("keys", tests, NULL, NULL);
}
