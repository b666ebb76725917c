/* rtsh — the append buffer (abuf.h). */
#include "base/abuf.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

void abuf_init(abuf *a)
{
	a->b = NULL;
	a->len = a->cap = 0;
	a->failed = false;
}

void abuf_free(abuf *a)
{
	free(a->b);
	abuf_init(a);
}

void abuf_reset(abuf *a)
{
	a->len = 0;
	a->failed = false;
}

static bool reserve(abuf *a, size_t n)
{
	if (a->failed)
		return false;
	if (a->len + n + 1 <= a->cap)
		return true;
	size_t cap = a->cap ? a->cap : 256;
	while (cap < a->len + n + 1)
		cap *= 2;
	char *p = realloc(a->b, cap);
	if (!p) {
		a->failed = true;
		return false;
	}
	a->b = p;
	a->cap = cap;
	return true;
}

void abuf_add(abuf *a, const char *s, size_t n)
{
	if (n == 0)
		return; /* nothing to add, and s may be NULL (an empty abuf's b) */
	if (!reserve(a, n))
		return;
	memcpy(a->b + a->len, s, n);
	a->len += n;
	a->b[a->len] = '\0';
}

void abuf_str(abuf *a, const char *s)
{
	abuf_add(a, s, strlen(s));
}

void abuf_char(abuf *a, char c)
{
	abuf_add(a, &c, 1);
}

void abuf_uint(abuf *a, unsigned v)
{
	char d[12];
	int n = 0;
	do {
		d[sizeof d - 1 - n++] = (char)('0' + v % 10);
		v /= 10;
	} while (v);
	abuf_add(a, d + sizeof d - n, (size_t)n);
}

void abuf_printf(abuf *a, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	int n = vsnprintf(NULL, 0, fmt, ap);
	va_end(ap);
	if (n < 0 || !reserve(a, (size_t)n))
		return;
	va_start(ap, fmt);
	vsnprintf(a->b + a->len, (size_t)n + 1, fmt, ap);
	va_end(ap);
	a->len += (size_t)n;
}

bool write_all(int fd, const void *buf, size_t n)
{
	const char *p = buf;
	while (n > 0) {
		ssize_t k = write(fd, p, n);
		if (k < 0) {
			if (errno == EINTR)
				continue;
			return false;
		}
		p += k;
		n -= (size_t)k;
	}
	return true;
}
