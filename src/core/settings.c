/* rtsh — the settings table (settings.h). */
#include "rtsh/settings.h"

#include "rtsh/num.h"

#include <errno.h>
#include <stddef.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rtsh/memory.h"

/* The names of the denoise_mode values, in order. */
static const char *const denoise_names[] = {"auto", "on", "off"};
/* The names of term/pixels.h's pixels_mode values, in order. */
static const char *const pixels_names[] = {"off", "kitty", "sixel", "iterm", "auto"};
/* The names of term/symbols.h's symbols_kind values, in order. */
static const char *const symbols_names[] = {"half", "quadrant", "sextant", "octant", "auto"};

const setting_def settings_table[] = {
#define AT(field) offsetof(render_settings, field)
	{"resolution", SETTING_RESOLUTION, 1, RENDER_MAX_DIM, AT(width), "full-resolution image size, WxH"},
	{"samples", SETTING_INT, 1, 1000000, AT(samples), "samples (rays or paths) per pixel"},
	{"depth", SETTING_INT, 0, 1000, AT(depth), "reflection depth (whitted) or bounces (path)"},
	{"mode", SETTING_MODE, 0, 1, AT(mode), "render mode: whitted or path"},
	{"threads", SETTING_INT, 0, 256, AT(threads), "render threads; 0 = one per online CPU"},
	{"seed", SETTING_U64, 0, 0, AT(seed), "random seed of the sampler"},
	{"exposure", SETTING_DOUBLE, -20, 20, AT(exposure), "exposure in stops: output = radiance x 2^exposure"},
	{"denoise", SETTING_DENOISE, 0, 2, AT(denoise),
	 "path mode: denoise auto (previews only), on (saved images too) or off"},
	{"pixels", SETTING_PIXELS, 0, 4, AT(pixels),
	 "the picture in real pixels: off (half blocks), kitty, sixel, iterm, or auto (ask the terminal)"},
	{"symbols", SETTING_SYMBOLS, 0, 4, AT(symbols),
	 "the cells' glyphs: half, quadrant, sextant, octant, or auto (what the terminal is known to draw)"},
#undef AT
};
const size_t settings_count = sizeof settings_table / sizeof settings_table[0];

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

bool settings_set(render_settings *s, const setting_def *def, const char *value, rt_error *err)
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
			return rt_error_set(err, "%s \"%s\" is not valid; expected a whole number >= 0",
			                    def->name, value);
		*(uint64_t *)field(s, def) = v;
		return true;
	}
	case SETTING_DOUBLE: {
		double v = 0;
		if (num_scan_str(value, HUGE_VAL, &v) != NUM_OK || !(v >= def->min && v <= def->max))
			return rt_error_set(err, "%s \"%s\" is not valid; expected a number in %g..%g",
			                    def->name, value, def->min, def->max);
		*(double *)field(s, def) = v;
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
		if (!mem_check((double)a * (double)b * MEM_PER_PIXEL, what, err))
			return false;
		s->width = (int)a;
		s->height = (int)b;
		return true;
	}
	case SETTING_MODE:
		if (strcmp(value, "whitted") == 0)
			s->mode = MODE_WHITTED;
		else if (strcmp(value, "path") == 0)
			s->mode = MODE_PATH;
		else
			return rt_error_set(err, "mode \"%s\" is not valid; expected whitted or path", value);
		return true;
	case SETTING_DENOISE:
		for (int i = 0; i < 3; i++)
			if (strcmp(value, denoise_names[i]) == 0) {
				s->denoise = i;
				return true;
			}
		return rt_error_set(err, "denoise \"%s\" is not valid; expected auto, on or off", value);
	case SETTING_PIXELS:
		for (int i = 0; i < 5; i++)
			if (strcmp(value, pixels_names[i]) == 0) {
				s->pixels = i;
				return true;
			}
		return rt_error_set(err, "pixels \"%s\" is not valid; expected off, kitty, sixel, iterm or auto",
		                    value);
	case SETTING_SYMBOLS:
		for (int i = 0; i < 5; i++)
			if (strcmp(value, symbols_names[i]) == 0) {
				s->symbols = i;
				return true;
			}
		return rt_error_set(err,
		                    "symbols \"%s\" is not valid; expected half, quadrant, sextant, octant or auto",
		                    value);
	}
	return rt_error_set(err, "internal: setting %s has no type", def->name);
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
	case SETTING_DOUBLE:
		snprintf(buf, size, "%g", *(const double *)cfield(s, def));
		return;
	case SETTING_RESOLUTION:
		snprintf(buf, size, "%dx%d", s->width, s->height);
		return;
	case SETTING_MODE:
		snprintf(buf, size, "%s", render_mode_name(s->mode));
		return;
	case SETTING_DENOISE:
		snprintf(buf, size, "%s", denoise_names[s->denoise >= 0 && s->denoise < 3 ? s->denoise : 0]);
		return;
	case SETTING_PIXELS:
		snprintf(buf, size, "%s", pixels_names[s->pixels >= 0 && s->pixels < 5 ? s->pixels : 0]);
		return;
	case SETTING_SYMBOLS:
		snprintf(buf, size, "%s", symbols_names[s->symbols >= 0 && s->symbols < 5 ? s->symbols : 4]);
		return;
	}
}
