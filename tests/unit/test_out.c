/* rtsh — tests of the output scheduler (term/out.h): answers taken out of
 * the keys, the start-up probe, slices paced by DSR answers, a newer
 * picture overtaking one half sent (the terminal ends up showing exactly
 * the newest), the fall-back when nothing answers, and lossy damage for
 * refinement passes on a slow link with an exact final picture. The time
 * is passed in, so the tests need no waiting. */
#include "termemu.h"

#include <fcntl.h>
#include <unistd.h>

#include "term/encoder.h"
#include "term/frame.h"
#include "term/caps.h"
#include "term/out.h"

static int write_end = -1;

/* A scheduler writing into a pipe, the pipe's read end in *rd. */
static termout *open_out(int *rd)
{
	int p[2];
	assert_int_equal(pipe(p), 0);
	fcntl(p[0], F_SETFL, fcntl(p[0], F_GETFL) | O_NONBLOCK);
	*rd = p[0];
	write_end = p[1];
	termout *o = termout_new(p[1]);
	assert_non_null(o);
	return o;
}

/* Frees o and closes both ends of its pipe (termout does not own its fd). */
static void close_out(termout *o, int rd)
{
	termout_free(o);
	close(rd);
	close(write_end);
}

/* Everything written so far. */
static size_t drain(int rd, char *buf, size_t size)
{
	size_t n = 0;
	ssize_t r;
	while (n < size - 1 && (r = read(rd, buf + n, size - 1 - n)) > 0)
		n += (size_t)r;
	buf[n] = '\0';
	return n;
}

static void feed(termout *o, const char *s, double t, abuf *keys)
{
	termout_input(o, s, strlen(s), t, keys);
}

static void test_answers_out_of_keys(void **state)
{
	(void)state;
	int rd;
	termout *o = open_out(&rd);
	char buf[4096];
	abuf keys;
	abuf_init(&keys);
	termout_probe(o, true, 0.0);
	drain(rd, buf, sizeof buf);
	/* The questions, in order, the DA1 fence last. */
	const char *rqss = strstr(buf, "\x1bP$qm\x1b\\"), *tcap = strstr(buf, "\x1bP+q524742;5463\x1b\\"),
	           *da1 = strstr(buf, "\x1b[c");
	assert_non_null(rqss);
	assert_non_null(tcap);
	assert_non_null(da1);
	assert_true(rqss < tcap && tcap < da1);
	assert_int_equal(termout_get_state(o), TERMOUT_PROBING);

	/* Keys around an answer cut in three reads; an arrow key stays a key. */
	feed(o, "ab\x1bP1$r0;48:2::1", 0.05, &keys);
	feed(o, ":2:3m\x1b", 0.06, &keys);
	feed(o, "\\c\x1b[A", 0.07, &keys);
	assert_int_equal(keys.len, 6);
	assert_memory_equal(keys.b, "abc\x1b[A", 6);
	assert_int_equal(termout_truecolor(o), 1);
	/* XTGETTCAP not answered (the terminal ignores it): DA1 ends the probe. */
	feed(o, "\x1b[?62;22c", 0.1, &keys);
	assert_int_equal(keys.len, 6);
	assert_int_equal(termout_get_state(o), TERMOUT_PACED);
	assert_false(termout_awaiting(o));
	termout_stats st = termout_get_stats(o);
	assert_near(st.rtt, 0.07, 1e-9); /* the quickest answer: DECRQSS, complete at 0.07 */
	/* With nothing awaited, a lone Esc is a key at once. */
	feed(o, "\x1b", 0.2, &keys);
	assert_int_equal(keys.len, 7);
	abuf_free(&keys);
	close_out(o, rd);
}

/* XTGETTCAP's answer (DCS 1 + r NAME[=VALUE] ST, names in hex; issue 31,
 * friction 6): RGB (524742, with xterm's value 8/8/8) or Tc (5463) is
 * truecolor; another name, or "0+r" (not known), is not. */
