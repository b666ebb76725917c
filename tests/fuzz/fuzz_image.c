/* rtsh — libFuzzer target: the image readers (PPM P6 and PFM).
 *
 * The readers take a path, so each input is written to one file in a
 * private temporary folder and read back by both readers (each checks its
 * own magic). A crash, a leak, undefined behaviour, or an allocation beyond
 * libFuzzer's -rss_limit_mb / -malloc_limit_mb (a header promising a huge
 * image that the file does not hold) stops the fuzzer.
 *
 * The model and texture readers (OBJ, MTL, PLY, glTF, XPM, HDR) get their
 * own fuzz_NAME.c here as they land: the same shape, one reader per target.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "rtsh/image.h"

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char path[64];

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
	(void)argc, (void)argv;
	char dir[] = "/tmp/rtsh-fuzz-image-XXXXXX";
	if (!mkdtemp(dir))
		abort();
	snprintf(path, sizeof path, "%s/in", dir);
	return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	FILE *f = fopen(path, "wb");
	if (!f || fwrite(data, 1, size, f) != size || fclose(f) != 0)
		abort();
	rt_error err;
	framebuffer *fb = image_read_ppm(path, &err);
	if (fb) {
		/* Every code decodes to a linear value in [0,1]. */
		for (size_t i = 0; i < (size_t)fb->w * fb->h * 3; i++)
			if (!(fb->rgb[i] >= 0.0f && fb->rgb[i] <= 1.0f))
				abort();
		fb_free(fb);
	}
	fb = image_read_pfm(path, &err);
	fb_free(fb);
	return 0;
}
