/* rtsh — the glTF 2.0 reader (mesh_gltf.c, gltf.h): files the tests write
 * themselves, every expected value worked out by hand. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "core/integrators.h"
#include "rtsh/gltf.h"
#include "rtsh/memory.h"
#include "rtsh/mesh.h"
#include "rtsh/packet.h"
#include "rtsh/render.h"
#include "rtsh/rtfile.h"
#include "rtsh/world.h"
#include "testutil.h"
#include "tmpdir.h"

/* s saved as tmpdir/name reads back as s; the copy read back (the caller
 * frees it). */
static scene *saved_again(const scene *s, const char *name)
{
	char rt[256];
	snprintf(rt, sizeof rt, "%s/%s", tmpdir, name);
	rt_error err = {0};
	assert_true(rt_save(s, rt, &err));
	scene *t = rt_load_file(rt, NULL, &err);
	if (!t)
		fail_msg("%s", err.msg);
	assert_true(scene_equal(s, t));
	return t;
}

/* --- writing glTF --- */

static void b64(const unsigned char *in, size_t n, char *out)
{
	static const char a[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
	size_t k = 0;
	for (size_t i = 0; i < n; i += 3) {
		uint32_t v = (uint32_t)in[i] << 16 | (i + 1 < n ? (uint32_t)in[i + 1] << 8 : 0) | (i + 2 < n ? in[i + 2] : 0);
		out[k++] = a[v >> 18 & 63];
		out[k++] = a[v >> 12 & 63];
		out[k++] = i + 1 < n ? a[v >> 6 & 63] : '=';
		out[k++] = i + 2 < n ? a[v & 63] : '=';
	}
	out[k] = '\0';
}

/* One triangle (1,0,0) (0,1,0) (0,0,1)... given as 3 positions and the
 * indices 0 1 2 (uint16, padded to 8 bytes): the buffer as a data: URI, and
 * a bufferView/accessor pair for each. `rest` holds the file's other
 * top-level members (nodes, scenes, ...), ending with a comma. */
static char *tri_gltf(const float p[3][3], const char *rest)
{
	unsigned char bin[44];
	memcpy(bin, p, 36);
	const uint16_t idx[4] = {0, 1, 2, 0};
	memcpy(bin + 36, idx, 8);
	char data[80];
	b64(bin, sizeof bin, data);
	char *s = malloc(4096);
	assert_non_null(s);
	snprintf(s, 4096,
	         "{\"asset\":{\"version\":\"2.0\"},%s"
	         "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}],"
	         "\"buffers\":[{\"byteLength\":44,\"uri\":\"data:application/octet-stream;base64,%s\"}],"
	         "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":6}],"
	         "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
	         "{\"bufferView\":1,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"}]}",
	         rest, data);
	return s;
}

static const float unit_tri[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};

static bool has_vertex(const mesh *m, vec3 v, double tol)
{
	for (uint32_t i = 0; i < m->nverts; i++)
		if (fabs(m->p[i][0] - v.x) <= tol && fabs(m->p[i][1] - v.y) <= tol && fabs(m->p[i][2] - v.z) <= tol)
			return true;
	return false;
}

/* --- the node hierarchy --- */

/* A parent at T(1,2,3) R(90 degrees about Z) S(2) over a child whose
 * matrix moves it by (1,0,0). By hand, a vertex (x,y,z) of the child's mesh
 * goes to (x+1, y, z), then scaled (2x+2, 2y, 2z), turned about Z (x, y) ->
 * (-y, x): (-2y, 2x+2, 2z), then moved: (1-2y, 2x+4, 2z+3); the reader
 * mirrors X (scene frame): (2y-1, 2x+4, 2z+3). So (1,0,0) -> (-1,6,3),
 * (0,1,0) -> (1,4,3), (0,0,1) -> (-1,4,5). */
static void test_trs_composition(void **state)
{
	(void)state;
	double h = sqrt(0.5);
	char rest[512];
	snprintf(rest, sizeof rest,
	         "\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"translation\":[1,2,3],"
	         "\"rotation\":[0,0,%.17g,%.17g],\"scale\":[2,2,2],\"children\":[1]},"
	         "{\"mesh\":0,\"matrix\":[1,0,0,0, 0,1,0,0, 0,0,1,0, 1,0,0,1]}],",
	         h, h);
	char *text = tri_gltf(unit_tri, rest);
	rt_error err = {0};
	mesh *m = mesh_parse_gltf("trs.gltf", NULL, text, strlen(text), &err);
	if (!m)
		fail_msg("%s", err.msg);
	assert_int_equal(m->ntris, 1);
	assert_true(has_vertex(m, v3(-1, 6, 3), 1e-5));
	assert_true(has_vertex(m, v3(1, 4, 3), 1e-5));
	assert_true(has_vertex(m, v3(-1, 4, 5), 1e-5));
	mesh_free(m);
	free(text);
}

/* A mirroring node (scale -1 on X) keeps the faces' outward side: the
 * triangle (1,0,0) (0,1,0) (0,0,1) faces (1,1,1) in the file; mirrored by
 * the node it faces (-1,1,1), and mirrored again into the scene frame
 * (1,1,1). The geometric normal of the prepared mesh says which side. */
static void test_mirroring_node_keeps_winding(void **state)
{
	(void)state;
	char *text = tri_gltf(unit_tri, "\"nodes\":[{\"mesh\":0,\"scale\":[-1,1,1]}],");
	rt_error err = {0};
	mesh *m = mesh_parse_gltf("mirror.gltf", NULL, text, strlen(text), &err);
	if (!m)
		fail_msg("%s", err.msg);
	assert_true(mesh_prepare(m, false, 0, &err));
	mesh_surf sf;
	const float b[3] = {1.0f / 3, 1.0f / 3, 1.0f / 3};
	mesh_surface(m, 0, b, &sf);
	vec3 n = v3_norm(sf.ng);
	assert_vec_near(n, v3_norm(v3(1, 1, 1)), 1e-6);
	mesh_free(m);
	free(text);
	/* without the node's mirror: (1,1,1) in the file, (-1,1,1) in the scene */
	text = tri_gltf(unit_tri, "\"nodes\":[{\"mesh\":0}],");
	m = mesh_parse_gltf("plain.gltf", NULL, text, strlen(text), &err);
	assert_non_null(m);
	assert_true(mesh_prepare(m, false, 0, &err));
	mesh_surface(m, 0, b, &sf);
	assert_vec_near(v3_norm(sf.ng), v3_norm(v3(-1, 1, 1)), 1e-6);
	mesh_free(m);
	free(text);
}

/* --- materials --- */

static void test_material_extensions(void **state)
{
	(void)state;
	char *text = tri_gltf(unit_tri,
	                      "\"nodes\":[{\"mesh\":0}],\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":"
	                      "[0.5,0.25,1,0.75],\"metallicFactor\":0.3,\"roughnessFactor\":0.2},"
	                      "\"emissiveFactor\":[1,0.5,0],\"alphaMode\":\"MASK\",\"alphaCutoff\":0.4,"
	                      "\"extensions\":{\"KHR_materials_emissive_strength\":{\"emissiveStrength\":4},"
	                      "\"KHR_materials_transmission\":{\"transmissionFactor\":0.9},"
	                      "\"KHR_materials_ior\":{\"ior\":1.33},\"KHR_materials_volume\":{\"thicknessFactor\":0.1,"
	                      "\"attenuationDistance\":2,\"attenuationColor\":[1,0.5,0.25]},"
	                      "\"KHR_materials_clearcoat\":{\"clearcoatFactor\":1,\"clearcoatRoughnessFactor\":0.1},"
	                      "\"KHR_materials_specular\":{\"specularFactor\":0.5,\"specularColorFactor\":[1,1,0.5]}}}],");
	/* the primitive names material 0 */
	char *at = strstr(text, "\"indices\":1}");
	assert_non_null(at);
	char fixed[4096];
	snprintf(fixed, sizeof fixed, "%.*s\"indices\":1,\"material\":0}%s", (int)(at - text), text,
	         at + strlen("\"indices\":1}"));
	rt_error err = {0};
	mesh *m = mesh_parse_gltf("mat.gltf", NULL, fixed, strlen(fixed), &err);
	if (!m)
		fail_msg("%s", err.msg);
	assert_int_equal(m->nmats, 1);
	const mesh_mat *mm = &m->mats[0];
	assert_near(mm->kd[0], 0.5, 0);
	assert_near(mm->kd[1], 0.25, 0);
	assert_near(mm->alpha, 0.75, 0);
	assert_near(mm->metallic, 0.3, 1e-7);
	assert_near(mm->roughness, 0.2, 1e-7);
	/* emissive x strength: (1, 0.5, 0) x 4 */
	assert_near(mm->ke[0], 4, 0);
	assert_near(mm->ke[1], 2, 0);
	assert_near(mm->ke[2], 0, 0);
	assert_int_equal(mm->alpha_mode, MESH_ALPHA_MASK);
	assert_near(mm->alpha_cutoff, 0.4, 1e-7);
	assert_near(mm->transmission, 0.9, 1e-7);
	assert_near(mm->ior, 1.33, 1e-6);
	assert_near(mm->thickness, 0.1, 1e-7);
	assert_near(mm->att_dist, 2, 0);
	assert_near(mm->att_color[2], 0.25, 0);
	assert_near(mm->clearcoat, 1, 0);
	assert_near(mm->clearcoat_roughness, 0.1, 1e-7);
	assert_near(mm->specular, 0.5, 0);
	assert_near(mm->specular_color[2], 0.5, 0);
	mesh_free(m);
	free(text);
}

/* --- cameras and lights --- */

/* A camera at (2,1,5) turned 90 degrees about +Y: glTF cameras look down
 * their -Z, which the turn takes to -X; mirrored into the scene frame: the
 * position (-2,1,5), looking along +X, up +Y. yfov 0.5 rad, aspect 2. An
 * orthographic camera with xmag 3, ymag 1.5. A point light of 100 cd, a
 * spot of 50 cd (cones 0.2 and 0.4 rad) under a node scaled 2 (its range 5
 * becomes 10) and a directional light of 3 lux shining down -Y. */
