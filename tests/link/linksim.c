/* rtsh tests — a slow link between a program and its terminal.
 *
 *   linksim [OPTIONS] -- COMMAND ARGS...
 *
 * COMMAND runs on a pseudo-terminal. What it writes is read at once into an
 * unbounded buffer (what sshd and the network's buffers do), then goes down
 * a "wire" of RATE bytes a second and RTT/2 seconds of latency, into a
 * "terminal" that parses what arrives and answers, only when the query
 * arrives: DSR (CSI 5 n -> CSI 0 n), DA1 (CSI c -> CSI ? 62 ; 22 c),
 * DECRQSS of SGR (with the 24-bit background it was last given) and
 * XTGETTCAP (RGB: yes). Answers and typed keys go up the same kind of wire.
 * --cell WxH gives the pty cells of W x H pixels (TIOCGWINSZ); --sixel
 * makes the terminal draw sixel: DA1 says 4, XTSMGRAPHICS answers xterm's
 * default 1000x1000, and a sixel image counts as the picture.
 *
 * Scenarios (--scenario):
 *   refine  types 'Z' every 250 ms from the first picture until the render
 *           is over (the status line says N/N spp with no ellipsis, N given
 *           by --samples), then waits for the wire to fall idle. Prints
 *           the echo latency of the keys (p50, p95, max; from the key
 *           press at the terminal to its echo there), the seconds from the
 *           end of the render (as the program wrote it) to the last byte
 *           at the terminal, the picture updates a second (ends of
 *           synchronized updates, CSI ? 2026 l: slices) and the whole
 *           pictures a second (rtsh ends a picture's last slice with DA1,
 *           the others with DSR) while it refined.
 *   ctrlc   presses Ctrl-C 2 s after the first picture; prints the seconds
 *           from the key press to the last byte at the terminal.
 *   user    what a person does, from the first picture on (the picture
 *           still refining at first): types "help" Enter at +1 s, q at +4 s
 *           (the pager), "view" Enter at +6 s, w at +8.5 s and Esc at +10 s
 *           (key mode: one step forward, then back to the shell), then 'Z'
 *           every 250 ms from +12 s, four times. Prints the seconds from
 *           the Enter to the pager's key line at the terminal (pager_s),
 *           from the Esc to the shell's "change kept" message (view_s), and
 *           the echo of the Zs.
 * The result is one line of key=value pairs on standard output.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <pty.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

typedef struct bytes {
	char *b;
	size_t len, cap, pos;
} bytes;

static void put(bytes *q, const char *p, size_t n)
{
	if (q->len + n > q->cap) {
		size_t c = q->cap ? q->cap : 4096;
		while (c < q->len + n)
			c *= 2;
		q->b = realloc(q->b, c);
		if (!q->b) {
			perror("linksim");
			exit(3);
		}
		q->cap = c;
	}
	memcpy(q->b + q->len, p, n);
	q->len += n;
}

/* A wire: bytes enter, leave at `rate` after `delay`. */
typedef struct packet {
	double at;
	size_t off, n; /* in the wire's byte store */
} packet;

typedef struct wire {
	double rate, delay, credit, last;
	bytes waiting;    /* not yet sent (unbounded) */
	bytes store;      /* sent, in flight */
	packet *pk;
	size_t npk, cpk, head;
} wire;

static double now(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)t.tv_sec + t.tv_nsec * 1e-9;
}

static void wire_tick(wire *w, double t)
{
	w->credit += (t - w->last) * w->rate;
	w->last = t;
	double cap = w->rate * 0.005 + 64;
	size_t avail = w->waiting.len - w->waiting.pos;
	if (avail == 0 && w->credit > cap)
		w->credit = cap;
	size_t n = w->credit < (double)avail ? (size_t)w->credit : avail;
	if (n == 0)
		return;
	w->credit -= (double)n;
	if (w->npk == w->cpk) {
		w->cpk = w->cpk ? 2 * w->cpk : 256;
		w->pk = realloc(w->pk, w->cpk * sizeof *w->pk);
		if (!w->pk)
			exit(3);
	}
	w->pk[w->npk++] = (packet){t + w->delay, w->store.len, n};
	put(&w->store, w->waiting.b + w->waiting.pos, n);
	w->waiting.pos += n;
}

