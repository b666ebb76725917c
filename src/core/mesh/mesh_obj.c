/* rtsh — Wavefront OBJ and MTL (mesh.h).
 *
 * What is read: v (x y z, a w or colour ignored), vt (u v), vn, f with any
 * number of corners (a fan of triangles) each v, v/vt, v//vn or v/vt/vn,
 * indices from 1 or negative (from the end, -1 the last), usemtl and
 * mtllib. Groups, objects, smoothing groups, lines and points are skipped.
 * MTL: newmtl, Kd, Ke, map_Kd, bump / map_Bump (with -bm scale), norm /
 * map_Kn; a missing MTL file leaves the default grey. The format is
 * described in the Wavefront "Advanced Visualizer" manual, appendix B1.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/mesh/mesh_io.h"
#include "rtsh/filesrc.h"
#include "rtsh/memory.h"
#include "rtsh/mesh.h"
#include "rtsh/srgb.h"

typedef struct cursor {
	const char *s, *end;
} cursor;

static bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

static void skip_blanks(cursor *c)
{
	while (c->s < c->end && is_blank(*c->s))
		c->s++;
}

/* The rest of the line with the blanks at both ends cut. */
static size_t rest_of_line(cursor *c, const char **start)
{
	skip_blanks(c);
	const char *e = c->end;
	while (e > c->s && is_blank(e[-1]))
		e--;
	*start = c->s;
	return (size_t)(e - c->s);
}

static bool keyword(cursor *c, const char *w)
{
	size_t n = strlen(w);
	if ((size_t)(c->end - c->s) < n || memcmp(c->s, w, n) != 0)
		return false;
	if (c->s + n < c->end && !is_blank(c->s[n]))
		return false;
	c->s += n;
	return true;
}


/* --- MTL --- */

static mesh_mat mat_default(void)
{
	return (mesh_mat){.kd = {0.64f, 0.64f, 0.64f}, .roughness = 1.0f, .bump_scale = 1.0f};
}

static double srgb_to_lin(double v)
{
	/* MTL colours are written as display values */
	return srgb_to_linear(v < 0 ? 0 : v > 1 ? 1 : v);
}

/* A map statement's file: the last word, after options such as -bm 0.5. */
static char *map_file(cursor *c, const char *dir, float *bm)
{
	skip_blanks(c);
	while (c->s < c->end && *c->s == '-') {
		const char *o = c->s;
		while (c->s < c->end && !is_blank(*c->s))
			c->s++;
		size_t on = (size_t)(c->s - o);
		int args = 1;
		if ((on == 2 && (o[1] == 's' || o[1] == 'o' || o[1] == 't')))
			args = 3;
		else if (on == 3 && memcmp(o, "-mm", 3) == 0)
			args = 2;
		for (int a = 0; a < args; a++) {
			skip_blanks(c);
			const char *v = c->s;
			double d;
			if (on == 3 && memcmp(o, "-bm", 3) == 0 && a == 0 && scan_double(&v, c->end, &d) && bm)
				*bm = (float)d;
			/* a numeric option's values, or one word (on/off, a channel) */
			while (c->s < c->end && !is_blank(*c->s))
				c->s++;
		}
		skip_blanks(c);
	}
	const char *f;
	size_t n = rest_of_line(c, &f);
	if (n == 0)
		return NULL;
	char *rel = mem_dupz(f, n);
	if (!rel)
		return NULL;
	for (char *q = rel; *q; q++)
		if (*q == '\\')
			*q = '/';
	char *p = path_join(dir, rel);
	free(rel);
	return p;
}

static bool read_mtl(mesh_builder *b, const char *path, const char *dir, const char *obj_name, int line)
{
	size_t len;
	rt_error ferr;
	rt_error_clear(&ferr);
	char *buf = rt_file_read(path, "material library", &len, &ferr);
	if (!buf) {
		/* A missing library leaves the defaults, and says so (once). */
		if (!b->warning) {
			char why[RT_ERROR_MSG_MAX + RT_ERROR_FILE_MAX + 32], msg[sizeof why + 256];
			rt_error_format(&ferr, why, sizeof why);
			snprintf(msg, sizeof msg, "%s:%d: mtllib: %s; the model's materials are the defaults", obj_name, line,
			         why);
			b->warning = strdup(msg);
		}
		return true;
	}
	mesh_mat *cur = NULL;
	bool ok = true;
	const char *s = buf, *end = buf + len;
	while (s < end && ok) {
		const char *nl = memchr(s, '\n', (size_t)(end - s));
		cursor c = {s, nl ? nl : end};
		s = nl ? nl + 1 : end;
		skip_blanks(&c);
		if (keyword(&c, "newmtl")) {
			const char *name;
			size_t n = rest_of_line(&c, &name);
			mesh_mat m = mat_default();
			m.name = mem_dupz(name, n);
			if (!m.name || b->nmats >= 65535 ||
			    !(b->nmats < b->cmats || (b->mats = realloc(b->mats, (b->cmats = 2 * b->cmats + 4) *
			                                                               sizeof *b->mats)))) {
				free(m.name);
				ok = false;
				break;
			}
			b->mats[b->nmats] = m;
			cur = &b->mats[b->nmats++];
		} else if (!cur) {
			continue;
		} else if (keyword(&c, "Kd") || keyword(&c, "Ke")) {
			bool kd = c.s[-1] == 'd';
			float *dst = kd ? cur->kd : cur->ke;
			double v[3];
			int k = 0;
			for (; k < 3; k++) {
				skip_blanks(&c);
				if (!scan_double(&c.s, c.end, &v[k]) || !isfinite(v[k]))
					break;
			}
			if (k == 1)
				v[1] = v[2] = v[0];
			if (k == 1 || k == 3)
				for (int i = 0; i < 3; i++)
					dst[i] = (float)(kd ? srgb_to_lin(v[i]) : fmax(0.0, v[i]));
		} else if (keyword(&c, "map_Kd")) {
			free(cur->map_kd);
			cur->map_kd = map_file(&c, dir, NULL);
		} else if (keyword(&c, "bump") || keyword(&c, "map_Bump") || keyword(&c, "map_bump")) {
			free(cur->map_bump);
			cur->map_bump = map_file(&c, dir, &cur->bump_scale);
		} else if (keyword(&c, "norm") || keyword(&c, "map_Kn")) {
			free(cur->map_norm);
			cur->map_norm = map_file(&c, dir, NULL);
		}
	}
	free(buf);
	return ok;
}

