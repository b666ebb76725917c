/* rtsh — key mode (keymode.h): the session and its loop.
 *
 * Key mode is three files: the key table and the edits keys make
 * (keymode_keys.c), the key view's drawing (term/keyview.c: every escape
 * sequence of key mode, sent through the output scheduler), and this one:
 *   1. the session: requests to the render service (shell/render_service.h),
 *      the adaptive pixel ratio, the picture with the selection marked and
 *      the status line's text;
 *   2. the loop: the terminal's input through the output scheduler (its
 *      answers pace the picture) and on to ncurses for the keys, termios,
 *      signals, and giving the shell's screen back.
 * The keypad transmit mode (terminfo's smkx / rmkx, so that the arrow keys
 * send what ncurses expects) is sent by screen_keypad (term/screen.h).
 */
#include "shell/keymode.h"

#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include <readline/readline.h>

#include "rtsh/mesh.h"
#include "rtsh/orbit.h"
#include "rtsh/settings.h"
#include "rtsh/shape.h"
#include "rtsh/world.h"
#include "shell/commands.h"
#include "base/abuf.h"
#include "term/frame.h"
#include "term/keys.h"
#include "term/keyview.h"

static double now(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)t.tv_sec + t.tv_nsec * 1e-9;
}

/* ------------------------------------------------------------------ */
/* 1. The session                                                      */
/* ------------------------------------------------------------------ */

/* The request the newest images must answer. */
typedef struct km_cur {
	uint64_t seq;         /* rsvc_start's number (0: none yet) */
	uint64_t gen;         /* the scene generation the world shows */
	render_settings set;
	int w_px, h_px;       /* the render size */
	bool refine;          /* all the samples, in passes that accumulate */
} km_cur;

/* The pixel ratios a fast frame may use. */
static const double ratios[] = {1, 1.5, 2, 3, 4, 6, 8, 12, 16};
#define NRATIOS ((int)(sizeof ratios / sizeof ratios[0]))

/* A selection outline: gold, drawn just outside the selected pixels. */
static const uint8_t mark_rgb[3] = {255, 205, 0};

struct keymode {
	shell *sh;
	keyview kv;            /* the screen (term/keyview.h) */
	keyview_item bar[32];  /* the help bar, from the key table */
	termout *out;          /* borrowed: the output scheduler */
	abuf late;             /* key bytes the scheduler gave up holding (keymode_late_keys) */
	bool help;             /* the help bar is shown */
	double layout_aspect;  /* the image aspect the layout is for */

	rsvc *rs;              /* the shell's render service */
	const world *w;        /* a reference to the world for wgen (NULL: none yet) */
	uint64_t wgen;
	double step;

	km_sel sel;
	bool run_open;         /* an undo group is open: typed keys since the last pause, a drag, a turn */
	int run_key;           /* what opened it: a key, KEYS_MOUSE (a drag), KEYS_NONE (the turntable) */
	km_sel run_sel;
	double last_edit;      /* when the last edit key came */

	km_cur cur;
	bool want_fast, want_refine; /* a render to start */
	bool refined;          /* the newest request is a refine (or needs none) */
	bool stopped;
	double last_key;
	int ratio_i;
	double cost;           /* seconds per pixel and sample; 0 = not known */
	rsvc_image img;        /* the newest image taken (of the request cur) */
	rsvc_image spare;      /* what rsvc_take copies out, swapped in when it answers cur */
	bool have_img, dirty;
	bool held;             /* a new image waits to be drawn */
	double last_draw;
	uint8_t *small, *big, *mask;
	size_t small_cap, big_cap, mask_cap;
	bool mask_ok;
	uint64_t mask_gen;
	km_sel mask_sel;
	int mask_w, mask_h;
	bool sel_visible;
	bool light_behind;     /* the selected light is behind the camera */

	bool model;            /* the model viewer's scene: arrows orbit */
	camera home;           /* `0` brings it back */
	/* The mouse: a button held since (press_x, press_y); the camera
	 * follows (mouse_x, mouse_y) from (done_x, done_y) at the next tick. */
	bool drag, pan, moved;
	int press_x, press_y, done_x, done_y, mouse_x, mouse_y;
	vec3 pivot;
	/* The turntable: a turn in spin seconds (0: not spinning) from
	 * spin_cam at spin_t0. */
	double spin, spin_t0;
	camera spin_cam;
	vec3 spin_pivot;

	char msg[256];
	double msg_until;
	double fast_times[16]; /* when the last fast frames were drawn */
	long fast_frames, frames;
	int edits;
	bool quit;
};

/* --- layout --- */

static double km_aspect(const keymode *km)
{
	return (double)km->sh->set.width / km->sh->set.height;
}

static void km_layout(keymode *km)
{
	km->layout_aspect = km_aspect(km);
	keyview_layout(&km->kv, km->kv.cols, km->kv.rows, km->help, km->layout_aspect);
	km->mask_ok = false;
}

