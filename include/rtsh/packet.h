/* rtsh — coherent rays traced together (issue 29): camera rays and shadow
 * rays toward a point light, up to PACKET_MAX at a time, through the
 * world's object tree (src/core/packet.c).
 *
 * The packet walks the tree once for all its rays: an interval test
 * (the rays' origins and inverse directions as intervals, Wald et al.,
 * "Ray tracing deformable scenes using dynamic bounding volume
 * hierarchies", 2007) culls a node for the whole packet, and the children
 * are visited nearest first for the packet. At a leaf every ray meets the
 * primitives with the same double-precision tests as a single ray.
 *
 * The answers are those of the single-ray queries, to the bit: the
 * distance, the primitive, what its test left (trace_hit.nl), hence the
 * hit record world_finish makes. Nearest hits do not depend on the order in
 * which the tree is walked, except for ties: two primitives at exactly the
 * same distance, of which a single ray keeps the first it meets. The
 * packet keeps the distance of a tie but not which primitive wins: a ray
 * that found one is traced again alone (world_trace_coherent), so the
 * rule stays the single ray's and today's pictures stay the same. Rays fall
 * back to the single walk as well when the packet would not be coherent:
 * when their directions do not share each axis's sign, or a component is
 * zero.
 *
 * A model's triangles are walked by packets of their own
 * (mesh_intersect_world_packet, mesh_occluded_world_packet, mesh.h): for a
 * lone model (the world's only primitive beside planes) by camera and
 * shadow packets, for a model among other objects by the camera packets
 * at the object tree's leaf; the same answers as its single rays. */
#ifndef RTSH_PACKET_H
#define RTSH_PACKET_H

#include <stdbool.h>

#include "rtsh/world.h"

/* The most rays a packet holds: 16, a 4 x 4 block of pixels (measured
 * against 4 and 8 in bench/README.md). */
#define PACKET_MAX 16

/* The nearest hits of rays r[0..n) (n <= PACKET_MAX) with tmin < t < tmax,
 * as world_trace_coherent gives them one by one: found[i] says whether ray i
 * hit, th[i] what (th[i] is not set where found[i] is false). Camera rays,
 * or any rays that start close together and point the same way. */
void world_trace_packet(const world *w, int n, const ray *r, double tmin, double tmax, trace_hit *th, bool *found);
/* world_trace_packet, then world_finish of each hit into h[i]. */
void world_intersect_packet(const world *w, int n, const ray *r, double tmin, double tmax, hit *h, bool *found);
/* Whether something lies on ray i with tmin < t < tmax[i], as
 * world_occluded answers: shadow rays toward one light. */
void world_occluded_packet(const world *w, int n, const ray *r, double tmin, const double *tmax, bool *occ);

#endif
