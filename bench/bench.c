/* rtsh — the benchmark (`make bench`, `make bench-quick`).
 *
 * Prints one table and writes it as TSV (--out FILE): scene, mode,
 * resolution, samples, threads, runs, the median wall time over the runs,
 * Mrays/s and a note. Rows:
 *   grid.rt at 1920x1080, 1 sample, 1 and 2 threads, and POV-Ray 3.7 on its
 *     twin bench/grid.pov in the same run (interleaved) when `povray` is
 *     installed;
 *   primary rays on the grid (camera rays and world_intersect only, 1
 *     thread), the same by brute force, and Embree 3's rtcIntersect1 on the
 *     same rays when bench/embree_primary was built;
 *   generated spheres-only scenes of 10, 1k, 100k and 1M spheres at one view,
 *     1 and 2 threads; their world_build time and memory per object; the
 *     rays alone at 1k and 1M (camera and shadow packets) beside Embree's;
 *     the load time of the 1M scene saved as .rt;
 *   the Whitted preview frame (160x96 pixels, showcase.rt) and the bytes of
 *     the terminal frame that shows it;
 *   key mode (`view`): the time from a key to the first updated frame on
 *     showcase.rt at 160x48 cells (bench_keymode).
 * A render row's Mrays/s counts every ray the integrator traced (camera,
 * shadow and reflection rays, counted in one extra 1-thread pass); the
 * primary-ray rows count camera rays only. Times are medians: the machine is
 * shared, so compare rows of the same run. --quick runs small sizes once, as
 * a smoke test for CI. Nothing here asserts a time.
 */
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "core/bvh/bvh.h"
#include "rtsh/denoise.h"
#include "mesh_rays.h"
#include "rtsh/mesh.h"
#include "rtsh/packet.h"
#include "rtsh/generate.h"
#include "rtsh/render.h"
#include "rtsh/rtfile.h"
#include "rtsh/world.h"
#include "shell/keymode.h"
#include "shell/options.h"
#include "term/encoder.h"
#include "term/frame.h"
#include "term/keys.h"
#include "term/pixels.h"
#include "term/symbols.h"

#include "symbols_quality.h"

#define MAX_RUNS 101
#define MAX_ROWS 128

typedef struct row {
	char scene[48];
	char mode[24];
	char res[16];
	int samples, threads, runs;
	double seconds; /* median; < 0: none */
	double mrays;   /* < 0: none */
	char note[160];
} row;

static row rows[MAX_ROWS];
static int nrows;
static bool quick, no_povray;
static int runs = 5;
static const char *bench_dir = "build/bench"; /* where embree_primary lives */
static char rtsh_bin[1100] = "./rtsh";         /* the binary of this build */
static char out_ppm[64];                        /* images of the process rows */

static double now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* The process's CPU time: the triangle rows time one thread on both sides
 * (rtsh and the Embree harness) by it, so a loaded machine (other jobs
 * taking the cores) slows neither side's figure. */
static double cpu_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
	return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static int cmp_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return x < y ? -1 : x > y;
}

