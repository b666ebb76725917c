/* rtsh — the shell: set-up, the scene and its settings, full-resolution
 * renders (shell_main.c picks script or interactive mode). */
#include "shell/shell.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "base/visible.h"
#include "rtsh/settings.h"
#include "shell/builtin_scene.h"
#include "shell/progress.h"
#include "shell/signals.h"
#include "term/caps.h"
#include "term/keyview.h"

bool shell_fail(shell *sh, const char *fmt, ...)
{
	char buf[SHELL_MSG_MAX];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(buf, sizeof buf, fmt, ap);
	va_end(ap);
	/* a file name with escape sequences shows them, never runs them */
	text_visible(sh->err, sizeof sh->err, buf, true);
	return false;
}

/* Command output goes to standard output, or to the pager's buffer while
 * an interactive command runs. */
static void out_text(shell *sh, const char *text)
{
	if (sh->capture)
		abuf_add(sh->capture, text, strlen(text));
	else
		fputs(text, stdout);
}

/* The text with its control characters made visible (visible.h): names
 * of files and of a model's parts, which may hold escape sequences, are
 * printed by many commands. */
static void out_visible(shell *sh, const char *text, size_t n)
{
	if (!text_has_controls(text, true)) {
		out_text(sh, text);
		return;
	}
	size_t size = 4 * n + 1; /* ^X for one byte, M-^X for two */
	char *vis = malloc(size);
	if (vis)
		out_text(sh, text_visible(vis, size, text, true));
	free(vis);
}

static void out_v(shell *sh, const char *fmt, va_list ap)
{
	char small[512];
	va_list copy;
	va_copy(copy, ap);
	int n = vsnprintf(small, sizeof small, fmt, copy);
	va_end(copy);
	if (n < 0)
		return;
	if ((size_t)n < sizeof small) {
		out_visible(sh, small, (size_t)n);
		return;
	}
	char *big = malloc((size_t)n + 1);
	if (!big)
		return;
	vsnprintf(big, (size_t)n + 1, fmt, ap);
	out_visible(sh, big, (size_t)n);
	free(big);
}

void shell_out(shell *sh, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	out_v(sh, fmt, ap);
	va_end(ap);
}

void shell_info(shell *sh, const char *fmt, ...)
{
	if (sh->opt->quiet)
		return;
	va_list ap;
	va_start(ap, fmt);
	out_v(sh, fmt, ap);
	va_end(ap);
}

void shell_note(shell *sh, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	va_list copy;
	va_copy(copy, ap);
	int n = vsnprintf(NULL, 0, fmt, copy);
	va_end(copy);
	char *buf = n >= 0 ? malloc((size_t)n + 1) : NULL, *vis = n >= 0 ? malloc(4 * (size_t)n + 1) : NULL;
	if (buf && vis) {
		vsnprintf(buf, (size_t)n + 1, fmt, ap);
		/* escape sequences in a name shown, not run (visible.h) */
		text_visible(vis, 4 * (size_t)n + 1, buf, true);
		if (sh && sh->notes) {
			abuf_add(sh->notes, vis, strlen(vis));
		} else {
			fflush(stdout);
			fputs(vis, stderr);
		}
	}
	free(buf);
	free(vis);
	va_end(ap);
}

static double now(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)t.tv_sec + t.tv_nsec * 1e-9;
}

void shell_notice(shell *sh, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(sh->notice, sizeof sh->notice, fmt, ap);
	va_end(ap);
	sh->notice_until = now() + 15.0;
	if (sh->status_hook)
		sh->status_hook(sh);
}

char *shell_expand_path(const char *path)
{
	const char *home = getenv("HOME");
	if (path[0] == '~' && (path[1] == '/' || path[1] == '\0') && home && *home) {
		size_t n = strlen(home) + strlen(path);
		char *p = malloc(n);
		if (p)
			snprintf(p, n, "%s%s", home, path + 1);
		return p;
	}
	return strdup(path);
}

