/* rtsh — key mode's keys (keymode.h): the key table, the help texts it
 * generates (`help view` and the help bar), and the edits keys make (pure
 * functions of the key, the scene and the selection, unit-tested without a
 * terminal). */
#include "shell/keymode.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "rtsh/orbit.h"
#include "rtsh/shape.h"
#include "base/abuf.h"
#include "term/keys.h"

/* The key table. Each row is one line of `help view` (and of rtsh(1), KEY
 * MODE, where tests/unit/test_keymode.c checks that every row's keys are
 * named); a row may also be a part of the help bar. */
const km_keyrow keymode_keys[] = {
	{"Up Down, w s", "move forward, back (the camera flies where it looks; a selected\n"
	                 "object or light moves level with the floor)",
	 "←↑↓→ wasd", "move", 2,
	 {{KEYS_UP, KM_MOVE, 1}, {'w', KM_MOVE, 1}, {'W', KM_MOVE, 1},
	  {KEYS_DOWN, KM_MOVE, -1}, {'s', KM_MOVE, -1}, {'S', KM_MOVE, -1}}},
	{"Left Right, a d", "move left, right (along the camera's right)", NULL, NULL, 0,
	 {{KEYS_LEFT, KM_MOVE, -2}, {'a', KM_MOVE, -2}, {'A', KM_MOVE, -2},
	  {KEYS_RIGHT, KM_MOVE, 2}, {'d', KM_MOVE, 2}, {'D', KM_MOVE, 2}}},
	{"r f", "move up, down", "r f", "up/down", 3,
	 {{'r', KM_MOVE, 3}, {'R', KM_MOVE, 3}, {'f', KM_MOVE, -3}, {'F', KM_MOVE, -3}}},
	{"i k, Shift+Up Shift+Down", "pitch the camera up, down by 3 degrees", "ijkl ⇧←↑↓→", "turn", 4,
	 {{'i', KM_TURN, 2}, {'I', KM_TURN, 2}, {KEYS_SHIFT_UP, KM_TURN, 2},
	  {'k', KM_TURN, -2}, {'K', KM_TURN, -2}, {KEYS_SHIFT_DOWN, KM_TURN, -2}}},
	{"j l, Shift+Left Shift+Right", "turn the camera left, right by 3 degrees", NULL, NULL, 0,
	 {{'j', KM_TURN, -1}, {'J', KM_TURN, -1}, {KEYS_SHIFT_LEFT, KM_TURN, -1},
	  {'l', KM_TURN, 1}, {'L', KM_TURN, 1}, {KEYS_SHIFT_RIGHT, KM_TURN, 1}}},
	{"Tab, Shift+Tab", "select the next / previous object or light, then the camera", "Tab", "select", 5,
	 {{'\t', KM_SELECT, 1}, {KEYS_BACKTAB, KM_SELECT, -1}}},
	{"[ ]", "turn the selected object about the vertical by 15 degrees", "[ ] { }", "rotate", 6,
	 {{'[', KM_ROTATE, 1}, {']', KM_ROTATE, -1}}},
	{"{ }", "roll it about the line of sight by 15 degrees", NULL, NULL, 0,
	 {{'{', KM_ROTATE, 2}, {'}', KM_ROTATE, -2}}},
	{"- +", "shrink / grow it (x1.1); a light: dimmer / brighter;\n"
	        "the camera: zoom out / in (field of view; orthographic: height)",
	 "- +", "size", 7,
	 {{'-', KM_SCALE, -1}, {'_', KM_SCALE, -1}, {'+', KM_SCALE, 1}, {'=', KM_SCALE, 1}}},
	{", .", "halve / double the samples per pixel", ", .", "spp", 10,
	 {{',', KM_SAMPLES, -1}, {'.', KM_SAMPLES, 1}}},
	{"< >", "depth one less / one more", "< >", "depth", 11, {{'<', KM_DEPTH, -1}, {'>', KM_DEPTH, 1}}},
	{"PgUp PgDn", "the previous / next .rt file of the scene's folder", "PgUp PgDn", "scene", 12,
	 {{KEYS_PAGE_UP, KM_SCENE, -1}, {KEYS_PAGE_DOWN, KM_SCENE, 1}}},
	{"m", "switch between whitted and path mode", "m", "mode", 9, {{'m', KM_MODE, 0}, {'M', KM_MODE, 0}}},
	{"Space", "stop the render in progress", "Space", "stop", 13, {{' ', KM_STOP, 0}}},
	{"u U", "undo / redo (a run of the same key is one step)", "u", "undo", 8,
	 {{'u', KM_UNDO, 0}, {'U', KM_REDO, 0}}},
	{"? F1", "hide / show the help bar", "?", "hide this", 14, {{'?', KM_HELP, 0}, {KEYS_F(1), KM_HELP, 0}}},
	{"Ctrl-L F5", "repaint", NULL, NULL, 0, {{12, KM_REDRAW, 0}, {KEYS_F(5), KM_REDRAW, 0}}},
	{"0", "reset the view: the camera as key mode began", NULL, NULL, 0, {{'0', KM_HOME, 0}}},
	{"f (model viewer)", "frame the selection (the whole model when the camera is selected);\n"
	                     "in the model viewer the arrows orbit (Shift+arrows fly), F moves down",
	 NULL, NULL, 0, {{0, KM_NONE, 0}}},
	{"Esc q", "back to the shell; every change stays (undo, save x.rt)", "Esc", "back", 1,
	 {{KEYS_ESC, KM_QUIT, 0}, {'q', KM_QUIT, 0}, {'Q', KM_QUIT, 0}}},
};
const size_t keymode_nkeys = sizeof keymode_keys / sizeof keymode_keys[0];

