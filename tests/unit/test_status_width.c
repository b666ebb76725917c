/* rtsh — the status line's width with non-ASCII scene names (issue 16, 7):
 * a CJK name or an emoji takes two columns each, so the line is cut and
 * padded by wcwidth, never by bytes or code points; checked against the
 * widths by definition (Unicode East Asian Width: 場 and 🌈 are wide). */
#define _XOPEN_SOURCE 700
#include "testutil.h"

#include <locale.h>
#include <wchar.h>

#include "base/abuf.h"
#include "term/screen.h"

/* The columns the text takes, by wcwidth, and whether it is valid UTF-8. */
static int columns(const char *s, size_t len)
{
	int w = 0;
	mbstate_t st;
	memset(&st, 0, sizeof st);
	while (len > 0) {
		wchar_t wc;
		size_t n = mbrtowc(&wc, s, len, &st);
		if (n == (size_t)-1 || n == (size_t)-2 || n == 0)
			fail_msg("the output is cut inside a character");
		w += wcwidth(wc);
		s += n;
		len -= n;
	}
	return w;
}

static void test_wide_names(void **state)
{
	(void)state;
	if (!setlocale(LC_CTYPE, "C.UTF-8") && !setlocale(LC_CTYPE, "en_US.UTF-8"))
		skip();
	static const char *const names[] = {"\xe5\xa0\xb4\xe6\x99\xaf.rt  path 16 spp", /* 場景.rt */
	                                    "rainbow \xf0\x9f\x8c\x88.rt  whitted",      /* 🌈 */
	                                    "plain.rt  whitted", "caf\x65\xcc\x81.rt"}; /* e + combining acute */
	for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
		for (int cols = 1; cols <= 40; cols++) {
			abuf a;
			abuf_init(&a);
			screen_fit_text(&a, names[i], cols);
			int got = columns(a.b, a.len);
			if (got != cols)
				fail_msg("\"%s\" in %d columns takes %d", names[i], cols, got);
			abuf_free(&a);
		}
	/* by hand: 場景 is 4 columns, so in 6 columns "場景.r" */
	abuf a;
	abuf_init(&a);
	screen_fit_text(&a, names[0], 6);
	assert_int_equal(a.len, 8);
	assert_memory_equal(a.b, "\xe5\xa0\xb4\xe6\x99\xaf.r", 8);
	abuf_free(&a);
	/* and a wide character that does not fit is left out, not split */
	abuf_init(&a);
	screen_fit_text(&a, names[0], 3);
	assert_int_equal(a.len, 4);
	assert_memory_equal(a.b, "\xe5\xa0\xb4 ", 4);
	abuf_free(&a);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_wide_names),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
