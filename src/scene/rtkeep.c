/* rtsh — saving a scene the way the user wrote it (rtkeep.h).
 *
 * Three steps. The source is cut into lines and each line is read on its
 * own, which says what it holds: nothing (a comment or a blank line),
 * object k, light k, camera k, or a once-only element (A, sky, R or set
 * resolution, set samples/depth/mode) or an ignored repeat of one. Then the
 * objects, lights and cameras of the source are matched with the scene's by
 * a longest common subsequence of equal elements; between two matches, the
 * leftovers pair up in order as edits, and the rest are deletions or
 * insertions. Last, the lines are written back: copied, rewritten, dropped,
 * with insertions before the line of the element that follows them.
 */
#include "rtsh/rtkeep.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/abuf.h"
#include "rtsh/image.h"
#include "rtsh/memory.h"
#include "rtsh/rtfile.h"
#include "rtsh/settings.h"
#include "scene/rtfile_priv.h"

#define NONE SIZE_MAX

_Thread_local const char *rt_keep_source;
/* The largest middle part matched by dynamic programming (cells of 4 bytes);
 * beyond it a walk with a bounded look-ahead matches them (exact for edits
 * in place and for runs of up to LOOKAHEAD deletions or insertions). */
#define LCS_MAX_CELLS ((uint64_t)1 << 21)
/* How far the walk of long lists looks for an element that moved. */
#define LOOKAHEAD 64
/* Formatted lines are shorter than this. */
#define BODY_MAX 4096

/* --- cutting a line as the reader does --- */

typedef struct ltok {
	size_t at, len; /* in the line, blanks inside included */
	bool comma;
} ltok;

#define LTOK_MAX 16

typedef struct lline {
	ltok t[LTOK_MAX];
	size_t n;       /* tokens (may exceed LTOK_MAX; only the first are kept) */
	size_t np;      /* positional fields after the identifier */
	size_t lead;    /* bytes of blanks before the first token */
	size_t tail;    /* where the kept tail starts: blanks before a comment */
} lline;

static bool blank(char c)
{
	return c == ' ' || c == '\t';
}

static bool comment_at(const char *s, size_t i, size_t len)
{
	return s[i] == '#' || (s[i] == '/' && i + 1 < len && s[i + 1] == '/');
}

static void lex(const char *s, size_t len, lline *l)
{
	memset(l, 0, sizeof *l);
	l->tail = len;
	size_t i = 0, last_end = 0;
	while (i < len) {
		if (blank(s[i])) {
			i++;
			continue;
		}
		if (comment_at(s, i, len)) {
			l->tail = last_end;
			break;
		}
		ltok t = {.at = i};
		for (;;) {
			while (i < len && !blank(s[i]) && !comment_at(s, i, len)) {
				t.comma |= s[i] == ',';
				i++;
			}
			size_t j = i;
			while (j < len && blank(s[j]))
				j++;
			bool more = j < len && !comment_at(s, j, len);
			if (j > i && more && (s[i - 1] == ',' || s[j] == ',')) {
				i = j;
				continue;
			}
			break;
		}
		t.len = i - t.at;
		last_end = i;
		if (l->n == 0)
			l->lead = t.at;
		if (l->n < LTOK_MAX)
			l->t[l->n] = t;
		l->n++;
	}
	l->np = l->n ? l->n - 1 : 0;
	for (size_t k = 1; k < l->n && k < LTOK_MAX; k++)
		if (memchr(s + l->t[k].at, '=', l->t[k].len)) {
			l->np = k - 1;
			break;
		}
}

static bool tok_is(const char *s, const ltok *t, const char *word)
{
	return t->len == strlen(word) && memcmp(s + t->at, word, t->len) == 0;
}

/* True when an object line is in a short form: the extended form is the one
 * whose position, rotation, scaling and colour are all vectors (a short
 * form has a plain size among them, or only three fields, as a plane). */
static bool short_form(const char *s, const lline *l)
{
	(void)s;
	if (l->n < 5)
		return true;
	return !(l->np >= 4 && l->t[1].comma && l->t[2].comma && l->t[3].comma && l->t[4].comma);
}

/* --- what the source says --- */

typedef enum line_kind {
	LK_TEXT, LK_OBJ, LK_LIGHT, LK_CAM, LK_ONCE, LK_REPEAT,
} line_kind;

typedef enum once_kind {
	ONCE_AMB, ONCE_SKY, ONCE_RES, ONCE_SAMPLES, ONCE_DEPTH, ONCE_MODE, ONCE_CAM,
	ONCE_KEPT, /* ONCE_KEPT + i: the `set` line of scene_hints.kept[i] */
	ONCE_N = ONCE_KEPT + SCENE_KEPT_MAX,
} once_kind;

typedef struct src_line {
	size_t at, len, end; /* content s[at, at+len), then its line end up to end */
	line_kind kind;
	size_t idx;          /* element number, or the once_kind */
} src_line;

