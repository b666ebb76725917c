/* rtsh — the interactive loop: readline's callback interface on the event
 * loop (term/evloop.h: standard input, the wake-up pipe, the output
 * scheduler), so typing never waits for a render. The render thread
 * (render_service.c) writes a byte to the pipe when an image is ready; the
 * signal handlers (signals.c) set a flag and write a byte too; everything
 * else happens here, in the main thread, which alone talks to the terminal.
 */
#include <errno.h>
#include <locale.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include <readline/history.h>
#include <readline/readline.h>

#include "shell/keymode.h"
#include "shell/complete.h"
#include "shell/history.h"
#include "term/pager.h"
#include "shell/signals.h"
#include "shell/shell.h"
#include "base/abuf.h"
#include "term/caps.h"
#include "term/evloop.h"

/* At most ten frames a second; and on a slow link (an SSH session whose
 * writes block while the bytes drain), a frame at most every third of the
 * time, so that the link stays free for typing and the prompt. */
#define FRAME_INTERVAL 0.1
#define FRAME_LINK_SHARE 3.0
#define FRAME_GAP_MAX 5.0
#define PROMPT "rtsh> "

/* What one interactive session holds beside the shell (sh->ev is its event
 * loop): everything is passed to the functions below, except to readline's
 * hooks (the line handler, getc, input-available), which take no context:
 * they reach it through rl_loop, set for the duration of shell_interactive
 * and nothing else. */
typedef struct loop {
	shell *sh;
	shell_history hist;
	bool asked_color; /* the start-up probe asks for truecolor */
	bool probe_seen;  /* its answers are in */
} loop;

static loop *rl_loop;

static double now(void)
{
	return evloop_now();
}

/* readline's input: the next key byte from the event loop (keys, the
 * terminal's answers taken out), waiting for one if need be. */
static int loop_getc(FILE *f)
{
	(void)f;
	int c = evloop_getc_wait(rl_loop->sh->ev);
	return c < 0 ? EOF : c;
}

static int loop_input_available(void)
{
	return evloop_has_keys(rl_loop->sh->ev);
}

/* Readers waiting inside the loop give up on SIGTERM (readline: as at the
 * end of the input). */
static bool stop_reading(void *ctx)
{
	(void)ctx;
	return shell_sig_term != 0;
}

/* The pager gives up on every signal the shell serves. */
static bool stop_paging(void *ctx)
{
	(void)ctx;
	return shell_sig_term || shell_sig_int || shell_sig_winch || shell_sig_cont;
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
	evloop_pump(sh->ev);
	sh->last_draw = now();
	sh->frame_cost = sh->last_draw - t0;
	draw_status(sh); /* the status line tells about the picture shown */
}

static void relayout_screen(shell *sh);

/* Text shown in the command area, remembered for a new layout. */
static void area_log(shell *sh, const char *text, size_t n)
{
	if (sh->scr && sh->scr->active)
		screen_log(sh->scr, text, n);
}

/* Prints sh->err (shell_report), remembered for a new layout. */
static void report(shell *sh)
{
	if (!sh->err_reported && sh->err[0]) {
		area_log(sh, sh->err, strlen(sh->err));
		area_log(sh, "\n", 1);
	}
	shell_report(sh);
}

/* Prints a command's output in the command area, or pages it when it would
 * scroll out of sight there. */
