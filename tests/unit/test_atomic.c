/* rtsh — tests of file_write_atomic (what a failing writer leaves, the
 * temporary files, links, modes, extended attributes and ACLs, notes) and
 * of the memory estimates. */
#define _GNU_SOURCE /* preadv2, RWF_NOWAIT */
#include "testutil.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <time.h>
#include <sys/stat.h>
#include <sys/uio.h>
#include <sys/vfs.h>
#include <sys/xattr.h>
#include <unistd.h>

#include "rtsh/atomic.h"
#include "rtsh/edit.h"
#include "rtsh/generate.h"
#include "rtsh/memory.h"

static char dir[] = "/tmp/rtsh-test-atomic-XXXXXX";

static int setup(void **state)
{
	(void)state;
	return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state)
{
	(void)state;
	char cmd[128];
	snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
	return system(cmd);
}

static bool write_text(FILE *f, void *ctx, rt_error *err)
{
	(void)err;
	return fputs(ctx, f) >= 0;
}

/* Writes half the text, then fails as an encoder would. */
static bool write_half_then_fail(FILE *f, void *ctx, rt_error *err)
{
	const char *s = ctx;
	fwrite(s, 1, strlen(s) / 2, f);
	fflush(f);
	return rt_error_set(err, "encoder failed");
}

static char *slurp(const char *path)
{
	static char buf[4096];
	FILE *f = fopen(path, "rb");
	if (!f)
		return NULL;
	size_t n = fread(buf, 1, sizeof buf - 1, f);
	fclose(f);
	buf[n] = '\0';
	return buf;
}

/* Entries of the test folder whose name starts with prefix. */
static int count_prefix(const char *prefix)
{
	DIR *d = opendir(dir);
	int n = 0;
	struct dirent *e;
	while ((e = readdir(d)))
		n += strncmp(e->d_name, prefix, strlen(prefix)) == 0;
	closedir(d);
	return n;
}

static void test_failing_writer_keeps_the_old_file(void **state)
{
	(void)state;
	char path[128], lpath[128], other[128];
	snprintf(path, sizeof path, "%s/a.txt", dir);
	rt_error err;
	assert_true(file_write_atomic(path, write_text, "old content\n", &err));
	assert_string_equal(file_write_note(), "");
	assert_false(file_write_atomic(path, write_half_then_fail, "new content that fails\n", &err));
	assert_string_equal(err.msg, "encoder failed");
	assert_string_equal(slurp(path), "old content\n");
	assert_int_equal(count_prefix(".a.txt.tmp."), 0);
	/* In place (two hard links): the content is made first, so a failing
	 * writer does not truncate the file either. */
	snprintf(other, sizeof other, "%s/b.txt", dir);
	assert_int_equal(link(path, other), 0);
	assert_false(file_write_atomic(path, write_half_then_fail, "new content that fails\n", &err));
	assert_string_equal(slurp(other), "old content\n");
	assert_true(file_write_atomic(path, write_text, "both\n", &err));
	assert_string_equal(slurp(other), "both\n");
	char want[256];
	snprintf(want, sizeof want, "%s has 2 hard links: written in place to keep them", path);
	assert_string_equal(file_write_note(), want);
	/* Through a symbolic link the target gets it, the link stays. */
	snprintf(lpath, sizeof lpath, "%s/l.txt", dir);
	assert_int_equal(symlink("b.txt", lpath), 0);
	unlink(path);
	assert_true(file_write_atomic(lpath, write_text, "via link\n", &err));
	struct stat st;
	assert_int_equal(lstat(lpath, &st), 0);
	assert_true(S_ISLNK(st.st_mode));
	assert_string_equal(slurp(other), "via link\n");
}

/* The byte at offset i of the big old file below. */
static unsigned char big_byte(size_t i)
{
	return (unsigned char)(i * 7 % 251);
}

