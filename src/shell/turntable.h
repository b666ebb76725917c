/* rtsh — the turntable: a full turn of the camera about the scene's centre
 * (rtsh/orbit.h), frame k turned by 360 k / FRAMES degrees.
 *
 * `rtsh SCENE --turntable FRAMES -o OUT` renders FRAMES frames, one render
 * job each, at the scene's resolution and samples, and writes them as one
 * animated GIF (OUT ends in .gif; rtsh/gif.h) or as numbered images (OUT
 * holds one %d, %03d ...: frame%03d.png writes frame000.png,
 * frame001.png ...). In the terminal, `turntable [SECONDS]` (and
 * `rtsh --turntable`) spins key mode's camera (keymode.h).
 */
#ifndef RTSH_TURNTABLE_H
#define RTSH_TURNTABLE_H

#include <stdbool.h>
#include <stddef.h>

#include "shell/options.h"

/* Hundredths of a second a GIF frame is shown: a turn lasts about
 * TURNTABLE_TURN_CS, each frame at least TURNTABLE_MIN_CS. */
#define TURNTABLE_TURN_CS 400
#define TURNTABLE_MIN_CS 4

/* The name of frame `index` from a numbered pattern (exactly one %d, with
 * an optional 0 flag and width, as in frame%03d.png; %% is a %): false
 * when pat is not such a pattern or the name does not fit. */
bool turntable_name(const char *pat, int index, char *out, size_t size);
/* True when out names a GIF (.gif in any case). */
bool turntable_is_gif(const char *out);
/* True when out is a turntable's output: a GIF, or a numbered name of an
 * image format (turntable_name). */
bool turntable_output_ok(const char *out);
/* The batch turntable of o->scene to o->output; returns the exit status. */
int turntable_batch(const rtsh_options *o);

#endif
