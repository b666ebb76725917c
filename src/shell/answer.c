/* rtsh — what a command says back (answer.h). */
#include "shell/answer.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rtsh/edit.h"
#include "rtsh/rtfile.h"
#include "rtsh/settings.h"

/* The 0-based element number that `rest` starts with ("3 move 1,0,0"). */
static bool leading_index(const char *rest, size_t n, size_t *out)
{
	char *end;
	unsigned long v = strtoul(rest, &end, 10);
	if (end == rest || v < 1 || v > n)
		return false;
	*out = (size_t)(v - 1);
	return true;
}

static void say_object(shell *sh, size_t i)
{
	const scene *s = editor_scene(sh->ed);
	char line[1024];
	rt_format_object(&s->objs[i], line, sizeof line);
	shell_info(sh, "object %zu: %s\n", i + 1, line);
}

static void say_light(shell *sh, size_t i)
{
	const scene *s = editor_scene(sh->ed);
	char line[512];
	rt_format_light(&s->lights[i], line, sizeof line);
	shell_info(sh, "light %zu: %s\n", i + 1, line);
}

static void say_camera(shell *sh, size_t i)
{
	const scene *s = editor_scene(sh->ed);
	char line[512];
	rt_format_camera(&s->cams[i], line, sizeof line);
	shell_info(sh, "camera %zu%s: %s\n", i + 1, s->ncams > 1 && i == s->cam ? " (active)" : "", line);
}

/* Whether c is the table's command `name`: the answers are keyed by name,
 * as help's details are, so this file needs none of the handlers. */
static bool is(const command *c, const char *name)
{
	return strcmp(c->name, name) == 0;
}

void answer_after_command(shell *sh, const command *c, const char *rest, uint64_t gen0)
{
	if (editor_generation(sh->ed) == gen0)
		return;
	/* source and view name nothing: their own commands (or keys) made the steps. */
	if (is(c, "undo") || is(c, "redo") || is(c, "source") || is(c, "view"))
		return;
	size_t n = strlen(c->name) + strlen(rest) + 2;
	char *note = malloc(n);
	if (note) {
		snprintf(note, n, "%s%s%s", c->name, *rest ? " " : "", rest);
		editor_note(sh->ed, note);
		free(note);
	}
	const scene *s = editor_scene(sh->ed);
	size_t i;
	if (is(c, "object") && leading_index(rest, s->nobjs, &i))
		say_object(sh, i);
	else if (is(c, "light") && leading_index(rest, s->nlights, &i))
		say_light(sh, i);
	else if (is(c, "camera") && s->ncams > 0)
		say_camera(sh, s->cam < s->ncams ? s->cam : 0);
	else if (is(c, "ambient") && s->has_ambient)
		shell_info(sh, "ambient: A %g %g,%g,%g\n", s->amb.ratio, s->amb.color.x, s->amb.color.y,
		           s->amb.color.z);
}

static void field_vec(shell *sh, const char *name, vec3 v)
{
	shell_out(sh, "  %-11s %.10g,%.10g,%.10g\n", name, v.x, v.y, v.z);
}

static void field_num(shell *sh, const char *name, double v)
{
	shell_out(sh, "  %-11s %.10g\n", name, v);
}