/* Whether the page at off of the file at path is in the page cache: a
 * read that must not wait for the disk (RWF_NOWAIT) fails with EAGAIN
 * when it is not. */
static bool page_cached(const char *path, off_t off)
{
	int fd = open(path, O_RDONLY);
	assert_true(fd >= 0);
	char b[16];
	struct iovec v = {b, sizeof b};
	ssize_t n = preadv2(fd, &v, 1, off, RWF_NOWAIT);
	int e = errno;
	close(fd);
	assert_true(n == (ssize_t)sizeof b || (n < 0 && e == EAGAIN));
	return n == (ssize_t)sizeof b;
}

/* A save over a file of 1 MB or more drops the old file's cached pages
 * while it writes (so that the rename does not free them on the save's
 * tail), and still leaves the old bytes whole when the writer fails. */
static void test_big_old_file_uncached_and_kept(void **state)
{
	(void)state;
	struct statfs fs;
	assert_int_equal(statfs(dir, &fs), 0);
	if (fs.f_type == 0x01021994) /* tmpfs: its pages are the file, never dropped */
		skip();
	char path[128];
	snprintf(path, sizeof path, "%s/big.ppm", dir);
	size_t n = (size_t)2 << 20;
	unsigned char *data = malloc(n);
	assert_non_null(data);
	for (size_t i = 0; i < n; i++)
		data[i] = big_byte(i);
	int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
	assert_true(fd >= 0);
	assert_true(write(fd, data, n) == (ssize_t)n);
	assert_int_equal(fsync(fd), 0); /* clean pages: the ones a drop may drop */
	assert_int_equal(close(fd), 0);
	assert_true(page_cached(path, (off_t)n / 2));
	rt_error err;
	assert_false(file_write_atomic(path, write_half_then_fail, "new content that fails\n", &err));
	assert_false(page_cached(path, (off_t)n / 2));
	FILE *f = fopen(path, "rb");
	assert_non_null(f);
	assert_true(fread(data, 1, n, f) == n);
	assert_int_equal(fgetc(f), EOF);
	fclose(f);
	size_t bad = 0;
	for (size_t i = 0; i < n; i++)
		bad += data[i] != big_byte(i);
	assert_int_equal(bad, 0);
	free(data);
	assert_int_equal(count_prefix(".big.ppm.tmp."), 0);
}

/* The process's descriptors: how many, and how many name a deleted file. */
static int open_fds(int *deleted)
{
	DIR *d = opendir("/proc/self/fd");
	assert_non_null(d);
	int n = 0;
	*deleted = 0;
	struct dirent *e;
	char to[512];
	while ((e = readdir(d))) {
		if (e->d_name[0] == '.')
			continue;
		n++;
		ssize_t k = readlinkat(dirfd(d), e->d_name, to, sizeof to - 1);
		if (k > 0) {
			to[k] = '\0';
			*deleted += strstr(to, " (deleted)") != NULL;
		}
	}
	closedir(d);
	return n;
}

/* The old file of a save over a big file stays open past the rename (so
 * that the rename does not free it; a thread's close does): by the time
 * the save returns it is closed, no descriptor left to it or to anything
 * deleted, and the new content is in place. */
static void test_big_old_file_released(void **state)
{
	(void)state;
	char path[128];
	snprintf(path, sizeof path, "%s/release.ppm", dir);
	size_t n = (size_t)2 << 20;
	char *data = malloc(n + 1);
	assert_non_null(data);
	memset(data, 'o', n);
	data[n] = '\0';
	int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
	assert_true(fd >= 0);
	assert_true(write(fd, data, n) == (ssize_t)n);
	assert_int_equal(close(fd), 0);
	int deleted, before = open_fds(&deleted);
	assert_int_equal(deleted, 0);
	rt_error err;
	assert_true(file_write_atomic(path, write_text, "new\n", &err));
	assert_int_equal(open_fds(&deleted), before);
	assert_int_equal(deleted, 0);
	assert_string_equal(slurp(path), "new\n");
	free(data);
}

