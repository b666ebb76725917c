/* rtsh — rendering: settings, the framebuffer and render jobs.
 *
 * A render job traces a range of samples [sample_begin, sample_end) for
 * every pixel of a framebuffer, with `threads` workers pulling small tiles
 * from a shared atomic counter (the thread that calls render_run is one of
 * them). Every random number is a function of
 * (pixel, sample, seed), and each pixel's samples are summed in sample order,
 * so the image is bit-identical for any thread count, any tile order and any
 * split of the samples into passes (progressive preview == batch render).
 */
#ifndef RTSH_RENDER_H
#define RTSH_RENDER_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>

#include "rtsh/error.h"
#include "rtsh/world.h"

/* The integrators (integrators.def): MODE_WHITTED, MODE_PATH, ... */
typedef enum render_mode {
#define RT_INTEGRATOR(e, name, desc) MODE_##e,
#include "rtsh/integrators.def"
#undef RT_INTEGRATOR
	MODE_COUNT
} render_mode;

/* The integrator's name, the `mode` setting's value ("whitted"). */
const char *render_mode_name(render_mode m);
/* The names, NULL-terminated (the `mode` setting's values). */
extern const char *const render_mode_names[MODE_COUNT + 1];
/* The integrator of mode m gives the denoiser its features: the `denoise`
 * setting applies to its pictures (path mode). */
bool render_mode_denoises(render_mode m);

/* When path-mode images are denoised (denoise.h). */
typedef enum denoise_mode {
	DENOISE_AUTO, /* the shell's previews only (the default) */
	DENOISE_ON,   /* every path-mode image: previews, save, batch output */
	DENOISE_OFF,
} denoise_mode;

/* rtsh-mpi sends these field by field (src/mpi/wire.c; a static assertion
 * there stops the build when a field is added here and not there). */
typedef struct render_settings {
	int width, height; /* full resolution */
	int samples;       /* per pixel */
	int depth;         /* reflection depth (whitted) / bounces (path) */
	int threads;       /* 0 = the online CPU count */
	render_mode mode;
	uint64_t seed;
	double exposure;   /* stops; output = radiance x 2^exposure */
	int denoise;       /* denoise_mode */
	/* The terminal's choices (SETTING_TERMINAL rows): `set` keeps them here
	 * beside the rest, but no renderer reads them and rtsh-mpi's wire
	 * leaves them out. */
	int pixels;        /* the shell's picture: off (half blocks), kitty, sixel,
	                    * iterm, auto (term/pixels.h, pixels_mode) */
	int symbols;       /* the cells' glyphs when not in real pixels: half,
	                    * quadrant, sextant, octant, auto (term/symbols.h) */
} render_settings;

render_settings render_settings_default(void);
/* The largest side a scene file's resolution (R, set resolution) may ask
 * for: larger ones are scaled down to it, keeping their aspect, as the 42
 * subject clamps R to the screen. The command line may ask for up to
 * RENDER_MAX_DIM. */
#define RENDER_HINT_MAX_DIM 7680

/* Applies the hints of a scene file (R, set lines) over s; true when the
 * file's resolution had to be scaled down (the caller may warn). */
bool render_settings_apply_hints(render_settings *s, const scene_hints *h);
/* The thread count to use: s->threads, or the online CPUs when 0. */
int render_threads(const render_settings *s);

/* A linear-light image. rgb holds w*h*3 floats, rows top to bottom: the mean
 * of the samples so far. sum holds the running per-pixel sums (double) and
 * spp how many samples they contain; it is NULL in an image made in one
 * pass (render_image), which cannot take further passes. */
typedef struct framebuffer {
	int w, h;
	float *rgb;
	double *sum;
	int spp;
	float *feat;  /* optional: the first hit's features for the denoiser
	               * (denoise.h), recorded by path-mode jobs; NULL: none */
	uint8_t *srgb8; /* optional: w*h*3 8-bit sRGB codes of rgb x srgb8_gain,
	                 * written by render jobs as each tile finishes, so that an
	                 * 8-bit file's encode is not left to one thread after the
	                 * render (image.c uses them when its gain is the same);
	                 * whoever changes rgb outside a job frees them; NULL: none */
	double srgb8_gain;
	int srgb8_ring; /* 0: srgb8 holds every row; k > 0: only a ring of k
	                 * bands of RENDER_TILE rows, band b in slot b % k, each
	                 * reused once job->rows has taken it (render_image_rows) */
	double *sum2;   /* with feat and sum (denoise_prepare): each pixel's
	                 * running sum of its samples' squared brightness, so
	                 * that the features' mean of it (denoise.h, 7) is the
	                 * same for any split of the samples into passes */
	uint16_t *pixel_spp; /* optional: each pixel's own sample count (a
	                      * denoised render's adaptive samples, denoise.h);
	                      * NULL: spp samples in every pixel */
} framebuffer;

