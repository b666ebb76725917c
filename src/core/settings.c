/* rtsh — the settings table (settings.h). */
#include "rtsh/settings.h"

#include "rtsh/num.h"

#include <errno.h>
#include <math.h>
#include <stddef.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rtsh/memory.h"

/* The names of the denoise_mode values, in order. */
static const char *const denoise_names[] = {"auto", "on", "off", NULL};
/* The names of term/pixels.h's pixels_mode values, in order. */
static const char *const pixels_names[] = {"off", "kitty", "sixel", "iterm", "auto", NULL};
/* The names of term/symbols.h's symbols_kind values, in order. */
static const char *const symbols_names[] = {"half", "quadrant", "sextant", "octant", "auto", NULL};

_Static_assert(sizeof(render_mode) == sizeof(int), "an enum setting is stored as an int");

const setting_def settings_table[] = {
#define AT(field) offsetof(render_settings, field)
	{"resolution", SETTING_RESOLUTION, 1, RENDER_MAX_DIM, AT(width), "full-resolution image size, WxH", "1280x720", NULL, SETTING_SCENE},
	{"samples", SETTING_INT, 1, 1000000, AT(samples), "samples (rays or paths) per pixel", "1", NULL, SETTING_SCENE},
	{"depth", SETTING_INT, 0, 1000, AT(depth), "reflection depth (whitted, faint rays cut) or bounces (path)", "5", NULL, SETTING_SCENE},
	{"mode", SETTING_ENUM, 0, 0, AT(mode), "render mode: whitted or path", "whitted", render_mode_names, SETTING_SCENE},
	{"threads", SETTING_INT, 0, 256, AT(threads), "render and tree-build threads; 0 = one per online CPU", "0", NULL, 0},
	{"seed", SETTING_U64, 0, 0, AT(seed), "random seed of the sampler", "1", NULL, SETTING_SCENE},
	{"exposure", SETTING_DOUBLE, -20, 20, AT(exposure), "exposure in stops: output = radiance x 2^exposure", "0", NULL, SETTING_SCENE},
	{"denoise", SETTING_ENUM, 0, 0, AT(denoise),
	 "path mode: denoise auto (previews only), on (saved images too) or off", "auto", denoise_names,
	 SETTING_BARE_ON | SETTING_SCENE},
	{"pixels", SETTING_ENUM, 0, 0, AT(pixels),
	 "the picture in real pixels: off (half blocks), kitty, sixel, iterm, or auto (ask the terminal)", "off",
	 pixels_names, SETTING_TERMINAL},
	{"symbols", SETTING_ENUM, 0, 0, AT(symbols),
	 "the cells' glyphs: half, quadrant, sextant, octant, or auto (what the terminal is known to draw)", "auto",
	 symbols_names, SETTING_TERMINAL},
#undef AT
};
const size_t settings_count = sizeof settings_table / sizeof settings_table[0];
_Static_assert(sizeof settings_table / sizeof settings_table[0] <= SCENE_KEPT_MAX,
               "scene_hints.kept has a slot per row: raise SCENE_KEPT_MAX (scene.h)");

static bool set_value(render_settings *s, const setting_def *def, const char *value, bool check_memory,
                      rt_error *err);

render_settings render_settings_default(void)
{
	render_settings s;
	memset(&s, 0, sizeof s);
	rt_error err;
	for (size_t i = 0; i < settings_count; i++)
		set_value(&s, &settings_table[i], settings_table[i].def, false, &err);
	return s;
}

bool render_settings_apply_hints(render_settings *s, const scene_hints *h)
{
	bool clamped = false;
	if (h->width > 0 && h->height > 0) {
		double w = h->width, hh = h->height, big = fmax(w, hh);
		if (big > RENDER_HINT_MAX_DIM) {
			w = fmax(1.0, round(w * RENDER_HINT_MAX_DIM / big));
			hh = fmax(1.0, round(hh * RENDER_HINT_MAX_DIM / big));
			clamped = true;
		}
		s->width = (int)w;
		s->height = (int)hh;
	}
	if (h->samples > 0)
		s->samples = h->samples;
	if (h->depth >= 0)
		s->depth = h->depth;
	if (h->mode >= 0)
		s->mode = (render_mode)h->mode;
	rt_error err;
	for (size_t i = 0; i < settings_count; i++)
		if (settings_kept_slot(&settings_table[i]) && h->kept[i][0])
			set_value(s, &settings_table[i], h->kept[i], false, &err);
	return clamped;
}

int settings_choices(const setting_def *def)
{
	int n = 0;
	if (def->type == SETTING_ENUM)
		while (def->choices[n])
			n++;
	return n;
}

void settings_choices_text(const setting_def *def, const char *sep, const char *last, char *buf, size_t size)
{
	int n = settings_choices(def);
	size_t at = 0;
	if (size)
		buf[0] = '\0';
	for (int i = 0; i < n && at < size; i++) {
		int k = snprintf(buf + at, size - at, "%s%s", i == 0 ? "" : i == n - 1 ? last : sep, def->choices[i]);
		if (k < 0)
			break;
		at += (size_t)k;
	}
}

int settings_get_int(const render_settings *s, const setting_def *def)
{
	int v;
	memcpy(&v, (const char *)s + def->offset, sizeof v);
	return v;
}

void settings_put_int(render_settings *s, const setting_def *def, int v)
{
	memcpy((char *)s + def->offset, &v, sizeof v);
}