static double median(double *v, int n)
{
	if (n <= 0)
		return -1;
	qsort(v, (size_t)n, sizeof *v, cmp_double);
	return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

static row *add_row(const char *name, const char *mode, int w, int h, int samples, int threads, int nruns,
                    double seconds, double mrays)
{
	if (nrows == MAX_ROWS)
		return &rows[MAX_ROWS - 1];
	row *r = &rows[nrows++];
	memset(r, 0, sizeof *r);
	snprintf(r->scene, sizeof r->scene, "%s", name);
	snprintf(r->mode, sizeof r->mode, "%s", mode);
	if (w > 0)
		snprintf(r->res, sizeof r->res, "%dx%d", w, h);
	else
		snprintf(r->res, sizeof r->res, "-");
	r->samples = samples;
	r->threads = threads;
	r->runs = nruns;
	r->seconds = seconds;
	r->mrays = mrays;
	fprintf(stderr, "  %-22s %-16s %-10s %2d thr  %10.4f s  %8.2f Mrays/s\n", name, mode, r->res, threads,
	        seconds, mrays);
	return r;
}

static void fail(const char *what, const rt_error *err)
{
	fprintf(stderr, "bench: %s: %s\n", what, err ? err->msg : strerror(errno));
	exit(1);
}

static scene *load(const char *path)
{
	rt_error err;
	scene *s = rt_load_file(path, NULL, &err);
	if (!s) {
		char buf[RT_ERROR_MSG_MAX + RT_ERROR_FILE_MAX + 32];
		rt_error_format(&err, buf, sizeof buf);
		fprintf(stderr, "bench: %s\n", buf);
		exit(1);
	}
	return s;
}

static world *build_threads(const scene *s, int threads)
{
	rt_error err;
	world *w = world_build_threads(s, threads, NULL, &err);
	if (!w)
		fail("world_build", &err);
	return w;
}

static world *build(const scene *s)
{
	return build_threads(s, 1);
}

static render_settings settings(int w, int h, int threads)
{
	render_settings set = render_settings_default();
	set.width = w;
	set.height = h;
	set.samples = 1;
	set.threads = threads;
	return set;
}

/* One render of every pixel into fb (cleared first); seconds. */
static double render_once(const world *w, const render_settings *set, framebuffer *fb)
{
	fb_clear(fb);
	render_job job = {.w = w, .set = *set, .fb = fb, .sample_begin = 0, .sample_end = set->samples};
	rt_error err;
	double t0 = now();
	if (render_run(&job, &err) != RENDER_DONE)
		fail("render", &err);
	return now() - t0;
}

/* Every ray one render traces: a 1-thread render runs in this thread, whose
 * counter world_rays_traced reads. */
static uint64_t count_rays(const world *w, render_settings set, framebuffer *fb)
{
	set.threads = 1;
	world_rays_reset();
	render_once(w, &set, fb);
	return world_rays_traced();
}

/* --- POV-Ray and Embree, as child processes --- */

static bool have_povray(void)
{
	return system("command -v povray >/dev/null 2>&1") == 0;
}

/* Runs POV-Ray on bench/grid.pov, writing a PPM as `rtsh -o x.ppm` does;
 * *trace = its own "Trace Time". Wall seconds of the process, < 0 on
 * failure. */
static double run_povray(int w, int h, int threads, double *trace)
{
	char cmd[512];
	snprintf(cmd, sizeof cmd,
	         "povray +Ibench/grid.pov +FP +O%s -D -A +W%d +H%d +WT%d 2>&1", out_ppm, w, h, threads);
	double t0 = now();
	FILE *p = popen(cmd, "r");
	if (!p)
		return -1;
	char line[256];
	*trace = -1;
	bool in_trace = false;
	while (fgets(line, sizeof line, p)) {
		if (strstr(line, "Trace Time:"))
			in_trace = true;
		char *paren = strchr(line, '(');
		if (in_trace && paren && *trace < 0)
			*trace = strtod(paren + 1, NULL);
	}
	int rc = pclose(p);
	double t = now() - t0;
	return rc == 0 ? t : -1;
}

/* Runs the rtsh binary end to end (read, prepare, render, write the PPM),
 * as POV-Ray is run. Wall seconds, < 0 when it cannot. */
static double run_rtsh(const char *scene_path, int w, int h, int threads)
{
	char cmd[1400];
	snprintf(cmd, sizeof cmd, "%s %s -o %s -q -r %dx%d -s 1 -t %d >/dev/null 2>&1", rtsh_bin, scene_path,
	         out_ppm, w, h, threads);
	double t0 = now();
	int rc = system(cmd);
	double t = now() - t0;
	return rc == 0 ? t : -1;
}

/* Embree's packet calls in the harnesses' output (bench/embree_packets.h):
 * "packet N mrays M seconds S" for N = 4, 8, 16 into mr[k], sec[k], k = 0..2;
 * "packet-fill 16 seconds F" makes slot 3 rtcIntersect16's pass less F (the
 * call alone: what the harness spends making and storing the packets, left
 * out), its rate from the 16-ray pass's. */
#define EMBREE_PACKETS 3
#define EMBREE_SLOTS (EMBREE_PACKETS + 1)
static const char *const packet_tiles[EMBREE_PACKETS] = {"2x2", "2x4", "4x4"};

static void parse_packet(const char *line, double mr[EMBREE_SLOTS], double sec[EMBREE_SLOTS])
{
	int n;
	double m, s;
	if (sscanf(line, "packet %d mrays %lf seconds %lf", &n, &m, &s) == 3 && (n == 4 || n == 8 || n == 16)) {
		int k = n == 4 ? 0 : n == 8 ? 1 : 2;
		mr[k] = m;
		sec[k] = s;
	} else if (sscanf(line, "packet-fill 16 seconds %lf", &s) == 1 && sec[2] > s && s >= 0) {
		sec[EMBREE_PACKETS] = sec[2] - s;
		mr[EMBREE_PACKETS] = mr[2] * sec[2] / sec[EMBREE_PACKETS];
	}
}

/* The row of rtcIntersect16's call alone (slot EMBREE_PACKETS), beside
 * rtsh's packet row `ours` at `mine` Mrays/s. */
static void embree_call_row(const char *scene_name, int w, int h, double *mr, double *sec, int n,
                            double mine, const char *ours)
{
	if (!n)
		return;
	double pm = median(mr, n), ps = median(sec, n);
	row *r = add_row(scene_name, "embree-packet16-call", w, h, 1, 1, n, ps, pm);
	snprintf(r->note, sizeof r->note,
	         "rtcIntersect16's pass less a pass that makes and stores the same packets untraced: %s %.2fx",
	         ours, mine / pm);
}

/* Runs the Embree harness once; Mrays/s of its timed pass, < 0 if absent;
 * its packet rows into pm, ps (-1 when missing). */
static double run_embree(const char *scene_path, int w, int h, double *seconds, double pm[EMBREE_SLOTS],
                         double ps[EMBREE_SLOTS])
{
	for (int k = 0; k < EMBREE_SLOTS; k++)
		pm[k] = ps[k] = -1;
	char exe[512], cmd[1200];
	snprintf(exe, sizeof exe, "%s/embree_primary", bench_dir);
	if (access(exe, X_OK) != 0)
		return -1;
	snprintf(cmd, sizeof cmd, "%s %s %d %d 2>&1", exe, scene_path, w, h);
	FILE *p = popen(cmd, "r");
	if (!p)
		return -1;
	char line[256];
	double mrays = -1;
	while (fgets(line, sizeof line, p)) {
		double m, s;
		if (sscanf(line, "mrays %lf seconds %lf", &m, &s) == 2) {
			mrays = m;
			*seconds = s;
		}
		parse_packet(line, pm, ps);
	}
	return pclose(p) == 0 ? mrays : -1;
}

/* --- the rows --- */

/* grid.rt, 1 and 2 threads: the render in this process, the rtsh binary
 * end to end, and POV-Ray end to end, interleaved in one loop so that they
 * share the machine's load. */
static void bench_grid(void)
{
	const char *path = "scenes/grid.rt";
	int w = quick ? 320 : 1920, h = quick ? 180 : 1080;
	scene *s = load(path);
	world *wd = build(s);
	framebuffer *fb = fb_new(w, h);
	if (!fb)
		fail("framebuffer", NULL);
	bool pov = !quick && !no_povray && have_povray();
	bool cli = !quick && access(rtsh_bin, X_OK) == 0;
	double t[2][MAX_RUNS], c[2][MAX_RUNS], pw[2][MAX_RUNS], pt[2][MAX_RUNS];
	int nc[2] = {0, 0}, np[2] = {0, 0};
	uint64_t rays = count_rays(wd, settings(w, h, 1), fb);
	for (int i = 0; i < runs; i++)
		for (int k = 0; k < 2; k++) {
			render_settings set = settings(w, h, k + 1);
			t[k][i] = render_once(wd, &set, fb);
			if (cli) {
				double x = run_rtsh(path, w, h, k + 1);
				if (x > 0)
					c[k][nc[k]++] = x;
			}
			if (pov) {
				double tr, x = run_povray(w, h, k + 1, &tr);
				if (x > 0) {
					pw[k][np[k]] = x;
					pt[k][np[k]++] = tr;
				}
			}
		}
	double m[2], mc[2] = {-1, -1};
	for (int k = 0; k < 2; k++) {
		m[k] = median(t[k], runs);
		row *r = add_row("grid.rt", "whitted", w, h, 1, k + 1, runs, m[k], (double)rays / m[k] * 1e-6);
		if (k == 0)
			snprintf(r->note, sizeof r->note, "render only; %.2f rays/pixel", (double)rays / ((double)w * h));
		else
			snprintf(r->note, sizeof r->note, "render only; %.2fx one thread", m[0] / m[1]);
	}
	for (int k = 0; k < 2 && cli; k++) {
		mc[k] = median(c[k], nc[k]);
		row *r = add_row("grid.rt", "rtsh-process", w, h, 1, k + 1, nc[k], mc[k], -1);
		snprintf(r->note, sizeof r->note, "rtsh grid.rt -o x.ppm: start, read, prepare, render + write, sync");
	}
	for (int k = 0; k < 2 && pov && np[0] && np[1]; k++) {
		double mw = median(pw[k], np[k]), mt = median(pt[k], np[k]);
		row *r = add_row("grid.pov", "povray-process", w, h, 1, k + 1, np[k], mw, -1);
		if (mc[k] > 0)
			snprintf(r->note, sizeof r->note, "+FP: rtsh-process %.2fx faster", mw / mc[k]);
		r = add_row("grid.pov", "povray-trace", w, h, 1, k + 1, np[k], mt, -1);
		snprintf(r->note, sizeof r->note, "POV's own Trace Time: rtsh render %.2fx faster", mt / m[k]);
	}
	if (!pov && !quick && !no_povray) {
		row *r = add_row("grid.pov", "povray", w, h, 1, 1, 0, -1, -1);
		snprintf(r->note, sizeof r->note, "povray not installed: no comparison");
	}
	fb_free(fb);
	world_free(wd);
	scene_free(s);
}

/* The camera rays of a w x h image through pixel centres: nearest hits. */
static double primary_pass(const world *wd, int w, int h, bool brute, long *hits)
{
	double t0 = now();
	long n = 0;
	hit hh;
	for (int y = 0; y < h; y++)
		for (int x = 0; x < w; x++) {
			ray r = cam_ray(&wd->cam, x + 0.5, y + 0.5, w, h);
			n += brute ? world_intersect_brute(wd, &r, 0.0, INFINITY, &hh)
			           : world_intersect_coherent(wd, &r, 0.0, INFINITY, &hh);
		}
	*hits = n;
	return now() - t0;
}

/* primary_pass's rays and hit records traced as packets of 4x4 pixels
 * (world_intersect_packet, packet.h): the same hits. The rays made as the
 * render's blocks make them (cam_block_rays: the same bits as cam_ray, a
 * column's and a row's terms shared), as Embree's packet rows do. */
static double primary_packet_pass(const world *wd, int w, int h)
{
	double t0 = now();
	for (int y0 = 0; y0 < h; y0 += 4)
		for (int x0 = 0; x0 < w; x0 += 4) {
			ray r[PACKET_MAX];
			hit hh[PACKET_MAX];
			bool found[PACKET_MAX];
			int x1 = x0 + 4 < w ? x0 + 4 : w, y1 = y0 + 4 < h ? y0 + 4 : h, n = (x1 - x0) * (y1 - y0);
			cam_block_rays(&wd->cam, x0, y0, x1, y1, w, h, r);
			world_intersect_packet(wd, n, r, 0.0, INFINITY, hh, found);
		}
	return now() - t0;
}

static void bench_primary(void)
{
	const char *path = "scenes/grid.rt";
	int w = quick ? 320 : 1920, h = quick ? 180 : 1080;
	scene *s = load(path);
	world *wd = build(s);
	double t[MAX_RUNS], tb[MAX_RUNS], tp[MAX_RUNS], te[MAX_RUNS], em[MAX_RUNS];
	double pkm[EMBREE_SLOTS][MAX_RUNS], pks[EMBREE_SLOTS][MAX_RUNS];
	int ne = 0, npk[EMBREE_SLOTS] = {0};
	long hits;
	primary_pass(wd, w, h, false, &hits); /* warm up */
	for (int i = 0; i < runs; i++) {
		t[i] = primary_pass(wd, w, h, false, &hits);
		tb[i] = primary_pass(wd, w, h, true, &hits);
		tp[i] = primary_packet_pass(wd, w, h);
		double sec = 0, pm[EMBREE_SLOTS], ps[EMBREE_SLOTS];
		double m = quick ? -1 : run_embree(path, w, h, &sec, pm, ps);
		if (m > 0) {
			em[ne] = m;
			te[ne++] = sec;
			for (int k = 0; k < EMBREE_SLOTS; k++)
				if (pm[k] > 0) {
					pkm[k][npk[k]] = pm[k];
					pks[k][npk[k]++] = ps[k];
				}
		}
	}
	double rays = (double)w * h * 1e-6;
	double m = median(t, runs), mb = median(tb, runs);
	row *r = add_row("grid.rt", "primary", w, h, 1, 1, runs, m, rays / m);
	snprintf(r->note, sizeof r->note, "camera rays only, %.0f%% hit", 100.0 * (double)hits / ((double)w * h));
	r = add_row("grid.rt", "primary-brute", w, h, 1, 1, runs, mb, rays / mb);
	snprintf(r->note, sizeof r->note, "every primitive tested");
	double mp = median(tp, runs), best = -1;
	for (int k = 0; k < EMBREE_PACKETS; k++)
		if (npk[k] && median(pkm[k], npk[k]) > best)
			best = median(pkm[k], npk[k]);
	r = add_row("grid.rt", "primary-packet16", w, h, 1, 1, runs, mp, rays / mp);
	if (best > 0)
		snprintf(r->note, sizeof r->note, "world_intersect_packet, 4x4 pixels: %.2fx primary, %.2fx Embree's best packet call",
		         m / mp, (rays / mp) / best);
	else
		snprintf(r->note, sizeof r->note, "world_intersect_packet, 4x4 pixels: %.2fx primary", m / mp);
	if (ne) {
		double me = median(em, ne), se = median(te, ne);
		r = add_row("grid.rt", "embree-primary", w, h, 1, 1, ne, se, me);
		snprintf(r->note, sizeof r->note, "Embree 3 rtcIntersect1; rtsh %.2fx Embree", (rays / m) / me);
		for (int k = 0; k < EMBREE_PACKETS; k++) {
			if (!npk[k])
				continue;
			char mode[32];
			snprintf(mode, sizeof mode, "embree-packet%d", 4 << k);
			double pm = median(pkm[k], npk[k]), ps = median(pks[k], npk[k]);
			r = add_row("grid.rt", mode, w, h, 1, 1, npk[k], ps, pm);
			snprintf(r->note, sizeof r->note, "rtcIntersect%d, %s-pixel tiles, coherent flag; rtsh primary %.2fx",
			         4 << k, packet_tiles[k], (rays / m) / pm);
		}
		embree_call_row("grid.rt", w, h, pkm[EMBREE_PACKETS], pks[EMBREE_PACKETS], npk[EMBREE_PACKETS],
		                rays / mp, "primary-packet16");
	} else if (!quick) {
		r = add_row("grid.rt", "embree-primary", w, h, 1, 1, 0, -1, -1);
		snprintf(r->note, sizeof r->note, "no %s/embree_primary (needs embree3/rtcore.h)", bench_dir);
	}
	world_free(wd);
	scene_free(s);
}

/* The camera rays of a w x h image through pixel centres in 4 x 4 blocks
 * (cam_block_rays, as the render makes them),
 * and shadow rays from their hits toward the first light: single rays
 * (world_intersect_coherent, world_occluded) or packets
 * (world_intersect_packet, world_occluded_packet, packet.h), the same
 * answers. Returns the seconds of the camera rays; *shadow_sec those of
 * the shadow rays (the camera rays' time for them not counted), *nshadow
 * their count. */
static long packet_blocked; /* packet_pass's last count of blocked shadow rays */

static double packet_pass(const world *wd, int w, int h, bool packet, int bw, int bh, double *shadow_sec,
                          long *nshadow)
{
	double tc = 0, ts = 0;
	long ns = 0, nblocked = 0;
	vec3 lamp = wd->nlights ? wd->lights[0].pos : v3(0, 10, 0);
	int nb = (w + bw - 1) / bw;
	ray *sr = malloc((size_t)nb * PACKET_MAX * sizeof *sr);
	double *dist = malloc((size_t)nb * PACKET_MAX * sizeof *dist);
	int *cnt = malloc((size_t)nb * sizeof *cnt);
	if (!sr || !dist || !cnt)
		fail("packet_pass: out of memory", NULL);
	for (int y0 = 0; y0 < h; y0 += bh) {
		/* a row of blocks: camera rays (timed), their shadow rays made,
		 * then traced (timed) */
		double t0 = now();
		for (int b = 0; b < nb; b++) {
			int x0 = bw * b, m = 0;
			int x1 = x0 + bw < w ? x0 + bw : w, y1 = y0 + bh < h ? y0 + bh : h, n = (x1 - x0) * (y1 - y0);
			ray r[PACKET_MAX];
			hit hh[PACKET_MAX];
			bool found[PACKET_MAX];
			cam_block_rays(&wd->cam, x0, y0, x1, y1, w, h, r);
			if (packet)
				world_intersect_packet(wd, n, r, 0.0, INFINITY, hh, found);
			else
				for (int i = 0; i < n; i++)
					found[i] = world_intersect_coherent(wd, &r[i], 0.0, INFINITY, &hh[i]);
			ray *q = sr + (size_t)b * PACKET_MAX;
			double *d = dist + (size_t)b * PACKET_MAX;
			for (int i = 0; i < n; i++)
				if (found[i]) {
					vec3 p = v3_madd(hh[i].p, hh[i].n, 1e-7);
					vec3 to = v3_sub(lamp, p);
					d[m] = v3_len(to);
					q[m] = (ray){p, v3_scale(to, 1.0 / d[m])};
					m++;
				}
			cnt[b] = m;
			ns += m;
		}
		double t1 = now();
		for (int b = 0; b < nb; b++) {
			bool occ[PACKET_MAX];
			const ray *q = sr + (size_t)b * PACKET_MAX;
			const double *d = dist + (size_t)b * PACKET_MAX;
			if (packet)
				world_occluded_packet(wd, cnt[b], q, 0.0, d, occ);
			else
				for (int i = 0; i < cnt[b]; i++)
					occ[i] = world_occluded(wd, &q[i], 0.0, d[i]);
			for (int i = 0; i < cnt[b]; i++)
				nblocked += occ[i];
		}
		ts += now() - t1;
		tc += t1 - t0;
	}
	free(sr);
	free(dist);
	free(cnt);
	*shadow_sec = ts;
	*nshadow = ns;
	packet_blocked = nblocked;
	return tc;
}

/* Packets against single rays on the grid, interleaved run by run; and
 * packets of 4 (2x2 pixels) and 8 (4x2) against 16 (4x4). */
static void bench_packets(void)
{
	const char *path = "scenes/grid.rt";
	int w = quick ? 320 : 1920, h = quick ? 180 : 1080;
	scene *s = load(path);
	world *wd = build(s);
	static const int shape[4][2] = {{4, 4}, {4, 4}, {2, 2}, {4, 2}}; /* single, then 16, 4, 8 */
	double tc[4][MAX_RUNS], ts[4][MAX_RUNS];
	long ns = 0;
	packet_pass(wd, w, h, true, 4, 4, &ts[0][0], &ns); /* warm up */
	for (int i = 0; i < runs; i++)
		for (int k = 0; k < 4; k++)
			tc[k][i] = packet_pass(wd, w, h, k > 0, shape[k][0], shape[k][1], &ts[k][i], &ns);
	double rays = (double)w * h * 1e-6, srays = (double)ns * 1e-6;
	double c[4], sh[4];
	for (int k = 0; k < 4; k++) {
		c[k] = median(tc[k], runs);
		sh[k] = median(ts[k], runs);
	}
	row *r = add_row("grid.rt", "primary-single", w, h, 1, 1, runs, c[0], rays / c[0]);
	snprintf(r->note, sizeof r->note, "world_intersect_coherent, 4x4 blocks (the packet rows' twin)");
	r = add_row("grid.rt", "primary-packet", w, h, 1, 1, runs, c[1], rays / c[1]);
	snprintf(r->note, sizeof r->note, "world_intersect_packet, 16 rays (4x4): %.2fx single; 8 (4x2): %.2fx, 4 (2x2): %.2fx",
	         c[0] / c[1], c[0] / c[3], c[0] / c[2]);
	r = add_row("grid.rt", "shadow-single", w, h, 1, 1, runs, sh[0], srays / sh[0]);
	snprintf(r->note, sizeof r->note, "world_occluded, from each camera hit to the light");
	r = add_row("grid.rt", "shadow-packet", w, h, 1, 1, runs, sh[1], srays / sh[1]);
	snprintf(r->note, sizeof r->note, "world_occluded_packet, 16 rays: %.2fx single; 8: %.2fx, 4: %.2fx", sh[0] / sh[1],
	         sh[0] / sh[3], sh[0] / sh[2]);
	world_free(wd);
	scene_free(s);
}

/* The spheres-N rows' scene: scene_generate(n, 1) with spheres only. */
static scene *gen_spheres(size_t n)
{
	gen_opts o = {.spheres_only = true};
	rt_error err;
	scene *s = scene_generate(n, 1, &o, &err);
	if (!s)
		fail("generate", &err);
	return s;
}

/* Embree 3's build of the spheres-N scene (bench/embree_build): seconds, or
 * < 0 when the harness is absent or fails; its bytes in *bytes. */
static double run_embree_build(size_t n, int threads, double *bytes)
{
	char exe[512], cmd[1200];
	snprintf(exe, sizeof exe, "%s/embree_build", bench_dir);
	if (access(exe, X_OK) != 0)
		return -1;
	snprintf(cmd, sizeof cmd, "%s %zu %d 2>&1", exe, n, threads);
	FILE *p = popen(cmd, "r");
	if (!p)
		return -1;
	char line[256];
	double t = -1;
	while (fgets(line, sizeof line, p))
		if (sscanf(line, "build %lf bytes %lf", &t, bytes) == 2)
			break;
	while (fgets(line, sizeof line, p))
		;
	return pclose(p) == 0 ? t : -1;
}

static void bench_spheres(void)
{
	static const size_t full[] = {10, 1000, 100000, 1000000};
	static const size_t small[] = {10, 1000};
	const size_t *sizes = quick ? small : full;
	int nsizes = quick ? 2 : 4;
	int w = quick ? 320 : 1920, h = quick ? 180 : 1080;
	framebuffer *fb = fb_new(w, h);
	if (!fb)
		fail("framebuffer", NULL);
	double base = -1;
	for (int k = 0; k < nsizes; k++) {
		size_t n = sizes[k];
		scene *s = gen_spheres(n);
		char name[48];
		snprintf(name, sizeof name, "spheres-%zu", n);
		/* world_build: the BVH rebuild after an edit, on one core */
		int bruns = n >= 1000000 ? (runs < 3 ? runs : 3) : runs;
		double tb[MAX_RUNS];
		world *wd = NULL;
		for (int i = 0; i < bruns; i++) {
			world_free(wd);
			double t0 = now();
			wd = build(s);
			tb[i] = now() - t0;
		}
		row *r = add_row(name, "world_build", -1, -1, 0, 1, bruns, median(tb, bruns), -1);
		snprintf(r->note, sizeof r->note, "%zu B/object: model %zu + world %zu; %zu BVH nodes", 
		         (s->nobjs * sizeof(object) + world_memory(wd)) / s->nobjs, sizeof(object),
		         world_memory(wd) / s->nobjs, wd->tree->nnodes);
		/* Embree's build of the same spheres, right after rtsh's (the
		 * harness takes the median of its own three builds) */
		double ebytes = 0, eb = quick ? -1 : run_embree_build(n, 1, &ebytes);
		if (eb > 0) {
			r = add_row(name, "embree-build", -1, -1, 0, 1, 3, eb, -1);
			snprintf(r->note, sizeof r->note,
			         "Embree 3 spheres, default (medium) quality, 1 thread: rtsh world_build %.2fx its time; "
			         "%.0f B/sphere",
			         median(tb, bruns) / eb, ebytes / (double)n);
		}
		/* the same at 2 threads, like with like (world_build_threads:
		 * the same tree; Embree's device given threads=2) */
		double tb2[MAX_RUNS];
		for (int i = 0; i < bruns; i++) {
			world_free(wd);
			double t0 = now();
			wd = build_threads(s, 2);
			tb2[i] = now() - t0;
		}
		r = add_row(name, "world_build", -1, -1, 0, 2, bruns, median(tb2, bruns), -1);
		snprintf(r->note, sizeof r->note, "%.2fx one thread", median(tb, bruns) / median(tb2, bruns));
		double eb2 = quick ? -1 : run_embree_build(n, 2, &ebytes);
		if (eb2 > 0) {
			r = add_row(name, "embree-build", -1, -1, 0, 2, 3, eb2, -1);
			snprintf(r->note, sizeof r->note,
			         "Embree 3 spheres, 2 threads: rtsh world_build at 2 threads %.2fx its time; %.2fx its 1 thread",
			         median(tb2, bruns) / eb2, eb > 0 ? eb / eb2 : 0.0);
		}
		render_settings set1 = settings(w, h, 1), set2 = settings(w, h, 2);
		uint64_t rays = count_rays(wd, set1, fb);
		double t1[MAX_RUNS], t2[MAX_RUNS];
		for (int i = 0; i < runs; i++) {
			t1[i] = render_once(wd, &set1, fb);
			t2[i] = render_once(wd, &set2, fb);
		}
		double m1 = median(t1, runs), m2 = median(t2, runs);
		if (n == 1000)
			base = m1;
		r = add_row(name, "whitted", w, h, 1, 1, runs, m1, (double)rays / m1 * 1e-6);
		snprintf(r->note, sizeof r->note, "%zu lights, %.2f rays/pixel", s->nlights,
		         (double)rays / ((double)w * h));
		if (base > 0 && n > 1000)
			snprintf(r->note + strlen(r->note), sizeof r->note - strlen(r->note), "; %.2fx the 1k time",
			         m1 / base);
		r = add_row(name, "whitted", w, h, 1, 2, runs, m2, (double)rays / m2 * 1e-6);
		snprintf(r->note, sizeof r->note, "%.2fx one thread", m1 / m2);
		world_free(wd);
		scene_free(s);
	}
	fb_free(fb);
}

/* Embree's lines "packet 16 mrays M", "shadow mrays M" and "shadow-packet
 * 16 mrays M ... blocked B" for the scene at path (bench/embree_primary):
 * false when the harness is absent or fails. */
static bool run_embree_rays(const char *path, int w, int h, double *cam16, double *shadow1, double *shadow16,
                            long *blocked)
{
	char exe[512], cmd[1200];
	snprintf(exe, sizeof exe, "%s/embree_primary", bench_dir);
	if (access(exe, X_OK) != 0)
		return false;
	snprintf(cmd, sizeof cmd, "%s %s %d %d 2>&1", exe, path, w, h);
	FILE *p = popen(cmd, "r");
	if (!p)
		return false;
	char line[256];
	*cam16 = *shadow1 = *shadow16 = -1;
	while (fgets(line, sizeof line, p)) {
		double m, sec;
		if (sscanf(line, "packet 16 mrays %lf", &m) == 1)
			*cam16 = m;
		else if (sscanf(line, "shadow mrays %lf", &m) == 1)
			*shadow1 = m;
		else if (sscanf(line, "shadow-packet 16 mrays %lf seconds %lf blocked %ld", &m, &sec, blocked) == 3)
			*shadow16 = m;
	}
	return pclose(p) == 0 && *cam16 > 0 && *shadow1 > 0 && *shadow16 > 0;
}

/* The rays alone at 1k and 1M spheres (the spheres-N scenes, 1 thread):
 * camera rays in 4x4 packets and shadow rays from their hits toward the
 * first light (packet_pass), beside Embree's rtcIntersect16 and
 * rtcOccluded1/16 on the same rays (embree_primary, from the scene saved
 * as .rt), so that the spheres rows' "Nx the 1k time" can be read against
 * what the 1M tree costs Embree's walks too. */
static void bench_sphere_rays(void)
{
	static const size_t full[] = {1000, 1000000}, small[] = {10, 1000};
	const size_t *sizes = quick ? small : full;
	int w = quick ? 320 : 1920, h = quick ? 180 : 1080;
	double cam[2], sh[2], ecam[2] = {-1, -1}, esh1[2] = {-1, -1}, esh[2] = {-1, -1};
	for (int k = 0; k < 2; k++) {
		size_t n = sizes[k];
		scene *s = gen_spheres(n);
		world *wd = build(s);
		double tc[MAX_RUNS], ts[MAX_RUNS];
		long ns = 0;
		packet_pass(wd, w, h, true, 4, 4, &ts[0], &ns); /* warm up */
		for (int i = 0; i < runs; i++)
			tc[i] = packet_pass(wd, w, h, true, 4, 4, &ts[i], &ns);
		long blocked = packet_blocked, eblocked = -1;
		cam[k] = (double)w * h * 1e-6 / median(tc, runs);
		sh[k] = (double)ns * 1e-6 / median(ts, runs);
		char name[48], path[] = "/tmp/rtsh-bench-XXXXXX";
		snprintf(name, sizeof name, "spheres-%zu", n);
		int fd = quick ? -1 : mkstemp(path);
		if (fd >= 0) {
			close(fd);
			rt_error err;
			if (!rt_save(s, path, &err))
				fail("save", &err);
			if (!run_embree_rays(path, w, h, &ecam[k], &esh1[k], &esh[k], &eblocked))
				ecam[k] = esh1[k] = esh[k] = -1;
			unlink(path);
		}
		row *r = add_row(name, "primary-packet16", w, h, 1, 1, runs, median(tc, runs), cam[k]);
		snprintf(r->note, sizeof r->note, "camera rays alone, 4x4 packets");
		if (ecam[k] > 0)
			snprintf(r->note + strlen(r->note), sizeof r->note - strlen(r->note),
			         "; Embree rtcIntersect16 %.2f Mrays/s: rtsh %.2fx", ecam[k], cam[k] / ecam[k]);
		r = add_row(name, "shadow-packet", w, h, 1, 1, runs, median(ts, runs), sh[k]);
		snprintf(r->note, sizeof r->note, "%ld rays to light 1, %.0f%% blocked", ns,
		         100.0 * (double)blocked / (double)(ns > 0 ? ns : 1));
		if (esh[k] > 0)
			snprintf(r->note + strlen(r->note), sizeof r->note - strlen(r->note),
			         "; Embree rtcOccluded16 %.2f, rtcOccluded1 %.2f Mrays/s (%ld blocked)", esh[k], esh1[k],
			         eblocked);
		world_free(wd);
		scene_free(s);
	}
	row *r = add_row(quick ? "spheres 1k/10" : "spheres 1M/1k", "rays-ratio", w, h, 1, 1, runs, -1, -1);
	snprintf(r->note, sizeof r->note, "time a ray at %zu over %zu spheres: rtsh camera %.2fx, shadow %.2fx", sizes[1],
	         sizes[0], cam[0] / cam[1], sh[0] / sh[1]);
	if (ecam[0] > 0 && ecam[1] > 0)
		snprintf(r->note + strlen(r->note), sizeof r->note - strlen(r->note),
		         "; Embree camera (16) %.2fx, shadow (16) %.2fx, shadow (1) %.2fx", ecam[0] / ecam[1],
		         esh[0] / esh[1], esh1[0] / esh1[1]);
}

/* The 1M-sphere scene saved as .rt and loaded back. */
static void bench_load(void)
{
	size_t n = quick ? 10000 : 1000000;
	rt_error err;
	scene *s = gen_spheres(n);
	char path[] = "/tmp/rtsh-bench-XXXXXX";
	int fd = mkstemp(path);
	if (fd < 0)
		fail("temporary file", NULL);
	close(fd);
	double t0 = now();
	if (!rt_save(s, path, &err))
		fail("save", &err);
	double tsave = now() - t0;
	struct stat st;
	stat(path, &st);
	int lruns = quick ? 1 : 3;
	double tl[MAX_RUNS];
	for (int i = 0; i < lruns; i++) {
		t0 = now();
		scene *back = rt_load_file(path, NULL, &err);
		tl[i] = now() - t0;
		if (!back)
			fail("load", &err);
		if (i == 0 && !scene_equal(s, back))
			fprintf(stderr, "bench: the saved scene did not load back identical\n");
		scene_free(back);
	}
	unlink(path);
	char name[48];
	snprintf(name, sizeof name, "spheres-%zu.rt", n);
	row *r = add_row(name, "load", -1, -1, 0, 1, lruns, median(tl, lruns), -1);
	snprintf(r->note, sizeof r->note, "%.1f MB file; rt_save took %.2f s", (double)st.st_size / 1e6, tsave);
	scene_free(s);
}

/* The Whitted preview frame and the terminal frame that shows it. */
/* --- path tracing (issue 4): paths per second --- */

/* A path-traced scene at the resolution, samples and depth of a reference
 * renderer's own benchmark, 1 and 2 threads: Ray Tracing in One Weekend's
 * final scene (400x225, 50 samples, depth 50) and smallpt's Cornell box
 * (256x192, 256 samples). Paths/s counts camera samples. */
static void bench_path_scene(const char *path, const char *name, int w, int h, int spp, int depth,
                             const char *reference)
{
	if (quick) {
		w /= 4;
		h /= 4;
		spp = 4;
	}
	scene *s = load(path);
	world *wd = build(s);
	framebuffer *fb = fb_new(w, h);
	if (!fb)
		fail("framebuffer", NULL);
	double t[2][MAX_RUNS];
	for (int i = 0; i < runs; i++)
		for (int k = 0; k < 2; k++) {
			render_settings set = settings(w, h, k + 1);
			set.mode = MODE_PATH;
			set.samples = spp;
			set.depth = depth;
			t[k][i] = render_once(wd, &set, fb);
		}
	double m[2];
	for (int k = 0; k < 2; k++) {
		m[k] = median(t[k], runs);
		row *r = add_row(name, "path", w, h, spp, k + 1, runs, m[k], -1);
		double mpaths = (double)w * h * spp / m[k] * 1e-6;
		if (k == 0)
			snprintf(r->note, sizeof r->note, "%.2f Mpaths/s; depth %d; %s", mpaths, depth, reference);
		else
			snprintf(r->note, sizeof r->note, "%.2f Mpaths/s; %.2fx one thread", mpaths, m[0] / m[1]);
	}
	fb_free(fb);
	world_free(wd);
	scene_free(s);
}

static void bench_path(void)
{
	bench_path_scene("scenes/final.rt", "final.rt", 400, 225, 50, 50,
	                 "RTOW's own code, one core: 39 s (book 1), 7.5 s (book 2)");
	bench_path_scene("scenes/cornell.rt", "cornell.rt", 256, 192, 256, 12, "smallpt, one core: 21 s");
}

static void bench_preview(void)
{
	const char *path = "scenes/showcase.rt";
	int w = 160, h = 96;
	scene *s = load(path);
	framebuffer *fb = fb_new(w, h);
	if (!fb)
		fail("framebuffer", NULL);
	int pruns = quick ? 3 : 31;
	for (int threads = 1; threads <= 2; threads++) {
		render_settings set = settings(w, h, threads);
		double t[MAX_RUNS];
		uint64_t rays = 0;
		for (int i = 0; i < pruns; i++) {
			double t0 = now();
			world *wd = build(s); /* an edit rebuilds the world */
			render_once(wd, &set, fb);
			t[i] = now() - t0;
			if (i == 0)
				rays = count_rays(wd, set, fb);
			world_free(wd);
		}
		double m = median(t, pruns);
		row *r = add_row("showcase.rt", "preview", w, h, 1, threads, pruns, m, (double)rays / m * 1e-6);
		snprintf(r->note, sizeof r->note, "world_build + render, depth %d; target < 15 ms (2 threads)",
		         set.depth);
	}

	/* The frame: every cell first, then the update after the camera turns
	 * by one degree (what an arrow key in `view` sends). */
	static const struct {
		frame_palette pal;
		const char *name;
	} pals[] = {{PALETTE_TRUECOLOR, "truecolor"}, {PALETTE_256, "256"}};
	uint8_t *rgb = malloc((size_t)w * h * 3);
	if (!rgb)
		fail("memory", NULL);
	render_settings set = settings(w, h, 2);
	world *wd = build(s);
	render_once(wd, &set, fb);
	world_free(wd);
	scene *turned = scene_clone(s);
	if (!turned)
		fail("memory", NULL);
	camera *c = &turned->cams[turned->cam];
	vec3 d = v3_norm(c->dir);
	double a = deg_to_rad(1.0);
	c->dir = v3(d.x * cos(a) + d.z * sin(a), d.y, -d.x * sin(a) + d.z * cos(a));
	framebuffer *fb2 = fb_new(w, h);
	if (!fb2)
		fail("framebuffer", NULL);
	wd = build(turned);
	render_once(wd, &set, fb2);
	world_free(wd);
	for (size_t k = 0; k < sizeof pals / sizeof pals[0]; k++) {
		double t[MAX_RUNS];
		size_t full = 0, update = 0;
		for (int i = 0; i < pruns; i++) {
			frame *f = frame_new(w, h / 2, pals[k].pal);
			if (!f)
				fail("frame", NULL);
			double t0 = now();
			frame_srgb_from_linear(fb->rgb, (size_t)w * h, 0.0, rgb);
			frame_put_image(f, rgb, w, h, 0, 0);
			full = frame_update(f)->len;
			t[i] = now() - t0;
			frame_srgb_from_linear(fb2->rgb, (size_t)w * h, 0.0, rgb);
			frame_put_image(f, rgb, w, h, 0, 0);
			update = frame_update(f)->len;
			frame_free(f);
		}
		char mode[24];
		snprintf(mode, sizeof mode, "frame-%s", pals[k].name);
		row *r = add_row("showcase.rt", mode, w, h, 1, 1, pruns, median(t, pruns), -1);
		snprintf(r->note, sizeof r->note, "%zu bytes full frame, %zu after a 1-degree turn (%dx%d cells)",
		         full, update, w, h / 2);
	}
	fb_free(fb2);
	scene_free(turned);
	free(rgb);
	fb_free(fb);
	scene_free(s);
}

/* --- the denoiser (issues 12 and 27, src/core/denoise.c) -------------
 * denoise_image alone on a path preview of cornell.rt at 200x120 (8 samples,
 * features recorded), 1 and 2 threads; what recording the features
 * costs the render; and (not --quick) the filter at 1920x1080 against the
 * 8 samples it filters. */
static void bench_denoise(void)
{
	const char *path = "scenes/cornell.rt";
	int w = 200, h = 120;
	scene *s = load(path);
	world *wd = build(s);
	framebuffer *fb = fb_new(w, h), *plain = fb_new(w, h);
	float *out = malloc((size_t)w * h * 3 * sizeof *out);
	if (!fb || !plain || !out || !denoise_prepare(fb))
		fail("memory", NULL);
	render_settings set = settings(w, h, 2);
	set.mode = MODE_PATH;
	set.samples = 8;
	set.depth = 12;
	int druns = quick ? 3 : 31;
	double tf[MAX_RUNS], tp[MAX_RUNS];
	for (int i = 0; i < (quick ? 1 : 5); i++) {
		tf[i] = render_once(wd, &set, fb);
		tp[i] = render_once(wd, &set, plain);
	}
	int rruns = quick ? 1 : 5;
	double mf = median(tf, rruns), mp = median(tp, rruns);
	for (int threads = 1; threads <= 2; threads++) {
		double t[MAX_RUNS], cpu[MAX_RUNS];
		for (int i = 0; i < druns; i++) {
			struct timespec c0, c1;
			clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c0);
			double t0 = now();
			if (!denoise_image(fb, out, threads))
				fail("denoise", NULL);
			t[i] = now() - t0;
			clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c1);
			cpu[i] = (double)(c1.tv_sec - c0.tv_sec) + (c1.tv_nsec - c0.tv_nsec) * 1e-9;
		}
		row *r = add_row("cornell.rt", "denoise", w, h, 8, threads, druns, median(t, druns), -1);
		snprintf(r->note, sizeof r->note,
		         "denoise_image alone; CPU time %.1f ms (all threads); target <= 10 ms wall (2 threads)",
		         median(cpu, druns) * 1e3);
	}
	row *r = add_row("cornell.rt", "path+features", w, h, 8, 2, rruns, mf, -1);
	snprintf(r->note, sizeof r->note, "render recording the features: %.2fx the plain render (%.1f ms)",
	         mf / mp, mp * 1e3);
	if (!quick) {
		/* `save` at 1920x1080: the denoiser against the 8 samples it
		 * filters (issue 27: at most their time), 2 threads, one run. */
		int W = 1920, H = 1080;
		framebuffer *big = fb_new(W, H);
		float *bout = malloc((size_t)W * H * 3 * sizeof *bout);
		if (!big || !bout || !denoise_prepare(big))
			fail("memory", NULL);
		render_settings bs = set;
		bs.width = W;
		bs.height = H;
		double t8 = render_once(wd, &bs, big);
		double t0 = now();
		if (!denoise_image(big, bout, 2))
			fail("denoise", NULL);
		double td = now() - t0;
		r = add_row("cornell.rt", "denoise", W, H, 8, 2, 1, td, -1);
		snprintf(r->note, sizeof r->note,
		         "denoise_image at save size: %.2fx the 8 samples' render with features (%.2f s); target <= 1x",
		         td / t8, t8);
		free(bout);
		fb_free(big);
	}
	free(out);
	fb_free(plain);
	fb_free(fb);
	world_free(wd);
	scene_free(s);
}

