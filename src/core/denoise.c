/* rtsh — the first-hit features and the edge-avoiding a-trous denoiser
 * (denoise.h). */
#include "rtsh/denoise.h"

#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "integrators.h"

/* --- features -------------------------------------------------------------- */

bool denoise_prepare(framebuffer *fb)
{
	if (fb->feat)
		return true;
	fb->feat = calloc((size_t)fb->w * (size_t)fb->h * DENOISE_FEATURES, sizeof *fb->feat);
	return fb->feat != NULL;
}

static double clamp01(double v)
{
	return v > 0.0 ? (v < 1.0 ? v : 1.0) : 0.0;
}

/* What the camera ray r shows first, in f (albedo, normal, depth). A
 * surface that is mostly a perfect mirror or glass is looked through (up to
 * four times): its features are those of the surface seen in it, the albedo
 * tinted by the mirror's or the glass's colour, the depth the length of the
 * whole path. Glass is followed along the refracted ray unless the
 * reflection is total. */
static void first_surface(const world *w, ray r, double f[7])
{
	vec3 tint = v3(1, 1, 1);
	double dist = 0.0;
	for (int k = 0;; k++) {
		hit h;
		if (!(k == 0 ? world_intersect_coherent : world_intersect)(w, &r, 0.0, INFINITY, &h)) {
			/* The sky: its own colour, no normal, no depth. */
			f[0] += clamp01(tint.x);
			f[1] += clamp01(tint.y);
			f[2] += clamp01(tint.z);
			return;
		}
		const mat_lin *m = &w->mats[h.mat]; /* a model's own material, too */
		bsdf b;
		bsdf_make(&b, m, &h, v3_neg(r.d));
		dist += h.t;
		vec3 a, tt = v3(0, 0, 0), dir = v3(0, 0, 0);
		int follow = bsdf_features(&b, &a, &tt, &dir);
		if (follow == 0 || k == 3 || m->emission.x + m->emission.y + m->emission.z > 0.0) {
			a = v3_add(a, m->emission); /* a lamp is white */
			a = v3_mul(a, tint);
			f[0] += clamp01(a.x);
			f[1] += clamp01(a.y);
			f[2] += clamp01(a.z);
			f[3] += b.n.x;
			f[4] += b.n.y;
			f[5] += b.n.z;
			f[6] += dist;
			return;
		}
		tint = v3_mul(tint, tt);
		if (follow == 1)
			r = (ray){offset_point(w, h.p, b.n), v3_sub(v3_scale(b.n, 2.0 * b.cos_o), b.wo)};
		else
			r = (ray){offset_point(w, h.p, v3_neg(b.n)), v3_norm(dir)};
	}
}

/* Albedo below this is not divided out (a black surface has no lighting to
 * recover). */
#define ALBEDO_MIN 0.02

static inline double albedo_divisor(double a)
{
	return a > ALBEDO_MIN ? a : 1.0;
}

void denoise_sample(const world *w, ray r, double *acc)
{
	double f[7] = {0};
	first_surface(w, r, f);
	for (int k = 0; k < 7; k++)
		acc[k] += f[k];
	acc[8] += f[0] * f[0] + f[1] * f[1] + f[2] * f[2];
	acc[9] += f[6] * f[6];
}

/* Whether the first hits of a pixel's samples differ: albedo or depth
 * spread, or normals that do not agree (their mean is shorter than one). */
static bool features_vary(const float *f)
{
	if (f[6] <= 0.0f)
		return false; /* all sky */
	double a2 = (double)f[0] * f[0] + (double)f[1] * f[1] + (double)f[2] * f[2];
	double n2 = (double)f[3] * f[3] + (double)f[4] * f[4] + (double)f[5] * f[5];
	double va = f[8] - a2, vz = f[9] - (double)f[6] * f[6];
	return va > 1e-4 || vz > 1e-4 * (double)f[6] * f[6] || n2 < 0.998;
}

