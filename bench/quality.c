/* rtsh — equal-quality benchmarks (`make bench` runs them after the speed
 * table; bench/README.md explains the rows):
 *
 *   quality [--only cycles|preview] [--scene cornell|glass-sky|pbr|gltf] [--out FILE.tsv]
 *           [--no-cycles]
 *
 * cycles   rtsh's path mode against Blender's Cycles on the same scenes
 *          (scenes/cornell.rt at 256x256, bench/glass-sky.rt at 128x128 and
 *          bench/pbr-spheres.rt at 192x108, rebuilt in Cycles by
 *          bench/cycles_scene.py; and `gltf`, issue 26's scene built in
 *          Blender by bench/gltf_scene.py, rtsh on its glTF export and
 *          Cycles on the .blend, 192x108): CPU, one thread, a
 *          1-pixel box filter, no adaptive sampling, no denoising, the
 *          scene's bounces.
 *          Each renderer is judged against its own 4096-sample reference
 *          (2048 for the PBR scene, which also prints the mean radiance
 *          of every object, rtsh / Cycles)
 *          (rendered once and kept in build/quality/). At 16, 64 and 256
 *          samples it prints the CPU seconds per sample and
 *            eff = (MSE x seconds of rtsh) / (MSE x seconds of Cycles)
 *          over the whole picture and away from emitter edges: below 1 rtsh
 *          reaches a given noise in less time. Without `blender` the rtsh
 *          columns are still measured and the Cycles ones say why not.
 * preview  the shell's progressive preview of scenes/cornell.rt at 160x96
 *          (all threads, passes of 1, 1, 2, 4, ... samples): the RMS error
 *          of the picture after each pass against a 4096-sample reference,
 *          and the time it takes to reach given errors.
 *
 * Times are CPU seconds of the render (the rendering thread for one thread,
 * the process for the preview), so that the other work on a shared machine
 * counts less. Nothing here asserts a time.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "rtsh/denoise.h"
#include "rtsh/image.h"
#include "rtsh/render.h"
#include "rtsh/rtfile.h"
#include "rtsh/world.h"

#ifndef QDIR
#define QDIR "build/quality"
#endif

static FILE *tsv;

static void die(const char *what, const rt_error *err)
{
	fprintf(stderr, "quality: %s: %s\n", what, err ? err->msg : strerror(errno));
	exit(1);
}

static double cpu_now(clockid_t id)
{
	struct timespec ts;
	clock_gettime(id, &ts);
	return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static scene *load(const char *path)
{
	rt_error err;
	scene *s = rt_load_file(path, NULL, &err);
	if (!s)
		die(path, &err);
	return s;
}

static render_settings path_settings(int w, int h, int spp, int depth, int threads, uint64_t seed)
{
	render_settings set = render_settings_default();
	set.width = w;
	set.height = h;
	set.samples = spp;
	set.depth = depth;
	set.threads = threads;
	set.mode = MODE_PATH;
	set.seed = seed;
	return set;
}

/* A one-pass render; *cpu = the CPU seconds of this thread (one thread
 * renders here) or of the process. */
static framebuffer *render_timed(const world *w, const render_settings *set, double *cpu)
{
	clockid_t id = set->threads == 1 ? CLOCK_THREAD_CPUTIME_ID : CLOCK_PROCESS_CPUTIME_ID;
	rt_error err;
	double t0 = cpu_now(id);
	framebuffer *fb = render_image(w, set, NULL, NULL, NULL, &err);
	*cpu = cpu_now(id) - t0;
	if (!fb)
		die("render", &err);
	return fb;
}

static bool exists(const char *path)
{
	struct stat st;
	return stat(path, &st) == 0;
}

/* The cached reference at path, rendered first when missing. */
static framebuffer *reference(const world *w, render_settings set, const char *path)
{
	rt_error err;
	if (!exists(path)) {
		fprintf(stderr, "quality: rendering the reference %s (%d samples, once)\n", path, set.samples);
		set.threads = 0;
		double cpu;
		framebuffer *fb = render_timed(w, &set, &cpu);
		if (!image_write(path, fb, 0.0, &err))
			die(path, &err);
		fb_free(fb);
	}
	framebuffer *ref = image_read_pfm(path, &err);
	if (!ref)
		die(path, &err);
	return ref;
}

