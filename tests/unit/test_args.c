/* rtsh tests — the command line (shell/args.h): GNU getopt_long forms,
 * one long option per setting of the table, usage errors with status 2. */
#include "testutil.h"

#include "rtsh/settings.h"
#include "shell/args.h"

#define MAXARGS 16

/* Parses the words of a space-separated line (no quoting needed here). */
static int parse(args_kind kind, const char *line, rtsh_options *o)
{
	static char buf[512];
	static char *argv[MAXARGS + 1];
	snprintf(buf, sizeof buf, "rtsh %s", line);
	int argc = 0;
	for (char *t = strtok(buf, " "); t && argc < MAXARGS; t = strtok(NULL, " "))
		argv[argc++] = t;
	argv[argc] = NULL;
	return args_parse(argc, argv, kind, "rtsh", o);
}

/* The value the command line gives for a setting, or NULL. */
static const char *value_of(const rtsh_options *o, const char *name)
{
	for (int i = 0; i < o->nsettings; i++)
		if (strcmp(o->settings[i].def->name, name) == 0)
			return o->settings[i].value;
	return NULL;
}

static void test_value_forms(void **state)
{
	(void)state;
	const char *forms[] = {"-s4", "-s 4", "--samples=4", "--samples 4", "--samp=4"};
	for (size_t i = 0; i < sizeof forms / sizeof forms[0]; i++) {
		rtsh_options o;
		assert_int_equal(parse(ARGS_RTSH, forms[i], &o), -1);
		assert_non_null(value_of(&o, "samples"));
		assert_string_equal(value_of(&o, "samples"), "4");
		assert_int_equal(o.nsettings, 1);
		assert_null(o.scene);
	}
}

static void test_bundles_and_order(void **state)
{
	(void)state;
	rtsh_options o;
	assert_int_equal(parse(ARGS_RTSH, "-qs4 --mode=path scenes/cornell.rt -o x.png", &o), -1);
	assert_true(o.quiet);
	assert_string_equal(value_of(&o, "samples"), "4");
	assert_string_equal(value_of(&o, "mode"), "path");
	assert_string_equal(o.scene, "scenes/cornell.rt");
	assert_string_equal(o.output, "x.png");

	assert_int_equal(parse(ARGS_RTSH, "-qi -c list a.rt", &o), -1);
	assert_true(o.quiet && o.interactive);
	assert_string_equal(o.commands, "list");
	assert_string_equal(o.scene, "a.rt");

	/* Options after the scene; after "--" a word that looks like an option
	 * is the scene. */
	assert_int_equal(parse(ARGS_RTSH, "a.rt -d 3 --strict", &o), -1);
	assert_string_equal(o.scene, "a.rt");
	assert_string_equal(value_of(&o, "depth"), "3");
	assert_true(o.strict);
	assert_int_equal(parse(ARGS_RTSH, "-t 2 -- -odd.rt", &o), -1);
	assert_string_equal(o.scene, "-odd.rt");
	assert_null(o.output);

	/* The same setting twice: the last one wins, kept once. */
	assert_int_equal(parse(ARGS_RTSH, "-s 2 --samples=9", &o), -1);
	assert_int_equal(o.nsettings, 1);
	assert_string_equal(value_of(&o, "samples"), "9");

	assert_int_equal(parse(ARGS_RTSH, "--color=256", &o), -1);
	assert_int_equal(o.color, COLOR_256);
	assert_int_equal(parse(ARGS_RTSH, "--color truecolor", &o), -1);
	assert_int_equal(o.color, COLOR_TRUECOLOR);
}

/* Every entry of the settings table is a long option taking what `set`
 * takes: its default value, written by settings_format, reads back. */
static void test_every_setting(void **state)
{
	(void)state;
	render_settings def = render_settings_default();
	for (size_t i = 0; i < settings_count; i++) {
		char value[64], line[128];
		settings_format(&def, &settings_table[i], value, sizeof value);
		snprintf(line, sizeof line, "--%s=%s", settings_table[i].name, value);
		rtsh_options o;
		assert_int_equal(parse(ARGS_RTSH, line, &o), -1);
		assert_int_equal(o.nsettings, 1);
		assert_ptr_equal(o.settings[0].def, &settings_table[i]);
		assert_string_equal(o.settings[0].value, value);
		render_settings s = render_settings_default();
		s.samples = 77; /* something the option must not disturb unless it sets it */
		options_apply_settings(&o, &s);
		char back[64];
		settings_format(&s, &settings_table[i], back, sizeof back);
		assert_string_equal(back, value);
	}
	/* exposure by hand: --exposure=1.5 is set exposure 1.5 */
	rtsh_options o;
	assert_int_equal(parse(ARGS_RTSH, "--exposure=1.5", &o), -1);
	render_settings s = render_settings_default();
	options_apply_settings(&o, &s);
	assert_near(s.exposure, 1.5, 0);
}

static void test_usage_errors(void **state)
{
	(void)state;
	rtsh_options o;
	const char *bad[] = {
		"-s",              /* no value */
		"--samples",       /* no value */
		"-x",              /* unknown */
		"--nope=1",        /* unknown */
		"--s 4",           /* ambiguous: samples, seed, strict */
		"-s 0",            /* out of range */
		"--depth=deep",    /* not a number */
		"--color=pink",    /* not a colour mode */
		"a.rt b.rt",       /* two scenes */
		"a.rt -o x.png -c list",
		"-i",              /* -i without -c or -f */
		"-c list -f x",
		"-c list -c help",  /* the first -c was dropped without a word */
		"-f a -f b",
		"a.rt -o x.png -o y.png",
		"a.rt --output=x.png -o y.png",
	};
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
		if (parse(ARGS_RTSH, bad[i], &o) != 2)
			fail_msg("\"%s\" was not a usage error", bad[i]);
	}
	/* The batch form for other programs: no shell options, and a scene and
	 * an output are needed. */
	assert_int_equal(parse(ARGS_BATCH, "a.rt -o x.png -s4 -m path", &o), -1);
	assert_string_equal(value_of(&o, "mode"), "path");
	assert_int_equal(parse(ARGS_BATCH, "a.rt -o x.png -c list", &o), 2);
	assert_int_equal(parse(ARGS_BATCH, "a.rt", &o), 2);
	assert_int_equal(parse(ARGS_BATCH, "-o x.png", &o), 2);
	assert_int_equal(parse(ARGS_BATCH, "a.rt -o x.png -o y.png", &o), 2);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_value_forms),
		cmocka_unit_test(test_bundles_and_order),
		cmocka_unit_test(test_every_setting),
		cmocka_unit_test(test_usage_errors),
	};
	return cmocka_run_group_tests_name("args", tests, NULL, NULL);
}
