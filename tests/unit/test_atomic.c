/* rtsh — tests of file_write_atomic (what a failing writer leaves, the
 * temporary files, links, modes, notes) and of the memory estimates. */
#include "testutil.h"

#include <dirent.h>
#include <fcntl.h>
#include <time.h>
#include <sys/stat.h>
#include <unistd.h>

#include "rtsh/atomic.h"
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

static void test_stale_temporary_files(void **state)
{
	(void)state;
	char path[128], stale[160], old_style[160], live[160], other[160];
	snprintf(path, sizeof path, "%s/t.txt", dir);
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
	/* A temporary file newer than this process is not touched. */
	FILE *f = fopen(stale, "w");
	fclose(f);
	assert_true(file_write_atomic(path, write_text, "t\n", &err));
	assert_int_equal(access(stale, F_OK), 0);
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

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_failing_writer_keeps_the_old_file),
		cmocka_unit_test(test_mode_is_kept),
		cmocka_unit_test(test_stale_temporary_files),
		cmocka_unit_test(test_memory_check),
	};
	return cmocka_run_group_tests(tests, setup, teardown);
}
