/* rtsh-mpi — the tile farm (farm.h). */
#include "mpi/farm.h"

#include <math.h>
#include <mpi.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "shell/progress.h"

enum { FARM_ASK = 1, FARM_TILES = 2, FARM_RESULT = 3 };

static double now(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)t.tv_sec + t.tv_nsec * 1e-9;
}

/* CPU seconds of the calling thread. */
static double thread_cpu(void)
{
	struct timespec t;
	clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
	return (double)t.tv_sec + t.tv_nsec * 1e-9;
}

static void sleep_us(long us)
{
	struct timespec t = {us / 1000000, (us % 1000000) * 1000};
	nanosleep(&t, NULL);
}

/* The tiles of the image, row by row, in one of the passes (farm_opts.pass).
 * A tile's result (out bytes a pixel) is, in one pass, its pixels'
 * radiance (3 floats a pixel), then, when the image is to be denoised,
 * their features (DENOISE_FEATURES floats a pixel): rank 0 denoises the
 * whole image. A denoised image's first pass sends its running sums (3
 * doubles a pixel) and the features; its adaptive pass is handed each
 * tile's state (in bytes a pixel: the sums, the features, each pixel's own
 * count of samples, uint16) and sends the radiance and features as one
 * pass does. */
typedef struct tiling {
	int w, h, side, across;
	long count;
	int pass, first;
	size_t out, in; /* bytes a pixel: of a result, of a tile's state */
} tiling;

#define SUMS_BYTES (3 * sizeof(double))
#define FEAT_BYTES (DENOISE_FEATURES * sizeof(float))

static tiling tiling_of(const render_settings *s, const farm_opts *o)
{
	tiling t = {s->width, s->height, o->tile, (s->width + o->tile - 1) / o->tile, 0, o->pass, o->first,
	            3 * sizeof(float), 0};
	t.count = (long)t.across * ((s->height + o->tile - 1) / o->tile);
	if (farm_denoises(s))
		t.out += FEAT_BYTES;
	if (t.pass == FARM_FIRST)
		t.out = SUMS_BYTES + FEAT_BYTES;
	if (t.pass == FARM_ADAPTIVE)
		t.in = SUMS_BYTES + FEAT_BYTES + sizeof(uint16_t);
	return t;
}

bool farm_denoises(const render_settings *s)
{
	return render_mode_denoises(s->mode) && s->denoise == DENOISE_ON;
}

int farm_first(const render_settings *s)
{
	return render_adaptive_first(s->samples, farm_denoises(s));
}

static void tile_rect(const tiling *t, long i, int r[4])
{
	r[0] = (int)(i % t->across) * t->side;
	r[1] = (int)(i / t->across) * t->side;
	r[2] = r[0] + t->side < t->w ? r[0] + t->side : t->w;
	r[3] = r[1] + t->side < t->h ? r[1] + t->side : t->h;
}

static size_t tile_pixels(const tiling *t, long i)
{
	int r[4];
	tile_rect(t, i, r);
	return (size_t)(r[2] - r[0]) * (size_t)(r[3] - r[1]);
}

/* Bytes up to a multiple of 8: a tile's doubles stay aligned after it. */
static size_t round8(size_t n)
{
	return (n + 7) & ~(size_t)7;
}

/* The most bytes of a tile's result, of its state (room for either and
 * what follows aligned). */
static size_t most_out(const tiling *t)
{
	return round8((size_t)t->side * (size_t)t->side * t->out);
}

static size_t most_in(const tiling *t)
{
	return round8((size_t)t->side * (size_t)t->side * t->in);
}

/* Renders tile i into out (its result); in: its state in the adaptive pass
 * (8-byte aligned; its sums and features are used up). */
