/* rtsh — a temporary folder for a group of cmocka tests: tmpdir_setup and
 * tmpdir_teardown as the group's set-up and tear-down, and files written
 * into the folder by name. */
#ifndef RTSH_TEST_TMPDIR_H
#define RTSH_TEST_TMPDIR_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "testutil.h"

/* The group's folder, made by tmpdir_setup. */
static char tmpdir[64];

static inline int tmpdir_setup(void **state)
{
	(void)state;
	snprintf(tmpdir, sizeof tmpdir, "/tmp/rtsh-test-XXXXXX");
	return mkdtemp(tmpdir) ? 0 : -1;
}

/* Removes the folder and everything the tests left in it. */
static inline int tmpdir_teardown(void **state)
{
	(void)state;
	char cmd[128];
	snprintf(cmd, sizeof cmd, "rm -rf %s", tmpdir);
	return system(cmd) == 0 ? 0 : -1;
}

/* Writes len bytes to the file NAME in the folder; returns its path, which
 * stays valid for the next 7 calls. */
static inline const char *tmp_write(const char *name, const void *data, size_t len)
{
	static char path[8][256];
	static int k;
	char *p = path[k++ % 8];
	snprintf(p, 256, "%s/%s", tmpdir, name);
	FILE *f = fopen(p, "wb");
	assert_non_null(f);
	assert_int_equal(fwrite(data, 1, len, f), len);
	assert_int_equal(fclose(f), 0);
	return p;
}

static inline const char *tmp_text(const char *name, const char *text)
{
	return tmp_write(name, text, strlen(text));
}

#endif
