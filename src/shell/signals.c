/* rtsh — signals (signals.h). */
#include "shell/signals.h"

#include <errno.h>
#include <string.h>
#include <termios.h>
#include <unistd.h>

#include "rtsh/atomic.h"
#include "term/screen.h"

volatile sig_atomic_t shell_sig_int, shell_sig_term, shell_sig_winch, shell_sig_cont;

static atomic_bool *volatile cancel_flag;
static volatile sig_atomic_t wake_write = -1;
static volatile sig_atomic_t modes_fd = -1;
static struct termios start_modes;

static void poke(void)
{
	int fd = wake_write;
	if (fd >= 0) {
		ssize_t r = write(fd, "s", 1);
		(void)r; /* a full pipe already holds a wake-up */
	}
}

static void cancel_render(void)
{
	atomic_bool *c = cancel_flag;
	if (c)
		atomic_store(c, true);
}

void signals_set_cancel(atomic_bool *cancel)
{
	cancel_flag = cancel;
}

/* Ctrl-Z: the terminal back as it was, stop; continued: as we had it. */
static void stop_now(void)
{
	int fd = modes_fd;
	struct termios ours;
	int have_ours = fd >= 0 && tcgetattr(fd, &ours) == 0;
	screen_restore_async();
	if (fd >= 0)
		tcsetattr(fd, TCSADRAIN, &start_modes);
	raise(SIGSTOP);
	/* ... continued. */
	if (have_ours)
		tcsetattr(fd, TCSADRAIN, &ours);
	screen_reenter_async();
	shell_sig_cont = 1;
}

static void on_signal(int sig)
{
	int saved = errno;
	switch (sig) {
	case SIGINT:
		shell_sig_int = 1;
		cancel_render();
		break;
	case SIGWINCH:
		shell_sig_winch = 1;
		break;
	case SIGTSTP:
		stop_now();
		break;
	case SIGCONT:
		shell_sig_cont = 1;
		break;
	default: /* SIGTERM, SIGHUP, SIGQUIT */
		shell_sig_term = sig;
		cancel_render();
		break;
	}
	poke();
	errno = saved;
}

static void on_crash(int sig)
{
	atomic_cleanup_on_signal(); /* a save in progress leaves no temporary file */
	screen_restore_async();
	int fd = modes_fd;
	if (fd >= 0)
		tcsetattr(fd, TCSANOW, &start_modes);
	/* SA_RESETHAND made the action the default again: the signal kills us
	 * (with a core dump) once this handler returns. */
	raise(sig);
}

static const int handled[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGWINCH, SIGTSTP, SIGCONT};
/* The crashes, then every other signal whose default action ends the
 * process and that rtsh has no use for (signal(7)): they too give the
 * terminal back before they end it. SIGPIPE is not among them: a write to a
 * closed pipe fails with EPIPE where rtsh writes to pipes (atomic.c). */
static const int crashes[] = {
	SIGSEGV, SIGBUS,  SIGFPE,    SIGILL,  SIGABRT, SIGTRAP, SIGSYS, SIGXCPU, SIGXFSZ,
	SIGUSR1, SIGUSR2, SIGALRM, SIGVTALRM, SIGPROF, SIGIO,   SIGPWR,
#ifdef SIGSTKFLT
	SIGSTKFLT,
#endif
};
#define NHANDLED (sizeof handled / sizeof handled[0])
#define NCRASHES (sizeof crashes / sizeof crashes[0])
/* The real-time signals end the process by default too. */
#define NRT 64
static struct sigaction old_handled[NHANDLED], old_crashes[NCRASHES], old_rt[NRT], old_int;
static int rt_first, rt_count;

void signals_interactive_begin(int tty_fd, int wake_fd)
{
	shell_sig_int = shell_sig_term = shell_sig_winch = shell_sig_cont = 0;
	modes_fd = -1;
	if (tty_fd >= 0 && tcgetattr(tty_fd, &start_modes) == 0)
		modes_fd = tty_fd;
	wake_write = wake_fd;
	struct sigaction sa;
	memset(&sa, 0, sizeof sa);
	sigemptyset(&sa.sa_mask);
	sa.sa_handler = on_signal;
	for (size_t i = 0; i < NHANDLED; i++)
		sigaction(handled[i], &sa, &old_handled[i]);
	sa.sa_handler = on_crash;
	sa.sa_flags = SA_RESETHAND;
	for (size_t i = 0; i < NCRASHES; i++)
		sigaction(crashes[i], &sa, &old_crashes[i]);
	rt_first = SIGRTMIN;
	rt_count = SIGRTMAX - SIGRTMIN + 1;
	if (rt_count > NRT)
		rt_count = NRT;
	for (int i = 0; i < rt_count; i++)
		sigaction(rt_first + i, &sa, &old_rt[i]);
}

void signals_interactive_end(void)
{
	for (size_t i = 0; i < NHANDLED; i++)
		sigaction(handled[i], &old_handled[i], NULL);
	for (size_t i = 0; i < NCRASHES; i++)
		sigaction(crashes[i], &old_crashes[i], NULL);
	for (int i = 0; i < rt_count; i++)
		sigaction(rt_first + i, &old_rt[i], NULL);
	wake_write = -1;
	modes_fd = -1;
}

void signals_script_begin(void)
{
	struct sigaction sa;
	memset(&sa, 0, sizeof sa);
	sigemptyset(&sa.sa_mask);
	sa.sa_handler = on_signal;
	sigaction(SIGINT, &sa, &old_int);
}

void signals_script_end(void)
{
	sigaction(SIGINT, &old_int, NULL);
}