typedef struct base {
	src_line *lines;
	size_t nlines;
	scene *s;            /* the source's elements, in order */
	size_t *obj_line, *light_line, *cam_line;
	size_t once_line[ONCE_N]; /* first line of each, or NONE */
	bool sky_strength;   /* the sky line wrote its strength */
} base;

static bool push_line(base *b, size_t *cap, src_line l)
{
	if (b->nlines == *cap) {
		size_t n = *cap ? *cap * 2 : 256;
		src_line *p = realloc(b->lines, n * sizeof *p);
		if (!p)
			return false;
		b->lines = p;
		*cap = n;
	}
	b->lines[b->nlines++] = l;
	return true;
}

static bool push_index(size_t **arr, size_t n, size_t v)
{
	/* Grows at powers of two, like the scene's own arrays. */
	if ((n & (n - 1)) == 0) {
		size_t *p = realloc(*arr, (n ? n * 2 : 8) * sizeof *p);
		if (!p)
			return false;
		*arr = p;
	}
	(*arr)[n] = v;
	return true;
}

static void base_free(base *b)
{
	scene_free(b->s);
	mem_free_all(b->lines, b->obj_line, b->light_line, b->cam_line);
}

/* Reads the source line by line; false when a line does not parse (the
 * caller then writes from scratch). */
static bool base_read(base *b, const char *src, size_t len)
{
	memset(b, 0, sizeof *b);
	for (int k = 0; k < ONCE_N; k++)
		b->once_line[k] = NONE;
	b->s = scene_new();
	scene *t = scene_new();
	char *buf = NULL;
	size_t cap_lines = 0, cap_buf = 0;
	bool ok = b->s && t;
	scene_hints unset = t ? t->hints : (scene_hints){0};
	rt_error err;
	for (size_t i = 0; ok && i < len;) {
		size_t j = i;
		while (j < len && src[j] != '\n' && src[j] != '\r')
			j++;
		size_t end = j < len ? j + 1 : j;
		if (j + 1 < len && src[j] == '\r' && src[j + 1] == '\n')
			end = j + 2;
		src_line sl = {.at = i, .len = j - i, .end = end, .kind = LK_TEXT};
		lline l;
		lex(src + i, j - i, &l);
		if (l.n > 0) {
			if (sl.len + 1 > cap_buf) {
				cap_buf = sl.len + 1;
				char *nb = realloc(buf, cap_buf);
				if (!nb) {
					ok = false;
					break;
				}
				buf = nb;
			}
			memcpy(buf, src + i, sl.len);
			buf[sl.len] = '\0';
			t->nobjs = t->nlights = t->ncams = 0;
			t->cam = 0;
			t->has_ambient = t->has_sky = false;
			t->hints = unset;
			if (!rt_parse_line(t, buf, rt_keep_source ? rt_keep_source : "source", (int)b->nlines + 1, NULL,
			                   &err)) {
				ok = false;
				break;
			}
			bool is_c = tok_is(src + i, &l.t[0], "C");
			int once = -1;
			if (t->nobjs == 1) {
				sl.kind = LK_OBJ;
				sl.idx = b->s->nobjs;
				ok = push_index(&b->obj_line, b->s->nobjs, b->nlines) &&
				     scene_add_object(b->s, &t->objs[0], &err);
			} else if (t->nlights == 1) {
				sl.kind = LK_LIGHT;
				sl.idx = b->s->nlights;
				ok = push_index(&b->light_line, b->s->nlights, b->nlines) &&
				     scene_add_light(b->s, &t->lights[0], &err);
			} else if (t->ncams == 1 && !(is_c && b->once_line[ONCE_CAM] != NONE)) {
				sl.kind = LK_CAM;
				sl.idx = b->s->ncams;
				if (is_c)
					b->once_line[ONCE_CAM] = b->nlines;
				ok = push_index(&b->cam_line, b->s->ncams, b->nlines) &&
				     scene_add_camera(b->s, &t->cams[0], &err);
			} else if (t->ncams == 1) {
				once = ONCE_CAM;
			} else if (t->has_ambient) {
				once = ONCE_AMB;
			} else if (t->has_sky) {
				once = ONCE_SKY;
			} else if (t->hints.width > 0) {
				once = ONCE_RES;
			} else if (t->hints.samples > 0) {
				once = ONCE_SAMPLES;
			} else if (t->hints.depth >= 0) {
				once = ONCE_DEPTH;
			} else if (t->hints.mode >= 0) {
				once = ONCE_MODE;
			} else {
				for (int k = 0; k < SCENE_KEPT_MAX && once < 0; k++)
					if (t->hints.kept[k][0])
						once = ONCE_KEPT + k;
			}
			/* Else an object of size 0, which the reader leaves out: a
			 * line of text like a comment. */
			if (once >= 0 && b->once_line[once] != NONE) {
				sl.kind = LK_REPEAT;
				sl.idx = (size_t)once;
			} else if (once >= 0) {
				sl.kind = LK_ONCE;
				sl.idx = (size_t)once;
				b->once_line[once] = b->nlines;
				if (once == ONCE_AMB) {
					b->s->has_ambient = true;
					b->s->amb = t->amb;
				} else if (once == ONCE_SKY) {
					b->s->has_sky = true;
					b->s->sky = t->sky;
					b->sky_strength = l.np >= 3;
				} else if (once == ONCE_RES) {
					b->s->hints.width = t->hints.width;
					b->s->hints.height = t->hints.height;
				} else if (once == ONCE_SAMPLES) {
					b->s->hints.samples = t->hints.samples;
				} else if (once == ONCE_DEPTH) {
					b->s->hints.depth = t->hints.depth;
				} else if (once == ONCE_MODE) {
					b->s->hints.mode = t->hints.mode;
				} else if (once >= ONCE_KEPT) {
					memcpy(b->s->hints.kept[once - ONCE_KEPT], t->hints.kept[once - ONCE_KEPT],
					       sizeof t->hints.kept[0]);
				}
			}
		}
		if (ok)
			ok = push_line(b, &cap_lines, sl);
		i = end;
	}
	free(buf);
	scene_free(t);
	return ok;
}

