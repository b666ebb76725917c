/* rtsh — the render service (render_service.h). */
#include "shell/render_service.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "rtsh/denoise.h"

struct rsvc {
	int wake_fd;
	pthread_t thread;
	bool started;

	pthread_mutex_t m; /* guards the fields below up to `cancel` */
	pthread_cond_t work, idle;
	bool quit, held, pending, busy;
	rsvc_request req;      /* waiting to start (holds a reference to req.world) */
	uint64_t req_seq;
	rsvc_request last;     /* the last one run (its world pointer not held) */
	uint64_t last_seq, seq;
	bool last_complete;
	atomic_bool cancel;

	/* The world of the newest generation seen (a reference). */
	pthread_mutex_t wm;
	const world *w;
	uint64_t wgen;

	/* The published image and the last cancelled frame. */
	pthread_mutex_t im;
	rsvc_image img;
	uint64_t serial, taken;
	uint64_t cut_seq;
	double cut_seconds, cut_frac;
	bool cut_new;

	/* The thread's own: a small framebuffer (quick passes, frames) and the
	 * refine's, with the request whose samples it holds. */
	framebuffer *small, *fb;
	rsvc_request fb_req;
	bool fb_valid;
	long tiles_done, tiles_total;
};

static double now(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)t.tv_sec + t.tv_nsec * 1e-9;
}

void rsvc_frame_size(int w, int h, double r, int *fw, int *fh)
{
	if (!(r >= 1))
		r = 1;
	int x = w > 0 ? (int)ceil(w / r) : 1;
	if (x < 1)
		x = 1;
	int y = w > 0 ? (int)lround((double)x * h / w) : 1;
	*fw = x;
	*fh = y < 1 ? 1 : y;
}

rsvc *rsvc_new(int wake_fd)
{
	rsvc *sv = calloc(1, sizeof *sv);
	if (!sv)
		return NULL;
	sv->wake_fd = wake_fd;
	pthread_mutex_init(&sv->m, NULL);
	pthread_mutex_init(&sv->wm, NULL);
	pthread_mutex_init(&sv->im, NULL);
	pthread_cond_init(&sv->work, NULL);
	pthread_cond_init(&sv->idle, NULL);
	atomic_init(&sv->cancel, false);
	return sv;
}

void rsvc_image_free(rsvc_image *img)
{
	free(img->rgb);
	img->rgb = NULL;
	img->cap = 0;
}

void rsvc_free(rsvc *sv)
{
	if (!sv)
		return;
	if (sv->started) {
		pthread_mutex_lock(&sv->m);
		sv->quit = true;
		atomic_store(&sv->cancel, true);
		pthread_cond_signal(&sv->work);
		pthread_mutex_unlock(&sv->m);
		pthread_join(sv->thread, NULL);
	}
	if (sv->pending)
		world_release(sv->req.world);
	world_release(sv->w);
	fb_free(sv->fb);
	fb_free(sv->small);
	rsvc_image_free(&sv->img);
	pthread_mutex_destroy(&sv->m);
	pthread_mutex_destroy(&sv->wm);
	pthread_mutex_destroy(&sv->im);
	pthread_cond_destroy(&sv->work);
	pthread_cond_destroy(&sv->idle);
	free(sv);
}

static void wake(rsvc *sv)
{
	if (sv->wake_fd >= 0) {
		ssize_t r = write(sv->wake_fd, "p", 1);
		(void)r; /* a full pipe already holds a wake-up */
	}
}

/* Copies an image into dst, growing its buffer; false when out of memory. */
static bool copy_image(rsvc_image *dst, const rsvc_image *src)
{
	size_t n = (size_t)src->w * (size_t)src->h * 3;
	if (n > dst->cap) {
		float *p = realloc(dst->rgb, n * sizeof *p);
		if (!p)
			return false;
		dst->rgb = p;
		dst->cap = n;
	}
	float *keep = dst->rgb;
	size_t cap = dst->cap;
	*dst = *src;
	dst->rgb = keep;
	dst->cap = cap;
	if (n)
		memcpy(dst->rgb, src->rgb, n * sizeof *dst->rgb);
	return true;
}

