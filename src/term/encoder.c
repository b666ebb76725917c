/* rtsh — the table of picture encoders (encoder.h). */
#include "term/encoder.h"

#include <string.h>

const encoder_ops *const encoder_table[] = {
	&encoder_halfblock,
	NULL,
};

const encoder_ops *encoder_find(const char *name)
{
	for (size_t i = 0; encoder_table[i]; i++)
		if (strcmp(encoder_table[i]->name, name) == 0)
			return encoder_table[i];
	return NULL;
}
