/* rtsh — a denoiser for path-traced images, guided by the first hit.
 *
 * A path-mode render job whose framebuffer has feature buffers
 * (denoise_prepare) also records, for every pixel, the mean over its first
 * DENOISE_FEATURE_SAMPLES samples' own camera rays of what they first see:
 * the surface's albedo, its normal and its distance. Through perfect
 * mirrors, glass and metals of little fuzz (a Phong lobe of exponent 200
 * or more) the features are those of the surface seen in them, so
 * reflections keep their own edges. Where those first rays disagree (an
 * edge runs through the pixel), or where they agree but the pixel's four
 * corners (DENOISE_PROBE_INSET of a pixel inside it) find something else
 * (an edge that covers too little of the pixel for the first ones to
 * meet: a straight edge leaves a corner on each side), DENOISE_EDGE_SAMPLES
 * camera positions are taken (first hits only), so that the features of an
 * edge pixel are as well antialiased as that many samples would make its
 * colour.
 *
 * The sky's albedo feature is its colour in that direction (a black
 * background's is white); through glass the surface behind is tinted by the
 * share the glass lets through and the share it reflects is added as
 * white. A lamp's albedo feature is its emission, far from any surface's, so that
 * no filter mixes a lamp with what lies next to it; but a lamp seen through
 * a glossy metal (not a perfect mirror) is blurred by it, and there the
 * metal's own features are taken. A further feature is the direct light
 * the surface sends to the eye (the point lights exactly, each lamp from 4
 * points a sample and the sky from 4 directions a sample drawn from the
 * surface's bsdf, shadowed: over the first DENOISE_FEATURE_SAMPLES samples one
 * fixed set of 32 of each, the same for every pixel, so that the feature is
 * smooth; through a glossy metal that is looked through, its own highlight
 * too, the lamps from 8 directions a sample of its own lobe, 64 fixed ones
 * in all; at an edge pixel that lobe's light over the DENOISE_EDGE_SAMPLES
 * positions, one direction each, so that how much of the pixel a
 * highlight covers is as well known as its albedo): it explains shadows,
 * highlights and the sky's contact shadows that albedo and normal do not. The job also keeps the mean
 * radiance and squared brightness of the even-numbered samples: with
 * those of all of them they split the samples into two independent halves,
 * and the albedo at the even samples' and all the samples' own positions.
 *
 * denoise_image is a feature regression after NFOR (Bitterli et al.,
 * "Nonlinearly Weighted First-order Regression for Denoising Monte Carlo
 * Renderings", EGSR 2016), with its colour weights left out. The radiance
 * is divided by the albedo (textures are not blurred, only the lighting):
 * with at most DENOISE_FEATURE_SAMPLES samples by the albedo at the
 * samples' own positions (each half by its own), so that how many samples
 * met which surface at an edge is no noise of the lighting, and multiplied
 * again by the features' better antialiased albedo. Around each pixel a
 * first-order model of the lighting in screen position, normal, depth and
 * direct light is fitted by least squares over 9x9 pixels, each weighted
 * by how alike its albedo, normal and depth (off the pixel's plane) are to
 * the pixel's, and evaluated at the pixel. No weight depends on the noise,
 * so the fit of each half depends on that half's samples alone, and the
 * other half's raw pixel estimates the fit's squared error without bias
 * (NFOR's cross-buffer estimate: half a's fit against half b's pixel is
 * off by a's error plus b's noise, whose variance the samples give). A
 * second fit over the same taps takes the direct light alone (a constant
 * and its slope), for where few taps are alike. Per pixel a fit or the raw
 * pixel's lighting is kept, whichever the estimate, averaged over 9x9
 * pixels, says is closer (where both fits beat the raw pixel, their blend
 * weighted by their estimated gains on it): shadows and highlights the
 * features do not see stay sharp. Last, a pixel that is part one surface, part another
 * is regressed on the features of its 3x3 window: it gets the mix of its
 * neighbours that its features say. With one sample there are no halves:
 * the fit is taken.
 *
 * The result depends only on the image and its features, never on the
 * number of threads.
 */
#ifndef RTSH_DENOISE_H
#define RTSH_DENOISE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rtsh/render.h"
#include "rtsh/world.h"

