/* rtsh — the interactive loop: readline's callback interface and select()
 * on standard input and the wake-up pipe, so typing never waits for a
 * render. The render thread (preview.c) writes a byte to the pipe when an
 * image is ready; the signal handlers (signals.c) set a flag and write a
 * byte too; everything else happens here, in the main thread, which alone talks
 * to the terminal.
 */
#include <errno.h>
#include <locale.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/select.h>
#include <time.h>
#include <unistd.h>

#include <readline/history.h>
#include <readline/readline.h>

#include "shell/complete.h"
#include "shell/history.h"
#include "shell/pager.h"
#include "shell/signals.h"
#include "shell/shell.h"
#include "term/abuf.h"
#include "term/caps.h"

/* At most ten frames a second; and on a slow link (an SSH session whose
 * writes block while the bytes drain), a frame at most every third of the
 * time, so that the link stays free for typing and the prompt. */
#define FRAME_INTERVAL 0.1
#define FRAME_LINK_SHARE 3.0
#define FRAME_GAP_MAX 5.0
#define PROMPT "rtsh> "

static shell *active;     /* the shell readline's line handler runs commands in */
static shell_history hist;

static double now(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)t.tv_sec + t.tv_nsec * 1e-9;
}

static void draw_status(shell *sh)
{
	if (!sh->scr || !sh->scr->active)
		return;
	char text[512];
	shell_status_text(sh, text, sizeof text);
	fflush(stdout);
	screen_status(sh->scr, text);
}

/* Sends the newest preview image, converted with the exposure. */
static void draw_picture(shell *sh)
{
	sh->redraw = false;
	screen *scr = sh->scr;
	const preview_image *im = &sh->img;
	if (!scr || !scr->active || im->w != scr->img_w || im->h != scr->img_h || !im->rgb) {
		draw_status(sh);
		return;
	}
	size_t n = (size_t)im->w * im->h * 3;
	if (n > sh->srgb_cap) {
		uint8_t *p = realloc(sh->srgb, n);
		if (!p)
			return;
		sh->srgb = p;
		sh->srgb_cap = n;
	}
	frame_srgb_from_linear(im->rgb, (size_t)im->w * im->h, sh->set.exposure, sh->srgb);
	fflush(stdout);
	double t0 = now();
	screen_picture(scr, sh->srgb, im->w, im->h);
	sh->last_draw = now();
	sh->frame_cost = sh->last_draw - t0;
	draw_status(sh); /* the status line tells about the picture shown */
}

static void relayout_screen(shell *sh);

/* Prints a command's output in the command area, or pages it when it would
 * scroll out of sight there. */
static void show_output(shell *sh, const abuf *out)
{
	screen *scr = sh->scr;
	int area = scr->rows - scr->region_top; /* the command area, prompt included */
	if (pager_rows(out->b, out->len, scr->cols) < area) {
		fwrite(out->b, 1, out->len, stdout);
		return;
	}
	fflush(stdout);
	write_all(scr->fd, "\x1b[r\x1b[2J", 9);
	pager_show(STDIN_FILENO, scr->fd, out->b, out->len, scr->cols, scr->rows);
	/* Readline draws the prompt again when the command returns. */
	relayout_screen(sh);
}

/* The time to leave between two frames. */
static double frame_gap(const shell *sh)
{
	double g = FRAME_LINK_SHARE * sh->frame_cost;
	return g < FRAME_INTERVAL ? FRAME_INTERVAL : g > FRAME_GAP_MAX ? FRAME_GAP_MAX : g;
}

static void on_line(char *line)
{
	shell *sh = active;
	if (!line) { /* Ctrl-D or end of input */
		fputs("\n", stdout);
		sh->quit = true;
		return;
	}
	history_add_line(&hist, line);
	shell_sig_int = 0;
	/* With a picture on screen, the output is held back: if it is longer
	 * than the command area, the pager shows it over the whole screen. */
	abuf out;
	abuf_init(&out);
	if (sh->scr && sh->scr->active)
		sh->capture = &out;
	bool ok = shell_run_line(sh, line);
	sh->capture = NULL;
	free(line);
	if (out.len && !out.failed)
		show_output(sh, &out);
	abuf_free(&out);
	if (!ok)
		shell_report(sh);
	fflush(stdout);
	shell_sig_int = 0;
	/* The command may have taken a while: show what came meanwhile. */
	if (preview_take(sh->pv, &sh->img))
		sh->redraw = true;
	draw_status(sh);
}

