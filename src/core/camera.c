/* rtsh — the camera's rays: the view a camera gives (world.h) and the ray
 * of each sample of each pixel (render.h, integrators.h). */
#include <math.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "integrators.h"

cam_view cam_view_make(const camera *c)
{
	cam_view v;
	v.pos = c->pos;
	v.fwd = v3_norm(c->dir);
	vec3 up_ref = fabs(v.fwd.y) > 0.999999 ? v3(0, 0, 1) : v3(0, 1, 0);
	v.right = v3_norm(v3_cross(up_ref, v.fwd));
	v.up = v3_cross(v.fwd, v.right);
	if (c->roll != 0) { /* the up turned towards the right by roll degrees */
		double a = deg_to_rad(c->roll), ca = cos(a), sa = sin(a);
		vec3 r = v.right, u = v.up;
		v.up = v3_add(v3_scale(u, ca), v3_scale(r, sa));
		v.right = v3_sub(v3_scale(r, ca), v3_scale(u, sa));
	}
	double fov = clampd(c->fov, 0.01, 179.99);
	v.tan_half = tan(deg_to_rad(fov) * 0.5);
	v.vertical = c->vertical;
	v.ortho = c->ortho > 0 ? c->ortho : 0;
	return v;
}

ray cam_ray(const cam_view *c, double fx, double fy, int w, int h)
{
	double x = 2.0 * fx / w - 1.0, y = 1.0 - 2.0 * fy / h;
	if (c->ortho > 0) { /* parallel rays from the image's rectangle */
		vec3 o = v3_add(c->pos, v3_add(v3_scale(c->right, x * c->ortho * w / h), v3_scale(c->up, y * c->ortho)));
		return (ray){o, c->fwd};
	}
	double u = x * c->tan_half, v = y * c->tan_half;
	if (c->vertical)
		u *= (double)w / h;
	else
		v *= (double)h / w;
	vec3 d = v3_add(c->fwd, v3_add(v3_scale(c->right, u), v3_scale(c->up, v)));
	return (ray){c->pos, v3_norm(d)};
}

/* The sampler is left positioned after the two dimensions that place the
 * sample in its pixel. */
ray camera_sample_ray(const world *w, const render_settings *s, bool sampled, int px, int py, int fw, int fh,
                      int sample, sampler *sp)
{
	uint64_t pixel = (uint64_t)py * (uint64_t)fw + (uint64_t)px;
	double u = 0.5, v = 0.5;
	/* Dimensions 0 and 1 place the sample in its pixel (one Whitted sample
	 * sits at the centre and needs no numbers); the path's numbers follow.
	 * Every pixel has its own scrambles, the same for all its samples, so
	 * that its first 2^k positions are stratified (sampler.h). */
	*sp = (sampler){0, 0, 0, 0};
	if (s->samples > 1 || sampled) {
		*sp = sampler_for(s->seed, pixel, (uint32_t)sample);
		if (s->samples > 1)
			samp_2d(sp, &u, &v);
		sp->dim = 2;
	}
	return cam_ray(&w->cam, px + u, py + v, fw, fh);
}

/* cam_ray through the centre of every pixel of the block [x0, x1) x
 * [y0, y1), row by row, into r (world.h). Through a pinhole cam_ray's terms
 * of a column (its x, u and right x u) and of a row (y, v, up x v) are the
 * same for every pixel of the column or row, so the block computes each
 * once, by cam_ray's own expressions in its order, and each pixel adds
 * them and normalises: the same bits, a quarter of the divisions. An
 * orthographic view, or a block wider or taller than CAM_BLOCK_MAX, goes
 * pixel by pixel. */