/* Floats per pixel in framebuffer.feat:
 *   0-2  albedo r g b,
 *   3-5  normal x y z (the side facing the camera),
 *   6    depth (distance along the camera ray; 0 for the sky),
 *   7    the mean over all the samples of their squared brightness
 *        (denoise_radiance), from which the noise of the pixel is estimated,
 *   8    the mean squared length of the albedo, 9 of the depth (how much
 *        the features vary inside the pixel),
 *   10-12 the mean radiance of the pixel's even-numbered samples, 13 the
 *        mean of their squared brightness: with the means over all of them
 *        (framebuffer.rgb, 7) they split the samples into two independent
 *        halves,
 *   14   the direct light's brightness (see above),
 *   15-17 the mean albedo at the even-numbered samples' own camera rays,
 *        18-20 at all of them (the first DENOISE_FEATURE_SAMPLES),
 *   21   the part of 14 that glossy lobes looked through send.
 * 0-6, 8, 9 and 21 are means over the first DENOISE_FEATURE_SAMPLES
 * samples' camera rays, or over DENOISE_EDGE_SAMPLES positions where those
 * disagree; 14 is 21 and the rest's mean over the first samples. */
#define DENOISE_FEATURES 22
/* The features are the mean of at most this many samples per pixel... */
#define DENOISE_FEATURE_SAMPLES 8
/* ...or of this many camera positions (first hits only, no paths) at a
 * pixel whose first ones see different surfaces: the albedo the lighting
 * is multiplied by again after filtering is then as well antialiased as
 * that many samples would make it. */
#define DENOISE_EDGE_SAMPLES 64
/* ...or where the first ones agree, but the pixel's corners, this share of
 * a pixel inside it on each side, do not. */
#define DENOISE_PROBE_INSET 0.125
/* Doubles of a pixel's feature sums over a run of its samples
 * (denoise_sample): 0-6 and 8-9 as the features, 7 the direct light, 10-12
 * the albedo of the even-numbered samples, 13 the glossy lobes' part of 7. */
#define DENOISE_ACC 14

/* Gives fb its feature buffer (cleared) if it has none, so that path-mode
 * render jobs into it record features; false when out of memory. */
bool denoise_prepare(framebuffer *fb);

/* Doubles of a pixel's radiance sums over a run of its samples
 * (denoise_radiance): the squared brightness, the even samples' radiance
 * and squared brightness. */
#define DENOISE_RACC 5

/* Adds sample k's radiance c to ra (DENOISE_RACC doubles): its squared
 * brightness (Rec. 709 luminance), and when k is even c and that again. */
static inline void denoise_radiance(vec3 c, int k, double *ra)
{
	double l = 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
	ra[0] += l * l;
	if (!(k & 1)) {
		ra[1] += c.x;
		ra[2] += c.y;
		ra[3] += c.z;
		ra[4] += l * l;
	}
}

/* Adds to acc (DENOISE_ACC doubles) what the camera ray r of sample k
 * first sees. */
void denoise_sample(const world *w, ray r, int k, double *acc);

/* Updates the features f of pixel (px, py) of an fw x fh image (those of
 * samples [0, begin)) with samples [begin, end): acc holds denoise_sample's
 * sums over those of them below DENOISE_FEATURE_SAMPLES, ra the sums of
 * denoise_radiance over all of them. Render jobs call it per pixel; when the
 * pixel reaches DENOISE_FEATURE_SAMPLES and its features vary, the edge
 * positions are added (render_sample_ray with s). */
void denoise_features(const world *w, const render_settings *s, int px, int py, int fw, int fh,
                      int begin, int end, const double *ra, const double *acc, float *f);

/* The same for camera positions [begin, end) (end at most
 * DENOISE_FEATURE_SAMPLES) of no radiance sample: the features of a pixel
 * whose adaptive samples (render_job.pixel_end) are fewer than
 * DENOISE_FEATURE_SAMPLES are still made over that many positions (the
 * albedo at its radiance samples' own positions, 15-20, over its own). */
void denoise_features_only(const world *w, const render_settings *s, int px, int py, int fw, int fh,
                           int begin, int end, float *f);

/* Writes the denoised radiance of fb (which has features and samples) to
 * out, w*h*3 linear floats; out may be fb->rgb. threads: the workers to use
 * (>= 1). False when out of memory (out is then untouched). */
bool denoise_image(const framebuffer *fb, float *out, int threads);

/* Adaptive sampling at the same budget: a denoised render of S samples
 * spends S x W x H camera paths, DENOISE_FIRST(S) (3/4 of S, even) in
 * every pixel first, then the rest where the noise the filter leaves is
 * (render_image: denoise_sigma times a power of denoise_reach). */
#define DENOISE_FIRST(S) ((3 * (S) / 4) & ~1)
/* ...each pixel at most 16 times the mean (8: metal-fuzz 1-2% worse, its
 * highlights' pixels held at 64 of 8), and below 65535 (a pixel's count is
 * 16 bits, framebuffer.pixel_spp; RENDER_ADAPTIVE_MAX x 16 is 65536). */
