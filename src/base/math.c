/* rtsh — 4x4 matrices and transforms (math.h). */
#include "rtsh/math.h"

mat4 m4_identity(void)
{
	mat4 r = {{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}};
	return r;
}

mat4 m4_mul(mat4 a, mat4 b)
{
	/* Row by row: each element still sums a.m[i][k] * b.m[k][j] from 0.0
	 * in the order k = 0..3 (the same bits), while the four of a row are
	 * computed side by side (half the instructions: loading a scene builds
	 * a transform per object). */
	mat4 r;
	for (int i = 0; i < 4; i++) {
		double s[4] = {0.0, 0.0, 0.0, 0.0};
		for (int k = 0; k < 4; k++) {
			double x = a.m[i][k];
			for (int j = 0; j < 4; j++)
				s[j] += x * b.m[k][j];
		}
		for (int j = 0; j < 4; j++)
			r.m[i][j] = s[j];
	}
	return r;
}

mat4 m4_transpose(mat4 a)
{
	mat4 r;
	for (int i = 0; i < 4; i++)
		for (int j = 0; j < 4; j++)
			r.m[i][j] = a.m[j][i];
	return r;
}

/* The inverse of an affine matrix [A t; 0 1] is [A^-1, -A^-1 t; 0 1]. A is
 * inverted by its adjugate; it counts as singular when its determinant is
 * tiny next to the product of its column lengths (the volume a unit cube
 * keeps, relative to a box of the same edge lengths), which is independent
 * of the overall scale and of the translation. */
static bool affine_invert(const mat4 *a, mat4 *out)
{
	const double(*m)[4] = a->m;
	double c00 = m[1][1] * m[2][2] - m[1][2] * m[2][1];
	double c01 = m[1][2] * m[2][0] - m[1][0] * m[2][2];
	double c02 = m[1][0] * m[2][1] - m[1][1] * m[2][0];
	double det = m[0][0] * c00 + m[0][1] * c01 + m[0][2] * c02;
	double vol = 1.0;
	for (int j = 0; j < 3; j++)
		vol *= sqrt(m[0][j] * m[0][j] + m[1][j] * m[1][j] + m[2][j] * m[2][j]);
	if (!(fabs(det) > 1e-12 * vol) || !isfinite(det))
		return false;
	double id = 1.0 / det;
	mat4 r = m4_identity();
	r.m[0][0] = c00 * id;
	r.m[1][0] = c01 * id;
	r.m[2][0] = c02 * id;
	r.m[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) * id;
	r.m[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) * id;
	r.m[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) * id;
	r.m[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) * id;
	r.m[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) * id;
	r.m[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) * id;
	for (int i = 0; i < 3; i++)
		r.m[i][3] = -(r.m[i][0] * m[0][3] + r.m[i][1] * m[1][3] + r.m[i][2] * m[2][3]);
	*out = r;
	return true;
}

bool m4_invert(mat4 a, mat4 *out)
{
	for (int i = 0; i < 4; i++)
		for (int j = 0; j < 4; j++)
			if (!isfinite(a.m[i][j]))
				return false;
	if (a.m[3][0] == 0.0 && a.m[3][1] == 0.0 && a.m[3][2] == 0.0 && a.m[3][3] == 1.0)
		return affine_invert(&a, out);

	/* General matrices: Gauss-Jordan elimination with scaled partial
	 * pivoting (each row compared relative to its largest element). */
	mat4 inv = m4_identity();
	double rowmax[4];
	for (int i = 0; i < 4; i++) {
		rowmax[i] = 0.0;
		for (int j = 0; j < 4; j++)
			rowmax[i] = fmax(rowmax[i], fabs(a.m[i][j]));
		if (rowmax[i] == 0.0)
			return false;
	}
	for (int col = 0; col < 4; col++) {
		int piv = col;
		for (int r = col + 1; r < 4; r++)
			if (fabs(a.m[r][col]) / rowmax[r] > fabs(a.m[piv][col]) / rowmax[piv])
				piv = r;
		if (fabs(a.m[piv][col]) <= 1e-14 * rowmax[piv])
			return false;
		if (piv != col) {
			for (int j = 0; j < 4; j++) {
				double t = a.m[col][j];
				a.m[col][j] = a.m[piv][j];
				a.m[piv][j] = t;
				t = inv.m[col][j];
				inv.m[col][j] = inv.m[piv][j];
				inv.m[piv][j] = t;
			}
			double t = rowmax[col];
			rowmax[col] = rowmax[piv];
			rowmax[piv] = t;
		}
		double p = 1.0 / a.m[col][col];
		for (int j = 0; j < 4; j++) {
			a.m[col][j] *= p;
			inv.m[col][j] *= p;
		}
		for (int r = 0; r < 4; r++) {
			if (r == col || a.m[r][col] == 0.0)
				continue;
			double f = a.m[r][col];
			for (int j = 0; j < 4; j++) {
				a.m[r][j] -= f * a.m[col][j];
				inv.m[r][j] -= f * inv.m[col][j];
			}
		}
	}
	for (int i = 0; i < 4; i++)
		for (int j = 0; j < 4; j++)
			if (!isfinite(inv.m[i][j]))
				return false;
	*out = inv;
	return true;
}

