/* rtsh — textures: mip chains, filtered lookups and the cache (texture.h). */
#include "rtsh/texture.h"

#include <errno.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "base/readhelp.h"
#include "rtsh/filesrc.h"

static _Thread_local double pixel_angle;

void texture_set_pixel_angle(double a)
{
	pixel_angle = a;
}

double texture_pixel_angle(void)
{
	return pixel_angle;
}

void texture_free(texture *t)
{
	if (!t)
		return;
	for (int i = 0; i < t->nlevels; i++)
		free(t->level[i].rgb);
	free(t->path);
	free(t);
}

texture *texture_make(float *rgb, int w, int h, const char *name, bool srgb, rt_error *err)
{
	texture *t = calloc(1, sizeof *t);
	if (!t) {
		free(rgb);
		rt_error_set(err, "%s: out of memory", name ? name : "texture");
		return NULL;
	}
	t->level[0] = (tex_level){w, h, rgb};
	t->nlevels = 1;
	t->srgb = srgb;
	if (name && !(t->path = strdup(name))) {
		texture_free(t);
		rt_error_set(err, "%s: out of memory", name);
		return NULL;
	}
	/* each level the 2x2 box average of the one above (an odd row or
	 * column is folded into its neighbour by clamping) */
	while (t->nlevels < TEX_MAX_LEVELS) {
		const tex_level *a = &t->level[t->nlevels - 1];
		if (a->w == 1 && a->h == 1)
			break;
		int nw = a->w > 1 ? a->w / 2 : 1, nh = a->h > 1 ? a->h / 2 : 1;
		float *o = read_cancelled() ? NULL : malloc((size_t)nw * (size_t)nh * 3 * sizeof *o);
		if (!o) { /* or Ctrl-C, looked at once a level */
			texture_free(t);
			rt_error_set(err, read_cancelled() ? "stopped" : "out of memory building mip-maps");
			return NULL;
		}
		for (int y = 0; y < nh; y++)
			for (int x = 0; x < nw; x++) {
				int x0 = 2 * x < a->w ? 2 * x : a->w - 1, x1 = 2 * x + 1 < a->w ? 2 * x + 1 : a->w - 1;
				int y0 = 2 * y < a->h ? 2 * y : a->h - 1, y1 = 2 * y + 1 < a->h ? 2 * y + 1 : a->h - 1;
				for (int c = 0; c < 3; c++)
					o[3 * ((size_t)y * nw + x) + c] =
					    0.25f * (a->rgb[3 * ((size_t)y0 * a->w + x0) + c] + a->rgb[3 * ((size_t)y0 * a->w + x1) + c] +
					             a->rgb[3 * ((size_t)y1 * a->w + x0) + c] + a->rgb[3 * ((size_t)y1 * a->w + x1) + c]);
			}
		t->level[t->nlevels++] = (tex_level){nw, nh, o};
	}
	return t;
}

texture *texture_load(const char *path, bool srgb, rt_error *err)
{
	int w, h;
	float *rgb = image_load_rgb(path, srgb, &w, &h, err);
	if (!rgb)
		return NULL;
	return texture_make(rgb, w, h, path, srgb, err);
}

static inline int wrap(int i, int n)
{
	int r = i % n;
	return r < 0 ? r + n : r;
}

static vec3 bilinear(const tex_level *l, double u, double v)
{
	/* texel centres at (i + 0.5) / w; v = 0 is the bottom row */
	double x = u * l->w - 0.5, y = (1.0 - v) * l->h - 0.5;
	if (!isfinite(x) || !isfinite(y))
		return v3(0, 0, 0);
	x = fmod(x, (double)l->w);
	y = fmod(y, (double)l->h);
	double fx = floor(x), fy = floor(y);
	double ax = x - fx, ay = y - fy;
	int x0 = wrap((int)fx, l->w), y0 = wrap((int)fy, l->h);
	int x1 = wrap(x0 + 1, l->w), y1 = wrap(y0 + 1, l->h);
	const float *p00 = &l->rgb[3 * ((size_t)y0 * l->w + x0)], *p10 = &l->rgb[3 * ((size_t)y0 * l->w + x1)];
	const float *p01 = &l->rgb[3 * ((size_t)y1 * l->w + x0)], *p11 = &l->rgb[3 * ((size_t)y1 * l->w + x1)];
	double c[3];
	for (int k = 0; k < 3; k++)
		c[k] = (1 - ay) * ((1 - ax) * p00[k] + ax * p10[k]) + ay * ((1 - ax) * p01[k] + ax * p11[k]);
	return v3(c[0], c[1], c[2]);
}

