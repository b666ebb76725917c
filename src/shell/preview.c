/* rtsh — previews for file managers (preview.h). */
#include "shell/preview.h"

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "rtsh/filesrc.h"
#include "rtsh/mesh.h"
#include "rtsh/orbit.h"
#include "rtsh/render.h"
#include "rtsh/rtfile.h"
#include "rtsh/settings.h"
#include "rtsh/texture.h"
#include "rtsh/world.h"
#include "shell/args.h"
#include "base/abuf.h"
#include "base/visible.h"
#include "term/caps.h"
#include "term/frame.h"
#include "term/encoder.h"
#include "term/pixels.h"

#define STR(x) #x
#define XSTR(x) STR(x)

/* The watchdog: a loader or a render that takes too long ends the process
 * (write and _exit are async-signal-safe); a file manager never waits on a
 * hung previewer. */
static void watchdog(int sig)
{
	(void)sig;
	static const char msg[] = "rtsh: --preview: gave up after " XSTR(PREVIEW_TIMEOUT) " seconds\n";
	ssize_t w = write(STDERR_FILENO, msg, sizeof msg - 1);
	(void)w;
	_exit(1);
}

/* The file's name with its control characters made visible: a file
 * manager shows this message, and a name may hold escape sequences. */
static const char *shown(const char *file, char *buf, size_t size)
{
	return text_visible(buf, size, file, false);
}

static int fail(const char *file, const char *what)
{
	char name[4096];
	fprintf(stderr, "rtsh: %s: %s\n", shown(file, name, sizeof name), what);
	return 1;
}

/* --pixels auto on a terminal: ask it, at most a second (pixels_probe
 * puts it in raw mode for the answers and back). */
static pixels_mode ask_terminal(int *cell_w, int *cell_h)
{
	pixels_caps c = {0};
	if (isatty(STDIN_FILENO)) {
		abuf keys;
		abuf_init(&keys);
		pixels_probe(STDIN_FILENO, STDOUT_FILENO, 1.0, &c, &keys);
		abuf_free(&keys);
	}
	pixels_caps_env(&c, getenv("TERM_PROGRAM"), getenv("LC_TERMINAL"), getenv("TMUX"));
	if (c.cell_w > 0 && c.cell_h > 0) {
		*cell_w = c.cell_w;
		*cell_h = c.cell_h;
	}
	return pixels_choose(&c);
}

/* The size of a cell in pixels: the terminal's, when standard output is
 * one that says; else 10 x 20. */
static void cell_size(int *w, int *h)
{
	struct winsize ws;
	*w = 10;
	*h = 20;
	if (isatty(STDOUT_FILENO) && ioctl(STDOUT_FILENO, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0 &&
	    ws.ws_row > 0 && ws.ws_xpixel >= ws.ws_col && ws.ws_ypixel >= ws.ws_row) {
		*w = ws.ws_xpixel / ws.ws_col;
		*h = ws.ws_ypixel / ws.ws_row;
	}
}

/* The palette: --color when given; else, on a terminal, what it says;
 * into a pipe (the file managers), 24-bit colour unless NO_COLOR. */
static frame_palette preview_palette(color_mode m)
{
	if (m != COLOR_AUTO || isatty(STDOUT_FILENO))
		return caps_palette(m, STDOUT_FILENO);
	const char *nc = getenv("NO_COLOR");
	return nc && *nc ? PALETTE_NONE : PALETTE_TRUECOLOR;
}

/* --- the time budget --- */

/* A thread that sets *cancel at `at` (CLOCK_MONOTONIC) unless told to stop
 * first. */
typedef struct alarm_clock {
	pthread_mutex_t m;
	pthread_cond_t c;
	bool stop;
	struct timespec at;
	atomic_bool *cancel;
	pthread_t th;
	bool running;
} alarm_clock;

static void *alarm_run(void *arg)
{
	alarm_clock *a = arg;
	pthread_mutex_lock(&a->m);
	while (!a->stop)
		if (pthread_cond_timedwait(&a->c, &a->m, &a->at) == ETIMEDOUT) {
			atomic_store(a->cancel, true);
			break;
		}
	pthread_mutex_unlock(&a->m);
	return NULL;
}

static struct timespec after(double s)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	if (!(s > 0))
		s = 0;
	double whole = floor(s);
	t.tv_sec += (time_t)whole;
	t.tv_nsec += (long)((s - whole) * 1e9);
	if (t.tv_nsec >= 1000000000L) {
		t.tv_sec++;
		t.tv_nsec -= 1000000000L;
	}
	return t;
}