void denoise_features(const world *w, const render_settings *s, int px, int py, int fw, int fh,
                      int begin, int end, double sq, const double *acc, float *f)
{
	f[7] = (float)(((double)f[7] * begin + sq) / end);
	int n0 = begin < DENOISE_FEATURE_SAMPLES ? begin : DENOISE_FEATURE_SAMPLES;
	int n1 = end < DENOISE_FEATURE_SAMPLES ? end : DENOISE_FEATURE_SAMPLES;
	if (n1 <= n0)
		return;
	for (int k = 0; k < DENOISE_FEATURES; k++)
		if (k != 7)
			f[k] = (float)(((double)f[k] * n0 + acc[k]) / n1);
	if (n1 < DENOISE_FEATURE_SAMPLES || !features_vary(f))
		return;
	/* An edge: more camera positions, the radiance samples' own. */
	double sum[DENOISE_ACC];
	for (int k = 0; k < DENOISE_ACC; k++)
		sum[k] = (double)f[k] * n1;
	for (int k = n1; k < DENOISE_EDGE_SAMPLES; k++) {
		double one[7] = {0};
		first_surface(w, render_sample_ray(w, s, px, py, fw, fh, k), one);
		for (int q = 0; q < 7; q++)
			sum[q] += one[q];
		sum[8] += one[0] * one[0] + one[1] * one[1] + one[2] * one[2];
		sum[9] += one[6] * one[6];
	}
	for (int k = 0; k < DENOISE_FEATURES; k++)
		if (k != 7)
			f[k] = (float)(sum[k] / DENOISE_EDGE_SAMPLES);
}

/* --- the filter ------------------------------------------------------------ */

/* The constants were tuned at 160x90, 8 samples, against 4096-sample
 * references of scenes/cornell.rt (tests/unit/test_denoise.c),
 * sky-spheres.rt, final.rt and metal-fuzz.rt, three seeds each. */
#define LEVELS 5
/* Edge-stopping strengths: brightness in standard deviations of its noise
 * (SVGF's sigma_l) on the first pass, narrowed on each later pass (Dammertz
 * et al. halve it); normals and albedo as squared distances; depth as the
 * distance off the plane that the pixel's depth and gradient predict, in
 * shares of its depth. */
#define SIGMA_L 8.0f
#define SIGMA_L_DECAY 0.6f
#define SIGMA_N2 0.08f
#define SIGMA_A2 0.01f
#define SIGMA_Z 0.02f
/* Fireflies: a pixel brighter than its same-surface 3x3 neighbours' mean by
 * more than this many of their standard deviations is brought down to it. */
#define FIREFLY_K 4.0f

/* What every tap reads (32 bytes: two to a cache line)... */
typedef struct guide {
	float f[6];   /* albedo / sqrt(SIGMA_A2), normal / sqrt(SIGMA_N2) */
	float z;      /* depth */
	float unused;
} guide;

/* ...and what only the pixel itself does. */
typedef struct pixel_info {
	float gx, gy; /* the depth's gradient per pixel */
	float am[3];  /* the albedo the radiance was divided by */
	bool mixed;   /* its features vary inside the pixel (features_vary) */
} pixel_info;

/* Radiance over albedo, and its estimated noise variance. */
typedef struct texel {
	float c[3];
	float var;
} texel;

typedef struct job {
	const framebuffer *fb;
	guide *g;
	pixel_info *px;
	texel *buf[2];
	float *out;
	int threads;            /* workers sharing the rows, this thread included */
	pthread_barrier_t bar;  /* between the passes */
	pthread_mutex_t lock;
	pthread_cond_t go_cond;
	int go;                 /* 0 wait, 1 work, -1 leave without working */
} job;

static inline float lum(const float *c)
{
	return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2];
}

/* exp(-x) for x >= 0 as (1 - x/16)^16 (its limit definition), 0 from
 * x = 16 on: within 0.03 of it everywhere, four multiplications. */
static inline float exp_fast(float x)
{
	float t = 1.0f - x * (1.0f / 16);
	t = t > 0.0f ? t : 0.0f;
	t *= t;
	t *= t;
	t *= t;
	return t * t;
}

static float depth_slope(const float *z, int x, int w, int stride)
{
	float here = z[0];
	float back = x > 0 ? here - z[-stride] : INFINITY;
	float fwd = x < w - 1 ? z[stride] - here : INFINITY;
	float g = fabsf(back) < fabsf(fwd) ? back : fwd;
	return isfinite(g) ? g : 0.0f;
}

