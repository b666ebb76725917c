/* rtsh — text made safe to show on a terminal (visible.h). */
#include "base/visible.h"

#include <string.h>

/* The length of the control character at s (1, or 2 for a C1 control
 * in UTF-8), or 0 when s starts with none. */
static size_t control_at(const unsigned char *s, bool lines)
{
	if (s[0] < 0x20)
		return lines && (s[0] == '\n' || s[0] == '\t') ? 0 : 1;
	if (s[0] == 0x7f)
		return 1;
	if (s[0] == 0xc2 && s[1] >= 0x80 && s[1] <= 0x9f)
		return 2;
	return 0;
}

bool text_has_controls(const char *s, bool lines)
{
	for (const unsigned char *p = (const unsigned char *)s; *p; p++)
		if (control_at(p, lines))
			return true;
	return false;
}

char *text_visible(char *dst, size_t size, const char *src, bool lines)
{
	if (!size)
		return dst;
	size_t n = 0;
	const unsigned char *p = (const unsigned char *)src;
	while (*p) {
		char rep[5];
		size_t k = control_at(p, lines), len, step;
		if (k == 1) {
			rep[0] = '^';
			rep[1] = p[0] == 0x7f ? '?' : (char)(p[0] + 0x40);
			len = 2;
			step = 1;
		} else if (k == 2) {
			memcpy(rep, "M-^", 3);
			rep[3] = (char)(p[1] - 0x80 + 0x40);
			len = 4;
			step = 2;
		} else {
			/* a whole UTF-8 character: its lead byte and continuations */
			step = 1;
			while (p[step] && (p[step] & 0xc0) == 0x80 && step < 4)
				step++;
			if (n + step >= size)
				break;
			memcpy(dst + n, p, step);
			n += step;
			p += step;
			continue;
		}
		if (n + len >= size)
			break;
		memcpy(dst + n, rep, len);
		n += len;
		p += step;
	}
	dst[n] = '\0';
	return dst;
}