static bool tcap_says(const char *answer)
{
	int rd;
	termout *o = open_out(&rd);
	char buf[4096];
	abuf keys;
	abuf_init(&keys);
	termout_probe(o, true, 0.0);
	feed(o, "\x1bP1$r0;48;5;16m\x1b\\", 0.01, &keys); /* DECRQSS: no 24-bit SGR */
	feed(o, answer, 0.02, &keys);
	feed(o, "\x1b[?1;2c", 0.03, &keys);
	assert_int_equal(keys.len, 0);
	bool tc = termout_truecolor(o) == 1;
	abuf_free(&keys);
	drain(rd, buf, sizeof buf);
	close_out(o, rd);
	return tc;
}

static void test_xtgettcap_answer(void **state)
{
	(void)state;
	assert_true(tcap_says("\x1bP1+r524742=382F382F38\x1b\\"));
	assert_true(tcap_says("\x1bP1+r524742\x1b\\"));
	assert_true(tcap_says("\x1bP1+r5463\x1b\\"));
	assert_true(tcap_says("\x1bP1+r636F6C6F7273=323536;524742=382F382F38\x1b\\")); /* colors, then RGB */
	assert_true(tcap_says("\x1bP1+r524742\a"));
	assert_false(tcap_says("\x1bP0+r524742\x1b\\"));
	assert_false(tcap_says("\x1bP0+r\x1b\\"));
	assert_false(tcap_says("\x1bP1+r636F6C6F7273=323536\x1b\\")); /* colors=256 alone */
	assert_false(tcap_says("\x1bP1+r52474\x1b\\"));                /* a name cut short */
}

/* tmux's client features (caps_features_rgb): what `tmux display-message -p
 * '#{client_termfeatures}'` printed here, tmux 3.3a attached from an
 * xterm-256color terminal with terminal-features ',xterm*:RGB', and
 * without. */
static void test_tmux_features(void **state)
{
	(void)state;
	assert_true(caps_features_rgb("256,bpaste,ccolour,clipboard,cstyle,focus,mouse,overline,RGB,strikethrough,title,"
	                              "usstyle\n"));
	assert_false(caps_features_rgb("256,bpaste,ccolour,clipboard,cstyle,focus,mouse,overline,strikethrough,title,"
	                               "usstyle\n"));
	assert_true(caps_features_rgb("RGB"));
	assert_false(caps_features_rgb(""));   /* a detached session: no client */
	assert_false(caps_features_rgb("\n"));
	assert_false(caps_features_rgb("RGBA,xRGB"));
}

static void test_probe_without_color_and_timeout(void **state)
{
	(void)state;
	int rd;
	termout *o = open_out(&rd);
	char buf[4096];
	abuf keys;
	abuf_init(&keys);
	/* A terminal that says no to 24-bit colour (DECRQSS gives the SGR
	 * without it) and answers the rest. */
	termout_probe(o, true, 0.0);
	feed(o, "\x1bP1$r0;48;5;16m\x1b\\\x1bP0+r\x1b\\\x1b[?1;2c", 0.05, &keys);
	assert_int_equal(keys.len, 0);
	assert_int_equal(termout_truecolor(o), 0);
	assert_int_equal(termout_get_state(o), TERMOUT_PACED);
	assert_null(termout_notice(o));
	drain(rd, buf, sizeof buf);
	close_out(o, rd);

	/* A terminal that answers nothing: unpaced after the time-out, said once. */
	o = open_out(&rd);
	termout_probe(o, false, 10.0);
	termout_pump(o, 10.0 + TERMOUT_PROBE_TIMEOUT / 2, &keys);
	assert_int_equal(termout_get_state(o), TERMOUT_PROBING);
	assert_near(termout_wait(o, 10.0 + TERMOUT_PROBE_TIMEOUT / 2), TERMOUT_PROBE_TIMEOUT / 2, 1e-9);
	termout_pump(o, 10.0 + TERMOUT_PROBE_TIMEOUT, &keys);
	assert_int_equal(termout_get_state(o), TERMOUT_UNPACED);
	assert_non_null(termout_notice(o));
	assert_null(termout_notice(o));
	/* A cut sequence held while an answer is awaited is keys after a while. */
	drain(rd, buf, sizeof buf);
	close_out(o, rd);
	o = open_out(&rd);
	termout_probe(o, false, 0.0);
	feed(o, "\x1b[1", 0.0, &keys);
	assert_int_equal(keys.len, 0);
	termout_pump(o, 1.0, &keys); /* an answer cut on a loaded machine: it waits */
	assert_int_equal(keys.len, 0);
	termout_pump(o, 2.0, &keys);
	assert_int_equal(keys.len, 3);
	assert_memory_equal(keys.b, "\x1b[1", 3);
	abuf_free(&keys);
	drain(rd, buf, sizeof buf);
	close_out(o, rd);
}

