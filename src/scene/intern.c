/* rtsh — interned strings (scene.h, rt_intern): file names in objects.
 *
 * A hash set of strings that are never freed, guarded by a mutex: the few
 * model and texture names a session sees cost a few bytes each, and in
 * exchange an object with a file name is still a plain value. */
#include <pthread.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "rtsh/scene.h"

static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static char **set;
static size_t nset, cap; /* cap a power of two, at most half full */

static uint64_t hash(const char *s, size_t n)
{
	uint64_t h = 1469598103934665603ull; /* FNV-1a */
	for (size_t i = 0; i < n; i++)
		h = (h ^ (unsigned char)s[i]) * 1099511628211ull;
	return h;
}

static bool insert(char **tab, size_t c, char *s)
{
	size_t i = (size_t)hash(s, strlen(s)) & (c - 1);
	while (tab[i])
		i = (i + 1) & (c - 1);
	tab[i] = s;
	return true;
}

const char *rt_intern(const char *s, size_t n)
{
	if (memchr(s, '\0', n))
		n = strlen(s);
	pthread_mutex_lock(&lock);
	const char *out = NULL;
	if (cap) {
		size_t i = (size_t)hash(s, n) & (cap - 1);
		while (set[i]) {
			if (strlen(set[i]) == n && memcmp(set[i], s, n) == 0) {
				out = set[i];
				break;
			}
			i = (i + 1) & (cap - 1);
		}
	}
	if (!out && 2 * (nset + 1) > cap) {
		size_t c = cap ? 2 * cap : 64;
		char **t = calloc(c, sizeof *t);
		if (t) {
			for (size_t i = 0; i < cap; i++)
				if (set[i])
					insert(t, c, set[i]);
			free(set);
			set = t;
			cap = c;
		}
	}
	if (!out && 2 * (nset + 1) <= cap) {
		char *d = malloc(n + 1);
		if (d) {
			memcpy(d, s, n);
			d[n] = '\0';
			insert(set, cap, d);
			nset++;
			out = d;
		}
	}
	pthread_mutex_unlock(&lock);
	return out;
}