/* --- matching elements --- */

typedef bool (*same_fn)(const void *a, const void *b);

static bool same_object(const void *a, const void *b)
{
	return object_equal(a, b);
}

static bool same_light(const void *a, const void *b)
{
	const light *x = a, *y = b;
	return v3_eq(x->pos, y->pos) && x->ratio == y->ratio && v3_eq(x->color, y->color);
}

static bool same_camera(const void *a, const void *b)
{
	const camera *x = a, *y = b;
	return v3_eq(x->pos, y->pos) && v3_eq(x->dir, y->dir) && x->fov == y->fov;
}

typedef struct match {
	size_t *o2s;    /* per source element: the scene's element it became, or NONE (deleted) */
	size_t *s2o;    /* per scene element: the source's, or NONE (new) */
	size_t *anchor; /* per new scene element: the source element it goes before, or NONE (the end) */
} match;

static void match_free(match *m)
{
	free(m->o2s);
	free(m->s2o);
	free(m->anchor);
}

/* Where the new elements go: before the next element that has a line. */
static bool anchor(match *m, size_t n)
{
	m->anchor = malloc((n ? n : 1) * sizeof(size_t));
	if (!m->anchor)
		return false;
	size_t next = NONE;
	for (size_t j = n; j-- > 0;) {
		if (m->s2o[j] != NONE)
			next = m->s2o[j];
		m->anchor[j] = next;
	}
	return true;
}

static bool align(const char *O, size_t n, const char *S, size_t m, size_t size, same_fn same, match *out)
{
	out->o2s = malloc((n ? n : 1) * sizeof(size_t));
	out->s2o = malloc((m ? m : 1) * sizeof(size_t));
	if (!out->o2s || !out->s2o)
		return false;
	for (size_t i = 0; i < n; i++)
		out->o2s[i] = NONE;
	for (size_t j = 0; j < m; j++)
		out->s2o[j] = NONE;
	size_t p = 0, q = 0;
	while (p < n && p < m && same(O + p * size, S + p * size)) {
		out->o2s[p] = p;
		out->s2o[p] = p;
		p++;
	}
	while (q < n - p && q < m - p && same(O + (n - 1 - q) * size, S + (m - 1 - q) * size)) {
		out->o2s[n - 1 - q] = m - 1 - q;
		out->s2o[m - 1 - q] = n - 1 - q;
		q++;
	}
	size_t a = n - p - q, b = m - p - q;
	if (a > 0 && b > 0 && (uint64_t)(a + 1) * (b + 1) <= LCS_MAX_CELLS) {
		/* L[i][j]: the longest common subsequence of O[p+i..] and S[p+j..]. */
		uint32_t *L = calloc((a + 1) * (b + 1), sizeof *L);
		if (!L)
			return false;
#define AT(i, j) L[(i) * (b + 1) + (j)]
		for (size_t i = a; i-- > 0;)
			for (size_t j = b; j-- > 0;) {
				if (same(O + (p + i) * size, S + (p + j) * size))
					AT(i, j) = AT(i + 1, j + 1) + 1;
				else
					AT(i, j) = AT(i + 1, j) > AT(i, j + 1) ? AT(i + 1, j) : AT(i, j + 1);
			}
		size_t i = 0, j = 0;
		while (i < a && j < b) {
			if (AT(i, j) == AT(i + 1, j + 1) + 1 && same(O + (p + i) * size, S + (p + j) * size)) {
				out->o2s[p + i] = p + j;
				out->s2o[p + j] = p + i;
				i++, j++;
			} else if (AT(i + 1, j) >= AT(i, j + 1)) {
				i++;
			} else {
				j++;
			}
		}
#undef AT
		free(L);
	} else if (a > 0 && b > 0) {
		/* Too long for the table: walk both lists, taking a run of
		 * deletions or insertions when the element looked for comes back
		 * within a few places, else an edit in place. */
		size_t i = p, j = p, iend = n - q, jend = m - q;
		while (i < iend && j < jend) {
			if (same(O + i * size, S + j * size)) {
				out->o2s[i] = j;
				out->s2o[j] = i;
				i++, j++;
				continue;
			}
			size_t d = 1;
			for (; d <= LOOKAHEAD; d++) {
				if (i + d < iend && same(O + (i + d) * size, S + j * size)) {
					i += d; /* O[i, i+d) deleted */
					break;
				}
				if (j + d < jend && same(O + i * size, S + (j + d) * size)) {
					j += d; /* S[j, j+d) new */
					break;
				}
			}
			if (d > LOOKAHEAD) {
				out->o2s[i] = j; /* edited in place */
				out->s2o[j] = i;
				i++, j++;
			}
		}
	}
	/* Between two matches, the leftovers pair up in order: edits. */
	size_t i = 0, j = 0;
	while (i < n) {
		size_t i1 = i;
		while (i1 < n && out->o2s[i1] == NONE)
			i1++;
		size_t j1 = i1 < n ? out->o2s[i1] : m;
		for (; i < i1 && j < j1; i++, j++) {
			out->o2s[i] = j;
			out->s2o[j] = i;
		}
		i = i1 + 1;
		j = j1 + 1;
	}
	return true;
}

