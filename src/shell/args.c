/* rtsh — the command line (args.h). */
#include "shell/args.h"

#include <getopt.h>
#include <stddef.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "rtsh/image.h"

/* Long options that are not settings get these codes (past any char). */
enum {
	OPT_STRICT = 0x100,
	OPT_COLOR,
	OPT_PREVIEW,
	OPT_TURNTABLE,
	OPT_SETTING = 0x200, /* OPT_SETTING + i: settings_table[i] */
};

/* The short options that name a setting. */
static const struct {
	char letter;
	const char *setting;
} short_settings[] = {
	{'r', "resolution"}, {'s', "samples"}, {'d', "depth"}, {'t', "threads"}, {'m', "mode"},
};
#define NSHORT (sizeof short_settings / sizeof short_settings[0])

/* The options that are not settings; `shell` ones only for ARGS_RTSH. A
 * plain option names its field of rtsh_options (`field`, an offsetof; 0:
 * the option is handled in args_parse): its value there, or true for an
 * option with no value. */
static const struct {
	struct option opt;
	bool shell;
	const char *arg, *help;
	size_t field;
} fixed[] = {
	{{"output", required_argument, NULL, 'o'}, false, "OUT", "render at full resolution to OUT (@images), exit",
	 offsetof(rtsh_options, output)},
	{{"command", required_argument, NULL, 'c'}, true, "'CMD; CMD'", "run shell commands, then exit",
	 offsetof(rtsh_options, commands)},
	{{"file", required_argument, NULL, 'f'}, true, "FILE", "run a command file (- = standard input), then exit",
	 offsetof(rtsh_options, file)},
	{{"interactive", no_argument, NULL, 'i'}, true, NULL, "with -c or -f: stay in the interactive shell afterwards",
	 offsetof(rtsh_options, interactive)},
	{{"quiet", no_argument, NULL, 'q'}, false, NULL, "no progress output", offsetof(rtsh_options, quiet)},
	{{"strict", no_argument, NULL, OPT_STRICT}, false, NULL, "validate scenes by the 42 subject's rules",
	 offsetof(rtsh_options, strict)},
	{{"color", required_argument, NULL, OPT_COLOR}, false, "WHEN", "auto|truecolor|256|16|none: colour output (default auto)",
	 0},
	{{"preview", required_argument, NULL, OPT_PREVIEW}, true, "COLSxROWS",
	 "print a still picture of the scene or model, COLS x ROWS cells, and exit (file managers)", 0},
	{{"turntable", optional_argument, NULL, OPT_TURNTABLE}, false, "[FRAMES]",
	 "a full turn of the camera about the scene: in the terminal, or FRAMES frames with -o (.gif, frame%03d.png)", 0},
	{{"help", no_argument, NULL, 'h'}, false, NULL, "this help", 0},
	{{"version", no_argument, NULL, 'V'}, false, NULL, "the version", 0},
};
#define NFIXED (sizeof fixed / sizeof fixed[0])

