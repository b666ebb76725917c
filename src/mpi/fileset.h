/* rtsh-mpi — the files a scene needs, in memory: (path, bytes) pairs.
 *
 * Rank 0 loads the scene with fileset_record as the loader's reader
 * (rt_load_opts.read): every file the loader reads, the scene and anything
 * it references, is read from disk once and kept. The set is packed into
 * one buffer, broadcast, unpacked on every other rank, and the loader there
 * reads through fileset_serve, so only rank 0 needs the files. The files
 * the core reads while the world is built (models, material libraries,
 * textures, the sky) go the same way through fileset_source, the core's
 * process-wide file source (rtsh/filesrc.h).
 *
 * Packed form: for each file, u64 path length, the path, u64 data length,
 * the data (little-endian lengths).
 */
#ifndef RTSH_MPI_FILESET_H
#define RTSH_MPI_FILESET_H

#include <stdbool.h>
#include <stddef.h>

#include "rtsh/error.h"
#include "rtsh/filesrc.h"

typedef struct file_entry {
	char *path;
	char *data; /* NUL-terminated, len bytes before the NUL */
	size_t len;
} file_entry;

typedef struct fileset {
	file_entry *files;
	size_t n, cap;
} fileset;

void fileset_free(fileset *fs);
/* An rt_read_fn (ctx = fileset *): reads from disk and records the file. */
char *fileset_record(void *ctx, const char *path, size_t *len, rt_error *err);
/* An rt_read_fn (ctx = fileset *): a copy of the recorded file, or "PATH:
 * not among the files rank 0 sent". */
char *fileset_serve(void *ctx, const char *path, size_t *len, rt_error *err);
/* The core's file source over fs: with record, files are read from disk
 * (rt_file_read_disk) and kept, stat is stat(2); else a file is a copy of
 * the kept one, and stat says only that it is a regular file of that size
 * (ENOENT when rank 0 did not send it). fs must outlive the source's use. */
rt_file_source fileset_source(fileset *fs, bool record);
/* The packed set in a new buffer of *size bytes; NULL when out of memory. */
char *fileset_pack(const fileset *fs, size_t *size);
/* Fills an empty fs from a packed buffer; false when it is malformed or
 * memory runs out (fs then holds what was read; free it). */
bool fileset_unpack(fileset *fs, const char *buf, size_t size);

#endif