static void render_tile_px(const world *w, const render_settings *s, const tiling *t, long i, unsigned char *in,
                           unsigned char *out)
{
	int r[4];
	tile_rect(t, i, r);
	size_t n = tile_pixels(t, i);
	if (t->pass == FARM_FIRST) {
		render_rect_first(w, s, r[0], r[1], r[2], r[3], t->first, (double *)(void *)out,
		                  (float *)(void *)(out + n * SUMS_BYTES));
	} else if (t->pass == FARM_ADAPTIVE) {
		float *feat = (float *)(void *)(out + n * 3 * sizeof(float));
		memcpy(feat, in + n * SUMS_BYTES, n * FEAT_BYTES);
		render_rect_adaptive(w, s, r[0], r[1], r[2], r[3], t->first,
		                     (const uint16_t *)(void *)(in + n * (SUMS_BYTES + FEAT_BYTES)),
		                     (double *)(void *)in, (float *)(void *)out, feat);
	} else {
		float *px = (float *)(void *)out;
		render_rect_features(w, s, r[0], r[1], r[2], r[3], px, t->out > 3 * sizeof(float) ? px + n * 3 : NULL);
	}
}

/* Copies a tile's per-pixel block (size bytes a pixel, rows top to
 * bottom) from src into the rows of tile r in the image's array img (w
 * pixels a row); returns what follows it in src. */
static const unsigned char *rows_in(const int r[4], int w, size_t size, const unsigned char *src, void *img)
{
	size_t row = (size_t)(r[2] - r[0]) * size;
	for (int y = r[1]; y < r[3]; y++, src += row)
		memcpy((unsigned char *)img + ((size_t)y * (size_t)w + (size_t)r[0]) * size, src, row);
	return src;
}

/* The other way: the rows of tile r of img into dst; returns its end. */
static unsigned char *rows_out(const int r[4], int w, size_t size, const void *img, unsigned char *dst)
{
	size_t row = (size_t)(r[2] - r[0]) * size;
	for (int y = r[1]; y < r[3]; y++, dst += row)
		memcpy(dst, (const unsigned char *)img + ((size_t)y * (size_t)w + (size_t)r[0]) * size, row);
	return dst;
}

/* Copies a tile's result into the image: its radiance into fb->rgb, or
 * its first pass's sums into fb->sum; its features, when it has them,
 * into fb->feat. */
static void place(const tiling *t, long i, const unsigned char *px, framebuffer *fb)
{
	int r[4];
	tile_rect(t, i, r);
	if (t->pass == FARM_FIRST)
		px = rows_in(r, fb->w, SUMS_BYTES, px, fb->sum);
	else
		px = rows_in(r, fb->w, 3 * sizeof(float), px, fb->rgb);
	if (t->out > 3 * sizeof(float) && fb->feat)
		rows_in(r, fb->w, FEAT_BYTES, px, fb->feat);
}

/* The state of tile i for the adaptive pass, from the image (its first
 * pass and counts), into in (t->in bytes a pixel). */
static void pack(const tiling *t, long i, const framebuffer *fb, unsigned char *in)
{
	int r[4];
	tile_rect(t, i, r);
	in = rows_out(r, fb->w, SUMS_BYTES, fb->sum, in);
	in = rows_out(r, fb->w, FEAT_BYTES, fb->feat, in);
	rows_out(r, fb->w, sizeof(uint16_t), fb->pixel_spp, in);
}

/* ---------------------------------------------------------------- rank 0 */

typedef struct server {
	const world *w;
	const render_settings *s;
	tiling t;
	framebuffer *fb;
	_Alignas(64) atomic_long next;  /* the one tile counter of the job */
	_Alignas(64) atomic_long done;  /* tiles placed in fb */
	_Alignas(64) atomic_ullong rays;
	atomic_long local;              /* tiles rank 0's threads rendered */
	_Atomic double busy;
	_Atomic double slowest; /* the longest tile rank 0 rendered (seconds) */
} server;

static void add_double(_Atomic double *a, double v)
{
	double old = atomic_load(a);
	while (!atomic_compare_exchange_weak(a, &old, old + v))
		;
}

typedef struct server_arg {
	server *sv;
	unsigned char *buf; /* one tile: its result, then its state */
} server_arg;

