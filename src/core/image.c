/* rtsh — image files (image.h); atomic.c writes them. */
#define _GNU_SOURCE /* sync_file_range */
#include "rtsh/image.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <png.h>
#include <stb/stb_image_write.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "rtsh/filesrc.h"
#include "rtsh/texture.h"

/* The extension of path ("" when none). */
static const char *extension(const char *path)
{
	const char *dot = strrchr(path, '.');
	const char *slash = strrchr(path, '/');
	return !dot || (slash && dot < slash) ? "" : dot;
}


typedef struct image_ctx {
	const framebuffer *fb;
	double gain;
	const char *path;
} image_ctx;

/* The 8-bit codes of the image: the framebuffer's own when its render wrote
 * them with this gain (render.h), else a new array (*owned set). */
static uint8_t *encode_rows(const image_ctx *c, bool *owned)
{
	const framebuffer *fb = c->fb;
	*owned = false;
	if (fb->srgb8 && fb->srgb8_gain == c->gain)
		return fb->srgb8;
	size_t n = (size_t)fb->w * (size_t)fb->h * 3;
	uint8_t *px = malloc(n);
	if (!px)
		return NULL;
	linear_to_srgb8_n(fb->rgb, c->gain, px, n);
	*owned = true;
	return px;
}

/* An 8-bit format's encoder, given the image's sRGB codes px (rows top to
 * bottom, R,G,B). */
typedef bool (*write8_fn)(FILE *f, const image_ctx *c, uint8_t *px, rt_error *err);

/* Runs an 8-bit encoder on the image's codes (encode_rows) and frees them
 * when they were made for it. */
static bool write_8bit(FILE *f, const image_ctx *c, write8_fn put, rt_error *err)
{
	bool owned;
	uint8_t *px = encode_rows(c, &owned);
	if (!px)
		return rt_error_at(err, c->path, 0, 0, "out of memory");
	bool ok = put(f, c, px, err);
	if (owned)
		free(px);
	return ok;
}

static bool ppm_put(FILE *f, const image_ctx *c, uint8_t *px, rt_error *err)
{
	fprintf(f, "P6\n%d %d\n255\n", c->fb->w, c->fb->h);
	size_t n = (size_t)c->fb->w * (size_t)c->fb->h * 3;
	return fwrite(px, 1, n, f) == n || rt_error_at(err, c->path, 0, 0, "write failed");
}

static bool write_ppm(FILE *f, void *vctx, rt_error *err)
{
	return write_8bit(f, vctx, ppm_put, err);
}

static bool write_pfm(FILE *f, void *vctx, rt_error *err)
{
	image_ctx *c = vctx;
	const framebuffer *fb = c->fb;
	/* A negative scale means little-endian; rows go bottom to top. */
	fprintf(f, "PF\n%d %d\n-1.0\n", fb->w, fb->h);
	float *row = malloc((size_t)fb->w * 3 * sizeof *row);
	if (!row)
		return rt_error_at(err, c->path, 0, 0, "out of memory");
	bool ok = true;
	for (int y = fb->h - 1; y >= 0 && ok; y--) {
		const float *src = fb->rgb + (size_t)y * fb->w * 3;
		for (int i = 0; i < fb->w * 3; i++) {
			float v = src[i]; /* linear radiance, exposure not applied */
			uint32_t bits;
			memcpy(&bits, &v, 4);
			uint8_t le[4] = {(uint8_t)bits, (uint8_t)(bits >> 8), (uint8_t)(bits >> 16),
			                 (uint8_t)(bits >> 24)};
			memcpy(&row[i], le, 4);
		}
		ok = fwrite(row, sizeof *row, (size_t)fb->w * 3, f) == (size_t)fb->w * 3;
	}
	free(row);
	return ok || rt_error_at(err, c->path, 0, 0, "write failed");
}

/* libpng's errors end in our message, not on its own line on stderr (the
 * error pointer is a char[160]); its warnings (none for what we write) are
 * dropped. */
static void png_error_kept(png_structp png, png_const_charp msg)
{
	snprintf(png_get_error_ptr(png), 160, "%s", msg);
	png_longjmp(png, 1);
}

static void png_warning_dropped(png_structp png, png_const_charp msg)
{
	(void)png;
	(void)msg;
}

