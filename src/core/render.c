/* rtsh — render jobs: tiles pulled from an atomic counter by a pool of
 * pthreads; each pixel's samples are summed in sample order (render.h). */
#include "rtsh/render.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "integrators.h"
#include "rtsh/denoise.h"
#include "rtsh/memory.h"
#include "rtsh/mesh.h"
#include "rtsh/packet.h"
#include "rtsh/srgb.h"
#include "rtsh/texture.h"

int render_threads(const render_settings *s)
{
	if (s->threads > 0)
		return s->threads;
	long n = sysconf(_SC_NPROCESSORS_ONLN);
	return n < 1 ? 1 : n > 256 ? 256 : (int)n;
}

/* A w x h framebuffer with its float image (rgb) and its running sums
 * (sum) when asked; NULL when a side is out of range or out of memory. */
static framebuffer *fb_alloc(int w, int h, bool rgb, bool sum)
{
	if (w < 1 || h < 1 || w > RENDER_MAX_DIM || h > RENDER_MAX_DIM)
		return NULL;
	framebuffer *fb = calloc(1, sizeof *fb);
	if (!fb)
		return NULL;
	size_t n = (size_t)w * (size_t)h * 3;
	fb->w = w;
	fb->h = h;
	if ((rgb && !(fb->rgb = calloc(n, sizeof *fb->rgb))) || (sum && !(fb->sum = calloc(n, sizeof *fb->sum)))) {
		fb_free(fb);
		return NULL;
	}
	return fb;
}

framebuffer *fb_new(int w, int h)
{
	return fb_alloc(w, h, true, true);
}

void fb_free(framebuffer *fb)
{
	if (fb)
		mem_free_all(fb->rgb, fb->sum, fb->sum2, fb->feat, fb->srgb8, fb->pixel_spp, fb);
}

void fb_clear(framebuffer *fb)
{
	size_t n = (size_t)fb->w * (size_t)fb->h * 3;
	memset(fb->rgb, 0, n * sizeof *fb->rgb);
	if (fb->sum)
		memset(fb->sum, 0, n * sizeof *fb->sum);
	if (fb->feat)
		memset(fb->feat, 0, n / 3 * DENOISE_FEATURES * sizeof *fb->feat);
	if (fb->sum2)
		memset(fb->sum2, 0, n / 3 * sizeof *fb->sum2);
	free(fb->pixel_spp);
	fb->pixel_spp = NULL;
	fb->spp = 0;
}

framebuffer *fb_reuse(framebuffer **fb, int w, int h)
{
	if (*fb && ((*fb)->w != w || (*fb)->h != h || !(*fb)->sum)) {
		fb_free(*fb);
		*fb = NULL;
	}
	if (!*fb)
		*fb = fb_new(w, h);
	if (*fb)
		fb_clear(*fb);
	return *fb;
}

vec3 render_sample(const world *w, const render_settings *s, int px, int py, int fw, int fh, int sample)
{
	sampler sp;
	const integrator *in = integrator_of(s->mode);
	mesh_alpha_hashed(in->sampled); /* glTF BLEND: see-through by alpha when sampled (until the end) */
	ray r = camera_sample_ray(w, s, in->sampled, px, py, fw, fh, sample, &sp);
	vec3 c = in->radiance(w, s, r, &sp);
	mesh_alpha_hashed(false);
	/* A NaN or infinity from a degenerate case must not poison the pixel. */
	if (!v3_finite(c))
		c = v3(0, 0, 0);
	return c;
}

/* The counters every thread writes have a cache line each, apart from the
 * fields every tile reads, so that taking a tile does not evict the job
 * from the other threads' caches (false sharing). */
typedef struct shared {
	render_job *job;
	int tiles_x;
	long tiles;
	_Alignas(64) atomic_long next;
	_Alignas(64) atomic_long done;
	_Alignas(64) atomic_int running;
	pthread_mutex_t lock;
	pthread_cond_t finished; /* also signalled when a band of tiles is finished (job->rows) */
	pthread_cond_t slot_free; /* a band handed over: its slot of the ring is free */
	/* job->rows: the tiles left in each band (row of tiles), the first
	 * band not yet handed over, and whether a handover failed */
	atomic_int *band_left;
	int bands;
	atomic_int band_next;
	atomic_bool stop;
} shared;

/* Ctrl-C within a tile: the cancel flag of the render this thread's
 * tiles belong to (NULL: none), polled by block_add every 16 samples and by
 * render_tile before each block, and whether it stopped a block short. A tile of many samples (set samples
 * 100000: seconds of work) then stops within a fraction of a second; a
 * tile stopped short is not counted done, so the pass is cancelled. */
static _Thread_local const atomic_bool *tile_cancel;
static _Thread_local bool tile_stopped;

