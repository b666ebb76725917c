/* rtsh — the event loop (evloop.h). */
#include "term/evloop.h"

#include <errno.h>
#include <poll.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "base/abuf.h"

struct evloop {
	int in_fd, wake_fd;
	termout *out;
	abuf keys;        /* key bytes read, answers out; keys.b[pos..len) unread */
	size_t pos;
	bool eof;
	int pending;      /* events seen while a reader blocked, for the next wait */
	double returned;  /* when the last evloop_wait returned (0: never) */
	bool (*interrupted)(void *ctx);
	void *ctx;
};

double evloop_now(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)t.tv_sec + t.tv_nsec * 1e-9;
}

evloop *evloop_new(int in_fd, int wake_fd)
{
	evloop *l = calloc(1, sizeof *l);
	if (!l)
		return NULL;
	l->in_fd = in_fd;
	l->wake_fd = wake_fd;
	abuf_init(&l->keys);
	return l;
}

void evloop_free(evloop *l)
{
	if (!l)
		return;
	abuf_free(&l->keys);
	free(l);
}

void evloop_set_out(evloop *l, termout *o)
{
	l->out = o;
}

termout *evloop_out(const evloop *l)
{
	return l->out;
}

void evloop_set_interrupt(evloop *l, bool (*interrupted)(void *ctx), void *ctx)
{
	l->interrupted = interrupted;
	l->ctx = ctx;
}

void evloop_unread(evloop *l, size_t n)
{
	/* Nothing compacts the buffer between evloop_key's return and this:
	 * its bytes are still at pos - n. */
	l->pos -= n <= l->pos ? n : l->pos;
}

bool evloop_has_keys(const evloop *l)
{
	return l->pos < l->keys.len;
}

bool evloop_eof(const evloop *l)
{
	return l->eof && l->pos >= l->keys.len;
}

/* Room for more keys: the bytes read are dropped from the buffer. */
static void compact(evloop *l)
{
	if (l->pos == 0)
		return;
	if (l->pos >= l->keys.len) {
		abuf_reset(&l->keys);
	} else if (l->pos > 4096) {
		memmove(l->keys.b, l->keys.b + l->pos, l->keys.len - l->pos);
		l->keys.len -= l->pos;
	} else {
		return;
	}
	l->pos = 0;
}

/* Reads what the terminal sent: answers to the scheduler, keys kept. */
static int read_input(evloop *l)
{
	char b[4096];
	ssize_t n = read(l->in_fd, b, sizeof b);
	if (n < 0 && (errno == EINTR || errno == EAGAIN))
		return 0;
	if (n <= 0) {
		l->eof = true;
		return EVLOOP_KEYS;
	}
	compact(l);
	size_t before = l->keys.len;
	long answers = l->out ? termout_get_stats(l->out).answers : 0;
	if (l->out)
		termout_input(l->out, b, (size_t)n, evloop_now(), &l->keys);
	else
		abuf_add(&l->keys, b, (size_t)n);
	int ev = l->keys.len > before ? EVLOOP_KEYS : 0;
	if (l->out && termout_get_stats(l->out).answers != answers)
		ev |= EVLOOP_ANSWER;
	return ev;
}

/* Lets the scheduler send what its pacing allows; keys it gave up holding
 * (a lone Esc) join the keys. */
static int pump(evloop *l)
{
	if (!l->out)
		return 0;
	compact(l);
	size_t before = l->keys.len;
	termout_pump(l->out, evloop_now(), &l->keys);
	return l->keys.len > before ? EVLOOP_KEYS : 0;
}

/* One poll over every source, at most `timeout` seconds (< 0: none of the
 * caller's); the scheduler's deadlines shorten it. */
static int turn(evloop *l, double timeout)
{
	double now = evloop_now();
	double wait = timeout;
	bool caller_timer = timeout >= 0;
	if (l->out) {
		double w = termout_wait(l->out, now);
		if (w >= 0 && (wait < 0 || w < wait)) {
			wait = w;
			caller_timer = false;
		}
	}
	struct pollfd pf[3];
	int n = 0, in_i = -1, wake_i = -1, out_i = -1;
	if (!l->eof) {
		in_i = n;
		pf[n++] = (struct pollfd){l->in_fd, POLLIN, 0};
	}
	if (l->wake_fd >= 0) {
		wake_i = n;
		pf[n++] = (struct pollfd){l->wake_fd, POLLIN, 0};
	}
	if (l->out && termout_want_write(l->out)) {
		out_i = n;
		pf[n++] = (struct pollfd){termout_fd(l->out), POLLOUT, 0};
	}
	int ms = wait < 0 ? -1 : (int)(wait * 1000.0 + 0.999);
	int r = poll(pf, (nfds_t)n, ms);
	if (r < 0)
		return errno == EINTR ? EVLOOP_WAKE : 0;
	int ev = 0;
	if (r == 0 && caller_timer)
		ev |= EVLOOP_TIMER;
	if (wake_i >= 0 && (pf[wake_i].revents & POLLIN)) {
		char buf[256];
		while (read(l->wake_fd, buf, sizeof buf) > 0)
			;
		ev |= EVLOOP_WAKE;
	}
	/* The terminal's answers first: they let the next slice go. */
	if (in_i >= 0 && (pf[in_i].revents & (POLLIN | POLLHUP | POLLERR)))
		ev |= read_input(l);
	(void)out_i; /* writable or not, the pump below writes what it may */
	ev |= pump(l);
	return ev;
}

