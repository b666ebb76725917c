/* rtsh — tests of the pixel protocols (term/pixels.h). Each protocol's
 * bytes are read back by a decoder written here from the protocol's own
 * documentation, never by the code under test:
 *   - kitty: APC \e_G<keys>;<payload>\e\\ chunks (m=1 but the last, keys on
 *     the first only, payload <= 4096), base64, zlib (o=z), f=24 RGB of
 *     s x v pixels (sw.kovidgoyal.net/kitty/graphics-protocol);
 *   - iTerm2: OSC 1337;File=inline=1;size=N...:<base64 PNG> BEL, the PNG read
 *     back with libpng (iterm2.com/documentation-images.html);
 *   - sixel: DCS ... q, "Pan;Pad;Ph;Pv, #Pc;2;R;G;B in percent, #Pc,
 *     !Pn repeats, $ carriage return, - next band, data bytes 0x3f..0x7e
 *     whose bit k is the pixel k rows down (VT330/VT340 Programmer
 *     Reference Manual, ch. 14);
 *   - base64 by RFC 4648's test vectors;
 *   - answers to the start-up questions, a terminal that answers nothing
 *     (no hang, half blocks) and one that answers DA1 with sixel, on a pty. */
#include "testutil.h"

#include <poll.h>
#include <pthread.h>
#include <pty.h>
#include <signal.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <png.h>
#include <zlib.h>

#include "term/encoder.h"
#include "term/pixels.h"

/* --- a picture --------------------------------------------------------------- */

/* A w x h picture: smooth gradients and a few hard edges (deterministic). */
static uint8_t *picture(int w, int h, int colors)
{
	uint8_t *p = malloc((size_t)w * h * 3);
	assert_non_null(p);
	for (int y = 0; y < h; y++)
		for (int x = 0; x < w; x++) {
			uint8_t *q = p + ((size_t)y * w + x) * 3;
			if (colors) { /* a few flat colours in blocks */
				int k = (x / 7 + y / 5) % colors;
				q[0] = (uint8_t)(k * 255 / colors);
				q[1] = (uint8_t)(255 - k * 200 / colors);
				q[2] = (uint8_t)(k & 1 ? 200 : 30);
			} else {
				q[0] = (uint8_t)(x * 255 / (w - 1));
				q[1] = (uint8_t)(y * 255 / (h - 1));
				q[2] = (uint8_t)((x ^ y) & 0x80 ? 220 : 40);
			}
		}
	return p;
}

/* --- base64 ---------------------------------------------------------------- */

static int b64_value(char c)
{
	if (c >= 'A' && c <= 'Z')
		return c - 'A';
	if (c >= 'a' && c <= 'z')
		return c - 'a' + 26;
	if (c >= '0' && c <= '9')
		return c - '0' + 52;
	if (c == '+')
		return 62;
	if (c == '/')
		return 63;
	return -1;
}

/* Decodes n base64 characters (padding included) into out; the length. */
static size_t b64_decode(const char *s, size_t n, uint8_t *out)
{
	size_t o = 0;
	uint32_t acc = 0;
	int bits = 0;
	for (size_t i = 0; i < n && s[i] != '='; i++) {
		int v = b64_value(s[i]);
		if (v < 0)
			fail_msg("not base64: 0x%02x at %zu", (unsigned char)s[i], i);
		acc = acc << 6 | (uint32_t)v;
		bits += 6;
		if (bits >= 8) {
			bits -= 8;
			out[o++] = (uint8_t)(acc >> bits);
		}
	}
	return o;
}

static void test_base64(void **state)
{
	(void)state;
	const char *in[] = {"", "f", "fo", "foo", "foob", "fooba", "foobar"};
	const char *want[] = {"", "Zg==", "Zm8=", "Zm9v", "Zm9vYg==", "Zm9vYmE=", "Zm9vYmFy"};
	for (int i = 0; i < 7; i++) {
		abuf a;
		abuf_init(&a);
		pixels_base64(&a, (const uint8_t *)in[i], strlen(in[i]));
		assert_int_equal(a.len, strlen(want[i]));
		assert_memory_equal(a.b, want[i], a.len);
		abuf_free(&a);
	}
}

/* --- kitty ------------------------------------------------------------------ */

typedef struct kitty_image {
	char keys[256];   /* the first chunk's keys */
	int w, h;         /* s, v */
	uint8_t *rgb;     /* decoded, w*h*3 */
	int chunks;
} kitty_image;

