/* rtsh — tests of the pager's row count: long lines wrap at the width,
 * escape sequences take no room, a code point takes one column. */
#include "testutil.h"

#include <fcntl.h>
#include <string.h>
#include <unistd.h>

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

/* The pager on keys from a pipe (written before it reads), its screen to
 * /dev/null: returns whether it left; *next the first key byte left for
 * the command line (-1: none). */
static bool page_keys(const char *text, int rows, const char *keys, size_t *at, int *next)
{
	int p[2];
	assert_int_equal(pipe(p), 0);
	assert_int_equal(write(p[1], keys, strlen(keys)), (ssize_t)strlen(keys));
	close(p[1]);
	int out = open("/dev/null", O_WRONLY);
	assert_true(out >= 0);
	evloop *l = evloop_new(p[0], -1);
	assert_non_null(l);
	bool left = pager_show(l, out, text, strlen(text), 40, rows, at);
	*next = evloop_getc(l);
	evloop_free(l);
	close(out);
	close(p[0]);
	return left;
}

/* Typing while the pager shows `help set` (issue: a command typed before q
 * lost its first letters): a key that is not the pager's leaves it and
 * starts the command line, whole. */
static void test_typing_leaves(void **state)
{
	(void)state;
	const char *shortt = "one\ntwo\nthree\n"; /* 3 rows: fits a page of 9 */
	size_t at = 0;
	int next;
	/* "set" typed: 's' is not a pager key, the pager leaves, s comes next */
	assert_true(page_keys(shortt, 10, "set", &at, &next));
	assert_int_equal(next, 's');
	/* fitting text: the moving letters are typed text too ("keys") */
	at = 0;
	assert_true(page_keys(shortt, 10, "keys", &at, &next));
	assert_int_equal(next, 'k');
	/* q leaves and is the pager's: the next key is what follows it */
	at = 0;
	assert_true(page_keys(shortt, 10, "qab", &at, &next));
	assert_int_equal(next, 'a');
	/* Enter leaves a text that fits, taken by the pager */
	at = 0;
	assert_true(page_keys(shortt, 10, "\rz", &at, &next));
	assert_int_equal(next, 'z');
	/* 30 rows, a page of 9: j moves a line on (twice: row 3, "r2\n" begins
	 * at 2 x 3 bytes), then 'e' leaves and is kept */
	char longt[128] = "";
	for (int i = 0; i < 30; i++) {
		char r[16];
		snprintf(r, sizeof r, "r%d\n", i);
		strcat(longt, r);
	}
	at = 0;
	assert_true(page_keys(longt, 10, "jje", &at, &next));
	assert_int_equal(at, 6);
	assert_int_equal(next, 'e');
	/* a UTF-8 letter is typed text, all its bytes kept */
	at = 0;
	assert_true(page_keys(longt, 10, "\xc3\xa9", &at, &next));
	assert_int_equal(next, 0xc3);
	/* the input ends in the pager: it leaves, nothing is left */
	at = 0;
	assert_true(page_keys(longt, 10, "j", &at, &next));
	assert_int_equal(next, -1);
	assert_int_equal(at, 3);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_rows),
		cmocka_unit_test(test_word_wrap),
		cmocka_unit_test(test_hanging_indent),
		cmocka_unit_test(test_typing_leaves),
	};
	return cmocka_run_group_tests_name("pager", tests, NULL, NULL);
}