int evloop_wait(evloop *l, double timeout)
{
	double now = evloop_now();
	/* Busy between two waits (a command ran): the answers that came
	 * meanwhile were read late. */
	if (l->out && l->returned > 0 && now - l->returned > EVLOOP_BUSY_SECONDS)
		termout_stale(l->out, now);
	int ev = l->pending;
	l->pending = 0;
	if (evloop_has_keys(l) || evloop_eof(l) || ev)
		timeout = 0; /* only look: the caller has work */
	ev |= turn(l, timeout);
	if (evloop_has_keys(l) || evloop_eof(l))
		ev |= EVLOOP_KEYS;
	l->returned = evloop_now();
	return ev;
}

int evloop_getc(evloop *l)
{
	if (l->pos >= l->keys.len)
		return -1;
	return (unsigned char)l->keys.b[l->pos++];
}

/* Waits for a key byte inside the loop (other events kept); false at the
 * end of the input or when the interrupt hook says so. */
static bool wait_key(evloop *l, double max_seconds)
{
	double end = max_seconds < 0 ? -1 : evloop_now() + max_seconds;
	while (l->pos >= l->keys.len) {
		if (l->eof)
			return false;
		if ((l->pending & EVLOOP_WAKE) && l->interrupted && l->interrupted(l->ctx))
			return false;
		double left = -1;
		if (end >= 0) {
			left = end - evloop_now();
			if (left <= 0)
				return false;
		}
		int ev = turn(l, left);
		l->pending |= ev & ~(EVLOOP_KEYS | EVLOOP_TIMER);
	}
	return true;
}

int evloop_getc_wait(evloop *l)
{
	if (!wait_key(l, -1))
		return -1;
	return evloop_getc(l);
}

/* Length of the key at p[0..n): 0 when it is cut short. */
static size_t key_len(const unsigned char *p, size_t n)
{
	if (p[0] != 0x1b) {
		size_t len = p[0] < 0x80 ? 1 : p[0] >= 0xf0 ? 4 : p[0] >= 0xe0 ? 3 : p[0] >= 0xc0 ? 2 : 1;
		return len <= n ? len : 0;
	}
	if (n < 2)
		return 0;
	if (p[1] == '[') {
		for (size_t i = 2; i < n; i++)
			if (p[i] >= 0x40 && p[i] <= 0x7e)
				return i + 1;
		return 0;
	}
	if (p[1] == 'O')
		return n >= 3 ? 3 : 0;
	return 2; /* Alt+key */
}

size_t evloop_key(evloop *l, char *seq, size_t size, double esc_wait)
{
	if (size < 2 || !wait_key(l, -1))
		return 0;
	double end = evloop_now() + esc_wait;
	size_t len;
	for (;;) {
		size_t have = l->keys.len - l->pos;
		len = key_len((const unsigned char *)l->keys.b + l->pos, have);
		if (len)
			break;
		/* Cut short: the rest may be on its way. */
		double left = end - evloop_now();
		if (have >= size - 1 || left <= 0 || l->eof) {
			/* It did not come: a lone Esc (then the rest as keys). */
			len = l->keys.b[l->pos] == 0x1b ? 1 : have;
			break;
		}
		int ev = turn(l, left);
		l->pending |= ev & ~(EVLOOP_KEYS | EVLOOP_TIMER);
	}
	if (len > size - 1)
		len = size - 1;
	memcpy(seq, l->keys.b + l->pos, len);
	seq[len] = '\0';
	l->pos += len;
	return len;
}

void evloop_pump(evloop *l)
{
	pump(l);
}

int evloop_in_fd(const evloop *l)
{
	return l->in_fd;
}

void evloop_settle(evloop *l, double max_seconds)
{
	if (!l->out)
		return;
	double end = evloop_now() + max_seconds;
	while (termout_awaiting(l->out) && !l->eof) {
		double left = end - evloop_now();
		if (left <= 0)
			break;
		int ev = turn(l, left);
		l->pending |= ev & ~(EVLOOP_KEYS | EVLOOP_TIMER);
	}
	/* A cut sequence still held is keys now. */
	compact(l);
	termout_release_held(l->out, &l->keys);
}
