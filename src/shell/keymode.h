/* rtsh — key mode (`view`): fly through the scene with the keyboard.
 *
 * Key mode takes over the whole terminal the shell is on: the picture fills
 * it but for a status line and a help bar at the bottom. ncurses only reads
 * the keys (its output goes to /dev/null); the picture is drawn by the
 * shell's own frame encoder (term/frame.h), one write() per frame.
 *
 * Every key that changes the scene is one editor call (rtsh/edit.h), so
 * everything done in key mode stays in the shell's undo history; a run of
 * the same key (holding an arrow down) is one undo step.
 *
 * The step rule (documented in rtsh(1), KEY MODE): a movement key moves by
 * step = L / 40, where L is the longest side of the axis-aligned box around
 * the bounded objects (planes are left out), the lights and the camera,
 * measured when key mode starts and when the scene is replaced; L = 1 when
 * that box is a point. Turning keys turn the camera by 3 degrees; `[` `]`
 * `{` `}` rotate an object by 15 degrees; `-` `+` scale it by 1/1.1 and 1.1.
 *
 * While keys arrive, frames are rendered at a reduced resolution (a pixel
 * ratio picked from the measured cost of a pixel so that a frame takes at
 * most KEYMODE_FRAME_BUDGET) and scaled up by pixel replication; 150 ms
 * after the last key the picture is refined to the full resolution and, in
 * path mode, accumulates samples. A new key cancels the frame in flight.
 */
#ifndef RTSH_KEYMODE_H
#define RTSH_KEYMODE_H

#include <stdbool.h>
#include <stddef.h>

#include "rtsh/edit.h"
#include "rtsh/scene.h"
#include "shell/shell.h"
#include "term/keys.h"
#include "term/keyview.h"
#include "term/out.h"

/* The fraction of the scene's size one movement key moves by. */
#define KEYMODE_STEP_FRACTION (1.0 / 40.0)
/* Degrees per key: camera turns, object rotations. */
#define KEYMODE_TURN_DEG 3.0
#define KEYMODE_ROTATE_DEG 15.0
/* Object scale factor per key (and its inverse). */
#define KEYMODE_SCALE 1.1
/* Light brightness per key; camera field of view per key (degrees). */
#define KEYMODE_BRIGHTNESS 0.05
#define KEYMODE_FOV_DEG 5.0
/* The model viewer's arrow keys orbit the camera by this many degrees; a
 * mouse drag by KEYMODE_DRAG_DEG a pixel of the picture (a column is one
 * pixel across, a row two down: a Right arrow is a drag of two columns to
 * the right, an Up arrow a drag of one row up). The wheel moves the camera
 * a tenth of the way to what it turns about. */
#define KEYMODE_ORBIT_DEG 5.0
#define KEYMODE_DRAG_DEG 2.5
#define KEYMODE_DOLLY 0.1
/* Seconds a turn of `turntable` takes when not told. */
#define KEYMODE_SPIN_SECONDS 8.0
/* Seconds: the longest a frame may take while keys arrive; the quiet time
 * after the last key before the picture is refined. */
#define KEYMODE_FRAME_BUDGET 0.025
#define KEYMODE_IDLE 0.15
/* Edits with no pause this long (seconds) between them undo as one step. */
#define KEYMODE_STEP_PAUSE 1.0
/* Seconds: the length the refine's passes aim at (after a first of one
 * sample). */
#define KEYMODE_PASS_SECONDS 0.2

/* What the keys act on: the camera, or an object or a light (0-based). */
typedef enum km_sel_kind {
	KM_SEL_CAMERA,
	KM_SEL_OBJECT,
	KM_SEL_LIGHT,
} km_sel_kind;

typedef struct km_sel {
	km_sel_kind kind;
	size_t index;
} km_sel;

