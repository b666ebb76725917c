/* rtsh — the table of image formats (image.h): every format writes a file
 * that starts with its own signature (P6, PF, the PNG signature), every
 * readable one reads back what was written, dispatch is by extension in any
 * case, and the messages list exactly the table's extensions. */
#include "testutil.h"

#include <unistd.h>

#include "rtsh/image.h"

static void test_every_format(void **state)
{
	(void)state;
	framebuffer *fb = fb_new(5, 3);
	assert_non_null(fb);
	for (int i = 0; i < 5 * 3 * 3; i++)
		fb->rgb[i] = (float)(i % 7) / 7.0f;
	fb->spp = 1;
	char dir[] = "/tmp/rtsh-imgXXXXXX";
	assert_non_null(mkdtemp(dir));
	size_t n = 0;
	char all[256] = "";
	for (const image_type *t; (t = image_type_at(n)); n++) {
		char path[128], upper[16];
		snprintf(upper, sizeof upper, "%s", t->ext);
		for (char *c = upper; *c; c++)
			*c = (char)(*c >= 'a' && *c <= 'z' ? *c - 32 : *c);
		snprintf(path, sizeof path, "%s/x%s", dir, upper); /* the extension in capitals */
		assert_ptr_equal(image_type_of(path), t);
		rt_error err;
		if (!image_write(path, fb, 0, &err))
			fail_msg("%s: %s", t->ext, err.msg);
		FILE *f = fopen(path, "rb");
		assert_non_null(f);
		unsigned char head[8] = {0};
		assert_true(fread(head, 1, 8, f) == 8);
		fclose(f);
		const char *sig = strcmp(t->name, "PPM") == 0   ? "P6"
		                  : strcmp(t->name, "PFM") == 0 ? "PF"
		                  : strcmp(t->name, "JPEG") == 0 ? "\xff\xd8\xff" /* SOI, then a marker */
		                                            : "\x89PNG";
		assert_memory_equal(head, sig, strlen(sig));
		if (t->read) {
			framebuffer *back = image_read(path, &err);
			if (!back)
				fail_msg("%s: %s", t->ext, err.msg);
			assert_int_equal(back->w, 5);
			assert_int_equal(back->h, 3);
			double tol = strcmp(t->name, "PFM") == 0? 0 : 0.02; /* 8-bit sRGB codes */
			for (int i = 0; i < 5 * 3 * 3; i++)
				assert_near(back->rgb[i], fb->rgb[i], tol);
			fb_free(back);
		}
		unlink(path);
		size_t used = strlen(all);
		snprintf(all + used, sizeof all - used, "%s%s", n ? " " : "", t->ext);
	}
	assert_true(n >= 3);
	assert_string_equal(all, ".ppm .pfm .png .jpg .jpeg");
	/* an unknown extension: the message lists the table */
	char path[128];
	snprintf(path, sizeof path, "%s/x.bmp", dir);
	rt_error err;
	assert_false(image_write(path, fb, 0, &err));
	assert_non_null(strstr(err.msg, "expected .ppm, .pfm, .png, .jpg or .jpeg"));
	assert_null(image_read(path, &err));
	assert_non_null(strstr(err.msg, "expected .ppm or .pfm"));
	char exts[64];
	image_extensions(exts, sizeof exts, true);
	assert_string_equal(exts, ".ppm or .pfm");
	rmdir(dir);
	fb_free(fb);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_every_format),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
