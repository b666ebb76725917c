/* rtsh — every model and texture reader is linear in its input (issue 31,
 * defect 2): four times the input costs at most five times the work.
 *
 * The work is the process's instructions (perf_event_open) where the
 * machine counts them, else its user CPU time (getrusage: time other
 * processes take is not counted, unlike wall-clock time, nor the kernel's,
 * as the instruction count leaves it out). Each case
 * finds a size n whose load costs at least MIN_COST_NS (doubling from a
 * small start, so that a quadratic reader fails fast instead of running for
 * minutes), then loads n and 4n alternately, five times each, and compares
 * the least costs (a second round when the first looks too high: see
 * check_growth). Under a sanitizer the costs mean nothing: the test says it
 * is skipped. The inputs are the hostile ones of the issue: one triangle
 * repeated (every corner shared by every face), one polygon of n corners
 * (a fan whose first corner every triangle shares), and ordinary grids as a
 * control, in OBJ, ASCII and binary PLY, STL (assimp), GLB (glTF) and
 * textures (PPM, PFM, PNG). */
#include "testutil.h"

#include <linux/perf_event.h>
#include <sys/ioctl.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

#include "rtsh/image.h"
#include "rtsh/mesh.h"
#include "rtsh/texture.h"

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define SANITIZED 1
#endif
#endif
#ifndef SANITIZED
#define SANITIZED 0
#endif

/* The smallest cost of the smaller load: 60 ms of CPU (or the instructions
 * of about as much), large against the clock's and the scheduler's grain. */
#define MIN_COST_NS 60e6
#define MIN_COST_INSTR 150e6
#define RUNS 5
/* About 5x: linear work gives 4x, the triangle tree's SAH build (n log n)
 * about 4.5x at these sizes, and larger arrays outgrow the caches (plain
 * grids measured 4.4x to 5.5x on a loaded 2-core machine, the hostile
 * inputs 4.0x to 4.6x); a quadratic reader gives 16x. */
#define MAX_RATIO 6.0

static char tmpdir[64];
static int perf_fd = -1;

static int setup(void **state)
{
	(void)state;
	snprintf(tmpdir, sizeof tmpdir, "/tmp/rtsh-growth-XXXXXX");
	if (!mkdtemp(tmpdir))
		return -1;
	struct perf_event_attr a;
	memset(&a, 0, sizeof a);
	a.type = PERF_TYPE_HARDWARE;
	a.size = sizeof a;
	a.config = PERF_COUNT_HW_INSTRUCTIONS;
	a.exclude_kernel = 1;
	a.exclude_hv = 1;
	a.inherit = 1; /* the threads a load starts */
	perf_fd = (int)syscall(SYS_perf_event_open, &a, 0, -1, -1, 0);
	print_message("work counted as %s\n", perf_fd >= 0 ? "instructions (perf_event_open)"
	                                                   : "process CPU time (no instruction counter here)");
	return 0;
}

static int teardown(void **state)
{
	(void)state;
	if (perf_fd >= 0)
		close(perf_fd);
	char cmd[128];
	snprintf(cmd, sizeof cmd, "rm -rf %s", tmpdir);
	return system(cmd) == 0 ? 0 : -1;
}

static double work_now(void)
{
	if (perf_fd >= 0) {
		uint64_t c = 0;
		if (read(perf_fd, &c, sizeof c) == (ssize_t)sizeof c)
			return (double)c;
	}
	/* the user part, as the instructions counted above (exclude_kernel):
	 * the kernel's work for fresh pages grows with what the rest of the
	 * machine holds, not with the reader's input (hostile2: loads of
	 * 2^18-2^20 copies of one STL facet, dropped as duplicates since, spent
	 * 24% to 40% of their CPU time in page faults) */
	struct rusage ru;
	getrusage(RUSAGE_SELF, &ru);
	return ru.ru_utime.tv_sec * 1e9 + ru.ru_utime.tv_usec * 1e3;
}

/* A growable byte buffer for the generated files. */
typedef struct bytes {
	char *b;
	size_t n, cap;
} bytes;

