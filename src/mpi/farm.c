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

/* The tiles of the image, row by row. A tile's floats are its pixels'
 * radiance (3 a pixel), then, when the image is to be denoised, their
 * features (DENOISE_FEATURES a pixel): rank 0 denoises the whole image. */
typedef struct tiling {
	int w, h, side, across;
	long count;
	int per; /* floats a pixel */
} tiling;

static tiling tiling_of(const render_settings *s, int side)
{
	tiling t = {s->width, s->height, side, (s->width + side - 1) / side, 0, 3};
	t.count = (long)t.across * ((s->height + side - 1) / side);
	if (farm_denoises(s))
		t.per += DENOISE_FEATURES;
	return t;
}

bool farm_denoises(const render_settings *s)
{
	return render_mode_denoises(s->mode) && s->denoise == DENOISE_ON;
}

static void tile_rect(const tiling *t, long i, int r[4])
{
	r[0] = (int)(i % t->across) * t->side;
	r[1] = (int)(i / t->across) * t->side;
	r[2] = r[0] + t->side < t->w ? r[0] + t->side : t->w;
	r[3] = r[1] + t->side < t->h ? r[1] + t->side : t->h;
}

static size_t tile_floats(const tiling *t, long i)
{
	int r[4];
	tile_rect(t, i, r);
	return (size_t)(r[2] - r[0]) * (size_t)(r[3] - r[1]) * (size_t)t->per;
}

/* Renders tile i into px (tile_floats floats). */
static void render_tile_px(const world *w, const render_settings *s, const tiling *t, long i, float *px)
{
	int r[4];
	tile_rect(t, i, r);
	size_t n = (size_t)(r[2] - r[0]) * (size_t)(r[3] - r[1]);
	render_rect_features(w, s, r[0], r[1], r[2], r[3], px, t->per > 3 ? px + n * 3 : NULL);
}

/* Copies a tile's floats into the image (and its features, when it has
 * them, into fb->feat). */
static void place(const tiling *t, long i, const float *px, framebuffer *fb)
{
	int r[4];
	tile_rect(t, i, r);
	size_t row = (size_t)(r[2] - r[0]) * 3;
	for (int y = r[1]; y < r[3]; y++, px += row)
		memcpy(fb->rgb + ((size_t)y * (size_t)fb->w + (size_t)r[0]) * 3, px, row * sizeof *px);
	if (t->per > 3 && fb->feat) {
		row = (size_t)(r[2] - r[0]) * DENOISE_FEATURES;
		for (int y = r[1]; y < r[3]; y++, px += row)
			memcpy(fb->feat + ((size_t)y * (size_t)fb->w + (size_t)r[0]) * DENOISE_FEATURES, px,
			       row * sizeof *px);
	}
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
	float *buf; /* one tile */
} server_arg;

static void *server_thread(void *arg)
{
	server *sv = ((server_arg *)arg)->sv;
	float *buf = ((server_arg *)arg)->buf;
	world_rays_reset();
	double busy = 0.0;
	for (;;) {
		long i = atomic_fetch_add(&sv->next, 1);
		if (i >= sv->t.count)
			break;
		double t0 = now();
		render_tile_px(sv->w, sv->s, &sv->t, i, buf);
		double took = now() - t0;
		busy += took;
		for (double old = atomic_load(&sv->slowest); took > old;)
			if (atomic_compare_exchange_weak(&sv->slowest, &old, took))
				break;
		place(&sv->t, i, buf, sv->fb);
		atomic_fetch_add(&sv->local, 1);
		atomic_fetch_add(&sv->done, 1);
	}
	atomic_fetch_add(&sv->rays, world_rays_traced());
	add_double(&sv->busy, busy);
	return NULL;
}

/* The progress line (shell/progress.h) on standard error. */
static void show_progress(const render_settings *s, long done, long total, double elapsed)
{
	progress_state ps = {s->width, s->height, s->samples, done, total, elapsed};
	progress_print(stderr, &ps);
}

