/* rtsh — the first-hit features and the feature-regression denoiser
 * (denoise.h). */
#include "rtsh/denoise.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "emitters.h"
#include "integrators.h"
#include "rtsh/memory.h"

/* --- features -------------------------------------------------------------- */

bool denoise_prepare(framebuffer *fb)
{
	size_t n = (size_t)fb->w * (size_t)fb->h;
	if (fb->sum && !fb->sum2 && !(fb->sum2 = calloc(n, sizeof *fb->sum2)))
		return false;
	if (fb->feat)
		return true;
	fb->feat = calloc(n * DENOISE_FEATURES, sizeof *fb->feat);
	return fb->feat != NULL;
}

static double clamp01(double v)
{
	return v > 0.0 ? (v < 1.0 ? v : 1.0) : 0.0;
}

/* A number in [0, 1) from the bits of x (splitmix64's finaliser). */
static double hash_unit(uint64_t x)
{
	x ^= x >> 30;
	x *= 0xbf58476d1ce4e5b9u;
	x ^= x >> 27;
	x *= 0x94d049bb133111ebu;
	x ^= x >> 31;
	return (double)(x >> 11) * 0x1.0p-53;
}

static double lum_d(vec3 c)
{
	return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
}

/* Point idx of a Hammersley set of n points (n a power of two) of the
 * unit square, at its strata's centres: (idx + 1/2) / n and idx's bits
 * reversed. Sample k of the first DENOISE_FEATURE_SAMPLES takes the points
 * k, k + DENOISE_FEATURE_SAMPLES, ...: each sample's share is spread over
 * the square, and all of them make the whole set. */
static void hammersley(unsigned idx, unsigned n, double *u, double *v)
{
	unsigned rev = 0;
	for (unsigned bit = 1, r = n / 2; bit < n; bit <<= 1, r >>= 1)
		if (idx & bit)
			rev |= r;
	*u = (idx + 0.5) / n;
	*v = (rev + 0.5) / n;
}

/* The three numbers bsdf_sample_u takes for point idx of a fixed set of
 * n: the lobe's pick (where there are more) from a golden-ratio sequence,
 * apart from the direction's two, point idx of the Hammersley set. */
static void fixed_u(unsigned idx, unsigned n, double u[3])
{
	hammersley(idx, n, &u[1], &u[2]);
	double g = (idx + 0.5) * 0.6180339887498949;
	u[0] = g - (double)(long)g;
}

/* Which point of a fixed set of n the q-th direction of sample ks takes:
 * each of the first DENOISE_FEATURE_SAMPLES samples the points ks,
 * ks + DENOISE_FEATURE_SAMPLES, ... (its share, n / DENOISE_FEATURE_SAMPLES
 * of them); an edge pixel's later camera positions (ks from
 * DENOISE_FEATURE_SAMPLES to DENOISE_EDGE_SAMPLES) one point each, ks
 * modulo n (feature_dirs), so that over the 64 positions every point of
 * the set is taken as often. */
static unsigned set_index(int q, int ks, unsigned n)
{
	if (ks < DENOISE_FEATURE_SAMPLES)
		return (unsigned)(q * DENOISE_FEATURE_SAMPLES + ks);
	return (unsigned)ks % n;
}

/* How many directions (or points) of its set sample ks takes: its share
 * (per) among the first DENOISE_FEATURE_SAMPLES, else one. */
static int feature_dirs(int ks, int per)
{
	return ks < DENOISE_FEATURE_SAMPLES ? per : 1;
}

/* Emitters sampled for the direct-light feature at most (more: these many
 * picked, their light scaled up). */
#define DIRECT_EMITTERS 4

/* The direct light that the point lights and the lamps send through b at p
 * (on object self) toward the eye, as brightness: the point lights
 * exactly, each lamp from 4 points (an edge position's: 1) of the solid angle (or area)
 * emitter_sample maps them to, sample ks taking its share of one fixed
 * Hammersley set of 4 DENOISE_FEATURE_SAMPLES (hammersley): the same
 * points for every pixel, so that the feature is a smooth function of the
 * position (random points made it noisy where a glossy lobe sees the lamp,
 * its highlight). With more than DIRECT_EMITTERS lamps, r1 picks them;
 * without lamps (false: lobe_feature takes them), the point lights alone. No
 * weight of multiple importance sampling: the full direct light. */
static double direct_feature(const world *w, const bsdf *b, vec3 p, uint32_t self, int ks, double r1, bool lamps)
{
	double sum = 0.0;
	int nq = feature_dirs(ks, 4);
	if (!b->smooth)
		return 0.0;
	for (size_t i = 0; i < w->nlights; i++) {
		vec3 wi;
		double dist;
		vec3 lr = light_at(&w->lights[i], p, &wi, &dist);
		double c = v3_dot(b->n, wi);
		if (!(lr.x > 0.0 || lr.y > 0.0 || lr.z > 0.0) || c <= 0.0)
			continue;
		vec3 f = bsdf_eval(b, wi);
		ray sr = {p, wi};
		if (lum_d(f) <= 0.0 || world_occluded(w, &sr, 0.0, dist))
			continue;
		sum += lum_d(v3_mul(f, v3_scale(lr, RT_PI * c)));
	}
	size_t ne = lamps ? w->nemitters : 0, pick = ne < DIRECT_EMITTERS ? ne : DIRECT_EMITTERS;
	for (size_t k = 0; k < pick; k++) {
		size_t ei = ne <= DIRECT_EMITTERS ? k : (size_t)((k + r1) * (double)ne / DIRECT_EMITTERS);
		const emitter *e = &w->emitters[ei < ne ? ei : ne - 1];
		if (e->object == self)
			continue;
		double part = 0.0;
		for (int q = 0; q < nq; q++) {
			double u1, u2;
			hammersley(set_index(q, ks, 4 * DENOISE_FEATURE_SAMPLES), 4 * DENOISE_FEATURE_SAMPLES, &u1, &u2);
			vec3 wi;
			double pdf, t;
			if (!emitter_sample(e, p, u1, u2, &wi, &pdf, &t) || !(pdf > 0.0))
				continue;
			double c = v3_dot(b->n, wi);
			if (c <= 0.0)
				continue;
			vec3 f = bsdf_eval(b, wi);
			ray sr = {p, wi};
			if (lum_d(f) <= 0.0 || world_occluded(w, &sr, 0.0, t * (1.0 - 1e-7)))
				continue;
			part += lum_d(v3_mul(f, w->mats[e->mat].emission)) * c / pdf;
		}
		sum += part / nq * (double)ne / (double)pick;
	}
	return sum;
}

/* Directions of the sky's part of the direct-light feature, per sample:
 * the first DENOISE_FEATURE_SAMPLES samples take ENV_DIRS each of one
 * fixed set of ENV_DIRS * DENOISE_FEATURE_SAMPLES. */
#define ENV_DIRS 4
#define ENV_SET (ENV_DIRS * DENOISE_FEATURE_SAMPLES)

/* Whether the world has light from its background (a sky, an HDR sky or
 * path mode's ambient). */
static bool env_lit(const world *w)
{
	return w->env || w->has_sky || w->ambient.x > 0.0 || w->ambient.y > 0.0 || w->ambient.z > 0.0;
}

/* What the sky sends along sr for the features: the sky where sr meets
 * nothing; where it meets a surface (not a lamp: the lamps are
 * direct_feature's), that surface's albedo times the sky along its normal
 * (turned toward sr's origin) where that ray is free, a surface of albedo
 * a lit by a sky of radiance L, unshadowed, sending a L back; else
 * nothing. */
static vec3 sky_along(const world *w, const ray *sr)
{
	hit h;
	if (world_intersect(w, sr, 0.0, INFINITY, &h)) {
		const mat_lin *m = &w->mats[h.mat];
		if (m->emission.x + m->emission.y + m->emission.z > 0.0)
			return v3(0, 0, 0);
		vec3 n = v3_dot(h.n, sr->d) > 0.0 ? v3_neg(h.n) : h.n;
		ray up = {offset_point(w, h.p, n), n};
		if (world_occluded(w, &up, 0.0, INFINITY))
			return v3(0, 0, 0);
		return v3_mul(hit_albedo(m, &h), world_background(w, n, MODE_PATH));
	}
	return world_background(w, sr->d, MODE_PATH);
}

