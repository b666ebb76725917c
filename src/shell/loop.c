/* rtsh — the interactive loop: readline's callback interface and select()
 * on standard input and the wake-up pipe, so typing never waits for a
 * render. The render thread (render_service.c) writes a byte to the pipe when an
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
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include <readline/history.h>
#include <readline/readline.h>

#include "shell/complete.h"
#include "shell/history.h"
#include "term/pager.h"
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

/* The keys read from the terminal, the answers to rtsh's queries taken
 * out (term/out.h); readline reads them through loop_getc. */
static abuf keys;
static size_t keys_pos;
static bool keys_eof;

/* Takes bytes read from the terminal: answers out, keys in. */
static void take_input(shell *sh, const char *b, size_t n)
{
	if (keys_pos == keys.len) {
		abuf_reset(&keys);
		keys_pos = 0;
	}
	if (sh->scr && sh->scr->out)
		termout_input(sh->scr->out, b, n, now(), &keys);
	else
		abuf_add(&keys, b, n);
}

/* Keys already free of answers, after the ones waiting. */
static void take_input_raw(const abuf *k)
{
	if (keys_pos == keys.len) {
		abuf_reset(&keys);
		keys_pos = 0;
	}
	abuf_add(&keys, k->b, k->len);
}

/* Reads what the terminal sent (end of input: keys_eof). */
static void read_input(shell *sh)
{
	char b[4096];
	ssize_t n = read(STDIN_FILENO, b, sizeof b);
	if (n > 0)
		take_input(sh, b, (size_t)n);
	else if (n == 0 || (errno != EINTR && errno != EAGAIN))
		keys_eof = true;
}

static bool keys_waiting(void)
{
	return keys_pos < keys.len || keys_eof;
}

/* readline's input: the next key byte, waiting for one if need be. */
static int loop_getc(FILE *f)
{
	(void)f;
	while (keys_pos >= keys.len) {
		if (keys_eof || shell_sig_term)
			return EOF;
		read_input(active);
	}
	return (unsigned char)keys.b[keys_pos++];
}

static int loop_input_available(void)
{
	return keys_pos < keys.len;
}

/* Waits for the answers the terminal owes before a part of rtsh reads
 * the terminal on its own (the pager; key mode calls shell_settle). */
