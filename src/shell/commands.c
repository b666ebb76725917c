/* rtsh — command lookup, argument parsing, `help`, `quit` and `clear`
 * (the table itself is command_table.c). */
#include "shell/commands.h"

#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rtsh/image.h"
#include "rtsh/mesh.h"
#include "rtsh/num.h"
#include "rtsh/rtfile.h"
#include "shell/answer.h"
#include "shell/keymode.h"
#include "shell/suggest.h"

/* `help set`: the settings table (settings.h), each with its values. */
static const char *settings_help(void)
{
	static char text[4096];
	size_t used = 0;
	used += (size_t)snprintf(text, sizeof text, "settings:\n");
	for (size_t i = 0; i < settings_count && used < sizeof text; i++) {
		const setting_def *d = &settings_table[i];
		char values[256];
		if (d->type == SETTING_ENUM)
			settings_choices_text(d, "|", "|", values, sizeof values);
		else if (d->type == SETTING_RESOLUTION) /* with the ranges `set` checks */
			snprintf(values, sizeof values, "WxH (each %.0f..%.0f)", d->min, d->max);
		else if (d->type == SETTING_DOUBLE)
			snprintf(values, sizeof values, "NUMBER (%g..%g)", d->min, d->max);
		else if (d->type == SETTING_U64)
			snprintf(values, sizeof values, "N (0..2^64-1)");
		else
			snprintf(values, sizeof values, "N (%.0f..%.0f)", d->min, d->max);
		used += (size_t)snprintf(text + used, sizeof text - used, "  %-10s %-34s %s\n", d->name, values,
		                         d->help);
	}
	/* The SETTING_SCENE rows: what a .rt file's set lines and save x.rt hold. */
	if (used < sizeof text)
		used += (size_t)snprintf(text + used, sizeof text - used, "kept with a scene (.rt set lines, save x.rt):");
	for (size_t i = 0; i < settings_count && used < sizeof text; i++)
		if (settings_table[i].flags & SETTING_SCENE)
			used += (size_t)snprintf(text + used, sizeof text - used, " %s", settings_table[i].name);
	if (used < sizeof text)
		snprintf(text + used, sizeof text - used, "\n");
	return text;
}

/* `help load` and `help save`: the formats, from the model readers' table
 * (mesh_load.c) and the image table (image.c). */
static const char *load_help(void)
{
	static char text[512];
	char models[256];
	mesh_format_list(models, sizeof models);
	snprintf(text, sizeof text, "model formats: %s\n", models);
	return text;
}

static const char *save_help(void)
{
	static char text[2048];
	size_t used = (size_t)snprintf(text, sizeof text, "image formats:\n");
	const image_type *t;
	for (size_t i = 0; (t = image_type_at(i)) && used < sizeof text; i++)
		used += (size_t)snprintf(text + used, sizeof text - used, "  %-6s %s\n", t->ext, t->help);
	if (used < sizeof text)
		snprintf(text + used, sizeof text - used, "  %-6s %s\n  %-6s %s\n", ".ans",
		         "the picture as ANSI text (the terminal's cells)", ".rt", "the scene");
	return text;
}

/* More for `help COMMAND` than its usage and one line (text, or made by
 * gen from a table). */
static const struct {
	const char *name, *text;
	const char *(*gen)(void);
} details[] = {
	{"view", NULL, keymode_help_text},
	{"set", NULL, settings_help},
	{"load", NULL, load_help},
	{"save", NULL, save_help},
	{"add", "examples: add sp 0,1,0 1 255,0,0 texture=earth.png\n"
	        "          add mesh bunny.obj 0,0.5,0 0,1,0 1 200,200,200 smooth=1 crease=60\n"
	        "          add sky sky.hdr 1 90   (an HDR sky, turned 90 degrees)\n"
	        "keys: texture= normalmap= bump= bumpscale= uvscale=U,V uvoffset=U,V, and for a mesh smooth= "
	        "crease= (see rtsh(5))\n",
	 NULL},
};

/* True when `word` is one of the space-separated names in list. */
static bool in_list(const char *list, const char *word, size_t len, bool prefix)
{
	if (!list)
		return false;
	const char *p = list;
	while (*p) {
		size_t n = strcspn(p, " ");
		if (prefix ? (len <= n && strncmp(p, word, len) == 0) : (n == len && strncmp(p, word, n) == 0))
			return true;
		p += n;
		while (*p == ' ')
			p++;
	}
	return false;
}

