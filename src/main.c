/* rtsh — the command line: options, then a batch render or the shell. */
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
#include "shell/options.h"

static void usage(FILE *f)
{
	fputs("usage: rtsh [OPTIONS] [SCENE.rt]\n"
	      "  rtsh                      open the shell on the built-in showcase scene\n"
	      "  rtsh SCENE.rt             open the shell on SCENE.rt\n"
	      "  rtsh SCENE.rt -o OUT      render at full resolution to OUT (.ppm .pfm .png), exit\n"
	      "options:\n"
	      "  -c 'CMD; CMD'    run shell commands, then exit\n"
	      "  -f FILE          run a command file (- = standard input), then exit\n"
	      "  -i               with -c or -f: stay in the interactive shell afterwards\n"
	      "  -o OUT           batch render to OUT\n"
	      "  -r WxH           resolution          -s N   samples per pixel\n"
	      "  -d N             depth               -t N   threads (0 = all CPUs)\n"
	      "  -m whitted|path  render mode         --seed N  random seed\n"
	      "  --color auto|truecolor|256|16|none   colour output (default auto)\n"
	      "  -q               no progress output\n"
	      "  --strict         validate scenes by the 42 subject's rules\n"
	      "  -h, --help       this help           -V, --version  version\n"
	      "See rtsh(1) for the shell's commands and rtsh(5) for the scene format.\n",
	      f);
}

static int usage_error(const char *fmt, const char *arg)
{
	fputs("rtsh: ", stderr);
	fprintf(stderr, fmt, arg);
	fputs("\nTry 'rtsh --help' for more information.\n", stderr);
	return 2;
}

void options_apply_settings(const rtsh_options *o, render_settings *s)
{
	for (int i = 0; i < o->nsettings; i++)
		settings_set(s, o->settings[i].def, o->settings[i].value, NULL);
}

/* Records a setting option after checking its value. */
static int add_setting(rtsh_options *o, const char *name, const char *value)
{
	rt_error err;
	const setting_def *def = settings_find(name, &err);
	render_settings probe = render_settings_default();
	if (!def || !settings_set(&probe, def, value, &err))
		return usage_error("%s", err.msg);
	if (o->nsettings == OPTIONS_MAX_SETTINGS)
		return usage_error("too many setting options%s", "");
	o->settings[o->nsettings++] = (option_setting){def, value};
	return 0;
}

/* Parses argv into o; returns -1 to go on, or an exit status. */
static int parse_args(int argc, char **argv, rtsh_options *o)
{
	for (int i = 1; i < argc; i++) {
		const char *a = argv[i];
		const char *next = i + 1 < argc ? argv[i + 1] : NULL;
#define NEED_ARG()                                                  \
	do {                                                        \
		if (!next)                                          \
			return usage_error("option %s needs a value", a); \
		i++;                                                \
	} while (0)
		int rc = 0;
		if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
			usage(stdout);
			return 0;
		} else if (strcmp(a, "-V") == 0 || strcmp(a, "--version") == 0) {
			printf("rtsh %s\n", RTSH_VERSION);
			return 0;
		} else if (strcmp(a, "-o") == 0) {
			NEED_ARG();
			o->output = next;
		} else if (strcmp(a, "-c") == 0) {
			NEED_ARG();
			o->commands = next;
		} else if (strcmp(a, "-f") == 0) {
			NEED_ARG();
			o->file = next;
		} else if (strcmp(a, "-i") == 0) {
			o->interactive = true;
		} else if (strcmp(a, "-q") == 0) {
			o->quiet = true;
		} else if (strcmp(a, "--strict") == 0) {
			o->strict = true;
		} else if (strcmp(a, "-r") == 0) {
			NEED_ARG();
			rc = add_setting(o, "resolution", next);
		} else if (strcmp(a, "-s") == 0) {
			NEED_ARG();
			rc = add_setting(o, "samples", next);
		} else if (strcmp(a, "-d") == 0) {
			NEED_ARG();
			rc = add_setting(o, "depth", next);
		} else if (strcmp(a, "-t") == 0) {
			NEED_ARG();
			rc = add_setting(o, "threads", next);
		} else if (strcmp(a, "-m") == 0) {
			NEED_ARG();
			rc = add_setting(o, "mode", next);
		} else if (strcmp(a, "--seed") == 0) {
			NEED_ARG();
			rc = add_setting(o, "seed", next);
		} else if (strcmp(a, "--color") == 0 || strncmp(a, "--color=", 8) == 0) {
			const char *v = a[7] == '=' ? a + 8 : next;
			if (a[7] != '=')
				NEED_ARG();
			if (!v)
				return usage_error("option --color needs a value%s", "");
			if (strcmp(v, "auto") == 0)
				o->color = COLOR_AUTO;
			else if (strcmp(v, "truecolor") == 0 || strcmp(v, "24bit") == 0)
				o->color = COLOR_TRUECOLOR;
			else if (strcmp(v, "256") == 0)
				o->color = COLOR_256;
			else if (strcmp(v, "16") == 0)
				o->color = COLOR_16;
			else if (strcmp(v, "none") == 0)
				o->color = COLOR_NONE;
			else
				return usage_error("--color \"%s\" is not valid; expected auto, truecolor, 256, 16 or none", v);
		} else if (strcmp(a, "--") == 0) {
			if (next && !o->scene) {
				o->scene = next;
				i++;
			}
		} else if (a[0] == '-' && a[1] != '\0') {
			return usage_error("unknown option \"%s\"", a);
		} else if (o->scene) {
			return usage_error("more than one scene file given (\"%s\"); expected one", a);
		} else {
			o->scene = a;
		}
		if (rc)
			return rc;
#undef NEED_ARG
	}
	if (o->output && (o->commands || o->file))
		return usage_error("-o cannot be combined with -c or -f%s; use the shell's save command", "");
	if (o->commands && o->file)
		return usage_error("give -c or -f, not both%s", "");
	if (o->interactive && !o->commands && !o->file)
		return usage_error("-i needs -c or -f%s", "");
	return -1;
}