/* Adds samples [s0, s1) of the pixels of block [x0, x1) x [y0, y1) (at
 * most PACKET_MAX of them, row by row) of an fw x fh image to acc[i], each
 * pixel's in sample order: render_tile and render_rect share it, so a tile
 * rendered anywhere holds the same bits as the whole image. The block's
 * camera rays of one sample are traced together as a packet (packet.h),
 * which finds the same hits as single rays to the bit. feat[i]: pixel i's
 * features for the denoiser (denoise.h), updated with these samples; NULL:
 * none. sq[i] (with feat[i]; may be NULL): the running sum of the pixel's
 * squared brightness, continued as acc is (framebuffer.sum2). */
static void block_add(const world *w, const render_settings *s, int x0, int y0, int x1, int y1, int fw, int fh,
                      int s0, int s1, double (*acc)[3], float *const *feat, double *const *sq)
{
	double fa[PACKET_MAX][DENOISE_ACC], ra[PACKET_MAX][DENOISE_RACC];
	int n = (x1 - x0) * (y1 - y0);
	const integrator *in = integrator_of(s->mode);
	bool any_feat = false;
	for (int i = 0; i < n; i++)
		any_feat |= feat[i] != NULL;
	mesh_alpha_hashed(in->sampled); /* glTF BLEND: see-through by alpha when sampled */
	if (any_feat) {
		memset(fa, 0, sizeof fa);
		memset(ra, 0, sizeof ra);
		for (int i = 0; i < n; i++)
			if (feat[i] && sq[i] && s0 > 0) /* the squared brightness summed on, as acc */
				ra[i][0] = *sq[i];
	}
	for (int k = s0; k < s1; k++) {
		if (((k - s0) & 15) == 15 && tile_cancel && atomic_load_explicit(tile_cancel, memory_order_relaxed)) {
			tile_stopped = true;
			break;
		}
		ray r[PACKET_MAX];
		sampler sp[PACKET_MAX];
		hit h[PACKET_MAX];
		bool found[PACKET_MAX];
		camera_block_rays(w, s, in->sampled, x0, y0, x1, y1, fw, fh, k, r, sp);
		world_intersect_packet(w, n, r, 0.0, INFINITY, h, found);
		uint32_t known[PACKET_MAX], blocked[PACKET_MAX];
		if (in->shadow_packets)
			in->shadow_packets(w, n, h, found, known, blocked);
		else
			for (int i = 0; i < n; i++)
				known[i] = blocked[i] = 0;
		for (int y = y0, i = 0; y < y1; y++)
			for (int x = x0; x < x1; x++, i++) {
				vec3 c = in->radiance_first(w, s, r[i], &sp[i], found[i], &h[i], known[i], blocked[i]);
				/* A NaN or infinity from a degenerate case must not poison the pixel. */
				if (!v3_finite(c))
					c = v3(0, 0, 0);
				acc[i][0] += c.x;
				acc[i][1] += c.y;
				acc[i][2] += c.z;
				if (any_feat && feat[i]) {
					denoise_radiance(c, k, ra[i]);
					if (k < DENOISE_FEATURE_SAMPLES) /* what this sample's ray first sees */
						denoise_sample(w, render_sample_ray(w, s, x, y, fw, fh, k), k, fa[i]);
				}
			}
	}
	if (any_feat)
		for (int y = y0, i = 0; y < y1; y++)
			for (int x = x0; x < x1; x++, i++)
				if (feat[i]) {
					denoise_features(w, s, x, y, fw, fh, s0, s1, ra[i], fa[i], feat[i]);
					/* ra[i][0] holds all the samples' sum: feature 7
					 * its mean (for a first pass the value
					 * denoise_features made of it) */
					if (sq[i]) {
						*sq[i] = ra[i][0];
						feat[i][7] = (float)(ra[i][0] / s1);
					}
				}
	mesh_alpha_hashed(false);
}

/* The blocks of PACKET_MAX pixels, 4 x 4, that render_tile and render_rect
 * walk their rectangles in. */
#define BLOCK_SIDE 4

/* Row y's 8-bit codes: the image's row, or its row in its band's slot of
 * the ring (framebuffer.srgb8_ring). */
static uint8_t *codes_row(const framebuffer *fb, int y)
{
	size_t r = (size_t)y;
	if (fb->srgb8_ring)
		r = (size_t)(y / RENDER_TILE % fb->srgb8_ring) * RENDER_TILE + (size_t)(y % RENDER_TILE);
	return fb->srgb8 + r * (size_t)fb->w * 3;
}

/* The 8-bit codes of a finished tile (framebuffer.srgb8), by the expression
 * of image.c's encoder: the same codes it would make. */
static void tile_srgb8(framebuffer *fb, int x0, int y0, int x1, int y1)
{
	for (int y = y0; y < y1; y++)
		linear_to_srgb8_n(fb->rgb + ((size_t)y * (size_t)fb->w + (size_t)x0) * 3, fb->srgb8_gain,
		                  codes_row(fb, y) + (size_t)x0 * 3, (size_t)(x1 - x0) * 3);
}