static void km_message(keymode *km, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void km_message(keymode *km, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(km->msg, sizeof km->msg, fmt, ap);
	va_end(ap);
	km->msg_until = now() + 3.0;
	km->dirty = true;
}

/* --- the world and the requests --- */

/* The world for the editor's scene, from the render service (built when
 * the scene changed); key mode holds a reference until the scene changes
 * again, so neither the selection marks nor a render ever use a world the
 * service (or the shell's preview) let go of. */
static const world *km_world(keymode *km)
{
	uint64_t gen = editor_generation(km->sh->ed);
	if (km->w && km->wgen == gen)
		return km->w;
	world_release(km->w);
	rt_error err;
	rt_error_clear(&err);
	km->w = rsvc_world(km->rs, editor_scene(km->sh->ed), gen, render_threads(&km->sh->set), NULL, &err);
	km->wgen = gen;
	if (!km->w)
		km_message(km, "the scene cannot be shown: %s", err.msg);
	return km->w;
}

static int km_pick_ratio(keymode *km)
{
	if (!(km->cost > 0))
		return km->ratio_i > 0 ? km->ratio_i : 2;
	int loose = NRATIOS - 1, strict = NRATIOS - 1;
	for (int i = NRATIOS - 1; i >= 0; i--) {
		double r = ratios[i];
		double px = ceil(km->kv.img_w / r) * ceil(km->kv.img_h / r);
		double t = px * km->cost;
		if (t <= KEYMODE_FRAME_BUDGET)
			loose = i;
		if (t <= 0.7 * KEYMODE_FRAME_BUDGET)
			strict = i;
	}
	int i = km->ratio_i;
	if (i < loose)
		i = loose;
	if (i > strict)
		i = strict;
	return i;
}

/* What the last cancelled fast frame says about the cost of a pixel. */
static void km_learn_from_cut(keymode *km)
{
	uint64_t seq;
	double sec, frac;
	if (!rsvc_cut(km->rs, &seq, &sec, &frac) || seq != km->cur.seq || km->cur.refine)
		return;
	double px = (double)km->cur.w_px * km->cur.h_px;
	if (px <= 0 || sec < 0.002)
		return; /* cut at once: says nothing */
	double c = frac > 0.05 ? sec / (frac * px) : sec / px;
	if (c > km->cost)
		km->cost = km->cost > 0 ? 0.5 * (km->cost + c) : c;
}

static void km_start(keymode *km, bool refine)
{
	shell *sh = km->sh;
	if (km->kv.img_w <= 0 || km->kv.img_h <= 0)
		return;
	rsvc_hold(km->rs);
	km_learn_from_cut(km);
	const world *w = km_world(km);
	if (!w)
		return;
	/* refinement goes to the preview's target (path mode's own when no
	 * samples were chosen); a frame while keys arrive takes sh->set's */
	render_settings set = refine ? shell_preview_settings(sh) : sh->set;
	rsvc_request r = {
		.world = w,
		.gen = km->wgen,
		.set = set,
		.w = km->kv.img_w,
		.h = km->kv.img_h,
	};
	km_cur c = {.gen = km->wgen, .set = set, .refine = refine, .w_px = km->kv.img_w, .h_px = km->kv.img_h};
	if (refine) {
		/* Goes on from the samples already in when only their number
		 * changed. */
		r.kind = RSVC_REFINE;
		r.accumulate = true;
		r.pass_seconds = KEYMODE_PASS_SECONDS;
		/* Path passes denoised, as the shell's previews (set denoise). */
		r.denoise = render_mode_denoises(sh->set.mode) && sh->set.denoise != DENOISE_OFF;
	} else {
		km->ratio_i = km_pick_ratio(km);
		r.kind = RSVC_FRAME;
		r.ratio = ratios[km->ratio_i];
		rsvc_frame_size(km->kv.img_w, km->kv.img_h, r.ratio, &c.w_px, &c.h_px);
	}
	c.seq = rsvc_start(km->rs, &r);
	km->cur = c;
	km->refined = refine;
	km->stopped = false;
	if (!c.seq)
		km_message(km, "cannot start the render thread");
}

/* --- drawing --- */

static bool grow(uint8_t **p, size_t *cap, size_t n)
{
	if (n <= *cap)
		return true;
	uint8_t *q = realloc(*p, n);
	if (!q)
		return false;
	*p = q;
	*cap = n;
	return true;
}

/* Which picture pixels show the selected object (primary rays through the
 * pixel centres, as the renderer casts them). */
static void km_mask(keymode *km)
{
	uint64_t gen = km->wgen;
	if (km->mask_ok && km->mask_gen == gen && km->mask_sel.kind == km->sel.kind &&
	    km->mask_sel.index == km->sel.index && km->mask_w == km->kv.img_w && km->mask_h == km->kv.img_h)
		return;
	km->mask_ok = false;
	km->sel_visible = false;
	if (km->sel.kind != KM_SEL_OBJECT || !km->w)
		return;
	size_t n = (size_t)km->kv.img_w * (size_t)km->kv.img_h;
	if (!grow(&km->mask, &km->mask_cap, n))
		return;
	const world *w = km->w;
	uint32_t want = (uint32_t)km->sel.index;
	for (int y = 0; y < km->kv.img_h; y++)
		for (int x = 0; x < km->kv.img_w; x++) {
			ray r = cam_ray(&w->cam, x + 0.5, y + 0.5, km->kv.img_w, km->kv.img_h);
			hit h;
			bool on = world_intersect(w, &r, 0.0, INFINITY, &h) && h.object == want;
			km->mask[(size_t)y * km->kv.img_w + x] = on;
			km->sel_visible |= on;
		}
	km->mask_ok = true;
	km->mask_gen = gen;
	km->mask_sel = km->sel;
	km->mask_w = km->kv.img_w;
	km->mask_h = km->kv.img_h;
}

static void put_px(uint8_t *img, int w, int h, int x, int y, const uint8_t c[3])
{
	if (x < 0 || y < 0 || x >= w || y >= h)
		return;
	memcpy(img + ((size_t)y * w + x) * 3, c, 3);
}

/* Marks the selection on the picture (img_w x img_h sRGB). */
static void km_mark(keymode *km, uint8_t *img)
{
	int w = km->kv.img_w, h = km->kv.img_h;
	if (km->sel.kind == KM_SEL_OBJECT) {
		km_mask(km);
		if (!km->mask_ok)
			return;
		const uint8_t *m = km->mask;
		/* An outline just outside the object's pixels. */
		for (int y = 0; y < h; y++)
			for (int x = 0; x < w; x++) {
				size_t i = (size_t)y * w + x;
				if (m[i])
					continue;
				bool edge = (x > 0 && m[i - 1]) || (x + 1 < w && m[i + 1]) || (y > 0 && m[i - w]) ||
				            (y + 1 < h && m[i + w]);
				if (edge)
					memcpy(img + i * 3, mark_rgb, 3);
			}
	} else if (km->sel.kind == KM_SEL_LIGHT && km->w) {
		const scene *s = editor_scene(km->sh->ed);
		km->sel_visible = false;
		if (km->sel.index >= s->nlights)
			return;
		const cam_view *c = &km->w->cam;
		vec3 p = v3_sub(s->lights[km->sel.index].pos, c->pos);
		double z = v3_dot(p, c->fwd);
		km->light_behind = !(z > 0);
		if (km->light_behind)
			return; /* the status line says so */
		double tx = cam_tan_x(c, w, h);
		if (!(tx > 0))
			return; /* an orthographic view: no marker */
		double u = v3_dot(p, c->right) / (z * tx);
		double v = v3_dot(p, c->up) / (z * tx * ((double)h / w));
		double fx = (u + 1) * 0.5 * w, fy = (1 - v) * 0.5 * h;
		static const uint8_t white[3] = {255, 255, 255}, dark[3] = {40, 30, 0};
		if (!(fx >= 0 && fy >= 0 && fx < w && fy < h)) {
			/* Off the picture but ahead: a gold bar on the edge it lies
			 * beyond, at the nearest point. */
			int px = (int)clampd(floor(fx), 0, w - 1), py = (int)clampd(floor(fy), 0, h - 1);
			bool horizontal = fy < 0 || fy >= h;
			for (int d = -3; d <= 3; d++)
				for (int k = 0; k < 2; k++) {
					int x = horizontal ? px + d : px == 0 ? k : w - 1 - k;
					int y = horizontal ? (py == 0 ? k : h - 1 - k) : py + d;
					put_px(img, w, h, x, y, k ? dark : mark_rgb);
				}
			return;
		}
		int px = (int)fx, py = (int)fy;
		km->sel_visible = true;
		/* A plus of gold arms around a white centre, on a dark ring. */
		for (int d = -3; d <= 3; d++) {
			put_px(img, w, h, px + d, py - 1, dark);
			put_px(img, w, h, px + d, py + 1, dark);
			put_px(img, w, h, px - 1, py + d, dark);
			put_px(img, w, h, px + 1, py + d, dark);
		}
		for (int d = -3; d <= 3; d++) {
			put_px(img, w, h, px + d, py, mark_rgb);
			put_px(img, w, h, px, py + d, mark_rgb);
		}
		put_px(img, w, h, px, py, white);
	}
}

static const char *km_sel_name(const keymode *km, char *buf, size_t size)
{
	const scene *s = editor_scene(km->sh->ed);
	switch (km->sel.kind) {
	case KM_SEL_OBJECT:
		if (km->sel.index < s->nobjs) {
			snprintf(buf, size, "object %zu %s%s", km->sel.index + 1,
			         obj_kind_name(s->objs[km->sel.index].kind), km->sel_visible ? "" : " (hidden)");
			return buf;
		}
		break;
	case KM_SEL_LIGHT:
		if (km->sel.index < s->nlights) {
			snprintf(buf, size, "light %zu%s", km->sel.index + 1,
			         km->sel_visible ? "" : km->light_behind ? " (behind the camera)" : " (out of view: the gold bar)");
			return buf;
		}
		break;
	case KM_SEL_CAMERA:
		break;
	}
	snprintf(buf, size, "camera");
	return buf;
}

/* Fast frames a second over the last ones drawn within a second; 0 when
 * not moving. */
static double km_fps(const keymode *km)
{
	long total = km->fast_frames;
	double t = now();
	if (total < 2 || t - km->fast_times[(total - 1) % 16] > 0.5)
		return 0;
	double newest = km->fast_times[(total - 1) % 16], oldest = newest;
	int n = 1;
	for (long i = total - 2; i >= 0 && i > total - 16; i--) {
		double ti = km->fast_times[i % 16];
		if (newest - ti > 1.0)
			break;
		oldest = ti;
		n++;
	}
	return n > 1 && newest > oldest ? (n - 1) / (newest - oldest) : 0;
}

static void km_status_text(keymode *km, char *buf, size_t size)
{
	shell *sh = km->sh;
	char sel[128], spp[64], res[48] = "", fps[32] = "", t[32] = "";
	km_sel_name(km, sel, sizeof sel);
	const rsvc_image *im = &km->img;
	bool refine = im->kind == RSVC_REFINE;
	if (!km->have_img)
		snprintf(spp, sizeof spp, "rendering");
	else if (!refine && !km->refined)
		snprintf(spp, sizeof spp, "moving");
	else if (!refine)
		snprintf(spp, sizeof spp, "1/1 spp");
	else
		snprintf(spp, sizeof spp, "%d/%d spp%s%s", im->spp, im->target,
		         km->stopped ? " stopped" : im->done ? "" : "…", im->denoised ? " │ denoised" : "");
	if (km->have_img && !refine && ratios[km->ratio_i] > 1)
		snprintf(res, sizeof res, " (1/%g res)", ratios[km->ratio_i]);
	double f = km_fps(km);
	if (f > 0)
		snprintf(fps, sizeof fps, "%.0f fps", f);
	if (km->have_img)
		snprintf(t, sizeof t, "%.0f ms", im->pass_seconds * 1000);
	/* A message goes right after the selection, where it is not cut off. */
	bool msg = km->msg[0] && now() < km->msg_until;
	char depth[32], size_s[96], step[48];
	snprintf(depth, sizeof depth, "depth %d", sh->set.depth);
	snprintf(size_s, sizeof size_s, "%dx%d%s", km->kv.img_w, km->kv.img_h, res);
	snprintf(step, sizeof step, "step %.3g", km->step);
	/* Fitted to the width (issue 31, friction 3): the timings go first,
	 * then the depth, the size, the scene's name and the mode; the
	 * selection, a message, the samples and the step stay. */
	const char *fields[] = {"view", sh->name, sel, msg ? km->msg : "", render_mode_name(sh->set.mode), spp,
	                        depth, size_s, fps, t, step};
	const int drop[] = {0, 5, 0, 0, 6, 0, 3, 4, 2, 1, 0};
	keyview_fit_status(buf, size, fields, drop, sizeof fields / sizeof fields[0], km->kv.cols > 0 ? km->kv.cols : 80);
}

/* Puts the newest image (scaled up to the picture size) with the marks
 * for the output scheduler, and draws the status line (and all of the
 * screen after a repaint). */
static void km_draw(keymode *km)
{
	const rsvc_image *im = &km->img;
	if (km->kv.enc && km->have_img && im->w > 0 && im->h > 0) {
		int W = km->kv.img_w, H = km->kv.img_h;
		size_t n = (size_t)W * H * 3, sn = (size_t)im->w * im->h * 3;
		if (grow(&km->small, &km->small_cap, sn) && grow(&km->big, &km->big_cap, n)) {
			frame_srgb_from_linear(im->rgb, (size_t)im->w * im->h, km->sh->set.exposure, km->small);
			/* Pixel replication up to the picture size. */
			for (int y = 0; y < H; y++) {
				int sy = (int)((long)y * im->h / H);
				const uint8_t *src = km->small + (size_t)sy * im->w * 3;
				uint8_t *dst = km->big + (size_t)y * W * 3;
				for (int x = 0; x < W; x++)
					memcpy(dst + (size_t)x * 3, src + (size_t)((long)x * im->w / W) * 3, 3);
			}
			km_mark(km, km->big);
			keyview_picture(&km->kv, km->big, im->kind != RSVC_REFINE || im->done);
		}
	}
	char status[1024];
	km_status_text(km, status, sizeof status);
	keyview_draw(&km->kv, status);
	km->dirty = false;
	km->last_draw = now();
}

/* --- keys --- */

static void km_close_run(keymode *km)
{
	if (km->run_open) {
		editor_group_end(km->sh->ed);
		km->run_open = false;
	}
}

/* The scene's home view and whether it is the model viewer's. */
static void km_home(keymode *km)
{
	const char *label = editor_label(km->sh->ed);
	km->model = label && mesh_format_known(label);
	km->home = scene_camera(editor_scene(km->sh->ed));
	/* The help bar says what the arrows do here. */
	size_t n = km->model ? keymode_help_bar_model(km->bar, sizeof km->bar / sizeof km->bar[0])
	                     : keymode_help_bar(km->bar, sizeof km->bar / sizeof km->bar[0]);
	km->kv.bar = km->bar;
	km->kv.nbar = n;
	keyview_repaint(&km->kv);
}

/* After an edit that may have replaced the scene (undo, redo, PgUp/PgDn):
 * the step, the selection and the layout follow the new scene. */
static void km_after_replace(keymode *km, const char *label_before)
{
	shell *sh = km->sh;
	const char *label = editor_label(sh->ed);
	bool same = label == label_before || (label && label_before && strcmp(label, label_before) == 0);
	if (!same) {
		/* Another scene: its own step, and the camera selected. */
		km->step = keymode_step(editor_scene(sh->ed));
		km->cost = 0;
		km->sel = (km_sel){KM_SEL_CAMERA, 0};
		km_home(km);
	}
	if (!keymode_sel_valid(editor_scene(sh->ed), km->sel))
		km->sel = (km_sel){KM_SEL_CAMERA, 0};
	if (km_aspect(km) != km->layout_aspect)
		km_layout(km);
}

/* Runs a shell command (next, prev) with its output and notes caught
 * (the shell's sinks, not the terminal) and the last line shown in the
 * status line instead. */
static bool km_shell_command(keymode *km, cmd_fn fn)
{
	shell *sh = km->sh;
	abuf out;
	abuf_init(&out);
	abuf *capture = sh->capture, *notes = sh->notes;
	sh->capture = sh->notes = &out;
	sh->err[0] = '\0';
	bool ok = fn(sh, 0, NULL, "");
	sh->capture = capture;
	sh->notes = notes;
	/* The last line that says something. */
	char last[256] = "";
	for (size_t i = 0; i < out.len && !out.failed;) {
		size_t j = i;
		while (j < out.len && out.b[j] != '\n')
			j++;
		if (j > i)
			snprintf(last, sizeof last, "%.*s", (int)(j - i), out.b + i);
		i = j + 1;
	}
	abuf_free(&out);
	if (!ok)
		km_message(km, "%s", sh->err);
	else if (last[0])
		km_message(km, "%s", last);
	sh->err[0] = '\0';
	return ok;
}

static void km_settings(keymode *km, const km_action *a)
{
	shell *sh = km->sh;
	rt_error err;
	const setting_def *def;
	switch (a->op) {
	case KM_SAMPLES:
		def = settings_find("samples", &err);
		if (def) {
			long v = a->n > 0 ? (long)sh->set.samples * 2 : sh->set.samples / 2;
			v = v < (long)def->min ? (long)def->min : v > (long)def->max ? (long)def->max : v;
			if (v == sh->set.samples)
				km_message(km, "samples: %d is the %s", sh->set.samples, a->n > 0 ? "most" : "least");
			sh->set.samples = (int)v;
		}
		break;
	case KM_DEPTH:
		def = settings_find("depth", &err);
		if (def) {
			long v = sh->set.depth + a->n;
			v = v < (long)def->min ? (long)def->min : v > (long)def->max ? (long)def->max : v;
			if (v == sh->set.depth)
				km_message(km, "depth: %d is the %s", sh->set.depth, a->n > 0 ? "most" : "least");
			sh->set.depth = (int)v;
		}
		km->cost = 0;
		break;
	default: /* KM_MODE */
		sh->set.mode = sh->set.mode == MODE_PATH ? MODE_WHITTED : MODE_PATH;
		km->cost = 0;
		break;
	}
	km->want_refine = true;
	km->want_fast = false;
}

/* One edit of the active camera (an undo step of its own unless a run or
 * a drag is open). */
static void km_set_camera(keymode *km, const camera *c)
{
	shell *sh = km->sh;
	uint64_t gen = editor_generation(sh->ed);
	rt_error err;
	if (!editor_set_camera(sh->ed, editor_scene(sh->ed)->cam, c, &err))
		km_message(km, "%s", err.msg);
	if (editor_generation(sh->ed) != gen) {
		km->edits++;
		km->want_fast = true;
		km->last_key = now();
	}
}

static void km_stop_spin(keymode *km)
{
	if (km->spin > 0) {
		km->spin = 0;
		km_close_run(km);
		km_message(km, "turntable stopped; u undoes the turn");
	}
}

void keymode_spin(keymode *km, double seconds)
{
	if (!(seconds > 0))
		return;
	km_close_run(km);
	const scene *s = editor_scene(km->sh->ed);
	km->spin = seconds;
	km->spin_t0 = now();
	km->spin_cam = scene_camera(s);
	km->spin_pivot = orbit_scene_centre(s);
	editor_group_begin(km->sh->ed);
	km->run_open = true;
	km->run_key = KEYS_NONE;
	km->run_sel = km->sel;
	km->want_fast = true;
	km_message(km, "turntable: a turn in %g s; any key stops it", seconds);
}

/* The turntable's next view, once the last one is drawn (frames are paced
 * as the keys' are: one in flight, a newer picture overtaking an older
 * one on a slow link). */
static void km_spin_step(keymode *km, double t)
{
	if (!(km->spin > 0) || km->want_fast || km->held || (rsvc_busy(km->rs) && !km->cur.refine))
		return;
	double turns = (t - km->spin_t0) / km->spin;
	double deg = 360.0 * (turns - floor(turns));
	camera c = orbit_camera(km->spin_cam, km->spin_pivot, deg, 0.0);
	km_set_camera(km, &c);
}

/* The encoder's canvas pixels a cell: 1x2 for half blocks, 2x4 for the
 * other symbol sets, the cell's size in real pixels. */
static void km_cell_pixels(const keymode *km, double *sx, double *sy)
{
	int cw = km->kv.cols, ch = 2 * km->kv.pic_rows;
	if (km->kv.enc)
		km->kv.enc->ops->canvas(&km->kv.enc->geom, &cw, &ch);
	*sx = km->kv.cols > 0 ? (double)cw / km->kv.cols : 1;
	*sy = km->kv.pic_rows > 0 ? (double)ch / km->kv.pic_rows : 2;
}

/* The object under the cell (x, y) (1-based): a ray through its middle,
 * as the renderer casts them. */
static void km_pick(keymode *km, int x, int y)
{
	const world *w = km_world(km);
	double sx, sy;
	km_cell_pixels(km, &sx, &sy);
	double px = ((x - 1) + 0.5) * sx - km->kv.img_x, py = ((y - 1) + 0.5) * sy - km->kv.img_y;
	if (!w || px < 0 || py < 0 || px >= km->kv.img_w || py >= km->kv.img_h)
		return;
	const scene *s = editor_scene(km->sh->ed);
	ray r = cam_ray(&w->cam, px, py, km->kv.img_w, km->kv.img_h);
	hit h;
	km_close_run(km);
	if (world_intersect(w, &r, 0.0, INFINITY, &h) && h.object < s->nobjs) {
		km->sel = (km_sel){KM_SEL_OBJECT, h.object};
		km_message(km, "selected object %zu %s", (size_t)h.object + 1, obj_kind_name(s->objs[h.object].kind));
	} else {
		km->sel = (km_sel){KM_SEL_CAMERA, 0};
		km_message(km, "nothing there: the camera is selected");
	}
	km->dirty = true;
}

/* The drag so far: the camera from (done_x, done_y) to (mouse_x, mouse_y). */
static void km_apply_drag(keymode *km)
{
	int dx = km->mouse_x - km->done_x, dy = km->mouse_y - km->done_y;
	if (!km->drag || (dx == 0 && dy == 0))
		return;
	km->done_x = km->mouse_x;
	km->done_y = km->mouse_y;
	const scene *s = editor_scene(km->sh->ed);
	camera c = scene_camera(s);
	if (km->pan) {
		/* The scene follows the cursor: at the pivot's distance, a pixel
		 * of the picture is 2 d tan(fov/2) / width. */
		cam_view v = cam_view_make(&c);
		double d = v3_len(v3_sub(c.pos, km->pivot)), sx, sy;
		km_cell_pixels(km, &sx, &sy);
		double u = km->kv.img_w > 0 ? 2.0 * d * v.tan_half / km->kv.img_w : 0;
		vec3 mv = v3_add(v3_scale(v.right, -dx * sx * u), v3_scale(v.up, dy * sy * u));
		c.pos = v3_add(c.pos, mv);
		km->pivot = v3_add(km->pivot, mv);
	} else {
		c = orbit_camera(c, km->pivot, -dx * KEYMODE_DRAG_DEG, 2.0 * dy * KEYMODE_DRAG_DEG);
	}
	km_set_camera(km, &c);
}

void keymode_mouse(keymode *km, const keys_mouse *m)
{
	if (km->quit)
		return;
	km_stop_spin(km);
	const scene *s = editor_scene(km->sh->ed);
	if (m->button == KEYS_WHEEL_UP || m->button == KEYS_WHEEL_DOWN) {
		km_apply_drag(km);
		if (!km->drag)
			km_close_run(km);
		camera c = orbit_dolly(scene_camera(s), keymode_pivot(s, km->sel),
		                       m->button == KEYS_WHEEL_UP ? KEYMODE_DOLLY : 1.0 - 1.0 / (1.0 - KEYMODE_DOLLY));
		km_set_camera(km, &c);
		return;
	}
	if (m->motion) {
		if (km->drag) {
			km->mouse_x = m->x;
			km->mouse_y = m->y;
			km->moved |= m->x != km->press_x || m->y != km->press_y;
		}
		return;
	}
	if (!m->release && (m->button == KEYS_BUTTON_LEFT || m->button == KEYS_BUTTON_MIDDLE)) {
		km_close_run(km);
		km->drag = true;
		km->pan = m->shift || m->button == KEYS_BUTTON_MIDDLE;
		km->moved = false;
		km->press_x = km->done_x = km->mouse_x = m->x;
		km->press_y = km->done_y = km->mouse_y = m->y;
		km->pivot = keymode_pivot(s, km->sel);
		/* The whole drag is one undo step. */
		editor_group_begin(km->sh->ed);
		km->run_open = true;
		km->run_key = KEYS_MOUSE;
		km->run_sel = km->sel;
		return;
	}
	if (m->release && km->drag) {
		km->mouse_x = m->x;
		km->mouse_y = m->y;
		km->moved |= m->x != km->press_x || m->y != km->press_y;
		km_apply_drag(km);
		km->drag = false;
		km_close_run(km);
		if (!km->moved && !km->pan)
			km_pick(km, m->x, m->y);
	}
}

void keymode_key(keymode *km, int key)
{
	if (km->quit)
		return;
	km_stop_spin(km);
	shell *sh = km->sh;
	const scene *s = editor_scene(sh->ed);
	km_action a = km->model ? keymode_map_model(key, s, km->sel, km->step) : keymode_map(key, s, km->sel, km->step);
	if (a.op == KM_NONE)
		return;
	km->last_key = now();
	if (keymode_is_edit(a.op)) {
		/* Edit keys without a pause in typing between them (whichever
		 * keys, whichever selection) undo as one step. */
		if (!(km->run_open && km->run_key != KEYS_MOUSE && km->run_key != KEYS_NONE &&
		      km->last_key - km->last_edit < KEYMODE_STEP_PAUSE)) {
			km_close_run(km);
			editor_group_begin(sh->ed);
			km->run_open = true;
			km->run_key = key;
			km->run_sel = km->sel;
		}
		km->last_edit = km->last_key;
		uint64_t gen = editor_generation(sh->ed);
		rt_error err;
		if (!keymode_apply(sh->ed, &a, &err))
			km_message(km, "%s", err.msg);
		if (editor_generation(sh->ed) != gen) {
			km->edits++;
			km->want_fast = true;
		}
		return;
	}
	km_close_run(km);
	uint64_t gen = editor_generation(sh->ed);
	const char *label = editor_label(sh->ed);
	char *label_copy = label ? strdup(label) : NULL;
	rt_error err;
	switch (a.op) {
	case KM_SELECT:
		km->sel = a.sel;
		km->dirty = true;
		break;
	case KM_UNDO:
	case KM_REDO:
		/* The shell's calls below hold and release the render service: nothing
		 * of ours may be rendering then. */
		rsvc_hold(km->rs);
		shell_edit_begin(sh);
		if (!(a.op == KM_UNDO ? editor_undo(sh->ed, &err) : editor_redo(sh->ed, &err)))
			km_message(km, "%s", err.msg);
		shell_edit_end(sh);
		km_after_replace(km, label_copy);
		if (editor_generation(sh->ed) != gen)
			km->want_fast = true;
		else if (!km->stopped)
			km->want_refine = true; /* the render held above goes on */
		break;
	case KM_SCENE:
		rsvc_hold(km->rs);
		km_shell_command(km, a.n > 0 ? cmd_next : cmd_prev);
		km_after_replace(km, label_copy);
		km->want_refine = true;
		km->want_fast = false;
		break;
	case KM_SAMPLES:
	case KM_DEPTH:
	case KM_MODE:
		km_settings(km, &a);
		break;
	case KM_STOP:
		if (rsvc_busy(km->rs) || km->want_fast || km->want_refine || !km->refined) {
			rsvc_hold(km->rs);
			km->want_fast = km->want_refine = false;
			km->refined = true;
			km->stopped = true;
			km_message(km, "stopped; any key that changes the picture renders again");
		} else {
			km_message(km, "nothing to stop: the picture is done");
		}
		break;
	case KM_REDRAW:
		keyview_repaint(&km->kv);
		km->dirty = true;
		break;
	case KM_HELP:
		km->help = !km->help;
		km_layout(km);
		km->want_refine = true;
		break;
	case KM_QUIT:
		km->quit = true;
		break;
	case KM_FRAME: {
		box b = km->sel.kind == KM_SEL_OBJECT && km->sel.index < s->nobjs ? object_bounds(&s->objs[km->sel.index])
		                                                                  : orbit_scene_bounds(s);
		if (km->sel.kind == KM_SEL_LIGHT && km->sel.index < s->nlights)
			b = (box){v3_sub(s->lights[km->sel.index].pos, v3_splat(km->step * 4)),
			          v3_add(s->lights[km->sel.index].pos, v3_splat(km->step * 4))};
		camera c = orbit_frame(scene_camera(s), b, km_aspect(km));
		km_set_camera(km, &c);
		break;
	}
	case KM_HOME:
		km_set_camera(km, &km->home);
		break;
	default:
		break;
	}
	free(label_copy);
}

/* Takes the newest image from the service; true when there is one to show
 * (images of an older request are dropped). */
static bool km_take(keymode *km)
{
	if (!rsvc_take(km->rs, &km->spare) || km->spare.seq != km->cur.seq)
		return false;
	rsvc_image t = km->img;
	km->img = km->spare;
	km->spare = t;
	km->have_img = true;
	/* What a pixel costs, for the next fast frame's ratio. */
	if (km->img.px_cost > 0)
		km->cost = km->cost > 0 ? 0.5 * (km->cost + km->img.px_cost) : km->img.px_cost;
	return true;
}

int keymode_tick(keymode *km)
{
	double t = now();
	km_apply_drag(km);
	km_spin_step(km, t);
	if (km->want_fast) {
		km->want_fast = false;
		km->want_refine = false;
		km_start(km, false);
	} else if (km->want_refine || (!km->refined && t - km->last_key >= KEYMODE_IDLE)) {
		km->want_refine = false;
		/* A fast frame at full resolution with one sample is final. */
		const km_cur *c = &km->cur;
		bool final = c->seq != 0 && !c->refine && km->ratio_i == 0 && shell_preview_settings(km->sh).samples == 1 &&
		             c->gen == editor_generation(km->sh->ed) && c->set.mode == km->sh->set.mode &&
		             c->set.depth == km->sh->set.depth && c->w_px == km->kv.img_w && c->h_px == km->kv.img_h;
		if (final)
			km->refined = true;
		else
			km_start(km, true);
	}
	if (km_take(km))
		km->held = true;
	/* Fast frames are drawn at once; passes of a refine at most 10 times a
	 * second (its first and last pass at once). */
	bool picture = km->held && (km->img.kind != RSVC_REFINE || km->img.done || km->img.spp <= 1 ||
	                            t - km->last_draw >= 0.1);
	if (km->msg[0] && t >= km->msg_until) {
		km->msg[0] = '\0';
		km->dirty = true;
	}
	if (!picture && !km->dirty) {
		/* The status line alone may have changed (the fps figure). */
		char status[1024];
		km_status_text(km, status, sizeof status);
		km->dirty = keyview_status_differs(&km->kv, status);
	}
	int drawn = 0;
	if (picture || km->dirty || km->kv.repaint) {
		km_draw(km);
		if (picture) {
			km->held = false;
			km->frames++;
			if (km->img.kind != RSVC_REFINE)
				km->fast_times[km->fast_frames++ % 16] = km->last_draw;
			drawn = 1;
		}
	}
	/* What the pacing allows of the picture now (the rest at the next
	 * ticks, or by the event loop's turns). */
	termout_pump(km->out, now(), &km->late);
	return drawn;
}

void keymode_late_keys(keymode *km, abuf *to)
{
	abuf_add(to, km->late.b, km->late.len);
	abuf_reset(&km->late);
}

double keymode_timeout(const keymode *km)
{
	double t = now(), best = -1;
	if (!km->refined) {
		double d = km->last_key + KEYMODE_IDLE - t;
		best = d < 0 ? 0 : d;
	}
	if (km->msg[0]) {
		double d = km->msg_until - t;
		d = d < 0 ? 0 : d;
		if (best < 0 || d < best)
			best = d;
	}
	/* A refine pass waiting for its turn to be drawn. */
	if (km->held) {
		double d = km->last_draw + 0.1 - t;
		d = d < 0 ? 0 : d;
		if (best < 0 || d < best)
			best = d;
	}
	/* The turntable's next view. */
	if (km->spin > 0 && (best < 0 || best > 0.02))
		best = 0.02;
	/* Let the fps figure go when keys stop. */
	if (km->fast_frames > 1 && t - km->fast_times[(km->fast_frames - 1) % 16] < 0.6) {
		double d = km->fast_times[(km->fast_frames - 1) % 16] + 0.6 - t;
		if (best < 0 || d < best)
			best = d < 0 ? 0 : d;
	}
	return best;
}

bool keymode_done(const keymode *km)
{
	return km->quit;
}

int keymode_edits(const keymode *km)
{
	return km->edits;
}

double keymode_ratio(const keymode *km)
{
	return ratios[km->ratio_i];
}

long keymode_frames(const keymode *km)
{
	return km->frames;
}

void keymode_resize(keymode *km, int cols, int rows)
{
	km->kv.cols = cols;
	km->kv.rows = rows;
	km_layout(km);
	km->want_refine = true;
	km->dirty = true;
}

keymode *keymode_new(shell *sh, termout *out, frame_palette pal, int cols, int rows)
{
	keymode *km = calloc(1, sizeof *km);
	if (!km) {
		shell_fail(sh, "view: out of memory");
		return NULL;
	}
	km->sh = sh;
	km->out = out;
	size_t nbar = keymode_help_bar(km->bar, sizeof km->bar / sizeof km->bar[0]);
	keyview_init(&km->kv, out, pal, km->bar, nbar);
	km->kv.cols = cols;
	km->kv.rows = rows;
	km->help = true;
	abuf_init(&km->late);
	km->rs = sh->rs;
	rsvc_hold(km->rs);
	km->step = keymode_step(editor_scene(sh->ed));
	km->sel = (km_sel){KM_SEL_CAMERA, 0};
	km_home(km);
	km_layout(km);
	km->want_refine = true;
	km->refined = true;
	km->dirty = true;
	return km;
}

void keymode_set_encoder(keymode *km, const encoder_ops *ops, int cell_w, int cell_h, int max_w, int max_h)
{
	keyview_set_encoder(&km->kv, ops, cell_w, cell_h, max_w, max_h);
	km_layout(km);
}

void keymode_free(keymode *km)
{
	if (!km)
		return;
	rsvc_hold(km->rs);
	world_release(km->w);
	km_close_run(km);
	keyview_end(&km->kv);
	keyview_free(&km->kv);
	abuf_free(&km->late);
	rsvc_image_free(&km->img);
	rsvc_image_free(&km->spare);
	free(km->small);
	free(km->big);
	free(km->mask);
	free(km);
}

/* ------------------------------------------------------------------ */
/* 2. The loop                                                         */
/* ------------------------------------------------------------------ */

static void term_size(int fd, int *cols, int *rows)
{
	struct winsize ws;
	if (ioctl(fd, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0 && ws.ws_row > 0) {
		*cols = ws.ws_col;
		*rows = ws.ws_row;
	} else {
		*cols = 80;
		*rows = 24;
	}
}

/* The terminal modes of key mode: keys one at a time, no echo; Ctrl-C,
 * Ctrl-Z and Ctrl-\ still send their signals. */
static void raw_modes(int fd, const struct termios *saved)
{
	struct termios t = *saved;
	t.c_lflag &= ~(tcflag_t)(ICANON | ECHO);
	t.c_iflag &= ~(tcflag_t)ICRNL;
	t.c_cc[VMIN] = 1;
	t.c_cc[VTIME] = 0;
	tcsetattr(fd, TCSANOW, &t);
}

bool keymode_run(shell *sh)
{
	return keymode_turntable(sh, 0);
}

bool keymode_turntable(shell *sh, double seconds)
{
	screen *scr = sh->scr;
	evloop *ev = sh->ev;
	const char *cmd = seconds > 0 ? "turntable" : "view"; /* the command's name for its errors */
	if (!sh->interactive || !scr || !scr->active || !scr->out || !ev || evloop_out(ev) != scr->out ||
	    !isatty(evloop_in_fd(ev)))
		return shell_fail(sh, "%s: key mode needs the full-screen shell on a terminal", cmd);
	int in = evloop_in_fd(ev), fd = scr->fd;
	termout *out = scr->out;
	fflush(stdout);
	struct termios saved;
	if (tcgetattr(in, &saved) != 0)
		return shell_fail(sh, "%s: cannot read the terminal's modes: %s", cmd, strerror(errno));
	/* The answers the terminal owes the output scheduler come in before
	 * key mode starts (keys typed meanwhile are dropped). */
	evloop_settle(ev, 5.0);
	while (evloop_getc(ev) >= 0)
		;
	abuf pend;
	abuf_init(&pend);
	/* The shell's event loop reads the terminal: the scheduler takes its
	 * answers out (they pace the picture), and the keys go on to ncurses
	 * (keys_feed), which never reads the terminal itself. */
	keys *k = keys_open_fed(25);
	if (!k) {
		abuf_free(&pend);
		return shell_fail(sh, "%s: ncurses cannot read the keys of this terminal (TERM=%s)", cmd,
		                  getenv("TERM") ? getenv("TERM") : "");
	}
	/* kitty images float over text: none may stay under key mode's. */
	screen_drop_images(scr);
	/* The shell's screen steps aside: nothing of the shell draws until
	 * key mode is over. */
	void (*hook)(shell *) = sh->status_hook;
	sh->status_hook = NULL;
	sh->scr = NULL;
	raw_modes(in, &saved);
	/* The keypad transmit mode and the mouse (SGR reports of presses,
	 * releases and drags), off again on every way out (screen.h). */
	char on[96], off[96];
	snprintf(on, sizeof on, "%s%s", keys_keypad_on(k), KEYS_MOUSE_ON);
	snprintf(off, sizeof off, "%s%s", KEYS_MOUSE_OFF, keys_keypad_off(k));
	screen_keypad(fd, on, off, true);
	int cols, rows;
	term_size(fd, &cols, &rows);
	size_t undo0 = editor_undo_count(sh->ed);
	keymode *km = keymode_new(sh, out, scr->pal, cols, rows);
	bool ok = km != NULL;
	if (km) {
		/* The shell's picture: real pixels or its symbol set. */
		const pixels_caps *pc = termout_pixels(out);
		const encoder_ops *ops = scr->pix_ops ? scr->pix_ops : encoder_symbols(scr->sym);
		keymode_set_encoder(km, ops, scr->cell_w, scr->cell_h, pc ? pc->sixel_w : 0, pc ? pc->sixel_h : 0);
	}
	if (km)
		keymode_spin(km, seconds);
	while (km && !keymode_done(km)) {
		keymode_tick(km);
		/* Keys, wake-ups (a frame, a signal), the scheduler's slices and
		 * time-outs, or key mode's own timer. */
		evloop_wait(ev, keymode_timeout(km));
		if (shell_sig_term)
			break;
		if (shell_sig_int) {
			/* Ctrl-C leaves key mode (Space stops a render). */
			shell_sig_int = 0;
			atomic_store(&sh->cancel, false);
			break;
		}
		if (shell_sig_winch) {
			shell_sig_winch = 0;
			term_size(fd, &cols, &rows);
			keymode_resize(km, cols, rows);
		}
		if (shell_sig_cont) {
			/* Continued after Ctrl-Z (signals.c gave the terminal back
			 * and took it again): paint it all. */
			shell_sig_cont = 0;
			term_size(fd, &cols, &rows);
			keymode_resize(km, cols, rows);
		}
		/* Every key waiting, before the next frame starts. */
		int b;
		while ((b = evloop_getc(ev)) >= 0)
			abuf_char(&pend, (char)b);
		keymode_late_keys(km, &pend);
		if (pend.len && !pend.failed)
			keys_feed(k, pend.b, pend.len); /* a full pipe: keys typed far ahead are dropped */
		abuf_reset(&pend);
		int c;
		while (!keymode_done(km) && (c = keys_next(k)) != KEYS_NONE)
			if (c == KEYS_MOUSE) {
				keys_mouse m = keys_mouse_event(k);
				keymode_mouse(km, &m);
			} else if (c != KEYS_RESIZE) {
				keymode_key(km, c);
			}
		if (evloop_eof(ev))
			break; /* the terminal is gone */
	}
	keymode_free(km);
	size_t steps = editor_undo_count(sh->ed);
	steps = steps > undo0 ? steps - undo0 : 0;
	/* Give the terminal and the screen back to the shell. */
	screen_keypad(fd, NULL, NULL, false);
	keys_close(k);
	abuf_free(&pend);
	tcsetattr(in, TCSANOW, &saved);
	sh->scr = scr;
	sh->status_hook = hook;
	screen_drop_images(scr); /* key mode's kitty images, if any */
	termout_set_picture(out, scr->enc);
	screen_layout(scr, (double)sh->set.width / sh->set.height, true);
	rl_set_screen_size(scr->rows - scr->region_top, scr->cols);
	shell_refresh(sh);
	sh->redraw = true;
	if (ok && steps > 0)
		shell_info(sh, "%s: %zu change%s kept; undo takes %s back (a run of one key is one change)\n", cmd,
		           steps, steps == 1 ? "" : "s", steps == 1 ? "it" : "them");
	return ok;
}