static void print_warning(void *ctx, const rt_error *w)
{
	char buf[RT_ERROR_MSG_MAX + RT_ERROR_FILE_MAX + 32];
	rt_error_format(w, buf, sizeof buf);
	shell_note(ctx, "%s (warning)\n", buf);
}

/* --- settings per scene --- */

/* Defaults, then the scene's hints, then the command line's settings; the
 * thread count carries over (it is about the machine, not the scene). */
static render_settings fresh_settings(const shell *sh, bool keep_threads)
{
	render_settings s = render_settings_default();
	render_settings_apply_hints(&s, &editor_scene(sh->ed)->hints);
	for (int i = 0; i < sh->opt->nsettings; i++)
		settings_set(&s, sh->opt->settings[i].def, sh->opt->settings[i].value, NULL);
	if (keep_threads)
		s.threads = sh->set.threads;
	return s;
}

static bool same_str(const char *a, const char *b)
{
	return a == b || (a && b && strcmp(a, b) == 0);
}

static scene_memo *memo_find(shell *sh, const char *label)
{
	for (size_t i = 0; i < sh->nmemo; i++)
		if (same_str(sh->memo[i].label, label))
			return &sh->memo[i];
	return NULL;
}

static void memo_put(shell *sh, const char *label, const render_settings *set)
{
	scene_memo *m = memo_find(sh, label);
	if (m) {
		m->set = *set;
		return;
	}
	char *l = label ? strdup(label) : NULL;
	if (label && !l)
		return;
	scene_memo *p = realloc(sh->memo, (sh->nmemo + 1) * sizeof *p);
	if (!p) {
		free(l);
		return;
	}
	sh->memo = p;
	sh->memo[sh->nmemo++] = (scene_memo){l, *set};
}

/* Name and folder from a label: NULL = the built-in scene, "generate:N:S" =
 * a generated one, anything else = a file path. */
static void name_from_label(shell *sh)
{
	const char *l = sh->label;
	if (!l) {
		snprintf(sh->name, sizeof sh->name, "%s", BUILTIN_SCENE_NAME);
		return;
	}
	long n;
	unsigned long long seed;
	if (sscanf(l, "generate:%ld:%llu", &n, &seed) == 2) {
		snprintf(sh->name, sizeof sh->name, "generated: %ld object%s, seed %llu", n, n == 1 ? "" : "s",
		         seed);
		return;
	}
	const char *slash = strrchr(l, '/');
	/* the status line's name: escape sequences in it shown, not run */
	text_visible(sh->name, sizeof sh->name, slash ? slash + 1 : l, false);
	free(sh->dir);
	sh->dir = slash ? strndup(l, slash == l ? 1 : (size_t)(slash - l)) : strdup(".");
}

/* Notices that the editor holds another scene (load, undo of a load, ...):
 * keeps the old scene's settings and takes the new one's. */
static void sync_scene(shell *sh)
{
	const char *l = editor_label(sh->ed);
	if (same_str(l, sh->label))
		return;
	memo_put(sh, sh->label, &sh->set);
	free(sh->label);
	sh->label = l ? strdup(l) : NULL;
	const scene_memo *m = memo_find(sh, sh->label);
	sh->set = m ? m->set : fresh_settings(sh, true);
	name_from_label(sh);
}

/* --- the preview --- */

static double aspect_of(const render_settings *s)
{
	return (double)s->width / s->height;
}

void shell_pixels_notice(shell *sh)
{
	/* kitty or iTerm2 asked for inside tmux, and half blocks drawn: the
	 * pane has no passthrough (or no cell size); say so, not a blank. */
	if ((sh->set.pixels == PIXELS_KITTY || sh->set.pixels == PIXELS_ITERM) && getenv("TMUX") && sh->scr &&
	    !sh->scr->pix_ops)
		shell_notice(sh, "%s images do not show in this tmux pane (allow-passthrough on?): half blocks",
		             sh->set.pixels == PIXELS_KITTY ? "kitty" : "iTerm2");
	char why[400];
	if (sh->scr && sh->scr->sixel_missing && !pixels_sixel_available(why, sizeof why))
		shell_notice(sh, "sixel images cannot be drawn: %s: half blocks", why);
}

