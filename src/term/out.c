/* rtsh — the output scheduler (out.h). */
#include "term/out.h"

#include <errno.h>
#include <poll.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>
#include <unistd.h>

#define DSR_QUERY "\x1b[5n"
#define DA1_QUERY "\x1b[c"
#define RQSS_QUERY "\x1b" "7\x1b[48;2;1;2;3m\x1bP$qm\x1b\\\x1b[m\x1b" "8"
#define TCAP_QUERY "\x1bP+q524742;5463\x1b\\"

#define MAX_QUERIES 64
#define HOLD_SECONDS 0.3    /* a cut Esc waits this long for the rest of an answer */
#define HOLD_ANSWER 2.0     /* a cut answer (CSI digits, DCS) waits this long for its end */
#define HOLD_MAX 512        /* bytes of a cut sequence held at most */
#define SLICE_MIN 1024
#define SLICE_FIRST 4096    /* the first slice, before the link is measured */
#define SLICE_START_MAX (32u << 10) /* the largest slice before then */
#define SLICE_MAX (4u << 20)
#define SLICE_TIMEOUT_MIN 10.0
#define SAMPLE_SECONDS 0.1 /* the least link time one throughput figure spans */

typedef enum query_kind { Q_DSR, Q_DA1, Q_RQSS, Q_TCAP } query_kind;

typedef struct query {
	query_kind kind;
	double sent;
	size_t bytes; /* the slice before a DSR; 0 for the others */
	bool stale;   /* the loop was busy meanwhile: no figure from it */
} query;

struct termout {
	int fd;
	termout_state state;
	encoder *pic;
	abuf buf;

	query q[MAX_QUERIES]; /* awaited answers, oldest first (a ring) */
	int qhead, qlen;
	double probe_sent;
	double last_dsr;   /* when the last slice's answer (DSR or DA1) came (0: none yet) */
	double acc_bytes, acc_seconds; /* slices answered since the last figure */
	double link_free;  /* when the link will have sent the slices out, at bps (estimate) */
	size_t start_budget; /* the slice before the link is measured */
	double last_slice_seconds; /* the link time of the last slice answered */

	/* Input held: an escape sequence cut at the end of a read. */
	char hold[HOLD_MAX];
	size_t nhold;
	double hold_since, hold_for;

	int truecolor;
	bool ask_pixels;   /* the pixel questions go with the probe */
	bool ask_version;  /* XTVERSION goes with it (it is one of the pixel questions) */
	pixels_caps pix;   /* their answers */
	bool final;         /* the picture is not a refinement pass */
	bool fresh;         /* a new picture was put and has not gone whole yet */
	bool notice_given;
	const char *notice;
	termout_stats st;
};

termout *termout_new(int fd)
{
	termout *o = calloc(1, sizeof *o);
	if (!o)
		return NULL;
	o->fd = fd;
	o->start_budget = SLICE_FIRST;
	o->state = TERMOUT_IDLE;
	o->final = true;
	abuf_init(&o->buf);
	return o;
}

void termout_free(termout *o)
{
	if (!o)
		return;
	abuf_free(&o->buf);
	free(o);
}

void termout_text(termout *o, const void *b, size_t n)
{
	if (n)
		write_all(o->fd, b, n);
}

static void set_lossy(termout *o);

void termout_set_picture(termout *o, encoder *e)
{
	o->pic = e;
	set_lossy(o);
}

/* Lossy damage for refinement passes on a slow link: the changes beyond
 * the JND go first; once none is left, the exact remainder goes while the
 * link has nothing better to carry (a new pass makes it lossy again). */
static void set_lossy(termout *o)
{
	if (!o->pic || !o->pic->ops->set_lossy)
		return;
	bool slow = o->state == TERMOUT_PACED && o->st.bps > 0 && o->st.bps < TERMOUT_SLOW_BPS;
	if (!slow || o->final) {
		o->pic->ops->set_lossy(o->pic, 0);
		return;
	}
	o->pic->ops->set_lossy(o->pic, TERMOUT_JND);
	if (!encoder_dirty(o->pic))
		o->pic->ops->set_lossy(o->pic, 0);
}

