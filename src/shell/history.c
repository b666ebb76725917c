/* rtsh — the command history file (history.h). */
#include "shell/history.h"

#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <readline/history.h>

bool history_path(char *buf, size_t size)
{
	const char *home = getenv("HOME");
	if (!home || !*home) {
		if (size)
			buf[0] = '\0';
		return false;
	}
	return snprintf(buf, size, "%s%s.rtsh_history", home, home[strlen(home) - 1] == '/' ? "" : "/") <
	       (int)size;
}

static void warn_once(shell_history *h, int err)
{
	if (!h->warned && h->warn)
		fprintf(h->warn, "rtsh: cannot write %s (%s); the history of this session is not kept\n",
		        h->path[0] ? h->path : "the history file (HOME is not set)", strerror(err));
	h->warned = true;
	h->writable = false;
}

void history_setup(shell_history *h, FILE *warn)
{
	memset(h, 0, sizeof *h);
	h->warn = warn;
	stifle_history(HISTORY_MAX);
	if (!history_path(h->path, sizeof h->path)) {
		warn_once(h, ENOENT);
		return;
	}
	read_history(h->path); /* a missing file is an empty history */
	/* Can the file be written? Open it for appending (creating it). */
	int fd = open(h->path, O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0600);
	if (fd < 0) {
		warn_once(h, errno);
		return;
	}
	close(fd);
	h->writable = true;
}

void history_add_line(shell_history *h, const char *line)
{
	if (!line[strspn(line, " \t")])
		return;
	HIST_ENTRY *last = history_length > 0 ? history_get(history_base + history_length - 1) : NULL;
	if (last && strcmp(last->line, line) == 0)
		return;
	add_history(line);
	if (h->writable) {
		int rc = append_history(1, h->path);
		if (rc != 0)
			warn_once(h, rc);
	}
}

void history_finish(shell_history *h)
{
	if (h->writable)
		history_truncate_file(h->path, HISTORY_MAX);
}
