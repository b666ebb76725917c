/* rtsh — the one strict number scanner (num.h). */
#include "rtsh/num.h"

#include <errno.h>
#include <limits.h>
#include <locale.h>
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static bool is_digit(char c) { return c >= '0' && c <= '9'; }

/* Exactly representable powers of ten: 10^22 < 2^53 * 2^22 is the last whose
 * odd part (5^22 < 2^53) fits a double's 53 bits. */
static const double exact_pow10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                       1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                       1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

/* Reads the decimal s[0..end) of num.h's grammar in one pass: -1 when it
 * is not one; 1 with its value in *out when that can be had exactly without
 * strtod: at most 15 significant digits m (so m < 2^53 is an exact double)
 * and a decimal exponent e with |e| <= 22 (so 10^|e| is exact), when m *
 * 10^e or m / 10^-e is one correctly rounded IEEE operation, the same
 * double strtod gives (Clinger, "How to read floating point numbers
 * accurately", PLDI 1990: the fast path); 0 when strtod must read it. */
static int decimal_read(const char *s, const char *end, double *out)
{
	const char *q = s;
	bool neg = false, slow = false;
	if (q < end && (*q == '+' || *q == '-'))
		neg = *q++ == '-';
	uint64_t m = 0;
	int ndig = 0, sig = 0, exp10 = 0;
	for (; q < end && is_digit(*q); q++, ndig++)
		if (sig || *q != '0') { /* leading zeros are not significant */
			if (++sig > 15)
				slow = true;
			else
				m = m * 10 + (uint64_t)(*q - '0');
		}
	if (q < end && *q == '.')
		for (q++; q < end && is_digit(*q); q++, ndig++) {
			exp10--;
			if (sig || *q != '0') {
				if (++sig > 15)
					slow = true;
				else
					m = m * 10 + (uint64_t)(*q - '0');
			}
		}
	if (ndig == 0)
		return -1;
	if (q < end && (*q == 'e' || *q == 'E')) {
		q++;
		bool eneg = false;
		if (q < end && (*q == '+' || *q == '-'))
			eneg = *q++ == '-';
		const char *e0 = q;
		int e = 0;
		for (; q < end && is_digit(*q); q++)
			if (e <= 1000) /* far outside the fast path: no overflow */
				e = e * 10 + (*q - '0');
		if (q == e0)
			return -1;
		if (e > 1000)
			slow = true;
		exp10 += eneg ? -e : e;
	}
	if (q != end)
		return -1;
	if (m == 0 && !slow)
		exp10 = 0; /* zero whatever the exponent */
	if (slow || exp10 < -22 || exp10 > 22)
		return 0;
	double v = (double)m;
	v = exp10 >= 0 ? v * exact_pow10[exp10] : v / exact_pow10[-exp10];
	*out = neg ? -v : v;
	return 1;
}

static locale_t c_locale;
static pthread_once_t c_once = PTHREAD_ONCE_INIT;

static void c_locale_init(void)
{
	c_locale = newlocale(LC_NUMERIC_MASK, "C", (locale_t)0);
}

/* The common decimals, [+-]DIGITS[.DIGITS] with at most 15 digits in all
 * and no exponent, in one tight pass: true with *out set to the value
 * decimal_read gives (the digits, leading zeros and all, are an integer m <
 * 10^15, exact, over 10^f for f fraction digits: one correctly rounded
 * division, as there). False leaves the rest to decimal_read. */
static inline bool decimal_short(const char *s, const char *end, double *out)
{
	const char *q = s;
	bool neg = false;
	if (q < end && (*q == '+' || *q == '-'))
		neg = *q++ == '-';
	const char *d0 = q;
	uint64_t m = 0;
	unsigned d;
	while (q < end && (d = (unsigned)(unsigned char)*q - '0') < 10) {
		m = m * 10 + d;
		q++;
	}
	size_t whole = (size_t)(q - d0), frac = 0;
	if (q < end && *q == '.') {
		const char *f0 = ++q;
		while (q < end && (d = (unsigned)(unsigned char)*q - '0') < 10) {
			m = m * 10 + d;
			q++;
		}
		frac = (size_t)(q - f0);
	}
	if (q != end || whole + frac == 0 || whole + frac > 15)
		return false;
	double v = (double)m;
	if (frac)
		v /= exact_pow10[frac];
	*out = neg ? -v : v;
	return true;
}

/* num_scan's numbers that decimal_short leaves: exponents, long ones, bad
 * ones (its own function, so that num_scan's frame stays small). */
static __attribute__((noinline)) num_status num_scan_rest(const char *s, size_t len, double max, double *out);

num_status num_scan(const char *s, size_t len, double max, double *out)
{
	if (len == 0)
		return NUM_EMPTY;
	double v;
	if (decimal_short(s, s + len, &v)) {
		if (!(fabs(v) <= max))
			return NUM_BIG;
		*out = v;
		return NUM_OK;
	}
	return num_scan_rest(s, len, max, out);
}

static __attribute__((noinline)) num_status num_scan_rest(const char *s, size_t len, double max, double *out)
{
	double fast;
	int got = decimal_read(s, s + len, &fast);
	if (got < 0)
		return NUM_BAD;
	if (got > 0) {
		if (!(fabs(fast) <= max))
			return NUM_BIG;
		*out = fast;
		return NUM_OK;
	}
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