/* Pixels whose camera ray (through the pixel's centre) meets an emitter or
 * leaves the scene (the sky or background) are "emitter" pixels; a pixel
 * within 2 pixels of both kinds is on an emitter's edge. */
static unsigned char *edge_mask(const world *w, int fw, int fh)
{
	unsigned char *em = calloc((size_t)fw * fh, 1), *edge = calloc((size_t)fw * fh, 1);
	if (!em || !edge)
		die("memory", NULL);
	for (int y = 0; y < fh; y++)
		for (int x = 0; x < fw; x++) {
			ray r = cam_ray(&w->cam, x + 0.5, y + 0.5, fw, fh);
			hit h;
			bool hit_it = world_intersect(w, &r, 0.0, INFINITY, &h);
			vec3 e = hit_it ? w->mats[h.mat].emission : v3(1, 1, 1);
			em[y * fw + x] = e.x > 0 || e.y > 0 || e.z > 0;
		}
	for (int y = 0; y < fh; y++)
		for (int x = 0; x < fw; x++) {
			int kinds = 0;
			for (int dy = -2; dy <= 2; dy++)
				for (int dx = -2; dx <= 2; dx++) {
					int X = x + dx, Y = y + dy;
					if (X >= 0 && Y >= 0 && X < fw && Y < fh)
						kinds |= em[Y * fw + X] ? 1 : 2;
				}
			edge[y * fw + x] = kinds == 3;
		}
	free(em);
	return edge;
}

/* Mean squared error of the linear radiance over all pixels and over the
 * pixels off the mask. */
static void mse(const framebuffer *a, const framebuffer *ref, const unsigned char *edge, double *all,
                double *off)
{
	double s = 0, so = 0;
	long n = (long)a->w * a->h, no = 0;
	for (long i = 0; i < n; i++) {
		double e = 0;
		for (int c = 0; c < 3; c++) {
			double d = (double)a->rgb[i * 3 + c] - ref->rgb[i * 3 + c];
			e += d * d;
		}
		s += e;
		if (!edge[i]) {
			so += e;
			no++;
		}
	}
	*all = s / (3.0 * n);
	*off = so / (3.0 * (no ? no : 1));
}

static double mean(const framebuffer *fb)
{
	double s = 0;
	long n = (long)fb->w * fb->h * 3;
	for (long i = 0; i < n; i++)
		s += fb->rgb[i];
	return s / n;
}

/* --- rtsh against Cycles ---------------------------------------------------- */

#define NSPP 3
/* the glTF row's references (both renderers) */
#define GLTF_REF 2048
static const int spps[NSPP] = {16, 64, 256};

static bool have_blender(void)
{
	return system("command -v blender >/dev/null 2>&1") == 0;
}

/* Runs bench/cycles_scene.py; fills secs[] for spps (< 0 when missing) and
 * writes QDIR/NAME-cycles-SPP.pfm. */
static bool run_cycles(const char *path, const char *blend, int depth, const char *name, int w, int h,
                       int threads, int seed, const char *tag, const int *spp, int n, double *secs)
{
	char cmd[1024];
	int len = blend ? snprintf(cmd, sizeof cmd,
	                           "blender -b --factory-startup %s -P bench/gltf_scene.py -- render "
	                           "%dx%d %d %d %d " QDIR "/%s-%s",
	                           blend, w, h, threads, seed, depth, name, tag)
	                : snprintf(cmd, sizeof cmd,
	                           "blender -b --factory-startup -P bench/cycles_scene.py -- %s %dx%d %d %d "
	                           QDIR "/%s-%s",
	                           path, w, h, threads, seed, name, tag);
	for (int i = 0; i < n; i++)
		len += snprintf(cmd + len, sizeof cmd - (size_t)len, " %d", spp[i]);
	snprintf(cmd + len, sizeof cmd - (size_t)len, " 2>&1");
	FILE *p = popen(cmd, "r");
	if (!p)
		return false;
	for (int i = 0; i < n; i++)
		secs[i] = -1;
	char line[512];
	while (fgets(line, sizeof line, p)) {
		int s;
		double t;
		if (sscanf(line, "cycles %d %lf", &s, &t) == 2) {
			for (int i = 0; i < n; i++)
				if (spp[i] == s)
					secs[i] = t;
		} else if (strstr(line, "_scene.py:") || strstr(line, "Error")) {
			fprintf(stderr, "quality: blender: %s", line);
		}
	}
	int rc = pclose(p);
	return rc == 0;
}

