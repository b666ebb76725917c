/* rtsh-mpi — one image rendered by many processes: `mpirun -n N rtsh-mpi
 * SCENE -o OUT [options]` writes the same bytes as `rtsh SCENE -o OUT
 * [options]`.
 *
 * Rank 0 reads the command line, the scene and every file it references,
 * and broadcasts the settings and the files' bytes (fileset.h); every rank
 * builds the same world from them. Rank 0 then serves tiles from one queue
 * while rendering too, the others render the tiles they are given with all
 * their threads (farm.h), and rank 0 assembles the image and writes it
 * atomically. Every rank ends with the same exit status.
 */
#include <errno.h>
#include <math.h>
#include <mpi.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include <fcntl.h>
#include <sys/resource.h>

#include "mpi/farm.h"
#include "mpi/fileset.h"
#include "mpi/wire.h"
#include "rtsh/denoise.h"
#include "rtsh/gif.h"
#include "rtsh/image.h"
#include "rtsh/orbit.h"
#include "rtsh/render.h"
#include "rtsh/rtfile.h"
#include "rtsh/settings.h"
#include "rtsh/world.h"
#include "shell/args.h"
#include "shell/turntable.h"

#define MSG_MAX (RT_ERROR_MSG_MAX + RT_ERROR_FILE_MAX + 32)
/* MPI counts are ints: large buffers go in pieces of 1 GiB. */
#define BCAST_PIECE (1 << 30)

static void usage(FILE *f)
{
	char exts[128]; /* image.c's table of formats */
	image_extensions_join(exts, sizeof exts, "", " ", false);
	fprintf(f, "usage: mpirun -n N [--hostfile HOSTS] rtsh-mpi SCENE.rt -o OUT [OPTIONS]\n"
	      "Renders SCENE.rt to OUT (%s) across the ranks of an MPI job; the\n"
	      "output is the same, byte for byte, as `rtsh SCENE.rt -o OUT [OPTIONS]`.\n"
	      "  -v, --verbose                per-rank figures at the end: tiles, seconds,\n"
	      "                               Mrays/s, bytes sent\n"
	      "  -t N                         render threads per rank (0: the node's CPUs\n"
	      "                               shared among its ranks)\n"
	      "and rtsh's batch options:\n",
	      exts);
	args_usage(f, ARGS_BATCH, "rtsh-mpi");
	fputs("See rtsh-mpi(1).\n", f);
}

static void print_warning(void *ctx, const rt_error *w)
{
	(void)ctx;
	char buf[MSG_MAX];
	rt_error_format(w, buf, sizeof buf);
	fprintf(stderr, "%s (warning)\n", buf);
}

/* A whole number in lo..hi from the environment variable into *out, or def
 * when it is unset; false (message printed) when it is not valid. */
static bool env_number(const char *name, long def, long lo, long hi, long *out)
{
	const char *v = getenv(name);
	*out = def;
	if (!v || !*v)
		return true;
	char *end;
	long n = strtol(v, &end, 10);
	if (*end || n < lo || n > hi) {
		fprintf(stderr, "rtsh-mpi: %s=\"%s\" is not valid; expected a whole number in %ld..%ld\n",
		        name, v, lo, hi);
		return false;
	}
	*out = n;
	return true;
}

/* Under mpirun, standard error is a pipe to mpirun even when the user
 * watches a terminal: then the job's controlling terminal says so. */
static bool watched(void)
{
	if (isatty(STDERR_FILENO))
		return true;
	if (!getenv("OMPI_COMM_WORLD_SIZE"))
		return false;
	int fd = open("/dev/tty", O_WRONLY | O_NOCTTY);
	if (fd < 0)
		return false;
	close(fd);
	return true;
}

/* Whether a file can be created in path's folder (as image_write will). */
static bool folder_writable(const char *path, rt_error *err)
{
	const char *slash = strrchr(path, '/');
	char dir[4096];
	if (!slash)
		snprintf(dir, sizeof dir, ".");
	else if (slash == path)
		snprintf(dir, sizeof dir, "/");
	else
		snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
	if (access(dir, W_OK | X_OK) == 0)
		return true;
	return rt_error_at(err, path, 0, 0,
	                   "cannot create a file in that folder (%s); expected a writable folder",
	                   strerror(errno));
}

/* Rank 0: the command line, the scene and its files, the world, the image.
 * Sets c->status to an exit status when the job must not render. */