/* --- formatting --- */

/* The tokens of an rt_format_light line: "L X,Y,Z RATIO R,G,B". */
static void light_tokens(const light *l, char *buf, size_t size, char **tok, int ntok)
{
	rt_format_light(l, buf, size);
	char *p = buf;
	for (int k = 0; k < ntok; k++) {
		tok[k] = p;
		p = strchr(p, ' ');
		if (!p)
			break;
		*p++ = '\0';
	}
}

/* Numbers and vectors as the writer spells them (fewest digits that read
 * back exactly, in the "C" locale), borrowed from the light formatter. */
static void put_vec(abuf *o, vec3 v)
{
	char buf[256], *tok[4] = {0};
	light l = {.pos = v};
	light_tokens(&l, buf, sizeof buf, tok, 4);
	abuf_str(o, tok[1] ? tok[1] : "0,0,0");
}

static void put_num(abuf *o, double v)
{
	char buf[256], *tok[4] = {0};
	light l = {.ratio = v};
	light_tokens(&l, buf, sizeof buf, tok, 4);
	abuf_str(o, tok[2] ? tok[2] : "0");
}

static void put_int(abuf *o, long v)
{
	char t[32];
	snprintf(t, sizeof t, "%ld", v);
	abuf_str(o, t);
}

/* An object in the extended form, whatever the short form could say. */
static void put_extended(abuf *o, const object *ob)
{
	char f[BODY_MAX];
	rt_format_object_extended(ob, f, sizeof f);
	abuf_str(o, f);
}

static void put_object(abuf *o, const object *ob, bool want_short)
{
	char f[BODY_MAX];
	rt_format_object(ob, f, sizeof f);
	lline l;
	lex(f, strlen(f), &l);
	if (want_short || !short_form(f, &l))
		abuf_str(o, f);
	else
		put_extended(o, ob);
}

/* id: the identifier to keep ("L" or "l", "C" or "c"). */
static void put_light(abuf *o, const light *li, const char *id)
{
	char f[BODY_MAX];
	rt_format_light(li, f, sizeof f);
	abuf_str(o, id);
	abuf_str(o, f + 1);
}

static void put_camera(abuf *o, const camera *c, const char *id)
{
	char f[BODY_MAX];
	rt_format_camera(c, f, sizeof f);
	abuf_str(o, id);
	abuf_str(o, f + 1);
}

static const char *mode_name(int m)
{
	return m == 1 ? "path" : "whitted";
}