/* The object (by_mat: the material, which tells the parts of a glTF file
 * read as one object apart) each pixel shows whole: the camera rays through
 * its centre and its four corners meet the same object (else -1). mat[k]
 * (nmat entries) gets the material object k shows. */
static int *object_mask(const world *w, int fw, int fh, bool by_mat, uint32_t *mat, size_t nmat)
{
	int *id = malloc(sizeof *id * (size_t)fw * fh);
	if (!id)
		die("memory", NULL);
	static const double off[5][2] = {{0.5, 0.5}, {0, 0}, {1, 0}, {0, 1}, {1, 1}};
	for (int y = 0; y < fh; y++)
		for (int x = 0; x < fw; x++) {
			int o = -2;
			for (int k = 0; k < 5 && o != -1; k++) {
				ray r = cam_ray(&w->cam, x + off[k][0], y + off[k][1], fw, fh);
				hit h;
				int ok = world_intersect(w, &r, 0.0, INFINITY, &h) ? (int)(by_mat ? h.mat : h.object) : -1;
				if (ok >= 0 && (size_t)ok < nmat)
					mat[ok] = h.mat;
				o = o == -2 || o == ok ? ok : -1;
			}
			id[y * fw + x] = o;
		}
	return id;
}

/* The mean radiance (all channels) of the pixels of object k. */
static double object_mean(const framebuffer *fb, const int *id, int k, long *n)
{
	double sum = 0;
	long c = 0;
	for (long i = 0; i < (long)fb->w * fb->h; i++)
		if (id[i] == k) {
			sum += (double)fb->rgb[i * 3] + fb->rgb[i * 3 + 1] + fb->rgb[i * 3 + 2];
			c++;
		}
	*n = c;
	return c ? sum / (3.0 * c) : 0.0;
}

/* A short name for object k's material. */
static void object_label(const object *o, char *buf, size_t n)
{
	const material_pbr *p = o->mat.pbr;
	if (!p)
		snprintf(buf, n, "%s%s", obj_kind_id(o->kind), o->mat.emission > 0 ? " lamp" : "");
	else
		snprintf(buf, n, "%s r=%.2f", p->metallic >= 0.5 ? "metal" : p->transmission >= 0.5 ? "glass" : "plastic",
		         p->roughness >= 0 ? p->roughness : 1.0);
}

/* A short name for world material k (a glTF file's). */
static void mat_label(const mat_lin *m, char *buf, size_t n)
{
	if (m->emission.x > 0 || m->emission.y > 0 || m->emission.z > 0)
		snprintf(buf, n, "lamp");
	else if (m->family != MAT_PBR)
		snprintf(buf, n, "phong");
	else
		snprintf(buf, n, "%s r=%.2f",
		         m->pbr.metallic >= 0.5f ? "metal" : m->pbr.transmission >= 0.5f ? "glass" : "plastic",
		         (double)m->pbr.roughness);
}

/* Per object: the mean radiance of rtsh's and Cycles' references and of
 * their renders at spp samples, and Cycles' own error at spp against its
 * reference (the noise to compare rtsh's difference with). */
