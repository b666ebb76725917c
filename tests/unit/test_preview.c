/* rtsh — the preview's time budget (preview.h, preview_render): within it
 * the full picture, bit for bit render_image's; past it the coarse pass
 * (a quarter of each side, 1 sample, not denoised) with each of its pixels
 * made 4 x 4; past the coarse pass's own, nothing and "stopped". The
 * expected pictures are rendered here by render_image with the settings
 * preview.h describes, and the coarse one enlarged by that definition. */
#include "testutil.h"

#include "rtsh/render.h"
#include "rtsh/rtfile.h"
#include "rtsh/settings.h"
#include "rtsh/world.h"
#include "shell/preview.h"

static const char scene_text[] = "A 0.2 255,255,255\nC 0,0,-8 0,0,1 60\nL -4,5,-6 0.8 255,255,255\n"
                                 "sp 0,0,0 3 230,60,50\nsp 1.5,1,-1 1 50,200,80\npl 0,-1.5,0 0,1,0 200,200,200\n";

static world *make_world(void)
{
	rt_error err = {0};
	scene *s = rt_load_string(scene_text, sizeof scene_text - 1, "p.rt", NULL, &err);
	if (!s)
		fail_msg("%s", err.msg);
	world *w = world_build(s, &err);
	scene_free(s);
	if (!w)
		fail_msg("%s", err.msg);
	return w;
}

/* 37 x 21: neither side a multiple of 4 */
static render_settings settings(int mode)
{
	render_settings set = render_settings_default();
	set.width = 37;
	set.height = 21;
	set.samples = 2;
	set.mode = mode;
	set.threads = 2;
	return set;
}

static void test_within_budget_is_the_full_picture(void **state)
{
	(void)state;
	world *w = make_world();
	const int modes[] = {MODE_WHITTED, MODE_PATH};
	for (size_t m = 0; m < sizeof modes / sizeof modes[0]; m++) {
		render_settings set = settings(modes[m]);
		rt_error err = {0};
		bool coarse = true;
		framebuffer *fb = preview_render(w, &set, 100, 100, &coarse, &err);
		if (!fb)
			fail_msg("%s", err.msg);
		assert_false(coarse);
		framebuffer *want = render_image(w, &set, NULL, NULL, NULL, &err);
		assert_non_null(want);
		assert_int_equal(fb->w, 37);
		assert_int_equal(fb->h, 21);
		assert_memory_equal(fb->rgb, want->rgb, (size_t)37 * 21 * 3 * sizeof *fb->rgb);
		fb_free(fb);
		fb_free(want);
	}
	world_free(w);
}

static void test_past_budget_is_the_coarse_picture(void **state)
{
	(void)state;
	world *w = make_world();
	render_settings set = settings(MODE_PATH);
	set.denoise = DENOISE_ON;
	rt_error err = {0};
	bool coarse = false;
	/* the full picture's budget spent before it starts */
	framebuffer *fb = preview_render(w, &set, 0, 100, &coarse, &err);
	if (!fb)
		fail_msg("%s", err.msg);
	assert_true(coarse);
	assert_int_equal(fb->w, 37);
	assert_int_equal(fb->h, 21);
	render_settings cs = set;
	cs.width = 10; /* ceil(37 / 4) */
	cs.height = 6; /* ceil(21 / 4) */
	cs.samples = 1;
	cs.denoise = DENOISE_OFF;
	framebuffer *small = render_image(w, &cs, NULL, NULL, NULL, &err);
	assert_non_null(small);
	for (int y = 0; y < 21; y++)
		for (int x = 0; x < 37; x++)
			for (int c = 0; c < 3; c++)
				if (fb->rgb[3 * (y * 37 + x) + c] != small->rgb[3 * ((y / 4) * 10 + x / 4) + c])
					fail_msg("pixel %d,%d channel %d: %g, the coarse pixel %d,%d has %g", x, y, c,
					         (double)fb->rgb[3 * (y * 37 + x) + c], x / 4, y / 4,
					         (double)small->rgb[3 * ((y / 4) * 10 + x / 4) + c]);
	fb_free(fb);
	fb_free(small);
	/* the coarse pass's budget spent too: nothing */
	err.msg[0] = '\0';
	assert_null(preview_render(w, &set, 0, 0, &coarse, &err));
	assert_string_equal(err.msg, "stopped");
	world_free(w);
}

/* A scene's camera in a pane wider than 16:9 (64 x 18 pixels): a
 * horizontal fov of 60 widens to 2 atan(tan 30 x 9/16 x 64/18) = 2 atan(2
 * tan 30) = 98.2132 degrees (by hand); a vertical=1 fov keeps the height
 * as it is (it was widened too: a glTF camera zoomed out); an orthographic
 * camera is left alone. A 16:9 pane changes none. */
static void test_scene_camera_in_a_wide_pane(void **state)
{
	(void)state;
	camera h = {v3(0, 0, -5), v3(0, 0, 1), 60, false, 0, 0};
	camera v = h, o = h;
	v.vertical = true;
	o.ortho = 2;
	box none = box_empty();
	preview_camera(&h, false, none, 64, 18);
	assert_near(h.fov, 98.2132107, 1e-6);
	preview_camera(&v, false, none, 64, 18);
	assert_near(v.fov, 60, 0);
	assert_true(v.vertical);
	preview_camera(&o, false, none, 64, 18);
	assert_near(o.fov, 60, 0);
	assert_near(o.ortho, 2, 0);
	camera n = {v3(0, 0, -5), v3(0, 0, 1), 60, false, 0, 0};
	preview_camera(&n, false, none, 32, 18);
	assert_near(n.fov, 60, 1e-12);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_within_budget_is_the_full_picture),
		cmocka_unit_test(test_past_budget_is_the_coarse_picture),
		cmocka_unit_test(test_scene_camera_in_a_wide_pane),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