/* --- real pixels (issue 12, src/term/pixels*.c) ---------------------------
 * One full frame of the showcase at 1600x900 pixels in each protocol: the
 * bytes sent and the time to encode them (1 thread); and, for comparison,
 * the half-block frame of the same screen area at 8x16-pixel cells (200x56
 * cells, a 200x112 picture). */
static void bench_pixels(void)
{
	int w = 1600, h = 900;
	scene *s = load("scenes/showcase.rt");
	world *wd = build(s);
	framebuffer *fb = fb_new(w, h), *small = fb_new(200, 112);
	uint8_t *rgb = malloc((size_t)w * h * 3);
	if (!fb || !small || !rgb)
		fail("memory", NULL);
	render_settings set = settings(w, h, 2);
	render_once(wd, &set, fb);
	frame_srgb_from_linear(fb->rgb, (size_t)w * h, 0.0, rgb);
	int pruns = quick ? 1 : 5;
	const pixels_mode modes[] = {PIXELS_KITTY, PIXELS_SIXEL, PIXELS_ITERM};
	for (size_t k = 0; k < 3; k++) {
		double t[MAX_RUNS];
		size_t bytes = 0;
		for (int i = 0; i < pruns; i++) {
			abuf a;
			abuf_init(&a);
			double t0 = now();
			if (!pixels_encode(modes[k], &a, rgb, w, h, 200, 56))
				fail("pixels", NULL);
			t[i] = now() - t0;
			bytes = a.len;
			abuf_free(&a);
		}
		char mode[32];
		snprintf(mode, sizeof mode, "pixels-%s", pixels_mode_name(modes[k]));
		row *r = add_row("showcase.rt", mode, w, h, 1, 1, pruns, median(t, pruns), -1);
		snprintf(r->note, sizeof r->note, "%zu bytes a full frame (%.2f bytes a pixel)", bytes,
		         (double)bytes / ((double)w * h));
	}
	render_settings sset = settings(200, 112, 2);
	render_once(wd, &sset, small);
	uint8_t *srgb = malloc((size_t)200 * 112 * 3);
	frame *f = frame_new(200, 56, PALETTE_TRUECOLOR);
	if (!srgb || !f)
		fail("memory", NULL);
	frame_srgb_from_linear(small->rgb, (size_t)200 * 112, 0.0, srgb);
	frame_put_image(f, srgb, 200, 112, 0, 0);
	double t0 = now();
	size_t hb = frame_update(f)->len;
	row *r = add_row("showcase.rt", "pixels-off", 200, 112, 1, 1, 1, now() - t0, -1);
	snprintf(r->note, sizeof r->note, "half blocks, the same area at 8x16-pixel cells: %zu bytes", hb);
	frame_free(f);
	free(srgb);
	free(rgb);
	fb_free(small);
	fb_free(fb);
	world_free(wd);
	scene_free(s);
}