static void test_cameras_and_lights(void **state)
{
	(void)state;
	double h = sqrt(0.5);
	char rest[2048];
	snprintf(rest, sizeof rest,
	         "\"nodes\":[{\"camera\":0,\"translation\":[2,1,5],\"rotation\":[0,%.17g,0,%.17g]},"
	         "{\"camera\":1},{\"mesh\":0},"
	         "{\"translation\":[0,4,0],\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}},"
	         "{\"scale\":[2,2,2],\"extensions\":{\"KHR_lights_punctual\":{\"light\":1}}},"
	         "{\"rotation\":[%.17g,0,0,%.17g],\"extensions\":{\"KHR_lights_punctual\":{\"light\":2}}}],"
	         "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.5,\"aspectRatio\":2,\"znear\":0.1}},"
	         "{\"type\":\"orthographic\",\"orthographic\":{\"xmag\":3,\"ymag\":1.5,\"znear\":0,\"zfar\":10}}],"
	         "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[{\"type\":\"point\",\"intensity\":100,"
	         "\"color\":[1,0.5,0.25]},{\"type\":\"spot\",\"intensity\":50,\"range\":5,\"spot\":"
	         "{\"innerConeAngle\":0.2,\"outerConeAngle\":0.4}},{\"type\":\"directional\",\"intensity\":3}]}},",
	         h, h, -h, h);
	char *text = tri_gltf(unit_tri, rest);
	gltf_info gi;
	rt_error err = {0};
	if (!gltf_parse_info("cl.gltf", text, strlen(text), &gi, &err))
		fail_msg("%s", err.msg);
	assert_int_equal(gi.ncams, 2);
	assert_vec_near(gi.cams[0].pos, v3(-2, 1, 5), 1e-12);
	assert_vec_near(gi.cams[0].fwd, v3(1, 0, 0), 1e-12);
	assert_vec_near(gi.cams[0].up, v3(0, 1, 0), 1e-12);
	assert_false(gi.cams[0].ortho);
	assert_near(gi.cams[0].yfov, 0.5, 0);
	assert_near(gi.cams[0].aspect, 2, 0);
	assert_true(gi.cams[1].ortho);
	assert_near(gi.cams[1].xmag, 3, 0);
	assert_near(gi.cams[1].ymag, 1.5, 0);
	assert_vec_near(gi.cams[1].fwd, v3(0, 0, -1), 0);
	assert_int_equal(gi.nlights, 3);
	assert_int_equal(gi.lights[0].type, GLTF_POINT);
	assert_vec_near(gi.lights[0].pos, v3(0, 4, 0), 0);
	assert_near(gi.lights[0].intensity, 100, 0);
	assert_near(gi.lights[0].color[1], 0.5, 0);
	assert_int_equal(gi.lights[1].type, GLTF_SPOT);
	assert_near(gi.lights[1].range, 10, 1e-12);
	assert_near(gi.lights[1].inner, 0.2, 0);
	assert_near(gi.lights[1].outer, 0.4, 0);
	/* -90 degrees about X takes -Z to -Y */
	assert_int_equal(gi.lights[2].type, GLTF_DIRECTIONAL);
	assert_vec_near(gi.lights[2].dir, v3(0, -1, 0), 1e-12);
	assert_false(gi.emissive);
	gltf_info_free(&gi);
	free(text);
}

/* --- bad files: the JSON path or byte, and what was expected --- */

static void expect_fail(const char *text, const char *want1, const char *want2)
{
	rt_error err = {0};
	mesh *m = mesh_parse_gltf("bad.gltf", NULL, text, strlen(text), &err);
	if (m)
		fail_msg("read \"%s\"; expected the error \"%s\"", text, want1);
	if (!strstr(err.msg, want1) || !strstr(err.msg, want2))
		fail_msg("message \"%s\" lacks \"%s\" / \"%s\"", err.msg, want1, want2);
}

