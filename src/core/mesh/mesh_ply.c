/* rtsh — the PLY polygon file format (mesh.h), after Greg Turk's
 * description ("The PLY polygon file format", 1994).
 *
 * ASCII and binary (little and big endian). From `vertex`: x y z, nx ny nz,
 * and u v (or s t, texture_u texture_v); from `face`: vertex_indices (or
 * vertex_index), polygons cut into fans; from `tristrips`: vertex_indices
 * as strips, -1 starting a new strip, every other triangle turned so that
 * all keep the strip's winding. Other elements and properties are skipped.
 * Errors give the line (ASCII) or the byte offset (binary).
 */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/mesh/mesh_io.h"
#include "rtsh/filesrc.h"
#include "rtsh/mesh.h"

enum { T_NONE, T_I8, T_U8, T_I16, T_U16, T_I32, T_U32, T_F32, T_F64 };
static const int type_size[] = {0, 1, 1, 2, 2, 4, 4, 4, 8};

static int type_of(const char *s, size_t n)
{
	static const struct {
		const char *name;
		int t;
	} names[] = {{"char", T_I8},    {"int8", T_I8},     {"uchar", T_U8},    {"uint8", T_U8},
	             {"short", T_I16},  {"int16", T_I16},   {"ushort", T_U16},  {"uint16", T_U16},
	             {"int", T_I32},    {"int32", T_I32},   {"uint", T_U32},    {"uint32", T_U32},
	             {"float", T_F32},  {"float32", T_F32}, {"double", T_F64},  {"float64", T_F64}};
	for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
		if (strlen(names[i].name) == n && memcmp(names[i].name, s, n) == 0)
			return names[i].t;
	return T_NONE;
}

#define MAX_PROPS 64
#define MAX_ELEMS 16

/* what a property means to us */
enum { P_SKIP, P_X, P_Y, P_Z, P_NX, P_NY, P_NZ, P_U, P_V, P_INDICES };

typedef struct prop {
	int type, count_type; /* count_type != T_NONE: a list */
	int role;
} prop;

typedef struct elem {
	char name[32];
	size_t count;
	prop props[MAX_PROPS];
	int nprops;
} elem;

typedef struct ply_reader {
	const char *name;
	const unsigned char *s, *end, *start;
	int format; /* 0 ascii, 1 little, 2 big */
	int line;
	rt_error *err;
	mesh_builder b;
	int32_t *list;
	size_t clist;
} ply_reader;