/* The body of a once-only element's line; `as_r`: resolution as `R W H`. */
static void put_once(abuf *o, const scene *s, once_kind k, bool as_r, bool strength)
{
	const scene_hints *h = &s->hints;
	switch (k) {
	case ONCE_AMB:
		abuf_str(o, "A ");
		put_num(o, s->amb.ratio);
		abuf_str(o, " ");
		put_vec(o, s->amb.color);
		break;
	case ONCE_SKY:
		abuf_str(o, "sky ");
		put_vec(o, s->sky.zenith);
		abuf_str(o, " ");
		put_vec(o, s->sky.horizon);
		if (strength || s->sky.strength != 1) {
			abuf_str(o, " ");
			put_num(o, s->sky.strength);
		}
		break;
	case ONCE_RES:
		abuf_str(o, as_r ? "R " : "set resolution ");
		put_int(o, h->width);
		abuf_str(o, as_r ? " " : "x");
		put_int(o, h->height);
		break;
	case ONCE_SAMPLES:
		abuf_str(o, "set samples ");
		put_int(o, h->samples);
		break;
	case ONCE_DEPTH:
		abuf_str(o, "set depth ");
		put_int(o, h->depth);
		break;
	case ONCE_MODE:
		abuf_str(o, "set mode ");
		abuf_str(o, mode_name(h->mode));
		break;
	default:
		if (k >= ONCE_KEPT && (size_t)(k - ONCE_KEPT) < settings_count) {
			abuf_str(o, "set ");
			abuf_str(o, settings_table[k - ONCE_KEPT].name);
			abuf_str(o, " ");
			abuf_str(o, h->kept[k - ONCE_KEPT]);
		}
		break;
	}
}

/* Whether the scene has the once-only element, and whether it is what the
 * source said. */
static bool once_present(const scene *s, once_kind k)
{
	switch (k) {
	case ONCE_AMB:
		return s->has_ambient;
	case ONCE_SKY:
		return s->has_sky;
	case ONCE_RES:
		return s->hints.width > 0 && s->hints.height > 0;
	case ONCE_SAMPLES:
		return s->hints.samples > 0;
	case ONCE_DEPTH:
		return s->hints.depth >= 0;
	case ONCE_MODE:
		return s->hints.mode >= 0;
	default:
		return k >= ONCE_KEPT ? s->hints.kept[k - ONCE_KEPT][0] != '\0' : true;
	}
}

static bool once_same(const scene *a, const scene *b, once_kind k)
{
	if (once_present(a, k) != once_present(b, k))
		return false;
	if (!once_present(a, k))
		return true;
	switch (k) {
	case ONCE_AMB:
		return a->amb.ratio == b->amb.ratio && v3_eq(a->amb.color, b->amb.color);
	case ONCE_SKY:
		return v3_eq(a->sky.zenith, b->sky.zenith) && v3_eq(a->sky.horizon, b->sky.horizon) &&
		       a->sky.strength == b->sky.strength;
	case ONCE_RES:
		return a->hints.width == b->hints.width && a->hints.height == b->hints.height;
	case ONCE_SAMPLES:
		return a->hints.samples == b->hints.samples;
	case ONCE_DEPTH:
		return a->hints.depth == b->hints.depth;
	case ONCE_MODE:
		return a->hints.mode == b->hints.mode;
	default:
		return k >= ONCE_KEPT ? strcmp(a->hints.kept[k - ONCE_KEPT], b->hints.kept[k - ONCE_KEPT]) == 0 : true;
	}
}

/* --- writing --- */

typedef struct writer {
	abuf o;
	const char *src;
	const char *nl;     /* the line end for new lines */
	const scene *s;
	const base *b;
	match objs, lights, cams;
	bool c_line;        /* the output has a C line */
	size_t ncams;       /* the scene's cameras matched (0: the default camera only) */
	size_t ins_obj, ins_light, ins_cam; /* the next new element to place */
} writer;

/* Starts a new line: the previous one needs its end (a source whose last
 * line had none). */
static void new_line(writer *w)
{
	if (w->o.len > 0 && w->o.b[w->o.len - 1] != '\n' && w->o.b[w->o.len - 1] != '\r')
		abuf_str(&w->o, w->nl);
}

static void end_new_line(writer *w)
{
	abuf_str(&w->o, w->nl);
}

/* Writes the new elements of a list that go before source element `before`
 * (NONE: all that are left); *next walks the scene's elements in order. */
static void place_new(writer *w, const match *m, size_t n, size_t *next, size_t before, int what)
{
	for (; *next < n; (*next)++) {
		size_t j = *next;
		if (m->s2o[j] != NONE) {
			if (before != NONE && m->s2o[j] >= before)
				return; /* its line is still to come */
			continue;
		}
		if (before != NONE && (m->anchor[j] == NONE || m->anchor[j] > before))
			return;
		new_line(w);
		if (what == 0) {
			put_object(&w->o, &w->s->objs[j], true);
		} else if (what == 1) {
			put_light(&w->o, &w->s->lights[j], "L");
		} else {
			put_camera(&w->o, &w->s->cams[j], w->c_line ? "c" : "C");
			w->c_line = true;
		}
		end_new_line(w);
	}
}

/* The line with its element's new body, keeping indentation and comment. */
static void rewrite(writer *w, const src_line *sl, const lline *l, const abuf *body)
{
	const char *s = w->src + sl->at;
	abuf_add(&w->o, s, l->lead);
	abuf_add(&w->o, body->b, body->len);
	if (l->tail < sl->len)
		abuf_add(&w->o, s + l->tail, sl->len - l->tail);
	abuf_add(&w->o, s + sl->len, sl->end - sl->at - sl->len);
}