static void test_bad_files(void **state)
{
	(void)state;
	expect_fail("{\"asset\":{\"version\":\"1.0\"}}", "bad.gltf: asset.version", "expected a glTF 2.0 file");
	expect_fail("[1,2]", "bad.gltf: byte 0", "not a glTF file");
	expect_fail("{\"asset\":{\"version\":\"2.0\"},\"extensionsRequired\":[\"KHR_draco_mesh_compression\"]}",
	            "extensionsRequired[0]: \"KHR_draco_mesh_compression\" is not read by rtsh", "expected only");
	/* the POSITION accessor names a view that is too short */
	char *t = tri_gltf(unit_tri, "\"nodes\":[{\"mesh\":0}],");
	char *at = strstr(t, "\"byteLength\":36}");
	assert_non_null(at);
	memcpy(at, "\"byteLength\":35}", 16);
	expect_fail(t, "bad.gltf: accessors[0]:", "bufferViews[0] has 35; expected the accessor inside its view");
	free(t);
	t = tri_gltf(unit_tri, "\"nodes\":[{\"mesh\":0}],");
	/* the indices read as two uint32 (0x00010000, 0x00000002) */
	at = strstr(t, "\"componentType\":5123");
	assert_non_null(at);
	memcpy(at, "\"componentType\":5125", 20);
	at = strstr(t, "\"byteLength\":6}");
	memcpy(at, "\"byteLength\":8}", 15);
	at = strstr(t, "\"count\":3,\"type\":\"SCALAR\"");
	at[8] = '2';
	/* 2 indices make no triangle: no triangles in the scene */
	expect_fail(t, "bad.gltf: no triangles in the scene", "expected a node with a mesh");
	free(t);
	/* a missing POSITION, named by its path */
	expect_fail("{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"mesh\":0}],\"meshes\":[{\"primitives\":"
	            "[{\"attributes\":{\"NORMAL\":0}}]}],\"accessors\":[{\"componentType\":5126,\"count\":3,"
	            "\"type\":\"VEC3\"}]}",
	            "bad.gltf: meshes[0].primitives[0].attributes.POSITION: no \"POSITION\"", "expected an index");
	/* a node placed twice, and a cycle: a tree is expected */
	t = tri_gltf(unit_tri, "\"nodes\":[{\"children\":[1,1]},{\"mesh\":0}],");
	expect_fail(t, "bad.gltf: nodes[0]: children[1]: node 1 is already in the hierarchy", "expected a tree");
	free(t);
	t = tri_gltf(unit_tri, "\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"children\":[1]},{\"mesh\":0,\"children\":[0]}],");
	expect_fail(t, "bad.gltf: nodes[1]: children[0]: node 0 is already in the hierarchy", "expected a tree");
	free(t);
	/* a buffer that says more than its data holds */
	t = tri_gltf(unit_tri, "\"nodes\":[{\"mesh\":0}],");
	at = strstr(t, "\"byteLength\":44");
	memcpy(at, "\"byteLength\":48", 15);
	expect_fail(t, "bad.gltf: buffers[0]: byteLength 48, the data has 44 bytes", "expected at most 44");
	free(t);
	/* an index out of range */
	const float p[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
	t = tri_gltf(p, "\"nodes\":[{\"mesh\":0}],");
	/* the index data is "AAABAAIAAAA=": 0 1 2 0; make the second index 7 */
	at = strstr(t, "AAABAAIAAAA=");
	assert_non_null(at);
	memcpy(at, "AAAHAAIAAAA=", 12);
	expect_fail(t, "bad.gltf: meshes[0].primitives[0].indices: index 1 of 3 is 7",
	            "expected below 3, the POSITION count");
	free(t);
	/* a .glb cut short */
	static const unsigned char glb[24] = {'g', 'l', 'T', 'F', 2, 0, 0, 0, 24, 0, 0, 0,
	                                      0xf8, 0xff, 0xff, 0xff, 'J', 'S', 'O', 'N', '{', '}', ' ', ' '};
	rt_error err;
	assert_null(mesh_parse_gltf("cut.glb", NULL, (const char *)glb, sizeof glb, &err));
	assert_non_null(strstr(err.msg, "cut.glb: byte 12: a .glb chunk of 4294967288 bytes, 4 left"));
}

/* A buffer's or an image's file that cannot be read is named after the
 * .gltf and the buffer or image that points to it (the file reader alone
 * said "nothere.bin: cannot read the glTF buffer: ..." without the model);
 * a %00 in a uri is refused, not read as a shorter name. */
static void expect_file_fail(const char *name, const char *text, const char *want1, const char *want2)
{
	rt_error err = {0};
	const char *path = tmp_text(name, text);
	mesh *m = mesh_read_gltf(path, &err);
	if (m)
		fail_msg("%s was read; expected the error \"%s\"", name, want1);
	if (!strstr(err.msg, want1) || !strstr(err.msg, want2))
		fail_msg("message \"%s\" lacks \"%s\" / \"%s\"", err.msg, want1, want2);
}

static void test_buffer_files_named(void **state)
{
	(void)state;
	char *t = tri_gltf(unit_tri, "\"nodes\":[{\"mesh\":0}],");
	char *at = strstr(t, "data:application/octet-stream;base64,");
	assert_non_null(at);
	char *end = strchr(at, '"');
	char text[4096];
	snprintf(text, sizeof text, "%.*snothere.bin%s", (int)(at - t), t, end);
	expect_file_fail("miss.gltf", text, "miss.gltf: buffers[0]: ", "nothere.bin: cannot read the glTF buffer");
	snprintf(text, sizeof text, "%.*s%%00x.bin%s", (int)(at - t), t, end);
	expect_file_fail("nul.gltf", text, "nul.gltf: buffers[0]: uri: \"%00x.bin\" holds %00", "expected a file name");
	/* a short buffer file: named already, its size and the expected one */
	tmp_write("short.bin", "abc", 3);
	snprintf(text, sizeof text, "%.*sshort.bin%s", (int)(at - t), t, end);
	expect_file_fail("short.gltf", text, "short.gltf: buffers[0]: byteLength 44, the data has 3 bytes",
	                 "expected at most 3");
	free(t);
	/* an alpha-masked material's image file, read with the model */
	t = tri_gltf(unit_tri, "\"nodes\":[{\"mesh\":0}],\"images\":[{\"uri\":\"gone.png\"}],"
	                       "\"textures\":[{\"source\":0}],\"materials\":[{\"alphaMode\":\"MASK\","
	                       "\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}],");
	at = strstr(t, "\"attributes\"");
	assert_non_null(at);
	snprintf(text, sizeof text, "%.*s\"material\":0,%s", (int)(at - t), t, at);
	expect_file_fail("mask.gltf", text, "mask.gltf: images[0]: ", "gone.png: cannot read the image");
	free(t);
}

/* A small file whose nodes place one mesh many times makes more triangles
 * than its bytes: the triangles the nodes place are checked against the
 * memory limit before any is built. 1,000 nodes naming a one-triangle mesh
 * need about 1,000 x 200 + 3,000 x 64 = 392,000 bytes by the reader's
 * estimate, over a limit of 300,000 (the JSON itself, about 3,100 values of
 * 64 bytes, fits). */
static void test_hostile_instancing(void **state)
{
	(void)state;
	size_t cap = 1000 * 16 + 256;
	char *nodes = malloc(cap);
	assert_non_null(nodes);
	size_t k = (size_t)snprintf(nodes, cap, "\"nodes\":[");
	for (int i = 0; i < 1000; i++)
		k += (size_t)snprintf(nodes + k, cap - k, "%s{\"mesh\":0}", i ? "," : "");
	snprintf(nodes + k, cap - k, "],");
	char *t = tri_gltf(unit_tri, "");
	/* tri_gltf's buffer is 4096 bytes: build the file by hand around it */
	size_t n = strlen(t) + strlen(nodes) + 1;
	char *text = malloc(n);
	assert_non_null(text);
	const char *after = t + strlen("{\"asset\":{\"version\":\"2.0\"},");
	snprintf(text, n, "{\"asset\":{\"version\":\"2.0\"},%s%s", nodes, after);
	mem_set_limit(300000);
	rt_error err = {0};
	mesh *m = mesh_parse_gltf("many.gltf", NULL, text, strlen(text), &err);
	mem_set_limit(0);
	assert_null(m);
	assert_non_null(strstr(err.msg, "many.gltf (1000 triangles) needs about"));
	m = mesh_parse_gltf("many.gltf", NULL, text, strlen(text), &err);
	if (!m)
		fail_msg("%s", err.msg);
	/* without the limit: the 1,000 placed copies coincide (every node the
	 * same identity transform), so all but one are dropped as duplicates */
	assert_int_equal(m->ntris, 1);
	assert_non_null(m->warning);
	assert_non_null(strstr(m->warning, "many.gltf: 999 duplicate triangles dropped"));
	mesh_free(m);
	free(text);
	free(t);
	free(nodes);
}

/* --- the file as a scene: lights in physical units ---------------------- */

/* A scene from a .gltf holding the unit triangle far below (y = -100), a
 * camera 5 above the origin looking straight down (-90 degrees about X
 * takes its -Z to -Y) and the given lights; then a Lambertian plane y = 0
 * of linear albedo a (diffuse 1, no specular) is added to it. */
static world *lit_plane(const char *lights, const char *light_nodes, double a, scene **out)
{
	double h = sqrt(0.5);
	char rest[2048];
	snprintf(rest, sizeof rest,
	         "\"scene\":0,\"scenes\":[{\"nodes\":[0,1%s]}],"
	         "\"nodes\":[{\"camera\":0,\"translation\":[0,5,0],\"rotation\":[%.17g,0,0,%.17g]},"
	         "{\"mesh\":0,\"translation\":[0,-100,0]}%s],"
	         "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.5,\"znear\":0.1}}],"
	         "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[%s]}},",
	         light_nodes[0] ? ",2,3" : "", -h, h, light_nodes, lights);
	char *text = tri_gltf(unit_tri, rest);
	rt_error err = {0};
	scene *s = rt_load_file(tmp_text("lit.gltf", text), NULL, &err);
	free(text);
	if (!s)
		fail_msg("%s", err.msg);
	assert_false(s->has_ambient); /* lit by what it holds, on black */
	assert_false(s->has_sky);
	object pl = object_make(OBJ_PLANE, linear_to_srgb255(v3(a, a, a)));
	pl.dir = v3(0, 1, 0);
	pl.mat.diffuse = 1;
	pl.mat.specular = 0;
	assert_true(scene_add_object(s, &pl, &err));
	world *w = world_build(s, &err);
	if (!w)
		fail_msg("%s", err.msg);
	*out = s;
	return w;
}

/* The radiance the camera's centre pixel (straight down onto the origin)
 * brings back, by both integrators; path mode adds nothing: the plane's
 * bounces leave into the black. The image is 1001 pixels wide, so that
 * the samples' jitter in the pixel moves the point seen by at most 0.0013
 * units (yfov 0.5 from 5 units): 1e-7 of the value. */
static void centre_radiance(const world *w, vec3 *whitted, vec3 *path)
{
	render_settings set = render_settings_default();
	set.width = set.height = 1001;
	set.samples = 1;
	set.depth = 4;
	set.mode = MODE_WHITTED;
	float px[3];
	render_rect(w, &set, 500, 500, 501, 501, px);
	*whitted = v3(px[0], px[1], px[2]);
	set.mode = MODE_PATH;
	set.samples = 4;
	render_rect(w, &set, 500, 500, 501, 501, px);
	*path = v3(px[0], px[1], px[2]);
}

/* A directional light of E lux shining straight down on a Lambertian plane
 * of albedo a: the irradiance is E, the radiance a E / pi. E = 3, a = 0.5:
 * 0.477465. */
static void test_directional_light_lux(void **state)
{
	(void)state;
	double h = sqrt(0.5);
	char nodes[256];
	snprintf(nodes, sizeof nodes,
	         ",{\"rotation\":[%.17g,0,0,%.17g],\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}},"
	         "{\"translation\":[0,-200,0],\"extensions\":{\"KHR_lights_punctual\":{\"light\":1}}}",
	         -h, h);
	scene *s;
	/* the second light, a point far below the plane, lights none of it */
	world *w = lit_plane("{\"type\":\"directional\",\"intensity\":3},{\"type\":\"point\",\"intensity\":1}",
	                     nodes, 0.5, &s);
	assert_int_equal(s->nlights, 2);
	vec3 wh, pa;
	centre_radiance(w, &wh, &pa);
	double want = 0.5 * 3 / M_PI;
	assert_vec_near(wh, v3_splat(want), 1e-5);
	assert_vec_near(pa, v3_splat(want), 1e-5);
	world_free(w);
	scene_free(s);
}

/* A point light of I candela at height d above a Lambertian plane facing
 * it: at the point below it the irradiance is I / d^2, the radiance
 * a I / (pi d^2). I = 40, d = 2, a = 0.25, colour (1, 0.5, 0.25) linear:
 * 0.795775 x the colour. The same light 4 units up gives a quarter:
 * inverse-square fall-off (a miniRT light gives the same at any height). */
static void test_point_light_candela(void **state)
{
	(void)state;
	for (int k = 0; k < 2; k++) {
		double d = k ? 4 : 2;
		char nodes[256];
		snprintf(nodes, sizeof nodes,
		         ",{\"translation\":[0,%g,0],\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}},"
		         "{\"translation\":[0,-200,0],\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}}",
		         d);
		scene *s;
		world *w = lit_plane("{\"type\":\"point\",\"intensity\":40,\"color\":[1,0.5,0.25]}", nodes, 0.25, &s);
		vec3 wh, pa;
		centre_radiance(w, &wh, &pa);
		double want = 0.25 * 40 / (M_PI * d * d);
		vec3 c = v3(want, want * 0.5, want * 0.25);
		assert_vec_near(wh, c, 1e-5);
		assert_vec_near(pa, c, 1e-5);
		world_free(w);
		scene_free(s);
	}
}

/* A spot's smooth cone (KHR_lights_punctual): with cos_o, cos_i the cosines
 * of its outer and inner angles and cos_t that of the angle off its axis,
 * the intensity is I x clamp((cos_t - cos_o) / (cos_i - cos_o), 0, 1)^2.
 * A spot of 40 cd, cones 10 and 20 degrees, 2 above the origin pointing
 * down: at the origin (on the axis) I; at 15 degrees off the axis, on the
 * plane at x = 2 tan 15, distance 2 / cos 15, the factor
 * ((cos 15 - cos 20) / (cos 10 - cos 20))^2; at 25 degrees nothing. */
static void test_spot_cone(void **state)
{
	(void)state;
	rt_error err = {0};
	const char *text = "C 0,5,0 0,-1,0 60\nL 0,2,0 1 255,255,255 cd=40 dir=0,-1,0 cone=10,20\n";
	scene *s = rt_load_string(text, strlen(text), "spot.rt", NULL, &err);
	if (!s)
		fail_msg("%s", err.msg);
	world *w = world_build(s, &err);
	assert_non_null(w);
	vec3 wi;
	double dist;
	vec3 l = light_at(&w->lights[0], v3(0, 0, 0), &wi, &dist);
	assert_near(l.x * M_PI, 40 / 4.0, 1e-9); /* pi L = I / d^2 */
	assert_near(dist, 2, 1e-12);
	assert_vec_near(wi, v3(0, 1, 0), 1e-12);
	double t = 15 * M_PI / 180, x = 2 * tan(t), d = 2 / cos(t);
	double f = (cos(t) - cos(20 * M_PI / 180)) / (cos(10 * M_PI / 180) - cos(20 * M_PI / 180));
	l = light_at(&w->lights[0], v3(x, 0, 0), &wi, &dist);
	assert_near(l.x * M_PI, 40 / (d * d) * f * f, 1e-9);
	l = light_at(&w->lights[0], v3(2 * tan(25 * M_PI / 180), 0, 0), &wi, &dist);
	assert_near(l.x, 0, 0);
	/* behind a sun nothing changes with distance: E / pi everywhere */
	world_free(w);
	scene_free(s);
}

/* A camera's yfov: on a 2:1 image the top edge's middle is yfov / 2 from
 * the axis and the right edge's middle atan(2 tan(yfov / 2)); an
 * orthographic camera's rays are parallel, the top edge ymag above its
 * centre and the right edge ymag x 2 to its right. The scene also saves
 * to a .rt that reloads to the same scene. */
static void test_camera_frustum(void **state)
{
	(void)state;
	double h = sqrt(0.5);
	char rest[1024];
	snprintf(rest, sizeof rest,
	         "\"nodes\":[{\"mesh\":0},{\"camera\":0,\"translation\":[0,0,5]},"
	         "{\"camera\":1,\"translation\":[1,2,3],\"rotation\":[0,%.17g,0,%.17g]}],"
	         "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":1,\"aspectRatio\":2,\"znear\":0.1}},"
	         "{\"type\":\"orthographic\",\"orthographic\":{\"xmag\":4,\"ymag\":2,\"znear\":0,\"zfar\":9}}],",
	         h, h);
	char *text = tri_gltf(unit_tri, rest);
	rt_error err = {0};
	const char *path = tmp_text("cams.gltf", text);
	free(text);
	scene *s = rt_load_file(path, NULL, &err);
	if (!s)
		fail_msg("%s", err.msg);
	assert_int_equal(s->ncams, 2);
	/* aspectRatio 2: the file's shape becomes the resolution hint */
	assert_int_equal(s->hints.width, 1280);
	assert_int_equal(s->hints.height, 640);
	cam_view v = cam_view_make(&s->cams[0]);
	assert_vec_near(v.pos, v3(0, 0, 5), 0);
	assert_vec_near(v.fwd, v3(0, 0, -1), 0);
	ray top = cam_ray(&v, 100, 0, 200, 100), right = cam_ray(&v, 200, 50, 200, 100);
	assert_near(acos(v3_dot(top.d, v.fwd)), 0.5, 1e-12);
	assert_near(acos(v3_dot(right.d, v.fwd)), atan(2 * tan(0.5)), 1e-12);
	/* the orthographic camera at (1,2,3) turned 90 degrees about Y looks
	 * along -X in the file, +X mirrored, from (-1,2,3) */
	v = cam_view_make(&s->cams[1]);
	assert_vec_near(v.fwd, v3(1, 0, 0), 1e-12);
	top = cam_ray(&v, 100, 0, 200, 100);
	right = cam_ray(&v, 200, 50, 200, 100);
	assert_vec_near(top.d, v.fwd, 1e-12);
	assert_vec_near(top.o, v3(-1, 4, 3), 1e-12);
	assert_vec_near(v3_sub(right.o, v3(-1, 2, 3)), v3_scale(v.right, 4), 1e-12);
	/* save and load again: the same scene */
	scene *t = saved_again(s, "cams.rt");
	scene_free(t);
	scene_free(s);
}

/* A camera turned 90 degrees about its own axis (the node's rotation about
 * Z: the camera's up +Y goes to -X in the file, +X once the reader mirrors
 * X; its right +X goes to +Y). rtsh's upright camera looking along -Z has
 * right = (0,1,0) x (0,0,-1) = (-1,0,0) and up (0,1,0): the file's up is
 * minus the upright right, a roll of -90 degrees (the up turned towards the
 * left). The view's up is then (1,0,0) and its right (0,1,0), and the save
 * keeps the roll. */
static void test_camera_roll(void **state)
{
	(void)state;
	double h = sqrt(0.5);
	char rest[1024];
	snprintf(rest, sizeof rest,
	         "\"nodes\":[{\"mesh\":0},{\"camera\":0,\"translation\":[0,0,5],\"rotation\":[0,0,%.17g,%.17g]}],"
	         "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":1,\"aspectRatio\":2,\"znear\":0.1}}],",
	         h, h);
	char *text = tri_gltf(unit_tri, rest);
	rt_error err = {0};
	const char *path = tmp_text("roll.gltf", text);
	free(text);
	scene *s = rt_load_file(path, NULL, &err);
	if (!s)
		fail_msg("%s", err.msg);
	assert_int_equal(s->ncams, 1);
	assert_near(s->cams[0].roll, -90, 1e-9);
	cam_view v = cam_view_make(&s->cams[0]);
	assert_vec_near(v.fwd, v3(0, 0, -1), 1e-12);
	assert_vec_near(v.up, v3(1, 0, 0), 1e-12);
	assert_vec_near(v.right, v3(0, 1, 0), 1e-12);
	/* the middle of the top row: up by tan(yfov / 2) */
	ray top = cam_ray(&v, 100, 0, 200, 100);
	assert_vec_near(top.d, v3_norm(v3(tan(0.5), 0, -1)), 1e-12);
	scene *t = saved_again(s, "roll.rt");
	scene_free(t);
	scene_free(s);
}

/* Nodes as objects: two nodes place the unit triangle, the second moved by
 * (5,0,0). Each becomes a mesh object of its own (node=0, node=1). Node 1's
 * triangle, mirrored in X, is (-6,0,0) (-5,1,0) (-5,0,1): its plane is
 * (x + 6) - y - z = 0, so the ray along +Z through x = -5.5, y = 0.2 meets
 * it at z = 0.3 (barycentric 0.2 and 0.3, inside), from z = -10 at
 * t = 10.3. Moved up by 1 as any object is moved, the ray through y = 1.2
 * meets it at the same z. save keeps node=. */
static void test_nodes_as_objects(void **state)
{
	(void)state;
	char *text = tri_gltf(unit_tri, "\"nodes\":[{\"mesh\":0},{\"mesh\":0,\"translation\":[5,0,0]},"
	                                "{\"camera\":0,\"translation\":[0,0,9]}],"
	                                "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":1}}],");
	rt_error err = {0};
	const char *path = tmp_text("nodes.gltf", text);
	free(text);
	scene *s = rt_load_file(path, NULL, &err);
	if (!s)
		fail_msg("%s", err.msg);
	assert_int_equal(s->nobjs, 3); /* and the stage's floor (no lights): y = 0, under the rays */
	assert_int_equal(s->objs[0].node, 0);
	assert_int_equal(s->objs[1].node, 1);
	world *w = world_build(s, &err);
	if (!w)
		fail_msg("%s", err.msg);
	hit h;
	ray r = {v3(-5.5, 0.2, -10), v3(0, 0, 1)};
	assert_true(world_intersect(w, &r, 0, INFINITY, &h));
	assert_int_equal(h.object, 1);
	assert_near(h.t, 10.3, 1e-6);
	world_free(w);
	s->objs[1].pos = v3_add(s->objs[1].pos, v3(0, 1, 0));
	w = world_build(s, &err);
	if (!w)
		fail_msg("%s", err.msg);
	r.o = v3(-5.5, 1.2, -10);
	assert_true(world_intersect(w, &r, 0, INFINITY, &h));
	assert_int_equal(h.object, 1);
	assert_near(h.t, 10.3, 1e-6);
	r.o = v3(-5.5, 0.2, -10); /* where it was: nothing now */
	assert_false(world_intersect(w, &r, 0, INFINITY, &h));
	world_free(w);
	scene *t = saved_again(s, "nodes.rt");
	assert_int_equal(t->objs[1].node, 1);
	scene_free(t);
	scene_free(s);
	/* a node the scene does not place, and node= on another format */
	mesh *m = mesh_read_gltf_node(path, 7, &err);
	assert_null(m);
	assert_non_null(strstr(err.msg, "node 7: not a node the scene places"));
	/* in a .rt file, with its line */
	const char *bad = tmp_text("badnode.rt", "C 0,0,-5 0,0,1 60\nmesh nodes.gltf 0,0,0 0,1,0 1 node=7\n");
	assert_null(rt_load_file(bad, NULL, &err));
	char msg[RT_ERROR_MSG_MAX];
	rt_error_format(&err, msg, sizeof msg);
	assert_non_null(strstr(msg, "badnode.rt:2:"));
	assert_non_null(strstr(msg, "node 7: not a node the scene places"));
}