/* The value of key k in "a=T,f=24,..." (-1 when absent; a letter value as
 * its character code). */
static long key(const char *keys, const char *k)
{
	size_t n = strlen(k);
	for (const char *p = keys; *p;) {
		if (strncmp(p, k, n) == 0 && p[n] == '=') {
			const char *v = p + n + 1;
			return (*v >= '0' && *v <= '9') ? strtol(v, NULL, 10) : (long)*v;
		}
		p = strchr(p, ',');
		if (!p)
			break;
		p++;
	}
	return -1;
}

/* Reads one kitty image (its chunks) from s; text between chunks is
 * allowed and skipped. */
static void kitty_decode(const char *s, size_t n, kitty_image *img)
{
	memset(img, 0, sizeof *img);
	char *payload = malloc(n + 1);
	assert_non_null(payload);
	size_t plen = 0;
	bool more = true;
	for (size_t i = 0; i < n && more;) {
		if (!(s[i] == 0x1b && i + 2 < n && s[i + 1] == '_' && s[i + 2] == 'G')) {
			i++;
			continue;
		}
		size_t j = i + 3, semi = 0;
		while (j + 1 < n && !(s[j] == 0x1b && s[j + 1] == '\\')) {
			if (s[j] == ';' && !semi)
				semi = j;
			j++;
		}
		assert_true(j + 1 < n && semi);
		char keys[256];
		assert_true(semi - (i + 3) < sizeof keys);
		memcpy(keys, s + i + 3, semi - (i + 3));
		keys[semi - (i + 3)] = '\0';
		if (img->chunks == 0) {
			snprintf(img->keys, sizeof img->keys, "%s", keys);
		} else {
			/* later chunks carry only m (and q) */
			for (char *p = keys; *p; p++)
				if (p == keys || p[-1] == ',')
					assert_true(*p == 'm' || *p == 'q');
		}
		size_t len = j - semi - 1;
		assert_true(len <= 4096);
		memcpy(payload + plen, s + semi + 1, len);
		plen += len;
		more = key(keys, "m") == 1;
		img->chunks++;
		i = j + 2;
	}
	assert_false(more);
	img->w = (int)key(img->keys, "s");
	img->h = (int)key(img->keys, "v");
	assert_true(img->w > 0 && img->h > 0);
	uint8_t *z = malloc(plen);
	assert_non_null(z);
	size_t zn = b64_decode(payload, plen, z);
	uLongf rn = (uLongf)img->w * img->h * 3;
	img->rgb = malloc(rn);
	assert_non_null(img->rgb);
	assert_int_equal(key(img->keys, "o"), 'z');
	assert_int_equal(uncompress(img->rgb, &rn, z, (uLong)zn), Z_OK);
	assert_int_equal(rn, (uLongf)img->w * img->h * 3);
	free(z);
	free(payload);
}

static void test_kitty(void **state)
{
	(void)state;
	const int sizes[][2] = {{1, 1}, {37, 23}, {320, 180}};
	for (int k = 0; k < 3; k++) {
		int w = sizes[k][0], h = sizes[k][1];
		uint8_t *rgb = w > 1 ? picture(w, h, 0) : calloc(3, 1);
		assert_non_null(rgb);
		abuf a;
		abuf_init(&a);
		abuf_str(&a, "text before");
		assert_true(pixels_kitty(&a, rgb, w, h, 40, 12, PIXELS_KITTY_ID + k));
		kitty_image img;
		kitty_decode(a.b, a.len, &img);
		assert_int_equal(key(img.keys, "a"), 'T');
		assert_int_equal(key(img.keys, "f"), 24);
		assert_int_equal(key(img.keys, "i"), PIXELS_KITTY_ID + k);
		assert_int_equal(key(img.keys, "p"), 1);
		assert_int_equal(key(img.keys, "c"), 40);
		assert_int_equal(key(img.keys, "r"), 12);
		assert_int_equal(key(img.keys, "q"), 2);
		assert_int_equal(key(img.keys, "C"), 1);
		assert_int_equal(img.w, w);
		assert_int_equal(img.h, h);
		assert_memory_equal(img.rgb, rgb, (size_t)w * h * 3);
		if (k == 2)
			assert_true(img.chunks > 1);
		free(img.rgb);
		abuf_free(&a);
		free(rgb);
	}
	abuf a;
	abuf_init(&a);
	pixels_kitty_delete(&a, 77);
	const char *want = "\x1b_Ga=d,d=I,i=77,q=2\x1b\\";
	assert_int_equal(a.len, strlen(want));
	assert_memory_equal(a.b, want, a.len);
	abuf_free(&a);
}