/* --- file names in a file written elsewhere --- */

/* True when a and b name the same file (the same spelling, or the same
 * real path). */
static bool same_file(const char *a, const char *b)
{
	if (a == b || (a && b && strcmp(a, b) == 0))
		return true;
	if (!a || !b)
		return false;
	char ra[4096], rb[4096];
	return realpath(a, ra) && realpath(b, rb) && strcmp(ra, rb) == 0;
}

/* Makes t's file names ref's where they name the same files (the model,
 * the RT_KEY_FILE keys), so that object_equal compares the files, not how
 * they are spelt. */
static void files_agree(object *t, const object *ref)
{
	if (t->file != ref->file && same_file(t->file, ref->file))
		t->file = ref->file;
	for (size_t i = 0; i < rt_nkeys; i++) {
		if (rt_keys[i].type != RT_KEY_FILE || (rt_keys[i].offset & RT_KEY_PBR))
			continue;
		const char **a = (const char **)(void *)((char *)t + rt_keys[i].offset);
		const char *b = *(const char *const *)(const void *)((const char *)ref + rt_keys[i].offset);
		if (*a != b && same_file(*a, b))
			*a = b;
	}
}

/* The name a line is read with in the folder written to. */
static void dest_name(char *name, size_t size)
{
	snprintf(name, size, "%s%ssaved.rt", rt_write_dir ? rt_write_dir : "",
	         rt_write_dir && rt_write_dir[0] ? "/" : "");
}

/* True when the source line sl, read from the folder written to, gives
 * the object want (or, sky, the scene's sky with its file). */
static bool line_reads_as(const writer *w, const src_line *sl, const object *want, bool is_sky)
{
	char name[4200];
	dest_name(name, sizeof name);
	char *line = malloc(sl->len + 1);
	scene *t = scene_new();
	bool same = false;
	rt_error err;
	if (line && t) {
		memcpy(line, w->src + sl->at, sl->len);
		line[sl->len] = '\0';
		if (rt_parse_line(t, line, name, 1, NULL, &err)) {
			if (is_sky) {
				same = t->has_sky && same_file(t->sky.file, w->s->sky.file);
			} else if (t->nobjs == 1) {
				object o = t->objs[0];
				files_agree(&o, want);
				same = object_equal(&o, want);
			}
		}
	}
	free(line);
	scene_free(t);
	return same;
}

/* An unchanged element's line in a file written to another folder: its
 * file names (a model's, key=FILE, the sky's) are rewritten where they
 * would no longer name the same file from there, and nothing else; false
 * when the line has more tokens than the lexer keeps (then the caller
 * writes the element afresh). */
static bool retarget_files(writer *w, const src_line *sl, const object *o, const char *sky_file)
{
	const char *text = w->src + sl->at;
	lline l;
	lex(text, sl->len, &l);
	if (l.n > LTOK_MAX)
		return false;
	abuf body = {0};
	size_t pos = l.lead;
	for (size_t k = 0; k < l.n; k++) {
		const ltok *t = &l.t[k];
		abuf_add(&body, text + pos, t->at - pos);
		pos = t->at + t->len;
		char name[4200];
		const char *eq = k > 0 ? memchr(text + t->at, '=', t->len) : NULL;
		if (k == 1 && sky_file) {
			rt_write_file_name(sky_file, name, sizeof name);
			abuf_str(&body, name);
			continue;
		}
		if (k == 1 && o && (obj_kind_flags(o->kind) & KIND_MODEL) && o->file && !eq) {
			rt_write_file_name(o->file, name, sizeof name);
			abuf_str(&body, name);
			continue;
		}
		if (eq && o) {
			size_t klen = (size_t)(eq - (text + t->at));
			const rt_key *key = NULL;
			for (size_t i = 0; i < rt_nkeys && !key; i++)
				if (rt_keys[i].type == RT_KEY_FILE && !(rt_keys[i].offset & RT_KEY_PBR) &&
				    strlen(rt_keys[i].name) == klen && memcmp(rt_keys[i].name, text + t->at, klen) == 0)
					key = &rt_keys[i];
			const char *f = key ? *(const char *const *)(const void *)((const char *)o + key->offset) : NULL;
			if (f) {
				rt_write_file_name(f, name, sizeof name);
				abuf_add(&body, text + t->at, klen + 1);
				abuf_str(&body, name);
				continue;
			}
		}
		abuf_add(&body, text + t->at, t->len);
	}
	if (body.failed) {
		free(body.b);
		return false;
	}
	rewrite(w, sl, &l, &body);
	free(body.b);
	return true;
}

