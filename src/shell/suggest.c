/* rtsh — "did you mean …?" (suggest.h). */
#include "shell/suggest.h"

#include <stdio.h>
#include <string.h>

#include "base/nearest.h"
#include "rtsh/settings.h"
#include "shell/commands.h"

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