/* Whether the samples were chosen: by `set samples`, -s or the scene. */
static bool samples_chosen(const shell *sh)
{
	rt_error err;
	const setting_def *def = settings_find("samples", &err);
	if (!def)
		return true;
	size_t bit = (size_t)(def - settings_table);
	if (bit < sizeof sh->hand_set * 8 && (sh->hand_set & 1u << bit))
		return true;
	for (int i = 0; i < sh->opt->nsettings; i++)
		if (sh->opt->settings[i].def == def)
			return true;
	return editor_scene(sh->ed)->hints.samples > 0;
}

render_settings shell_preview_settings(const shell *sh)
{
	render_settings pset = sh->set;
	if (pset.mode == MODE_PATH && pset.samples < PREVIEW_PATH_SAMPLES && !samples_chosen(sh))
		pset.samples = PREVIEW_PATH_SAMPLES; /* the preview's own target (the status line says so) */
	return pset;
}

void shell_refresh(shell *sh)
{
	if (!sh->scr || !sh->scr->active) {
		rsvc_release(sh->rs);
		return;
	}
	/* A new pixels setting takes effect here; what the terminal answered
	 * later, in the loop's after_probe. */
	if (sh->set.symbols != sh->scr->symbols)
		screen_set_symbols(sh->scr, sh->set.symbols);
	bool new_pixels = sh->set.pixels != sh->scr->pixels;
	if (!new_pixels || !screen_set_pixels(sh->scr, sh->set.pixels))
		screen_layout(sh->scr, aspect_of(&sh->set), false);
	if (new_pixels && sh->scr->out && termout_get_state(sh->scr->out) != TERMOUT_PROBING)
		shell_pixels_notice(sh);
	if (sh->scr->img_w <= 0 || sh->scr->img_h <= 0) {
		rsvc_release(sh->rs);
		return;
	}
	/* A quick pass, then passes of PREVIEW_PASS_SECONDS; path previews are
	 * denoised unless `set denoise off`. */
	render_settings pset = shell_preview_settings(sh);
	rsvc_request req = {
		.s = editor_scene(sh->ed),
		.gen = editor_generation(sh->ed),
		.set = pset,
		.w = sh->scr->img_w,
		.h = sh->scr->img_h,
		.kind = RSVC_REFINE,
		.quick = true,
		.denoise = render_mode_denoises(sh->set.mode) && sh->set.denoise != DENOISE_OFF,
		.pass_seconds = PREVIEW_PASS_SECONDS,
	};
	sh->preview_seq = rsvc_start(sh->rs, &req);
	sh->redraw = true;
	if (sh->status_hook)
		sh->status_hook(sh);
}

void shell_edit_begin(shell *sh)
{
	rsvc_hold(sh->rs);
}

void shell_edit_end(shell *sh)
{
	sync_scene(sh);
	shell_refresh(sh);
}

static void format_seconds(double s, char *buf, size_t size)
{
	if (s < 1)
		snprintf(buf, size, "%.0f ms", s * 1000);
	else if (s < 60)
		snprintf(buf, size, "%.2f s", s);
	else
		snprintf(buf, size, "%.0fm%02.0fs", floor(s / 60), fmod(s, 60));
}

