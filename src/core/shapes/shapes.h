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

/* Texture coordinates (shape_kind.uv). The planar u = (x + 1) / 2,
 * v = (z + 1) / 2: the disc, the rectangle, the caps (and kinds with no uv
 * of their own). */
void uv_planar(vec3 q, vec3 nl, double tube, double *u, double *v, vec3 *dqdu, vec3 *dqdv);
/* The cylinder's and cone's: around the side the sphere's u and
 * v = (y + 1) / 2, the caps planar. */
void uv_capped_side(vec3 q, vec3 nl, double tube, double *u, double *v, vec3 *dqdu, vec3 *dqdv);

/* The short-form reader and writer of kinds sized by one number in every
 * direction (the sphere: DIAMETER; scale = that x 3). */
void read_uniform(object *o, const double *sizes);
bool write_uniform(const object *o, double *sizes);
/* DIAMETER HEIGHT: scale (d, h, d) (cylinder, cone). */
void read_tube(object *o, const double *sizes);
bool write_tube(const object *o, double *sizes);

#endif