static void setup(int argc, char **argv, job_config *c, fileset *files, world **w,
                  framebuffer **fb, const char **output, int *frames, camera *cam0, vec3 *pivot)
{
	char msg[MSG_MAX];
	rt_error err;
	c->status = 2;
	/* rtsh-mpi's own option -v, and its own help; the rest are rtsh's */
	char **args = calloc((size_t)argc + 1, sizeof *args);
	if (!args) {
		fputs("rtsh-mpi: out of memory\n", stderr);
		c->status = 1;
		return;
	}
	int n = 0;
	bool dashdash = false;
	for (int i = 0; i < argc; i++) {
		const char *a = argv[i];
		if (i > 0 && !dashdash && (strcmp(a, "-v") == 0 || strcmp(a, "--verbose") == 0)) {
			c->verbose = 1;
			continue;
		}
		if (i > 0 && !dashdash && (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0)) {
			usage(stdout);
			c->status = 0;
			goto out;
		}
		if (strcmp(a, "--") == 0)
			dashdash = true;
		args[n++] = argv[i];
	}
	rtsh_options o;
	int rc = args_parse(n, args, ARGS_BATCH, "rtsh-mpi", &o);
	if (rc >= 0) {
		c->status = rc;
		goto out;
	}
	*frames = o.turntable ? o.turntable_frames : 0;
	if (o.turntable && !turntable_output_ok(o.output)) {
		fprintf(stderr, "rtsh-mpi: --turntable: output \"%s\" is neither a .gif nor a numbered image name; "
		        "expected spin.gif or a name with one %%d such as frame%%03d.png\n"
		        "Try 'rtsh-mpi --help' for more information.\n", o.output);
		goto out;
	}
	if (!o.turntable && !image_type_of(o.output)) {
		char exts[128];
		image_extensions(exts, sizeof exts, false);
		fprintf(stderr, "rtsh-mpi: output \"%s\" has an unknown type; expected %s\n"
		        "Try 'rtsh-mpi --help' for more information.\n", o.output, exts);
		goto out;
	}
	long tile, prefetch, delay; /* tile 0: auto_tile; prefetch -1: half the threads, at least 2 */
	if (!env_number("RTSH_MPI_TILE", 0, 4, 1024, &tile) ||
	    !env_number("RTSH_MPI_PREFETCH", -1, 0, 1024, &prefetch) ||
	    !env_number("RTSH_MPI_DELAY_US", 0, 0, 10000000, &delay))
		goto out;
	c->tile = (int32_t)tile;
	c->prefetch = (int32_t)prefetch;
	c->delay_us = (int32_t)delay;
	c->strict = o.strict;

	c->status = 1;
	rt_warnings warn = {print_warning, NULL};
	rt_load_opts lo = {.strict = o.strict, .warn = o.quiet ? NULL : &warn,
	                   .read = fileset_record, .read_ctx = files};
	/* the models, textures and sky, read while loading and building */
	static rt_file_source src;
	src = fileset_source(files, true);
	rt_file_source_set(&src);
	scene *s = rt_load_file(o.scene, &lo, &err);
	if (!s) {
		rt_error_format(&err, msg, sizeof msg);
		fprintf(stderr, "%s\n", msg);
		goto out;
	}
	c->set = render_settings_default();
	bool clamped = render_settings_apply_hints(&c->set, &s->hints);
	int cw = c->set.width, ch = c->set.height;
	options_apply_settings(&o, &c->set);
	/* Said only when the clamped size is the one rendered (not -r's). */
	if (clamped && c->set.width == cw && c->set.height == ch && !o.quiet)
		fprintf(stderr, "%s: resolution %dx%d is too large; rendering %dx%d (use -r to choose)\n",
		        o.scene, s->hints.width, s->hints.height, c->set.width, c->set.height);
	*cam0 = scene_camera(s);
	*pivot = orbit_scene_centre(s);
	*w = world_build(s, &err);
	scene_free(s);
	rt_file_source_set(NULL);
	if (!*w) {
		rt_error_format(&err, msg, sizeof msg);
		fprintf(stderr, "%s: %s\n", o.scene, msg);
		goto out;
	}
	/* An hour's render must not end in a folder that cannot take the file:
	 * check it now, in the words the final write would use. */
	if (!folder_writable(o.output, &err)) {
		rt_error_format(&err, msg, sizeof msg);
		fprintf(stderr, "%s\n", msg);
		goto out;
	}
	*fb = fb_new(c->set.width, c->set.height);
	if (!*fb) {
		fprintf(stderr, "%s: cannot make a %dx%d image; expected 1..%d pixels a side, and memory\n",
		        o.scene, c->set.width, c->set.height, RENDER_MAX_DIM);
		goto out;
	}
	if (farm_first(&c->set) == c->set.samples) {
		free((*fb)->sum); /* one pass: no running sums, as render_image */
		(*fb)->sum = NULL;
	}
	if (farm_denoises(&c->set) && !denoise_prepare(*fb)) {
		fprintf(stderr, "%s: out of memory for the denoiser's features of a %dx%d image\n", o.scene,
		        c->set.width, c->set.height);
		fb_free(*fb);
		*fb = NULL;
		goto out;
	}
	free((*fb)->sum2); /* the first pass's sums of squares: in its features */
	(*fb)->sum2 = NULL;
	c->progress = !o.quiet && watched();
	*output = o.output;
	c->status = -1;
out:
	rt_file_source_set(NULL);
	free(args);
}