/* Publishes fb at w x h (a nearest-neighbour scale-up when fb is smaller:
 * the quick pass) as the newest image; fb NULL publishes no picture (an
 * error). */
static void publish(rsvc *sv, const framebuffer *fb, int w, int h, const rsvc_image *meta)
{
	pthread_mutex_lock(&sv->im);
	rsvc_image *img = &sv->img;
	size_t n = (size_t)w * (size_t)h * 3;
	bool ok = true;
	if (n > img->cap) {
		float *p = realloc(img->rgb, n * sizeof *p);
		if (p) {
			img->rgb = p;
			img->cap = n;
		} else {
			ok = false;
		}
	}
	if (ok) {
		float *keep = img->rgb;
		size_t cap = img->cap;
		*img = *meta;
		img->rgb = keep;
		img->cap = cap;
		img->w = w;
		img->h = h;
		if (fb && fb->w == w && fb->h == h) {
			memcpy(img->rgb, fb->rgb, n * sizeof *img->rgb);
		} else if (fb) {
			for (int y = 0; y < h; y++) {
				int sy = (int)((long)y * fb->h / h);
				for (int x = 0; x < w; x++) {
					int sx = (int)((long)x * fb->w / w);
					memcpy(img->rgb + ((size_t)y * w + x) * 3, fb->rgb + ((size_t)sy * fb->w + sx) * 3,
					       3 * sizeof *img->rgb);
				}
			}
		} else {
			img->w = img->h = 0;
		}
		sv->serial++;
	}
	pthread_mutex_unlock(&sv->im);
	if (ok)
		wake(sv);
}

static void on_progress(void *ctx, long done, long total)
{
	rsvc *sv = ctx;
	sv->tiles_done = done;
	sv->tiles_total = total;
}

/* True when the refine framebuffer (rendered for a) can take more samples
 * for b: the same picture, every sample the same. With one sample per pixel
 * the renderer takes the pixel centre, with more a jittered position, so
 * 1 and more never mix. */
static bool continues(const rsvc_request *a, const rsvc_request *b)
{
	return a->gen == b->gen && a->w == b->w && a->h == b->h && a->set.mode == b->set.mode &&
	       a->set.depth == b->set.depth && a->set.seed == b->set.seed && a->denoise == b->denoise &&
	       (a->set.samples > 1) == (b->set.samples > 1);
}

/* A render that is not denoised records no features (denoise.h): the
 * buffers are shared by every kind of request. */
static void drop_features(framebuffer *fb)
{
	if (fb && fb->feat) {
		free(fb->feat);
		fb->feat = NULL;
	}
}

/* A frame at a ratio: one centred sample per pixel. */
static void run_frame(rsvc *sv, const rsvc_request *req, uint64_t seq, const world *w, rsvc_image *meta, double t0)
{
	int fw, fh;
	rsvc_frame_size(req->w, req->h, req->ratio, &fw, &fh);
	framebuffer *fb = fb_reuse(&sv->small, fw, fh);
	if (!fb) {
		snprintf(meta->error, sizeof meta->error, "out of memory for a %dx%d frame", fw, fh);
		publish(sv, NULL, 0, 0, meta);
		return;
	}
	drop_features(fb);
	rt_error err;
	render_job job = {
		.w = w,
		.set = req->set,
		.fb = fb,
		.sample_begin = 0,
		.sample_end = 1,
		.cancel = &sv->cancel,
		.progress = on_progress,
		.progress_ctx = sv,
	};
	job.set.samples = 1;
	sv->tiles_done = 0;
	sv->tiles_total = 1;
	render_status st = render_run(&job, &err);
	double dt = now() - t0;
	if (st == RENDER_DONE) {
		meta->spp = meta->target = 1;
		meta->done = true;
		meta->seconds = meta->pass_seconds = dt;
		meta->px_cost = dt / ((double)fw * fh);
		publish(sv, fb, fw, fh, meta);
	} else if (st == RENDER_CANCELLED) {
		pthread_mutex_lock(&sv->im);
		sv->cut_seq = seq;
		sv->cut_seconds = dt;
		sv->cut_frac = sv->tiles_total > 0 ? (double)sv->tiles_done / (double)sv->tiles_total : 0.0;
		sv->cut_new = true;
		pthread_mutex_unlock(&sv->im);
	}
}