void termout_picture_new(termout *o)
{
	o->fresh = true;
}

void termout_picture_final(termout *o, bool final)
{
	o->final = final;
	set_lossy(o);
}

bool termout_picture_pending(const termout *o)
{
	return o->pic && encoder_dirty(o->pic);
}

void termout_drop_picture(termout *o)
{
	if (o->pic)
		o->pic->ops->keep_shown(o->pic);
}

static bool push_query(termout *o, query_kind k, double now, size_t bytes)
{
	if (o->qlen == MAX_QUERIES)
		return false;
	o->q[(o->qhead + o->qlen++) % MAX_QUERIES] = (query){k, now, bytes, false};
	o->st.in_flight += bytes;
	return true;
}

static void say(termout *o, const char *msg)
{
	if (!o->notice_given) {
		o->notice = msg;
		o->notice_given = true;
	}
}

void termout_ask_pixels(termout *o, bool on)
{
	o->ask_pixels = on;
}

void termout_ask_version(termout *o, bool on)
{
	o->ask_version = on;
}

const pixels_caps *termout_pixels(const termout *o)
{
	return &o->pix;
}

void termout_probe(termout *o, bool ask_color, double now)
{
	abuf *a = &o->buf;
	abuf_reset(a);
	if (ask_color) {
		abuf_str(a, RQSS_QUERY TCAP_QUERY);
		push_query(o, Q_RQSS, now, 0);
		push_query(o, Q_TCAP, now, 0);
	}
	if (o->ask_pixels)
		pixels_questions(a); /* answered before DA1, or never */
	else if (o->ask_version)
		abuf_str(a, "\x1b[>q");
	abuf_str(a, DA1_QUERY);
	push_query(o, Q_DA1, now, 0);
	o->probe_sent = now;
	o->state = TERMOUT_PROBING;
	if (!a->failed)
		write_all(o->fd, a->b, a->len);
}

/* The link figures from an answer that came at `now`, `t` seconds after
 * its query was sent, `bytes` (a slice) before it. With slices pipelined,
 * a slice's bytes start down the link when it was sent or when the one
 * before it had gone (its answer, less the round trip), whichever is later:
 * they took min(t - rtt, now - last answer) seconds. Answers read in a
 * bunch (the loop was slow to read them) would make that tiny: the bytes
 * and seconds are summed until they span SAMPLE_SECONDS, which the sum of
 * those minimums does over a busy stretch of the link. */
static void learn(termout *o, double now, double t, size_t bytes, bool slice)
{
	if (t <= 0)
		t = 1e-6;
	/* The round trip: the quickest answer to a query with (almost)
	 * nothing before it; a slice's answer also holds the slice's time on
	 * the link. One read late (the loop was busy at start) is soon
	 * replaced: a query goes ahead of every slice sent on an idle link. */
	if (bytes < 512 && (o->st.rtt == 0 || t < o->st.rtt))
		o->st.rtt = t;
	if (bytes >= 512) {
		double d = t - o->st.rtt;
		if (o->last_dsr > 0 && now - o->last_dsr < d)
			d = now - o->last_dsr;
		o->acc_bytes += (double)bytes;
		o->acc_seconds += d > 0 ? d : 0;
		o->last_slice_seconds = d > 0 ? d : 0;
		if (o->acc_seconds >= SAMPLE_SECONDS) {
			double bps = o->acc_bytes / o->acc_seconds;
			o->st.bps = o->st.bps > 0 ? 0.6 * o->st.bps + 0.4 * bps : bps;
			o->acc_bytes = o->acc_seconds = 0;
		}
	}
	if (slice)
		o->last_dsr = now;
	/* Not measured yet after a slice: the link took it in less than
	 * SAMPLE_SECONDS, so the next one is twice as big (a slow start):
	 * on a fast link, 4 KB slices one round trip apart would use a
	 * fraction of it and take seconds to span a figure (at 1 MB/s with a
	 * 20 ms round trip, 175 KB/s for 2.5 s); here it is measured within a
	 * few round trips, and on a slow link after the first slice. Twice
	 * as big only while that takes at most SAMPLE_SECONDS of link, so a
	 * key typed meanwhile never waits behind more than that. */
	if (slice && !(o->st.bps > 0) && 2 * o->last_slice_seconds <= SAMPLE_SECONDS) {
		size_t b = o->start_budget * 2;
		o->start_budget = b < SLICE_START_MAX ? b : SLICE_START_MAX;
	}
}