/* --- OBJ --- */

typedef struct obj_reader {
	mesh_builder b;
	const char *name, *dir;
	int line;
	rt_error *err;
	int32_t (*poly)[3];
	size_t cpoly;
} obj_reader;

static bool bad(obj_reader *r, const char *fmt, const char *what)
{
	char msg[RT_ERROR_MSG_MAX];
	snprintf(msg, sizeof msg, fmt, what);
	return rt_error_at(r->err, r->name, r->line, 0, "%s", msg);
}

static bool read_floats(obj_reader *r, cursor *c, int need, int max, double *v, const char *what)
{
	for (int k = 0; k < max; k++) {
		skip_blanks(c);
		const char *s0 = c->s;
		if (!scan_double(&c->s, c->end, &v[k])) {
			if (k >= need)
				return true;
			return bad(r, "%s: expected a number here", what);
		}
		if (!isfinite(v[k]) || fabs(v[k]) > MESH_COORD_MAX) {
			char tok[48];
			snprintf(tok, sizeof tok, "%.*s", (int)(c->s - s0 < 40 ? c->s - s0 : 40), s0);
			char msg[160];
			snprintf(msg, sizeof msg, "%s \"%s\" is not a finite number; expected |value| <= 1e15", what, tok);
			return rt_error_at(r->err, r->name, r->line, 0, "%s", msg);
		}
	}
	return true;
}

/* One index of a corner, resolved to 0-based: 1..n, or -1..-n from the end. */
static bool resolve(obj_reader *r, long i, size_t n, const char *what, int32_t *out)
{
	if (i == 0 || i > (long)n || i < -(long)n) {
		char msg[200];
		snprintf(msg, sizeof msg, "face %s index %ld is out of range; expected 1..%zu or -%zu..-1", what, i,
		         n, n);
		if (n == 0)
			snprintf(msg, sizeof msg, "face %s index %ld refers to no %s (none read yet)", what, i, what);
		return rt_error_at(r->err, r->name, r->line, 0, "%s", msg);
	}
	*out = (int32_t)(i > 0 ? i - 1 : (long)n + i);
	return true;
}

static bool read_face(obj_reader *r, cursor *c)
{
	size_t nc = 0;
	for (;;) {
		skip_blanks(c);
		if (c->s >= c->end || *c->s == '#')
			break;
		long idx[3] = {0, 0, 0};
		bool has[3] = {false, false, false};
		if (!scan_long(&c->s, c->end, &idx[0]))
			return bad(r, "%s: expected a vertex index (v, v/vt, v//vn or v/vt/vn)", "face");
		has[0] = true;
		for (int k = 1; k < 3 && c->s < c->end && *c->s == '/'; k++) {
			c->s++;
			if (c->s < c->end && *c->s != '/' && !is_blank(*c->s)) {
				if (!scan_long(&c->s, c->end, &idx[k]))
					return bad(r, "%s: expected a vertex index (v, v/vt, v//vn or v/vt/vn)", "face");
				has[k] = true;
			}
		}
		if (c->s < c->end && !is_blank(*c->s) && *c->s != '#')
			return bad(r, "%s: expected a vertex index (v, v/vt, v//vn or v/vt/vn)", "face");
		if (nc + 1 > r->cpoly) {
			size_t cap = r->cpoly ? 2 * r->cpoly : 16;
			void *p = realloc(r->poly, cap * sizeof *r->poly);
			if (!p)
				return bad(r, "%s: out of memory", "face");
			r->poly = p;
			r->cpoly = cap;
		}
		int32_t *q = r->poly[nc];
		q[1] = q[2] = -1;
		if (!resolve(r, idx[0], r->b.nv, "vertex", &q[0]) ||
		    (has[1] && !resolve(r, idx[1], r->b.nvt, "texture", &q[1])) ||
		    (has[2] && !resolve(r, idx[2], r->b.nvn, "normal", &q[2])))
			return false;
		nc++;
	}
	if (nc < 3)
		return bad(r, "%s: fewer than 3 corners; expected a polygon", "face");
	for (size_t k = 1; k + 1 < nc; k++) {
		int32_t t[3][3];
		memcpy(t[0], r->poly[0], sizeof t[0]);
		memcpy(t[1], r->poly[k], sizeof t[1]);
		memcpy(t[2], r->poly[k + 1], sizeof t[2]);
		if (!mb_triangle(&r->b, t))
			return bad(r, "%s", mb_failure(&r->b));
	}
	return true;
}

