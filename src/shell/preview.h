/* rtsh — the background preview renderer.
 *
 * One render thread turns requests (a scene generation, settings and a
 * preview size) into images: it builds the world when the scene changed,
 * renders a cheap pass at half the width and height (a quarter of the
 * pixels), then the full preview in passes of samples that accumulate
 * (progressive in path mode), publishing an image after each pass and
 * writing a byte to a wake-up file descriptor so that the front end's
 * select() loop knows. The front end only copies images out (preview_take)
 * and encodes them; it never waits for a render.
 *
 * The scene belongs to the front end. The thread reads it only while
 * building a world; the front end must call preview_hold before it changes
 * the scene (hold cancels the render in flight and waits for the thread to
 * stop using the scene), then preview_start or preview_release.
 *
 * While held, preview_world gives the front end the prepared world (built
 * in the calling thread when stale) for full-resolution renders, so a huge
 * scene is prepared once. Without preview_start the thread never starts:
 * scripts use a preview only as that world cache.
 */
#ifndef RTSH_PREVIEW_H
#define RTSH_PREVIEW_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rtsh/error.h"
#include "rtsh/render.h"
#include "rtsh/scene.h"
#include "rtsh/world.h"

typedef struct preview preview;

typedef struct preview_request {
	const scene *s;       /* read by the thread until the next preview_hold */
	uint64_t gen;         /* the scene's generation (edit.h) */
	render_settings set;  /* samples = the target per pixel */
	int w, h;             /* the preview size in pixels */
} preview_request;

/* An image copied out of the preview. */
typedef struct preview_image {
	int w, h;
	float *rgb;          /* w*h*3 linear floats; reallocated by preview_take */
	size_t cap;          /* floats allocated */
	int spp, target;     /* samples per pixel done / wanted (spp 0: the quick pass) */
	bool done;           /* all the samples are in */
	bool stopped;        /* preview_stop ended it early */
	bool denoised;       /* passed through the denoiser (path mode, set denoise) */
	double seconds;      /* from the request to this image */
	uint64_t gen;        /* the scene generation it shows */
	char error[RT_ERROR_MSG_MAX]; /* not empty: the world could not be built */
} preview_image;

/* A new preview that writes to wake_fd (a non-blocking pipe) whenever an
 * image is ready; NULL when out of memory. */
preview *preview_new(int wake_fd);
/* Stops the thread and frees everything. */
void preview_free(preview *pv);

/* Cancels the render in flight and waits until the thread is idle. */
void preview_hold(preview *pv);
/* The world for scene s at generation gen, built now if the one kept is
 * older; only between preview_hold and preview_start/release. NULL (err set)
 * when it cannot be built. */
const world *preview_world(preview *pv, const scene *s, uint64_t gen, rt_error *err);
/* Ends a hold and renders req in the background (starting the thread on
 * first use). A request equal to the last one completed does nothing. */
void preview_start(preview *pv, const preview_request *req);
/* Ends a hold with nothing new to render. */
void preview_release(preview *pv);
/* Stops the render in flight (Ctrl-C); true when one was running. */
bool preview_stop(preview *pv);
/* True while a request is being rendered or waits to be. */
bool preview_busy(preview *pv);
/* Copies the newest image into img when there is one not taken yet. */
bool preview_take(preview *pv, preview_image *img);
void preview_image_free(preview_image *img);

#endif