/* --- a PNG of one texel, for textures the tests embed --- */

static uint32_t crc32_of(const unsigned char *p, size_t n)
{
	uint32_t c = 0xffffffffu;
	for (size_t i = 0; i < n; i++) {
		c ^= p[i];
		for (int k = 0; k < 8; k++)
			c = c & 1 ? 0xedb88320u ^ (c >> 1) : c >> 1;
	}
	return c ^ 0xffffffffu;
}

static void put32(unsigned char *p, uint32_t v)
{
	p[0] = (unsigned char)(v >> 24);
	p[1] = (unsigned char)(v >> 16);
	p[2] = (unsigned char)(v >> 8);
	p[3] = (unsigned char)v;
}

/* A 1x1 8-bit RGB PNG of (r, g, b): the IDAT a zlib stream of one stored
 * block (filter byte 0 and the texel); 69 bytes into out. */
static size_t png_1x1(unsigned char r, unsigned char g, unsigned char b, unsigned char *out)
{
	static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
	size_t n = 0;
	memcpy(out, sig, 8);
	n = 8;
	unsigned char ihdr[17] = {'I', 'H', 'D', 'R', 0, 0, 0, 1, 0, 0, 0, 1, 8, 2, 0, 0, 0};
	put32(out + n, 13);
	memcpy(out + n + 4, ihdr, 17);
	put32(out + n + 21, crc32_of(ihdr, 17));
	n += 25;
	unsigned char raw[4] = {0, r, g, b};
	uint32_t a = 1, b2 = 0; /* adler32 */
	for (int i = 0; i < 4; i++) {
		a = (a + raw[i]) % 65521;
		b2 = (b2 + a) % 65521;
	}
	unsigned char idat[4 + 2 + 5 + 4 + 4] = {'I', 'D', 'A', 'T', 0x78, 0x01, 0x01, 4, 0, 0xfb, 0xff};
	memcpy(idat + 11, raw, 4);
	put32(idat + 15, b2 << 16 | a);
	put32(out + n, sizeof idat - 4);
	memcpy(out + n + 4, idat, sizeof idat);
	put32(out + n + 4 + sizeof idat, crc32_of(idat, sizeof idat));
	n += 4 + sizeof idat + 4;
	unsigned char iend[4] = {'I', 'E', 'N', 'D'};
	put32(out + n, 0);
	memcpy(out + n + 4, iend, 4);
	put32(out + n + 8, crc32_of(iend, 4));
	return n + 12;
}

/* The triangle (-1,-1,0) (1,-1,0) (0,1,0) with uv (0,0) (1,0) (0.5,1), of
 * material 0, whose texture 0 is one PNG texel (r, g, b); a camera of
 * vertical field yfov at `at` ("[0,0,5]") looks at it. `materials` is the
 * file's materials array. Written to tmpdir/name and loaded as a scene. */
