/* rtsh — the background preview renderer (preview.h). */
#include "shell/preview.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "rtsh/denoise.h"

/* Aim for passes of about this long, so the picture refreshes steadily. */
#define PASS_SECONDS 0.1

struct preview {
	int wake_fd;
	pthread_t thread;
	bool started;

	pthread_mutex_t m; /* guards the fields below up to `cancel` */
	pthread_cond_t work, idle;
	bool quit, held, pending, busy;
	preview_request req;  /* waiting to start */
	preview_request last; /* the last one run */
	bool last_complete;
	atomic_bool cancel;

	/* The world: the thread's while busy, the holder's while held. */
	world *w;
	uint64_t wgen;

	/* The published image. */
	pthread_mutex_t im;
	preview_image img;
	uint64_t serial, taken;

	/* The thread's own framebuffers. */
	framebuffer *fb, *qfb;
};

static double now(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)t.tv_sec + t.tv_nsec * 1e-9;
}

preview *preview_new(int wake_fd)
{
	preview *pv = calloc(1, sizeof *pv);
	if (!pv)
		return NULL;
	pv->wake_fd = wake_fd;
	pthread_mutex_init(&pv->m, NULL);
	pthread_mutex_init(&pv->im, NULL);
	pthread_cond_init(&pv->work, NULL);
	pthread_cond_init(&pv->idle, NULL);
	atomic_init(&pv->cancel, false);
	return pv;
}

void preview_image_free(preview_image *img)
{
	free(img->rgb);
	img->rgb = NULL;
	img->cap = 0;
}

void preview_free(preview *pv)
{
	if (!pv)
		return;
	if (pv->started) {
		pthread_mutex_lock(&pv->m);
		pv->quit = true;
		atomic_store(&pv->cancel, true);
		pthread_cond_signal(&pv->work);
		pthread_mutex_unlock(&pv->m);
		pthread_join(pv->thread, NULL);
	}
	world_free(pv->w);
	fb_free(pv->fb);
	fb_free(pv->qfb);
	preview_image_free(&pv->img);
	pthread_mutex_destroy(&pv->m);
	pthread_mutex_destroy(&pv->im);
	pthread_cond_destroy(&pv->work);
	pthread_cond_destroy(&pv->idle);
	free(pv);
}

static void wake(preview *pv)
{
	if (pv->wake_fd >= 0) {
		ssize_t r = write(pv->wake_fd, "p", 1);
		(void)r; /* a full pipe already holds a wake-up */
	}
}

/* Copies an image into dst, growing its buffer; false when out of memory. */
static bool copy_image(preview_image *dst, const preview_image *src)
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

/* Publishes fb (or the quick pass scaled up to w x h when fb is the quarter
 * buffer) as the newest image. */
static void publish(preview *pv, const framebuffer *fb, int w, int h, const preview_image *meta)
{
	pthread_mutex_lock(&pv->im);
	preview_image *img = &pv->img;
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
			/* Nearest-neighbour scale-up of the quick pass. */
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
		pv->serial++;
	}
	pthread_mutex_unlock(&pv->im);
	if (ok)
		wake(pv);
}

/* A framebuffer of w x h with no samples, reusing *fb when it fits. */
/* Renders one request; true when every sample is in. */
static bool run(preview *pv, const preview_request *req)
{
	double t0 = now();
	preview_image meta;
	memset(&meta, 0, sizeof meta);
	meta.target = req->set.samples;
	meta.gen = req->gen;
	rt_error err;
	if (!pv->w || pv->wgen != req->gen) {
		world_free(pv->w);
		pv->w = world_build(req->s, &err);
		pv->wgen = req->gen;
		if (!pv->w) {
			snprintf(meta.error, sizeof meta.error, "%s", err.msg);
			publish(pv, NULL, 0, 0, &meta);
			return true;
		}
	}
	if (atomic_load(&pv->cancel))
		return false;

	/* The quick pass: half the width and height, one sample. */
	int qw = req->w / 2 > 0 ? req->w / 2 : 1, qh = req->h / 2 > 0 ? req->h / 2 : 1;
	framebuffer *q = fb_reuse(&pv->qfb, qw, qh);
	framebuffer *fb = fb_reuse(&pv->fb, req->w, req->h);
	if (!q || !fb) {
		snprintf(meta.error, sizeof meta.error, "out of memory for a %dx%d preview", req->w, req->h);
		publish(pv, NULL, 0, 0, &meta);
		return true;
	}
	render_job job = {
		.w = pv->w,
		.set = req->set,
		.fb = q,
		.sample_begin = 0,
		.sample_end = 1,
		.cancel = &pv->cancel,
	};
	/* Path previews are denoised unless `set denoise off`; each pass
	 * rewrites rgb from the sums, so the filter may work in place. */
	bool denoise = req->set.mode == MODE_PATH && req->set.denoise != DENOISE_OFF &&
	               denoise_prepare(q) && denoise_prepare(fb);
	int threads = render_threads(&req->set);
	if (req->w >= 8 && req->h >= 8) {
		if (render_run(&job, &err) != RENDER_DONE)
			return false;
		meta.denoised = denoise && denoise_image(q, q->rgb, threads);
		meta.seconds = now() - t0;
		publish(pv, q, req->w, req->h, &meta);
	}

	/* The full preview, in passes that accumulate. */
	int done = 0, n = 1;
	while (done < req->set.samples) {
		if (n > req->set.samples - done)
			n = req->set.samples - done;
		job.fb = fb;
		job.sample_begin = done;
		job.sample_end = done + n;
		double t1 = now();
		if (render_run(&job, &err) != RENDER_DONE)
			return false;
		double per = (now() - t1) / n;
		meta.denoised = denoise && denoise_image(fb, fb->rgb, threads);
		done += n;
		meta.spp = done;
		meta.done = done == req->set.samples;
		meta.seconds = now() - t0;
		publish(pv, fb, req->w, req->h, &meta);
		n = per > 0 ? (int)(PASS_SECONDS / per) : 64;
		if (n < 1)
			n = 1;
	}
	return true;
}