/* Features, demodulated radiance and its variance for rows [y0, y1). */
static void setup_rows(job *j, int y0, int y1)
{
	const framebuffer *fb = j->fb;
	int w = fb->w, h = fb->h;
	for (int y = y0; y < y1; y++)
		for (int x = 0; x < w; x++) {
			size_t i = (size_t)y * w + x;
			const float *f = fb->feat + i * DENOISE_FEATURES;
			guide *g = &j->g[i];
			pixel_info *p = &j->px[i];
			for (int k = 0; k < 3; k++) {
				g->f[k] = f[k] * (1.0f / sqrtf(SIGMA_A2));
				g->f[3 + k] = f[3 + k] * (1.0f / sqrtf(SIGMA_N2));
				p->am[k] = (float)albedo_divisor(f[k]);
			}
			g->z = f[6];
			g->unused = 0;
			p->mixed = features_vary(f);
			p->gx = depth_slope(f + 6, x, w, DENOISE_FEATURES);
			p->gy = depth_slope(f + 6, y, h, DENOISE_FEATURES * w);
			texel *t = &j->buf[0][i];
			for (int k = 0; k < 3; k++) {
				float c = fb->rgb[i * 3 + k];
				t->c[k] = isfinite(c) ? c / p->am[k] : 0.0f;
			}
		}
}

/* The brightness of the 3x3 neighbours of (x, y) in src that lie on the
 * same surface: those whose features k0..5 are within a squared distance
 * of 4 of the pixel's own (k0 = 3: the normals alone; 0: all of them).
 * Sums the brightness and its square into s1 and s2 and counts them in n;
 * the pixel itself counts when with_self. */
static void neighbours(const job *j, const texel *src, int x, int y, int k0, bool with_self,
                       float *s1, float *s2, float *n)
{
	int w = j->fb->w, h = j->fb->h;
	const guide *gp = &j->g[(size_t)y * w + x];
	*s1 = *s2 = *n = 0;
	for (int dy = -1; dy <= 1; dy++) {
		int qy = y + dy;
		if (qy < 0 || qy >= h)
			continue;
		for (int dx = -1; dx <= 1; dx++) {
			int qx = x + dx;
			if (qx < 0 || qx >= w || (!with_self && dx == 0 && dy == 0))
				continue;
			size_t q = (size_t)qy * w + qx;
			const guide *gq = &j->g[q];
			float d = 0; /* the features' squared distance, scaled */
			for (int k = k0; k < 6; k++)
				d += (gp->f[k] - gq->f[k]) * (gp->f[k] - gq->f[k]);
			if (d > 4.0f)
				continue;
			float l = lum(src[q].c);
			*s1 += l;
			*s2 += l * l;
			*n += 1;
		}
	}
}

/* The noise variance of each pixel's brightness: from its own samples
 * (the mean of their squares), or with a single sample the variance over
 * its 3x3 neighbours on the same surface (a spatial estimate, as SVGF's
 * when a pixel has no history). */
static void variance_rows(job *j, int y0, int y1)
{
	const framebuffer *fb = j->fb;
	int w = fb->w;
	texel *t = j->buf[1];
	for (int y = y0; y < y1; y++)
		for (int x = 0; x < w; x++) {
			size_t i = (size_t)y * w + x;
			if (fb->spp >= 2) {
				/* The variance of the pixel's mean, from its own samples,
				 * over the albedo squared like its radiance. */
				float m1 = lum(fb->rgb + i * 3), m2 = fb->feat[i * DENOISE_FEATURES + 7];
				float am = lum(j->px[i].am);
				float v = (m2 - m1 * m1) / (float)(fb->spp - 1) / (am * am);
				t[i].var = v > 0 ? v : 0;
				continue;
			}
			float s1, s2, n;
			neighbours(j, t, x, y, 3, true, &s1, &s2, &n);
			float mean = s1 / n, var = s2 / n - mean * mean;
			/* n samples estimate it with n - 1 degrees of freedom */
			t[i].var = n > 1 ? (var > 0 ? var : 0) * n / (n - 1) : 0.0f;
		}
}

