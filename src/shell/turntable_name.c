/* rtsh — the turntable's output names (turntable.h), apart from the
 * batch turntable so that rtsh-mpi links them alone. */
#include "shell/turntable.h"

#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "rtsh/image.h"

bool turntable_name(const char *pat, int index, char *out, size_t size)
{
	size_t o = 0;
	int convs = 0;
	for (const char *p = pat; *p; p++) {
		char piece[32];
		size_t n;
		if (*p != '%') {
			piece[0] = *p;
			n = 1;
		} else if (p[1] == '%') {
			piece[0] = '%';
			n = 1;
			p++;
		} else {
			/* %[0][width]d, width at most 2 digits */
			const char *q = p + 1;
			bool zero = *q == '0';
			if (zero)
				q++;
			int width = 0, digits = 0;
			while (*q >= '0' && *q <= '9' && digits < 3) {
				width = width * 10 + (*q++ - '0');
				digits++;
			}
			if (*q != 'd' || digits > 2 || ++convs > 1)
				return false;
			int k = zero ? snprintf(piece, sizeof piece, "%0*d", width, index)
			             : snprintf(piece, sizeof piece, "%*d", width, index);
			if (k < 0 || (size_t)k >= sizeof piece)
				return false;
			n = (size_t)k;
			p = q;
		}
		if (o + n >= size)
			return false;
		memcpy(out + o, piece, n);
		o += n;
	}
	if (convs != 1 || size == 0)
		return false;
	out[o] = '\0';
	return true;
}

bool turntable_is_gif(const char *out)
{
	size_t n = strlen(out);
	return n >= 4 && strcasecmp(out + n - 4, ".gif") == 0;
}

bool turntable_output_ok(const char *out)
{
	char name[4096];
	return turntable_is_gif(out) ||
	       (turntable_name(out, 0, name, sizeof name) && image_type_of(name));
}