static void settle(shell *sh)
{
	if (!sh->scr || !sh->scr->out)
		return;
	abuf got;
	abuf_init(&got);
	termout_settle(sh->scr->out, STDIN_FILENO, 5.0, &got);
	if (got.len)
		take_input_raw(&got);
	abuf_free(&got);
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
	const rsvc_image *im = &sh->img;
	if (!scr || !scr->active || im->w != scr->img_w || im->h != scr->img_h || !im->rgb || im->stopped) {
		/* A stopped render's picture stays as the terminal shows it. */
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
	termout_picture_final(scr->out, im->done);
	termout_pump(scr->out, t0, &keys);
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
	settle(sh);
	screen_clear_all(scr);
	pager_show(STDIN_FILENO, scr->fd, out->b, out->len, scr->cols, scr->rows);
	/* Readline draws the prompt again when the command returns. */
	relayout_screen(sh);
}

/* The time to leave between two pictures: paced by the terminal's
 * answers, at most ten a second; else three times what the last write
 * took, so that a link whose writes block stays free for typing. */
static double frame_gap(const shell *sh)
{
	if (sh->scr && sh->scr->out && termout_get_state(sh->scr->out) == TERMOUT_PACED)
		return FRAME_INTERVAL;
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
	/* readline gave the terminal its own modes back while the command
	 * runs: echo off all the same, so that an answer of the terminal (to
	 * a picture slice in flight) is not echoed onto the screen. On again
	 * before readline takes the terminal (it shows the line only when the
	 * terminal echoes). */
	struct termios modes;
	bool quiet = sh->scr && tcgetattr(STDIN_FILENO, &modes) == 0 && (modes.c_lflag & ECHO);
	if (quiet) {
		struct termios q = modes;
		q.c_lflag &= ~(tcflag_t)ECHO;
		tcsetattr(STDIN_FILENO, TCSADRAIN, &q);
	}
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
	if (quiet)
		tcsetattr(STDIN_FILENO, TCSADRAIN, &modes);
	shell_sig_int = 0;
	/* The command may have taken a while: show what came meanwhile. */
	if (rsvc_take(sh->rs, &sh->img))
		sh->redraw = true;
	draw_status(sh);
}

/* Ctrl-C at the prompt: stop a render in flight, else clear the line. */
static void interrupt(shell *sh)
{
	atomic_store(&sh->cancel, false);
	if (rsvc_stop(sh->rs)) {
		rsvc_take(sh->rs, &sh->img);
		/* The picture stops where the terminal has it: no more of it
		 * goes out over a slow link. */
		if (sh->scr && sh->scr->out)
			termout_drop_picture(sh->scr->out);
		draw_status(sh);
		return;
	}
	if (sh->scr && sh->scr->out && termout_picture_pending(sh->scr->out)) {
		/* The render is done but its picture is still on its way over a
		 * slow link: Ctrl-C stops that too. */
		termout_drop_picture(sh->scr->out);
		shell_notice(sh, "Ctrl-C: the rest of the picture was not sent");
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

static bool asked_color, probe_seen;

/* Once the start-up answers are in (or did not come): truecolor when the
 * terminal said so, and the one-time notices. */
static void after_probe(shell *sh)
{
	termout *o = sh->scr->out;
	const char *n = termout_notice(o);
	if (n)
		shell_notice(sh, "%s", n);
	if (probe_seen || termout_get_state(o) == TERMOUT_PROBING)
		return;
	probe_seen = true;
	if (sh->set.pixels != PIXELS_OFF && screen_set_pixels(sh->scr, sh->set.pixels)) {
		/* The answers told the cell size or, for auto, the protocol: the
		 * screen was laid out again for it. */
		shell_refresh(sh);
		draw_status(sh);
		rl_forced_update_display();
	}
	if (!asked_color)
		return;
	if (termout_truecolor(o) == 1) {
		/* The same picture in other colours: drawn again, not rendered
		 * again. */
		screen_set_palette(sh->scr, PALETTE_TRUECOLOR);
		sh->redraw = true;
		draw_status(sh);
		rl_forced_update_display();
	} else {
		shell_notice(sh, "%s colours: the terminal did not say it has 24-bit colour (rtsh --color truecolor if it does)",
		             sh->scr->pal == PALETTE_256 ? "256" : "16");
	}
}

int shell_interactive(shell *sh, bool use_screen, const int wake[2])
{
	int wake_fd = wake[0];
	setlocale(LC_CTYPE, "");
	active = sh;
	sh->wake[0] = wake[0];
	sh->wake[1] = wake[1];

	screen scr;
	frame_palette pal = caps_palette(sh->opt->color, STDOUT_FILENO);
	if (use_screen && screen_enter(&scr, STDOUT_FILENO, pal, (double)sh->set.width / sh->set.height))
		sh->scr = &scr;
	abuf_init(&keys);
	keys_pos = 0;
	keys_eof = false;
	/* Ask the terminal (over SSH, COLORTERM is not there to tell): the
	 * answers set the pacing and, maybe, truecolor. */
	asked_color = sh->scr && sh->opt->color == COLOR_AUTO && pal != PALETTE_TRUECOLOR && pal != PALETTE_NONE;
	probe_seen = false;
	history_setup(&hist, stderr);
	signals_interactive_begin(STDIN_FILENO, wake[1]);

	rl_catch_signals = 0;
	rl_catch_sigwinch = 0;
	rl_change_environment = 0;
	rl_readline_name = "rtsh";
	rl_getc_function = loop_getc;
	rl_input_available_hook = loop_input_available;
	if (!sh->scr && !isatty(STDOUT_FILENO))
		rl_outstream = stderr;
	complete_install(sh);
	if (sh->scr)
		rl_set_screen_size(scr.rows - scr.region_top, scr.cols);
	sh->status_hook = draw_status;
	shell_refresh(sh);
	draw_status(sh);
	rl_callback_handler_install(PROMPT, on_line);
	/* After readline turned echo off, so the answers are not echoed. */
	if (sh->scr && !getenv("RTSH_NO_PACING")) {
		termout_ask_pixels(scr.out, sh->set.pixels != PIXELS_OFF);
		termout_probe(scr.out, asked_color, now());
	}

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
		double wait = -1;
		if (sh->redraw) {
			wait = sh->last_draw + frame_gap(sh) - now();
			if (wait < 0)
				wait = 0;
		}
		if (sh->scr && sh->scr->out) {
			double w = termout_wait(sh->scr->out, now());
			if (w >= 0 && (wait < 0 || w < wait))
				wait = w;
		}
		if (keys_waiting())
			wait = 0;
		struct timeval tv, *tvp = NULL;
		if (wait >= 0) {
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
		/* The terminal's answers first: they let the next slice go. */
		if (n > 0 && FD_ISSET(STDIN_FILENO, &rd))
			read_input(sh);
		if (sh->scr && sh->scr->out) {
			termout_pump(sh->scr->out, now(), &keys);
			after_probe(sh);
		}
		if (rsvc_take(sh->rs, &sh->img))
			sh->redraw = true;
		if (sh->redraw && now() - sh->last_draw >= frame_gap(sh))
			draw_picture(sh);
		/* Then the keys, to readline (a command may run for a while:
		 * the answers awaited meanwhile say nothing of the link). */
		while (keys_waiting() && !sh->quit && !shell_sig_term) {
			double t0 = now();
			rl_callback_read_char();
			if (sh->scr && sh->scr->out && now() - t0 > 0.05)
				termout_stale(sh->scr->out, now());
			if (keys_eof && keys_pos >= keys.len)
				break;
		}
	}
	rl_callback_handler_remove();
	history_finish(&hist);
	sh->status_hook = NULL;
	rsvc_hold(sh->rs);
	if (sh->scr) {
		screen_leave(sh->scr);
		sh->scr = NULL;
	}
	signals_interactive_end();
	abuf_free(&keys);
	sh->wake[0] = sh->wake[1] = -1;
	active = NULL;
	return status;
}
