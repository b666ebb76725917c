/* rtsh — tests of the event loop (term/evloop.h) on pipes: key bytes in
 * order with the terminal's answers taken out, whole keys (escape
 * sequences, UTF-8, a lone Esc after the wait, the rest of a sequence that
 * comes late), wake-ups, the caller's timer, the interrupt hook, the end of
 * the input, events kept while a reader blocked, settling the answers owed,
 * and a picture sent without pacing in parts the terminal takes one at a
 * time, which end with the screen showing exactly the picture. */
#include "termemu.h"

#include <fcntl.h>
#include <pthread.h>
#include <time.h>
#include <unistd.h>

#include "term/encoder.h"
#include "term/evloop.h"
#include "term/out.h"

typedef struct pipes {
	int in[2], wake[2], out[2];
} pipes;

static void open_pipes(pipes *p)
{
	assert_int_equal(pipe(p->in), 0);
	assert_int_equal(pipe(p->wake), 0);
	assert_int_equal(pipe(p->out), 0);
	for (int i = 0; i < 2; i++)
		fcntl(p->wake[i], F_SETFL, fcntl(p->wake[i], F_GETFL) | O_NONBLOCK);
	fcntl(p->out[0], F_SETFL, fcntl(p->out[0], F_GETFL) | O_NONBLOCK);
}

static void close_pipes(pipes *p)
{
	int *fds[] = {p->in, p->wake, p->out};
	for (int k = 0; k < 3; k++)
		for (int i = 0; i < 2; i++)
			if (fds[k][i] >= 0)
				close(fds[k][i]);
}

static void put(int fd, const char *s)
{
	assert_int_equal(write(fd, s, strlen(s)), (ssize_t)strlen(s));
}

static size_t drain(int rd, char *buf, size_t size)
{
	size_t n = 0;
	ssize_t r;
	while (n < size - 1 && (r = read(rd, buf + n, size - 1 - n)) > 0)
		n += (size_t)r;
	buf[n] = '\0';
	return n;
}

/* Every key byte waiting, as a string. */
static void take_keys(evloop *l, char *buf, size_t size)
{
	size_t n = 0;
	int c;
	while (n < size - 1 && (c = evloop_getc(l)) >= 0)
		buf[n++] = (char)c;
	buf[n] = '\0';
}

static void test_keys_and_answers(void **state)
{
	(void)state;
	pipes p;
	open_pipes(&p);
	termout *o = termout_new(p.out[1]);
	evloop *l = evloop_new(p.in[0], p.wake[0]);
	assert_non_null(o);
	assert_non_null(l);
	evloop_set_out(l, o);
	termout_probe(o, false, evloop_now());
	char buf[256];
	drain(p.out[0], buf, sizeof buf);
	assert_string_equal(buf, "\x1b[c");

	/* Keys around the DA1 answer: the answer goes to the scheduler. */
	put(p.in[1], "ab\x1b[?62;22c\x1b[Ac");
	int ev = evloop_wait(l, 1.0);
	assert_true(ev & EVLOOP_KEYS);
	assert_true(ev & EVLOOP_ANSWER);
	assert_int_equal(termout_get_state(o), TERMOUT_PACED);
	take_keys(l, buf, sizeof buf);
	assert_string_equal(buf, "ab\x1b[Ac");
	assert_false(evloop_has_keys(l));

	/* A stray status report in the keys is not a key either. */
	put(p.in[1], "x\x1b[0ny");
	evloop_wait(l, 1.0);
	take_keys(l, buf, sizeof buf);
	assert_string_equal(buf, "xy");

	/* Whole keys: an arrow, SS3, a UTF-8 character, Alt+x, a byte. */
	put(p.in[1], "\x1b[1;2A\x1bOB\xc3\xa9\x1bxq");
	const char *want[] = {"\x1b[1;2A", "\x1bOB", "\xc3\xa9", "\x1bx", "q"};
	for (size_t i = 0; i < sizeof want / sizeof *want; i++) {
		char k[16];
		assert_int_equal(evloop_key(l, k, sizeof k, 0.05), strlen(want[i]));
		assert_string_equal(k, want[i]);
	}
	evloop_free(l);
	termout_free(o);
	close_pipes(&p);
}

