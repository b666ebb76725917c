/* rtsh — orbiting a camera: the model viewer's mouse and arrow keys, its
 * `f` (frame) key and the turntable all move the camera on a sphere about
 * a point it looks at, as a turntable does under a fixed camera.
 *
 * Angles are degrees. The camera has no roll (as everywhere in rtsh): yaw
 * turns about the world's vertical (+Y), pitch changes the elevation, kept
 * within ORBIT_PITCH_LIMIT of the horizon.
 */
#ifndef RTSH_ORBIT_H
#define RTSH_ORBIT_H

#include <stdbool.h>

#include "rtsh/math.h"
#include "rtsh/scene.h"

#define ORBIT_PITCH_LIMIT 89.0

/* The box around the scene's bounded objects (planes left out), or an
 * empty box when it has none. */
box orbit_scene_bounds(const scene *s);
/* The point the turntable and the mouse turn about: the centre of
 * orbit_scene_bounds, or, when the scene has no bounded object, the point
 * the camera looks at one unit ahead. */
vec3 orbit_scene_centre(const scene *s);
/* c moved on the sphere about pivot: its position yaw degrees about the
 * vertical through pivot (positive: the camera goes to its right, so the
 * scene seems to turn to the left) and pitch degrees up; its direction
 * turned by the same angles (a camera that looked at pivot still does). */
camera orbit_camera(camera c, vec3 pivot, double yaw_deg, double pitch_deg);
/* c moved along the line to pivot by factor of its distance (0.1: a tenth
 * nearer; -0.1: a tenth farther); never nearer than a thousandth of the
 * distance. Its direction stays. An orthographic camera stays where it is
 * and its half height is multiplied by 1 - factor instead. */
camera orbit_dolly(camera c, vec3 pivot, double factor);
/* c keeping its direction, moved so that box b fills an image of aspect
 * (width / height): b's bounding sphere within the narrower field of view,
 * (the sphere around the box is margin enough). An empty box leaves c as it is.
 * A vertical=1 camera's fov is the height's; an orthographic camera gets the
 * half height that holds the sphere, from two radii in front of it. */
camera orbit_frame(camera c, box b, double aspect);
/* The frame'th of frames views of a full turn of c about pivot (frame 0 is
 * c itself; frame k is turned by 360 k / frames degrees). */
camera orbit_turntable(camera c, vec3 pivot, int frame, int frames);

#endif