void shell_status_text(shell *sh, char *buf, size_t size)
{
	const rsvc_image *im = &sh->img;
	char samples[RT_ERROR_MSG_MAX + 16], t[32] = "";
	bool busy = rsvc_busy(sh->rs);
	if (im->error[0]) {
		snprintf(samples, sizeof samples, "error: %s", im->error);
	} else if (im->w == 0) {
		snprintf(samples, sizeof samples, "rendering");
	} else if (im->stopped) {
		snprintf(samples, sizeof samples, "stopped at %d/%d spp", im->spp, im->target);
	} else if (im->spp == 0) {
		snprintf(samples, sizeof samples, "quick pass, 0/%d spp", im->target);
	} else {
		snprintf(samples, sizeof samples, "%d/%d spp%s", im->spp, im->target, busy && !im->done ? "…" : "");
	}
	if (im->w > 0 && !im->error[0] && im->target > sh->set.samples)
		strncat(samples, " (preview's own)", sizeof samples - strlen(samples) - 1);
	if (im->denoised && !im->error[0])
		strncat(samples, " │ denoised", sizeof samples - strlen(samples) - 1);
	if (im->w > 0)
		format_seconds(im->seconds, t, sizeof t);
	int th = render_threads(&sh->set);
	bool note = sh->notice[0] && now() < sh->notice_until;
	const scene *sc = editor_scene(sh->ed);
	const char *snote = sc && sc->note ? sc->note : NULL; /* the glTF loader's "stage lighting" */
	char depth[32], size_s[48], threads[32];
	snprintf(depth, sizeof depth, "depth %d", sh->set.depth);
	snprintf(size_s, sizeof size_s, "%dx%d", sh->scr ? sh->scr->img_w : 0, sh->scr ? sh->scr->img_h : 0);
	snprintf(threads, sizeof threads, "%d thread%s", th, th == 1 ? "" : "s");
	/* Fitted to the width: the threads go first, then the depth, the
	 * size, the time, the scene's note and its name; a notice, the mode
	 * and the samples stay. */
	const char *fields[] = {sh->name, snote ? snote : "", note ? sh->notice : "", render_mode_name(sh->set.mode),
	                        samples, depth, size_s, threads, t};
	const int drop[] = {6, 5, 0, 0, 0, 2, 3, 1, 4};
	keyview_fit_status(buf, size, fields, drop, sizeof fields / sizeof fields[0],
	                   sh->scr && sh->scr->cols > 0 ? sh->scr->cols : 1 << 20);
}

/* --- full-resolution images --- */

typedef struct progress_ctx {
	shell *sh;
	double t0;
	bool shown;
	bool repainted; /* after a stop and a continue */
	int w, h;
} progress_ctx;

static void on_progress(void *ctx, long done, long total)
{
	progress_ctx *p = ctx;
	char prog[192];
	progress_state ps = {p->w, p->h, p->sh->set.samples, done, total, now() - p->t0};
	progress_text(&ps, 20, prog, sizeof prog);
	if (p->sh->scr && p->sh->scr->active) {
		if (shell_sig_cont && !p->repainted) {
			/* Continued after Ctrl-Z in the middle of a render: the
			 * screen's frame now, the picture and prompt after it. */
			p->repainted = true;
			screen_resume(p->sh->scr);
		}
		char text[256];
		/* A bar only where it fits. */
		for (int bar = 20; bar >= 0; bar -= 10) {
			progress_text(&ps, bar, prog, sizeof prog);
			snprintf(text, sizeof text, " rendering %dx%d %s (Ctrl-C stops)", p->w, p->h, prog);
			if ((int)strlen(text) <= p->sh->scr->cols)
				break;
		}
		screen_status(p->sh->scr, text);
	} else {
		fprintf(stderr, "\r%s   ", prog);
		p->shown = true;
	}
}

static bool same_image_settings(const render_settings *a, const render_settings *b)
{
	return a->width == b->width && a->height == b->height && a->samples == b->samples &&
	       a->depth == b->depth && a->mode == b->mode && a->seed == b->seed &&
	       (!render_mode_denoises(a->mode) || (a->denoise == DENOISE_ON) == (b->denoise == DENOISE_ON));
}

