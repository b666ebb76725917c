/* rtsh — saving a file so that it keeps what was there (atomic.h).
 *
 * The steps of file_write_atomic:
 *   1. follow symbolic links to the file that is really written;
 *   2. look at what is there: nothing (create), an ordinary file with one
 *      link (replace atomically), or something whose identity must stay
 *      (hard links, another owner, a FIFO, a device: write in place);
 *   3. replace: remove stale temporary files of our naming, create one
 *      (O_EXCL), register it for the signal handlers, fill it, flush, sync,
 *      give it the old owner, mode and extended attributes (the ACL among
 *      them), rename it over the target, sync the folder;
 *   4. in place: make the whole content in memory, then write it over the
 *      file from its start and cut the file to its new length.
 */
#define _GNU_SOURCE /* fallocate */
#include "rtsh/atomic.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <pthread.h>
#include <stdint.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/xattr.h>
#include <time.h>
#include <unistd.h>

#include "base/abuf.h" /* write_all */

#define MAX_HOPS 40
/* The temporary file's name keeps at most this much of the target's name,
 * so that ".NAME.tmp.PID.XXXXXX" stays within NAME_MAX. */
#define TMP_BASE_MAX 200

static _Thread_local char note[PATH_MAX + 128];

const char *file_write_note(void)
{
	return note;
}

/* --- the temporary file, for the signal handlers --- */

static char sig_tmp[PATH_MAX + 64];
static volatile sig_atomic_t sig_tmp_set;

void atomic_cleanup_on_signal(void)
{
	if (sig_tmp_set) {
		int saved = errno;
		unlink(sig_tmp);
		sig_tmp_set = 0;
		errno = saved;
	}
}

/* Signals whose default action ends the process; while a temporary file
 * exists, those the program leaves at the default get a handler that
 * removes it and then dies of the same signal. */
static const int fatal_signals[] = {SIGTERM, SIGHUP, SIGINT, SIGQUIT};
#define NFATAL (sizeof fatal_signals / sizeof fatal_signals[0])

static void on_fatal(int sig)
{
	atomic_cleanup_on_signal();
	/* SA_RESETHAND made the action the default again: the signal, raised
	 * now and delivered when this returns, ends the process as before. */
	raise(sig);
}

typedef struct guard {
	struct sigaction old[NFATAL];
	bool ours[NFATAL];
} guard;

/* Installs the handlers; the temporary file is registered later. */
static void guard_on(guard *g)
{
	struct sigaction sa;
	memset(&sa, 0, sizeof sa);
	sa.sa_handler = on_fatal;
	sa.sa_flags = SA_RESETHAND;
	sigemptyset(&sa.sa_mask);
	for (size_t i = 0; i < NFATAL; i++) {
		g->ours[i] = false;
		if (sigaction(fatal_signals[i], NULL, &g->old[i]) == 0 && !(g->old[i].sa_flags & SA_SIGINFO) &&
		    g->old[i].sa_handler == SIG_DFL)
			g->ours[i] = sigaction(fatal_signals[i], &sa, NULL) == 0;
	}
}

/* Creates the temporary file: the template's last six characters ("XXXXXX")
 * are replaced until the name is new (O_EXCL). `mode` goes through the
 * umask and the folder's default ACL like any new file's. */
static int create_exclusive(char *tmp, mode_t mode)
{
	static const char digits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789";
	static _Atomic unsigned long counter;
	char *x = tmp + strlen(tmp) - 6;
	struct timespec now;
	clock_gettime(CLOCK_REALTIME, &now);
	unsigned long long v = (unsigned long long)now.tv_nsec ^ ((unsigned long long)now.tv_sec << 20) ^
	                       ((unsigned long long)getpid() << 40);
	for (int attempt = 0; attempt < 1000; attempt++) {
		/* splitmix64 of the clock, the pid and a counter: a different
		 * name for every attempt, thread and process. */
		unsigned long long z = v + (unsigned long long)(++counter) * 0x9e3779b97f4a7c15ULL;
		z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
		z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
		z ^= z >> 31;
		for (int i = 0; i < 6; i++, z /= 62)
			x[i] = digits[z % 62];
		int fd = open(tmp, O_RDWR | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, mode);
		if (fd >= 0 || errno != EEXIST)
			return fd;
	}
	errno = EEXIST;
	return -1;
}

