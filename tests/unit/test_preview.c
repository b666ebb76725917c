/* rtsh — tests of the background preview renderer: its final image equals a
 * direct render bit for bit (passes accumulate exactly), edits in quick
 * succession cancel cleanly, Ctrl-C (preview_stop) stops, and the world is
 * shared with full renders. Run under ThreadSanitizer by `make test`. */
#include "testutil.h"

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include "rtsh/edit.h"
#include "rtsh/rtfile.h"
#include "shell/preview.h"

static const char basic[] = "A 0.2 255,255,255\n"
                            "C 0,0,-5 0,0,1 70\n"
                            "L 2,0,-10 1 255,255,255\n"
                            "sp 0,0,0 2 255,0,0\n"
                            "pl 0,-1,0 0,1,0 1,1,1 200,200,200 0.9 0.1 40 0.3\n";

typedef struct fixture {
	int pipe[2];
	preview *pv;
	editor *ed;
} fixture;

static void setup(fixture *f)
{
	assert_int_equal(pipe(f->pipe), 0);
	fcntl(f->pipe[0], F_SETFL, O_NONBLOCK);
	fcntl(f->pipe[1], F_SETFL, O_NONBLOCK);
	f->pv = preview_new(f->pipe[1]);
	rt_error err;
	scene *s = rt_load_string(basic, sizeof basic - 1, "basic.rt", NULL, &err);
	assert_non_null(s);
	f->ed = editor_new(s, NULL);
}

static void teardown(fixture *f)
{
	preview_free(f->pv);
	editor_free(f->ed);
	close(f->pipe[0]);
	close(f->pipe[1]);
}

/* Waits for images until one is done (or 20 s pass); returns it in img. */
static void wait_done(fixture *f, preview_image *img, int *images)
{
	uint64_t gen = editor_generation(f->ed);
	*images = 0;
	for (int i = 0; i < 2000; i++) {
		struct pollfd p = {f->pipe[0], POLLIN, 0};
		poll(&p, 1, 10);
		char buf[64];
		while (read(f->pipe[0], buf, sizeof buf) > 0)
			;
		if (preview_take(f->pv, img)) {
			(*images)++;
			if (img->gen == gen && (img->done || img->error[0]))
				return;
		}
	}
	fail_msg("the preview did not finish");
}

static preview_request request(fixture *f, render_mode mode, int samples, int w, int h)
{
	render_settings set = render_settings_default();
	set.mode = mode;
	set.samples = samples;
	set.threads = 2;
	return (preview_request){editor_scene(f->ed), editor_generation(f->ed), set, w, h};
}

static void assert_equals_direct_render(fixture *f, const preview_request *rq, const preview_image *img)
{
	rt_error err;
	world *w = world_build(editor_scene(f->ed), &err);
	render_settings s = rq->set;
	s.width = rq->w;
	s.height = rq->h;
	s.threads = 1;
	framebuffer *fb = render_image(w, &s, NULL, NULL, NULL, &err);
	assert_non_null(fb);
	assert_int_equal(img->w, fb->w);
	assert_int_equal(img->h, fb->h);
	if (img->denoised) {
		/* A denoised path preview equals a denoised render of the same
		 * samples, but for rounding: the features of progressive passes
		 * are kept as running means in floats. */
		assert_int_equal(s.mode, MODE_PATH);
		fb_free(fb);
		s.denoise = DENOISE_ON;
		fb = render_image(w, &s, NULL, NULL, NULL, &err);
		assert_non_null(fb);
		for (size_t i = 0; i < 3 * (size_t)fb->w * fb->h; i++)
			assert_near(img->rgb[i], fb->rgb[i], 1e-4 + 1e-3 * fabsf(fb->rgb[i]));
	} else {
		assert_memory_equal(img->rgb, fb->rgb, sizeof(float) * 3 * (size_t)fb->w * fb->h);
	}
	fb_free(fb);
	world_free(w);
}

static void test_final_image_equals_direct_render(void **state)
{
	(void)state;
	fixture f;
	setup(&f);
	preview_image img = {0};
	int images;
	/* Whitted: the quick pass, then the full preview. */
	preview_request rq = request(&f, MODE_WHITTED, 1, 64, 36);
	preview_start(f.pv, &rq);
	wait_done(&f, &img, &images);
	assert_true(images >= 1);
	assert_int_equal(img.spp, 1);
	assert_false(img.denoised); /* whitted never is */
	assert_equals_direct_render(&f, &rq, &img);
	/* Path: progressive passes add up to the same image as one render. */
	rq = request(&f, MODE_PATH, 12, 40, 30);
	preview_start(f.pv, &rq);
	wait_done(&f, &img, &images);
	assert_int_equal(img.spp, 12);
	assert_int_equal(img.target, 12);
	assert_true(img.denoised); /* set denoise auto: path previews are */
	assert_equals_direct_render(&f, &rq, &img);
	rq.set.denoise = DENOISE_OFF;
	preview_start(f.pv, &rq);
	wait_done(&f, &img, &images);
	assert_false(img.denoised);
	assert_equals_direct_render(&f, &rq, &img);
	/* The same request again does nothing. */
	preview_hold(f.pv);
	preview_start(f.pv, &rq);
	assert_false(preview_busy(f.pv));
	preview_image_free(&img);
	teardown(&f);
}

static void test_edits_cancel_and_restart(void **state)
{
	(void)state;
	fixture f;
	setup(&f);
	rt_error err;
	preview_image img = {0};
	int images;
	for (int i = 0; i < 40; i++) {
		preview_hold(f.pv);
		assert_true(editor_object_move(f.ed, 0, v3(0.01, 0, 0), &err));
		preview_request rq = request(&f, i % 2 ? MODE_WHITTED : MODE_PATH, 4, 80, 45);
		preview_start(f.pv, &rq);
		if (i % 7 == 0)
			usleep(2000);
	}
	preview_request last = request(&f, MODE_WHITTED, 4, 80, 45);
	wait_done(&f, &img, &images);
	assert_int_equal(img.gen, editor_generation(f.ed));
	assert_equals_direct_render(&f, &last, &img);
	/* A full render borrows the world while held. */
	preview_hold(f.pv);
	const world *w = preview_world(f.pv, editor_scene(f.ed), editor_generation(f.ed), &err);
	assert_non_null(w);
	render_settings s = render_settings_default();
	s.width = 32;
	s.height = 18;
	framebuffer *fb = render_image(w, &s, NULL, NULL, NULL, &err);
	assert_non_null(fb);
	fb_free(fb);
	preview_release(f.pv);
	/* Stop: a long path preview ends early and says so. */
	preview_request slow = request(&f, MODE_PATH, 100000, 64, 64);
	preview_start(f.pv, &slow);
	usleep(50000);
	assert_true(preview_stop(f.pv));
	assert_false(preview_busy(f.pv));
	while (preview_take(f.pv, &img))
		;
	assert_true(img.stopped);
	assert_false(preview_stop(f.pv)); /* nothing left to stop */
	preview_image_free(&img);
	teardown(&f);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_final_image_equals_direct_render),
		cmocka_unit_test(test_edits_cancel_and_restart),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