static bool png_put(FILE *f, const image_ctx *c, uint8_t *px, rt_error *err)
{
	png_bytep *rows = malloc((size_t)c->fb->h * sizeof *rows);
	if (!rows)
		return rt_error_at(err, c->path, 0, 0, "out of memory");
	char why[160] = "";
	png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, why, png_error_kept, png_warning_dropped);
	png_infop info = png ? png_create_info_struct(png) : NULL;
	bool ok = false;
	if (png && info && !setjmp(png_jmpbuf(png))) {
		png_init_io(png, f);
		png_set_IHDR(png, info, (png_uint_32)c->fb->w, (png_uint_32)c->fb->h, 8, PNG_COLOR_TYPE_RGB,
		             PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
		png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
		for (int y = 0; y < c->fb->h; y++)
			rows[y] = px + (size_t)y * c->fb->w * 3;
		png_write_info(png, info);
		png_write_image(png, rows);
		png_write_end(png, NULL);
		ok = true;
	}
	png_destroy_write_struct(&png, &info);
	free(rows);
	/* a failed write is named by the writer's errno (the caller checks
	 * the file); libpng's own words otherwise */
	if (!ok && ferror(f))
		return rt_error_at(err, c->path, 0, 0, "write failed");
	return ok || rt_error_at(err, c->path, 0, 0, "PNG encoding failed%s%s", why[0] ? ": " : "", why);
}

static bool write_png(FILE *f, void *vctx, rt_error *err)
{
	return write_8bit(f, vctx, png_put, err);
}

/* stb_image_write's output goes to the file; a failed write is kept. */
static void jpeg_out(void *ctx, void *data, int size)
{
	FILE *f = ctx;
	if (size > 0)
		fwrite(data, 1, (size_t)size, f);
}

static bool jpeg_put(FILE *f, const image_ctx *c, uint8_t *px, rt_error *err)
{
	/* Quality 92: no blocks a person sees on a rendered picture. */
	if (!stbi_write_jpg_to_func(jpeg_out, f, c->fb->w, c->fb->h, 3, px, 92))
		return rt_error_at(err, c->path, 0, 0, "JPEG encoding failed");
	return !ferror(f) || rt_error_at(err, c->path, 0, 0, "write failed");
}

static bool write_jpeg(FILE *f, void *vctx, rt_error *err)
{
	return write_8bit(f, vctx, jpeg_put, err);
}

/* --- writing the rows as the render finishes them (image_write_rendered) --- */

typedef struct stream {
	const char *path;
	int w, h;
	image_make_fn make;
	void *make_ctx;
	FILE *f;
	int fd;           /* the file's descriptor; -1: in memory (written in place later) */
	off_t synced;     /* write-back started up to here */
	png_structp png;
	char why[160];    /* libpng's words */
	int write_errno;  /* why a write of rows failed; 0: none did */
	pthread_t freer;  /* frees the rendered framebuffer (stream_release) */
	bool freeing;     /* freer runs: joined before image_write_rendered returns */
} stream;

/* Starts the disk's write-back of what was written since the last call,
 * every megabyte, so that the sync after the render has little left to
 * wait for (sync_file_range does not wait; on a FIFO or device, or a file
 * system without it, it does nothing). */
static void stream_writeback(stream *st)
{
	if (st->fd < 0)
		return;
	off_t end = ftello(st->f);
	if (end < 0 || end - st->synced < ((off_t)1 << 20))
		return;
	if (fflush(st->f) == 0) {
		(void)sync_file_range(st->fd, st->synced, end - st->synced, SYNC_FILE_RANGE_WRITE);
		st->synced = end;
	}
}

static bool ppm_rows(void *vctx, const framebuffer *fb, int y0, int y1, const uint8_t *codes)
{
	stream *st = vctx;
	size_t n = (size_t)(y1 - y0) * (size_t)fb->w * 3;
	if (fwrite(codes, 1, n, st->f) != n) {
		st->write_errno = errno ? errno : EIO;
		return false;
	}
	stream_writeback(st);
	return true;
}

static void *free_fb(void *fb)
{
	fb_free(fb);
	return NULL;
}

/* The rendered framebuffer is not needed once its rows are written: a
 * thread frees it (the munmap of the 8-bit codes, 6 MB at 1920x1080, about
 * 0.6 ms) while this one syncs and renames the file, on the core the
 * render's workers have left (issue 29: the process's serial tail). */
