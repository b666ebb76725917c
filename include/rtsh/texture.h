/* rtsh — image textures: reading images, mip-maps and filtered lookups.
 *
 * Any image rtsh reads (PNG, JPEG, BMP, TGA and Radiance HDR through
 * stb_image; PPM/PGM and PFM by our own code; XPM through libXpm) becomes a
 * texture: linear RGB floats in a chain of mip levels, each half the size
 * of the one above (box-filtered). A lookup takes texture coordinates
 * (u right, v up: (0,0) is the image's bottom-left corner, as in OBJ and
 * glTF after its flip) and the footprint of the pixel in u units; it picks
 * the two levels around the footprint and filters each bilinearly
 * (trilinear filtering, Williams, "Pyramidal parametrics", 1983), which
 * keeps a distant checkerboard from shimmering in the low-resolution
 * terminal preview. Coordinates wrap (repeat).
 */
#ifndef RTSH_TEXTURE_H
#define RTSH_TEXTURE_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>

#include "rtsh/error.h"
#include "rtsh/math.h"

#define TEX_MAX_LEVELS 24

typedef struct tex_level {
	int w, h;
	float *rgb; /* w * h * 3, top row first */
} tex_level;

typedef struct texture {
	char *path;
	bool srgb;
	int nlevels;
	tex_level level[TEX_MAX_LEVELS];
	size_t refs;
} texture;

/* An image as read: w x h linear RGB floats, top row first. srgb: 8-bit
 * codes are sRGB-decoded (colour textures); otherwise divided by 255 (normal
 * and bump maps). HDR and PFM are linear whatever srgb says. NULL (err set,
 * "PATH: what is wrong") on failure: a missing file, an unknown extension,
 * a corrupt or zero-sized image, an XPM with a bad colour table. */
float *image_load_rgb(const char *path, bool srgb, int *w, int *h, rt_error *err);
/* The same from memory; the format from `path`'s extension (fuzzing). */
float *image_decode_rgb(const char *path, const unsigned char *buf, size_t len, bool srgb, int *w, int *h,
                        rt_error *err);
/* The alpha channel of an image in memory (glTF MASK cut-outs): *alpha
 * w x h bytes, top row first, codes / 255 the linear alpha (never
 * sRGB-decoded). PNG, TGA and BMP with an alpha channel (grey+alpha or
 * RGBA); *alpha NULL for an image without one (opaque). False (err set)
 * when the image cannot be decoded. */
bool image_decode_alpha(const char *path, const unsigned char *buf, size_t len, unsigned char **alpha, int *w, int *h,
                        rt_error *err);
/* The previewer's budget for textures (rtsh(1), --preview): an image of
 * more pixels than this is not decoded; its reader fails, and the callers
 * that can go on without it (texture=, normalmap=, bump=, a model's own
 * images) see image_budget_refused and leave the surface untextured. 0 (the
 * default): no budget. Set before any thread reads images. */
void image_budget_set(size_t pixels);
/* On this thread, images read until it is called again with false are not
 * held to the budget (the sky: without it there is no picture). */
void image_budget_exempt(bool on);
/* True when err is this thread's last refusal by the budget. */
bool image_budget_refused(const rt_error *err);
/* How many different images the budget refused, and the first one's
 * message in first (size bytes). */
size_t image_budget_report(char *first, size_t size);
/* The one netpbm and PFM reader, for a file on disk whatever its name:
 * pfm false, PPM/PGM (P2 P3 P5 P6, 8 or 16 bits, sRGB-decoded); pfm true,
 * PFM (PF colour, Pf grey, linear; non-finite values read as 0). image.c's
 * image_read_ppm and image_read_pfm read rendered pictures back with it. */
float *image_load_netpbm(const char *path, bool pfm, int *w, int *h, rt_error *err);
/* True when the extension is one image_load_rgb reads. */
bool image_format_known(const char *path);

/* A texture with its mip chain; takes the pixels (freed on failure). Its
 * path is a copy of name (NULL: none) and srgb says how its pixels were
 * decoded (the caches' key). */
texture *texture_make(float *rgb, int w, int h, const char *name, bool srgb, rt_error *err);
texture *texture_load(const char *path, bool srgb, rt_error *err);
void texture_free(texture *t);

/* Loaded once per (path, srgb, file version); thread-safe. */
texture *texture_cache_get(const char *path, bool srgb, const atomic_bool *cancel, rt_error *err);
void texture_cache_put(texture *t);

/* The filtered colour at (u, v); `width` is the footprint in u units (0:
 * the finest level, bilinear). */
vec3 texture_lookup(const texture *t, double u, double v, double width);
/* One texel of level 0 (x right, y down from the top row), clamped. */
vec3 texture_texel(const texture *t, int x, int y);

/* The angle one pixel of the image being rendered spans, for footprints:
 * render.c sets it for its thread (0: no footprint, finest level). */
void texture_set_pixel_angle(double a);
double texture_pixel_angle(void);

#endif
