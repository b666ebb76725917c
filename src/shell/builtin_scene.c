/* rtsh — the built-in showcase scene (builtin_scene.h). */
#include "shell/builtin_scene.h"

const char builtin_scene_text[] =
#include "gen/showcase.inc"
	;
const size_t builtin_scene_len = sizeof builtin_scene_text - 1;