/* An answer of kind k: the queries before the first of that kind were not
 * answered (the terminal ignores them) and go too. */
static void answered(termout *o, query_kind k, double now)
{
	int n = 0;
	while (n < o->qlen && o->q[(o->qhead + n) % MAX_QUERIES].kind != k)
		n++;
	if (n == o->qlen)
		return; /* not asked: a stray answer, dropped all the same */
	for (int i = 0; i <= n; i++) {
		query q = o->q[o->qhead];
		o->qhead = (o->qhead + 1) % MAX_QUERIES;
		o->qlen--;
		o->st.in_flight -= q.bytes;
		if (i == n) {
			if (!q.stale)
				learn(o, now, now - q.sent, q.bytes, q.bytes > 0);
			else if (q.bytes > 0)
				o->last_dsr = 0; /* read late: no start time from it */
			if (q.kind == Q_DA1 && o->state == TERMOUT_PROBING)
				o->state = TERMOUT_PACED;
		}
	}
	o->st.answers++;
}

static bool awaiting(const termout *o, query_kind k)
{
	for (int i = 0; i < o->qlen; i++)
		if (o->q[(o->qhead + i) % MAX_QUERIES].kind == k)
			return true;
	return false;
}

bool termout_awaiting(const termout *o)
{
	return o->qlen > 0;
}

/* A DCS answer's body (between "\eP" and the string terminator). */
static void dcs_answer(termout *o, const char *p, size_t n, double now)
{
	if (n >= 3 && p[1] == '$' && p[2] == 'r') {
		/* DECRQSS: "1$r" + the SGR as the terminal keeps it. The
		 * background must still be the 24-bit colour we set. */
		if (p[0] == '1') {
			char body[128];
			snprintf(body, sizeof body, "%.*s", (int)(n - 3), p + 3);
			if (strstr(body, "48:2::1:2:3") || strstr(body, "48:2:1:2:3") || strstr(body, "48;2;1;2;3"))
				o->truecolor = 1;
		}
		answered(o, Q_RQSS, now);
	} else if (n >= 3 && p[1] == '+' && p[2] == 'r') {
		/* XTGETTCAP: "1+r" then NAME[=VALUE] in hex, ';' between: RGB
		 * (524742) or Tc (5463) is there; "0+r": not known */
		for (size_t i = 3; p[0] == '1' && i < n;) {
			size_t j = i;
			while (j < n && p[j] != '=' && p[j] != ';')
				j++;
			if ((j - i == 6 && strncasecmp(p + i, "524742", 6) == 0) ||
			    (j - i == 4 && strncasecmp(p + i, "5463", 4) == 0))
				o->truecolor = 1;
			while (j < n && p[j] != ';')
				j++;
			i = j + 1;
		}
		answered(o, Q_TCAP, now);
	}
}

/* Length of the sequence at p (ESC first) when it is complete: >0; 0 when
 * cut short; the kind of answer in *kind (-1: not an answer). */
