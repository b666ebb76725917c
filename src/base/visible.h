/* rtsh — text made safe to show on a terminal. */
#ifndef RTSH_VISIBLE_H
#define RTSH_VISIBLE_H

#include <stdbool.h>
#include <stddef.h>

/* Copies src into dst (size bytes, always terminated, cut at a whole
 * character) with every terminal control character made visible, as
 * cat -v writes it: C0 controls as ^@ .. ^_ (ESC is ^[), DEL as ^?, and the
 * C1 controls U+0080..U+009F (UTF-8 C2 80 .. C2 9F) as M-^@ .. M-^_. A file
 * name or a string of a model file then cannot move the cursor, recolour
 * or retitle the terminal, or write its clipboard (OSC 52). With lines,
 * '\n' and '\t' are kept (a command's output); without, they are shown
 * too (a one-line message). Returns dst. dst and src must not overlap. */
char *text_visible(char *dst, size_t size, const char *src, bool lines);

/* True when text_visible would change s. */
bool text_has_controls(const char *s, bool lines);

#endif