const framebuffer *shell_full_image(shell *sh, bool force)
{
	uint64_t gen = editor_generation(sh->ed);
	if (!force && sh->full && sh->full_gen == gen && same_image_settings(&sh->full_set, &sh->set))
		return sh->full;
	rsvc_hold(sh->rs);
	rt_error err;
	rt_error_clear(&err);
	atomic_store(&sh->cancel, false);
	const world *w =
	    rsvc_world(sh->rs, editor_scene(sh->ed), gen, render_threads(&sh->set), &sh->cancel, &err);
	if (!w) {
		shell_refresh(sh);
		if (atomic_load(&sh->cancel)) {
			shell_sig_int = 0; /* the Ctrl-C is used up */
			shell_fail(sh, "render: stopped while preparing the scene");
		} else {
			shell_fail(sh, "render: %s", err.msg);
		}
		return NULL;
	}
	atomic_store(&sh->cancel, false);
	progress_ctx p = {sh, now(), false, false, sh->set.width, sh->set.height};
	framebuffer *fb = render_image(w, &sh->set, &sh->cancel, sh->progress ? on_progress : NULL, &p, &err);
	world_release(w);
	double seconds = now() - p.t0;
	if (p.shown)
		fputc('\n', stderr);
	bool stopped = atomic_load(&sh->cancel);
	if (stopped)
		shell_sig_int = 0; /* the Ctrl-C is used up */
	shell_refresh(sh);
	if (!fb) {
		if (stopped)
			shell_fail(sh, "render: stopped");
		else
			shell_fail(sh, "render: %s", err.msg);
		return NULL;
	}
	fb_free(sh->full);
	sh->full = fb;
	sh->full_gen = gen;
	sh->full_set = sh->set;
	sh->full_seconds = seconds;
	return fb;
}

frame *shell_picture_frame(shell *sh, frame_palette pal, int cols)
{
	const float *rgb;
	int w, h;
	framebuffer *fb = NULL;
	/* The symbol set asked for, else the screen's (a file: half blocks). */
	symbols_kind k = sh->set.symbols >= SYMBOLS_HALF && sh->set.symbols < SYMBOLS_AUTO
	                     ? (symbols_kind)sh->set.symbols
	                 : sh->scr && sh->scr->active ? sh->scr->sym
	                                              : SYMBOLS_HALF;
	if (pal == PALETTE_NONE)
		k = SYMBOLS_HALF;
	int sx = k == SYMBOLS_HALF ? 1 : SYMBOLS_SAMPLE_W, sy = k == SYMBOLS_HALF ? 2 : SYMBOLS_SAMPLE_H;
	/* The preview's picture when it shows the scene and settings as they
	 * are: the newest image taken, of the preview asked for last (an edit
	 * or a `set` earlier on the same line asked for a new one), past its
	 * quick pass. Else the picture is rendered here. */
	if (sh->scr && rsvc_take(sh->rs, &sh->img))
		sh->redraw = true;
	bool current = sh->img.seq == sh->preview_seq && sh->img.spp > 0 && !sh->img.error[0];
	if (sh->scr && current && sh->img.w > 0 && sh->img.rgb && !sh->scr->pix_ops && sh->scr->sym == k) {
		rgb = sh->img.rgb;
		w = sh->img.w;
		h = sh->img.h;
	} else {
		screen_fit(cols, 1000, aspect_of(&sh->set), pal == PALETTE_NONE, &w, &h);
		w = w * sx;
		h = h * sy / 2;
		rsvc_hold(sh->rs);
		rt_error err;
		rt_error_clear(&err);
		atomic_store(&sh->cancel, false);
		const world *wd = rsvc_world(sh->rs, editor_scene(sh->ed), editor_generation(sh->ed), render_threads(&sh->set),
		                              &sh->cancel, &err);
		render_settings s = sh->set;
		s.width = w;
		s.height = h;
		if (wd) {
			atomic_store(&sh->cancel, false);
			fb = render_image(wd, &s, &sh->cancel, NULL, NULL, &err);
		}
		world_release(wd);
		shell_refresh(sh);
		if (!fb) { /* as the full image's failures say it */
			shell_fail(sh, "render: %s", err.msg);
			return NULL;
		}
		rgb = fb->rgb;
	}
	frame *f = frame_new_symbols((w + sx - 1) / sx, (h + sy - 1) / sy, pal, k);
	uint8_t *px = malloc((size_t)w * h * 3);
	if (!f || !px) {
		frame_free(f);
		free(px);
		fb_free(fb);
		shell_fail(sh, "out of memory");
		return NULL;
	}
	frame_srgb_from_linear(rgb, (size_t)w * h, sh->set.exposure, px);
	frame_put_image(f, px, w, h, 0, 0);
	free(px);
	fb_free(fb);
	return f;
}

/* --- scenes --- */