/* --- symbols (issue 27, src/term/symbols.c) -----------------------------
 * The picture as the terminal shows it, per symbol set, against a render at
 * 2x4 samples a cell (the octants' grid): rtsh's cell encoder fed that
 * render (half blocks: its 2x2 means, what a half block covers), and chafa
 * fed the same render as a PPM, both decoded by symbols_quality.h; PSNR,
 * SSIM and the bytes of one full frame in 24-bit colour. */

/* chafa's output for the reference image in ppm (cols x crows cells), or
 * NULL when chafa is not there; *len its bytes. */
static char *run_chafa(const char *ppm, int cols, int nrow, const char *syms, size_t *len, double *seconds)
{
	char cmd[512];
	snprintf(cmd, sizeof cmd,
	         "chafa --size %dx%d --stretch --symbols %s -c full --dither none -w 9 -O 9 -f symbols "
	         "--polite on '%s' 2>/dev/null",
	         cols, nrow, syms, ppm);
	double t0 = now();
	FILE *p = popen(cmd, "r");
	if (!p)
		return NULL;
	size_t cap = 1 << 16, n = 0;
	char *b = malloc(cap);
	for (size_t k; b && (k = fread(b + n, 1, cap - n, p)) > 0;) {
		n += k;
		if (n == cap) {
			char *nb = realloc(b, cap *= 2);
			if (!nb) {
				free(b);
				b = NULL;
			}
			b = nb;
		}
	}
	int st = pclose(p);
	*seconds = now() - t0;
	if (st != 0 || n == 0) {
		free(b);
		return NULL;
	}
	*len = n;
	return b;
}

