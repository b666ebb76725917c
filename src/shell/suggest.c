/* rtsh — "did you mean …?" (suggest.h). */
#include "shell/suggest.h"

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rtsh/settings.h"
#include "shell/commands.h"

/* Words longer than this are not typos of any name. */
#define SUGGEST_MAX_LEN 64

size_t suggest_distance(const char *a, const char *b)
{
	size_t n = strlen(a), m = strlen(b);
	if (n > SUGGEST_MAX_LEN || m > SUGGEST_MAX_LEN)
		return n > m ? n : m;
	/* Three rows of the dynamic programme: i-2, i-1 and i. */
	size_t rows[3][SUGGEST_MAX_LEN + 1];
	size_t *pp = rows[0], *prev = rows[1], *cur = rows[2];
	for (size_t j = 0; j <= m; j++)
		prev[j] = j;
	for (size_t i = 1; i <= n; i++) {
		cur[0] = i;
		int ca = tolower((unsigned char)a[i - 1]);
		for (size_t j = 1; j <= m; j++) {
			int cb = tolower((unsigned char)b[j - 1]);
			size_t best = prev[j - 1] + (ca != cb);
			if (prev[j] + 1 < best)
				best = prev[j] + 1;
			if (cur[j - 1] + 1 < best)
				best = cur[j - 1] + 1;
			if (i > 1 && j > 1 && ca == tolower((unsigned char)b[j - 2]) &&
			    tolower((unsigned char)a[i - 2]) == cb && pp[j - 2] + 1 < best)
				best = pp[j - 2] + 1;
			cur[j] = best;
		}
		size_t *t = pp;
		pp = prev;
		prev = cur;
		cur = t;
	}
	return prev[m];
}

/* The largest distance worth a suggestion for a word of len bytes. */
static size_t allowed(size_t len)
{
	size_t d = len <= 5 ? 1 : len <= 9 ? 2 : 3;
	return d < len ? d : len - 1;
}

/* The nearest candidate seen so far. */
typedef struct nearest {
	const char *word;
	size_t len, d;
	const char *best;  /* NULL: none yet */
	size_t best_len;   /* bytes of best that name it (for "a|b" and "a b" lists) */
} nearest;

static nearest nearest_start(const char *word)
{
	return (nearest){word, strlen(word), (size_t)-1, NULL, 0};
}

static void nearest_try(nearest *n, const char *cand, size_t len)
{
	char c[SUGGEST_MAX_LEN + 1];
	if (len == 0 || len > SUGGEST_MAX_LEN || n->len == 0 || n->len > SUGGEST_MAX_LEN)
		return;
	memcpy(c, cand, len);
	c[len] = '\0';
	size_t d = suggest_distance(n->word, c);
	if (d < n->d) {
		n->d = d;
		n->best = cand;
		n->best_len = len;
	}
}

static bool nearest_ok(const nearest *n)
{
	return n->best && n->d <= allowed(n->len);
}

const char *suggest_closest(const char *word, const char *const *cands, size_t n)
{
	nearest near = nearest_start(word);
	for (size_t i = 0; i < n; i++)
		if (cands[i])
			nearest_try(&near, cands[i], strlen(cands[i]));
	return nearest_ok(&near) ? near.best : NULL;
}

/* Every name in a list separated by `sep`. */
static void nearest_list(nearest *n, const char *list, char sep)
{
	char seps[2] = {sep, '\0'};
	for (const char *p = list; p && *p;) {
		size_t k = strcspn(p, seps);
		nearest_try(n, p, k);
		p += k;
		while (*p == sep)
			p++;
	}
}

bool suggest_choice(const char *choices, const char *word, char *buf, size_t size)
{
	nearest near = nearest_start(word);
	nearest_list(&near, choices, '|');
	if (!nearest_ok(&near))
		return false;
	snprintf(buf, size, "%.*s", (int)near.best_len, near.best);
	return true;
}

bool suggest_command_in(const command *table, size_t count, const char *word, char *buf, size_t size)
{
	/* Names first, so that a name wins a tie with an alias. */
	nearest near = nearest_start(word);
	for (size_t i = 0; i < count; i++)
		nearest_try(&near, table[i].name, strlen(table[i].name));
	for (size_t i = 0; i < count; i++)
		nearest_list(&near, table[i].aliases, ' ');
	if (!nearest_ok(&near))
		return false;
	snprintf(buf, size, "%.*s", (int)near.best_len, near.best);
	return true;
}

const char *suggest_setting(const char *word)
{
	nearest near = nearest_start(word);
	for (size_t i = 0; i < settings_count; i++)
		nearest_try(&near, settings_table[i].name, strlen(settings_table[i].name));
	return nearest_ok(&near) ? near.best : NULL;
}