/* An adaptive pass over the pixels x0 <= x < x1, y0 <= y < y1 of an fw x fh
 * image (render_rect_adaptive), its arrays from the rectangle's first pixel,
 * stride pixels a row: each pixel alone, its samples [begin, its own end)
 * continuing its sums, and its features made up to DENOISE_FEATURE_SAMPLES
 * positions when it has fewer radiance samples than that. */
static void rect_adaptive(const world *w, const render_settings *s, int x0, int y0, int x1, int y1, int fw, int fh,
                          size_t stride, int begin, const uint16_t *end, double *sum, float *rgb, float *feat)
{
	bool features = feat && integrator_of(s->mode)->features;
	for (int y = y0; y < y1; y++)
		for (int x = x0; x < x1; x++) {
			size_t p = (size_t)(y - y0) * stride + (size_t)(x - x0), i = p * 3;
			int e = end[p];
			double acc[1][3] = {{sum[i], sum[i + 1], sum[i + 2]}};
			float *fp[1] = {features ? feat + p * DENOISE_FEATURES : NULL};
			/* feature 7 as a running mean here: the allocation read it
			 * before, from the sums (framebuffer.sum2), and an adaptive
			 * image takes no further pass */
			double *sq[1] = {NULL};
			if (e > begin)
				block_add(w, s, x, y, x + 1, y + 1, fw, fh, begin, e, acc, fp, sq);
			int from = e > begin ? e : begin;
			if (fp[0] && from < DENOISE_FEATURE_SAMPLES)
				denoise_features_only(w, s, x, y, fw, fh, from, DENOISE_FEATURE_SAMPLES, fp[0]);
			double inv = 1.0 / from;
			for (int c = 0; c < 3; c++) {
				sum[i + c] = acc[0][c];
				rgb[i + c] = (float)(acc[0][c] * inv);
			}
		}
}

/* An adaptive pass (job->pixel_end): the tile's pixels in the image's
 * arrays. */
static void render_tile_adaptive(render_job *job, int x0, int y0, int x1, int y1)
{
	framebuffer *fb = job->fb;
	size_t p = (size_t)y0 * (size_t)fb->w + (size_t)x0;
	rect_adaptive(job->w, &job->set, x0, y0, x1, y1, fb->w, fb->h, (size_t)fb->w, job->sample_begin,
	              job->pixel_end + p, fb->sum + p * 3, fb->rgb + p * 3,
	              fb->feat ? fb->feat + p * DENOISE_FEATURES : NULL);
}

/* False when the render's cancel flag stopped the tile short. */
static bool render_tile(shared *sh, long t)
{
	render_job *job = sh->job;
	framebuffer *fb = job->fb;
	/* no float image (render_image_rows): the tile's floats, for its codes */
	float own[RENDER_TILE * RENDER_TILE * 3];
	int x0 = (int)(t % sh->tiles_x) * RENDER_TILE, y0 = (int)(t / sh->tiles_x) * RENDER_TILE;
	int x1 = x0 + RENDER_TILE < fb->w ? x0 + RENDER_TILE : fb->w;
	int y1 = y0 + RENDER_TILE < fb->h ? y0 + RENDER_TILE : fb->h;
	double inv = 1.0 / job->sample_end;
	texture_set_pixel_angle(2.0 * cam_tan_x(&job->w->cam, fb->w, fb->h) / fb->w); /* texture footprints */
	tile_stopped = false;
	if (job->pixel_end) {
		render_tile_adaptive(job, x0, y0, x1, y1);
		return !tile_stopped;
	}
	bool feat = fb->feat && integrator_of(job->set.mode)->features;
	for (int by = y0; by < y1; by += BLOCK_SIDE)
		for (int bx = x0; bx < x1; bx += BLOCK_SIDE) {
			int ex = bx + BLOCK_SIDE < x1 ? bx + BLOCK_SIDE : x1, ey = by + BLOCK_SIDE < y1 ? by + BLOCK_SIDE : y1;
			/* and before each block: a pass of fewer than 16 samples (a
			 * preview's 1) is stopped here, where every ray of a block may
			 * meet thousands of overlapping triangles */
			if (tile_cancel && atomic_load_explicit(tile_cancel, memory_order_relaxed)) {
				tile_stopped = true;
				return false;
			}
			double acc[PACKET_MAX][3];
			float *fp[PACKET_MAX];
			double *sq[PACKET_MAX];
			for (int y = by, k = 0; y < ey; y++)
				for (int x = bx; x < ex; x++, k++) {
					size_t i = ((size_t)y * (size_t)fb->w + (size_t)x) * 3;
					sq[k] = fb->sum2 ? fb->sum2 + i / 3 : NULL;
					/* A first pass starts from zero whatever the sums hold (a
					 * cancelled pass leaves them half done). */
					acc[k][0] = acc[k][1] = acc[k][2] = 0.0;
					if (job->sample_begin > 0) {
						acc[k][0] = fb->sum[i];
						acc[k][1] = fb->sum[i + 1];
						acc[k][2] = fb->sum[i + 2];
					}
					fp[k] = feat ? fb->feat + i / 3 * DENOISE_FEATURES : NULL;
				}
			block_add(job->w, &job->set, bx, by, ex, ey, fb->w, fb->h, job->sample_begin, job->sample_end, acc, fp,
			          sq);
			if (tile_stopped)
				return false;
			double *sum = fb->sum;
			float *rgb = fb->rgb;
			for (int y = by, k = 0; y < ey; y++) {
				/* the row's floats: the image's, or the tile's own */
				float *o = rgb ? rgb + ((size_t)y * (size_t)fb->w + (size_t)bx) * 3
				               : own + ((size_t)(y - y0) * RENDER_TILE + (size_t)(bx - x0)) * 3;
				for (int x = bx; x < ex; x++, k++, o += 3) {
					if (sum) {
						size_t i = ((size_t)y * (size_t)fb->w + (size_t)x) * 3;
						sum[i] = acc[k][0];
						sum[i + 1] = acc[k][1];
						sum[i + 2] = acc[k][2];
					}
					o[0] = (float)(acc[k][0] * inv);
					o[1] = (float)(acc[k][1] * inv);
					o[2] = (float)(acc[k][2] * inv);
				}
			}
		}
	if (fb->rgb && fb->srgb8)
		tile_srgb8(fb, x0, y0, x1, y1);
	else if (fb->srgb8)
		for (int y = y0; y < y1; y++) /* the same expression on the same floats */
			linear_to_srgb8_n(own + (size_t)(y - y0) * RENDER_TILE * 3, fb->srgb8_gain,
			                  codes_row(fb, y) + (size_t)x0 * 3, (size_t)(x1 - x0) * 3);
	return true;
}