static void bench_symbols(void)
{
	static const struct {
		const char *path, *name;
		int spp;
	} scenes[] = {
		{"scenes/showcase.rt", "showcase.rt", 4},
		{"scenes/cornell.rt", "cornell.rt", 64},
		{"scenes/spot.rt", "spot.rt", 16},
	};
	const int cols = 160, crows = 45;
	const int W = cols * SQ_W, H = crows * SQ_H;
	uint8_t *ref = malloc((size_t)W * H * 3), *shown = malloc((size_t)W * H * 3),
	        *half = malloc((size_t)cols * crows * 2 * 3), *adapt = malloc((size_t)W * H * 3),
	        *ref4 = malloc((size_t)W * H * 3);
	int64_t *ids = malloc(sizeof *ids * (size_t)W * H);
	framebuffer *fb = fb_new(W, H);
	if (!ref || !shown || !half || !adapt || !ref4 || !ids || !fb)
		fail("memory", NULL);
	char ppm[64];
	snprintf(ppm, sizeof ppm, "/tmp/rtsh-bench-sym-%ld.ppm", (long)getpid());
	for (size_t si = 0; si < sizeof scenes / sizeof scenes[0]; si++) {
		scene *s = load(scenes[si].path);
		world *wd = build(s);
		render_settings set = settings(W, H, 2);
		render_settings_apply_hints(&set, &s->hints);
		set.width = W;
		set.height = H;
		set.threads = 2;
		set.samples = scenes[si].spp;
		render_once(wd, &set, fb);
		frame_srgb_from_linear(fb->rgb, (size_t)W * H, set.exposure, ref);
		/* what each sample's first ray hits (object and material; -1: none),
		 * for the adaptive rows below */
		for (int y = 0; y < H; y++)
			for (int x = 0; x < W; x++) {
				ray r = render_sample_ray(wd, &set, x, y, W, H, 0);
				hit h;
				ids[(size_t)y * W + x] = world_intersect(wd, &r, 1e-9, INFINITY, &h)
				                             ? (int64_t)h.object << 32 | h.mat
				                             : -1;
			}
		/* a render of 4x the samples, to tell the adaptive rows' error from
		 * the reference's own noise */
		set.samples = 4 * scenes[si].spp;
		render_once(wd, &set, fb);
		frame_srgb_from_linear(fb->rgb, (size_t)W * H, set.exposure, ref4);
		set.samples = scenes[si].spp;
		world_free(wd);
		scene_free(s);
		/* the half blocks' input: each half block's 2x2 samples */
		for (int y = 0; y < crows * 2; y++)
			for (int x = 0; x < cols; x++)
				for (int c = 0; c < 3; c++) {
					int v = 0;
					for (int k = 0; k < 4; k++)
						v += ref[((size_t)(2 * y + k / 2) * W + 2 * x + k % 2) * 3 + c];
					half[((size_t)y * cols + x) * 3 + c] = (uint8_t)((v + 2) / 4);
				}
		size_t half_bytes = 0, full_bytes[SYMBOLS_AUTO] = {0};
		double half_psnr = 0, full_psnr[SYMBOLS_AUTO] = {0};
		for (int k = SYMBOLS_HALF; k <= SYMBOLS_OCTANT; k++) {
			double t[MAX_RUNS];
			size_t bytes = 0;
			int nr = quick ? 1 : 5;
			for (int i = 0; i < nr; i++) {
				frame *f = frame_new_symbols(cols, crows, PALETTE_TRUECOLOR, (symbols_kind)k);
				if (!f)
					fail("memory", NULL);
				double t0 = now();
				if (k == SYMBOLS_HALF)
					frame_put_image(f, half, cols, crows * 2, 0, 0);
				else
					frame_put_image(f, ref, W, H, 0, 0);
				const abuf *out = frame_update(f);
				t[i] = now() - t0;
				bytes = out->len;
				if (i == 0 && sq_decode(out->b, out->len, cols, crows, shown) != 0)
					fail("symbols: the decoder met a glyph it does not know", NULL);
				frame_free(f);
			}
			double psnr = sq_psnr(ref, shown, (size_t)W * H), ssim = sq_ssim(ref, shown, W, H);
			if (k == SYMBOLS_HALF) {
				half_bytes = bytes;
				half_psnr = psnr;
			}
			full_psnr[k] = psnr;
			full_bytes[k] = bytes;
			char mode[24];
			snprintf(mode, sizeof mode, "sym-%s", symbols_name((symbols_kind)k));
			row *r = add_row(scenes[si].name, mode, cols, crows, set.samples, 1, nr, median(t, nr), -1);
			snprintf(r->note, sizeof r->note,
			         "PSNR %.2f dB (%+.2f vs half), SSIM %.4f, %zu bytes (%.2fx half); put+update time",
			         psnr, psnr - half_psnr, ssim, bytes, (double)bytes / (double)half_bytes);
		}
		/* Adaptive tracing, simulated on the same render: a first pass
		 * traces each cell's four corner samples and its inner sample
		 * (1,1); a cell whose five samples hit the same object and
		 * material and lie within ADAPT_TOL sRGB levels of each other in
		 * every channel is flat, and its three other inner samples are not
		 * traced: each takes the line between its column's two corners. The note gives the rays saved, the PSNR
		 * and bytes against the full trace (the rows above), and the PSNR
		 * of both against a render of 4x the samples (the reference's own
		 * noise set apart). Not in the render loop: see bench/README.md. */
		for (int k = SYMBOLS_SEXTANT; k <= SYMBOLS_OCTANT; k++) {
			enum { ADAPT_TOL = 2 };
			memcpy(adapt, ref, (size_t)W * H * 3);
			long flat = 0;
			for (int cy = 0; cy < crows; cy++)
				for (int cx = 0; cx < cols; cx++) {
					/* the first pass: the corners, then one inner sample */
					static const int first[5][2] = {{0, 0}, {1, 0}, {0, 3}, {1, 3}, {1, 1}};
					size_t at[5];
					bool same = true;
					int lo[3] = {255, 255, 255}, hi[3] = {0, 0, 0};
					for (int i = 0; i < 5; i++) {
						at[i] = (size_t)(cy * SQ_H + first[i][1]) * W + (size_t)(cx * SQ_W + first[i][0]);
						same &= ids[at[i]] == ids[at[0]];
						for (int c = 0; c < 3; c++) {
							int v = ref[at[i] * 3 + c];
							lo[c] = v < lo[c] ? v : lo[c];
							hi[c] = v > hi[c] ? v : hi[c];
						}
					}
					for (int c = 0; c < 3; c++)
						same &= hi[c] - lo[c] <= ADAPT_TOL;
					if (!same)
						continue;
					flat++;
					/* each column's inner samples: the line between its
					 * corners (rows 1 and 2 at a third and two thirds) */
					for (int y = 1; y < 3; y++)
						for (int x = 0; x < 2 && !(x == 1 && y == 1); x++)
							for (int c = 0; c < 3; c++) {
								int top = ref[at[x] * 3 + c], bot = ref[at[2 + x] * 3 + c];
								adapt[((size_t)(cy * SQ_H + y) * W + (size_t)(cx * SQ_W + x)) * 3 + c] =
								    (uint8_t)(((3 - y) * top + y * bot + 1) / 3);
							}
				}
			/* both pictures against the render of 4x the samples */
			double hi_psnr[2];
			for (int a = 0; a < 2; a++) {
				frame *f = frame_new_symbols(cols, crows, PALETTE_TRUECOLOR, (symbols_kind)k);
				if (!f)
					fail("memory", NULL);
				frame_put_image(f, a ? adapt : ref, W, H, 0, 0);
				const abuf *out = frame_update(f);
				if (sq_decode(out->b, out->len, cols, crows, shown) != 0)
					fail("symbols: the decoder met a glyph it does not know", NULL);
				hi_psnr[a] = sq_psnr(ref4, shown, (size_t)W * H);
				frame_free(f);
			}
			frame *f = frame_new_symbols(cols, crows, PALETTE_TRUECOLOR, (symbols_kind)k);
			if (!f)
				fail("memory", NULL);
			double t0 = now();
			frame_put_image(f, adapt, W, H, 0, 0);
			const abuf *out = frame_update(f);
			double t = now() - t0;
			size_t bytes = out->len;
			if (sq_decode(out->b, out->len, cols, crows, shown) != 0)
				fail("symbols: the decoder met a glyph it does not know", NULL);
			frame_free(f);
			double psnr = sq_psnr(ref, shown, (size_t)W * H), ssim = sq_ssim(ref, shown, W, H);
			long cells = (long)cols * crows;
			char mode[24];
			snprintf(mode, sizeof mode, "sym-%s-adapt", symbols_name((symbols_kind)k));
			row *r = add_row(scenes[si].name, mode, cols, crows, set.samples, 1, 1, t, -1);
			snprintf(r->note, sizeof r->note,
			         "%.1f%% rays saved; PSNR %.2f dB (%+.2f vs all rays), SSIM %.4f, %zu bytes (%.3fx); vs 4x spp "
			         "%.2f dB (%+.2f)",
			         100.0 * (double)flat * 3 / ((double)cells * 8), psnr, psnr - full_psnr[k], ssim, bytes,
			         (double)bytes / (double)full_bytes[k], hi_psnr[1], hi_psnr[1] - hi_psnr[0]);
		}
		/* chafa on the same render */
		FILE *f = fopen(ppm, "wb");
		if (!f)
			fail(ppm, NULL);
		fprintf(f, "P6\n%d %d\n255\n", W, H);
		fwrite(ref, 1, (size_t)W * H * 3, f);
		if (fclose(f) != 0)
			fail(ppm, NULL);
		static const char *const sets[] = {"half", "quad", "sextant", "block", "block+quad+sextant"};
		for (size_t k = 0; k < sizeof sets / sizeof sets[0]; k++) {
			size_t len = 0;
			double secs = 0;
			char *out = run_chafa(ppm, cols, crows, sets[k], &len, &secs);
			if (!out) {
				fprintf(stderr, "bench: chafa is not installed: its symbols crows are left out\n");
				break;
			}
			int unknown = sq_decode(out, len, cols, crows, shown);
			double psnr = sq_psnr(ref, shown, (size_t)W * H), ssim = sq_ssim(ref, shown, W, H);
			char mode[24];
			snprintf(mode, sizeof mode, "chafa-%.17s", sets[k]);
			row *r = add_row(scenes[si].name, mode, cols, crows, set.samples, 1, 1, secs, -1);
			snprintf(r->note, sizeof r->note,
			         "PSNR %.2f dB (%+.2f vs rtsh half), SSIM %.4f, %zu bytes (%.2fx rtsh half)%s", psnr,
			         psnr - half_psnr, ssim, len, (double)len / (double)half_bytes,
			         unknown ? ", glyphs not known to the decoder" : "");
			free(out);
		}
	}
	unlink(ppm);
	fb_free(fb);
	free(adapt);
	free(ref4);
	free(ids);
	free(half);
	free(shown);
	free(ref);
}

