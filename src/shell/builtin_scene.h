/* rtsh — the showcase scene compiled into the binary, so that `rtsh` works
 * from any folder (generated from scenes/showcase.rt by tests/embed.sh). */
#ifndef RTSH_BUILTIN_SCENE_H
#define RTSH_BUILTIN_SCENE_H

#include <stddef.h>

extern const char builtin_scene_text[];
extern const size_t builtin_scene_len;
/* The name the built-in scene goes by in messages and the status line. */
#define BUILTIN_SCENE_NAME "showcase.rt (built in)"

#endif
