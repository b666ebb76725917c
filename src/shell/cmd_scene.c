/* rtsh — commands about the scene as a whole: load, save, render, set, list,
 * generate, show, source, view (next/prev: cmd_step.c). */
#include <dirent.h>
#include <errno.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>
#include <unistd.h>

#include "rtsh/num.h"
#include "rtsh/generate.h"
#include "rtsh/image.h"
#include "rtsh/mesh.h"
#include "rtsh/rtfile.h"
#include "rtsh/settings.h"
#include "shell/answer.h"
#include "shell/commands.h"
#include "shell/complete_files.h"
#include "shell/keymode.h"
#include "shell/save_rt.h"
#include "shell/suggest.h"
#include "term/caps.h"

/* A failed save, with the file it names ("save: FILE: what is wrong"). */
static bool save_failed(shell *sh, const rt_error *err)
{
	char msg[RT_ERROR_MSG_MAX + RT_ERROR_FILE_MAX + 32];
	rt_error_format(err, msg, sizeof msg);
	return shell_fail(sh, "save: %s", msg);
}

bool cmd_load(shell *sh, int argc, char **argv, const char *rest)
{
	(void)argc, (void)rest;
	render_settings before = sh->set;
	if (!argv[0][0]) /* load "": the message had no name in it */
		return shell_fail(sh, "load: \"\" is not a file name; expected a .rt file or a model");
	if (!shell_load(sh, argv[0]))
		return false;
	answer_loaded(sh, "loaded", &before);
	return true;
}

static bool has_ext(const char *path, const char *ext)
{
	size_t n = strlen(path), e = strlen(ext);
	return n > e && strcasecmp(path + n - e, ext) == 0;
}

typedef struct text_ctx {
	const abuf *a;
} text_ctx;

static bool write_text(FILE *f, void *ctx, rt_error *err)
{
	const text_ctx *t = ctx;
	if (t->a->len && fwrite(t->a->b, 1, t->a->len, f) != t->a->len)
		return rt_error_set(err, "cannot write: %s", strerror(errno));
	return true;
}

/* The terminal width for pictures printed outside the full screen. */
static int picture_columns(void)
{
	const char *c = getenv("COLUMNS");
	long v = c ? strtol(c, NULL, 10) : 0;
	return v >= 8 && v <= 1000 ? (int)v : 80;
}

bool cmd_save(shell *sh, int argc, char **argv, const char *rest)
{
	(void)argc, (void)rest;
	char *path = shell_expand_path(argv[0]);
	if (!path)
		return shell_fail(sh, "out of memory");
	rt_error err;
	bool ok = true;
	if (has_ext(path, ".rt")) {
		if (!save_rt(sh, path, &err)) {
			ok = save_failed(sh, &err);
		} else {
			sh->saved_gen = editor_generation(sh->ed);
			shell_info(sh, "saved the scene to %s\n", path);
			/* The file says which cameras, not which one is active. */
			const scene *s = editor_scene(sh->ed);
			if (s->cam > 0 && s->cam < s->ncams)
				shell_note(sh,
				           "save: %s opens with camera 1, not camera %zu, the active one (a .rt file opens "
				           "with its first camera) (warning)\n",
				           path, s->cam + 1);
		}
	} else if (has_ext(path, ".ans")) {
		frame *f = shell_picture_frame(sh, PALETTE_TRUECOLOR, picture_columns());
		if (!f) {
			ok = sh->err[0] ? false : shell_fail(sh, "save: no picture to save");
		} else {
			abuf a;
			abuf_init(&a);
			frame_text(f, &a);
			text_ctx t = {&a};
			if (a.failed)
				ok = shell_fail(sh, "save: out of memory");
			else if (!file_write_atomic(path, write_text, &t, &err))
				ok = save_failed(sh, &err);
			else
				shell_info(sh, "saved the %dx%d-cell picture to %s\n", f->cols, f->rows, path);
			abuf_free(&a);
			frame_free(f);
		}
	} else if (image_type_of(path)) {
		const framebuffer *fb = NULL;
		if (!file_folder_exists(path, &err)) /* now, not after the render */
			ok = save_failed(sh, &err);
		else if (!(fb = shell_full_image(sh, false)))
			ok = false;
		else if (!image_write(path, fb, sh->set.exposure, &err))
			ok = save_failed(sh, &err);
		else
			/* In path mode the preview is denoised and, under denoise
			 * auto, the saved image is not: say so, with the way to. */
			shell_info(sh, "saved %s (%dx%d, %d sample%s, %s%s)\n", path, fb->w, fb->h, fb->spp,
			           fb->spp == 1 ? "" : "s", render_mode_name(sh->full_set.mode),
			           render_mode_denoises(sh->full_set.mode) && sh->full_set.denoise == DENOISE_AUTO
			               ? "; the raw samples: the preview is denoised, set denoise on denoises saves too"
			           : render_mode_denoises(sh->full_set.mode) && sh->full_set.denoise == DENOISE_ON
			               ? ", denoised"
			               : "");
	} else {
		char exts[256] = "";
		const char *const *x = output_extensions();
		for (size_t i = 0; x[i]; i++) {
			size_t l = strlen(exts);
			snprintf(exts + l, sizeof exts - l, "%s%s", i == 0 ? "" : x[i + 1] ? ", " : " or ", x[i]);
		}
		ok = shell_fail(sh, "save: \"%s\" has an unknown type; expected %s", path, exts);
	}
	if (ok && *file_write_note()) /* written in place: say so */
		shell_note(sh, "save: %s\n", file_write_note());
	free(path);
	return ok;
}

