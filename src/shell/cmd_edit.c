/* rtsh — commands that edit the scene: camera, light, object, ambient, add,
 * delete, undo, redo. Each parses its arguments, then makes one editor call
 * between shell_edit_begin and shell_edit_end. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rtsh/edit.h"
#include "rtsh/num.h"
#include "rtsh/rtfile.h"
#include "shell/answer.h"
#include "shell/commands.h"
#include "shell/suggest.h"

#define SUBS_CAMERA "pos|dir|lookat|fov|move|turn"
#define SUBS_LIGHT "pos|move|brightness|color"
#define SUBS_OBJECT "move|rotate|scale|color|set"

/* The subcommand `word` among choices, or a message naming them. */
static int pick_sub(shell *sh, const char *cmd, const char *kind, const char *choices, const char *word)
{
	int i = choice_pick(choices, word);
	if (i < 0) {
		char list[256];
		char near[64];
		choice_list(choices, list, sizeof list);
		if (suggest_choice(choices, word, near, sizeof near))
			shell_fail(sh, "%s: \"%s\" is not %s; did you mean \"%s\"? (expected %s)", cmd, word,
			           kind, near, list);
		else
			shell_fail(sh, "%s: \"%s\" is not %s; expected %s", cmd, word, kind, list);
	}
	return i;
}

/* Runs an editor call, reporting its error as "WHAT: message". */
#define EDIT(sh, what, call)                                             \
	do {                                                             \
		rt_error err_;                                           \
		shell_edit_begin(sh);                                    \
		bool ok_ = (call);                                       \
		shell_edit_end(sh);                                      \
		if (!ok_)                                                \
			return shell_fail(sh, "%s: %s", what, err_.msg); \
		return true;                                             \
	} while (0)

/* An edit of item i by a vector: `v` read as hint says ("X,Y,Z"; NULL: a
 * colour R,G,B), then the editor's call. */
typedef bool (*vec_edit)(editor *ed, size_t i, vec3 v, rt_error *err);
static bool edit_vec(shell *sh, const char *what, size_t i, const char *v, const char *hint, vec_edit call)
{
	vec3 p;
	if (hint ? !arg_vec(sh, what, v, hint, &p) : !arg_color(sh, what, v, &p))
		return false;
	EDIT(sh, what, call(sh->ed, i, p, &err_));
}

static bool need_value(shell *sh, const char *what, const char *usage, int argc, int want)
{
	if (argc != want)
		return shell_fail(sh, "%s: %s; usage: %s", what, argc < want ? "too few arguments" : "too many arguments",
		                  usage);
	return true;
}