static int usage_error(const char *prog, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static int usage_error(const char *prog, const char *fmt, ...)
{
	fprintf(stderr, "%s: ", prog);
	va_list ap;
	va_start(ap, fmt);
	vfprintf(stderr, fmt, ap);
	va_end(ap);
	fprintf(stderr, "\nTry '%s --help' for more information.\n", prog);
	return 2;
}

/* Keeps a plain option's value (fixed[].field): 0 when kept, -1 when c is
 * not one, 2 (a usage error, said) when an option with a value comes twice:
 * the first value would be lost without a word (-c A -c B ran only B). */
static int keep_plain(int c, const char *prog, rtsh_options *o)
{
	for (size_t i = 0; i < NFIXED; i++)
		if (fixed[i].opt.val == c && fixed[i].field) {
			char *at = (char *)o + fixed[i].field;
			if (fixed[i].opt.has_arg == required_argument) {
				const char **v = (const char **)(void *)at;
				if (*v)
					return usage_error(prog, "option -%c (--%s) given twice (\"%s\" and \"%s\"); expected it once%s",
					                   c, fixed[i].opt.name, *v, optarg, c == 'c' ? " (join commands with ;: -c 'CMD; CMD')" : "");
				*v = optarg;
			} else {
				*(bool *)(void *)at = true;
			}
			return 0;
		}
	return -1;
}

static char short_of(const char *setting)
{
	for (size_t i = 0; i < NSHORT; i++)
		if (strcmp(short_settings[i].setting, setting) == 0)
			return short_settings[i].letter;
	return 0;
}

/* A help text with "@images" replaced by the image formats' extensions
 * (image.c's table). */
static void put_help(FILE *f, const char *left, const char *help)
{
	const char *at = strstr(help, "@images");
	char exts[128];
	image_extensions_join(exts, sizeof exts, "", " ", false);
	if (at)
		fprintf(f, "  %-28s %.*s%s%s\n", left, (int)(at - help), help, exts, at + strlen("@images"));
	else
		fprintf(f, "  %-28s %s\n", left, help);
}

void args_usage(FILE *f, args_kind kind, const char *prog)
{
	char exts[128];
	image_extensions_join(exts, sizeof exts, "", " ", false);
	if (kind == ARGS_RTSH)
		fprintf(f,
		        "usage: %s [OPTIONS] [SCENE.rt]\n"
		        "  %s                      open the shell on the built-in showcase scene\n"
		        "  %s SCENE.rt             open the shell on SCENE.rt\n"
		        "  %s SCENE.rt -o OUT      render at full resolution to OUT (%s), exit\n",
		        prog, prog, prog, prog, exts);
	else
		fprintf(f, "usage: %s [OPTIONS] SCENE.rt -o OUT\n", prog);
	fputs("options (GNU style: -s4 or -s 4, --samples=4 or --samples 4, -qi, options after the scene):\n", f);
	for (size_t i = 0; i < NFIXED; i++) {
		if (fixed[i].shell && kind != ARGS_RTSH)
			continue;
		char left[64];
		int v = fixed[i].opt.val;
		if (v < 0x100)
			snprintf(left, sizeof left, "-%c, --%s%s%s", v, fixed[i].opt.name, fixed[i].arg ? " " : "",
			         fixed[i].arg ? fixed[i].arg : "");
		else
			snprintf(left, sizeof left, "    --%s%s%s", fixed[i].opt.name, fixed[i].arg ? " " : "",
			         fixed[i].arg ? fixed[i].arg : "");
		put_help(f, left, fixed[i].help);
	}
	fputs("settings (the shell's `set NAME VALUE`; they win over the scene's own):\n", f);
	for (size_t i = 0; i < settings_count; i++) {
		char left[64];
		char c = short_of(settings_table[i].name);
		if (c)
			snprintf(left, sizeof left, "-%c, --%s=VALUE", c, settings_table[i].name);
		else
			snprintf(left, sizeof left, "    --%s%s", settings_table[i].name,
			         (settings_table[i].flags & SETTING_BARE_ON) ? "[=VALUE]" : "=VALUE");
		fprintf(f, "  %-28s %s\n", left, settings_table[i].help);
	}
	if (kind == ARGS_RTSH)
		fputs("See rtsh(1) for the shell's commands and rtsh(5) for the scene format.\n", f);
}

void options_apply_settings(const rtsh_options *o, render_settings *s)
{
	for (int i = 0; i < o->nsettings; i++)
		settings_set(s, o->settings[i].def, o->settings[i].value, NULL);
}

/* Records a setting after checking its value; a later one replaces an
 * earlier one of the same setting. */
static int add_setting(const char *prog, rtsh_options *o, const setting_def *def, const char *opt,
                       const char *value)
{
	rt_error err;
	render_settings probe = render_settings_default();
	if (!settings_set(&probe, def, value, &err))
		return usage_error(prog, "option %s: %s", opt, err.msg);
	for (int i = 0; i < o->nsettings; i++)
		if (o->settings[i].def == def) {
			o->settings[i].value = value;
			return 0;
		}
	if (o->nsettings == OPTIONS_MAX_SETTINGS)
		return usage_error(prog, "too many setting options (at most %d)", OPTIONS_MAX_SETTINGS);
	o->settings[o->nsettings++] = (option_setting){def, value};
	return 0;
}

static int parse_color(const char *prog, const char *v, color_mode *out)
{
	static const struct {
		const char *name;
		color_mode mode;
	} names[] = {{"auto", COLOR_AUTO},  {"truecolor", COLOR_TRUECOLOR}, {"24bit", COLOR_TRUECOLOR},
	             {"256", COLOR_256},    {"16", COLOR_16},               {"none", COLOR_NONE}};
	for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
		if (strcmp(v, names[i].name) == 0) {
			*out = names[i].mode;
			return 0;
		}
	return usage_error(prog, "option --color: \"%s\" is not valid; expected auto, truecolor, 256, 16 or none", v);
}

/* "COLSxROWS", each 1..OPTIONS_MAX_CELLS. */
static bool parse_cells(const char *s, int *cols, int *rows)
{
	if (s[0] < '0' || s[0] > '9')
		return false;
	char *end;
	long c = strtol(s, &end, 10);
	if (*end != 'x' && *end != 'X')
		return false;
	const char *r0 = end + 1;
	if (r0[0] < '0' || r0[0] > '9')
		return false;
	long r = strtol(r0, &end, 10);
	if (*end || c < 1 || c > OPTIONS_MAX_CELLS || r < 1 || r > OPTIONS_MAX_CELLS)
		return false;
	*cols = (int)c;
	*rows = (int)r;
	return true;
}

/* The option as the user wrote it, for a message: "-x", or "--name" (the
 * argument after '=' left off). */
static void option_text(char *const *argv, int at, int short_opt, char *buf, size_t size)
{
	if (short_opt > 0 && short_opt < 0x100) {
		snprintf(buf, size, "-%c", short_opt);
		return;
	}
	const char *a = argv[at];
	size_t n = strcspn(a, "=");
	snprintf(buf, size, "%.*s", (int)n, a);
}

int args_parse(int argc, char **argv, args_kind kind, const char *prog, rtsh_options *o)
{
	memset(o, 0, sizeof *o);
	/* The long options: the fixed ones, then one per setting. */
	struct option *longs = calloc(NFIXED + settings_count + 1, sizeof *longs);
	if (!longs) {
		fprintf(stderr, "%s: out of memory\n", prog);
		return 1;
	}
	size_t n = 0;
	for (size_t i = 0; i < NFIXED; i++)
		if (!fixed[i].shell || kind == ARGS_RTSH)
			longs[n++] = fixed[i].opt;
	for (size_t i = 0; i < settings_count; i++)
		longs[n++] = (struct option){settings_table[i].name,
		                             /* --denoise alone means on */
		                             (settings_table[i].flags & SETTING_BARE_ON) ? optional_argument
		                                                                       : required_argument,
		                             NULL, OPT_SETTING + (int)i};
	/* '-': operands come back in order as option 1 (so options may follow
	 * the scene whatever POSIXLY_CORRECT says); ':': missing values are
	 * told apart from unknown options. */
	const char *shorts = kind == ARGS_RTSH ? "-:hVo:c:f:iqr:s:d:t:m:" : "-:hVo:qr:s:d:t:m:";
	int rc = -1;
	opterr = 0;
	optind = 0; /* a full reset, so that args_parse can run again */
	int c;
	while (rc < 0 && (c = getopt_long(argc, argv, shorts, longs, NULL)) != -1) {
		char name[64];
		const setting_def *def = NULL;
		int kept = keep_plain(c, prog, o);
		if (kept == 0)
			continue;
		if (kept > 0) {
			rc = kept;
			break;
		}
		switch (c) {
		case 1: /* an operand: the scene */
			if (o->scene)
				rc = usage_error(prog, "more than one scene file given (\"%s\" and \"%s\"); expected one",
				                 o->scene, optarg);
			else
				o->scene = optarg;
			break;
		case 'h':
			args_usage(stdout, kind, prog);
			rc = 0;
			break;
		case 'V':
			printf("%s %s\n", prog, RTSH_VERSION);
			rc = 0;
			break;
		case OPT_COLOR:
			rc = parse_color(prog, optarg, &o->color);
			if (rc == 0)
				rc = -1;
			break;
		case OPT_PREVIEW:
			o->preview = optarg;
			if (!parse_cells(optarg, &o->preview_cols, &o->preview_rows))
				rc = usage_error(prog, "option --preview: \"%s\" is not a size; expected COLSxROWS, each 1..%d",
				                 optarg, OPTIONS_MAX_CELLS);
			break;
		case OPT_TURNTABLE: {
			/* --turntable FRAMES as well as --turntable=FRAMES */
			const char *v = optarg;
			if (!v && optind < argc && argv[optind][0] >= '0' && argv[optind][0] <= '9')
				v = argv[optind++];
			o->turntable = true;
			if (v) {
				char *end;
				long f = strtol(v, &end, 10);
				if (end == v || *end || f < 1 || f > OPTIONS_MAX_FRAMES)
					rc = usage_error(prog, "option --turntable: \"%s\" is not a frame count; expected 1..%d", v,
					                 OPTIONS_MAX_FRAMES);
				else
					o->turntable_frames = (int)f;
			}
			break;
		}
		case ':':
			option_text(argv, optind - 1, optopt, name, sizeof name);
			rc = usage_error(prog, "option %s needs a value", name);
			break;
		case '?':
			option_text(argv, optind - 1, optopt, name, sizeof name);
			rc = usage_error(prog, "unknown or ambiguous option \"%s\"", name);
			break;
		default:
			if (c >= OPT_SETTING && c < OPT_SETTING + (int)settings_count) {
				def = &settings_table[c - OPT_SETTING];
				snprintf(name, sizeof name, "--%s", def->name);
			} else {
				for (size_t i = 0; i < NSHORT; i++)
					if (short_settings[i].letter == c)
						def = settings_find(short_settings[i].setting, NULL);
				snprintf(name, sizeof name, "-%c", c);
			}
			if (def) {
				rc = add_setting(prog, o, def, name, optarg ? optarg : "on");
				if (rc == 0)
					rc = -1;
			} else {
				rc = usage_error(prog, "option %s is not known to this build", name);
			}
			break;
		}
	}
	/* After "--": operands only. */
	for (int i = optind; rc < 0 && i < argc; i++) {
		if (o->scene)
			rc = usage_error(prog, "more than one scene file given (\"%s\" and \"%s\"); expected one", o->scene,
			                 argv[i]);
		else
			o->scene = argv[i];
	}
	free(longs);
	if (rc >= 0)
		return rc;
	if (kind == ARGS_BATCH && (!o->scene || !o->output))
		return usage_error(prog, "a scene file and -o OUT are needed");
	if (o->output && (o->commands || o->file))
		return usage_error(prog, "-o cannot be combined with -c or -f; use the shell's save command");
	if (o->commands && o->file)
		return usage_error(prog, "give -c or -f, not both");
	if (o->preview && (o->output || o->commands || o->file || o->turntable))
		return usage_error(prog, "--preview prints the picture; it cannot be combined with -o, -c, -f or --turntable");
	if (o->turntable_frames && !o->output)
		return usage_error(prog, "--turntable FRAMES needs -o OUT (.gif, or a numbered name such as frame%%03d.png)");
	if (o->turntable && !o->turntable_frames && o->output)
		return usage_error(prog, "--turntable with -o needs a frame count: --turntable FRAMES -o OUT");
	if (o->interactive && !o->commands && !o->file)
		return usage_error(prog, "-i needs -c or -f");
	return -1;
}
