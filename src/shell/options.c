/* rtsh — the command-line options: parsed once here for rtsh and rtsh-mpi. */
#include <stdio.h>
#include <string.h>

#include "shell/options.h"

/* The program name in messages: argv[0]'s last part (rtsh, rtsh-mpi). */
static const char *prog = "rtsh";

static void usage(FILE *f)
{
	fputs("usage: rtsh [OPTIONS] [SCENE.rt]\n"
	      "  rtsh                      open the shell on the built-in showcase scene\n"
	      "  rtsh SCENE.rt             open the shell on SCENE.rt\n"
	      "  rtsh SCENE.rt -o OUT      render at full resolution to OUT (.ppm .pfm .png), exit\n"
	      "options:\n"
	      "  -c 'CMD; CMD'    run shell commands, then exit\n"
	      "  -f FILE          run a command file (- = standard input), then exit\n"
	      "  -i               with -c or -f: stay in the interactive shell afterwards\n"
	      "  -o OUT           batch render to OUT\n"
	      "  -r WxH           resolution          -s N   samples per pixel\n"
	      "  -d N             depth               -t N   threads (0 = all CPUs)\n"
	      "  -m whitted|path  render mode         --seed N  random seed\n"
	      "  --color auto|truecolor|256|16|none   colour output (default auto)\n"
	      "  -q               no progress output\n"
	      "  --strict         validate scenes by the 42 subject's rules\n"
	      "  -h, --help       this help           -V, --version  version\n"
	      "See rtsh(1) for the shell's commands and rtsh(5) for the scene format.\n",
	      f);
}

int options_usage_error(const char *fmt, const char *arg)
{
	fprintf(stderr, "%s: ", prog);
	fprintf(stderr, fmt, arg);
	fprintf(stderr, "\nTry '%s --help' for more information.\n", prog);
	return 2;
}

void options_apply_settings(const rtsh_options *o, render_settings *s)
{
	for (int i = 0; i < o->nsettings; i++)
		settings_set(s, o->settings[i].def, o->settings[i].value, NULL);
}

/* Records a setting option after checking its value. */
static int add_setting(rtsh_options *o, const char *name, const char *value)
{
	rt_error err;
	const setting_def *def = settings_find(name, &err);
	render_settings probe = render_settings_default();
	if (!def || !settings_set(&probe, def, value, &err))
		return options_usage_error("%s", err.msg);
	if (o->nsettings == OPTIONS_MAX_SETTINGS)
		return options_usage_error("too many setting options%s", "");
	o->settings[o->nsettings++] = (option_setting){def, value};
	return 0;
}

int options_parse(int argc, char **argv, rtsh_options *o)
{
	if (argc > 0 && argv[0][0]) {
		const char *slash = strrchr(argv[0], '/');
		prog = slash && slash[1] ? slash + 1 : argv[0];
	}
	for (int i = 1; i < argc; i++) {
		const char *a = argv[i];
		const char *next = i + 1 < argc ? argv[i + 1] : NULL;
#define NEED_ARG()                                                  \
	do {                                                        \
		if (!next)                                          \
			return options_usage_error("option %s needs a value", a); \
		i++;                                                \
	} while (0)
		int rc = 0;
		if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
			usage(stdout);
			return 0;
		} else if (strcmp(a, "-V") == 0 || strcmp(a, "--version") == 0) {
			printf("rtsh %s\n", RTSH_VERSION);
			return 0;
		} else if (strcmp(a, "-o") == 0) {
			NEED_ARG();
			o->output = next;
		} else if (strcmp(a, "-c") == 0) {
			NEED_ARG();
			o->commands = next;
		} else if (strcmp(a, "-f") == 0) {
			NEED_ARG();
			o->file = next;
		} else if (strcmp(a, "-i") == 0) {
			o->interactive = true;
		} else if (strcmp(a, "-q") == 0) {
			o->quiet = true;
		} else if (strcmp(a, "--strict") == 0) {
			o->strict = true;
		} else if (strcmp(a, "-r") == 0) {
			NEED_ARG();
			rc = add_setting(o, "resolution", next);
		} else if (strcmp(a, "-s") == 0) {
			NEED_ARG();
			rc = add_setting(o, "samples", next);
		} else if (strcmp(a, "-d") == 0) {
			NEED_ARG();
			rc = add_setting(o, "depth", next);
		} else if (strcmp(a, "-t") == 0) {
			NEED_ARG();
			rc = add_setting(o, "threads", next);
		} else if (strcmp(a, "-m") == 0) {
			NEED_ARG();
			rc = add_setting(o, "mode", next);
		} else if (strcmp(a, "--seed") == 0) {
			NEED_ARG();
			rc = add_setting(o, "seed", next);
		} else if (strcmp(a, "--color") == 0 || strncmp(a, "--color=", 8) == 0) {
			const char *v = a[7] == '=' ? a + 8 : next;
			if (a[7] != '=')
				NEED_ARG();
			if (!v)
				return options_usage_error("option --color needs a value%s", "");
			if (strcmp(v, "auto") == 0)
				o->color = COLOR_AUTO;
			else if (strcmp(v, "truecolor") == 0 || strcmp(v, "24bit") == 0)
				o->color = COLOR_TRUECOLOR;
			else if (strcmp(v, "256") == 0)
				o->color = COLOR_256;
			else if (strcmp(v, "16") == 0)
				o->color = COLOR_16;
			else if (strcmp(v, "none") == 0)
				o->color = COLOR_NONE;
			else
				return options_usage_error("--color \"%s\" is not valid; expected auto, truecolor, 256, 16 or none", v);
		} else if (strcmp(a, "--") == 0) {
			if (next && !o->scene) {
				o->scene = next;
				i++;
			}
		} else if (a[0] == '-' && a[1] != '\0') {
			return options_usage_error("unknown option \"%s\"", a);
		} else if (o->scene) {
			return options_usage_error("more than one scene file given (\"%s\"); expected one", a);
		} else {
			o->scene = a;
		}
		if (rc)
			return rc;
#undef NEED_ARG
	}
	if (o->output && (o->commands || o->file))
		return options_usage_error("-o cannot be combined with -c or -f%s; use the shell's save command", "");
	if (o->commands && o->file)
		return options_usage_error("give -c or -f, not both%s", "");
	if (o->interactive && !o->commands && !o->file)
		return options_usage_error("-i needs -c or -f%s", "");
	return -1;
}