/* A tile is finished: the last of its band wakes the thread that hands the
 * bands to job->rows. */
static void tile_finished(shared *sh, long t)
{
	if (sh->band_left && atomic_fetch_sub(&sh->band_left[t / sh->tiles_x], 1) == 1) {
		pthread_mutex_lock(&sh->lock);
		pthread_cond_signal(&sh->finished);
		pthread_mutex_unlock(&sh->lock);
	}
}

/* Wakes the workers waiting for a slot of the ring (slot_ready). */
static void slots_freed(shared *sh)
{
	if (!sh->job->fb->srgb8_ring)
		return;
	pthread_mutex_lock(&sh->lock);
	pthread_cond_broadcast(&sh->slot_free);
	pthread_mutex_unlock(&sh->lock);
}

/* Hands the finished bands at the top to job->rows: in one call, or with a
 * ring a call a band (a slot's rows are contiguous, not two slots'), each
 * slot free again after its call; false when it failed (the workers are
 * then told to stop). */
static bool hand_rows(shared *sh)
{
	if (atomic_load(&sh->stop)) /* a handover failed: never a band again */
		return false;
	int b = atomic_load(&sh->band_next), e = b;
	while (e < sh->bands && atomic_load(&sh->band_left[e]) == 0)
		e++;
	const framebuffer *fb = sh->job->fb;
	for (int step = fb->srgb8_ring ? 1 : e - b; b < e; b += step) {
		int y0 = b * RENDER_TILE, y1 = (b + step) * RENDER_TILE < fb->h ? (b + step) * RENDER_TILE : fb->h;
		if (!sh->job->rows(sh->job->rows_ctx, fb, y0, y1, codes_row(fb, y0))) {
			atomic_store(&sh->stop, true);
			slots_freed(sh); /* the waiting workers see the stop */
			return false;
		}
		atomic_store(&sh->band_next, b + step);
		slots_freed(sh);
	}
	return true;
}

static bool band_ready(shared *sh)
{
	int b = atomic_load(&sh->band_next);
	return sh->band_left && b < sh->bands && atomic_load(&sh->band_left[b]) == 0;
}

static bool stopped(const shared *sh)
{
	return (sh->job->cancel && atomic_load(sh->job->cancel)) || atomic_load(&sh->stop);
}

/* The time ms milliseconds from now, for pthread_cond_timedwait. */
static void in_ms(struct timespec *ts, long ms)
{
	clock_gettime(CLOCK_REALTIME, ts);
	ts->tv_nsec += ms * 1000 * 1000;
	while (ts->tv_nsec >= 1000000000L) {
		ts->tv_sec++;
		ts->tv_nsec -= 1000000000L;
	}
}

/* Whether tile t may write its codes: with a ring, once the band that had
 * its band's slot before it is handed over. Waits until then or until the
 * render stops (false; a cancel is seen within 20 ms). The thread that
 * hands the rows over (hands) hands what is finished meanwhile: no other
 * thread does, and every earlier band's tiles have started, so the wait
 * ends. */