static void objects_against_cycles(const scene *s, const world *w, const framebuffer *ref, const framebuffer *cref,
                                   const char *name, int W, int H, int spp, const framebuffer *fb)
{
	char cpath[256];
	snprintf(cpath, sizeof cpath, QDIR "/%s-cycles-%d.pfm", name, spp);
	rt_error err;
	framebuffer *cfb = image_read_pfm(cpath, &err);
	bool by_mat = s->nobjs == 1; /* one glTF file: its materials */
	size_t nk = by_mat ? w->nmats : s->nobjs;
	uint32_t *mat = calloc(nk ? nk : 1, sizeof *mat);
	if (!mat)
		die("memory", NULL);
	int *id = object_mask(w, W, H, by_mat, mat, nk);
	printf("per object, whole pixels only: mean radiance of rtsh / Cycles (references), and at %d spp\n", spp);
	printf("%4s %-16s %6s %9s %9s %7s %7s %9s\n", "obj", "material", "pixels", "rtsh ref", "cyc ref", "ratio",
	       "ratio@", "cyc err@");
	for (size_t k = 0; k < nk; k++) {
		long n;
		double a = object_mean(ref, id, (int)k, &n), b = object_mean(cref, id, (int)k, &n);
		if (n < 20)
			continue;
		double a1 = object_mean(fb, id, (int)k, &n), b1 = cfb ? object_mean(cfb, id, (int)k, &n) : -1;
		char label[32];
		if (by_mat || (obj_kind_flags(s->objs[k].kind) & KIND_MODEL)) /* a glTF node: its material */
			mat_label(&w->mats[mat[k]], label, sizeof label);
		else
			object_label(&s->objs[k], label, sizeof label);
		printf("%4zu %-16s %6ld %9.5f %9.5f %7.4f %7.4f %9.4f\n", k, label, n, a, b, a / b, cfb ? a1 / b1 : -1,
		       cfb ? b1 / b - 1 : -1);
		if (tsv)
			fprintf(tsv, "%s\tobject\t%zu\t%s\t%.6g\t%.6g\t%.4f\t%.4f\t%.4f\n", name, k, label, a, b, a / b,
			        cfb ? a1 / b1 : -1, cfb ? b1 / b - 1 : -1);
	}
	free(id);
	free(mat);
	fb_free(cfb);
}

/* path: the scene rtsh renders; blend: NULL (bench/cycles_scene.py
 * rebuilds the .rt in Cycles) or the .blend that Cycles renders (the glTF
 * row: path is its export); depth: 0 = the scene's. */
static void bench_cycles_scene(const char *path, const char *blend, int depth, const char *name, int W, int H,
                               int REF, bool objects, bool cycles)
{
	scene *s = load(path);
	if (depth <= 0)
		depth = s->hints.depth >= 0 ? s->hints.depth : 5;
	rt_error err;
	world *w = world_build(s, &err);
	if (!w)
		die("world_build", &err);
	char rpath[256], cpath[256];
	snprintf(rpath, sizeof rpath, QDIR "/%s-rtsh-ref.pfm", name);
	framebuffer *ref = reference(w, path_settings(W, H, REF, depth, 0, 4242), rpath);
	unsigned char *edge = edge_mask(w, W, H);
	long nedge = 0;
	for (int i = 0; i < W * H; i++)
		nedge += edge[i];

	framebuffer *cref = NULL;
	double csec[NSPP];
	const char *why = NULL;
	if (!cycles) {
		why = "not asked for (--no-cycles)";
	} else if (!have_blender()) {
		why = "blender is not installed (apt-get install blender); skipped";
	} else {
		snprintf(cpath, sizeof cpath, QDIR "/%s-cycles-ref-%d.pfm", name, REF);
		if (!exists(cpath)) {
			fprintf(stderr, "quality: rendering the Cycles reference %s (once; minutes)\n", cpath);
			double t;
			const int one = REF;
			if (!run_cycles(path, blend, depth, name, W, H, 2, 4242, "cycles-ref", &one, 1, &t))
				why = "blender failed on the reference";
		}
		if (!why && !(cref = image_read_pfm(cpath, &err)))
			why = "no Cycles reference";
		if (!why && !run_cycles(path, blend, depth, name, W, H, 1, 7, "cycles", spps, NSPP, csec))
			why = "blender failed";
	}
	printf("\n%s, %dx%d, depth %d, one thread, against each renderer's own %d-sample reference\n",
	       name, W, H, depth, REF);
	printf("(%ld pixels within 2 of an emitter's edge are left out of the \"away\" columns)\n", nedge);
	if (cref)
		printf("references: mean radiance rtsh / Cycles = %.4f\n", mean(ref) / mean(cref));
	else
		printf("Cycles: %s\n", why);
	printf("%5s %9s %9s %11s %11s %11s %11s %7s %7s\n", "spp", "rtsh s/spp", "cyc s/spp", "rtsh MSE",
	       "cyc MSE", "rtsh away", "cyc away", "eff", "eff away");
	for (int i = 0; i < NSPP; i++) {
		double t;
		render_settings set = path_settings(W, H, spps[i], depth, 1, 1 + (uint64_t)i);
		framebuffer *fb = render_timed(w, &set, &t);
		double m, mo, cm = -1, cmo = -1, ct = -1;
		mse(fb, ref, edge, &m, &mo);
		if (objects && cref && i == NSPP - 1)
			objects_against_cycles(s, w, ref, cref, name, W, H, spps[i], fb);
		fb_free(fb);
		if (cref && csec[i] > 0) {
			snprintf(cpath, sizeof cpath, QDIR "/%s-cycles-%d.pfm", name, spps[i]);
			framebuffer *cfb = image_read_pfm(cpath, &err);
			if (cfb && cfb->w == W && cfb->h == H) {
				mse(cfb, cref, edge, &cm, &cmo);
				ct = csec[i];
			}
			fb_free(cfb);
		}
		if (ct > 0) {
			double eff = m * t / (cm * ct), effo = mo * t / (cmo * ct);
			printf("%5d %9.5f %9.5f %11.4g %11.4g %11.4g %11.4g %7.3f %7.3f\n", spps[i], t / spps[i],
			       ct / spps[i], m, cm, mo, cmo, eff, effo);
			if (tsv)
				fprintf(tsv, "%s\tcycles\t%d\t%.6f\t%.6f\t%.6g\t%.6g\t%.6g\t%.6g\t%.4f\t%.4f\n", name,
				        spps[i], t, ct, m, cm, mo, cmo, eff, effo);
		} else {
			printf("%5d %9.5f %9s %11.4g %11s %11.4g %11s %7s %7s\n", spps[i], t / spps[i], "-", m, "-",
			       mo, "-", "-", "-");
			if (tsv)
				fprintf(tsv, "%s\tcycles\t%d\t%.6f\t-\t%.6g\t-\t%.6g\t-\t-\t-\n", name, spps[i], t, m,
				        mo);
		}
		fflush(stdout);
	}
	free(edge);
	fb_free(cref);
	fb_free(ref);
	world_free(w);
	scene_free(s);
}

