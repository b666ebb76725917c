/* rtsh-mpi — the tile farm: rank 0 hands out tiles from one counter, its
 * own threads take theirs from the same counter, and every other rank
 * renders the tiles it is given with all of its threads and sends each one
 * back as linear radiance (floats) for rank 0 to place in the image.
 *
 * Messages (all between rank 0 and one worker, in order):
 *   worker -> 0   FARM_ASK      int64 k: send me k tiles (once, at the start)
 *   0 -> worker   FARM_TILES    int64[] tile numbers, -1 last when none are left
 *   worker -> 0   FARM_RESULT   int64 tile number, then the tile's floats:
 *                               its radiance, 3 a pixel, and when the image
 *                               is denoised (farm_denoises) the denoiser's
 *                               features, DENOISE_FEATURES a pixel;
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

typedef struct farm_opts {
	int tile;       /* tile side in pixels */
	int prefetch;   /* tiles a worker asks for beyond its threads */
	int delay_us;   /* test mode: each result waits this long before it is sent */
	int threads;    /* render threads on this rank */
	bool progress;  /* rank 0: a progress line on standard error */
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
/* Whether the job's image is denoised (path mode, denoise on, as
 * render_image): its tiles then carry the features too. */
bool farm_denoises(const render_settings *s);
/* Rank 0: renders the image into fb (s->width x s->height; rgb, and feat
 * when farm_denoises and fb has it) with the workers of MPI_COMM_WORLD. */
bool farm_serve(const world *w, const render_settings *s, const farm_opts *o, framebuffer *fb,
                farm_stats *st, rt_error *err);
/* Every other rank: renders the tiles rank 0 hands out until it says none
 * are left. */
bool farm_work(const world *w, const render_settings *s, const farm_opts *o, farm_stats *st,
               rt_error *err);

#endif
