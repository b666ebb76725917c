/* rtsh — fuzz target: the OBJ reader (mesh_parse_obj) and, on success, the
 * normals and the triangle tree. libFuzzer entry point; build e.g.
 *   clang -g -O1 -fsanitize=fuzzer,address,undefined -Iinclude -Isrc \
 *         tests/fuzz/fuzz_obj.c build/librtsh.a -lpng -lassimp -lXpm -lstb -lm
 * Any input must give a mesh or an error, never a crash, leak or hang. */
#include <stddef.h>
#include <stdint.h>

#include "mesh_check.h"
#include "rtsh/mesh.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	rt_error err;
	mesh *m = mesh_parse_obj("fuzz.obj", "/nonexistent", (const char *)data, size, &err);
	if (m && m->ntris < 100000 && mesh_prepare(m, true, 60, &err)) {
		/* the tree against every triangle (mesh_check.h), on small meshes */
		mesh *raw = m->ntris <= 4096 ? mesh_parse_obj("fuzz.obj", "/nonexistent", (const char *)data, size, &err) : NULL;
		char msg[256];
		if (raw && mesh_check(raw, m, data, size, msg)) {
			fprintf(stderr, "%s\n", msg);
			abort();
		}
		mesh_free(raw);
	}
	mesh_free(m);
	return 0;
}