/* Starts the clock; false (and *cancel set: no render) when the budget is
 * spent already or no thread can be had. */
static bool alarm_start(alarm_clock *a, atomic_bool *cancel, double s)
{
	atomic_store(cancel, !(s > 0));
	a->running = false;
	if (!(s > 0))
		return false;
	pthread_condattr_t ca;
	pthread_condattr_init(&ca);
	pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
	pthread_mutex_init(&a->m, NULL);
	pthread_cond_init(&a->c, &ca);
	pthread_condattr_destroy(&ca);
	a->stop = false;
	a->at = after(s);
	a->cancel = cancel;
	a->running = pthread_create(&a->th, NULL, alarm_run, a) == 0;
	if (!a->running) {
		pthread_cond_destroy(&a->c);
		pthread_mutex_destroy(&a->m);
	}
	return a->running;
}

static void alarm_stop(alarm_clock *a)
{
	if (!a->running)
		return;
	pthread_mutex_lock(&a->m);
	a->stop = true;
	pthread_cond_signal(&a->c);
	pthread_mutex_unlock(&a->m);
	pthread_join(a->th, NULL);
	pthread_cond_destroy(&a->c);
	pthread_mutex_destroy(&a->m);
	a->running = false;
}

/* A render stopped at s seconds from now; NULL (err set) when stopped
 * (*stopped set) or failed. Without a clock thread the render runs
 * unstopped (the watchdog is still there). */
static framebuffer *render_within(const world *wd, const render_settings *set, double s, bool *stopped,
                                  rt_error *err)
{
	atomic_bool cancel;
	atomic_init(&cancel, false);
	alarm_clock a;
	*stopped = false;
	if (!alarm_start(&a, &cancel, s) && atomic_load(&cancel)) {
		*stopped = true;
		rt_error_set(err, "render stopped");
		return NULL;
	}
	framebuffer *fb = render_image(wd, set, &cancel, NULL, NULL, err);
	alarm_stop(&a);
	*stopped = !fb && atomic_load(&cancel);
	return fb;
}

framebuffer *preview_render(const world *wd, const render_settings *set, double full_s, double coarse_s, bool *coarse,
                            rt_error *err)
{
	*coarse = false;
	render_settings cs = *set;
	cs.width = (set->width + 3) / 4;
	cs.height = (set->height + 3) / 4;
	cs.samples = 1;
	cs.denoise = DENOISE_OFF;
	struct timespec t0;
	clock_gettime(CLOCK_MONOTONIC, &t0);
	bool stopped;
	framebuffer *small = render_within(wd, &cs, coarse_s, &stopped, err);
	if (!small) {
		if (stopped)
			rt_error_set(err, "stopped");
		return NULL;
	}
	struct timespec t1;
	clock_gettime(CLOCK_MONOTONIC, &t1);
	double spent = (double)(t1.tv_sec - t0.tv_sec) + (double)(t1.tv_nsec - t0.tv_nsec) * 1e-9;
	rt_error ferr;
	rt_error_clear(&ferr);
	framebuffer *fb = render_within(wd, set, full_s - spent, &stopped, &ferr);
	if (fb) {
		fb_free(small);
		return fb;
	}
	if (!stopped) { /* failed */
		fb_free(small);
		*err = ferr;
		return NULL;
	}
	fb = fb_new(set->width, set->height);
	if (!fb) {
		fb_free(small);
		rt_error_set(err, "out of memory");
		return NULL;
	}
	for (int y = 0; y < fb->h; y++)
		for (int x = 0; x < fb->w; x++)
			memcpy(&fb->rgb[3 * ((size_t)y * fb->w + x)], &small->rgb[3 * ((size_t)(y / 4) * small->w + x / 4)],
			       3 * sizeof *fb->rgb);
	fb->spp = small->spp;
	fb_free(small);
	*coarse = true;
	return fb;
}

