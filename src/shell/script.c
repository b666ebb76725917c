/* rtsh — running commands from text: a typed line, -c, -f, source, piped
 * standard input. '#' starts a comment (at the start of a word, outside
 * quotes); ';' separates commands on a line.
 *
 * Errors in a command file read "FILE:LINE: message"; in -c text, which is
 * often one line, "-c: command N: message" with N counting the commands;
 * commands read from standard input are "stdin:LINE: message". The first
 * error stops the file.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rtsh/filesrc.h"
#include "rtsh/memory.h"
#include "shell/commands.h"
#include "shell/shell.h"

/* The first character of s, outside quotes and not escaped, that `stop`
 * accepts; the terminating NUL when there is none. */
static char *scan(char *s, bool (*stop)(const char *s, const char *p))
{
	char quote = 0;
	char *p = s;
	for (; *p; p++) {
		if (quote) {
			if (*p == '\\' && quote == '"' && p[1])
				p++;
			else if (*p == quote)
				quote = 0;
		} else if (*p == '\\' && p[1]) {
			p++;
		} else if (*p == '\'' || *p == '"') {
			quote = *p;
		} else if (stop(s, p)) {
			break;
		}
	}
	return p;
}

/* '#' at the start of a word. */
static bool comment_start(const char *s, const char *p)
{
	return *p == '#' && (p == s || p[-1] == ' ' || p[-1] == '\t');
}

static bool semicolon(const char *s, const char *p)
{
	(void)s;
	return *p == ';';
}

/* Cuts a comment off line (in place). */
static void strip_comment(char *line)
{
	*scan(line, comment_start) = '\0';
}

/* The end of the command starting at p: the next ';' outside quotes, or
 * the end of the string. */
static char *command_end(char *p)
{
	return scan(p, semicolon);
}

static bool blank(const char *s)
{
	return s[strspn(s, " \t\r\n")] == '\0';
}

/* Runs the commands of one line. For a file, name/lineno locate errors and
 * *count numbers the commands (for -c). False on the first error. */
static bool run_line(shell *sh, const char *text, const char *name, long lineno, long *count,
                     bool count_commands)
{
	char *line = strdup(text);
	if (!line)
		return shell_fail(sh, "out of memory");
	strip_comment(line);
	bool ok = true;
	for (char *p = line; ok && !sh->quit;) {
		char *end = command_end(p);
		bool last = *end == '\0';
		*end = '\0';
		if (!blank(p)) {
			(*count)++;
			/* One command at most SHELL_LINE_MAX bytes, wherever it came
			 * from (a file's lines are cut at that length as they are
			 * read; -c text is bounded by the kernel's argument limit
			 * and may hold many commands). */
			if ((size_t)(end - p) > SHELL_LINE_MAX) {
				sh->err[0] = '\0';
				ok = shell_fail(sh, "the command is longer than " SHELL_LINE_MAX_TEXT
				                    " bytes; expected at most " SHELL_LINE_MAX_TEXT);
			} else if (shell_sig_int && name) {
				ok = shell_fail(sh, "interrupted");
			} else {
				sh->err[0] = '\0';
				ok = command_run(sh, p);
			}
			if (!ok && name && !sh->err_reported) {
				fflush(stdout);
				if (count_commands)
					fprintf(stderr, "%s: command %ld: %s\n", name, *count, sh->err);
				else
					fprintf(stderr, "%s:%ld: %s\n", name, lineno, sh->err);
				sh->err_reported = true;
			}
		}
		if (last)
			break;
		p = end + 1;
	}
	free(line);
	return ok;
}

bool shell_run_line(shell *sh, const char *line)
{
	long count = 0;
	sh->err_reported = false;
	return run_line(sh, line, NULL, 0, &count, false);
}

void shell_report(shell *sh)
{
	if (!sh->err_reported && sh->err[0]) {
		fflush(stdout);
		fprintf(stderr, "%s\n", sh->err);
	}
	sh->err_reported = false;
	sh->err[0] = '\0';
}