static void stream_release(stream *st, framebuffer *fb)
{
	st->freeing = pthread_create(&st->freer, NULL, free_fb, fb) == 0;
	if (!st->freeing)
		fb_free(fb);
}

/* Runs the render; false (err set) when it failed or a write stopped it. */
static bool stream_make(stream *st, render_rows_fn rows, rt_error *err)
{
	framebuffer *fb = st->make(st->make_ctx, rows, st, err);
	if (!fb) {
		if (st->write_errno) /* the render stopped for it */
			rt_error_at(err, st->path, 0, 0, "write failed (%s)", strerror(st->write_errno));
		else if (st->why[0])
			rt_error_at(err, st->path, 0, 0, "PNG encoding failed: %s", st->why);
		return false;
	}
	stream_release(st, fb);
	return true;
}

/* Points the stream at the file the atomic save opened (image_write_rendered). */
static void stream_open(stream *st, FILE *f)
{
	st->f = f;
	st->fd = fileno(f);
	st->synced = 0;
	st->why[0] = '\0';
}

static bool write_ppm_rendered(FILE *f, void *vctx, rt_error *err)
{
	stream *st = vctx;
	stream_open(st, f);
	if (fprintf(f, "P6\n%d %d\n255\n", st->w, st->h) < 0)
		return rt_error_at(err, st->path, 0, 0, "write failed");
	return stream_make(st, ppm_rows, err);
}

/* libpng's errors come back here, not through write_png_rendered's frame: a
 * longjmp across the render would leave its threads running. */
static bool png_rows(void *vctx, const framebuffer *fb, int y0, int y1, const uint8_t *codes)
{
	stream *st = vctx;
	if (setjmp(png_jmpbuf(st->png))) {
		st->write_errno = ferror(st->f) ? (errno ? errno : EIO) : 0;
		if (!st->write_errno && !st->why[0])
			snprintf(st->why, sizeof st->why, "libpng stopped");
		return false;
	}
	for (int y = y0; y < y1; y++)
		png_write_row(st->png, codes + (size_t)(y - y0) * (size_t)fb->w * 3);
	if (ferror(st->f)) {
		st->write_errno = errno ? errno : EIO;
		return false;
	}
	stream_writeback(st);
	return true;
}