static void test_mode_is_kept(void **state)
{
	(void)state;
	char path[128];
	snprintf(path, sizeof path, "%s/m.txt", dir);
	rt_error err;
	assert_true(file_write_atomic(path, write_text, "x\n", &err));
	const mode_t modes[] = {0600, 0640, 0444, 0755};
	for (size_t i = 0; i < sizeof modes / sizeof modes[0]; i++) {
		assert_int_equal(chmod(path, modes[i]), 0);
		assert_true(file_write_atomic(path, write_text, "y\n", &err));
		struct stat st;
		assert_int_equal(stat(path, &st), 0);
		assert_int_equal(st.st_mode & 07777, modes[i]);
	}
}

/* Stale temporary files of the same file are removed (on this thread when
 * the old file is small; beside the write when it is big, by the thread
 * that drops its cache), the others are not; the new content is in place. */
static void test_stale_temporary_files(void **state)
{
	(void)state;
	for (int big = 0; big < 2; big++) {
		char path[128], stale[160], old_style[160], live[160], other[160];
		snprintf(path, sizeof path, "%s/t.txt", dir);
		if (big) { /* a 2 MB old file */
			FILE *f = fopen(path, "w");
			assert_non_null(f);
			for (int i = 0; i < 2 << 20; i++)
				fputc('b', f);
			assert_int_equal(fclose(f), 0);
		}
		/* pid 0x7ffffff0 runs nowhere (above pid_max); our own pid counts as a
		 * process that no longer runs when the file is older than us. */
		snprintf(stale, sizeof stale, "%s/.t.txt.tmp.2147483632.Abc123", dir);
		snprintf(old_style, sizeof old_style, "%s/.t.txt.tmp.Xyz789", dir);
		snprintf(live, sizeof live, "%s/.t.txt.tmp.1.Abc123", dir); /* init runs */
		snprintf(other, sizeof other, "%s/.u.txt.tmp.2147483632.Abc123", dir);
		const char *files[] = {stale, old_style, live, other};
		for (int i = 0; i < 4; i++) {
			FILE *f = fopen(files[i], "w");
			assert_non_null(f);
			fclose(f);
			/* an hour before this process started */
			struct timespec ts[2] = {{time(NULL) - 3600, 0}, {time(NULL) - 3600, 0}};
			assert_int_equal(utimensat(AT_FDCWD, files[i], ts, 0), 0);
		}
		rt_error err;
		assert_true(file_write_atomic(path, write_text, "t\n", &err));
		assert_int_equal(access(stale, F_OK), -1);
		assert_int_equal(access(old_style, F_OK), -1);
		assert_int_equal(access(live, F_OK), 0);  /* its process runs */
		assert_int_equal(access(other, F_OK), 0); /* another file's */
		assert_string_equal(slurp(path), "t\n");
		/* A temporary file newer than this process is not touched. */
		FILE *f = fopen(stale, "w");
		fclose(f);
		assert_true(file_write_atomic(path, write_text, "t\n", &err));
		assert_int_equal(access(stale, F_OK), 0);
		assert_int_equal(unlink(stale), 0);
		assert_int_equal(unlink(live), 0);
		assert_int_equal(unlink(other), 0);
	}
}

/* --- extended attributes and ACLs --- */

/* A POSIX access or default ACL as the kernel stores it in the
 * system.posix_acl_* attributes (include/uapi/linux/posix_acl_xattr.h):
 * a little-endian header (version 2), then entries {tag u16, perm u16,
 * id u32} in tag order. Tags: 1 owner, 2 named user, 4 owning group,
 * 8 named group, 0x10 mask, 0x20 others. */
typedef struct acl_blob {
	unsigned char b[4 + 8 * 8];
	size_t n;
} acl_blob;

