/* rtsh — `save FILE.rt`: the scene as the user wrote it, with the shell's
 * settings (rtsh/rtkeep.h does the writing). */
#ifndef RTSH_SAVE_RT_H
#define RTSH_SAVE_RT_H

#include <stdbool.h>

#include "rtsh/error.h"
#include "rtsh/scene.h"
#include "shell/shell.h"

/* The scene's hints made to reopen with the shell's current settings that
 * are kept with a scene (resolution, samples, depth, mode and every other
 * SETTING_SCENE row): a hint that already gives the current value (from the
 * defaults) stays as it is; any other is set to the current value. */
scene_hints save_rt_hints(const scene_hints *h, const render_settings *set);

/* Writes the current scene to path. The text it was loaded from (its file,
 * read again now, or the built-in scene's) is kept where the scene still
 * agrees with it; a generated scene is written from scratch. */
bool save_rt(shell *sh, const char *path, rt_error *err);

#endif
