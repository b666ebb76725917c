/* rtsh — the render service: one background renderer for the shell's
 * preview, key mode's fast frames and path accumulation.
 *
 * One thread turns requests into images. A request is one of:
 *   - a frame at ratio r (RSVC_FRAME): one centred sample per pixel at
 *     1/r of the picture's width and height (key mode while keys arrive);
 *     a cancelled frame reports how far it got (rsvc_cut), so the front end
 *     learns what a pixel costs;
 *   - a refine (RSVC_REFINE): every sample of the settings at the picture's
 *     size, in passes of about pass_seconds that accumulate, an image
 *     published after each; optionally a quick pass first (half the width
 *     and height, one sample, scaled up: the shell's preview) and the
 *     path-mode denoiser after each pass;
 *   - an accumulation (a refine with `accumulate`): goes on from the samples
 *     an earlier refine of the same picture left (more samples asked for, or
 *     a render stopped between passes), so nothing is rendered twice.
 * Publishing writes a byte to a wake-up file descriptor, so the front end's
 * event loop knows; the front end only copies images out (rsvc_take).
 *
 * Any edit cancels: the front end calls rsvc_hold before it changes the
 * scene or the settings (it cancels the render in flight and waits until
 * the thread is idle), then rsvc_start (a new request) or rsvc_release.
 *
 * Worlds are reference-counted (rtsh/world.h). The service keeps the world
 * of the newest scene generation it saw (built in the thread for a request,
 * or in the caller by rsvc_world); a render holds its own reference for
 * as long as it runs, and rsvc_world gives the caller one, so no thread
 * ever renders from a world another may free. A request carries either a
 * world (retained for it) or the scene and its generation; the thread reads
 * such a scene only while it builds a world, so it must not change until
 * the next rsvc_hold.
 */
#ifndef RTSH_RENDER_SERVICE_H
#define RTSH_RENDER_SERVICE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rtsh/error.h"
#include "rtsh/render.h"
#include "rtsh/scene.h"
#include "rtsh/world.h"

typedef struct rsvc rsvc;

/* The length of the shell preview's passes, so the picture refreshes
 * steadily. */
#define PREVIEW_PASS_SECONDS 0.1
/* Path mode: the samples the preview refines to when neither the scene,
 * -s nor `set samples` chose any (the status line says "preview's own"). */
#define PREVIEW_PATH_SAMPLES 64

typedef enum rsvc_kind {
	RSVC_REFINE, /* every sample, in passes that accumulate */
	RSVC_FRAME,  /* one sample per pixel at 1/ratio of the size */
} rsvc_kind;

typedef struct rsvc_request {
	const world *world;   /* the world to render (retained for the request); NULL: from s and gen */
	const scene *s;       /* when world is NULL: read while a world is built, until the next rsvc_hold */
	uint64_t gen;         /* the scene's generation (edit.h) */
	render_settings set;  /* samples = the target of a refine */
	int w, h;             /* the picture size in pixels */
	rsvc_kind kind;
	double ratio;         /* RSVC_FRAME: >= 1 */
	bool quick;           /* RSVC_REFINE: a quick pass first */
	bool accumulate;      /* RSVC_REFINE: go on from the samples an earlier refine left */
	bool denoise;         /* run the denoiser after each pass (path mode) */
	double pass_seconds;  /* RSVC_REFINE: the length passes aim at (after a first of one sample) */
} rsvc_request;

/* An image copied out of the service. */
typedef struct rsvc_image {
	uint64_t seq;         /* the request it answers (rsvc_start's number) */
	rsvc_kind kind;
	int w, h;
	float *rgb;           /* w*h*3 linear floats; reallocated by rsvc_take */
	size_t cap;           /* floats allocated */
	int spp, target;      /* samples per pixel done / wanted (spp 0: the quick pass) */
	bool done;            /* all the samples are in */
	bool stopped;         /* rsvc_stop ended it early */
	bool denoised;        /* passed through the denoiser */
	double seconds;       /* from the request to this image */
	double pass_seconds;  /* the render time of this frame or pass (0: nothing rendered) */
	double px_cost;       /* seconds per pixel and sample that pass measured (0: none) */
	uint64_t gen;         /* the scene generation it shows */
	char error[RT_ERROR_MSG_MAX]; /* not empty: the world could not be built */
} rsvc_image;

/* The size of a frame at ratio r of a w x h picture: ceil(w / r) wide and
 * the picture's aspect kept (square pixels); both at least 1. */
void rsvc_frame_size(int w, int h, double r, int *fw, int *fh);

/* A new service that writes to wake_fd (a non-blocking pipe; -1: none)
 * whenever an image is ready; NULL when out of memory. */
rsvc *rsvc_new(int wake_fd);
/* Stops the thread and frees everything (the worlds it holds released). */
void rsvc_free(rsvc *sv);

/* Cancels the render in flight and any request waiting, and waits until
 * the thread is idle: the scene may change after. */
void rsvc_hold(rsvc *sv);
/* A reference to the world of scene s at generation gen (the caller
 * releases it), built now by up to `threads` threads if the one kept is
 * older (world_build_threads: the same world for any count); NULL (err
 * set) when it cannot be built, or "stopped" when *cancel (NULL: never) was
 * set during the build (the next call builds it again). */
const world *rsvc_world(rsvc *sv, const scene *s, uint64_t gen, int threads, const atomic_bool *cancel,
                        rt_error *err);
/* Ends a hold and renders req in the background (starting the thread on
 * first use); an image taken later answers it when its seq is the number
 * returned (0: the thread could not start). A request equal to the last one completed renders nothing and
 * returns that one's number. An image published for an older request and
 * not yet taken is dropped. */
uint64_t rsvc_start(rsvc *sv, const rsvc_request *req);
/* Ends a hold with nothing new to render. */
void rsvc_release(rsvc *sv);
/* Stops the render in flight (Ctrl-C); true when one was running. */
bool rsvc_stop(rsvc *sv);
/* True while a request is being rendered or waits to be. */
bool rsvc_busy(rsvc *sv);
/* Copies the newest image into img when there is one not taken yet. */
bool rsvc_take(rsvc *sv, rsvc_image *img);
void rsvc_image_free(rsvc_image *img);
/* The last frame that was cancelled: its request, the seconds it ran and
 * the fraction of its tiles done; false when none since the last call. */
bool rsvc_cut(rsvc *sv, uint64_t *seq, double *seconds, double *frac);

#endif
