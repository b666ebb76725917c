/* rtsh — private declarations shared by the unit-shape files. */
#ifndef RTSH_SHAPES_PRIV_H
#define RTSH_SHAPES_PRIV_H

#include "rtsh/shape.h"

/* Solves a t^2 + 2 b t + c = 0 (note the half b) stably; false when there is
 * no real root. t0 <= t1. */
bool solve_quadratic_half(double a, double b, double c, double *t0, double *t1);

/* The cube [-1,1]^3 (the bounds of most unit shapes). */
box unit_cube_bounds(double tube);
/* The square [-1,1] x {0} x [-1,1] (flat shapes). */
box unit_flat_bounds(double tube);

/* The angle about +Y of p as u in [0,1) (0 on +X, a quarter on +Z), and the
 * unit tangent along it ((1,0,0) on the axis). */
double around_y(vec3 p, vec3 *tangent);
/* u = (x+1)/2, v = (z+1)/2, tangent +X: flat shapes and caps. */
void uv_flat(vec3 p, double tube, double *u, double *v, vec3 *tangent);

/* The short-form reader and writer of kinds sized by one number in every
 * direction (the sphere: DIAMETER; scale = that x 3). */
void read_uniform(object *o, const double *sizes);
bool write_uniform(const object *o, double *sizes);
/* DIAMETER HEIGHT: scale (d, h, d) (cylinder, cone). */
void read_tube(object *o, const double *sizes);
bool write_tube(const object *o, double *sizes);

#endif