static bool slot_ready(shared *sh, long t, bool hands)
{
	int b = (int)(t / sh->tiles_x), ring = sh->job->fb->srgb8_ring;
	if (!ring || b - ring < atomic_load(&sh->band_next))
		return true;
	bool ok = true;
	pthread_mutex_lock(&sh->lock);
	while (b - ring >= atomic_load(&sh->band_next)) {
		if (stopped(sh)) {
			ok = false;
			break;
		}
		if (hands && band_ready(sh)) {
			pthread_mutex_unlock(&sh->lock);
			bool handed = hand_rows(sh);
			pthread_mutex_lock(&sh->lock);
			if (!handed) {
				ok = false;
				break;
			}
			continue;
		}
		struct timespec deadline;
		in_ms(&deadline, 20);
		pthread_cond_timedwait(hands ? &sh->finished : &sh->slot_free, &sh->lock, &deadline);
	}
	pthread_mutex_unlock(&sh->lock);
	return ok;
}

void render_rect(const world *w, const render_settings *s, int x0, int y0, int x1, int y1,
                 float *out)
{
	render_rect_features(w, s, x0, y0, x1, y1, out, NULL);
}

/* Samples [0, samples) of the rectangle (render_rect_features,
 * render_rect_first): the mean into out, the sums into sum, when not NULL. */
static void rect_first(const world *w, const render_settings *s, int x0, int y0, int x1, int y1, int samples,
                       float *out, double *sum, float *feat)
{
	double inv = 1.0 / samples;
	texture_set_pixel_angle(2.0 * cam_tan_x(&w->cam, s->width, s->height) / s->width); /* as render_tile */
	size_t row = (size_t)(x1 - x0);
	for (int by = y0; by < y1; by += BLOCK_SIDE)
		for (int bx = x0; bx < x1; bx += BLOCK_SIDE) {
			int ex = bx + BLOCK_SIDE < x1 ? bx + BLOCK_SIDE : x1, ey = by + BLOCK_SIDE < y1 ? by + BLOCK_SIDE : y1;
			double acc[PACKET_MAX][3] = {{0}};
			float *fp[PACKET_MAX];
			double *const sq[PACKET_MAX] = {NULL};
			for (int y = by, k = 0; y < ey; y++)
				for (int x = bx; x < ex; x++, k++) {
					size_t i = (size_t)(y - y0) * row + (size_t)(x - x0);
					fp[k] = NULL;
					if (feat) {
						memset(feat + i * DENOISE_FEATURES, 0, DENOISE_FEATURES * sizeof *feat);
						if (integrator_of(s->mode)->features)
							fp[k] = feat + i * DENOISE_FEATURES;
					}
				}
			block_add(w, s, bx, by, ex, ey, s->width, s->height, 0, samples, acc, fp, sq);
			for (int y = by, k = 0; y < ey; y++)
				for (int x = bx; x < ex; x++, k++) {
					size_t i = (size_t)(y - y0) * row + (size_t)(x - x0);
					for (int c = 0; c < 3; c++) {
						if (out)
							out[i * 3 + c] = (float)(acc[k][c] * inv);
						if (sum)
							sum[i * 3 + c] = acc[k][c];
					}
				}
		}
}

void render_rect_features(const world *w, const render_settings *s, int x0, int y0, int x1, int y1,
                          float *out, float *feat)
{
	rect_first(w, s, x0, y0, x1, y1, s->samples, out, NULL, feat);
}

void render_rect_first(const world *w, const render_settings *s, int x0, int y0, int x1, int y1, int samples,
                       double *sum, float *feat)
{
	rect_first(w, s, x0, y0, x1, y1, samples, NULL, sum, feat);
}

void render_rect_adaptive(const world *w, const render_settings *s, int x0, int y0, int x1, int y1, int begin,
                          const uint16_t *end, double *sum, float *rgb, float *feat)
{
	texture_set_pixel_angle(2.0 * cam_tan_x(&w->cam, s->width, s->height) / s->width); /* as render_tile */
	rect_adaptive(w, s, x0, y0, x1, y1, s->width, s->height, (size_t)(x1 - x0), begin, end, sum, rgb, feat);
}

static void *worker(void *arg)
{
	shared *sh = arg;
	tile_cancel = sh->job->cancel;
	for (;;) {
		if ((sh->job->cancel && atomic_load_explicit(sh->job->cancel, memory_order_relaxed)) ||
		    atomic_load_explicit(&sh->stop, memory_order_relaxed))
			break;
		long t = atomic_fetch_add(&sh->next, 1);
		if (t >= sh->tiles || !slot_ready(sh, t, false))
			break;
		if (!render_tile(sh, t))
			break; /* stopped short: not done */
		atomic_fetch_add(&sh->done, 1);
		tile_finished(sh, t);
	}
	tile_cancel = NULL;
	pthread_mutex_lock(&sh->lock);
	if (atomic_fetch_sub(&sh->running, 1) == 1)
		pthread_cond_signal(&sh->finished);
	pthread_mutex_unlock(&sh->lock);
	return NULL;
}

