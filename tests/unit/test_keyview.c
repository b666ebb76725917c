/* rtsh — tests of the key view (term/keyview.h): the layout of the picture,
 * the status line and the help bar (figures worked out by hand below), what
 * each draw sends through the output scheduler (a repaint clears and draws
 * the help bar; an unchanged status line sends nothing but the bracket), and
 * the picture sent by the scheduler with the cursor left hidden. */
#include "testutil.h"

#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "shell/keymode.h"
#include "term/keyview.h"

typedef struct out_file {
	int fd;
	size_t pos;
	char text[1 << 16];
} out_file;

/* What was written since the last call. */
static const char *take(out_file *f)
{
	ssize_t n = pread(f->fd, f->text, sizeof f->text - 1, (off_t)f->pos);
	n = n < 0 ? 0 : n;
	f->pos += (size_t)n;
	f->text[n] = '\0';
	return f->text;
}

static const keyview_item bar[] = {{"Esc", "back"}, {"←↑↓→ wasd", "move"}};

static void test_layout(void **state)
{
	(void)state;
	termout *o = termout_new(-1);
	keyview v;
	keyview_init(&v, o, PALETTE_TRUECOLOR, bar, 2);
	/* 160x48 cells and the help bar: 46 rows of picture, a canvas of
	 * 160x92 pixels; 16:9 is 160 wide and round(160 * 9 / 16) = 90 high,
	 * one pixel row of margin above. */
	keyview_layout(&v, 160, 48, true, 16.0 / 9.0);
	assert_int_equal(v.pic_rows, 46);
	assert_int_equal(v.img_w, 160);
	assert_int_equal(v.img_h, 90);
	assert_int_equal(v.img_x, 0);
	assert_int_equal(v.img_y, 1);
	/* Without the bar: 47 rows, a canvas 94 high, two rows of margin. */
	keyview_layout(&v, 160, 48, false, 16.0 / 9.0);
	assert_int_equal(v.pic_rows, 47);
	assert_int_equal(v.img_y, 2);
	/* A tall picture: 94 high, round(94 / 2) = 47 wide, centred. */
	keyview_layout(&v, 160, 48, false, 0.5);
	assert_int_equal(v.img_w, 47);
	assert_int_equal(v.img_h, 94);
	assert_int_equal(v.img_x, (160 - 47) / 2);
	/* No room: no picture. */
	keyview_layout(&v, 6, 48, true, 1.0);
	assert_int_equal(v.pic_rows, 0);
	assert_int_equal(v.img_w, 0);
	assert_null(v.enc);
	keyview_free(&v);
	termout_free(o);
}

static void test_draw(void **state)
{
	(void)state;
	out_file f = {0};
	FILE *tf = tmpfile();
	assert_non_null(tf);
	f.fd = dup(fileno(tf));
	fclose(tf);
	termout *o = termout_new(f.fd);
	keyview v;
	keyview_init(&v, o, PALETTE_TRUECOLOR, bar, 2);
	/* 20x8 cells with the bar: 6 rows of picture (a 20x12 canvas, all of
	 * it the picture at 20:12), the status line on row 7, the bar on 8. */
	keyview_layout(&v, 20, 8, true, 20.0 / 12.0);
	assert_int_equal(v.img_w, 20);
	assert_int_equal(v.img_h, 12);
	keyview_draw(&v, "abc");
	const char *t = take(&f);
	assert_non_null(strstr(t, "\x1b[2J"));
	/* The bar: "  Esc back" takes 10 columns; the next item would need 16
	 * more of the 19 usable (never the last cell). */
	assert_non_null(strstr(t, "\x1b[8H  \x1b[1mEsc\x1b[22m back\x1b[K"));
	assert_null(strstr(t, "move"));
	/* The status line: reverse video, padded to the 20 columns. */
	assert_non_null(strstr(t, "\x1b[7H\x1b[7mabc                 \x1b[m"));
	/* The same status again: only the brackets. */
	keyview_draw(&v, "abc");
	assert_string_equal(take(&f), "\x1b[?2026h\x1b[?25l\x1b[?2026l");
	assert_false(keyview_status_differs(&v, "abc"));
	/* A longer one is cut at the width. */
	keyview_draw(&v, "0123456789abcdefghijKLMN");
	assert_non_null(strstr(take(&f), "\x1b[7H\x1b[7m0123456789abcdefghij\x1b[m"));
	/* The picture: a red top half and a blue bottom half go out when the
	 * scheduler pumps (unpaced here), and the cursor stays hidden. */
	uint8_t px[20 * 12 * 3];
	for (int i = 0; i < 20 * 12; i++) {
		px[3 * i] = i < 20 * 6 ? 255 : 0;
		px[3 * i + 1] = 0;
		px[3 * i + 2] = i < 20 * 6 ? 0 : 255;
	}
	keyview_picture(&v, px, true);
	abuf got;
	abuf_init(&got);
	termout_pump(o, 0.0, &got);
	t = take(&f);
	assert_non_null(strstr(t, "255;0;0m"));
	assert_non_null(strstr(t, "0;0;255m"));
	assert_null(strstr(t, "\x1b[?25h"));
	/* Nothing changed: nothing more. */
	keyview_picture(&v, px, true);
	termout_pump(o, 0.0, &got);
	assert_string_equal(take(&f), "");
	/* The way out shows the cursor again. */
	keyview_end(&v);
	assert_string_equal(take(&f), "\x1b[m\x1b[?25h");
	abuf_free(&got);
	keyview_free(&v);
	termout_free(o);
	close(f.fd);
}