static bool fail(ply_reader *r, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

static bool fail(ply_reader *r, const char *fmt, ...)
{
	char msg[RT_ERROR_MSG_MAX];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(msg, sizeof msg, fmt, ap);
	va_end(ap);
	if (r->format == 0)
		return rt_error_at(r->err, r->name, r->line, 0, "%s", msg);
	return rt_error_set(r->err, "%s: byte %zu: %s", r->name, (size_t)(r->s - r->start), msg);
}

/* --- values --- */

static bool ascii_value(ply_reader *r, double *v)
{
	r->s = skip_space(r->s, r->end, false, &r->line);
	const char *p = (const char *)r->s;
	if (!scan_double(&p, (const char *)r->end, v))
		return false;
	r->s = (const unsigned char *)p;
	return true;
}

static bool value(ply_reader *r, int type, double *v, const char *what, size_t index)
{
	if (r->format == 0) {
		if (ascii_value(r, v))
			return true;
		if (r->s >= r->end)
			return fail(r, "the file ends inside %s %zu; expected more values", what, index);
		return fail(r, "%s %zu: expected a number", what, index);
	}
	int n = type_size[type];
	if ((size_t)(r->end - r->s) < (size_t)n)
		return fail(r, "the file ends inside %s %zu (truncated?); expected %d more bytes", what, index, n);
	unsigned char b[8];
	if (r->format == 1)
		memcpy(b, r->s, (size_t)n);
	else
		for (int i = 0; i < n; i++)
			b[i] = r->s[n - 1 - i];
	r->s += n;
	switch (type) {
	case T_I8: *v = (int8_t)b[0]; break;
	case T_U8: *v = b[0]; break;
	case T_I16: { int16_t x; memcpy(&x, b, 2); *v = x; break; }
	case T_U16: { uint16_t x; memcpy(&x, b, 2); *v = x; break; }
	case T_I32: { int32_t x; memcpy(&x, b, 4); *v = x; break; }
	case T_U32: { uint32_t x; memcpy(&x, b, 4); *v = x; break; }
	case T_F32: { float x; memcpy(&x, b, 4); *v = x; break; }
	default: { double x; memcpy(&x, b, 8); *v = x; break; }
	}
	return true;
}

/* --- header --- */

static bool header_line(const unsigned char **s, const unsigned char *end, const char **ls, size_t *ln)
{
	if (*s >= end)
		return false;
	const unsigned char *nl = memchr(*s, '\n', (size_t)(end - *s));
	const unsigned char *e = nl ? nl : end;
	*ls = (const char *)*s;
	*ln = (size_t)(e - *s);
	while (*ln && ((*ls)[*ln - 1] == '\r' || (*ls)[*ln - 1] == ' '))
		(*ln)--;
	*s = nl ? nl + 1 : end;
	return true;
}

/* The n-th blank-separated word of a line (0-based). */
static bool word(const char *s, size_t len, int n, const char **w, size_t *wn)
{
	size_t i = 0;
	for (int k = 0;; k++) {
		while (i < len && (s[i] == ' ' || s[i] == '\t'))
			i++;
		if (i >= len)
			return false;
		size_t st = i;
		while (i < len && s[i] != ' ' && s[i] != '\t')
			i++;
		if (k == n) {
			*w = s + st;
			*wn = i - st;
			return true;
		}
	}
}

static bool is_word(const char *w, size_t n, const char *lit)
{
	return strlen(lit) == n && memcmp(w, lit, n) == 0;
}

static int role_of(const char *ename, const char *w, size_t n)
{
	if (strcmp(ename, "vertex") == 0) {
		static const struct {
			const char *name;
			int role;
		} r[] = {{"x", P_X},  {"y", P_Y},  {"z", P_Z},          {"nx", P_NX},         {"ny", P_NY},
		         {"nz", P_NZ}, {"u", P_U},  {"v", P_V},          {"s", P_U},           {"t", P_V},
		         {"texture_u", P_U}, {"texture_v", P_V}, {"texture_s", P_U}, {"texture_t", P_V}};
		for (size_t i = 0; i < sizeof r / sizeof r[0]; i++)
			if (is_word(w, n, r[i].name))
				return r[i].role;
	}
	if ((strcmp(ename, "face") == 0 || strcmp(ename, "tristrips") == 0) &&
	    (is_word(w, n, "vertex_indices") || is_word(w, n, "vertex_index")))
		return P_INDICES;
	return P_SKIP;
}

/* --- the body --- */

static bool add_poly(ply_reader *r, const int32_t *idx, size_t n, bool strip, size_t elem_i)
{
	const char *what = strip ? "strip" : "face";
	for (size_t k = 0; k < n; k++)
		if (idx[k] != -1 || !strip) {
			if (idx[k] < 0 || (size_t)idx[k] >= r->b.nv)
				return fail(r, "%s %zu: vertex index %d is out of range; expected 0..%zu", what, elem_i,
				            idx[k], r->b.nv ? r->b.nv - 1 : 0);
		}
	if (!strip) {
		for (size_t k = 1; k + 1 < n; k++) {
			int32_t t[3][3] = {{idx[0], -1, -1}, {idx[k], -1, -1}, {idx[k + 1], -1, -1}};
			if (!mb_triangle(&r->b, t))
				return fail(r, "%s", mb_failure(&r->b));
		}
		return true;
	}
	size_t run = 0; /* vertices in the current strip */
	for (size_t k = 0; k < n; k++) {
		if (idx[k] == -1) {
			run = 0;
			continue;
		}
		run++;
		if (run < 3)
			continue;
		int32_t a = idx[k - 2], b = idx[k - 1], c = idx[k];
		if (a == b || b == c || a == c)
			continue; /* a strip's joining degenerate */
		/* even triangles of a strip keep its winding, odd ones are turned */
		bool odd = ((run - 3) & 1) != 0;
		int32_t t[3][3] = {{a, -1, -1}, {odd ? c : b, -1, -1}, {odd ? b : c, -1, -1}};
		if (!mb_triangle(&r->b, t))
			return fail(r, "%s", mb_failure(&r->b));
	}
	return true;
}

static bool read_elem(ply_reader *r, const elem *e)
{
	bool vert = strcmp(e->name, "vertex") == 0;
	bool strip = strcmp(e->name, "tristrips") == 0;
	bool face = strcmp(e->name, "face") == 0;
	bool has_n = false, has_uv = false;
	for (int p = 0; p < e->nprops; p++) {
		has_n |= e->props[p].role == P_NX;
		has_uv |= e->props[p].role == P_U;
	}
	for (size_t i = 0; i < e->count; i++) {
		double pos[3] = {0, 0, 0}, nrm[3] = {0, 0, 0}, uv[2] = {0, 0};
		for (int p = 0; p < e->nprops; p++) {
			const prop *pr = &e->props[p];
			double v;
			if (pr->count_type != T_NONE) {
				if (!value(r, pr->count_type, &v, e->name, i))
					return false;
				if (!(v >= 0) || v > 1e9 || v != floor(v))
					return fail(r, "%s %zu: list length %.15g; expected a whole number in 0..1000000000",
					            e->name, i, v);
				size_t n = (size_t)v;
				size_t min = r->format == 0 ? 2 : (size_t)type_size[pr->type];
				if (n > (size_t)(r->end - r->s) / min + 1)
					return fail(r, "%s %zu: a list of %zu values is longer than the rest of the file "
					               "(truncated?)", e->name, i, n);
				if (n > r->clist) {
					int32_t *l = realloc(r->list, n * sizeof *l);
					if (!l)
						return fail(r, "out of memory");
					r->list = l;
					r->clist = n;
				}
				for (size_t k = 0; k < n; k++) {
					if (!value(r, pr->type, &v, e->name, i))
						return false;
					if (pr->role == P_INDICES) {
						if (!(v >= -1 && v < 2147483647.0) || v != floor(v))
							return fail(r, "%s %zu: vertex index %.15g; expected a whole number from 0",
							            e->name, i, v);
						r->list[k] = (int32_t)v;
					}
				}
				if (pr->role == P_INDICES && (face || strip)) {
					if (face && n < 3)
						return fail(r, "face %zu has %zu corners; expected at least 3", i, n);
					if (!add_poly(r, r->list, n, strip, i))
						return false;
				}
				continue;
			}
			if (!value(r, pr->type, &v, e->name, i))
				return false;
			switch (pr->role) {
			case P_X: case P_Y: case P_Z: pos[pr->role - P_X] = v; break;
			case P_NX: case P_NY: case P_NZ: nrm[pr->role - P_NX] = v; break;
			case P_U: case P_V: uv[pr->role - P_U] = v; break;
			default: break;
			}
		}
		if (vert) {
			for (int k = 0; k < 3; k++)
				if (!isfinite(pos[k]) || fabs(pos[k]) > MESH_COORD_MAX)
					return fail(r, "vertex %zu: coordinate %g is not a finite number; expected "
					               "|value| <= 1e15", i, pos[k]);
			float fp[3] = {(float)pos[0], (float)pos[1], (float)pos[2]};
			float fn[3] = {(float)nrm[0], (float)nrm[1], (float)nrm[2]};
			float ft[2] = {(float)uv[0], (float)uv[1]};
			if (!mb_vertex(&r->b, fp) || (has_n && !mb_normal(&r->b, fn)) || (has_uv && !mb_uv(&r->b, ft)))
				return fail(r, "%s", mb_failure(&r->b));
		}
	}
	return true;
}

mesh *mesh_parse_ply(const char *name, const char *buf, size_t len, rt_error *err)
{
	ply_reader r = {.name = name, .err = err};
	r.b.name = name;
	r.start = r.s = (const unsigned char *)buf;
	r.end = r.s + len;
	const char *ls;
	size_t ln;
	elem elems[MAX_ELEMS];
	int nelems = 0;
	bool got_format = false, ended = false;
	r.line = 0;
	while (header_line(&r.s, r.end, &ls, &ln)) {
		r.line++;
		const char *w;
		size_t wn;
		if (r.line == 1) {
			if (!is_word(ls, ln, "ply")) {
				rt_error_at(err, name, 1, 0, "not a PLY file; expected the line \"ply\" first");
				goto fail;
			}
			continue;
		}
		if (!word(ls, ln, 0, &w, &wn) || is_word(w, wn, "comment") || is_word(w, wn, "obj_info"))
			continue;
		if (is_word(w, wn, "end_header")) {
			ended = true;
			break;
		}
		if (is_word(w, wn, "format")) {
			const char *f;
			size_t fn;
			if (word(ls, ln, 1, &f, &fn) && is_word(f, fn, "ascii"))
				r.format = 0;
			else if (word(ls, ln, 1, &f, &fn) && is_word(f, fn, "binary_little_endian"))
				r.format = 1;
			else if (word(ls, ln, 1, &f, &fn) && is_word(f, fn, "binary_big_endian"))
				r.format = 2;
			else {
				rt_error_at(err, name, r.line, 0, "unknown PLY format; expected ascii, "
				            "binary_little_endian or binary_big_endian");
				goto fail;
			}
			got_format = true;
		} else if (is_word(w, wn, "element")) {
			const char *en, *ec;
			size_t enn, ecn;
			if (nelems >= MAX_ELEMS) {
				rt_error_at(err, name, r.line, 0, "more than %d elements; expected fewer", MAX_ELEMS);
				goto fail;
			}
			if (!word(ls, ln, 1, &en, &enn) || !word(ls, ln, 2, &ec, &ecn)) {
				rt_error_at(err, name, r.line, 0, "expected \"element NAME COUNT\"");
				goto fail;
			}
			elem *e = &elems[nelems++];
			memset(e, 0, sizeof *e);
			snprintf(e->name, sizeof e->name, "%.*s", (int)(enn < 31 ? enn : 31), en);
			long cnt;
			const char *cp = ec;
			if (!scan_long(&cp, ec + ecn, &cnt) || cp != ec + ecn || cnt < 0) {
				rt_error_at(err, name, r.line, 0, "element count \"%.*s\"; expected a whole number >= 0",
				            (int)(ecn < 40 ? ecn : 40), ec);
				goto fail;
			}
			e->count = (size_t)cnt;
		} else if (is_word(w, wn, "property")) {
			if (nelems == 0) {
				rt_error_at(err, name, r.line, 0, "a property before any element");
				goto fail;
			}
			elem *e = &elems[nelems - 1];
			if (e->nprops >= MAX_PROPS) {
				rt_error_at(err, name, r.line, 0, "more than %d properties in one element", MAX_PROPS);
				goto fail;
			}
			prop *p = &e->props[e->nprops];
			const char *t1, *t2, *t3, *pn;
			size_t n1, n2, n3, pnn;
			bool ok = word(ls, ln, 1, &t1, &n1);
			if (ok && is_word(t1, n1, "list")) {
				ok = word(ls, ln, 2, &t2, &n2) && word(ls, ln, 3, &t3, &n3) && word(ls, ln, 4, &pn, &pnn);
				p->count_type = ok ? type_of(t2, n2) : T_NONE;
				p->type = ok ? type_of(t3, n3) : T_NONE;
				ok = ok && p->count_type != T_NONE && p->type != T_NONE && p->count_type < T_F32;
			} else {
				ok = ok && word(ls, ln, 2, &pn, &pnn);
				p->count_type = T_NONE;
				p->type = ok ? type_of(t1, n1) : T_NONE;
				ok = ok && p->type != T_NONE;
			}
			if (!ok) {
				rt_error_at(err, name, r.line, 0, "bad property; expected \"property TYPE NAME\" or "
				            "\"property list COUNT_TYPE TYPE NAME\" with char..double types");
				goto fail;
			}
			p->role = role_of(e->name, pn, pnn);
			if (p->role == P_INDICES && p->count_type == T_NONE)
				p->role = P_SKIP;
			e->nprops++;
		} else {
			rt_error_at(err, name, r.line, 0, "unknown header line \"%.*s\"; expected format, element, "
			            "property, comment or end_header", (int)(wn < 40 ? wn : 40), w);
			goto fail;
		}
	}
	if (!ended || !got_format) {
		rt_error_at(err, name, r.line, 0, "the header has no %s; expected a PLY header",
		            got_format ? "end_header" : "format line");
		goto fail;
	}
	r.line++;
	for (int i = 0; i < nelems; i++) {
		const elem *e = &elems[i];
		if (strcmp(e->name, "vertex") == 0 && e->count > 0) {
			int xyz = 0;
			for (int p = 0; p < e->nprops; p++)
				xyz += e->props[p].role >= P_X && e->props[p].role <= P_Z;
			if (xyz != 3) {
				rt_error_set(err, "%s: the vertex element has %d of the properties x, y, z; expected all three",
				             name, xyz);
				goto fail;
			}
		}
		if (e->nprops == 0)
			continue; /* records of nothing: nothing to read */
		/* counts larger than the file: refuse before allocating anything */
		size_t min = 0;
		for (int p = 0; p < e->nprops; p++)
			min += r.format == 0 ? 2 : (size_t)type_size[e->props[p].count_type != T_NONE ? e->props[p].count_type
			                                                                     : e->props[p].type];
		if (min && e->count > (size_t)(r.end - r.s) / min) {
			fail(&r, "element %s claims %zu records but the file has room for at most %zu (truncated?)",
			     e->name, e->count, (size_t)(r.end - r.s) / min);
			goto fail;
		}
		if (!read_elem(&r, e))
			goto fail;
	}
	free(r.list);
	if (r.b.nc == 0) {
		mb_free(&r.b);
		rt_error_set(err, "%s: no faces or strips in the model; expected at least one triangle", name);
		return NULL;
	}
	return mb_finish(&r.b, err);
fail:
	free(r.list);
	mb_free(&r.b);
	return NULL;
}

mesh *mesh_read_ply(const char *path, rt_error *err)
{
	size_t len;
	char *buf = rt_file_read(path, "model", &len, err);
	if (!buf)
		return NULL;
	mesh *m = mesh_parse_ply(path, buf, len, err);
	free(buf);
	return m;
}