/* --- iTerm2 ---------------------------------------------------------------- */

static void test_iterm(void **state)
{
	(void)state;
	int w = 61, h = 33;
	uint8_t *rgb = picture(w, h, 0);
	abuf a;
	abuf_init(&a);
	assert_true(pixels_iterm(&a, rgb, w, h, 30, 16));
	abuf_char(&a, '\0');
	const char *osc = strstr(a.b, "\x1b]1337;File=");
	assert_non_null(osc);
	const char *colon = strchr(osc, ':'), *bel = strchr(osc, '\a');
	assert_true(colon && bel && colon < bel);
	char args[256];
	snprintf(args, sizeof args, "%.*s", (int)(colon - osc), osc);
	assert_non_null(strstr(args, "inline=1"));
	assert_non_null(strstr(args, ";width=30;"));
	assert_non_null(strstr(args, ";height=16;"));
	const char *sz = strstr(args, "size=");
	assert_non_null(sz);
	size_t size = strtoul(sz + 5, NULL, 10);
	uint8_t *file = malloc((size_t)(bel - colon));
	assert_non_null(file);
	size_t n = b64_decode(colon + 1, (size_t)(bel - colon - 1), file);
	assert_int_equal(n, size);
	png_image im;
	memset(&im, 0, sizeof im);
	im.version = PNG_IMAGE_VERSION;
	assert_true(png_image_begin_read_from_memory(&im, file, n));
	im.format = PNG_FORMAT_RGB;
	assert_int_equal(im.width, (png_uint_32)w);
	assert_int_equal(im.height, (png_uint_32)h);
	uint8_t *back = malloc(PNG_IMAGE_SIZE(im));
	assert_non_null(back);
	assert_true(png_image_finish_read(&im, NULL, back, 0, NULL));
	assert_memory_equal(back, rgb, (size_t)w * h * 3);
	free(back);
	free(file);
	abuf_free(&a);
	free(rgb);
}

/* --- sixel ----------------------------------------------------------------- */

/* Decodes the first sixel image in s into a w x h picture (pixels never
 * drawn stay 0); the number of colour registers defined. */
static int sixel_decode(const char *s, size_t n, uint8_t *out, int w, int h)
{
	const char *p = s, *end = s + n;
	while (p + 1 < end && !(p[0] == 0x1b && p[1] == 'P'))
		p++;
	assert_true(p + 1 < end);
	p += 2;
	while (p < end && *p != 'q')
		p++; /* P1;P2;P3 */
	assert_true(p < end);
	p++;
	uint8_t pal[256][3] = {{0}};
	int cur = 0, x = 0, band = 0, defined = 0, raster_w = 0, raster_h = 0;
	while (p < end && !(p[0] == 0x1b)) {
		char c = *p;
		if (c == '"') { /* raster attributes Pan;Pad;Ph;Pv */
			long v[4] = {0};
			int k = 0;
			p++;
			while (p < end && ((*p >= '0' && *p <= '9') || *p == ';')) {
				if (*p == ';')
					k++;
				else if (k < 4)
					v[k] = v[k] * 10 + (*p - '0');
				p++;
			}
			raster_w = (int)v[2];
			raster_h = (int)v[3];
			continue;
		}
		if (c == '#') {
			long v[5] = {0};
			int k = 0;
			p++;
			while (p < end && ((*p >= '0' && *p <= '9') || *p == ';')) {
				if (*p == ';')
					k++;
				else if (k < 5)
					v[k] = v[k] * 10 + (*p - '0');
				p++;
			}
			assert_true(v[0] >= 0 && v[0] < 256);
			cur = (int)v[0];
			if (k == 4) { /* a definition: Pu = 2, RGB in percent */
				assert_int_equal(v[1], 2);
				for (int i = 0; i < 3; i++)
					pal[cur][i] = (uint8_t)((v[2 + i] * 255 + 50) / 100);
				defined++;
			}
			continue;
		}
		if (c == '$') {
			x = 0;
			p++;
			continue;
		}
		if (c == '-') {
			x = 0;
			band++;
			p++;
			continue;
		}
		int count = 1;
		if (c == '!') {
			count = 0;
			p++;
			while (p < end && *p >= '0' && *p <= '9')
				count = count * 10 + (*p++ - '0');
			c = *p;
		}
		if (c >= 0x3f && c <= 0x7e) {
			int bits = c - 0x3f;
			for (int i = 0; i < count; i++, x++)
				for (int b = 0; b < 6; b++)
					if (bits & (1 << b)) {
						int y = band * 6 + b;
						if (x < w && y < h)
							memcpy(out + ((size_t)y * w + x) * 3, pal[cur], 3);
					}
		}
		p++;
	}
	assert_true(p + 1 < end && p[1] == '\\');
	assert_int_equal(raster_w, w);
	assert_int_equal(raster_h, h);
	return defined;
}