#define DENOISE_CAP_TIMES 16
#define DENOISE_CAP(S) (DENOISE_CAP_TIMES * (S) < 65534 ? DENOISE_CAP_TIMES * (S) : 65534)
/* A pixel that got at least this many times the mean (framebuffer.spp,
 * with pixel_spp set) chooses among the denoiser's candidates (its raw
 * mean, the two regressions) by its own cross-half error estimates, not
 * by those averaged over its window, and no mixed pixel's step moves it.
 * The allocation gives so many where the neighbours are the noisiest, a
 * glossy highlight's: there the window's pixels have few samples, their
 * estimates say the fits beat the raw pixel, and the fits are biased;
 * with 4 x 8 samples and more the pixel's own halves tell (metal-fuzz
 * 160x96, 4 seeds: 1.755 -> 1.580 times the 64 samples' squared error;
 * 2 x: cornell 25% worse; bench/README, the denoise7 session). */
#define DENOISE_OWN_TIMES 4

/* The noise about each pixel of fb (features and at least 2 samples a
 * pixel) into sigma (w*h): the standard deviation of one sample's
 * brightness over its 3x3 window, the root of the mean of the nine
 * variances (those of fixed pixels, denoise_fixed, left out: their noise
 * is not known), its own included. Until the denoise12 session its own was
 * left out, so that its count would not depend on its samples (a pixel
 * whose first samples happened to miss a bright path keeps fewer, and its
 * mean is low on average); but then a pixel whose first samples met one,
 * a firefly, gave more samples to its neighbours and kept its firefly at
 * 6 of 8 samples, which cost more: with its own included, 4 seeds,
 * metal-fuzz, final, cornell, spot, sky-spheres, RMS new/old: 128x96
 * 1.006 0.992 0.991 0.962 0.990, 200x120 0.989 0.991 0.981 0.964 0.987,
 * 640x360 0.979 0.995 1.011 0.948 0.997 (bench/README). False when out of
 * memory. */
bool denoise_sigma(const framebuffer *fb, float *sigma);
/* How much of each pixel's noise the filter passes on, from the features
 * alone (no sample's radiance) into reach (w*h): the sum, over the pixels
 * whose 9x9 window holds it, of its share of that pixel's fit squared,
 * (w_pt / sum_q w_pq)^2, w the regression's weight of the tap (albedo,
 * normal, depth off the pixel's plane and direct light, as denoise_image
 * weighs its taps). The filtered image's variance is then about
 * sum_t reach_t sigma_t^2 / n_t: 1/K in a surface of K alike pixels
 * around, 1 for a pixel like none of its window (a highlight a pixel
 * wide, a sliver of a small sphere), whose noise the fit keeps. False
 * when out of memory. */
bool denoise_reach(const framebuffer *fb, float *reach);
/* The adaptive samples go where sigma_p reach_p^DENOISE_REACH_POW is: the
 * n_p that minimise sum_p reach_p sigma_p^2 / n_p are proportional to
 * sigma_p reach_p^0.5; less than that hedges for the pixels where the
 * filter keeps the raw mean (its reach is 1 there, whatever the features
 * say). 4 seeds, metal-fuzz, final, cornell, spot, sky-spheres, RMS
 * new/old: 128x96 0.975 0.962 0.984 1.010 1.002, 200x120 0.980 0.957
 * 0.993 1.007 0.989 (bench/README, the denoise12 session; 0.5: geomean
 * 0.9907, 0.25: 0.9877). */
#define DENOISE_REACH_POW 0.375
/* Whether a pixel of features f keeps the samples a uniform render gives it
 * and its noise counts for none of its neighbours: its first positions all
 * missed the scene (the background or the sky: a path there is one ray,
 * and its samples spent on a surface would cost a whole path each; depth
 * 0 and no direct light, feature 14), or they see a lamp (albedo feature
 * above 1: a lamp's edge is noise of radiance far above the display's, and
 * took the samples of the surfaces around it). The sky seen in a glossy
 * metal (depth 0 too: the features are the sky's) has the lamps the lobe
 * sees as its direct light: a whole path, and the noise of the highlight;
 * it was fixed until the denoise7 session (metal-fuzz 200x120, 4 seeds,
 * 0.816 -> 0.729 of the uniform render's RMS error). */
bool denoise_fixed(const float *f);

/* Each of n pixels' samples into out: first (even) or more, at most cap,
 * first + an even number, summing to mean x n (or the even total below it
 * when (mean - first) x n is odd): the n_p that minimise
 * sum sigma_p^2 / n_p under those bounds, n_p = clamp(l sigma_p, first,
 * cap), rounded to pairs by their running sum (deterministic, in pixel
 * order). Every pixel has a thousandth of the mean sigma added, so that
 * the budget is spent whatever sigma holds. cap >= mean >= first. */
void denoise_allocate(const float *sigma, size_t n, int first, int mean, int cap, uint16_t *out);

#endif