bool cmd_render(shell *sh, int argc, char **argv, const char *rest)
{
	(void)argc, (void)argv, (void)rest;
	const framebuffer *before = sh->full;
	const framebuffer *fb = shell_full_image(sh, false);
	if (!fb)
		return false;
	shell_info(sh, "%s %dx%d, %d sample%s, %s, depth %d in %.2f s\n",
	          fb == before ? "up to date:" : "rendered", fb->w,
	          fb->h, fb->spp, fb->spp == 1 ? "" : "s", render_mode_name(sh->full_set.mode),
	          sh->full_set.depth, sh->full_seconds);
	return true;
}

bool cmd_set(shell *sh, int argc, char **argv, const char *rest)
{
	(void)rest;
	char val[64];
	if (argc == 0) {
		for (size_t i = 0; i < settings_count; i++) {
			settings_format(&sh->set, &settings_table[i], val, sizeof val);
			shell_out(sh, "  %-11s %-11s %s\n", settings_table[i].name, val, settings_table[i].help);
		}
		return true;
	}
	rt_error err;
	const setting_def *def = settings_find(argv[0], &err);
	if (!def) {
		const char *near = suggest_setting(argv[0]);
		if (near && strncmp(err.msg, "unknown", 7) == 0)
			return shell_fail(sh, "set: unknown setting \"%s\"; did you mean \"%s\"?", argv[0], near);
		return shell_fail(sh, "set: %s", err.msg);
	}
	if (argc == 1) {
		settings_format(&sh->set, def, val, sizeof val);
		shell_out(sh, "%s %s\n", def->name, val);
		return true;
	}
	render_settings s = sh->set;
	if (!settings_set(&s, def, argv[1], &err)) {
		char near[32], choices[256], expected[256];
		settings_choices_text(def, "|", "|", choices, sizeof choices);
		settings_choices_text(def, ", ", " or ", expected, sizeof expected);
		if (def->type == SETTING_ENUM && suggest_choice(choices, argv[1], near, sizeof near))
			return shell_fail(sh, "set: %s \"%s\" is not valid; did you mean \"%s\"? (expected %s)", def->name,
			                  argv[1], near, expected);
		return shell_fail(sh, "set: %s", err.msg);
	}
	char was[64];
	settings_format(&sh->set, def, was, sizeof was);
	size_t bit = (size_t)(def - settings_table); /* before the refresh, which reads it */
	if (bit < sizeof sh->hand_set * 8)
		sh->hand_set |= 1u << bit;
	shell_edit_begin(sh);
	sh->set = s;
	shell_edit_end(sh);
	settings_format(&sh->set, def, val, sizeof val);
	shell_info(sh, "%s %s%s%s%s\n", def->name, val, strcmp(was, val) ? " (was " : "",
	           strcmp(was, val) ? was : "", strcmp(was, val) ? ")" : "");
	return true;
}

/* The `list` of the cameras (which 0), lights (1) or objects (2): a line
 * an item, "camera 2 (active): C ...", or a line that says there are none. */
static void list_items(shell *sh, const scene *s, int which)
{
	static const char *const name[] = {"camera", "light", "object"};
	static const char *const none[] = {"no camera (the default one is used)", "no lights", "no objects"};
	size_t n = which == 0 ? s->ncams : which == 1 ? s->nlights : s->nobjs;
	if (n == 0)
		shell_out(sh, "%s\n", none[which]);
	for (size_t i = 0; i < n; i++) {
		char line[1024], note[48] = "";
		if (which == 0) {
			rt_format_camera(&s->cams[i], line, sizeof line);
		} else if (which == 1) {
			rt_format_light(&s->lights[i], line, sizeof line);
		} else {
			const object *o = &s->objs[i];
			rt_format_object(o, line, sizeof line);
			/* a mesh: its triangle count (the model is cached, so this is cheap) */
			mesh *m = o->kind == OBJ_MESH && o->file ? mesh_cache_get(o->file, o->smooth != 0, o->crease, NULL, NULL)
			                                         : NULL;
			if (m)
				snprintf(note, sizeof note, "  # %u triangle%s", m->ntris, m->ntris == 1 ? "" : "s");
			mesh_cache_put(m);
		}
		shell_out(sh, "%s %zu%s: %s%s\n", name[which], i + 1, which == 0 && i == s->cam ? " (active)" : "", line,
		          note);
	}
}

