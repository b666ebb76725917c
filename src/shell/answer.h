/* rtsh — what a command says back: the element an edit changed, an
 * element's fields, and the name each edit leaves on the undo stack (so that
 * undo and redo can say what they did). */
#ifndef RTSH_ANSWER_H
#define RTSH_ANSWER_H

#include <stdint.h>

#include "shell/commands.h"

/* Called by command_run after a command succeeded; gen0 is the editor's
 * generation before it ran. Names the undo step the command made and, for
 * the element edits (camera, light, object, ambient), prints the element's
 * new line ("object 3: sp 0.5,0,0 1 255,0,0"). */
void answer_after_command(shell *sh, const command *c, const char *rest, uint64_t gen0);

/* `object N`, `light N`, `camera`: the element's line, then its fields one
 * per line. i is 0-based. */
void answer_object_fields(shell *sh, size_t i);
void answer_light_fields(shell *sh, size_t i);
void answer_camera_fields(shell *sh, size_t i);

/* After load, next and prev: "loaded x.rt: 3 objects, 2 lights, 1 camera",
 * then one line for each setting set by hand (`set`) that the new scene
 * changed: "samples 16 -> 1 (from x.rt)". */
void answer_loaded(shell *sh, const char *verb, const render_settings *before);
/* Only the lines for the settings set by hand that changed (generate, and
 * undo or redo of a load). */
void answer_setting_changes(shell *sh, const render_settings *before);

/* "undone: WHAT" / "redone: WHAT", with the note taken before the step. */
void answer_undo(shell *sh, const char *verb, const char *note);

#endif