/* What a key does. */
typedef enum km_op {
	KM_NONE,       /* nothing */
	KM_MOVE,       /* move the selection by d (world space) */
	KM_TURN,       /* turn the camera: a = yaw degrees to the right, b = pitch degrees up */
	KM_ROTATE,     /* rotate the selected object by Euler angles d (degrees, about X, Y, Z) */
	KM_SCALE,      /* object: scale by a; light: brightness +- KEYMODE_BRIGHTNESS;
	                  camera: field of view -+ KEYMODE_FOV_DEG (a > 1 zooms in) */
	KM_SELECT,     /* n = +1 the next element, -1 the previous one */
	KM_SAMPLES,    /* n = +1 double the samples, -1 halve them */
	KM_DEPTH,      /* n = +1 / -1 */
	KM_SCENE,      /* n = +1 the next .rt file of the folder, -1 the previous one */
	KM_MODE,       /* whitted <-> path */
	KM_STOP,       /* stop the render in progress */
	KM_UNDO,
	KM_REDO,
	KM_REDRAW,     /* repaint the whole screen */
	KM_HELP,       /* show or hide the help bar */
	KM_QUIT,       /* back to the shell */
	KM_ORBIT,      /* orbit the camera about d: a = yaw, b = pitch degrees (orbit_camera) */
	KM_FRAME,      /* frame the selection (the whole scene when the camera is selected) */
	KM_HOME,       /* the camera as key mode began */
} km_op;

/* The key table (keymode_keys.c): each row is the keys of one line of
 * `help view`, each key with what it does; arg says which way:
 *   KM_MOVE    +-1 forward / back, +-2 right / left, +-3 up / down
 *   KM_TURN    +-1 yaw right / left, +-2 pitch up / down
 *   KM_ROTATE  +-1 about the vertical ([ ]), +-2 roll about the line of sight ({ })
 *   KM_SCALE, KM_SELECT, KM_SAMPLES, KM_DEPTH, KM_SCENE  +1 / -1
 * keymode_map, `help view` (keymode_help_text) and the help bar
 * (keymode_help_bar) are made from it. */
typedef struct km_key {
	int key;     /* a character or a KEYS_ code (term/keys.h) */
	km_op op;    /* KM_NONE ends a row's keys */
	int arg;
} km_key;

typedef struct km_keyrow {
	const char *names;     /* the keys as the help names them */
	const char *what;      /* what they do ("\n" breaks the line) */
	const char *bar_keys;  /* in the help bar (NULL: not) ... */
	const char *bar_what;
	int bar_rank;          /* ... at this place, from 1 */
	km_key keys[8];
} km_keyrow;

extern const km_keyrow keymode_keys[];
extern const size_t keymode_nkeys;

/* `help view`: the key table as text, one row a line. */
const char *keymode_help_text(void);
/* The help bar's items in their order (at most max); returns how many. */
size_t keymode_help_bar(keyview_item *items, size_t max);
/* The model viewer's help bar: the arrows orbit, f frames, F moves down. */
size_t keymode_help_bar_model(keyview_item *items, size_t max);

typedef struct km_action {
	km_op op;
	km_sel sel; /* what it acts on */
	vec3 d;
	double a, b;
	int n;
} km_action;

/* The movement step for scene s (the rule above). */
double keymode_step(const scene *s);
/* The selection dir (+1 / -1) places after sel in the order camera,
 * objects, lights, camera ... */
km_sel keymode_select(const scene *s, km_sel sel, int dir);
/* True when sel names an element of s (the camera always does). */
bool keymode_sel_valid(const scene *s, km_sel sel);
/* What `key` (a character or a KEYS_ code, term/keys.h) does with sel selected.
 * Movement is relative to the active camera: for the camera, forward is
 * where it looks; for objects and lights, forward is that direction made
 * horizontal; right is the camera's right; R/F go along world +Y. */
km_action keymode_map(int key, const scene *s, km_sel sel, double step);
/* The model viewer's keys (the scene is a model's, rtsh/rtfile.h): the
 * arrows orbit the camera about keymode_pivot (Right: the model turns to
 * the right, Up: its front tilts up), Shift+arrows fly as the arrows do
 * elsewhere, f frames the selection; every other key as keymode_map. */