static void test_sixel(void **state)
{
	(void)state;
	/* Few colours: every pixel comes back within libsixel's rounding
	 * (its histogram keeps 5 bits a channel: up to 7 levels low) and the
	 * percent's (1.3 levels). */
	int w = 50, h = 31;
	uint8_t *rgb = picture(w, h, 6);
	uint8_t *back = calloc((size_t)w * h * 3, 1);
	assert_non_null(back);
	abuf a;
	abuf_init(&a);
	assert_true(pixels_sixel(&a, rgb, w, h));
	int defined = sixel_decode(a.b, a.len, back, w, h);
	assert_true(defined >= 6 && defined <= 256);
	for (size_t i = 0; i < (size_t)w * h * 3; i++)
		if (abs(back[i] - rgb[i]) > 9)
			fail_msg("pixel %zu channel %zu: %d, expected %d", i / 3, i % 3, back[i], rgb[i]);
	abuf_free(&a);
	free(back);
	free(rgb);
	/* A gradient of thousands of colours: 256 registers, a small mean
	 * error, every pixel drawn. */
	w = 160;
	h = 96;
	rgb = picture(w, h, 0);
	back = calloc((size_t)w * h * 3, 1);
	assert_non_null(back);
	abuf_init(&a);
	assert_true(pixels_sixel(&a, rgb, w, h));
	defined = sixel_decode(a.b, a.len, back, w, h);
	assert_true(defined <= 256);
	double err = 0;
	for (size_t i = 0; i < (size_t)w * h * 3; i++)
		err += abs(back[i] - rgb[i]);
	err /= (double)w * h * 3;
	print_message("sixel: %d colours, mean error %.2f levels of 255 on a %dx%d gradient\n", defined, err,
	              w, h);
	assert_true(err < 8.0);
	abuf_free(&a);
	free(back);
	free(rgb);
}

/* The sixel encoder sends the picture in tiles of one cell row, at most
 * 256 pixels (and the terminal's largest sixel) across, each placed at its
 * own cell: decoded and put together they give the picture back; a slice
 * of budget 1 holds one tile. The cursor is hidden from before the cursor
 * move to after the image: xterm -ti vt340 drew its cursor on a tile's
 * first cell while the image's bytes were still coming, and painted that
 * cell over the image as text when the cursor left: a cell-sized hole in
 * the background colour (issue 31, defect 8). */
