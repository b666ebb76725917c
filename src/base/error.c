/* rtsh — errors as values (error.h). */
#include "rtsh/error.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "base/visible.h"

/* A message's text made safe for a terminal (visible.h): file names and
 * strings read from files (a glTF image's uri) may hold escape sequences,
 * and errors are printed where a file manager's preview pane or the shell
 * shows them. */
static void make_visible(char *msg)
{
	if (!text_has_controls(msg, false))
		return;
	char tmp[RT_ERROR_MSG_MAX];
	text_visible(tmp, sizeof tmp, msg, false);
	memcpy(msg, tmp, strlen(tmp) + 1);
}

static void set_file(rt_error *err, const char *file)
{
	/* visible first, so that a long name keeps its end */
	char vis[4 * RT_ERROR_FILE_MAX + 4096];
	file = text_visible(vis, sizeof vis, file ? file : "", false);
	size_t n = strlen(file);
	if (n >= sizeof err->file) {
		/* Keep the end of a long path: the file name matters most. */
		file += n - (sizeof err->file - 4);
		while ((*file & 0xc0) == 0x80) /* at a whole character */
			file++;
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
	make_visible(err->msg);
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
	make_visible(err->msg);
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
	make_visible(e.msg);
	w->emit(w->ctx, &e);
}