static scene *textured_tri(const char *name, unsigned char r, unsigned char g, unsigned char b, const char *at,
                           double yfov, const char *materials)
{
	unsigned char bin[68];
	const float pos[9] = {-1, -1, 0, 1, -1, 0, 0, 1, 0}, uv[6] = {0, 0, 1, 0, 0.5f, 1};
	const uint16_t idx[4] = {0, 1, 2, 0};
	memcpy(bin, pos, 36);
	memcpy(bin + 36, uv, 24);
	memcpy(bin + 60, idx, 8);
	char data[128], png64[128];
	b64(bin, sizeof bin, data);
	unsigned char png[80];
	b64(png, png_1x1(r, g, b, png), png64);
	char text[4096];
	snprintf(text, sizeof text,
	         "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"mesh\":0},{\"camera\":0,\"translation\":%s}],"
	         "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":%.17g}}],"
	         "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"indices\":2,"
	         "\"material\":0}]}],"
	         "\"materials\":%s,"
	         "\"textures\":[{\"source\":0}],\"images\":[{\"uri\":\"data:image/png;base64,%s\"}],"
	         "\"buffers\":[{\"byteLength\":68,\"uri\":\"data:application/octet-stream;base64,%s\"}],"
	         "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36},{\"buffer\":0,\"byteOffset\":36,\"byteLength\":24},"
	         "{\"buffer\":0,\"byteOffset\":60,\"byteLength\":6}],"
	         "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"},"
	         "{\"bufferView\":1,\"componentType\":5126,\"count\":3,\"type\":\"VEC2\"},"
	         "{\"bufferView\":2,\"componentType\":5123,\"count\":3,\"type\":\"SCALAR\"}]}",
	         at, yfov, materials, png64, data);
	rt_error err = {0};
	scene *sc = rt_load_file(tmp_text(name, text), NULL, &err);
	if (!sc)
		fail_msg("%s", err.msg);
	return sc;
}

/* The metallic-roughness texture in shading: a triangle with uv, metallic
 * 0.5 and roughness 0.8, and a texture of one texel (R, G, B) = (0, 128,
 * 255), read linear (glTF: G scales roughness, B metallic). At any point:
 * roughness 0.8 x 128/255 = 0.40157, metallic 0.5 x 255/255 = 0.5. */
static void test_metallic_roughness_texture(void **state)
{
	(void)state;
	scene *s = textured_tri("mr.gltf", 0, 128, 255, "[0,0,5]", 1,
	                        "[{\"pbrMetallicRoughness\":{\"metallicFactor\":0.5,\"roughnessFactor\":0.8,"
	                        "\"metallicRoughnessTexture\":{\"index\":0}}}]");
	rt_error err = {0};
	world *w = world_build(s, &err);
	if (!w)
		fail_msg("%s", err.msg);
	hit h;
	ray r = {v3(0, -0.2, 5), v3(0, 0, -1)};
	assert_true(world_intersect(w, &r, 0, INFINITY, &h));
	assert_true(h.has_uv);
	const mat_lin *m = &w->mats[h.mat];
	assert_int_equal(m->family, MAT_PBR);
	assert_near(m->pbr.roughness, 0.8, 1e-6);
	assert_near(m->pbr.metallic, 0.5, 1e-6);
	mat_lin tmp;
	const mat_lin *t = hit_material(m, &h, &tmp);
	assert_near(t->pbr.roughness, 0.8 * 128.0 / 255.0, 1e-6);
	assert_near(t->pbr.metallic, 0.5, 1e-6);
	world_free(w);
	scene_free(s);
}

/* KHR_texture_transform with a rotation. The triangle of the test above,
 * hit at (0, -0.2): barycentrics 0.3 and 0.4 for the second and third
 * corners, so the file's uv there is 0.3 (1,0) + 0.4 (0.5,1) = (0.5, 0.4).
 * Offset (0.1, 0.2), rotation pi/2, scale (2, 0.5), by the extension's
 * formula (u' = o_u + cos s_u u - sin s_v v, v' = o_v + sin s_u u + cos s_v v):
 * u' = 0.1 - 0.5 x 0.4 = -0.1 and v' = 0.2 + 2 x 0.5 = 1.2, which rtsh's v
 * (up) makes 1 - 1.2 = -0.2. The tangents follow: dp/du' and dp/dv' map back
 * to the moves of the hit point that change u' or v' alone. */
static void test_texture_rotation(void **state)
{
	(void)state;
	char mat[256];
	snprintf(mat, sizeof mat,
	         "[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0,\"extensions\":"
	         "{\"KHR_texture_transform\":{\"offset\":[0.1,0.2],\"rotation\":%.17g,\"scale\":[2,0.5]}}}}}]",
	         M_PI / 2);
	scene *s = textured_tri("rot.gltf", 200, 100, 50, "[0,0,5]", 1, mat);
	rt_error err = {0};
	world *w = world_build(s, &err);
	if (!w)
		fail_msg("%s", err.msg);
	hit h;
	ray r = {v3(0, -0.2, 5), v3(0, 0, -1)};
	assert_true(world_intersect(w, &r, 0, INFINITY, &h));
	assert_true(h.has_uv);
	assert_near(h.u, -0.1, 1e-6);
	assert_near(h.v, -0.2, 1e-6);
	/* a step along dp/du' changes u' by its length and v' not at all: seen
	 * through a second hit a little along it */
	vec3 step = v3_scale(h.dpdu, 1e-3);
	hit h2;
	ray r2 = {v3_add(r.o, step), r.d};
	assert_true(world_intersect(w, &r2, 0, INFINITY, &h2));
	assert_near(h2.u - h.u, 1e-3, 1e-7);
	assert_near(h2.v - h.v, 0, 1e-7);
	world_free(w);
	scene_free(s);
}

/* The emissive texture: the triangle above with emissiveFactor (1,1,1),
 * KHR_materials_emissive_strength 2 and an emissive texture of one sRGB
 * texel (255, 128, 0), seen straight on in path mode on black: the pixel is
 * the emission, 2 x (1, ((128/255 + 0.055) / 1.055)^2.4, 0) =
 * (2, 0.431722, 0). Such a material is left to the paths (no emitters). */
static void test_emissive_texture(void **state)
{
	(void)state;
	scene *s = textured_tri("emit.gltf", 255, 128, 0, "[0,-0.2,5]", 0.01,
	                        "[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,0,1]},\"emissiveFactor\":[1,1,1],"
	                        "\"emissiveTexture\":{\"index\":0},"
	                        "\"extensions\":{\"KHR_materials_emissive_strength\":{\"emissiveStrength\":2}}}]");
	rt_error err = {0};
	world *w = world_build(s, &err);
	if (!w)
		fail_msg("%s", err.msg);
	assert_int_equal(w->nemitters, 0);
	render_settings set = render_settings_default();
	set.width = set.height = 1;
	set.samples = 4;
	set.depth = 1;
	set.threads = 1;
	set.mode = MODE_PATH;
	framebuffer *fb = render_image(w, &set, NULL, NULL, NULL, &err);
	assert_non_null(fb);
	double g = pow((128.0 / 255 + 0.055) / 1.055, 2.4);
	assert_near(fb->rgb[0], 2.0, 1e-5);
	assert_near(fb->rgb[1], 2 * g, 1e-5);
	assert_near(fb->rgb[2], 0.0, 1e-6);
	fb_free(fb);
	world_free(w);
	scene_free(s);
}

/* A lamp made of a glTF mesh is sampled directly, as the .rt emitters are:
 * a 2 x 2 square of two triangles, emissiveFactor 1 x
 * KHR_materials_emissive_strength 2 (Le = 2), 1 above a Lambert floor of
 * albedo 0.8 at the origin, seen by a narrow camera at depth 1. By hand,
 * the form factor from the origin to a parallel rectangle whose corner is
 * straight above it, sides a and b at height h, X = a/h, Y = b/h, is
 *   F = (X / sqrt(1+X^2) atan(Y / sqrt(1+X^2)) + Y / sqrt(1+Y^2) atan(X / sqrt(1+Y^2))) / (2 pi);
 * the square is four such (X = Y = 1): F = 4 (2 / sqrt 2) atan(1 / sqrt 2) / (2 pi)
 * = 0.554128, and the floor sends back 0.8 Le F. The two triangles are the
 * world's emitters; the paths alone give the same. */
static void test_mesh_lamp(void **state)
{
	(void)state;
	unsigned char bin[60];
	const float pos[12] = {-1, 0, -1, 1, 0, -1, 1, 0, 1, -1, 0, 1};
	const uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
	memcpy(bin, pos, 48);
	memcpy(bin + 48, idx, 12);
	char data[128];
	b64(bin, sizeof bin, data);
	char text[2048];
	snprintf(text, sizeof text,
	         "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"mesh\":0}],"
	         "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1,\"material\":0}]}],"
	         "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,0,1]},\"emissiveFactor\":[1,1,1],"
	         "\"extensions\":{\"KHR_materials_emissive_strength\":{\"emissiveStrength\":2}}}],"
	         "\"buffers\":[{\"byteLength\":60,\"uri\":\"data:application/octet-stream;base64,%s\"}],"
	         "\"bufferViews\":[{\"buffer\":0,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":48,\"byteLength\":12}],"
	         "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
	         "{\"bufferView\":1,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"}]}",
	         data);
	tmp_text("lamp.gltf", text);
	const char *rt = tmp_text("lamp.rt", "C 0,0.5,-4 0,-0.5,4 0.2\npl 0,0,0 0,1,0 1,1,1 255,255,255 0.8 0 1 0\n"
	                                     "mesh lamp.gltf 0,1,0 0,1,0 2\n");
	rt_error err = {0};
	scene *s = rt_load_file(rt, NULL, &err);
	if (!s)
		fail_msg("%s", err.msg);
	double f = 4 * (2 / sqrt(2)) * atan(1 / sqrt(2)) / (2 * M_PI), want = 0.8 * 2 * f;
	double got[2];
	for (int k = 0; k < 2; k++) {
		world *w = world_build(s, &err);
		if (!w)
			fail_msg("%s", err.msg);
		assert_int_equal(w->nemitters, 2);
		if (k)
			w->nemitters = 0;
		render_settings set = render_settings_default();
		set.width = set.height = 1;
		set.samples = k ? 400000 : 20000;
		set.depth = 1;
		set.threads = 2;
		set.mode = MODE_PATH;
		set.seed = 5;
		framebuffer *fb = render_image(w, &set, NULL, NULL, NULL, &err);
		assert_non_null(fb);
		got[k] = fb->rgb[1];
		fb_free(fb);
		world_free(w);
	}
	print_message("expected %.5f, sampled %.5f, paths only %.5f\n", want, got[0], got[1]);
	assert_near(got[0], want, 0.005 * want);
	assert_near(got[1], want, 0.01 * want);
	scene_free(s);
}

