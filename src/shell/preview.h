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

#include "rtsh/render.h"
#include "rtsh/world.h"
#include "shell/options.h"

/* Seconds before a preview gives up (exit status 1). */
#define PREVIEW_TIMEOUT 20
/* Pixels a texture of a preview may have (4096 x 4096): a larger one is not
 * decoded, the surface is drawn untextured and one line on standard error
 * says so (image_budget_set; the sky is not held to it). A 12000 x 12000
 * PNG of 420 KB cost 2.9 s and 2.2 GB. */
#define PREVIEW_TEXTURE_PIXELS ((size_t)4096 * 4096)
/* Seconds from the start a preview's full picture may take; past them the
 * coarse picture is shown (preview_render). */
#define PREVIEW_FULL_BUDGET 10.0
/* ... and the coarse picture: past them the preview gives up (status 1),
 * before the watchdog. */
#define PREVIEW_COARSE_BUDGET 16.0
/* The picture of a preview in a time budget: first a coarse pass (a
 * quarter of the width and of the height, 1 sample, not denoised: 1/16 of
 * the pixels), stopped coarse_s seconds from now; then the picture of set,
 * stopped full_s seconds from now (both from the call). When the full picture is stopped, the
 * coarse one is returned, each of its pixels 4 x 4 (*coarse set true);
 * otherwise the full one, the same bits as render_image's. NULL (err set;
 * "stopped" when the coarse pass is stopped too) on failure. Both passes are stopped
 * between blocks of 4 x 4 pixels (render.c's polls). */
framebuffer *preview_render(const world *wd, const render_settings *set, double full_s, double coarse_s, bool *coarse,
                            rt_error *err);
/* The preview's camera on a w x h picture: a model (model true) framed to
 * fill it (orbit_frame of the objects' bounds); a scene's kept, at least as
 * high as in a 16:9 picture: a wide pane widens the horizontal field of view
 * rather than cutting the top off (a vertical=1 fov keeps the height
 * already; an orthographic camera is left as it is). */
void preview_camera(camera *c, bool model, box bounds, int w, int h);
/* Runs the preview of o->scene at o->preview_cols x o->preview_rows;
 * returns the exit status (0, or 1 after a message on standard error). */
int preview_main(const rtsh_options *o);

#endif
