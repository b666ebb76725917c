/* rtsh — the public face of the render core (rtsh.h): a scene in an editor,
 * its settings, and the world built from it when a render needs one. */
#include "rtsh/rtsh.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rtsh/edit.h"
#include "rtsh/memory.h"
#include "rtsh/rtfile.h"
#include "rtsh/settings.h"
#include "rtsh/srgb.h"
#include "rtsh/world.h"

struct rtsh_scene {
	editor *ed;
	render_settings set;
	world *w;          /* built for generation `built`, or NULL */
	uint64_t built;
	char error[RT_ERROR_MSG_MAX + RT_ERROR_FILE_MAX + 32];
};

struct rtsh_image {
	int w, h;
	double gain; /* 2^exposure, for the 8-bit form */
	float *rgb;
};

static void set_error(char *buf, size_t size, const rt_error *err)
{
	if (size)
		rt_error_format(err, buf, size);
}

/* The handle around a loaded scene (taken, also on failure). */
static rtsh_scene *wrap(scene *s, const char *label, const rt_error *err, char *buf, size_t size)
{
	if (!s) {
		set_error(buf, size, err);
		return NULL;
	}
	rtsh_scene *sc = calloc(1, sizeof *sc);
	if (sc)
		sc->ed = editor_new(s, label);
	if (!sc || !sc->ed) {
		free(sc);
		scene_free(s);
		if (size)
			snprintf(buf, size, "out of memory");
		return NULL;
	}
	sc->set = render_settings_default();
	render_settings_apply_hints(&sc->set, &s->hints);
	return sc;
}

rtsh_scene *rtsh_load(const char *path, char *err, size_t size)
{
	rt_error e;
	return wrap(rt_load_file(path, NULL, &e), path, &e, err, size);
}

rtsh_scene *rtsh_load_text(const char *text, const char *name, char *err, size_t size)
{
	rt_error e;
	return wrap(rt_load_string(text, strlen(text), name, NULL, &e), name, &e, err, size);
}

void rtsh_free(rtsh_scene *sc)
{
	if (!sc)
		return;
	if (sc->w)
		world_release(sc->w);
	editor_free(sc->ed);
	free(sc);
}

const char *rtsh_error(const rtsh_scene *sc)
{
	return sc->error;
}

/* Keeps err as the scene's last error when !ok. */
static bool done(rtsh_scene *sc, bool ok, const rt_error *err)
{
	if (!ok)
		set_error(sc->error, sizeof sc->error, err);
	return ok;
}

bool rtsh_set(rtsh_scene *sc, const char *name, const char *value)
{
	rt_error err;
	const setting_def *def = settings_find(name, &err);
	return done(sc, def && settings_set(&sc->set, def, value, &err), &err);
}

void rtsh_size(const rtsh_scene *sc, int *width, int *height)
{
	*width = sc->set.width;
	*height = sc->set.height;
}

size_t rtsh_object_count(const rtsh_scene *sc)
{
	return editor_scene(sc->ed)->nobjs;
}

bool rtsh_object_move(rtsh_scene *sc, size_t i, double dx, double dy, double dz)
{
	rt_error err;
	return done(sc, editor_object_move(sc->ed, i, v3(dx, dy, dz), &err), &err);
}

bool rtsh_object_color(rtsh_scene *sc, size_t i, double r, double g, double b)
{
	rt_error err;
	return done(sc, editor_object_color(sc->ed, i, v3(r, g, b), &err), &err);
}

bool rtsh_object_set(rtsh_scene *sc, size_t i, const char *assignment)
{
	rt_error err;
	return done(sc, editor_object_set_key(sc->ed, i, assignment, &err), &err);
}

bool rtsh_add(rtsh_scene *sc, const char *line)
{
	rt_error err;
	return done(sc, editor_add_line(sc->ed, line, "add", 1, NULL, &err), &err);
}

bool rtsh_undo(rtsh_scene *sc)
{
	rt_error err;
	return done(sc, editor_undo(sc->ed, &err), &err);
}

rtsh_image *rtsh_render(rtsh_scene *sc, int x0, int y0, int x1, int y1)
{
	rt_error err;
	if (x0 < 0 || y0 < 0 || x1 > sc->set.width || y1 > sc->set.height || x0 >= x1 || y0 >= y1) {
		snprintf(sc->error, sizeof sc->error,
		         "render: the rectangle %d,%d..%d,%d is not inside the %dx%d picture; expected "
		         "0 <= x0 < x1 <= width, 0 <= y0 < y1 <= height",
		         x0, y0, x1, y1, sc->set.width, sc->set.height);
		return NULL;
	}
	uint64_t gen = editor_generation(sc->ed);
	if (!sc->w || sc->built != gen) {
		if (sc->w)
			world_release(sc->w);
		sc->w = world_build(editor_scene(sc->ed), &err);
		if (!sc->w) {
			done(sc, false, &err);
			return NULL;
		}
		sc->built = gen;
	}
	rtsh_image *im = calloc(1, sizeof *im);
	if (!im) {
		snprintf(sc->error, sizeof sc->error, "render: out of memory");
		return NULL;
	}
	im->w = x1 - x0;
	im->h = y1 - y0;
	im->gain = exp2(sc->set.exposure);
	if (im->w == sc->set.width && im->h == sc->set.height) {
		/* the whole picture: on every render thread */
		framebuffer *fb = render_image(sc->w, &sc->set, NULL, NULL, NULL, &err);
		if (fb) {
			im->rgb = fb->rgb;
			fb->rgb = NULL;
			fb_free(fb);
		}
	} else {
		im->rgb = malloc((size_t)im->w * (size_t)im->h * 3 * sizeof *im->rgb);
		if (im->rgb)
			render_rect(sc->w, &sc->set, x0, y0, x1, y1, im->rgb);
		else
			rt_error_set(&err, "render: out of memory");
	}
	if (!im->rgb) {
		free(im);
		done(sc, false, &err);
		return NULL;
	}
	return im;
}

void rtsh_image_free(rtsh_image *im)
{
	if (im)
		mem_free_all(im->rgb, im);
}

int rtsh_image_width(const rtsh_image *im)
{
	return im->w;
}

int rtsh_image_height(const rtsh_image *im)
{
	return im->h;
}

const float *rtsh_image_pixels(const rtsh_image *im)
{
	return im->rgb;
}

void rtsh_image_srgb8(const rtsh_image *im, unsigned char *out)
{
	for (size_t i = 0; i < (size_t)im->w * (size_t)im->h * 3; i++)
		out[i] = linear_to_srgb8(im->rgb[i] * im->gain);
}