/* A file with neither lights nor emissive materials gets the model
 * viewer's stage lighting (ambient, a lamp, the sky, a floor) and a note
 * for the status line; with no camera it is framed as the viewer frames a
 * model. */
static void test_stage_lighting(void **state)
{
	(void)state;
	char *text = tri_gltf(unit_tri, "\"nodes\":[{\"mesh\":0}],");
	rt_error err = {0};
	scene *s = rt_load_file(tmp_text("bare.gltf", text), NULL, &err);
	free(text);
	if (!s)
		fail_msg("%s", err.msg);
	assert_non_null(s->note);
	assert_string_equal(s->note, "stage lighting");
	assert_true(s->has_ambient);
	assert_true(s->has_sky);
	assert_int_equal(s->nlights, 1);
	assert_int_equal(s->ncams, 1);
	/* the camera looks at the middle of the model's box */
	vec3 mid = v3(-0.5, 0.5, 0.5), d = v3_norm(s->cams[0].dir);
	vec3 to = v3_norm(v3_sub(mid, s->cams[0].pos));
	assert_vec_near(to, d, 1e-9);
	scene_free(s);
}

/* --- alphaMode MASK cut-outs --- */

/* A w x h 8-bit RGBA PNG (colour type 6) of the texels rgba, top row first:
 * the IDAT a zlib stream of one stored block (each row its filter byte 0
 * and its texels). At most 64 x 64 texels; the bytes into out. */
static size_t png_rgba(int w, int h, const unsigned char *rgba, unsigned char *out)
{
	static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
	memcpy(out, sig, 8);
	size_t n = 8;
	unsigned char ihdr[17] = {'I', 'H', 'D', 'R', 0, 0, 0, 0, 0, 0, 0, 0, 8, 6, 0, 0, 0};
	put32(ihdr + 4, (uint32_t)w);
	put32(ihdr + 8, (uint32_t)h);
	put32(out + n, 13);
	memcpy(out + n + 4, ihdr, 17);
	put32(out + n + 21, crc32_of(ihdr, 17));
	n += 25;
	unsigned char raw[64 * (1 + 4 * 64)];
	size_t nr = 0;
	for (int y = 0; y < h; y++) {
		raw[nr++] = 0;
		memcpy(raw + nr, rgba + (size_t)y * 4 * (size_t)w, 4 * (size_t)w);
		nr += 4 * (size_t)w;
	}
	uint32_t a = 1, b2 = 0; /* adler32 */
	for (size_t i = 0; i < nr; i++) {
		a = (a + raw[i]) % 65521;
		b2 = (b2 + a) % 65521;
	}
	unsigned char *idat = out + n + 4;
	memcpy(idat, "IDAT", 4);
	idat[4] = 0x78;
	idat[5] = 0x01;
	idat[6] = 0x01; /* the last block, stored */
	idat[7] = (unsigned char)(nr & 255);
	idat[8] = (unsigned char)(nr >> 8);
	idat[9] = (unsigned char)(~nr & 255);
	idat[10] = (unsigned char)(~nr >> 8 & 255);
	memcpy(idat + 11, raw, nr);
	put32(idat + 11 + nr, b2 << 16 | a);
	size_t nidat = 11 + nr + 4;
	put32(out + n, (uint32_t)(nidat - 4));
	put32(out + n + 4 + nidat, crc32_of(idat, nidat));
	n += 4 + nidat + 4;
	put32(out + n, 0);
	memcpy(out + n + 4, "IEND", 4);
	put32(out + n + 8, crc32_of(out + n + 4, 4));
	return n + 12;
}

/* The 2 x 1 texture of the cut-out tests: the left texel white and opaque
 * (alpha 255), the right one white and transparent (alpha 0), as a data:
 * URI. */
static void png_half(char *uri64)
{
	static const unsigned char t[8] = {255, 255, 255, 255, 255, 255, 255, 0};
	unsigned char png[128];
	b64(png, png_rgba(2, 1, t, png), uri64);
}

/* A glTF scene for the cut-out tests: a camera at (0, 5, 0) looking
 * straight down (yfov 0.5), a point light of 400 cd at (0, 20, 0), and a
 * 2 x 2 quad in its node's y = 0 plane, facing up, corners (+-1, 0, +-1),
 * uv = ((x + 1) / 2, (z + 1) / 2), of material `mat` (its JSON), moved by
 * (tx, qy, 0). tex: the file has the 2 x 1 texture above as textures[0].
 * Under it, added to the scene, a Lambertian plane y = 0 of albedo 1/2.
 *
 * By hand: the camera's centre ray runs down the y axis. The plane's point
 * at the origin, lit from 20 units straight above, has irradiance
 * 400 / 20^2 = 1 and radiance 0.5 / pi. The quad's point on the y axis
 * has x = -tx in the quad's own frame (glTF's x; the reader mirrors x for
 * both the node and the camera), so u = (1 - tx) / 2: tx = 0.5 gives u =
 * 0.25, the centre of the opaque texel, and tx = -0.5 gives u = 0.75, the
 * centre of the transparent one (bilinear, repeat: alpha 1.5 - 2u on
 * [0.25, 0.75]). */
static const char *cut_sampler; /* the texture's sampler (its JSON), NULL: none */
static bool cut_mirror;          /* the plane a perfect mirror, not Lambertian */

static world *cut_world(const char *mat, bool tex, double tx, double qy, scene **out)
{
	unsigned char bin[92];
	const float pos[12] = {-1, 0, -1, 1, 0, -1, 1, 0, 1, -1, 0, 1}, uv[8] = {0, 0, 1, 0, 1, 1, 0, 1};
	const uint16_t idx[6] = {0, 2, 1, 0, 3, 2};
	memcpy(bin, pos, 48);
	memcpy(bin + 48, uv, 32);
	memcpy(bin + 80, idx, 12);
	char data[160], png64[256] = "", images[400] = "";
	b64(bin, sizeof bin, data);
	if (tex) {
		png_half(png64);
		snprintf(images, sizeof images, "\"textures\":[{\"source\":0%s}],%s%s%s\"images\":[{\"uri\":\"data:image/png;base64,%s\"}],",
		         cut_sampler ? ",\"sampler\":0" : "", cut_sampler ? "\"samplers\":[" : "", cut_sampler ? cut_sampler : "",
		         cut_sampler ? "]," : "", png64);
	}
	double h = sqrt(0.5);
	char text[4096];
	snprintf(text, sizeof text,
	         "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0,1,2]}],"
	         "\"nodes\":[{\"camera\":0,\"translation\":[0,5,0],\"rotation\":[%.17g,0,0,%.17g]},"
	         "{\"mesh\":0,\"translation\":[%.17g,%.17g,0]},"
	         "{\"translation\":[0,20,0],\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}}],"
	         "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.5,\"znear\":0.1}}],"
	         "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[{\"type\":\"point\",\"intensity\":400}]}},"
	         "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"indices\":2,"
	         "\"material\":0}]}],\"materials\":[%s],%s"
	         "\"buffers\":[{\"byteLength\":92,\"uri\":\"data:application/octet-stream;base64,%s\"}],"
	         "\"bufferViews\":[{\"buffer\":0,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":48,\"byteLength\":32},"
	         "{\"buffer\":0,\"byteOffset\":80,\"byteLength\":12}],"
	         "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
	         "{\"bufferView\":1,\"componentType\":5126,\"count\":4,\"type\":\"VEC2\"},"
	         "{\"bufferView\":2,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"}]}",
	         -h, h, tx, qy, mat, images, data);
	rt_error err = {0};
	scene *s = rt_load_file(tmp_text("cut.gltf", text), NULL, &err);
	if (!s)
		fail_msg("%s", err.msg);
	object pl = object_make(OBJ_PLANE, linear_to_srgb255(v3(0.5, 0.5, 0.5)));
	pl.dir = v3(0, 1, 0);
	pl.mat.diffuse = cut_mirror ? 0 : 1;
	pl.mat.specular = 0;
	pl.mat.reflective = cut_mirror ? 1 : 0;
	assert_true(scene_add_object(s, &pl, &err));
	world *w = world_build(s, &err);
	if (!w)
		fail_msg("%s", err.msg);
	*out = s;
	return w;
}

/* The black metal of the quads (base colour 0: no diffuse part, F0 = 0, so
 * seen and lit along its normal it sends back nothing), with alpha a. */
#define CUT_MAT(a, rest) "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,0," a "]" rest "}"
#define CUT_TEX ",\"baseColorTexture\":{\"index\":0}}"
#define CUT_TEX_T(t) ",\"baseColorTexture\":{\"index\":0,\"extensions\":{\"KHR_texture_transform\":{" t "}}}}"

/* The radiance around the centre of the picture is `want`, found every way
 * the renderer finds it, on every vector unit of the walk: the single
 * Whitted ray (world_intersect, world_occluded), the camera packets and
 * shadow packets of a 4 x 4 block, and path mode (depth 1: the light
 * sampled at the first hit; its camera rays in packets too). The block's
 * points lie within 0.01 of the axis, where nothing changes but the light's
 * distance, by 1e-7. */