static void put_le(unsigned char *p, uint32_t v, int bytes)
{
	for (int i = 0; i < bytes; i++)
		p[i] = (unsigned char)(v >> (8 * i));
}

static void acl_add(acl_blob *a, unsigned tag, unsigned perm, uint32_t id)
{
	if (a->n == 0) {
		put_le(a->b, 2, 4);
		a->n = 4;
	}
	put_le(a->b + a->n, tag, 2);
	put_le(a->b + a->n + 2, perm, 2);
	put_le(a->b + a->n + 4, id, 4);
	a->n += 8;
}

/* owner rw-, user 65534 r--, group r--, mask rw-, others ---: the mode's
 * group bits show the mask, so the file's mode is 0660. */
static acl_blob acl_example(void)
{
	acl_blob a = {.n = 0};
	acl_add(&a, 0x01, 6, UINT32_MAX);
	acl_add(&a, 0x02, 4, 65534);
	acl_add(&a, 0x04, 4, UINT32_MAX);
	acl_add(&a, 0x10, 6, UINT32_MAX);
	acl_add(&a, 0x20, 0, UINT32_MAX);
	return a;
}

/* The value of attribute name of path (malloc'ed, *n its length), or NULL. */
static char *xget(const char *path, const char *name, ssize_t *n)
{
	*n = getxattr(path, name, NULL, 0);
	if (*n < 0)
		return NULL;
	char *v = malloc((size_t)*n + 1);
	assert_non_null(v);
	*n = getxattr(path, name, v, (size_t)*n);
	assert_true(*n >= 0);
	return v;
}

static void expect_xattr(const char *path, const char *name, const void *want, size_t n)
{
	ssize_t got;
	char *v = xget(path, name, &got);
	if (!v)
		fail_msg("%s: %s is gone (%s)", path, name, strerror(errno));
	assert_int_equal(got, (ssize_t)n);
	assert_memory_equal(v, want, n);
	free(v);
}

/* In folder `in`: a file with user attributes (one empty) and an access ACL
 * is replaced atomically (a new inode, no note) and the new file has the
 * same attributes, the same ACL and the mode the ACL gives. False when the
 * file system refuses user attributes or ACLs (the caller says so). */
static bool xattrs_kept_in(const char *in)
{
	char path[256];
	snprintf(path, sizeof path, "%s/x.rt", in);
	rt_error err;
	assert_true(file_write_atomic(path, write_text, "old\n", &err));
	if (setxattr(path, "user.rtsh.colour", "blue", 4, 0) != 0 || setxattr(path, "user.rtsh.empty", "", 0, 0) != 0) {
		print_message("skipped in %s: the file system refuses user extended attributes (%s)\n", in,
		              strerror(errno));
		return false;
	}
	acl_blob acl = acl_example();
	if (setxattr(path, "system.posix_acl_access", acl.b, acl.n, 0) != 0) {
		print_message("skipped in %s: the file system refuses ACLs (%s)\n", in, strerror(errno));
		return false;
	}
	struct stat before, after;
	assert_int_equal(stat(path, &before), 0);
	assert_int_equal(before.st_mode & 07777, 0660); /* what the ACL says */
	assert_true(file_write_atomic(path, write_text, "new\n", &err));
	assert_string_equal(file_write_note(), ""); /* replaced, not in place */
	assert_int_equal(stat(path, &after), 0);
	assert_true(after.st_ino != before.st_ino);
	assert_string_equal(slurp(path), "new\n");
	expect_xattr(path, "user.rtsh.colour", "blue", 4);
	expect_xattr(path, "user.rtsh.empty", "", 0);
	expect_xattr(path, "system.posix_acl_access", acl.b, acl.n);
	assert_int_equal(after.st_mode & 07777, 0660);
	/* Through a symbolic link: the file it points to is replaced and keeps
	 * them; the link stays a link. */
	char lpath[300];
	snprintf(lpath, sizeof lpath, "%s/x-link.rt", in);
	assert_int_equal(symlink("x.rt", lpath), 0);
	assert_true(file_write_atomic(lpath, write_text, "via link\n", &err));
	struct stat lst;
	assert_int_equal(lstat(lpath, &lst), 0);
	assert_true(S_ISLNK(lst.st_mode));
	assert_string_equal(slurp(path), "via link\n");
	expect_xattr(path, "user.rtsh.colour", "blue", 4);
	expect_xattr(path, "system.posix_acl_access", acl.b, acl.n);
	/* An attribute removed from the file is not brought back. */
	assert_int_equal(removexattr(path, "user.rtsh.colour"), 0);
	assert_true(file_write_atomic(path, write_text, "newer\n", &err));
	ssize_t n;
	assert_null(xget(path, "user.rtsh.colour", &n));
	expect_xattr(path, "user.rtsh.empty", "", 0);
	return true;
}

