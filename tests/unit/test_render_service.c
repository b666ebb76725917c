/* rtsh — tests of the render service: the preview's final image equals a
 * direct render bit for bit (passes accumulate exactly), edits in quick
 * succession cancel cleanly, Ctrl-C (rsvc_stop) stops, the world is shared
 * with full renders; a frame at a ratio has the size and pixels of a direct
 * render at that size; an accumulation goes on from the samples already in
 * and ends on the same picture (fewer samples start over); a world someone still holds outlives the
 * service moving on to another scene (a render from a released world is a
 * use after free under ASan); reference counts from many threads. Run
 * under ThreadSanitizer and AddressSanitizer by `make test`. */
#include "testutil.h"

#include <fcntl.h>
#include <poll.h>
#include <pthread.h>
#include <unistd.h>

#include "rtsh/edit.h"
#include "rtsh/rtfile.h"
#include "shell/render_service.h"

static const char basic[] = "A 0.2 255,255,255\n"
                            "C 0,0,-5 0,0,1 70\n"
                            "L 2,0,-10 1 255,255,255\n"
                            "sp 0,0,0 2 255,0,0\n"
                            "pl 0,-1,0 0,1,0 1,1,1 200,200,200 0.9 0.1 40 0.3\n";

typedef struct fixture {
	int pipe[2];
	rsvc *rs;
	editor *ed;
} fixture;

static void setup(fixture *f)
{
	assert_int_equal(pipe(f->pipe), 0);
	fcntl(f->pipe[0], F_SETFL, O_NONBLOCK);
	fcntl(f->pipe[1], F_SETFL, O_NONBLOCK);
	f->rs = rsvc_new(f->pipe[1]);
	rt_error err;
	scene *s = rt_load_string(basic, sizeof basic - 1, "basic.rt", NULL, &err);
	assert_non_null(s);
	f->ed = editor_new(s, NULL);
}

static void teardown(fixture *f)
{
	rsvc_free(f->rs);
	editor_free(f->ed);
	close(f->pipe[0]);
	close(f->pipe[1]);
}

/* Waits for images until one is done (or 20 s pass); returns it in img. */
static void wait_done(fixture *f, rsvc_image *img, int *images)
{
	uint64_t gen = editor_generation(f->ed);
	*images = 0;
	for (int i = 0; i < 2000; i++) {
		struct pollfd p = {f->pipe[0], POLLIN, 0};
		poll(&p, 1, 10);
		char buf[64];
		while (read(f->pipe[0], buf, sizeof buf) > 0)
			;
		if (rsvc_take(f->rs, img)) {
			(*images)++;
			if (img->gen == gen && (img->done || img->error[0]))
				return;
		}
	}
	fail_msg("the render service did not finish");
}

/* A request as the shell's preview makes it. */
static rsvc_request request(fixture *f, render_mode mode, int samples, int w, int h)
{
	render_settings set = render_settings_default();
	set.mode = mode;
	set.samples = samples;
	set.threads = 2;
	return (rsvc_request){
		.s = editor_scene(f->ed),
		.gen = editor_generation(f->ed),
		.set = set,
		.w = w,
		.h = h,
		.kind = RSVC_REFINE,
		.quick = true,
		.denoise = mode == MODE_PATH && set.denoise != DENOISE_OFF,
		.pass_seconds = PREVIEW_PASS_SECONDS,
	};
}

static void assert_equals_direct_render(fixture *f, const rsvc_request *rq, const rsvc_image *img)
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
		 * samples (both adaptive: the same counts in every pixel), but
		 * for rounding: the features of progressive passes are kept as
		 * running means in floats. */
		assert_int_equal(s.mode, MODE_PATH);
		fb_free(fb);
		s.denoise = DENOISE_ON;
		fb = render_image(w, &s, NULL, NULL, NULL, &err);
		assert_non_null(fb);
		assert_non_null(fb->pixel_spp);
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
	rsvc_image img = {0};
	int images;
	/* Whitted: the quick pass, then the full preview. */
	rsvc_request rq = request(&f, MODE_WHITTED, 1, 64, 36);
	rsvc_start(f.rs, &rq);
	wait_done(&f, &img, &images);
	assert_true(images >= 1);
	assert_int_equal(img.spp, 1);
	assert_false(img.denoised); /* whitted never is */
	assert_equals_direct_render(&f, &rq, &img);
	/* Path: progressive passes add up to the same image as one render. */
	rq = request(&f, MODE_PATH, 12, 40, 30);
	rsvc_start(f.rs, &rq);
	wait_done(&f, &img, &images);
	assert_int_equal(img.spp, 12);
	assert_int_equal(img.target, 12);
	assert_true(img.denoised); /* set denoise auto: path previews are */
	assert_equals_direct_render(&f, &rq, &img);
	rq.set.denoise = DENOISE_OFF;
	rq.denoise = false;
	rsvc_start(f.rs, &rq);
	wait_done(&f, &img, &images);
	assert_false(img.denoised);
	assert_equals_direct_render(&f, &rq, &img);
	/* The same request again does nothing. */
	rsvc_hold(f.rs);
	rsvc_start(f.rs, &rq);
	assert_false(rsvc_busy(f.rs));
	rsvc_image_free(&img);
	teardown(&f);
}