/* The next packet that has arrived by t, or NULL. */
static packet *wire_arrived(wire *w, double t)
{
	if (w->head < w->npk && w->pk[w->head].at <= t)
		return &w->pk[w->head++];
	return NULL;
}

static bool wire_busy(const wire *w)
{
	return w->waiting.pos < w->waiting.len || w->head < w->npk;
}

/* --- the terminal --- */
typedef struct term {
	int state; /* 0 text, 1 ESC, 2 CSI, 3 DCS, 4 DCS ESC, 5 OSC, 6 OSC ESC */
	char seq[256];
	size_t nseq;
	bool bg24;         /* the last SGR set a 24-bit background */
	long zs;           /* 'Z' seen in text */
	double *z_at;
	long updates;      /* CSI ? 2026 l seen */
	long pictures;     /* DA1 queries after the first picture: rtsh asks one after a picture's last slice */
	long sgr24;        /* SGRs with a 24-bit colour */
	long picture_bytes;
	bool picture;      /* a half block (or a sixel image) has arrived */
	bool sixel;        /* --sixel: answers DA1 with attribute 4, XTSMGRAPHICS */
	double first_picture;
	double last_byte;
} term;

static void answer(wire *up, const char *s)
{
	put(&up->waiting, s, strlen(s));
}

static void csi_done(term *tm, wire *up)
{
	char fin = tm->seq[tm->nseq - 1];
	tm->seq[tm->nseq] = '\0';
	const char *p = tm->seq + 2; /* after ESC [ */
	if (fin == 'n' && strcmp(p, "5n") == 0)
		answer(up, "\x1b[0n");
	else if (fin == 'c' && (strcmp(p, "c") == 0 || strcmp(p, "0c") == 0)) {
		answer(up, tm->sixel ? "\x1b[?62;4;22c" : "\x1b[?62;22c");
		if (tm->picture)
			tm->pictures++;
	} else if (fin == 'S' && tm->sixel && strcmp(p, "?2;1;0S") == 0)
		answer(up, "\x1b[?2;0;1000;1000S"); /* XTSMGRAPHICS: xterm's default */
	else if (fin == 'l' && strcmp(p, "?2026l") == 0)
		tm->updates++;
	else if (fin == 'm') {
		tm->bg24 = strstr(p, "48;2;") != NULL || strstr(p, "48:2:") != NULL;
		if (strstr(p, "38;2;") || strstr(p, "48;2;"))
			tm->sgr24++;
	}
}

static void dcs_done(term *tm, wire *up)
{
	tm->seq[tm->nseq] = '\0';
	const char *p = tm->seq + 2;
	if (strncmp(p, "$qm", 3) == 0)
		answer(up, tm->bg24 ? "\x1bP1$r0;48:2::1:2:3m\x1b\\" : "\x1bP1$r0m\x1b\\");
	else if (strncmp(p, "+q", 2) == 0)
		answer(up, "\x1bP1+r524742=382F382F38\x1b\\");
	else if (tm->sixel && strspn(p, "0123456789;") < 16 && p[strspn(p, "0123456789;")] == 'q') {
		if (!tm->picture) /* a sixel image counts as the picture */
			tm->first_picture = tm->last_byte;
		tm->picture = true;
	}
}