/* In a folder with a default ACL: replacing a file that has no ACL gives no
 * ACL (the temporary file inherited one; it is removed) and keeps the mode;
 * a new file gets what any new file there gets (compared with one made by
 * open(O_CREAT, 0666)). */
static bool default_acl_in(const char *in)
{
	char sub[256], path[300], fresh[300], ref[300];
	snprintf(sub, sizeof sub, "%s/defacl", in);
	assert_int_equal(mkdir(sub, 0755), 0);
	snprintf(path, sizeof path, "%s/old.rt", sub);
	rt_error err;
	assert_true(file_write_atomic(path, write_text, "old\n", &err));
	assert_int_equal(chmod(path, 0604), 0);
	acl_blob def = acl_example();
	if (setxattr(sub, "system.posix_acl_default", def.b, def.n, 0) != 0) {
		print_message("skipped in %s: the file system refuses default ACLs (%s)\n", in, strerror(errno));
		return false;
	}
	assert_true(file_write_atomic(path, write_text, "new\n", &err));
	ssize_t n;
	assert_null(xget(path, "system.posix_acl_access", &n));
	struct stat st, rst;
	assert_int_equal(stat(path, &st), 0);
	assert_int_equal(st.st_mode & 07777, 0604);
	snprintf(fresh, sizeof fresh, "%s/fresh.rt", sub);
	snprintf(ref, sizeof ref, "%s/reference", sub);
	int fd = open(ref, O_WRONLY | O_CREAT | O_EXCL, 0666);
	assert_true(fd >= 0);
	close(fd);
	assert_true(file_write_atomic(fresh, write_text, "fresh\n", &err));
	assert_int_equal(stat(fresh, &st), 0);
	assert_int_equal(stat(ref, &rst), 0);
	assert_int_equal(st.st_mode & 07777, rst.st_mode & 07777);
	ssize_t rn;
	char *want = xget(ref, "system.posix_acl_access", &rn);
	assert_non_null(want); /* inherited from the default ACL */
	expect_xattr(fresh, "system.posix_acl_access", want, (size_t)rn);
	free(want);
	return true;
}

static void test_xattrs_and_acls_are_kept(void **state)
{
	(void)state;
	/* The test folder (under /tmp) and, where there is one, a tmpfs. */
	char shm[] = "/dev/shm/rtsh-test-atomic-XXXXXX";
	const char *folders[] = {dir, mkdtemp(shm)};
	int ran = 0;
	for (int i = 0; i < 2; i++) {
		if (!folders[i])
			continue;
		ran += xattrs_kept_in(folders[i]);
		ran += default_acl_in(folders[i]);
	}
	if (folders[1]) {
		char cmd[128];
		snprintf(cmd, sizeof cmd, "rm -rf %s", shm);
		assert_int_equal(system(cmd), 0);
	}
	if (ran == 0)
		skip();
}

/* mem_alloc_huge's alignment by its definition (memory.h): 64 bytes below
 * 4 MB, 2 MB from 4 MB on; every byte asked for writable (ASan checks the
 * ends); mem_prefault leaves the contents as they were. */