/* key mode's own bar at 80x24 (issue 31, friction 3): it takes two rows
 * there, so that rotate, size, undo and mode are all shown. */
static void test_bar_fits(void **state)
{
	(void)state;
	out_file f = {0};
	FILE *tf = tmpfile();
	assert_non_null(tf);
	f.fd = dup(fileno(tf));
	fclose(tf);
	termout *o = termout_new(f.fd);
	keyview_item items[32];
	size_t n = keymode_help_bar(items, 32);
	keyview v;
	keyview_init(&v, o, PALETTE_TRUECOLOR, items, n);
	keyview_layout(&v, 80, 24, true, 16.0 / 9.0);
	assert_int_equal(v.help_rows, 2);
	assert_int_equal(v.pic_rows, 21); /* 24 - the status line - two bar rows */
	keyview_draw(&v, "status");
	const char *t = take(&f);
	assert_non_null(strstr(t, "\x1b[22H\x1b[7mstatus"));
	const char *r23 = strstr(t, "\x1b[23H"), *r24 = strstr(t, "\x1b[24H");
	assert_non_null(r23);
	assert_non_null(r24);
	const char *words[] = {" back", " move", " turn", " select", " rotate", " size", " undo", " mode"};
	for (size_t i = 0; i < sizeof words / sizeof words[0]; i++)
		assert_non_null(strstr(r23, words[i]));
	keyview_free(&v);
	/* 240 columns: one row is enough. */
	keyview_init(&v, o, PALETTE_TRUECOLOR, items, n);
	keyview_layout(&v, 240, 48, true, 16.0 / 9.0);
	assert_int_equal(v.help_rows, 1);
	keyview_free(&v);
	termout_free(o);
	close(f.fd);
}

/* keyview_fit_status (issue 31, friction 3: key mode's status line was cut
 * at 80 columns): fields leave in their drop order until the line fits;
 * rank 0 stays. Widths counted by hand: " a │ bb │ ccc" is 1+1+3+2+3+3 = 13. */
static void test_fit_status(void **state)
{
	(void)state;
	const char *fields[] = {"a", "bb", "", "ccc"};
	const int drop[] = {0, 2, 1, 1};
	char buf[64];
	keyview_fit_status(buf, sizeof buf, fields, drop, 4, 13);
	assert_string_equal(buf, " a │ bb │ ccc"); /* the empty field is left out */
	keyview_fit_status(buf, sizeof buf, fields, drop, 4, 12);
	assert_string_equal(buf, " a │ bb"); /* ccc (rank 1) first */
	keyview_fit_status(buf, sizeof buf, fields, drop, 4, 6);
	assert_string_equal(buf, " a"); /* then bb */
	keyview_fit_status(buf, sizeof buf, fields, drop, 4, 1);
	assert_string_equal(buf, " a"); /* rank 0 is never left out */
	/* key mode's fields: the timings, depth and size go first */
	const char *km[] = {"view", "spot_triangulated.obj", "camera", "", "path", "12/64 spp… │ denoised", "depth 5",
	                    "1280x720 (1/4 res)", "30 fps", "12 ms", "step 0.05"};
	const int kd[] = {0, 5, 0, 0, 6, 0, 3, 4, 2, 1, 0};
	char line[256];
	/* at 81 the name fits (5+24+9+7+24+12 = 81 columns) ... */
	keyview_fit_status(line, sizeof line, km, kd, 11, 81);
	assert_string_equal(line, " view │ spot_triangulated.obj │ camera │ path │ 12/64 spp… │ denoised │ step 0.05");
	/* ... at 80 it goes too */
	keyview_fit_status(line, sizeof line, km, kd, 11, 80);
	assert_string_equal(line, " view │ camera │ path │ 12/64 spp… │ denoised │ step 0.05");
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_layout),
		cmocka_unit_test(test_bar_fits),
		cmocka_unit_test(test_fit_status),
		cmocka_unit_test(test_draw),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