/* Renders tile i with buf (server_arg) and places it in the image. */
static void serve_tile(const world *w, const render_settings *s, const tiling *t, long i, framebuffer *fb,
                       unsigned char *buf)
{
	unsigned char *in = buf + most_out(t);
	if (t->pass == FARM_ADAPTIVE)
		pack(t, i, fb, in);
	render_tile_px(w, s, t, i, in, buf);
	place(t, i, buf, fb);
}

static void *server_thread(void *arg)
{
	server *sv = ((server_arg *)arg)->sv;
	unsigned char *buf = ((server_arg *)arg)->buf;
	world_rays_reset();
	double busy = 0.0;
	for (;;) {
		long i = atomic_fetch_add(&sv->next, 1);
		if (i >= sv->t.count)
			break;
		double t0 = now();
		serve_tile(sv->w, sv->s, &sv->t, i, sv->fb, buf);
		double took = now() - t0;
		busy += took;
		for (double old = atomic_load(&sv->slowest); took > old;)
			if (atomic_compare_exchange_weak(&sv->slowest, &old, took))
				break;
		atomic_fetch_add(&sv->local, 1);
		atomic_fetch_add(&sv->done, 1);
	}
	atomic_fetch_add(&sv->rays, world_rays_traced());
	add_double(&sv->busy, busy);
	return NULL;
}

double farm_clock(void)
{
	return now();
}

/* The progress line (shell/progress.h) on standard error: a denoised
 * image's two passes as one, each tile of the first counting its first
 * samples, of the second the rest (as rtsh shows them), the time since
 * o->t0 (the frame's start; 0: this pass's, t0). */
static void show_progress(const render_settings *s, const farm_opts *o, const tiling *t, long done, double t0)
{
	long total = t->count * s->samples, d = done * s->samples;
	if (t->pass == FARM_FIRST)
		d = done * t->first;
	else if (t->pass == FARM_ADAPTIVE)
		d = t->count * t->first + done * (s->samples - t->first);
	progress_state ps = {s->width, s->height, s->samples, d, total, now() - (o->t0 > 0 ? o->t0 : t0)};
	progress_print(stderr, &ps);
}

/* What rank 0 knows of each worker's pace, for the deadline (farm_opts). */
typedef struct pace {
	double last;     /* when it last sent something (or the farm began) */
	long held;       /* tiles handed to it and not yet back */
	double slowest;  /* the longest wait between two of its messages, while it held tiles */
} pace;

/* Room for a hand_out of k tiles. */
static size_t hand_bytes(const tiling *t, int64_t k)
{
	return ((size_t)k + 1) * sizeof(int64_t) + (size_t)k * most_in(t);
}

/* Sends a worker up to k tile numbers, each followed by its state in the
 * adaptive pass (list has hand_bytes(k)), with -1 after them when none are
 * left; then the worker is told. */
static void hand_out(server *sv, int worker, int64_t k, unsigned char *list, bool *told, int *active,
                     double *bytes, pace *pc)
{
	size_t at = 0;
	for (int n = 0; n < k; n++) {
		int64_t i = atomic_fetch_add(&sv->next, 1);
		if (i >= sv->t.count) {
			i = -1;
			memcpy(list + at, &i, sizeof i);
			at += sizeof i;
			*told = true;
			(*active)--;
			break;
		}
		memcpy(list + at, &i, sizeof i);
		at += sizeof i;
		if (sv->t.pass == FARM_ADAPTIVE) {
			pack(&sv->t, i, sv->fb, list + at);
			at += tile_pixels(&sv->t, i) * sv->t.in;
		}
		pc[worker].held++;
	}
	MPI_Send(list, (int)at, MPI_BYTE, worker, FARM_TILES, MPI_COMM_WORLD);
	*bytes += (double)at;
}

#define FARM_MAX_ASK 65536

/* Takes one waiting message from a worker and answers it; false (err set)
 * when the message breaks the protocol. */
