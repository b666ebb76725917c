/* The core's file source (rtsh/filesrc.h): with a source set, the model
 * readers, the material library, the textures and assimp's files come from
 * it and never from disk (rtsh-mpi's ranks rely on that); without one, from
 * disk as before. The files live under a folder that does not exist, so a
 * read that went to disk would fail. */
#include "testutil.h"

#include <errno.h>
#include <string.h>

#include "rtsh/filesrc.h"
#include "rtsh/mesh.h"
#include "rtsh/texture.h"

#define DIR "/nonexistent-rtsh-filesrc"

typedef struct mem_file {
	const char *path;
	const char *data;
	size_t len;
	int reads, stats;
} mem_file;

typedef struct mem_fs {
	mem_file *files;
	size_t n;
	int misses;
} mem_fs;

static mem_file *mem_find(mem_fs *fs, const char *path)
{
	for (size_t i = 0; i < fs->n; i++)
		if (strcmp(fs->files[i].path, path) == 0)
			return &fs->files[i];
	fs->misses++;
	return NULL;
}

static char *mem_read(void *ctx, const char *path, const char *what, size_t *len, rt_error *err)
{
	mem_file *f = mem_find(ctx, path);
	if (!f) {
		rt_error_set(err, "%s: cannot read the %s: not in memory", path, what);
		return NULL;
	}
	f->reads++;
	char *c = malloc(f->len + 1);
	assert_non_null(c);
	memcpy(c, f->data, f->len);
	c[f->len] = '\0';
	*len = f->len;
	return c;
}

static int mem_stat(void *ctx, const char *path, struct stat *st)
{
	mem_file *f = mem_find(ctx, path);
	if (!f) {
		errno = ENOENT;
		return -1;
	}
	f->stats++;
	memset(st, 0, sizeof *st);
	st->st_mode = S_IFREG;
	st->st_size = (off_t)f->len;
	return 0;
}

#define TEXT(p, s) {p, s, sizeof s - 1, 0, 0}

/* An OBJ with its MTL and a 2x2 PPM texture, all from memory. */
static void test_obj_mtl_texture_from_source(void **state)
{
	(void)state;
	mem_file files[] = {
	    TEXT(DIR "/m/box.obj", "mtllib box.mtl\nv 0 0 0\nv 2 0 0\nv 2 1 0\nvt 0 0\nvt 1 0\nvt 1 1\n"
	                           "usemtl paint\nf 1/1 2/2 3/3\n"),
	    TEXT(DIR "/m/box.mtl", "newmtl paint\nKd 0 1 0\nmap_Kd tex/c.ppm\n"),
	    TEXT(DIR "/m/tex/c.ppm", "P3\n2 2\n255\n255 0 0  0 255 0\n0 0 255  255 255 255\n"),
	};
	mem_fs fs = {files, 3, 0};
	rt_file_source src = {mem_read, mem_stat, &fs};
	rt_file_source_set(&src);
	rt_error err = {0};
	mesh *m = mesh_load(DIR "/m/box.obj", &err);
	if (!m)
		fail_msg("%s", err.msg);
	assert_int_equal(m->ntris, 1);
	assert_vec_near(m->bounds.hi, v3(0, 1, 0), 0); /* x in [0,2], mirrored on reading */
	assert_vec_near(m->bounds.lo, v3(-2, 0, 0), 0);
	assert_int_equal(files[0].reads, 1);
	assert_int_equal(files[1].reads, 1); /* the MTL through the source too */
	assert_int_equal(m->nmats, 1);
	assert_near(m->mats[0].kd[1], 1.0, 0); /* sRGB 1 is linear 1 */
	assert_near(m->mats[0].kd[0], 0.0, 0);
	assert_string_equal(m->mats[0].map_kd, DIR "/m/tex/c.ppm");
	/* the texture the world would load: sRGB 255 is 1, 0 is 0 */
	texture *t = texture_cache_get(m->mats[0].map_kd, true, NULL, &err);
	if (!t)
		fail_msg("%s", err.msg);
	assert_int_equal(files[2].reads, 1);
	assert_int_equal(files[2].stats, 1); /* the cache checks through the source */
	assert_vec_near(texture_texel(t, 1, 0), v3(0, 1, 0), 0);
	assert_vec_near(texture_texel(t, 0, 1), v3(0, 0, 1), 0);
	texture_cache_put(t);
	mesh_free(m);
	/* a file the source lacks: its message, nothing from disk */
	assert_null(mesh_load(DIR "/m/none.obj", &err));
	assert_non_null(strstr(err.msg, "not in memory"));
	rt_file_source_set(NULL);
}

/* A .gltf whose buffer is a separate .bin: assimp opens both through the
 * source. */
static void test_gltf_buffer_from_source(void **state)
{
	(void)state;
	static const float pos[12] = {0, 0, 0, 3, 0, 0, 3, 2, 0, 0, 2, 0};
	static const unsigned short idx[6] = {0, 1, 2, 0, 2, 3};
	char bin[60];
	memcpy(bin, pos, 48); /* glTF is little-endian, as this machine */
	memcpy(bin + 48, idx, 12);
	mem_file files[] = {
	    TEXT(DIR "/g/sq.gltf",
	         "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
	         "\"nodes\":[{\"mesh\":0}],"
	         "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}],"
	         "\"buffers\":[{\"byteLength\":60,\"uri\":\"sq.bin\"}],"
	         "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":48},"
	         "{\"buffer\":0,\"byteOffset\":48,\"byteLength\":12}],"
	         "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\","
	         "\"min\":[0,0,0],\"max\":[3,2,0]},{\"bufferView\":1,\"componentType\":5123,\"count\":6,"
	         "\"type\":\"SCALAR\"}]}"),
	    {DIR "/g/sq.bin", bin, sizeof bin, 0, 0},
	};
	mem_fs fs = {files, 2, 0};
	rt_file_source src = {mem_read, mem_stat, &fs};
	rt_file_source_set(&src);
	rt_error err = {0};
	mesh *m = mesh_load(DIR "/g/sq.gltf", &err);
	rt_file_source_set(NULL);
	if (!m)
		fail_msg("%s", err.msg);
	assert_int_equal(m->ntris, 2);
	assert_vec_near(m->bounds.lo, v3(-3, 0, 0), 0); /* X mirrored on reading */
	assert_vec_near(m->bounds.hi, v3(0, 2, 0), 0);
	assert_int_equal(files[0].reads, 1); /* the model is read once */
	assert_true(files[1].reads >= 1);
	mesh_free(m);
}

/* Without a source: the disk, with the readers' own words. */
static void test_disk_without_source(void **state)
{
	(void)state;
	rt_error err = {0};
	size_t len;
	assert_null(rt_file_read(DIR "/x.obj", "model", &len, &err));
	assert_string_equal(err.msg, DIR "/x.obj: cannot read the model: No such file or directory");
	struct stat st;
	errno = 0;
	assert_int_equal(rt_file_stat(DIR "/x.obj", &st), -1);
	assert_int_equal(errno, ENOENT);
	assert_null(mesh_load(DIR "/x.gltf", &err));
	assert_string_equal(err.msg, DIR "/x.gltf: cannot read the model: No such file or directory");
	char *self = rt_file_read("tests/unit/test_filesrc.c", "source", &len, &err);
	assert_non_null(self);
	assert_true(len > 0 && strstr(self, "test_disk_without_source") != NULL);
	free(self);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_obj_mtl_texture_from_source),
	    cmocka_unit_test(test_gltf_buffer_from_source),
	    cmocka_unit_test(test_disk_without_source),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