/* NULL when out of memory or the size is not in 1..RENDER_MAX_DIM. */
framebuffer *fb_new(int w, int h);
void fb_free(framebuffer *fb);
/* Clears to black with no samples. */
void fb_clear(framebuffer *fb);
/* A cleared framebuffer of w x h in *fb, reusing the one there when it has
 * that size (else freeing it); NULL when out of memory. */
framebuffer *fb_reuse(framebuffer **fb, int w, int h);

#define RENDER_MAX_DIM 16384
/* A denoised render of up to this many samples spends them adaptively
 * (render_image: the pixels' counts are 16-bit). */
#define RENDER_ADAPTIVE_MAX 4096
#define RENDER_TILE 16

typedef enum render_status {
	RENDER_DONE,
	RENDER_CANCELLED,
	RENDER_FAILED,
} render_status;

/* Called from the thread that runs render_run, about every 100 ms and once at
 * the end, with the tiles done so far. */
typedef void (*render_progress_fn)(void *ctx, long done, long total);

/* Called with the rows y0 <= y < y1 of the image once every tile of them is
 * finished: codes holds their final 8-bit codes, fb->w * 3 bytes a row, the
 * rows one after another, valid only during the call (with a ring,
 * framebuffer.srgb8_ring, the slot is rendered into again after it). In
 * order from the top, every row once, always on the thread that runs
 * render_run (between its own tiles, then while the other workers finish
 * theirs), while the other tiles still render (a file is written as the
 * picture is made: image.h's image_write_rendered). False stops the render
 * (RENDER_FAILED); the callback keeps its own error. */
typedef bool (*render_rows_fn)(void *ctx, const framebuffer *fb, int y0, int y1, const uint8_t *codes);

typedef struct render_job {
	const world *w;
	render_settings set;   /* mode, depth, seed, threads, samples (= total target) */
	framebuffer *fb;       /* the image size is fb->w x fb->h */
	int sample_begin;      /* 0 starts afresh; else must equal fb->spp (passes in order) */
	int sample_end;        /* <= set.samples */
	atomic_bool *cancel;   /* optional: set to stop; checked per tile */
	render_progress_fn progress; /* optional */
	void *progress_ctx;
	render_rows_fn rows;   /* optional: needs fb->srgb8 */
	void *rows_ctx;
	/* optional: pixel i's own end, sample_begin..sample_end (adaptive
	 * sampling: the pixel's sequence continues where the last pass left
	 * it); a pixel's features are still made over the first
	 * DENOISE_FEATURE_SAMPLES positions (denoise.h). NULL: sample_end. */
	const uint16_t *pixel_end;
} render_job;

/* Runs the job to the end or until cancelled. On RENDER_DONE the fb holds
 * sample_end samples per pixel; on RENDER_CANCELLED its spp is 0 (the sums
 * mix two passes, so the next pass starts again from sample 0) and rgb may
 * hold a partial pass (the front end shows or drops it). test_cancel stops
 * a pass in flight and checks the picture rendered again is the same. */
render_status render_run(render_job *job, rt_error *err);

/* A denoised image of S samples (render_image, the shell's preview) is made
 * in two passes: render_adaptive_first(S, true) samples in every pixel,
 * then render_adaptive; S itself (one pass) when not denoised, or when S is
 * under 3 or above RENDER_ADAPTIVE_MAX. */
int render_adaptive_first(int samples, bool denoise);
/* The adaptive pass: job->fb (with features, running sums and sum2)
 * holds job->sample_end samples in every pixel, the first pass, in one
 * pass or several; the rest of job->set.samples x W x H paths go where its
 * noise is, as the filter will pass it on (denoise.h: denoise_sigma,
 * denoise_reach, denoise_fixed, denoise_allocate) into
 * fb->pixel_spp, and each pixel's sequence is continued to its count
 * (job->pixel_end); then fb->spp is job->set.samples, the mean. The
 * allocation reads only what does not depend on how the first pass was
 * split (the sums, and feature 7 from sum2), so the image is the same. The
 * job's other fields (threads, cancel, progress) as render_run's. */
