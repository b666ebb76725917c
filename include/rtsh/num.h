/* rtsh — the one strict number scanner: the .rt reader, the shell's
 * arguments and the settings all read numbers with it, so that a number
 * means the same everywhere (`set exposure 0x1` and `camera fov 0x1` are
 * both refused).
 *
 * A decimal number is [+-] (DIGITS [. DIGITS] | . DIGITS) [(e|E) [+-] DIGITS]
 * filling the whole text: no blanks, no hexadecimal, no inf or nan, no
 * thousands separators, read in the "C" locale whatever the program's is.
 * A whole number is [+-] DIGITS.
 */
#ifndef RTSH_NUM_H
#define RTSH_NUM_H

#include <stdbool.h>
#include <stddef.h>

typedef enum num_status {
	NUM_OK,
	NUM_EMPTY, /* no text */
	NUM_BAD,   /* not a number of the grammar above */
	NUM_BIG,   /* a number, but its magnitude is above the limit (or overflows) */
} num_status;

/* The decimal number s[0..len), |v| <= max. A text of 64 bytes or more is
 * read in place: the byte after it must be readable and must not continue a
 * number (the reader's tokens end in ',', 'x' or NUL). */
num_status num_scan(const char *s, size_t len, double max, double *out);
/* The same for a NUL-terminated string. */
num_status num_scan_str(const char *s, double max, double *out);
/* A whole number filling s, in [min, max] (NUM_BIG outside). */
num_status num_scan_long(const char *s, long min, long max, long *out);
/* A whole number >= 0 filling s (DIGITS, no sign). */
num_status num_scan_u64(const char *s, unsigned long long *out);

/* a + b added in the decimals the two are written with (their shortest
 * round-trip forms): 0.101 + 0.001 is 0.102 exactly, not
 * 0.10200000000000001, so that many small edits do not drift. When the
 * decimals exceed what a double holds at the sum's magnitude (a move
 * computed in camera axes, 1/3), the plain sum. */
double num_add_decimal(double a, double b);

#endif
