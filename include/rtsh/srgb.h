/* rtsh — sRGB (IEC 61966-2-1), the one place it is decoded and encoded
 * (base layer, src/base/srgb.c). Scene colours, MTL colours, 8-bit
 * textures and PPM files are sRGB; the renderer works in linear light. */
#ifndef RTSH_SRGB_H
#define RTSH_SRGB_H

#include <stddef.h>
#include <stdint.h>

#include "rtsh/math.h"

/* A display value in [0,1] to linear light (not clamped). */
double srgb_to_linear(double v);
/* An sRGB code 0..255, not necessarily whole, to linear: srgb_to_linear(code
 * / 255); whole codes come from a table of the same bits. */
double srgb8_to_linear(double code);
/* The three channels of an sRGB colour 0..255 to linear. */
vec3 srgb255_to_linear(vec3 c);
/* The table srgb8_to_linear reads for the whole codes 0..255 (made at the
 * first call): for a caller that decodes a million colours in line
 * (world_build's materials), the same bits without a call a colour. */
const double *srgb8_table(void);
/* Linear [0,1] (and above) to sRGB codes 0..255, not rounded: the inverse of
 * srgb255_to_linear, for readers whose colours are linear (glTF factors). */
vec3 linear_to_srgb255(vec3 c);
/* Linear [0,1] to 8-bit sRGB, rounded, clamped; exact inverse of srgb8_to_linear
 * on the 256 codes. */
uint8_t linear_to_srgb8(double v);
/* out[i] = linear_to_srgb8(in[i] * gain) for i < n: the same codes, without
 * a call per value (image files, and render tiles as they finish). */
void linear_to_srgb8_n(const float *in, double gain, uint8_t *out, size_t n);

#endif