/* Creates the temporary file from the template and registers it, with the
 * fatal signals blocked in between, so none can come before it is known. */
static int create_registered(char *tmp, mode_t mode)
{
	sigset_t block, old;
	sigemptyset(&block);
	for (size_t i = 0; i < NFATAL; i++)
		sigaddset(&block, fatal_signals[i]);
	pthread_sigmask(SIG_BLOCK, &block, &old);
	int fd = create_exclusive(tmp, mode);
	int e = errno;
	if (fd >= 0) {
		size_t n = strlen(tmp);
		if (n >= sizeof sig_tmp)
			n = sizeof sig_tmp - 1;
		memcpy(sig_tmp, tmp, n);
		sig_tmp[n] = '\0';
		sig_tmp_set = 1;
	}
	pthread_sigmask(SIG_SETMASK, &old, NULL);
	errno = e;
	return fd;
}

static void guard_off(guard *g)
{
	for (size_t i = 0; i < NFATAL; i++)
		if (g->ours[i])
			sigaction(fatal_signals[i], &g->old[i], NULL);
	sig_tmp_set = 0;
}

/* --- names --- */

/* The folder part of path ("" for a bare name, "/" kept) and the name. */
static void split(const char *path, char *dir, size_t dsize, const char **base)
{
	const char *slash = strrchr(path, '/');
	int n = slash ? (int)(slash - path) + 1 : 0;
	snprintf(dir, dsize, "%.*s", n, path);
	*base = slash ? slash + 1 : path;
}

bool file_folder_exists(const char *path, rt_error *err)
{
	char dir[PATH_MAX];
	const char *base;
	split(path, dir, sizeof dir, &base);
	struct stat st;
	if (stat(*dir ? dir : ".", &st) == 0 || (errno != ENOENT && errno != ENOTDIR))
		return true;
	rt_error_at(err, path, 0, 0, "cannot create a file in that folder (%s); expected a writable folder",
	            strerror(errno));
	return false;
}

/* The file that writing `path` really writes: symbolic links followed, each
 * relative target taken from its link's folder. A link to a missing file
 * gives the missing file's path (it is created). Malloc'ed; NULL with err. */
static char *resolve(const char *path, rt_error *err)
{
	char *cur = strdup(path);
	if (!cur) {
		rt_error_at(err, path, 0, 0, "out of memory");
		return NULL;
	}
	for (int hop = 0;; hop++) {
		struct stat st;
		if (lstat(cur, &st) != 0 || !S_ISLNK(st.st_mode))
			return cur;
		if (hop == MAX_HOPS) {
			free(cur);
			rt_error_at(err, path, 0, 0, "too many levels of symbolic links; expected a link to a file");
			return NULL;
		}
		char target[PATH_MAX];
		ssize_t n = readlink(cur, target, sizeof target - 1);
		if (n < 0) {
			int e = errno;
			free(cur);
			rt_error_at(err, path, 0, 0, "cannot read the symbolic link (%s)", strerror(e));
			return NULL;
		}
		target[n] = '\0';
		char dir[PATH_MAX];
		const char *base;
		split(cur, dir, sizeof dir, &base);
		size_t len = (target[0] == '/' ? 0 : strlen(dir)) + (size_t)n + 1;
		char *next = malloc(len);
		if (!next) {
			free(cur);
			rt_error_at(err, path, 0, 0, "out of memory");
			return NULL;
		}
		snprintf(next, len, "%s%s", target[0] == '/' ? "" : dir, target);
		free(cur);
		cur = next;
	}
}

/* True when dir is on the file system of the device nodes (/dev), when that
 * is not the root file system. */