static void test_edits_cancel_and_restart(void **state)
{
	(void)state;
	fixture f;
	setup(&f);
	rt_error err;
	rsvc_image img = {0};
	int images;
	for (int i = 0; i < 40; i++) {
		rsvc_hold(f.rs);
		assert_true(editor_object_move(f.ed, 0, v3(0.01, 0, 0), &err));
		rsvc_request rq = request(&f, i % 2 ? MODE_WHITTED : MODE_PATH, 4, 80, 45);
		rsvc_start(f.rs, &rq);
		if (i % 7 == 0)
			usleep(2000);
	}
	rsvc_request last = request(&f, MODE_WHITTED, 4, 80, 45);
	wait_done(&f, &img, &images);
	assert_int_equal(img.gen, editor_generation(f.ed));
	assert_equals_direct_render(&f, &last, &img);
	/* A full render takes a reference to the world kept. */
	rsvc_hold(f.rs);
	const world *w = rsvc_world(f.rs, editor_scene(f.ed), editor_generation(f.ed), 1, NULL, &err);
	assert_non_null(w);
	render_settings s = render_settings_default();
	s.width = 32;
	s.height = 18;
	framebuffer *fb = render_image(w, &s, NULL, NULL, NULL, &err);
	assert_non_null(fb);
	fb_free(fb);
	world_release(w);
	rsvc_release(f.rs);
	/* Stop: a long path preview ends early and says so. */
	rsvc_request slow = request(&f, MODE_PATH, 100000, 64, 64);
	rsvc_start(f.rs, &slow);
	usleep(50000);
	assert_true(rsvc_stop(f.rs));
	assert_false(rsvc_busy(f.rs));
	while (rsvc_take(f.rs, &img))
		;
	assert_true(img.stopped);
	assert_false(rsvc_stop(f.rs)); /* nothing left to stop */
	rsvc_image_free(&img);
	teardown(&f);
}

/* A direct render of the editor's scene at w x h with the samples of set. */
static framebuffer *direct(fixture *f, render_settings set, int w, int h)
{
	rt_error err;
	world *wd = world_build(editor_scene(f->ed), &err);
	assert_non_null(wd);
	set.width = w;
	set.height = h;
	set.threads = 1;
	framebuffer *fb = render_image(wd, &set, NULL, NULL, NULL, &err);
	assert_non_null(fb);
	world_free(wd);
	return fb;
}

/* Waits for the image that answers request seq and is done. */
static void wait_seq(fixture *f, uint64_t seq, rsvc_image *img)
{
	for (int i = 0; i < 2000; i++) {
		struct pollfd p = {f->pipe[0], POLLIN, 0};
		poll(&p, 1, 10);
		char buf[64];
		while (read(f->pipe[0], buf, sizeof buf) > 0)
			;
		if (rsvc_take(f->rs, img) && img->seq == seq && (img->done || img->error[0]))
			return;
	}
	fail_msg("request %llu did not finish", (unsigned long long)seq);
}

/* A frame at ratio 3 of a 64x36 picture is ceil(64/3) = 22 pixels wide and
 * round(22 * 36 / 64) = round(12.375) = 12 high; its pixels are those of a
 * direct render of one sample at 22x12. */
