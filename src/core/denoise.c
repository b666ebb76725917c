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
		if (!world_intersect(w, &r, 0.0, INFINITY, &h)) {
			/* The sky: its own colour, no normal, no depth. */
			f[0] += clamp01(tint.x);
			f[1] += clamp01(tint.y);
			f[2] += clamp01(tint.z);
			return;
		}
		const mat_lin *m = &w->mats[h.object];
		bsdf b;
		bsdf_make(&b, m, &h, v3_neg(r.d));
		dist += h.t;
		double mirror = b.nm < 0.0 ? b.p[2] : 0.0, delta = mirror + b.p[3];
		if (delta < 0.5 || k == 3 || m->emission.x + m->emission.y + m->emission.z > 0.0) {
			vec3 a = v3_add(v3_add(b.kd, b.ks), v3_add(b.km, v3_scale(b.kt, b.wg)));
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
		vec3 refl = v3_sub(v3_scale(b.n, 2.0 * b.cos_o), b.wo);
		if (mirror >= b.p[3]) {
			tint = v3_mul(tint, b.km);
			r = (ray){offset_point(w, h.p, b.n), refl};
			continue;
		}
		/* Snell's law in vector form (pbrt 4th ed. 9.3.2). */
		double eta = b.front ? b.ior : 1.0 / b.ior;
		double sin2_t = (1.0 - b.cos_o * b.cos_o) / (eta * eta);
		tint = v3_mul(tint, sin2_t >= 1.0 ? v3_splat(b.wg) : v3_scale(b.kt, b.wg));
		if (sin2_t >= 1.0) {
			r = (ray){offset_point(w, h.p, b.n), refl};
		} else {
			double cos_t = sqrt(1.0 - sin2_t);
			vec3 t = v3_add(v3_scale(b.wo, -1.0 / eta), v3_scale(b.n, b.cos_o / eta - cos_t));
			r = (ray){offset_point(w, h.p, v3_neg(b.n)), v3_norm(t)};
		}
	}
}

void denoise_features(const world *w, int px, int py, int fw, int fh, int begin, int end, double sq,
                      float *f)
{
	f[7] = (float)(((double)f[7] * begin + sq) / end);
	int n0 = begin < DENOISE_FEATURE_SAMPLES ? begin : DENOISE_FEATURE_SAMPLES;
	int n1 = end < DENOISE_FEATURE_SAMPLES ? end : DENOISE_FEATURE_SAMPLES;
	if (n1 <= n0)
		return;
	double acc[7];
	for (int k = 0; k < 7; k++)
		acc[k] = n0 > 0 ? (double)f[k] * n0 : 0.0;
	for (int s = n0; s < n1; s++) {
		/* Positions of the R2 sequence (Roberts 2018), a low-discrepancy
		 * set of its own: the features need the pixel's area, not the
		 * radiance samples' exact rays. */
		double u = 0.5 + 0.7548776662466927 * s, v = 0.5 + 0.5698402909980532 * s;
		u -= floor(u);
		v -= floor(v);
		first_surface(w, cam_ray(&w->cam, px + u, py + v, fw, fh), acc);
	}
	for (int k = 0; k < 7; k++)
		f[k] = (float)(acc[k] / n1);
}

/* --- the filter ------------------------------------------------------------ */

/* The constants were tuned on scenes/cornell.rt at 160x90, 8 samples,
 * against a 4096-sample reference (tests/unit/test_denoise.c). */
#define LEVELS 5
/* Edge-stopping strengths: brightness in standard deviations of its noise
 * (SVGF's sigma_l) on the first pass, narrowed on each later pass (Dammertz
 * et al. halve it); normals and albedo as squared distances; depth as the
 * distance off the plane that the pixel's depth and gradient predict, in
 * shares of its depth. */
#define SIGMA_L 8.0f
#define SIGMA_L_DECAY 0.6f
#define SIGMA_N2 0.02f
#define SIGMA_A2 0.01f
#define SIGMA_Z 0.02f
/* Albedo below this is not divided out (a black surface has no lighting to
 * recover). */
#define ALBEDO_MIN 0.02f
/* Fireflies: a pixel brighter than its same-surface 3x3 neighbours' mean by
 * more than this many of their standard deviations is brought down to it. */
#define FIREFLY_K 2.0f

typedef struct guide {
	float f[6];   /* albedo / sqrt(SIGMA_A2), normal / sqrt(SIGMA_N2) */
	float z;      /* depth */
	float gx, gy; /* its gradient per pixel */
	float am[3];  /* the albedo the radiance was divided by */
} guide;

/* Radiance over albedo, and its estimated noise variance. */
typedef struct texel {
	float c[3];
	float var;
} texel;

