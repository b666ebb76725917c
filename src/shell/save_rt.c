/* rtsh — `save FILE.rt` (save_rt.h). */
#include "shell/save_rt.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "rtsh/filesrc.h"
#include "rtsh/mesh.h"
#include "rtsh/rtkeep.h"
#include "rtsh/rtfile.h"
#include "rtsh/settings.h"
#include "shell/builtin_scene.h"

/* Sources larger than this are not kept (the scene is written afresh). */
#define KEEP_MAX ((size_t)256 << 20)

scene_hints save_rt_hints(const scene_hints *h, const render_settings *set)
{
	scene_hints out = *h;
	render_settings r = render_settings_default();
	render_settings_apply_hints(&r, h);
	if (r.width != set->width || r.height != set->height) {
		out.width = set->width;
		out.height = set->height;
	}
	if (r.samples != set->samples)
		out.samples = set->samples;
	if (r.depth != set->depth)
		out.depth = set->depth;
	if (r.mode != set->mode)
		out.mode = (int)set->mode;
	for (size_t i = 0; i < settings_count; i++) {
		const setting_def *def = &settings_table[i];
		char was[SCENE_KEPT_LEN], now[SCENE_KEPT_LEN];
		if (!settings_kept_slot(def))
			continue;
		settings_format(&r, def, was, sizeof was);
		settings_format(set, def, now, sizeof now);
		if (strcmp(was, now) != 0) {
			memset(out.kept[i], 0, sizeof out.kept[i]);
			snprintf(out.kept[i], sizeof out.kept[i], "%s", now);
		}
	}
	return out;
}

/* The file's text, or NULL when it cannot be read (or is too big). */
static char *read_source(const char *path, size_t *len)
{
	const char *kind;
	FILE *f = rt_file_open_regular(path, &kind); /* a FIFO would wait for a writer */
	if (!f)
		return NULL;
	struct stat st;
	if (fstat(fileno(f), &st) != 0 || !S_ISREG(st.st_mode) || (size_t)st.st_size > KEEP_MAX) {
		fclose(f);
		return NULL;
	}
	size_t cap = (size_t)st.st_size + 1;
	char *buf = malloc(cap);
	size_t n = buf ? fread(buf, 1, cap, f) : 0;
	bool whole = buf && n < cap && !ferror(f);
	fclose(f);
	if (!whole) {
		free(buf);
		return NULL;
	}
	*len = n;
	return buf;
}

bool save_rt(shell *sh, const char *path, rt_error *err)
{
	scene s = *editor_scene(sh->ed); /* shares the arrays: read only */
	s.hints = save_rt_hints(&s.hints, &sh->set);
	const char *label = editor_label(sh->ed);
	if (!label)
		return rt_save_keeping(&s, builtin_scene_text, builtin_scene_len, path, err);
	if (strncmp(label, "generate:", 9) == 0)
		return rt_save(&s, path, err);
	size_t len = 0;
	/* The model viewer's scene was made from the model: its text is made
	 * again (the comment, the lines in their order). */
	rt_error merr;
	char *src = mesh_format_known(label) ? rt_model_text(label, NULL, &len, &merr) : read_source(label, &len);
	rt_keep_source = label; /* its folder resolves model and texture names */
	bool ok = rt_save_keeping(&s, src, len, path, err);
	rt_keep_source = NULL;
	free(src);
	return ok;
}