static void expect_centre(const world *w, double want)
{
	for (int isa = MESH_ISA_SCALAR; isa < MESH_ISA_BEST; isa++) {
		if (!mesh_isa_force((mesh_isa)isa))
			continue;
		render_settings set = render_settings_default();
		set.width = set.height = 1001;
		set.samples = 1;
		set.depth = 1;
		set.threads = 1;
		set.mode = MODE_WHITTED;
		vec3 c = whitted_radiance(w, &set, render_sample_ray(w, &set, 500, 500, 1001, 1001, 0));
		assert_vec_near(c, v3_splat(want), 1e-5);
		float px[16 * 3];
		render_rect(w, &set, 498, 498, 502, 502, px);
		for (int i = 0; i < 16 * 3; i++)
			assert_near(px[i], want, 1e-5);
		set.mode = MODE_PATH;
		set.samples = 2;
		render_rect(w, &set, 498, 498, 502, 502, px);
		for (int i = 0; i < 16 * 3; i++)
			assert_near(px[i], want, 1e-5);
	}
	mesh_isa_force(MESH_ISA_BEST);
}

/* Camera rays (and the reflection of nothing): the quad 1 above the plane,
 * between it and the camera, its MASK texture left opaque, right clear.
 * Through the opaque texel the camera sees the quad (black: 0); through
 * the clear one it sees the plane, lit through the same hole: 0.5 / pi.
 * OPAQUE (the default) ignores alpha: 0. Then the texture moved by
 * KHR_texture_transform, and the sampler's wrap. */
static void test_cutout_camera_rays(void **state)
{
	(void)state;
	double lit = 0.5 / M_PI;
	struct {
		const char *mat;
		double tx, want;
		const char *sampler;
	} c[] = {
	    {CUT_MAT("1", CUT_TEX ",\"alphaMode\":\"MASK\""), 0.5, 0, NULL},
	    {CUT_MAT("1", CUT_TEX ",\"alphaMode\":\"MASK\""), -0.5, lit, NULL},
	    {CUT_MAT("1", CUT_TEX ",\"alphaMode\":\"MASK\",\"alphaCutoff\":0.5"), -0.5, lit, NULL},
	    {CUT_MAT("1", CUT_TEX), -0.5, 0, NULL},
	    {CUT_MAT("1", CUT_TEX ",\"alphaMode\":\"OPAQUE\""), -0.5, 0, NULL},
	    /* KHR_texture_transform offset (0.5, 0): u 0.25 + 0.5, the clear texel */
	    {CUT_MAT("1", CUT_TEX_T("\"offset\":[0.5,0]") ",\"alphaMode\":\"MASK\""), 0.5, lit, NULL},
	    /* offset (1, 0): u 1.25, the opaque texel again by the default
	     * repeat, and by an explicit one; past the right edge, so the clear
	     * texel, with wrapS clamp (33071); mirrored (33648): 2 - 1.25 =
	     * 0.75, clear */
	    {CUT_MAT("1", CUT_TEX_T("\"offset\":[1,0]") ",\"alphaMode\":\"MASK\""), 0.5, 0, NULL},
	    {CUT_MAT("1", CUT_TEX_T("\"offset\":[1,0]") ",\"alphaMode\":\"MASK\""), 0.5, 0, "{\"wrapS\":10497}"},
	    {CUT_MAT("1", CUT_TEX_T("\"offset\":[1,0]") ",\"alphaMode\":\"MASK\""), 0.5, lit, "{\"wrapS\":33071}"},
	    {CUT_MAT("1", CUT_TEX_T("\"offset\":[1,0]") ",\"alphaMode\":\"MASK\""), 0.5, lit, "{\"wrapS\":33648}"},
	};
	for (size_t k = 0; k < sizeof c / sizeof c[0]; k++) {
		scene *s;
		cut_sampler = c[k].sampler;
		world *w = cut_world(c[k].mat, true, c[k].tx, 1, &s);
		cut_sampler = NULL;
		hit h;
		ray r = {v3(0, 5, 0), v3(0, -1, 0)};
		assert_true(world_intersect(w, &r, 0, INFINITY, &h));
		/* the quad at t = 4, or the plane at t = 5 */
		assert_near(h.t, c[k].want > 0 ? 5 : 4, 1e-6);
		expect_centre(w, c[k].want);
		world_free(w);
		scene_free(s);
	}
}

/* Shadow rays: the same quad 10 above the plane, above the camera (which
 * does not see it), between the plane and the light. The plane's point
 * under the light is lit exactly when its shadow ray passes the clear
 * texel. Then, with the quad centred (tx = 0), points (x, 0, 0) of the
 * plane: the shadow ray to (0, 20, 0) crosses the quad at x / 2, where the
 * quad's own x is -x / 2 and u = (1 - x / 2) / 2. x = -1.5 and -0.5: u =
 * 0.875 and 0.625, alpha 0.25 (the clear texel's and, by the repeat, the
 * opaque one's) and 0.25 again: lit. x = 0.5 and 1.5: u = 0.375 and 0.125,
 * alpha 0.75 both: in shadow. x = 2.5 crosses y = 10 at 1.25, past the
 * quad: lit. Single rays and one packet of all five. */
static void test_cutout_shadow_rays(void **state)
{
	(void)state;
	const char *mat = CUT_MAT("1", CUT_TEX ",\"alphaMode\":\"MASK\"");
	for (int k = 0; k < 2; k++) {
		scene *s;
		world *w = cut_world(mat, true, k ? -0.5 : 0.5, 10, &s);
		expect_centre(w, k ? 0.5 / M_PI : 0);
		world_free(w);
		scene_free(s);
	}
	scene *s;
	world *w = cut_world(mat, true, 0, 10, &s);
	const double xs[5] = {-1.5, -0.5, 0.5, 1.5, 2.5};
	const bool shade[5] = {false, false, true, true, false};
	ray r[5];
	double tmax[5];
	bool occ[5];
	for (int isa = MESH_ISA_SCALAR; isa < MESH_ISA_BEST; isa++) {
		if (!mesh_isa_force((mesh_isa)isa))
			continue;
		for (int i = 0; i < 5; i++) {
			vec3 p = v3(xs[i], 0, 0), to = v3_sub(v3(0, 20, 0), p);
			tmax[i] = v3_len(to);
			r[i] = (ray){p, v3_scale(to, 1 / tmax[i])};
			assert_int_equal(world_occluded(w, &r[i], 1e-6, tmax[i]), shade[i]);
		}
		world_occluded_packet(w, 5, r, 1e-6, tmax, occ);
		for (int i = 0; i < 5; i++)
			assert_int_equal(occ[i], shade[i]);
	}
	mesh_isa_force(MESH_ISA_BEST);
	world_free(w);
	scene_free(s);
}

/* baseColorFactor's alpha alone (no texture): 0.3 under the default cutoff
 * 0.5 removes the whole quad (the plane is seen and lit: 0.5 / pi); under a
 * cutoff of 0.2 the quad stays (0). The reader keeps no alpha channel for
 * such materials, nor for an OPAQUE one with an RGBA texture, and marks
 * only meshes with a MASK material (mesh.cuts). */
static void test_cutout_factor(void **state)
{
	(void)state;
	struct {
		const char *mat;
		double want;
	} c[] = {
	    {CUT_MAT("0.3", ",\"metallicFactor\":1},\"alphaMode\":\"MASK\""), 0.5 / M_PI},
	    {CUT_MAT("0.3", ",\"metallicFactor\":1},\"alphaMode\":\"MASK\",\"alphaCutoff\":0.2"), 0},
	    {CUT_MAT("0.3", ",\"metallicFactor\":1}"), 0},
	};
	for (size_t k = 0; k < sizeof c / sizeof c[0]; k++) {
		scene *s;
		world *w = cut_world(c[k].mat, false, 0, 1, &s);
		expect_centre(w, c[k].want);
		world_free(w);
		scene_free(s);
	}
	/* what the reader keeps */
	char png64[256];
	png_half(png64);
	for (int k = 0; k < 2; k++) {
		char *text = malloc(8192), rest[1024];
		assert_non_null(text);
		snprintf(rest, sizeof rest,
		         "\"nodes\":[{\"mesh\":0}],\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":"
		         "{\"index\":0}},\"alphaMode\":\"%s\"}],\"textures\":[{\"source\":0,\"sampler\":0}],"
		         "\"samplers\":[{\"wrapS\":33071,\"wrapT\":33648}],"
		         "\"images\":[{\"uri\":\"data:image/png;base64,%s\"}],",
		         k ? "MASK" : "OPAQUE", png64);
		char *base = tri_gltf(unit_tri, rest);
		/* tri_gltf's primitive has no material: give it material 0 */
		char *at = strstr(base, "\"indices\":1}");
		assert_non_null(at);
		snprintf(text, 8192, "%.*s\"indices\":1,\"material\":0}%s", (int)(at - base), base,
		         at + strlen("\"indices\":1}"));
		free(base);
		rt_error err = {0};
		mesh *m = mesh_parse_gltf("t.gltf", NULL, text, strlen(text), &err);
		free(text);
		if (!m)
			fail_msg("%s", err.msg);
		assert_int_equal(m->cuts, k == 1);
		if (k) {
			assert_non_null(m->mats[0].alpha_map);
			assert_int_equal(m->mats[0].alpha_w, 2);
			assert_int_equal(m->mats[0].alpha_h, 1);
			assert_int_equal(m->mats[0].alpha_map[0], 255);
			assert_int_equal(m->mats[0].alpha_map[1], 0);
			assert_int_equal(m->mats[0].alpha_wrap[0], MESH_WRAP_CLAMP);
			assert_int_equal(m->mats[0].alpha_wrap[1], MESH_WRAP_MIRROR);
		} else {
			assert_null(m->mats[0].alpha_map);
		}
		mesh_free(m);
	}
	/* bad values, by their JSON path */
	static const char *const bad[][3] = {
	    {"{\"alphaMode\":\"MASK\",\"alphaCutoff\":-1}", "materials[0]: alphaCutoff: not a number from 0", ""},
	    {"{\"alphaMode\":\"CUTOUT\"}", "materials[0]: alphaMode: not \"OPAQUE\", \"MASK\" or \"BLEND\"", "expected"},
	    {"{\"alphaMode\":\"MASK\",\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}",
	     "samplers[0]: wrapS: 5; expected 33071 (clamp), 33648 (mirrored repeat) or 10497 (repeat)", ""},
	};
	for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
		char rest[1024];
		snprintf(rest, sizeof rest,
		         "\"nodes\":[{\"mesh\":0}],\"materials\":[%s],\"textures\":[{\"source\":0,\"sampler\":0}],"
		         "\"samplers\":[{\"wrapS\":5}],\"images\":[{\"uri\":\"data:image/png;base64,%s\"}],",
		         bad[k][0], png64);
		char *text = tri_gltf(unit_tri, rest);
		expect_fail(text, bad[k][1], bad[k][2]);
		free(text);
	}
}

