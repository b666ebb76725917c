/* rtsh — the keyboard of key mode (keys.h). */
#include "term/keys.h"

#include <curses.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <term.h>
#include <unistd.h>

struct keys {
	SCREEN *scr;
	WINDOW *pad;
	FILE *in, *out;
	int feed_fd;          /* keys_open_fed: the write end of ncurses' input; -1: none */
	TERMINAL *saved_term; /* readline's (terminfo's current terminal) */
	char smkx[64], rmkx[64];
	/* Codes ncurses gives to terminfo's extended shift+arrow keys. */
	int shift_up, shift_down;
	keys_mouse mouse;     /* the last KEYS_MOUSE */
};

/* Signals ncurses may take over in newterm: the shell's handlers stay. */
static const int kept[] = {SIGINT, SIGTERM, SIGHUP, SIGWINCH, SIGTSTP, SIGCONT, SIGQUIT, SIGTTIN, SIGTTOU};
#define NKEPT (sizeof kept / sizeof kept[0])

static void copy_cap(const char *name, char *dst, size_t size)
{
	char n[16];
	snprintf(n, sizeof n, "%s", name);
	const char *s = tigetstr(n);
	if (!s || s == (const char *)-1 || strlen(s) >= size)
		s = "";
	snprintf(dst, size, "%s", s);
}

/* The key code ncurses gives to the extended capability `name`, or 0. */
static int ext_key(const char *name)
{
	char n[16];
	snprintf(n, sizeof n, "%s", name);
	const char *s = tigetstr(n);
	if (!s || s == (const char *)-1)
		return 0;
	int code = key_defined(s);
	return code > 0 ? code : 0;
}

keys *keys_open(int in_fd, int esc_ms)
{
	keys *k = calloc(1, sizeof *k);
	if (!k)
		return NULL;
	k->feed_fd = -1;
	struct sigaction old[NKEPT];
	for (size_t i = 0; i < NKEPT; i++)
		sigaction(kept[i], NULL, &old[i]);
	k->saved_term = cur_term;
	int fd = dup(in_fd);
	k->in = fd >= 0 ? fdopen(fd, "r") : NULL;
	if (!k->in && fd >= 0)
		close(fd);
	k->out = fopen("/dev/null", "w");
	if (k->in && k->out)
		k->scr = newterm(NULL, k->out, k->in);
	for (size_t i = 0; i < NKEPT; i++)
		sigaction(kept[i], &old[i], NULL);
	if (k->scr) {
		set_escdelay(esc_ms);
		noecho();
		nonl();
		k->pad = newpad(1, 1);
	}
	if (!k->pad) {
		keys_close(k);
		return NULL;
	}
	keypad(k->pad, TRUE);
	nodelay(k->pad, TRUE);
	copy_cap("smkx", k->smkx, sizeof k->smkx);
	copy_cap("rmkx", k->rmkx, sizeof k->rmkx);
	k->shift_up = ext_key("kUP");
	k->shift_down = ext_key("kDN");
	return k;
}

size_t keys_parse_mouse(const char *s, size_t n, keys_mouse *m)
{
	long v[3] = {0, 0, 0};
	size_t i = 0;
	for (int f = 0; f < 3; f++) {
		size_t start = i;
		while (i < n && s[i] >= '0' && s[i] <= '9' && i - start < 6)
			v[f] = v[f] * 10 + (s[i++] - '0');
		if (i == start || i >= n)
			return 0;
		if (f < 2 && s[i++] != ';')
			return 0;
	}
	if (s[i] != 'M' && s[i] != 'm')
		return 0;
	long b = v[0];
	memset(m, 0, sizeof *m);
	m->release = s[i] == 'm';
	m->x = (int)v[1];
	m->y = (int)v[2];
	m->shift = b & 4;
	m->meta = b & 8;
	m->ctrl = b & 16;
	m->motion = (b & 32) != 0;
	long low = b & 3;
	if (b & 128)
		m->button = KEYS_BUTTON_OTHER;
	else if (b & 64)
		m->button = low == 0 ? KEYS_WHEEL_UP : low == 1 ? KEYS_WHEEL_DOWN : KEYS_BUTTON_OTHER;
	else
		m->button = (keys_button)low; /* 3: no button */
	return i + 1;
}

/* The rest of an SGR mouse report, after its "\e[<" (ncurses took those
 * as the terminfo's kmous, or left them to late_answer): true with
 * k->mouse set; else every byte read is put back. */
static bool mouse_rest(keys *k)
{
	char seq[24];
	int got[24], n = 0, d;
	while (n < 23 && (d = wgetch(k->pad)) != ERR) {
		got[n] = d;
		seq[n++] = d < 128 ? (char)d : '?';
		if (d >= 0x40 && d <= 0x7e)
			break;
	}
	keys_mouse m;
	if (n > 0 && keys_parse_mouse(seq, (size_t)n, &m) == (size_t)n) {
		k->mouse = m;
		return true;
	}
	while (n > 0)
		ungetch(got[--n]);
	return false;
}

