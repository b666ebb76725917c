/* rtsh — where the core reads the files a scene references (filesrc.h). */
#include "rtsh/filesrc.h"

#include <errno.h>
#include <fcntl.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "rtsh/memory.h"

static _Atomic(const rt_file_source *) source;

void rt_file_source_set(const rt_file_source *src)
{
	atomic_store(&source, src);
}

char *rt_file_read(const char *path, const char *what, size_t *len, rt_error *err)
{
	const rt_file_source *s = atomic_load(&source);
	if (s && s->read)
		return s->read(s->ctx, path, what, len, err);
	return rt_file_read_disk(path, what, len, err);
}

int rt_file_stat(const char *path, struct stat *st)
{
	const rt_file_source *s = atomic_load(&source);
	if (s && s->stat)
		return s->stat(s->ctx, path, st);
	return stat(path, st);
}

const char *rt_file_kind(mode_t mode)
{
	return S_ISREG(mode)    ? NULL
	       : S_ISDIR(mode)  ? "a directory"
	       : S_ISFIFO(mode) ? "a FIFO (named pipe)"
	       : S_ISCHR(mode)  ? "a character device"
	       : S_ISBLK(mode)  ? "a block device"
	       : S_ISSOCK(mode) ? "a socket"
	                        : "not a regular file";
}

FILE *rt_file_open_regular(const char *path, const char **kind)
{
	*kind = NULL;
	struct stat st;
	if (stat(path, &st) != 0)
		return NULL;
	if ((*kind = rt_file_kind(st.st_mode)))
		return NULL;
	int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
	if (fd < 0)
		return NULL;
	int flags = fcntl(fd, F_GETFL);
	if (fstat(fd, &st) != 0 || (*kind = rt_file_kind(st.st_mode)) || flags < 0 ||
	    fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) != 0) {
		int e = errno;
		close(fd);
		errno = e;
		return NULL;
	}
	FILE *f = fdopen(fd, "rb");
	if (!f) {
		int e = errno;
		close(fd);
		errno = e;
	}
	return f;
}

/* Files larger than this are refused rather than read. */
#define SLURP_MAX ((size_t)4 << 30)

char *rt_file_read_disk(const char *path, const char *what, size_t *len, rt_error *err)
{
	const char *kind;
	FILE *f = rt_file_open_regular(path, &kind);
	if (!f) {
		if (kind)
			rt_error_set(err, "%s: cannot read the %s: it is %s; expected a regular file", path, what, kind);
		else
			rt_error_set(err, "%s: cannot read the %s: %s", path, what, strerror(errno));
		return NULL;
	}
	struct stat st;
	if (fstat(fileno(f), &st) != 0) {
		fclose(f);
		rt_error_set(err, "%s: cannot read the %s: %s", path, what, strerror(errno));
		return NULL;
	}
	if ((unsigned long long)st.st_size > SLURP_MAX) {
		fclose(f);
		rt_error_set(err, "%s: the %s is %lld bytes; expected at most %zu", path, what,
		             (long long)st.st_size, SLURP_MAX);
		return NULL;
	}
	size_t n = (size_t)st.st_size;
	char what_[300];
	snprintf(what_, sizeof what_, "the %s %s", what, path);
	if (!mem_check((double)n, what_, err)) {
		fclose(f);
		return NULL;
	}
	char *buf = malloc(n + 1);
	if (!buf) {
		fclose(f);
		rt_error_set(err, "%s: out of memory reading the %s (%zu bytes)", path, what, n);
		return NULL;
	}
	size_t got = fread(buf, 1, n, f);
	bool bad = ferror(f);
	fclose(f);
	if (bad || got != n) {
		free(buf);
		rt_error_set(err, "%s: cannot read the %s: %s", path, what, bad ? strerror(errno) : "short read");
		return NULL;
	}
	buf[n] = '\0';
	*len = n;
	return buf;
}