static size_t scan_seq(const termout *o, const char *p, size_t n, int *kind)
{
	*kind = -1;
	if (n < 2)
		return 0;
	if (p[1] == '[') {
		size_t i = 2;
		while (i < n && !((unsigned char)p[i] >= 0x40 && (unsigned char)p[i] <= 0x7e))
			i++;
		if (i >= n)
			return 0;
		char fin = p[i];
		bool digits = i > 2;
		for (size_t k = 2; k < i; k++)
			digits &= p[k] >= '0' && p[k] <= '9';
		if (fin == 'n' && digits)
			*kind = Q_DSR;
		else if (fin == 'c' && p[2] == '?')
			*kind = Q_DA1;
		return i + 1;
	}
	if (p[1] == 'P' && (awaiting(o, Q_RQSS) || awaiting(o, Q_TCAP))) {
		for (size_t i = 2; i < n; i++) {
			if (p[i] == '\a') {
				*kind = Q_RQSS; /* told apart in dcs_answer */
				return i + 1;
			}
			if (p[i] == '\x1b' && i + 1 < n && p[i + 1] == '\\') {
				*kind = Q_RQSS;
				return i + 2;
			}
			if (p[i] == '\x1b' && i + 1 == n)
				return 0;
		}
		return 0;
	}
	return 1; /* ESC and whatever follows: keys */
}

/* Runs the parser over p[0..n): answers are taken, keys appended; returns
 * how many bytes were used (the rest is a cut sequence to hold). */
static size_t parse(termout *o, const char *p, size_t n, double now, abuf *keys)
{
	size_t i = 0;
	while (i < n) {
		if (p[i] != '\x1b') {
			size_t j = i;
			while (j < n && p[j] != '\x1b')
				j++;
			abuf_add(keys, p + i, j - i);
			i = j;
			continue;
		}
		if (o->ask_pixels || o->ask_version) {
			size_t k = pixels_answer(&o->pix, p + i, n - i);
			if (k) {
				i += k;
				continue;
			}
			/* the kitty answer (an APC) or XTVERSION's (a DCS) cut short:
			 * hold it */
			if (n - i >= 2 && (p[i + 1] == '_' || (p[i + 1] == 'P' && (n - i < 3 || p[i + 2] == '>'))) &&
			    o->qlen > 0 && n - i < HOLD_MAX) {
				bool end = false;
				for (size_t j = i + 2; j + 1 < n && !end; j++)
					end = p[j] == '\x1b' && p[j + 1] == '\\';
				if (!end)
					return i;
			}
		}
		int kind;
		size_t len = scan_seq(o, p + i, n - i, &kind);
		if (len == 0) {
			/* Cut short: hold it while an answer may be coming. */
			if (o->qlen > 0 && n - i < HOLD_MAX)
				return i;
			len = n - i;
		}
		if (kind == Q_DSR)
			answered(o, Q_DSR, now);
		else if (kind == Q_DA1)
			answered(o, Q_DA1, now);
		else if (kind == Q_RQSS)
			dcs_answer(o, p + i + 2, len - 2 - (p[i + len - 1] == '\a' ? 1 : 2), now);
		else
			abuf_add(keys, p + i, len);
		i += len;
	}
	return n;
}

void termout_input(termout *o, const char *b, size_t n, double now, abuf *keys)
{
	/* The held bytes first, then the new ones. */
	char *tmp = NULL;
	const char *p = b;
	size_t len = n;
	if (o->nhold) {
		tmp = malloc(o->nhold + n);
		if (!tmp) {
			abuf_add(keys, o->hold, o->nhold);
			o->nhold = 0;
		} else {
			memcpy(tmp, o->hold, o->nhold);
			memcpy(tmp + o->nhold, b, n);
			p = tmp;
			len = o->nhold + n;
		}
	}
	bool was_held = o->nhold > 0;
	size_t used = parse(o, p, len, now, keys);
	size_t rest = len - used;
	if (rest) {
		memmove(o->hold, p + used, rest);
		if (!was_held || o->nhold == 0 || used > 0)
			o->hold_since = now;
		/* Keys come whole (a terminal writes a key's sequence at once);
		 * an answer may come in pieces, the more so on a loaded machine:
		 * "ESC [ digits", "ESC [ ?" and a DCS wait longer than a lone Esc. */
		o->hold_for = rest > 1 ? HOLD_ANSWER : HOLD_SECONDS;
	}
	o->nhold = rest;
	free(tmp);
}

