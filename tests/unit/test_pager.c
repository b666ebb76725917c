/* rtsh — tests of the pager's row count: long lines wrap at the width,
 * escape sequences take no room, a code point takes one column. */
#include "testutil.h"

#include <string.h>

#include "term/pager.h"

static int rows(const char *s, int cols)
{
	return pager_rows(s, strlen(s), cols);
}

static void test_rows(void **state)
{
	(void)state;
	assert_int_equal(rows("", 80), 0);
	assert_int_equal(rows("abc\ndef\n", 80), 2);
	assert_int_equal(rows("abc\ndef", 80), 2);   /* no final newline */
	assert_int_equal(rows("\n\n\n", 80), 3);     /* three empty lines */
	char line[201];
	memset(line, 'x', 200);
	line[200] = '\0';
	assert_int_equal(rows(line, 80), 3);         /* 80 + 80 + 40 */
	line[160] = '\0';
	assert_int_equal(rows(line, 80), 2);         /* exactly two rows */
	/* colour codes around 80 characters: one row */
	char coloured[128] = "\x1b[38;2;1;2;3m";
	memset(coloured + strlen(coloured), 'y', 80);
	coloured[13 + 80] = '\0';
	strcat(coloured, "\x1b[m");
	assert_int_equal(rows(coloured, 80), 1);
	/* 80 half blocks (3 bytes each) fill one row of 80 columns */
	char blocks[3 * 81 + 1] = "";
	for (int i = 0; i < 81; i++)
		strcat(blocks, "\xe2\x96\x80");
	assert_int_equal(rows(blocks, 80), 2);
	blocks[3 * 80] = '\0';
	assert_int_equal(rows(blocks, 80), 1);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_rows),
	};
	return cmocka_run_group_tests_name("pager", tests, NULL, NULL);
}
