/* rtsh — the scene-edit API: every change to a scene, with undo and redo.
 *
 * An editor owns one scene. Every change — a shell command, a key in key
 * mode, `add`, `delete`, `load`, `generate` — is one call here that
 * validates the new value, applies it, records what it replaced and bumps
 * the generation counter. Nothing else writes to the scene, so a front end
 * knows the prepared world is stale exactly when editor_generation()
 * differs from the generation it was built for.
 *
 * Undo records hold only the element that changed (one object, one light,
 * one camera, the ambient line, an index), so editing a scene of a million
 * objects costs a few hundred bytes per edit. Replacing the whole scene
 * (load, generate) keeps the old scene itself, never a copy; at most
 * EDITOR_MAX_SCENES old scenes are kept.
 *
 * Indices are 0-based; the shell numbers elements from 1 and converts.
 * Functions that fail leave the scene and the history untouched and fill
 * err ("what is wrong; expected ..."). The editor never prints.
 */
#ifndef RTSH_EDIT_H
#define RTSH_EDIT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rtsh/error.h"
#include "rtsh/rtfile.h"
#include "rtsh/rules.h"
#include "rtsh/scene.h"

/* How many undo steps are kept (older ones are forgotten). */
#define EDITOR_MAX_UNDO 1000
/* How many whole replaced scenes (load, generate) the history may hold. */
#define EDITOR_MAX_SCENES 4

typedef struct editor editor;

/* A new editor owning s (which must not be NULL), labelled `label` (copied,
 * may be NULL); NULL when out of memory (s is then still the caller's). */
editor *editor_new(scene *s, const char *label);
/* Frees the editor, its scene and its history. */
void editor_free(editor *ed);

/* The scene as edited so far; valid until the next edit. */
const scene *editor_scene(const editor *ed);
/* Increases with every change (including undo and redo); never 0. */
uint64_t editor_generation(const editor *ed);

/* --- element edits: replace element i with a validated copy of the value --- */
bool editor_set_object(editor *ed, size_t i, const object *o, rt_error *err);
bool editor_set_light(editor *ed, size_t i, const light *l, rt_error *err);
bool editor_set_camera(editor *ed, size_t i, const camera *c, rt_error *err);
/* Sets the ambient line (the scene then has one). */
bool editor_set_ambient(editor *ed, const ambient *a, rt_error *err);
/* Sets the sky (has = false removes it). */
bool editor_set_sky(editor *ed, bool has, const sky *sk, rt_error *err);
/* Makes camera i the active one. */
bool editor_select_camera(editor *ed, size_t i, rt_error *err);

/* --- adding and removing elements --- */
/* Inserts so that the new element becomes element i (i = count appends). */
bool editor_insert_object(editor *ed, size_t i, const object *o, rt_error *err);
bool editor_insert_light(editor *ed, size_t i, const light *l, rt_error *err);
/* Appends a camera (it does not become active). */
bool editor_add_camera(editor *ed, const camera *c, rt_error *err);
bool editor_delete_object(editor *ed, size_t i, rt_error *err);
bool editor_delete_light(editor *ed, size_t i, rt_error *err);
/* Removes camera i; the last camera cannot be removed. */
bool editor_delete_camera(editor *ed, size_t i, rt_error *err);
/* Parses one .rt line (rt_parse_line) and applies what it describes as one
 * undo step: an object or light is appended, `C` replaces the active
 * camera, `c` appends a camera, `A` and `sky` replace theirs, `R` and `set`
 * lines change the scene's hints. `name`/`lineno` locate parse errors. */
bool editor_add_line(editor *ed, const char *line, const char *name, int lineno,
                     const rt_load_opts *opts, rt_error *err);

/* Replaces the whole scene by s (load, generate), taking ownership of s
 * (also on failure, when s is freed). One undo step brings the old one back.
 * `label` (copied; NULL for none) names where the scene came from, such as
 * its file; undo and redo bring the label back with its scene. */
bool editor_replace(editor *ed, scene *s, const char *label, rt_error *err);
/* The label of the current scene (NULL when none was given). */
const char *editor_label(const editor *ed);

/* --- the verbs of the shell and key mode, built on the calls above --- */
/* Object i: move by d (world axes), rotate by Euler angles in degrees
 * (about X, then Y, then Z, about its centre), multiply its size, recolour. */
bool editor_object_move(editor *ed, size_t i, vec3 d, rt_error *err);
bool editor_object_rotate(editor *ed, size_t i, vec3 deg, rt_error *err);
bool editor_object_scale(editor *ed, size_t i, vec3 factor, rt_error *err);
bool editor_object_color(editor *ed, size_t i, vec3 rgb, rt_error *err);
/* One key=value field ("ior=1.5"), read and checked as the reader does
 * (the same table, scanner and rules). */
bool editor_object_set_key(editor *ed, size_t i, const char *assignment, rt_error *err);
/* Light i. */
bool editor_light_pos(editor *ed, size_t i, vec3 p, rt_error *err);
bool editor_light_move(editor *ed, size_t i, vec3 d, rt_error *err);
bool editor_light_brightness(editor *ed, size_t i, double ratio, rt_error *err);
bool editor_light_color(editor *ed, size_t i, vec3 rgb, rt_error *err);
/* The active camera. move: by d along the camera's own right, up and
 * forward axes (cam_view_make). turn: yaw degrees to the right about the
 * world's vertical, then pitch degrees up, keeping the view within
 * EDIT_PITCH_LIMIT degrees of the horizon (the camera has no roll); the new
 * direction is unit; a turn that changes nothing records no edit.
 * lookat: aim at a point (which must differ from the position). */
#define EDIT_PITCH_LIMIT 89.0
bool editor_camera_pos(editor *ed, vec3 p, rt_error *err);
bool editor_camera_dir(editor *ed, vec3 d, rt_error *err);
bool editor_camera_lookat(editor *ed, vec3 target, rt_error *err);
bool editor_camera_fov(editor *ed, double deg, rt_error *err);
bool editor_camera_move(editor *ed, vec3 d, rt_error *err);
bool editor_camera_turn(editor *ed, double yaw_deg, double pitch_deg, rt_error *err);

/* --- history --- */
/* Undoes / redoes one step (a group counts as one); false (err set) when
 * there is nothing to undo / redo. */
bool editor_undo(editor *ed, rt_error *err);
bool editor_redo(editor *ed, rt_error *err);
size_t editor_undo_count(const editor *ed);
size_t editor_redo_count(const editor *ed);
/* Names the step on top of the undo stack ("object 3 move 0.5,0,0"), for
 * the front end to say what undo and redo do; the note travels with the step.
 * A step named already keeps its name (false then, or with no step or no
 * memory). */
bool editor_note(editor *ed, const char *text);
/* The name of the step that undo / redo would apply next, or NULL. */
const char *editor_undo_note(const editor *ed);
const char *editor_redo_note(const editor *ed);
/* Edits between begin and end undo as one step (key mode: one drag). Groups
 * nest; only the outermost counts. */
void editor_group_begin(editor *ed);
void editor_group_end(editor *ed);

/* Validation, shared with the reader and the front ends: rules.h. */

#endif