static bool write_png_rendered(FILE *f, void *vctx, rt_error *err)
{
	stream *st = vctx;
	stream_open(st, f);
	png_infop info = NULL;
	st->png = png_create_write_struct(PNG_LIBPNG_VER_STRING, st->why, png_error_kept, png_warning_dropped);
	if (st->png)
		info = png_create_info_struct(st->png);
	volatile bool started = false, ended = false;
	if (st->png && info && !setjmp(png_jmpbuf(st->png))) {
		png_init_io(st->png, f);
		png_set_IHDR(st->png, info, (png_uint_32)st->w, (png_uint_32)st->h, 8, PNG_COLOR_TYPE_RGB,
		             PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
		png_set_sRGB_gAMA_and_cHRM(st->png, info, PNG_sRGB_INTENT_PERCEPTUAL);
		png_write_info(st->png, info);
		started = true;
	}
	if (started && !stream_make(st, png_rows, err)) {
		png_destroy_write_struct(&st->png, &info);
		return false; /* err says why */
	}
	if (started && !setjmp(png_jmpbuf(st->png))) {
		png_write_end(st->png, NULL);
		ended = true;
	}
	png_destroy_write_struct(&st->png, &info);
	if (ended)
		return true;
	if (ferror(f))
		return rt_error_at(err, st->path, 0, 0, "write failed");
	return rt_error_at(err, st->path, 0, 0, "PNG encoding failed%s%s", st->why[0] ? ": " : "", st->why);
}

bool image_write_rendered(const char *path, int w, int h, double exposure, image_make_fn make, void *make_ctx,
                          rt_error *err)
{
	const image_type *t = image_type_of(path);
	if (!t) {
		char exts[128];
		image_extensions(exts, sizeof exts, false);
		return rt_error_at(err, path, 0, 0, "unknown image type; expected %s", exts);
	}
	if (!t->write_rendered) {
		framebuffer *fb = make(make_ctx, NULL, NULL, err);
		if (!fb)
			return false;
		bool ok = image_write(path, fb, exposure, err);
		fb_free(fb);
		return ok;
	}
	stream st = {.path = path, .w = w, .h = h, .make = make, .make_ctx = make_ctx, .fd = -1};
	bool ok = file_write_atomic(path, t->write_rendered, &st, err);
	if (st.freeing)
		pthread_join(st.freer, NULL);
	return ok;
}

/* The formats, by extension: a new one is a line here (and its encoder
 * above, its decoder below). */
static const image_type types[] = {
	{".ppm", "PPM", write_ppm, image_read_ppm, "8-bit sRGB, binary netpbm (P6)", false, write_ppm_rendered},
	{".pfm", "PFM", write_pfm, image_read_pfm, "linear 32-bit float, as rendered", true, NULL},
	{".png", "PNG", write_png, NULL, "8-bit sRGB, libpng", false, write_png_rendered},
	{".jpg", "JPEG", write_jpeg, NULL, "8-bit sRGB, baseline, quality 92 (stb_image_write)", false, NULL},
	{".jpeg", "JPEG", write_jpeg, NULL, "8-bit sRGB, as .jpg", false, NULL},
};
#define NTYPES (sizeof types / sizeof types[0])

const image_type *image_type_at(size_t i)
{
	return i < NTYPES ? &types[i] : NULL;
}

const image_type *image_type_of(const char *path)
{
	const char *ext = extension(path);
	for (size_t i = 0; i < NTYPES; i++)
		if (strcasecmp(ext, types[i].ext) == 0)
			return &types[i];
	return NULL;
}

void image_extensions(char *buf, size_t size, bool readable)
{
	size_t n = 0, k = 0;
	for (size_t i = 0; i < NTYPES; i++)
		n += !readable || types[i].read;
	buf[0] = '\0';
	for (size_t i = 0, used = 0; i < NTYPES; i++) {
		if (readable && !types[i].read)
			continue;
		k++;
		used += (size_t)snprintf(buf + used, used < size ? size - used : 0, "%s%s",
		                         k == 1 ? "" : k == n ? " or " : ", ", types[i].ext);
	}
}

void image_extensions_join(char *buf, size_t size, const char *prefix, const char *sep, bool first_only)
{
	size_t used = 0;
	if (size)
		buf[0] = '\0';
	for (size_t i = 0; i < NTYPES; i++) {
		if (first_only && i > 0 && strcmp(types[i].name, types[i - 1].name) == 0)
			continue;
		used += (size_t)snprintf(buf + used, used < size ? size - used : 0, "%s%s%s", used ? sep : "", prefix,
		                         types[i].ext);
	}
}

bool image_write(const char *path, const framebuffer *fb, double exposure, rt_error *err)
{
	image_ctx c = {fb, exp2(exposure), path};
	const image_type *t = image_type_of(path);
	if (!t) {
		char exts[128];
		image_extensions(exts, sizeof exts, false);
		return rt_error_at(err, path, 0, 0, "unknown image type; expected %s", exts);
	}
	return file_write_atomic(path, t->write, &c, err);
}

framebuffer *image_read(const char *path, rt_error *err)
{
	const image_type *t = image_type_of(path);
	if (!t || !t->read) {
		char exts[128];
		image_extensions(exts, sizeof exts, true);
		rt_error_at(err, path, 0, 0, "cannot read this image type; expected %s", exts);
		return NULL;
	}
	return t->read(path, err);
}

/* The pixels of texture/image_read.c's one netpbm/PFM reader, as a
 * framebuffer. */
static framebuffer *read_netpbm(const char *path, bool pfm, rt_error *err)
{
	int w, h;
	float *rgb = image_load_netpbm(path, pfm, &w, &h, err);
	if (!rgb)
		return NULL;
	framebuffer *fb = fb_new(w, h);
	if (!fb) {
		free(rgb);
		rt_error_at(err, path, 0, 0, "the image is %dx%d pixels; expected at most %dx%d", w, h,
		            RENDER_MAX_DIM, RENDER_MAX_DIM);
		return NULL;
	}
	free(fb->rgb);
	fb->rgb = rgb;
	return fb;
}

framebuffer *image_read_pfm(const char *path, rt_error *err)
{
	framebuffer *fb = read_netpbm(path, true, err);
	if (fb)
		fb->spp = 0;
	return fb;
}

framebuffer *image_read_ppm(const char *path, rt_error *err)
{
	return read_netpbm(path, false, err);
}
