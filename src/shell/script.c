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
			if (shell_sig_int && name) {
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

bool shell_run_file(shell *sh, const char *path)
{
	bool is_stdin = strcmp(path, "-") == 0;
	FILE *f = is_stdin ? stdin : fopen(path, "r");
	if (!f)
		return shell_fail(sh, "cannot open %s: %s", path, strerror(errno));
	const char *name = is_stdin ? "stdin" : path;
	char *line = NULL;
	size_t cap = 0;
	long lineno = 0, count = 0;
	bool ok = true;
	ssize_t n;
	while (ok && !sh->quit && (n = getline(&line, &cap, f)) >= 0) {
		lineno++;
		if (memchr(line, '\0', (size_t)n)) {
			fprintf(stderr, "%s:%ld: the line holds a NUL byte; expected text\n", name, lineno);
			sh->err_reported = true;
			ok = shell_fail(sh, "the line holds a NUL byte; expected text");
			break;
		}
		ok = run_line(sh, line, name, lineno, &count, false);
	}
	if (ok && ferror(f)) {
		ok = shell_fail(sh, "cannot read %s: %s", name, strerror(errno));
	}
	free(line);
	if (!is_stdin)
		fclose(f);
	return ok;
}