/* The column the help's descriptions start at. */
#define HELP_COLUMN 31

const char *keymode_help_text(void)
{
	static char text[4096];
	if (text[0])
		return text;
	abuf a;
	abuf_init(&a);
	abuf_str(&a, "keys in view (key mode; letters in either case but u and U, and f and F in the model viewer):\n");
	for (size_t i = 0; i < keymode_nkeys; i++) {
		const km_keyrow *r = &keymode_keys[i];
		abuf_printf(&a, "  %-*s", HELP_COLUMN - 2, r->names);
		/* Each line of the description at the column. */
		for (const char *p = r->what; *p;) {
			size_t n = strcspn(p, "\n");
			abuf_add(&a, p, n);
			abuf_char(&a, '\n');
			p += n;
			if (*p == '\n') {
				p++;
				abuf_printf(&a, "%*s", HELP_COLUMN, "");
			}
		}
	}
	abuf_str(&a, "a movement key moves by 1/40 of the size of the scene (the box around the objects\n"
	             "but planes, the lights and the camera); see KEY MODE in rtsh(1)\n");
	snprintf(text, sizeof text, "%s", a.failed ? "" : a.b);
	abuf_free(&a);
	return text;
}

size_t keymode_help_bar(keyview_item *items, size_t max)
{
	size_t n = 0;
	for (int rank = 1; n < max; rank++) {
		bool found = false, more = false;
		for (size_t i = 0; i < keymode_nkeys; i++) {
			const km_keyrow *r = &keymode_keys[i];
			if (r->bar_rank == rank && n < max) {
				items[n++] = (keyview_item){r->bar_keys, r->bar_what};
				found = true;
			}
			more |= r->bar_rank > rank;
		}
		if (!found && !more)
			break;
	}
	return n;
}

size_t keymode_help_bar_model(keyview_item *items, size_t max)
{
	size_t n = keymode_help_bar(items, max);
	for (size_t i = 0; i < n; i++)
		if (strcmp(items[i].what, "move") == 0)
			items[i] = (keyview_item){"←↑↓→", "orbit  wasd move  f frame"};
		else if (strcmp(items[i].what, "up/down") == 0) /* f frames here: F is down */
			items[i] = (keyview_item){"r F", "up/down"};
	return n;
}

/* The row and entry of a key; NULL when no key of the table. */
static const km_key *find_key(int key)
{
	for (size_t i = 0; i < keymode_nkeys; i++)
		for (const km_key *k = keymode_keys[i].keys; k->op != KM_NONE; k++)
			if (k->key == key)
				return k;
	return NULL;
}

double keymode_step(const scene *s)
{
	camera c = scene_camera(s);
	box b = box_union(box_point(c.pos), orbit_scene_bounds(s));
	for (size_t i = 0; i < s->nlights; i++)
		b = box_add(b, s->lights[i].pos);
	double side = v3_max_comp(v3_sub(b.hi, b.lo));
	if (!(side > 0) || !isfinite(side))
		side = 1.0;
	return side * KEYMODE_STEP_FRACTION;
}