bool cmd_camera(shell *sh, int argc, char **argv, const char *rest)
{
	(void)rest;
	const scene *s = editor_scene(sh->ed);
	if (argc == 0) {
		answer_camera_fields(sh, s->cam < s->ncams ? s->cam : 0);
		return true;
	}
	if (argc > 1 && argv[0][0] >= '0' && argv[0][0] <= '9') /* it said "2" is not a camera command */
		return shell_fail(sh, "camera: too many arguments; usage: camera N (N alone makes camera N active)");
	if (argc == 1 && argv[0][0] >= '0' && argv[0][0] <= '9') {
		size_t i;
		if (!arg_index(sh, "camera", argv[0], "camera", s->ncams, &i))
			return false;
		EDIT(sh, "camera", editor_select_camera(sh->ed, i, &err_));
	}
	int sub = pick_sub(sh, "camera", "a camera command", SUBS_CAMERA, argv[0]);
	if (sub < 0)
		return false;
	static const char *const names[] = {"pos", "dir", "lookat", "fov", "move", "turn"};
	static const char *const forms[] = {"X,Y,Z", "X,Y,Z", "X,Y,Z", "DEG", "DX,DY,DZ", "YAW,PITCH"};
	char what[32], usage[64];
	snprintf(what, sizeof what, "camera %s", names[sub]);
	snprintf(usage, sizeof usage, "camera %s %s", names[sub], forms[sub]);
	if (!need_value(sh, what, usage, argc - 1, 1))
		return false;
	const char *v = argv[1];
	vec3 p;
	double d;
	switch (sub) {
	case 0:
		if (!arg_vec(sh, what, v, "X,Y,Z", &p))
			return false;
		EDIT(sh, what, editor_camera_pos(sh->ed, p, &err_));
	case 1:
		if (!arg_vec(sh, what, v, "X,Y,Z (not all zero)", &p))
			return false;
		EDIT(sh, what, editor_camera_dir(sh->ed, p, &err_));
	case 2:
		if (!arg_vec(sh, what, v, "X,Y,Z", &p))
			return false;
		EDIT(sh, what, editor_camera_lookat(sh->ed, p, &err_));
	case 3:
		if (!parse_number(v, &d)) /* the range is the editor's, as in files (rules.h) */
			return shell_fail(sh, "%s: \"%s\" is not a field of view; expected degrees in [0,180]",
			                  what, v);
		EDIT(sh, what, editor_camera_fov(sh->ed, d, &err_));
	case 4:
		if (!arg_vec(sh, what, v, "DX,DY,DZ", &p))
			return false;
		EDIT(sh, what, editor_camera_move(sh->ed, p, &err_));
	default: {
		double yp[2];
		char buf[128];
		char *comma = strchr(v, ',');
		if (strlen(v) >= sizeof buf || !comma || strchr(comma + 1, ','))
			return shell_fail(sh, "%s: \"%s\" is not a turn; expected YAW,PITCH in degrees", what, v);
		snprintf(buf, sizeof buf, "%s", v);
		buf[comma - v] = '\0';
		if (!parse_number(buf, &yp[0]) || !parse_number(buf + (comma - v) + 1, &yp[1]))
			return shell_fail(sh, "%s: \"%s\" is not a turn; expected YAW,PITCH in degrees", what, v);
		uint64_t gen = editor_generation(sh->ed);
		rt_error err;
		shell_edit_begin(sh);
		bool ok = editor_camera_turn(sh->ed, yp[0], yp[1], &err);
		shell_edit_end(sh);
		if (!ok)
			return shell_fail(sh, "%s: %s", what, err.msg);
		if (editor_generation(sh->ed) == gen && yp[1] != 0) /* nothing turned: say why */
			shell_info(sh, "%s: already %g degrees %s, the most it tilts; a %s pitch turns it back\n", what,
			           EDIT_PITCH_LIMIT, yp[1] > 0 ? "up" : "down", yp[1] > 0 ? "negative" : "positive");
		return true;
	}
	}
}

/* What `light N ...` and `object N ...` share. */
typedef struct item_cmd {
	const char *name, *list; /* "light", "lights" (the `list` subject) */
	const char *kind, *usage, *subs;
	const char *const *names; /* the subcommands in `subs` order */
	void (*fields)(shell *sh, size_t i);
} item_cmd;

/* No N lists the items; N alone shows its fields; otherwise the index in *i,
 * `what` ("light pos") and the subcommand's number are found. Returns the
 * subcommand, or -1 when the command is over with *result. */
static int item_sub(shell *sh, const item_cmd *c, size_t count, int argc, char **argv, size_t *i, char *what,
                    size_t wsize, bool *result)
{
	*result = false;
	if (argc == 0) {
		char *a[] = {(char *)c->list};
		*result = cmd_list(sh, 1, a, "");
		return -1;
	}
	if (!arg_index(sh, c->name, argv[0], c->name, count, i))
		return -1;
	if (argc == 1) {
		c->fields(sh, *i);
		*result = true;
		return -1;
	}
	if (argc < 3) {
		shell_fail(sh, "%s: too few arguments; usage: %s", c->name, c->usage);
		return -1;
	}
	int sub = pick_sub(sh, c->name, c->kind, c->subs, argv[1]);
	if (sub >= 0)
		snprintf(what, wsize, "%s %s", c->name, c->names[sub]);
	return sub;
}