typedef struct progress_state {
	struct timespec start;
	bool shown;
} progress_state;

static double since(const struct timespec *t0)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)(t.tv_sec - t0->tv_sec) + (t.tv_nsec - t0->tv_nsec) * 1e-9;
}

/* A progress bar with an ETA on standard error. */
static void show_progress(void *ctx, long done, long total)
{
	progress_state *p = ctx;
	double el = since(&p->start), frac = total ? (double)done / total : 1.0;
	const int width = 30;
	int fill = (int)(frac * width + 0.5);
	char bar[64];
	for (int i = 0; i < width; i++)
		bar[i] = i < fill ? '#' : '.';
	bar[width] = '\0';
	if (done > 0 && done < total)
		fprintf(stderr, "\r[%s] %3d%%  %.1fs, about %.1fs left ", bar, (int)(frac * 100), el,
		        el / frac - el);
	else
		fprintf(stderr, "\r[%s] %3d%%  %.1fs                  ", bar, (int)(frac * 100), el);
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
	if (image_format_of(o->output) == IMAGE_UNKNOWN)
		return usage_error("output \"%s\" has an unknown type; expected .ppm, .pfm or .png", o->output);
	if (!o->scene)
		return usage_error("-o needs a scene file%s", "");
	rt_warnings warn = {print_warning, NULL};
	rt_load_opts lo = {o->strict, o->quiet ? NULL : &warn};
	scene *s = rt_load_file(o->scene, &lo, &err);
	if (!s) {
		rt_error_format(&err, msg, sizeof msg);
		fprintf(stderr, "%s\n", msg);
		return 1;
	}
	render_settings set = render_settings_default();
	if (render_settings_apply_hints(&set, &s->hints) && !o->quiet)
		fprintf(stderr, "%s: resolution %dx%d is too large; rendering %dx%d (use -r to choose)\n",
		        o->scene, s->hints.width, s->hints.height, set.width, set.height);
	options_apply_settings(o, &set);
	world *w = world_build(s, &err);
	scene_free(s);
	if (!w) {
		rt_error_format(&err, msg, sizeof msg);
		fprintf(stderr, "%s: %s\n", o->scene, msg);
		return 1;
	}
	progress_state ps = {.shown = false};
	clock_gettime(CLOCK_MONOTONIC, &ps.start);
	bool bar = !o->quiet && isatty(STDERR_FILENO);
	framebuffer *fb = render_image(w, &set, NULL, bar ? show_progress : NULL, &ps, &err);
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
	memset(&o, 0, sizeof o);
	int rc = parse_args(argc, argv, &o);
	if (rc >= 0)
		return rc;
	if (o.output)
		return batch_render(&o);
	return shell_main(&o);
}