/* --- key mode (issue 6, src/shell/keymode.c) ---------------------------
 * The time from a key to the first updated frame: a key-mode session on
 * showcase.rt of 160x48 cells drawing into /dev/null. Each run waits until
 * the picture is refined, sends an arrow key through keymode_key (the
 * camera strafes) and ticks the session as its loop does until a frame is
 * written: the edit, the world build, the render at the adaptive pixel
 * ratio, the frame encoding and the write. The note gives the frames a
 * second drawn while a key repeats at 30 Hz. */
static long keymode_pump(keymode *km, int wake, double seconds, bool until_frame)
{
	long frames = 0;
	double end = now() + seconds;
	while (now() < end) {
		frames += keymode_tick(km);
		if (until_frame && frames)
			break;
		struct pollfd p = {wake, POLLIN, 0};
		double left = end - now();
		poll(&p, 1, left > 0 ? (int)(left * 1000) + 1 : 0);
		char buf[64];
		while (read(wake, buf, sizeof buf) > 0)
			;
	}
	return frames;
}

/* cols x cell_rows cells; sym: the picture's symbols (encoder_symbols), or -1
 * for keymode_new's own (half blocks) with the row named as before issue 29 */
static void bench_keymode_at(int cols, int cell_rows, int sym)
{
	rtsh_options o;
	memset(&o, 0, sizeof o);
	o.scene = "scenes/showcase.rt";
	o.quiet = true;
	int p[2], out = open("/dev/null", O_WRONLY);
	if (pipe(p) != 0 || out < 0)
		fail("pipe", NULL);
	for (int i = 0; i < 2; i++)
		fcntl(p[i], F_SETFL, O_NONBLOCK);
	static shell sh;
	if (!shell_init(&sh, &o, p[1]))
		fail("shell_init", NULL);
	sh.wake[0] = p[0];
	sh.wake[1] = p[1];
	termout *to = termout_new(out);
	keymode *km = to ? keymode_new(&sh, to, PALETTE_TRUECOLOR, cols, cell_rows) : NULL;
	if (!km)
		fail("keymode_new", NULL);
	if (sym >= 0)
		keymode_set_encoder(km, encoder_symbols((symbols_kind)sym), 0, 0, 0, 0);
	int kruns = quick ? 5 : 41;
	double t[MAX_RUNS];
	keymode_pump(km, p[0], 0.5, false);
	for (int i = 0; i < kruns; i++) {
		keymode_pump(km, p[0], 0.25, false);
		double t0 = now();
		keymode_key(km, i % 2 ? KEYS_LEFT : KEYS_RIGHT);
		if (!keymode_pump(km, p[0], 5.0, true))
			fail("key mode drew no frame", NULL);
		t[i] = now() - t0;
	}
	double m = median(t, kruns);
	/* A key held down: 30 repeats a second for 2 s. */
	long frames = 0;
	for (int i = 0; i < 60; i++) {
		keymode_key(km, i % 2 ? KEYS_LEFT : KEYS_RIGHT);
		frames += keymode_pump(km, p[0], 1.0 / 30, false);
	}
	static const char *const names[] = {"half", "quadrant", "sextant", "octant"};
	char mode[40];
	snprintf(mode, sizeof mode, sym < 0 ? "key-to-frame" : "key-to-frame-%s", sym < 0 ? "" : names[sym]);
	/* the first row keeps the size it was listed under before (160x90) */
	row *r = add_row("showcase.rt", mode, cols, sym < 0 ? 90 : cell_rows, 1, render_threads(&sh.set), kruns, m, -1);
	snprintf(r->note, sizeof r->note,
	         "view at %dx%d cells: key to first frame; %.0f frames/s at 30 Hz repeat; target < 50 ms", cols,
	         cell_rows, frames / 2.0);
	keymode_free(km);
	termout_free(to);
	shell_free(&sh);
	close(out);
	close(p[0]);
	close(p[1]);
}