static void test_frame_at_ratio(void **state)
{
	(void)state;
	fixture f;
	setup(&f);
	int fw, fh;
	rsvc_frame_size(64, 36, 3, &fw, &fh);
	assert_int_equal(fw, 22);
	assert_int_equal(fh, 12);
	rsvc_frame_size(64, 36, 1, &fw, &fh);
	assert_int_equal(fw, 64);
	assert_int_equal(fh, 36);
	rsvc_frame_size(5, 2, 16, &fw, &fh); /* never below one pixel */
	assert_int_equal(fw, 1);
	assert_int_equal(fh, 1);
	rsvc_request rq = request(&f, MODE_PATH, 16, 64, 36);
	rq.kind = RSVC_FRAME;
	rq.ratio = 3;
	rq.quick = rq.denoise = false;
	rsvc_image img = {0};
	uint64_t seq = rsvc_start(f.rs, &rq);
	assert_true(seq > 0);
	wait_seq(&f, seq, &img);
	assert_int_equal(img.kind, RSVC_FRAME);
	assert_int_equal(img.w, 22);
	assert_int_equal(img.h, 12);
	assert_int_equal(img.spp, 1);
	assert_true(img.px_cost > 0);
	render_settings one = rq.set;
	one.samples = 1;
	framebuffer *fb = direct(&f, one, 22, 12);
	assert_memory_equal(img.rgb, fb->rgb, sizeof(float) * 3 * 22 * 12);
	fb_free(fb);
	rsvc_image_free(&img);
	teardown(&f);
}

/* An accumulation: 4 samples, then 12 asked for go on from the 4 (no image
 * of the second request shows fewer than 5), and the end is bit for bit a
 * direct render of 12 samples. */
static void test_accumulate(void **state)
{
	(void)state;
	fixture f;
	setup(&f);
	rsvc_request rq = request(&f, MODE_PATH, 4, 40, 30);
	rq.quick = rq.denoise = false;
	rq.accumulate = true;
	rsvc_image img = {0};
	uint64_t seq = rsvc_start(f.rs, &rq);
	wait_seq(&f, seq, &img);
	assert_int_equal(img.spp, 4);
	rsvc_hold(f.rs);
	rq.set.samples = 12;
	seq = rsvc_start(f.rs, &rq);
	int least = 1 << 30;
	for (int i = 0; i < 2000; i++) {
		struct pollfd p = {f.pipe[0], POLLIN, 0};
		poll(&p, 1, 10);
		char buf[64];
		while (read(f.pipe[0], buf, sizeof buf) > 0)
			;
		if (rsvc_take(f.rs, &img) && img.seq == seq) {
			if (img.spp < least)
				least = img.spp;
			if (img.done)
				break;
		}
	}
	assert_true(img.done);
	assert_true(least > 4);
	assert_int_equal(img.spp, 12);
	framebuffer *fb = direct(&f, rq.set, 40, 30);
	assert_memory_equal(img.rgb, fb->rgb, sizeof(float) * 3 * 40 * 30);
	/* All 12 are in (a request that differs only in its pass length): the
	 * picture at once, nothing rendered. */
	rsvc_hold(f.rs);
	rq.pass_seconds = 0.3;
	seq = rsvc_start(f.rs, &rq);
	wait_seq(&f, seq, &img);
	assert_int_equal(img.spp, 12);
	assert_true(img.pass_seconds == 0);
	assert_memory_equal(img.rgb, fb->rgb, sizeof(float) * 3 * 40 * 30);
	/* Fewer than are in: starts over (the picture shows 8, not 12). */
	rsvc_hold(f.rs);
	rq.set.samples = 8;
	seq = rsvc_start(f.rs, &rq);
	wait_seq(&f, seq, &img);
	assert_int_equal(img.spp, 8);
	fb_free(fb);
	fb = direct(&f, rq.set, 40, 30);
	assert_memory_equal(img.rgb, fb->rgb, sizeof(float) * 3 * 40 * 30);
	/* Another scene generation starts over. */
	rt_error err;
	rsvc_hold(f.rs);
	assert_true(editor_object_move(f.ed, 0, v3(0.5, 0, 0), &err));
	rq.gen = editor_generation(f.ed);
	rq.set.samples = 4;
	seq = rsvc_start(f.rs, &rq);
	wait_seq(&f, seq, &img);
	assert_int_equal(img.spp, 4);
	fb_free(fb);
	fb = direct(&f, rq.set, 40, 30);
	assert_memory_equal(img.rgb, fb->rgb, sizeof(float) * 3 * 40 * 30);
	fb_free(fb);
	rsvc_image_free(&img);
	teardown(&f);
}

