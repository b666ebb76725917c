/* rtsh — tests of the shell's command table (lookup, prefixes, ambiguity,
 * usage errors), word splitting and argument parsing, tab completion and
 * the history file. */
#include "testutil.h"

#include <sys/stat.h>
#include <unistd.h>

#include <readline/history.h>

#include "shell/commands.h"
#include "shell/complete.h"
#include "shell/history.h"
#include "shell/shell.h"

static void test_lookup_and_prefixes(void **state)
{
	(void)state;
	char msg[256];
	assert_string_equal(command_find("object", msg, sizeof msg)->name, "object");
	assert_string_equal(command_find("obj", msg, sizeof msg)->name, "object");
	assert_string_equal(command_find("o", msg, sizeof msg)->name, "object");
	assert_string_equal(command_find("exit", msg, sizeof msg)->name, "quit");
	assert_string_equal(command_find("und", msg, sizeof msg)->name, "undo");
	assert_string_equal(command_find("gen", msg, sizeof msg)->name, "generate");
	/* An exact name wins over longer names it is a prefix of. */
	assert_string_equal(command_find("set", msg, sizeof msg)->name, "set");
	assert_null(command_find("s", msg, sizeof msg));
	assert_string_equal(msg, "ambiguous command \"s\"; could be save, set, show or source");
	assert_null(command_find("re", msg, sizeof msg));
	assert_string_equal(msg, "ambiguous command \"re\"; could be render or redo");
	assert_null(command_find("frobnicate", msg, sizeof msg));
	assert_string_equal(msg, "unknown command \"frobnicate\"; type help for the list of commands");
	/* Every name and alias finds its own entry. */
	for (size_t i = 0; i < command_count; i++) {
		assert_ptr_equal(command_find(command_table[i].name, msg, sizeof msg), &command_table[i]);
		assert_non_null(command_table[i].run);
		assert_non_null(command_table[i].help);
		assert_true(strncmp(command_table[i].usage, command_table[i].name, strlen(command_table[i].name)) == 0);
	}
}

static void test_choices(void **state)
{
	(void)state;
	assert_int_equal(choice_pick("move|rotate|scale|color", "rot"), 1);
	assert_int_equal(choice_pick("move|rotate|scale|color", "color"), 3);
	assert_int_equal(choice_pick("pos|dir|lookat|fov|move|turn", "m"), 4);
	assert_int_equal(choice_pick("brightness|color", "x"), -1);
	assert_int_equal(choice_pick("cameras|lights|objects|c", "c"), 3);
	char buf[128];
	choice_list("move|rotate|scale|color", buf, sizeof buf);
	assert_string_equal(buf, "move, rotate, scale or color");
}

static void test_split_words(void **state)
{
	(void)state;
	char *argv[8], buf[128], msg[128];
	size_t rest;
	const char *s = "  save \"my file.png\"  'a b' c\\ d ";
	int n = split_words(s, argv, 8, buf, &rest, msg, sizeof msg);
	assert_int_equal(n, 4);
	assert_string_equal(argv[0], "save");
	assert_string_equal(argv[1], "my file.png");
	assert_string_equal(argv[2], "a b");
	assert_string_equal(argv[3], "c d");
	assert_string_equal(s + rest, "\"my file.png\"  'a b' c\\ d ");
	assert_int_equal(split_words("load 'x", argv, 8, buf, &rest, msg, sizeof msg), -1);
	assert_string_equal(msg, "unclosed ' quote; expected a closing '");
}

static void test_numbers(void **state)
{
	(void)state;
	double v;
	assert_true(parse_number("1.5", &v) && v == 1.5);
	assert_true(parse_number("-2e3", &v) && v == -2000);
	assert_true(parse_number(".5", &v) && v == 0.5);
	assert_false(parse_number("inf", &v));
	assert_false(parse_number("nan", &v));
	assert_false(parse_number("0x10", &v));
	assert_false(parse_number("1,2", &v));
	assert_false(parse_number("", &v));
	assert_false(parse_number("1e", &v));
	assert_false(parse_number("1e400", &v));
}

