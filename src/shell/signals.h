/* rtsh — signals: the one place that installs handlers and owns the flags
 * they set. Handlers only set a flag, set the cancel flag of a render and
 * write a byte to the wake-up pipe, with three exceptions that must act at
 * once, wherever the main thread is (at the prompt, in `render`, in `view`,
 * in the pager):
 *   - SIGTSTP (Ctrl-Z) gives the terminal back (every mode reset, the
 *     terminal modes of the start), stops the process, and on SIGCONT puts
 *     back the modes and the alternate screen; the loops repaint;
 *   - crash signals (SIGSEGV SIGBUS SIGFPE SIGILL SIGABRT), and every
 *     other signal whose default ends the process (SIGUSR1, SIGALRM,
 *     SIGXCPU, the real-time signals...; not SIGPIPE), give the terminal
 *     back and let the signal kill the process.
 * SIGTERM, SIGHUP and SIGQUIT cancel the render in flight and end the
 * loops, which restore the terminal on their way out; the exit status is
 * 128 + the signal. Nothing catches SIGKILL: `reset` repairs the terminal.
 */
#ifndef RTSH_SIGNALS_H
#define RTSH_SIGNALS_H

#include <signal.h>
#include <stdatomic.h>

/* Set by the handlers, cleared by the loops that act on them. */
extern volatile sig_atomic_t shell_sig_int;   /* Ctrl-C */
extern volatile sig_atomic_t shell_sig_term;  /* SIGTERM, SIGHUP or SIGQUIT: its number */
extern volatile sig_atomic_t shell_sig_winch; /* the terminal was resized */
extern volatile sig_atomic_t shell_sig_cont;  /* continued after a stop: repaint */

/* The flag SIGINT, SIGTERM, SIGHUP and SIGQUIT set to stop a render (NULL:
 * none). */
void signals_set_cancel(atomic_bool *cancel);

/* The interactive handlers (every signal above); tty_fd's terminal modes,
 * read now, are the ones given back on a stop or a crash; wake_fd (-1:
 * none) gets a byte on every signal. */
void signals_interactive_begin(int tty_fd, int wake_fd);
/* Puts back the handlers that were there before. */
void signals_interactive_end(void);

/* Scripts: SIGINT stops the render and then the script. */
void signals_script_begin(void);
void signals_script_end(void);

#endif