static void term_feed(term *tm, wire *up, const char *b, size_t n, double t, long expect_z)
{
	for (size_t i = 0; i < n; i++) {
		char c = b[i];
		tm->last_byte = t;
		switch (tm->state) {
		case 0:
			if (c == '\x1b') {
				tm->state = 1;
				tm->nseq = 0;
				tm->seq[tm->nseq++] = c;
			} else if (c == 'Z') {
				if (tm->zs < expect_z)
					tm->z_at[tm->zs] = t;
				tm->zs++;
			} else if ((unsigned char)c == 0xe2 && i + 2 < n && (unsigned char)b[i + 1] == 0x96 &&
			           ((unsigned char)b[i + 2] == 0x80 || (unsigned char)b[i + 2] == 0x84)) {
				if (!tm->picture)
					tm->first_picture = t;
				tm->picture = true;
			}
			break;
		case 1:
			tm->seq[tm->nseq++] = c;
			tm->state = c == '[' ? 2 : c == 'P' ? 3 : c == ']' ? 5 : 0;
			break;
		case 2:
			if (tm->nseq < sizeof tm->seq - 1)
				tm->seq[tm->nseq++] = c;
			if ((unsigned char)c >= 0x40 && (unsigned char)c <= 0x7e) {
				csi_done(tm, up);
				tm->state = 0;
			}
			break;
		case 3:
		case 4:
			if (tm->state == 4 && c == '\\') {
				dcs_done(tm, up);
				tm->state = 0;
				break;
			}
			tm->state = c == '\x1b' ? 4 : 3;
			if (c != '\x1b' && tm->nseq < sizeof tm->seq - 1)
				tm->seq[tm->nseq++] = c;
			break;
		case 5:
		case 6:
			if (c == '\a' || (tm->state == 6 && c == '\\'))
				tm->state = 0;
			else
				tm->state = c == '\x1b' ? 6 : 5;
			break;
		}
	}
}

static int cmp_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

static void usage(void)
{
	fputs("usage: linksim [--rate B/s] [--rtt S] [--cols N] [--rows N] [--samples N] [--scenario refine|ctrlc|user]\n"
	      "               [--timeout S] [--cell WxH] [--sixel] -- COMMAND ARGS...\n",
	      stderr);
	exit(2);
}

