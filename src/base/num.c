/* rtsh — the one strict number scanner (num.h). */
#include "rtsh/num.h"

#include <errno.h>
#include <limits.h>
#include <locale.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static bool is_digit(char c) { return c >= '0' && c <= '9'; }

/* The end of the decimal number that starts at s, or NULL if none does. */
static const char *scan_decimal(const char *s, const char *end)
{
	const char *q = s;
	if (q < end && (*q == '+' || *q == '-'))
		q++;
	size_t ndig = 0;
	while (q < end && is_digit(*q)) {
		q++;
		ndig++;
	}
	if (q < end && *q == '.') {
		q++;
		while (q < end && is_digit(*q)) {
			q++;
			ndig++;
		}
	}
	if (ndig == 0)
		return NULL;
	if (q < end && (*q == 'e' || *q == 'E')) {
		q++;
		if (q < end && (*q == '+' || *q == '-'))
			q++;
		const char *e0 = q;
		while (q < end && is_digit(*q))
			q++;
		if (q == e0)
			return NULL;
	}
	return q;
}

static locale_t c_locale;
static pthread_once_t c_once = PTHREAD_ONCE_INIT;

static void c_locale_init(void)
{
	c_locale = newlocale(LC_NUMERIC_MASK, "C", (locale_t)0);
}

num_status num_scan(const char *s, size_t len, double max, double *out)
{
	if (len == 0)
		return NUM_EMPTY;
	if (scan_decimal(s, s + len) != s + len)
		return NUM_BAD;
	/* The syntax is checked: strtod reads exactly these bytes (in the "C"
	 * locale). Short ones from a copy ("0" before an 'x' would start a hex
	 * number); long ones in place, where the text after them (',', 'x',
	 * NUL: see num.h) ends the number, which the end pointer confirms. */
	char small[64];
	const char *from = s;
	if (len < sizeof small) {
		memcpy(small, s, len);
		small[len] = '\0';
		from = small;
	}
	pthread_once(&c_once, c_locale_init);
	locale_t old = c_locale ? uselocale(c_locale) : (locale_t)0;
	char *end;
	double v = strtod(from, &end);
	if (c_locale)
		uselocale(old);
	if (end != from + len)
		return NUM_BAD;
	if (!(fabs(v) <= max))
		return NUM_BIG;
	*out = v;
	return NUM_OK;
}

num_status num_scan_str(const char *s, double max, double *out)
{
	return num_scan(s, strlen(s), max, out);
}

num_status num_scan_long(const char *s, long min, long max, long *out)
{
	const char *q = s;
	if (!*q)
		return NUM_EMPTY;
	if (*q == '+' || *q == '-')
		q++;
	if (!is_digit(*q))
		return NUM_BAD;
	while (is_digit(*q))
		q++;
	if (*q)
		return NUM_BAD;
	errno = 0;
	long v = strtol(s, NULL, 10);
	if (errno == ERANGE || v < min || v > max)
		return NUM_BIG;
	*out = v;
	return NUM_OK;
}

num_status num_scan_u64(const char *s, unsigned long long *out)
{
	if (!*s)
		return NUM_EMPTY;
	for (const char *q = s; *q; q++)
		if (!is_digit(*q))
			return NUM_BAD;
	errno = 0;
	unsigned long long v = strtoull(s, NULL, 10);
	if (errno == ERANGE)
		return NUM_BIG;
	*out = v;
	return NUM_OK;
}

/* Decimals after the point in x's shortest round-trip form; 99 when it
 * needs 17 digits or is not finite. */
static int shortest_decimals(double x)
{
	if (!isfinite(x))
		return 99;
	if (x == 0)
		return 0;
	char t[40];
	for (int p = 1; p <= 16; p++) {
		snprintf(t, sizeof t, "%.*e", p - 1, x);
		if (strtod(t, NULL) == x) {
			int e = atoi(strchr(t, 'e') + 1);
			int d = p - 1 - e;
			return d < 0 ? 0 : d;
		}
	}
	return 99;
}

double num_add_decimal(double a, double b)
{
	double s = a + b;
	pthread_once(&c_once, c_locale_init);
	locale_t old = c_locale ? uselocale(c_locale) : (locale_t)0;
	int k = shortest_decimals(a), kb = shortest_decimals(b);
	if (kb > k)
		k = kb;
	/* a and b are within half an ulp of decimals of k places, so their
	 * sum is within an ulp or two of a decimal of k places: rounding finds
	 * it while an ulp of s is far below half a unit in the k-th place. */
	double r = s;
	if (k <= 15 && isfinite(s) && fabs(s) * pow(10.0, k) < 1e14) {
		char t[64];
		snprintf(t, sizeof t, "%.*f", k, s);
		r = strtod(t, NULL);
		if (r == 0)
			r = 0.0; /* not -0 */
	}
	if (old)
		uselocale(old);
	return r;
}