static void *thread_main(void *arg)
{
	preview *pv = arg;
	pthread_mutex_lock(&pv->m);
	for (;;) {
		while (!pv->quit && (pv->held || !pv->pending))
			pthread_cond_wait(&pv->work, &pv->m);
		if (pv->quit)
			break;
		preview_request req = pv->req;
		pv->pending = false;
		pv->busy = true;
		pthread_mutex_unlock(&pv->m);
		bool complete = run(pv, &req);
		pthread_mutex_lock(&pv->m);
		pv->last = req;
		pv->last_complete = complete;
		pv->busy = false;
		pthread_cond_broadcast(&pv->idle);
	}
	pthread_mutex_unlock(&pv->m);
	return NULL;
}

void preview_hold(preview *pv)
{
	pthread_mutex_lock(&pv->m);
	pv->held = true;
	if (pv->pending) {
		pv->pending = false;
		pv->last_complete = false;
	}
	atomic_store(&pv->cancel, true);
	while (pv->busy)
		pthread_cond_wait(&pv->idle, &pv->m);
	atomic_store(&pv->cancel, false);
	pthread_mutex_unlock(&pv->m);
}

const world *preview_world(preview *pv, const scene *s, uint64_t gen, rt_error *err)
{
	if (!pv->w || pv->wgen != gen) {
		world_free(pv->w);
		pv->w = world_build(s, err);
		pv->wgen = gen;
	}
	if (!pv->w && err && !err->msg[0])
		rt_error_set(err, "the scene cannot be prepared");
	return pv->w;
}

static bool same_request(const preview_request *a, const preview_request *b)
{
	return a->gen == b->gen && a->w == b->w && a->h == b->h && a->set.samples == b->set.samples &&
	       a->set.depth == b->set.depth && a->set.mode == b->set.mode && a->set.seed == b->set.seed &&
	       a->set.threads == b->set.threads && a->set.denoise == b->set.denoise;
}

void preview_start(preview *pv, const preview_request *req)
{
	pthread_mutex_lock(&pv->m);
	pv->held = false;
	if (!(pv->last_complete && same_request(req, &pv->last))) {
		pv->req = *req;
		pv->pending = true;
		pv->last_complete = false;
		if (!pv->started) {
			if (pthread_create(&pv->thread, NULL, thread_main, pv) == 0)
				pv->started = true;
			else
				pv->pending = false;
		}
		pthread_cond_signal(&pv->work);
	}
	pthread_mutex_unlock(&pv->m);
}

void preview_release(preview *pv)
{
	pthread_mutex_lock(&pv->m);
	pv->held = false;
	pthread_cond_signal(&pv->work);
	pthread_mutex_unlock(&pv->m);
}

bool preview_busy(preview *pv)
{
	pthread_mutex_lock(&pv->m);
	bool b = pv->busy || pv->pending;
	pthread_mutex_unlock(&pv->m);
	return b;
}

bool preview_stop(preview *pv)
{
	pthread_mutex_lock(&pv->m);
	bool was = pv->busy || pv->pending;
	if (pv->pending)
		pv->last = pv->req;
	pv->pending = false;
	atomic_store(&pv->cancel, true);
	while (pv->busy)
		pthread_cond_wait(&pv->idle, &pv->m);
	atomic_store(&pv->cancel, false);
	/* Stopped counts as complete: the same request does not start again. */
	if (was)
		pv->last_complete = true;
	pthread_mutex_unlock(&pv->m);
	if (was) {
		pthread_mutex_lock(&pv->im);
		pv->img.stopped = true;
		pv->serial++;
		pthread_mutex_unlock(&pv->im);
		wake(pv);
	}
	return was;
}

bool preview_take(preview *pv, preview_image *img)
{
	pthread_mutex_lock(&pv->im);
	bool fresh = pv->serial != pv->taken && copy_image(img, &pv->img);
	if (fresh)
		pv->taken = pv->serial;
	pthread_mutex_unlock(&pv->im);
	return fresh;
}