static void fill(uint8_t *img, int w, int h, unsigned seed)
{
	test_rng r = {seed};
	for (int i = 0; i < w * h * 3; i++)
		img[i] = (uint8_t)(trand(&r) * 256);
}

/* The query a slice ends with: DSR, or DA1 after the slice that ends a
 * picture; the length of the query, and the terminal's answer in *ans. */
static size_t slice_query(const char *b, size_t n, const char **ans)
{
	if (n >= 4 && memcmp(b + n - 4, "\x1b[5n", 4) == 0) {
		*ans = "\x1b[0n";
		return 4;
	}
	assert_true(n >= 3);
	assert_memory_equal(b + n - 3, "\x1b[c", 3);
	*ans = "\x1b[?62;22c";
	return 3;
}

/* What the terminal answers to the last slice applied. */
static const char *answer = "\x1b[0n";

/* A slice written on an idle link starts with a bare DSR (it times the
 * round trip): its length, 0 when none. */
static size_t bare_query(const char *b, size_t n)
{
	return n >= 4 && memcmp(b, "\x1b[5n", 4) == 0 ? 4 : 0;
}

/* Feeds a slice to the emulator, checking it ends with a query; a bare
 * DSR before it is answered at once. */
static void apply_slice(termout *o, double t, abuf *keys, emu *e, const char *b, size_t n)
{
	size_t bare = bare_query(b, n);
	if (bare)
		termout_input(o, "\x1b[0n", 4, t, keys);
	size_t q = slice_query(b, n, &answer);
	emu_feed(e, b + bare, n - bare - q);
}

/* The screen shows exactly the encoder's picture of img (truecolor). */
static void assert_screen_shows(const emu *e, const uint8_t *img, int w, int h, int tol)
{
	for (int y = 0; y < h; y += 2)
		for (int x = 0; x < w; x++) {
			const emu_cell *c = &e->cell[(y / 2) * e->cols + x];
			uint32_t top = 0, bot = 0;
			emu_pixels(c, &top, &bot, false);
			const uint8_t *t = img + ((size_t)y * w + x) * 3, *b = t + (size_t)w * 3;
			uint32_t wt = (uint32_t)t[0] << 16 | (uint32_t)t[1] << 8 | t[2];
			uint32_t wb = (uint32_t)b[0] << 16 | (uint32_t)b[1] << 8 | b[2];
			for (int sh = 0; sh < 24; sh += 8) {
				int d1 = (int)((top >> sh) & 0xff) - (int)((wt >> sh) & 0xff);
				int d2 = (int)((bot >> sh) & 0xff) - (int)((wb >> sh) & 0xff);
				if (abs(d1) > tol || abs(d2) > tol)
					fail_msg("cell %d,%d shows %06x/%06x, expected %06x/%06x (tolerance %d)", y / 2, x, top,
					         bot, wt, wb, tol);
			}
		}
}