km_action keymode_map_model(int key, const scene *s, km_sel sel, double step);
/* What the camera orbits about: the selected object's centre (its box's),
 * the selected light, or the scene's centre (orbit_scene_centre). */
vec3 keymode_pivot(const scene *s, km_sel sel);
/* True for the actions that edit the scene (those keymode_apply makes). */
bool keymode_is_edit(km_op op);
/* Makes the scene edit of a (KM_MOVE, KM_TURN, KM_ROTATE, KM_SCALE) as
 * editor calls; false (err set) when it cannot be done. An action that
 * would change nothing (a light already at full brightness) succeeds
 * without an edit. */
bool keymode_apply(editor *ed, const km_action *a, rt_error *err);
/* Euler angles (degrees; about X, then Y, then Z, as object_rotate takes
 * them) of the rotation by deg degrees about the unit axis. */
vec3 keymode_axis_euler(vec3 axis, double deg);

/* --- the session, without a terminal of its own (bench, tests) --- */
typedef struct keymode keymode;

/* A key-mode session on sh's scene drawing on a terminal of cols x rows
 * cells in palette pal, every byte through the output scheduler out
 * (borrowed; its picture is the session's until keymode_free). Its frames and refines are requests to the shell's
 * render service (sh->rs), which wakes the wake-up pipe the shell gave it
 * when a frame is ready; the shell's preview does not run until
 * keymode_free. NULL (the shell's error set) on failure. */
keymode *keymode_new(shell *sh, termout *out, frame_palette pal, int cols, int rows);
/* The picture's encoder (keyview_set_encoder's arguments) and a new layout
 * for it: what the shell's screen uses (its symbols or real pixels). */
void keymode_set_encoder(keymode *km, const encoder_ops *ops, int cell_w, int cell_h, int max_w, int max_h);
/* Ends the session: cancels its render, closes an open undo group, frees
 * it. The render service stays held (the caller restarts the preview). */
void keymode_free(keymode *km);
/* Handles one key (edits go to the editor at once; renders start in
 * keymode_tick). */
void keymode_key(keymode *km, int key);
/* Handles one mouse event (term/keys.h): a drag with the left button
 * orbits the camera about keymode_pivot, with Shift or the middle button
 * pans it, the wheel moves it nearer or farther, a click (press and
 * release in one cell) selects the object under the cursor. Motions are
 * coalesced: the camera follows the newest position at the next
 * keymode_tick. A drag is one undo step. */
void keymode_mouse(keymode *km, const keys_mouse *m);
/* Spins the camera about the scene's centre, a turn in `seconds` (the
 * turntable); any key or click stops it (the turn is one undo step). */
void keymode_spin(keymode *km, double seconds);
/* Starts, cancels and refines renders as needed and draws a finished
 * frame; returns the number of frames written (0 or 1). */
int keymode_tick(keymode *km);
/* Seconds until keymode_tick has something to do with no key and no
 * wake-up (a refine or a message to clear); < 0 when nothing. */
double keymode_timeout(const keymode *km);
/* Moves the key bytes the output scheduler gave up holding (typed while it
 * awaited the terminal's answer) to the end of `to`, in order. */
void keymode_late_keys(keymode *km, abuf *to);
/* True once a key asked to leave. */
bool keymode_done(const keymode *km);
/* A new terminal size: lays out again and repaints. */
void keymode_resize(keymode *km, int cols, int rows);
/* How many scene edits the session made. */
int keymode_edits(const keymode *km);
/* The pixel ratio of the last fast frame (1 = full resolution) and the
 * frames drawn so far. */
double keymode_ratio(const keymode *km);
long keymode_frames(const keymode *km);

/* --- the `view` command --- */
/* Runs key mode on the shell's terminal until Esc or q (or Ctrl-C, SIGTERM,
 * SIGHUP), then gives the shell's screen back as it was. False (error
 * recorded) when there is no full-screen terminal. */
bool keymode_run(shell *sh);
/* The same, the camera spinning (keymode_spin) from the start. */
bool keymode_turntable(shell *sh, double seconds);

#endif
