/* rtsh — path and number helpers of the model and image readers (readhelp.h). */
#include "base/readhelp.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static _Thread_local const atomic_bool *read_cancel;
static _Thread_local unsigned read_calls;

const atomic_bool *read_cancel_set(const atomic_bool *cancel)
{
	const atomic_bool *old = read_cancel;
	read_cancel = cancel;
	return old;
}

bool read_cancelled(void)
{
	return read_cancel && atomic_load_explicit(read_cancel, memory_order_relaxed);
}

bool read_poll(void)
{
	return (++read_calls & 4095) == 0 && read_cancelled();
}

char *path_join(const char *dir, const char *rel)
{
	if (rel[0] == '/' || !dir[0] || strcmp(dir, ".") == 0)
		return strdup(rel);
	size_t a = strlen(dir), b = strlen(rel);
	char *p = malloc(a + b + 2);
	if (!p)
		return NULL;
	memcpy(p, dir, a);
	size_t k = a;
	if (dir[a - 1] != '/')
		p[k++] = '/';
	memcpy(p + k, rel, b + 1);
	return p;
}

char *path_dir(const char *path)
{
	const char *slash = strrchr(path, '/');
	if (!slash)
		return strdup("");
	size_t n = slash == path ? 1 : (size_t)(slash - path);
	char *d = malloc(n + 1);
	if (!d)
		return NULL;
	memcpy(d, path, n);
	d[n] = '\0';
	return d;
}

static const double pow10_pos[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9, 1e10,
                                   1e11, 1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

/* Steps over a leading + or - at *s; true for -. */
static inline bool take_sign(const char **s, const char *end)
{
	if (*s < end && (**s == '-' || **s == '+'))
		return *(*s)++ == '-';
	return false;
}

static bool word_at(const char *s, const char *end, const char *w)
{
	size_t n = strlen(w);
	if ((size_t)(end - s) < n)
		return false;
	for (size_t i = 0; i < n; i++)
		if ((s[i] | 0x20) != w[i])
			return false;
	return true;
}

const unsigned char *skip_space(const unsigned char *s, const unsigned char *end, bool comments, int *lines)
{
	for (; s < end; s++) {
		if (*s == '\n' && lines)
			++*lines;
		else if (comments && *s == '#')
			while (s + 1 < end && s[1] != '\n')
				s++;
		else if (*s != ' ' && *s != '\t' && *s != '\r' && *s != '\n')
			break;
	}
	return s;
}

bool scan_double(const char **sp, const char *end, double *out)
{
	const char *s = *sp;
	bool neg = take_sign(&s, end);
	if (word_at(s, end, "nan")) {
		*out = NAN;
		*sp = s + 3;
		return true;
	}
	if (word_at(s, end, "inf")) {
		*out = neg ? -INFINITY : INFINITY;
		s += 3;
		if (word_at(s, end, "inity"))
			s += 5;
		*sp = s;
		return true;
	}
	uint64_t mant = 0;
	int digits = 0, scale = 0;
	bool any = false;
	/* The digits before and after one point: the first 19 significant ones
	 * make mant; a later one before the point scales it up, after the point
	 * it is dropped. */
	bool frac = false;
	for (; s < end; s++) {
		if (*s == '.' && !frac) {
			frac = true;
			continue;
		}
		if (*s < '0' || *s > '9')
			break;
		any = true;
		if (digits < 19) {
			mant = mant * 10 + (uint64_t)(*s - '0');
			if (mant)
				digits++;
			if (frac)
				scale--;
		} else if (!frac) {
			scale++;
		}
	}
	if (!any)
		return false;
	if (s < end && (*s == 'e' || *s == 'E')) {
		const char *e = s + 1;
		bool eneg = false;
		if (e < end && (*e == '-' || *e == '+'))
			eneg = *e++ == '-';
		if (e < end && *e >= '0' && *e <= '9') {
			int x = 0;
			while (e < end && *e >= '0' && *e <= '9') {
				if (x < 100000)
					x = x * 10 + (*e - '0');
				e++;
			}
			scale += eneg ? -x : x;
			s = e;
		}
	}
	double v = (double)mant;
	if (mant == 0)
		v = 0.0;
	else if (scale >= 0 && scale <= 22)
		v *= pow10_pos[scale];
	else if (scale < 0 && scale >= -22)
		v /= pow10_pos[-scale];
	else
		v *= pow(10.0, scale);
	*out = neg ? -v : v;
	*sp = s;
	return true;
}

bool scan_long(const char **sp, const char *end, long *out)
{
	const char *s = *sp;
	bool neg = take_sign(&s, end);
	if (!(s < end && *s >= '0' && *s <= '9'))
		return false;
	long v = 0;
	while (s < end && *s >= '0' && *s <= '9') {
		if (v < 100000000000L)
			v = v * 10 + (*s - '0');
		s++;
	}
	*out = neg ? -v : v;
	*sp = s;
	return true;
}
