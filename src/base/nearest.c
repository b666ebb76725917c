/* rtsh — the nearest name to a mistyped word (nearest.h). */
#include "base/nearest.h"

#include <ctype.h>
#include <string.h>

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

nearest nearest_start(const char *word)
{
	return (nearest){word, strlen(word), (size_t)-1, NULL, 0};
}

void nearest_try(nearest *n, const char *cand, size_t len)
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

bool nearest_ok(const nearest *n)
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