/* A refine: an optional quick pass, then passes that accumulate; true
 * when every sample is in. */
static bool run_refine(rsvc *sv, const rsvc_request *req, const world *w, rsvc_image *meta, double t0)
{
	rt_error err;
	framebuffer *fb = sv->fb;
	/* an adaptive image (denoised: its pixels' own counts) is continued by
	 * no pass, only shown again at its own samples */
	bool cont = req->accumulate && sv->fb_valid && fb && fb->spp > 0 && fb->spp <= req->set.samples &&
	            (!fb->pixel_spp || fb->spp == req->set.samples) && continues(&sv->fb_req, req);
	if (!cont)
		fb = fb_reuse(&sv->fb, req->w, req->h);
	int qw = req->w / 2 > 0 ? req->w / 2 : 1, qh = req->h / 2 > 0 ? req->h / 2 : 1;
	framebuffer *q = req->quick && !cont ? fb_reuse(&sv->small, qw, qh) : NULL;
	if (!fb || (req->quick && !cont && !q)) {
		sv->fb_valid = false;
		snprintf(meta->error, sizeof meta->error, "out of memory for a %dx%d preview", req->w, req->h);
		publish(sv, NULL, 0, 0, meta);
		return true;
	}
	if (!req->denoise) {
		drop_features(fb);
		drop_features(q);
	}
	sv->fb_req = *req;
	sv->fb_req.world = NULL;
	sv->fb_valid = true;
	render_job job = {
		.w = w,
		.set = req->set,
		.cancel = &sv->cancel,
		.progress = on_progress,
		.progress_ctx = sv,
	};
	/* Each pass rewrites rgb from the sums, so the filter may work in
	 * place. */
	bool denoise = req->denoise && (!q || denoise_prepare(q)) && denoise_prepare(fb);
	int threads = render_threads(&req->set);
	if (q && req->w >= 8 && req->h >= 8) {
		job.fb = q;
		job.sample_begin = 0;
		job.sample_end = 1;
		double t1 = now();
		if (render_run(&job, &err) != RENDER_DONE)
			return false;
		meta->pass_seconds = now() - t1;
		meta->denoised = denoise && denoise_image(q, q->rgb, threads);
		meta->seconds = now() - t0;
		publish(sv, q, req->w, req->h, meta);
	}
	int target = req->set.samples, done = fb->spp, n = 1;
	if (done >= target) {
		/* Accumulated already (more samples were asked for, then fewer). */
		meta->spp = done;
		meta->done = true;
		meta->pass_seconds = meta->px_cost = 0;
		meta->seconds = now() - t0;
		publish(sv, fb, req->w, req->h, meta);
		return true;
	}
	/* Denoised: passes up to the adaptive image's first samples, then its
	 * adaptive pass as the last (render_adaptive: save's image) */
	int first = render_adaptive_first(target, denoise);
	if (done > first)
		first = target; /* (uniform samples beyond it: no adaptive pass) */
	while (done < target) {
		bool adapt = done == first;
		if (n > first - done)
			n = first - done;
		if (adapt)
			n = target - done;
		job.fb = fb;
		job.sample_begin = done;
		job.sample_end = adapt ? first : done + n;
		double t1 = now();
		if ((adapt ? render_adaptive(&job, &err) : render_run(&job, &err)) != RENDER_DONE)
			return false;
		job.pixel_end = NULL;
		double dt = now() - t1, per = dt / n;
		meta->denoised = denoise && denoise_image(fb, fb->rgb, threads);
		done += n;
		meta->spp = done;
		meta->done = done == target;
		meta->pass_seconds = dt;
		meta->px_cost = per / ((double)fb->w * fb->h);
		meta->seconds = now() - t0;
		publish(sv, fb, req->w, req->h, meta);
		n = per > 0 ? (int)(req->pass_seconds / per) : 64;
		if (n < 1)
			n = 1;
	}
	return true;
}

