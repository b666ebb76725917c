/* rtsh — glTF 2.0 (.gltf, .glb): our own reader over cJSON (mesh.h, gltf.h).
 *
 * The file's JSON is parsed by cJSON (Debian's libcjson); the rest is ours:
 * the GLB container (glTF 2.0 spec, "GLB File Format Specification"),
 * buffers (the GLB's BIN chunk, base64 data: URIs, files beside the model,
 * all read through the file source), buffer views and accessors (every
 * component type, normalized integers, strides, an accessor with no view
 * as zeros), the default scene's node hierarchy (matrix or translation,
 * rotation, scale; a node placed twice, or a cycle, is an error: a node is
 * visited once, so the walk is linear in the file), triangle lists, strips
 * and fans, and the materials: metallic-roughness factors and textures,
 * normal and emissive textures, alphaMode, KHR_texture_transform,
 * KHR_materials_emissive_strength, _transmission, _ior, _volume,
 * _clearcoat and _specular. Every primitive a node places is flattened
 * into one mesh in the file's coordinates (as assimp's
 * PreTransformVertices did), normals by the inverse transpose, the winding
 * turned where a transform mirrors.
 *
 * Hostile files: the JSON's worst-case node count (one per structural
 * character) and the triangles the node hierarchy places are checked
 * against the memory limit before anything is allocated for them; every
 * accessor is checked against its view and every view against its buffer
 * before it is read; indices against the vertex count. Messages name the
 * file, the JSON path (meshes[0].primitives[1].attributes.POSITION) or the
 * byte offset, and what was expected.
 */
#include <ctype.h>
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cjson/cJSON.h>

#include "base/dynlib.h"
#include "core/mesh/mesh_io.h"
#include "rtsh/filesrc.h"
#include "rtsh/gltf.h"
#include "rtsh/memory.h"
#include "rtsh/mesh.h"
#include "rtsh/texture.h"

/* cJSON, opened on the first glTF (base/dynlib.h): a process that reads no
 * glTF does not map it (issue 29: the start-up's serial time). */
#ifndef RTSH_CJSON_SONAME
#define RTSH_CJSON_SONAME "libcjson.so.1"
#endif

static struct {
	cJSON *(*parse)(const char *value, size_t len, const char **end, cJSON_bool null_terminated);
	void (*del)(cJSON *item);
	cJSON *(*get)(const cJSON *object, const char *name);
	cJSON_bool (*is_string)(const cJSON *item);
	cJSON_bool (*is_array)(const cJSON *item);
	cJSON_bool (*is_number)(const cJSON *item);
	cJSON_bool (*is_object)(const cJSON *item);
	cJSON_bool (*is_true)(const cJSON *item);
} cj;
static dynlib_lazy cj_lazy = DYNLIB_LAZY;

static void cj_open(void)
{
	const dynlib_fn fns[] = {
	    {"cJSON_ParseWithLengthOpts", &cj.parse}, {"cJSON_Delete", &cj.del},
	    {"cJSON_GetObjectItemCaseSensitive", &cj.get}, {"cJSON_IsString", &cj.is_string},
	    {"cJSON_IsArray", &cj.is_array}, {"cJSON_IsNumber", &cj.is_number},
	    {"cJSON_IsObject", &cj.is_object}, {"cJSON_IsTrue", &cj.is_true},
	};
	cj_lazy.ok = dynlib_open(RTSH_CJSON_SONAME, fns, sizeof fns / sizeof fns[0], cj_lazy.why, sizeof cj_lazy.why);
}

#define WHERE_MAX 96
#define WHERE2_MAX 256 /* a path built on a WHERE_MAX one */
#define WHERE3_MAX 384

/* A 3x4 affine transform, row-major: p' = m (p, 1). */
typedef struct aff {
	double m[3][4];
} aff;

typedef struct table {
	const cJSON **v;
	size_t n;
} table;

typedef struct gl {
	const char *name; /* for messages */
	const char *dir;  /* external buffers: NULL, none */
	rt_error *err;
	cJSON *root;
	const unsigned char *bin; /* the GLB's BIN chunk */
	size_t nbin;
	bool has_bin;
	table nodes, meshes, accessors, views, buffers, materials, textures, images, samplers, cameras, lights;
	unsigned char **buf; /* decoded buffers, NULL until used */
	size_t *buflen;
	bool *bufown;
	aff *world;       /* per node, once visited */
	unsigned char *seen; /* per node: 1 visited */
	int32_t *order;   /* the nodes the scene places, in walk order */
	size_t norder;
	long only;        /* build only this node's mesh (a node object); -1: all */
} gl;

static bool fail(gl *g, const char *where, const char *fmt, ...)
{
	char msg[RT_ERROR_MSG_MAX];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(msg, sizeof msg, fmt, ap);
	va_end(ap);
	if (where && where[0])
		return rt_error_set(g->err, "%s: %s: %s", g->name, where, msg);
	return rt_error_set(g->err, "%s: %s", g->name, msg);
}

