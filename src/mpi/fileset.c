/* rtsh-mpi — the files a scene needs, in memory (fileset.h). */
#include "mpi/fileset.h"

#include <errno.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "rtsh/memory.h"
#include "rtsh/rtfile.h"

void fileset_free(fileset *fs)
{
	for (size_t i = 0; i < fs->n; i++) {
		free(fs->files[i].path);
		free(fs->files[i].data);
	}
	free(fs->files);
	*fs = (fileset){0};
}

/* Takes ownership of path and data (freed on failure). */
static bool add(fileset *fs, char *path, char *data, size_t len)
{
	if (path && data && fs->n == fs->cap) {
		size_t cap = fs->cap ? fs->cap * 2 : 8;
		file_entry *f = realloc(fs->files, cap * sizeof *f);
		if (f) {
			fs->files = f;
			fs->cap = cap;
		}
	}
	if (!path || !data || fs->n == fs->cap) {
		free(path);
		free(data);
		return false;
	}
	fs->files[fs->n++] = (file_entry){path, data, len};
	return true;
}

static const file_entry *find(const fileset *fs, const char *path)
{
	for (size_t i = 0; i < fs->n; i++)
		if (strcmp(fs->files[i].path, path) == 0)
			return &fs->files[i];
	return NULL;
}

/* Keeps a copy of data under path (when it is not kept yet). */
static bool keep(fileset *fs, const char *path, const char *data, size_t len)
{
	if (find(fs, path))
		return true;
	char *copy = mem_dupz(data, len), *name = mem_dupz(path, strlen(path));
	if (!copy || !name) {
		free(copy);
		free(name);
		return false;
	}
	return add(fs, name, copy, len);
}

/* Rank 0's reads: a kept file again, else the bytes `data` the caller read
 * (NULL: it failed, err set), kept for the other ranks. */
static char *recorded(fileset *fs, const char *path, char *data, size_t *len, rt_error *err, const char *what)
{
	if (data && !keep(fs, path, data, *len)) {
		free(data);
		rt_error_set(err, "%s: out of memory keeping the %s for the other ranks", path, what);
		return NULL;
	}
	return data;
}

/* True when path is kept: *copy its copy (NULL when memory ran out). */
static bool kept(const fileset *fs, const char *path, size_t *len, char **copy)
{
	const file_entry *e = find(fs, path);
	if (e) {
		*len = e->len;
		*copy = mem_dupz(e->data, e->len);
	}
	return e != NULL;
}

/* The other ranks' reads: a copy of the kept file, or NULL with err
 * set (in the words of the core's file source, or with what NULL the
 * scene loader's). */
static char *served(const fileset *fs, const char *path, size_t *len, rt_error *err, const char *what)
{
	char *c = NULL;
	bool there = kept(fs, path, len, &c);
	if (c)
		return c;
	if (what)
		rt_error_set(err, there ? "%s: out of memory reading the %s"
		                        : "%s: cannot read the %s: not among the files rank 0 sent",
		             path, what);
	else
		rt_error_at(err, path, 0, 0,
		            there ? "out of memory" : "not among the files rank 0 sent; expected a file rank 0 read");
	return NULL;
}

char *fileset_record(void *ctx, const char *path, size_t *len, rt_error *err)
{
	fileset *fs = ctx;
	char *copy;
	if (kept(fs, path, len, &copy))
		return copy;
	return recorded(fs, path, rt_read_file(path, NULL, len, err), len, err, "file");
}

char *fileset_serve(void *ctx, const char *path, size_t *len, rt_error *err)
{
	return served(ctx, path, len, err, NULL);
}

static char *src_record(void *ctx, const char *path, const char *what, size_t *len, rt_error *err)
{
	fileset *fs = ctx;
	char *copy;
	if (kept(fs, path, len, &copy))
		return copy;
	return recorded(fs, path, rt_file_read_disk(path, what, len, err), len, err, what);
}

static int src_stat_disk(void *ctx, const char *path, struct stat *st)
{
	(void)ctx;
	return stat(path, st);
}

static char *src_serve(void *ctx, const char *path, const char *what, size_t *len, rt_error *err)
{
	return served(ctx, path, len, err, what);
}

static int src_stat_kept(void *ctx, const char *path, struct stat *st)
{
	const file_entry *e = find(ctx, path);
	if (!e) {
		errno = ENOENT;
		return -1;
	}
	memset(st, 0, sizeof *st);
	st->st_mode = S_IFREG | 0444;
	st->st_size = (off_t)e->len;
	return 0;
}

rt_file_source fileset_source(fileset *fs, bool record)
{
	return record ? (rt_file_source){src_record, src_stat_disk, fs}
	              : (rt_file_source){src_serve, src_stat_kept, fs};
}

static char *put_u64(char *p, uint64_t v)
{
	for (int i = 0; i < 8; i++)
		*p++ = (char)(v >> (8 * i) & 0xff);
	return p;
}

static bool get_u64(const char **p, const char *end, uint64_t *v)
{
	if (end - *p < 8)
		return false;
	*v = 0;
	for (int i = 0; i < 8; i++)
		*v |= (uint64_t)(unsigned char)(*p)[i] << (8 * i);
	*p += 8;
	return true;
}

char *fileset_pack(const fileset *fs, size_t *size)
{
	size_t n = 0;
	for (size_t i = 0; i < fs->n; i++)
		n += 16 + strlen(fs->files[i].path) + fs->files[i].len;
	char *buf = malloc(n ? n : 1), *p = buf;
	if (!buf)
		return NULL;
	for (size_t i = 0; i < fs->n; i++) {
		size_t pl = strlen(fs->files[i].path);
		p = put_u64(p, pl);
		memcpy(p, fs->files[i].path, pl);
		p = put_u64(p + pl, fs->files[i].len);
		memcpy(p, fs->files[i].data, fs->files[i].len);
		p += fs->files[i].len;
	}
	*size = n;
	return buf;
}

bool fileset_unpack(fileset *fs, const char *buf, size_t size)
{
	const char *p = buf, *end = buf + size;
	while (p < end) {
		uint64_t pl, dl;
		if (!get_u64(&p, end, &pl) || pl > (uint64_t)(end - p))
			return false;
		const char *path = p;
		p += pl;
		if (!get_u64(&p, end, &dl) || dl > (uint64_t)(end - p) || memchr(path, '\0', pl))
			return false;
		if (!add(fs, mem_dupz(path, pl), mem_dupz(p, dl), dl))
			return false;
		p += dl;
	}
	return true;
}