const command *command_lookup(const command *table, size_t count, const char *word, char *msg, size_t size)
{
	size_t len = strlen(word);
	for (size_t i = 0; i < count; i++)
		if (strcmp(table[i].name, word) == 0 || in_list(table[i].aliases, word, len, false))
			return &table[i];
	const command *found = NULL;
	char names[512] = "";
	int n = 0;
	for (size_t i = 0; len && i < count; i++) {
		const command *c = &table[i];
		if (strncmp(c->name, word, len) == 0 || in_list(c->aliases, word, len, true)) {
			found = c;
			n++;
			size_t l = strlen(names);
			snprintf(names + l, sizeof names - l, "%s%s", l ? ", " : "", c->name);
		}
	}
	if (n == 1)
		return found;
	if (n > 1) {
		/* "a, b, c" -> "a, b or c" */
		char *last = strrchr(names, ',');
		char tail[128];
		if (last) {
			snprintf(tail, sizeof tail, "%s", last + 2);
			snprintf(last, sizeof names - (size_t)(last - names), " or %s", tail);
		}
		snprintf(msg, size, "ambiguous command \"%s\"; could be %s", word, names);
	} else if (suggest_command_in(table, count, word, names, sizeof names)) {
		snprintf(msg, size, "unknown command \"%s\"; did you mean \"%s\"?", word, names);
	} else {
		snprintf(msg, size, "unknown command \"%s\"; type help for the list of commands", word);
	}
	return NULL;
}

int choice_pick(const char *choices, const char *word)
{
	size_t len = strlen(word);
	int idx = 0, found = -1, n = 0;
	for (const char *p = choices; *p; idx++) {
		size_t k = strcspn(p, "|");
		if (k == len && strncmp(p, word, len) == 0)
			return idx;
		if (len && len < k && strncmp(p, word, len) == 0) {
			found = idx;
			n++;
		}
		p += k;
		if (*p == '|')
			p++;
	}
	return n == 1 ? found : -1;
}

void choice_list(const char *choices, char *buf, size_t size)
{
	size_t count = 1;
	for (const char *p = choices; *p; p++)
		count += *p == '|';
	buf[0] = '\0';
	size_t i = 0;
	for (const char *p = choices; *p; i++) {
		size_t k = strcspn(p, "|"), l = strlen(buf);
		const char *sep = i == 0 ? "" : i + 1 == count ? " or " : ", ";
		snprintf(buf + l, size - l, "%s%.*s", sep, (int)k, p);
		p += k;
		if (*p == '|')
			p++;
	}
}

