/* rtsh — animated GIF files (GIF89a), written by our own encoder: each
 * frame quantised to its own palette of at most 256 colours by median cut
 * (Heckbert 1982) over a 15-bit histogram, then LZW-compressed with
 * variable-length codes (the GIF89a specification, appendix F); the
 * NETSCAPE2.0 extension makes it loop for ever.
 *
 * The frames are kept encoded in memory and the file is written at the
 * end, atomically (rtsh/atomic.h).
 */
#ifndef RTSH_GIF_H
#define RTSH_GIF_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rtsh/error.h"

typedef struct gif_anim gif_anim;

/* An animation of w x h pixels (1..65535 each), each frame shown for
 * delay_cs hundredths of a second. NULL when out of memory or the size is
 * out of range. */
gif_anim *gif_new(int w, int h, int delay_cs);
void gif_free(gif_anim *g);
/* Adds a frame of w x h sRGB pixels (3 bytes each, rows top down); false
 * when out of memory. */
bool gif_add_frame(gif_anim *g, const uint8_t *rgb);
/* The same from linear radiance (w x h x 3 floats) at an exposure in
 * stops, sRGB-encoded as the 8-bit image files are (linear_to_srgb8). */
bool gif_add_linear(gif_anim *g, const float *rgb, double exposure);
/* The file's bytes so far, with the trailer (valid until the next call). */
const uint8_t *gif_bytes(gif_anim *g, size_t *len);
/* Writes the file atomically; false (err set) on failure. */
bool gif_save(gif_anim *g, const char *path, rt_error *err);
/* Median cut: at most max (1..256) colours for n sRGB pixels into pal
 * (max*3 bytes), and each pixel's index into idx (n bytes, may be NULL).
 * Returns the number of colours, 0 when out of memory. */
int gif_quantize(const uint8_t *rgb, size_t n, int max, uint8_t *pal, uint8_t *idx);

#endif