static void test_paced_slices_and_overtaking(void **state)
{
	(void)state;
	enum { COLS = 40, ROWS = 12, W = COLS, H = 2 * ROWS };
	int rd;
	termout *o = open_out(&rd);
	static char buf[1 << 20];
	abuf keys;
	abuf_init(&keys);
	encoder_geom g = {.cols = COLS, .rows = ROWS, .pal = PALETTE_TRUECOLOR};
	encoder *enc = encoder_halfblock.open(&g);
	assert_non_null(enc);
	termout_set_picture(o, enc);
	termout_probe(o, false, 0.0);
	drain(rd, buf, sizeof buf);
	feed(o, "\x1b[?62c", 0.01, &keys);
	assert_int_equal(termout_get_state(o), TERMOUT_PACED);

	uint8_t a[W * H * 3], b[W * H * 3];
	fill(a, W, H, 1);
	fill(b, W, H, 2);
	emu e;
	emu_init(&e, COLS, ROWS);
	encoder_put(enc, a, W, H, 0, 0);
	/* Random colours cost about 40 bytes a cell: the first slice (4 KB
	 * before the link is measured) holds only some of the 12 rows. */
	termout_pump(o, 1.0, &keys);
	size_t n = drain(rd, buf, sizeof buf);
	assert_true(n > 0 && n < 4096 + 40 * COLS + 64);
	apply_slice(o, 1.0, &keys, &e, buf, n);
	/* Nothing more until the answer. */
	termout_pump(o, 1.01, &keys);
	assert_int_equal(drain(rd, buf, sizeof buf), 0);
	assert_true(termout_get_stats(o).in_flight > 0);
	/* A newer picture overtakes the half-sent one. */
	encoder_put(enc, b, W, H, 0, 0);
	termout_picture_new(o);
	double t = 1.1;
	for (int i = 0; i < 100 && encoder_dirty(enc); i++) {
		feed(o, answer, t, &keys);
		termout_pump(o, t, &keys);
		n = drain(rd, buf, sizeof buf);
		if (n)
			apply_slice(o, t, &keys, &e, buf, n);
		t += 0.1;
	}
	assert_false(encoder_dirty(enc));
	assert_screen_shows(&e, b, W, H, 0);
	/* The slice that ended the picture asked DA1 (the others DSR). */
	assert_string_equal(answer, "\x1b[?62;22c");
	assert_int_equal(termout_get_stats(o).pictures, 1);
	assert_int_equal(keys.len, 0);
	/* The link was measured from the answers. */
	assert_true(termout_get_stats(o).bps > 0);

	/* A refinement pass on this slow link: cells within the JND stay, the
	 * others go; the final picture is exact. */
	feed(o, answer, t, &keys);
	uint8_t c[W * H * 3];
	memcpy(c, b, sizeof c);
	for (int i = 0; i < W * H * 3; i++)
		c[i] = (uint8_t)(c[i] > 128 ? c[i] - 3 : c[i] + 3); /* within the JND */
	for (int x = 0; x < 5; x++)
		c[x * 3] = (uint8_t)(c[x * 3] ^ 0x80); /* five pixels of row 0 move far */
	termout_picture_final(o, false);
	encoder_put(enc, c, W, H, 0, 0);
	t += 0.1;
	termout_pump(o, t, &keys);
	n = drain(rd, buf, sizeof buf);
	assert_true(n > 0);
	apply_slice(o, t, &keys, &e, buf, n);
	assert_false(encoder_dirty(enc));
	assert_true(n < 40 * 10); /* a run of five cells, not the picture */
	assert_screen_shows(&e, c, W, H, TERMOUT_JND);
	/* With no bigger change left, the exact remainder goes while the link
	 * is free: the terminal ends showing the pass exactly. */
	for (int i = 0; i < 100 && (termout_picture_pending(o) || termout_get_stats(o).in_flight); i++) {
		feed(o, answer, t, &keys);
		termout_pump(o, t, &keys);
		n = drain(rd, buf, sizeof buf);
		if (n)
			apply_slice(o, t, &keys, &e, buf, n);
		t += 0.1;
	}
	assert_screen_shows(&e, c, W, H, 0);
	termout_picture_final(o, true);
	for (int i = 0; i < 100 && encoder_dirty(enc); i++) {
		feed(o, answer, t, &keys);
		termout_pump(o, t, &keys);
		n = drain(rd, buf, sizeof buf);
		if (n)
			apply_slice(o, t, &keys, &e, buf, n);
		t += 0.1;
	}
	assert_screen_shows(&e, c, W, H, 0);

	/* Ctrl-C: what is not sent is dropped. */
	feed(o, answer, t, &keys);
	encoder_put(enc, a, W, H, 0, 0);
	termout_drop_picture(o);
	assert_false(encoder_dirty(enc));
	emu_free(&e);
	abuf_free(&keys);
	encoder_close(enc);
	drain(rd, buf, sizeof buf);
	close_out(o, rd);
}

