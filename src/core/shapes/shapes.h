/* rtsh — private declarations shared by the unit-shape files. */
#ifndef RTSH_SHAPES_PRIV_H
#define RTSH_SHAPES_PRIV_H

#include "rtsh/shape.h"

/* Solves a t^2 + 2 b t + c = 0 (note the half b) stably; false when there is
 * no real root. t0 <= t1. */
bool solve_quadratic_half(double a, double b, double c, double *t0, double *t1);

bool sphere_intersect(vec3 o, vec3 d, double tmin, double tmax, double *t, vec3 *n);
bool sphere_occluded(vec3 o, vec3 d, double tmin, double tmax);
bool plane_intersect(vec3 o, vec3 d, double tmin, double tmax, double *t, vec3 *n);
bool plane_occluded(vec3 o, vec3 d, double tmin, double tmax);
bool cylinder_intersect(vec3 o, vec3 d, double tmin, double tmax, double *t, vec3 *n);
bool cylinder_occluded(vec3 o, vec3 d, double tmin, double tmax);
bool cone_intersect(vec3 o, vec3 d, double tmin, double tmax, double *t, vec3 *n);
bool cone_occluded(vec3 o, vec3 d, double tmin, double tmax);
bool cube_intersect(vec3 o, vec3 d, double tmin, double tmax, double *t, vec3 *n);
bool cube_occluded(vec3 o, vec3 d, double tmin, double tmax);
bool disc_intersect(vec3 o, vec3 d, double tmin, double tmax, double *t, vec3 *n);
bool disc_occluded(vec3 o, vec3 d, double tmin, double tmax);
bool rect_intersect(vec3 o, vec3 d, double tmin, double tmax, double *t, vec3 *n);
bool rect_occluded(vec3 o, vec3 d, double tmin, double tmax);

#endif