static uint32_t le32(const unsigned char *p)
{
	return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* --- the container and the JSON --- */

/* Finds the JSON (and the BIN chunk of a .glb); false (err set) when the
 * bytes are neither. */
static bool split(gl *g, const unsigned char *b, size_t len, const char **json, size_t *njson, size_t *jstart)
{
	if (len >= 4 && le32(b) == 0x46546C67u) { /* "glTF" */
		if (len < 20)
			return fail(g, "byte 0", "a .glb of %zu bytes; expected a 12-byte header and a chunk", len);
		uint32_t version = le32(b + 4), total = le32(b + 8);
		if (version != 2)
			return fail(g, "byte 4", "binary glTF version %u; expected 2", version);
		if (total < 20 || total > len)
			return fail(g, "byte 8", "the .glb says it is %u bytes long, the file has %zu; expected a complete "
			            ".glb (20 bytes at least)", total, len);
		uint32_t n = le32(b + 12);
		if (n > total - 20)
			return fail(g, "byte 12", "a .glb chunk of %u bytes, %u left in the file; expected a complete .glb",
			            n, total - 20);
		if (le32(b + 16) != 0x4E4F534Au)
			return fail(g, "byte 16", "a first chunk that is not JSON; expected the type \"JSON\"");
		*json = (const char *)b + 20;
		*njson = n;
		*jstart = 20;
		size_t at = 20 + (((size_t)n + 3) & ~(size_t)3);
		if (at < total) {
			if (total - at < 8)
				return fail(g, NULL, "byte %zu: a .glb chunk header cut short (%zu of 8 bytes); expected a "
				            "complete .glb", at, (size_t)(total - at));
			uint32_t nb = le32(b + at);
			if (nb > total - at - 8)
				return fail(g, NULL, "byte %zu: a .glb chunk of %u bytes, %zu left in the file; expected a "
				            "complete .glb", at, nb, (size_t)(total - at - 8));
			if (le32(b + at + 4) == 0x004E4942u) { /* "BIN\0" */
				g->bin = b + at + 8;
				g->nbin = nb;
				g->has_bin = true;
			}
		}
		return true;
	}
	size_t i = len >= 3 && b[0] == 0xef && b[1] == 0xbb && b[2] == 0xbf ? 3 : 0;
	size_t j = i;
	while (j < len && (b[j] == ' ' || b[j] == '\t' || b[j] == '\r' || b[j] == '\n'))
		j++;
	if (j >= len || b[j] != '{')
		return fail(g, NULL, "byte %zu: not a glTF file; expected its JSON, from \"{\", or the bytes \"glTF\"", j);
	*json = (const char *)b + i;
	*njson = len - i;
	*jstart = i;
	return true;
}

/* cJSON keeps a 64-byte record per value: at most one value per structural
 * character (and one more), refused before parsing when that could pass
 * the memory limit. */
static bool parse_json(gl *g, const char *json, size_t n, size_t start)
{
	size_t marks = 1;
	for (size_t i = 0; i < n; i++)
		marks += json[i] == ',' || json[i] == '[' || json[i] == '{' || json[i] == ':';
	pthread_once(&cj_lazy.once, cj_open);
	if (!cj_lazy.ok)
		return fail(g, NULL, "cannot read the glTF: cJSON cannot be loaded (%s); expected %s installed", cj_lazy.why,
		            RTSH_CJSON_SONAME);
	char what[300];
	snprintf(what, sizeof what, "the JSON of %s", g->name);
	if (!mem_check((double)marks * sizeof(cJSON) + (double)n, what, g->err))
		return false;
	const char *end = NULL;
	/* cJSON resets and sets a process-wide error record in every parse:
	 * one parse at a time (models load on the render service's thread and
	 * the shell's) */
	static pthread_mutex_t parse_lock = PTHREAD_MUTEX_INITIALIZER;
	pthread_mutex_lock(&parse_lock);
	g->root = cj.parse(json, n, &end, false);
	pthread_mutex_unlock(&parse_lock);
	if (!g->root) {
		size_t at = end && end >= json && end <= json + n ? (size_t)(end - json) : 0;
		return fail(g, NULL, "byte %zu: not valid JSON; expected a JSON object (RFC 8259)", start + at);
	}
	if (!cj.is_object(g->root))
		return fail(g, NULL, "byte %zu: the JSON is not an object; expected a glTF object {...}", start);
	return true;
}

/* --- values --- */

static const cJSON *key(const cJSON *o, const char *k)
{
	return cj.is_object(o) ? cj.get(o, k) : NULL;
}

/* An index at o[k] into a table of n: false (err set) when present and not
 * an integer in [0, n). *out -1 when absent (required: an error). */
static bool get_index(gl *g, const cJSON *o, const char *k, const char *where, size_t n, const char *tname,
                      bool required, long *out)
{
	const cJSON *v = key(o, k);
	*out = -1;
	if (!v) {
		if (required)
			return fail(g, where, "no \"%s\"; expected an index into %s", k, tname);
		return true;
	}
	double d = cj.is_number(v) ? v->valuedouble : -1;
	if (!cj.is_number(v) || !(d >= 0) || d != floor(d) || d >= (double)n) {
		if (n == 0)
			return fail(g, where, "%s: %s has no entries; expected none to refer to", k, tname);
		return fail(g, where, "%s: not an index into %s; expected an integer from 0 to %zu", k, tname, n - 1);
	}
	*out = (long)d;
	return true;
}

/* A number at o[k] in [lo, hi], def when absent. */
static bool get_num(gl *g, const cJSON *o, const char *k, const char *where, double lo, double hi, double def,
                    double *out)
{
	const cJSON *v = key(o, k);
	*out = def;
	if (!v)
		return true;
	if (!cj.is_number(v) || !(v->valuedouble >= lo && v->valuedouble <= hi))
		return fail(g, where, "%s: not a number from %g to %g; expected one", k, lo, hi);
	*out = v->valuedouble;
	return true;
}

/* get_num into a float field (left as it was on an error). */
static bool get_float(gl *g, const cJSON *o, const char *k, const char *where, double lo, double hi, double def,
                      float *out)
{
	double v;
	if (!get_num(g, o, k, where, lo, hi, def, &v))
		return false;
	*out = (float)v;
	return true;
}

/* n numbers at o[k] in [lo, hi] (def when absent). */
static bool get_nums(gl *g, const cJSON *o, const char *k, const char *where, int n, double lo, double hi,
                     const double *def, double *out)
{
	const cJSON *v = key(o, k);
	for (int i = 0; i < n; i++)
		out[i] = def[i];
	if (!v)
		return true;
	int i = 0;
	const cJSON *e = cj.is_array(v) ? v->child : NULL;
	for (; e && i < n; e = e->next, i++) {
		if (!cj.is_number(e) || !(e->valuedouble >= lo && e->valuedouble <= hi))
			return fail(g, where, "%s[%d]: not a number from %g to %g; expected one", k, i, lo, hi);
		out[i] = e->valuedouble;
	}
	if (!cj.is_array(v) || i != n || e)
		return fail(g, where, "%s: not an array of %d numbers; expected %d", k, n, n);
	return true;
}

/* The top-level array k as a table of its elements (linear: cJSON's
 * GetArrayItem walks from the start each time). */
static bool get_table(gl *g, const char *k, table *t)
{
	const cJSON *a = key(g->root, k);
	t->v = NULL;
	t->n = 0;
	if (!a)
		return true;
	if (!cj.is_array(a))
		return fail(g, k, "not an array; expected [...]");
	size_t n = 0;
	for (const cJSON *e = a->child; e; e = e->next)
		n++;
	if (n == 0)
		return true;
	t->v = malloc(n * sizeof *t->v);
	if (!t->v)
		return fail(g, k, "out of memory");
	for (const cJSON *e = a->child; e; e = e->next) {
		if (!cj.is_object(e))
			return fail(g, NULL, "%s[%zu]: not an object; expected {...}", k, t->n);
		t->v[t->n++] = e;
	}
	return true;
}

static void gl_free(gl *g)
{
	if (g->root) /* (NULL too when cJSON could not be loaded) */
		cj.del(g->root);
	table *ts[] = {&g->nodes, &g->meshes, &g->accessors, &g->views, &g->buffers, &g->materials,
	               &g->textures, &g->images, &g->samplers, &g->cameras, &g->lights};
	for (size_t i = 0; i < sizeof ts / sizeof ts[0]; i++)
		free(ts[i]->v);
	for (size_t i = 0; g->buf && i < g->buffers.n; i++)
		if (g->bufown[i])
			free(g->buf[i]);
	mem_free_all(g->buf, g->buflen, g->bufown, g->world, g->seen, g->order);
}

/* The JSON and the tables; the asset must say glTF 2.x and every required
 * extension must be one rtsh reads. */
static bool gl_open(gl *g, const char *buf, size_t len)
{
	const char *json = NULL;
	size_t njson = 0, jstart = 0;
	if (!split(g, (const unsigned char *)buf, len, &json, &njson, &jstart) || !parse_json(g, json, njson, jstart))
		return false;
	const cJSON *asset = key(g->root, "asset"), *ver = key(asset, "version");
	if (!cj.is_string(ver) || ver->valuestring[0] != '2' || ver->valuestring[1] != '.')
		return fail(g, "asset.version", "not \"2.x\"; expected a glTF 2.0 file");
	const cJSON *req = key(g->root, "extensionsRequired");
	static const char *const known[] = {"KHR_lights_punctual", "KHR_texture_transform", "KHR_materials_emissive_strength",
	                                    "KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume",
	                                    "KHR_materials_clearcoat", "KHR_materials_specular"};
	int i = 0;
	for (const cJSON *e = cj.is_array(req) ? req->child : NULL; e; e = e->next, i++) {
		bool ok = false;
		for (size_t k = 0; cj.is_string(e) && k < sizeof known / sizeof known[0]; k++)
			ok |= strcmp(e->valuestring, known[k]) == 0;
		if (!ok)
			return fail(g, NULL, "extensionsRequired[%d]: \"%.60s\" is not read by rtsh; expected only %s, %s, %s, "
			            "%s, %s, %s, %s or %s", i, cj.is_string(e) ? e->valuestring : "?", known[0], known[1],
			            known[2], known[3], known[4], known[5], known[6], known[7]);
	}
	if (!get_table(g, "nodes", &g->nodes) || !get_table(g, "meshes", &g->meshes) ||
	    !get_table(g, "accessors", &g->accessors) || !get_table(g, "bufferViews", &g->views) ||
	    !get_table(g, "buffers", &g->buffers) || !get_table(g, "materials", &g->materials) ||
	    !get_table(g, "textures", &g->textures) || !get_table(g, "images", &g->images) ||
	    !get_table(g, "samplers", &g->samplers) || !get_table(g, "cameras", &g->cameras))
		return false;
	/* KHR_lights_punctual's lights sit in the root's extensions */
	const cJSON *la = key(key(key(g->root, "extensions"), "KHR_lights_punctual"), "lights");
	if (la) {
		if (!cj.is_array(la))
			return fail(g, "extensions.KHR_lights_punctual.lights", "not an array; expected [...]");
		size_t n = 0;
		for (const cJSON *e = la->child; e; e = e->next)
			n++;
		if (n && !(g->lights.v = malloc(n * sizeof *g->lights.v)))
			return fail(g, NULL, "out of memory");
		for (const cJSON *e = la->child; e; e = e->next)
			g->lights.v[g->lights.n++] = e;
	}
	size_t nb = g->buffers.n ? g->buffers.n : 1;
	g->buf = calloc(nb, sizeof *g->buf);
	g->buflen = calloc(nb, sizeof *g->buflen);
	g->bufown = calloc(nb, sizeof *g->bufown);
	if (!g->buf || !g->buflen || !g->bufown)
		return fail(g, NULL, "out of memory");
	return true;
}

/* --- buffers --- */

static int b64(int c)
{
	if (c >= 'A' && c <= 'Z')
		return c - 'A';
	if (c >= 'a' && c <= 'z')
		return c - 'a' + 26;
	if (c >= '0' && c <= '9')
		return c - '0' + 52;
	return c == '+' || c == '-' ? 62 : c == '/' || c == '_' ? 63 : -1;
}

/* The bytes of a data: URI (base64 only); NULL (err set) when it is not
 * one. */
static unsigned char *data_uri(gl *g, const char *uri, const char *where, size_t *len)
{
	const char *comma = strchr(uri, ',');
	if (!comma || comma - uri < 7 || strncmp(comma - 7, ";base64", 7) != 0) {
		fail(g, where, "uri: a data: URI that is not base64; expected \"data:...;base64,...\"");
		return NULL;
	}
	const char *s = comma + 1;
	size_t n = strlen(s);
	unsigned char *out = malloc(n / 4 * 3 + 3);
	if (!out) {
		fail(g, where, "out of memory");
		return NULL;
	}
	size_t k = 0;
	uint32_t acc = 0;
	int bits = 0;
	for (size_t i = 0; i < n && s[i] != '='; i++) {
		int v = b64((unsigned char)s[i]);
		if (v < 0) {
			free(out);
			fail(g, where, "uri: character %zu of the base64 data is '%c'; expected A-Z a-z 0-9 + /", i,
			     isprint((unsigned char)s[i]) ? s[i] : '?');
			return NULL;
		}
		acc = acc << 6 | (uint32_t)v;
		bits += 6;
		if (bits >= 8) {
			bits -= 8;
			out[k++] = (unsigned char)(acc >> bits);
		}
	}
	*len = k;
	return out;
}

/* A relative URI as a file name: %XX decoded. */
static char *uri_file(const char *dir, const char *uri)
{
	size_t n = strlen(uri);
	char *s = malloc(n + 1);
	if (!s)
		return NULL;
	size_t k = 0;
	for (size_t i = 0; i < n; i++) {
		if (uri[i] == '%' && isxdigit((unsigned char)uri[i + 1]) && isxdigit((unsigned char)uri[i + 2])) {
			char hex[3] = {uri[i + 1], uri[i + 2], 0};
			s[k++] = (char)strtol(hex, NULL, 16);
			i += 2;
		} else {
			s[k++] = uri[i];
		}
	}
	s[k] = '\0';
	char *p = path_join(dir, s);
	free(s);
	return p;
}

/* A file uri that %00 would cut short (the file read would be another). */
static bool uri_name_ok(gl *g, const char *uri, const char *where)
{
	if (!*uri)
		return fail(g, where, "uri: empty; expected a data: URI or a file name");
	for (const char *p = uri; (p = strchr(p, '%')) != NULL; p++)
		if (p[1] == '0' && p[2] == '0')
			return fail(g, where, "uri: \"%.80s\" holds %%00 (a NUL byte); expected a file name", uri);
	return true;
}

/* g->err, set by a reader that does not know the model (a file's "PATH:
 * cannot read ..."), again after the model's name and where. */
static bool fail_again(gl *g, const char *where)
{
	char why[RT_ERROR_MSG_MAX];
	rt_error_format(g->err, why, sizeof why);
	return fail(g, where, "%s", why);
}

/* Buffer i's bytes, read on first use. */
static bool buffer(gl *g, size_t i, const unsigned char **p, size_t *len)
{
	char where[WHERE_MAX];
	snprintf(where, sizeof where, "buffers[%zu]", i);
	if (!g->buf[i]) {
		const cJSON *b = g->buffers.v[i], *uri = key(b, "uri");
		double bl;
		if (!get_num(g, b, "byteLength", where, 1, 1e15, -1, &bl))
			return false;
		if (bl < 0)
			return fail(g, where, "no \"byteLength\"; expected the buffer's size in bytes");
		if (!uri) {
			if (!g->has_bin || i != 0)
				return fail(g, where, "no \"uri\" and no BIN chunk; expected a data: URI, a file name, or the "
				            "first buffer of a .glb");
			g->buf[i] = (unsigned char *)g->bin;
			g->buflen[i] = g->nbin;
		} else if (!cj.is_string(uri)) {
			return fail(g, where, "uri: not a string; expected a data: URI or a file name");
		} else if (strncmp(uri->valuestring, "data:", 5) == 0) {
			if (!(g->buf[i] = data_uri(g, uri->valuestring, where, &g->buflen[i])))
				return false;
			g->bufown[i] = true;
		} else {
			if (!g->dir)
				return fail(g, where, "uri: the file \"%.80s\" is not read here; expected the data in the file",
				            uri->valuestring);
			if (!uri_name_ok(g, uri->valuestring, where))
				return false;
			char *path = uri_file(g->dir, uri->valuestring);
			if (!path)
				return fail(g, where, "out of memory");
			size_t n = 0;
			char *data = rt_file_read(path, "glTF buffer", &n, g->err);
			free(path);
			if (!data) /* the reader's words, after the model's name */
				return fail_again(g, where);
			g->buf[i] = (unsigned char *)data;
			g->buflen[i] = n;
			g->bufown[i] = true;
		}
		if (bl > (double)g->buflen[i])
			return fail(g, where, "byteLength %.0f, the data has %zu bytes; expected at most %zu", bl,
			            g->buflen[i], g->buflen[i]);
		g->buflen[i] = (size_t)bl;
	}
	*p = g->buf[i];
	*len = g->buflen[i];
	return true;
}

/* Buffer view i's bytes and stride (0: tightly packed). */
static bool view(gl *g, size_t i, const unsigned char **p, size_t *len, size_t *stride)
{
	char where[WHERE_MAX];
	snprintf(where, sizeof where, "bufferViews[%zu]", i);
	const cJSON *v = g->views.v[i];
	long b;
	double off, n, st;
	if (!get_index(g, v, "buffer", where, g->buffers.n, "buffers", true, &b) ||
	    !get_num(g, v, "byteOffset", where, 0, 1e15, 0, &off) || !get_num(g, v, "byteLength", where, 1, 1e15, -1, &n) ||
	    !get_num(g, v, "byteStride", where, 4, 252, 0, &st))
		return false;
	if (n < 0)
		return fail(g, where, "no \"byteLength\"; expected the view's size in bytes");
	if (off != floor(off) || n != floor(n) || st != floor(st))
		return fail(g, where, "a byte offset, length or stride that is not a whole number; expected integers");
	const unsigned char *bp = NULL;
	size_t blen = 0;
	if (!buffer(g, (size_t)b, &bp, &blen))
		return false;
	if (off + n > (double)blen)
		return fail(g, where, "bytes %.0f to %.0f of buffers[%ld], which has %zu; expected a view inside its buffer",
		            off, off + n, b, blen);
	*p = bp + (size_t)off;
	*len = (size_t)n;
	*stride = (size_t)st;
	return true;
}

/* --- accessors --- */

typedef struct acc {
	const unsigned char *p; /* NULL: all zeros */
	size_t count, stride;
	int ctype, ncomp;
	bool norm;
} acc;

static int comp_size(int ctype)
{
	switch (ctype) {
	case 5120: case 5121: return 1;
	case 5122: case 5123: return 2;
	case 5125: case 5126: return 4;
	default: return 0;
	}
}

/* Accessor i, checked against its view: types names the component types
 * allowed (0-terminated), ncomp the element's components. */
static bool accessor(gl *g, size_t i, const char *use, int ncomp, const int *types, acc *a)
{
	char where[WHERE_MAX];
	snprintf(where, sizeof where, "accessors[%zu]", i);
	const cJSON *o = g->accessors.v[i];
	static const char *const tnames[] = {"SCALAR", "VEC2", "VEC3", "VEC4"};
	const cJSON *ty = key(o, "type");
	if (!cj.is_string(ty) || strcmp(ty->valuestring, tnames[ncomp - 1]) != 0)
		return fail(g, where, "type %s%.20s%s for %s; expected \"%s\"", cj.is_string(ty) ? "\"" : "",
		            cj.is_string(ty) ? ty->valuestring : "missing", cj.is_string(ty) ? "\"" : "", use,
		            tnames[ncomp - 1]);
	double ct, count, off;
	long v;
	if (!get_num(g, o, "componentType", where, 0, 1e9, -1, &ct) || !get_num(g, o, "count", where, 1, 1e15, -1, &count) ||
	    !get_num(g, o, "byteOffset", where, 0, 1e15, 0, &off) ||
	    !get_index(g, o, "bufferView", where, g->views.n, "bufferViews", false, &v))
		return false;
	if (count < 0 || count != floor(count))
		return fail(g, where, "count: missing or not a whole number; expected the number of elements, >= 1");
	bool ok = false;
	for (const int *t = types; *t; t++)
		ok |= (double)*t == ct;
	if (!ok) {
		char list[80] = "";
		for (const int *t = types; *t; t++)
			snprintf(list + strlen(list), sizeof list - strlen(list), "%s%d", t == types ? "" : " ", *t);
		return fail(g, where, "componentType %.0f for %s; expected one of %s", ct, use, list);
	}
	if (key(o, "sparse"))
		return fail(g, where, "sparse: sparse accessors are not read by rtsh; expected a plain accessor");
	const cJSON *nm = key(o, "normalized");
	*a = (acc){.count = (size_t)count, .ctype = (int)ct, .ncomp = ncomp, .norm = cj.is_true(nm)};
	size_t esize = (size_t)comp_size(a->ctype) * (size_t)ncomp;
	if (v < 0)
		return true; /* zeros */
	const unsigned char *p;
	size_t len, stride;
	if (!view(g, (size_t)v, &p, &len, &stride))
		return false;
	a->stride = stride ? stride : esize;
	if (off != floor(off) || (size_t)off % (size_t)comp_size(a->ctype))
		return fail(g, where, "byteOffset %.0f; expected a multiple of the component size, %d", off,
		            comp_size(a->ctype));
	/* the last element must end inside the view */
	double need = off + (count - 1) * (double)a->stride + (double)esize;
	if (need > (double)len)
		return fail(g, where, "%.0f elements of %zu bytes every %zu from byte %.0f need %.0f bytes, "
		            "bufferViews[%ld] has %zu; expected the accessor inside its view",
		            count, esize, a->stride, off, need, v, len);
	a->p = p + (size_t)off;
	return true;
}

/* Component k of element i as a float (normalized integers per the spec). */
static float acc_get(const acc *a, size_t i, int k)
{
	if (!a->p)
		return 0.0f;
	const unsigned char *e = a->p + i * a->stride + (size_t)k * (size_t)comp_size(a->ctype);
	switch (a->ctype) {
	case 5126: {
		float f;
		memcpy(&f, e, 4);
		return f;
	}
	case 5120: return a->norm ? fmaxf((int8_t)e[0] / 127.0f, -1.0f) : (float)(int8_t)e[0];
	case 5121: return a->norm ? e[0] / 255.0f : (float)e[0];
	case 5122: {
		int16_t s = (int16_t)(e[0] | e[1] << 8);
		return a->norm ? fmaxf(s / 32767.0f, -1.0f) : (float)s;
	}
	case 5123: {
		uint16_t s = (uint16_t)(e[0] | e[1] << 8);
		return a->norm ? s / 65535.0f : (float)s;
	}
	default: return (float)le32(e);
	}
}

static uint32_t acc_index(const acc *a, size_t i)
{
	if (!a->p)
		return 0;
	const unsigned char *e = a->p + i * a->stride;
	return a->ctype == 5121 ? e[0] : a->ctype == 5123 ? (uint32_t)(e[0] | e[1] << 8) : le32(e);
}

/* --- nodes --- */

static aff aff_identity(void)
{
	return (aff){{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}}};
}

