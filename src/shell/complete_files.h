/* rtsh — file names for tab completion, by what a command can use: `load`
 * is offered folders and scene files, `save` folders, the files it could
 * overwrite and, for a name without an extension, that name with each
 * extension it can write. */
#ifndef RTSH_COMPLETE_FILES_H
#define RTSH_COMPLETE_FILES_H

#include <stdbool.h>

typedef enum file_use {
	FILES_SCENE,  /* what `load` reads */
	FILES_OUTPUT, /* what `save` writes */
} file_use;

/* Calls add(ctx, candidate) for each name that completes text; folders end
 * in '/'. A leading ~/ is kept as typed. */
void complete_files(const char *text, file_use use, void (*add)(void *ctx, const char *s), void *ctx);
/* True when `save` writes a file of this name. */
bool output_name_ok(const char *name);
/* The extensions `save` writes, ".png" and so on, NULL-terminated. */
const char *const *output_extensions(void);

#endif