int split_words(const char *s, char **argv, int max, char *buf, size_t *rest_at, char *msg, size_t size)
{
	int argc = 0;
	const char *p = s;
	char *o = buf;
	*rest_at = strlen(s);
	for (;;) {
		while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n')
			p++;
		if (!*p)
			break;
		if (argc == 1)
			*rest_at = (size_t)(p - s);
		char *start = o;
		char quote = 0;
		while (*p && (quote || !(*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n'))) {
			if (quote) {
				if (*p == quote) {
					quote = 0;
					p++;
				} else if (*p == '\\' && quote == '"' && (p[1] == '"' || p[1] == '\\')) {
					*o++ = p[1];
					p += 2;
				} else {
					*o++ = *p++;
				}
			} else if (*p == '\'' || *p == '"') {
				quote = *p++;
			} else if (*p == '\\' && p[1]) {
				*o++ = p[1];
				p += 2;
			} else {
				*o++ = *p++;
			}
		}
		if (quote) {
			snprintf(msg, size, "unclosed %c quote; expected a closing %c", quote, quote);
			return -1;
		}
		*o++ = '\0';
		if (argc < max)
			argv[argc] = start;
		argc++;
	}
	if (argc == 1)
		*rest_at = strlen(s);
	return argc > max ? max + 1 : argc;
}

bool parse_number(const char *s, double *out)
{
	return num_scan_str(s, 1e20, out) == NUM_OK; /* the .rt reader's numbers (num.h) */
}

bool arg_number(shell *sh, const char *what, const char *word, double lo, double hi, double *out)
{
	double v;
	if (!parse_number(word, &v))
		return shell_fail(sh, "%s: \"%s\" is not a number; expected a number in %g..%g", what, word, lo, hi);
	if (v < lo || v > hi)
		return shell_fail(sh, "%s: %s is out of range; expected a number in %g..%g", what, word, lo, hi);
	*out = v;
	return true;
}

bool arg_int(shell *sh, const char *what, const char *word, long lo, long hi, long *out)
{
	long v = 0;
	num_status st = num_scan_long(word, LONG_MIN, LONG_MAX, &v);
	if (st == NUM_EMPTY || st == NUM_BAD)
		return shell_fail(sh, "%s: \"%s\" is not a whole number; expected %ld..%ld", what, word, lo, hi);
	if (st != NUM_OK || v < lo || v > hi)
		return shell_fail(sh, "%s: %s is out of range; expected %ld..%ld", what, word, lo, hi);
	*out = v;
	return true;
}

/* Exactly n numbers separated by commas. */
static bool parse_tuple(const char *word, double *v, int n)
{
	char buf[256];
	if (strlen(word) >= sizeof buf)
		return false;
	strcpy(buf, word);
	char *p = buf;
	for (int i = 0; i < n; i++) {
		char *comma = strchr(p, ',');
		if ((i < n - 1) != (comma != NULL))
			return false;
		if (comma)
			*comma = '\0';
		if (!parse_number(p, &v[i]))
			return false;
		p = comma ? comma + 1 : p;
	}
	return true;
}

bool arg_vec(shell *sh, const char *what, const char *word, const char *expect, vec3 *out)
{
	double v[3];
	if (!parse_tuple(word, v, 3))
		return shell_fail(sh, "%s: \"%s\" is not a vector; expected %s", what, word, expect);
	*out = v3(v[0], v[1], v[2]);
	return true;
}

bool arg_color(shell *sh, const char *what, const char *word, vec3 *out)
{
	double v[3];
	if (!parse_tuple(word, v, 3))
		return shell_fail(sh, "%s: \"%s\" is not a colour; expected R,G,B with each in 0..255", what, word);
	for (int i = 0; i < 3; i++)
		if (v[i] < 0 || v[i] > 255)
			return shell_fail(sh, "%s: %s is out of range; expected R,G,B with each in 0..255", what,
			                  word);
	*out = v3(v[0], v[1], v[2]);
	return true;
}

bool arg_index(shell *sh, const char *what, const char *word, const char *kind, size_t n, size_t *out)
{
	unsigned long long v = 0;
	bool ok = num_scan_u64(word, &v) == NUM_OK && v >= 1 && v <= n; /* num.h */
	if (!ok) {
		if (n == 0)
			return shell_fail(sh, "%s: \"%s\" is not %s %s number; the scene has no %ss", what, word,
			                  kind[0] == 'o' ? "an" : "a", kind, kind);
		return shell_fail(sh, "%s: \"%s\" is not %s %s number; expected 1..%zu", what, word,
		                  kind[0] == 'o' ? "an" : "a", kind, n);
	}
	*out = (size_t)(v - 1);
	return true;
}

/* The k bytes of a usage line at p with "@images" replaced by the image
 * formats the table in image.c writes: "FILE.ppm|FILE.pfm|...". */
static void usage_text(const char *p, size_t k, char *buf, size_t size)
{
	snprintf(buf, size, "%.*s", (int)k, p);
	char *at = strstr(buf, "@images");
	if (!at)
		return;
	char exts[256], rest[256];
	image_extensions_join(exts, sizeof exts, "FILE", "|", true);
	snprintf(rest, sizeof rest, "%s", at + 7);
	size_t l = (size_t)(at - buf);
	snprintf(at, size - l, "%s%s", exts, rest);
}

/* "usage: a | b | c" from the usage lines. */
static void usage_line(const command *c, char *buf, size_t size)
{
	snprintf(buf, size, "usage: ");
	for (const char *p = c->usage; *p;) {
		size_t k = strcspn(p, "\n"), l = strlen(buf);
		snprintf(buf + l, size - l, "%s", p == c->usage ? "" : " | ");
		l = strlen(buf);
		usage_text(p, k, buf + l, size - l);
		p += k;
		if (*p == '\n')
			p++;
	}
}

bool command_run(shell *sh, const char *text)
{
	size_t len = strlen(text);
	char *buf = malloc(len + 1);
	char *argv[CMD_MAX_ARGS + 1];
	size_t rest_at;
	char msg[256];
	if (!buf)
		return shell_fail(sh, "out of memory");
	int argc = split_words(text, argv, CMD_MAX_ARGS, buf, &rest_at, msg, sizeof msg);
	if (argc < 0) {
		free(buf);
		return shell_fail(sh, "%s", msg);
	}
	if (argc == 0) {
		free(buf);
		return true;
	}
	/* A command word ending in "!" forces it (quit!: no question). */
	size_t wl = strlen(argv[0]);
	bool force = wl > 1 && argv[0][wl - 1] == '!';
	if (force)
		argv[0][wl - 1] = '\0';
	if (!sh->commands) {
		free(buf);
		return shell_fail(sh, "no command table (command_table_install)");
	}
	const command *c = command_lookup(sh->commands, sh->ncommands, argv[0], msg, sizeof msg);
	if (!c || (force && c->run != cmd_quit)) {
		if (c)
			snprintf(msg, sizeof msg, "%s: \"%s!\" is not a command; only quit! takes a \"!\"", c->name,
			         argv[0]);
		free(buf);
		return shell_fail(sh, "%s", msg);
	}
	sh->force = force;
	int nargs = argc - 1;
	if (nargs < c->min_args || (c->max_args != CMD_ANY && nargs > c->max_args) || argc > CMD_MAX_ARGS) {
		char u[512];
		usage_line(c, u, sizeof u);
		free(buf);
		const char *why = nargs < c->min_args ? "too few arguments" : "too many arguments";
		return shell_fail(sh, "%s: %s; %s", c->name, why, u);
	}
	/* The raw text after the name, without trailing blanks. */
	char *rest = strdup(text + rest_at);
	if (!rest) {
		free(buf);
		return shell_fail(sh, "out of memory");
	}
	for (size_t n = strlen(rest); n > 0 && strchr(" \t\r\n", rest[n - 1]); n--)
		rest[n - 1] = '\0';
	uint64_t gen0 = editor_generation(sh->ed);
	bool ok = c->run(sh, nargs, argv + 1, rest);
	if (ok)
		answer_after_command(sh, c, rest, gen0);
	free(rest);
	free(buf);
	return ok;
}

bool cmd_help(shell *sh, int argc, char **argv, const char *rest)
{
	(void)rest;
	if (argc == 1) {
		char msg[256];
		const command *c = command_lookup(sh->commands, sh->ncommands, argv[0], msg, sizeof msg);
		if (!c)
			return shell_fail(sh, "help: %s", msg);
		for (const char *p = c->usage; *p;) {
			size_t k = strcspn(p, "\n");
			char line[512];
			usage_text(p, k, line, sizeof line);
			shell_out(sh, "%s%s\n", p == c->usage ? "usage: " : "       ", line);
			p += k;
			if (*p == '\n')
				p++;
		}
		shell_out(sh, "%s\n", c->help);
		for (size_t i = 0; i < sizeof details / sizeof details[0]; i++)
			if (strcmp(details[i].name, c->name) == 0)
				shell_out(sh, "%s", details[i].text ? details[i].text : details[i].gen());
		if (strcmp(c->name, "add") == 0) { /* the elements, from the reader's table */
			const char *usage;
			shell_out(sh, "elements (rtsh(5)):\n");
			for (size_t i = 0; rt_element(i, &usage); i++)
				shell_out(sh, "  %s\n", usage);
		}
		if (strcmp(c->name, "add") == 0 || strcmp(c->name, "object") == 0) { /* the keys, from the reader's table */
			const char *name, *kh;
			shell_out(sh, "object keys (KEY=VALUE after the fields, or object N set KEY=VALUE):\n");
			for (size_t i = 0; (name = rt_key_info(i, &kh)); i++)
				shell_out(sh, "  %-8s %s\n", name, kh);
		}
		if (c->aliases)
			shell_out(sh, "also: %s\n", c->aliases);
		return true;
	}
	shell_out(sh, "commands (a unique prefix is enough, a typo gets a suggestion; help COMMAND for its "
	              "usage):\n");
	for (size_t i = 0; i < sh->ncommands; i++) {
		const command *c = &sh->commands[i];
		/* A help of several lines: the others under the first. */
		const char *p = c->help;
		size_t k = strcspn(p, "\n");
		shell_out(sh, "  %-9s %.*s\n", c->name, (int)k, p);
		for (p += k; *p == '\n';) {
			p++;
			k = strcspn(p, "\n");
			shell_out(sh, "            %.*s\n", (int)k, p);
			p += k;
		}
	}
	shell_out(sh, "vectors X,Y,Z and colours R,G,B (0-255) as in .rt files; objects and lights "
	              "are numbered from 1 (see list)\n");
	return true;
}

bool cmd_quit(shell *sh, int argc, char **argv, const char *rest)
{
	(void)argc, (void)argv, (void)rest;
	if (!sh->force && shell_quit_asks(sh)) {
		shell_out(sh, "quit: the scene has edits not saved (save FILE.rt keeps them); quit again, or quit!, "
		              "leaves without them\n");
		return true;
	}
	sh->quit = true;
	return true;
}

bool cmd_clear(shell *sh, int argc, char **argv, const char *rest)
{
	(void)argc, (void)argv, (void)rest;
	if (sh->scr && sh->scr->active) {
		/* Clear the scroll region only, and start again at its bottom. */
		fflush(stdout);
		screen_clear_commands(sh->scr);
		screen_log_clear(sh->scr);
	}
	return true;
}