bool shell_quit_asks(shell *sh)
{
	uint64_t gen = editor_generation(sh->ed);
	if (!sh->interactive || sh->depth > 0 || sh->opt->quiet || gen == sh->saved_gen ||
	    sh->quit_asked_gen == gen + 1)
		return false;
	sh->quit_asked_gen = gen + 1;
	return true;
}

bool shell_replace_scene(shell *sh, scene *s, const char *label)
{
	rt_error err;
	shell_edit_begin(sh);
	bool ok = editor_replace(sh->ed, s, label, &err);
	shell_edit_end(sh);
	if (ok)
		sh->saved_gen = editor_generation(sh->ed);
	return ok ? true : shell_fail(sh, "%s", err.msg);
}

bool shell_load(shell *sh, const char *path)
{
	char *p = shell_expand_path(path);
	if (!p)
		return shell_fail(sh, "out of memory");
	rt_error err;
	/* Ctrl-C stops the load (rtsh(1)); the scene stays as it was */
	atomic_store(&sh->cancel, false);
	rt_load_opts lo = sh->load_opts;
	lo.cancel = &sh->cancel;
	scene *s = rt_load_file(p, &lo, &err);
	if (!s && atomic_load(&sh->cancel)) {
		shell_sig_int = 0; /* the Ctrl-C is used up */
		free(p);
		return shell_fail(sh, "load: stopped; the scene is as it was");
	}
	if (!s) {
		char msg[RT_ERROR_MSG_MAX + RT_ERROR_FILE_MAX + 32];
		rt_error_format(&err, msg, sizeof msg);
		free(p);
		return shell_fail(sh, "load: %s", msg);
	}
	/* A file label must not look like a generated scene's. */
	char *label = p;
	if (strncmp(p, "generate:", 9) == 0) {
		size_t n = strlen(p) + 3;
		label = malloc(n);
		if (label)
			snprintf(label, n, "./%s", p);
	}
	bool ok = label && shell_replace_scene(sh, s, label);
	if (!label) {
		scene_free(s);
		ok = shell_fail(sh, "out of memory");
	}
	if (label != p)
		free(label);
	free(p);
	return ok;
}

bool shell_init(shell *sh, const rtsh_options *o, int wake_fd)
{
	memset(sh, 0, sizeof *sh);
	sh->opt = o;
	sh->wake[0] = sh->wake[1] = -1;
	sh->warn = (rt_warnings){print_warning, sh};
	sh->load_opts = (rt_load_opts){.strict = o->strict, .warn = o->quiet ? NULL : &sh->warn};
	atomic_init(&sh->cancel, false);
	rt_error err;
	scene *s;
	if (o->scene)
		s = rt_load_file(o->scene, &sh->load_opts, &err);
	else
		s = rt_load_string(builtin_scene_text, builtin_scene_len, "showcase.rt", &sh->load_opts, &err);
	if (!s) {
		char msg[RT_ERROR_MSG_MAX + RT_ERROR_FILE_MAX + 32];
		rt_error_format(&err, msg, sizeof msg);
		fprintf(stderr, "%s\n", msg);
		return false;
	}
	sh->ed = editor_new(s, o->scene);
	sh->rs = rsvc_new(wake_fd);
	if (!sh->ed || !sh->rs) {
		if (!sh->ed)
			scene_free(s);
		fprintf(stderr, "rtsh: out of memory\n");
		shell_free(sh);
		return false;
	}
	sh->label = o->scene ? strdup(o->scene) : NULL;
	sh->saved_gen = editor_generation(sh->ed);
	sh->set = fresh_settings(sh, false);
	name_from_label(sh);
	return true;
}

void shell_free(shell *sh)
{
	rsvc_free(sh->rs);
	editor_free(sh->ed);
	fb_free(sh->full);
	rsvc_image_free(&sh->img);
	free(sh->srgb);
	free(sh->label);
	free(sh->dir);
	for (size_t i = 0; i < sh->nmemo; i++)
		free(sh->memo[i].label);
	free(sh->memo);
	memset(sh, 0, sizeof *sh);
}
