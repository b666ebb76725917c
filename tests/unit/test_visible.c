/* rtsh — tests of text_visible (base/visible.h): control characters of
 * file names and file strings shown, never sent to the terminal raw. */
#include "testutil.h"

#include "base/visible.h"
#include "rtsh/error.h"

/* No byte a terminal acts on: C0 (but \n and \t with lines), DEL, C1. */
static void assert_no_controls(const char *s, bool lines)
{
	for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
		if (*p < 0x20 && !(lines && (*p == '\n' || *p == '\t')))
			fail_msg("control byte 0x%02X in \"%s\"", *p, s);
		if (*p == 0x7f || (p[0] == 0xc2 && p[1] >= 0x80 && p[1] <= 0x9f))
			fail_msg("DEL or C1 control in \"%s\"", s);
	}
}

static void test_visible_as_cat_v(void **state)
{
	(void)state;
	char out[256];
	/* the expected strings written by hand from cat -v's notation */
	static const struct {
		const char *in, *one_line, *lines;
	} cases[] = {
		{"plain.rt", "plain.rt", "plain.rt"},
		{"\033[31mred\033[0m\a.rt", "^[[31mred^[[0m^G.rt", "^[[31mred^[[0m^G.rt"},
		{"\033]52;c;eA==\a", "^[]52;c;eA==^G", "^[]52;c;eA==^G"},
		{"a\nb\tc\rd", "a^Jb^Ic^Md", "a\nb\tc^Md"},
		{"\x01\x1f\x7f", "^A^_^?", "^A^_^?"},
		{"\xc2\x9b" "31m \xc2\x80", "M-^[31m M-^@", "M-^[31m M-^@"},
		/* not controls: Latin-1 letters, box drawing, an emoji */
		{"caf\xc3\xa9 \xc2\xa0\xe2\x94\x82\xf0\x9f\x99\x82", "caf\xc3\xa9 \xc2\xa0\xe2\x94\x82\xf0\x9f\x99\x82",
		 "caf\xc3\xa9 \xc2\xa0\xe2\x94\x82\xf0\x9f\x99\x82"},
	};
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		assert_string_equal(text_visible(out, sizeof out, cases[i].in, false), cases[i].one_line);
		assert_no_controls(out, false);
		assert_int_equal(text_has_controls(cases[i].in, false), strcmp(cases[i].in, cases[i].one_line) != 0);
		assert_string_equal(text_visible(out, sizeof out, cases[i].in, true), cases[i].lines);
		assert_no_controls(out, true);
	}
}

/* A short buffer: terminated, cut before a whole ^X or character. */
static void test_visible_cut(void **state)
{
	(void)state;
	char out[5];
	assert_string_equal(text_visible(out, sizeof out, "ab\033c", false), "ab^[");
	assert_string_equal(text_visible(out, sizeof out, "abc\033", false), "abc");
	assert_string_equal(text_visible(out, sizeof out, "ab\xe2\x94\x82", false), "ab");
	assert_string_equal(text_visible(out, 1, "abc", false), "");
}

/* Errors (what loaders fill, what every front end prints): the file name
 * and the message both made visible. */
static void test_errors_visible(void **state)
{
	(void)state;
	rt_error err;
	rt_error_at(&err, "\033[2Jx.rt", 3, 4, "image \"%s\" cannot be read", "\033]0;t\a.png");
	char buf[RT_ERROR_MSG_MAX + RT_ERROR_FILE_MAX + 32];
	rt_error_format(&err, buf, sizeof buf);
	assert_string_equal(buf, "^[[2Jx.rt:3:4: image \"^[]0;t^G.png\" cannot be read");
	rt_error_set(&err, "%s: no", "\x9b\xc2\x9b");
	assert_string_equal(err.msg, "\x9b" "M-^[: no");
	/* a long name keeps its end, whole characters */
	char longname[600];
	memset(longname, 'a', sizeof longname);
	memcpy(longname + sizeof longname - 8, "\033end.rt", 8);
	rt_error_at(&err, longname, 1, 0, "x");
	size_t n = strlen(err.file);
	assert_true(n < RT_ERROR_FILE_MAX);
	assert_string_equal(err.file + n - 8, "^[end.rt");
	assert_memory_equal(err.file, "...a", 4);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_visible_as_cat_v),
		cmocka_unit_test(test_visible_cut),
		cmocka_unit_test(test_errors_visible),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