static bool serve_one(server *sv, MPI_Status *ms, char *msg, unsigned char *one, bool *told, int *active,
                      double *bytes, pace *pc, rt_error *err)
{
	int src = ms->MPI_SOURCE, count;
	double t = now();
	if (pc[src].held > 0 && t - pc[src].last > pc[src].slowest)
		pc[src].slowest = t - pc[src].last;
	pc[src].last = t;
	if (ms->MPI_TAG == FARM_ASK) {
		int64_t k;
		MPI_Recv(&k, 1, MPI_INT64_T, src, FARM_ASK, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
		if (k < 1 || k > FARM_MAX_ASK || told[src])
			return rt_error_set(err, "rank %d asked for %lld tiles; expected one ask of 1..%d",
			                    src, (long long)k, FARM_MAX_ASK);
		unsigned char *list = malloc(hand_bytes(&sv->t, k));
		if (!list)
			return rt_error_set(err, "out of memory for %lld tiles", (long long)k);
		hand_out(sv, src, k, list, &told[src], active, bytes, pc);
		free(list);
		return true;
	}
	if (ms->MPI_TAG != FARM_RESULT)
		return rt_error_set(err, "rank %d sent message kind %d; expected a tile", src, ms->MPI_TAG);
	MPI_Get_count(ms, MPI_BYTE, &count);
	size_t cap = sizeof(int64_t) + most_out(&sv->t);
	if (count < (int)sizeof(int64_t) || (size_t)count > cap)
		return rt_error_set(err, "rank %d sent a tile of %d bytes; expected at most %zu", src,
		                    count, cap);
	MPI_Recv(msg, count, MPI_BYTE, src, FARM_RESULT, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
	int64_t i;
	memcpy(&i, msg, sizeof i);
	if (i < 0 || i >= sv->t.count ||
	    (size_t)count != sizeof i + tile_pixels(&sv->t, i) * sv->t.out)
		return rt_error_set(err, "rank %d sent tile %lld in %d bytes; expected one of the %ld tiles, whole",
		                    src, (long long)i, count, sv->t.count);
	/* msg is malloc'd and the floats and doubles start 8 bytes in: aligned */
	place(&sv->t, i, (const unsigned char *)msg + sizeof i, sv->fb);
	atomic_fetch_add(&sv->done, 1);
	if (pc[src].held > 0)
		pc[src].held--;
	if (!told[src])
		hand_out(sv, src, 1, one, &told[src], active, bytes, pc);
	return true;
}

bool farm_serve(const world *w, const render_settings *s, const farm_opts *o, framebuffer *fb,
                farm_stats *st, rt_error *err)
{
	int size;
	MPI_Comm_size(MPI_COMM_WORLD, &size);
	server sv = {.w = w, .s = s, .t = tiling_of(s, o), .fb = fb};
	atomic_init(&sv.next, 0);
	atomic_init(&sv.done, 0);
	atomic_init(&sv.rays, 0);
	atomic_init(&sv.local, 0);
	atomic_init(&sv.busy, 0.0);
	atomic_init(&sv.slowest, 0.0);
	size_t most = most_out(&sv.t) + most_in(&sv.t); /* a tile's buffer */
	int n = o->threads;
	char *msg = malloc(sizeof(int64_t) + most_out(&sv.t));
	unsigned char *one = malloc(hand_bytes(&sv.t, 1));
	bool *told = calloc((size_t)size, sizeof *told);
	pace *pc = calloc((size_t)size, sizeof *pc);
	pthread_t *tid = calloc((size_t)n, sizeof *tid);
	server_arg *args = calloc((size_t)n, sizeof *args);
	/* one tile for each thread, and one for this thread if none starts */
	unsigned char *bufs = malloc(((size_t)n + 1) * most);
	if (!msg || !one || !told || !pc || !tid || !args || !bufs) {
		free(msg);
		free(one);
		free(told);
		free(pc);
		free(tid);
		free(args);
		free(bufs);
		return rt_error_set(err, "out of memory for %d tiles of %dx%d", n + 1, o->tile, o->tile);
	}
	double t0 = now(), bytes = 0.0, shown = 0.0, cpu0 = thread_cpu();
	for (int r = 0; r < size; r++)
		pc[r].last = t0;
	int started = 0;
	for (; started < n; started++) {
		args[started] = (server_arg){&sv, bufs + (size_t)started * most};
		if (pthread_create(&tid[started], NULL, server_thread, &args[started]) != 0)
			break;
	}
	/* Serve until every worker has been told to stop and every tile is in:
	 * take all waiting messages, then sleep a little longer each idle round
	 * (50 us doubling to 1 ms), so serving costs no core of its own; the
	 * workers' prefetched tiles cover the wait. With no thread of its own
	 * left, rank 0 renders here between messages. */
	int active = size - 1;
	long nap = 50;
	bool ok = true;
	unsigned char *own = started == 0 ? bufs + (size_t)n * most : NULL;
	double own_busy = 0.0, checked = t0;
	long own_tiles = 0;
	if (started == 0)
		world_rays_reset();
	while (ok && (active > 0 || atomic_load(&sv.done) < sv.t.count)) {
		int flag = 0;
		MPI_Status ms;
		MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &ms);
		if (flag) {
			ok = serve_one(&sv, &ms, msg, one, told, &active, &bytes, pc, err);
			if (!ok) /* the threads stop after their tile; the caller aborts */
				atomic_store(&sv.next, sv.t.count);
			nap = 50;
			continue;
		}
		if (o->progress && now() - shown >= 0.1) {
			shown = now();
			show_progress(s, o, &sv.t, atomic_load(&sv.done), t0);
		}
		long i = own ? atomic_fetch_add(&sv.next, 1) : sv.t.count;
		if (i < sv.t.count) {
			double b0 = now();
			serve_tile(w, s, &sv.t, i, fb, own);
			own_busy += now() - b0;
			if (now() - b0 > atomic_load(&sv.slowest))
				atomic_store(&sv.slowest, now() - b0);
			own_tiles++;
			atomic_fetch_add(&sv.done, 1);
			continue;
		}
		if (o->deadline > 0 && now() - checked >= 0.25) {
			/* four times a second: is a worker late? */
			checked = now();
			double slow = atomic_load(&sv.slowest);
			for (int r = 1; r < size; r++)
				slow = fmax(slow, pc[r].slowest);
			double limit = fmax(o->deadline, FARM_DEADLINE_TILES * slow), t = now();
			for (int r = 1; ok && slow > 0 && r < size; r++)
				if ((!told[r] || pc[r].held > 0) && t - pc[r].last > limit) {
					ok = rt_error_set(err,
					                  "rank %d on %s sent no tile for %.0f s (stopped, or its host hangs); "
					                  "expected one within %.0f s (%g x the slowest tile, at least "
					                  "RTSH_MPI_DEADLINE=%g)",
					                  r, o->host ? o->host(r) : "?", t - pc[r].last, limit,
					                  FARM_DEADLINE_TILES, o->deadline);
					atomic_store(&sv.next, sv.t.count); /* the threads stop after their tile */
				}
			if (!ok)
				break;
		}
		sleep_us(nap);
		if (nap < 1000)
			nap *= 2;
	}
	for (int i = 0; i < started; i++)
		pthread_join(tid[i], NULL);
	if (o->progress) {
		show_progress(s, o, &sv.t, atomic_load(&sv.done), t0);
		/* the line goes on in the second pass, unless the farm failed:
		 * then the message that follows must start a line of its own */
		if (sv.t.pass != FARM_FIRST || !ok)
			fputc('\n', stderr);
	}
	if (started == 0)
		atomic_fetch_add(&sv.rays, world_rays_traced());
	*st = (farm_stats){
		.tiles = (double)(atomic_load(&sv.local) + own_tiles),
		.seconds = now() - t0,
		.busy = atomic_load(&sv.busy) + own_busy,
		.rays = (double)atomic_load(&sv.rays),
		.bytes = bytes,
		.serve = thread_cpu() - cpu0 - own_busy,
		.threads = started ? started : 1,
	};
	free(bufs);
	free(args);
	free(msg);
	free(one);
	free(told);
	free(pc);
	free(tid);
	return ok;
}

/* ------------------------------------------------------------ the others */

/* A tile message: the tile number, then its floats. */
typedef struct outgoing {
	char *msg;
	size_t bytes;
	double ready; /* when it may be sent (the delay test mode) */
} outgoing;

typedef struct crew {
	const world *w;
	const render_settings *s;
	tiling t;
	double delay;
	pthread_mutex_t lock;
	pthread_cond_t work; /* a tile was queued, or none will come */
	pthread_cond_t comm; /* a tile is ready to send */
	/* all below under lock */
	int64_t *queue;      /* tiles to render (ring) */
	unsigned char *state; /* the adaptive pass: queue[j]'s state at j x most_in */
	int qhead, qlen, cap;
	char **spare;        /* free message buffers (2 k: k tiles, and sends in flight) */
	int nspare;
	outgoing *out;       /* rendered, to send (ring) */
	int ohead, olen;
	bool no_more;        /* rank 0 has sent -1 */
	long tiles;
	double busy;
	uint64_t rays;
} crew;

static void *crew_thread(void *arg)
{
	crew *c = arg;
	world_rays_reset();
	pthread_mutex_lock(&c->lock);
	for (;;) {
		/* a tile and a buffer for it (one may still be on its way to rank 0) */
		while ((c->qlen == 0 || c->nspare == 0) && !(c->qlen == 0 && c->no_more))
			pthread_cond_wait(&c->work, &c->lock);
		if (c->qlen == 0)
			break;
		int64_t i = c->queue[c->qhead];
		char *msg = c->spare[--c->nspare];
		/* the state after the result's room (8 + most_out: aligned) */
		unsigned char *in = (unsigned char *)msg + sizeof i + most_out(&c->t);
		if (c->t.in)
			memcpy(in, c->state + (size_t)c->qhead * most_in(&c->t), tile_pixels(&c->t, i) * c->t.in);
		c->qhead = (c->qhead + 1) % c->cap;
		c->qlen--;
		pthread_mutex_unlock(&c->lock);

		memcpy(msg, &i, sizeof i);
		double t0 = now();
		render_tile_px(c->w, c->s, &c->t, i, in, (unsigned char *)msg + sizeof i);
		double t1 = now();

		pthread_mutex_lock(&c->lock);
		c->out[(c->ohead + c->olen++) % c->cap] =
			(outgoing){msg, sizeof i + tile_pixels(&c->t, i) * c->t.out, t1 + c->delay};
		c->tiles++;
		c->busy += t1 - t0;
		pthread_cond_signal(&c->comm);
	}
	c->rays += world_rays_traced();
	pthread_mutex_unlock(&c->lock);
	return NULL;
}

/* Waits on cond for at most `us` microseconds. */
static void wait_us(pthread_cond_t *cond, pthread_mutex_t *lock, double us)
{
	struct timespec ts;
	clock_gettime(CLOCK_REALTIME, &ts);
	long ns = ts.tv_nsec + (long)(us * 1000.0);
	ts.tv_sec += ns / 1000000000L;
	ts.tv_nsec = ns % 1000000000L;
	pthread_cond_timedwait(cond, lock, &ts);
}

bool farm_work(const world *w, const render_settings *s, const farm_opts *o, farm_stats *st,
               rt_error *err)
{
	int n = o->threads, k = o->threads + o->prefetch;
	crew c = {.w = w, .s = s, .t = tiling_of(s, o), .delay = o->delay_us * 1e-6, .cap = k};
	/* a message: the tile number, its result, then its state */
	size_t msgsize = sizeof(int64_t) + most_out(&c.t) + most_in(&c.t);
	size_t replysize = hand_bytes(&c.t, k);
	c.queue = calloc((size_t)k, sizeof *c.queue);
	c.state = malloc((size_t)k * most_in(&c.t) + 1);
	int nbuf = 2 * k;
	c.spare = calloc((size_t)nbuf, sizeof *c.spare);
	MPI_Request *sreq = calloc((size_t)nbuf, sizeof *sreq);
	char **smsg = calloc((size_t)nbuf, sizeof *smsg);
	int nsend = 0; /* results on their way (MPI_Isend: no core spins while rank 0 takes them) */
	c.out = calloc((size_t)k, sizeof *c.out);
	unsigned char *reply = malloc(replysize);
	double *sent_at = calloc((size_t)k + 1, sizeof *sent_at);
	pthread_t *tid = calloc((size_t)n, sizeof *tid);
	char *slab = malloc((size_t)nbuf * msgsize);
	bool ok = c.queue && c.state && c.spare && c.out && reply && sent_at && tid && slab && sreq && smsg;
	if (!ok)
		rt_error_set(err, "out of memory for %d tiles of %dx%d", nbuf, o->tile, o->tile);
	for (int i = 0; ok && i < nbuf; i++)
		c.spare[c.nspare++] = slab + (size_t)i * msgsize;
	pthread_mutex_init(&c.lock, NULL);
	pthread_cond_init(&c.work, NULL);
	pthread_cond_init(&c.comm, NULL);
	int started = 0;
	for (; ok && started < n; started++)
		if (pthread_create(&tid[started], NULL, crew_thread, &c) != 0)
			break;
	if (ok && started == 0)
		ok = rt_error_set(err, "cannot start a render thread");

	double t0 = now(), bytes = 0.0, rtt = 0.0;
	long assigned = 0, sent = 0, answers = 0;
	int expect = 0, sq = 0; /* replies due; send times in sent_at (ring of k + 1) */
	MPI_Request req = MPI_REQUEST_NULL;
	if (ok) {
		int64_t ask = k;
		MPI_Send(&ask, 1, MPI_INT64_T, 0, FARM_ASK, MPI_COMM_WORLD);
		bytes += sizeof ask;
		expect = 1;
		sent_at[sq++] = -1.0; /* the ask: not a tile round trip */
	}
	double nap = 20.0;
	while (ok) {
		bool event = false;
		/* a reply: queue its tiles */
		if (expect > 0 && req == MPI_REQUEST_NULL)
			MPI_Irecv(reply, (int)replysize, MPI_BYTE, 0, FARM_TILES, MPI_COMM_WORLD, &req);
		if (req != MPI_REQUEST_NULL) {
			int flag = 0, count = 0;
			MPI_Status ms;
			MPI_Test(&req, &flag, &ms);
			if (flag) {
				event = true;
				MPI_Get_count(&ms, MPI_BYTE, &count);
				int slot = (sq - expect + (k + 1)) % (k + 1);
				if (sent_at[slot] >= 0.0) {
					rtt += now() - sent_at[slot];
					answers++;
				}
				expect--;
				pthread_mutex_lock(&c.lock);
				/* tile numbers, each with its state (the adaptive pass) */
				for (size_t at = 0; ok && at < (size_t)count;) {
					int64_t j;
					if ((size_t)count - at < sizeof j) {
						ok = rt_error_set(err, "rank 0 sent %d bytes of tiles; expected whole tiles", count);
						break;
					}
					memcpy(&j, reply + at, sizeof j);
					at += sizeof j;
					size_t sb = j >= 0 && j < c.t.count ? tile_pixels(&c.t, j) * c.t.in : 0;
					if (j < 0) {
						c.no_more = true;
						expect = 0;
					} else if (j < c.t.count && c.qlen < c.cap && (size_t)count - at >= sb) {
						int q = (c.qhead + c.qlen++) % c.cap;
						c.queue[q] = j;
						if (sb)
							memcpy(c.state + (size_t)q * most_in(&c.t), reply + at, sb);
						at += sb;
						assigned++;
					} else {
						ok = rt_error_set(err,
						                  "rank 0 sent tile %lld; expected one of %ld with its state, at most %d "
						                  "at once",
						                  (long long)j, c.t.count, c.cap);
					}
				}
				pthread_cond_broadcast(&c.work);
				pthread_mutex_unlock(&c.lock);
			}
		}
		/* rendered tiles whose time has come: send them */
		double t = now(), next_ready = -1.0;
		for (;;) {
			pthread_mutex_lock(&c.lock);
			outgoing g = {0};
			if (c.olen > 0 && c.out[c.ohead].ready <= t) {
				g = c.out[c.ohead];
				c.ohead = (c.ohead + 1) % c.cap;
				c.olen--;
			} else if (c.olen > 0) {
				next_ready = c.out[c.ohead].ready;
			}
			pthread_mutex_unlock(&c.lock);
			if (!g.msg)
				break;
			event = true;
			smsg[nsend] = g.msg;
			MPI_Isend(g.msg, (int)g.bytes, MPI_BYTE, 0, FARM_RESULT, MPI_COMM_WORLD, &sreq[nsend++]);
			bytes += (double)g.bytes;
			sent++;
			if (!c.no_more) {
				expect++;
				sent_at[sq] = now();
				sq = (sq + 1) % (k + 1);
			}
		}
		/* sends that are through give their buffers back */
		for (int i = 0; i < nsend;) {
			int flag = 0;
			MPI_Test(&sreq[i], &flag, MPI_STATUS_IGNORE);
			if (!flag) {
				i++;
				continue;
			}
			event = true;
			pthread_mutex_lock(&c.lock);
			c.spare[c.nspare++] = smsg[i];
			pthread_cond_signal(&c.work);
			pthread_mutex_unlock(&c.lock);
			sreq[i] = sreq[--nsend];
			smsg[i] = smsg[nsend];
		}
		if (c.no_more && sent == assigned && nsend == 0)
			break;
		if (event) {
			nap = 20.0;
			continue;
		}
		/* Nothing happened: wait for a tile to finish, at most a nap when
		 * a reply is due (MPI cannot wake us), or until the next delayed
		 * tile may go. */
		pthread_mutex_lock(&c.lock);
		double wait = expect > 0 || nsend > 0 ? nap : 1e6;
		if (next_ready >= 0.0 && (next_ready - t) * 1e6 < wait)
			wait = (next_ready - t) * 1e6 + 1.0;
		if (c.olen == 0 || next_ready >= 0.0)
			wait_us(&c.comm, &c.lock, wait);
		pthread_mutex_unlock(&c.lock);
		if (nap < 500.0)
			nap *= 2.0;
	}
	if (req != MPI_REQUEST_NULL) {
		MPI_Cancel(&req);
		MPI_Wait(&req, MPI_STATUS_IGNORE);
	}
	/* Sends still in flight only after an error, which aborts the job. */
	pthread_mutex_lock(&c.lock);
	c.no_more = true; /* on an error, the threads stop after their tile */
	c.qlen = 0;
	pthread_cond_broadcast(&c.work);
	pthread_mutex_unlock(&c.lock);
	for (int i = 0; i < started; i++)
		pthread_join(tid[i], NULL);
	*st = (farm_stats){
		.tiles = (double)c.tiles,
		.seconds = now() - t0,
		.busy = c.busy,
		.rays = (double)c.rays,
		.bytes = bytes,
		.rtt = answers ? rtt / (double)answers : 0.0,
		.threads = started,
	};
	pthread_mutex_destroy(&c.lock);
	pthread_cond_destroy(&c.work);
	pthread_cond_destroy(&c.comm);
	free(c.queue);
	free(c.state);
	free(c.spare);
	free(c.out);
	free(reply);
	free(sent_at);
	free(tid);
	free(slab);
	free(sreq);
	free(smsg);
	return ok;
}
