/* rtsh — errors as values (error.h). */
#include "rtsh/error.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

static void set_file(rt_error *err, const char *file)
{
	if (!file)
		file = "";
	size_t n = strlen(file);
	if (n >= sizeof err->file) {
		/* Keep the end of a long path: the file name matters most. */
		file += n - (sizeof err->file - 4);
		snprintf(err->file, sizeof err->file, "...%s", file);
	} else {
		memcpy(err->file, file, n + 1);
	}
}

bool rt_error_set(rt_error *err, const char *fmt, ...)
{
	if (!err)
		return false;
	err->file[0] = '\0';
	err->line = err->col = 0;
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(err->msg, sizeof err->msg, fmt, ap);
	va_end(ap);
	return false;
}

bool rt_error_at(rt_error *err, const char *file, int line, int col, const char *fmt, ...)
{
	if (!err)
		return false;
	set_file(err, file);
	err->line = line;
	err->col = col;
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(err->msg, sizeof err->msg, fmt, ap);
	va_end(ap);
	return false;
}

void rt_error_clear(rt_error *err)
{
	if (!err)
		return;
	err->file[0] = '\0';
	err->line = err->col = 0;
	err->msg[0] = '\0';
}

void rt_error_format(const rt_error *err, char *buf, size_t size)
{
	if (!size)
		return;
	if (!err->file[0])
		snprintf(buf, size, "%s", err->msg);
	else if (err->line <= 0)
		snprintf(buf, size, "%s: %s", err->file, err->msg);
	else if (err->col <= 0)
		snprintf(buf, size, "%s:%d: %s", err->file, err->line, err->msg);
	else
		snprintf(buf, size, "%s:%d:%d: %s", err->file, err->line, err->col, err->msg);
}

void rt_warn(const rt_warnings *w, const char *file, int line, int col, const char *fmt, ...)
{
	if (!w || !w->emit)
		return;
	rt_error e;
	set_file(&e, file);
	e.line = line;
	e.col = col;
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(e.msg, sizeof e.msg, fmt, ap);
	va_end(ap);
	w->emit(w->ctx, &e);
}