/* Waits for a request, sleeping between tests: Open MPI's blocking calls
 * spin, and a rank waiting for rank 0 (while it reads the scene, or renders
 * its last tiles) must not take a core from it. */
static void wait_for(MPI_Request *req)
{
	long nap = 50;
	for (;;) {
		int flag = 0;
		MPI_Test(req, &flag, MPI_STATUS_IGNORE);
		if (flag)
			return;
		struct timespec t = {0, nap * 1000};
		nanosleep(&t, NULL);
		if (nap < 2000)
			nap *= 2;
	}
}

/* One farmed pass (fo->pass); its figures added to *st (first: set). */
static bool farm_pass(int rank, const world *w, const render_settings *s, const farm_opts *fo, framebuffer *fb,
                      farm_stats *st, bool first, rt_error *err)
{
	farm_stats f;
	bool ok = rank == 0 ? farm_serve(w, s, fo, fb, &f, err) : farm_work(w, s, fo, &f, err);
	if (first) {
		*st = f;
	} else {
		st->rtt = (st->rtt * st->tiles + f.rtt * f.tiles) / fmax(st->tiles + f.tiles, 1.0);
		st->tiles += f.tiles;
		st->seconds += f.seconds;
		st->busy += f.busy;
		st->rays += f.rays;
		st->bytes += f.bytes;
		st->serve += f.serve;
	}
	return ok;
}

/* Renders a frame into fb on rank 0 with every rank: one pass of the farm,
 * or a denoised image's two (farm.h), as render_image makes it, to the
 * same bits: the first samples in every pixel, rank 0's allocation of the
 * rest from the whole image (render_adaptive_counts), told to every rank
 * (its most: whether there is a second pass), and the adaptive pass.
 * The figures are added to *st (set by a turntable's first frame), so that
 * -v reports the whole job. */
static bool render_frame(int rank, const world *w, const render_settings *s, farm_opts *fo, framebuffer *fb,
                         farm_stats *st, bool first_frame, rt_error *err)
{
	int first = farm_first(s);
	fo->first = first;
	fo->t0 = farm_clock();
	fo->pass = first < s->samples ? FARM_FIRST : FARM_ONE;
	if (!farm_pass(rank, w, s, fo, fb, st, first_frame, err))
		return false;
	if (fo->pass == FARM_ONE)
		return true;
	int most = 0;
	if (rank == 0) {
		fb->spp = first;
		most = render_adaptive_counts(fb, s->samples, first, err);
		if (most < 0)
			return false;
	}
	/* every rank done with the first pass before any asks for a tile of
	 * the second */
	MPI_Request b;
	MPI_Ibcast(&most, 1, MPI_INT, 0, MPI_COMM_WORLD, &b);
	wait_for(&b);
	if (most > first) {
		fo->pass = FARM_ADAPTIVE;
		return farm_pass(rank, w, s, fo, fb, st, false, err);
	}
	/* no pixel takes more (render_adaptive: no second pass): the first
	 * pass's means, as a render job writes them */
	if (rank == 0)
		for (size_t i = 0; i < (size_t)fb->w * (size_t)fb->h * 3; i++)
			fb->rgb[i] = (float)(fb->sum[i] * (1.0 / first));
	return true;
}

static void bcast(void *buf, int count, MPI_Datatype type)
{
	MPI_Request r;
	MPI_Ibcast(buf, count, type, 0, MPI_COMM_WORLD, &r);
	wait_for(&r);
}

static void gather(const void *mine, void *all, int bytes)
{
	MPI_Request r;
	MPI_Igather(mine, bytes, MPI_BYTE, all, bytes, MPI_BYTE, 0, MPI_COMM_WORLD, &r);
	wait_for(&r);
}

/* Broadcasts size bytes from rank 0 in pieces an int can count. */
static void bcast_bytes(char *buf, uint64_t size)
{
	for (uint64_t at = 0; at < size; at += BCAST_PIECE) {
		uint64_t left = size - at;
		bcast(buf + at, (int)(left < BCAST_PIECE ? left : BCAST_PIECE), MPI_BYTE);
	}
}

/* The render threads of this rank: -t, or the node's CPUs shared among the
 * ranks on the node. */
static int rank_threads(const render_settings *s)
{
	if (s->threads > 0)
		return s->threads;
	MPI_Comm node;
	int here = 1;
	if (MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node) ==
	    MPI_SUCCESS) {
		MPI_Comm_size(node, &here);
		MPI_Comm_free(&node);
	}
	int cpus = render_threads(s);
	return cpus / here > 1 ? cpus / here : 1;
}

/* Who each rank is, for the message about a rank that ended. */
typedef struct rank_id {
	int32_t pid;
	char host[64];
} rank_id;

/* What rank 0's SIGTERM/SIGINT handler reads: set before it is installed
 * (output) or published once complete (ids, by the atomic store). */