/* The glTF row (issue 26): bench/gltf_scene.py builds the scene in Blender
 * and exports it with Blender's glTF exporter (once, kept in QDIR); rtsh
 * renders the .glb from its own camera and lamp, Cycles the .blend. */
static void bench_gltf(bool cycles)
{
	const char *glb = QDIR "/pbr-gltf.glb", *blend = QDIR "/pbr-gltf.blend";
	if (!exists(glb) || !exists(blend)) {
		if (!cycles || !have_blender()) {
			printf("\npbr-gltf: skipped (%s); the scene is built by Blender\n",
			       cycles ? "blender is not installed" : "--no-cycles");
			return;
		}
		fprintf(stderr, "quality: building %s in Blender (once)\n", glb);
		if (system("blender -b --factory-startup -P bench/gltf_scene.py -- build " QDIR
		           "/pbr-gltf >" QDIR "/pbr-gltf-build.log 2>&1") != 0 ||
		    !exists(glb)) {
			printf("\npbr-gltf: Blender could not build or export the scene (%s; the exporter needs "
			       "python3-numpy)\n",
			       QDIR "/pbr-gltf-build.log");
			return;
		}
	}
	bench_cycles_scene(glb, blend, 8, "pbr-gltf", 192, 108, GLTF_REF, true, cycles);
}

/* --- the progressive preview ------------------------------------------------ */

/* The RMS error of the displayed picture: sRGB codes / 255, as the
 * terminal shows it (exposure 0, clamped). */
static double rms_display(const framebuffer *a, const framebuffer *ref)
{
	double s = 0;
	long n = (long)a->w * a->h * 3;
	for (long i = 0; i < n; i++) {
		double d = ((double)linear_to_srgb8(a->rgb[i]) - linear_to_srgb8(ref->rgb[i])) / 255.0;
		s += d * d;
	}
	return sqrt(s / n);
}

/* The RMS error of the linear radiance. */
static double rms_linear(const framebuffer *a, const framebuffer *ref)
{
	double s = 0;
	long n = (long)a->w * a->h * 3;
	for (long i = 0; i < n; i++) {
		double d = (double)a->rgb[i] - ref->rgb[i];
		s += d * d;
	}
	return sqrt(s / n);
}

/* Updates reach[k], the time target k was first met, from the errors
 * (prev_t, prev_e) and (t, e) of two passes, interpolated in log-log. */