bool keymode_sel_valid(const scene *s, km_sel sel)
{
	switch (sel.kind) {
	case KM_SEL_OBJECT:
		return sel.index < s->nobjs;
	case KM_SEL_LIGHT:
		return sel.index < s->nlights;
	case KM_SEL_CAMERA:
		break;
	}
	return true;
}

km_sel keymode_select(const scene *s, km_sel sel, int dir)
{
	size_t total = 1 + s->nobjs + s->nlights, at = 0;
	if (sel.kind == KM_SEL_OBJECT && sel.index < s->nobjs)
		at = 1 + sel.index;
	else if (sel.kind == KM_SEL_LIGHT && sel.index < s->nlights)
		at = 1 + s->nobjs + sel.index;
	at = dir >= 0 ? (at + 1) % total : (at + total - 1) % total;
	if (at == 0)
		return (km_sel){KM_SEL_CAMERA, 0};
	if (at <= s->nobjs)
		return (km_sel){KM_SEL_OBJECT, at - 1};
	return (km_sel){KM_SEL_LIGHT, at - 1 - s->nobjs};
}

vec3 keymode_axis_euler(vec3 axis, double deg)
{
	mat4 r = m4_rotate_axis(v3_norm(axis), deg_to_rad(deg));
	/* r = Rz(c) Ry(b) Rx(a): r[2][0] = -sin b, r[2][1] = cos b sin a,
	 * r[2][2] = cos b cos a, r[1][0] = sin c cos b, r[0][0] = cos c cos b. */
	double sb = clampd(-r.m[2][0], -1.0, 1.0);
	double a, b = asin(sb), c;
	if (fabs(sb) < 0.9999999) {
		a = atan2(r.m[2][1], r.m[2][2]);
		c = atan2(r.m[1][0], r.m[0][0]);
	} else {
		/* Gimbal lock: only a - c (or a + c) is defined; put it all in a. */
		c = 0.0;
		a = atan2(-r.m[1][2], r.m[1][1]);
	}
	return v3(rad_to_deg(a), rad_to_deg(b), rad_to_deg(c));
}

static km_action act(km_op op, km_sel sel)
{
	km_action a;
	memset(&a, 0, sizeof a);
	a.op = op;
	a.sel = sel;
	return a;
}

km_action keymode_map(int key, const scene *s, km_sel sel, double step)
{
	const km_key *k = find_key(key);
	if (!k)
		return act(KM_NONE, sel);
	int arg = k->arg, axis = arg < 0 ? -arg : arg;
	double sign = arg < 0 ? -1.0 : 1.0;
	camera c = scene_camera(s);
	cam_view v = cam_view_make(&c);
	km_action a = act(k->op, sel);
	switch (k->op) {
	case KM_MOVE: {
		vec3 fwd = v.fwd;
		if (sel.kind != KM_SEL_CAMERA) {
			/* Objects and lights slide level with the floor. */
			vec3 flat = v3(v.fwd.x, 0, v.fwd.z);
			fwd = v3_len(flat) > 1e-6 ? v3_norm(flat) : v3_norm(v3(v.up.x, 0, v.up.z));
		}
		vec3 dir = axis == 1 ? fwd : axis == 2 ? v.right : v3(0, 1, 0);
		a.d = v3_scale(dir, sign * step);
		return a;
	}
	case KM_TURN: /* 1: yaw to the right; 2: pitch up */
		if (axis == 1)
			a.a = sign * KEYMODE_TURN_DEG;
		else
			a.b = sign * KEYMODE_TURN_DEG;
		return a;
	case KM_ROTATE:
		/* 1: [ turns the front to the left as the camera sees it; 2: {
		 * rolls counterclockwise on the screen. */
		a.d = axis == 1 ? v3(0, sign * KEYMODE_ROTATE_DEG, 0) : keymode_axis_euler(v.fwd, sign * KEYMODE_ROTATE_DEG);
		return a;
	case KM_SCALE:
		a.a = arg > 0 ? KEYMODE_SCALE : 1.0 / KEYMODE_SCALE;
		return a;
	case KM_SELECT:
		a.sel = keymode_select(s, sel, arg);
		a.n = arg;
		return a;
	case KM_SAMPLES:
	case KM_DEPTH:
	case KM_SCENE:
		a.n = arg;
		return a;
	default:
		return a;
	}
}

