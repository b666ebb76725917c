/* rtsh — fuzz target: the models assimp reads for rtsh (STL; glTF 2.0 is
 * our own reader's now, fuzz_gltf.c), through our glue (mesh_assimp.c:
 * bounds and index checks), then normals and the triangle tree. The first
 * byte is skipped (it picked the extension when assimp read glTF too, and
 * the corpus keeps it); the rest is the file, written to a private
 * temporary folder (assimp reads from a path, through rtsh's file source).
 * Memory requests are held to 512 MiB.
 *
 * assimp 5.2 keeps some of what it allocated when it refuses a malformed
 * file (inside its importers: aiImportFileExWithProperties, after the
 * error; ours frees everything it is given): those leaks are suppressed
 * below, with full stacks (fast_unwind_on_malloc=0) so that the library's
 * frames can be seen, and a leak of ours still shows. */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "rtsh/memory.h"
#include "rtsh/mesh.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerInitialize(int *argc, char ***argv);
const char *__lsan_default_suppressions(void);
const char *__asan_default_options(void);

const char *__lsan_default_suppressions(void)
{
	return "leak:libassimp.so\n";
}

const char *__asan_default_options(void)
{
	return "fast_unwind_on_malloc=0";
}

static char path[3][80];

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
	(void)argc, (void)argv;
	char dir[] = "/tmp/rtsh-fuzz-model-XXXXXX";
	if (!mkdtemp(dir))
		abort();
	snprintf(path[0], sizeof path[0], "%s/in.gltf", dir);
	snprintf(path[1], sizeof path[1], "%s/in.glb", dir);
	snprintf(path[2], sizeof path[2], "%s/in.stl", dir);
	mem_set_limit((size_t)512 << 20);
	return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	if (size < 1)
		return 0;
	const char *p = path[2];
	FILE *f = fopen(p, "wb");
	if (!f || fwrite(data + 1, 1, size - 1, f) != size - 1 || fclose(f) != 0)
		abort();
	rt_error err;
	mesh *m = mesh_read_assimp(p, &err);
	if (m && m->ntris < 100000)
		mesh_prepare(m, true, 60, &err);
	mesh_free(m);
	return 0;
}