/* Fireflies brought down (FIREFLY_K), src to dst. */
static void clamp_rows(job *j, const texel *src, texel *dst, int y0, int y1)
{
	int w = j->fb->w;
	for (int y = y0; y < y1; y++)
		for (int x = 0; x < w; x++) {
			size_t i = (size_t)y * w + x;
			float s1, s2, n;
			neighbours(j, src, x, y, 0, false, &s1, &s2, &n);
			dst[i] = src[i];
			if (n < 3)
				continue;
			float mean = s1 / n, var = s2 / n - mean * mean;
			float limit = mean + FIREFLY_K * sqrtf(var > 0 ? var : 0);
			float l = lum(src[i].c);
			if (l > limit && l > 0) {
				float k = limit / l;
				dst[i].c[0] *= k;
				dst[i].c[1] *= k;
				dst[i].c[2] *= k;
			}
		}
}

/* The 3x3 B-spline kernel (1 2 1)/4 in each direction. Dammertz et al. and
 * SVGF use the 5x5 one (1 4 6 4 1)/16; on cornell.rt at 160x90 the 3x3 one
 * with 5 passes (taps up to 31 pixels away) gave the same error within 1%
 * in 40% of the time. */
#define KR 1
/* The first-order fit's slopes are held back by a ridge of this share of
 * the weights (a plane through few taps would otherwise swing widely). */
#define LWR_RIDGE 0.15f
/* The first pass (taps next to each other) keeps the weighted mean: a
 * plane through adjacent noisy pixels follows their noise. */
#define LWR_STEP 2
static const float kernel2[2 * KR + 1][2 * KR + 1] = {
	{1.0f / 16, 1.0f / 8, 1.0f / 16}, {1.0f / 8, 1.0f / 4, 1.0f / 8}, {1.0f / 16, 1.0f / 8, 1.0f / 16}};

/* One a-trous pass with taps `step` pixels apart, rows [y0, y1) from src to
 * dst. */
