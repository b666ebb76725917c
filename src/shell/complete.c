/* rtsh — tab completion (complete.h), driven by the command table's
 * `complete` specs. */
#include "shell/complete.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <readline/readline.h>

#include "rtsh/rtfile.h"
#include "rtsh/settings.h"
#include "shell/commands.h"
#include "shell/complete_files.h"

/* Numbers beyond this many are not offered (a million objects...). */
#define MAX_CANDIDATES 1000

typedef struct list {
	char **v;
	size_t n, cap;
	bool failed;
} list;

static void add(list *l, const char *s, const char *text)
{
	if (l->failed || strncmp(s, text, strlen(text)) != 0 || l->n >= MAX_CANDIDATES)
		return;
	for (size_t i = 0; i < l->n; i++)
		if (strcmp(l->v[i], s) == 0)
			return;
	if (l->n + 2 > l->cap) {
		size_t cap = l->cap ? l->cap * 2 : 16;
		char **p = realloc(l->v, cap * sizeof *p);
		if (!p) {
			l->failed = true;
			return;
		}
		l->v = p;
		l->cap = cap;
	}
	char *d = strdup(s);
	if (!d) {
		l->failed = true;
		return;
	}
	l->v[l->n++] = d;
	l->v[l->n] = NULL;
}

static void add_file(void *ctx, const char *s)
{
	list *l = ctx;
	add(l, s, "");
}

static void add_numbers(list *l, size_t n, const char *text)
{
	char buf[32];
	for (size_t i = 1; i <= n && l->n < MAX_CANDIDATES; i++) {
		snprintf(buf, sizeof buf, "%zu", i);
		add(l, buf, text);
	}
}

static void add_commands(list *l, const char *text)
{
	for (size_t i = 0; i < command_count; i++)
		add(l, command_table[i].name, text);
}

/* The candidates are file names (load, save): readline quotes them. */
static bool listed_files;

/* One '|'-separated alternative of a spec. */
static void add_alternative(list *l, const shell *sh, const char *alt, size_t len, char **words, int nwords,
                            const char *text, bool *files)
{
	const scene *s = editor_scene(sh->ed);
	char a[64];
	snprintf(a, sizeof a, "%.*s", (int)len, alt);
	if (strcmp(a, "@file") == 0) {
		*files = true;
	} else if (strcmp(a, "@scene") == 0) {
		complete_files(text, FILES_SCENE, add_file, l);
		listed_files = true;
	} else if (strcmp(a, "@output") == 0) {
		complete_files(text, FILES_OUTPUT, add_file, l);
		listed_files = true;
	} else if (strcmp(a, "@command") == 0) {
		add_commands(l, text);
	} else if (strcmp(a, "@setting") == 0) {
		for (size_t i = 0; i < settings_count; i++)
			add(l, settings_table[i].name, text);
	} else if (strcmp(a, "@value") == 0) {
		rt_error err;
		const setting_def *d = nwords >= 2 ? settings_find(words[1], &err) : NULL;
		for (int i = 0; d && i < settings_choices(d); i++)
			add(l, d->choices[i], text);
	} else if (strcmp(a, "@key") == 0) {
		const char *name, *kh;
		char buf[64];
		if (nwords >= 1 && strcmp(words[nwords - 1], "set") == 0)
			for (size_t i = 0; (name = rt_key_info(i, &kh)); i++) {
				snprintf(buf, sizeof buf, "%s=", name);
				add(l, buf, text);
			}
	} else if (strcmp(a, "@element") == 0) {
		const char *usage;
		for (size_t i = 0; rt_element(i, &usage); i++)
			add(l, rt_element(i, &usage), text);
	} else if (strcmp(a, "@object") == 0) {
		add_numbers(l, s->nobjs, text);
	} else if (strcmp(a, "@light") == 0) {
		add_numbers(l, s->nlights, text);
	} else if (strcmp(a, "@camera") == 0) {
		add_numbers(l, s->ncams, text);
	} else if (strcmp(a, "@ref") == 0) {
		int k = choice_pick("object|light|camera", words[nwords - 1]);
		add_numbers(l, k == 0 ? s->nobjs : k == 1 ? s->nlights : k == 2 ? s->ncams : 0, text);
	} else {
		add(l, a, text);
	}
}

char **complete_words(const shell *sh, const char *line, int start, const char *text, bool *files)
{
	*files = false;
	/* The words of the current command before the one being completed. */
	const char *cmd = line;
	for (int i = 0; i < start; i++)
		if (line[i] == ';')
			cmd = line + i + 1;
	size_t len = (size_t)(line + start - cmd);
	char *copy = strndup(cmd, len);
	if (!copy)
		return NULL;
	char *words[8];
	int nwords = 0;
	for (char *tok = strtok(copy, " \t"); tok && nwords < 8; tok = strtok(NULL, " \t"))
		words[nwords++] = tok;
	list l = {NULL, 0, 0, false};
	if (nwords == 0) {
		add_commands(&l, text);
	} else {
		char msg[256];
		const command *c = command_find(words[0], msg, sizeof msg);
		int arg = nwords - 1;
		const char *spec = c && arg < 3 ? c->complete[arg] : NULL;
		for (const char *p = spec; p && *p;) {
			size_t k = strcspn(p, "|");
			add_alternative(&l, sh, p, k, words, nwords, text, files);
			p += k;
			if (*p == '|')
				p++;
		}
	}
	free(copy);
	if (l.failed || l.n == 0) {
		for (size_t i = 0; i < l.n; i++)
			free(l.v[i]);
		free(l.v);
		return NULL;
	}
	return l.v;
}

/* --- readline glue --- */

static shell *completing;
static char **pending;
static size_t pending_at;

static char *next_candidate(const char *text, int state)
{
	(void)text;
	if (state == 0)
		pending_at = 0;
	if (!pending || !pending[pending_at])
		return NULL;
	return pending[pending_at++]; /* readline frees it */
}

static char **attempt(const char *text, int start, int end)
{
	(void)end;
	bool files = false;
	listed_files = false;
	/* Inside an open quote the word starts at the quote. */
	if (rl_completion_quote_character && start > 0)
		start--;
	pending = complete_words(completing, rl_line_buffer, start, text, &files);
	/* File names are quoted as the shell reads them ('my scenes/'). */
	rl_filename_completion_desired = rl_filename_quoting_desired = listed_files;
	if (files && !pending) {
		rl_attempted_completion_over = 0; /* readline completes file names */
		return NULL;
	}
	rl_attempted_completion_over = 1;
	if (!pending)
		return NULL;
	char **m = rl_completion_matches(text, next_candidate);
	/* A folder is not finished: no space after it. */
	if (m && !m[1] && m[0][0] && m[0][strlen(m[0]) - 1] == '/')
		rl_completion_append_character = '\0';
	/* Candidates not handed to readline are ours to free. */
	for (size_t i = pending_at; pending[i]; i++)
		free(pending[i]);
	free(pending);
	pending = NULL;
	return m;
}

void complete_install(shell *sh)
{
	completing = sh;
	rl_attempted_completion_function = attempt;
	rl_completer_word_break_characters = " \t;";
	/* A name with a blank or a quote is quoted, and completion goes on
	 * inside an open quote. */
	rl_completer_quote_characters = "'\"";
	rl_filename_quote_characters = " \t;'\"\\#";
	/* An ambiguous Tab lists the candidates at once (save out<Tab>: out.png,
	 * out.rt, ...); an inputrc may say otherwise. */
	rl_variable_bind("show-all-if-ambiguous", "on");
}