/* The bug of issue 9: key mode kept the preview's world after the shell
 * had released the preview, and a request for another scene generation
 * would have freed it under key mode's renders. Here a holder keeps a
 * reference to generation 1's world; the scene changes and the service
 * renders generation 2 (its kept world replaced); the holder then renders
 * from its world, while the service renders too: the picture is that of
 * generation 1, bit for bit (a freed world would be a use after free under
 * ASan, a race under TSan). */
static void test_world_outlives_the_service(void **state)
{
	(void)state;
	fixture f;
	setup(&f);
	rt_error err;
	render_settings one = render_settings_default();
	framebuffer *before = direct(&f, one, 32, 18);
	const world *held = rsvc_world(f.rs, editor_scene(f.ed), editor_generation(f.ed), 1, NULL, &err);
	assert_non_null(held);
	rsvc_hold(f.rs);
	assert_true(editor_object_move(f.ed, 0, v3(1, 0, 0), &err));
	rsvc_request rq = request(&f, MODE_WHITTED, 1, 48, 27);
	uint64_t seq = rsvc_start(f.rs, &rq);
	rsvc_image img = {0};
	wait_seq(&f, seq, &img);
	assert_int_equal(img.gen, editor_generation(f.ed));
	/* A long render of generation 2 while the holder renders from 1. */
	rsvc_request slow = request(&f, MODE_PATH, 100000, 64, 64);
	rsvc_start(f.rs, &slow);
	render_settings s = one;
	s.width = 32;
	s.height = 18;
	s.threads = 2;
	framebuffer *fb = render_image(held, &s, NULL, NULL, NULL, &err);
	assert_non_null(fb);
	assert_memory_equal(fb->rgb, before->rgb, sizeof(float) * 3 * 32 * 18);
	assert_true(rsvc_stop(f.rs));
	world_release(held);
	fb_free(fb);
	fb_free(before);
	rsvc_image_free(&img);
	teardown(&f);
}

typedef struct ref_ctx {
	const world *w;
	atomic_int *sum;
} ref_ctx;

/* Takes and drops references many times, tracing a ray with each. */
static void *refs_worker(void *arg)
{
	ref_ctx *c = arg;
	for (int i = 0; i < 2000; i++) {
		const world *w = world_retain(c->w);
		ray r = cam_ray(&w->cam, 8, 8, 16, 16);
		hit h;
		atomic_fetch_add(c->sum, world_intersect(w, &r, 0.0, INFINITY, &h));
		world_release(w);
	}
	return NULL;
}

/* References from four threads at once: the world lives until the last
 * one is dropped, then it is freed (ASan's leak check, TSan). The ray
 * through the centre of the picture hits the sphere every time. */
static void test_world_refcount(void **state)
{
	(void)state;
	rt_error err;
	scene *sc = rt_load_string(basic, sizeof basic - 1, "basic.rt", NULL, &err);
	assert_non_null(sc);
	world *w = world_build(sc, &err);
	assert_non_null(w);
	assert_int_equal(atomic_load(&w->refs), 1);
	assert_ptr_equal(world_retain(w), w);
	assert_int_equal(atomic_load(&w->refs), 2);
	world_release(w);
	assert_int_equal(atomic_load(&w->refs), 1);
	world_retain(NULL);
	world_release(NULL);
	atomic_int sum;
	atomic_init(&sum, 0);
	ref_ctx c = {w, &sum};
	pthread_t t[4];
	for (int i = 0; i < 4; i++)
		assert_int_equal(pthread_create(&t[i], NULL, refs_worker, &c), 0);
	for (int i = 0; i < 4; i++)
		pthread_join(t[i], NULL);
	assert_int_equal(atomic_load(&sum), 4 * 2000);
	assert_int_equal(atomic_load(&w->refs), 1);
	world_release(w); /* the last: freed */
	scene_free(sc);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_final_image_equals_direct_render),
		cmocka_unit_test(test_edits_cancel_and_restart),
		cmocka_unit_test(test_frame_at_ratio),
		cmocka_unit_test(test_accumulate),
		cmocka_unit_test(test_world_outlives_the_service),
		cmocka_unit_test(test_world_refcount),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
