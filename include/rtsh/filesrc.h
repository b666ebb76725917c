/* rtsh — where the core reads the files a scene references: models,
 * material libraries, textures, the sky.
 *
 * By default they are read from disk. A program may set one process-wide
 * source instead, before any thread starts: rtsh-mpi does, so that rank 0
 * keeps every file it reads and the other ranks read the bytes rank 0
 * broadcast (src/mpi/fileset.h). The .rt file itself goes through the
 * loader's per-load hook (rt_load_opts.read, rt_read_file); these files are
 * read later, while the world is built, where no load options exist.
 *
 * Every reader in src/core reads such a file through rt_file_read, checks
 * it through rt_file_stat (the caches), and assimp opens its files through
 * rt_file_ai_import (src/core/mesh/ai_files.c). Base layer (src/base).
 */
#ifndef RTSH_FILESRC_H
#define RTSH_FILESRC_H

#include <stddef.h>
#include <stdio.h>
#include <sys/stat.h>

#include "rtsh/error.h"

typedef struct rt_file_source {
	/* The whole file, NUL-terminated (*len without the NUL), or NULL with
	 * err set as rt_file_read_disk words it. what: "model", "image"... */
	char *(*read)(void *ctx, const char *path, const char *what, size_t *len, rt_error *err);
	/* As stat(2): 0, or -1 with errno set. */
	int (*stat)(void *ctx, const char *path, struct stat *st);
	void *ctx;
} rt_file_source;

/* Sets the source (NULL: disk again). src must outlive its use. Call it
 * while no other thread reads files. */
void rt_file_source_set(const rt_file_source *src);
/* Reads through the source, or from disk when none is set. */
char *rt_file_read(const char *path, const char *what, size_t *len, rt_error *err);
/* stat(2) through the source, or on disk. */
int rt_file_stat(const char *path, struct stat *st);
/* Reads from disk: "PATH: cannot read the WHAT: reason" on failure (files
 * larger than 4 GiB are refused). */
char *rt_file_read_disk(const char *path, const char *what, size_t *len, rt_error *err);

/* Opens a file on disk for reading ("rb") when it is a regular file. It is
 * stat(2)ed first, so a FIFO, a device, a socket or a directory (or a link
 * to one) is refused without being opened: opening a FIFO waits for a
 * writer, and /dev/zero never ends. Then it is opened without blocking and
 * checked again (fstat), in case the name changed in between. NULL on
 * failure, with *kind the file's kind (rt_file_kind) when that is why, else
 * *kind NULL and errno set. */
FILE *rt_file_open_regular(const char *path, const char **kind);
/* The kind of a file that is not a regular one: "a FIFO (named pipe)",
 * "a directory", "a character device"...; NULL for a regular file. */
const char *rt_file_kind(mode_t mode);

#endif
