/* rtsh — the HDR sky (envmap.h).
 *
 * Directions map to the image as on a sphere (surface.c): u = 1/2 +
 * atan2(x, -z) / 2pi + rotation / 360, v = 1/2 + asin(y) / pi, v = 1 the
 * top row. Sampling follows pbrt (Pharr, Jakob & Humphreys, 4th ed.,
 * 12.5.2, "Image infinite lights"): a piecewise-constant 2D distribution
 * over the texels of a mip level at most 1024 wide, each texel's weight
 * its luminance times sin(theta) (the solid angle a texel row spans), a
 * marginal distribution over rows and a conditional one per row, each
 * inverted by binary search; a picked (u, v) has density p(u, v) in the
 * unit square and p(u, v) / (2 pi^2 sin theta) per steradian.
 */
#include "envmap.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rtsh/memory.h"
#include "rtsh/texture.h"

struct envmap {
	texture *tex;
	double strength, rot; /* rotation in u units */
	int w, h;             /* of the sampling level */
	double *marg;         /* h + 1: cumulative row weights, marg[h] = 1 */
	double *cond;         /* h rows of w + 1: cumulative texel weights */
	double *rowsum;       /* h: a row's share of the total */
	double *texw;         /* w * h: a texel's weight / total */
};

static const double PI = 3.14159265358979323846;

envmap *envmap_new(const char *path, double strength, double rotation_deg, const atomic_bool *cancel, rt_error *err)
{
	envmap *e = calloc(1, sizeof *e);
	if (!e) {
		rt_error_set(err, "out of memory loading the sky");
		return NULL;
	}
	image_budget_exempt(true); /* the previewer's budget is for textures */
	e->tex = texture_cache_get(path, false, cancel, err);
	image_budget_exempt(false);
	if (!e->tex) {
		free(e);
		return NULL;
	}
	e->strength = strength;
	e->rot = rotation_deg / 360.0;
	int lv = 0;
	while (lv + 1 < e->tex->nlevels && e->tex->level[lv].w > 1024)
		lv++;
	const tex_level *l = &e->tex->level[lv];
	e->w = l->w;
	e->h = l->h;
	size_t n = (size_t)l->w * (size_t)l->h;
	e->marg = malloc(((size_t)l->h + 1) * sizeof *e->marg);
	e->cond = malloc((size_t)l->h * ((size_t)l->w + 1) * sizeof *e->cond);
	e->rowsum = malloc((size_t)l->h * sizeof *e->rowsum);
	e->texw = malloc(n * sizeof *e->texw);
	if (!e->marg || !e->cond || !e->rowsum || !e->texw) {
		envmap_free(e);
		rt_error_set(err, "%s: out of memory building the sky's distribution", path);
		return NULL;
	}
	double total = 0;
	for (int y = 0; y < l->h; y++) {
		if (cancel && atomic_load_explicit(cancel, memory_order_relaxed)) { /* Ctrl-C */
			envmap_free(e);
			rt_error_set(err, "stopped");
			return NULL;
		}
		double st = sin(PI * (y + 0.5) / l->h);
		double *c = &e->cond[(size_t)y * (l->w + 1)];
		c[0] = 0;
		for (int x = 0; x < l->w; x++) {
			const float *p = &l->rgb[3 * ((size_t)y * l->w + x)];
			double lum = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
			double wt = (lum > 0 && isfinite(lum) ? lum : 0) * st;
			e->texw[(size_t)y * l->w + x] = wt;
			c[x + 1] = c[x] + wt;
		}
		e->rowsum[y] = c[l->w];
		total += c[l->w];
	}
	if (!(total > 0)) {
		/* a black sky: uniform, so the densities stay defined */
		for (size_t i = 0; i < n; i++)
			e->texw[i] = sin(PI * ((double)(i / (size_t)l->w) + 0.5) / l->h);
		total = 0;
		for (int y = 0; y < l->h; y++) {
			double *c = &e->cond[(size_t)y * (l->w + 1)];
			for (int x = 0; x < l->w; x++)
				c[x + 1] = c[x] + e->texw[(size_t)y * l->w + x];
			e->rowsum[y] = c[l->w];
			total += c[l->w];
		}
	}
	e->marg[0] = 0;
	for (int y = 0; y < l->h; y++) {
		double *c = &e->cond[(size_t)y * (l->w + 1)];
		for (int x = 1; x <= l->w; x++)
			c[x] = e->rowsum[y] > 0 ? c[x] / e->rowsum[y] : (double)x / l->w;
		e->marg[y + 1] = e->marg[y] + e->rowsum[y] / total;
		e->rowsum[y] /= total;
	}
	e->marg[l->h] = 1;
	for (size_t i = 0; i < n; i++)
		e->texw[i] /= total;
	return e;
}