static shell *new_shell(rtsh_options *o)
{
	memset(o, 0, sizeof *o);
	o->quiet = true;
	shell *sh = malloc(sizeof *sh);
	assert_true(shell_init(sh, o, -1));
	command_table_install(sh);
	return sh;
}

static void free_shell(shell *sh)
{
	shell_free(sh);
	free(sh);
}

static void test_arguments_and_messages(void **state)
{
	(void)state;
	rtsh_options o;
	shell *sh = new_shell(&o);
	size_t nobj = editor_scene(sh->ed)->nobjs;
	char want[256];
	assert_false(command_run(sh, "object 99 move 1,0,0"));
	snprintf(want, sizeof want, "object: \"99\" is not an object number; expected 1..%zu", nobj);
	assert_string_equal(sh->err, want);
	assert_false(command_run(sh, "camera move 1,2"));
	assert_string_equal(sh->err, "camera move: \"1,2\" is not a vector; expected DX,DY,DZ");
	assert_false(command_run(sh, "light 1 color 300,0,0"));
	assert_string_equal(sh->err, "light color: 300,0,0 is out of range; expected R,G,B with each in 0..255");
	assert_false(command_run(sh, "object 1 spin 1,2,3"));
	assert_string_equal(sh->err,
	                    "object: \"spin\" is not an object command; expected move, rotate, scale, color or set");
	assert_false(command_run(sh, "delete"));
	assert_string_equal(sh->err, "delete: too few arguments; usage: delete object N | delete light N | "
	                             "delete camera N");
	assert_false(command_run(sh, "undo now"));
	assert_string_equal(sh->err, "undo: \"now\" is not a number of steps; expected 1..1000");
	assert_false(command_run(sh, "undo 1 2"));
	assert_string_equal(sh->err, "undo: too many arguments; usage: undo [N]");
	assert_false(command_run(sh, "undo"));
	assert_string_equal(sh->err, "undo: nothing to undo");
	assert_false(command_run(sh, "set samples lots"));
	/* fov 180 is clamped as in files (issue 14: one rule); 181 is refused */
	assert_false(command_run(sh, "camera fov 181"));
	assert_string_equal(sh->err, "camera fov: camera field of view 181 is out of range; expected degrees "
	                             "in [0,180] (the ends are clamped to 0.01 and 179.99)");
	/* Good commands change the scene and undo brings it back. */
	scene *before = scene_clone(editor_scene(sh->ed));
	assert_true(command_run(sh, "obj 1 mo 1,0,0"));
	assert_false(scene_equal(before, editor_scene(sh->ed)));
	assert_true(command_run(sh, "undo"));
	assert_true(scene_equal(before, editor_scene(sh->ed)));
	assert_true(command_run(sh, "set samples 4"));
	assert_int_equal(sh->set.samples, 4);
	scene_free(before);
	free_shell(sh);
}

/* The candidates for completing the end of `line`. */
static char **complete_at_end(shell *sh, const char *line, bool *files)
{
	const char *sp = strrchr(line, ' ');
	int start = sp ? (int)(sp - line) + 1 : 0;
	return complete_words(sh, line, start, line + start, files);
}

static void assert_candidates(char **c, const char *want)
{
	char got[1024] = "";
	for (size_t i = 0; c && c[i]; i++) {
		strcat(got, i ? " " : "");
		strcat(got, c[i]);
		free(c[i]);
	}
	free(c);
	assert_string_equal(got, want);
}

