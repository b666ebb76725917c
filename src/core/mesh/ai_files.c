/* rtsh — assimp opens a model's files (the model, a .gltf's buffers)
 * through the scene's file source (rt_file_read, rtsh/filesrc.h). */
#include "core/mesh/mesh_io.h"

#include <pthread.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "base/dynlib.h"
#include "core/mesh/ai_lib.h"
#include "rtsh/filesrc.h"

static ai_lib ai;
static dynlib_lazy ai_lazy = DYNLIB_LAZY;

static void ai_open_lib(void)
{
	const dynlib_fn fns[] = {
	    {"aiImportFileEx", &ai.import_file_ex},
	    {"aiReleaseImport", &ai.release_import},
	    {"aiGetErrorString", &ai.get_error_string},
	    {"aiGetMaterialColor", &ai.get_material_color},
	    {"aiGetMaterialFloatArray", &ai.get_material_float_array},
	    {"aiGetMaterialTexture", &ai.get_material_texture},
	};
	ai_lazy.ok = dynlib_open(RTSH_ASSIMP_SONAME, fns, sizeof fns / sizeof fns[0], ai_lazy.why, sizeof ai_lazy.why);
}

const ai_lib *ai_lib_get(const char *path, rt_error *err)
{
	pthread_once(&ai_lazy.once, ai_open_lib);
	if (!ai_lazy.ok) {
		rt_error_set(err, "%s: cannot read the model: assimp cannot be loaded (%s); expected %s installed", path,
		             ai_lazy.why, RTSH_ASSIMP_SONAME);
		return NULL;
	}
	return &ai;
}

/* One import: the model's bytes, read once before assimp starts. */
typedef struct ai_job {
	const char *path;
	const char *bytes;
	size_t len;
} ai_job;

/* One file assimp opened. */
typedef struct ai_open {
	const char *bytes;
	char *owned; /* bytes when this file read them (not the model's) */
	size_t len, pos;
} ai_open;

static ai_open *open_of(struct aiFile *f)
{
	return (ai_open *)(void *)f->UserData;
}

static size_t ai_read(struct aiFile *f, char *buf, size_t size, size_t count)
{
	ai_open *o = open_of(f);
	if (size == 0 || o->pos >= o->len)
		return 0;
	size_t n = (o->len - o->pos) / size;
	if (n > count)
		n = count;
	memcpy(buf, o->bytes + o->pos, n * size);
	o->pos += n * size;
	return n;
}

static size_t ai_write(struct aiFile *f, const char *buf, size_t size, size_t count)
{
	(void)f, (void)buf, (void)size, (void)count;
	return 0;
}

static size_t ai_tell(struct aiFile *f)
{
	return open_of(f)->pos;
}

static size_t ai_size(struct aiFile *f)
{
	return open_of(f)->len;
}

static enum aiReturn ai_seek(struct aiFile *f, size_t off, enum aiOrigin from)
{
	ai_open *o = open_of(f);
	size_t base = from == aiOrigin_SET ? 0 : from == aiOrigin_CUR ? o->pos : from == aiOrigin_END ? o->len
	                                                                                             : SIZE_MAX;
	if (base == SIZE_MAX || off > o->len - base)
		return aiReturn_FAILURE;
	o->pos = base + off;
	return aiReturn_SUCCESS;
}

static void ai_flush(struct aiFile *f)
{
	(void)f;
}

static struct aiFile *ai_open_file(struct aiFileIO *io, const char *name, const char *mode)
{
	const ai_job *job = (const ai_job *)(void *)io->UserData;
	if (strpbrk(mode, "wa+"))
		return NULL;
	struct aiFile *f = calloc(1, sizeof *f);
	ai_open *o = calloc(1, sizeof *o);
	if (!f || !o)
		goto fail;
	if (strcmp(name, job->path) == 0) {
		o->bytes = job->bytes;
		o->len = job->len;
	} else {
		rt_error ignored;
		o->owned = rt_file_read(name, "model", &o->len, &ignored);
		if (!o->owned)
			goto fail;
		o->bytes = o->owned;
	}
	*f = (struct aiFile){ai_read, ai_write, ai_tell, ai_size, ai_seek, ai_flush, (aiUserData)(void *)o};
	return f;
fail:
	free(o);
	free(f);
	return NULL;
}

static void ai_close_file(struct aiFileIO *io, struct aiFile *f)
{
	(void)io;
	if (!f)
		return;
	ai_open *o = open_of(f);
	free(o->owned);
	free(o);
	free(f);
}