void answer_object_fields(shell *sh, size_t i)
{
	const scene *s = editor_scene(sh->ed);
	const object *o = &s->objs[i];
	char line[1024];
	rt_format_object(o, line, sizeof line);
	shell_out(sh, "object %zu: %s\n", i + 1, line);
	shell_out(sh, "  %-11s %s\n", "kind", obj_kind_name(o->kind));
	if (o->kind == OBJ_TRIANGLE) {
		field_vec(sh, "point 1", o->tri[0]);
		field_vec(sh, "point 2", o->tri[1]);
		field_vec(sh, "point 3", o->tri[2]);
	} else {
		field_vec(sh, "position", o->pos);
		field_vec(sh, "direction", o->dir);
		if (o->twist != 0)
			field_num(sh, "twist", o->twist);
		field_vec(sh, "scale", o->scale);
		bool sheared = false;
		for (int k = 0; k < 6; k++)
			sheared |= o->shear[k] != 0;
		if (sheared)
			shell_out(sh, "  %-11s %g,%g,%g,%g,%g,%g\n", "shear", o->shear[0], o->shear[1], o->shear[2],
			          o->shear[3], o->shear[4], o->shear[5]);
	}
	const material *m = &o->mat;
	field_vec(sh, "colour", m->color);
	shell_out(sh, "  %-11s diffuse %g, specular %g, shininess %g, reflective %g\n", "material", m->diffuse,
	          m->specular, m->shininess, m->reflective);
	/* The key=value extensions, as the line writes them (non-defaults only). */
	char keys[1024] = "";
	/* the fields split at blanks outside double quotes: a quoted file name
	 * with a blank stays whole (texture="my wood.png" was cut at the
	 * blank), and a quoted one with '=' in it is not a key */
	for (char *t = line; *t;) {
		while (*t == ' ')
			t++;
		char *end = t;
		for (bool quoted = false; *end && (quoted || *end != ' '); end++)
			if (*end == '"')
				quoted = !quoted;
		size_t n = (size_t)(end - t);
		char *eq = memchr(t, '=', n);
		if (n && t[0] != '"' && eq && (!memchr(t, '"', n) || memchr(t, '"', n) > (void *)eq)) {
			size_t l = strlen(keys);
			snprintf(keys + l, sizeof keys - l, "%s%.*s", l ? " " : "", (int)n, t);
		}
		t = end;
	}
	if (keys[0])
		shell_out(sh, "  %-11s %s\n", "extensions", keys);
}

void answer_light_fields(shell *sh, size_t i)
{
	const light *l = &editor_scene(sh->ed)->lights[i];
	char line[512];
	rt_format_light(l, line, sizeof line);
	shell_out(sh, "light %zu: %s\n", i + 1, line);
	field_vec(sh, "position", l->pos);
	field_num(sh, "brightness", l->ratio);
	field_vec(sh, "colour", l->color);
}

void answer_camera_fields(shell *sh, size_t i)
{
	const scene *s = editor_scene(sh->ed);
	const camera *c = &s->cams[i];
	char line[512];
	rt_format_camera(c, line, sizeof line);
	shell_out(sh, "camera %zu%s: %s\n", i + 1, i == s->cam ? " (active)" : "", line);
	field_vec(sh, "position", c->pos);
	field_vec(sh, "direction", c->dir);
	if (c->ortho > 0)
		field_num(sh, "ortho", c->ortho); /* the half height; its fov is unused */
	else
		field_num(sh, c->vertical ? "vertical fov" : "fov", c->fov);
	if (s->ncams > 1)
		shell_out(sh, "  (%zu cameras: camera N makes camera N active, list cameras shows them)\n",
		          s->ncams);
}

void answer_undo(shell *sh, const char *verb, const char *note)
{
	if (note)
		shell_info(sh, "%s: %s\n", verb, note);
	else
		shell_info(sh, "%s: edits made in key mode (view)\n", verb);
}

static const char *plural(size_t n)
{
	return n == 1 ? "" : "s";
}

void answer_loaded(shell *sh, const char *verb, const render_settings *before)
{
	const scene *s = editor_scene(sh->ed);
	const char *where = sh->label ? sh->label : sh->name;
	shell_info(sh, "%s %s: %zu object%s, %zu light%s, %zu camera%s\n", verb, where, s->nobjs,
	           plural(s->nobjs), s->nlights, plural(s->nlights), s->ncams, plural(s->ncams));
	answer_setting_changes(sh, before);
}

void answer_setting_changes(shell *sh, const render_settings *before)
{
	for (size_t i = 0; i < settings_count && i < sizeof sh->hand_set * 8; i++) {
		if (!(sh->hand_set & 1u << i))
			continue;
		char was[64], now[64];
		settings_format(before, &settings_table[i], was, sizeof was);
		settings_format(&sh->set, &settings_table[i], now, sizeof now);
		if (strcmp(was, now) != 0) {
			shell_info(sh, "%s %s -> %s (from %s)\n", settings_table[i].name, was, now, sh->name);
			sh->hand_set &= ~(1u << i); /* the value set by hand is gone */
		}
	}
}