static bool use_material(obj_reader *r, const char *name, size_t n)
{
	for (size_t i = 0; i < r->b.nmats; i++)
		if (strlen(r->b.mats[i].name) == n && memcmp(r->b.mats[i].name, name, n) == 0) {
			r->b.cur_mat = (uint16_t)i;
			return true;
		}
	/* an unknown material: a default one of that name */
	if (r->b.nmats >= 65535)
		return bad(r, "%s: more than 65535 materials", "usemtl");
	mesh_mat m = mat_default();
	m.name = mem_dupz(name, n);
	mesh_mat *mats = realloc(r->b.mats, (r->b.nmats + 1) * sizeof *mats);
	if (!m.name || !mats) {
		free(m.name);
		if (mats)
			r->b.mats = mats;
		return bad(r, "%s: out of memory", "usemtl");
	}
	r->b.mats = mats;
	r->b.cmats = r->b.nmats + 1;
	r->b.mats[r->b.nmats] = m;
	r->b.cur_mat = (uint16_t)r->b.nmats++;
	return true;
}

mesh *mesh_parse_obj(const char *name, const char *dir, const char *buf, size_t len, rt_error *err)
{
	obj_reader r = {.name = name, .dir = dir, .err = err};
	r.b.name = name;
	const char *s = buf, *end = buf + len;
	bool ok = true;
	while (s < end && ok) {
		const char *nl = memchr(s, '\n', (size_t)(end - s));
		cursor c = {s, nl ? nl : end};
		s = nl ? nl + 1 : end;
		r.line++;
		skip_blanks(&c);
		if (c.s >= c.end)
			continue;
		double v[3];
		switch (*c.s) {
		case 'v':
			if (keyword(&c, "v")) {
				ok = read_floats(&r, &c, 3, 3, v, "vertex coordinate");
				float f[3] = {(float)v[0], (float)v[1], (float)v[2]};
				ok = ok && (mb_vertex(&r.b, f) || bad(&r, "%s", mb_failure(&r.b)));
			} else if (keyword(&c, "vt")) {
				v[1] = 0;
				ok = read_floats(&r, &c, 1, 2, v, "texture coordinate");
				float f[2] = {(float)v[0], (float)v[1]};
				ok = ok && (mb_uv(&r.b, f) || bad(&r, "%s", mb_failure(&r.b)));
			} else if (keyword(&c, "vn")) {
				ok = read_floats(&r, &c, 3, 3, v, "normal component");
				float f[3] = {(float)v[0], (float)v[1], (float)v[2]};
				ok = ok && (mb_normal(&r.b, f) || bad(&r, "%s", mb_failure(&r.b)));
			}
			break;
		case 'f':
			if (keyword(&c, "f"))
				ok = read_face(&r, &c);
			break;
		case 'u':
			if (keyword(&c, "usemtl")) {
				const char *n;
				size_t nn = rest_of_line(&c, &n);
				ok = use_material(&r, n, nn);
			}
			break;
		case 'm':
			if (keyword(&c, "mtllib")) {
				const char *n;
				size_t nn = rest_of_line(&c, &n);
				char *rel = mem_dupz(n, nn);
				char *path = rel ? path_join(dir, rel) : NULL;
				char *mdir = path ? path_dir(path) : NULL;
				ok = mdir && read_mtl(&r.b, path, mdir, r.name, r.line);
				if (!ok)
					bad(&r, "%s: out of memory", "mtllib");
				free(rel);
				free(path);
				free(mdir);
			}
			break;
		default:
			break;
		}
	}
	free(r.poly);
	if (!ok) {
		mb_free(&r.b);
		return NULL;
	}
	if (r.b.nc == 0) {
		mb_free(&r.b);
		rt_error_set(err, "%s: no faces (f lines) in the model; expected at least one triangle", name);
		return NULL;
	}
	return mb_finish(&r.b, err);
}

mesh *mesh_read_obj(const char *path, rt_error *err)
{
	size_t len;
	char *buf = rt_file_read(path, "model", &len, err);
	if (!buf)
		return NULL;
	char *dir = path_dir(path);
	mesh *m = dir ? mesh_parse_obj(path, dir, buf, len, err) : NULL;
	if (!dir)
		rt_error_set(err, "%s: out of memory", path);
	free(dir);
	free(buf);
	return m;
}
