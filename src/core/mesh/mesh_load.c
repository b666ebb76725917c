/* rtsh — models by format, and the cache of prepared meshes (mesh.h). */
#include "rtsh/mesh.h"

#include <errno.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "base/readhelp.h"
#include "rtsh/filesrc.h"
#include "rtsh/memory.h"

static const char *ext_of(const char *path)
{
	const char *slash = strrchr(path, '/');
	const char *dot = strrchr(slash ? slash : path, '.');
	return dot ? dot + 1 : "";
}

/* The model formats: an extension (any case) and its reader. A format is a
 * reader file in this folder and one line here; mesh_format_known, the
 * message for an unknown extension and the scene reader follow. */
static const struct model_format {
	const char *ext;
	mesh *(*read)(const char *path, rt_error *err);
} formats[] = {
	{"obj", mesh_read_obj},   {"ply", mesh_read_ply},    {"gltf", mesh_read_gltf},
	{"glb", mesh_read_gltf},  {"stl", mesh_read_assimp},
};
enum { NFORMATS = sizeof formats / sizeof formats[0] };

static const struct model_format *format_of(const char *path)
{
	const char *e = ext_of(path);
	for (size_t i = 0; i < NFORMATS; i++)
		if (strcasecmp(e, formats[i].ext) == 0)
			return &formats[i];
	return NULL;
}

bool mesh_format_known(const char *path)
{
	return format_of(path) != NULL;
}

void mesh_format_list(char *buf, size_t size)
{
	size_t n = 0;
	buf[0] = '\0';
	for (size_t i = 0; i < NFORMATS && n < size; i++) {
		const char *sep = i == 0 ? "" : i + 1 == NFORMATS ? " or " : ", ";
		int k = snprintf(buf + n, size - n, "%s.%s", sep, formats[i].ext);
		if (k < 0)
			break;
		n += (size_t)k;
	}
}

static mesh *load_node(const char *path, long node, rt_error *err)
{
	const struct model_format *f = format_of(path);
	if (!f) {
		char list[128];
		mesh_format_list(list, sizeof list);
		if (!*ext_of(path)) /* "." would name no format: say what is missing */
			rt_error_set(err, "%s: the name has no extension; expected %s", path, list);
		else
			rt_error_set(err, "%s: unknown model format \".%s\"; expected %s", path, ext_of(path), list);
		return NULL;
	}
	if (node >= 0 && f->read != mesh_read_gltf) {
		rt_error_set(err, "%s: node=%ld: only glTF files (.gltf, .glb) have nodes", path, node);
		return NULL;
	}
	mesh *m = node >= 0 ? mesh_read_gltf_node(path, node, err) : f->read(path, err);
	if (m && !m->path) {
		m->path = strdup(path);
		if (!m->path) {
			mesh_free(m);
			rt_error_set(err, "%s: out of memory", path);
			return NULL;
		}
	}
	return m;
}

mesh *mesh_load(const char *path, rt_error *err)
{
	return load_node(path, -1, err);
}

typedef struct cache_entry {
	mesh *m;
	char *path;
	long node;
	bool smooth;
	double crease;
	off_t size;
	struct timespec mtime;
} cache_entry;

static pthread_mutex_t cache_lock = PTHREAD_MUTEX_INITIALIZER;
static cache_entry *cache;
static size_t ncache, ccache;

mesh *mesh_cache_get(const char *path, bool smooth, double crease_deg, const atomic_bool *cancel, rt_error *err)
{
	return mesh_cache_get_node(path, -1, smooth, crease_deg, cancel, err);
}

mesh *mesh_cache_get_node(const char *path, long node, bool smooth, double crease_deg, const atomic_bool *cancel,
                          rt_error *err)
{
	if (node < 0)
		node = -1;
	struct stat st;
	if (rt_file_stat(path, &st) != 0) {
		rt_error_set(err, "%s: cannot read the model: %s", path, strerror(errno));
		return NULL;
	}
	if (!smooth)
		crease_deg = 0;
	pthread_mutex_lock(&cache_lock);
	for (size_t i = 0; i < ncache; i++) {
		cache_entry *c = &cache[i];
		if (strcmp(c->path, path) == 0 && c->node == node && c->smooth == smooth && c->crease == crease_deg &&
		    c->size == st.st_size && c->mtime.tv_sec == st.st_mtim.tv_sec &&
		    c->mtime.tv_nsec == st.st_mtim.tv_nsec) {
			c->m->refs++;
			pthread_mutex_unlock(&cache_lock);
			return c->m;
		}
	}
	pthread_mutex_unlock(&cache_lock);
	/* the readers poll the flag every few thousand elements (the builder,
	 * mesh.c); assimp's own parse (STL) runs to its end */
	const atomic_bool *outer = read_cancel_set(cancel);
	mesh *m = load_node(path, node, err);
	read_cancel_set(outer);
	if (!m && cancel && atomic_load(cancel))
		rt_error_set(err, "stopped");
	if (!m)
		return NULL;
	/* a stopped model is not cached */
	if (cancel && atomic_load(cancel)) {
		mesh_free(m);
		rt_error_set(err, "stopped");
		return NULL;
	}
	if (!mesh_prepare_cancel(m, smooth, crease_deg, cancel, err)) {
		mesh_free(m);
		return NULL;
	}
	pthread_mutex_lock(&cache_lock);
	char *p = strdup(path);
	if (!p || !mem_grow((void **)&cache, &ccache, ncache + 1, sizeof *cache)) {
		pthread_mutex_unlock(&cache_lock);
		free(p);
		mesh_free(m);
		rt_error_set(err, "%s: out of memory", path);
		return NULL;
	}
	m->refs = 1;
	cache[ncache++] = (cache_entry){m, p, node, smooth, crease_deg, st.st_size, st.st_mtim};
	pthread_mutex_unlock(&cache_lock);
	return m;
}

/* Meshes nobody uses stay cached (a world is rebuilt on every edit, and the
 * next one usually wants the same models) unless the cache holds more than
 * this many unused ones, when the unused are dropped. */
#define CACHE_KEEP 8

void mesh_cache_put(mesh *m)
{
	if (!m)
		return;
	pthread_mutex_lock(&cache_lock);
	if (m->refs > 0)
		m->refs--;
	size_t unused = 0;
	for (size_t i = 0; i < ncache; i++)
		unused += cache[i].m->refs == 0;
	if (unused > CACHE_KEEP) {
		size_t j = 0;
		for (size_t i = 0; i < ncache; i++) {
			if (cache[i].m->refs == 0) {
				mesh_free(cache[i].m);
				free(cache[i].path);
			} else {
				cache[j++] = cache[i];
			}
		}
		ncache = j;
	}
	pthread_mutex_unlock(&cache_lock);
}
