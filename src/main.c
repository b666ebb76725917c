/* rtsh — the command line (shell/args.h), then a batch render or the shell. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

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

static int batch_render(const rtsh_options *o)
{
	rt_error err;
	char msg[RT_ERROR_MSG_MAX + RT_ERROR_FILE_MAX + 32];
	if (!image_type_of(o->output)) {
		char exts[128], fmt[512]; /* the extensions from image.c's table of formats */
		image_extensions(exts, sizeof exts, false);
		snprintf(fmt, sizeof fmt, "output \"%%s\" has an unknown type; expected %s", exts);
		return usage_error(fmt, o->output);
	}
	if (!o->scene)
		return usage_error("-o needs a scene file%s", "");
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
		        o->scene, s->hints.width, s->hints.height, set.width, set.height);
	world *w = world_build(s, &err);
	scene_free(s);
	if (!w) {
		rt_error_format(&err, msg, sizeof msg);
		fprintf(stderr, "%s: %s\n", o->scene, msg);
		return 1;
	}
	batch_progress ps = {.w = set.width, .h = set.height, .samples = set.samples, .shown = false};
	clock_gettime(CLOCK_MONOTONIC, &ps.start);
	bool bar = !o->quiet && isatty(STDERR_FILENO);
	/* the 8-bit codes are made by the render's threads as tiles finish */
	bool eight = !image_type_of(o->output)->linear;
	framebuffer *fb = (eight ? render_image_srgb8 : render_image)(w, &set, NULL, bar ? show_progress : NULL,
	                                                               &ps, &err);
	world_free(w);
	if (ps.shown)
		fputc('\n', stderr);
	if (!fb) {
		rt_error_format(&err, msg, sizeof msg);
		fprintf(stderr, "%s: %s\n", o->scene, msg);
		return 1;
	}
	bool ok = image_write(o->output, fb, set.exposure, &err);
	fb_free(fb);
	if (!ok) {
		rt_error_format(&err, msg, sizeof msg);
		fprintf(stderr, "%s\n", msg);
		return 1;
	}
	if (*file_write_note())
		fprintf(stderr, "rtsh: %s\n", file_write_note());
	if (!o->quiet && isatty(STDERR_FILENO))
		fprintf(stderr, "wrote %s (%dx%d, %d samples, %s) in %.2fs\n", o->output, set.width,
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