static bool device_folder(const char *dir)
{
	struct stat d, null, root;
	return stat(*dir ? dir : ".", &d) == 0 && stat("/dev/null", &null) == 0 && S_ISCHR(null.st_mode) &&
	       stat("/", &root) == 0 && null.st_dev != root.st_dev && d.st_dev == null.st_dev;
}

/* --- stale temporary files --- */

static struct timespec process_start;

__attribute__((constructor)) static void note_start(void)
{
	clock_gettime(CLOCK_REALTIME, &process_start);
}

static bool older_than_process(const struct stat *st)
{
	return st->st_mtim.tv_sec < process_start.tv_sec ||
	       (st->st_mtim.tv_sec == process_start.tv_sec && st->st_mtim.tv_nsec < process_start.tv_nsec);
}

/* Removes ".BASE.tmp.PID.XXXXXX" files (and the older ".BASE.tmp.XXXXXX")
 * in dir that a save of the same file left when its process was killed:
 * ours (same user), older than this process, and whose process no longer
 * runs; never `skip` (NULL: none), the save's own temporary file (a file's
 * time is the kernel's coarse clock, which can lag the process's start by a
 * tick). */
static void remove_stale(const char *dir, const char *base, const char *skip)
{
	char prefix[TMP_BASE_MAX + 8];
	int plen = snprintf(prefix, sizeof prefix, ".%.*s.tmp.", TMP_BASE_MAX, base);
	DIR *d = opendir(*dir ? dir : ".");
	if (!d)
		return;
	struct dirent *e;
	while ((e = readdir(d))) {
		if (strncmp(e->d_name, prefix, (size_t)plen) != 0 || (skip && strcmp(e->d_name, skip) == 0))
			continue;
		const char *rest = e->d_name + plen;
		const char *dot = strchr(rest, '.');
		long pid = 0;
		if (dot) {
			char *end;
			pid = strtol(rest, &end, 10);
			if (end != dot || pid <= 0 || strlen(dot + 1) != 6)
				continue;
		} else if (strlen(rest) != 6) {
			continue;
		}
		if (pid && pid != (long)getpid() && !(kill((pid_t)pid, 0) != 0 && errno == ESRCH))
			continue; /* its process still runs: a save in progress */
		char full[PATH_MAX];
		if (snprintf(full, sizeof full, "%s%s", dir, e->d_name) >= (int)sizeof full)
			continue;
		struct stat st;
		if (lstat(full, &st) == 0 && S_ISREG(st.st_mode) && st.st_uid == geteuid() && older_than_process(&st))
			unlink(full);
	}
	closedir(d);
}

/* --- writing --- */

/* Runs the writer into memory; the text (malloc'ed) and its length. */
static char *make_content(const char *path, file_writer_fn write, void *ctx, size_t *len, rt_error *err)
{
	char *buf = NULL;
	FILE *f = open_memstream(&buf, len);
	if (!f) {
		rt_error_at(err, path, 0, 0, "out of memory");
		return NULL;
	}
	bool ok = write(f, ctx, err);
	if (fclose(f) != 0 && ok)
		ok = rt_error_at(err, path, 0, 0, "out of memory");
	if (!ok) {
		free(buf);
		return NULL;
	}
	return buf;
}