static size_t slice_budget(const termout *o)
{
	if (!(o->st.bps > 0))
		return o->start_budget;
	double b = o->st.bps * TERMOUT_SLICE_SECONDS;
	return b < SLICE_MIN ? SLICE_MIN : b > SLICE_MAX ? SLICE_MAX : (size_t)b;
}

/* When another slice may go (now or later; < 0: only after an answer).
 * Two bounds: the slices not yet down the link, at the measured rate,
 * stay within TERMOUT_QUEUE_SECONDS, which is all text (an echo) waits
 * behind; and the bytes unanswered stay within what the link holds in a
 * round trip plus that queue, should the rate be overestimated. Within
 * them the link never waits for an answer. Before the link is measured:
 * one slice at a time. */
static double slice_time(const termout *o, double now)
{
	if (o->st.in_flight == 0)
		return now;
	if (!(o->st.bps > 0) || o->last_dsr == 0)
		return -1;
	double budget = (double)slice_budget(o);
	if ((double)o->st.in_flight + budget > o->st.bps * (o->st.rtt + TERMOUT_QUEUE_SECONDS))
		return -1;
	double at = o->link_free - (TERMOUT_QUEUE_SECONDS - budget / o->st.bps);
	return at > now ? at : now;
}

/* How long an answer to the oldest slice may take before the terminal
 * counts as one that does not answer. */
static double slice_timeout(const termout *o)
{
	double expect = o->st.rtt + (o->st.bps > 0 ? (double)o->st.in_flight / o->st.bps : 1.0);
	double t = 4 * expect;
	return t < SLICE_TIMEOUT_MIN ? SLICE_TIMEOUT_MIN : t;
}

static void give_up(termout *o, const char *why)
{
	o->state = TERMOUT_UNPACED;
	say(o, why);
}

void termout_pump(termout *o, double now, abuf *keys)
{
	if (o->nhold && now - o->hold_since >= o->hold_for) {
		/* Nothing more came: keys after all (Esc, Alt+key). */
		abuf_add(keys, o->hold, o->nhold);
		o->nhold = 0;
	}
	if (o->state == TERMOUT_PROBING && now - o->probe_sent >= TERMOUT_PROBE_TIMEOUT)
		give_up(o, "the terminal does not answer status queries: the picture is not paced");
	if (o->state == TERMOUT_PACED && o->st.in_flight > 0 && o->qlen > 0 &&
	    now - o->q[o->qhead].sent >= slice_timeout(o))
		give_up(o, "the terminal stopped answering status queries: the picture is not paced");
	set_lossy(o);
	if (!o->pic || o->state == TERMOUT_PROBING || !encoder_dirty(o->pic))
		return;
	abuf *a = &o->buf;
	abuf_reset(a);
	if (o->state != TERMOUT_PACED) {
		/* A part at a time: the loop reads keys between parts, and
		 * sends the next when the terminal can take it. */
		encoder_update(o->pic, a, TERMOUT_UNPACED_PART);
	} else {
		double at = slice_time(o, now);
		if (at < 0 || at > now || o->qlen == MAX_QUERIES)
			return;
		/* On an idle link a bare query first: its answer times the
		 * round trip alone. */
		bool idle = o->st.in_flight == 0 && o->qlen + 2 <= MAX_QUERIES;
		if (idle)
			abuf_str(a, DSR_QUERY);
		size_t head = a->len;
		encoder_update(o->pic, a, slice_budget(o));
		if (a->len == head) {
			abuf_reset(a);
			return;
		}
		if (idle)
			push_query(o, Q_DSR, now, 0);
		/* The slice that ends a new picture (its changes beyond the
		 * tolerance all sent) asks DA1, the others DSR: both are
		 * answered in order, and the terminal's side can count the
		 * pictures it was shown. */
		bool whole = o->fresh && !encoder_dirty(o->pic);
		if (whole)
			o->fresh = false;
		abuf_str(a, whole ? DA1_QUERY : DSR_QUERY);
		push_query(o, whole ? Q_DA1 : Q_DSR, now, a->len - head);
		if (whole)
			o->st.pictures++;
	}
	if (a->len && !a->failed) {
		write_all(o->fd, a->b, a->len);
		o->st.slices++;
		if (o->st.bps > 0)
			o->link_free = (o->link_free > now ? o->link_free : now) + (double)a->len / o->st.bps;
	}
}

