/* rtsh — a denoiser for path-traced images, guided by the first hit.
 *
 * A path-mode render job whose framebuffer has feature buffers
 * (denoise_prepare) also records, for every pixel, the mean over its first
 * DENOISE_FEATURE_SAMPLES samples of what the camera ray first sees: the
 * surface's albedo, its normal and its distance. Through perfect mirrors and
 * glass the features are those of the surface seen in them, so reflections
 * keep their own edges. The features are nearly free of noise, so they tell
 * the filter where the picture's edges are.
 *
 * denoise_image filters the noisy radiance with the edge-avoiding a-trous
 * wavelet transform (Dammertz, Sewtz, Hanika & Lensch, "Edge-avoiding
 * A-Trous wavelet transform for fast global illumination filtering", HPG
 * 2010): five passes of a 5x5 B3-spline kernel whose taps lie 1, 2, 4, 8
 * and 16 pixels apart, each tap weighted down by how much its normal,
 * albedo, depth and brightness differ from the centre's. As in SVGF (Schied
 * et al., "Spatiotemporal variance-guided filtering", HPG 2017) the
 * radiance is divided by the albedo first (textures are not blurred, only
 * the lighting), depth is compared along its own gradient (slanted planes
 * are one surface), and brightness differences are measured against a
 * per-pixel estimate of the noise that each pass carries along, so that
 * converged pixels are left alone and shadow edges stay.
 *
 * The result depends only on the image and its features, never on the
 * number of threads.
 */
#ifndef RTSH_DENOISE_H
#define RTSH_DENOISE_H

#include <stdbool.h>

#include "rtsh/render.h"
#include "rtsh/world.h"

/* Floats per pixel in framebuffer.feat: albedo r g b, normal x y z (the
 * side facing the camera), depth (distance along the camera ray; 0 for the
 * sky), and the mean over all the samples of their squared brightness
 * (denoise_sq), from which the noise of the pixel is estimated. */
#define DENOISE_FEATURES 8
/* The features are the mean of at most this many samples per pixel. */
#define DENOISE_FEATURE_SAMPLES 8

/* Gives fb its feature buffer (cleared) if it has none, so that path-mode
 * render jobs into it record features; false when out of memory. */
bool denoise_prepare(framebuffer *fb);

/* The squared brightness (Rec. 709 luminance) of one sample's radiance. */
static inline double denoise_sq(vec3 c)
{
	double l = 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
	return l * l;
}

/* Adds the features of samples [begin, end) of pixel (px, py) of an fw x fh
 * image to f (DENOISE_FEATURES floats holding those of samples [0, begin));
 * sq is the sum of denoise_sq over the new samples. Render jobs call it per
 * pixel. */
void denoise_features(const world *w, int px, int py, int fw, int fh, int begin, int end, double sq,
                      float *f);

/* Writes the denoised radiance of fb (which has features and samples) to
 * out, w*h*3 linear floats; out may be fb->rgb. threads: the workers to use
 * (>= 1). False when out of memory (out is then untouched). */
bool denoise_image(const framebuffer *fb, float *out, int threads);

#endif
