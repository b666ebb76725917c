/* rtsh — errors as values.
 *
 * The core never prints and never exits: a function that can fail takes an
 * rt_error * (which may be NULL), fills it and returns false / NULL / -1.
 * The front end decides how to show it (rt_error_format).
 */
#ifndef RTSH_ERROR_H
#define RTSH_ERROR_H

#include <stdbool.h>
#include <stddef.h>

#define RT_ERROR_MSG_MAX 512
#define RT_ERROR_FILE_MAX 256

typedef struct rt_error {
	char file[RT_ERROR_FILE_MAX]; /* "" when not from a file */
	int line;                     /* 1-based; 0 = no line */
	int col;                      /* 1-based; 0 = no column */
	char msg[RT_ERROR_MSG_MAX];   /* "what is wrong; expected ..." */
} rt_error;

/* Sets err (if not NULL) to a message with no location. Always returns false. */
bool rt_error_set(rt_error *err, const char *fmt, ...)
	__attribute__((format(printf, 2, 3)));
/* Sets err (if not NULL) with a location. Always returns false. */
bool rt_error_at(rt_error *err, const char *file, int line, int col, const char *fmt, ...)
	__attribute__((format(printf, 5, 6)));
/* Clears err to "no error". */
void rt_error_clear(rt_error *err);
/* "FILE:LINE:COL: msg", "FILE:LINE: msg", "FILE: msg" or "msg", as much as is known. */
void rt_error_format(const rt_error *err, char *buf, size_t size);

/* Warnings (non-fatal notes such as a clamped FOV) are collected by the
 * caller through this optional sink; NULL ignores them. */
typedef struct rt_warnings {
	void (*emit)(void *ctx, const rt_error *w);
	void *ctx;
} rt_warnings;
void rt_warn(const rt_warnings *w, const char *file, int line, int col, const char *fmt, ...)
	__attribute__((format(printf, 5, 6)));

#endif