bool cmd_light(shell *sh, int argc, char **argv, const char *rest)
{
	(void)rest;
	static const char *const names[] = {"pos", "move", "brightness", "color"};
	static const item_cmd c = {"light", "lights", "a light command", "light N pos|move|brightness|color VALUE",
	                           SUBS_LIGHT, names, answer_light_fields};
	size_t i;
	char what[32];
	bool result;
	int sub = item_sub(sh, &c, editor_scene(sh->ed)->nlights, argc, argv, &i, what, sizeof what, &result);
	if (sub < 0)
		return result;
	const char *v = argv[2];
	double d;
	switch (sub) {
	case 0:
		return edit_vec(sh, what, i, v, "X,Y,Z", editor_light_pos);
	case 1:
		return edit_vec(sh, what, i, v, "DX,DY,DZ", editor_light_move);
	case 2:
		if (!arg_number(sh, what, v, 0, 1, &d))
			return false;
		EDIT(sh, what, editor_light_brightness(sh->ed, i, d, &err_));
	default:
		return edit_vec(sh, what, i, v, NULL, editor_light_color);
	}
}

bool cmd_object(shell *sh, int argc, char **argv, const char *rest)
{
	(void)rest;
	static const char *const names[] = {"move", "rotate", "scale", "color", "set"};
	static const item_cmd c = {"object", "objects", "an object command",
	                           "object N move|rotate|scale|color VALUE | object N set KEY=VALUE",
	                           SUBS_OBJECT, names, answer_object_fields};
	size_t i;
	char what[32];
	bool result;
	int sub = item_sub(sh, &c, editor_scene(sh->ed)->nobjs, argc, argv, &i, what, sizeof what, &result);
	if (sub < 0)
		return result;
	if (sub == 4) /* KEY=VALUE, from the reader's table of keys (rtfile.h) */
		EDIT(sh, what, editor_object_set_key(sh->ed, i, argv[2], &err_));
	const char *v = argv[2];
	vec3 p;
	switch (sub) {
	case 0:
		return edit_vec(sh, what, i, v, "DX,DY,DZ", editor_object_move);
	case 1:
		return edit_vec(sh, what, i, v, "RX,RY,RZ in degrees", editor_object_rotate);
	case 2:
		if (!arg_vec(sh, what, v, "SX,SY,SZ (factors > 0)", &p))
			return false;
		if (!(p.x > 0 && p.y > 0 && p.z > 0))
			return shell_fail(sh, "%s: %s has a factor <= 0; expected SX,SY,SZ with each > 0", what, v);
		EDIT(sh, what, editor_object_scale(sh->ed, i, p, &err_));
	default:
		return edit_vec(sh, what, i, v, NULL, editor_object_color);
	}
}

bool cmd_ambient(shell *sh, int argc, char **argv, const char *rest)
{
	(void)rest;
	const scene *s = editor_scene(sh->ed);
	ambient a = s->has_ambient ? s->amb : (ambient){0.0, v3(255, 255, 255)};
	if (argc == 0) {
		if (s->has_ambient)
			shell_out(sh, "ambient: A %g %g,%g,%g\n", a.ratio, a.color.x, a.color.y, a.color.z);
		else
			shell_out(sh, "ambient: none\n");
		return true;
	}
	int sub = pick_sub(sh, "ambient", "an ambient command", "brightness|color", argv[0]);
	if (sub < 0)
		return false;
	const char *what = sub == 0 ? "ambient brightness" : "ambient color";
	if (!need_value(sh, what, sub == 0 ? "ambient brightness B" : "ambient color R,G,B", argc - 1, 1))
		return false;
	if (sub == 0) {
		if (!arg_number(sh, what, argv[1], 0, 1, &a.ratio))
			return false;
	} else if (!arg_color(sh, what, argv[1], &a.color)) {
		return false;
	}
	EDIT(sh, what, editor_set_ambient(sh->ed, &a, &err_));
}

bool cmd_add(shell *sh, int argc, char **argv, const char *rest)
{
	(void)argc, (void)argv;
	rt_error err;
	const scene *s = editor_scene(sh->ed);
	size_t nobjs = s->nobjs, nlights = s->nlights, ncams = s->ncams;
	shell_edit_begin(sh);
	bool ok = editor_add_line(sh->ed, rest, "add", 0, &sh->load_opts, &err);
	shell_edit_end(sh);
	if (!ok) {
		/* The parser's column counts from the start of LINE. */
		if (err.col > 0)
			return shell_fail(sh, "add: column %d: %s", err.col, err.msg);
		return shell_fail(sh, "add: %s", err.msg);
	}
	s = editor_scene(sh->ed);
	if (s->nobjs > nobjs)
		shell_info(sh, "added object %zu (%s)\n", s->nobjs, obj_kind_name(s->objs[s->nobjs - 1].kind));
	else if (s->nlights > nlights)
		shell_info(sh, "added light %zu\n", s->nlights);
	else if (s->ncams > ncams)
		shell_info(sh, "added camera %zu\n", s->ncams);
	else
		shell_info(sh, "replaced: %s\n", rest);
	return true;
}

