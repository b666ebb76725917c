/* rtsh — the output scheduler: the bytes rtsh's screen sends to the
 * terminal, paced by the terminal's own answers.
 *
 * Text (the status line, the screen's frame, messages) is written at once.
 * The picture is an encoder (encoder.h) whose damage is sent in slices:
 * after each slice a Device Status Report query, CSI 5 n, which the
 * terminal answers with CSI 0 n once it has read everything before it
 * (after the slice that ends a picture, DA1 instead: answered in order
 * too, it tells the far side a picture is whole). The
 * bytes sent and not yet answered stay within a window: what the link
 * carries in a round trip plus QUEUE_SECONDS of it, however deep the
 * buffers between rtsh and the terminal are (sshd, the network). So the
 * link never idles waiting for an answer, and text (echo, the prompt)
 * never waits behind more than QUEUE_SECONDS of picture. Slices are about
 * SLICE_SECONDS of the link; the throughput and round-trip time are
 * measured on the answers. A picture that changes while slices are out is
 * not finished: the next slice starts from what the terminal really shows
 * (the encoder's damage).
 *
 * On a slow link a refinement pass is lossy: cells whose colour moved by at
 * most TERMOUT_JND levels stay; once no bigger change is left, the exact
 * remainder goes while the link has nothing better to carry. The final
 * picture is exact.
 *
 * At start the scheduler asks (termout_probe): DECRQSS of a 24-bit SGR and
 * XTGETTCAP of RGB and Tc (is there truecolor?), then DA1 (CSI c), which
 * every terminal answers, as the fence: once DA1's answer is in, the
 * questions before it were answered or never will be. No picture is sent
 * before that. A terminal that answers nothing within PROBE_TIMEOUT (or a
 * slice within its timeout) gets today's unpaced output, and the
 * scheduler says so once (termout_notice).
 *
 * The answers come in on the terminal's input, mixed with keys:
 * termout_input takes them out and gives back the keys alone.
 *
 * Escape sequences sent here:
 *   \e[5n                  DSR: status report (answer \e[0n), after a slice
 *   \e[c                   DA1: primary device attributes (answer \e[?...c):
 *                          the start-up fence, and after a picture's last slice
 *   \e7 \e[48;2;1;2;3m \eP$qm\e\\ \e[m \e8
 *                          DECRQSS of the SGR with a 24-bit background
 *                          (answer \eP1$r...48:2:...1:2:3m\e\\ when kept)
 *   \eP+q524742;5463\e\\   XTGETTCAP of RGB and Tc (answer \eP1+r...\e\\)
 */
#ifndef RTSH_OUT_H
#define RTSH_OUT_H

#include <stdbool.h>
#include <stddef.h>

#include "base/abuf.h"
#include "term/encoder.h"
#include "term/pixels.h"

#define TERMOUT_SLICE_SECONDS 0.05
#define TERMOUT_QUEUE_SECONDS 0.08
#define TERMOUT_PROBE_TIMEOUT 2.0
#define TERMOUT_SLOW_BPS 2e6
#define TERMOUT_JND 4
#define TERMOUT_UNPACED_PART (32u << 10)

typedef struct termout termout;

typedef enum termout_state {
	TERMOUT_IDLE,     /* no probe sent: unpaced */
	TERMOUT_PROBING,  /* waiting for the start-up answers */
	TERMOUT_PACED,    /* slices wait for the terminal's answers */
	TERMOUT_UNPACED,  /* the terminal did not answer: whole updates */
} termout_state;

/* Figures for tests and the status of a session. */
typedef struct termout_stats {
	double rtt;        /* seconds, the smallest round trip seen (0: none yet) */
	double bps;        /* bytes a second the link carries (0: not known) */
	long slices;       /* picture slices sent */
	long pictures;     /* pictures sent whole (their changes beyond the tolerance) */
	long answers;      /* answers taken out of the input */
	size_t in_flight;  /* picture bytes sent and not yet answered */
} termout_stats;