/* The row of issue 6 (160x48 cells, half blocks), and issue 29's at 200x60
 * cells with half blocks, the sextant set and octants (2x4 samples a cell). */
static void bench_keymode(void)
{
	bench_keymode_at(160, 48, -1);
	bench_keymode_at(200, 60, SYMBOLS_HALF);
	bench_keymode_at(200, 60, SYMBOLS_SEXTANT);
	bench_keymode_at(200, 60, SYMBOLS_OCTANT);
}

/* --- triangle meshes beside Embree 3 (issue 10) --- */

#define BUNNY "../shared/models/stanford-bunny.obj"

/* Runs the Embree mesh harness once: 0 on success. */
static int run_embree_mesh(const char *model, int w, int h, double *build, double *bytes, double *primary,
                           double *sec, double pm[EMBREE_SLOTS], double ps[EMBREE_SLOTS])
{
	for (int k = 0; k < EMBREE_SLOTS; k++)
		pm[k] = ps[k] = -1;
	char exe[512], cmd[1400];
	snprintf(exe, sizeof exe, "%s/embree_mesh", bench_dir);
	if (access(exe, X_OK) != 0)
		return -1;
	snprintf(cmd, sizeof cmd, "%s %s %d %d 2>&1", exe, model, w, h);
	FILE *p = popen(cmd, "r");
	if (!p)
		return -1;
	char line[256];
	int got = 0;
	while (fgets(line, sizeof line, p)) {
		long hits;
		if (sscanf(line, "build %lf bytes %lf primary %lf hits %ld secondary %lf", build, bytes, primary, &hits,
		           sec) == 5)
			got = 1;
		parse_packet(line, pm, ps);
	}
	return pclose(p) == 0 && got ? 0 : -1;
}

/* A w x h grid of quads on a torus: 2 w h triangles, as an OBJ file. */
static bool write_torus_obj(const char *path, int w, int h)
{
	FILE *f = fopen(path, "w");
	if (!f)
		return false;
	for (int j = 0; j < h; j++)
		for (int i = 0; i < w; i++) {
			double a = 2 * RT_PI * i / w, b = 2 * RT_PI * j / h, r = 1 + 0.3 * cos(b);
			fprintf(f, "v %.6f %.6f %.6f\n", r * cos(a), 0.3 * sin(b), r * sin(a));
		}
	for (int j = 0; j < h; j++)
		for (int i = 0; i < w; i++) {
			int a = j * w + i + 1, b = j * w + (i + 1) % w + 1, c = (j + 1) % h * w + i + 1,
			    d = (j + 1) % h * w + (i + 1) % w + 1;
			fprintf(f, "f %d %d %d\nf %d %d %d\n", a, c, b, b, c, d);
		}
	return fclose(f) == 0;
}

static void bench_mesh_load(void)
{
	/* 1M triangles in an OBJ: rtsh's reader and assimp's */
	char path[64];
	snprintf(path, sizeof path, "/tmp/rtsh-bench-%ld.obj", (long)getpid());
	int gw = quick ? 100 : 1000, gh = quick ? 50 : 500;
	if (!write_torus_obj(path, gw, gh))
		fail("writing the torus OBJ", NULL);
	double t[MAX_RUNS], ta[MAX_RUNS];
	int n = quick ? 1 : 3;
	for (int i = 0; i < n; i++) {
		rt_error err = {0};
		double t0 = now();
		mesh *m = mesh_read_obj(path, &err);
		t[i] = now() - t0;
		if (!m)
			fail(path, &err);
		mesh_free(m);
		t0 = now();
		m = mesh_read_assimp(path, &err);
		ta[i] = now() - t0;
		if (!m)
			fail(path, &err);
		mesh_free(m);
	}
	double mo = median(t, n), ma = median(ta, n);
	char name[48];
	snprintf(name, sizeof name, "torus %dk tris .obj", 2 * gw * gh / 1000);
	row *r = add_row(name, "load-rtsh", 0, 0, 0, 1, n, mo, -1);
	snprintf(r->note, sizeof r->note, "our OBJ reader (target < 1.5 s for 1M); %.2fx faster than assimp", ma / mo);
	r = add_row(name, "load-assimp", 0, 0, 0, 1, n, ma, -1);
	snprintf(r->note, sizeof r->note, "aiImportFile, triangulate + pretransform");
	unlink(path);
}

/* The camera rays through the kernel (world_trace + Ng, what Embree's
 * rtcIntersect1 returns), with the coherent hint or without: CPU time. */
static double kernel_primary(const world *wd, int w, int h, bool coherent, double *sink)
{
	double t0 = cpu_now();
	for (int y = 0; y < h; y++)
		for (int x = 0; x < w; x++) {
			ray r = cam_ray(&wd->cam, x + 0.5, y + 0.5, w, h);
			trace_hit th;
			if ((coherent ? world_trace_coherent : world_trace)(wd, &r, 0.0, INFINITY, &th))
				*sink += world_trace_ng(wd, &r, &th).x;
		}
	return cpu_now() - t0;
}

/* kernel_primary's rays and answers traced as packets of 4x4 pixels
 * (world_trace_packet: the model's own packet walk), Embree's 4x4 tiles
 * for rtcIntersect16: CPU time of one pass. The rays made as the render's
 * blocks make them (cam_block_rays: cam_ray's bits, a column's and a row's
 * terms shared), as Embree's packet rows (embree_packets.h) make theirs. */
static double kernel_packet_pass(const world *wd, int w, int h, double *sink)
{
	double t0 = cpu_now();
	for (int y0 = 0; y0 < h; y0 += 4)
		for (int x0 = 0; x0 < w; x0 += 4) {
			ray r[PACKET_MAX];
			trace_hit th[PACKET_MAX];
			bool found[PACKET_MAX];
			int x1 = x0 + 4 < w ? x0 + 4 : w, y1 = y0 + 4 < h ? y0 + 4 : h, n = (x1 - x0) * (y1 - y0);
			cam_block_rays(&wd->cam, x0, y0, x1, y1, w, h, r);
			world_trace_packet(wd, n, r, 0.0, INFINITY, th, found);
			for (int i = 0; i < n; i++)
				if (found[i])
					*sink += world_trace_ng(wd, &r[i], &th[i]).x;
		}
	return cpu_now() - t0;
}

/* The fastest of three passes after one that warms the caches: what
 * embree_packets.h gives for Embree's packet rows, so that the two compare
 * alike. */
static double kernel_packet(const world *wd, int w, int h, double *sink)
{
	double best = -1;
	for (int pass = 0; pass < 4; pass++) {
		double t = kernel_packet_pass(wd, w, h, sink);
		if (pass > 0 && (best < 0 || t < best))
			best = t;
	}
	return best;
}