void envmap_free(envmap *e)
{
	if (!e)
		return;
	texture_cache_put(e->tex);
	mem_free_all(e->marg, e->cond, e->rowsum, e->texw, e);
}

size_t envmap_memory(const envmap *e)
{
	return sizeof *e + ((size_t)e->h + 1 + (size_t)e->h * ((size_t)e->w + 2) + (size_t)e->w * e->h) * sizeof(double);
}

static void dir_uv(const envmap *e, vec3 d, double *u, double *v)
{
	double len = v3_len(d);
	double y = len > 0 ? d.y / len : 0;
	*u = 0.5 + atan2(d.x, -d.z) / (2 * PI) + e->rot;
	*u -= floor(*u);
	*v = 0.5 + asin(y < -1 ? -1 : y > 1 ? 1 : y) / PI;
}

vec3 envmap_eval(const envmap *e, vec3 d)
{
	double u, v;
	dir_uv(e, d, &u, &v);
	return v3_scale(texture_lookup(e->tex, u, v, 0), e->strength);
}

double envmap_pdf(const envmap *e, vec3 d)
{
	double u, v;
	dir_uv(e, d, &u, &v);
	int x = (int)(u * e->w), y = (int)((1 - v) * e->h);
	x = x < 0 ? 0 : x >= e->w ? e->w - 1 : x;
	y = y < 0 ? 0 : y >= e->h ? e->h - 1 : y;
	double st = sin(PI * (1 - v));
	if (!(st > 0))
		return 0;
	double p_uv = e->texw[(size_t)y * e->w + x] * (double)e->w * (double)e->h;
	return p_uv / (2 * PI * PI * st);
}

/* the first index i in [0, n) with c[i + 1] > x (c[0] = 0, c[n] = 1) */
static int find(const double *c, int n, double x)
{
	int lo = 0, hi = n - 1;
	while (lo < hi) {
		int mid = (lo + hi) / 2;
		if (c[mid + 1] > x)
			hi = mid;
		else
			lo = mid + 1;
	}
	return lo;
}

vec3 envmap_sample(const envmap *e, double u1, double u2, double *pdf)
{
	int y = find(e->marg, e->h, u1);
	const double *c = &e->cond[(size_t)y * (e->w + 1)];
	int x = find(c, e->w, u2);
	/* the place inside the texel, from what is left of the numbers */
	double dy = e->marg[y + 1] - e->marg[y], dx = c[x + 1] - c[x];
	double fy = dy > 0 ? (u1 - e->marg[y]) / dy : 0.5, fx = dx > 0 ? (u2 - c[x]) / dx : 0.5;
	double u = (x + fx) / e->w, v = 1 - (y + fy) / e->h;
	double phi = (u - 0.5 - e->rot) * 2 * PI, theta = (v - 0.5) * PI; /* latitude */
	double ct = cos(theta);
	vec3 d = v3(sin(phi) * ct, sin(theta), -cos(phi) * ct);
	double st = sin(PI * (1 - v));
	double p_uv = e->texw[(size_t)y * e->w + x] * (double)e->w * (double)e->h;
	*pdf = st > 0 ? p_uv / (2 * PI * PI * st) : 0;
	return d;
}