/* Renders one request; true when it is complete. */
static bool run(rsvc *sv, const rsvc_request *req, uint64_t seq)
{
	double t0 = now();
	rsvc_image meta;
	memset(&meta, 0, sizeof meta);
	meta.seq = seq;
	meta.kind = req->kind;
	meta.target = req->set.samples;
	meta.gen = req->gen;
	rt_error err;
	rt_error_clear(&err);
	const world *w = req->world ? world_retain(req->world)
	                            : rsvc_world(sv, req->s, req->gen, render_threads(&req->set), &sv->cancel, &err);
	if (!w && atomic_load(&sv->cancel))
		return false; /* a hold stopped the build: as a stopped render, nothing to show */
	if (!w) {
		snprintf(meta.error, sizeof meta.error, "%s", err.msg);
		publish(sv, NULL, 0, 0, &meta);
		return true;
	}
	bool complete = false;
	if (!atomic_load(&sv->cancel)) {
		if (req->kind == RSVC_FRAME) {
			run_frame(sv, req, seq, w, &meta, t0);
			complete = true;
		} else {
			complete = run_refine(sv, req, w, &meta, t0);
		}
	}
	world_release(w);
	return complete;
}

static void *thread_main(void *arg)
{
	rsvc *sv = arg;
	pthread_mutex_lock(&sv->m);
	for (;;) {
		while (!sv->quit && (sv->held || !sv->pending))
			pthread_cond_wait(&sv->work, &sv->m);
		if (sv->quit)
			break;
		rsvc_request req = sv->req; /* its world reference moves here */
		uint64_t seq = sv->req_seq;
		sv->pending = false;
		sv->busy = true;
		pthread_mutex_unlock(&sv->m);
		bool complete = run(sv, &req, seq);
		world_release(req.world);
		pthread_mutex_lock(&sv->m);
		sv->last = req;
		sv->last.world = NULL;
		sv->last_seq = seq;
		sv->last_complete = complete;
		sv->busy = false;
		pthread_cond_broadcast(&sv->idle);
	}
	pthread_mutex_unlock(&sv->m);
	return NULL;
}

/* Drops the request waiting (with sv->m held). */
static void drop_pending(rsvc *sv)
{
	if (sv->pending) {
		world_release(sv->req.world);
		sv->req.world = NULL;
		sv->pending = false;
	}
}

void rsvc_hold(rsvc *sv)
{
	pthread_mutex_lock(&sv->m);
	sv->held = true;
	if (sv->pending) {
		drop_pending(sv);
		sv->last_complete = false;
	}
	atomic_store(&sv->cancel, true);
	while (sv->busy)
		pthread_cond_wait(&sv->idle, &sv->m);
	atomic_store(&sv->cancel, false);
	pthread_mutex_unlock(&sv->m);
}

const world *rsvc_world(rsvc *sv, const scene *s, uint64_t gen, int threads, const atomic_bool *cancel,
                        rt_error *err)
{
	pthread_mutex_lock(&sv->wm);
	if (!sv->w || sv->wgen != gen) {
		world_release(sv->w);
		sv->w = world_build_threads(s, threads, cancel, err); /* stopped: NULL, built again next time */
		sv->wgen = gen;
	}
	const world *w = world_retain(sv->w);
	pthread_mutex_unlock(&sv->wm);
	if (!w && err && !err->msg[0])
		rt_error_set(err, "the scene cannot be prepared");
	return w;
}