vec3 texture_lookup(const texture *t, double u, double v, double width)
{
	/* the level whose texels are as wide as the footprint */
	double texels = width * t->level[0].w;
	double lod = texels > 1.0 ? log2(texels) : 0.0;
	if (!(lod < t->nlevels - 1))
		lod = t->nlevels - 1;
	int l0 = (int)lod;
	double f = lod - l0;
	vec3 a = bilinear(&t->level[l0], u, v);
	if (f <= 0.0 || l0 + 1 >= t->nlevels)
		return a;
	return v3_lerp(a, bilinear(&t->level[l0 + 1], u, v), f);
}

vec3 texture_texel(const texture *t, int x, int y)
{
	const tex_level *l = &t->level[0];
	x = x < 0 ? 0 : x >= l->w ? l->w - 1 : x;
	y = y < 0 ? 0 : y >= l->h ? l->h - 1 : y;
	const float *p = &l->rgb[3 * ((size_t)y * l->w + x)];
	return v3(p[0], p[1], p[2]);
}

/* --- the cache --- */

typedef struct entry {
	texture *t;
	off_t size;
	struct timespec mtime;
} entry;

static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static entry *cache;
static size_t ncache, ccache;
#define CACHE_KEEP 16

texture *texture_cache_get(const char *path, bool srgb, const atomic_bool *cancel, rt_error *err)
{
	struct stat st;
	if (rt_file_stat(path, &st) != 0) {
		rt_error_set(err, "%s: cannot read the image: %s", path, strerror(errno));
		return NULL;
	}
	pthread_mutex_lock(&lock);
	for (size_t i = 0; i < ncache; i++) {
		entry *e = &cache[i];
		if (e->t->srgb == srgb && strcmp(e->t->path, path) == 0 && e->size == st.st_size &&
		    e->mtime.tv_sec == st.st_mtim.tv_sec && e->mtime.tv_nsec == st.st_mtim.tv_nsec) {
			e->t->refs++;
			pthread_mutex_unlock(&lock);
			return e->t;
		}
	}
	pthread_mutex_unlock(&lock);
	/* the PPM and PFM decoders and the mip chain poll the flag; stb_image's
	 * (PNG, JPEG, HDR, ...) run to their end */
	const atomic_bool *outer = read_cancel_set(cancel);
	texture *t = texture_load(path, srgb, err);
	read_cancel_set(outer);
	if (!t && cancel && atomic_load(cancel))
		rt_error_set(err, "stopped");
	if (!t)
		return NULL;
	/* a stopped image is not cached */
	if (cancel && atomic_load(cancel)) {
		texture_free(t);
		rt_error_set(err, "stopped");
		return NULL;
	}
	if (!t->path) {
		texture_free(t);
		rt_error_set(err, "%s: out of memory", path);
		return NULL;
	}
	pthread_mutex_lock(&lock);
	if (ncache == ccache) {
		size_t c = ccache ? 2 * ccache : 16;
		entry *n = realloc(cache, c * sizeof *n);
		if (!n) {
			pthread_mutex_unlock(&lock);
			texture_free(t);
			rt_error_set(err, "%s: out of memory", path);
			return NULL;
		}
		cache = n;
		ccache = c;
	}
	t->refs = 1;
	cache[ncache++] = (entry){t, st.st_size, st.st_mtim};
	pthread_mutex_unlock(&lock);
	return t;
}

void texture_cache_put(texture *t)
{
	if (!t)
		return;
	pthread_mutex_lock(&lock);
	if (t->refs > 0)
		t->refs--;
	size_t unused = 0;
	for (size_t i = 0; i < ncache; i++)
		unused += cache[i].t->refs == 0;
	if (unused > CACHE_KEEP) {
		size_t j = 0;
		for (size_t i = 0; i < ncache; i++) {
			if (cache[i].t->refs == 0)
				texture_free(cache[i].t);
			else
				cache[j++] = cache[i];
		}
		ncache = j;
	}
	pthread_mutex_unlock(&lock);
}