int main(int argc, char **argv)
{
	double rate = 30000, rtt = 0.1, timeout = 120;
	int cols = 200, rows = 60, samples = 128, cell_w = 0, cell_h = 0;
	bool sixel = false;
	const char *scenario = "refine";
	int i = 1;
	for (; i < argc; i++) {
		if (strcmp(argv[i], "--") == 0) {
			i++;
			break;
		}
		if (i + 1 >= argc)
			usage();
		if (strcmp(argv[i], "--rate") == 0)
			rate = atof(argv[++i]);
		else if (strcmp(argv[i], "--rtt") == 0)
			rtt = atof(argv[++i]);
		else if (strcmp(argv[i], "--cols") == 0)
			cols = atoi(argv[++i]);
		else if (strcmp(argv[i], "--rows") == 0)
			rows = atoi(argv[++i]);
		else if (strcmp(argv[i], "--samples") == 0)
			samples = atoi(argv[++i]);
		else if (strcmp(argv[i], "--scenario") == 0)
			scenario = argv[++i];
		else if (strcmp(argv[i], "--timeout") == 0)
			timeout = atof(argv[++i]);
		else if (strcmp(argv[i], "--cell") == 0 && sscanf(argv[++i], "%dx%d", &cell_w, &cell_h) == 2)
			;
		else if (strcmp(argv[i], "--sixel") == 0)
			sixel = true;
		else
			usage();
	}
	if (i >= argc || rate <= 0)
		usage();
	bool ctrlc = strcmp(scenario, "ctrlc") == 0, user = strcmp(scenario, "user") == 0;
	/* The person of the user scenario: what to type when, and what the
	 * terminal should then show. */
	struct step {
		double at;
		const char *keys, *expect;
		double sent, seen;
		size_t from;
	} steps[] = {
		{1.0, "help\r", "Space next page", -1, -1, 0},
		{4.0, "q", NULL, -1, -1, 0},
		{6.0, "view\r", NULL, -1, -1, 0},
		{8.5, "w", NULL, -1, -1, 0},
		{10.0, "\x1b", "change kept", -1, -1, 0},
	};
	const int nsteps = (int)(sizeof steps / sizeof steps[0]);
	size_t delivered = 0; /* bytes of down.store at the terminal */

	struct winsize ws = {.ws_row = (unsigned short)rows, .ws_col = (unsigned short)cols,
	                     .ws_xpixel = (unsigned short)(cols * cell_w), .ws_ypixel = (unsigned short)(rows * cell_h)};
	int master;
	pid_t pid = forkpty(&master, NULL, NULL, &ws);
	if (pid < 0) {
		perror("linksim: forkpty");
		return 3;
	}
	if (pid == 0) {
		execvp(argv[i], argv + i);
		perror("linksim: exec");
		_exit(127);
	}
	fcntl(master, F_SETFL, fcntl(master, F_GETFL) | O_NONBLOCK);

	wire down = {.rate = rate, .delay = rtt / 2}, up = {.rate = rate, .delay = rtt / 2};
	term tm = {.sixel = sixel};
	const long max_z = 4096;
	tm.z_at = calloc((size_t)max_z, sizeof *tm.z_at);
	double *z_sent = calloc((size_t)max_z, sizeof *z_sent);
	long z_typed = 0;

	/* The end of the render, seen in what the program writes. */
	char done_pat[64];
	snprintf(done_pat, sizeof done_pat, "%d/%d spp \xe2\x94\x82", samples, samples);
	bytes prog = {0}; /* everything the program wrote, for the pattern */
	size_t end_off = 0;
	const char *dump = getenv("LINKSIM_DUMP"); /* what the program wrote after the event */
	double t0 = now(), render_end = -1, key_at = -1, next_key = -1, first_pic_written = -1;
	down.last = up.last = t0;
	bool child_done = false;
	long pic_updates_at_end = -1, pictures_at_end = -1;
	for (;;) {
		double t = now();
		if (t - t0 > timeout)
			break;
		/* The program's output, at once, into the unbounded buffer. */
		char buf[65536];
		ssize_t n;
		while ((n = read(master, buf, sizeof buf)) > 0) {
			put(&down.waiting, buf, (size_t)n);
			size_t from = prog.len > 64 ? prog.len - 64 : 0;
			put(&prog, buf, (size_t)n);
			if (render_end < 0 && memmem(prog.b + from, prog.len - from, done_pat, strlen(done_pat))) {
				render_end = t;
				end_off = prog.len;
			}
			if (first_pic_written < 0 && memmem(buf, (size_t)n, "\xe2\x96\x80", 3))
				first_pic_written = t;
		}
		if (n == 0 || (n < 0 && errno == EIO))
			child_done = true;
		wire_tick(&down, t);
		wire_tick(&up, t);
		packet *p;
		while ((p = wire_arrived(&down, t))) {
			term_feed(&tm, &up, down.store.b + p->off, p->n, t, max_z);
			delivered = p->off + p->n;
		}
		for (int k = 0; user && k < nsteps; k++) {
			struct step *st = &steps[k];
			if (st->sent < 0 && tm.picture && t - tm.first_picture >= st->at) {
				st->sent = t;
				st->from = delivered;
				answer(&up, st->keys);
			}
			if (st->expect && st->sent >= 0 && st->seen < 0 && delivered > st->from &&
			    memmem(down.store.b + st->from, delivered - st->from, st->expect, strlen(st->expect)))
				st->seen = t;
		}
		while ((p = wire_arrived(&up, t))) {
			const char *b = up.store.b + p->off;
			size_t left = p->n;
			while (left > 0) {
				ssize_t w = write(master, b, left);
				if (w < 0 && errno == EAGAIN) {
					struct pollfd pf = {master, POLLOUT, 0};
					poll(&pf, 1, 5);
					continue;
				}
				if (w <= 0)
					break;
				b += w;
				left -= (size_t)w;
			}
		}
		/* The person at the terminal. */
		if (user && tm.picture && t - tm.first_picture >= 12.0 && z_typed < 4 && t >= next_key) {
			if (z_typed == 0)
				tm.zs = 0; /* Zs in the help text before do not count */
			z_sent[z_typed++] = t;
			answer(&up, "Z");
			next_key = t + 0.25;
		}
		if (tm.picture && !ctrlc && !user && render_end < 0) {
			if (next_key < 0)
				next_key = t + 0.5;
			/* no key in the last second before the time-out: each key typed
			 * has had a second to echo when the run is cut off */
			if (t >= next_key && z_typed < max_z && t - t0 < timeout - 1.0) {
				z_sent[z_typed++] = t;
				answer(&up, "Z");
				next_key = t + 0.25;
			}
		}
		if (!user && render_end >= 0 && pic_updates_at_end < 0) {
			pic_updates_at_end = tm.updates;
			pictures_at_end = tm.pictures;
			if (!ctrlc && z_typed)
				answer(&up, "\x15"); /* Ctrl-U: the line cleared */
		}
		if (ctrlc && tm.picture && key_at < 0 && t - tm.first_picture >= 2.0) {
			key_at = t;
			end_off = prog.len;
			answer(&up, "\x03");
		}
		/* Done when the wire has been idle for 3 s after the event. */
		double event = ctrlc ? key_at : user ? (z_typed == 4 ? z_sent[3] : -1) : render_end;
		if (event >= 0 && !wire_busy(&down) && t - tm.last_byte >= 3.0 && t - event >= 3.0)
			break;
		if (child_done && !wire_busy(&down))
			break;
		usleep(1000);
	}
	double end_t = now();
	if (dump && end_off) {
		FILE *f = fopen(dump, "wb");
		if (f) {
			fwrite(prog.b + end_off, 1, prog.len - end_off, f);
			fclose(f);
		}
	}
	kill(pid, SIGTERM);
	for (int k = 0; k < 200; k++) {
		if (waitpid(pid, NULL, WNOHANG) == pid)
			break;
		if (k == 100)
			kill(pid, SIGKILL);
		usleep(10000);
	}
	/* Echo latencies of the keys whose echo came. */
	long got = tm.zs < z_typed ? tm.zs : z_typed;
	double *lat = calloc((size_t)(got ? got : 1), sizeof *lat);
	for (long k = 0; k < got; k++)
		lat[k] = tm.z_at[k] - z_sent[k];
	qsort(lat, (size_t)got, sizeof *lat, cmp_double);
	double p50 = got ? lat[(got - 1) / 2] : -1, p95 = got ? lat[(long)((got - 1) * 0.95)] : -1,
	       mx = got ? lat[got - 1] : -1;
	double refine_s = render_end > 0 && tm.first_picture > 0 ? render_end - tm.first_picture : -1;
	printf("scenario=%s rate=%.0f rtt=%.3f cols=%d rows=%d", scenario, rate, rtt, cols, rows);
	printf(" first_picture=%.2f", tm.picture ? tm.first_picture - t0 : -1.0);
	if (user) {
		printf(" keys=%ld echoed=%ld echo_p50=%.3f echo_p95=%.3f echo_max=%.3f", z_typed, got, p50, p95, mx);
		printf(" pager_s=%.2f view_s=%.2f", steps[0].seen > 0 ? steps[0].seen - steps[0].sent : -1.0,
		       steps[4].seen > 0 ? steps[4].seen - steps[4].sent : -1.0);
	} else if (!ctrlc) {
		printf(" keys=%ld echoed=%ld echo_p50=%.3f echo_p95=%.3f echo_max=%.3f", z_typed, got, p50, p95, mx);
		printf(" render_end=%.2f idle_after_end=%.2f", render_end > 0 ? render_end - t0 : -1.0,
		       render_end > 0 ? tm.last_byte - render_end : -1.0);
		printf(" updates_per_s=%.1f",
		       refine_s > 0 && first_pic_written > 0 && pic_updates_at_end >= 0 ? (double)pic_updates_at_end / (render_end - first_pic_written) : -1.0);
		printf(" pictures_per_s=%.1f",
		       refine_s > 0 && first_pic_written > 0 && pictures_at_end >= 0 ? (double)pictures_at_end / (render_end - first_pic_written) : -1.0);
	} else {
		printf(" idle_after_ctrlc=%.2f", key_at > 0 ? tm.last_byte - key_at : -1.0);
	}
	printf(" sgr24=%ld bytes=%zu timed_out=%d\n", tm.sgr24, down.store.len, end_t - t0 > timeout ? 1 : 0);
	return 0;
}