static void crossing(const double *targets, int nt, double *reach, double prev_t, double prev_e, double t,
                     double e)
{
	for (int k = 0; k < nt; k++)
		if (reach[k] < 0 && e <= targets[k]) {
			if (prev_t > 0 && prev_e > e)
				reach[k] = exp(log(prev_t) + (log(targets[k]) - log(prev_e)) / (log(e) - log(prev_e)) *
				                                 (log(t) - log(prev_t)));
			else
				reach[k] = t;
		}
}

static void bench_preview(void)
{
	const int W = 160, H = 96, MAX = 256;
	scene *s = load("scenes/cornell.rt");
	int depth = s->hints.depth >= 0 ? s->hints.depth : 5;
	rt_error err;
	world *w = world_build(s, &err);
	if (!w)
		die("world_build", &err);
	framebuffer *ref = reference(w, path_settings(W, H, 4096, depth, 0, 4242),
	                             QDIR "/cornell-preview-ref.pfm");
	static const double targets[] = {0.05, 0.03, 0.02};
	const int nt = 3;
	double reach[2][3] = {{-1, -1, -1}, {-1, -1, -1}}, prev_t = 0, prev_e[2] = {0, 0};
	printf("\ncornell.rt preview, %dx%d, all threads, passes 1, 1, 2, 4, ... samples; RMS error "
	       "against a 4096-sample reference, of the displayed sRGB picture (codes / 255) and of the "
	       "linear radiance\n",
	       W, H);
	printf("%6s %10s %10s %10s\n", "spp", "cpu s", "rms sRGB", "rms linear");
	framebuffer *fb = fb_new(W, H);
	render_settings set = path_settings(W, H, MAX, depth, 0, 3);
	double t = 0;
	for (int done = 0, n = 1; done < MAX; done += n, n = done) {
		render_job job = {.w = w, .set = set, .fb = fb, .sample_begin = done, .sample_end = done + n};
		double t0 = cpu_now(CLOCK_PROCESS_CPUTIME_ID);
		if (render_run(&job, &err) != RENDER_DONE)
			die("render", &err);
		t += cpu_now(CLOCK_PROCESS_CPUTIME_ID) - t0;
		double e[2] = {rms_display(fb, ref), rms_linear(fb, ref)};
		printf("%6d %10.4f %10.5f %10.5f\n", done + n, t, e[0], e[1]);
		for (int m = 0; m < 2; m++) {
			crossing(targets, nt, reach[m], prev_t, prev_e[m], t, e[m]);
			prev_e[m] = e[m];
		}
		prev_t = t;
	}
	for (int m = 0; m < 2; m++)
		for (int k = 0; k < nt; k++) {
			const char *space = m ? "linear" : "sRGB";
			if (reach[m][k] > 0)
				printf("RMS %s %.3f reached after %.3f CPU s\n", space, targets[k], reach[m][k]);
			else
				printf("RMS %s %.3f not reached in %d samples\n", space, targets[k], MAX);
			if (tsv)
				fprintf(tsv, "cornell.rt\tpreview-rms-%s\t%.3f\t%.4f\n", space, targets[k],
				        reach[m][k]);
		}
	fb_free(fb);
	fb_free(ref);
	world_free(w);
	scene_free(s);
}

/* --- the denoiser (issue 27) ------------------------------------------------ */

/* The scenes and sizes of issue 27: the preview's sizes from 128x96 to
 * 640x360, and 1280x720 for `save`. */
static const char *const dn_scenes[] = {"cornell", "sky-spheres", "metal-fuzz", "final", "spot"};
static const int dn_sizes[][2] = {{128, 96}, {160, 96}, {200, 120}, {320, 180},
                                  {480, 270}, {640, 360}, {1280, 720}};
/* Samples of the references: 1024 up to 320x180, 256 above (a reference
 * already rendered with more is used instead). A reference's own noise
 * (another seed) adds the same to every column's expected squared error:
 * 64/256 of the 64-sample column's at 256 samples, so it can only bring
 * the ratios towards 1 and never changes which column is lower. */
static int dn_ref_samples(int w, int h)
{
	long px = (long)w * h;
	return px <= 320 * 180 ? 1024 : 256;
}

/* Pixels left out: those whose centre ray meets a lamp (an emitting
 * object, not the sky) and their 8 neighbours, where any picture's error is
 * the lamp's edge (radiance 8 or more next to radiance below 1). */