keys_mouse keys_mouse_event(const keys *k)
{
	return k->mouse;
}

/* After an Esc that ncurses could not make a key of: true (and the bytes
 * gone) when it starts a terminal's answer to a status query that came
 * late (CSI digits n, CSI ? digits c: no key looks like that); else the
 * bytes read are put back. */
static bool late_answer(keys *k)
{
	int seq[24], n = 0, d;
	while (n < 24 && (d = wgetch(k->pad)) != ERR) {
		seq[n++] = d;
		if (d >= KEY_MIN || (n == 1 && d != '[') || (n > 1 && d >= 0x40 && d <= 0x7e))
			break;
	}
	bool answer = n >= 3 && seq[0] == '[' && (seq[n - 1] == 'n' || (seq[n - 1] == 'c' && seq[1] == '?'));
	for (int i = 1; answer && i < n - 1; i++)
		answer = (seq[i] >= '0' && seq[i] <= '9') || seq[i] == ';' || (i == 1 && seq[i] == '?');
	if (!answer)
		while (n > 0)
			ungetch(seq[--n]);
	return answer;
}

int keys_next(keys *k)
{
	int c = wgetch(k->pad);
	if (c == ERR)
		return KEYS_NONE;
	if (c == 27) {
		/* An SGR mouse report where terminfo names another (tmux's
		 * kmous is \e[M): \e [ < ... */
		int b1 = wgetch(k->pad);
		if (b1 == '[') {
			int b2 = wgetch(k->pad);
			if (b2 == '<' && mouse_rest(k))
				return KEYS_MOUSE;
			if (b2 != ERR)
				ungetch(b2);
		}
		if (b1 != ERR)
			ungetch(b1);
		if (late_answer(k))
			return KEYS_OTHER;
	}
	if (c == KEY_MOUSE) {
		/* terminfo's kmous is \e[< (xterm's): the report follows. */
		return mouse_rest(k) ? KEYS_MOUSE : KEYS_OTHER;
	}
	if (c < KEY_MIN)
		return c;
	if (c >= KEY_F(1) && c <= KEY_F(63))
		return KEYS_F(c - KEY_F0);
	if (c == k->shift_up)
		return KEYS_SHIFT_UP;
	if (c == k->shift_down)
		return KEYS_SHIFT_DOWN;
	switch (c) {
	case KEY_UP:
		return KEYS_UP;
	case KEY_DOWN:
		return KEYS_DOWN;
	case KEY_LEFT:
		return KEYS_LEFT;
	case KEY_RIGHT:
		return KEYS_RIGHT;
	case KEY_SR: /* scroll backward: shift+up on xterm-like terminals */
		return KEYS_SHIFT_UP;
	case KEY_SF:
		return KEYS_SHIFT_DOWN;
	case KEY_SLEFT:
		return KEYS_SHIFT_LEFT;
	case KEY_SRIGHT:
		return KEYS_SHIFT_RIGHT;
	case KEY_PPAGE:
		return KEYS_PAGE_UP;
	case KEY_NPAGE:
		return KEYS_PAGE_DOWN;
	case KEY_HOME:
		return KEYS_HOME;
	case KEY_END:
		return KEYS_END;
	case KEY_BTAB:
		return KEYS_BACKTAB;
	case KEY_RESIZE:
		return KEYS_RESIZE;
	case KEY_ENTER:
		return '\r';
	case KEY_BACKSPACE:
		return 127;
	default:
		return KEYS_OTHER;
	}
}

keys *keys_open_fed(int esc_ms)
{
	int p[2];
	if (pipe(p) != 0)
		return NULL;
	/* A full pipe drops keys rather than blocking the loop. */
	fcntl(p[1], F_SETFL, fcntl(p[1], F_GETFL) | O_NONBLOCK);
	fcntl(p[0], F_SETFD, FD_CLOEXEC);
	fcntl(p[1], F_SETFD, FD_CLOEXEC);
	keys *k = keys_open(p[0], esc_ms); /* ncurses reads a dup of p[0] */
	close(p[0]);
	if (!k) {
		close(p[1]);
		return NULL;
	}
	k->feed_fd = p[1];
	return k;
}

bool keys_feed(keys *k, const char *b, size_t n)
{
	if (k->feed_fd < 0)
		return false;
	while (n > 0) {
		ssize_t w = write(k->feed_fd, b, n);
		if (w <= 0)
			return false;
		b += w;
		n -= (size_t)w;
	}
	return true;
}

const char *keys_keypad_on(const keys *k)
{
	return k->smkx;
}

const char *keys_keypad_off(const keys *k)
{
	return k->rmkx;
}

void keys_close(keys *k)
{
	if (!k)
		return;
	if (k->scr) {
		if (k->pad)
			delwin(k->pad);
		endwin();
		delscreen(k->scr);
	}
	set_curterm(k->saved_term);
	if (k->in)
		fclose(k->in);
	if (k->out)
		fclose(k->out);
	if (k->feed_fd >= 0)
		close(k->feed_fd);
	free(k);
}