/* A scheduler writing to fd; NULL when out of memory. */
termout *termout_new(int fd);
void termout_free(termout *o);

/* Writes text now (it goes ahead of every picture slice not yet sent). */
void termout_text(termout *o, const void *b, size_t n);
/* The picture to send (NULL: none); the scheduler does not own it. */
void termout_set_picture(termout *o, encoder *e);
/* The picture's encoder was given a new picture (screen_picture): the
 * slice that sends the last of its changes ends with DA1 (counted in
 * termout_stats.pictures). */
void termout_picture_new(termout *o);
/* Drops the picture's changes not yet sent (Ctrl-C): the terminal keeps
 * what it shows. */
void termout_drop_picture(termout *o);
/* True while the terminal does not show the newest picture yet. */
bool termout_picture_pending(const termout *o);
/* Whether the picture is final (the render is done) or a refinement pass.
 * On a slow link (paced, under TERMOUT_SLOW_BPS) a refinement pass is sent
 * with lossy damage first: cells whose colour moved by at most TERMOUT_JND
 * sRGB levels in every channel wait until no bigger change is left; a
 * final picture is exact. */
void termout_picture_final(termout *o, bool final);

/* Also asks, in the next termout_probe, what pixels the terminal shows
 * (term/pixels.h: the kitty graphics query, XTSMGRAPHICS, the cell size);
 * the answers are kept for termout_pixels. */
void termout_ask_pixels(termout *o, bool on);
/* Also asks XTVERSION (the terminal's name, for `symbols auto`; asked
 * anyway with the pixel questions), kept in termout_pixels()->version. */
void termout_ask_version(termout *o, bool on);
/* What the terminal said about pixels (all false/0 until it answered). */
const pixels_caps *termout_pixels(const termout *o);
/* Sends the start-up questions (the truecolor ones when ask_color) and
 * the DA1 fence; pacing starts when the fence is answered. */
void termout_probe(termout *o, bool ask_color, double now);
/* Takes the answers out of bytes read from the terminal and appends the
 * rest (keys) to keys. An escape sequence cut at the end of the bytes is
 * held while an answer is awaited (until more comes, or termout_pump
 * gives it up as keys after a short while). */
void termout_input(termout *o, const char *b, size_t n, double now, abuf *keys);
/* Sends what the pacing allows of the picture, checks the time-outs and
 * gives up held key bytes that waited too long (appended to keys). */
void termout_pump(termout *o, double now, abuf *keys);
/* Seconds until termout_pump has something to do without new input; < 0
 * when nothing. */
double termout_wait(const termout *o, double now);
/* True while answers are awaited. */
bool termout_awaiting(const termout *o);
/* True when, not paced, a picture part waits for the terminal to take it:
 * the event loop calls termout_pump when the fd is writable (each part is
 * at most TERMOUT_UNPACED_PART bytes, so keys are read between parts). */
bool termout_want_write(const termout *o);
/* The terminal's fd the scheduler writes to. */
int termout_fd(const termout *o);
/* Gives up a cut escape sequence held (appended to keys). */
void termout_release_held(termout *o, abuf *keys);

/* The loop was busy (a command ran) and did not read the answers in time:
 * those awaited now tell nothing about the link. */
void termout_stale(termout *o, double now);
/* Waits up to max_seconds for every awaited answer, reading in_fd (keys
 * read meanwhile are appended to keys): before a part of rtsh that reads
 * the terminal on its own (key mode, the pager). */
void termout_settle(termout *o, int in_fd, double max_seconds, abuf *keys);

termout_state termout_get_state(const termout *o);
/* After the probe: 1 when the terminal said it has 24-bit colour, 0 when
 * it did not (or was not asked). */
int termout_truecolor(const termout *o);
/* A message to show once (the fall-back to unpaced output), then NULL. */
const char *termout_notice(termout *o);
termout_stats termout_get_stats(const termout *o);

#endif