bool cmd_list(shell *sh, int argc, char **argv, const char *rest)
{
	(void)rest;
	const scene *s = editor_scene(sh->ed);
	int which = -1;
	if (argc == 1) {
		which = choice_pick("cameras|lights|objects", argv[0]);
		char near[32];
		if (which < 0 && suggest_choice("cameras|lights|objects", argv[0], near, sizeof near))
			return shell_fail(sh, "list: \"%s\" is not a list; did you mean \"%s\"?", argv[0], near);
		if (which < 0)
			return shell_fail(sh, "list: \"%s\" is not a list; expected cameras, lights or objects",
			                  argv[0]);
	}
	if (which < 0 || which == 0)
		list_items(sh, s, 0);
	if (which < 0) {
		if (s->has_ambient)
			shell_out(sh, "ambient: A %g %g,%g,%g\n", s->amb.ratio, s->amb.color.x, s->amb.color.y,
			          s->amb.color.z);
		else
			shell_out(sh, "ambient: none\n");
		if (s->has_sky)
			shell_out(sh, "sky: %g,%g,%g %g,%g,%g %g\n", s->sky.zenith.x, s->sky.zenith.y,
			          s->sky.zenith.z, s->sky.horizon.x, s->sky.horizon.y, s->sky.horizon.z,
			          s->sky.strength);
	}
	if (which < 0 || which == 1)
		list_items(sh, s, 1);
	if (which < 0 || which == 2)
		list_items(sh, s, 2);
	return true;
}

bool cmd_generate(shell *sh, int argc, char **argv, const char *rest)
{
	(void)rest;
	long n;
	if (!arg_int(sh, "generate", argv[0], 1, GENERATE_MAX, &n))
		return false;
	uint64_t seed;
	if (argc == 2) {
		unsigned long long v;
		if (num_scan_u64(argv[1], &v) != NUM_OK) /* num.h */
			return shell_fail(sh, "generate: \"%s\" is not a seed; expected a whole number >= 0", argv[1]);
		seed = v;
	} else {
		struct timespec t;
		clock_gettime(CLOCK_REALTIME, &t);
		seed = ((uint64_t)t.tv_sec * 1000003u ^ (uint64_t)t.tv_nsec) % 1000000;
	}
	rt_error err;
	atomic_store(&sh->cancel, false);
	scene *s = scene_generate((size_t)n, seed, &(gen_opts){.cancel = &sh->cancel}, &err);
	if (!s && atomic_load(&sh->cancel)) {
		shell_sig_int = 0; /* the Ctrl-C is used up */
		return shell_fail(sh, "generate: stopped; the scene is as it was");
	}
	if (!s)
		return shell_fail(sh, "generate: %s", err.msg);
	char label[96];
	snprintf(label, sizeof label, "generate:%ld:%" PRIu64, n, seed);
	render_settings before = sh->set;
	if (!shell_replace_scene(sh, s, label))
		return false;
	shell_info(sh, "generated %ld object%s with seed %" PRIu64 "\n", n, n == 1 ? "" : "s", seed);
	answer_setting_changes(sh, &before);
	return true;
}

bool cmd_show(shell *sh, int argc, char **argv, const char *rest)
{
	(void)rest;
	long cols = sh->capture && sh->scr ? sh->scr->cols : picture_columns();
	if (argc == 1 && !arg_int(sh, "show", argv[0], 8, 1000, &cols))
		return false;
	frame *f = shell_picture_frame(sh, sh->pal, (int)cols);
	if (!f)
		return sh->err[0] ? false : shell_fail(sh, "show: no picture");
	abuf a;
	abuf_init(&a);
	frame_text(f, &a);
	bool ok = !a.failed;
	if (ok && sh->capture) {
		/* On the full screen: through the pager, like help and list, when
		 * it is taller than the command area. */
		abuf_add(sh->capture, a.b, a.len);
	} else if (ok) {
		fflush(stdout);
		ok = write_all(1, a.b, a.len);
	}
	abuf_free(&a);
	frame_free(f);
	return ok ? true : shell_fail(sh, "show: cannot write the picture");
}

bool cmd_source(shell *sh, int argc, char **argv, const char *rest)
{
	(void)argc, (void)rest;
	if (sh->depth >= 16)
		return shell_fail(sh, "source: files nest more than 16 deep; expected no loop of source commands");
	char *path = shell_expand_path(argv[0]);
	if (!path)
		return shell_fail(sh, "out of memory");
	sh->depth++;
	bool ok = shell_run_file(sh, path);
	sh->depth--;
	if (ok)
		shell_info(sh, "ran %s\n", path);
	free(path);
	return ok;
}

/* Key mode (keymode.c). */
bool cmd_view(shell *sh, int argc, char **argv, const char *rest)
{
	(void)argc, (void)argv, (void)rest;
	return keymode_run(sh);
}

/* Key mode with the turntable on (keymode.c). */
bool cmd_turntable(shell *sh, int argc, char **argv, const char *rest)
{
	(void)rest;
	double seconds = KEYMODE_SPIN_SECONDS;
	if (argc == 1 && !arg_number(sh, "turntable", argv[0], 0.5, 3600, &seconds))
		return false;
	return keymode_turntable(sh, seconds);
}