bool cmd_delete(shell *sh, int argc, char **argv, const char *rest)
{
	(void)rest;
	static const char usage[] = "usage: delete object N | delete light N | delete camera N";
	const scene *s = editor_scene(sh->ed);
	if (argc == 1 && argv[0][0] >= '0' && argv[0][0] <= '9')
		return shell_fail(sh, "delete: object or light? %s", usage);
	int kind = pick_sub(sh, "delete", "something to delete", "object|light|camera", argv[0]);
	if (kind < 0)
		return false;
	static const char *const kinds[] = {"object", "light", "camera"};
	size_t n = kind == 0 ? s->nobjs : kind == 1 ? s->nlights : s->ncams, i;
	if (argc == 1)
		return shell_fail(sh, "delete: which %s? expected delete %s N with N in 1..%zu", kinds[kind],
		                  kinds[kind], n);
	if (!arg_index(sh, "delete", argv[1], kinds[kind], n, &i))
		return false;
	char what[80] = "";
	if (kind == 0)
		snprintf(what, sizeof what, " (%s)", obj_kind_name(s->objs[i].kind));
	rt_error err;
	shell_edit_begin(sh);
	bool ok = kind == 0   ? editor_delete_object(sh->ed, i, &err)
	          : kind == 1 ? editor_delete_light(sh->ed, i, &err)
	                      : editor_delete_camera(sh->ed, i, &err);
	shell_edit_end(sh);
	if (!ok)
		return shell_fail(sh, "delete: %s", err.msg);
	shell_info(sh, "deleted %s %zu%s\n", kinds[kind], i + 1, what);
	return true;
}

/* Undo or redo one step, saying which. */
static bool undo_redo(shell *sh, bool redo)
{
	const char *note = redo ? editor_redo_note(sh->ed) : editor_undo_note(sh->ed);
	char *copy = note ? strdup(note) : NULL;
	render_settings before = sh->set;
	rt_error err;
	shell_edit_begin(sh);
	bool ok = redo ? editor_redo(sh->ed, &err) : editor_undo(sh->ed, &err);
	shell_edit_end(sh);
	if (ok) {
		answer_undo(sh, redo ? "redone" : "undone", copy);
		answer_setting_changes(sh, &before);
	}
	free(copy);
	return ok ? true : shell_fail(sh, "%s: %s", redo ? "redo" : "undo", err.msg);
}

/* undo [N] / redo [N]: N steps (1 without N); all of them or, when fewer
 * are there, none. */
static bool undo_redo_n(shell *sh, bool redo, int argc, char **argv)
{
	const char *what = redo ? "redo" : "undo";
	long n = 1;
	if (argc == 1 && num_scan_long(argv[0], 1, EDITOR_MAX_UNDO, &n) != NUM_OK)
		return shell_fail(sh, "%s: \"%s\" is not a number of steps; expected 1..%d", what, argv[0],
		                  EDITOR_MAX_UNDO);
	size_t have = redo ? editor_redo_count(sh->ed) : editor_undo_count(sh->ed);
	if (have > 0 && (size_t)n > have)
		return shell_fail(sh, "%s: %ld steps asked, %zu to %s; expected %s 1..%zu", what, n, have, what,
		                  what, have);
	for (long i = 0; i < n; i++)
		if (!undo_redo(sh, redo))
			return false;
	return true;
}

bool cmd_undo(shell *sh, int argc, char **argv, const char *rest)
{
	(void)rest;
	return undo_redo_n(sh, false, argc, argv);
}

bool cmd_redo(shell *sh, int argc, char **argv, const char *rest)
{
	(void)rest;
	return undo_redo_n(sh, true, argc, argv);
}