static const char *stop_output;
static rank_id *stop_ids;
static _Atomic int stop_nids;
static _Atomic int stop_progress; /* a progress line is open: end it first */
static _Atomic int stop_written;  /* the image (every frame) is on disk, complete */

static void put(char *buf, size_t *n, size_t cap, const char *s)
{
	while (*s && *n < cap)
		buf[(*n)++] = *s++;
}

static void put_int(char *buf, size_t *n, size_t cap, int v)
{
	char d[16];
	int k = 0;
	do
		d[k++] = (char)('0' + v % 10);
	while ((v /= 10) > 0 && k < 15);
	while (k > 0 && *n < cap)
		buf[(*n)++] = d[--k];
}

/* Rank 0, on the launcher's SIGTERM (sent to every rank when one dies, and
 * on Ctrl-C at mpirun) or SIGINT: says which ranks on its host are gone
 * (those on other hosts it cannot see) and that no image was written, then
 * ends by the signal. The launcher follows with SIGKILL within about a
 * second and rank 0 may be inside a blocking MPI call, so this is done here,
 * with async-signal-safe calls only (kill, write, strcmp, raise, alarm). */
static _Atomic int stop_rank = -1; /* this process's rank once known */

static void on_stop(int sig)
{
	int me = atomic_load(&stop_rank);
	if (me > 0) {
		/* another rank: end quietly, but a second later (SIGALRM's
		 * default action), so that rank 0 speaks first: the launcher
		 * takes a rank that ends at once for a new failure and may
		 * kill rank 0 before it has run this handler */
		alarm(1);
		return;
	}
	if (me != 0) {
		/* MPI not started yet, or all is said: end quietly */
		signal(sig, SIG_DFL);
		raise(sig);
		return;
	}
	char buf[4096];
	size_t n = 0, cap = sizeof buf;
	if (atomic_load(&stop_progress))
		put(buf, &n, cap, "\n");
	int named = 0, nids = atomic_load(&stop_nids);
	for (int r = 1; r < nids; r++)
		if (strcmp(stop_ids[r].host, stop_ids[0].host) == 0 && kill(stop_ids[r].pid, 0) != 0 &&
		    errno == ESRCH) {
			put(buf, &n, cap, "rtsh-mpi: rank ");
			put_int(buf, &n, cap, r);
			put(buf, &n, cap, " on ");
			put(buf, &n, cap, stop_ids[r].host);
			put(buf, &n, cap, " ended before the image was complete\n");
			named++;
		}
	if (!named)
		put(buf, &n, cap, sig == SIGINT ? "rtsh-mpi: interrupted before the image was complete\n"
		                                : "rtsh-mpi: stopped before the image was complete "
		                                  "(interrupted, or a rank on another host ended)\n");
	put(buf, &n, cap, "rtsh-mpi: ");
	put(buf, &n, cap, stop_output ? stop_output : "the image");
	put(buf, &n, cap, atomic_load(&stop_written) ? " was written and is complete\n" : " not written\n");
	ssize_t wr = write(STDERR_FILENO, buf, n);
	(void)wr;
	signal(sig, SIG_DFL);
	raise(sig);
}

/* A rank's host, for rank 0's messages (farm_opts.host). */
static const char *host_of(int rank)
{
	return stop_ids && rank >= 0 && rank < atomic_load(&stop_nids) ? stop_ids[rank].host : "?";
}

/* Rank 0: what is on disk so far, for the message when a wait expires
 * ("" until something is written). */
static char end_written[4200];

/* The end of a frame and of the job, as messages between rank 0 and each
 * worker on a communicator of their own (farm_serve's probe never sees
 * them), so that rank 0 can wait for each with a time limit and name the
 * rank it waits for: a rank stopped once it has no tile left (SIGSTOP, a
 * frozen host) is beyond the farm's deadline, and a collective (gather,
 * broadcast, barrier, MPI_Finalize) would wait for it for ever.
 *   worker -> 0   END_DONE     int32 frame: done with that frame (turntable)
 *   0 -> worker   END_GO       int32 frame: the next frame may be asked for
 *   worker -> 0   END_STATS    its farm_stats, as bytes
 *   0 -> worker   END_STATUS   int32 the job's exit status
 *   worker -> 0   END_FIN      int32 0: about to call MPI_Finalize */
enum { END_DONE = 1, END_GO, END_STATS, END_STATUS, END_FIN };
static MPI_Comm end_comm = MPI_COMM_NULL;
static double end_deadline = 30; /* rank 0: RTSH_MPI_DEADLINE */

/* Rank 0: says that a rank did not answer and what was written, and ends
 * the job with status 1. */
static void end_late(const char *host, int r, const char *what, double waited)
{
	fprintf(stderr,
	        "rtsh-mpi: rank 0 on %s: rank %d on %s did not %s within %.0f s (stopped, or its host hangs; "
	        "RTSH_MPI_DEADLINE=%g); %s\n",
	        host, r, host_of(r), what, waited, end_deadline,
	        end_written[0] ? end_written : "the image was not written");
	fflush(stderr);
	atomic_store(&stop_rank, -1); /* all said: the launcher's SIGTERM ends us quietly */
	MPI_Abort(MPI_COMM_WORLD, 1);
}