static void put(bytes *o, const void *p, size_t n)
{
	if (o->n + n > o->cap) {
		o->cap = (o->n + n) * 2 + 4096;
		o->b = realloc(o->b, o->cap);
		assert_non_null(o->b);
	}
	memcpy(o->b + o->n, p, n);
	o->n += n;
}

static void putf(bytes *o, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void putf(bytes *o, const char *fmt, ...)
{
	char line[256];
	va_list ap;
	va_start(ap, fmt);
	int n = vsnprintf(line, sizeof line, fmt, ap);
	va_end(ap);
	put(o, line, (size_t)n);
}

static void put_f32(bytes *o, float v)
{
	put(o, &v, 4); /* little-endian machines: the formats below say so */
}

static void put_u32(bytes *o, uint32_t v)
{
	put(o, &v, 4);
}

/* --- the inputs: a case makes the file of size n --- */

typedef enum kind { K_OBJ, K_PLY, K_STL, K_GLB, K_TEX, K_PNG } kind;

typedef struct gcase {
	const char *name; /* also the file's name */
	kind k;
	void (*make)(bytes *o, size_t n);
	size_t start; /* the first n tried */
} gcase;

static void obj_same(bytes *o, size_t n)
{
	putf(o, "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
	for (size_t i = 0; i < n; i++)
		putf(o, "f 1 2 3\n");
}

/* n corners on a circle: one convex polygon. */
static void obj_polygon(bytes *o, size_t n)
{
	for (size_t i = 0; i < n; i++) {
		double a = 2 * M_PI * (double)i / (double)n;
		putf(o, "v %.9f %.9f 0\n", cos(a), sin(a));
	}
	putf(o, "f");
	for (size_t i = 0; i < n; i++)
		putf(o, " %zu", i + 1);
	putf(o, "\n");
}

/* A bumpy grid of about n triangles (a control: what a model looks like). */
static void obj_grid(bytes *o, size_t n)
{
	size_t w = 2;
	while (2 * w * w < n)
		w++;
	for (size_t y = 0; y <= w; y++)
		for (size_t x = 0; x <= w; x++)
			putf(o, "v %zu %zu %.6f\n", x, y, 0.3 * sin(0.7 * (double)x) * cos(0.5 * (double)y));
	for (size_t y = 0; y < w; y++)
		for (size_t x = 0; x < w; x++) {
			size_t a = y * (w + 1) + x + 1, b = a + 1, c = a + w + 1, d = c + 1;
			putf(o, "f %zu %zu %zu\nf %zu %zu %zu\n", a, b, d, a, d, c);
		}
}

static void ply_same_ascii(bytes *o, size_t n)
{
	putf(o, "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
	        "property float z\nelement face %zu\nproperty list uchar int vertex_indices\nend_header\n"
	        "0 0 0\n1 0 0\n0 1 0\n",
	     n);
	for (size_t i = 0; i < n; i++)
		putf(o, "3 0 1 2\n");
}

static void ply_polygon_binary(bytes *o, size_t n)
{
	putf(o, "ply\nformat binary_little_endian 1.0\nelement vertex %zu\nproperty float x\n"
	        "property float y\nproperty float z\nelement face 1\nproperty list uint int vertex_indices\n"
	        "end_header\n",
	     n);
	for (size_t i = 0; i < n; i++) {
		double a = 2 * M_PI * (double)i / (double)n;
		put_f32(o, (float)cos(a));
		put_f32(o, (float)sin(a));
		put_f32(o, 0);
	}
	put_u32(o, (uint32_t)n);
	for (size_t i = 0; i < n; i++)
		put_u32(o, (uint32_t)i);
}

/* Binary STL: 80 bytes of header, a count, 50 bytes a triangle. */
static void stl_same(bytes *o, size_t n)
{
	char head[80] = "rtsh growth test";
	put(o, head, sizeof head);
	put_u32(o, (uint32_t)n);
	static const float tri[12] = {0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0};
	for (size_t i = 0; i < n; i++) {
		for (int k = 0; k < 12; k++)
			put_f32(o, tri[k]);
		put(o, "\0", 2);
	}
}

static void stl_grid(bytes *o, size_t n)
{
	char head[80] = "rtsh growth test";
	put(o, head, sizeof head);
	size_t w = 2;
	while (2 * w * w < n)
		w++;
	put_u32(o, (uint32_t)(2 * w * w));
	for (size_t y = 0; y < w; y++)
		for (size_t x = 0; x < w; x++) {
			float a[3] = {(float)x, (float)y, 0}, b[3] = {(float)x + 1, (float)y, 0},
			      c[3] = {(float)x, (float)y + 1, 0}, d[3] = {(float)x + 1, (float)y + 1, 0};
			const float *t[2][3] = {{a, b, d}, {a, d, c}};
			for (int k = 0; k < 2; k++) {
				put_f32(o, 0), put_f32(o, 0), put_f32(o, 1);
				for (int j = 0; j < 3; j++)
					for (int i = 0; i < 3; i++)
						put_f32(o, t[k][j][i]);
				put(o, "\0", 2);
			}
		}
}

/* A GLB (glTF 2.0 binary): one triangle's three corners, and n triangles
 * of indices 0 1 2. */
static void glb_same(bytes *o, size_t n)
{
	size_t pos = 36, idx = 12 * n, bin = pos + idx;
	char json[1024];
	int jl = snprintf(json, sizeof json,
	                  "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
	                  "\"nodes\":[{\"mesh\":0}],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},"
	                  "\"indices\":1}]}],\"buffers\":[{\"byteLength\":%zu}],\"bufferViews\":["
	                  "{\"buffer\":0,\"byteOffset\":0,\"byteLength\":%zu},"
	                  "{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu}],\"accessors\":["
	                  "{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
	                  "\"min\":[0,0,0],\"max\":[1,1,0]},"
	                  "{\"bufferView\":1,\"componentType\":5125,\"count\":%zu,\"type\":\"SCALAR\"}]}",
	                  bin, pos, pos, idx, 3 * n);
	while (jl % 4)
		json[jl++] = ' ';
	put(o, "glTF", 4);
	put_u32(o, 2);
	put_u32(o, (uint32_t)(12 + 8 + (size_t)jl + 8 + bin));
	put_u32(o, (uint32_t)jl);
	put(o, "JSON", 4);
	put(o, json, (size_t)jl);
	put_u32(o, (uint32_t)bin);
	put(o, "BIN", 4); /* with its NUL */
	static const float corners[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
	for (int k = 0; k < 9; k++)
		put_f32(o, corners[k]);
	for (size_t i = 0; i < 3 * n; i++)
		put_u32(o, (uint32_t)(i % 3));
}

/* A PPM texture of about n pixels, 256 wide. */
static void ppm_rows(bytes *o, size_t n)
{
	size_t h = (n + 255) / 256;
	putf(o, "P6\n256 %zu\n255\n", h);
	for (size_t i = 0; i < 256 * h; i++) {
		unsigned char px[3] = {(unsigned char)i, (unsigned char)(i >> 8), (unsigned char)(i * 7)};
		put(o, px, 3);
	}
}

/* A square PFM texture of about n pixels. */
static void pfm_square(bytes *o, size_t n)
{
	size_t w = 1;
	while (w * w < n)
		w++;
	putf(o, "PF\n%zu %zu\n-1\n", w, w);
	for (size_t i = 0; i < 3 * w * w; i++)
		put_f32(o, (float)(i % 97) / 97.0f);
}

/* Writes the file, loads it (and prepares a model: normals and tree), and
 * returns the work it took. */
static double load_cost(const gcase *c, size_t n)
{
	char path[256];
	snprintf(path, sizeof path, "%s/%zu-%s", tmpdir, n, c->name);
	if (c->k == K_PNG && access(path, F_OK) != 0) {
		/* a square PNG of about n pixels, written by image.c */
		int side = 1;
		while ((size_t)side * (size_t)side < n)
			side++;
		framebuffer *fb = fb_new(side, side);
		assert_non_null(fb);
		for (size_t i = 0; i < 3 * (size_t)fb->w * fb->h; i++)
			fb->rgb[i] = (float)(i % 89) / 89.0f;
		rt_error e;
		assert_true(image_write(path, fb, 0, &e));
		fb_free(fb);
	} else if (access(path, F_OK) != 0) {
		bytes o = {0};
		c->make(&o, n);
		FILE *f = fopen(path, "wb");
		assert_non_null(f);
		assert_int_equal(fwrite(o.b, 1, o.n, f), o.n);
		fclose(f);
		free(o.b);
	}
	rt_error err = {0};
	double w0 = work_now();
	if (c->k == K_TEX || c->k == K_PNG) {
		texture *t = texture_load(path, true, &err);
		if (!t)
			fail_msg("%s, n = %zu: %s", c->name, n, err.msg);
		texture_free(t);
	} else {
		mesh *m = c->k == K_OBJ   ? mesh_read_obj(path, &err)
		          : c->k == K_PLY ? mesh_read_ply(path, &err)
		          : c->k == K_STL ? mesh_read_assimp(path, &err)
		                          : mesh_load(path, &err);
		if (!m || !mesh_prepare(m, true, 180, &err))
			fail_msg("%s, n = %zu: %s", c->name, n, err.msg);
		mesh_free(m);
	}
	return work_now() - w0;
}

static void check_growth(const gcase *c)
{
	double min_cost = perf_fd >= 0 ? MIN_COST_INSTR : MIN_COST_NS;
	size_t n = c->start;
	while (load_cost(c, n) < min_cost)
		n *= 2;
	/* The least cost of each size: other processes only ever add to a
	 * load's CPU time (cache and memory contention, page faults), never
	 * take from it, so the minimum is the cost closest to the reader's own.
	 * When the ratio still looks too high, a second round of as many loads
	 * joins the first: a loaded machine's burst passes, a quadratic reader's
	 * 16x stays. */
	double small = HUGE_VAL, big = HUGE_VAL, ratio = HUGE_VAL;
	for (int round = 0; round < 2 && ratio > MAX_RATIO; round++) {
		for (int r = 0; r < RUNS; r++) {
			small = fmin(small, load_cost(c, n));
			big = fmin(big, load_cost(c, 4 * n));
		}
		ratio = big / small;
	}
	print_message("%-12s n = %8zu: 4n costs %.2fx n\n", c->name, n, ratio);
	/* the files of sizes below n are no longer needed */
	char cmd[160];
	snprintf(cmd, sizeof cmd, "rm -f %s/*-%s", tmpdir, c->name);
	if (system(cmd) != 0)
		print_message("could not remove %s/*-%s\n", tmpdir, c->name);
	if (ratio > MAX_RATIO)
		fail_msg("%s: %zu -> %zu costs %.2fx; expected at most %.1fx (linear)", c->name, n, 4 * n, ratio,
		         MAX_RATIO);
}

static const gcase cases[] = {
    {"same.obj", K_OBJ, obj_same, 256},
    {"polygon.obj", K_OBJ, obj_polygon, 256},
    {"grid.obj", K_OBJ, obj_grid, 256},
    {"same.ply", K_PLY, ply_same_ascii, 256},
    {"polygon.ply", K_PLY, ply_polygon_binary, 256},
    {"same.stl", K_STL, stl_same, 256},
    {"grid.stl", K_STL, stl_grid, 256},
    {"same.glb", K_GLB, glb_same, 256},
    {"rows.ppm", K_TEX, ppm_rows, 4096},
    {"square.pfm", K_TEX, pfm_square, 4096},
    {"square.png", K_PNG, NULL, 4096},
};

static void test_growth(void **state)
{
	const gcase *c = *state;
	if (SANITIZED) {
		print_message("skipped: costs under a sanitizer say nothing of the reader\n");
		skip();
	}
	check_growth(c);
}

/* One test a case, named after its file. */
#define GROWTH(i) {.name = cases[i].name, .test_func = test_growth, .initial_state = (void *)&cases[i]}

int main(void)
{
	const struct CMUnitTest tests[] = {GROWTH(0), GROWTH(1), GROWTH(2), GROWTH(3), GROWTH(4),  GROWTH(5),
	                                   GROWTH(6), GROWTH(7), GROWTH(8), GROWTH(9), GROWTH(10)};
	return cmocka_run_group_tests(tests, setup, teardown);
}