/* Writes the content over the existing file target, from its start. */
static bool write_in_place(const char *path, const char *target, const struct stat *st, file_writer_fn write,
                           void *ctx, rt_error *err)
{
	size_t len;
	char *buf = make_content(path, write, ctx, &len, err);
	if (!buf)
		return false;
	bool fifo = S_ISFIFO(st->st_mode);
	/* A FIFO with no reader would block the shell: say so instead. */
	int fd = open(target, O_WRONLY | O_NOCTTY | O_CLOEXEC | (fifo ? O_NONBLOCK : 0));
	if (fd < 0) {
		int e = errno;
		free(buf);
		if (fifo && e == ENXIO)
			return rt_error_at(err, path, 0, 0, "is a FIFO with no reader; expected a program reading it");
		return rt_error_at(err, path, 0, 0, "cannot open the file to write it in place (%s)", strerror(e));
	}
	if (fifo)
		fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) & ~O_NONBLOCK);
	/* A reader that leaves the FIFO before the end: the write fails with
	 * EPIPE instead of a SIGPIPE ending rtsh (the shell with it). */
	sigset_t pipe_set, old_mask, pending;
	sigemptyset(&pipe_set);
	sigaddset(&pipe_set, SIGPIPE);
	bool was_pending = sigpending(&pending) == 0 && sigismember(&pending, SIGPIPE);
	pthread_sigmask(SIG_BLOCK, &pipe_set, &old_mask);
	bool regular = S_ISREG(st->st_mode);
	/* The blocks first (beyond the end, the size unchanged): a full disk is
	 * found before the file's first byte is overwritten. File systems
	 * without fallocate are written as they are. */
	if (regular && len > (size_t)st->st_size && fallocate(fd, FALLOC_FL_KEEP_SIZE, 0, (off_t)len) != 0 &&
	    (errno == ENOSPC || errno == EDQUOT || errno == EFBIG)) {
		int e = errno;
		pthread_sigmask(SIG_SETMASK, &old_mask, NULL);
		close(fd);
		free(buf);
		return rt_error_at(err, path, 0, 0, "write failed (%s); the file was left as it was", strerror(e));
	}
	bool ok = write_all(fd, buf, len) && (!regular || ftruncate(fd, (off_t)len) == 0) &&
	          (!regular || fsync(fd) == 0);
	int e = errno;
	if (!ok && e == EPIPE && !was_pending) {
		struct timespec zero = {0, 0};
		while (sigtimedwait(&pipe_set, NULL, &zero) < 0 && errno == EINTR) {
		}
	}
	pthread_sigmask(SIG_SETMASK, &old_mask, NULL);
	if (close(fd) != 0 && ok) {
		ok = false;
		e = errno;
	}
	free(buf);
	if (!ok && e == EPIPE)
		return rt_error_at(err, path, 0, 0, "write failed (%s): the program reading it stopped before the end",
		                   strerror(e));
	if (!ok)
		return rt_error_at(err, path, 0, 0, "write failed (%s)", strerror(e));
	return true;
}

/* Syncs the folder, so that the rename itself survives a power cut. */
static void sync_folder(const char *dir)
{
	int fd = open(*dir ? dir : ".", O_RDONLY | O_DIRECTORY | O_CLOEXEC);
	if (fd >= 0) {
		fsync(fd);
		close(fd);
	}
}

/* --- extended attributes --- */

/* The names of a file's extended attributes, NUL-separated, in a malloc'ed
 * buffer (NULL with *n = 0 when it has none or the file system has none);
 * false on another error. From the path (fd < 0) or the descriptor. */
static bool xattr_names(const char *path, int fd, char **names, ssize_t *n)
{
	*names = NULL;
	*n = 0;
	for (int attempt = 0; attempt < 8; attempt++) {
		ssize_t size = fd < 0 ? llistxattr(path, NULL, 0) : flistxattr(fd, NULL, 0);
		if (size < 0)
			return errno == ENOTSUP || errno == ENOSYS;
		if (size == 0)
			return true;
		char *buf = malloc((size_t)size);
		if (!buf)
			return false;
		ssize_t got = fd < 0 ? llistxattr(path, buf, (size_t)size) : flistxattr(fd, buf, (size_t)size);
		if (got >= 0) {
			*names = buf;
			*n = got;
			return true;
		}
		free(buf);
		if (errno != ERANGE) /* ERANGE: the list grew in between; again */
			return false;
	}
	return false;
}

static bool name_in(const char *name, const char *names, ssize_t n)
{
	/* by offset: names is NULL when the list is empty */
	for (ssize_t off = 0; off < n; off += (ssize_t)strlen(names + off) + 1)
		if (strcmp(names + off, name) == 0)
			return true;
	return false;
}

/* The SELinux label is the system's to give (the new file already has the
 * label its folder's policy gives): not setting it is no loss. */
static bool system_label(const char *name)
{
	return strcmp(name, "security.selinux") == 0;
}

