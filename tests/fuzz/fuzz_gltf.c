/* rtsh — fuzz target: our glTF 2.0 reader (mesh_gltf.c), .gltf JSON and
 * .glb alike (the reader goes by the bytes): the container, the JSON
 * (cJSON), buffers from the BIN chunk or base64 data: URIs (files outside
 * are refused: no directory is given), accessors, the node hierarchy,
 * primitives, materials and embedded images; then the cameras and lights
 * (gltf_parse_info), and for up to 100k triangles normals and the tree,
 * for up to 4,096 the tree against brute force (mesh_check.h, with the
 * cut-outs off) and the cut-outs' walk against itself (cut_check). Memory
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

/* The walk with the cut-outs of alphaMode MASK and BLEND (mesh_cut_hole),
 * on mesh_check's rays: every vector unit finds the same hit, never one in
 * a hole, never nearer than the walk without holes, and mesh_occluded
 * agrees. NULL, or what broke (into msg). */
static const char *cut_check(mesh *m, const uint8_t *data, size_t size, char msg[256])
{
	box b = m->bounds;
	vec3 e = v3_sub(b.hi, b.lo);
	double pad = 0.25 * v3_max_comp(e) + 1e-3;
	for (int k = 0; k < 8; k++) {
		vec3 o = v3(k & 1 ? b.hi.x + pad : b.lo.x - pad, k & 2 ? b.hi.y + pad : b.lo.y - pad,
		            k & 4 ? b.hi.z + pad : b.lo.z - pad);
		uint8_t q[3] = {0, 0, 0};
		for (int i = 0; i < 3 && size; i++)
			q[i] = data[((size_t)k * 5 + (size_t)i) % size];
		vec3 d = v3_sub(v3(b.lo.x + e.x * q[0] / 255.0, b.lo.y + e.y * q[1] / 255.0, b.lo.z + e.z * q[2] / 255.0), o);
		if (!(v3_len(d) > 0))
			continue;
		mesh_ray r;
		mesh_ray_make(&r, o, d);
		float t0 = INFINITY, b0[3], tref = INFINITY;
		uint32_t k0;
		m->cuts = false;
		bool h0 = mesh_intersect(m, &r, 0, &t0, &k0, b0);
		m->cuts = true;
		bool href = false;
		for (int isa = MESH_ISA_SCALAR; isa < MESH_ISA_BEST; isa++) {
			if (!mesh_isa_force((mesh_isa)isa))
				continue;
			float tt = INFINITY, bt[3];
			uint32_t kt;
			bool ht = mesh_intersect(m, &r, 0, &tt, &kt, bt);
			bool occ = mesh_occluded(m, &r, 0, INFINITY);
			const char *broken = NULL;
			if (occ != ht)
				broken = "occluded disagrees";
			else if (ht && mesh_cut_hole(m, kt, bt))
				broken = "a hit in a hole";
			else if (ht && !(h0 && tt >= t0))
				broken = "nearer than without holes";
			else if (isa > MESH_ISA_SCALAR && (ht != href || (ht && tt != tref)))
				broken = "the vector units disagree";
			if (broken) {
				snprintf(msg, 256, "cut-outs (vector unit %d): %s: ray %d hit %d occluded %d t %.9g, without holes %d %.9g, "
				         "scalar %d %.9g", isa, broken, k, ht, occ, tt, h0, t0, href, tref);
				mesh_isa_force(MESH_ISA_BEST);
				return msg;
			}
			if (isa == MESH_ISA_SCALAR) {
				href = ht;
				tref = tt;
			}
		}
		mesh_isa_force(MESH_ISA_BEST);
	}
	return NULL;
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
		bool cuts = m->cuts;
		m->cuts = false; /* the geometry alone: brute force knows no holes */
		if (raw && mesh_check(raw, m, data, size, msg)) {
			fprintf(stderr, "%s\n", msg);
			abort();
		}
		m->cuts = cuts;
		if (raw && cuts && cut_check(m, data, size, msg)) {
			fprintf(stderr, "%s\n", msg);
			abort();
		}
		mesh_free(raw);
	}
	mesh_free(m);
	return 0;
}