const setting_def *settings_find(const char *name, rt_error *err)
{
	const setting_def *found = NULL;
	size_t len = strlen(name);
	int matches = 0;
	for (size_t i = 0; i < settings_count; i++) {
		if (strcmp(settings_table[i].name, name) == 0)
			return &settings_table[i];
		if (len && strncmp(settings_table[i].name, name, len) == 0) {
			found = &settings_table[i];
			matches++;
		}
	}
	if (matches == 1)
		return found;
	char names[256] = "";
	for (size_t i = 0; i < settings_count; i++) {
		strncat(names, " ", sizeof names - strlen(names) - 1);
		strncat(names, settings_table[i].name, sizeof names - strlen(names) - 1);
	}
	rt_error_set(err, "%s setting \"%s\"; expected one of%s", matches ? "ambiguous" : "unknown", name,
	             names);
	return NULL;
}

static void *field(render_settings *s, const setting_def *def)
{
	return (char *)s + def->offset;
}

static const void *cfield(const render_settings *s, const setting_def *def)
{
	return (const char *)s + def->offset;
}

/* A whole number in [min, max] filling all of s. */
static bool parse_long(const char *s, double min, double max, long *out)
{
	return num_scan_long(s, (long)min, (long)max, out) == NUM_OK;
}

/* settings_set; a resolution's memory is checked when check_memory. */
static bool set_value(render_settings *s, const setting_def *def, const char *value, bool check_memory,
                      rt_error *err)
{
	long a, b;
	switch (def->type) {
	case SETTING_INT:
		if (!parse_long(value, def->min, def->max, &a))
			return rt_error_set(err, "%s \"%s\" is not valid; expected a whole number in %.0f..%.0f",
			                    def->name, value, def->min, def->max);
		*(int *)field(s, def) = (int)a;
		return true;
	case SETTING_U64: {
		unsigned long long v;
		if (num_scan_u64(value, &v) != NUM_OK)
			return rt_error_set(err, "%s \"%s\" is not valid; expected a whole number in 0..%llu",
			                    def->name, value, (unsigned long long)UINT64_MAX);
		*(uint64_t *)field(s, def) = v;
		return true;
	}
	case SETTING_DOUBLE: {
		double v = 0;
		if (num_scan_str(value, HUGE_VAL, &v) != NUM_OK || !(v >= def->min && v <= def->max))
			return rt_error_set(err, "%s \"%s\" is not valid; expected a number in %g..%g",
			                    def->name, value, def->min, def->max);
		*(double *)field(s, def) = v + 0.0; /* -0 is 0: shown and saved as 0 */
		return true;
	}
	case SETTING_RESOLUTION: {
		const char *x = strpbrk(value, "xX");
		char wbuf[32];
		if (!x || (size_t)(x - value) >= sizeof wbuf)
			return rt_error_set(err, "resolution \"%s\" is not valid; expected WxH like 1280x720",
			                    value);
		memcpy(wbuf, value, (size_t)(x - value));
		wbuf[x - value] = '\0';
		if (!parse_long(wbuf, def->min, def->max, &a) || !parse_long(x + 1, def->min, def->max, &b))
			return rt_error_set(err, "resolution \"%s\" is not valid; expected WxH with each of W "
			                         "and H in %.0f..%.0f",
			                    value, def->min, def->max);
		char what[64];
		snprintf(what, sizeof what, "a %ldx%ld image", a, b);
		if (check_memory && !mem_check((double)a * (double)b * MEM_PER_PIXEL, what, err))
			return false;
		s->width = (int)a;
		s->height = (int)b;
		return true;
	}
	case SETTING_ENUM: {
		int n = settings_choices(def);
		for (int k = 0; k < n; k++)
			if (strcmp(value, def->choices[k]) == 0) {
				settings_put_int(s, def, k);
				return true;
			}
		char names[256];
		settings_choices_text(def, ", ", " or ", names, sizeof names);
		return rt_error_set(err, "%s \"%s\" is not valid; expected %s", def->name, value, names);
	}
	}
	return rt_error_set(err, "internal: setting %s has no type", def->name);
}

bool settings_set(render_settings *s, const setting_def *def, const char *value, rt_error *err)
{
	return set_value(s, def, value, true, err);
}

void settings_format(const render_settings *s, const setting_def *def, char *buf, size_t size)
{
	switch (def->type) {
	case SETTING_INT:
		snprintf(buf, size, "%d", *(const int *)cfield(s, def));
		return;
	case SETTING_U64:
		snprintf(buf, size, "%" PRIu64, *(const uint64_t *)cfield(s, def));
		return;
	case SETTING_DOUBLE: {
		/* %g, or the fewest digits beyond it that read back the same */
		double v = *(const double *)cfield(s, def);
		for (int digits = 6; digits <= 17; digits++) {
			snprintf(buf, size, "%.*g", digits, v);
			if (strtod(buf, NULL) == v)
				break;
		}
		return;
	}
	case SETTING_RESOLUTION:
		snprintf(buf, size, "%dx%d", s->width, s->height);
		return;
	case SETTING_ENUM: {
		int v = settings_get_int(s, def), n = settings_choices(def);
		snprintf(buf, size, "%s", v >= 0 && v < n ? def->choices[v] : "?");
		return;
	}
	}
}

bool settings_scene_value(const setting_def *def, const char *value, char *out, size_t size, rt_error *err)
{
	render_settings s = render_settings_default();
	if (!set_value(&s, def, value, false, err))
		return false;
	char text[64];
	settings_format(&s, def, text, sizeof text);
	if (strlen(text) >= size)
		return rt_error_set(err, "%s \"%s\" is not valid; expected at most %zu characters", def->name, value,
		                    size - 1);
	memset(out, 0, size);
	memcpy(out, text, strlen(text));
	return true;
}

bool settings_kept_slot(const setting_def *def)
{
	return (def->flags & SETTING_SCENE) && def->offset != offsetof(render_settings, width) &&
	       def->offset != offsetof(render_settings, samples) && def->offset != offsetof(render_settings, depth) &&
	       def->offset != offsetof(render_settings, mode);
}