/* Ctrl-C at the prompt: stop a render in flight, else clear the line. */
static void interrupt(shell *sh)
{
	atomic_store(&sh->cancel, false);
	if (preview_stop(sh->pv)) {
		preview_take(sh->pv, &sh->img);
		draw_status(sh);
		return;
	}
	rl_callback_sigcleanup();
	rl_replace_line("", 0);
	fputs("^C", rl_outstream);
	rl_crlf();
	rl_on_new_line();
	rl_redisplay();
}

/* Lays the screen out again and asks for the picture (after a resize or
 * the pager). */
static void relayout_screen(shell *sh)
{
	screen_layout(sh->scr, (double)sh->set.width / sh->set.height, true);
	rl_set_screen_size(sh->scr->rows - sh->scr->region_top, sh->scr->cols);
	shell_refresh(sh);
	sh->redraw = true;
	draw_status(sh);
}

static void relayout(shell *sh)
{
	if (sh->scr)
		relayout_screen(sh);
	else
		rl_resize_terminal();
	rl_forced_update_display();
}

int shell_interactive(shell *sh, bool use_screen, const int wake[2])
{
	int wake_fd = wake[0];
	setlocale(LC_CTYPE, "");
	active = sh;
	sh->wake[0] = wake[0];
	sh->wake[1] = wake[1];

	screen scr;
	if (use_screen && screen_enter(&scr, STDOUT_FILENO, caps_palette(sh->opt->color, STDOUT_FILENO),
	                               (double)sh->set.width / sh->set.height))
		sh->scr = &scr;
	history_setup(&hist, stderr);
	signals_interactive_begin(STDIN_FILENO, wake[1]);

	rl_catch_signals = 0;
	rl_catch_sigwinch = 0;
	rl_change_environment = 0;
	rl_readline_name = "rtsh";
	if (!sh->scr && !isatty(STDOUT_FILENO))
		rl_outstream = stderr;
	complete_install(sh);
	if (sh->scr)
		rl_set_screen_size(scr.rows - scr.region_top, scr.cols);
	sh->status_hook = draw_status;
	shell_refresh(sh);
	draw_status(sh);
	rl_callback_handler_install(PROMPT, on_line);

	int status = 0;
	while (!sh->quit) {
		/* A signal may have come while a command ran (key mode drains
		 * the pipe): leave before waiting. */
		if (shell_sig_term) {
			status = 128 + shell_sig_term;
			break;
		}
		fd_set rd;
		FD_ZERO(&rd);
		FD_SET(STDIN_FILENO, &rd);
		if (wake_fd >= 0)
			FD_SET(wake_fd, &rd);
		struct timeval tv, *tvp = NULL;
		if (sh->redraw) {
			double wait = sh->last_draw + frame_gap(sh) - now();
			if (wait < 0)
				wait = 0;
			tv.tv_sec = (time_t)wait;
			tv.tv_usec = (suseconds_t)((wait - (double)tv.tv_sec) * 1e6);
			tvp = &tv;
		}
		int n = select((wake_fd > STDIN_FILENO ? wake_fd : STDIN_FILENO) + 1, &rd, NULL, NULL, tvp);
		if (n < 0 && errno != EINTR)
			break;
		if (n > 0 && wake_fd >= 0 && FD_ISSET(wake_fd, &rd)) {
			char buf[256];
			while (read(wake_fd, buf, sizeof buf) > 0)
				;
		}
		if (shell_sig_term) {
			status = 128 + shell_sig_term;
			break;
		}
		if (shell_sig_winch) {
			shell_sig_winch = 0;
			relayout(sh);
		}
		if (shell_sig_cont) {
			/* Continued after Ctrl-Z: the handler gave the screen back;
			 * draw it all again. */
			shell_sig_cont = 0;
			if (sh->scr)
				screen_resume(sh->scr);
			relayout(sh);
		}
		if (shell_sig_int) {
			shell_sig_int = 0;
			interrupt(sh);
		}
		if (preview_take(sh->pv, &sh->img))
			sh->redraw = true;
		if (sh->redraw && now() - sh->last_draw >= frame_gap(sh))
			draw_picture(sh);
		if (n > 0 && FD_ISSET(STDIN_FILENO, &rd))
			rl_callback_read_char();
	}
	rl_callback_handler_remove();
	history_finish(&hist);
	sh->status_hook = NULL;
	preview_hold(sh->pv);
	if (sh->scr) {
		screen_leave(sh->scr);
		sh->scr = NULL;
	}
	signals_interactive_end();
	sh->wake[0] = sh->wake[1] = -1;
	active = NULL;
	return status;
}