/* A link of `rate` bytes a second and round trip `rtt` in virtual time:
 * a slice written at s goes down once the link is free, for its bytes'
 * time; the terminal answers its DSR as it arrives, the answer is back
 * rtt after the slice's last byte went out. The program reads its input
 * every `read_every` seconds (answers pile up in between) and the probe's
 * answer `probe_late` seconds late. A new
 * refinement pass of random colours every 0.1 s keeps the picture dirty. */
typedef struct sim_result {
	double bps;        /* the scheduler's figure at the end */
	double util;       /* bytes carried / what the link could carry since the first slice */
	double max_queue;  /* the most link time ahead of a key's echo written right after a slice
	                    * (once the link is measured) */
	long slices;
	double measured_in; /* seconds from the first slice to the first figure (-1: never) */
	double start_slice; /* the most link time of one slice before that figure */
} sim_result;

static sim_result simulate(double rate, double rtt, double read_every, double seconds, double probe_late)
{
	enum { COLS = 100, ROWS = 30, W = COLS, H = 2 * ROWS, MAXQ = 1 << 15 };
	int rd;
	termout *o = open_out(&rd);
	static char buf[1 << 22];
	abuf keys;
	abuf_init(&keys);
	encoder_geom g = {.cols = COLS, .rows = ROWS, .pal = PALETTE_TRUECOLOR};
	encoder *enc = encoder_halfblock.open(&g);
	assert_non_null(enc);
	termout_set_picture(o, enc);
	termout_picture_final(o, false);
	double t = 0, busy_until = 0, first = -1, carried = 0;
	termout_probe(o, false, t);
	drain(rd, buf, sizeof buf);
	static double answers[MAXQ];
	static const char *kinds[MAXQ];
	int qa = 0, qn = 0;
	kinds[qn] = "\x1b[?62c";
	answers[qn++] = rtt + probe_late; /* the probe's DA1 (read late: the loop was busy) */
	sim_result r = {.measured_in = -1};
	static uint8_t img[W * H * 3];
	double next_pass = 0, next_read = 0;
	const double dt = 0.001;
	for (; t < seconds; t += dt) {
		if (t >= next_pass) {
			fill(img, W, H, (unsigned)(t * 1000) + 3);
			encoder_put(enc, img, W, H, 0, 0);
			termout_picture_new(o);
			next_pass += 0.1;
		}
		if (t >= next_read) {
			while (qa < qn && answers[qa] <= t) {
				feed(o, kinds[qa], t, &keys);
				qa++;
			}
			next_read += read_every;
		}
		bool measured = termout_get_stats(o).bps > 0; /* the slices after the first figure */
		if (measured && r.measured_in < 0)
			r.measured_in = t - first;
		termout_pump(o, t, &keys);
		size_t n = drain(rd, buf, sizeof buf);
		if (n) {
			assert_true(qn + 1 < MAXQ);
			if (bare_query(buf, n)) { /* its answer: once its 4 bytes went down */
				kinds[qn] = "\x1b[0n";
				answers[qn++] = (busy_until > t ? busy_until : t) + 4 / rate + rtt;
			}
			slice_query(buf, n, &kinds[qn]);
			if (first < 0)
				first = t;
			double start = busy_until > t ? busy_until : t;
			busy_until = start + (double)n / rate;
			double q = busy_until - t; /* an echo written now waits this long */
			if (measured && q > r.max_queue)
				r.max_queue = q;
			answers[qn++] = busy_until + rtt; /* kinds[qn] set above */
			if (!measured && (double)n / rate > r.start_slice)
				r.start_slice = (double)n / rate;
			carried += (double)n;
			r.slices++;
		}
	}
	/* The bytes still queued at the end were not carried yet. */
	if (busy_until > t)
		carried -= (busy_until - t) * rate;
	r.util = carried / (rate * (t - first));
	r.bps = termout_get_stats(o).bps;
	abuf_free(&keys);
	encoder_close(enc);
	drain(rd, buf, sizeof buf);
	close_out(o, rd);
	return r;
}