static void atrous_rows(job *j, const texel *src, texel *dst, int step, int y0, int y1)
{
	float sigma_l = SIGMA_L;
	for (int s = 1; s < step; s *= 2)
		sigma_l *= SIGMA_L_DECAY;
	const framebuffer *fb = j->fb;
	int w = fb->w, h = fb->h;
	for (int y = y0; y < y1; y++)
		for (int x = 0; x < w; x++) {
			size_t i = (size_t)y * w + x;
			const guide *gp = &j->g[i];
			const texel *tp = &src[i];
			/* the variance, smoothed by a 3x3 Gaussian (SVGF) */
			float gv = 0, gw = 0;
			if (x > 0 && x < w - 1 && y > 0 && y < h - 1) {
				const texel *a = tp - w, *c = tp + w;
				gv = 0.0625f * (a[-1].var + a[1].var + c[-1].var + c[1].var) +
				     0.125f * (a[0].var + c[0].var + tp[-1].var + tp[1].var) + 0.25f * tp->var;
				gw = 1.0f;
			} else {
				for (int dy = -1; dy <= 1; dy++)
					for (int dx = -1; dx <= 1; dx++) {
						int qx = x + dx, qy = y + dy;
						if (qx < 0 || qx >= w || qy < 0 || qy >= h)
							continue;
						float k = (dx ? 0.25f : 0.5f) * (dy ? 0.25f : 0.5f);
						gv += k * src[(size_t)qy * w + qx].var;
						gw += k;
					}
			}
			if (gv <= 0.0f) {
				/* no noise around: nothing to filter */
				dst[i] = *tp;
				continue;
			}
			float lp = lum(tp->c);
			float inv_l = 1.0f / (sigma_l * sqrtf(gv / gw) + 1e-6f);
			/* Depth: how far the tap lies off the plane through this pixel
			 * along its depth gradient, against a share of the depth. */
			float inv_z = 1.0f / (SIGMA_Z * gp->z + 1e-6f);
			float gxs = j->px[i].gx * (float)step, gys = j->px[i].gy * (float)step;
			int lo = -KR, hi = KR;
			while (x + lo * step < 0)
				lo++;
			while (x + hi * step >= w)
				hi--;
			/* the taps: weight, offset (in steps) and texel; and the
			 * weights' moments for the first-order fit */
			float tw[9];
			int tx[9], ty[9];
			const texel *tt[9];
			tw[0] = kernel2[KR][KR];
			tx[0] = ty[0] = 0;
			tt[0] = tp;
			int nt = 1;
			float s0 = tw[0], sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
			for (int dy = -KR; dy <= KR; dy++) {
				int qy = y + dy * step;
				if (qy < 0 || qy >= h)
					continue;
				const guide *gr = &j->g[(size_t)qy * w + x];
				const texel *tr = &src[(size_t)qy * w + x];
				float zrow = gp->z + gys * (float)dy;
				for (int dx = lo; dx <= hi; dx++) {
					if (dx == 0 && dy == 0)
						continue;
					const guide *gq = gr + dx * step;
					const texel *tq = tr + dx * step;
					float e = 0;
					for (int k = 0; k < 6; k++)
						e += (gp->f[k] - gq->f[k]) * (gp->f[k] - gq->f[k]);
					e += fabsf(gq->z - (zrow + gxs * (float)dx)) * inv_z;
					e += fabsf(lp - lum(tq->c)) * inv_l;
					float wt = kernel2[dy + KR][dx + KR] * exp_fast(e);
					tw[nt] = wt;
					tx[nt] = dx;
					ty[nt] = dy;
					tt[nt] = tq;
					nt++;
					/* offsets are -1, 0 or 1: their squares are 0 or 1 */
					s0 += wt;
					sx += (float)dx * wt;
					sy += (float)dy * wt;
					sxx += dx ? wt : 0.0f;
					syy += dy ? wt : 0.0f;
					sxy += (float)(dx * dy) * wt;
				}
			}
			/* Zero order: the weighted mean. First order (a plane through
			 * the taps, least squares, its value at the centre): the same
			 * where the weights are symmetric, unbiased on a slope where an
			 * edge cuts them off on one side. */
			float ca = 1.0f / s0, cb = 0, cc = 0;
			if (step >= LWR_STEP) {
				float ridge = LWR_RIDGE * s0;
				sxx += ridge;
				syy += ridge;
				float c00 = sxx * syy - sxy * sxy, c01 = sxy * sy - sx * syy, c02 = sx * sxy - sxx * sy;
				float det = s0 * c00 + sx * c01 + sy * c02;
				if (det > 1e-6f * s0 * s0 * s0) {
					ca = c00 / det;
					cb = c01 / det;
					cc = c02 / det;
				}
			}
			/* the result: sum l_t c_t with l_t = w_t (ca + cb x_t + cc y_t),
			 * its variance sum l_t^2 var_t */
			float sum[3] = {0, 0, 0}, vsum = 0;
			for (int t = 0; t < nt; t++) {
				float l = tw[t] * (ca + cb * (float)tx[t] + cc * (float)ty[t]);
				sum[0] += l * tt[t]->c[0];
				sum[1] += l * tt[t]->c[1];
				sum[2] += l * tt[t]->c[2];
				vsum += l * l * tt[t]->var;
			}
			texel *o = &dst[i];
			o->c[0] = sum[0] > 0 ? sum[0] : 0;
			o->c[1] = sum[1] > 0 ? sum[1] : 0;
			o->c[2] = sum[2] > 0 ? sum[2] : 0;
			o->var = vsum;
		}
}

/* The filtered lighting times the albedo again, into dst (radiance and
 * the variance of its brightness). */
static void finish_rows(job *j, const texel *src, texel *dst, int y0, int y1)
{
	int w = j->fb->w;
	for (int y = y0; y < y1; y++)
		for (int x = 0; x < w; x++) {
			size_t i = (size_t)y * w + x;
			for (int k = 0; k < 3; k++)
				dst[i].c[k] = src[i].c[k] * j->px[i].am[k];
			float am = lum(j->px[i].am);
			dst[i].var = src[i].var * am * am;
		}
}

/* The regression may move a pixel by at most this many standard
 * deviations of its remaining noise. */
#define REG_K 1.0f
#define RR 1        /* the regression's window: (2 RR + 1)^2 pixels */
#define NR 8        /* its unknowns: a constant and 7 feature slopes */

/* Cholesky solve of the NR x NR system a x = b (a positive definite; a is
 * overwritten). False when it is not. */