static void test_sixel_tiles(void **state)
{
	(void)state;
	const int cols = 70, rows = 5, cw = 8, ch = 16, w = cols * cw, h = rows * ch;
	const int max_w[2] = {0, 100}, tile_px[2] = {256, 96}; /* 256 / 8 and 100 / 8 cells */
	uint8_t *rgb = picture(w, h, 0);
	for (int m = 0; m < 2; m++) {
		encoder_geom g = {.cols = cols, .rows = rows, .x0 = 3, .y0 = 2, .cell_w = cw, .cell_h = ch,
		                  .max_w = max_w[m]};
		encoder *e = encoder_sixel.open(&g);
		assert_non_null(e);
		encoder_put(e, rgb, w, h, 0, 0);
		uint8_t *back = calloc((size_t)w * h * 3, 1), *tile = malloc((size_t)256 * ch * 3);
		bool *drawn = calloc((size_t)w * h, 1);
		assert_true(back && tile && drawn);
		int tiles = 0, slices = 0;
		for (bool more = true; more; slices++) {
			abuf a;
			abuf_init(&a);
			more = encoder_update(e, &a, 1);
			/* one tile: ESC 7, cursor hidden, ESC [ row ; col H, the
			 * image, ESC 8, cursor shown */
			int r, c, used = 0;
			assert_int_equal(sscanf(a.b, "\x1b" "7\x1b[?25l\x1b[%d;%dH%n", &r, &c, &used), 2);
			assert_true(used > 0 && a.b[used] == 0x1b && a.b[used + 1] == 'P');
			int x0 = (c - 1 - g.x0) * cw, y0 = (r - 1 - g.y0) * ch;
			int tw = w - x0 < tile_px[m] ? w - x0 : tile_px[m];
			assert_true(x0 >= 0 && x0 % tile_px[m] == 0 && y0 >= 0 && y0 < h);
			sixel_decode(a.b + used, a.len - (size_t)used, tile, tw, ch); /* checks its size */
			for (int y = 0; y < ch; y++)
				for (int x = 0; x < tw; x++) {
					size_t i = (size_t)(y0 + y) * w + x0 + x;
					assert_false(drawn[i]);
					drawn[i] = true;
					memcpy(back + i * 3, tile + ((size_t)y * tw + x) * 3, 3);
				}
			assert_memory_equal(a.b + a.len - 8, "\x1b" "8\x1b[?25h", 8);
			assert_null(strstr(a.b + used + 2, "\x1bP")); /* one image a slice */
			tiles++;
			abuf_free(&a);
		}
		int across = (w + tile_px[m] - 1) / tile_px[m];
		assert_int_equal(tiles, across * rows);
		assert_false(encoder_dirty(e));
		double err = 0;
		for (size_t i = 0; i < (size_t)w * h; i++) {
			assert_true(drawn[i]);
			for (int k = 0; k < 3; k++)
				err += abs(back[i * 3 + k] - rgb[i * 3 + k]);
		}
		err /= (double)w * h * 3;
		print_message("sixel tiles of %d px across: %d tiles, mean error %.2f levels of 255\n",
		              tile_px[m], tiles, err);
		assert_true(err < 8.0);
		free(back);
		free(tile);
		free(drawn);
		encoder_close(e);
	}
	free(rgb);
}

/* Inside tmux with allow-passthrough on: each tile is one passthrough,
 * \ePtmux; ... \e\\ with every ESC inside doubled, and its cursor move is
 * in the outer terminal's cells (the pane's place added). */
static void test_tmux_passthrough(void **state)
{
	(void)state;
	abuf a;
	abuf_init(&a);
	pixels_passthrough(&a, "x\x1b[1;2Hy\x1b\\", 10);
	assert_int_equal(a.len, 7 + 12 + 2);
	assert_memory_equal(a.b, "\x1bPtmux;x\x1b\x1b[1;2Hy\x1b\x1b\\\x1b\\", a.len);
	abuf_free(&a);
	const int cols = 10, rows = 2, cw = 8, ch = 16;
	uint8_t *rgb = picture(cols * cw, rows * ch, 0);
	encoder_geom g = {.cols = cols, .rows = rows, .x0 = 0, .y0 = 1, .cell_w = cw, .cell_h = ch,
	                  .passthrough = true, .pass_x = 40, .pass_y = 5};
	encoder *e = encoder_sixel.open(&g);
	assert_non_null(e);
	encoder_put(e, rgb, cols * cw, rows * ch, 0, 0);
	abuf_init(&a);
	encoder_update(e, &a, 1); /* the first tile (and maybe the second) */
	/* ESC 7, the cursor hidden, moved to row 5+1+1, column 40+0+1 */
	const char head[] = "\x1bPtmux;\x1b\x1b" "7\x1b\x1b[?25l\x1b\x1b[7;41H\x1b\x1bP";
	assert_memory_equal(a.b, head, sizeof head - 1);
	assert_memory_equal(a.b + a.len - 2, "\x1b\\", 2);
	/* no ESC alone inside: each one doubled but the last two */
	for (size_t i = 7; i + 2 < a.len; i++)
		if (a.b[i] == 0x1b) {
			assert_true(a.b[i + 1] == 0x1b);
			i++;
		}
	abuf_free(&a);
	encoder_close(e);
	free(rgb);
}

/* --- answers ----------------------------------------------------------------- */

