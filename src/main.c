/* rtsh — the command line (shell/args.h), then a batch render or the shell. */
#include <errno.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>
#include <unistd.h>

#include "base/visible.h"
#include "rtsh/image.h"
#include "rtsh/render.h"
#include "rtsh/rtfile.h"
#include "rtsh/settings.h"
#include "rtsh/world.h"
#include "shell/args.h"
#include "shell/preview.h"
#include "shell/progress.h"
#include "shell/turntable.h"

static int usage_error(const char *fmt, const char *arg)
{
	fputs("rtsh: ", stderr);
	fprintf(stderr, fmt, arg);
	fputs("\nTry 'rtsh --help' for more information.\n", stderr);
	return 2;
}

typedef struct batch_progress {
	struct timespec start;
	int w, h, samples;
	bool shown;
} batch_progress;

static double since(const struct timespec *t0)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)(t.tv_sec - t0->tv_sec) + (t.tv_nsec - t0->tv_nsec) * 1e-9;
}

/* The progress line (shell/progress.h) on standard error. */
static void show_progress(void *ctx, long done, long total)
{
	batch_progress *p = ctx;
	progress_state ps = {p->w, p->h, p->samples, done, total, since(&p->start)};
	progress_print(stderr, &ps);
	p->shown = true;
}

static void print_warning(void *ctx, const rt_error *w)
{
	(void)ctx;
	char buf[RT_ERROR_MSG_MAX + RT_ERROR_FILE_MAX + 32];
	rt_error_format(w, buf, sizeof buf);
	fprintf(stderr, "%s (warning)\n", buf);
}

/* What image_write_rendered's make needs: the render of batch mode. */
typedef struct batch_make {
	const world *w;
	const render_settings *set;
	bool eight;       /* an 8-bit format: the codes made as tiles finish */
	bool bar;
	batch_progress *ps;
	render_rows_fn rows; /* the file's, which batch_rows calls */
	void *rows_ctx;
	bool write_stopped; /* the file's write stopped the render */
	bool failed;      /* the render failed by itself: err is its */
	rt_error err;
} batch_make;

static bool batch_rows(void *ctx, const framebuffer *fb, int y0, int y1, const uint8_t *codes)
{
	batch_make *b = ctx;
	if (b->rows(b->rows_ctx, fb, y0, y1, codes))
		return true;
	b->write_stopped = true;
	return false;
}

static framebuffer *batch_make_fn(void *ctx, render_rows_fn rows, void *rows_ctx, rt_error *err)
{
	batch_make *b = ctx;
	clock_gettime(CLOCK_MONOTONIC, &b->ps->start);
	render_progress_fn progress = b->bar ? show_progress : NULL;
	b->rows = rows;
	b->rows_ctx = rows_ctx;
	framebuffer *fb = rows ? render_image_rows(b->w, b->set, NULL, progress, b->ps, batch_rows, b, &b->err)
	                  : b->eight ? render_image_srgb8(b->w, b->set, NULL, progress, b->ps, &b->err)
	                             : render_image(b->w, b->set, NULL, progress, b->ps, &b->err);
	if (b->ps->shown) {
		fputc('\n', stderr);
		b->ps->shown = false;
	}
	if (!fb) {
		b->failed = !b->write_stopped;
		*err = b->err;
	}
	return fb;
}

static int batch_render(const rtsh_options *o)
{
	rt_error err;
	char msg[RT_ERROR_MSG_MAX + RT_ERROR_FILE_MAX + 32];
	if (!image_type_of(o->output)) {
		char exts[128], fmt[640]; /* the extensions from image.c's table of formats */
		image_extensions(exts, sizeof exts, false);
		/* a scene or a picture as text is the shell's save, not -o's */
		const char *dot = strrchr(o->output, '.');
		bool text = dot && (strcasecmp(dot, ".rt") == 0 || strcasecmp(dot, ".ans") == 0);
		snprintf(fmt, sizeof fmt, "output \"%%s\" has an unknown type; expected %s%s", exts,
		         text ? " (a .rt scene or an .ans picture is written by the shell's save: -c 'save FILE')" : "");
		char shown[4096]; /* escape sequences visible, not run */
		text_visible(shown, sizeof shown, o->output, false);
		return usage_error(fmt, shown);
	}
	if (!o->scene)
		return usage_error("-o needs a scene file%s", "");
	/* the names as messages show them: escape sequences visible, not run */
	char scene_name[4096], output_name[4096];
	text_visible(scene_name, sizeof scene_name, o->scene, false);
	text_visible(output_name, sizeof output_name, o->output, false);
	rt_warnings warn = {print_warning, NULL};
	rt_load_opts lo = {.strict = o->strict, .warn = o->quiet ? NULL : &warn};
	scene *s = rt_load_file(o->scene, &lo, &err);
	if (!s) {
		rt_error_format(&err, msg, sizeof msg);
		fprintf(stderr, "%s\n", msg);
		return 1;
	}
	render_settings set = render_settings_default();
	bool clamped = render_settings_apply_hints(&set, &s->hints);
	int cw = set.width, ch = set.height;
	options_apply_settings(o, &set);
	/* Said only when the clamped size is the one rendered (not -r's). */
	if (clamped && set.width == cw && set.height == ch && !o->quiet)
		fprintf(stderr, "%s: resolution %dx%d is too large; rendering %dx%d (use -r to choose)\n",
		        scene_name, s->hints.width, s->hints.height, set.width, set.height);
	/* the tree built by the render's threads too (the same world) */
	world *w = world_build_threads(s, render_threads(&set), NULL, &err);
	scene_free(s);
	if (!w) {
		rt_error_format(&err, msg, sizeof msg);
		fprintf(stderr, "%s: %s\n", scene_name, msg);
		return 1;
	}
	batch_progress ps = {.w = set.width, .h = set.height, .samples = set.samples, .shown = false};
	clock_gettime(CLOCK_MONOTONIC, &ps.start);
	/* The file is written as the render's rows finish (PPM, PNG), then
	 * synced and renamed over the old one (image.h). */
	batch_make bm = {.w = w, .set = &set, .eight = !image_type_of(o->output)->linear,
	                 .bar = !o->quiet && isatty(STDERR_FILENO), .ps = &ps};
	bool ok = image_write_rendered(o->output, set.width, set.height, set.exposure, batch_make_fn, &bm, &err);
	world_free(w);
	if (!ok && bm.failed) {
		rt_error_format(&bm.err, msg, sizeof msg);
		fprintf(stderr, "%s: %s\n", scene_name, msg);
		return 1;
	}
	if (!ok) {
		rt_error_format(&err, msg, sizeof msg);
		fprintf(stderr, "%s\n", msg);
		return 1;
	}
	if (*file_write_note())
		fprintf(stderr, "rtsh: %s\n", file_write_note());
	if (!o->quiet && isatty(STDERR_FILENO))
		fprintf(stderr, "wrote %s (%dx%d, %d samples, %s) in %.2fs\n", output_name, set.width,
		        set.height, set.samples, render_mode_name(set.mode), since(&ps.start));
	return 0;
}

int main(int argc, char **argv)
{
	rtsh_options o;
	int rc = args_parse(argc, argv, ARGS_RTSH, "rtsh", &o);
	if (rc >= 0)
		return rc;
	if (o.preview)
		return preview_main(&o);
	if (o.output && o.turntable)
		return turntable_batch(&o);
	if (o.output)
		return batch_render(&o);
	return shell_main(&o);
}
