/* rtsh — the value rules of the scene model, ONE set for the .rt reader and
 * the editor: whatever the editor accepts, the reader accepts (an edit that
 * would leave the valid range is refused with the range), so that a saved
 * scene always loads again.
 *
 * The reader checks each field as it reads it (to point at its column) and
 * then the whole element with these functions; the editor checks every new
 * value with them before it applies it.
 */
#ifndef RTSH_RULES_H
#define RTSH_RULES_H

#include <stdbool.h>

#include "rtsh/error.h"
#include "rtsh/scene.h"

/* Numbers in .rt files never exceed this magnitude. Scenes in the wild use
 * coordinates up to 1.5e18 (and -2^31 is common); 1e20 keeps every product
 * the renderer forms far from overflow. */
#define RT_NUM_MAX 1e20
#define RT_NUM_MAX_TEXT "1e20"

/* The field of view is read in [0,180] degrees; the ends, which cannot be
 * rendered, are clamped to these (with a warning in files, a note in the
 * shell). */
#define RT_FOV_MIN 0.01
#define RT_FOV_MAX 179.99
/* fov clamped to [RT_FOV_MIN, RT_FOV_MAX]; *clamped says whether it moved.
 * False (err set) outside [0,180] or not a number. */
bool fov_rule(double *fov, bool *clamped, rt_error *err);

/* A colour with each channel in 0..255. */
bool color_validate(vec3 rgb, const char *what, rt_error *err);
bool light_validate(const light *l, rt_error *err);
/* The fov must already be in [RT_FOV_MIN, RT_FOV_MAX] (see fov_rule). */
bool camera_validate(const camera *c, rt_error *err);
bool ambient_validate(const ambient *a, rt_error *err);
bool sky_validate(const sky *k, rt_error *err);
/* Every field of the object: object_validate (scene.h), magnitudes within
 * RT_NUM_MAX, sizes > 0, the material's ranges and its key=value fields'
 * (rtfile_priv.h's rt_keys). */
bool object_rules(const object *o, rt_error *err);

#endif