vec3 keymode_pivot(const scene *s, km_sel sel)
{
	if (sel.kind == KM_SEL_OBJECT && sel.index < s->nobjs && s->objs[sel.index].kind != OBJ_PLANE) {
		box b = object_bounds(&s->objs[sel.index]);
		if (!box_is_empty(b) && v3_finite(b.lo) && v3_finite(b.hi))
			return box_center(b);
	}
	if (sel.kind == KM_SEL_LIGHT && sel.index < s->nlights)
		return s->lights[sel.index].pos;
	return orbit_scene_centre(s);
}

km_action keymode_map_model(int key, const scene *s, km_sel sel, double step)
{
	double yaw = 0, pitch = 0;
	switch (key) {
	case KEYS_LEFT:
		yaw = KEYMODE_ORBIT_DEG;
		break;
	case KEYS_RIGHT:
		yaw = -KEYMODE_ORBIT_DEG;
		break;
	case KEYS_UP:
		pitch = -KEYMODE_ORBIT_DEG;
		break;
	case KEYS_DOWN:
		pitch = KEYMODE_ORBIT_DEG;
		break;
	case KEYS_SHIFT_UP:
		return keymode_map(KEYS_UP, s, sel, step);
	case KEYS_SHIFT_DOWN:
		return keymode_map(KEYS_DOWN, s, sel, step);
	case KEYS_SHIFT_LEFT:
		return keymode_map(KEYS_LEFT, s, sel, step);
	case KEYS_SHIFT_RIGHT:
		return keymode_map(KEYS_RIGHT, s, sel, step);
	case 'f':
		return act(KM_FRAME, sel);
	default:
		return keymode_map(key, s, sel, step);
	}
	km_action a = act(KM_ORBIT, sel);
	a.a = yaw;
	a.b = pitch;
	a.d = keymode_pivot(s, sel);
	return a;
}

bool keymode_is_edit(km_op op)
{
	return op == KM_MOVE || op == KM_TURN || op == KM_ROTATE || op == KM_SCALE || op == KM_ORBIT;
}

bool keymode_apply(editor *ed, const km_action *a, rt_error *err)
{
	const scene *s = editor_scene(ed);
	if (!keymode_sel_valid(s, a->sel))
		return rt_error_set(err, "the selection is gone; press Tab to select again");
	size_t i = a->sel.index;
	switch (a->op) {
	case KM_MOVE:
		if (a->sel.kind == KM_SEL_OBJECT)
			return editor_object_move(ed, i, a->d, err);
		if (a->sel.kind == KM_SEL_LIGHT)
			return editor_light_move(ed, i, a->d, err);
		return editor_camera_pos(ed, v3_add(scene_camera(s).pos, a->d), err);
	case KM_TURN:
		return editor_camera_turn(ed, a->a, a->b, err);
	case KM_ORBIT: {
		camera c = orbit_camera(scene_camera(s), a->d, a->a, a->b);
		return editor_set_camera(ed, s->cam, &c, err);
	}
	case KM_ROTATE:
		if (a->sel.kind != KM_SEL_OBJECT)
			return rt_error_set(err, "only objects rotate; press Tab to select one");
		return editor_object_rotate(ed, i, a->d, err);
	case KM_SCALE:
		if (a->sel.kind == KM_SEL_OBJECT)
			return editor_object_scale(ed, i, v3_splat(a->a), err);
		if (a->sel.kind == KM_SEL_LIGHT) {
			double r = s->lights[i].ratio + (a->a > 1 ? KEYMODE_BRIGHTNESS : -KEYMODE_BRIGHTNESS);
			r = clampd(round(r * 1000.0) / 1000.0, 0.0, 1.0);
			return r == s->lights[i].ratio ? true : editor_light_brightness(ed, i, r, err);
		} else if (scene_camera(s).ortho > 0) {
			/* an orthographic camera: its height, by the objects' factor */
			camera c = scene_camera(s);
			double h = c.ortho / a->a; /* + (1.1) shows less: zooms in */
			if (!(h >= 1e-6 && h <= 1e6))
				return true;
			c.ortho = h;
			return editor_set_camera(ed, s->cam, &c, err);
		} else {
			double fov = scene_camera(s).fov + (a->a > 1 ? -KEYMODE_FOV_DEG : KEYMODE_FOV_DEG);
			fov = clampd(fov, 5.0, 170.0);
			return fov == scene_camera(s).fov ? true : editor_camera_fov(ed, fov, err);
		}
	default:
		return rt_error_set(err, "not a scene edit");
	}
}