/* What rank 0 knows of each worker's pace, for the deadline (farm_opts). */
typedef struct pace {
	double last;     /* when it last sent something (or the farm began) */
	long held;       /* tiles handed to it and not yet back */
	double slowest;  /* the longest wait between two of its messages, while it held tiles */
} pace;

/* Sends a worker up to k tile numbers (list has room for k + 1), with -1
 * after them when none are left; then the worker is told. */
static void hand_out(server *sv, int worker, int64_t k, int64_t *list, bool *told, int *active,
                     double *bytes, pace *pc)
{
	int n = 0;
	while (n < k) {
		long i = atomic_fetch_add(&sv->next, 1);
		if (i >= sv->t.count) {
			list[n++] = -1;
			*told = true;
			(*active)--;
			break;
		}
		list[n++] = i;
		pc[worker].held++;
	}
	MPI_Send(list, n, MPI_INT64_T, worker, FARM_TILES, MPI_COMM_WORLD);
	*bytes += (double)n * sizeof *list;
}

#define FARM_MAX_ASK 65536

/* Takes one waiting message from a worker and answers it; false (err set)
 * when the message breaks the protocol. */
static bool serve_one(server *sv, MPI_Status *ms, char *msg, size_t most, bool *told, int *active,
                      double *bytes, pace *pc, rt_error *err)
{
	int src = ms->MPI_SOURCE, count;
	int64_t one[2];
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
		int64_t *list = malloc(((size_t)k + 1) * sizeof *list);
		if (!list)
			return rt_error_set(err, "out of memory");
		hand_out(sv, src, k, list, &told[src], active, bytes, pc);
		free(list);
		return true;
	}
	if (ms->MPI_TAG != FARM_RESULT)
		return rt_error_set(err, "rank %d sent message kind %d; expected a tile", src, ms->MPI_TAG);
	MPI_Get_count(ms, MPI_BYTE, &count);
	size_t cap = sizeof(int64_t) + most * sizeof(float);
	if (count < (int)sizeof(int64_t) || (size_t)count > cap)
		return rt_error_set(err, "rank %d sent a tile of %d bytes; expected at most %zu", src,
		                    count, cap);
	MPI_Recv(msg, count, MPI_BYTE, src, FARM_RESULT, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
	int64_t i;
	memcpy(&i, msg, sizeof i);
	if (i < 0 || i >= sv->t.count ||
	    (size_t)count != sizeof i + tile_floats(&sv->t, i) * sizeof(float))
		return rt_error_set(err, "rank %d sent tile %lld in %d bytes; expected one of the %ld tiles, whole",
		                    src, (long long)i, count, sv->t.count);
	/* msg is malloc'd and the floats start 8 bytes in: aligned */
	place(&sv->t, i, (const float *)(void *)(msg + sizeof i), sv->fb);
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
	server sv = {.w = w, .s = s, .t = tiling_of(s, o->tile), .fb = fb};
	atomic_init(&sv.next, 0);
	atomic_init(&sv.done, 0);
	atomic_init(&sv.rays, 0);
	atomic_init(&sv.local, 0);
	atomic_init(&sv.busy, 0.0);
	atomic_init(&sv.slowest, 0.0);
	size_t most = (size_t)o->tile * (size_t)o->tile * (size_t)sv.t.per;
	int n = o->threads;
	char *msg = malloc(sizeof(int64_t) + most * sizeof(float));
	bool *told = calloc((size_t)size, sizeof *told);
	pace *pc = calloc((size_t)size, sizeof *pc);
	pthread_t *tid = calloc((size_t)n, sizeof *tid);
	server_arg *args = calloc((size_t)n, sizeof *args);
	/* one tile for each thread, and one for this thread if none starts */
	float *bufs = malloc(((size_t)n + 1) * most * sizeof *bufs);
	if (!msg || !told || !pc || !tid || !args || !bufs) {
		free(msg);
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
	float *own = started == 0 ? bufs + (size_t)n * most : NULL;
	double own_busy = 0.0, checked = t0;
	long own_tiles = 0;
	if (started == 0)
		world_rays_reset();
	while (ok && (active > 0 || atomic_load(&sv.done) < sv.t.count)) {
		int flag = 0;
		MPI_Status ms;
		MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &ms);
		if (flag) {
			ok = serve_one(&sv, &ms, msg, most, told, &active, &bytes, pc, err);
			if (!ok) /* the threads stop after their tile; the caller aborts */
				atomic_store(&sv.next, sv.t.count);
			nap = 50;
			continue;
		}
		if (o->progress && now() - shown >= 0.1) {
			shown = now();
			show_progress(s, atomic_load(&sv.done), sv.t.count, shown - t0);
		}
		long i = own ? atomic_fetch_add(&sv.next, 1) : sv.t.count;
		if (i < sv.t.count) {
			double b0 = now();
			render_tile_px(w, s, &sv.t, i, own);
			own_busy += now() - b0;
			if (now() - b0 > atomic_load(&sv.slowest))
				atomic_store(&sv.slowest, now() - b0);
			place(&sv.t, i, own, fb);
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
		show_progress(s, atomic_load(&sv.done), sv.t.count, now() - t0);
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
		c->qhead = (c->qhead + 1) % c->cap;
		c->qlen--;
		char *msg = c->spare[--c->nspare];
		pthread_mutex_unlock(&c->lock);

		memcpy(msg, &i, sizeof i);
		double t0 = now();
		render_tile_px(c->w, c->s, &c->t, i, (float *)(void *)(msg + sizeof i));
		double t1 = now();

		pthread_mutex_lock(&c->lock);
		c->out[(c->ohead + c->olen++) % c->cap] =
			(outgoing){msg, sizeof i + tile_floats(&c->t, i) * sizeof(float), t1 + c->delay};
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
	crew c = {.w = w, .s = s, .t = tiling_of(s, o->tile), .delay = o->delay_us * 1e-6, .cap = k};
	size_t most = (size_t)o->tile * (size_t)o->tile * (size_t)c.t.per;
	size_t msgsize = sizeof(int64_t) + most * sizeof(float);
	c.queue = calloc((size_t)k, sizeof *c.queue);
	int nbuf = 2 * k;
	c.spare = calloc((size_t)nbuf, sizeof *c.spare);
	MPI_Request *sreq = calloc((size_t)nbuf, sizeof *sreq);
	char **smsg = calloc((size_t)nbuf, sizeof *smsg);
	int nsend = 0; /* results on their way (MPI_Isend: no core spins while rank 0 takes them) */
	c.out = calloc((size_t)k, sizeof *c.out);
	int64_t *reply = calloc((size_t)k + 1, sizeof *reply);
	double *sent_at = calloc((size_t)k + 1, sizeof *sent_at);
	pthread_t *tid = calloc((size_t)n, sizeof *tid);
	char *slab = malloc((size_t)nbuf * msgsize);
	bool ok = c.queue && c.spare && c.out && reply && sent_at && tid && slab && sreq && smsg;
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
			MPI_Irecv(reply, k + 1, MPI_INT64_T, 0, FARM_TILES, MPI_COMM_WORLD, &req);
		if (req != MPI_REQUEST_NULL) {
			int flag = 0, count = 0;
			MPI_Status ms;
			MPI_Test(&req, &flag, &ms);
			if (flag) {
				event = true;
				MPI_Get_count(&ms, MPI_INT64_T, &count);
				int slot = (sq - expect + (k + 1)) % (k + 1);
				if (sent_at[slot] >= 0.0) {
					rtt += now() - sent_at[slot];
					answers++;
				}
				expect--;
				pthread_mutex_lock(&c.lock);
				for (int j = 0; j < count; j++) {
					if (reply[j] < 0) {
						c.no_more = true;
						expect = 0;
					} else if (reply[j] < c.t.count && c.qlen < c.cap) {
						c.queue[(c.qhead + c.qlen++) % c.cap] = reply[j];
						assigned++;
					} else {
						ok = rt_error_set(err, "rank 0 sent tile %lld; expected one of %ld, at most %d at once",
						                  (long long)reply[j], c.t.count, c.cap);
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