static bool same_request(const rsvc_request *a, const rsvc_request *b)
{
	return a->gen == b->gen && a->kind == b->kind && a->ratio == b->ratio && a->w == b->w && a->h == b->h &&
	       a->quick == b->quick && a->accumulate == b->accumulate && a->denoise == b->denoise &&
	       a->pass_seconds == b->pass_seconds && a->set.samples == b->set.samples &&
	       a->set.depth == b->set.depth && a->set.mode == b->set.mode && a->set.seed == b->set.seed &&
	       a->set.threads == b->set.threads && a->set.denoise == b->set.denoise;
}

uint64_t rsvc_start(rsvc *sv, const rsvc_request *req)
{
	pthread_mutex_lock(&sv->m);
	sv->held = false;
	uint64_t seq;
	if (sv->last_complete && !sv->pending && !sv->busy && same_request(req, &sv->last)) {
		seq = sv->last_seq;
	} else {
		drop_pending(sv);
		sv->req = *req;
		world_retain(req->world);
		sv->req_seq = seq = ++sv->seq;
		sv->pending = true;
		sv->last_complete = false;
		if (!sv->started) {
			if (pthread_create(&sv->thread, NULL, thread_main, sv) == 0) {
				sv->started = true;
			} else {
				drop_pending(sv);
				seq = 0;
			}
		}
		pthread_cond_signal(&sv->work);
		/* An image of an older request not taken yet is stale now. */
		pthread_mutex_lock(&sv->im);
		sv->taken = sv->serial;
		pthread_mutex_unlock(&sv->im);
	}
	pthread_mutex_unlock(&sv->m);
	return seq;
}

void rsvc_release(rsvc *sv)
{
	pthread_mutex_lock(&sv->m);
	sv->held = false;
	pthread_cond_signal(&sv->work);
	pthread_mutex_unlock(&sv->m);
}

bool rsvc_busy(rsvc *sv)
{
	pthread_mutex_lock(&sv->m);
	bool b = sv->busy || sv->pending;
	pthread_mutex_unlock(&sv->m);
	return b;
}

bool rsvc_stop(rsvc *sv)
{
	pthread_mutex_lock(&sv->m);
	bool was = sv->busy || sv->pending;
	if (sv->pending) {
		sv->last = sv->req;
		sv->last.world = NULL;
		sv->last_seq = sv->req_seq;
	}
	drop_pending(sv);
	atomic_store(&sv->cancel, true);
	while (sv->busy)
		pthread_cond_wait(&sv->idle, &sv->m);
	atomic_store(&sv->cancel, false);
	/* Stopped counts as complete: the same request does not start again. */
	if (was)
		sv->last_complete = true;
	pthread_mutex_unlock(&sv->m);
	if (was) {
		pthread_mutex_lock(&sv->im);
		sv->img.stopped = true;
		sv->serial++;
		pthread_mutex_unlock(&sv->im);
		wake(sv);
	}
	return was;
}

bool rsvc_take(rsvc *sv, rsvc_image *img)
{
	pthread_mutex_lock(&sv->im);
	bool fresh = sv->serial != sv->taken && copy_image(img, &sv->img);
	if (fresh)
		sv->taken = sv->serial;
	pthread_mutex_unlock(&sv->im);
	return fresh;
}

bool rsvc_cut(rsvc *sv, uint64_t *seq, double *seconds, double *frac)
{
	pthread_mutex_lock(&sv->im);
	bool fresh = sv->cut_new;
	*seq = sv->cut_seq;
	*seconds = sv->cut_seconds;
	*frac = sv->cut_frac;
	sv->cut_new = false;
	pthread_mutex_unlock(&sv->im);
	return fresh;
}