/* Gives the open temporary file fd the extended attributes of the file
 * `from` — the access ACL (system.posix_acl_access), user.*, and those
 * this process may set — and removes those fd has that `from` lacks (an
 * ACL inherited from the folder's default ACL). Call after fchown and
 * fchmod: an ACL sets the group bits of the mode, and chown drops
 * security.capability. False, with the attribute's name in `failed` and
 * errno set, when one cannot be copied. */
static bool copy_xattrs(const char *from, int fd, char *failed, size_t fsize)
{
	char *names, *have;
	ssize_t n, nhave;
	if (!xattr_names(from, -1, &names, &n)) {
		snprintf(failed, fsize, "(the list)");
		return false;
	}
	bool ok = true;
	char *value = NULL;
	for (ssize_t off = 0; ok && off < n; off += (ssize_t)strlen(names + off) + 1) {
		const char *p = names + off;
		ssize_t size = lgetxattr(from, p, NULL, 0);
		char *v = size > 0 ? realloc(value, (size_t)size) : value;
		if (size > 0 && !v) {
			errno = ENOMEM;
			size = -1;
		} else if (size > 0) {
			value = v;
			size = lgetxattr(from, p, value, (size_t)size);
		}
		if (size == -1 && errno == ENODATA) /* removed in between */
			continue;
		if ((size < 0 || fsetxattr(fd, p, value, (size_t)size, 0) != 0) && !system_label(p)) {
			snprintf(failed, fsize, "%s", p);
			ok = false;
		}
	}
	free(value);
	if (ok && !xattr_names(NULL, fd, &have, &nhave)) {
		snprintf(failed, fsize, "(the list)");
		ok = false;
	} else if (ok) {
		for (ssize_t off = 0; ok && off < nhave; off += (ssize_t)strlen(have + off) + 1) {
			const char *p = have + off;
			if (!name_in(p, names, n) && !system_label(p) && fremovexattr(fd, p) != 0 && errno != ENODATA) {
				snprintf(failed, fsize, "%s", p);
				ok = false;
			}
		}
		free(have);
	}
	int e = errno;
	free(names);
	errno = e;
	return ok;
}

/* The old file's cached pages are dropped while the new one is written,
 * by a thread of their own: otherwise the rename frees them (about 0.4 ms
 * for 6 MB, loaded) on the save's serial tail (issue 29). Only its cache:
 * its bytes stay on the disk until the rename, so an interrupted save still
 * leaves it whole. The same thread looks for stale temporary files
 * (remove_stale: a read of the whole folder, 0.2 ms for 400 files). Small
 * files are not worth a thread. */
#define DROP_CACHE_MIN ((off_t)1 << 20)

typedef struct cache_drop {
	pthread_t thread;
	bool running;
	int fd; /* the old file, open until cache_drop_release; -1: none */
	const char *dir, *base, *skip; /* remove_stale's */
} cache_drop;

static void *drop_cache(void *arg)
{
	cache_drop *d = arg;
	remove_stale(d->dir, d->base, d->skip);
	(void)posix_fadvise(d->fd, 0, 0, POSIX_FADV_DONTNEED);
	return NULL;
}

static void *close_fd(void *arg)
{
	close((int)(intptr_t)arg);
	return NULL;
}

/* Starts the thread for a big old file, else removes the stale files here;
 * skip: the temporary file's name in dir. */
