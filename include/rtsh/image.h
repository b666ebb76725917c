/* rtsh — image files and atomic writes.
 *
 * PPM P6 (8-bit sRGB), PFM (linear 32-bit float, little-endian, bottom row
 * first as the format requires) and PNG (8-bit sRGB, libpng). Every file is
 * written to a temporary file in the same folder and renamed over the
 * target, so an interrupted save never destroys an older file.
 */
#ifndef RTSH_IMAGE_H
#define RTSH_IMAGE_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "rtsh/error.h"
#include "rtsh/render.h"
#include "rtsh/srgb.h" /* linear_to_srgb8: the 8-bit formats */

/* One image file format: a row of the table in image.c, by extension.
 * Adding a format is its encoder (and decoder) in image.c and one row:
 * `save`, `rtsh -o`, rtsh-mpi, their messages, usage texts and completion
 * list the table. */
typedef struct image_type {
	const char *ext;    /* ".ppm" */
	const char *name;   /* "PPM"; rows of one format share it (".jpg", ".jpeg") */
	bool (*write)(FILE *f, void *ctx, rt_error *err); /* image.c's encoder */
	framebuffer *(*read)(const char *path, rt_error *err); /* NULL: not read */
	const char *help;   /* one line */
	bool linear;        /* keeps linear radiance (PFM); else 8-bit sRGB codes */
	/* image_write_rendered's encoder, that writes the rows as the render
	 * finishes them; NULL: the format needs the whole picture first */
	bool (*write_rendered)(FILE *f, void *ctx, rt_error *err);
} image_type;

/* The i-th format, NULL past the last; the format of path by its
 * extension (case-insensitive), or NULL. */
const image_type *image_type_at(size_t i);
const image_type *image_type_of(const char *path);
/* The extensions as a message lists them (".ppm, .pfm or .png"); only
 * those read back when `readable`. */
void image_extensions(char *buf, size_t size, bool readable);
/* The extensions of the formats written, each after prefix, joined by sep:
 * ("FILE", "|") "FILE.ppm|FILE.pfm|FILE.png|FILE.jpg"; only the first
 * extension of a format (not .jpeg) when first_only. */
void image_extensions_join(char *buf, size_t size, const char *prefix, const char *sep, bool first_only);
/* Reads any readable format, by extension. */
framebuffer *image_read(const char *path, rt_error *err);

/* Writes the framebuffer. `exposure` (stops: radiance x 2^exposure) applies
 * to the 8-bit formats; a PFM keeps the linear radiance as rendered. */
bool image_write(const char *path, const framebuffer *fb, double exposure, rt_error *err);

/* Makes the picture while its file is written (batch mode): the file is
 * created first; make(make_ctx, rows, rows_ctx, err) renders the w x h
 * picture with render_image_rows(..., rows, rows_ctx, ...) and returns its
 * framebuffer, or NULL with err set; a PPM or PNG then takes each band of
 * rows as the render finishes it (the main thread writes and starts the
 * disk's write-back while the workers render), so that only the last band,
 * the sync and the rename are left after the render. A format that needs
 * the whole picture (image_type.write_rendered NULL: PFM, JPEG) gets make
 * called with rows NULL (make renders as render_image or
 * render_image_srgb8 do) and is written after it, as image_write does. The
 * file is replaced atomically either way: a render that fails or is
 * interrupted leaves the old file as it was. `exposure` as image_write's;
 * the framebuffer is freed here. */
typedef framebuffer *(*image_make_fn)(void *make_ctx, render_rows_fn rows, void *rows_ctx, rt_error *err);
bool image_write_rendered(const char *path, int w, int h, double exposure, image_make_fn make, void *make_ctx,
                          rt_error *err);

/* Readers for tests and tools: a new framebuffer with linear values (PPM
 * codes are sRGB-decoded), through the textures' one netpbm/PFM reader
 * (image_load_netpbm, texture.h). NULL with err set on failure. */
framebuffer *image_read_pfm(const char *path, rt_error *err);
framebuffer *image_read_ppm(const char *path, rt_error *err);

/* file_write_atomic (atomic.h) writes every image. */
#include "rtsh/atomic.h"

#endif
