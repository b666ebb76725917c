/* rtsh — math value types: vectors, rays, boxes, 4x4 matrices, transforms.
 *
 * Everything geometric is double precision: scenes in the wild use
 * coordinates up to 2^31, and double keeps self-intersection offsets small
 * relative to the scene (see DESIGN notes in README, "float or double").
 * All helpers are pure functions on values; nothing here allocates.
 */
#ifndef RTSH_MATH_H
#define RTSH_MATH_H

#include <math.h>
#include <stdbool.h>

#define RT_PI 3.14159265358979323846

typedef struct vec3 {
	double x, y, z;
} vec3;

typedef struct ray {
	vec3 o; /* origin */
	vec3 d; /* direction, not necessarily unit length */
} ray;

/* Axis-aligned box; an empty box has lo > hi. */
typedef struct box {
	vec3 lo, hi;
} box;

/* Row-major 4x4 matrix acting on column vectors: p' = M p. */
typedef struct mat4 {
	double m[4][4];
} mat4;

/* A transform and its inverse, kept together so neither is recomputed. */
typedef struct xform {
	mat4 m, inv;
} xform;

static inline vec3 v3(double x, double y, double z) { return (vec3){x, y, z}; }
static inline vec3 v3_splat(double s) { return (vec3){s, s, s}; }
static inline vec3 v3_add(vec3 a, vec3 b) { return (vec3){a.x + b.x, a.y + b.y, a.z + b.z}; }
static inline vec3 v3_sub(vec3 a, vec3 b) { return (vec3){a.x - b.x, a.y - b.y, a.z - b.z}; }
static inline vec3 v3_mul(vec3 a, vec3 b) { return (vec3){a.x * b.x, a.y * b.y, a.z * b.z}; }
static inline vec3 v3_scale(vec3 a, double s) { return (vec3){a.x * s, a.y * s, a.z * s}; }
static inline vec3 v3_neg(vec3 a) { return (vec3){-a.x, -a.y, -a.z}; }
/* a + b*s */
static inline vec3 v3_madd(vec3 a, vec3 b, double s)
{
	return (vec3){a.x + b.x * s, a.y + b.y * s, a.z + b.z * s};
}
static inline double v3_dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline vec3 v3_cross(vec3 a, vec3 b)
{
	return (vec3){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
static inline double v3_len2(vec3 a) { return v3_dot(a, a); }
static inline double v3_len(vec3 a) { return sqrt(v3_dot(a, a)); }
/* Unit vector along a; a must not be zero. */
static inline vec3 v3_norm(vec3 a) { return v3_scale(a, 1.0 / v3_len(a)); }
static inline vec3 v3_min(vec3 a, vec3 b) { return (vec3){fmin(a.x, b.x), fmin(a.y, b.y), fmin(a.z, b.z)}; }
static inline vec3 v3_max(vec3 a, vec3 b) { return (vec3){fmax(a.x, b.x), fmax(a.y, b.y), fmax(a.z, b.z)}; }
static inline double v3_max_comp(vec3 a) { return fmax(a.x, fmax(a.y, a.z)); }
static inline double v3_max_abs(vec3 a) { return fmax(fabs(a.x), fmax(fabs(a.y), fabs(a.z))); }
static inline double v3_get(vec3 a, int axis) { return axis == 0 ? a.x : axis == 1 ? a.y : a.z; }
static inline bool v3_eq(vec3 a, vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }
static inline bool v3_finite(vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }
static inline vec3 v3_lerp(vec3 a, vec3 b, double t) { return v3_add(v3_scale(a, 1.0 - t), v3_scale(b, t)); }
/* Mirror reflection of d about the unit normal n. */
static inline vec3 v3_reflect(vec3 d, vec3 n) { return v3_sub(d, v3_scale(n, 2.0 * v3_dot(d, n))); }
static inline vec3 ray_at(ray r, double t) { return v3_madd(r.o, r.d, t); }

static inline double deg_to_rad(double d) { return d * (RT_PI / 180.0); }
static inline double rad_to_deg(double r) { return r * (180.0 / RT_PI); }
static inline double clampd(double v, double lo, double hi) { return v < lo ? lo : v > hi ? hi : v; }

static inline box box_empty(void) { return (box){v3_splat(INFINITY), v3_splat(-INFINITY)}; }
static inline box box_point(vec3 p) { return (box){p, p}; }
static inline box box_union(box a, box b) { return (box){v3_min(a.lo, b.lo), v3_max(a.hi, b.hi)}; }
static inline box box_add(box a, vec3 p) { return (box){v3_min(a.lo, p), v3_max(a.hi, p)}; }
static inline bool box_is_empty(box b) { return b.lo.x > b.hi.x || b.lo.y > b.hi.y || b.lo.z > b.hi.z; }
static inline vec3 box_center(box b) { return v3_scale(v3_add(b.lo, b.hi), 0.5); }
/* Half the surface area (the SAH only needs ratios); 0 for an empty box. */
static inline double box_half_area(box b)
{
	if (box_is_empty(b))
		return 0.0;
	vec3 e = v3_sub(b.hi, b.lo);
	return e.x * e.y + e.y * e.z + e.z * e.x;
}

/* --- 4x4 matrices (math.c) --- */
mat4 m4_identity(void);
mat4 m4_mul(mat4 a, mat4 b);
mat4 m4_transpose(mat4 a);
/* Inverts a by Gauss-Jordan elimination with partial pivoting; false when
 * a is singular (or not finite), leaving *out untouched. */
bool m4_invert(mat4 a, mat4 *out);
mat4 m4_translate(vec3 t);
mat4 m4_scale(vec3 s);
mat4 m4_rotate_x(double rad);
mat4 m4_rotate_y(double rad);
mat4 m4_rotate_z(double rad);
/* Rotation by rad about the unit axis (Rodrigues' formula). */
mat4 m4_rotate_axis(vec3 axis, double rad);
/* Shearing x' = x + xy*y + xz*z, y' = y + yx*x + yz*z, z' = z + zx*x + zy*y,
 * with s = {xy, xz, yx, yz, zx, zy} (the order of the miniRT seed). */
mat4 m4_shear(const double s[6]);
/* The rotation that turns +Y onto the unit vector dir by the shortest arc
 * (for dir = -Y: a half turn about X), then turns by twist radians about dir. */
mat4 m4_orient(vec3 dir, double twist_rad);

static inline vec3 m4_point(const mat4 *a, vec3 p)
{
	return (vec3){
		a->m[0][0] * p.x + a->m[0][1] * p.y + a->m[0][2] * p.z + a->m[0][3],
		a->m[1][0] * p.x + a->m[1][1] * p.y + a->m[1][2] * p.z + a->m[1][3],
		a->m[2][0] * p.x + a->m[2][1] * p.y + a->m[2][2] * p.z + a->m[2][3],
	};
}
static inline vec3 m4_vector(const mat4 *a, vec3 v)
{
	return (vec3){
		a->m[0][0] * v.x + a->m[0][1] * v.y + a->m[0][2] * v.z,
		a->m[1][0] * v.x + a->m[1][1] * v.y + a->m[1][2] * v.z,
		a->m[2][0] * v.x + a->m[2][1] * v.y + a->m[2][2] * v.z,
	};
}
/* Normal transform: the transpose of the inverse applied to n (not normalised). */
static inline vec3 m4_normal(const mat4 *inv, vec3 n)
{
	return (vec3){
		inv->m[0][0] * n.x + inv->m[1][0] * n.y + inv->m[2][0] * n.z,
		inv->m[0][1] * n.x + inv->m[1][1] * n.y + inv->m[2][1] * n.z,
		inv->m[0][2] * n.x + inv->m[1][2] * n.y + inv->m[2][2] * n.z,
	};
}

/* --- transforms --- */
xform xf_identity(void);
/* Builds {m, m^-1}; false when m is singular. */
bool xf_make(mat4 m, xform *out);
/* The transform that applies a first, then b. */
xform xf_then(xform a, xform b);
/* World bounds of the local box b under x (the eight corners transformed). */
box xf_box(const xform *x, box b);

#endif
