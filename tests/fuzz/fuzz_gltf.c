/* rtsh — fuzz target: our glTF 2.0 reader (mesh_gltf.c), .gltf JSON and
 * .glb alike (the reader goes by the bytes): the container, the JSON
 * (cJSON), buffers from the BIN chunk or base64 data: URIs (files outside
 * are refused: no directory is given), accessors, the node hierarchy,
 * primitives, materials and embedded images; then the cameras and lights
 * (gltf_parse_info), and for up to 100k triangles normals and the tree,
 * for up to 4,096 the tree against brute force (mesh_check.h). Memory
 * requests are held to 512 MiB (mem_set_limit): a file that asks for more
 * must be refused by the reader's own estimates. */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "mesh_check.h"
#include "rtsh/gltf.h"
#include "rtsh/memory.h"
#include "rtsh/mesh.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerInitialize(int *argc, char ***argv);

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
	(void)argc, (void)argv;
	mem_set_limit((size_t)512 << 20);
	return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	rt_error err;
	gltf_info gi;
	if (gltf_parse_info("fuzz.glb", (const char *)data, size, &gi, &err))
		gltf_info_free(&gi);
	mesh *m = mesh_parse_gltf("fuzz.glb", NULL, (const char *)data, size, &err);
	if (m && m->ntris < 100000 && mesh_prepare(m, true, 60, &err)) {
		mesh *raw = m->ntris <= 4096 ? mesh_parse_gltf("fuzz.glb", NULL, (const char *)data, size, &err) : NULL;
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