static void test_memory_huge_arrays(void **state)
{
	(void)state;
	static const size_t sizes[] = {0, 1, 63, 65, 4095, ((size_t)4 << 20) - 1, (size_t)4 << 20,
	                               ((size_t)5 << 20) + 3};
	for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
		size_t n = sizes[k];
		unsigned char *p = mem_alloc_huge(n);
		assert_non_null(p);
		uintptr_t align = n >= ((size_t)4 << 20) ? (uintptr_t)2 << 20 : 64;
		assert_int_equal((uintptr_t)p % align, 0);
		for (size_t i = 0; i < n; i += 4093)
			p[i] = (unsigned char)(i * 7 + 1);
		if (n) {
			p[n - 1] = 0xa5;
			mem_prefault(p, n);
			for (size_t i = 0; i + 1 < n; i += 4093)
				assert_int_equal(p[i], (unsigned char)(i * 7 + 1));
			assert_int_equal(p[n - 1], 0xa5);
		}
		free(p);
	}
	/* a calloc'ed array prefaulted is still zero */
	size_t n = (size_t)6 << 20;
	unsigned char *z = calloc(n, 1);
	assert_non_null(z);
	mem_prefault(z, n);
	for (size_t i = 0; i < n; i += 509)
		assert_int_equal(z[i], 0);
	free(z);
}

static void test_memory_check(void **state)
{
	(void)state;
	rt_error err;
	mem_set_limit(1000);
	const char *why;
	assert_true(mem_limit(&why) == 1000.0);
	assert_string_equal(why, "the set limit");
	assert_true(mem_check(1000, "this", &err));
	assert_false(mem_check(1001, "this", &err));
	assert_string_equal(err.msg, "this needs about 1001 bytes of memory; expected at most 1000 bytes (the set limit)");
	assert_false(mem_check(3.5 * 1024 * 1024 * 1024, "that", &err));
	assert_string_equal(err.msg, "that needs about 3.5 GiB of memory; expected at most 1000 bytes (the set limit)");
	mem_set_limit(0);
	/* Without a set limit: at most the physical memory. */
	double phys = (double)sysconf(_SC_PHYS_PAGES) * (double)sysconf(_SC_PAGE_SIZE);
	assert_true(mem_limit(NULL) <= phys);
	assert_false(mem_check(phys * 2, "twice the machine", &err));
}

/* Bytes as the messages give them (memory.h): in the largest unit of 1024
 * that leaves at least 1, one decimal below 10. */
static void human_test(double b, char *buf, size_t size)
{
	const char *units[] = {"bytes", "KiB", "MiB", "GiB"};
	int u = 0;
	for (; b >= 1024 && u < 3; u++)
		b /= 1024;
	snprintf(buf, size, u && b < 10 ? "%.1f %s" : "%.0f %s", b, units[u]);
}

/* The bytes a scene's model takes, from its arrays' capacities and the
 * element sizes. */
static double model_bytes(const scene *s)
{
	return (double)(sizeof(scene) + s->cap_cams * sizeof(camera) + s->cap_lights * sizeof(light) +
	                s->cap_objs * sizeof(object));
}

/* The scenes an editor holds (its current one and those its undo and redo
 * history keep after load/generate) are counted by the memory estimates: a
 * request that fits alone is refused when it does not fit with them. */