static void copy_line(writer *w, const src_line *sl)
{
	abuf_add(&w->o, w->src + sl->at, sl->end - sl->at);
}

static void write_line(writer *w, const src_line *sl)
{
	const base *b = w->b;
	const scene *s = w->s;
	const char *text = w->src + sl->at;
	lline l;
	abuf body = {0};
	char id[4] = "";
	switch (sl->kind) {
	case LK_TEXT:
		copy_line(w, sl);
		return;
	case LK_OBJ: {
		place_new(w, &w->objs, s->nobjs, &w->ins_obj, sl->idx, 0);
		size_t j = w->objs.o2s[sl->idx];
		if (j == NONE)
			return;
		if (object_equal(&b->s->objs[sl->idx], &s->objs[j])) {
			/* Written to another folder, its file names may need to
			 * change; nothing else does. */
			bool files = s->objs[j].file || s->objs[j].mat.texture || s->objs[j].mat.normalmap ||
			             s->objs[j].mat.bump;
			if (!files || line_reads_as(w, sl, &s->objs[j], false) || !retarget_files(w, sl, &s->objs[j], NULL))
				copy_line(w, sl);
			return;
		}
		lex(text, sl->len, &l);
		put_object(&body, &s->objs[j], short_form(text, &l));
		break;
	}
	case LK_LIGHT: {
		place_new(w, &w->lights, s->nlights, &w->ins_light, sl->idx, 1);
		size_t j = w->lights.o2s[sl->idx];
		if (j == NONE)
			return;
		if (same_light(&b->s->lights[sl->idx], &s->lights[j])) {
			copy_line(w, sl);
			return;
		}
		lex(text, sl->len, &l);
		id[0] = text[l.lead];
		put_light(&body, &s->lights[j], id);
		break;
	}
	case LK_CAM: {
		place_new(w, &w->cams, w->ncams, &w->ins_cam, sl->idx, 2);
		size_t j = w->cams.o2s[sl->idx];
		if (j == NONE)
			return;
		if (same_camera(&b->s->cams[sl->idx], &s->cams[j])) {
			copy_line(w, sl);
			return;
		}
		lex(text, sl->len, &l);
		id[0] = text[l.lead];
		put_camera(&body, &s->cams[j], id);
		break;
	}
	case LK_ONCE:
		if (!once_present(s, (once_kind)sl->idx))
			return;
		if (once_same(b->s, s, (once_kind)sl->idx)) {
			if (sl->idx != ONCE_SKY || !s->sky.file || line_reads_as(w, sl, NULL, true) ||
			    !retarget_files(w, sl, NULL, s->sky.file))
				copy_line(w, sl);
			return;
		}
		lex(text, sl->len, &l);
		put_once(&body, s, (once_kind)sl->idx, tok_is(text, &l.t[0], "R"), w->b->sky_strength);
		break;
	case LK_REPEAT: {
		/* An ignored repeat stays only while it still repeats the first. */
		bool keep;
		if (sl->idx == ONCE_CAM) {
			size_t first = b->once_line[ONCE_CAM];
			size_t i = b->lines[first].idx, j = w->cams.o2s[i];
			keep = j != NONE && same_camera(&b->s->cams[i], &s->cams[j]);
		} else {
			keep = once_same(b->s, s, (once_kind)sl->idx);
		}
		if (keep)
			copy_line(w, sl);
		return;
	}
	}
	if (body.failed)
		w->o.failed = true;
	else
		rewrite(w, sl, &l, &body);
	free(body.b);
}

/* The keeping writer's text, or NULL (out of memory, or a source that does
 * not read line by line). */