static aff aff_mul(const aff *a, const aff *b)
{
	aff r;
	for (int i = 0; i < 3; i++)
		for (int j = 0; j < 4; j++) {
			double s = a->m[i][0] * b->m[0][j] + a->m[i][1] * b->m[1][j] + a->m[i][2] * b->m[2][j];
			r.m[i][j] = j == 3 ? s + a->m[i][3] : s;
		}
	return r;
}

static vec3 aff_point(const aff *a, double x, double y, double z)
{
	return v3(a->m[0][0] * x + a->m[0][1] * y + a->m[0][2] * z + a->m[0][3],
	          a->m[1][0] * x + a->m[1][1] * y + a->m[1][2] * z + a->m[1][3],
	          a->m[2][0] * x + a->m[2][1] * y + a->m[2][2] * z + a->m[2][3]);
}

static vec3 aff_vector(const aff *a, double x, double y, double z)
{
	return v3(a->m[0][0] * x + a->m[0][1] * y + a->m[0][2] * z, a->m[1][0] * x + a->m[1][1] * y + a->m[1][2] * z,
	          a->m[2][0] * x + a->m[2][1] * y + a->m[2][2] * z);
}

static double aff_det(const aff *a)
{
	const double(*m)[4] = a->m;
	return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
	       m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

/* The node's own transform: its matrix (column-major), or T R S. */
static bool node_local(gl *g, size_t i, aff *out)
{
	char where[WHERE_MAX];
	snprintf(where, sizeof where, "nodes[%zu]", i);
	const cJSON *n = g->nodes.v[i];
	if (key(n, "matrix")) {
		static const double id[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
		double a[16];
		if (!get_nums(g, n, "matrix", where, 16, -1e300, 1e300, id, a))
			return false;
		for (int r = 0; r < 3; r++)
			for (int c = 0; c < 4; c++)
				out->m[r][c] = a[c * 4 + r];
		return true;
	}
	static const double t0[3] = {0, 0, 0}, r0[4] = {0, 0, 0, 1}, s0[3] = {1, 1, 1};
	double t[3], q[4], s[3];
	if (!get_nums(g, n, "translation", where, 3, -1e300, 1e300, t0, t) ||
	    !get_nums(g, n, "rotation", where, 4, -1, 1, r0, q) || !get_nums(g, n, "scale", where, 3, -1e300, 1e300, s0, s))
		return false;
	double l = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
	if (!(l > 0))
		return fail(g, where, "rotation: a quaternion of length 0; expected a unit quaternion (x, y, z, w)");
	double x = q[0] / l, y = q[1] / l, z = q[2] / l, w = q[3] / l;
	/* the rotation matrix of a unit quaternion */
	double r[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
	                  {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
	                  {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}};
	for (int a = 0; a < 3; a++) {
		for (int b = 0; b < 3; b++)
			out->m[a][b] = r[a][b] * s[b];
		out->m[a][3] = t[a];
	}
	return true;
}

/* Walks the scene's nodes from its roots, each node once: world[i] and the
 * order of the placed nodes. */
static bool walk(gl *g)
{
	size_t n = g->nodes.n;
	if (n == 0)
		return true;
	g->world = malloc(n * sizeof *g->world);
	g->seen = calloc(n, 1);
	g->order = malloc(n * sizeof *g->order);
	int32_t *stack = malloc(n * sizeof *stack);
	if (!g->world || !g->seen || !g->order || !stack) {
		free(stack);
		return fail(g, NULL, "out of memory");
	}
	/* the roots: the scene's nodes, else every node no other names */
	const cJSON *scenes = key(g->root, "scenes");
	long sc = -1;
	size_t nscenes = 0;
	for (const cJSON *e = cj.is_array(scenes) ? scenes->child : NULL; e; e = e->next)
		nscenes++;
	if (scenes && !cj.is_array(scenes)) {
		free(stack);
		return fail(g, "scenes", "not an array; expected [...]");
	}
	if (!get_index(g, g->root, "scene", "", nscenes, "scenes", false, &sc)) {
		free(stack);
		return false;
	}
	if (sc < 0 && nscenes > 0)
		sc = 0;
	size_t top = 0;
	char where[WHERE_MAX];
	bool ok = true;
	if (sc >= 0) {
		const cJSON *s = scenes->child;
		for (long k = 0; k < sc; k++)
			s = s->next;
		const cJSON *roots = key(s, "nodes");
		snprintf(where, sizeof where, "scenes[%ld]", sc);
		if (roots && !cj.is_array(roots))
			ok = fail(g, where, "nodes: not an array; expected [...]");
		/* pushed in reverse, so that the walk goes in the file's order */
		size_t nr = 0;
		for (const cJSON *e = ok && roots ? roots->child : NULL; e; e = e->next)
			nr++;
		const cJSON **rv = nr ? malloc(nr * sizeof *rv) : NULL;
		if (nr && !rv)
			ok = fail(g, NULL, "out of memory");
		size_t k = 0;
		for (const cJSON *e = ok && roots ? roots->child : NULL; e; e = e->next)
			rv[k++] = e;
		for (size_t j = nr; ok && j-- > 0;) {
			double d = cj.is_number(rv[j]) ? rv[j]->valuedouble : -1;
			if (!(d >= 0 && d < (double)n && d == floor(d)))
				ok = fail(g, where, "nodes[%zu]: not an index into nodes; expected an integer from 0 to %zu", j,
				          n - 1);
			else if (g->seen[(size_t)d])
				ok = fail(g, where, "nodes[%zu]: node %.0f is placed twice; expected each node once", j, d);
			else {
				g->seen[(size_t)d] = 1;
				g->world[(size_t)d] = aff_identity();
				stack[top++] = (int32_t)d;
			}
		}
		free(rv);
	} else {
		/* no scene: the nodes that are nobody's child */
		unsigned char *child = calloc(n, 1);
		if (!child)
			ok = fail(g, NULL, "out of memory");
		for (size_t i = 0; ok && i < n; i++) {
			const cJSON *c = key(g->nodes.v[i], "children");
			for (const cJSON *e = cj.is_array(c) ? c->child : NULL; e; e = e->next)
				if (cj.is_number(e) && e->valuedouble >= 0 && e->valuedouble < (double)n)
					child[(size_t)e->valuedouble] = 1;
		}
		for (size_t i = n; ok && i-- > 0;)
			if (!child[i]) {
				g->seen[i] = 1;
				g->world[i] = aff_identity();
				stack[top++] = (int32_t)i;
			}
		free(child);
	}
	while (ok && top > 0) {
		int32_t i = stack[--top];
		aff local;
		if (!node_local(g, (size_t)i, &local)) {
			ok = false;
			break;
		}
		g->world[i] = aff_mul(&g->world[i], &local); /* parent x local */
		g->order[g->norder++] = i;
		snprintf(where, sizeof where, "nodes[%d]", i);
		const cJSON *c = key(g->nodes.v[i], "children");
		if (c && !cj.is_array(c)) {
			ok = fail(g, where, "children: not an array; expected [...]");
			break;
		}
		/* children pushed in reverse (file order); each is seen here, so the
		 * stack never holds a node twice and never more than n */
		size_t nc = 0;
		for (const cJSON *e = c ? c->child : NULL; e; e = e->next)
			nc++;
		size_t base = top;
		if (nc > n - top) {
			ok = fail(g, where, "children: %zu children; expected each node once in the hierarchy", nc);
			break;
		}
		top += nc;
		size_t j = 0;
		for (const cJSON *e = c ? c->child : NULL; ok && e; e = e->next, j++) {
			double d = cj.is_number(e) ? e->valuedouble : -1;
			if (!(d >= 0 && d < (double)n && d == floor(d)))
				ok = fail(g, where, "children[%zu]: not an index into nodes; expected an integer from 0 to %zu", j,
				          n - 1);
			else if (g->seen[(size_t)d])
				ok = fail(g, where, "children[%zu]: node %.0f is already in the hierarchy; expected a tree (each "
				          "node once)", j, d);
			else {
				g->seen[(size_t)d] = 1;
				g->world[(size_t)d] = g->world[i];
				stack[base + nc - 1 - j] = (int32_t)d;
			}
		}
	}
	free(stack);
	return ok;
}

/* --- geometry --- */

static const int T_FLOAT[] = {5126, 0};
static const int T_UV[] = {5126, 5121, 5123, 0};
static const int T_INDEX[] = {5121, 5123, 5125, 0};

typedef struct prim {
	acc pos, nrm, uv, idx;
	bool has_n, has_uv, has_idx;
	int mode;
	long mat;
	size_t ntri;
} prim;

/* Primitive k of mesh m, its accessors checked; p->ntri 0 for points and
 * lines (skipped). */
static bool primitive(gl *g, size_t m, size_t k, const cJSON *pr, prim *p)
{
	char where[WHERE_MAX], use[WHERE2_MAX];
	snprintf(where, sizeof where, "meshes[%zu].primitives[%zu]", m, k);
	memset(p, 0, sizeof *p);
	double mode;
	if (!get_num(g, pr, "mode", where, 0, 6, 4, &mode))
		return false;
	p->mode = (int)mode;
	if (!get_index(g, pr, "material", where, g->materials.n, "materials", false, &p->mat))
		return false;
	if (p->mode < 4)
		return true;
	const cJSON *at = key(pr, "attributes");
	long ia;
	snprintf(use, sizeof use, "%s.attributes", where);
	if (!cj.is_object(at))
		return fail(g, use, "missing or not an object; expected {\"POSITION\": ...}");
	snprintf(use, sizeof use, "%s.attributes.POSITION", where);
	if (!get_index(g, at, "POSITION", use, g->accessors.n, "accessors", true, &ia) ||
	    !accessor(g, (size_t)ia, use, 3, T_FLOAT, &p->pos))
		return false;
	if (!get_index(g, at, "NORMAL", use, g->accessors.n, "accessors", false, &ia))
		return false;
	snprintf(use, sizeof use, "%s.attributes.NORMAL", where);
	if (ia >= 0 && !accessor(g, (size_t)ia, use, 3, T_FLOAT, &p->nrm))
		return false;
	p->has_n = ia >= 0 && p->nrm.count == p->pos.count;
	if (ia >= 0 && !p->has_n)
		return fail(g, use, "%zu normals for %zu positions; expected as many", p->nrm.count, p->pos.count);
	if (!get_index(g, at, "TEXCOORD_0", use, g->accessors.n, "accessors", false, &ia))
		return false;
	snprintf(use, sizeof use, "%s.attributes.TEXCOORD_0", where);
	if (ia >= 0 && !accessor(g, (size_t)ia, use, 2, T_UV, &p->uv))
		return false;
	p->has_uv = ia >= 0;
	if (ia >= 0 && p->uv.count != p->pos.count)
		return fail(g, use, "%zu texture coordinates for %zu positions; expected as many", p->uv.count, p->pos.count);
	snprintf(use, sizeof use, "%s.indices", where);
	if (!get_index(g, pr, "indices", where, g->accessors.n, "accessors", false, &ia))
		return false;
	if (ia >= 0 && !accessor(g, (size_t)ia, use, 1, T_INDEX, &p->idx))
		return false;
	p->has_idx = ia >= 0;
	size_t n = p->has_idx ? p->idx.count : p->pos.count;
	p->ntri = p->mode == 4 ? n / 3 : n >= 3 ? n - 2 : 0;
	return true;
}

/* Adds primitive p of mesh m as node `node` places it (world x). */
static bool add_primitive(gl *g, mesh_builder *b, const prim *p, size_t m, size_t k, const aff *x, bool any_uv,
                          uint16_t mat)
{
	char where[WHERE_MAX];
	if (b->nv + p->pos.count > (size_t)INT32_MAX)
		return fail(g, NULL, "more than %d vertices; expected fewer", INT32_MAX);
	int32_t base = (int32_t)b->nv;
	/* normals by the cofactor matrix: det x the inverse transpose */
	const double(*a)[4] = x->m;
	double cof[3][3];
	for (int r = 0; r < 3; r++)
		for (int c = 0; c < 3; c++)
			cof[r][c] = a[(r + 1) % 3][(c + 1) % 3] * a[(r + 2) % 3][(c + 2) % 3] -
			            a[(r + 1) % 3][(c + 2) % 3] * a[(r + 2) % 3][(c + 1) % 3];
	double det = aff_det(x);
	double sgn = det < 0 ? -1 : 1;
	for (size_t i = 0; i < p->pos.count; i++) {
		vec3 q = aff_point(x, acc_get(&p->pos, i, 0), acc_get(&p->pos, i, 1), acc_get(&p->pos, i, 2));
		float f[3] = {(float)q.x, (float)q.y, (float)q.z};
		for (int c = 0; c < 3; c++)
			if (!isfinite(f[c]) || fabsf(f[c]) > (float)MESH_COORD_MAX) {
				snprintf(where, sizeof where, "meshes[%zu].primitives[%zu].attributes.POSITION", m, k);
				return fail(g, where, "vertex %zu: coordinate %g is not a finite number of at most 1e15 once "
				            "placed; expected |value| <= 1e15", i, (double)f[c]);
			}
		if (!mb_vertex(b, f))
			goto full;
		if (p->has_n) {
			double nx = acc_get(&p->nrm, i, 0), ny = acc_get(&p->nrm, i, 1), nz = acc_get(&p->nrm, i, 2);
			float fn[3];
			for (int r = 0; r < 3; r++) {
				double v = sgn * (cof[r][0] * nx + cof[r][1] * ny + cof[r][2] * nz);
				fn[r] = isfinite(v) ? (float)v : 0.0f;
			}
			if (!mb_normal(b, fn))
				goto full;
		}
		if (any_uv) {
			float t[2] = {0, 0};
			if (p->has_uv) {
				t[0] = acc_get(&p->uv, i, 0);
				t[1] = 1.0f - acc_get(&p->uv, i, 1); /* glTF's v runs down the image */
				if (!isfinite(t[0]) || !isfinite(t[1]))
					t[0] = t[1] = 0;
			}
			if (!mb_uv(b, t))
				goto full;
		}
	}
	/* uv and normals are numbered as the positions: the builder's arrays
	 * grow together within a primitive, but earlier primitives may lack
	 * normals (then the mesh has none: mb_finish) */
	int32_t nbase = (int32_t)b->nvn - (p->has_n ? (int32_t)p->pos.count : 0);
	int32_t tbase = (int32_t)b->nvt - (any_uv ? (int32_t)p->pos.count : 0);
	b->cur_mat = mat;
	size_t n = p->has_idx ? p->idx.count : p->pos.count;
	for (size_t t = 0; t < p->ntri; t++) {
		size_t c[3];
		if (p->mode == 4) {
			c[0] = 3 * t, c[1] = 3 * t + 1, c[2] = 3 * t + 2;
		} else if (p->mode == 5) { /* strip: every other triangle turned */
			c[0] = t, c[1] = t + 1 + t % 2, c[2] = t + 2 - t % 2;
		} else { /* fan */
			c[0] = t + 1, c[1] = t + 2, c[2] = 0;
		}
		int32_t tri[3][3];
		for (int e = 0; e < 3; e++) {
			uint32_t v = p->has_idx ? acc_index(&p->idx, c[e]) : (uint32_t)c[e];
			if (v >= p->pos.count) {
				snprintf(where, sizeof where, "meshes[%zu].primitives[%zu].indices", m, k);
				return fail(g, where, "index %zu of %zu is %u; expected below %zu, the POSITION count", c[e], n, v,
				            p->pos.count);
			}
			int ee = det < 0 ? (3 - e) % 3 : e; /* a mirroring transform turns the winding */
			tri[ee][0] = base + (int32_t)v;
			tri[ee][1] = any_uv ? tbase + (int32_t)v : -1;
			tri[ee][2] = p->has_n ? nbase + (int32_t)v : -1;
		}
		if (!mb_triangle(b, tri))
			goto full;
	}
	return true;
full:
	return fail(g, NULL, "%s", mb_failure(b));
}

/* --- materials --- */

/* Where image im's bytes are (image_bytes): in a buffer view or a data URI
 * (data, len; own when they need freeing), or in a file beside the model
 * (file, owned; nothing read). */
typedef struct img_bytes {
	char where[WHERE_MAX];                /* "images[im]", for messages */
	char name[RT_ERROR_FILE_MAX + 64];    /* the decoder's: "MODEL: images[im].png" */
	const unsigned char *data;
	size_t len;
	unsigned char *own;
	char *file;
} img_bytes;

static bool image_bytes(gl *g, long im, img_bytes *ib)
{
	const cJSON *img = g->images.v[im], *uri = key(img, "uri"), *mime = key(img, "mimeType");
	memset(ib, 0, sizeof *ib);
	snprintf(ib->where, sizeof ib->where, "images[%ld]", im);
	const char *iw = ib->where;
	long bv;
	if (!get_index(g, img, "bufferView", iw, g->views.n, "bufferViews", false, &bv))
		return false;
	bool in_uri = bv < 0 && cj.is_string(uri) && strncmp(uri->valuestring, "data:", 5) == 0;
	const char *ext = "png";
	if ((cj.is_string(mime) && strcmp(mime->valuestring, "image/jpeg") == 0) ||
	    (in_uri && strncmp(uri->valuestring, "data:image/jpeg", 15) == 0))
		ext = "jpg";
	snprintf(ib->name, sizeof ib->name, "%s: images[%ld].%s", g->name, im, ext);
	if (bv >= 0) {
		size_t stride;
		return view(g, (size_t)bv, &ib->data, &ib->len, &stride);
	} else if (in_uri) {
		if (!(ib->own = data_uri(g, uri->valuestring, iw, &ib->len)))
			return false;
		ib->data = ib->own;
		return true;
	} else if (cj.is_string(uri)) {
		if (!uri_name_ok(g, uri->valuestring, iw))
			return false;
		ib->file = uri_file(g->dir ? g->dir : "", uri->valuestring);
		return ib->file ? true : fail(g, iw, "out of memory");
	}
	return fail(g, iw, "neither \"uri\" nor \"bufferView\"; expected one");
}

/* An alphaMode MASK material's coverage: the alpha channel of its base
 * colour texture (textureInfo ti; mesh_mat.alpha_map, NULL for an image
 * without one) and its sampler's wrap modes. Read from the model's own
 * bytes, or from the image file beside it (not from a buffer: dir NULL). */
static bool alpha_info(gl *g, const cJSON *ti, const char *where, mesh_mat *m)
{
	if (!ti)
		return true;
	long t, im, sm;
	if (!get_index(g, ti, "index", where, g->textures.n, "textures", true, &t))
		return false;
	char tw[WHERE_MAX];
	snprintf(tw, sizeof tw, "textures[%ld]", t);
	if (!get_index(g, g->textures.v[t], "source", tw, g->images.n, "images", false, &im) ||
	    !get_index(g, g->textures.v[t], "sampler", tw, g->samplers.n, "samplers", false, &sm))
		return false;
	if (sm >= 0) {
		static const char *const axis[2] = {"wrapS", "wrapT"};
		char sw[WHERE_MAX];
		snprintf(sw, sizeof sw, "samplers[%ld]", sm);
		for (int a = 0; a < 2; a++) {
			double v;
			if (!get_num(g, g->samplers.v[sm], axis[a], sw, 0, 1e9, 10497, &v))
				return false;
			if (v != 10497 && v != 33071 && v != 33648)
				return fail(g, sw, "%s: %g; expected 33071 (clamp), 33648 (mirrored repeat) or 10497 (repeat)",
				            axis[a], v);
			m->alpha_wrap[a] = v == 33071 ? MESH_WRAP_CLAMP : v == 33648 ? MESH_WRAP_MIRROR : MESH_WRAP_REPEAT;
		}
	}
	if (im < 0)
		return true;
	img_bytes ib;
	if (!image_bytes(g, im, &ib))
		return false;
	char *disk = NULL;
	if (ib.file) {
		if (!g->dir) { /* a buffer: no file is read */
			free(ib.file);
			return true;
		}
		disk = rt_file_read(ib.file, "image", &ib.len, g->err);
		snprintf(ib.name, sizeof ib.name, "%s", ib.file);
		free(ib.file);
		if (!disk)
			return fail_again(g, ib.where);
		ib.data = (const unsigned char *)disk;
	}
	int w = 0, h = 0;
	bool ok = image_decode_alpha(ib.name, ib.data, ib.len, &m->alpha_map, &w, &h, g->err);
	free(ib.own);
	free(disk);
	if (!ok && image_budget_refused(g->err)) /* the previewer's budget: no cut-outs */
		return true;
	m->alpha_w = w;
	m->alpha_h = h;
	return ok;
}

/* The texture a textureInfo names: a file beside the model (*file), or an
 * embedded image decoded once per image and colour space (*tex, held by
 * the builder). Neither when the texture has no image rtsh reads. */
static bool tex_info(gl *g, mesh_builder *b, texture **cache, const cJSON *ti, const char *where, bool srgb,
                     char **file, texture **tex)
{
	*file = NULL;
	*tex = NULL;
	if (!ti)
		return true;
	long t, im;
	if (!get_index(g, ti, "index", where, g->textures.n, "textures", true, &t))
		return false;
	char tw[WHERE_MAX];
	snprintf(tw, sizeof tw, "textures[%ld]", t);
	if (!get_index(g, g->textures.v[t], "source", tw, g->images.n, "images", false, &im))
		return false;
	if (im < 0)
		return true;
	texture **slot = &cache[2 * im + srgb];
	if (*slot) {
		*tex = *slot;
		return true;
	}
	img_bytes ib;
	if (!image_bytes(g, im, &ib))
		return false;
	if ((*file = ib.file))
		return true;
	int w = 0, h = 0;
	float *rgb = image_decode_rgb(ib.name, ib.data, ib.len, srgb, &w, &h, g->err);
	free(ib.own);
	if (!rgb)
		return image_budget_refused(g->err); /* the previewer's budget: untextured */
	texture *x = texture_make(rgb, w, h, ib.name, srgb, g->err);
	if (!x)
		return false;
	if (!mb_texture(b, x))
		return fail(g, ib.where, "out of memory");
	*slot = *tex = x;
	return true;
}

static bool material(gl *g, mesh_builder *b, texture **cache, size_t i, mesh_mat *m)
{
	char where[WHERE_MAX], w2[WHERE2_MAX];
	snprintf(where, sizeof where, "materials[%zu]", i);
	const cJSON *o = g->materials.v[i], *pbr = key(o, "pbrMetallicRoughness"), *ext = key(o, "extensions");
	static const double one4[4] = {1, 1, 1, 1}, zero3[3] = {0, 0, 0}, one3[3] = {1, 1, 1};
	double c[4], e[3], v;
	snprintf(w2, sizeof w2, "%s.pbrMetallicRoughness", where);
	if (!get_nums(g, pbr, "baseColorFactor", w2, 4, 0, 1, one4, c) || !get_nums(g, o, "emissiveFactor", where, 3, 0, 1, zero3, e))
		return false;
	for (int k = 0; k < 3; k++) {
		m->kd[k] = (float)c[k];
		m->ke[k] = (float)e[k];
	}
	m->alpha = (float)c[3];
	if (!get_float(g, pbr, "metallicFactor", w2, 0, 1, 1, &m->metallic) ||
	    !get_float(g, pbr, "roughnessFactor", w2, 0, 1, 1, &m->roughness))
		return false;
	const cJSON *am = key(o, "alphaMode");
	if (am) {
		const char *s = cj.is_string(am) ? am->valuestring : "";
		m->alpha_mode = strcmp(s, "MASK") == 0 ? MESH_ALPHA_MASK : strcmp(s, "BLEND") == 0 ? MESH_ALPHA_BLEND : 0;
		if (!m->alpha_mode && strcmp(s, "OPAQUE") != 0)
			return fail(g, where, "alphaMode: not \"OPAQUE\", \"MASK\" or \"BLEND\"; expected one of them");
	}
	if (!get_float(g, o, "alphaCutoff", where, 0, 1e300, 0.5, &m->alpha_cutoff))
		return false;
	const cJSON *nt = key(o, "normalTexture");
	snprintf(w2, sizeof w2, "%s.normalTexture", where);
	if (!get_float(g, nt, "scale", w2, -1e300, 1e300, 1, &m->normal_scale))
		return false;
	/* the extensions */
	const cJSON *x;
	m->ior = 1.5f;
	m->specular = 1;
	for (int k = 0; k < 3; k++)
		m->att_color[k] = m->specular_color[k] = 1;
	if ((x = key(ext, "KHR_materials_emissive_strength"))) {
		snprintf(w2, sizeof w2, "%s.extensions.KHR_materials_emissive_strength", where);
		if (!get_num(g, x, "emissiveStrength", w2, 0, 1e300, 1, &v))
			return false;
		for (int k = 0; k < 3; k++)
			m->ke[k] = (float)(m->ke[k] * v);
	}
	if ((x = key(ext, "KHR_materials_transmission"))) {
		snprintf(w2, sizeof w2, "%s.extensions.KHR_materials_transmission", where);
		if (!get_float(g, x, "transmissionFactor", w2, 0, 1, 0, &m->transmission))
			return false;
	}
	if ((x = key(ext, "KHR_materials_ior"))) {
		snprintf(w2, sizeof w2, "%s.extensions.KHR_materials_ior", where);
		if (!get_num(g, x, "ior", w2, 0, 1e300, 1.5, &v))
			return false;
		if (v != 0 && v < 1)
			return fail(g, w2, "ior %g; expected 0 or a number >= 1", v);
		m->ior = (float)v;
	}
	if ((x = key(ext, "KHR_materials_volume"))) {
		snprintf(w2, sizeof w2, "%s.extensions.KHR_materials_volume", where);
		double ac[3];
		if (!get_float(g, x, "thicknessFactor", w2, 0, 1e300, 0, &m->thickness) ||
		    !get_float(g, x, "attenuationDistance", w2, 0, 1e300, 0, &m->att_dist) ||
		    !get_nums(g, x, "attenuationColor", w2, 3, 0, 1, one3, ac))
			return false;
		for (int k = 0; k < 3; k++)
			m->att_color[k] = (float)ac[k];
	}
	if ((x = key(ext, "KHR_materials_clearcoat"))) {
		snprintf(w2, sizeof w2, "%s.extensions.KHR_materials_clearcoat", where);
		if (!get_float(g, x, "clearcoatFactor", w2, 0, 1, 0, &m->clearcoat) ||
		    !get_float(g, x, "clearcoatRoughnessFactor", w2, 0, 1, 0, &m->clearcoat_roughness))
			return false;
	}
	if ((x = key(ext, "KHR_materials_specular"))) {
		snprintf(w2, sizeof w2, "%s.extensions.KHR_materials_specular", where);
		double sc[3];
		if (!get_float(g, x, "specularFactor", w2, 0, 1, 1, &m->specular) ||
		    !get_nums(g, x, "specularColorFactor", w2, 3, 0, 1e300, one3, sc))
			return false;
		for (int k = 0; k < 3; k++)
			m->specular_color[k] = (float)sc[k];
	}
	/* textures */
	m->gltf = true;
	m->uvs[0] = m->uvs[1] = 1;
	const cJSON *bt = key(pbr, "baseColorTexture");
	snprintf(w2, sizeof w2, "%s.pbrMetallicRoughness.baseColorTexture", where);
	if (!tex_info(g, b, cache, bt, w2, true, &m->map_kd, &m->tex_kd))
		return false;
	const cJSON *tt = key(key(bt, "extensions"), "KHR_texture_transform");
	if (tt) {
		/* glTF: uv' = T(offset) R(rotation) S(scale) uv, v down, R's
		 * columns (cos r, sin r) and (-sin r, cos r) (the extension's GLSL):
		 *   u' = o_u + c s_u u - s s_v v,  v' = o_v + s s_u u + c s_v v;
		 * in rtsh's v (up: 1 - v on both sides)
		 *   u' = (o_u - s s_v) + c s_u u + s s_v v
		 *   v' = (1 - o_v - c s_v) - s s_u u + c s_v v */
		static const double o0[2] = {0, 0}, s0[2] = {1, 1};
		double off[2], sc[2], rot;
		snprintf(w2, sizeof w2, "%s.pbrMetallicRoughness.baseColorTexture.extensions.KHR_texture_transform", where);
		if (!get_nums(g, tt, "offset", w2, 2, -1e300, 1e300, o0, off) ||
		    !get_nums(g, tt, "scale", w2, 2, -1e300, 1e300, s0, sc) ||
		    !get_num(g, tt, "rotation", w2, -1e300, 1e300, 0, &rot))
			return false;
		double cr = cos(rot), sn = sin(rot);
		if (rot == 0) {
			cr = 1;
			sn = 0;
		}
		m->uvs[0] = (float)(cr * sc[0]);
		m->uvs[1] = (float)(cr * sc[1]);
		m->uvx[0] = (float)(sn * sc[1]);
		m->uvx[1] = (float)(-sn * sc[0]);
		m->uvo[0] = (float)(off[0] - sn * sc[1]);
		m->uvo[1] = (float)(1 - off[1] - cr * sc[1]);
	}
	snprintf(w2, sizeof w2, "%s.pbrMetallicRoughness.baseColorTexture", where);
	if (m->alpha_mode != MESH_ALPHA_OPAQUE && !alpha_info(g, bt, w2, m))
		return false;
	snprintf(w2, sizeof w2, "%s.pbrMetallicRoughness.metallicRoughnessTexture", where);
	if (!tex_info(g, b, cache, key(pbr, "metallicRoughnessTexture"), w2, false, &m->map_mr, &m->tex_mr))
		return false;
	snprintf(w2, sizeof w2, "%s.normalTexture", where);
	if (!tex_info(g, b, cache, nt, w2, false, &m->map_norm, &m->tex_norm))
		return false;
	snprintf(w2, sizeof w2, "%s.emissiveTexture", where);
	if (!tex_info(g, b, cache, key(o, "emissiveTexture"), w2, true, &m->map_emit, &m->tex_emit))
		return false;
	const cJSON *nm = key(o, "name");
	if (cj.is_string(nm) && !(m->name = strdup(nm->valuestring)))
		return fail(g, where, "out of memory");
	return true;
}

/* glTF's default material: white, metallic 1, roughness 1. */
static void material_default(mesh_mat *m)
{
	memset(m, 0, sizeof *m);
	m->kd[0] = m->kd[1] = m->kd[2] = 1;
	m->alpha = 1;
	m->metallic = m->roughness = 1;
	m->alpha_cutoff = 0.5f;
	m->normal_scale = 1;
	m->ior = 1.5f;
	m->specular = 1;
	for (int k = 0; k < 3; k++)
		m->att_color[k] = m->specular_color[k] = 1;
	m->gltf = true;
	m->uvs[0] = m->uvs[1] = 1;
	m->bump_scale = 1;
}

/* --- the mesh --- */

static mesh *build(gl *g)
{
	mesh_builder b = {.name = g->name};
	texture **cache = NULL;
	if (!walk(g))
		return NULL;
	/* first the primitives' accessors and the triangles the nodes place,
	 * checked against the memory limit before anything is built */
	double ntri = 0, nvert = 0;
	bool any_uv = false, need_default = false;
	char where[WHERE_MAX];
	if (g->only >= 0) {
		bool placed = false;
		for (size_t o = 0; o < g->norder; o++)
			placed |= g->order[o] == g->only;
		if (!placed)
			return fail(g, NULL, "node %ld: not a node the scene places; expected one of its %zu nodes", g->only,
			            g->nodes.n),
			       NULL;
	}
	for (size_t o = 0; o < g->norder; o++) {
		size_t i = (size_t)g->order[o];
		long mi;
		if (g->only >= 0 && (long)i != g->only)
			continue;
		snprintf(where, sizeof where, "nodes[%zu]", i);
		if (!get_index(g, g->nodes.v[i], "mesh", where, g->meshes.n, "meshes", false, &mi))
			return NULL;
		if (mi < 0)
			continue;
		const cJSON *prs = key(g->meshes.v[mi], "primitives");
		snprintf(where, sizeof where, "meshes[%ld]", mi);
		if (!cj.is_array(prs))
			return fail(g, where, "primitives: missing or not an array; expected [...]"), NULL;
		size_t k = 0;
		for (const cJSON *pr = prs->child; pr; pr = pr->next, k++) {
			prim p;
			if (!primitive(g, (size_t)mi, k, pr, &p))
				return NULL;
			ntri += (double)p.ntri;
			nvert += p.ntri ? (double)p.pos.count : 0;
			any_uv |= p.ntri && p.has_uv;
			need_default |= p.ntri && p.mat < 0;
		}
	}
	char what[300];
	snprintf(what, sizeof what, "the model %s (%.0f triangles)", g->name, ntri);
	if (!mem_check(ntri * MESH_PREPARE_BYTES + nvert * 64, what, g->err))
		return NULL;
	if (ntri == 0 && g->only >= 0)
		return fail(g, NULL, "node %ld: no triangles; expected a node with a mesh of triangles", g->only), NULL;
	if (ntri == 0)
		return fail(g, NULL, "no triangles in the scene; expected a node with a mesh of triangles"), NULL;
	/* the materials, and glTF's default after them when a primitive has none */
	size_t nm = g->materials.n + need_default;
	if (nm > 65535)
		return fail(g, "materials", "%zu materials; expected at most 65535", nm), NULL;
	if (nm) {
		b.mats = calloc(nm, sizeof *b.mats);
		cache = calloc(2 * (g->images.n ? g->images.n : 1), sizeof *cache);
		if (!b.mats || !cache) {
			free(cache);
			mb_free(&b);
			return fail(g, NULL, "out of memory"), NULL;
		}
		b.cmats = nm;
		for (size_t i = 0; i < g->materials.n; i++) {
			material_default(&b.mats[i]);
			b.nmats++;
			if (!material(g, &b, cache, i, &b.mats[i])) {
				free(cache);
				mb_free(&b);
				return NULL;
			}
		}
		if (need_default)
			material_default(&b.mats[b.nmats++]);
	}
	free(cache);
	for (size_t o = 0; o < g->norder; o++) {
		size_t i = (size_t)g->order[o];
		long mi;
		if (g->only >= 0 && (long)i != g->only)
			continue;
		get_index(g, g->nodes.v[i], "mesh", "", g->meshes.n, "meshes", false, &mi); /* checked above */
		if (mi < 0)
			continue;
		size_t k = 0;
		for (const cJSON *pr = key(g->meshes.v[mi], "primitives")->child; pr; pr = pr->next, k++) {
			prim p;
			if (!primitive(g, (size_t)mi, k, pr, &p)) {
				mb_free(&b);
				return NULL;
			}
			if (p.ntri == 0)
				continue;
			uint16_t mat = (uint16_t)(p.mat >= 0 ? (size_t)p.mat : g->materials.n);
			if (!add_primitive(g, &b, &p, (size_t)mi, k, &g->world[i], any_uv, mat)) {
				mb_free(&b);
				return NULL;
			}
		}
	}
	mesh *m = mb_finish(&b, g->err);
	for (uint32_t i = 0; m && i < m->nmats; i++)
		m->cuts |= m->mats[i].alpha_mode != MESH_ALPHA_OPAQUE;
	return m;
}

mesh *mesh_parse_gltf_node(const char *name, const char *dir, const char *buf, size_t len, long node, rt_error *err)
{
	gl g = {.name = name, .dir = dir, .err = err, .only = node < 0 ? -1 : node};
	mesh *m = NULL;
	if (gl_open(&g, buf, len))
		m = build(&g);
	gl_free(&g);
	return m;
}

mesh *mesh_parse_gltf(const char *name, const char *dir, const char *buf, size_t len, rt_error *err)
{
	return mesh_parse_gltf_node(name, dir, buf, len, -1, err);
}

mesh *mesh_read_gltf(const char *path, rt_error *err)
{
	return mesh_read_gltf_node(path, -1, err);
}

mesh *mesh_read_gltf_node(const char *path, long node, rt_error *err)
{
	size_t len;
	char *buf = rt_file_read(path, "model", &len, err);
	if (!buf)
		return NULL;
	char *dir = path_dir(path);
	mesh *m = NULL;
	if (!dir)
		rt_error_set(err, "%s: out of memory", path);
	else
		m = mesh_parse_gltf_node(path, dir, buf, len, node, err);
	free(dir);
	free(buf);
	return m;
}

/* --- cameras and lights --- */

/* Model files are mirrored in X on reading (mesh.c): so are these. */
static vec3 mirror(vec3 v)
{
	return v3(-v.x, v.y, v.z);
}

static bool info(gl *g, gltf_info *out)
{
	if (!walk(g))
		return false;
	char where[WHERE_MAX], w2[WHERE2_MAX];
	size_t nc = 0, nl = 0;
	for (size_t o = 0; o < g->norder; o++) {
		const cJSON *n = g->nodes.v[g->order[o]];
		nc += key(n, "camera") != NULL;
		nl += key(key(n, "extensions"), "KHR_lights_punctual") != NULL;
	}
	if ((nc && !(out->cams = calloc(nc, sizeof *out->cams))) || (nl && !(out->lights = calloc(nl, sizeof *out->lights))) ||
	    (g->norder && !(out->mesh_nodes = calloc(g->norder, sizeof *out->mesh_nodes))))
		return fail(g, NULL, "out of memory");
	for (size_t o = 0; o < g->norder; o++) {
		size_t i = (size_t)g->order[o];
		const cJSON *n = g->nodes.v[i];
		const aff *x = &g->world[i];
		snprintf(where, sizeof where, "nodes[%zu]", i);
		long ci, li, mi;
		if (!get_index(g, n, "camera", where, g->cameras.n, "cameras", false, &ci))
			return false;
		if (ci >= 0) {
			gltf_camera *c = &out->cams[out->ncams++];
			const cJSON *cam = g->cameras.v[ci], *ty = key(cam, "type");
			snprintf(w2, sizeof w2, "cameras[%ld]", ci);
			c->index = (int)ci;
			c->pos = mirror(aff_point(x, 0, 0, 0));
			c->fwd = mirror(aff_vector(x, 0, 0, -1));
			c->up = mirror(aff_vector(x, 0, 1, 0));
			if (!(v3_len(c->fwd) > 0) || !(v3_len(c->up) > 0) || !isfinite(v3_len(c->pos)))
				return fail(g, where, "a camera whose transform is singular; expected one that keeps directions");
			c->fwd = v3_norm(c->fwd);
			c->up = v3_norm(c->up);
			bool ortho = cj.is_string(ty) && strcmp(ty->valuestring, "orthographic") == 0;
			if (!ortho && !(cj.is_string(ty) && strcmp(ty->valuestring, "perspective") == 0))
				return fail(g, w2, "type: not \"perspective\" or \"orthographic\"; expected one of them");
			c->ortho = ortho;
			const cJSON *pp = key(cam, ortho ? "orthographic" : "perspective");
			snprintf(w2, sizeof w2, "cameras[%ld].%s", ci, ortho ? "orthographic" : "perspective");
			if (!cj.is_object(pp))
				return fail(g, w2, "missing; expected the camera's projection {...}");
			if (ortho) {
				if (!get_num(g, pp, "xmag", w2, -1e300, 1e300, 0, &c->xmag) ||
				    !get_num(g, pp, "ymag", w2, -1e300, 1e300, 0, &c->ymag))
					return false;
				c->xmag = fabs(c->xmag);
				c->ymag = fabs(c->ymag);
				if (!(c->ymag > 0))
					return fail(g, w2, "ymag: missing or 0; expected the half height of the view, > 0");
			} else {
				if (!get_num(g, pp, "yfov", w2, 1e-9, M_PI - 1e-9, -1, &c->yfov) ||
				    !get_num(g, pp, "aspectRatio", w2, 1e-6, 1e6, 0, &c->aspect))
					return false;
				if (c->yfov < 0)
					return fail(g, w2, "yfov: missing; expected the vertical field of view in radians, in (0, pi)");
			}
		}
		const cJSON *lp = key(key(n, "extensions"), "KHR_lights_punctual");
		snprintf(w2, sizeof w2, "%s.extensions.KHR_lights_punctual", where);
		if (lp && !get_index(g, lp, "light", w2, g->lights.n, "extensions.KHR_lights_punctual.lights", true, &li))
			return false;
		if (lp) {
			gltf_light *l = &out->lights[out->nlights++];
			const cJSON *lo = g->lights.v[li], *ty = key(lo, "type");
			snprintf(w2, sizeof w2, "extensions.KHR_lights_punctual.lights[%ld]", li);
			if (!cj.is_object(lo))
				return fail(g, w2, "not an object; expected {...}");
			const char *t = cj.is_string(ty) ? ty->valuestring : "";
			l->type = strcmp(t, "point") == 0 ? GLTF_POINT : strcmp(t, "spot") == 0 ? GLTF_SPOT
			          : strcmp(t, "directional") == 0 ? GLTF_DIRECTIONAL : -1;
			if (l->type < 0)
				return fail(g, w2, "type: not \"point\", \"spot\" or \"directional\"; expected one of them");
			static const double one3[3] = {1, 1, 1};
			if (!get_nums(g, lo, "color", w2, 3, 0, 1e300, one3, l->color) ||
			    !get_num(g, lo, "intensity", w2, 0, 1e300, 1, &l->intensity) ||
			    !get_num(g, lo, "range", w2, 0, 1e300, 0, &l->range))
				return false;
			l->pos = mirror(aff_point(x, 0, 0, 0));
			vec3 d = mirror(aff_vector(x, 0, 0, -1));
			if (!(v3_len(d) > 0) || !isfinite(v3_len(l->pos)))
				return fail(g, where, "a light whose transform is singular; expected one that keeps directions");
			l->dir = v3_norm(d);
			/* the range is in the node's units: scaled as the node is */
			l->range *= cbrt(fabs(aff_det(x)));
			if (l->type == GLTF_SPOT) {
				const cJSON *sp = key(lo, "spot");
				char w3[WHERE3_MAX];
				snprintf(w3, sizeof w3, "%s.spot", w2);
				if (!get_num(g, sp, "innerConeAngle", w3, 0, M_PI / 2, 0, &l->inner) ||
				    !get_num(g, sp, "outerConeAngle", w3, 0, M_PI / 2, M_PI / 4, &l->outer))
					return false;
				if (!(l->inner < l->outer))
					return fail(g, w3, "innerConeAngle %g, outerConeAngle %g; expected inner < outer", l->inner,
					            l->outer);
			}
		}
		/* emissive materials of the meshes placed */
		if (!get_index(g, n, "mesh", where, g->meshes.n, "meshes", false, &mi))
			return false;
		if (mi >= 0)
			out->mesh_nodes[out->nmesh_nodes++] = (long)i;
		const cJSON *prs = mi >= 0 ? key(g->meshes.v[mi], "primitives") : NULL;
		for (const cJSON *pr = cj.is_array(prs) ? prs->child : NULL; pr; pr = pr->next) {
			const cJSON *mat = key(pr, "material");
			if (!cj.is_number(mat) || !(mat->valuedouble >= 0 && mat->valuedouble < (double)g->materials.n))
				continue;
			const cJSON *ef = key(g->materials.v[(size_t)mat->valuedouble], "emissiveFactor");
			for (const cJSON *e = cj.is_array(ef) ? ef->child : NULL; e; e = e->next)
				out->emissive |= cj.is_number(e) && e->valuedouble > 0;
		}
	}
	return true;
}

void gltf_info_free(gltf_info *g)
{
	free(g->cams);
	free(g->lights);
	free(g->mesh_nodes);
	memset(g, 0, sizeof *g);
}

bool gltf_parse_info(const char *name, const char *buf, size_t len, gltf_info *out, rt_error *err)
{
	gl g = {.name = name, .err = err, .only = -1};
	memset(out, 0, sizeof *out);
	bool ok = gl_open(&g, buf, len) && info(&g, out);
	gl_free(&g);
	if (!ok)
		gltf_info_free(out);
	return ok;
}

bool gltf_read_info(const char *path, gltf_info *out, rt_error *err)
{
	size_t len;
	memset(out, 0, sizeof *out);
	char *buf = rt_file_read(path, "model", &len, err);
	if (!buf)
		return false;
	bool ok = gltf_parse_info(path, buf, len, out, err);
	free(buf);
	return ok;
}