static void bench_mesh(void)
{
	bench_mesh_load();
	if (access(BUNNY, R_OK) != 0) {
		row *r = add_row("bunny", "triangles", 0, 0, 0, 1, 0, -1, -1);
		snprintf(r->note, sizeof r->note, "skipped: %s is absent", BUNNY);
		return;
	}
	int w = quick ? 320 : 1920, h = quick ? 180 : 1080;
	rt_error err = {0};
	/* the tree alone, as Embree's build: the mesh read again each time */
	double tb[MAX_RUNS];
	mesh *m = NULL;
	for (int i = 0; i < runs; i++) {
		mesh_free(m);
		m = mesh_load(BUNNY, &err);
		if (!m)
			fail(BUNNY, &err);
		double t0 = cpu_now();
		if (!mesh_prepare(m, false, 0, &err))
			fail(BUNNY, &err);
		tb[i] = cpu_now() - t0;
	}
	box bb = m->bounds;
	uint32_t ntris = m->ntris;
	mesh_free(m);
	/* the world: the model where it is (its box centre, its longest side) */
	camera c = bench_mesh_camera(bb);
	vec3 ctr = box_center(bb), ext = v3_sub(bb.hi, bb.lo);
	char text[1024];
	snprintf(text, sizeof text, "C %.17g,%.17g,%.17g %.17g,%.17g,%.17g %g\nmesh %s %.17g,%.17g,%.17g 0,1,0 %.17g smooth=0\n",
	         c.pos.x, c.pos.y, c.pos.z, c.dir.x, c.dir.y, c.dir.z, c.fov, "stanford-bunny.obj", ctr.x, ctr.y, ctr.z,
	         v3_max_comp(ext));
	scene *s = rt_load_string(text, strlen(text), "../shared/models/bench.rt", NULL, &err);
	if (!s)
		fail("bunny scene", &err);
	world *wd = build(s);
	double bytes = (double)world_memory(wd) / ntris;
	double eps = 1e-4 * v3_len(ext);
	double tp[MAX_RUNS], ts[MAX_RUNS], tpk[MAX_RUNS], tpu[MAX_RUNS], tsk[MAX_RUNS], tpp[MAX_RUNS], be[MAX_RUNS], byte_e = -1,
	    pe[MAX_RUNS], se[MAX_RUNS];
	double sink = 0; /* the kernel rows' normals, so that none is left out */
	int ne = 0, npk[EMBREE_SLOTS] = {0};
	double pkm[EMBREE_SLOTS][MAX_RUNS], pks[EMBREE_SLOTS][MAX_RUNS];
	ray *sr = malloc((size_t)w * h * sizeof *sr);
	if (!sr)
		fail("secondary rays", NULL);
	long hits = 0, nsec = 0;
	for (int i = 0; i < runs; i++) {
		double t0 = cpu_now();
		primary_pass(wd, w, h, false, &hits);
		tp[i] = cpu_now() - t0;
		nsec = 0;
		for (int y = 0; y < h; y++)
			for (int x = 0; x < w; x++) {
				ray r = cam_ray(&wd->cam, x + 0.5, y + 0.5, w, h);
				hit hh;
				if (!world_intersect(wd, &r, 0.0, INFINITY, &hh))
					continue;
				vec3 n = hh.front ? hh.n : v3_neg(hh.n);
				sr[nsec++] = (ray){v3_madd(hh.p, n, eps), bench_diffuse_dir(n, (uint64_t)y * (uint64_t)w + (uint64_t)x)};
			}
		t0 = cpu_now();
		for (long k = 0; k < nsec; k++) {
			hit hh;
			world_intersect(wd, &sr[k], 0.0, INFINITY, &hh);
		}
		ts[i] = cpu_now() - t0;
		/* the kernel alone, as Embree's rtcIntersect1: distance, triangle,
		 * barycentric weights and the geometric normal (not unit); camera
		 * rays with the coherent hint, as the renderer traces them, and
		 * without it */
		tpk[i] = kernel_primary(wd, w, h, true, &sink);
		tpu[i] = kernel_primary(wd, w, h, false, &sink);
		tpp[i] = kernel_packet(wd, w, h, &sink);
		t0 = cpu_now();
		for (long k = 0; k < nsec; k++) {
			trace_hit th;
			if (world_trace(wd, &sr[k], 0.0, INFINITY, &th))
				sink += world_trace_ng(wd, &sr[k], &th).x;
		}
		tsk[i] = cpu_now() - t0;
		double eb, ebytes, ep, es, pm[EMBREE_SLOTS], ps[EMBREE_SLOTS];
		if (!quick && run_embree_mesh(BUNNY, w, h, &eb, &ebytes, &ep, &es, pm, ps) == 0) {
			for (int k = 0; k < EMBREE_SLOTS; k++)
				if (pm[k] > 0) {
					pkm[k][npk[k]] = pm[k];
					pks[k][npk[k]++] = ps[k];
				}
			be[ne] = eb;
			pe[ne] = ep;
			se[ne++] = es;
			byte_e = ebytes / ntris;
		}
	}
	free(sr);
	double mb = median(tb, runs), mp = median(tp, runs), ms = median(ts, runs);
	double mpk = median(tpk, runs), msk = median(tsk, runs), mpu = median(tpu, runs);
	double mpp = median(tpp, runs), mrpp = (double)w * h / mpp * 1e-6;
	double mrp = (double)w * h / mp * 1e-6, mrs = (double)nsec / ms * 1e-6;
	double mrpk = (double)w * h / mpk * 1e-6, mrsk = (double)nsec / msk * 1e-6, mrpu = (double)w * h / mpu * 1e-6;
	if (sink == 12345.678)
		puts(""); /* (never: keeps the normals computed) */
	double eb = ne ? median(be, ne) : -1, ep = ne ? median(pe, ne) : -1, es = ne ? median(se, ne) : -1;
	row *r = add_row("bunny 69k tris", "tri-build", 0, 0, 0, 1, runs, mb, -1);
	if (ne)
		snprintf(r->note, sizeof r->note, "BVH over triangles (CPU time); Embree high %.3f s: %.2fx its time; %.1f B/tri, Embree %.1f",
		         eb, mb / eb, bytes, byte_e);
	else
		snprintf(r->note, sizeof r->note, "BVH over triangles; %.1f bytes/triangle in the world", bytes);
	r = add_row("bunny 69k tris", "tri-primary", w, h, 1, 1, runs, mpk, mrpk);
	if (ne)
		snprintf(r->note, sizeof r->note,
		         "CPU time; world_trace_coherent + Ng; %.0f%% hit; Embree %.2f Mrays/s: "
		         "rtsh %.2fx (world_trace, no hint: %.2f, %.2fx)",
		         100.0 * hits / ((double)w * h), ep, mrpk / ep, mrpu, mrpu / ep);
	r = add_row("bunny 69k tris", "tri-primary-hit", w, h, 1, 1, runs, mp, mrp);
	if (ne)
		snprintf(r->note, sizeof r->note,
		         "CPU time; world_intersect (with the hit record shading uses): %.2fx Embree",
		         mrp / ep);
	r = add_row("bunny 69k tris", "tri-diffuse", w, h, 1, 1, runs, msk, mrsk);
	if (ne)
		snprintf(r->note, sizeof r->note,
		         "CPU time; world_trace + Ng; 1 cosine ray per primary hit; Embree %.2f Mrays/s: rtsh %.2fx", es,
		         mrsk / es);
	r = add_row("bunny 69k tris", "tri-diffuse-hit", w, h, 1, 1, runs, ms, mrs);
	if (ne)
		snprintf(r->note, sizeof r->note, "CPU time; world_intersect (with the hit record): %.2fx Embree", mrs / es);
	for (int k = 0; k < EMBREE_PACKETS; k++) {
		if (!npk[k])
			continue;
		char mode[32];
		snprintf(mode, sizeof mode, "embree-packet%d", 4 << k);
		double pm = median(pkm[k], npk[k]), ps = median(pks[k], npk[k]);
		r = add_row("bunny 69k tris", mode, w, h, 1, 1, npk[k], ps, pm);
		snprintf(r->note, sizeof r->note,
		         "rtcIntersect%d, %s-pixel tiles, coherent flag (CPU time); rtsh tri-primary %.2fx, rtcIntersect1 %.2f",
		         4 << k, packet_tiles[k], mrpk / pm, ep);
	}
	embree_call_row("bunny 69k tris", w, h, pkm[EMBREE_PACKETS], pks[EMBREE_PACKETS], npk[EMBREE_PACKETS], mrpp,
	                "tri-primary-packet16");
	r = add_row("bunny 69k tris", "tri-primary-packet16", w, h, 1, 1, runs, mpp, mrpp);
	if (npk[EMBREE_PACKETS - 1])
		snprintf(r->note, sizeof r->note,
		         "CPU, best of 3 after a warm-up (as Embree's); world_trace_packet 4x4 + Ng: %.2fx tri-primary; "
		         "rtcIntersect16 %.2f: rtsh %.2fx",
		         mrpp / mrpk, median(pkm[EMBREE_PACKETS - 1], npk[EMBREE_PACKETS - 1]),
		         mrpp / median(pkm[EMBREE_PACKETS - 1], npk[EMBREE_PACKETS - 1]));
	else
		snprintf(r->note, sizeof r->note,
		         "CPU, best of 3 after a warm-up (as Embree's); world_trace_packet 4x4 + Ng: %.2fx tri-primary",
		         mrpp / mrpk);
	if (!ne && !quick) {
		r = add_row("bunny 69k tris", "embree-mesh", 0, 0, 0, 1, 0, -1, -1);
		snprintf(r->note, sizeof r->note, "no %s/embree_mesh (needs embree3/rtcore.h)", bench_dir);
	}
	world_free(wd);
	scene_free(s);
}

static void print_table(FILE *f, bool tsv)
{
	if (tsv)
		fprintf(f, "scene\tmode\tresolution\tsamples\tthreads\truns\tmedian_s\tmrays_s\tnote\n");
	else
		fprintf(f, "%-20s %-15s %-10s %3s %3s %4s %11s %8s  %s\n", "scene", "mode", "resolution", "spp",
		        "thr", "runs", "median", "Mrays/s", "note");
	for (int i = 0; i < nrows; i++) {
		const row *r = &rows[i];
		char sec[32], mr[32];
		if (r->seconds < 0)
			snprintf(sec, sizeof sec, "-");
		else if (tsv)
			snprintf(sec, sizeof sec, "%.6f", r->seconds);
		else if (r->seconds < 1)
			snprintf(sec, sizeof sec, "%.2f ms", r->seconds * 1e3);
		else
			snprintf(sec, sizeof sec, "%.3f s", r->seconds);
		if (r->mrays < 0)
			snprintf(mr, sizeof mr, "-");
		else
			snprintf(mr, sizeof mr, "%.2f", r->mrays);
		if (tsv)
			fprintf(f, "%s\t%s\t%s\t%d\t%d\t%d\t%s\t%s\t%s\n", r->scene, r->mode, r->res, r->samples,
			        r->threads, r->runs, sec, mr, r->note);
		else
			fprintf(f, "%-20s %-15s %-10s %3d %3d %4d %11s %8s  %s\n", r->scene, r->mode, r->res, r->samples,
			        r->threads, r->runs, sec, mr, r->note);
	}
}

static void usage(void)
{
	fputs("usage: bench [--quick] [--runs N] [--out FILE.tsv] [--only grid|primary|packets|spheres|sphere-rays|load|path|preview|denoise|pixels|keymode|mesh|symbols]\n",
	      stderr);
	exit(2);
}

int main(int argc, char **argv)
{
	const char *out = NULL, *only = NULL;
	for (int i = 1; i < argc; i++) {
		if (strcmp(argv[i], "--quick") == 0)
			quick = true;
		else if (strcmp(argv[i], "--runs") == 0 && i + 1 < argc)
			runs = atoi(argv[++i]);
		else if (strcmp(argv[i], "--out") == 0 && i + 1 < argc)
			out = argv[++i];
		else if (strcmp(argv[i], "--only") == 0 && i + 1 < argc)
			only = argv[++i];
		else if (strcmp(argv[i], "--no-povray") == 0)
			no_povray = true;
		else
			usage();
	}
	if (quick && runs == 5)
		runs = 1;
	if (runs < 1 || runs > MAX_RUNS)
		usage();
	/* The Embree harness is built beside this program. */
	static char dir[1024];
	snprintf(dir, sizeof dir, "%s", argv[0]);
	char *slash = strrchr(dir, '/');
	if (slash) {
		*slash = '\0';
		bench_dir = dir;
	}
	/* the rtsh of this build: $(BUILD)/rtsh, or ./rtsh for the default build */
	snprintf(rtsh_bin, sizeof rtsh_bin, "%s/../rtsh", bench_dir);
	if (access(rtsh_bin, X_OK) != 0)
		snprintf(rtsh_bin, sizeof rtsh_bin, "./rtsh");
	snprintf(out_ppm, sizeof out_ppm, "/tmp/rtsh-bench-%ld.ppm", (long)getpid());
	double load1, load5, load15;
	FILE *la = fopen("/proc/loadavg", "r");
	if (la && fscanf(la, "%lf %lf %lf", &load1, &load5, &load15) == 3)
		fprintf(stderr, "bench: %s, %d runs per row; load average %.2f %.2f %.2f\n",
		        quick ? "quick" : "full", runs, load1, load5, load15);
	if (la)
		fclose(la);
	double t0 = now();
	if (!only || strcmp(only, "grid") == 0)
		bench_grid();
	if (!only || strcmp(only, "primary") == 0)
		bench_primary();
	if (!only || strcmp(only, "packets") == 0)
		bench_packets();
	if (!only || strcmp(only, "spheres") == 0)
		bench_spheres();
	if (!only || strcmp(only, "sphere-rays") == 0)
		bench_sphere_rays();
	if (!only || strcmp(only, "load") == 0)
		bench_load();
	if (!only || strcmp(only, "path") == 0)
		bench_path();
	if (!only || strcmp(only, "preview") == 0)
		bench_preview();
	if (!only || strcmp(only, "denoise") == 0)
		bench_denoise();
	if (!only || strcmp(only, "pixels") == 0)
		bench_pixels();
	if (!only || strcmp(only, "keymode") == 0)
		bench_keymode();
	if (!only || strcmp(only, "symbols") == 0)
		bench_symbols();
	if (!only || strcmp(only, "mesh") == 0)
		bench_mesh();
	la = fopen("/proc/loadavg", "r");
	if (la && fscanf(la, "%lf %lf %lf", &load1, &load5, &load15) == 3)
		fprintf(stderr, "bench: done in %.0f s; load average %.2f %.2f %.2f\n", now() - t0, load1, load5,
		        load15);
	if (la)
		fclose(la);
	unlink(out_ppm);
	print_table(stdout, false);
	if (out) {
		FILE *f = fopen(out, "w");
		if (!f)
			fail(out, NULL);
		print_table(f, true);
		if (fclose(f) != 0)
			fail(out, NULL);
	}
	return 0;
}