/* The makers below write their matrix out row by row. */
mat4 m4_translate(vec3 t)
{
	return (mat4){{{1, 0, 0, t.x}, {0, 1, 0, t.y}, {0, 0, 1, t.z}, {0, 0, 0, 1}}};
}

mat4 m4_scale(vec3 s)
{
	return (mat4){{{s.x, 0, 0, 0}, {0, s.y, 0, 0}, {0, 0, s.z, 0}, {0, 0, 0, 1}}};
}

mat4 m4_rotate_x(double a)
{
	double c = cos(a), s = sin(a);
	return (mat4){{{1, 0, 0, 0}, {0, c, -s, 0}, {0, s, c, 0}, {0, 0, 0, 1}}};
}

mat4 m4_rotate_y(double a)
{
	double c = cos(a), s = sin(a);
	return (mat4){{{c, 0, s, 0}, {0, 1, 0, 0}, {-s, 0, c, 0}, {0, 0, 0, 1}}};
}

mat4 m4_rotate_z(double a)
{
	double c = cos(a), s = sin(a);
	return (mat4){{{c, -s, 0, 0}, {s, c, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}};
}

mat4 m4_rotate_axis(vec3 k, double a)
{
	/* Rodrigues: R = cI + s[k]x + (1-c) k k^T */
	double c = cos(a), s = sin(a), t = 1.0 - c;
	mat4 r = m4_identity();
	r.m[0][0] = c + t * k.x * k.x;
	r.m[0][1] = t * k.x * k.y - s * k.z;
	r.m[0][2] = t * k.x * k.z + s * k.y;
	r.m[1][0] = t * k.y * k.x + s * k.z;
	r.m[1][1] = c + t * k.y * k.y;
	r.m[1][2] = t * k.y * k.z - s * k.x;
	r.m[2][0] = t * k.z * k.x - s * k.y;
	r.m[2][1] = t * k.z * k.y + s * k.x;
	r.m[2][2] = c + t * k.z * k.z;
	return r;
}

mat4 m4_shear(const double s[6])
{
	mat4 r = m4_identity();
	r.m[0][1] = s[0]; /* xy */
	r.m[0][2] = s[1]; /* xz */
	r.m[1][0] = s[2]; /* yx */
	r.m[1][2] = s[3]; /* yz */
	r.m[2][0] = s[4]; /* zx */
	r.m[2][1] = s[5]; /* zy */
	return r;
}

mat4 m4_orient(vec3 d, double twist)
{
	/* Shortest arc from +Y to d: for d = (x,y,z), the axis is Y x d =
	 * (z, 0, -x) and cos = y. Written out to stay exact for d = +Y. */
	mat4 r = m4_identity();
	double c = d.y;
	if (c < -1.0 + 1e-12) {
		r = m4_rotate_x(RT_PI);
	} else {
		/* R = cI + [k]x + k k^T / (1 + c), with k = Y x d (unnormalised). */
		double kx = d.z, kz = -d.x, f = 1.0 / (1.0 + c);
		r.m[0][0] = c + kx * kx * f;
		r.m[0][1] = -kz;
		r.m[0][2] = kx * kz * f;
		r.m[1][0] = kz;
		r.m[1][1] = c;
		r.m[1][2] = -kx;
		r.m[2][0] = kz * kx * f;
		r.m[2][1] = kx;
		r.m[2][2] = c + kz * kz * f;
	}
	if (twist != 0.0)
		r = m4_mul(r, m4_rotate_y(twist));
	return r;
}

xform xf_identity(void)
{
	return (xform){m4_identity(), m4_identity()};
}

bool xf_make(mat4 m, xform *out)
{
	mat4 inv;
	if (!m4_invert(m, &inv))
		return false;
	out->m = m;
	out->inv = inv;
	return true;
}

xform xf_then(xform a, xform b)
{
	return (xform){m4_mul(b.m, a.m), m4_mul(a.inv, b.inv)};
}

box xf_box(const xform *x, box b)
{
	box r = box_empty();
	for (int i = 0; i < 8; i++) {
		vec3 p = {i & 1 ? b.hi.x : b.lo.x, i & 2 ? b.hi.y : b.lo.y, i & 4 ? b.hi.z : b.lo.z};
		r = box_add(r, m4_point(&x->m, p));
	}
	return r;
}
