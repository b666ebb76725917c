/* rtsh — fuzz target: the texture image readers by format (the first byte picks
 * PPM, PFM, XPM, or stb_image's PNG/JPEG/BMP/TGA/HDR), then the mip chain.
 * Build as fuzz_obj.c. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include "rtsh/memory.h"
#include "rtsh/texture.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerInitialize(int *argc, char ***argv);
const char *__lsan_default_suppressions(void);

/* Images too large for 512 MiB are refused up front (memory.h), well
 * inside libFuzzer's RSS limit. */
int LLVMFuzzerInitialize(int *argc, char ***argv)
{
	(void)argc, (void)argv;
	mem_set_limit((size_t)512 << 20);
	return 0;
}

/* libXpm (3.5.x) loses a few bytes in xpmParseColors when a colour line is
 * malformed, whatever its caller frees afterwards: not ours to fix. */
const char *__lsan_default_suppressions(void)
{
	return "leak:xpmParseColors\n";
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	static const char *const names[] = {"f.ppm", "f.pfm", "f.xpm", "f.png", "f.jpg", "f.bmp", "f.tga", "f.hdr"};
	if (size < 1)
		return 0;
	rt_error err;
	int w, h;
	float *rgb = image_decode_rgb(names[data[0] % 8], data + 1, size - 1, true, &w, &h, &err);
	if (rgb && (size_t)w * (size_t)h <= ((size_t)1 << 22)) {
		texture *t = texture_make(rgb, w, h, NULL, true, &err);
		if (t)
			texture_lookup(t, 0.3, 0.7, 0.01);
		texture_free(t);
	} else {
		free(rgb);
	}
	return 0;
}
