/* rtsh — tab completion from the command table: command names, setting
 * names and values, object/light/camera numbers, subcommands, file names. */
#ifndef RTSH_COMPLETE_H
#define RTSH_COMPLETE_H

#include <stdbool.h>

#include "shell/shell.h"

/* The candidates for the word `text` that starts at offset `start` of
 * `line`: a NULL-terminated array of new strings (free each and the array),
 * or NULL with *files set when file names should be completed. */
char **complete_words(const shell *sh, const char *line, int start, const char *text, bool *files);
/* Installs completion into readline for sh. */
void complete_install(shell *sh);

#endif