typedef struct late_write {
	int fd;
	const char *s;
	double delay;
} late_write;

static void *write_late(void *arg)
{
	const late_write *w = arg;
	struct timespec ts = {(time_t)w->delay, (long)((w->delay - (double)(time_t)w->delay) * 1e9)};
	nanosleep(&ts, NULL);
	put(w->fd, w->s);
	return NULL;
}

static void test_esc_and_late_rest(void **state)
{
	(void)state;
	pipes p;
	open_pipes(&p);
	evloop *l = evloop_new(p.in[0], p.wake[0]);
	assert_non_null(l);
	char k[16];
	/* A lone Esc: nothing follows within the wait. */
	put(p.in[1], "\x1b");
	double t0 = evloop_now();
	assert_int_equal(evloop_key(l, k, sizeof k, 0.05), 1);
	assert_true(evloop_now() - t0 >= 0.045);
	assert_string_equal(k, "\x1b");

	/* The rest of a sequence comes 30 ms later, within a 2 s wait: one key. */
	put(p.in[1], "\x1b[");
	late_write w = {p.in[1], "6~", 0.03};
	pthread_t th;
	assert_int_equal(pthread_create(&th, NULL, write_late, &w), 0);
	assert_int_equal(evloop_key(l, k, sizeof k, 2.0), 4);
	pthread_join(th, NULL);
	assert_string_equal(k, "\x1b[6~");
	evloop_free(l);
	close_pipes(&p);
}

static bool flag;
static bool flag_set(void *ctx)
{
	(void)ctx;
	return flag;
}

static void test_wake_timer_interrupt_eof(void **state)
{
	(void)state;
	pipes p;
	open_pipes(&p);
	evloop *l = evloop_new(p.in[0], p.wake[0]);
	assert_non_null(l);

	/* The caller's timer. */
	double t0 = evloop_now();
	int ev = evloop_wait(l, 0.03);
	assert_int_equal(ev, EVLOOP_TIMER);
	assert_true(evloop_now() - t0 >= 0.029);

	/* A wake-up: the pipe is drained, once. */
	put(p.wake[1], "xxx");
	assert_int_equal(evloop_wait(l, 1.0), EVLOOP_WAKE);
	assert_int_equal(evloop_wait(l, 0), EVLOOP_TIMER);

	/* A wake-up while a reader waits for a key is kept for the next wait;
	 * the reader still gets its key. */
	put(p.wake[1], "x");
	late_write w = {p.in[1], "k", 0.03};
	pthread_t th;
	assert_int_equal(pthread_create(&th, NULL, write_late, &w), 0);
	assert_int_equal(evloop_getc_wait(l), 'k');
	pthread_join(th, NULL);
	assert_true(evloop_wait(l, 0) & EVLOOP_WAKE);

	/* The interrupt hook: a reader gives up after a wake-up when it says so. */
	evloop_set_interrupt(l, flag_set, NULL);
	flag = true;
	put(p.wake[1], "x");
	char k[16];
	assert_int_equal(evloop_key(l, k, sizeof k, 0.05), 0);
	assert_int_equal(evloop_getc_wait(l), -1);
	flag = false;
	evloop_wait(l, 0);

	/* Keys before the end of the input come first; then the end. */
	put(p.in[1], "z");
	close(p.in[1]);
	p.in[1] = -1;
	assert_int_equal(evloop_getc_wait(l), 'z');
	assert_int_equal(evloop_getc_wait(l), -1);
	assert_true(evloop_eof(l));
	assert_true(evloop_wait(l, 1.0) & EVLOOP_KEYS);
	assert_int_equal(evloop_key(l, k, sizeof k, 0.05), 0);
	evloop_free(l);
	close_pipes(&p);
}

