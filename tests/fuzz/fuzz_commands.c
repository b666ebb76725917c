/* rtsh — libFuzzer target: the command language, as `rtsh -c` runs it.
 *
 * Each input is a command file run by a fresh script-mode shell on the
 * built-in scene, inside a private temporary folder that is emptied before
 * every input. Inputs holding '/', '~' or '$' are skipped, so every path a
 * command names stays inside that folder (rtsh as root must not write over
 * the machine). The shell starts at 32x18 pixels, 1 sample, 1 thread;
 * a watchdog cancels any render still running after a second (the cancel
 * flag Ctrl-C sets), so `set resolution 16384x16384; render` costs a second,
 * not an hour; and memory requests are held to 256 MiB (mem_set_limit), so a
 * request beyond it must be refused with a message, as it would be beyond
 * the machine's memory.
 */
#include <dirent.h>
#include <fcntl.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "rtsh/memory.h"
#include "rtsh/settings.h"
#include "shell/commands.h"
#include "shell/shell.h"

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char sandbox[] = "/tmp/rtsh-fuzz-cmd-XXXXXX";
static rtsh_options opts;
static shell *_Atomic running;        /* the shell the watchdog may cancel */
static _Atomic long long started_ms;  /* when its input started */

static long long now_ms(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (long long)t.tv_sec * 1000 + t.tv_nsec / 1000000;
}

static void *watchdog(void *arg)
{
	(void)arg;
	for (;;) {
		struct timespec tick = {0, 50 * 1000000};
		nanosleep(&tick, NULL);
		shell *sh = atomic_load(&running);
		if (sh && now_ms() - atomic_load(&started_ms) > 1000)
			atomic_store(&sh->cancel, true);
	}
	return NULL;
}

static void add_setting(const char *name, const char *value)
{
	rt_error err;
	const setting_def *def = settings_find(name, &err);
	if (!def)
		abort();
	opts.settings[opts.nsettings++] = (option_setting){def, value};
}

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
	(void)argc, (void)argv;
	if (!mkdtemp(sandbox) || chdir(sandbox) != 0)
		abort();
	/* Command output is noise here; errors still go to stderr. */
	int null = open("/dev/null", O_RDWR);
	dup2(null, STDIN_FILENO);
	dup2(null, STDOUT_FILENO);
	close(null);
	opts.quiet = true;
	add_setting("resolution", "32x18");
	add_setting("samples", "1");
	add_setting("threads", "1");
	mem_set_limit((size_t)256 << 20);
	pthread_t t;
	if (pthread_create(&t, NULL, watchdog, NULL) != 0)
		abort();
	pthread_detach(t);
	return 0;
}

/* Empties the sandbox (it holds only what commands saved: no folders). */
static void empty_sandbox(void)
{
	DIR *d = opendir(".");
	if (!d)
		abort();
	struct dirent *e;
	while ((e = readdir(d)))
		if (strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0)
			unlink(e->d_name);
	closedir(d);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	if (size > 4096 || memchr(data, '/', size) || memchr(data, '~', size) || memchr(data, '$', size) ||
	    memchr(data, '\0', size))
		return 0;
	char *text = malloc(size + 1);
	if (!text)
		abort();
	memcpy(text, data, size);
	text[size] = '\0';
	empty_sandbox();
	static shell sh;
	if (shell_init(&sh, &opts, -1)) {
		sh.interactive = false;
		command_table_install(&sh);
		shell_sig_int = 0;
		atomic_store(&started_ms, now_ms());
		atomic_store(&running, &sh);
		shell_run_text(&sh, text, "-c", true);
		atomic_store(&running, NULL);
		shell_free(&sh);
	}
	free(text);
	return 0;
}