static void show_output(shell *sh, const abuf *out)
{
	screen *scr = sh->scr;
	int area = scr->rows - scr->region_top; /* the command area, prompt included */
	if (pager_rows(out->b, out->len, scr->cols) < area) {
		/* wrapped as the pager wraps (words whole, hanging indent) */
		size_t n;
		char *w = pager_wrap(out->b, out->len, scr->cols, &n);
		fwrite(w ? w : out->b, 1, w ? n : out->len, stdout);
		screen_log(scr, w ? w : out->b, w ? n : out->len);
		free(w);
		return;
	}
	fflush(stdout);
	size_t at = 0;
	for (;;) {
		/* The loop takes the terminal's answers out of the pager's keys;
		 * the picture waits (screen_clear_all) until the layout comes
		 * back. */
		screen_clear_all(scr);
		evloop_set_interrupt(sh->ev, stop_paging, NULL);
		bool left = pager_show(sh->ev, scr->fd, out->b, out->len, scr->cols, scr->rows, &at);
		evloop_set_interrupt(sh->ev, stop_reading, NULL);
		if (left || shell_sig_term || shell_sig_int)
			break;
		/* Continued after Ctrl-Z, or the window changed size: the pager
		 * again where it was, for the window as it is now. */
		shell_sig_cont = shell_sig_winch = 0;
		screen_layout(scr, (double)sh->set.width / sh->set.height, true);
	}
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

/* Runs one line of what readline gave (a pasted block has several); its
 * output goes to `out` when the picture is on screen. With `inline_errors`
 * (a paste of several lines) an error goes to `out` too, after the
 * output of the lines before it, so that each message stays next to its
 * line. */
static bool run_one(loop *lp, const char *line, abuf *out, bool inline_errors)
{
	shell *sh = lp->sh;
	history_add_line(&lp->hist, line);
	if (sh->scr && sh->scr->active)
		sh->capture = sh->notes = out; /* warnings too, in their place */
	bool ok = shell_run_line(sh, line);
	sh->capture = sh->notes = NULL;
	if (!ok && inline_errors) {
		if (sh->scr && sh->scr->active) {
			if (!sh->err_reported && sh->err[0])
				abuf_printf(out, "%s\n", sh->err);
			sh->err_reported = false;
			sh->err[0] = '\0';
		} else {
			report(sh);
		}
	}
	return ok;
}

static void on_line(char *line)
{
	loop *lp = rl_loop;
	shell *sh = lp->sh;
	if (!line) { /* Ctrl-D or end of input */
		fputs("\n", stdout);
		if (!evloop_eof(sh->ev) && shell_quit_asks(sh)) {
			/* Ctrl-D again leaves. */
			static const char q[] = "the scene has edits not saved (save FILE.rt keeps them); Ctrl-D again, "
			                        "or quit!, leaves without them\n";
			fputs(q, stdout);
			area_log(sh, PROMPT "\n", strlen(PROMPT) + 1);
			area_log(sh, q, sizeof q - 1);
			fflush(stdout);
			return;
		}
		sh->quit = true;
		return;
	}
	area_log(sh, PROMPT, strlen(PROMPT));
	area_log(sh, line, strlen(line));
	area_log(sh, "\n", 1);
	shell_sig_int = 0;
	atomic_store(&sh->cancel, false);
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
	 * than the command area, the pager shows it over the whole screen.
	 * A bracketed paste of several lines comes as one line with newlines
	 * in it: each line is a command of its own, run in turn as bash does
	 * (its own history entry and error); Ctrl-C stops the rest. */
	abuf out;
	abuf_init(&out);
	bool several = strpbrk(line, "\n\r") != NULL;
	long left = 0;
	bool ok = true;
	for (char *p = line; p && !sh->quit;) {
		char *end = p + strcspn(p, "\n\r");
		char *next = *end ? end + 1 : NULL;
		*end = '\0';
		if (shell_sig_int || (several && atomic_load(&sh->cancel))) {
			left += p[strspn(p, " \t")] != '\0';
		} else if (!several) {
			ok = run_one(lp, p, &out, false);
		} else if (p[strspn(p, " \t")]) {
			run_one(lp, p, &out, true);
			fflush(stdout);
		}
		p = next;
	}
	free(line);
	if (left)
		abuf_printf(&out, "Ctrl-C: %ld pasted line%s not run\n", left, left == 1 ? "" : "s");
	if (out.len && !out.failed) {
		if (sh->scr && sh->scr->active)
			show_output(sh, &out);
		else
			fwrite(out.b, 1, out.len, stdout);
	}
	abuf_free(&out);
	if (!ok)
		report(sh);
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
	area_log(sh, PROMPT, strlen(PROMPT));
	area_log(sh, rl_line_buffer, strlen(rl_line_buffer));
	area_log(sh, "^C\n", 3);
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

/* Once the start-up answers are in (or did not come): truecolor when the
 * terminal said so, and the one-time notices. */
static void after_probe(loop *lp)
{
	shell *sh = lp->sh;
	termout *o = sh->scr->out;
	const char *n = termout_notice(o);
	if (n)
		shell_notice(sh, "%s", n);
	if (lp->probe_seen || termout_get_state(o) == TERMOUT_PROBING)
		return;
	lp->probe_seen = true;
	bool sym = sh->set.symbols == SYMBOLS_AUTO && screen_set_symbols(sh->scr, sh->set.symbols);
	if ((sh->set.pixels != PIXELS_OFF && screen_set_pixels(sh->scr, sh->set.pixels)) || sym) {
		/* The answers told the cell size or, for auto, the protocol: the
		 * screen was laid out again for it. */
		shell_refresh(sh);
		draw_status(sh);
		rl_forced_update_display();
	}
	shell_pixels_notice(sh); /* kitty asked for in a tmux pane without passthrough */
	if (!lp->asked_color)
		return;
	if (termout_truecolor(o) == 1) {
		/* The same picture in other colours: drawn again, not rendered
		 * again. */
		screen_set_palette(sh->scr, PALETTE_TRUECOLOR);
		sh->redraw = true;
		draw_status(sh);
		rl_forced_update_display();
	} else {
		/* Short: the status line's mode and samples stay in sight at 80
		 * columns (rtsh(1) says the rest). */
		shell_notice(sh, "%s colours (--color truecolor?)", sh->scr->pal == PALETTE_256 ? "256" : "16");
	}
}

int shell_interactive(shell *sh, bool use_screen, const int wake[2])
{
	int wake_fd = wake[0];
	setlocale(LC_CTYPE, "");
	loop lp = {.sh = sh};
	rl_loop = &lp;
	sh->wake[0] = wake[0];
	sh->wake[1] = wake[1];

	screen scr;
	frame_palette pal = caps_palette(sh->opt->color, STDOUT_FILENO);
	if (use_screen && screen_enter(&scr, STDOUT_FILENO, pal, (double)sh->set.width / sh->set.height))
		sh->scr = &scr;
	evloop *ev = evloop_new(STDIN_FILENO, wake_fd);
	if (!ev) {
		if (sh->scr)
			screen_leave(sh->scr);
		sh->scr = NULL;
		fputs("rtsh: out of memory\n", stderr);
		rl_loop = NULL;
		return 1;
	}
	evloop_set_out(ev, sh->scr ? sh->scr->out : NULL);
	evloop_set_interrupt(ev, stop_reading, NULL);
	sh->ev = ev;
	/* Ask the terminal (over SSH, COLORTERM is not there to tell): the
	 * answers set the pacing and, maybe, truecolor. */
	lp.asked_color = sh->scr && sh->opt->color == COLOR_AUTO && pal != PALETTE_TRUECOLOR && pal != PALETTE_NONE;
	history_setup(&lp.hist, stderr);
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
		termout_ask_version(scr.out, sh->set.symbols == SYMBOLS_AUTO);
		termout_probe(scr.out, lp.asked_color, now());
	}

	/* rtsh --turntable: key mode spinning from the start. */
	if (sh->opt->turntable && sh->scr)
		keymode_turntable(sh, KEYMODE_SPIN_SECONDS);

	int status = 0;
	while (!sh->quit) {
		/* A signal may have come while a command ran (key mode drains
		 * the pipe): leave before waiting. */
		if (shell_sig_term) {
			status = 128 + shell_sig_term;
			break;
		}
		double wait = -1;
		if (sh->redraw) {
			wait = sh->last_draw + frame_gap(sh) - now();
			if (wait < 0)
				wait = 0;
		}
		/* Input, wake-ups, the scheduler's slices and time-outs. */
		evloop_wait(ev, wait);
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
		if (sh->scr && sh->scr->out)
			after_probe(&lp);
		if (rsvc_take(sh->rs, &sh->img))
			sh->redraw = true;
		if (sh->redraw && now() - sh->last_draw >= frame_gap(sh))
			draw_picture(sh);
		/* Then the keys, to readline (a command may run for a while:
		 * the loop counts the answers awaited meanwhile as stale). */
		while ((evloop_has_keys(ev) || evloop_eof(ev)) && !sh->quit && !shell_sig_term) {
			rl_callback_read_char();
			if (evloop_eof(ev))
				break;
		}
	}
	rl_callback_handler_remove();
	history_finish(&lp.hist);
	sh->status_hook = NULL;
	rsvc_hold(sh->rs);
	if (sh->scr) {
		screen_leave(sh->scr);
		sh->scr = NULL;
	}
	signals_interactive_end();
	sh->ev = NULL;
	evloop_free(ev);
	sh->wake[0] = sh->wake[1] = -1;
	rl_loop = NULL;
	return status;
}
