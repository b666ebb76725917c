/* rtsh — terminal capabilities (caps.h), from the environment and terminfo. */
#include "term/caps.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <term.h>
#include <time.h>
#include <unistd.h>

extern char **environ;

static bool env_is(const char *name, const char *a, const char *b)
{
	const char *v = getenv(name);
	return v && (strcmp(v, a) == 0 || (b && strcmp(v, b) == 0));
}

static bool term_usable(void)
{
	const char *t = getenv("TERM");
	return t && *t && strcmp(t, "dumb") != 0;
}

bool caps_screen_ok(int fd)
{
	return isatty(fd) && term_usable();
}

/* The depth terminfo gives for $TERM, or PALETTE_NONE when it does not know
 * the terminal. */
static frame_palette terminfo_palette(int fd)
{
	int status = 0;
	if (setupterm(NULL, fd, &status) != 0)
		return PALETTE_16; /* a terminal with no entry: assume the basic colours */
	frame_palette p = PALETTE_NONE;
	char rgb[] = "RGB", tc[] = "Tc", colors[] = "colors";
	int n = tigetnum(colors);
	if (tigetflag(rgb) > 0 || tigetflag(tc) > 0)
		p = PALETTE_TRUECOLOR;
	else if (n >= 256)
		p = PALETTE_256;
	else if (n >= 8)
		p = PALETTE_16;
	del_curterm(cur_term);
	return p;
}

bool caps_features_rgb(const char *features)
{
	const char *p = features;
	while (*p) {
		size_t n = strcspn(p, ",\n");
		if (n == 3 && strncmp(p, "RGB", 3) == 0)
			return true;
		p += n;
		if (*p)
			p++;
	}
	return false;
}

static double mono_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* tmux's client terminal features (caps.h), asked once: 1 RGB, 0 not (or
 * no answer within 0.5 s, or no tmux to ask). */
static int tmux_rgb(void)
{
	static int known = -1;
	if (known >= 0)
		return known;
	known = 0;
	int p[2];
	if (pipe(p) != 0)
		return known;
	posix_spawn_file_actions_t fa;
	posix_spawn_file_actions_init(&fa);
	posix_spawn_file_actions_addopen(&fa, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
	posix_spawn_file_actions_adddup2(&fa, p[1], STDOUT_FILENO);
	posix_spawn_file_actions_addopen(&fa, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
	posix_spawn_file_actions_addclose(&fa, p[0]);
	posix_spawn_file_actions_addclose(&fa, p[1]);
	char *argv[] = {"tmux", "display-message", "-p", "#{client_termfeatures}", NULL};
	pid_t pid;
	int rc = posix_spawnp(&pid, "tmux", &fa, NULL, argv, environ);
	posix_spawn_file_actions_destroy(&fa);
	close(p[1]);
	if (rc != 0) {
		close(p[0]);
		return known;
	}
	char buf[1024];
	size_t len = 0;
	double end = mono_now() + 0.5;
	for (;;) {
		int left = (int)((end - mono_now()) * 1000);
		struct pollfd pf = {p[0], POLLIN, 0};
		if (left <= 0 || poll(&pf, 1, left) <= 0)
			break;
		ssize_t k = read(p[0], buf + len, sizeof buf - 1 - len);
		if (k <= 0)
			break;
		len += (size_t)k;
		if (len == sizeof buf - 1)
			break;
	}
	buf[len] = '\0';
	close(p[0]);
	if (waitpid(pid, NULL, WNOHANG) == 0) { /* still running: not waited for */
		kill(pid, SIGKILL);
		waitpid(pid, NULL, 0);
	}
	known = caps_features_rgb(buf);
	return known;
}

frame_palette caps_palette(color_mode mode, int fd)
{
	switch (mode) {
	case COLOR_TRUECOLOR:
		return PALETTE_TRUECOLOR;
	case COLOR_256:
		return PALETTE_256;
	case COLOR_16:
		return PALETTE_16;
	case COLOR_NONE:
		return PALETTE_NONE;
	case COLOR_AUTO:
		break;
	}
	const char *nc = getenv("NO_COLOR");
	if (!isatty(fd) || (nc && *nc) || !term_usable())
		return PALETTE_NONE;
	if (env_is("COLORTERM", "truecolor", "24bit"))
		return PALETTE_TRUECOLOR;
	const char *tmux = getenv("TMUX");
	if (tmux && *tmux && tmux_rgb())
		return PALETTE_TRUECOLOR;
	return terminfo_palette(fd);
}

bool caps_raw_modes(int fd, cc_t vmin, int when, struct termios *saved)
{
	if (tcgetattr(fd, saved) != 0)
		return false;
	struct termios raw = *saved;
	raw.c_lflag &= ~(tcflag_t)(ICANON | ECHO);
	raw.c_cc[VMIN] = vmin;
	raw.c_cc[VTIME] = 0;
	tcsetattr(fd, when, &raw);
	return true;
}