static void test_settle(void **state)
{
	(void)state;
	pipes p;
	open_pipes(&p);
	termout *o = termout_new(p.out[1]);
	evloop *l = evloop_new(p.in[0], p.wake[0]);
	evloop_set_out(l, o);
	termout_probe(o, true, evloop_now());
	assert_true(termout_awaiting(o));
	/* The answers come 30 ms later, after a key; the key is kept. */
	late_write w = {p.in[1], "q\x1bP0$r\x1b\\\x1bP0+r\x1b\\\x1b[?62c", 0.03};
	pthread_t th;
	assert_int_equal(pthread_create(&th, NULL, write_late, &w), 0);
	evloop_settle(l, 2.0);
	pthread_join(th, NULL);
	assert_false(termout_awaiting(o));
	assert_int_equal(termout_truecolor(o), 0);
	assert_int_equal(evloop_getc(l), 'q');
	assert_int_equal(evloop_getc(l), -1);
	evloop_free(l);
	termout_free(o);
	close_pipes(&p);
}

static void fill(uint8_t *img, int w, int h, unsigned seed)
{
	test_rng r = {seed};
	for (int i = 0; i < w * h * 3; i++)
		img[i] = (uint8_t)(trand(&r) * 256);
}

/* A terminal that does not answer: the picture goes unpaced, a part of at
 * most TERMOUT_UNPACED_PART bytes each time the fd can take one, and the
 * screen ends showing it exactly. */
static void test_unpaced_parts(void **state)
{
	(void)state;
	enum { COLS = 100, ROWS = 30, W = COLS, H = 2 * ROWS };
	pipes p;
	open_pipes(&p);
	termout *o = termout_new(p.out[1]);
	evloop *l = evloop_new(p.in[0], p.wake[0]);
	evloop_set_out(l, o);
	/* exact: the cells are the image's own pixels, none traded for bytes */
	encoder_geom g = {.cols = COLS, .rows = ROWS, .pal = PALETTE_TRUECOLOR, .exact = true};
	encoder *enc = encoder_halfblock.open(&g);
	assert_non_null(enc);
	termout_set_picture(o, enc);
	static uint8_t img[W * H * 3];
	fill(img, W, H, 7);
	encoder_put(enc, img, W, H, 0, 0);
	assert_int_equal(termout_get_state(o), TERMOUT_IDLE);
	assert_true(termout_want_write(o));
	emu e;
	emu_init(&e, COLS, ROWS);
	static char buf[1 << 20];
	int parts = 0;
	for (int i = 0; i < 100 && termout_want_write(o); i++) {
		evloop_wait(l, 1.0);
		size_t n = drain(p.out[0], buf, sizeof buf);
		/* a part: the budget and at most one row's run beyond it */
		assert_true(n > 0 && n <= TERMOUT_UNPACED_PART + 64 * COLS);
		emu_feed(&e, buf, n);
		parts++;
	}
	assert_false(termout_want_write(o));
	/* random colours: about 40 bytes a cell, 3000 cells */
	assert_true(parts >= (int)(40 * COLS * ROWS / 2 / TERMOUT_UNPACED_PART));
	for (int y = 0; y < H; y += 2)
		for (int x = 0; x < W; x++) {
			uint32_t top = 0, bot = 0;
			emu_pixels(&e.cell[(y / 2) * COLS + x], &top, &bot, false);
			const uint8_t *t = img + ((size_t)y * W + x) * 3, *b = t + (size_t)W * 3;
			assert_int_equal(top, (uint32_t)t[0] << 16 | (uint32_t)t[1] << 8 | t[2]);
			assert_int_equal(bot, (uint32_t)b[0] << 16 | (uint32_t)b[1] << 8 | b[2]);
		}
	emu_free(&e);
	encoder_close(enc);
	evloop_free(l);
	termout_free(o);
	close_pipes(&p);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_keys_and_answers),
		cmocka_unit_test(test_esc_and_late_rest),
		cmocka_unit_test(test_wake_timer_interrupt_eof),
		cmocka_unit_test(test_settle),
		cmocka_unit_test(test_unpaced_parts),
	};
	return cmocka_run_group_tests_name("evloop", tests, NULL, NULL);
}