bool shell_run_text(shell *sh, const char *text, const char *name, bool count_commands)
{
	char *copy = strdup(text);
	if (!copy)
		return shell_fail(sh, "out of memory");
	long lineno = 0, count = 0;
	bool ok = true;
	for (char *p = copy; ok && !sh->quit && *p;) {
		char *nl = strchr(p, '\n');
		if (nl)
			*nl = '\0';
		lineno++;
		ok = run_line(sh, p, name, lineno, &count, count_commands);
		if (!nl)
			break;
		p = nl + 1;
	}
	free(copy);
	return ok;
}

/* How reading one line ended. */
typedef enum line_end { LINE_OK, LINE_EOF, LINE_NUL, LINE_LONG, LINE_ERROR } line_end;

/* Reads one line of f into buf (SHELL_LINE_MAX + 2 bytes) without its
 * newline, NUL-terminated. Stops at the first NUL byte (LINE_NUL) and at the
 * first byte past SHELL_LINE_MAX (LINE_LONG), so endless input (/dev/zero, a
 * line that never ends) costs one line's buffer and no more. */
static line_end read_line(FILE *f, char *buf)
{
	size_t n = 0;
	int c;
	while ((c = getc(f)) != EOF && c != '\n') {
		if (c == '\0')
			return LINE_NUL;
		if (n == SHELL_LINE_MAX)
			return LINE_LONG;
		buf[n++] = (char)c;
	}
	buf[n] = '\0';
	if (c == EOF && ferror(f))
		return LINE_ERROR;
	return c == EOF && n == 0 ? LINE_EOF : LINE_OK;
}

bool shell_run_file(shell *sh, const char *path)
{
	bool is_stdin = strcmp(path, "-") == 0 || strcmp(path, "/dev/stdin") == 0;
	const char *kind = NULL;
	errno = 0;
	/* Only standard input may be a pipe or a device: a FIFO given by name is
	 * refused before it is opened, which would wait for a writer (issue 31). */
	FILE *f = is_stdin ? stdin : rt_file_open_regular(path, &kind);
	if (!f && kind)
		return shell_fail(sh, "%s: is %s; expected a command file (a regular file, or - for standard input)",
		                  path, kind);
	if (!f && !path[0])
		return shell_fail(sh, "the command file's name is empty; expected a file name (or - for standard input)");
	if (!f)
		return shell_fail(sh, "cannot open %s: %s", path, strerror(errno));
	const char *name = strcmp(path, "-") == 0 ? "stdin" : path;
	rt_error merr;
	bool fits = mem_check(SHELL_LINE_MAX + 2, "a command line", &merr);
	char *line = fits ? malloc(SHELL_LINE_MAX + 2) : NULL;
	if (!line) {
		if (!is_stdin)
			fclose(f);
		return shell_fail(sh, "%s", fits ? "out of memory reading a command line" : merr.msg);
	}
	long lineno = 0, count = 0;
	bool ok = true;
	while (ok && !sh->quit) {
		line_end e = read_line(f, line);
		if (e == LINE_EOF)
			break;
		lineno++;
		const char *bad = e == LINE_NUL    ? "the line holds a NUL byte; expected text"
		                  : e == LINE_LONG ? "the line is longer than " SHELL_LINE_MAX_TEXT
		                                     " bytes; expected at most " SHELL_LINE_MAX_TEXT
		                  : e == LINE_ERROR ? strerror(errno)
		                                    : NULL;
		if (bad) {
			fflush(stdout);
			if (e == LINE_ERROR)
				fprintf(stderr, "%s:%ld: cannot read: %s\n", name, lineno, bad);
			else
				fprintf(stderr, "%s:%ld: %s\n", name, lineno, bad);
			sh->err_reported = true;
			ok = shell_fail(sh, "%s", bad);
			break;
		}
		ok = run_line(sh, line, name, lineno, &count, false);
	}
	free(line);
	if (!is_stdin)
		fclose(f);
	return ok;
}