static void test_answers(void **state)
{
	(void)state;
	pixels_caps c;
	memset(&c, 0, sizeof c);
	char buf[] = "a\x1b_Gi=31;OK\x1b\\b\x1b[?2;0;1600;900S\x1b[6;20;10tc\x1b[?62;4;22c\x1b[Ad";
	size_t n = strlen(buf);
	size_t taken = pixels_take_answers(&c, buf, n);
	assert_int_equal(n - taken, 7);
	assert_memory_equal(buf, "abc\x1b[Ad", 7); /* the keys, an arrow among them */
	assert_true(c.kitty && c.sixel && c.da1);
	assert_int_equal(c.sixel_w, 1600);
	assert_int_equal(c.sixel_h, 900);
	assert_int_equal(c.cell_w, 10);
	assert_int_equal(c.cell_h, 20);
	assert_int_equal(pixels_choose(&c), PIXELS_KITTY);
	/* a kitty error, a DA1 without 4 */
	memset(&c, 0, sizeof c);
	char buf2[] = "\x1b_Gi=31;ENOTSUPPORTED:no\x1b\\\x1b[?1;2c";
	pixels_take_answers(&c, buf2, strlen(buf2));
	assert_false(c.kitty);
	assert_false(c.sixel);
	assert_true(c.da1);
	assert_int_equal(pixels_choose(&c), PIXELS_OFF);
	pixels_caps_env(&c, NULL, "iTerm2", NULL);
	assert_int_equal(pixels_choose(&c), PIXELS_ITERM);
	pixels_caps_env(&c, "iTerm.app", NULL, "/tmp/tmux-0/default,1,0");
	assert_int_equal(pixels_choose(&c), PIXELS_OFF); /* in tmux */
	c.sixel = true;
	assert_int_equal(pixels_choose(&c), PIXELS_SIXEL); /* tmux draws sixel itself */
	pixels_mode m;
	assert_true(pixels_mode_parse("sixel", &m));
	assert_int_equal(m, PIXELS_SIXEL);
	assert_false(pixels_mode_parse("png", &m));
	assert_string_equal(pixels_mode_name(PIXELS_ITERM), "iterm");
}

/* --- real ptys ----------------------------------------------------------------- */

static double mono(void)
{
	struct timespec t;
	clock_gettime(CLOCK_MONOTONIC, &t);
	return (double)t.tv_sec + t.tv_nsec * 1e-9;
}

/* A terminal that answers nothing: the probe gives up after its timeout,
 * finds nothing, and keys typed meanwhile are kept. */
static void test_silent_terminal(void **state)
{
	(void)state;
	int master, slave;
	assert_int_equal(openpty(&master, &slave, NULL, NULL, NULL), 0);
	assert_int_equal(write(master, "xy", 2), 2); /* typed ahead */
	pixels_caps c;
	memset(&c, 0, sizeof c);
	abuf keys;
	abuf_init(&keys);
	double t0 = mono();
	pixels_probe(slave, slave, 0.3, &c, &keys);
	double dt = mono() - t0;
	print_message("a terminal that answers nothing: the probe gave up after %.2f s\n", dt);
	assert_true(dt >= 0.29 && dt < 1.5);
	assert_false(c.da1);
	assert_int_equal(pixels_choose(&c), PIXELS_OFF);
	assert_int_equal(keys.len, 2);
	assert_memory_equal(keys.b, "xy", 2);
	/* the questions went out, DA1 last */
	char out[256];
	ssize_t got = read(master, out, sizeof out - 1);
	assert_true(got > 0);
	out[got] = '\0';
	assert_non_null(strstr(out, "\x1b_Gi=31"));
	assert_non_null(strstr(out, "\x1b[c"));
	abuf_free(&keys);
	close(master);
	close(slave);
}

typedef struct answerer {
	int fd;
	const char *reply;
} answerer;

/* Plays a terminal: waits for DA1, then answers. */
static void *answer(void *arg)
{
	answerer *a = arg;
	char buf[512];
	size_t have = 0;
	while (have < sizeof buf - 1) {
		struct pollfd p = {a->fd, POLLIN, 0};
		if (poll(&p, 1, 2000) <= 0)
			break;
		ssize_t n = read(a->fd, buf + have, sizeof buf - 1 - have);
		if (n <= 0)
			break;
		have += (size_t)n;
		buf[have] = '\0';
		if (strstr(buf, "\x1b[c")) {
			assert_true(write(a->fd, a->reply, strlen(a->reply)) > 0);
			break;
		}
	}
	return NULL;
}

