/* rtsh — `rtsh --preview COLSxROWS FILE`: a still picture of a model or a
 * scene for a file manager's preview pane, on standard output.
 *
 * The picture is exactly COLS x ROWS cells: ROWS lines of COLS half blocks
 * (or the glyphs of --symbols quadrant, sextant or octant), each ended by
 * "\e[m\n" (frame_text), or one image of the pixel protocols covering
 * that area (--pixels kitty, sixel or iterm). Nothing else is
 * written to standard output: no alternate screen, no cursor movement, and
 * no question to the terminal unless standard output is one and
 * --pixels auto asked for it.
 *
 * Fast over good: Whitted with at most 4 samples, or path tracing with at
 * most 8 samples through the denoiser, at the picture's own size; models
 * and scenes alike. Only regular files are opened (a FIFO, a device or a
 * folder is refused), and a watchdog ends the process after
 * PREVIEW_TIMEOUT seconds, so a hostile file never hangs the file manager.
 */
#ifndef RTSH_PREVIEW_H
#define RTSH_PREVIEW_H

#include <stdbool.h>

#include "shell/options.h"

/* Seconds before a preview gives up (exit status 1). */
#define PREVIEW_TIMEOUT 20
/* Pixels a texture of a preview may have (4096 x 4096): a larger one is not
 * decoded, the surface is drawn untextured and one line on standard error
 * says so (image_budget_set; the sky is not held to it). A 12000 x 12000
 * PNG of 420 KB cost 2.9 s and 2.2 GB. */
#define PREVIEW_TEXTURE_PIXELS ((size_t)4096 * 4096)
/* Runs the preview of o->scene at o->preview_cols x o->preview_rows;
 * returns the exit status (0, or 1 after a message on standard error). */
int preview_main(const rtsh_options *o);

#endif
