/* rtsh — tests of the half-block frame encoder: what a terminal shows after
 * the encoder's bytes (a small emulator decodes them) is exactly the
 * quantised image, for full and incremental frames, in every palette. */
#include "termemu.h"

#include "rtsh/render.h"
#include "rtsh/rtfile.h"
#include "rtsh/world.h"
#include "shell/builtin_scene.h"
#include "term/frame.h"

/* Every cell of the screen (at the frame's place) shows the frame's cells. */
static void assert_screen_is_frame(const emu *e, const frame *f)
{
	for (int y = 0; y < f->rows; y++)
		for (int x = 0; x < f->cols; x++) {
			const emu_cell *c = &e->cell[(f->y0 + y) * e->cols + f->x0 + x];
			uint32_t top = 0, bot = 0;
			emu_pixels(c, &top, &bot, f->pal == PALETTE_NONE);
			frame_cell want = f->cur[y * f->cols + x];
			if (top != want.top || bot != want.bot)
				fail_msg("cell %d,%d shows %08x/%08x, expected %08x/%08x", y, x, top, bot,
				         want.top, want.bot);
		}
}

static void random_image(test_rng *r, uint8_t *img, int w, int h, int levels)
{
	/* Few levels make equal neighbours (spaces, shared colours) common. */
	for (int i = 0; i < w * h * 3; i++)
		img[i] = (uint8_t)((int)(trand(r) * levels) * (255 / (levels - 1)));
}

/* Full frame, then several incremental frames over it, in one palette. */
static void round_trip(frame_palette pal, int levels)
{
	const int cols = 37, rows = 11, sw = 45, sh = 16;
	test_rng r = {(uint64_t)pal * 77 + (uint64_t)levels};
	frame *f = frame_new(cols, rows, pal);
	assert_non_null(f);
	f->x0 = 3;
	f->y0 = 2;
	emu e;
	emu_init(&e, sw, sh);
	int w = cols, h = 2 * rows - 1; /* an odd height: one half-row stays default */
	uint8_t *img = malloc((size_t)w * h * 3);
	random_image(&r, img, w, h, levels);
	frame_put_image(f, img, w, h, 0, 1);
	const abuf *out = frame_update(f);
	emu_feed(&e, out->b, out->len);
	assert_screen_is_frame(&e, f);
	assert_true(e.cursor_visible);
	assert_false(e.sync);
	assert_int_equal(e.x, 0); /* the cursor is back where it was */
	assert_int_equal(e.y, 0);
	for (int round = 0; round < 20; round++) {
		/* Change a few pixels, a block, or nothing. */
		int changes = round % 5 == 4 ? 0 : 1 + (int)(trand(&r) * 30);
		for (int k = 0; k < changes; k++) {
			int i = (int)(trand(&r) * w * h);
			for (int c = 0; c < 3; c++)
				img[i * 3 + c] = (uint8_t)(trand(&r) * 256);
		}
		if (round % 7 == 3)
			for (int y = 2; y < 9; y++)
				for (int x = 5; x < 20; x++)
					memset(img + ((size_t)y * w + x) * 3, 40 + round, 3);
		frame_put_image(f, img, w, h, 0, 1);
		out = frame_update(f);
		if (changes == 0 && round % 7 != 3)
			assert_int_equal(out->len, 0);
		emu_feed(&e, out->b, out->len);
		assert_screen_is_frame(&e, f);
		assert_int_equal(e.x, 0);
		assert_int_equal(e.y, 0);
	}
	/* Text mode: rows with newlines, decoded from the top-left corner. */
	abuf t;
	abuf_init(&t);
	frame_text(f, &t);
	emu te;
	emu_init(&te, cols, rows + 1);
	emu_feed(&te, t.b, t.len);
	frame g = *f;
	g.x0 = g.y0 = 0;
	assert_screen_is_frame(&te, &g);
	assert_int_equal(te.y, rows);
	if (pal != PALETTE_NONE) /* ends reset: nothing bleeds into the shell */
		assert_true(te.fg == EMU_DEFAULT && te.bg == EMU_DEFAULT);
	emu_free(&te);
	abuf_free(&t);
	free(img);
	emu_free(&e);
	frame_free(f);
}

static void test_round_trip_truecolor(void **state)
{
	(void)state;
	round_trip(PALETTE_TRUECOLOR, 256);
	round_trip(PALETTE_TRUECOLOR, 3);
}

static void test_round_trip_256(void **state)
{
	(void)state;
	round_trip(PALETTE_256, 256);
	round_trip(PALETTE_256, 4);
}

static void test_round_trip_16(void **state)
{
	(void)state;
	round_trip(PALETTE_16, 256);
}

static void test_round_trip_none(void **state)
{
	(void)state;
	round_trip(PALETTE_NONE, 256);
}