static bool solve(float a[NR][NR], float b[NR][3], float x[NR][3])
{
	for (int c = 0; c < NR; c++) {
		float d = a[c][c];
		for (int k = 0; k < c; k++)
			d -= a[c][k] * a[c][k];
		if (!(d > 1e-12f))
			return false;
		d = sqrtf(d);
		a[c][c] = d;
		for (int r = c + 1; r < NR; r++) {
			float v = a[r][c];
			for (int k = 0; k < c; k++)
				v -= a[r][k] * a[c][k];
			a[r][c] = v / d;
		}
	}
	for (int ch = 0; ch < 3; ch++) {
		float z[NR];
		for (int r = 0; r < NR; r++) {
			float v = b[r][ch];
			for (int k = 0; k < r; k++)
				v -= a[r][k] * z[k];
			z[r] = v / a[r][r];
		}
		for (int r = NR - 1; r >= 0; r--) {
			float v = z[r];
			for (int k = r + 1; k < NR; k++)
				v -= a[k][r] * x[k][ch];
			x[r][ch] = v / a[r][r];
		}
	}
	return true;
}

/* A pixel whose features vary inside it (part one surface, part another):
 * a first-order regression of the filtered radiance on the features over
 * its 3x3 window, each pixel weighted by the inverse of its remaining
 * noise, evaluated at the pixel's own features, so that it gets the mix
 * its features say. False when the system is singular. */
static bool regress_pixel(const job *j, const texel *src, int x, int y, float o[3])
{
	int w = j->fb->w, h = j->fb->h;
	size_t i = (size_t)y * w + x;
	const guide *gp = &j->g[i];
	float a[NR][NR] = {{0}}, b[NR][3] = {{0}}, beta[NR][3];
	float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {0, 0, 0};
	float inv_z = 1.0f / (gp->z + 1e-6f);
	for (int dy = -RR; dy <= RR; dy++)
		for (int dx = -RR; dx <= RR; dx++) {
			int qx = x + dx, qy = y + dy;
			if (qx < 0 || qx >= w || qy < 0 || qy >= h)
				continue;
			size_t q = (size_t)qy * w + qx;
			const guide *gq = &j->g[q];
			float v[NR];
			v[0] = 1;
			for (int k = 0; k < 6; k++)
				v[1 + k] = gq->f[k] - gp->f[k];
			v[7] = (gq->z - gp->z) * inv_z * 10.0f;
			float wt = 1.0f / (src[q].var + 1e-6f);
			for (int ch = 0; ch < 3; ch++) {
				float c = src[q].c[ch];
				lo[ch] = c < lo[ch] ? c : lo[ch];
				hi[ch] = c > hi[ch] ? c : hi[ch];
			}
			for (int r = 0; r < NR; r++) {
				for (int c = 0; c <= r; c++)
					a[r][c] += wt * v[r] * v[c];
				for (int ch = 0; ch < 3; ch++)
					b[r][ch] += wt * v[r] * src[q].c[ch];
			}
		}
	float ridge = a[0][0] * 1e-3f; /* slopes held back a little */
	for (int r = 1; r < NR; r++)
		a[r][r] += ridge;
	if (!solve(a, b, beta))
		return false;
	/* Within the window's range; and a move the pixel's remaining noise
	 * cannot explain (more than REG_K standard deviations of its
	 * brightness) is cut down to that. */
	float r[3];
	for (int k = 0; k < 3; k++)
		r[k] = beta[0][k] < lo[k] ? lo[k] : beta[0][k] > hi[k] ? hi[k] : beta[0][k];
	float d = fabsf(lum(r) - lum(src[i].c));
	float lim = REG_K * sqrtf(src[i].var), t = d > lim ? lim / d : 1.0f;
	for (int k = 0; k < 3; k++)
		o[k] = src[i].c[k] + t * (r[k] - src[i].c[k]);
	return true;
}

/* The final radiance into out: mixed pixels regressed, the others as
 * filtered. */