static unsigned char *lamp_mask(const world *w, int fw, int fh, long *count)
{
	unsigned char *em = calloc((size_t)fw * fh, 1), *out = calloc((size_t)fw * fh, 1);
	if (!em || !out)
		die("memory", NULL);
	for (int y = 0; y < fh; y++)
		for (int x = 0; x < fw; x++) {
			ray r = cam_ray(&w->cam, x + 0.5, y + 0.5, fw, fh);
			hit h;
			if (world_intersect(w, &r, 0.0, INFINITY, &h)) {
				vec3 e = w->mats[h.mat].emission;
				em[y * fw + x] = e.x > 0 || e.y > 0 || e.z > 0;
			}
		}
	*count = 0;
	for (int y = 0; y < fh; y++)
		for (int x = 0; x < fw; x++) {
			for (int dy = -1; dy <= 1; dy++)
				for (int dx = -1; dx <= 1; dx++) {
					int X = x + dx, Y = y + dy;
					if (X >= 0 && Y >= 0 && X < fw && Y < fh && em[Y * fw + X])
						out[y * fw + x] = 1;
				}
			*count += out[y * fw + x];
		}
	free(em);
	return out;
}

/* The RMS error of the linear radiance over the pixels off the mask. */
static double rms_masked(const framebuffer *a, const framebuffer *ref, const unsigned char *mask)
{
	double s = 0;
	long n = 0;
	for (long i = 0; i < (long)a->w * a->h; i++) {
		if (mask[i])
			continue;
		for (int c = 0; c < 3; c++) {
			double d = (double)a->rgb[i * 3 + c] - ref->rgb[i * 3 + c];
			s += d * d;
		}
		n += 3;
	}
	return sqrt(s / (n ? n : 1));
}

/* The render of set, its samples spent uniformly (every pixel set->samples,
 * no adaptive pass: render_image spends a denoised render's adaptively),
 * then denoised: the column that shows what the adaptive budget did. */
static framebuffer *render_uniform_denoised(const world *w, const render_settings *set)
{
	rt_error err;
	framebuffer *fb = fb_new(set->width, set->height);
	if (!fb || !denoise_prepare(fb))
		die("memory", NULL);
	render_job job = {.w = w, .set = *set, .fb = fb, .sample_begin = 0, .sample_end = set->samples};
	if (render_run(&job, &err) != RENDER_DONE)
		die("render", &err);
	if (!denoise_image(fb, fb->rgb, render_threads(set)))
		die("memory", NULL);
	return fb;
}

/* 8 samples denoised, 64 and 8 raw, against a reference of another seed
 * (the same seed would share its first samples with the pictures). */