static void test_memory_counts_the_undo_scenes(void **state)
{
	(void)state;
	rt_error err;
	long n;
	assert_true(mem_held(&n) == 0.0);
	assert_int_equal(n, 0);
	scene *a = scene_generate(1000, 1, NULL, &err);
	assert_non_null(a);
	assert_int_equal(a->cap_objs, 1001); /* 1000 and the ground plane, allocated at once */
	double wa = model_bytes(a);
	editor *ed = editor_new(a, "a");
	assert_non_null(ed);
	assert_true(mem_held(&n) == wa);
	assert_int_equal(n, 1);
	/* Three more scenes replace it in turn; each old one is kept for undo. */
	double want = wa;
	const size_t sizes[] = {2000, 3000, 4000};
	for (int i = 0; i < 3; i++) {
		scene *s = scene_generate(sizes[i], 2, NULL, &err);
		assert_non_null(s);
		want += model_bytes(s);
		assert_true(editor_replace(ed, s, NULL, &err));
		assert_true(mem_held(&n) == want);
		assert_int_equal(n, i + 2);
	}
	/* Undo and redo move scenes between the stacks: the same are held. */
	assert_true(editor_undo(ed, &err));
	assert_true(editor_undo(ed, &err));
	assert_true(mem_held(&n) == want);
	assert_int_equal(n, 4);
	/* A new edit drops the redo history (2 scenes of 3000 and 4000). */
	double w3 = 0, w4 = 0;
	{
		scene *s3 = scene_generate(3000, 2, NULL, &err), *s4 = scene_generate(4000, 2, NULL, &err);
		w3 = model_bytes(s3);
		w4 = model_bytes(s4);
		scene_free(s3);
		scene_free(s4);
	}
	assert_true(editor_object_move(ed, 0, v3(1, 0, 0), &err));
	want -= w3 + w4;
	assert_true(mem_held(&n) == want);
	assert_int_equal(n, 2);

	/* A request of 100 objects: about 101 x MEM_PER_OBJECT alone. With a
	 * limit between that alone and that on top of what is held, it is
	 * refused, saying what is held; alone (no editor) it fits. */
	double alone = 101 * MEM_PER_OBJECT;
	assert_true(want > 1000); /* a clear gap */
	mem_set_limit((size_t)(alone + want / 2));
	assert_null(scene_generate(100, 3, NULL, &err));
	char expect[512], need[32], held[32], limit[32];
	human_test(alone, need, sizeof need);
	human_test(want, held, sizeof held);
	human_test((double)(size_t)(alone + want / 2), limit, sizeof limit);
	snprintf(expect, sizeof expect,
	         "generating 100 objects needs about %s of memory on top of the %s held by 2 scenes (the current "
	         "one and those kept for undo); expected at most %s in all (the set limit)",
	         need, held, limit);
	assert_string_equal(err.msg, expect);
	/* A request too big on its own is refused as such. */
	double lim2 = (double)(size_t)(alone + want / 2);
	assert_false(mem_check(lim2 + 1, "this", &err));
	human_test(lim2 + 1, need, sizeof need);
	snprintf(expect, sizeof expect, "this needs about %s of memory; expected at most %s (the set limit)", need,
	         limit);
	assert_string_equal(err.msg, expect);
	mem_set_limit((size_t)(alone + want)); /* exactly fits */
	scene *fits = scene_generate(100, 3, NULL, &err);
	assert_non_null(fits);
	scene_free(fits);
	mem_set_limit((size_t)(alone + want / 2));
	editor_free(ed);
	assert_true(mem_held(&n) == 0.0);
	assert_int_equal(n, 0);
	fits = scene_generate(100, 3, NULL, &err);
	assert_non_null(fits);
	scene_free(fits);
	mem_set_limit(0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_failing_writer_keeps_the_old_file),
		cmocka_unit_test(test_big_old_file_uncached_and_kept),
		cmocka_unit_test(test_big_old_file_released),
		cmocka_unit_test(test_mode_is_kept),
		cmocka_unit_test(test_stale_temporary_files),
		cmocka_unit_test(test_xattrs_and_acls_are_kept),
		cmocka_unit_test(test_memory_huge_arrays),
		cmocka_unit_test(test_memory_check),
		cmocka_unit_test(test_memory_counts_the_undo_scenes),
	};
	return cmocka_run_group_tests(tests, setup, teardown);
}
