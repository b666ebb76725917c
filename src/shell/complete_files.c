/* rtsh — file names for tab completion (complete_files.h). */
#include "shell/complete_files.h"

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "rtsh/image.h"
#include "rtsh/mesh.h"

/* What `save` writes besides the image formats of image.h. */
static const char *const text_exts[] = {".ans", ".rt", NULL};
static bool ends_with(const char *name, const char *ext)
{
	size_t n = strlen(name), e = strlen(ext);
	return n > e && strcasecmp(name + n - e, ext) == 0;
}

static bool in(const char *const *exts, const char *name)
{
	for (size_t i = 0; exts[i]; i++)
		if (ends_with(name, exts[i]))
			return true;
	return false;
}

const char *const *output_extensions(void)
{
	/* image.c's table of formats, then the text outputs */
	static const char *list[32];
	if (!list[0]) {
		size_t n = 0;
		for (size_t i = 0; image_type_at(i) && n < 24; i++)
			list[n++] = image_type_at(i)->ext;
		for (size_t i = 0; text_exts[i]; i++)
			list[n++] = text_exts[i];
		list[n] = NULL;
	}
	return list;
}

bool output_name_ok(const char *name)
{
	return in(output_extensions(), name);
}

void complete_files(const char *text, file_use use, void (*add)(void *ctx, const char *s), void *ctx)
{
	/* Split text into the folder part (kept as typed) and the name part. */
	const char *slash = strrchr(text, '/');
	size_t dlen = slash ? (size_t)(slash - text) + 1 : 0;
	const char *part = text + dlen;
	char dir[4096];
	const char *home = getenv("HOME");
	if (dlen == 0)
		snprintf(dir, sizeof dir, ".");
	else if (strncmp(text, "~/", 2) == 0 && home && *home)
		snprintf(dir, sizeof dir, "%s/%.*s", home, (int)(dlen - 2), text + 2);
	else
		snprintf(dir, sizeof dir, "%.*s", (int)dlen, text);
	DIR *d = opendir(dir);
	size_t plen = strlen(part);
	char cand[4096], full[8192];
	if (d) {
		struct dirent *e;
		while ((e = readdir(d))) {
			const char *n = e->d_name;
			if (strcmp(n, ".") == 0 || strcmp(n, "..") == 0 || strncmp(n, part, plen) != 0)
				continue;
			if (n[0] == '.' && part[0] != '.')
				continue; /* hidden, unless asked for */
			snprintf(full, sizeof full, "%s/%s", dir, n);
			struct stat st;
			bool is_dir = stat(full, &st) == 0 && S_ISDIR(st.st_mode);
			if (!is_dir && !(use == FILES_SCENE ? (ends_with(n, ".rt") || mesh_format_known(n)) : output_name_ok(n)))
				continue;
			snprintf(cand, sizeof cand, "%.*s%s%s", (int)dlen, text, n, is_dir ? "/" : "");
			add(ctx, cand);
		}
		closedir(d);
	}
	/* save NAME<Tab>: NAME with each extension save writes. */
	if (use == FILES_OUTPUT && plen > 0 && !strchr(part, '.')) {
		for (const char *const *x = output_extensions(); *x; x++) {
			snprintf(cand, sizeof cand, "%s%s", text, *x);
			add(ctx, cand);
		}
	}
}