/* The light of the background (the sky) that b at p sends toward the eye,
 * as brightness: ENV_DIRS directions drawn from the bsdf itself
 * (bsdf_sample_u: about the normal, cosine-distributed, for a Lambertian
 * surface; a glossy lobe's own directions for a rough metal) with the
 * numbers of one fixed Hammersley set of ENV_SET, sample k taking the
 * points k, k + DENOISE_FEATURE_SAMPLES, ...; each weighed by f cos / pdf.
 * A direction that meets a surface brings that surface's sky once more
 * (sky_along). That is the sky a rough metal shows in its lobe
 * below the horizon, the floor and the shadows on it (final.rt's rough
 * spheres: the fits flattened the dark band of a shadow seen in them), and
 * the light a sky-lit surface gets from its neighbours. The same numbers
 * for every pixel: a function of the position and normal, smooth wherever
 * what blocks the sky changes slowly, and no noise between neighbours. */
static double env_feature(const world *w, const bsdf *b, vec3 p, int k)
{
	if (!b->smooth || !env_lit(w))
		return 0.0;
	double sum = 0.0;
	int nq = feature_dirs(k, ENV_DIRS);
	for (int q = 0; q < nq; q++) {
		double u[3];
		fixed_u(set_index(q, k, ENV_SET), ENV_SET, u);
		bsdf_sample sm;
		if (!bsdf_sample_u(b, u, &sm) || sm.transmit)
			continue;
		ray sr = {p, sm.wi};
		sum += lum_d(v3_mul(sm.weight, sky_along(w, &sr)));
	}
	return sum / nq;
}

/* Directions of a glossy lobe's lamp feature per sample (LOBE_DIRS x
 * DENOISE_FEATURE_SAMPLES in the whole set). */
#define LOBE_DIRS 8

/* The lamps' light that a glossy lobe looked through (a metal of little
 * fuzz: narrower than a lamp, so that a few points on the lamp would make
 * spikes) sends toward the eye, as brightness: LOBE_DIRS directions a
 * sample drawn from the lobe itself (bsdf_sample_u) with sample ks's share
 * of one fixed Hammersley set, each one's emission where it meets a lamp
 * first (what the direction meets first: shadows included). The same
 * directions about every mirror direction: the lamp's image blurred by the
 * lobe, smooth from pixel to pixel. */
static double lobe_feature(const world *w, const bsdf *b, vec3 p, int ks)
{
	if (!b->smooth || w->nemitters == 0)
		return 0.0;
	double sum = 0.0;
	int nq = feature_dirs(ks, LOBE_DIRS);
	for (int q = 0; q < nq; q++) {
		double u[3];
		fixed_u(set_index(q, ks, LOBE_DIRS * DENOISE_FEATURE_SAMPLES), LOBE_DIRS * DENOISE_FEATURE_SAMPLES, u);
		bsdf_sample sm;
		if (!bsdf_sample_u(b, u, &sm) || sm.transmit)
			continue;
		ray r = {p, sm.wi};
		hit h;
		if (!world_intersect(w, &r, 0.0, INFINITY, &h))
			continue;
		vec3 e = hit_emission(&w->mats[h.mat], &h);
		if (e.x + e.y + e.z > 0.0)
			sum += lum_d(v3_mul(sm.weight, e));
	}
	return sum / nq;
}

/* What the camera ray r shows first, in f (albedo, normal, depth; with
 * ks >= 0 the direct light, 7, and of it the part of glossy lobes looked
 * through, 8: at an edge position, ks from DENOISE_FEATURE_SAMPLES on,
 * that part alone). A
 * surface that is mostly a perfect mirror, a metal of little fuzz or glass
 * is looked through (up to four times): its features are those of the
 * surface seen in it, the albedo tinted by the mirror's or the glass's
 * colour, the depth the length of the whole path. Glass is followed along the refracted ray unless the
 * reflection is total, the albedo tinted by its transmitted share 1 - F
 * and, where the ray enters it, its reflected share F added as white (the
 * Phong family's glass). */
