/* rtsh — next and prev: the .rt files of the scene's folder in turn, by
 * name. Key mode's scene keys run them too, so they sit below key mode
 * (cmd_scene.c's `view` runs key mode). */
#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "shell/answer.h"
#include "shell/commands.h"

static int cmp_names(const void *a, const void *b)
{
	return strcmp(*(char *const *)a, *(char *const *)b);
}

/* The .rt files of dir in sorted order; NULL with a message on failure. */
static char **list_rt_files(shell *sh, const char *what, const char *dir, size_t *count)
{
	DIR *d = opendir(dir);
	if (!d) {
		shell_fail(sh, "%s: cannot read the folder %s: %s", what, dir, strerror(errno));
		return NULL;
	}
	char **names = NULL;
	size_t n = 0, cap = 0;
	struct dirent *e;
	while ((e = readdir(d))) {
		size_t len = strlen(e->d_name);
		if (len < 4 || strcmp(e->d_name + len - 3, ".rt") != 0)
			continue;
		if (n == cap) {
			cap = cap ? cap * 2 : 16;
			char **p = realloc(names, cap * sizeof *p);
			if (!p)
				break;
			names = p;
		}
		names[n] = strdup(e->d_name);
		if (names[n])
			n++;
	}
	closedir(d);
	if (n > 0)
		qsort(names, n, sizeof *names, cmp_names);
	*count = n;
	if (n == 0) {
		free(names);
		shell_fail(sh, "%s: no .rt files in %s", what, dir);
		return NULL;
	}
	return names;
}

static const char *base_name(const char *path)
{
	const char *s = strrchr(path, '/');
	return s ? s + 1 : path;
}

/* Opens the .rt file `step` places from the current one (wrapping around),
 * skipping files that fail to load (with a note). */
static bool step_scene(shell *sh, int step, const char *what)
{
	const char *dir = sh->dir ? sh->dir : ".";
	size_t n;
	char **names = list_rt_files(sh, what, dir, &n);
	if (!names)
		return false;
	const char *cur = sh->label && strncmp(sh->label, "generate:", 9) != 0 ? base_name(sh->label) : NULL;
	long at = -1;
	for (size_t i = 0; cur && i < n; i++)
		if (strcmp(names[i], cur) == 0)
			at = (long)i;
	if (at < 0)
		at = step > 0 ? -1 : (long)n;
	bool ok = false;
	for (size_t tries = 0; tries < n && !ok; tries++) {
		at = ((at + step) % (long)n + (long)n) % (long)n;
		if (cur && strcmp(names[at], cur) == 0 && tries > 0)
			break;
		char path[4096];
		if (strcmp(dir, ".") == 0)
			snprintf(path, sizeof path, "%s", names[at]);
		else
			snprintf(path, sizeof path, "%s/%s", dir, names[at]);
		ok = shell_load(sh, path);
		if (!ok && tries + 1 < n) {
			shell_note(sh, "%s (skipped)\n", sh->err);
			sh->err[0] = '\0';
		}
	}
	for (size_t i = 0; i < n; i++)
		free(names[i]);
	free(names);
	return ok;
}

bool cmd_next(shell *sh, int argc, char **argv, const char *rest)
{
	(void)argc, (void)argv, (void)rest;
	render_settings before = sh->set;
	if (!step_scene(sh, 1, "next"))
		return false;
	answer_loaded(sh, "opened", &before);
	return true;
}

bool cmd_prev(shell *sh, int argc, char **argv, const char *rest)
{
	(void)argc, (void)argv, (void)rest;
	render_settings before = sh->set;
	if (!step_scene(sh, -1, "prev"))
		return false;
	answer_loaded(sh, "opened", &before);
	return true;
}