/* A flat colour: one SGR, then spaces; counted by hand. */
static void test_flat_frame_bytes(void **state)
{
	(void)state;
	frame *f = frame_new(10, 2, PALETTE_TRUECOLOR);
	uint8_t img[10 * 4 * 3];
	for (int i = 0; i < 40; i++)
		img[i * 3] = 30, img[i * 3 + 1] = 60, img[i * 3 + 2] = 90;
	frame_put_image(f, img, 10, 4, 0, 0);
	const abuf *out = frame_update(f);
	const char *want = "\x1b[?2026h\x1b" "7\x1b[?25l"
	                   "\x1b[1H\x1b[48;2;30;60;90m          "
	                   "\x1b[2H          "
	                   "\x1b[m\x1b" "8\x1b[?25h\x1b[?2026l";
	assert_int_equal(out->len, strlen(want)); /* 16 + 30 + 14 + 19 = 79 */
	assert_int_equal(out->len, 79);
	assert_memory_equal(out->b, want, out->len);
	/* One changed cell: a cursor move and the cell. */
	img[(2 * 10 + 4) * 3] = 200; /* row 1 of cells, top pixel of column 4 */
	frame_put_image(f, img, 10, 4, 0, 0);
	out = frame_update(f);
	const char *want2 = "\x1b[?2026h\x1b" "7\x1b[?25l"
	                    "\x1b[2;5H\x1b[38;2;200;60;90;48;2;30;60;90m\xe2\x96\x80"
	                    "\x1b[m\x1b" "8\x1b[?25h\x1b[?2026l";
	assert_int_equal(out->len, strlen(want2));
	assert_memory_equal(out->b, want2, out->len);
	frame_free(f);
}

static void test_palette_256_by_hand(void **state)
{
	(void)state;
	assert_int_equal(palette_256(0, 0, 0), 16);
	assert_int_equal(palette_256(255, 255, 255), 231);
	assert_int_equal(palette_256(128, 128, 128), 244); /* grey 8+10*12 = 128 exactly */
	assert_int_equal(palette_256(95, 135, 175), 67);   /* cube (1,2,3) exactly */
	/* 100,100,100: cube 95,95,95 is 75 away; grey 98 is 12 away. */
	assert_int_equal(palette_256(100, 100, 100), 241);
	/* 250,10,10: cube 255,0,0 (196) is 225 away; greys are far. */
	assert_int_equal(palette_256(250, 10, 10), 196);
	/* 12,12,12: black cube is 432 away, grey 8 is 48. */
	assert_int_equal(palette_256(12, 12, 12), 232);
	/* 0,0,120: cube levels 0,0,135 (index 18) is 225 away; greys are far. */
	assert_int_equal(palette_256(0, 0, 120), 18);
	uint8_t c[3];
	palette_rgb(67, c);
	assert_true(c[0] == 95 && c[1] == 135 && c[2] == 175);
	palette_rgb(255, c);
	assert_true(c[0] == 238 && c[1] == 238 && c[2] == 238);
	assert_int_equal(palette_16(200, 0, 0), 1);
	assert_int_equal(palette_16(250, 250, 250), 15);
	assert_int_equal(palette_16(128, 128, 128), 8);
	assert_int_equal(palette_16(90, 90, 250), 12);
}

/* The showcase rendered at 100 x 60 cells: bytes per cell of a full frame
 * (chafa's half blocks need about 25-34 on this image) and of an unchanged
 * frame. */
static void test_real_render_bytes(void **state)
{
	(void)state;
	rt_error err;
	scene *s = rt_load_string(builtin_scene_text, builtin_scene_len, "showcase.rt", NULL, &err);
	assert_non_null(s);
	world *w = world_build(s, &err);
	assert_non_null(w);
	render_settings set = render_settings_default();
	set.width = 100;
	set.height = 120;
	set.threads = 2;
	framebuffer *fb = render_image(w, &set, NULL, NULL, NULL, &err);
	assert_non_null(fb);
	uint8_t *img = malloc((size_t)fb->w * fb->h * 3);
	frame_srgb_from_linear(fb->rgb, (size_t)fb->w * fb->h, 0, img);
	frame *f = frame_new(100, 60, PALETTE_TRUECOLOR);
	frame_put_image(f, img, fb->w, fb->h, 0, 0);
	const abuf *out = frame_update(f);
	double per_cell = (double)out->len / (100 * 60);
	print_message("showcase 100x60 cells: %zu bytes, %.1f per cell\n", out->len, per_cell);
	assert_true(per_cell < 25);
	emu e;
	emu_init(&e, 100, 60);
	emu_feed(&e, out->b, out->len);
	assert_screen_is_frame(&e, f);
	frame_put_image(f, img, fb->w, fb->h, 0, 0);
	out = frame_update(f);
	assert_true(out->len < 100);
	emu_free(&e);
	frame_free(f);
	free(img);
	fb_free(fb);
	world_free(w);
	scene_free(s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_round_trip_truecolor),
		cmocka_unit_test(test_round_trip_256),
		cmocka_unit_test(test_round_trip_16),
		cmocka_unit_test(test_round_trip_none),
		cmocka_unit_test(test_flat_frame_bytes),
		cmocka_unit_test(test_palette_256_by_hand),
		cmocka_unit_test(test_real_render_bytes),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