/* Slices are pipelined: the link stays busy (no waiting a round trip for
 * each answer), the throughput figure is the link's and comes soon, and an
 * echo never waits behind much more than TERMOUT_QUEUE_SECONDS of picture.
 * Also when the answers are read in bunches. */
static void test_pipelined_slices(void **state)
{
	(void)state;
	/* 30 KB/s and 100 ms; the same with answers read in bunches; 1 MB/s and
	 * 20 ms with the start-up answer read 0.3 s late (the round trip is
	 * then first overestimated 15 times); 45 KB/s, where the first slice
	 * is just short of a figure. */
	const struct {
		double rate, rtt, read_every, probe_late;
	} cases[] = {{30000, 0.1, 0.001, 0}, {30000, 0.1, 0.03, 0}, {1e6, 0.02, 0.001, 0.3}, {45000, 0.1, 0.001, 0}};
	for (int k = 0; k < 4; k++) {
		double rate = cases[k].rate;
		sim_result r = simulate(rate, cases[k].rtt, cases[k].read_every, 6.0, cases[k].probe_late);
		print_message("%.0f B/s, read every %.3f s: bps %.0f, link used %.2f, queue max %.3f s, %ld slices, "
		              "measured %.3f s after the first, start-up slices at most %.3f s\n",
		              rate, cases[k].read_every, r.bps, r.util, r.max_queue, r.slices, r.measured_in, r.start_slice);
		assert_true(r.bps > 0.85 * rate && r.bps < 1.2 * rate);
		assert_true(r.util > 0.85);
		/* measured within a few round trips of the first slice, by the
		 * slices' growth (a slow start) on a fast link: 4 KB, 8, 16, 32,
		 * 32, 32 at 1 MB/s is 0.124 s of link time, plus six round trips
		 * (0.12 s); the first slice alone spans a figure at 30 KB/s (4 KB
		 * take 0.137 s), after its round trip (0.1 s) */
		assert_true(r.measured_in >= 0 && r.measured_in < 0.5);
		/* and the slices grow only while they take at most 0.1 s of link
		 * (the figure's span): at 45 KB/s the first 4 KB take 0.091 s, so
		 * the next is 4 KB again, not 8 (0.18 s ahead of a key); the first
		 * is 4 KB whatever the link (0.137 s at 30 KB/s) */
		double first_slice = 4096 / rate;
		assert_true(r.start_slice <= (first_slice > 0.1 ? first_slice : 0.1) + 16 * 40 / rate);
		/* the queue, the slice just written, and what one row's run may
		 * add past the budget (16 cells of about 40 bytes) */
		assert_true(r.max_queue <= TERMOUT_QUEUE_SECONDS + TERMOUT_SLICE_SECONDS + 16 * 40 / rate + 0.02);
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_answers_out_of_keys),
		cmocka_unit_test(test_probe_without_color_and_timeout),
		cmocka_unit_test(test_xtgettcap_answer),
		cmocka_unit_test(test_tmux_features),
		cmocka_unit_test(test_paced_slices_and_overtaking),
		cmocka_unit_test(test_pipelined_slices),
	};
	return cmocka_run_group_tests_name("out", tests, NULL, NULL);
}