static void bench_denoise(const char *only_scene, int only_w, int only_h)
{
	printf("\nthe denoiser (issue 27): RMS error of the linear radiance against a reference of another "
	       "seed (ref: its samples), lamp pixels and their neighbours left out; all threads\n");
	printf("8 dn: 8 samples a pixel on average, the first 6 everywhere and the rest where the noise is "
	       "(adaptive); 8 un: 8 in every pixel (uniform); both denoised\n");
	printf("%-12s %9s %5s %10s %10s %10s %10s %8s %8s %8s\n", "scene", "size", "ref", "8 dn", "8 un",
	       "64 raw", "8 raw", "dn/64", "un/64", "dn/8");
	int nbad = 0, nrows = 0;
	for (size_t si = 0; si < sizeof dn_scenes / sizeof *dn_scenes; si++) {
		if (only_scene && strcmp(only_scene, dn_scenes[si]) != 0)
			continue;
		char path[256];
		snprintf(path, sizeof path, "scenes/%s.rt", dn_scenes[si]);
		scene *s = load(path);
		int depth = s->hints.depth >= 0 ? s->hints.depth : 5;
		rt_error err;
		world *w = world_build(s, &err);
		if (!w)
			die("world_build", &err);
		for (size_t ri = 0; ri < sizeof dn_sizes / sizeof *dn_sizes; ri++) {
			int W = dn_sizes[ri][0], H = dn_sizes[ri][1];
			if (only_w > 0 && (W != only_w || H != only_h))
				continue;
			int nref = dn_ref_samples(W, H);
			char rpath[300];
			for (int more = 1024; more > nref; more /= 2) {
				snprintf(rpath, sizeof rpath, QDIR "/dn-%s-%dx%d-%d.pfm", dn_scenes[si], W, H, more);
				if (exists(rpath)) {
					nref = more;
					break;
				}
			}
			snprintf(rpath, sizeof rpath, QDIR "/dn-%s-%dx%d-%d.pfm", dn_scenes[si], W, H, nref);
			framebuffer *ref = reference(w, path_settings(W, H, nref, depth, 0, 4242), rpath);
			long nlamp;
			unsigned char *mask = lamp_mask(w, W, H, &nlamp);
			double e[4];
			static const int spp[4] = {8, 64, 8, 8};
			for (int k = 0; k < 4; k++) {
				render_settings set = path_settings(W, H, spp[k], depth, 0, 1);
				set.denoise = k == 0 || k == 3 ? DENOISE_ON : DENOISE_OFF;
				double cpu;
				framebuffer *fb = k == 3 ? render_uniform_denoised(w, &set) : render_timed(w, &set, &cpu);
				e[k] = rms_masked(fb, ref, mask);
				fb_free(fb);
			}
			char size[32];
			snprintf(size, sizeof size, "%dx%d", W, H);
			bool win = e[0] < e[1];
			nbad += !win;
			nrows++;
			printf("%-12s %9s %5d %10.5f %10.5f %10.5f %10.5f %8.3f %8.3f %8.3f%s\n", dn_scenes[si], size, nref,
			       e[0], e[3], e[1], e[2], e[0] / e[1], e[3] / e[1], e[0] / e[2], win ? "" : "  (loses to 64 raw)");
			fflush(stdout);
			if (tsv)
				fprintf(tsv, "%s.rt\tdenoise-rms\t%s\t%d\t%.6f\t%.6f\t%.6f\t%ld\n", dn_scenes[si], size,
				        nref, e[0], e[1], e[2], nlamp);
			free(mask);
			fb_free(ref);
		}
		world_free(w);
		scene_free(s);
	}
	printf("8 spp denoised below 64 raw in %d of %d rows\n", nrows - nbad, nrows);
}

int main(int argc, char **argv)
{
	const char *only = NULL, *out = NULL, *one = NULL;
	bool cycles = true;
	int only_w = 0, only_h = 0;
	for (int i = 1; i < argc; i++) {
		if (strcmp(argv[i], "--only") == 0 && i + 1 < argc)
			only = argv[++i];
		else if (strcmp(argv[i], "--out") == 0 && i + 1 < argc)
			out = argv[++i];
		else if (strcmp(argv[i], "--no-cycles") == 0)
			cycles = false;
		else if (strcmp(argv[i], "--scene") == 0 && i + 1 < argc)
			one = argv[++i];
		else if (strcmp(argv[i], "--size") == 0 && i + 1 < argc &&
		         sscanf(argv[i + 1], "%dx%d", &only_w, &only_h) == 2)
			i++;
		else {
			fputs("usage: quality [--only cycles|preview|denoise] [--scene NAME] [--size WxH] "
			      "[--out FILE.tsv] [--no-cycles]\n",
			      stderr);
			return 2;
		}
	}
	mkdir("build", 0777);
	mkdir(QDIR, 0777);
	if (out && !(tsv = fopen(out, "w")))
		die(out, NULL);
	if (!only || strcmp(only, "cycles") == 0) {
		if (!one || strcmp(one, "cornell") == 0)
			bench_cycles_scene("scenes/cornell.rt", NULL, 0, "cornell", 256, 256, 4096, false, cycles);
		if (!one || strcmp(one, "glass-sky") == 0)
			bench_cycles_scene("bench/glass-sky.rt", NULL, 0, "glass-sky", 128, 128, 4096, false, cycles);
		if (!one || strcmp(one, "pbr") == 0)
			bench_cycles_scene("bench/pbr-spheres.rt", NULL, 0, "pbr", 192, 108, 2048, true, cycles);
		if (!one || strcmp(one, "gltf") == 0)
			bench_gltf(cycles);
	}
	if (!only || strcmp(only, "preview") == 0)
		bench_preview();
	if (!only || strcmp(only, "denoise") == 0)
		bench_denoise(one, only_w, only_h);
	if (tsv && fclose(tsv) != 0)
		die(out, NULL);
	return 0;
}