static void first_surface(const world *w, ray r, int ks, double f[9])
{
	vec3 tint = v3(1, 1, 1);
	uint64_t bits[2];
	memcpy(&bits[0], &r.d.x, sizeof bits[0]);
	memcpy(&bits[1], &r.d.y, sizeof bits[1]);
	double r1 = hash_unit(bits[0] ^ (bits[1] << 1));
	double dist = 0.0;
	/* the first glossy surface looked through (its features) */
	bool gl = false;
	vec3 gl_a = v3(0, 0, 0), gl_n = v3(0, 0, 0);
	double gl_d = 0.0;
	/* the glass surfaces' reflections on the way, as albedo */
	vec3 refl = v3(0, 0, 0);
	/* the normal where the ray first entered glass (0 if it did not) */
	vec3 glass_n = v3(0, 0, 0);
	bool in_glass = false;
	for (int k = 0;; k++) {
		hit h;
		if (!(k == 0 ? world_intersect_coherent : world_intersect)(w, &r, 0.0, INFINITY, &h)) {
			/* The sky: its own colour in that direction as albedo (so
			 * that its lighting is one); a black background white, as
			 * a surface's tint; no normal. No depth seen directly; seen
			 * through glass or in a mirror, the distance to the last
			 * surface the ray left: the sky there is light of that
			 * surface (its Fresnel share, paths inside the glass), and
			 * its colour alone, near the open sky's, did not keep the
			 * filter from mixing the two (the open sky's taps pulled
			 * final.rt's big glass sphere up by 0.1 to 0.15; 4 seeds,
			 * metal-fuzz.rt 1.5-2.4% less error, bench/README, the
			 * denoise8 session). Not background then for the adaptive
			 * allocation (denoise_fixed). */
			vec3 back = world_background(w, r.d, MODE_PATH);
			vec3 bg = back.x > 0.0 || back.y > 0.0 || back.z > 0.0 ? v3_mul(tint, back) : tint;
			f[0] += clamp01(bg.x + refl.x);
			f[1] += clamp01(bg.y + refl.y);
			f[2] += clamp01(bg.z + refl.z);
			/* The sky seen through glass: the glass's own normal
			 * where the ray entered it. Its Fresnel shares (F in
			 * the albedo where the ray enters, F leaving in the
			 * lighting) grow toward the rim of what a sphere shows,
			 * and the lighting there falls (final.rt's big sphere
			 * before the sky: reference 0.43 at its rim, 0.9-1.0
			 * inside, over the same albedo); with no normal the
			 * rim's fits took the inside's lighting and came out
			 * 0.1 to 0.15 too bright, and the choice's window could
			 * not tell the rim's estimates from the inside's
			 * (bench/README, the denoise13 session). */
			f[3] += glass_n.x;
			f[4] += glass_n.y;
			f[5] += glass_n.z;
			f[6] += dist;
			return;
		}
		const mat_lin *m = &w->mats[h.mat]; /* a model's own material, too */
		bsdf b;
		bsdf_make(&b, m, &h, v3_neg(r.d));
		dist += h.t;
		vec3 a, tt = v3(0, 0, 0), dir = v3(0, 0, 0);
		int follow = bsdf_features(&b, &a, &tt, &dir);
		if (follow == 0 || k == 3 || m->emission.x + m->emission.y + m->emission.z > 0.0) {
			vec3 e = m->emission;
			if (e.x + e.y + e.z > 0.0 && gl) {
				/* A lamp seen through a glossy lobe is blurred by it: the
				 * features are the glossy surface's own, and its direct
				 * light (added there) explains the highlight. */
				f[0] += gl_a.x;
				f[1] += gl_a.y;
				f[2] += gl_a.z;
				f[3] += gl_n.x;
				f[4] += gl_n.y;
				f[5] += gl_n.z;
				f[6] += gl_d;
				return;
			}
			if (e.x + e.y + e.z > 0.0) {
				/* A lamp's "albedo" is its emission, unclamped: far from any
				 * surface's, so that no filter mixes the two. */
				a = v3_mul(v3_add(v3_scale(a, 0.0), e), tint);
			} else {
				a = v3_add(v3_mul(a, tint), refl);
				a = v3(clamp01(a.x), clamp01(a.y), clamp01(a.z));
			}
			f[0] += a.x;
			f[1] += a.y;
			f[2] += a.z;
			f[3] += b.n.x;
			f[4] += b.n.y;
			f[5] += b.n.z;
			f[6] += dist;
			if (ks >= 0 && ks < DENOISE_FEATURE_SAMPLES && !(e.x + e.y + e.z > 0.0)) {
				vec3 p = offset_point(w, h.p, b.n);
				f[7] += (direct_feature(w, &b, p, h.object, ks, r1, true) + env_feature(w, &b, p, ks)) * lum_d(tint);
			}
			return;
		}
		if (ks >= 0 && b.smooth) { /* a glossy lobe looked through: its own highlights */
			vec3 p = offset_point(w, h.p, b.n);
			double l = (direct_feature(w, &b, p, h.object, ks, r1, false) + lobe_feature(w, &b, p, ks)) * lum_d(tint);
			f[7] += l;
			f[8] += l;
		}
		if (b.smooth && !gl) {
			gl = true;
			gl_a = v3_mul(a, tint);
			gl_a = v3(clamp01(gl_a.x), clamp01(gl_a.y), clamp01(gl_a.z));
			gl_n = b.n;
			gl_d = dist;
		}
		if (follow == 2 && b.family == MAT_PHONG) {
			/* Glass that is looked through sends back its Fresnel share
			 * F of the light (the paths reflect with probability F):
			 * the surface behind is tinted by 1 - F, and F joins the
			 * albedo as a white reflection's, so that dividing the
			 * radiance by the albedo does not blow the reflection up
			 * where what lies behind is dark. Where the ray leaves the
			 * glass (its back face) F is the share reflected back
			 * inside it, to leave it elsewhere after more bounces
			 * and see something else, mostly darker than a white
			 * surface would be: it is left out of the albedo (in the
			 * lighting, as the 1 - F tint already says). Counted
			 * white, it made the albedo of pixels near the rim of
			 * what a sphere shows (F large, up to total reflection)
			 * as bright as their neighbours' while their radiance is
			 * 0.1 to 0.15 darker, and the filter brought them up to
			 * their neighbours (final.rt's big glass sphere, 4 seeds:
			 * 128x96 0.987, 200x120 0.990 of the error before;
			 * bench/README, the denoise10 session). */
			double eta = b.front ? b.ior : 1.0 / b.ior, cos_t;
			double fr = fresnel_dielectric(b.cos_o, eta, &cos_t);
			if (b.front)
				refl = v3_add(refl, v3_scale(tint, b.wg * fr));
			if (b.front && !in_glass) {
				glass_n = b.n;
				in_glass = true;
			}
			if (ks >= 0 && ks < DENOISE_FEATURE_SAMPLES && env_lit(w)) {
				/* and that share of the sky in the mirror direction
				 * (or of a surface's there, env_feature's rule) joins
				 * the direct light: the glass's reflection, brighter
				 * toward its rim, is no noise of the lighting behind */
				ray mr = {offset_point(w, h.p, b.n), v3_sub(v3_scale(b.n, 2.0 * b.cos_o), b.wo)};
				f[7] += lum_d(v3_mul(v3_scale(tint, b.wg * fr), sky_along(w, &mr)));
			}
			tt = v3_scale(tt, 1.0 - fr);
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

void denoise_sample(const world *w, ray r, int k, double *acc)
{
	double f[9] = {0};
	first_surface(w, r, k, f);
	for (int q = 0; q < 8; q++)
		acc[q] += f[q];
	acc[8] += f[0] * f[0] + f[1] * f[1] + f[2] * f[2];
	acc[9] += f[6] * f[6];
	if (!(k & 1))
		for (int q = 0; q < 3; q++)
			acc[10 + q] += f[q];
	acc[13] += f[8];
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

/* Whether the features of the first n positions (f, their means) and of
 * the pixel's four corners, DENOISE_PROBE_INSET of a pixel inside it,
 * vary (features_vary) all together. */
static bool corners_vary(const world *w, int px, int py, int fw, int fh, const float *f, int n)
{
	double sum[10];
	for (int q = 0; q < 10; q++)
		sum[q] = (double)f[q] * n;
	for (int c = 0; c < 4; c++) {
		double one[9] = {0};
		double u = c & 1 ? 1.0 - DENOISE_PROBE_INSET : DENOISE_PROBE_INSET;
		double v = c & 2 ? 1.0 - DENOISE_PROBE_INSET : DENOISE_PROBE_INSET;
		first_surface(w, cam_ray(&w->cam, px + u, py + v, fw, fh), -1, one);
		for (int q = 0; q < 7; q++)
			sum[q] += one[q];
		sum[8] += one[0] * one[0] + one[1] * one[1] + one[2] * one[2];
		sum[9] += one[6] * one[6];
	}
	float all[10];
	for (int q = 0; q < 10; q++)
		all[q] = (float)(sum[q] / (n + 4));
	return features_vary(all);
}

/* denoise_features, and denoise_features_only with ra NULL: then samples
 * [begin, end) are camera positions of no radiance sample, and the
 * radiance's features and the albedo at its samples' own positions (7,
 * 10-13, 15-20) are left as they are. */
static void features_update(const world *w, const render_settings *s, int px, int py, int fw, int fh,
                            int begin, int end, const double *ra, const double *acc, float *f)
{
	if (ra) {
		f[7] = (float)(((double)f[7] * begin + ra[0]) / end);
		/* the even samples: (begin + 1) / 2 of them before, (end + 1) / 2 after */
		int e0 = (begin + 1) / 2, e1 = (end + 1) / 2;
		if (e1 > e0)
			for (int k = 0; k < 3; k++)
				f[10 + k] = (float)(((double)f[10 + k] * e0 + ra[1 + k]) / e1);
		if (e1 > e0)
			f[13] = (float)(((double)f[13] * e0 + ra[4]) / e1);
	}
	int n0 = begin < DENOISE_FEATURE_SAMPLES ? begin : DENOISE_FEATURE_SAMPLES;
	int n1 = end < DENOISE_FEATURE_SAMPLES ? end : DENOISE_FEATURE_SAMPLES;
	if (n1 <= n0)
		return;
	for (int k = 0; k < 10; k++)
		if (k != 7)
			f[k] = (float)(((double)f[k] * n0 + acc[k]) / n1);
	f[14] = (float)(((double)f[14] * n0 + acc[7]) / n1);
	f[21] = (float)(((double)f[21] * n0 + acc[13]) / n1);
	/* the albedo of the radiance samples' own positions: the even ones
	 * and all of them */
	int ne0 = (n0 + 1) / 2, ne1 = (n1 + 1) / 2;
	for (int k = 0; k < 3 && ra; k++) {
		if (ne1 > ne0)
			f[15 + k] = (float)(((double)f[15 + k] * ne0 + acc[10 + k]) / ne1);
		f[18 + k] = f[k];
	}
	if (n1 < DENOISE_FEATURE_SAMPLES)
		return;
	/* Where the first positions agree, the pixel's four corners (first
	 * hits only, DENOISE_PROBE_INSET of a pixel inside it) are looked at
	 * too: a straight edge through the pixel leaves a corner on each side
	 * of it, so one that covers a sliver of the pixel, missed by all the
	 * first positions (as often by its radiance samples, and the filter
	 * took the pixel for the one surface), is found there. */
	if (!features_vary(f) && !corners_vary(w, px, py, fw, fh, f, n1))
		return;
	/* An edge: more camera positions, the radiance samples' own. The
	 * direct light seen through glossy lobes too, from one direction
	 * (point) of each set a position (feature_dirs), so that how much of
	 * the pixel a highlight covers is known as well as where the edge is
	 * (from the first samples alone a highlight's edge in a glossy metal
	 * was as noisy as the radiance); the rest of the direct light stays
	 * the mean of the first samples (refined too, it helped little for
	 * its cost: a shadow ray a position). */
	double sum[10], lobe = (double)f[21] * n1;
	for (int k = 0; k < 10; k++)
		sum[k] = (double)f[k] * n1;
	for (int k = n1; k < DENOISE_EDGE_SAMPLES; k++) {
		double one[9] = {0};
		first_surface(w, render_sample_ray(w, s, px, py, fw, fh, k), k, one);
		for (int q = 0; q < 8; q++)
			if (q != 7)
				sum[q] += one[q];
		sum[8] += one[0] * one[0] + one[1] * one[1] + one[2] * one[2];
		sum[9] += one[6] * one[6];
		lobe += one[8];
	}
	for (int q = 0; q < 10; q++)
		if (q != 7)
			f[q] = (float)(sum[q] / DENOISE_EDGE_SAMPLES);
	lobe /= DENOISE_EDGE_SAMPLES;
	f[14] = (float)((double)f[14] - (double)f[21] + lobe);
	f[21] = (float)lobe;
}

void denoise_features(const world *w, const render_settings *s, int px, int py, int fw, int fh,
                      int begin, int end, const double *ra, const double *acc, float *f)
{
	features_update(w, s, px, py, fw, fh, begin, end, ra, acc, f);
}

void denoise_features_only(const world *w, const render_settings *s, int px, int py, int fw, int fh,
                           int begin, int end, float *f)
{
	double acc[DENOISE_ACC] = {0};
	if (end > DENOISE_FEATURE_SAMPLES)
		end = DENOISE_FEATURE_SAMPLES;
	if (end <= begin)
		return;
	for (int k = begin; k < end; k++)
		denoise_sample(w, render_sample_ray(w, s, px, py, fw, fh, k), k, acc);
	features_update(w, s, px, py, fw, fh, begin, end, NULL, acc, f);
}

/* --- the filter ------------------------------------------------------------ */

/* The constants were chosen at 128x96 and 200x120, 8 samples, against
 * 1024-sample references of scenes/cornell.rt, sky-spheres.rt, spot.rt,
 * metal-fuzz.rt and final.rt (bench/quality.c, `--only denoise`).
 *
 * Feature distances: albedo and normals as squared distances over these,
 * depth as the distance off the plane that the pixel's depth and gradient
 * predict, in shares of its depth. With the direct light's own fit and the
 * sky's colour as its albedo, twice the albedo's and the normals' (0.04,
 * 0.16 before) took metal-fuzz, final, sky-spheres, cornell, spot at
 * 200x120 from 1.491, 1.614, 0.975, 0.636, 0.786 times the 64 samples'
 * error to 1.475, 1.582, 0.962, 0.633, 0.782; then the depth's 0.03
 * instead of 0.015: 1.475, 1.582, 0.947, 0.632, 0.772. */
#define SIGMA_A2 0.08f
#define SIGMA_N2 0.32f
#define SIGMA_Z 0.03f
/* The regression's window: radius 4 (9x9 pixels). */
#define WIN 4
#define TAPS ((2 * WIN + 1) * (2 * WIN + 1))
/* Its unknowns: a constant, the slopes along x and y, along the normal's
 * three components, along the depth and along the direct light. */
#define NU 8
/* The slopes are held back by a ridge of this share of the weights; the
 * direct light's own fit's slope by more (1e-3 there: metal-fuzz, final
 * and sky-spheres at 200x120 1.529, 1.730, 0.988 times the 64 samples'
 * error; 1e-2: 1.528, 1.721, 0.972; 3e-2: 1.538, 1.716, 0.963). */
#define RIDGE 1e-3f
#define DIRECT_RIDGE 1e-2f
/* The candidates' errors are averaged over (2 PICK_R + 1)^2 pixels,
 * weighted by how alike the pixels' albedo and normal are: exp(-PICK_SCALE
 * d^2), d^2 their squared distance in the regression's scaled features (a
 * quarter of the regression's own weight's exponent: wider, since the
 * estimates are noisier than the radiance). */
#define PICK_R 4
#define PICK_SCALE 0.25f
/* The regression's taps, and the pixels in the choice's average, are
 * also weighted by how alike their direct light is: DIRECT_W dd^2 more in
 * the weight's exponent (before PICK_SCALE in the choice's), dd the
 * regression's direct-light regressor (the tap's direct light less the
 * pixel's, over 0.5 |d| + 0.05 of the pixel's). Where a rough metal
 * reflects the horizon, the dark band and the bright sky beside it have
 * the same albedo, normal and depth, and the fits flattened the band; the
 * direct light (the sky through the metal's lobe) tells them apart, and
 * the radiance need not be linear in it across the window. 4 seeds (1,
 * 7920, 15839, 23758), RMS new/old of metal-fuzz, final, cornell, spot,
 * sky-spheres: 128x96 0.955 0.991 1.004 0.987 1.007, 200x120 0.957 0.984
 * 1.002 0.980 1.003, 640x360 0.984 0.984 1.000 0.990 1.002; in the
 * regression alone geomean 0.9887 (128x96, 200x120; 0.9867 both),
 * DIRECT_W 0.5 and 2 there 0.9894 and 0.9929 (bench/README, the denoise9
 * session). */
#define DIRECT_W 1.0f
/* A mixed pixel's regression may move it by at most this many standard
 * deviations of its noise: the move is clipped as Huber's M-estimator
 * clips a residual, at his 1.345 (the constant at which the estimate keeps
 * 95% of the mean's efficiency where the noise is Gaussian and nothing is
 * an outlier). It was 3; 4 seeds (1, 7920, 15839, 23758), RMS new/old of
 * metal-fuzz, final, cornell, spot, sky-spheres: 128x96 1.000 0.995 1.000
 * 0.983 1.001, 200x120 0.995 0.999 1.000 0.991 1.000 (bench/README, the
 * denoise11 session). */
#define MIX_K 1.345f
#define MIX_R 1     /* the mixed pixels' window: (2 MIX_R + 1)^2 pixels */
#define MIX_NU 8    /* its unknowns: a constant and 7 feature slopes */

/* What every regression tap reads of a pixel. */
typedef struct guide {
	float f[6];   /* albedo / sqrt(SIGMA_A2), normal / sqrt(SIGMA_N2) */
	float z;      /* depth */
	float gx, gy; /* the depth's gradient per pixel */
	float d;      /* the direct light over the albedo */
} guide;

/* A pixel's value in one chain: radiance over albedo, and the variance of
 * one sample's brightness (over albedo squared). */
typedef struct chan {
	float c[3];
	float v;
} chan;

/* The chains: the even-numbered samples (half a), the odd ones (half b),
 * and all of them. */
enum { CH_A, CH_B, CH_ALL, NCH };
typedef struct texel {
	chan h[NCH];
} texel;

/* The candidates for a pixel: itself, the regression on all the
 * features, and the regression on the direct light alone (a constant and
 * its slope: where a highlight or a shadow leaves few taps alike, as in a
 * glossy metal's highlight a few pixels wide, eight unknowns fit the
 * noise; two do not). */
enum { CAND_RAW, CAND_FIT, CAND_DIRECT, NCAND };
/* The regressions' values: those of CAND_FIT, then of CAND_DIRECT. */
#define NFIT (NCAND - CAND_FIT)

/* What regression_rows reads, one plane a quantity (structure of arrays),
 * so that neighbouring pixels' values are one load: the guide's six
 * scaled features, depth, direct light, depth gradient, and what the
 * regression fits (all the samples' colour and each half's brightness);
 * and what it writes for pick_rows, the candidates' estimated squared
 * errors.
 * Each plane has PL_PAD floats of zeros before and after it, so that the
 * loads of eight pixels at a row's ends stay inside. */
enum { PL_F0, PL_Z = 6, PL_D, PL_GX, PL_GY, PL_DATA, PL_ERR = PL_DATA + 5, NPL = PL_ERR + NCAND };
#define PL_PAD 16

typedef struct job {
	const framebuffer *fb;
	guide *g;
	float *am;              /* 3 a pixel: the albedo the radiance is divided by */
	bool *mixed;            /* the pixel's features vary inside it */
	texel *t;               /* the chains; CH_ALL later holds the result */
	float *pl;              /* the regression's planes (plane), NPL of them */
	size_t pstride;         /* floats from one plane to the next */
	float *fit;             /* 3 x NFIT a pixel: the regressions' values */
	float *out;
	bool halves;            /* at least two samples: two independent halves */
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

/* Pixel i's samples: its own (adaptive sampling), or the image's. */
static inline int pixel_spp(const framebuffer *fb, size_t i)
{
	return fb->pixel_spp ? fb->pixel_spp[i] : fb->spp;
}

/* Whether pixel i has so many samples (DENOISE_OWN_TIMES the mean) that
 * its own error estimates choose its candidate, and no mixed pixel's step
 * moves it. */
static inline bool trusts_own(const framebuffer *fb, size_t i)
{
	return fb->pixel_spp && fb->pixel_spp[i] >= DENOISE_OWN_TIMES * fb->spp;
}

/* The samples in each chain of a pixel of spp samples. */
static inline void chain_n(int spp, float n[NCH])
{
	bool halves = spp >= 2;
	n[CH_A] = halves ? (float)((spp + 1) / 2) : 1.0f;
	n[CH_B] = halves ? (float)(spp / 2) : 1.0f;
	n[CH_ALL] = spp > 1 ? (float)spp : 1.0f;
}

/* Plane k's first pixel (regression_rows). */
static inline float *plane(const job *j, int k)
{
	return j->pl + (size_t)k * j->pstride + PL_PAD;
}

static float depth_slope(const float *z, int x, int w, int stride)
{
	float here = z[0];
	float back = x > 0 ? here - z[-stride] : INFINITY;
	float fwd = x < w - 1 ? z[stride] - here : INFINITY;
	float g = fabsf(back) < fabsf(fwd) ? back : fwd;
	return isfinite(g) ? g : 0.0f;
}

/* Features and the chains (radiance over albedo) for rows [y0, y1). */
static void setup_rows(job *j, int y0, int y1)
{
	const framebuffer *fb = j->fb;
	int w = fb->w, h = fb->h;
	for (int y = y0; y < y1; y++)
		for (int x = 0; x < w; x++) {
			size_t i = (size_t)y * w + x;
			const float *f = fb->feat + i * DENOISE_FEATURES;
			guide *g = &j->g[i];
			float *am = j->am + i * 3;
			for (int k = 0; k < 3; k++) {
				g->f[k] = f[k] * (1.0f / sqrtf(SIGMA_A2));
				g->f[3 + k] = f[3 + k] * (1.0f / sqrtf(SIGMA_N2));
				am[k] = (float)albedo_divisor(f[k]);
			}
			g->z = f[6];
			g->d = f[14] / lum(am);
			g->gx = depth_slope(f + 6, x, w, DENOISE_FEATURES);
			g->gy = depth_slope(f + 6, y, h, DENOISE_FEATURES * w);
			j->mixed[i] = features_vary(f);
			texel *t = &j->t[i];
			int spp = pixel_spp(fb, i);
			bool own = spp <= DENOISE_FEATURE_SAMPLES;
			float nc[NCH];
			chain_n(spp, nc);
			for (int k = 0; k < 3; k++) {
				float c = fb->rgb[i * 3 + k], a = c, b = c;
				if (j->halves) {
					a = f[10 + k];
					b = (c * nc[CH_ALL] - a * nc[CH_A]) / nc[CH_B];
				}
				/* Divided by the albedo at the samples' own positions
				 * where they are all the samples (each half by its
				 * own), so that how many of them met which surface is
				 * no noise of the lighting; multiplied again by the
				 * features' (better antialiased) albedo. */
				float da = am[k], db = am[k], dc = am[k];
				if (own && f[k] > ALBEDO_MIN) {
					float sa = f[15 + k], sc = f[18 + k];
					float sb = (sc * nc[CH_ALL] - sa * nc[CH_A]) / nc[CH_B];
					da = sa > ALBEDO_MIN ? sa : am[k];
					db = sb > ALBEDO_MIN ? sb : am[k];
					dc = sc > ALBEDO_MIN ? sc : am[k];
				}
				t->h[CH_A].c[k] = isfinite(a) ? a / da : 0.0f;
				t->h[CH_B].c[k] = isfinite(b) ? b / db : 0.0f;
				t->h[CH_ALL].c[k] = isfinite(c) ? c / dc : 0.0f;
			}
			for (int k = 0; k < 6; k++)
				plane(j, PL_F0 + k)[i] = g->f[k];
			plane(j, PL_Z)[i] = g->z;
			plane(j, PL_D)[i] = g->d;
			plane(j, PL_GX)[i] = g->gx;
			plane(j, PL_GY)[i] = g->gy;
			/* all the samples' colour and each half's brightness */
			for (int k = 0; k < 3; k++)
				plane(j, PL_DATA + k)[i] = t->h[CH_ALL].c[k];
			plane(j, PL_DATA + 3)[i] = lum(t->h[CH_A].c);
			plane(j, PL_DATA + 4)[i] = lum(t->h[CH_B].c);
		}
}

/* The noise variance of one sample's brightness in each chain: from the
 * chain's own samples (with two or more in each half; else the pixel's,
 * pooled), or with a single sample the variance over the pixel's 3x3
 * neighbours on the same surface (a spatial estimate, as SVGF's when a
 * pixel has no history). */
static void variance_rows(job *j, int y0, int y1)
{
	const framebuffer *fb = j->fb;
	int w = fb->w, h = fb->h;
	for (int y = y0; y < y1; y++)
		for (int x = 0; x < w; x++) {
			size_t i = (size_t)y * w + x;
			const float *f = fb->feat + i * DENOISE_FEATURES;
			float am = lum(j->am + i * 3), am2 = am * am;
			chan *hc = j->t[i].h;
			int spp = pixel_spp(fb, i);
			if (spp >= 2) {
				float nc[NCH];
				chain_n(spp, nc);
				float n = nc[CH_ALL], m1 = lum(hc[CH_ALL].c) * am;
				float v = (f[7] - m1 * m1) * n / (n - 1) / am2;
				hc[CH_ALL].v = hc[CH_A].v = hc[CH_B].v = v > 0 ? v : 0;
				if (spp >= 4) {
					float na = nc[CH_A], nb = nc[CH_B];
					float ma = lum(hc[CH_A].c) * am, mb = lum(hc[CH_B].c) * am;
					float qa = f[13], qb = (f[7] * n - f[13] * na) / nb;
					float va = (qa - ma * ma) * na / (na - 1) / am2;
					float vb = (qb - mb * mb) * nb / (nb - 1) / am2;
					hc[CH_A].v = va > 0 ? va : 0;
					hc[CH_B].v = vb > 0 ? vb : 0;
				}
				continue;
			}
			const guide *gp = &j->g[i];
			float s1 = 0, s2 = 0, n = 0;
			for (int dy = -1; dy <= 1; dy++)
				for (int dx = -1; dx <= 1; dx++) {
					int qx = x + dx, qy = y + dy;
					if (qx < 0 || qx >= w || qy < 0 || qy >= h)
						continue;
					size_t q = (size_t)qy * w + qx;
					float d = 0; /* the normals' squared distance, scaled */
					for (int k = 3; k < 6; k++)
						d += (gp->f[k] - j->g[q].f[k]) * (gp->f[k] - j->g[q].f[k]);
					if (d > 4.0f)
						continue;
					float l = lum(j->t[q].h[CH_ALL].c);
					s1 += l;
					s2 += l * l;
					n += 1;
				}
			float mean = s1 / n, var = s2 / n - mean * mean;
			/* n samples estimate it with n - 1 degrees of freedom */
			hc[CH_ALL].v = hc[CH_A].v = hc[CH_B].v = n > 1 ? (var > 0 ? var : 0) * n / (n - 1) : 0.0f;
		}
}

/* Right-hand sides of the regressions: red, green, blue of all the
 * samples, and the brightness of each half. */
#define NRHS 5

/* Cholesky solve of the n x n system a x = b with m right-hand sides (a
 * positive definite and overwritten; only its lower triangle is read).
 * False when it is not. Inlined and unrolled: its callers' n and m are
 * constants. */
static inline __attribute__((always_inline)) bool solve(int n, float a[][MIX_NU], int m, float b[][NRHS], float x[][NRHS])
{
	float inv[MIX_NU]; /* 1 / the factor's diagonal */
#pragma GCC unroll 8
	for (int c = 0; c < n; c++) {
		float d = a[c][c];
#pragma GCC unroll 8
		for (int k = 0; k < c; k++)
			d -= a[c][k] * a[c][k];
		if (!(d > 1e-12f))
			return false;
		d = sqrtf(d);
		a[c][c] = d;
		inv[c] = 1.0f / d;
#pragma GCC unroll 8
		for (int r = c + 1; r < n; r++) {
			float v = a[r][c];
#pragma GCC unroll 8
			for (int k = 0; k < c; k++)
				v -= a[r][k] * a[c][k];
			a[r][c] = v * inv[c];
		}
	}
#pragma GCC unroll 8
	for (int ch = 0; ch < m; ch++) {
		float z[MIX_NU];
#pragma GCC unroll 8
		for (int r = 0; r < n; r++) {
			float v = b[r][ch];
#pragma GCC unroll 8
			for (int k = 0; k < r; k++)
				v -= a[r][k] * z[k];
			z[r] = v * inv[r];
		}
#pragma GCC unroll 8
		for (int r = n - 1; r >= 0; r--) {
			float v = z[r];
#pragma GCC unroll 8
			for (int k = r + 1; k < n; k++)
				v -= a[k][r] * x[k][ch];
			x[r][ch] = v * inv[r];
		}
	}
	return true;
}

/* The error of a candidate whose halves came out at brightness la and lb,
 * from the halves (NFOR's cross-buffer estimate): half a's value against
 * half b's raw one is off by a's error and by b's noise, whose variance is
 * known, and so with b against a; less that noise, and less half the
 * halves' own noise (their difference squared over 4), since the whole has
 * half their variance. Unbiased for any candidate whose half a depends on
 * half a's samples only, and b on b's. */
static float cross_error(const chan *r, float na, float nb, float la, float lb)
{
	float da = la - lum(r[CH_B].c), db = lb - lum(r[CH_A].c);
	return 0.5f * (da * da + db * db) - 0.5f * (r[CH_B].v / nb + r[CH_A].v / na) -
	       0.25f * (la - lb) * (la - lb);
}

/* Where the sum of row r and column c (c <= r) of the normal equations is
 * kept: their lower triangle, row by row. */
#define TRI(r, c) ((r) * ((r) + 1) / 2 + (c))
#define NTRI (NU * (NU + 1) / 2)

/* The regression (regression_rows) and the choice (pick_rows) several
 * pixels at a time (denoise_lanes.h): eight where the processor has AVX2
 * (a copy built for it, chosen when the filter runs: not by an ifunc,
 * which ThreadSanitizer cannot start before), else four. The same floats
 * either way: the same operations lane by lane, and no fused
 * multiply-adds (-ffp-contract=off is GCC's default under -std=c17, and
 * "avx2" does not enable FMA). Their vectors are never passed to a
 * function (all inlined): GCC's note that it would change the ABI
 * without AVX is off. */
#pragma GCC diagnostic ignored "-Wpsabi"
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define HAVE_AVX2_COPY 1
#define VL 8
#define LANES(name) name##_8
#define LANES_TARGET __attribute__((target("avx2")))
#include "denoise_lanes.h"
#undef VL
#undef LANES
#undef LANES_TARGET
#endif
#define VL 4
#define LANES(name) name##_4
#define LANES_TARGET
#include "denoise_lanes.h"
#undef VL
#undef LANES
#undef LANES_TARGET

/* Rows y0..y1 of the lane pass fn: its 8-lane copy where the processor
 * has AVX2, else its 4-lane one. */
#ifdef HAVE_AVX2_COPY
#define LANES_ROWS(fn, j, y0, y1) (__builtin_cpu_supports("avx2") ? fn##_8(j, y0, y1) : fn##_4(j, y0, y1))
#else
#define LANES_ROWS(fn, j, y0, y1) fn##_4(j, y0, y1)
#endif

static void regression_rows(job *j, int y0, int y1)
{
	LANES_ROWS(regression_rows, j, y0, y1);
}

static void pick_rows(job *j, int y0, int y1)
{
	LANES_ROWS(pick_rows, j, y0, y1);
}

/* A pixel whose features vary inside it (part one surface, part another):
 * a first-order regression of the chosen radiance on the features over
 * its 3x3 window, evaluated at the pixel's own features, so that it gets
 * the mix its features say. False when the system is singular. */
static bool mix_pixel(const job *j, int x, int y, float o[3])
{
	int w = j->fb->w, h = j->fb->h;
	size_t i = (size_t)y * w + x;
	const guide *gp = &j->g[i];
	float a[MIX_NU][MIX_NU] = {{0}}, b[MIX_NU][NRHS] = {{0}}, beta[MIX_NU][NRHS];
	float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {0, 0, 0};
	float inv_z = 1.0f / (gp->z + 1e-6f);
	float vsum = 0; /* the window's noise variances */
	int ntap = 0;
	for (int dy = -MIX_R; dy <= MIX_R; dy++)
		for (int dx = -MIX_R; dx <= MIX_R; dx++) {
			int qx = x + dx, qy = y + dy;
			if (qx < 0 || qx >= w || qy < 0 || qy >= h)
				continue;
			size_t q = (size_t)qy * w + qx;
			const guide *gq = &j->g[q];
			const float *c = j->t[q].h[CH_ALL].c;
			vsum += j->t[q].h[CH_ALL].v;
			ntap++;
			float v[MIX_NU];
			v[0] = 1;
			for (int k = 0; k < 6; k++)
				v[1 + k] = gq->f[k] - gp->f[k];
			v[7] = (gq->z - gp->z) * inv_z * 10.0f;
			for (int ch = 0; ch < 3; ch++) {
				lo[ch] = c[ch] < lo[ch] ? c[ch] : lo[ch];
				hi[ch] = c[ch] > hi[ch] ? c[ch] : hi[ch];
			}
			for (int r = 0; r < MIX_NU; r++) {
				for (int k = 0; k <= r; k++)
					a[r][k] += v[r] * v[k];
				for (int ch = 0; ch < 3; ch++)
					b[r][ch] += v[r] * c[ch];
			}
		}
	float ridge = a[0][0] * 1e-3f; /* slopes held back a little */
	for (int r = 1; r < MIX_NU; r++)
		a[r][r] += ridge;
	if (!solve(MIX_NU, a, 3, b, beta))
		return false;
	/* Within the window's range; and a move the pixel's noise cannot
	 * explain (more than MIX_K standard deviations of its brightness) is
	 * cut down to that. That noise is at least the window's mean: where
	 * all the pixel's samples agree (an edge whose other side they all
	 * missed, a sliver of a sphere in the sky) their variance is 0, and
	 * the pixel would keep its one surface's colour whatever its features
	 * say (metal-fuzz, final and sky-spheres at 128x96 1.630, 1.794, 1.001
	 * times the 64 samples' error before, 1.599, 1.773, 0.988 with this; a
	 * floor of a tenth of the mean, or none, within 0.003 of it). */
	float vmean = vsum / (float)ntap;
	const chan *p = &j->t[i].h[CH_ALL];
	float r[3];
	for (int k = 0; k < 3; k++)
		r[k] = beta[0][k] < lo[k] ? lo[k] : beta[0][k] > hi[k] ? hi[k] : beta[0][k];
	float d = fabsf(lum(r) - lum(p->c));
	float v = p->v > vmean ? p->v : vmean;
	float lim = MIX_K * sqrtf(v), t = d > lim ? lim / d : 1.0f;
	for (int k = 0; k < 3; k++)
		o[k] = p->c[k] + t * (r[k] - p->c[k]);
	return true;
}

/* The final radiance into out: mixed pixels regressed, the others as
 * chosen. */
static void mix_rows(job *j, int y0, int y1)
{
	int w = j->fb->w;
	for (int y = y0; y < y1; y++)
		for (int x = 0; x < w; x++) {
			size_t i = (size_t)y * w + x;
			float *o = j->out + i * 3;
			if (!j->mixed[i] || trusts_own(j->fb, i) || !mix_pixel(j, x, y, o))
				for (int k = 0; k < 3; k++)
					o[k] = j->t[i].h[CH_ALL].c[k];
		}
}

static void barrier(job *j)
{
	if (j->threads > 1)
		pthread_barrier_wait(&j->bar);
}

static void run_rows(job *j, int y0, int y1)
{
	setup_rows(j, y0, y1);
	barrier(j);
	variance_rows(j, y0, y1);
	barrier(j);
	regression_rows(j, y0, y1);
	barrier(j);
	pick_rows(j, y0, y1);
	barrier(j); /* out may be fb->rgb, read by setup */
	mix_rows(j, y0, y1);
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

/* The arrays of one call (the job's): one block, with its planes' pads
 * zero (calloc; no pass writes them). A block of at most SCRATCH_KEEP bytes
 * is kept for the next call of as many pixels (the preview's frames): a new
 * one is 4.7 MB at 200x120, and its pages, returned to the kernel when it
 * was freed, cost about 1100 page faults a call, the kernel zeroing each.
 * One block is kept at a time (the last one given back). Every array is
 * written before it is read in a call, so what a kept block held does not
 * matter. */
#define SCRATCH_KEEP ((size_t)64 << 20)
typedef struct scratch {
	size_t n;     /* pixels */
	size_t bytes; /* of the whole block */
} scratch;
enum { SC_G, SC_AM, SC_MIXED, SC_T, SC_PL, SC_FIT, NSC };
static _Atomic(scratch *) kept_scratch;

static size_t scratch_round(size_t x)
{
	return (x + 63) & ~(size_t)63;
}

/* Where each array starts in a block for n pixels (off); its bytes. */
static size_t scratch_layout(size_t n, size_t off[NSC])
{
	size_t size[NSC] = {
		[SC_G] = n * sizeof(guide),
		[SC_AM] = n * 3 * sizeof(float),
		[SC_MIXED] = n * sizeof(bool),
		[SC_T] = n * sizeof(texel),
		[SC_PL] = NPL * (n + 2 * PL_PAD) * sizeof(float),
		[SC_FIT] = n * 3 * NFIT * sizeof(float),
	};
	size_t at = scratch_round(sizeof(scratch));
	for (int k = 0; k < NSC; k++) {
		off[k] = at;
		at += scratch_round(size[k]);
	}
	return at;
}

/* The kept block when it is for n pixels, else a new one; NULL when out of
 * memory. */
static scratch *scratch_take(size_t n, size_t off[NSC])
{
	size_t bytes = scratch_layout(n, off);
	scratch *s = atomic_exchange(&kept_scratch, NULL);
	if (s && s->n == n)
		return s;
	free(s);
	s = calloc(1, bytes);
	if (s) {
		s->n = n;
		s->bytes = bytes;
	}
	return s;
}

/* Keeps s (if small enough) in place of the block kept before, or frees it. */
static void scratch_give(scratch *s)
{
	if (s && s->bytes <= SCRATCH_KEEP)
		s = atomic_exchange(&kept_scratch, s);
	free(s);
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
	/* halves in every pixel (an adaptive render's pixels have at least
	 * its first pass's samples, fb->spp counts its mean) */
	j.halves = fb->spp >= 2;
	if (fb->pixel_spp)
		for (size_t i = 0; i < n; i++)
			j.halves &= fb->pixel_spp[i] >= 2;
	size_t off[NSC];
	scratch *sc = scratch_take(n, off);
	if (sc) {
		char *base = (char *)sc;
		j.g = (guide *)(void *)(base + off[SC_G]);
		j.am = (float *)(void *)(base + off[SC_AM]);
		j.mixed = (bool *)(void *)(base + off[SC_MIXED]);
		j.t = (texel *)(void *)(base + off[SC_T]);
		j.pl = (float *)(void *)(base + off[SC_PL]); /* the pads zero */
		j.fit = (float *)(void *)(base + off[SC_FIT]);
	}
	j.pstride = n + 2 * PL_PAD;
	pthread_t *tid = malloc((size_t)threads * sizeof *tid);
	worker_arg *args = malloc((size_t)threads * sizeof *args);
	bool ok = sc && tid && args;
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
	scratch_give(sc);
	mem_free_all(tid, args);
	return ok;
}

/* --- adaptive sampling ------------------------------------------------------ */

/* Four floats, four lanes (SSE2 and NEON have them; GCC and clang both
 * take the element-wise operators). */
typedef float v4f __attribute__((vector_size(16)));
typedef int v4i __attribute__((vector_size(16)));

static inline v4f v4_load(const float *p)
{
	v4f v;
	memcpy(&v, p, sizeof v);
	return v;
}

static inline void v4_store(float *p, v4f v)
{
	memcpy(p, &v, sizeof v);
}

/* The rows of the planes denoise_reach keeps at a time: a window's. */
#define REACH_ROWS (2 * WIN + 1)
enum { R_Z = 6, R_GX, R_GY, R_D, R_HS, R_N };

/* Image row y of fb into its slot of the planes (rows of S floats, pixel
 * x at x + WIN, np floats a plane): the six scaled features, depth, its
 * slopes, the direct light over the albedo; the reach's sums cleared. */
static void reach_row(const framebuffer *fb, int y, float *pl, size_t np, int S)
{
	int w = fb->w, h = fb->h;
	size_t o0 = (size_t)(y % REACH_ROWS) * S;
	for (int k = 0; k < R_N; k++)
		for (int x = 0; x < S; x++)
			pl[k * np + o0 + x] = k < 3 ? 1e4f : 0.0f; /* pads: far from any pixel */
	for (int x = 0; x < w; x++) {
		size_t i = (size_t)y * w + x, o = o0 + x + WIN;
		const float *f = fb->feat + i * DENOISE_FEATURES;
		float am[3];
		for (int k = 0; k < 3; k++) {
			pl[k * np + o] = f[k] * (1.0f / sqrtf(SIGMA_A2));
			pl[(3 + k) * np + o] = f[3 + k] * (1.0f / sqrtf(SIGMA_N2));
			am[k] = (float)albedo_divisor(f[k]);
		}
		pl[R_Z * np + o] = f[6];
		pl[R_GX * np + o] = depth_slope(f + 6, x, w, DENOISE_FEATURES);
		pl[R_GY * np + o] = depth_slope(f + 6, y, h, DENOISE_FEATURES * w);
		pl[R_D * np + o] = f[14] / lum(am);
	}
}

/* Row y of the reach's sums, complete, out of its slot. */
static void reach_out(const framebuffer *fb, int y, const float *hs, int S, float *reach)
{
	const float *r = hs + (size_t)(y % REACH_ROWS) * S + WIN;
	memcpy(reach + (size_t)y * fb->w, r, (size_t)fb->w * sizeof *reach);
}

bool denoise_reach(const framebuffer *fb, float *reach)
{
	int w = fb->w, h = fb->h;
	int wr = (w + 3) & ~3, S = wr + 2 * WIN; /* a padded row */
	/* a window's rows of each plane, a ring: row y in slot y % REACH_ROWS */
	size_t np = (size_t)REACH_ROWS * S;
	float *pl = malloc(np * R_N * sizeof *pl), *wt = malloc((size_t)TAPS * wr * sizeof *wt);
	if (!pl || !wt) {
		mem_free_all(pl, wt);
		return false;
	}
	float *hs = pl + R_HS * np;
	for (int y = 0; y < WIN && y < h; y++)
		reach_row(fb, y, pl, np, S);
	for (int y = 0; y < h; y++) {
		/* row y - WIN - 1 has had all its sums (the last from centre y -
		 * 1); row y + WIN takes its slot */
		if (y - WIN - 1 >= 0)
			reach_out(fb, y - WIN - 1, hs, S, reach);
		if (y + WIN < h)
			reach_row(fb, y + WIN, pl, np, S);
		size_t orow = (size_t)(y % REACH_ROWS) * S;
		for (int xb = 0; xb < wr; xb += 4) {
			size_t o = orow + xb + WIN;
			v4f g[6];
			for (int k = 0; k < 6; k++)
				g[k] = v4_load(pl + k * np + o);
			v4f gz = v4_load(pl + R_Z * np + o), gx = v4_load(pl + R_GX * np + o),
			    gy = v4_load(pl + R_GY * np + o), gd = v4_load(pl + R_D * np + o);
			v4f one = {1, 1, 1, 1}, zero = {0, 0, 0, 0};
			v4f inv_z = one / ((v4f){SIGMA_Z, SIGMA_Z, SIGMA_Z, SIGMA_Z} * gz + 1e-6f);
			v4f ad = (v4f)((v4i)gd & 0x7fffffff);
			v4f dscale = one / (0.5f * ad + 0.05f);
			v4i xs = {xb, xb + 1, xb + 2, xb + 3};
			v4i in = xs < w;
			v4f sw = zero;
			int t = 0;
			for (int dy = -WIN; dy <= WIN; dy++)
				for (int dx = -WIN; dx <= WIN; dx++, t++) {
					int qy = y + dy;
					v4f u = zero;
					if (qy >= 0 && qy < h) {
						size_t q = (size_t)(qy % REACH_ROWS) * S + xb + dx + WIN;
						v4f e = zero;
						for (int k = 0; k < 6; k++) {
							v4f d = g[k] - v4_load(pl + k * np + q);
							e += d * d;
						}
						v4f dz = v4_load(pl + R_Z * np + q) - (gz + gx * (float)dx + gy * (float)dy);
						e += (v4f)((v4i)dz & 0x7fffffff) * inv_z;
						v4f dd = (v4_load(pl + R_D * np + q) - gd) * dscale;
						e += DIRECT_W * dd * dd;
						/* the regression's weight, exp(-e) as (1 - e / 16)^16 */
						u = one - e * (1.0f / 16);
						u = (v4f)((v4i)u & ((u > zero) & in));
						u *= u;
						u *= u;
						u *= u;
						u *= u;
					}
					v4_store(wt + (size_t)t * wr + xb, u);
					sw += u;
				}
			/* each tap's share of the pixel's fit, squared, to the tap */
			v4f inv = one / (sw * sw + 1e-30f);
			t = 0;
			for (int dy = -WIN; dy <= WIN; dy++)
				for (int dx = -WIN; dx <= WIN; dx++, t++) {
					int qy = y + dy;
					if (qy < 0 || qy >= h)
						continue;
					v4f u = v4_load(wt + (size_t)t * wr + xb);
					float *dst = hs + (size_t)(qy % REACH_ROWS) * S + xb + dx + WIN;
					v4_store(dst, v4_load(dst) + u * u * inv);
				}
		}
	}
	for (int y = h - WIN - 1 < 0 ? 0 : h - WIN - 1; y < h; y++)
		reach_out(fb, y, hs, S, reach);
	mem_free_all(pl, wt);
	return true;
}


/* The noise of one sample's brightness about each pixel of fb (its samples
 * so far, at least two; features 7): the variance in each pixel from the
 * mean of the squared brightness and the mean's square, n / (n - 1)
 * unbiased; then each pixel the root of the mean over its 3x3 window (the
 * pixels inside the image and not fixed), its own included. */
bool denoise_fixed(const float *f)
{
	/* the sky or background: depth 0 and no direct light (a glossy
	 * metal's lobe that the sky is seen through brings its lamps; the
	 * sky behind glass or in a mirror has that surface's depth) */
	bool background = !(f[6] > 0.0f) && !(f[14] > 0.0f);
	return background || f[0] > 1.0f || f[1] > 1.0f || f[2] > 1.0f;
}

bool denoise_sigma(const framebuffer *fb, float *sigma)
{
	int w = fb->w, h = fb->h;
	size_t n = (size_t)w * (size_t)h;
	float *v = malloc(n * sizeof *v);
	if (!v)
		return false;
	for (size_t i = 0; i < n; i++) {
		int spp = pixel_spp(fb, i);
		/* the mean from the sums when there are (the shell's preview
		 * denoises rgb in place after each pass), as a job writes rgb */
		float own[3];
		const float *c = fb->rgb + i * 3;
		if (fb->sum) {
			double inv = 1.0 / spp;
			for (int k = 0; k < 3; k++)
				own[k] = (float)(fb->sum[i * 3 + k] * inv);
			c = own;
		}
		double m = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
		double var = spp > 1 ? ((double)fb->feat[i * DENOISE_FEATURES + 7] - m * m) * spp / (spp - 1) : 0.0;
		v[i] = var > 0 && !denoise_fixed(fb->feat + i * DENOISE_FEATURES) ? (float)var : 0.0f;
	}
	for (int y = 0; y < h; y++)
		for (int x = 0; x < w; x++) {
			double s = 0;
			int k = 0;
			for (int dy = -1; dy <= 1; dy++)
				for (int dx = -1; dx <= 1; dx++) {
					int qx = x + dx, qy = y + dy;
					/* a fixed pixel's noise is not known (its
					 * variance was set to 0): it does not count */
					if (qx < 0 || qy < 0 || qx >= w || qy >= h ||
					    denoise_fixed(fb->feat + ((size_t)qy * w + qx) * DENOISE_FEATURES))
						continue;
					s += v[(size_t)qy * w + qx];
					k++;
				}
			sigma[(size_t)y * w + x] = k ? (float)sqrt(s / k) : 0.0f;
		}
	free(v);
	return true;
}

/* A pixel's samples before rounding: l (sigma + floor), clamped to
 * [first, cap]. */
static inline double alloc_one(float sigma, double l, double floor_, int first, int cap)
{
	double v = l * ((double)sigma + floor_);
	return v < first ? first : v > cap ? cap : v;
}

/* The pixels' alloc_one summed. */
static double alloc_total_floor(const float *sigma, size_t n, double l, double floor_, int first, int cap)
{
	double t = 0;
	for (size_t i = 0; i < n; i++)
		t += alloc_one(sigma[i], l, floor_, first, cap);
	return t;
}

void denoise_allocate(const float *sigma, size_t n, int first, int mean, int cap, uint16_t *out)
{
	/* Every pixel a little weight: a black image, or one of a few noisy
	 * pixels, still spends the whole budget (a thousandth of the mean). */
	double ms = 0;
	for (size_t i = 0; i < n; i++)
		ms += sigma[i];
	ms = ms > 0 ? ms / (double)n * 1e-3 : 1.0;
	/* l: the samples per unit of noise, so that the pixels' clamped
	 * shares sum to mean n (the sum grows with l; bisection) */
	double total = (double)mean * (double)n, lo = 0, hi = 1;
	while (alloc_total_floor(sigma, n, hi, ms, first, cap) < total && hi < 1e30)
		hi *= 2;
	for (int it = 0; it < 64; it++) {
		double mid = 0.5 * (lo + hi);
		if (alloc_total_floor(sigma, n, mid, ms, first, cap) < total)
			lo = mid;
		else
			hi = mid;
	}
	/* The pairs of samples above first: each pixel's real share, rounded
	 * by their running sum (so that they sum to the whole exactly, and
	 * each pixel gets its share rounded down or up). */
	long pairs = (long)(((long long)(mean - first) * (long long)n) / 2);
	double sum = 0;
	for (size_t i = 0; i < n; i++)
		sum += alloc_one(sigma[i], hi, ms, first, cap) - first;
	double run = 0, scale = sum > 0 ? (double)pairs / (0.5 * sum) : 0.0;
	long given = 0;
	for (size_t i = 0; i < n; i++) {
		run += 0.5 * (alloc_one(sigma[i], hi, ms, first, cap) - first) * scale;
		long upto = i + 1 == n ? pairs : (long)floor(run + 0.5);
		if (upto > pairs)
			upto = pairs;
		if (upto < given)
			upto = given;
		out[i] = (uint16_t)(first + 2 * (upto - given));
		given = upto;
	}
}