render_status render_adaptive(render_job *job, rt_error *err);
/* Its allocation alone: fb (features, running sums and sum2, first
 * samples in every pixel) gets its pixels' counts of samples in
 * fb->pixel_spp (replacing any there); returns the largest, or -1 (err set)
 * when out of memory. rtsh-mpi allocates its image's samples with it. */
int render_adaptive_counts(framebuffer *fb, int samples, int first, rt_error *err);

/* Convenience: a new framebuffer of s->width x s->height with all s->samples
 * samples. NULL (err set) on failure or cancellation. */
framebuffer *render_image(const world *w, const render_settings *s, atomic_bool *cancel,
                          render_progress_fn progress, void *ctx, rt_error *err);
/* The same, and fb->srgb8 filled with the codes of rgb x 2^s->exposure as the
 * tiles finish (left NULL when the image is denoised after its render): for
 * an 8-bit file written next (batch mode). */
framebuffer *render_image_srgb8(const world *w, const render_settings *s, atomic_bool *cancel,
                                render_progress_fn progress, void *ctx, rt_error *err);
/* The codes alone (the same as render_image_srgb8's), handed to rows
 * (render_rows_fn) as bands of tiles finish, through a ring of a few bands
 * (framebuffer.srgb8_ring: not the whole image's codes, whose first touch
 * cost page faults; a tile waits when its band's slot is still to be
 * handed over). The framebuffer returned is a receipt: no float image (rgb
 * NULL: the tiles keep their floats to themselves) and no codes (freed with
 * the ring), unless the image is denoised after its render: then it holds
 * rgb and srgb8, and every row is handed over at the end. NULL on failure
 * (err set; when rows returned false, err says the write stopped the
 * render). */
framebuffer *render_image_rows(const world *w, const render_settings *s, atomic_bool *cancel,
                               render_progress_fn progress, void *ctx, render_rows_fn rows, void *rows_ctx,
                               rt_error *err);

/* Renders the pixels x0 <= x < x1, y0 <= y < y1 of the s->width x s->height
 * image, all s->samples samples, on the calling thread, into out: (x1-x0) x
 * (y1-y0) pixels, rows top to bottom, 3 floats each, bit for bit the values
 * render_image gives those pixels (rtsh-mpi renders its tiles with it). */
void render_rect(const world *w, const render_settings *s, int x0, int y0, int x1, int y1,
                 float *out);
/* The same, and (path mode, feat not NULL) the denoiser's features of those
 * pixels into feat, DENOISE_FEATURES floats a pixel in the same order, bit
 * for bit what a render job into a framebuffer with features records. */
void render_rect_features(const world *w, const render_settings *s, int x0, int y0, int x1, int y1,
                          float *out, float *feat);
/* The two passes of a denoised render (render_adaptive) on a rectangle, as
 * rtsh-mpi farms them: render_rect_first renders samples [0, samples) of
 * each pixel into sum (3 running sums a pixel, doubles) and feat (as
 * render_rect_features); render_rect_adaptive continues each pixel p of
 * the rectangle from those sums and features, sum[p] and feat[p], to its
 * own end[p] (samples [begin, end[p]); at least begin), updating them, and
 * writes its mean into rgb. Bit for bit the values render_image gives those
 * pixels when end is its allocation (render_adaptive_counts). Arrays are
 * the rectangle's, rows top to bottom. */
void render_rect_first(const world *w, const render_settings *s, int x0, int y0, int x1, int y1, int samples,
                       double *sum, float *feat);
void render_rect_adaptive(const world *w, const render_settings *s, int x0, int y0, int x1, int y1, int begin,
                          const uint16_t *end, double *sum, float *rgb, float *feat);

/* The radiance along one camera sample: the integrators (whitted.c, path.c).
 * px, py: pixel; sample: index; the random stream depends only on these and
 * the seed. */
vec3 render_sample(const world *w, const render_settings *s, int px, int py, int fw, int fh,
                   int sample);
/* The camera ray of that sample (the denoiser's features follow it). */
ray render_sample_ray(const world *w, const render_settings *s, int px, int py, int fw, int fh,
                      int sample);

#endif