static uint32_t le32(const unsigned char *p)
{
	return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* A binary glTF's header and chunk lengths against the file's size: assimp
 * takes them on trust and allocates what they say (a 600-byte file asked
 * it for 4 GB; a 281-byte one whose header says 0 bytes asked for 1.5 GB
 * in its JSON chunk: both found by fuzz_model). So the header's length
 * must cover the 12-byte header and one chunk header and not pass the end
 * of the file, and every chunk must end inside it. Chunks are stepped over
 * as assimp does, their lengths rounded up to 4 bytes. glTF 1.0's binary
 * form has one content block after a 20-byte header: its length is checked
 * the same way. False (err set) when something says more than the file
 * holds. */
static bool glb_fits(const char *path, const unsigned char *b, size_t len, rt_error *err)
{
	if (len < 12 || le32(b) != 0x46546C67u) /* "glTF": else assimp says what it is */
		return true;
	uint32_t total = le32(b + 8);
	if (total < 20 || total > len)
		return rt_error_set(err, "%s: byte 8: the .glb says it is %u bytes long, the file has %zu; expected a "
		                    "complete .glb (20 bytes at least)", path, total, len);
	if (le32(b + 4) != 2) {
		uint32_t n = le32(b + 12); /* glTF 1.0: contentLength */
		if (n > total - 20)
			return rt_error_set(err, "%s: byte 12: a .glb content of %u bytes, %u left in the file; expected "
			                    "a complete .glb", path, n, total - 20);
		return true;
	}
	for (size_t at = 12; at < total;) {
		if (total - at < 8)
			return rt_error_set(err, "%s: byte %zu: a .glb chunk header cut short (%zu of 8 bytes); expected a "
			                    "complete .glb", path, at, (size_t)(total - at));
		uint32_t n = le32(b + at);
		if (n > total - at - 8)
			return rt_error_set(err, "%s: byte %zu: a .glb chunk of %u bytes, %zu left in the file; expected a "
			                    "complete .glb", path, at, n, (size_t)(total - at - 8));
		at += 8 + (((size_t)n + 3) & ~(size_t)3);
	}
	return true;
}

static bool has_ext(const char *path, const char *ext)
{
	const char *slash = strrchr(path, '/'), *dot = strrchr(slash ? slash : path, '.');
	return dot && strcasecmp(dot + 1, ext) == 0;
}

/* Whether the bytes are what the extension says (rtsh reads .gltf, .glb
 * and .stl through assimp): when they are not, assimp would try every one
 * of its importers on them, and one of those reads past its buffer on a
 * 20-byte file (found by fuzz_model). So only its glTF and STL readers
 * see a file. False (err set) when they are not. */
static bool looks_like(const char *path, const unsigned char *b, size_t len, rt_error *err)
{
	size_t i = len >= 3 && b[0] == 0xef && b[1] == 0xbb && b[2] == 0xbf ? 3 : 0; /* a UTF-8 BOM */
	while (i < len && (b[i] == ' ' || b[i] == '\t' || b[i] == '\r' || b[i] == '\n'))
		i++;
	if (has_ext(path, "glb")) {
		if (len >= 4 && le32(b) == 0x46546C67u)
			return true;
		return rt_error_set(err, "%s: byte 0: not a binary glTF; expected the bytes \"glTF\" at its start", path);
	}
	if (has_ext(path, "gltf")) {
		if (i < len && b[i] == '{')
			return true;
		return rt_error_set(err, "%s: byte %zu: not a glTF file; expected its JSON, from \"{\"", path, i);
	}
	if (has_ext(path, "stl")) {
		/* binary: an 80-byte header, a count, 50 bytes a triangle */
		if (len >= 84 && (uint64_t)len == 84 + 50 * (uint64_t)le32(b + 80))
			return true;
		if (len - i >= 5 && strncasecmp((const char *)b + i, "solid", 5) == 0)
			return true;
		return rt_error_set(err, "%s: not an STL file; expected \"solid\" (text) or 84 bytes and 50 a triangle "
		                    "(binary)", path);
	}
	return true;
}

const struct aiScene *rt_file_ai_import(const char *path, unsigned flags, rt_error *err)
{
	size_t len;
	char *bytes = rt_file_read(path, "model", &len, err);
	if (!bytes)
		return NULL;
	if (!looks_like(path, (const unsigned char *)bytes, len, err) ||
	    (has_ext(path, "glb") && !glb_fits(path, (const unsigned char *)bytes, len, err))) {
		free(bytes);
		return NULL;
	}
	const ai_lib *lib = ai_lib_get(path, err);
	if (!lib) {
		free(bytes);
		return NULL;
	}
	ai_job job = {path, bytes, len};
	struct aiFileIO io = {ai_open_file, ai_close_file, (aiUserData)(void *)&job};
	const struct aiScene *sc = lib->import_file_ex(path, flags, &io);
	free(bytes);
	if (!sc)
		rt_error_set(err, "%s: cannot read the model: %s", path, lib->get_error_string());
	return sc;
}
