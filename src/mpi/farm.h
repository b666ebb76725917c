/* rtsh-mpi — the tile farm: rank 0 hands out tiles from one counter, its
 * own threads take theirs from the same counter, and every other rank
 * renders the tiles it is given with all of its threads and sends each one
 * back as linear radiance (floats) for rank 0 to place in the image.
 *
 * A denoised image (farm_denoises) of S samples is farmed in two passes,
 * as render_image makes it (render.h: render_adaptive): FARM_FIRST renders
 * farm_first(S) samples in every pixel; rank 0 allocates the rest from the
 * whole image's sums (render_adaptive_counts: a pixel's count depends on
 * its 3x3 window, across tiles); FARM_ADAPTIVE hands every tile out with
 * its pixels' sums, features and counts, and each pixel's sequence is
 * continued to its count. Any other image is one pass, FARM_ONE.
 *
 * Messages (all between rank 0 and one worker, in order; bytes):
 *   worker -> 0   FARM_ASK      int64 k: send me k tiles (once, at the start)
 *   0 -> worker   FARM_TILES    int64 tile numbers, -1 last when none are
 *                               left; in FARM_ADAPTIVE each tile's number
 *                               followed by its state: its pixels' running
 *                               sums (3 doubles a pixel), features
 *                               (DENOISE_FEATURES floats) and counts (uint16)
 *   worker -> 0   FARM_RESULT   int64 tile number, then the tile's result:
 *                               its radiance, 3 floats a pixel, and when the
 *                               image is denoised the denoiser's features,
 *                               DENOISE_FEATURES floats a pixel; in
 *                               FARM_FIRST the running sums (3 doubles a
 *                               pixel) and features;
 *                               answered by FARM_TILES with one more tile
 * A worker holds at most threads + prefetch tiles (rendering, queued or
 * waiting to be sent) and never the image. After rank 0 has sent a worker
 * its -1 it sends it nothing more.
 */
#ifndef RTSH_MPI_FARM_H
#define RTSH_MPI_FARM_H

#include <stdbool.h>
#include <stdint.h>

#include "rtsh/denoise.h"
#include "rtsh/render.h"

/* The pass farmed (farm.h's head). */
enum { FARM_ONE, FARM_FIRST, FARM_ADAPTIVE };

typedef struct farm_opts {
	int pass;       /* FARM_ONE, FARM_FIRST or FARM_ADAPTIVE */
	int first;      /* the samples of FARM_FIRST (farm_first) */
	int tile;       /* tile side in pixels */
	int prefetch;   /* tiles a worker asks for beyond its threads */
	int delay_us;   /* test mode: each result waits this long before it is sent */
	int threads;    /* render threads on this rank */
	bool progress;  /* rank 0: a progress line on standard error */
	double t0;      /* rank 0: the progress line's start (farm_clock), 0: the pass's */
	/* Rank 0: a worker that holds tiles (or has not asked yet) and has sent
	 * nothing for max(deadline, FARM_DEADLINE_TILES x the slowest tile or
	 * gap between results seen so far) seconds is taken for stopped or hung
	 * (SIGSTOP, a frozen host): farm_serve fails naming it, and the caller
	 * ends the job. Before any tile has been timed, no deadline. */
	double deadline;
	const char *(*host)(int rank); /* rank 0: a rank's host for messages (NULL: none) */
} farm_opts;

#define FARM_DEADLINE_TILES 10.0

/* One rank's figures (gathered on rank 0 for -v). */
typedef struct farm_stats {
	double tiles;     /* tiles rendered */
	double seconds;   /* wall time of the render phase */
	double busy;      /* thread-seconds spent rendering */
	double rays;      /* rays traced (camera, shadow, secondary) */
	double bytes;     /* bytes this rank sent */
	double rtt;       /* worker: mean seconds from sending a result to the next tile arriving */
	double serve;     /* rank 0: CPU seconds its serving thread spent (not rendering) */
	double peak;      /* the process's peak resident memory, bytes (filled by the caller) */
	int threads;
	char host[64];
} farm_stats;

/* Both return false (err set) when a message breaks the protocol or memory
 * runs out; the caller then ends the job. */
/* The clock of farm_opts.t0, in seconds. */
double farm_clock(void);
/* Whether the job's image is denoised (path mode, denoise on, as
 * render_image): its tiles then carry the features too. */
bool farm_denoises(const render_settings *s);
/* The samples of a denoised image's first pass (render_adaptive_first);
 * s->samples when it is made in one pass. */
int farm_first(const render_settings *s);
/* Rank 0: renders one pass (o->pass) of the image into fb (s->width x
 * s->height): rgb, and feat when farm_denoises and fb has it; FARM_FIRST
 * fb->sum and fb->feat; FARM_ADAPTIVE reads fb->sum, fb->feat and
 * fb->pixel_spp and writes rgb and feat. With the workers of
 * MPI_COMM_WORLD. */
bool farm_serve(const world *w, const render_settings *s, const farm_opts *o, framebuffer *fb,
                farm_stats *st, rt_error *err);
/* Every other rank: renders the tiles rank 0 hands out until it says none
 * are left. */
bool farm_work(const world *w, const render_settings *s, const farm_opts *o, farm_stats *st,
               rt_error *err);

#endif
