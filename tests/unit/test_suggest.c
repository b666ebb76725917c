/* rtsh — tests of "did you mean …?" (shell/suggest.h): the distance against
 * values worked out by hand, and the suggestions the shell makes. */
#include "testutil.h"

#include "shell/commands.h"
#include "shell/suggest.h"

static void test_distance(void **state)
{
	(void)state;
	/* kitten -> sitten (k/s) -> sittin (e/i) -> sitting (+g): 3. */
	assert_int_equal(suggest_distance("kitten", "sitting"), 3);
	assert_int_equal(suggest_distance("", "abc"), 3);
	assert_int_equal(suggest_distance("abc", ""), 3);
	assert_int_equal(suggest_distance("load", "load"), 0);
	/* Case is ignored. */
	assert_int_equal(suggest_distance("LoAd", "load"), 0);
	/* One swap of neighbours is one edit... */
	assert_int_equal(suggest_distance("smaples", "samples"), 1);
	assert_int_equal(suggest_distance("ca", "ac"), 1);
	/* ...but a swapped pair is not edited again (optimal string alignment:
	 * ca -> ac -> abc would be 2 only with unrestricted Damerau). */
	assert_int_equal(suggest_distance("ca", "abc"), 3);
	/* One deletion, one insertion, one substitution. */
	assert_int_equal(suggest_distance("lod", "load"), 1);
	assert_int_equal(suggest_distance("loaad", "load"), 1);
	assert_int_equal(suggest_distance("loed", "load"), 1);
	/* Symmetric. */
	assert_int_equal(suggest_distance("sitting", "kitten"), 3);
}

static void test_closest(void **state)
{
	(void)state;
	const char *const names[] = {"load", "save", "render", "set"};
	assert_string_equal(suggest_closest("lod", names, 4), "load");
	assert_string_equal(suggest_closest("rendr", names, 4), "render");
	/* Two edits are too many for a word of up to 5 bytes, fine for longer. */
	assert_null(suggest_closest("lxx", names, 4));
	assert_null(suggest_closest("rnedr", names, 4));
	assert_string_equal(suggest_closest("rendeerr", names, 4), "render");
	/* Nothing close: no guess. A one-byte word is never "corrected". */
	assert_null(suggest_closest("frobnicate", names, 4));
	assert_null(suggest_closest("x", names, 4));
	assert_null(suggest_closest("", names, 4));
	/* "sat" -> "set" is 1 edit, "sat" -> "save" 2. */
	assert_string_equal(suggest_closest("sat", names, 4), "set");
	/* A tie goes to the first candidate. */
	const char *const tie[] = {"cat", "bat"};
	assert_string_equal(suggest_closest("at", tie, 2), "cat");
}

static void test_choices_and_tables(void **state)
{
	(void)state;
	char buf[64];
	assert_true(suggest_choice("pos|dir|lookat|fov|move|turn", "lokat", buf, sizeof buf));
	assert_string_equal(buf, "lookat");
	assert_true(suggest_choice("whitted|path", "pth", buf, sizeof buf));
	assert_string_equal(buf, "path");
	assert_true(suggest_choice("cameras|lights|objects", "lihgts", buf, sizeof buf));
	assert_string_equal(buf, "lights");
	assert_false(suggest_choice("whitted|path", "zzzz", buf, sizeof buf));
	assert_true(suggest_command("lod", buf, sizeof buf));
	assert_string_equal(buf, "load");
	/* Aliases count: "exti" is one swap from the alias "exit". */
	assert_true(suggest_command("exti", buf, sizeof buf));
	assert_string_equal(buf, "exit");
	assert_false(suggest_command("frobnicate", buf, sizeof buf));
	assert_string_equal(suggest_setting("smaples"), "samples");
	assert_string_equal(suggest_setting("dpeth"), "depth");
	assert_null(suggest_setting("colour"));
	/* The lookup's message carries the suggestion. */
	char msg[256];
	assert_null(command_find("lod", msg, sizeof msg));
	assert_string_equal(msg, "unknown command \"lod\"; did you mean \"load\"?");
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_distance),
		cmocka_unit_test(test_closest),
		cmocka_unit_test(test_choices_and_tables),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
