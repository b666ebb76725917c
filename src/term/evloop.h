/* rtsh — the event loop: the one place where rtsh waits on the terminal.
 *
 * Sources it waits on, in one poll():
 *   - the terminal's input: keys, and the answers to rtsh's queries (the
 *     output scheduler, out.h, takes those out: they never reach a key
 *     reader);
 *   - the wake pipe: the render thread writes a byte when a picture is
 *     ready, the signal handlers when a signal came (the flags are the
 *     caller's: src/shell/signals.h);
 *   - the output scheduler's deadlines (the next picture slice, time-outs,
 *     a cut escape sequence held) and, when it has a picture part to write
 *     without pacing, the terminal's writability;
 *   - the caller's own timer: the `timeout` of evloop_wait.
 * Every turn the scheduler is pumped: the answers read let the next slice
 * go at once, whoever is waiting.
 *
 * Use (the shell, the pager, key mode):
 *
 *     evloop *l = evloop_new(STDIN_FILENO, wake_fd);
 *     evloop_set_out(l, scr->out);           // or NULL: keys only
 *     for (;;) {
 *         int ev = evloop_wait(l, my_timeout); // seconds, < 0: none
 *         if (ev & EVLOOP_WAKE)  ...check the signal flags, take pictures...
 *         int c;
 *         while ((c = evloop_getc(l)) >= 0) ...a key byte...
 *         if (evloop_eof(l)) break;
 *     }
 *
 * Key bytes come in order, answers taken out; evloop_key reads one whole
 * key (a byte, or an escape sequence) for readers without their own
 * decoder; evloop_getc_wait blocks for one byte (readline's
 * rl_getc_function). Events seen while a reader blocked inside the loop
 * (a wake-up, a signal) are kept and given by the next evloop_wait.
 *
 * A caller that was busy between two waits for longer than
 * EVLOOP_BUSY_SECONDS (a command ran) makes the answers awaited meanwhile
 * stale: they tell nothing about the link (termout_stale).
 *
 * The loop never writes to the terminal itself; it is single-threaded (the
 * main thread's).
 */
#ifndef RTSH_EVLOOP_H
#define RTSH_EVLOOP_H

#include <stdbool.h>
#include <stddef.h>

#include "term/out.h"

#define EVLOOP_BUSY_SECONDS 0.05

/* What evloop_wait saw (bits). */
enum {
	EVLOOP_KEYS = 1,   /* key bytes wait (evloop_getc), or the input ended */
	EVLOOP_WAKE = 2,   /* the wake pipe had bytes, or a signal came (EINTR) */
	EVLOOP_TIMER = 4,  /* the caller's timeout passed */
	EVLOOP_ANSWER = 8, /* the terminal answered a query (the scheduler's state may have moved) */
};

typedef struct evloop evloop;

/* A loop on the terminal's input in_fd and the wake pipe's read end
 * wake_fd (< 0: none; it should be non-blocking). NULL when out of memory. */
evloop *evloop_new(int in_fd, int wake_fd);
void evloop_free(evloop *l);

/* The output scheduler whose answers are taken out of the input and which
 * is pumped every turn (NULL: none; the input is all keys). */
void evloop_set_out(evloop *l, termout *o);
termout *evloop_out(const evloop *l);

/* Called while a reader blocks inside the loop (evloop_getc_wait,
 * evloop_key) after a wake-up: true makes the reader return at once with
 * no key (a signal the caller must serve came). NULL: never. */
void evloop_set_interrupt(evloop *l, bool (*interrupted)(void *ctx), void *ctx);

/* Waits until something happens, at most `timeout` seconds (< 0: no limit
 * of the caller's; 0: only looks), and returns what happened (EVLOOP_
 * bits; 0 when only the scheduler's own business was done). Returns at
 * once with EVLOOP_KEYS while key bytes wait unread. */
int evloop_wait(evloop *l, double timeout);

/* The next key byte (0..255), or -1 when none waits. Never blocks. */
int evloop_getc(evloop *l);
/* The next key byte, waiting for one; -1 at the end of the input or when
 * the interrupt hook said so. */
int evloop_getc_wait(evloop *l);
/* One whole key into seq (NUL-terminated): a byte, a UTF-8 character, or
 * an escape sequence (CSI ... final, SS3 x, Alt+key), waiting up to
 * esc_wait seconds for the rest of a sequence cut short. Waits for the key.
 * Returns its length; 0 at the end of the input or when the interrupt hook
 * said so. */
size_t evloop_key(evloop *l, char *seq, size_t size, double esc_wait);
/* Gives back the last n bytes evloop_key returned, to be read again (by
 * the next reader: readline after the pager). Only right after that
 * evloop_key, with n at most its length. */
void evloop_unread(evloop *l, size_t n);
/* True while key bytes wait. */
bool evloop_has_keys(const evloop *l);
/* True once the input ended (and every key byte was read). */
bool evloop_eof(const evloop *l);

/* Lets the scheduler send what its pacing allows now (after a new
 * picture), without waiting. */
void evloop_pump(evloop *l);
/* The terminal's input fd (for its modes: the loop does not set any). */
int evloop_in_fd(const evloop *l);

/* Waits up to max_seconds for every answer the scheduler awaits (keys
 * read meanwhile are kept): before a part of rtsh that reads the terminal
 * on its own. */
void evloop_settle(evloop *l, double max_seconds);

/* Seconds on a monotonic clock (the loop's and the scheduler's time). */
double evloop_now(void);

#endif