static void cache_drop_start(cache_drop *d, const char *target, const struct stat *old, const char *dir,
                             const char *base, const char *skip)
{
	*d = (cache_drop){.running = false, .fd = -1, .dir = dir, .base = base, .skip = skip};
	if (old && S_ISREG(old->st_mode) && old->st_size >= DROP_CACHE_MIN)
		d->fd = open(target, O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
	/* unreadable: its pages stay, nothing else changes */
	d->running = d->fd >= 0 && pthread_create(&d->thread, NULL, drop_cache, d) == 0;
	if (d->running)
		return;
	if (d->fd >= 0)
		close(d->fd);
	d->fd = -1;
	remove_stale(dir, base, skip);
}

static void cache_drop_end(cache_drop *d)
{
	if (d->running)
		pthread_join(d->thread, NULL);
	d->running = false;
}

/* After the rename: the old file, no longer linked, is freed (its blocks,
 * 1.5-2 ms for 6 MB on ext4, issue 29) when its last descriptor closes,
 * ours: a thread closes it beside the folder's sync (joined by
 * cache_drop_end), not the rename on this thread. */
static void cache_drop_release(cache_drop *d)
{
	if (d->fd < 0)
		return;
	d->running = pthread_create(&d->thread, NULL, close_fd, (void *)(intptr_t)d->fd) == 0;
	if (!d->running)
		close(d->fd);
	d->fd = -1;
}

typedef enum replace_result {
	REPLACED,
	FAILED,
	CANNOT_CREATE,
	CANNOT_KEEP_OWNER,
	CANNOT_KEEP_XATTR, /* xattr_failed names it */
} replace_result;

static _Thread_local char xattr_failed[256];
static _Thread_local int xattr_errno;
static _Thread_local int create_errno; /* why the temporary file could not be made */

/* Writes a temporary file beside target and renames it over target. `old`
 * is the file being replaced (NULL: a new file). */
static replace_result replace(const char *path, const char *target, const struct stat *old, file_writer_fn write,
                              void *ctx, rt_error *err)
{
	char dir[PATH_MAX];
	const char *base;
	split(target, dir, sizeof dir, &base);
	char tmp[PATH_MAX + 64];
	if (snprintf(tmp, sizeof tmp, "%s.%.*s.tmp.%ld.XXXXXX", dir, TMP_BASE_MAX, base, (long)getpid()) >=
	    (int)sizeof tmp) {
		rt_error_at(err, path, 0, 0, "the path is too long");
		return FAILED;
	}
	guard g;
	guard_on(&g);
	/* A new file is created as any other (0666 through the umask and the
	 * folder's default ACL); a replacement starts private and takes the old
	 * file's owner, mode and attributes below. */
	int fd = create_registered(tmp, old ? 0600 : 0666);
	if (fd < 0) {
		int e = errno;
		remove_stale(dir, base, NULL);
		guard_off(&g);
		rt_error_at(err, path, 0, 0, "cannot create a file in that folder (%s); expected a writable folder",
		            strerror(e));
		create_errno = e;
		return e == EACCES || e == EPERM || e == EROFS ? CANNOT_CREATE : FAILED;
	}
	replace_result res = FAILED;
	if (old) {
		/* The old file's owner and group, then its mode (chown may clear
		 * set-id bits). Another user's file that we cannot give back to
		 * its owner is written in place instead; a group we may not set
		 * stays ours. */
		if (old->st_uid != geteuid() && fchown(fd, old->st_uid, old->st_gid) != 0) {
			res = CANNOT_KEEP_OWNER;
			goto fail_fd;
		}
		if (old->st_uid == geteuid() && old->st_gid != getegid())
			(void)!fchown(fd, (uid_t)-1, old->st_gid);
		fchmod(fd, old->st_mode & 07777);
		/* Its extended attributes and ACL; one that cannot be copied
		 * (a file system or a security module refusing it) is kept by
		 * writing in place instead. */
		if (!copy_xattrs(target, fd, xattr_failed, sizeof xattr_failed)) {
			xattr_errno = errno;
			res = CANNOT_KEEP_XATTR;
			goto fail_fd;
		}
	}
	FILE *f = fdopen(fd, "wb");
	if (!f) {
		rt_error_at(err, path, 0, 0, "cannot write (%s)", strerror(errno));
		goto fail_fd;
	}
	cache_drop drop;
	cache_drop_start(&drop, target, old, dir, base, tmp + strlen(dir));
	errno = 0;
	bool ok = write(f, ctx, err);
	int e = errno;
	cache_drop_end(&drop);
	if (!ok && ferror(f) && e) /* the writer stopped on a write error: say which */
		rt_error_at(err, path, 0, 0, "write failed (%s)", strerror(e));
	if (ok && (fflush(f) != 0 || ferror(f) || fsync(fd) != 0))
		ok = rt_error_at(err, path, 0, 0, "write failed (%s)", strerror(errno ? errno : EIO));
	if (fclose(f) != 0 && ok)
		ok = rt_error_at(err, path, 0, 0, "write failed (%s)", strerror(errno));
	if (ok && rename(tmp, target) != 0)
		ok = rt_error_at(err, path, 0, 0, "cannot replace the file (%s)", strerror(errno));
	if (!ok)
		unlink(tmp);
	cache_drop_release(&drop);
	guard_off(&g);
	if (ok)
		sync_folder(dir);
	cache_drop_end(&drop);
	return ok ? REPLACED : FAILED;
fail_fd:
	close(fd);
	unlink(tmp);
	remove_stale(dir, base, NULL);
	guard_off(&g);
	return res;
}

static const char *kind_name(mode_t m)
{
	return S_ISFIFO(m) ? "a FIFO" : S_ISCHR(m) ? "a character device" : S_ISBLK(m) ? "a block device" : "";
}

bool file_write_atomic(const char *path, file_writer_fn write, void *ctx, rt_error *err)
{
	note[0] = '\0';
	char *target = resolve(path, err);
	if (!target)
		return false;
	bool ok = false;
	struct stat st;
	if (lstat(target, &st) != 0) {
		if (errno != ENOENT) {
			rt_error_at(err, path, 0, 0, "cannot look at the file (%s)", strerror(errno));
			goto done;
		}
		char dir[PATH_MAX];
		const char *base;
		split(target, dir, sizeof dir, &base);
		if (device_folder(dir)) {
			rt_error_at(err, path, 0, 0,
			            "that folder holds device nodes; expected a folder for files (no file was created)");
			goto done;
		}
		ok = replace(path, target, NULL, write, ctx, err) == REPLACED;
		goto done;
	}
	if (S_ISDIR(st.st_mode)) {
		rt_error_at(err, path, 0, 0, "is a folder; expected a file name");
		goto done;
	}
	if (S_ISFIFO(st.st_mode) || S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode)) {
		ok = write_in_place(path, target, &st, write, ctx, err);
		if (ok)
			snprintf(note, sizeof note, "%s is %s: written to it in place", path, kind_name(st.st_mode));
		goto done;
	}
	if (!S_ISREG(st.st_mode)) {
		rt_error_at(err, path, 0, 0, "is a socket or other special file; expected a regular file");
		goto done;
	}
	if (st.st_nlink > 1) {
		ok = write_in_place(path, target, &st, write, ctx, err);
		if (ok)
			snprintf(note, sizeof note, "%s has %ju hard links: written in place to keep them", path,
			         (uintmax_t)st.st_nlink);
		goto done;
	}
	switch (replace(path, target, &st, write, ctx, err)) {
	case REPLACED:
		ok = true;
		break;
	case FAILED:
		break;
	case CANNOT_KEEP_OWNER:
		ok = write_in_place(path, target, &st, write, ctx, err);
		if (ok)
			snprintf(note, sizeof note, "%s belongs to another user: written in place to keep its owner",
			         path);
		break;
	case CANNOT_KEEP_XATTR:
		ok = write_in_place(path, target, &st, write, ctx, err);
		if (ok)
			snprintf(note, sizeof note,
			         "%s: its extended attribute %s cannot be copied (%s): written in place to keep it",
			         path, xattr_failed, strerror(xattr_errno));
		break;
	case CANNOT_CREATE:
		/* The folder is read-only; the file may still be writable. */
		if (access(target, W_OK) != 0) {
			int e = errno;
			rt_error_at(err, path, 0, 0,
			            "cannot create a file in that folder (%s) nor write the file in place (%s); expected a "
			            "writable folder or file",
			            strerror(create_errno), strerror(e));
		} else {
			ok = write_in_place(path, target, &st, write, ctx, err);
			if (ok)
				snprintf(note, sizeof note,
				         "%s: the folder is not writable, so the file was written in place (not atomically)",
				         path);
		}
		break;
	}
done:
	free(target);
	return ok;
}