/* An emissive cut-out is not sampled as a lamp (its holes would light
 * through): the paths find it, through its holes too. The lamp of
 * test_mesh_lamp (Le = 2, 2 x 2, 1 above a floor of albedo 0.8) as a MASK
 * with baseColorFactor alpha 0.3: all hole, the floor gets nothing (0);
 * with alpha 1 it is whole, found by the paths alone: 0.8 Le F. */
static void test_cutout_lamp(void **state)
{
	(void)state;
	unsigned char bin[60];
	const float pos[12] = {-1, 0, -1, 1, 0, -1, 1, 0, 1, -1, 0, 1};
	const uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
	memcpy(bin, pos, 48);
	memcpy(bin + 48, idx, 12);
	char data[128];
	b64(bin, sizeof bin, data);
	double f = 4 * (2 / sqrt(2)) * atan(1 / sqrt(2)) / (2 * M_PI), want = 0.8 * 2 * f;
	for (int k = 0; k < 2; k++) {
		char text[2048];
		snprintf(text, sizeof text,
		         "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"mesh\":0}],"
		         "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1,\"material\":0}]}],"
		         "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,0,%s]},\"emissiveFactor\":[1,1,1],"
		         "\"alphaMode\":\"MASK\",\"extensions\":{\"KHR_materials_emissive_strength\":{\"emissiveStrength\":2}}}],"
		         "\"buffers\":[{\"byteLength\":60,\"uri\":\"data:application/octet-stream;base64,%s\"}],"
		         "\"bufferViews\":[{\"buffer\":0,\"byteLength\":48},{\"buffer\":0,\"byteOffset\":48,\"byteLength\":12}],"
		         "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"
		         "{\"bufferView\":1,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"}]}",
		         k ? "1" : "0.3", data);
		tmp_text("cutlamp.gltf", text);
		const char *rt = tmp_text("cutlamp.rt", "C 0,0.5,-4 0,-0.5,4 0.2\npl 0,0,0 0,1,0 1,1,1 255,255,255 0.8 0 1 0\n"
		                                        "mesh cutlamp.gltf 0,1,0 0,1,0 2\n");
		rt_error err = {0};
		scene *s = rt_load_file(rt, NULL, &err);
		if (!s)
			fail_msg("%s", err.msg);
		world *w = world_build(s, &err);
		if (!w)
			fail_msg("%s", err.msg);
		assert_int_equal(w->nemitters, 0);
		render_settings set = render_settings_default();
		set.width = set.height = 1;
		set.samples = k ? 100000 : 64;
		set.depth = 1;
		set.threads = 2;
		set.mode = MODE_PATH;
		set.seed = 5;
		framebuffer *fb = render_image(w, &set, NULL, NULL, NULL, &err);
		assert_non_null(fb);
		if (k)
			assert_near(fb->rgb[1], want, 0.02 * want);
		else
			assert_near(fb->rgb[1], 0, 1e-9);
		fb_free(fb);
		world_free(w);
		scene_free(s);
	}
}

/* BLEND: in Whitted mode a MASK at 0.5, so baseColorFactor alpha 0.3 is
 * gone (the plane: 0.5 / pi) and 0.7 stays (0), on every path of
 * expect_centre but path mode. In path mode it is seen through by its
 * alpha: a ray passes with probability 1 - alpha, so with alpha 0.3 the
 * camera ray passes 0.7 of the time and the lit plane's shadow ray 0.7 of
 * the time: 0.49 x 0.5 / pi on average; alpha 0.7, 0.09 x 0.5 / pi. With
 * 160000 samples the mean's standard deviation is sqrt(p (1 - p) / 160000)
 * / p of it: 0.26% (p = 0.49) and 0.8% (p = 0.09); 3% allowed. */
static void test_blend(void **state)
{
	(void)state;
	double lit = 0.5 / M_PI;
	for (int k = 0; k < 2; k++) {
		scene *s;
		world *w = cut_world(k ? CUT_MAT("0.7", "},\"alphaMode\":\"BLEND\"") : CUT_MAT("0.3", "},\"alphaMode\":\"BLEND\""),
		                     false, 0, 1, &s);
		render_settings set = render_settings_default();
		set.width = set.height = 1001;
		set.samples = 1;
		set.depth = 1;
		set.threads = 1;
		set.mode = MODE_WHITTED;
		vec3 c = whitted_radiance(w, &set, render_sample_ray(w, &set, 500, 500, 1001, 1001, 0));
		assert_vec_near(c, v3_splat(k ? 0 : lit), 1e-5);
		float px[16 * 3];
		render_rect(w, &set, 498, 498, 502, 502, px);
		for (int i = 0; i < 16 * 3; i++)
			assert_near(px[i], k ? 0 : lit, 1e-5);
		set.mode = MODE_PATH;
		set.samples = 160000;
		render_rect(w, &set, 500, 500, 501, 501, px);
		double want = (k ? 0.3 * 0.3 : 0.7 * 0.7) * lit;
		print_message("BLEND alpha %s in path mode: expected %.5f, got %.5f\n", k ? "0.7" : "0.3", want, px[1]);
		assert_near(px[1], want, 0.03 * want);
		world_free(w);
		scene_free(s);
	}
}

/* The alpha of an image file beside the model (not inside it): read by the
 * reader from the file, as the colour is by the world; a missing file is
 * an error naming it. */
static void test_cutout_image_file(void **state)
{
	(void)state;
	static const unsigned char t[8] = {255, 255, 255, 255, 255, 255, 255, 0};
	unsigned char png[128];
	size_t n = png_rgba(2, 1, t, png);
	char path[256];
	snprintf(path, sizeof path, "%s/half.png", tmpdir);
	FILE *f = fopen(path, "wb");
	assert_non_null(f);
	assert_int_equal(fwrite(png, 1, n, f), n);
	assert_int_equal(fclose(f), 0);
	for (int k = 0; k < 2; k++) {
		char rest[512];
		snprintf(rest, sizeof rest,
		         "\"nodes\":[{\"mesh\":0}],\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":"
		         "{\"index\":0}},\"alphaMode\":\"MASK\"}],\"textures\":[{\"source\":0}],"
		         "\"images\":[{\"uri\":\"%s\"}],",
		         k ? "nothere.png" : "half.png");
		char *text = tri_gltf(unit_tri, rest);
		const char *model = tmp_text("file.gltf", text);
		free(text);
		rt_error err = {0};
		mesh *m = mesh_read_gltf(model, &err);
		if (k) {
			assert_null(m);
			assert_non_null(strstr(err.msg, "nothere.png"));
			continue;
		}
		if (!m)
			fail_msg("%s", err.msg);
		assert_true(m->cuts);
		assert_non_null(m->mats[0].alpha_map);
		assert_int_equal(m->mats[0].alpha_w, 2);
		assert_int_equal(m->mats[0].alpha_map[0], 255);
		assert_int_equal(m->mats[0].alpha_map[1], 0);
		mesh_free(m);
	}
}

/* Reflection rays: the plane a perfect mirror (no diffuse part), the quad
 * 10 above it, above the camera, glowing (emissiveFactor 0.5, black
 * metal). The camera's centre ray meets the mirror at the origin and goes
 * back up the y axis: through the opaque texel it meets the quad and
 * brings back its emission, 0.5 (Whitted: the mirror's weight 1 times
 * what the reflection sees); through the clear texel it leaves into the
 * black: 0. Single ray and packets. */
static void test_cutout_reflection(void **state)
{
	(void)state;
	const char *mat = "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,0,1],\"baseColorTexture\":{\"index\":0}},"
	                  "\"emissiveFactor\":[0.5,0.5,0.5],\"alphaMode\":\"MASK\"}";
	for (int k = 0; k < 2; k++) {
		scene *s;
		cut_mirror = true;
		world *w = cut_world(mat, true, k ? -0.5 : 0.5, 10, &s);
		cut_mirror = false;
		double want = k ? 0 : 0.5;
		render_settings set = render_settings_default();
		set.width = set.height = 1001;
		set.samples = 1;
		set.depth = 4;
		set.threads = 1;
		set.mode = MODE_WHITTED;
		vec3 c = whitted_radiance(w, &set, render_sample_ray(w, &set, 500, 500, 1001, 1001, 0));
		assert_vec_near(c, v3_splat(want), 1e-5);
		float px[16 * 3];
		render_rect(w, &set, 498, 498, 502, 502, px);
		for (int i = 0; i < 16 * 3; i++)
			assert_near(px[i], want, 1e-5);
		world_free(w);
		scene_free(s);
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_trs_composition),
	    cmocka_unit_test(test_mirroring_node_keeps_winding),
	    cmocka_unit_test(test_material_extensions),
	    cmocka_unit_test(test_cameras_and_lights),
	    cmocka_unit_test(test_bad_files),
	    cmocka_unit_test(test_buffer_files_named),
	    cmocka_unit_test(test_hostile_instancing),
	    cmocka_unit_test(test_directional_light_lux),
	    cmocka_unit_test(test_point_light_candela),
	    cmocka_unit_test(test_spot_cone),
	    cmocka_unit_test(test_camera_frustum),
	    cmocka_unit_test(test_camera_roll),
	    cmocka_unit_test(test_nodes_as_objects),
	    cmocka_unit_test(test_metallic_roughness_texture),
	    cmocka_unit_test(test_mesh_lamp),
	    cmocka_unit_test(test_texture_rotation),
	    cmocka_unit_test(test_emissive_texture),
	    cmocka_unit_test(test_stage_lighting),
	    cmocka_unit_test(test_cutout_camera_rays),
	    cmocka_unit_test(test_cutout_shadow_rays),
	    cmocka_unit_test(test_cutout_factor),
	    cmocka_unit_test(test_cutout_lamp),
	    cmocka_unit_test(test_blend),
	    cmocka_unit_test(test_cutout_image_file),
	    cmocka_unit_test(test_cutout_reflection),
	};
	return cmocka_run_group_tests(tests, tmpdir_setup, tmpdir_teardown);
}
