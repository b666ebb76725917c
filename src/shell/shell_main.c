/* rtsh — the shell's entry (options.h): a script (-c, -f, standard input)
 * or the interactive shell, or one then the other. Above every other file
 * of src/shell: it runs the script reader and the readline loop, which run
 * the commands. */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "shell/commands.h"
#include "shell/options.h"
#include "shell/shell.h"
#include "shell/signals.h"
#include "term/caps.h"

int shell_main(const rtsh_options *o)
{
	bool tty_in = isatty(STDIN_FILENO);
	bool script = o->commands || o->file || !tty_in;
	bool then_interactive = !script || (o->interactive && tty_in);
	if (o->interactive && !tty_in) /* it was dropped without a word */
		fprintf(stderr, "rtsh: -i: standard input is not a terminal: no interactive shell after the commands "
		                "(warning)\n");
	bool screen_ok = then_interactive && caps_screen_ok(STDOUT_FILENO);
	/* --turntable without -o turns the scene in the full screen: with no
	 * terminal to show it, it was dropped without a word (status 0). */
	if (o->turntable && !screen_ok) {
		fprintf(stderr,
		        "rtsh: --turntable turns the scene on the terminal's full screen, and %s; expected the "
		        "interactive shell on a terminal, or --turntable FRAMES -o OUT for files\n",
		        !then_interactive ? (tty_in ? "-c or -f without -i never opens it" : "standard input is not a terminal")
		                          : "standard output is not a terminal that shows pictures");
		return 2;
	}
	int wake[2] = {-1, -1};
	if (then_interactive) {
		if (pipe(wake) != 0) {
			fprintf(stderr, "rtsh: cannot make a pipe: %s\n", strerror(errno));
			return 1;
		}
		for (int i = 0; i < 2; i++) {
			fcntl(wake[i], F_SETFL, fcntl(wake[i], F_GETFL) | O_NONBLOCK);
			fcntl(wake[i], F_SETFD, FD_CLOEXEC);
		}
	}
	shell sh;
	if (!shell_init(&sh, o, wake[1])) {
		if (wake[0] >= 0)
			close(wake[0]), close(wake[1]);
		return 1;
	}
	command_table_install(&sh);
	signals_set_cancel(&sh.cancel);
	sh.pal = caps_palette(o->color, STDOUT_FILENO);
	int status = 0;
	if (script) {
		signals_script_begin();
		sh.interactive = false;
		sh.progress = !o->quiet && isatty(STDERR_FILENO);
		bool ok;
		if (o->commands)
			ok = shell_run_text(&sh, o->commands, "-c", true);
		else
			ok = shell_run_file(&sh, o->file ? o->file : "-");
		if (!ok && !sh.err_reported)
			fprintf(stderr, "rtsh: %s\n", sh.err);
		status = ok ? 0 : shell_sig_int ? 130 : 1;
		signals_script_end();
		if (sh.quit)
			then_interactive = false;
	}
	if (then_interactive) {
		if (!screen_ok && isatty(STDOUT_FILENO)) {
			const char *t = getenv("TERM");
			fprintf(stderr, "rtsh: this terminal (TERM=%s) cannot show the picture; commands work, "
			                "and save writes images\n",
			        t && *t ? t : "unset");
		}
		sh.interactive = true;
		sh.progress = !o->quiet; /* `render` shows its progress in the status line */
		sh.quit = false;
		shell_sig_int = 0;
		int st = shell_interactive(&sh, screen_ok, wake);
		if (st != 0 || status == 0)
			status = st;
	}
	signals_set_cancel(NULL);
	shell_free(&sh);
	if (wake[0] >= 0)
		close(wake[0]), close(wake[1]);
	return status;
}