static void test_sixel_terminal(void **state)
{
	(void)state;
	int master, slave;
	assert_int_equal(openpty(&master, &slave, NULL, NULL, NULL), 0);
	answerer a = {master, "\x1b[?2;0;1000;1000S\x1b[6;16;8t\x1b[?63;1;4;22c"};
	pthread_t t;
	assert_int_equal(pthread_create(&t, NULL, answer, &a), 0);
	pixels_caps c;
	memset(&c, 0, sizeof c);
	abuf keys;
	abuf_init(&keys);
	double t0 = mono();
	pixels_probe(slave, slave, 5.0, &c, &keys);
	double dt = mono() - t0;
	pthread_join(t, NULL);
	assert_true(dt < 2.0); /* done at DA1's answer, not at the timeout */
	assert_true(c.da1 && c.sixel && !c.kitty);
	assert_int_equal(c.cell_w, 8);
	assert_int_equal(c.cell_h, 16);
	assert_int_equal(pixels_choose(&c), PIXELS_SIXEL);
	assert_int_equal(keys.len, 0);
	abuf_free(&keys);
	close(master);
	close(slave);
}

/* rtsh itself, with --pixels auto, on a terminal that answers nothing:
 * it does not hang, it draws half blocks and no picture escape sequence,
 * and it still takes commands. */
static void test_rtsh_silent_terminal(void **state)
{
	(void)state;
	int master;
	struct winsize ws = {30, 100, 1000, 600};
	pid_t pid = forkpty(&master, NULL, NULL, &ws);
	assert_true(pid >= 0);
	if (pid == 0) {
		setenv("TERM", "xterm-256color", 1);
		unsetenv("TMUX");
		execl(test_rtsh_bin(), "rtsh", "scenes/basic.rt", "--pixels", "auto", (char *)NULL);
		_exit(127);
	}
	abuf got;
	abuf_init(&got);
	double t0 = mono();
	bool quit_sent = false;
	int status = -1;
	while (mono() - t0 < 15) {
		struct pollfd p = {master, POLLIN, 0};
		if (poll(&p, 1, 100) > 0) {
			char buf[4096];
			ssize_t n = read(master, buf, sizeof buf);
			if (n <= 0)
				break;
			abuf_add(&got, buf, (size_t)n);
		}
		/* after the probe's time-out (2 s) and a frame */
		if (!quit_sent && mono() - t0 > 4) {
			assert_int_equal(write(master, "quit\r", 5), 5);
			quit_sent = true;
		}
		if (quit_sent && waitpid(pid, &status, WNOHANG) == pid)
			break;
	}
	/* the pty closes as rtsh exits: wait for it a little */
	for (double t1 = mono(); status == -1 && mono() - t1 < 5;)
		if (waitpid(pid, &status, WNOHANG) != pid)
			usleep(10000);
	if (status == -1) {
		kill(pid, SIGKILL);
		waitpid(pid, &status, 0);
		fail_msg("rtsh did not quit on a terminal that answers nothing");
	}
	abuf_char(&got, '\0');
	assert_true(WIFEXITED(status) && WEXITSTATUS(status) == 0);
	assert_non_null(strstr(got.b, "\xe2\x96\x80")); /* the upper half block */
	assert_null(strstr(got.b, "\x1b_Ga=T"));        /* no kitty image */
	assert_null(strstr(got.b, "\x1b]1337;File"));   /* no iTerm2 image */
	const char *q = got.b;
	while ((q = strstr(q, "\x1bP")) != NULL) {     /* no sixel (DCS ... q) */
		const char *e = q + 2;
		while (*e >= '0' && *e <= ';')
			e++;
		assert_true(*e != 'q');
		q = e;
	}
	abuf_free(&got);
	close(master);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_base64),
		cmocka_unit_test(test_kitty),
		cmocka_unit_test(test_iterm),
		cmocka_unit_test(test_sixel),
		cmocka_unit_test(test_sixel_tiles),
		cmocka_unit_test(test_tmux_passthrough),
		cmocka_unit_test(test_answers),
		cmocka_unit_test(test_silent_terminal),
		cmocka_unit_test(test_sixel_terminal),
		cmocka_unit_test(test_rtsh_silent_terminal),
	};
	return cmocka_run_group_tests_name("pixels", tests, NULL, NULL);
}