void preview_camera(camera *c, bool model, box bounds, int w, int h)
{
	double aspect = (double)w / h;
	if (model) {
		*c = orbit_frame(*c, bounds, aspect);
	} else if (!c->vertical && !(c->ortho > 0)) {
		/* a vertical fov keeps the height already, and an orthographic
		 * camera has none: widening it zoomed a glTF's camera out */
		double th = tan(deg_to_rad(c->fov) * 0.5);
		double need = th * 9.0 / 16.0 * aspect;
		if (need > th)
			c->fov = fmin(2.0 * rad_to_deg(atan(need)), 150.0);
	}
}

int preview_main(const rtsh_options *o)
{
	struct timespec start;
	clock_gettime(CLOCK_MONOTONIC, &start);
	const char *file = o->scene;
	if (!file) {
		fprintf(stderr, "rtsh: --preview needs a file\nTry 'rtsh --help' for more information.\n");
		return 2;
	}
	signal(SIGALRM, watchdog);
	alarm(PREVIEW_TIMEOUT);
	/* Only regular files: a FIFO would block the open, a device or a
	 * folder means nothing. */
	struct stat st;
	if (!file[0])
		return fail("--preview", "the file name is empty; expected a scene (.rt) or model file");
	if (stat(file, &st) != 0) {
		char msg[160];
		snprintf(msg, sizeof msg, "cannot open: %s; expected a readable scene (.rt) or model file", strerror(errno));
		return fail(file, msg);
	}
	const char *kind = rt_file_kind(st.st_mode);
	if (kind) {
		char msg[160];
		snprintf(msg, sizeof msg, "not a regular file but %s; expected a scene (.rt) or a model file", kind);
		return fail(file, msg);
	}
	rt_error err;
	image_budget_set(PREVIEW_TEXTURE_PIXELS);
	rt_load_opts lo = {.strict = false, .warn = NULL};
	scene *s = rt_load_file(file, &lo, &err);
	if (!s) {
		char msg[RT_ERROR_MSG_MAX + RT_ERROR_FILE_MAX + 32];
		rt_error_format(&err, msg, sizeof msg);
		fprintf(stderr, "%s\n", msg);
		return 1;
	}
	render_settings set = render_settings_default();
	render_settings_apply_hints(&set, &s->hints);
	/* Fast: Whitted at most 4 samples; path at most 8, denoised. */
	if (set.mode == MODE_PATH) {
		set.samples = set.samples < 8 ? set.samples : 8;
		set.denoise = DENOISE_ON;
		set.depth = set.depth < 6 ? set.depth : 6;
	} else {
		set.samples = set.samples < 4 ? set.samples : 4;
	}
	options_apply_settings(o, &set);
	int cols = o->preview_cols, rows = o->preview_rows;
	pixels_mode pm = (pixels_mode)set.pixels;
	int cw, ch;
	cell_size(&cw, &ch);
	if (pm == PIXELS_AUTO)
		pm = isatty(STDOUT_FILENO) ? ask_terminal(&cw, &ch) : PIXELS_OFF;
	char why[400];
	if (pm == PIXELS_SIXEL && !pixels_sixel_available(why, sizeof why)) {
		char name[4096];
		fprintf(stderr, "rtsh: %s: sixel images cannot be drawn: %s: half blocks\n", shown(file, name, sizeof name),
		        why);
		pm = PIXELS_OFF;
	}
	/* The symbol set asked for (--symbols); auto: what the terminal is
	 * known to draw, half blocks into a pipe (the file manager's terminal
	 * is not known there). */
	frame_palette pal = preview_palette(o->color);
	symbols_kind sym = set.symbols >= SYMBOLS_HALF && set.symbols < SYMBOLS_AUTO ? (symbols_kind)set.symbols
	                   : isatty(STDOUT_FILENO) ? symbols_choose(getenv("TERM_PROGRAM"), NULL, getenv("VTE_VERSION"),
	                                                            getenv("TMUX") != NULL)
	                                           : SYMBOLS_HALF;
	if (pal == PALETTE_NONE)
		sym = SYMBOLS_HALF;
	int sx = sym == SYMBOLS_HALF ? 1 : SYMBOLS_SAMPLE_W, sy = sym == SYMBOLS_HALF ? 2 : SYMBOLS_SAMPLE_H;
	int w = cols * sx, h = rows * sy;
	if (pm != PIXELS_OFF) {
		w = cols * cw;
		h = rows * ch;
	}
	if (s->ncams > 0)
		preview_camera(&s->cams[s->cam], mesh_format_known(file), orbit_scene_bounds(s), w, h);
	set.width = w;
	set.height = h;
	world *wd = world_build(s, &err);
	scene_free(s);
	if (!wd)
		return fail(file, err.msg);
	/* the budget counts from the start: the load and the tree took some */
	struct timespec now;
	clock_gettime(CLOCK_MONOTONIC, &now);
	double spent = (double)(now.tv_sec - start.tv_sec) + (double)(now.tv_nsec - start.tv_nsec) * 1e-9;
	bool coarse = false;
	framebuffer *fb = preview_render(wd, &set, PREVIEW_FULL_BUDGET - spent, PREVIEW_COARSE_BUDGET - spent, &coarse, &err);
	world_free(wd);
	if (!fb && strcmp(err.msg, "stopped") == 0)
		return fail(file, "gave up: not even a coarse picture after " XSTR(PREVIEW_COARSE_BUDGET) " seconds");
	if (!fb)
		return fail(file, err.msg);
	if (coarse) {
		char name[4096];
		fprintf(stderr, "rtsh: %s: the full picture was not ready after %g seconds: shown at a quarter of its "
		        "resolution\n", shown(file, name, sizeof name), PREVIEW_FULL_BUDGET);
	}
	/* the textures the budget left out: one line, the picture still drawn */
	char first[RT_ERROR_MSG_MAX];
	size_t skipped = image_budget_report(first, sizeof first);
	if (skipped) {
		char name[4096], more[64] = "", shown_first[RT_ERROR_MSG_MAX];
		if (skipped > 1)
			snprintf(more, sizeof more, " (and %zu more images)", skipped - 1);
		fprintf(stderr, "rtsh: %s: %s%s\n", shown(file, name, sizeof name),
		        text_visible(shown_first, sizeof shown_first, first, false), more);
	}
	uint8_t *rgb = malloc((size_t)w * h * 3);
	if (!rgb) {
		fb_free(fb);
		return fail(file, "out of memory");
	}
	frame_srgb_from_linear(fb->rgb, (size_t)w * h, set.exposure, rgb);
	fb_free(fb);
	abuf a;
	abuf_init(&a);
	if (pm != PIXELS_OFF) {
		const encoder_ops *e = encoder_pixels(pm); /* by name, encoder.c's table */
		if (!e || !e->picture(&a, rgb, w, h, cols, rows))
			a.failed = true;
	} else {
		frame *f = frame_new_symbols(cols, rows, pal, sym);
		if (!f) {
			a.failed = true;
		} else {
			frame_put_image(f, rgb, w, h, 0, 0);
			frame_text(f, &a);
			frame_free(f);
		}
	}
	free(rgb);
	int rc = 0;
	if (a.failed)
		rc = fail(file, "out of memory");
	else if (!write_all(STDOUT_FILENO, a.b, a.len))
		rc = fail("standard output", strerror(errno));
	abuf_free(&a);
	alarm(0);
	return rc;
}