void cam_block_rays(const cam_view *c, int x0, int y0, int x1, int y1, int fw, int fh, ray *r)
{
	if (c->ortho > 0 || x1 - x0 > CAM_BLOCK_MAX || y1 - y0 > CAM_BLOCK_MAX) {
		for (int y = y0, i = 0; y < y1; y++)
			for (int x = x0; x < x1; x++, i++)
				r[i] = cam_ray(c, x + 0.5, y + 0.5, fw, fh);
		return;
	}
	vec3 col[CAM_BLOCK_MAX], row[CAM_BLOCK_MAX];
	for (int x = x0; x < x1; x++) {
		double fx = x + 0.5, u = (2.0 * fx / fw - 1.0) * c->tan_half;
		if (c->vertical)
			u *= (double)fw / fh;
		col[x - x0] = v3_scale(c->right, u);
	}
	for (int y = y0; y < y1; y++) {
		double fy = y + 0.5, v = (1.0 - 2.0 * fy / fh) * c->tan_half;
		if (!c->vertical)
			v *= (double)fh / fw;
		row[y - y0] = v3_scale(c->up, v);
	}
	for (int y = y0, i = 0; y < y1; y++) {
		int x = x0;
#if defined(__SSE2__)
		/* two pixels of the row at a time: the same operations in the
		 * same order per lane (additions, products, the square root and
		 * the division are each rounded once, as the scalar ones) */
		const vec3 rw = row[y - y0];
		const __m128d rx = _mm_set1_pd(rw.x), ry = _mm_set1_pd(rw.y), rz = _mm_set1_pd(rw.z);
		const __m128d fx = _mm_set1_pd(c->fwd.x), fy = _mm_set1_pd(c->fwd.y), fz = _mm_set1_pd(c->fwd.z);
		for (; x + 2 <= x1; x += 2, i += 2) {
			const vec3 *c0 = &col[x - x0], *c1 = c0 + 1;
			__m128d dx = _mm_add_pd(fx, _mm_add_pd(_mm_set_pd(c1->x, c0->x), rx));
			__m128d dy = _mm_add_pd(fy, _mm_add_pd(_mm_set_pd(c1->y, c0->y), ry));
			__m128d dz = _mm_add_pd(fz, _mm_add_pd(_mm_set_pd(c1->z, c0->z), rz));
			__m128d len = _mm_sqrt_pd(
				_mm_add_pd(_mm_add_pd(_mm_mul_pd(dx, dx), _mm_mul_pd(dy, dy)), _mm_mul_pd(dz, dz)));
			__m128d k = _mm_div_pd(_mm_set1_pd(1.0), len);
			dx = _mm_mul_pd(dx, k);
			dy = _mm_mul_pd(dy, k);
			dz = _mm_mul_pd(dz, k);
			r[i].o = c->pos;
			r[i + 1].o = c->pos;
			_mm_storel_pd(&r[i].d.x, dx);
			_mm_storeh_pd(&r[i + 1].d.x, dx);
			_mm_storel_pd(&r[i].d.y, dy);
			_mm_storeh_pd(&r[i + 1].d.y, dy);
			_mm_storel_pd(&r[i].d.z, dz);
			_mm_storeh_pd(&r[i + 1].d.z, dz);
		}
#endif
		for (; x < x1; x++, i++)
			r[i] = (ray){c->pos, v3_norm(v3_add(c->fwd, v3_add(col[x - x0], row[y - y0])))};
	}
}

/* One centred sample through a pinhole (Whitted's one sample per pixel):
 * cam_block_rays. Anything else goes pixel by pixel. */
void camera_block_rays(const world *w, const render_settings *s, bool sampled, int x0, int y0, int x1, int y1,
                       int fw, int fh, int sample, ray *r, sampler *sp)
{
	if (s->samples > 1 || sampled) {
		for (int y = y0, i = 0; y < y1; y++)
			for (int x = x0; x < x1; x++, i++)
				r[i] = camera_sample_ray(w, s, sampled, x, y, fw, fh, sample, &sp[i]);
		return;
	}
	cam_block_rays(&w->cam, x0, y0, x1, y1, fw, fh, r);
	for (int i = 0, n = (x1 - x0) * (y1 - y0); i < n; i++)
		sp[i] = (sampler){0, 0, 0, 0};
}