static void test_completion(void **state)
{
	(void)state;
	rtsh_options o;
	shell *sh = new_shell(&o);
	bool files;
	assert_candidates(complete_at_end(sh, "s", &files), "save set show source");
	assert_candidates(complete_at_end(sh, "ob", &files), "object");
	assert_candidates(complete_at_end(sh, "set sa", &files), "samples");
	assert_candidates(complete_at_end(sh, "set mode ", &files), "whitted path");
	assert_candidates(complete_at_end(sh, "set m", &files), "mode");
	assert_candidates(complete_at_end(sh, "object 1 ", &files), "move rotate scale color set");
	/* the keys after set come from the reader's table (rtfile.h) */
	assert_candidates(complete_at_end(sh, "object 1 set ", &files),
	                  "twist= fuzz= metal= ior= emit= checker= tube= texture= normalmap= bump= bumpscale= "
	                  "uvscale= uvoffset= roughness= metallic= transmission= thin= att_color= att_dist= clearcoat= "
	                  "clearcoat_roughness= specular_factor= specular_color= emit_color= multiscatter= smooth= crease= node=");
	assert_candidates(complete_at_end(sh, "object 1 move ", &files), "");
	assert_candidates(complete_at_end(sh, "obj 2 r", &files), "rotate");
	assert_candidates(complete_at_end(sh, "light ", &files), "1 2 3");
	assert_candidates(complete_at_end(sh, "delete li", &files), "light");
	assert_candidates(complete_at_end(sh, "delete light ", &files), "1 2 3");
	assert_candidates(complete_at_end(sh, "camera ", &files), "1 pos dir lookat fov move turn");
	assert_candidates(complete_at_end(sh, "help un", &files), "undo");
	assert_candidates(complete_at_end(sh, "undo; re", &files), "render redo");
	assert_candidates(complete_at_end(sh, "object 1 move ", &files), "");
	assert_false(files);
	assert_null(complete_at_end(sh, "source sc", &files));
	assert_true(files);
	/* load and save complete by file type (test_complete_files). */
	assert_candidates(complete_at_end(sh, "load scenes/basic.", &files), "scenes/basic.rt");
	assert_false(files);
	/* Object numbers follow the scene. */
	size_t n = editor_scene(sh->ed)->nobjs;
	char **c = complete_at_end(sh, "object ", &files);
	size_t k = 0;
	while (c[k])
		free(c[k++]);
	free(c);
	assert_int_equal(k, n);
	free_shell(sh);
}

static void test_history_file(void **state)
{
	(void)state;
	char home[] = "/tmp/rtsh-test-home-XXXXXX";
	assert_non_null(mkdtemp(home));
	setenv("HOME", home, 1);
	char path[4200], want[4200];
	assert_true(history_path(path, sizeof path));
	snprintf(want, sizeof want, "%s/.rtsh_history", home);
	assert_string_equal(path, want);
	clear_history();
	shell_history h;
	FILE *warn = tmpfile();
	history_setup(&h, warn);
	assert_true(h.writable);
	history_add_line(&h, "object 1 move 1,0,0");
	history_add_line(&h, "object 1 move 1,0,0"); /* a repeat is not added */
	history_add_line(&h, "   ");                 /* nor a blank line */
	history_add_line(&h, "undo");
	history_finish(&h);
	assert_int_equal(history_length, 2);
	/* A new session reads the file back. */
	clear_history();
	history_setup(&h, warn);
	assert_int_equal(history_length, 2);
	assert_string_equal(history_get(history_base)->line, "object 1 move 1,0,0");
	assert_string_equal(history_get(history_base + 1)->line, "undo");
	assert_int_equal(ftell(warn), 0); /* no warning so far */
	/* An unwritable place: one warning, and the shell goes on. */
	setenv("HOME", "/nonexistent/rtsh/home", 1);
	clear_history();
	history_setup(&h, warn);
	assert_false(h.writable);
	history_add_line(&h, "render");
	history_add_line(&h, "quit");
	long after = ftell(warn);
	assert_true(after > 0);
	rewind(warn);
	char line[512];
	int lines = 0;
	while (fgets(line, sizeof line, warn))
		lines++;
	assert_int_equal(lines, 1);
	assert_non_null(strstr(line, "/nonexistent/rtsh/home/.rtsh_history"));
	fclose(warn);
	unlink(want);
	rmdir(home);
	clear_history();
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_lookup_and_prefixes),
		cmocka_unit_test(test_choices),
		cmocka_unit_test(test_split_words),
		cmocka_unit_test(test_numbers),
		cmocka_unit_test(test_arguments_and_messages),
		cmocka_unit_test(test_completion),
		cmocka_unit_test(test_history_file),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
