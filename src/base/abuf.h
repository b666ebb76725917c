/* rtsh — an append buffer (base layer): a frame, a status line or a file's
 * text is built here and sent with one write(). Allocation failure is
 * sticky: the buffer is marked failed, later appends do nothing and the
 * caller drops the output. The text stays NUL-terminated. */
#ifndef RTSH_ABUF_H
#define RTSH_ABUF_H

#include <stdbool.h>
#include <stddef.h>

typedef struct abuf {
	char *b;
	size_t len, cap;
	bool failed;
} abuf;

void abuf_init(abuf *a);
void abuf_free(abuf *a);
/* Empties the buffer, keeping its memory. */
void abuf_reset(abuf *a);
void abuf_add(abuf *a, const char *s, size_t n);
void abuf_str(abuf *a, const char *s);
void abuf_char(abuf *a, char c);
/* Appends the decimal digits of v. */
void abuf_uint(abuf *a, unsigned v);
void abuf_printf(abuf *a, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* Writes all n bytes to fd, retrying after signals and short writes; false
 * on an error. */
bool write_all(int fd, const void *buf, size_t n);

#endif