static void regress_rows(job *j, const texel *src, int y0, int y1)
{
	int w = j->fb->w;
	for (int y = y0; y < y1; y++)
		for (int x = 0; x < w; x++) {
			size_t i = (size_t)y * w + x;
			float *o = j->out + i * 3;
			if (!j->px[i].mixed || !regress_pixel(j, src, x, y, o))
				for (int k = 0; k < 3; k++)
					o[k] = src[i].c[k];
		}
}

static void run_rows(job *j, int y0, int y1)
{
	setup_rows(j, y0, y1);
	if (j->threads > 1)
		pthread_barrier_wait(&j->bar);
	clamp_rows(j, j->buf[0], j->buf[1], y0, y1);
	if (j->threads > 1)
		pthread_barrier_wait(&j->bar);
	variance_rows(j, y0, y1);
	for (int l = 0; l < LEVELS; l++) {
		if (j->threads > 1)
			pthread_barrier_wait(&j->bar);
		atrous_rows(j, j->buf[(l + 1) & 1], j->buf[l & 1], 1 << l, y0, y1);
	}
	const texel *last = j->buf[(LEVELS + 1) & 1];
	texel *spare = j->buf[LEVELS & 1];
	if (j->threads > 1)
		pthread_barrier_wait(&j->bar); /* spare was the last pass's source */
	finish_rows(j, last, spare, y0, y1);
	if (j->threads > 1)
		pthread_barrier_wait(&j->bar); /* out may be fb->rgb, read by setup */
	regress_rows(j, spare, y0, y1);
}

typedef struct worker_arg {
	job *j;
	int index;
} worker_arg;

static int band(const job *j, int t)
{
	return (int)((long)j->fb->h * t / j->threads);
}

/* A worker waits until every thread has started and the rows are shared
 * out (the barrier needs the final count), then does its band. */
static void *worker(void *arg)
{
	worker_arg *a = arg;
	job *j = a->j;
	pthread_mutex_lock(&j->lock);
	while (j->go == 0)
		pthread_cond_wait(&j->go_cond, &j->lock);
	int go = j->go;
	pthread_mutex_unlock(&j->lock);
	if (go > 0)
		run_rows(j, band(j, a->index), band(j, a->index + 1));
	return NULL;
}

bool denoise_image(const framebuffer *fb, float *out, int threads)
{
	int w = fb->w, h = fb->h;
	size_t n = (size_t)w * (size_t)h;
	if (!fb->feat)
		return false;
	if (threads < 1)
		threads = 1;
	if (threads > h)
		threads = h;
	job j = {.fb = fb, .out = out};
	j.g = malloc(n * sizeof *j.g);
	j.px = malloc(n * sizeof *j.px);
	j.buf[0] = malloc(n * sizeof *j.buf[0]);
	j.buf[1] = malloc(n * sizeof *j.buf[1]);
	pthread_t *tid = malloc((size_t)threads * sizeof *tid);
	worker_arg *args = malloc((size_t)threads * sizeof *args);
	bool ok = j.g && j.px && j.buf[0] && j.buf[1] && tid && args;
	if (ok) {
		pthread_mutex_init(&j.lock, NULL);
		pthread_cond_init(&j.go_cond, NULL);
		int started = 0;
		for (int t = 1; t < threads; t++) {
			args[t] = (worker_arg){&j, started + 1};
			if (pthread_create(&tid[t], NULL, worker, &args[t]) != 0)
				break;
			started++;
		}
		j.threads = started + 1;
		int go = 1;
		if (j.threads > 1 && pthread_barrier_init(&j.bar, NULL, (unsigned)j.threads) != 0) {
			go = -1; /* the workers leave; this thread does it all */
			j.threads = 1;
		}
		pthread_mutex_lock(&j.lock);
		j.go = go;
		pthread_cond_broadcast(&j.go_cond);
		pthread_mutex_unlock(&j.lock);
		run_rows(&j, 0, band(&j, 1));
		for (int t = 1; t <= started; t++)
			pthread_join(tid[t], NULL);
		if (j.threads > 1)
			pthread_barrier_destroy(&j.bar);
		pthread_mutex_destroy(&j.lock);
		pthread_cond_destroy(&j.go_cond);
	}
	free(j.g);
	free(j.px);
	free(j.buf[0]);
	free(j.buf[1]);
	free(tid);
	free(args);
	return ok;
}