/* Rank 0: waits for reqs[0..n-1], one for each of the ranks 1..n, sleeping
 * between tests as wait_for; after end_deadline seconds, names the first
 * rank whose request is not done (end_late). */
static void end_wait(MPI_Request *reqs, int n, const char *host, const char *what)
{
	double t0 = MPI_Wtime();
	long nap = 50;
	int *done = malloc((size_t)(n > 0 ? n : 1) * sizeof *done);
	if (!done) {
		fputs("rtsh-mpi: out of memory\n", stderr);
		MPI_Abort(MPI_COMM_WORLD, 1);
	}
	for (;;) {
		int k = 0;
		MPI_Testsome(n, reqs, &k, done, MPI_STATUSES_IGNORE);
		if (k == MPI_UNDEFINED) /* every request done (MPI_REQUEST_NULL) */
			break;
		if (MPI_Wtime() - t0 > end_deadline) {
			int r = 1;
			while (r < n && reqs[r - 1] == MPI_REQUEST_NULL)
				r++;
			end_late(host, r, what, MPI_Wtime() - t0);
		}
		struct timespec t = {0, nap * 1000};
		nanosleep(&t, NULL);
		if (nap < 2000)
			nap *= 2;
	}
	free(done);
}

/* Rank 0: receives (recv) or sends count bytes at buf + r * stride with
 * tag from or to every rank r in 1..size-1, within end_deadline. */
static void end_each(bool recv, char *buf, size_t stride, int count, int tag, int size, const char *host,
                     const char *what)
{
	if (size < 2)
		return;
	MPI_Request *reqs = malloc((size_t)(size - 1) * sizeof *reqs);
	if (!reqs) {
		fputs("rtsh-mpi: out of memory\n", stderr);
		MPI_Abort(MPI_COMM_WORLD, 1);
	}
	for (int r = 1; r < size; r++) {
		char *p = buf + (size_t)r * stride;
		if (recv)
			MPI_Irecv(p, count, MPI_BYTE, r, tag, end_comm, &reqs[r - 1]);
		else
			MPI_Isend(p, count, MPI_BYTE, r, tag, end_comm, &reqs[r - 1]);
	}
	end_wait(reqs, size - 1, host, what);
	free(reqs);
}

/* A worker: sends or receives count bytes with tag to or from rank 0 (no
 * time limit: rank 0 has one, and ends the job). */
static void end_one(bool recv, void *buf, int count, int tag)
{
	MPI_Request r;
	if (recv)
		MPI_Irecv(buf, count, MPI_BYTE, 0, tag, end_comm, &r);
	else
		MPI_Isend(buf, count, MPI_BYTE, 0, tag, end_comm, &r);
	wait_for(&r);
}

/* Rank 0, around MPI_Finalize: every rank has said it is about to call it
 * (END_FIN), but one stopped in between would hold it for ever. This
 * thread ends the process (status 1; the launcher then ends the rest) if
 * MPI_Finalize has not returned within the deadline. */
static char finalize_msg[4400];

static void *finalize_watch(void *arg)
{
	(void)arg;
	struct timespec t = {(time_t)end_deadline, 0};
	while (nanosleep(&t, &t) != 0 && errno == EINTR)
		;
	ssize_t wr = write(STDERR_FILENO, finalize_msg, strlen(finalize_msg));
	(void)wr;
	_exit(1);
	return NULL;
}

/* The tile side when RTSH_MPI_TILE does not set one: 32 pixels, halved
 * (down to 8) until there are at least 8 tiles for every render thread of
 * the job, so that the last wave of tiles is a small part of the render
 * (bench/README.md has the model). */
static int auto_tile(int w, int h, long threads)
{
	int s = 32;
	while (s > 8 && (long)((w + s - 1) / s) * (long)((h + s - 1) / s) < 8 * threads)
		s /= 2;
	return s;
}

/* Ends the whole job from any rank with one message. */
static void die(int rank, const char *host, const char *what, const rt_error *err)
{
	char msg[MSG_MAX];
	rt_error_format(err, msg, sizeof msg);
	fprintf(stderr, "rtsh-mpi: rank %d on %s: %s%s%s\n", rank, host, what, *what ? ": " : "", msg);
	if (rank == 0) {
		/* --turntable: the frames kept so far; then all is said, and the
		 * launcher's SIGTERM ends rank 0 quietly */
		if (end_written[0])
			fprintf(stderr, "rtsh-mpi: %s\n", end_written);
		atomic_store(&stop_rank, -1);
	}
	fflush(stderr);
	MPI_Abort(MPI_COMM_WORLD, 1);
}