typedef struct job {
	const framebuffer *fb;
	guide *g;
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

/* exp(-x) for x >= 0, to about 2e-4 relative: 2^(-x log2 e), the integer
 * part in the exponent bits, the fraction by a cubic (no library call in the
 * inner loop). */
static inline float exp_neg(float x)
{
	if (!(x < 80.0f))
		return 0.0f;
	float t = x * 1.4426950409f;
	int i = (int)t;
	float fr = t - (float)i; /* 2^-fr on [0,1) */
	float p = 1.0f + fr * (-0.6930089f + fr * (0.2368309f + fr * -0.0438220f));
	union {
		float f;
		unsigned u;
	} s = {.u = (unsigned)(127 - i) << 23};
	return p * s.f;
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
			for (int k = 0; k < 3; k++) {
				g->f[k] = f[k] * (1.0f / sqrtf(SIGMA_A2));
				g->f[3 + k] = f[3 + k] * (1.0f / sqrtf(SIGMA_N2));
				g->am[k] = f[k] > ALBEDO_MIN ? f[k] : 1.0f;
			}
			g->z = f[6];
			g->gx = depth_slope(f + 6, x, w, DENOISE_FEATURES);
			g->gy = depth_slope(f + 6, y, h, DENOISE_FEATURES * w);
			texel *t = &j->buf[0][i];
			for (int k = 0; k < 3; k++) {
				float c = fb->rgb[i * 3 + k];
				t->c[k] = isfinite(c) ? c / g->am[k] : 0.0f;
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
				float am = lum(j->g[i].am);
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
static const float kernel[2 * KR + 1] = {1.0f / 4, 1.0f / 2, 1.0f / 4};

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
			for (int dy = -1; dy <= 1; dy++)
				for (int dx = -1; dx <= 1; dx++) {
					int qx = x + dx, qy = y + dy;
					if (qx < 0 || qx >= w || qy < 0 || qy >= h)
						continue;
					float k = (dx ? 0.25f : 0.5f) * (dy ? 0.25f : 0.5f);
					gv += k * src[(size_t)qy * w + qx].var;
					gw += k;
				}
			float lp = lum(tp->c);
			float inv_l = 1.0f / (sigma_l * sqrtf(gv / gw) + 1e-6f);
			/* Depth: how far the tap lies off the plane through this pixel
			 * along its depth gradient, against a share of the depth. */
			float inv_z = 1.0f / (SIGMA_Z * gp->z + 1e-6f);
			float gxs = gp->gx * (float)step, gys = gp->gy * (float)step;
			int lo = -KR, hi = KR;
			while (x + lo * step < 0)
				lo++;
			while (x + hi * step >= w)
				hi--;
			float k0 = kernel[KR] * kernel[KR];
			float sum[3] = {k0 * tp->c[0], k0 * tp->c[1], k0 * tp->c[2]};
			float wsum = k0, vsum = k0 * k0 * tp->var;
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
					float wt = kernel[dx + KR] * kernel[dy + KR] * exp_neg(e);
					sum[0] += wt * tq->c[0];
					sum[1] += wt * tq->c[1];
					sum[2] += wt * tq->c[2];
					wsum += wt;
					vsum += wt * wt * tq->var;
				}
			}
			texel *o = &dst[i];
			float inv = 1.0f / wsum; /* wsum >= the centre's own weight */
			o->c[0] = sum[0] * inv;
			o->c[1] = sum[1] * inv;
			o->c[2] = sum[2] * inv;
			o->var = vsum * inv * inv;
		}
}

static void finish_rows(job *j, const texel *src, int y0, int y1)
{
	int w = j->fb->w;
	for (int y = y0; y < y1; y++)
		for (int x = 0; x < w; x++) {
			size_t i = (size_t)y * w + x;
			for (int k = 0; k < 3; k++)
				j->out[i * 3 + k] = src[i].c[k] * j->g[i].am[k];
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
	if (j->threads > 1)
		pthread_barrier_wait(&j->bar); /* out may be fb->rgb, read by setup */
	finish_rows(j, j->buf[(LEVELS + 1) & 1], y0, y1);
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
	j.buf[0] = malloc(n * sizeof *j.buf[0]);
	j.buf[1] = malloc(n * sizeof *j.buf[1]);
	pthread_t *tid = malloc((size_t)threads * sizeof *tid);
	worker_arg *args = malloc((size_t)threads * sizeof *args);
	bool ok = j.g && j.buf[0] && j.buf[1] && tid && args;
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
	free(j.buf[0]);
	free(j.buf[1]);
	free(tid);
	free(args);
	return ok;
}