double termout_wait(const termout *o, double now)
{
	double best = -1;
#define CONSIDER(t)                                   \
	do {                                          \
		double d_ = (t) - now;                \
		d_ = d_ < 0 ? 0 : d_;                 \
		if (best < 0 || d_ < best)            \
			best = d_;                    \
	} while (0)
	if (o->nhold)
		CONSIDER(o->hold_since + o->hold_for);
	if (o->state == TERMOUT_PROBING)
		CONSIDER(o->probe_sent + TERMOUT_PROBE_TIMEOUT);
	if (o->state == TERMOUT_PACED && o->qlen > 0 && o->st.in_flight > 0)
		CONSIDER(o->q[o->qhead].sent + slice_timeout(o));
	if (o->pic && o->state == TERMOUT_PACED && encoder_dirty(o->pic)) {
		double at = slice_time(o, now);
		if (at >= 0)
			CONSIDER(at);
	}
#undef CONSIDER
	return best;
}

bool termout_want_write(const termout *o)
{
	return o->pic && (o->state == TERMOUT_IDLE || o->state == TERMOUT_UNPACED) && encoder_dirty(o->pic);
}

int termout_fd(const termout *o)
{
	return o->fd;
}

void termout_release_held(termout *o, abuf *keys)
{
	abuf_add(keys, o->hold, o->nhold);
	o->nhold = 0;
}

termout_state termout_get_state(const termout *o)
{
	return o->state;
}

int termout_truecolor(const termout *o)
{
	return o->truecolor;
}

const char *termout_notice(termout *o)
{
	const char *n = o->notice;
	o->notice = NULL;
	return n;
}

termout_stats termout_get_stats(const termout *o)
{
	return o->st;
}

void termout_stale(termout *o, double now)
{
	for (int i = 0; i < o->qlen; i++) {
		query *q = &o->q[(o->qhead + i) % MAX_QUERIES];
		q->stale = true;
		q->sent = now; /* the time-outs count from now */
	}
	if (o->state == TERMOUT_PROBING)
		o->probe_sent = now;
}

static double mono_now(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)t.tv_sec + t.tv_nsec * 1e-9;
}

void termout_settle(termout *o, int in_fd, double max_seconds, abuf *keys)
{
	double t0 = mono_now();
	while (o->qlen > 0) {
		double left = t0 + max_seconds - mono_now();
		if (left <= 0)
			break;
		struct pollfd pf = {in_fd, POLLIN, 0};
		int r = poll(&pf, 1, (int)(left * 1000) + 1);
		if (r < 0 && errno == EINTR)
			continue;
		if (r <= 0)
			break;
		char b[1024];
		ssize_t n = read(in_fd, b, sizeof b);
		if (n <= 0)
			break;
		termout_input(o, b, (size_t)n, mono_now(), keys);
	}
	/* What is held now is keys. */
	abuf_add(keys, o->hold, o->nhold);
	o->nhold = 0;
}