static void print_figures(const farm_stats *st, int size, const job_config *c, double total)
{
	double tiles = 0, rays = 0, bytes = 0;
	fprintf(stderr, "%-5s %-16s %7s %7s %8s %8s %9s %11s %9s %9s\n", "rank", "host", "threads",
	        "tiles", "seconds", "busy", "Mrays/s", "bytes sent", "rtt (us)", "peak MiB");
	for (int r = 0; r < size; r++) {
		const farm_stats *f = &st[r];
		double cap = f->seconds * f->threads;
		fprintf(stderr, "%-5d %-16.16s %7d %7.0f %8.2f %7.0f%% %9.2f %11.0f %9.0f %9.0f\n", r,
		        f->host, f->threads, f->tiles, f->seconds, cap > 0 ? 100.0 * f->busy / cap : 0.0,
		        f->seconds > 0 ? f->rays / f->seconds * 1e-6 : 0.0, f->bytes, f->rtt * 1e6,
		        f->peak / 1048576.0);
		tiles += f->tiles;
		rays += f->rays;
		bytes += f->bytes;
	}
	/* the tiles' count first (bench/mpi.sh reads the seconds after it) */
	fprintf(stderr, "all   %d ranks, %.0f tiles of %dx%d, %.2f s, %.2f Mrays/s, %.0f bytes sent%s\n", size, tiles,
	        c->tile, c->tile, total, total > 0 ? rays / total * 1e-6 : 0.0, bytes,
	        farm_first(&c->set) < c->set.samples ? " in two passes" : "");
	double remote = tiles - st[0].tiles;
	if (remote > 0)
		fprintf(stderr, "rank 0 served %.0f tiles to the others with %.1f us of CPU each\n", remote,
		        st[0].serve / remote * 1e6);
}

