/* rtsh embedded: load a scene, edit it, render a rectangle, read the pixels.
 * Built against include/rtsh/rtsh.h and librtsh.a alone (`make test` builds
 * and runs it). The scene is lit by its ambient light only, 0.2 of white, so
 * a white wall is 0.2 in linear light, and after the edit to pure red
 * (sRGB 255,0,0: linear 1,0,0) it is 0.2,0,0: values known by hand. */
#include <math.h>
#include <stdio.h>

#include "rtsh/rtsh.h"

int main(void)
{
	char err[512];
	rtsh_scene *sc = rtsh_load_text("A 0.2 255,255,255\nC 0,0,0 0,0,1 60\n"
	                                "pl 0,0,5 0,0,-1 255,255,255\n", "wall.rt", err, sizeof err);
	if (!sc || !rtsh_set(sc, "resolution", "64x48") || !rtsh_object_color(sc, 0, 255, 0, 0)) {
		fprintf(stderr, "embed: %s\n", sc ? rtsh_error(sc) : err);
		return 1;
	}
	rtsh_image *im = rtsh_render(sc, 16, 8, 48, 40); /* a 32x32 rectangle */
	if (!im) {
		fprintf(stderr, "embed: %s\n", rtsh_error(sc));
		return 1;
	}
	const float *px = rtsh_image_pixels(im);
	int n = rtsh_image_width(im) * rtsh_image_height(im), bad = 0;
	for (int i = 0; i < n; i++)
		bad += fabsf(px[3 * i] - 0.2f) > 1e-6f || px[3 * i + 1] != 0 || px[3 * i + 2] != 0;
	printf("%dx%d pixels, %d not 0.2,0,0\n", rtsh_image_width(im), rtsh_image_height(im), bad);
	rtsh_image_free(im);
	rtsh_free(sc);
	return bad != 0 || n != 32 * 32;
}
