/* rtsh — fuzz target: the MTL reader (newmtl, Kd, Ke, map_Kd, bump with -bm,
 * norm), reached as rtsh reaches it: an OBJ names the input as its material
 * library, read from a private temporary folder, and uses the input's first
 * material on a triangle; then normals and the tree. Build as fuzz_obj.c.
 * Any input must give a mesh (a material library that cannot be used leaves
 * the default grey), never a crash, leak or hang. */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "rtsh/mesh.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char dir[] = "/tmp/rtsh-fuzz-mtl-XXXXXX";
static char path[sizeof dir + 8];

static void remove_folder(void)
{
	unlink(path);
	rmdir(dir);
}

/* The name after the first "newmtl" (up to the line's end), or "none". */
static void first_material(const uint8_t *data, size_t size, char *name, size_t nsize)
{
	snprintf(name, nsize, "none");
	const char *key = "newmtl";
	for (size_t i = 0; i + 6 < size; i++) {
		if (memcmp(data + i, key, 6) != 0 || (data[i + 6] != ' ' && data[i + 6] != '\t'))
			continue;
		size_t j = i + 7, n = 0;
		while (j < size && (data[j] == ' ' || data[j] == '\t'))
			j++;
		while (j < size && data[j] != '\n' && data[j] != '\r' && data[j] != '\0' && n + 1 < nsize)
			name[n++] = (char)data[j++];
		name[n] = '\0';
		return;
	}
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	if (!path[0]) {
		if (!mkdtemp(dir))
			abort();
		snprintf(path, sizeof path, "%s/f.mtl", dir);
		atexit(remove_folder);
	}
	FILE *f = fopen(path, "wb");
	if (!f || fwrite(data, 1, size, f) != size || fclose(f) != 0)
		abort();
	char name[256], obj[512];
	first_material(data, size, name, sizeof name);
	int n = snprintf(obj, sizeof obj, "mtllib f.mtl\nusemtl %s\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\n"
	                                  "vt 0 1\nf 1/1 2/2 3/3\n",
	                 name);
	rt_error err;
	mesh *m = mesh_parse_obj("fuzz.obj", dir, obj, (size_t)n, &err);
	if (m)
		mesh_prepare(m, true, 60, &err);
	mesh_free(m);
	return 0;
}