int main(int argc, char **argv)
{
	int provided, rank, size;
	struct sigaction sa;
	memset(&sa, 0, sizeof sa);
	sa.sa_handler = on_stop;
	sigemptyset(&sa.sa_mask);
	sigaction(SIGTERM, &sa, NULL);
	sigaction(SIGINT, &sa, NULL);
	MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
	MPI_Comm_rank(MPI_COMM_WORLD, &rank);
	atomic_store(&stop_rank, rank);
	MPI_Comm_size(MPI_COMM_WORLD, &size);
	MPI_Comm_dup(MPI_COMM_WORLD, &end_comm);
	char host[64] = "?";
	int hl;
	char name[MPI_MAX_PROCESSOR_NAME];
	if (MPI_Get_processor_name(name, &hl) == MPI_SUCCESS)
		snprintf(host, sizeof host, "%.63s", name);

	job_config c;
	memset(&c, 0, sizeof c);
	fileset files = {0};
	world *w = NULL;
	framebuffer *fb = NULL;
	const char *output = NULL;
	char *packed = NULL;
	size_t packed_size = 0;
	int frames = 0;  /* --turntable FRAMES: frames of a turn (0: one image) */
	camera cam0;
	vec3 pivot = v3(0, 0, 0);
	memset(&cam0, 0, sizeof cam0);
	if (rank == 0) {
		setup(argc, argv, &c, &files, &w, &fb, &output, &frames, &cam0, &pivot);
		stop_output = output;
		atomic_store(&stop_progress, c.progress);
		if (c.status < 0) {
			packed = fileset_pack(&files, &packed_size);
			if (!packed) {
				fputs("rtsh-mpi: out of memory packing the scene's files\n", stderr);
				c.status = 1;
			}
			c.files = packed_size;
		}
	}
	/* the configuration, field by field (wire.h): every rank, rank 0 too,
	 * works from the decoded values */
	unsigned char wire[WIRE_CONFIG_SIZE];
	if (rank == 0)
		wire_put_config(&c, wire);
	bcast(wire, WIRE_CONFIG_SIZE, MPI_BYTE);
	int32_t nframes = frames;
	bcast(&nframes, 1, MPI_INT32_T);
	frames = nframes;
	char why[RT_ERROR_MSG_MAX];
	if (!wire_get_config(&c, wire, why, sizeof why)) {
		rt_error e;
		rt_error_set(&e, "%s", why);
		die(rank, host, "", &e);
	}
	if (c.status >= 0) {
		/* a usage or scene error: rank 0 said it once; all end alike (and
		 * the launcher may stop the last ones: quietly) */
		atomic_store(&stop_rank, -1);
		world_free(w);
		fb_free(fb);
		fileset_free(&files);
		MPI_Finalize();
		return c.status;
	}
	double t0 = MPI_Wtime();
	rt_error err;
	rank_id me = {(int32_t)getpid(), {0}}, *ids = rank == 0 ? calloc((size_t)size, sizeof *ids) : NULL;
	memcpy(me.host, host, sizeof me.host);
	gather(&me, ids, (int)sizeof me);
	if (rank == 0 && ids) {
		stop_ids = ids;
		atomic_store(&stop_nids, size);
	}
	if (rank != 0) {
		packed = malloc(c.files ? c.files : 1);
		if (!packed) {
			rt_error_set(&err, "out of memory for the scene's %llu bytes",
			             (unsigned long long)c.files);
			die(rank, host, "", &err);
		}
	}
	bcast_bytes(packed, c.files);
	if (rank != 0) {
		rt_load_opts lo = {.strict = c.strict, .read = fileset_serve, .read_ctx = &files};
		rt_file_source src = fileset_source(&files, false);
		rt_file_source_set(&src);
		if (!fileset_unpack(&files, packed, c.files) || files.n == 0) {
			rt_error_set(&err, "the scene's files arrived damaged or memory ran out");
			die(rank, host, "", &err);
		}
		scene *s = rt_load_file(files.files[0].path, &lo, &err);
		if (!s)
			die(rank, host, "loading the scene rank 0 sent", &err);
		cam0 = scene_camera(s);
		pivot = orbit_scene_centre(s);
		w = world_build(s, &err);
		scene_free(s);
		rt_file_source_set(NULL);
		if (!w)
			die(rank, host, "building the world", &err);
	}
	free(packed);
	fileset_free(&files);

	int threads = rank_threads(&c.set);
	long all_threads = threads, mine = threads;
	MPI_Request ar;
	MPI_Iallreduce(&mine, &all_threads, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD, &ar);
	wait_for(&ar);
	if (c.tile == 0)
		c.tile = auto_tile(c.set.width, c.set.height, all_threads);
	/* rank 0 alone reads the floor of the deadline for a silent rank */
	long deadline = 30;
	if (rank == 0 && !env_number("RTSH_MPI_DEADLINE", 30, 1, 86400, &deadline)) {
		rt_error_set(&err, "RTSH_MPI_DEADLINE is not valid");
		die(rank, host, "", &err);
	}
	end_deadline = (double)deadline;
	farm_opts fo = {
		.deadline = (double)deadline,
		.host = host_of,
		.tile = c.tile,
		.prefetch = c.prefetch >= 0 ? c.prefetch : threads / 2 > 2 ? threads / 2 : 2,
		.delay_us = c.delay_us,
		.threads = threads,
		.progress = c.progress != 0,
	};
	farm_stats st;
	int status = 0;
	/* --turntable: every frame is one farmed render job, the world's camera
	 * turned between them as rtsh turns it (orbit_turntable). */
	gif_anim *g = rank == 0 && frames > 0 && turntable_is_gif(output)
	                  ? gif_new(c.set.width, c.set.height,
	                            TURNTABLE_TURN_CS / frames > TURNTABLE_MIN_CS ? TURNTABLE_TURN_CS / frames
	                                                                          : TURNTABLE_MIN_CS)
	                  : NULL;
	if (rank == 0 && frames > 0 && turntable_is_gif(output) && !g) {
		rt_error_set(&err, "out of memory for a %dx%d GIF", c.set.width, c.set.height);
		die(rank, host, "", &err);
	}
	for (int k = 0; k < (frames > 0 ? frames : 1); k++) {
		if (frames > 0) {
			camera ck = orbit_turntable(cam0, pivot, k, frames);
			w->cam = cam_view_make(&ck);
		}
		if (!render_frame(rank, w, &c.set, &fo, fb, &st, k == 0, &err))
			die(rank, host, "", &err);
		if (rank == 0 && fb->feat) {
			/* --denoise: the whole frame, as rtsh denoises its image */
			fb->spp = c.set.samples;
			if (!denoise_image(fb, fb->rgb, threads)) {
				rt_error_set(&err, "out of memory denoising a %dx%d image", fb->w, fb->h);
				die(rank, host, "", &err);
			}
		}
		if (rank == 0 && frames > 0 && status == 0) {
			/* the frame is kept before any wait for the others */
			char fname[4096];
			if (g) {
				if (!gif_add_linear(g, fb->rgb, c.set.exposure)) {
					fputs("rtsh-mpi: out of memory for the GIF\n", stderr);
					status = 1;
				}
			} else if (turntable_name(output, k, fname, sizeof fname)) {
				if (!image_write(fname, fb, c.set.exposure, &err)) {
					char msg[MSG_MAX];
					rt_error_format(&err, msg, sizeof msg);
					fprintf(stderr, "%s\n", msg);
					status = 1;
				} else {
					snprintf(end_written, sizeof end_written,
					         "%d of %d frames were written (the last %s), the others not", k + 1,
					         frames, fname);
				}
			}
		}
		if (frames > 1 && k + 1 < frames) {
			/* every rank done with this frame before any asks for tiles
			 * of the next: rank 0 serves one frame at a time */
			int32_t fk = k;
			if (rank == 0) {
				int32_t *each = calloc((size_t)size, sizeof *each);
				if (!each) {
					rt_error_set(&err, "out of memory");
					die(rank, host, "", &err);
				}
				char what[64];
				snprintf(what, sizeof what, "end frame %d of %d", k + 1, frames);
				end_each(true, (char *)each, sizeof *each, (int)sizeof *each, END_DONE, size, host, what);
				for (int r = 0; r < size; r++)
					each[r] = fk;
				end_each(false, (char *)each, sizeof *each, (int)sizeof *each, END_GO, size, host,
				         "take the next frame");
				free(each);
			} else {
				end_one(false, &fk, (int)sizeof fk, END_DONE);
				end_one(true, &fk, (int)sizeof fk, END_GO);
			}
		}
	}
	atomic_store(&stop_progress, 0);
	memcpy(st.host, host, sizeof st.host);
	struct rusage ru;
	if (getrusage(RUSAGE_SELF, &ru) == 0)
		st.peak = (double)ru.ru_maxrss * 1024.0; /* Linux: KiB */
	if (rank == 0)
		st.bytes += (double)c.files * (size > 1);
	world_free(w);
	/* The end of the job: rank 0 writes the image first, then waits, each
	 * wait with a time limit (end_each), for every rank's figures, gives
	 * the exit status and hears that each rank is about to end. */
	farm_stats *all = NULL;
	if (rank == 0) {
		double rendered = MPI_Wtime() - t0;
		if (status == 0 && g && !gif_save(g, output, &err)) {
			char msg[MSG_MAX];
			rt_error_format(&err, msg, sizeof msg);
			fprintf(stderr, "%s\n", msg);
			status = 1;
		} else if (status == 0 && g) {
			snprintf(end_written, sizeof end_written, "%s was written and is complete, but the job did "
			         "not end cleanly", output);
			atomic_store(&stop_written, 1);
		}
		if (frames == 0 && !image_write(output, fb, c.set.exposure, &err)) {
			char msg[MSG_MAX];
			rt_error_format(&err, msg, sizeof msg);
			fprintf(stderr, "%s\n", msg);
			status = 1;
		} else if (frames == 0) {
			snprintf(end_written, sizeof end_written, "%s was written and is complete, but the job did "
			         "not end cleanly", output);
			atomic_store(&stop_written, 1);
		} else if (!g && status == 0) {
			snprintf(end_written, sizeof end_written, "all %d frames were written (%s...) and are "
			         "complete, but the job did not end cleanly", frames, output);
			atomic_store(&stop_written, 1);
		}
		all = calloc((size_t)size, sizeof *all);
		if (!all) {
			fputs("rtsh-mpi: out of memory\n", stderr);
			MPI_Abort(MPI_COMM_WORLD, 1);
		}
		all[0] = st;
		end_each(true, (char *)all, sizeof *all, (int)sizeof *all, END_STATS, size, host,
		         "send its figures at the end of the job");
		if (c.verbose)
			print_figures(all, size, &c, rendered);
		int32_t *each = calloc((size_t)size, sizeof *each);
		if (!each) {
			fputs("rtsh-mpi: out of memory\n", stderr);
			MPI_Abort(MPI_COMM_WORLD, 1);
		}
		for (int r = 0; r < size; r++)
			each[r] = status;
		end_each(false, (char *)each, sizeof *each, (int)sizeof *each, END_STATUS, size, host,
		         "take the exit status");
		end_each(true, (char *)each, sizeof *each, (int)sizeof *each, END_FIN, size, host,
		         "end (after the exit status)");
		free(each);
		/* said once every rank has said it ends */
		if (status == 0 && c.progress)
			fprintf(stderr, "wrote %s (%dx%d, %d samples, %s) on %d ranks in %.2fs\n", output,
			        c.set.width, c.set.height, c.set.samples, render_mode_name(c.set.mode), size,
			        MPI_Wtime() - t0);
	} else {
		end_one(false, &st, (int)sizeof st, END_STATS);
		int32_t s32 = 0;
		end_one(true, &s32, (int)sizeof s32, END_STATUS);
		status = s32;
		int32_t fin = 0;
		end_one(false, &fin, (int)sizeof fin, END_FIN);
	}
	free(all);
	gif_free(g);
	atomic_store(&stop_nids, 0);
	fb_free(fb);
	if (rank == 0) {
		/* every rank is about to end; one stopped before MPI_Finalize
		 * would still hold it: finalize_watch */
		snprintf(finalize_msg, sizeof finalize_msg,
		         "rtsh-mpi: rank 0 on %s: a rank did not end within %.0f s (stopped, or its host hangs; "
		         "RTSH_MPI_DEADLINE=%g); %s\n",
		         host, end_deadline, end_deadline, end_written[0] ? end_written : "the image was not written");
		pthread_t tid;
		if (pthread_create(&tid, NULL, finalize_watch, NULL) == 0)
			pthread_detach(tid);
	}
	free(ids);
	atomic_store(&stop_rank, -1); /* all said: the launcher may stop us quietly */
	MPI_Finalize();
	return status;
}