static char *keep_text(const scene *s, const char *src, size_t len, size_t *out_len)
{
	base b;
	if (!base_read(&b, src, len)) {
		base_free(&b);
		return NULL;
	}
	writer w = {.src = src, .s = s, .b = &b, .nl = "\n"};
	for (size_t i = 0; i < b.nlines; i++)
		if (b.lines[i].end > b.lines[i].at + b.lines[i].len) {
			const char *e = src + b.lines[i].at + b.lines[i].len;
			w.nl = e[0] == '\r' && b.lines[i].end - (b.lines[i].at + b.lines[i].len) == 2 ? "\r\n"
			       : e[0] == '\r'                                                         ? "\r"
			                                                                                : "\n";
			break;
		}
	/* Without a camera line the source's camera is the default one: the
	 * scene's cameras are all new unless it is still just that one. */
	camera def = scene_camera(b.s);
	bool default_only = b.s->ncams == 0 && s->ncams == 1 && same_camera(&s->cams[0], &def);
	size_t ncams = default_only ? 0 : s->ncams;
	w.ncams = ncams;
	bool ok = align((const char *)b.s->objs, b.s->nobjs, (const char *)s->objs, s->nobjs, sizeof(object),
	                same_object, &w.objs) &&
	          align((const char *)b.s->lights, b.s->nlights, (const char *)s->lights, s->nlights,
	                sizeof(light), same_light, &w.lights) &&
	          align((const char *)b.s->cams, b.s->ncams, (const char *)s->cams, ncams, sizeof(camera),
	                same_camera, &w.cams) &&
	          anchor(&w.objs, s->nobjs) && anchor(&w.lights, s->nlights) && anchor(&w.cams, ncams);
	/* A C line that survives. */
	for (size_t i = 0; ok && i < b.nlines; i++) {
		const src_line *sl = &b.lines[i];
		if (sl->kind == LK_CAM && w.cams.o2s[sl->idx] != NONE && b.once_line[ONCE_CAM] == i)
			w.c_line = true;
	}
	for (size_t i = 0; ok && i < b.nlines; i++)
		write_line(&w, &b.lines[i]);
	if (ok) {
		/* What is left goes at the end: settings (R, samples, depth, mode,
		 * then the other kept ones in the table's order), A, sky, then the
		 * lists. */
		static const once_kind order[] = {ONCE_RES, ONCE_SAMPLES, ONCE_DEPTH, ONCE_MODE, ONCE_AMB, ONCE_SKY};
		size_t norder = sizeof order / sizeof order[0];
		for (size_t k = 0; k < norder + SCENE_KEPT_MAX; k++) {
			once_kind ok_ = k < 4 ? order[k] : k < 4 + SCENE_KEPT_MAX ? (once_kind)(ONCE_KEPT + (k - 4))
			                                                        : order[k - SCENE_KEPT_MAX];
			if (b.once_line[ok_] != NONE || !once_present(s, ok_))
				continue;
			new_line(&w);
			put_once(&w.o, s, ok_, true, false);
			end_new_line(&w);
		}
		place_new(&w, &w.cams, ncams, &w.ins_cam, NONE, 2);
		place_new(&w, &w.lights, s->nlights, &w.ins_light, NONE, 1);
		place_new(&w, &w.objs, s->nobjs, &w.ins_obj, NONE, 0);
	}
	match_free(&w.objs);
	match_free(&w.lights);
	match_free(&w.cams);
	base_free(&b);
	if (!ok || w.o.failed) {
		free(w.o.b);
		return NULL;
	}
	if (!w.o.b) { /* an empty result */
		w.o.b = malloc(1);
		if (!w.o.b)
			return NULL;
		w.o.b[0] = '\0';
	}
	*out_len = w.o.len;
	return w.o.b;
}

/* True when text loads to exactly s (the active camera aside: a file's is
 * always its first). */
static bool loads_to(const char *text, size_t len, const scene *s)
{
	rt_error err;
	/* model and texture names resolve against the folder written to */
	char name[4200];
	snprintf(name, sizeof name, "%s%ssaved.rt", rt_write_dir ? rt_write_dir : "",
	         rt_write_dir && rt_write_dir[0] ? "/" : "");
	scene *t = rt_load_string(text, len, name, NULL, &err);
	if (!t)
		return false;
	/* the same files, however the names are spelt from there */
	for (size_t i = 0; i < t->nobjs && t->nobjs == s->nobjs; i++)
		files_agree(&t->objs[i], &s->objs[i]);
	if (t->has_sky && s->has_sky && t->sky.file != s->sky.file && same_file(t->sky.file, s->sky.file))
		t->sky.file = s->sky.file;
	scene c = *s;
	c.cam = 0;
	bool same = scene_equal(t, &c);
	scene_free(t);
	return same;
}

char *rt_keep_text(const scene *s, const char *src, size_t len, size_t *out_len)
{
	if (!src)
		return NULL;
	size_t n = 0;
	char *text = keep_text(s, src, len, &n);
	if (text && !loads_to(text, n, s)) {
		free(text);
		return NULL;
	}
	if (text)
		*out_len = n;
	return text;
}

bool rt_write_keeping(const scene *s, const char *src, size_t len, FILE *f, rt_error *err)
{
	size_t n = 0;
	char *text = rt_keep_text(s, src, len, &n);
	if (!text)
		return rt_write(s, f, err);
	bool ok = fwrite(text, 1, n, f) == n && fflush(f) == 0 && !ferror(f);
	free(text);
	return ok ? true : rt_error_set(err, "cannot write the scene");
}

typedef struct keep_ctx {
	const scene *s;
	const char *src;
	size_t len;
} keep_ctx;

static bool keep_writer(FILE *f, void *ctx, rt_error *err)
{
	const keep_ctx *c = ctx;
	return rt_write_keeping(c->s, c->src, c->len, f, err);
}

bool rt_save_keeping(const scene *s, const char *src, size_t len, const char *path, rt_error *err)
{
	keep_ctx c = {s, src, len};
	/* file names are written (and checked) relative to the new file's folder */
	return rt_save_in_folder(path, false, keep_writer, &c, err);
}
