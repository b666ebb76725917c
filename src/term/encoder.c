/* rtsh — the table of picture encoders (encoder.h). */
#include "term/encoder.h"

#include <string.h>

const encoder_ops *const encoder_table[] = {
	&encoder_halfblock,
	&encoder_quadrant,
	&encoder_sextant,
	&encoder_octant,
	&encoder_kitty,
	&encoder_sixel,
	&encoder_iterm,
	NULL,
};

const encoder_ops *encoder_find(const char *name)
{
	for (size_t i = 0; encoder_table[i]; i++)
		if (strcmp(encoder_table[i]->name, name) == 0)
			return encoder_table[i];
	return NULL;
}

const encoder_ops *encoder_pixels(pixels_mode m)
{
	if (m == PIXELS_OFF || m == PIXELS_AUTO)
		return NULL;
	const encoder_ops *e = encoder_find(pixels_mode_name(m));
	return e && e->picture ? e : NULL;
}

const encoder_ops *encoder_symbols(symbols_kind k)
{
	switch (k) {
	case SYMBOLS_QUADRANT:
		return &encoder_quadrant;
	case SYMBOLS_SEXTANT:
		return &encoder_sextant;
	case SYMBOLS_OCTANT:
		return &encoder_octant;
	default:
		return &encoder_halfblock;
	}
}
