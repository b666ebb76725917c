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

/* Long lines wrap at word boundaries (issue 31, friction 3): "the picture"
 * never becomes "the pic" / "ture"; a word wider than the row is cut. */
static void test_word_wrap(void **state)
{
	(void)state;
	const char *t = "samples accumulate while you watch the picture refine";
	size_t off[8], n[8];
	/* 20 columns: "samples accumulate " is 19 + ... by hand: */
	int r = pager_split(t, strlen(t), 20, off, n, 8);
	assert_int_equal(r, 3);
	assert_int_equal(n[0], strlen("samples accumulate"));
	assert_memory_equal(t + off[1], "while you watch the", n[1]);
	assert_int_equal(n[1], strlen("while you watch the"));
	assert_memory_equal(t + off[2], "picture refine", n[2]);
	assert_int_equal(n[2], strlen("picture refine"));
	/* A word longer than the row: cut at the width. */
	const char *w = "abcdefghijklmnop qr";
	r = pager_split(w, strlen(w), 8, off, n, 8);
	assert_int_equal(r, 3);
	assert_int_equal(n[0], 8);
	assert_memory_equal(w + off[1], "ijklmnop", n[1]);
	assert_memory_equal(w + off[2], "qr", 2);
	/* A row that ends exactly at a blank: no empty row after it. */
	assert_int_equal(rows("aaaa bbbb", 4), 2);
}

/* A wrapped table line goes on under its last column (issue 31, defect 10:
 * `help set` continuation lines started at column 0), prose under its own
 * indent; by hand at 40 columns: "random" starts at column 18, and the
 * line is 44 wide. */
static void test_hanging_indent(void **state)
{
	(void)state;
	const char *t = "  seed    N       random seed of the sampler\n  an indented line of prose that wraps here\n";
	size_t len;
	char *w = pager_wrap(t, strlen(t), 40, &len);
	assert_non_null(w);
	assert_string_equal(w, "  seed    N       random seed of the\n"
	                       "                  sampler\n"
	                       "  an indented line of prose that wraps\n"
	                       "  here\n");
	assert_int_equal(len, strlen(w));
	free(w);
	/* too little room left for a hanging indent (fewer than 20 columns) */
	w = pager_wrap(t, strlen(t), 30, &len);
	assert_non_null(w);
	assert_string_equal(w, "  seed    N       random seed\nof the sampler\n"
	                       "  an indented line of prose\n  that wraps here\n");
	free(w);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_rows),
		cmocka_unit_test(test_word_wrap),
		cmocka_unit_test(test_hanging_indent),
	};
	return cmocka_run_group_tests_name("pager", tests, NULL, NULL);
}