static double now_seconds(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

static void report(render_job *job, shared *sh)
{
	if (job->progress)
		job->progress(job->progress_ctx, atomic_load(&sh->done), sh->tiles);
}

render_status render_run(render_job *job, rt_error *err)
{
	framebuffer *fb = job->fb;
	if ((job->sample_begin > 0 && (job->sample_begin != fb->spp || !fb->sum)) ||
	    job->sample_end <= job->sample_begin) {
		rt_error_set(err, "render pass %d..%d does not follow the %d samples done",
		             job->sample_begin, job->sample_end, fb->spp);
		return RENDER_FAILED;
	}
	if (job->pixel_end && (job->sample_begin == 0 || !fb->rgb || fb->srgb8)) {
		rt_error_set(err, "an adaptive render pass needs a first pass before it, the float image and no 8-bit "
		                  "codes");
		return RENDER_FAILED;
	}
	if ((job->rows && !fb->srgb8) || (fb->srgb8_ring && !job->rows)) {
		rt_error_set(err, "a render job handing over rows needs the framebuffer's 8-bit codes, and a ring of "
		                  "codes a job handing over rows");
		return RENDER_FAILED;
	}
	shared sh;
	sh.job = job;
	sh.tiles_x = (fb->w + RENDER_TILE - 1) / RENDER_TILE;
	sh.bands = (fb->h + RENDER_TILE - 1) / RENDER_TILE;
	sh.tiles = (long)sh.tiles_x * sh.bands;
	atomic_init(&sh.band_next, 0);
	sh.band_left = NULL;
	atomic_init(&sh.stop, false);
	if (job->rows) {
		sh.band_left = malloc((size_t)sh.bands * sizeof *sh.band_left);
		if (!sh.band_left) {
			rt_error_set(err, "out of memory");
			return RENDER_FAILED;
		}
		for (int b = 0; b < sh.bands; b++)
			atomic_init(&sh.band_left[b], sh.tiles_x);
	}
	atomic_init(&sh.next, 0);
	atomic_init(&sh.done, 0);
	int n = render_threads(&job->set);
	if (n > sh.tiles)
		n = (int)sh.tiles;
	/* This thread is one of the n: n - 1 workers start beside it. */
	atomic_init(&sh.running, n - 1);
	pthread_mutex_init(&sh.lock, NULL);
	pthread_cond_init(&sh.finished, NULL);
	pthread_cond_init(&sh.slot_free, NULL);

	/* At once, not after this thread's first tile: a tile of many samples
	 * takes seconds, and the shell's status line says "rendering ...
	 * (Ctrl-C stops)" from this report on. Before the workers start, so
	 * that it says 0 done: a worker's first tile could otherwise end
	 * before this thread got here. */
	if (job->progress)
		report(job, &sh);
	pthread_t *tid = n > 1 ? calloc((size_t)(n - 1), sizeof *tid) : NULL;
	int started = 0;
	if (tid)
		for (; started < n - 1; started++)
			if (pthread_create(&tid[started], NULL, worker, &sh) != 0)
				break;
	if (started < n - 1) {
		/* Fewer threads than asked: the missing ones count as finished. */
		pthread_mutex_lock(&sh.lock);
		atomic_fetch_sub(&sh.running, n - 1 - started);
		pthread_mutex_unlock(&sh.lock);
	}
	/* Tiles here too, handing the finished bands to job->rows between
	 * them (no third thread to wake on two cores), reporting about every
	 * 100 ms. */
	double last = now_seconds();
	tile_cancel = job->cancel;
	for (;;) {
		if ((job->cancel && atomic_load(job->cancel)) || atomic_load(&sh.stop))
			break;
		long t = atomic_fetch_add(&sh.next, 1);
		if (t >= sh.tiles || !slot_ready(&sh, t, true))
			break;
		if (!render_tile(&sh, t))
			break; /* stopped short: not done */
		atomic_fetch_add(&sh.done, 1);
		if (sh.band_left) {
			atomic_fetch_sub(&sh.band_left[t / sh.tiles_x], 1);
			hand_rows(&sh);
		}
		if (job->progress && now_seconds() - last >= 0.1) {
			last = now_seconds();
			report(job, &sh);
		}
	}
	tile_cancel = NULL; /* this thread's other renders (render_rect) have none */
	if (started > 0) {
		/* The workers' last tiles: their bands are handed over as they
		 * finish; progress every 100 ms (a band that wakes this thread
		 * early does not move the deadline). */
		pthread_mutex_lock(&sh.lock);
		struct timespec deadline;
		in_ms(&deadline, 100);
		while (atomic_load(&sh.running) > 0) {
			if (!atomic_load(&sh.stop) && band_ready(&sh)) {
				pthread_mutex_unlock(&sh.lock);
				hand_rows(&sh);
				pthread_mutex_lock(&sh.lock);
				continue;
			}
			if (pthread_cond_timedwait(&sh.finished, &sh.lock, &deadline) == 0)
				continue;
			in_ms(&deadline, 100);
			if (atomic_load(&sh.running) > 0 && job->progress) {
				pthread_mutex_unlock(&sh.lock);
				report(job, &sh);
				pthread_mutex_lock(&sh.lock);
			}
		}
		pthread_mutex_unlock(&sh.lock);
		for (int i = 0; i < started; i++)
			pthread_join(tid[i], NULL);
	}
	free(tid);
	if (sh.band_left && !atomic_load(&sh.stop))
		hand_rows(&sh); /* the last bands */
	pthread_mutex_destroy(&sh.lock);
	pthread_cond_destroy(&sh.finished);
	pthread_cond_destroy(&sh.slot_free);
	free(sh.band_left);
	report(job, &sh);
	if (atomic_load(&sh.stop)) {
		fb->spp = 0;
		rt_error_set(err, "writing the image stopped the render");
		return RENDER_FAILED;
	}
	if (atomic_load(&sh.done) < sh.tiles) {
		fb->spp = 0; /* the sums now mix passes: the next pass must start over */
		return RENDER_CANCELLED;
	}
	fb->spp = job->sample_end;
	return RENDER_DONE;
}

/* A framebuffer for one pass: no running sums; no float image either when
 * only the 8-bit codes are wanted (codes_only: render_image_rows). */
static framebuffer *fb_one_pass(int w, int h, bool codes_only)
{
	return fb_alloc(w, h, !codes_only, false);
}

/* An adaptive render's progress: its two passes as one, each tile of the
 * first pass counting its first samples, of the second the rest. */
typedef struct two_passes {
	render_progress_fn progress;
	void *ctx;
	int first, samples;
	bool second;
} two_passes;

static void two_passes_progress(void *ctx, long done, long total)
{
	const two_passes *tp = ctx;
	long d = tp->second ? total * tp->first + done * (tp->samples - tp->first) : done * tp->first;
	tp->progress(tp->ctx, d, total * tp->samples);
}

int render_adaptive_first(int samples, bool denoise)
{
	int first = DENOISE_FIRST(samples);
	return denoise && first >= 2 && samples <= RENDER_ADAPTIVE_MAX ? first : samples;
}

int render_adaptive_counts(framebuffer *fb, int samples, int first, rt_error *err)
{
	size_t n = (size_t)fb->w * (size_t)fb->h;
	float *sigma = malloc(n * sizeof *sigma);
	uint16_t *spp = malloc(n * sizeof *spp);
	/* of the first pass, the same count in every pixel */
	free(fb->pixel_spp);
	fb->pixel_spp = NULL;
	float *reach = malloc(n * sizeof *reach);
	if (!sigma || !spp || !reach || !denoise_sigma(fb, sigma) || !denoise_reach(fb, reach)) {
		mem_free_all(sigma, spp, reach);
		rt_error_set(err, "out of memory for the adaptive samples of a %dx%d image", fb->w, fb->h);
		return -1;
	}
	fb->pixel_spp = spp;
	/* The noise the filtered pixel keeps, not the raw one: a pixel the
	 * fit averages with many alike ones needs fewer of its own. */
	for (size_t i = 0; i < n; i++)
		sigma[i] *= (float)pow(reach[i], DENOISE_REACH_POW);
	free(reach);
	/* A pixel that missed the scene or sees a lamp (denoise_fixed) keeps
	 * the samples a uniform render gives it (spent on surfaces, the
	 * background's one-ray paths cost cornell.rt's render 29% more
	 * instructions); the others share theirs, packed in pixel order. */
	size_t m = 0;
	for (size_t i = 0; i < n; i++)
		if (!denoise_fixed(fb->feat + i * DENOISE_FEATURES))
			sigma[m++] = sigma[i];
	denoise_allocate(sigma, m, first, samples, DENOISE_CAP(samples), spp + (n - m));
	for (size_t i = 0, k = n - m; i < n; i++)
		spp[i] = !denoise_fixed(fb->feat + i * DENOISE_FEATURES) ? spp[k++] : (uint16_t)samples;
	free(sigma);
	int most = first;
	for (size_t i = 0; i < n; i++)
		most = spp[i] > most ? spp[i] : most;
	return most;
}

render_status render_adaptive(render_job *job, rt_error *err)
{
	framebuffer *fb = job->fb;
	int samples = job->set.samples, first = job->sample_end;
	int most = render_adaptive_counts(fb, samples, first, err);
	if (most < 0)
		return RENDER_FAILED;
	render_status st = RENDER_DONE;
	if (most > first) {
		job->sample_begin = first;
		job->sample_end = most;
		job->pixel_end = fb->pixel_spp;
		st = render_run(job, err);
	}
	if (st == RENDER_DONE)
		fb->spp = samples; /* on average */
	return st;
}

static framebuffer *render_image_with(const world *w, const render_settings *s, atomic_bool *cancel,
                                      render_progress_fn progress, void *ctx, bool srgb8,
                                      render_rows_fn rows, void *rows_ctx, rt_error *err)
{
	bool denoise = integrator_of(s->mode)->features && s->denoise == DENOISE_ON;
	/* A denoised image of 4 samples or more is made in two passes: the
	 * first DENOISE_FIRST samples everywhere, the rest where the noise is
	 * (adaptive), and so keeps its running sums between them. */
	int first = render_adaptive_first(s->samples, denoise);
	bool adaptive = first < s->samples;
	/* One pass makes the whole image: no running sums are needed (nor,
	 * handing rows over, the floats: the tiles keep theirs). */
	framebuffer *fb = adaptive ? fb_alloc(s->width, s->height, true, true)
	                           : fb_one_pass(s->width, s->height, rows && !denoise);
	if (!fb) {
		rt_error_set(err, "cannot make a %dx%d image; expected 1..%d pixels a side, and memory",
		             s->width, s->height, RENDER_MAX_DIM);
		return NULL;
	}
	if (denoise && !denoise_prepare(fb)) {
		rt_error_set(err, "out of memory for the denoiser's features of a %dx%d image",
		             s->width, s->height);
		fb_free(fb);
		return NULL;
	}
	if (srgb8 && !denoise) {
		/* No zeroing: every tile writes its codes (a failed render frees
		 * them). Handing rows over, a ring of a few bands: the threads'
		 * tiles in flight span a band or two, and the codes of the whole
		 * image, 6 MB at 1920x1080, cost 1500 page faults (issue 29). */
		size_t kept = (size_t)fb->h;
		if (rows) {
			int bands = (fb->h + RENDER_TILE - 1) / RENDER_TILE, ring = render_threads(s) + 6;
			fb->srgb8_ring = ring < bands ? ring : bands;
			kept = (size_t)fb->srgb8_ring * RENDER_TILE;
		}
		fb->srgb8 = malloc((size_t)fb->w * kept * 3);
		fb->srgb8_gain = exp2(s->exposure);
		if (!fb->srgb8) {
			rt_error_set(err, "out of memory for a %dx%d image", s->width, s->height);
			fb_free(fb);
			return NULL;
		}
	}
	render_job job = {
		.w = w,
		.set = *s,
		.fb = fb,
		.sample_begin = 0,
		.sample_end = s->samples,
		.cancel = cancel,
		.progress = progress,
		.progress_ctx = ctx,
		.rows = denoise ? NULL : rows,
		.rows_ctx = rows_ctx,
	};
	two_passes tp = {progress, ctx, first, s->samples, false};
	if (adaptive) {
		job.sample_end = first;
		if (progress) {
			job.progress = two_passes_progress;
			job.progress_ctx = &tp;
		}
	}
	render_status st = render_run(&job, err);
	if (st == RENDER_DONE && adaptive) {
		tp.second = true;
		st = render_adaptive(&job, err);
	}
	if (st != RENDER_DONE) {
		if (st == RENDER_CANCELLED)
			rt_error_set(err, "render stopped");
		fb_free(fb);
		return NULL;
	}
	if (denoise && !denoise_image(fb, fb->rgb, render_threads(s))) {
		rt_error_set(err, "out of memory denoising a %dx%d image", s->width, s->height);
		fb_free(fb);
		return NULL;
	}
	if (denoise && rows) {
		/* the codes of the denoised image, every row at once */
		size_t n = (size_t)fb->w * (size_t)fb->h * 3;
		fb->srgb8 = malloc(n);
		fb->srgb8_gain = exp2(s->exposure);
		if (!fb->srgb8) {
			rt_error_set(err, "out of memory for a %dx%d image", s->width, s->height);
			fb_free(fb);
			return NULL;
		}
		linear_to_srgb8_n(fb->rgb, fb->srgb8_gain, fb->srgb8, n);
		if (!rows(rows_ctx, fb, 0, fb->h, fb->srgb8)) {
			rt_error_set(err, "writing the image stopped the render");
			fb_free(fb);
			return NULL;
		}
	}
	return fb;
}

framebuffer *render_image(const world *w, const render_settings *s, atomic_bool *cancel,
                          render_progress_fn progress, void *ctx, rt_error *err)
{
	return render_image_with(w, s, cancel, progress, ctx, false, NULL, NULL, err);
}

framebuffer *render_image_srgb8(const world *w, const render_settings *s, atomic_bool *cancel,
                                render_progress_fn progress, void *ctx, rt_error *err)
{
	return render_image_with(w, s, cancel, progress, ctx, true, NULL, NULL, err);
}

framebuffer *render_image_rows(const world *w, const render_settings *s, atomic_bool *cancel,
                               render_progress_fn progress, void *ctx, render_rows_fn rows, void *rows_ctx,
                               rt_error *err)
{
	return render_image_with(w, s, cancel, progress, ctx, true, rows, rows_ctx, err);
}
