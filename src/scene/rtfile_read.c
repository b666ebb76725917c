/* rtsh — the .rt reader: one lexer and one parser for every dialect.
 *
 * The file is read into memory whole and cut into lines (LF, CRLF or CR).
 * Each line is cut into tokens that remember their column; blanks next to
 * a comma are dropped so that "1, 2, 3" is one vector field. Each element
 * has an entry in `elements` (identifier, name, usage, parser); the parsers
 * check every field against its range and report the first problem as
 * "FILE:LINE:COL: <element> <field> "<token>" <problem>; expected <what>".
 * The grammar, the ranges and the dialects are documented in rtsh(5).
 */
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "base/nearest.h"
#include "rtsh/filesrc.h"
#include "rtsh/mesh.h"
#include "rtsh/num.h"
#include "rtsh/render.h"
#include "rtsh/texture.h"
#include "rtsh/rtfile.h"
#include "rtsh/settings.h"
#include "rtsh/shape.h"
#include "scene/rtfile_priv.h"

/* Files larger than this are refused rather than read. */
#define RT_FILE_MAX ((size_t)1 << 30)
/* --strict: a direction is unit length when |length - 1| <= this. */
#define STRICT_UNIT_TOL 1e-2
void rt_numloc_enter(rt_numloc *l)
{
	l->c = newlocale(LC_NUMERIC_MASK, "C", (locale_t)0);
	l->old = l->c ? uselocale(l->c) : (locale_t)0;
}

void rt_numloc_leave(rt_numloc *l)
{
	if (l->c) {
		uselocale(l->old);
		freelocale(l->c);
	}
}

/* --- the parser state --- */

typedef struct tok {
	const char *s; /* NUL-terminated, blanks beside commas removed */
	size_t len;
	int col;       /* 1-based byte column of the first character */
	int endcol;    /* the column just after the token */
	bool quoted;   /* written in double quotes */
} tok;

typedef struct parser {
	scene *s;
	const char *name; /* the file name in messages */
	bool strict;
	bool single;      /* rt_parse_line: once-only elements replace */
	const rt_warnings *warn;
	const atomic_bool *cancel; /* rt_load_opts.cancel */
	rt_error *err;
	int line;
	/* The line of the first A, C, L, R (or set resolution), sky and set
	 * samples/depth/mode seen, and of each other kept setting's `set` line
	 * (by its row of settings_table); 0 = none yet. */
	int line_a, line_c, line_l, line_r, line_sky, line_set[3], line_kept[SCENE_KEPT_MAX];
	size_t cam_c;     /* index of the C camera */
	size_t nelems;    /* elements read */
	tok *toks;
	size_t ntoks, cap_toks;
	size_t np;        /* positional fields after the identifier */
	int endcol;       /* the column after the line's last token */
	char *text;
	size_t cap_text;
	char quote[96];   /* a token shortened for a message */
	char usage[256], usage42[128]; /* an object element's usage lines */
	const shape_form *usage_form;  /* whose they are (NULL: none yet): a file of
	                                * a million spheres writes them once */
	char *dir;        /* the .rt file's folder ("" = the current one) */
} parser;

typedef struct elem_def elem_def;
struct elem_def {
	const char *id;
	const char *name;   /* in messages */
	int kind;           /* obj_kind, or -1 for the other elements */
	bool strict;        /* allowed by --strict */
	bool (*parse)(parser *p, const elem_def *e);
	const char *usage;  /* every accepted form */
	const char *usage42; /* the 42 subject's form, or NULL */
	const shape_form *form; /* objects: the form of the kind it reads */
};

static bool fail(parser *p, int col, const char *fmt, ...) __attribute__((format(printf, 3, 4)));

static bool fail(parser *p, int col, const char *fmt, ...)
{
	char msg[RT_ERROR_MSG_MAX];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(msg, sizeof msg, fmt, ap);
	va_end(ap);
	return rt_error_at(p->err, p->name, p->line, col, "%s", msg);
}

/* The token for a message: at most 40 bytes, cut on a character boundary. */
static const char *quoted(parser *p, const tok *t)
{
	size_t n = t->len;
	if (n <= 40) {
		snprintf(p->quote, sizeof p->quote, "%s", t->s);
		return p->quote;
	}
	n = 37;
	while (n > 0 && ((unsigned char)t->s[n] & 0xC0) == 0x80)
		n--;
	snprintf(p->quote, sizeof p->quote, "%.*s...", (int)n, t->s);
	return p->quote;
}

static bool fail_tok(parser *p, const tok *t, const char *elem, const char *field, const char *what,
                     const char *expect)
{
	return fail(p, t->col, "%s %s \"%s\" %s; expected %s", elem, field, quoted(p, t), what, expect);
}

/* --- lexing --- */

static bool is_blank(char c) { return c == ' ' || c == '\t'; }

/* The bytes lex_line looks at: control characters (all but the tab, and
 * DEL), and those that may end a token's run of plain bytes (blanks, the
 * comments' '#' and '/', the quote). */
enum { LEX_CONTROL = 1, LEX_STOP = 2 };
static const unsigned char lex_class[256] = {
	[0] = LEX_CONTROL, [1] = LEX_CONTROL, [2] = LEX_CONTROL, [3] = LEX_CONTROL, [4] = LEX_CONTROL,
	[5] = LEX_CONTROL, [6] = LEX_CONTROL, [7] = LEX_CONTROL, [8] = LEX_CONTROL, ['\t'] = LEX_STOP,
	[10] = LEX_CONTROL, [11] = LEX_CONTROL, [12] = LEX_CONTROL, [13] = LEX_CONTROL, [14] = LEX_CONTROL,
	[15] = LEX_CONTROL, [16] = LEX_CONTROL, [17] = LEX_CONTROL, [18] = LEX_CONTROL, [19] = LEX_CONTROL,
	[20] = LEX_CONTROL, [21] = LEX_CONTROL, [22] = LEX_CONTROL, [23] = LEX_CONTROL, [24] = LEX_CONTROL,
	[25] = LEX_CONTROL, [26] = LEX_CONTROL, [27] = LEX_CONTROL, [28] = LEX_CONTROL, [29] = LEX_CONTROL,
	[30] = LEX_CONTROL, [31] = LEX_CONTROL, [' '] = LEX_STOP, ['#'] = LEX_STOP, ['/'] = LEX_STOP,
	['"'] = LEX_STOP, [0x7F] = LEX_CONTROL,
};

/* The index of the first byte of s[i..len) whose class has `bits`, or len:
 * sixteen bytes at a time with SSE2 (a .rt file of a million objects is 66
 * MB read a byte at a time twice), the rest by the table. */
#if defined(__SSE2__)
static inline unsigned lex_mask16(__m128i x, unsigned bits)
{
	__m128i m = _mm_setzero_si128();
	if (bits & LEX_CONTROL) {
		/* x <= 0x1F except the tab, or DEL */
		__m128i low = _mm_cmpeq_epi8(_mm_max_epu8(x, _mm_set1_epi8(0x1F)), _mm_set1_epi8(0x1F));
		low = _mm_andnot_si128(_mm_cmpeq_epi8(x, _mm_set1_epi8('\t')), low);
		m = _mm_or_si128(low, _mm_cmpeq_epi8(x, _mm_set1_epi8(0x7F)));
	}
	if (bits & LEX_STOP) {
		m = _mm_or_si128(m, _mm_cmpeq_epi8(x, _mm_set1_epi8(' ')));
		m = _mm_or_si128(m, _mm_cmpeq_epi8(x, _mm_set1_epi8('\t')));
		m = _mm_or_si128(m, _mm_cmpeq_epi8(x, _mm_set1_epi8('#')));
		m = _mm_or_si128(m, _mm_cmpeq_epi8(x, _mm_set1_epi8('/')));
		m = _mm_or_si128(m, _mm_cmpeq_epi8(x, _mm_set1_epi8('"')));
	}
	return (unsigned)_mm_movemask_epi8(m);
}
#endif

static size_t lex_find(const char *s, size_t i, size_t len, unsigned bits)
{
#if defined(__SSE2__)
	for (; i + 16 <= len; i += 16) {
		unsigned m = lex_mask16(_mm_loadu_si128((const __m128i *)(const void *)(s + i)), bits);
		if (m)
			return i + (size_t)__builtin_ctz(m);
	}
#endif
	while (i < len && !(lex_class[(unsigned char)s[i]] & bits))
		i++;
	return i;
}

static bool comment_at(const char *s, size_t i, size_t len)
{
	return s[i] == '#' || (s[i] == '/' && i + 1 < len && s[i + 1] == '/');
}

static bool push_tok(parser *p, tok t)
{
	if (p->ntoks == p->cap_toks) {
		size_t cap = p->cap_toks ? p->cap_toks * 2 : 16;
		tok *n = realloc(p->toks, cap * sizeof *n);
		if (!n)
			return rt_error_set(p->err, "out of memory");
		p->toks = n;
		p->cap_toks = cap;
	}
	p->toks[p->ntoks++] = t;
	return true;
}

/* Cuts the line s[0..len) into p->toks. */
/* Copies the quoted text whose opening quote is s[*i] to *out and moves *i
 * past its closing quote; a quote that is not closed is an error (the form
 * `expect` named). Blanks, '#' and ',' inside are the text's own. */
static bool copy_quoted(parser *p, const char *s, size_t len, size_t *i, char **out, const char *expect)
{
	const char *q = memchr(s + *i + 1, '"', len - *i - 1);
	if (!q)
		return fail(p, (int)*i + 1, "a quote that is not closed; expected %s", expect);
	size_t n = (size_t)(q - (s + *i + 1));
	memcpy(*out, s + *i + 1, n);
	*out += n;
	*i = (size_t)(q - s) + 1;
	return true;
}

static bool lex_line(parser *p, const char *s, size_t len)
{
	p->ntoks = 0;
	p->endcol = 1;
	if (len > RT_FILE_MAX)
		return fail(p, 0, "the line is longer than 1 GiB; expected a shorter line");
	size_t bad = lex_find(s, 0, len, LEX_CONTROL);
	if (bad < len) {
		unsigned char c = (unsigned char)s[bad];
		if (c == 0)
			return fail(p, (int)bad + 1, "a NUL byte; expected text (is this a binary file?)");
		return fail(p, (int)bad + 1, "control character 0x%02X; expected text", c);
	}
	if (len + 2 > p->cap_text) {
		char *n = realloc(p->text, len + 2);
		if (!n)
			return rt_error_set(p->err, "out of memory");
		p->text = n;
		p->cap_text = len + 2;
	}
	/* Tokens are copied to p->text; a token and its NUL never take more
	 * room than its span and the blank after it, so len + 1 bytes do. */
	char *out = p->text;
	size_t i = 0;
	while (i < len) {
		if (is_blank(s[i])) {
			i++;
			continue;
		}
		if (comment_at(s, i, len))
			break;
		tok t = {.s = out, .col = (int)i + 1};
		if (s[i] == '"') {
			/* a quoted file name */
			if (!copy_quoted(p, s, len, &i, &out, "\"NAME\""))
				return false;
			t.quoted = true;
			t.endcol = (int)i + 1;
			t.len = (size_t)(out - t.s);
			*out++ = '\0';
			p->endcol = t.endcol;
			if (!push_tok(p, t))
				return false;
			continue;
		}
		for (;;) {
			for (;;) {
				/* the token's plain bytes, then what stopped them */
				size_t e = lex_find(s, i, len, LEX_STOP);
				memcpy(out, s + i, e - i);
				out += e - i;
				i = e;
				if (i == len || is_blank(s[i]) || comment_at(s, i, len))
					break;
				if (s[i] == '"' && out > t.s && out[-1] == '=') {
					/* KEY="a file name" */
					if (!copy_quoted(p, s, len, &i, &out, "KEY=\"NAME\""))
						return false;
					continue;
				}
				*out++ = s[i++]; /* a quote not after '=', a '/' alone */
			}
			t.endcol = (int)i + 1;
			size_t j = i;
			while (j < len && is_blank(s[j]))
				j++;
			bool more = j < len && !comment_at(s, j, len);
			if (j > i && more && (out[-1] == ',' || s[j] == ',')) {
				i = j;
				continue;
			}
			break;
		}
		t.len = (size_t)(out - t.s);
		*out++ = '\0';
		p->endcol = t.endcol;
		if (!push_tok(p, t))
			return false;
	}
	return true;
}

/* --- numbers --- */

/* Reads s[0..len), which must be followed by ',', 'x' or NUL: the one
 * scanner of num.h, within RT_NUM_MAX. */
static num_status num_parse(const char *s, size_t len, double *out)
{
	return num_scan(s, len, RT_NUM_MAX, out);
}

/* A field's range: lo..hi (lo excluded when lo_open), whole numbers only
 * when whole; `expect` says so in words. */
typedef struct range {
	double lo, hi;
	bool lo_open, whole;
	const char *expect;
} range;

static const range R_ANY = {-RT_NUM_MAX, RT_NUM_MAX, false, false, "a number"};
static const range R_RATIO = {0, 1, false, false, "a number in [0,1]"};
static const range R_POS = {0, RT_NUM_MAX, true, false, "a number > 0"};
static const range R_NONNEG = {0, RT_NUM_MAX, false, false, "a number >= 0"};
static const range R_FOV = {0, 180, false, false, "degrees in [0,180]"};
static const range R_SHINE = {1, 500, false, false, "a number in [1,500]"};
static const range R_SIZE = {1, 1e9, false, true, "a whole number in [1,1e9]"};
static const range R_COLOR = {0, 255, false, false, "R,G,B each in [0,255]"};
static const range R_COLOR42 = {0, 255, false, true,
				"R,G,B whole numbers in [0,255] (strict mode)"};
static const range R_SCALE = {0, RT_NUM_MAX, true, false, "three numbers > 0"};

/* NULL when v is in r, else what is wrong. */
static inline const char *range_problem(const range *r, double v)
{
	if (r->whole && v != floor(v))
		return "not a whole number";
	if (r->lo_open && v <= r->lo)
		return r->lo == 0 ? "not positive" : "out of range";
	if (v < r->lo || v > r->hi)
		return "out of range";
	return NULL;
}

static bool get_num(parser *p, const tok *t, const char *elem, const char *field, const range *r,
                    double *out)
{
	double v = 0;
	num_status st = memchr(t->s, ',', t->len) ? NUM_BAD : num_parse(t->s, t->len, &v);
	if (st == NUM_BIG)
		return fail_tok(p, t, elem, field, "is out of range", "a magnitude up to " RT_NUM_MAX_TEXT);
	if (st != NUM_OK)
		return fail_tok(p, t, elem, field, "is not a number", r->expect);
	const char *bad = range_problem(r, v);
	if (bad) {
		char what[64];
		snprintf(what, sizeof what, "is %s", bad);
		return fail_tok(p, t, elem, field, what, r->expect);
	}
	*out = v;
	return true;
}

/* A vector of n numbers separated by commas; `shape` names them ("X,Y,Z"). */
static bool get_tuple(parser *p, const tok *t, const char *elem, const char *field, int n,
                      const char *shape, const range *r, double *out)
{
	/* The common well-formed tuple in one pass: split at the first n - 1
	 * commas, each part a number in range (a part with a comma left in it
	 * is no number). Anything else, and every message, from the full pass
	 * below, which reads the same parts the same way. */
	if (n <= 8) {
		double v[8];
		const char *c = t->s, *end = t->s + t->len;
		int k = 0;
		for (; k < n; k++) {
			const char *e = k + 1 < n ? memchr(c, ',', (size_t)(end - c)) : end;
			if (!e || num_parse(c, (size_t)(e - c), &v[k]) != NUM_OK || range_problem(r, v[k]))
				break;
			c = e + 1;
		}
		if (k == n) {
			memcpy(out, v, (size_t)n * sizeof *v);
			return true;
		}
	}
	int count = 1;
	for (size_t i = 0; i < t->len; i++) {
		if (t->s[i] != ',')
			continue;
		if (i == 0 || i + 1 == t->len || t->s[i + 1] == ',')
			return fail_tok(p, t, elem, field, "has an empty component", shape);
		count++;
	}
	char what[64];
	if (count != n) {
		if (count == 1)
			snprintf(what, sizeof what, "is not a vector");
		else
			snprintf(what, sizeof what, "has %d components", count);
		return fail_tok(p, t, elem, field, what, shape);
	}
	const char *c = t->s, *end = t->s + t->len;
	for (int k = 0; k < n; k++) {
		const char *e = memchr(c, ',', (size_t)(end - c));
		if (!e)
			e = end;
		double v = 0;
		num_status st = num_parse(c, (size_t)(e - c), &v);
		if (st == NUM_BIG)
			return fail_tok(p, t, elem, field, "is out of range",
			                "a magnitude up to " RT_NUM_MAX_TEXT);
		if (st != NUM_OK)
			return fail_tok(p, t, elem, field, "has a component that is not a number",
			                shape);
		const char *bad = range_problem(r, v);
		if (bad) {
			snprintf(what, sizeof what, "has a component that is %s", bad);
			return fail_tok(p, t, elem, field, what, r->expect);
		}
		out[k] = v;
		c = e + 1;
	}
	return true;
}

static bool get_vec(parser *p, const tok *t, const char *elem, const char *field, const range *r,
                    vec3 *out)
{
	double v[3];
	if (!get_tuple(p, t, elem, field, 3, "X,Y,Z", r, v))
		return false;
	*out = v3(v[0], v[1], v[2]);
	return true;
}

static bool get_color(parser *p, const tok *t, const char *elem, const char *field, vec3 *out)
{
	double v[3];
	const range *r = p->strict ? &R_COLOR42 : &R_COLOR;
	if (!get_tuple(p, t, elem, field, 3, "R,G,B", r, v))
		return false;
	*out = v3(v[0], v[1], v[2]);
	return true;
}

/* A direction: not zero, long enough to normalise; under --strict, unit
 * length with components in [-1,1]. */
static bool get_dir(parser *p, const tok *t, const char *elem, const char *field, vec3 *out)
{
	vec3 d;
	if (!get_vec(p, t, elem, field, &R_ANY, &d))
		return false;
	if (d.x == 0 && d.y == 0 && d.z == 0)
		return fail(p, t->col, "%s %s is the zero vector; expected a non-zero direction", elem,
		            field);
	if (v3_len2(d) < DBL_MIN)
		return fail_tok(p, t, elem, field, "is too short to normalise",
		                "a direction of length > 1e-150");
	if (p->strict) {
		if (v3_max_abs(d) > 1)
			return fail_tok(p, t, elem, field, "has a component outside [-1,1]",
			                "a unit vector (strict mode)");
		if (fabs(v3_len(d) - 1) > STRICT_UNIT_TOL) {
			char what[64];
			snprintf(what, sizeof what, "is not a unit vector (length %.4g)", v3_len(d));
			return fail_tok(p, t, elem, field, what,
			                "a unit vector, length 1 within 0.01 (strict mode)");
		}
	}
	*out = d;
	return true;
}

/* --- field counts --- */

static bool count_ok(parser *p, const elem_def *e, size_t lo, size_t hi, const char *usage)
{
	if (p->np < lo)
		return fail(p, p->endcol, "%s: too few fields; expected %s", e->name, usage);
	if (p->np > hi)
		return fail(p, p->toks[hi + 1].col, "%s: too many fields; expected %s", e->name, usage);
	return true;
}

/* The usage to quote: only the 42 form under --strict. */
static const char *usage_of(const parser *p, const elem_def *e)
{
	return p->strict && e->usage42 ? e->usage42 : e->usage;
}

/* Key=value fields are for objects only. */
static bool no_keys(parser *p, const elem_def *e)
{
	if (p->np + 1 < p->ntoks) {
		const tok *t = &p->toks[p->np + 1];
		return fail(p, t->col, "%s field \"%s\" is a key=value field; expected %s", e->name,
		            quoted(p, t), e->usage);
	}
	return true;
}

/* A once-only element seen before: an identical repeat is ignored with a
 * warning, a different one is an error. Returns 1 to store the element, 0
 * to skip it, -1 on error. rt_parse_line replaces instead. */
static int once(parser *p, const elem_def *e, const char *what, int *first, bool same)
{
	if (p->single || *first == 0) {
		*first = p->line;
		return 1;
	}
	if (same && !p->strict) {
		rt_warn(p->warn, p->name, p->line, p->toks[0].col,
		        "%s: this %s line repeats line %d; ignored", e->name, what, *first);
		return 0;
	}
	fail(p, p->toks[0].col, "%s: a second %s line; expected only one (the first is on line %d)",
	     e->name, what, *first);
	return -1;
}

/* --- the elements --- */

static bool parse_ambient(parser *p, const elem_def *e)
{
	ambient a;
	if (!no_keys(p, e) || !count_ok(p, e, 2, 2, e->usage) ||
	    !get_num(p, &p->toks[1], e->name, "ratio", &R_RATIO, &a.ratio) ||
	    !get_color(p, &p->toks[2], e->name, "colour", &a.color))
		return false;
	bool same = p->s->has_ambient && p->s->amb.ratio == a.ratio && v3_eq(p->s->amb.color, a.color);
	int r = once(p, e, "A", &p->line_a, same);
	if (r > 0) {
		p->s->has_ambient = true;
		p->s->amb = a;
	}
	return r >= 0;
}

/* The key=value fields of a light or camera line: each token after the
 * positional ones split into its name and a token of its value; -1 when
 * the name is none of names[] (err set), else its index. */
static int elem_key(parser *p, const elem_def *e, size_t i, const char *const *names, size_t nnames, unsigned *seen,
                    tok *val)
{
	const tok *t = &p->toks[i];
	const char *eq = memchr(t->s, '=', t->len);
	char list[160] = "";
	for (size_t k = 0; k < nnames; k++)
		snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s=", k ? " " : "", names[k]);
	if (p->strict) {
		fail_tok(p, t, e->name, "key", "is not allowed in strict mode", "no key=value fields");
		return -1;
	}
	if (!eq) {
		fail(p, t->col, "%s field \"%s\" comes after the key=value fields; expected the key=value fields last",
		     e->name, quoted(p, t));
		return -1;
	}
	size_t n = (size_t)(eq - t->s);
	for (size_t k = 0; k < nnames; k++)
		if (strlen(names[k]) == n && memcmp(names[k], t->s, n) == 0) {
			if (*seen & (1u << k)) {
				fail_tok(p, t, e->name, "key", "repeats a key", "each key at most once");
				return -1;
			}
			*seen |= 1u << k;
			*val = *t;
			val->s = eq + 1;
			val->len = t->len - n - 1;
			val->col = t->col + (int)n + 1;
			return (int)k;
		}
	fail_tok(p, t, e->name, "key", "is unknown", list);
	return -1;
}

static bool parse_camera(parser *p, const elem_def *e)
{
	camera c = {0};
	if (!count_ok(p, e, 3, 3, e->usage) || !get_vec(p, &p->toks[1], e->name, "position", &R_ANY, &c.pos) ||
	    !get_dir(p, &p->toks[2], e->name, "direction", &c.dir) ||
	    !get_num(p, &p->toks[3], e->name, "fov", &R_FOV, &c.fov))
		return false;
	static const char *const cam_keys[] = {"vertical", "ortho", "roll"};
	unsigned seen = 0;
	for (size_t i = p->np + 1; i < p->ntoks; i++) {
		tok v;
		double x;
		int k = elem_key(p, e, i, cam_keys, 3, &seen, &v);
		if (k < 0)
			return false;
		if (k == 0) {
			static const range R_BOOL = {0, 1, false, true, "0 or 1"};
			if (!get_num(p, &v, e->name, "vertical=", &R_BOOL, &x))
				return false;
			c.vertical = x != 0;
		} else if (k == 2) {
			static const range R_ROLL = {-180, 180, false, false, "an angle in degrees from -180 to 180"};
			if (!get_num(p, &v, e->name, "roll=", &R_ROLL, &c.roll))
				return false;
		} else if (!get_num(p, &v, e->name, "ortho=", &R_POS, &c.ortho)) {
			return false;
		}
	}
	bool clamped;
	if (!fov_rule(&c.fov, &clamped, p->err)) /* R_FOV has checked [0,180] */
		return false;
	if (clamped)
		rt_warn(p->warn, p->name, p->line, p->toks[3].col,
		        "camera fov \"%s\" is clamped to %g degrees; expected an angle strictly "
		        "between 0 and 180",
		        quoted(p, &p->toks[3]), c.fov);
	scene *s = p->s;
	if (strcmp(e->id, "C") != 0)
		return scene_add_camera(s, &c, p->err);
	if (p->single) {
		if (s->ncams == 0)
			return scene_add_camera(s, &c, p->err);
		s->cams[s->cam < s->ncams ? s->cam : 0] = c;
		return true;
	}
	bool same = false;
	if (p->line_c) {
		const camera *o = &s->cams[p->cam_c];
		same = v3_eq(o->pos, c.pos) && v3_eq(o->dir, c.dir) && o->fov == c.fov && o->vertical == c.vertical &&
		       o->ortho == c.ortho && o->roll == c.roll;
	}
	int r = once(p, e, "C", &p->line_c, same);
	if (r > 0) {
		p->cam_c = s->ncams;
		return scene_add_camera(s, &c, p->err);
	}
	return r >= 0;
}

static bool parse_light(parser *p, const elem_def *e)
{
	light l = {.color = v3_splat(255)};
	if (!count_ok(p, e, p->strict ? 3 : 2, 3, usage_of(p, e)) ||
	    !get_vec(p, &p->toks[1], e->name, "position", &R_ANY, &l.pos) ||
	    !get_num(p, &p->toks[2], e->name, "ratio", &R_RATIO, &l.ratio))
		return false;
	if (p->np == 3 && !get_color(p, &p->toks[3], e->name, "colour", &l.color))
		return false;
	/* physical lights: cd= (point; with cone=, a spot) or lux= (a sun) */
	static const char *const light_keys[] = {"cd", "lux", "dir", "cone", "range"};
	unsigned seen = 0;
	int last = 0;
	for (size_t i = p->np + 1; i < p->ntoks; i++) {
		tok v;
		double x[2];
		int k = elem_key(p, e, i, light_keys, 5, &seen, &v);
		if (k < 0)
			return false;
		last = p->toks[i].col;
		static const range R_CONE = {0, 90, false, false, "degrees in [0,90]"};
		if ((k == 0 || k == 1) && !get_num(p, &v, e->name, k ? "lux=" : "cd=", &R_NONNEG, &l.intensity))
			return false;
		if (k == 2 && !get_dir(p, &v, e->name, "dir=", &l.dir))
			return false;
		if (k == 3) {
			if (!get_tuple(p, &v, e->name, "cone=", 2, "INNER,OUTER", &R_CONE, x))
				return false;
			if (!(x[0] < x[1]))
				return fail_tok(p, &v, e->name, "cone=", "has inner >= outer",
				                "INNER,OUTER degrees with INNER < OUTER");
			l.inner = x[0];
			l.outer = x[1];
		}
		if (k == 4 && !get_num(p, &v, e->name, "range=", &R_NONNEG, &l.range))
			return false;
	}
	if (seen) {
		bool cd = seen & 1, lux = seen & 2;
		if (cd == lux)
			return fail(p, last, "light: %s; expected cd=CANDELA (a point or spot light) or lux=LUX (a sun)",
			            cd ? "both cd= and lux=" : "dir=, cone= or range= without cd= or lux=");
		if (lux && (seen & (8 | 16)))
			return fail(p, last, "light: cone= or range= on a sun (lux=); expected them with cd=");
		if (lux && !(seen & 4))
			return fail(p, last, "light: a sun (lux=) without dir=; expected dir=X,Y,Z, where it shines");
		if ((seen & 8) && !(seen & 4))
			return fail(p, last, "light: a spot (cone=) without dir=; expected dir=X,Y,Z, where it shines");
		l.kind = lux ? LIGHT_SUN : (seen & 8) ? LIGHT_SPOT : LIGHT_POINT;
		if (l.kind == LIGHT_POINT)
			l.dir = v3(0, 0, 0); /* unused: not kept */
	}
	if (p->strict && p->line_l)
		return fail(p, p->toks[0].col,
		            "light: a second L line; expected exactly one in strict mode (the first "
		            "is on line %d)",
		            p->line_l);
	if (!p->line_l)
		p->line_l = p->line;
	return scene_add_light(p->s, &l, p->err);
}

static bool parse_resolution(parser *p, const elem_def *e)
{
	double w, h;
	if (!no_keys(p, e) || !count_ok(p, e, 2, 2, e->usage) ||
	    !get_num(p, &p->toks[1], e->name, "width", &R_SIZE, &w) ||
	    !get_num(p, &p->toks[2], e->name, "height", &R_SIZE, &h))
		return false;
	scene_hints *hn = &p->s->hints;
	int r = once(p, e, "R", &p->line_r, hn->width == (int)w && hn->height == (int)h);
	if (r > 0) {
		hn->width = (int)w;
		hn->height = (int)h;
	}
	return r >= 0;
}

static bool get_file(parser *p, const tok *t, const char *name, size_t n, const rt_key *key,
                     const char **out);

static bool parse_sky(parser *p, const elem_def *e)
{
	sky k = {.strength = 1};
	if (p->np >= 1 && (p->toks[1].quoted || !memchr(p->toks[1].s, ',', p->toks[1].len))) {
		/* sky FILE [STRENGTH [ROTATION]]: an HDR image */
		if (!no_keys(p, e) || !count_ok(p, e, 1, 3, e->usage) ||
		    !get_file(p, &p->toks[1], p->toks[1].s, p->toks[1].len, NULL, &k.file))
			return false;
		if (p->np >= 2 && !get_num(p, &p->toks[2], e->name, "strength", &R_NONNEG, &k.strength))
			return false;
		if (p->np >= 3 && !get_num(p, &p->toks[3], e->name, "rotation", &R_ANY, &k.rotation))
			return false;
	} else if (!no_keys(p, e) || !count_ok(p, e, 2, 3, e->usage) ||
	    !get_color(p, &p->toks[1], e->name, "zenith colour", &k.zenith) ||
	    !get_color(p, &p->toks[2], e->name, "horizon colour", &k.horizon))
		return false;
	else if (p->np == 3 && !get_num(p, &p->toks[3], e->name, "strength", &R_NONNEG, &k.strength))
		return false;
	const sky *o = &p->s->sky;
	bool same = p->s->has_sky && v3_eq(o->zenith, k.zenith) && v3_eq(o->horizon, k.horizon) &&
	            o->strength == k.strength && o->file == k.file && o->rotation == k.rotation;
	int r = once(p, e, "sky", &p->line_sky, same);
	if (r > 0) {
		p->s->has_sky = true;
		p->s->sky = k;
	}
	return r >= 0;
}

/* `set resolution WxH`: two whole numbers >= 1. */
static bool get_resolution(parser *p, const tok *t, int *w, int *h)
{
	static const char expect[] = "WIDTHxHEIGHT, whole numbers >= 1";
	const char *x = memchr(t->s, 'x', t->len);
	if (!x)
		x = memchr(t->s, 'X', t->len);
	double v[2];
	if (!x || memchr(t->s, ',', t->len))
		return fail_tok(p, t, "set", "resolution", "is not WxH", expect);
	size_t lens[2] = {(size_t)(x - t->s), t->len - (size_t)(x - t->s) - 1};
	const char *starts[2] = {t->s, x + 1};
	for (int k = 0; k < 2; k++) {
		num_status st = num_parse(starts[k], lens[k], &v[k]);
		if (st == NUM_BIG)
			return fail_tok(p, t, "set", "resolution", "is out of range", expect);
		if (st != NUM_OK)
			return fail_tok(p, t, "set", "resolution", "is not WxH", expect);
		const char *bad = range_problem(&R_SIZE, v[k]);
		if (bad) {
			char what[64];
			snprintf(what, sizeof what, "has a size that is %s", bad);
			return fail_tok(p, t, "set", "resolution", what, expect);
		}
	}
	*w = (int)v[0];
	*h = (int)v[1];
	return true;
}

/* `set NAME VALUE` for a kept setting other than the four of parse_set:
 * the settings table's row reads and checks the value. */
static bool parse_set_kept(parser *p, const elem_def *e, const tok *k, const tok *v)
{
	size_t row = 0;
	while (row < settings_count &&
	       !(settings_kept_slot(&settings_table[row]) && strcmp(k->s, settings_table[row].name) == 0))
		row++;
	if (row == settings_count) {
		char names[256] = "";
		nearest near = nearest_start(k->s);
		bool known = false;
		for (size_t j = 0; j < settings_count; j++) {
			known |= strcmp(k->s, settings_table[j].name) == 0;
			if (!(settings_table[j].flags & SETTING_SCENE))
				continue;
			snprintf(names + strlen(names), sizeof names - strlen(names), " %s", settings_table[j].name);
			nearest_try(&near, settings_table[j].name, strlen(settings_table[j].name));
		}
		if (known)
			return fail(p, k->col, "set key \"%s\" is not kept with a scene (it is the machine's or "
			                       "the terminal's: give it to the shell or the command line); expected one of%s",
			            quoted(p, k), names);
		if (nearest_ok(&near))
			return fail(p, k->col, "set key \"%s\" is unknown; did you mean \"%s\"? (expected one of%s)",
			            quoted(p, k), near.best, names);
		char expect[300];
		snprintf(expect, sizeof expect, "one of%s", names);
		return fail_tok(p, k, "set", "key", "is unknown", expect);
	}
	const setting_def *def = &settings_table[row];
	char val[SCENE_KEPT_LEN];
	rt_error err;
	if (!settings_scene_value(def, v->s, val, sizeof val, &err)) {
		nearest near = nearest_start(v->s);
		for (int j = 0; j < settings_choices(def); j++)
			nearest_try(&near, def->choices[j], strlen(def->choices[j]));
		char expect[256];
		settings_choices_text(def, ", ", " or ", expect, sizeof expect);
		if (nearest_ok(&near))
			return fail(p, v->col, "set %s \"%s\" is not valid; did you mean \"%s\"? (expected %s)",
			            def->name, quoted(p, v), near.best, expect);
		return fail(p, v->col, "set %s", err.msg);
	}
	scene_hints *hn = &p->s->hints;
	char what[64];
	snprintf(what, sizeof what, "set %s", def->name);
	int r = once(p, e, what, &p->line_kept[row], strcmp(hn->kept[row], val) == 0);
	if (r > 0)
		memcpy(hn->kept[row], val, sizeof val);
	return r >= 0;
}

static bool parse_set(parser *p, const elem_def *e)
{
	static const char *const keys[] = {"samples", "depth", "mode", "resolution"};
	static const range r_samples = {1, 1000000, false, true, "a whole number in [1,1000000]"};
	static const range r_depth = {0, 1000, false, true, "a whole number in [0,1000]"};
	if (!no_keys(p, e) || !count_ok(p, e, 2, 2, e->usage))
		return false;
	const tok *k = &p->toks[1], *v = &p->toks[2];
	size_t i = 0;
	while (i < 4 && strcmp(k->s, keys[i]) != 0)
		i++;
	if (i == 4)
		return parse_set_kept(p, e, k, v);
	scene_hints *hn = &p->s->hints;
	double d = 0;
	int r;
	switch (i) {
	case 0:
	case 1: {
		/* the whole numbers: samples, depth */
		int *field = i == 0 ? &hn->samples : &hn->depth;
		if (!get_num(p, v, "set", keys[i], i == 0 ? &r_samples : &r_depth, &d))
			return false;
		char what[32];
		snprintf(what, sizeof what, "set %s", keys[i]);
		r = once(p, e, what, &p->line_set[i], *field == (int)d);
		if (r > 0)
			*field = (int)d;
		break;
	}
	case 2: {
		int m = 0; /* the integrators' names (integrators.def) */
		while (m < MODE_COUNT && strcmp(v->s, render_mode_names[m]) != 0)
			m++;
		if (m == MODE_COUNT) {
			char names[256] = "";
			for (int j = 0; j < MODE_COUNT; j++)
				snprintf(names + strlen(names), sizeof names - strlen(names), "%s%s",
				         j == 0 ? "" : j == MODE_COUNT - 1 ? " or " : ", ", render_mode_names[j]);
			return fail_tok(p, v, "set", "mode", "is unknown", names);
		}
		r = once(p, e, "set mode", &p->line_set[2], hn->mode == m);
		if (r > 0)
			hn->mode = m;
		break;
	}
	default: {
		int w = 0, h = 0;
		if (!get_resolution(p, v, &w, &h))
			return false;
		r = once(p, e, "resolution (R or set resolution)", &p->line_r,
		         hn->width == w && hn->height == h);
		if (r > 0) {
			hn->width = w;
			hn->height = h;
		}
		break;
	}
	}
	return r >= 0;
}

/* A file name field: resolved against the .rt file's folder, checked to
 * load (a model or an image, so that a bad file is reported with this
 * line), and interned. */
static bool get_file(parser *p, const tok *t, const char *name, size_t n, const rt_key *key,
                     const char **out)
{
	if (n == 0)
		return fail(p, t->col, "%s is empty; expected %s", key ? key->name : "mesh file",
		            key ? key->expect : "a model file");
	char rel[4096];
	if (n >= sizeof rel)
		return fail(p, t->col, "the file name is longer than %zu bytes", sizeof rel - 1);
	memcpy(rel, name, n);
	rel[n] = '\0';
	char full[8192];
	if (rel[0] == '/' || !p->dir || !p->dir[0])
		snprintf(full, sizeof full, "%s", rel);
	else
		snprintf(full, sizeof full, "%s/%s", p->dir, rel);
	rt_error ferr;
	rt_error_clear(&ferr);
	bool ok = true;
	bool image = key || strcmp(p->toks[0].s, "sky") == 0;
	if (image) {
		image_budget_exempt(!key); /* the sky: no picture without it */
		texture *tx = texture_cache_get(full, key && strcmp(key->name, "texture") == 0, p->cancel, &ferr);
		image_budget_exempt(false);
		ok = tx != NULL;
		texture_cache_put(tx);
		if (!ok && key && image_budget_refused(&ferr)) { /* the previewer's budget: untextured */
			*out = NULL;
			return true;
		}
	} else if (!mesh_format_known(full)) {
		ok = mesh_load(full, &ferr) != NULL; /* gives the message */
	}
	if (!ok) {
		char msg[RT_ERROR_MSG_MAX];
		rt_error_format(&ferr, msg, sizeof msg);
		return fail(p, t->col, "%s \"%s\": %s", key ? key->name : image ? "sky file" : "mesh file",
		            quoted(p, t), msg);
	}
	*out = rt_intern(full, strlen(full));
	if (!*out)
		return rt_error_set(p->err, "out of memory");
	return true;
}

/* The trailing key=value fields of an object, from rt_keys. */
static bool parse_keys(parser *p, const elem_def *e, object *o)
{
	unsigned seen = 0;
	for (size_t i = p->np + 1; i < p->ntoks; i++) {
		const tok *t = &p->toks[i];
		if (p->strict)
			return fail_tok(p, t, e->name, "key", "is not allowed in strict mode",
			                "no key=value fields");
		const char *eq = memchr(t->s, '=', t->len);
		if (!eq)
			return fail(p, t->col,
			            "%s field \"%s\" comes after the key=value fields; expected the "
			            "key=value fields last",
			            e->name, quoted(p, t));
		size_t nlen = (size_t)(eq - t->s);
		size_t k = 0;
		while (k < rt_nkeys &&
		       !(strlen(rt_keys[k].name) == nlen && memcmp(rt_keys[k].name, t->s, nlen) == 0))
			k++;
		if (k == rt_nkeys || (!rt_keys[k].mesh_only && !rt_key_applies(&rt_keys[k], o->kind))) {
			char list[1024] = "";
			size_t used = 0;
			for (size_t j = 0; j < rt_nkeys; j++)
				if (used < sizeof list && rt_key_applies(&rt_keys[j], o->kind))
					used += (size_t)snprintf(list + used, sizeof list - used, "%s%s=",
					                         used ? " " : "", rt_keys[j].name);
			char what[64];
			snprintf(what, sizeof what, "does not apply to %ss", e->name);
			return fail_tok(p, t, e->name, "key", k == rt_nkeys ? "is unknown" : what, list);
		}
		const rt_key *key = &rt_keys[k];
		if (key->mesh_only && !(obj_kind_flags(o->kind) & KIND_MODEL))
			return fail_tok(p, t, e->name, "key", "applies to meshes only",
			                "smooth= and crease= on mesh lines");
		if (seen & (1u << k))
			return fail_tok(p, t, e->name, "key", "repeats a key", "each key at most once");
		seen |= 1u << k;
		double v = 0;
		const char *val = eq + 1;
		if (key->type == RT_KEY_FILE) {
			if (!get_file(p, t, val, t->len - nlen - 1, key, (const char **)(void *)((char *)o + key->offset)))
				return false;
			continue;
		}
		if (key->type == RT_KEY_RGB || key->type == RT_KEY_PAIR) {
			/* R,G,B or U,V, each in the key's range */
			bool rgb = key->type == RT_KEY_RGB;
			int n = rgb ? 3 : 2;
			tok pt = *t;
			pt.s = val;
			pt.len = t->len - nlen - 1;
			double c[3];
			range r = {key->min, key->max, false, false, key->expect};
			if (!get_tuple(p, &pt, e->name, key->name, n, rgb ? "R,G,B" : "U,V", &r, c))
				return false;
			if (strcmp(key->name, "uvscale") == 0 && (c[0] == 0 || c[1] == 0))
				return fail_tok(p, t, e->name, "key", "has a zero component", key->expect);
			if (!rt_key_set_n(key, o, c, n))
				return fail_tok(p, t, e->name, "key", "could not be kept: out of memory", key->expect);
			continue;
		}
		num_status st = num_parse(val, t->len - nlen - 1, &v);
		if (st == NUM_BIG)
			return fail_tok(p, t, e->name, "key", "is out of range", key->expect);
		if (st != NUM_OK)
			return fail_tok(p, t, e->name, "key", "has a value that is not a number",
			                key->expect);
		if (v < key->min || v > key->max || (key->is_int && v != floor(v)) ||
		    (key->extra && !key->extra(v)))
			return fail_tok(p, t, e->name, "key", "is out of range", key->expect);
		if (!rt_key_set(key, o, v))
			return fail_tok(p, t, e->name, "key", "could not be kept: out of memory", key->expect);
	}
	return true;
}

/* A 42-form size (diameter, height, side) of exactly 0, which the wild
 * corpus has: outside --strict it is accepted and the object, having no
 * volume, is left out with a warning. */
typedef struct zero_size {
	const tok *t;
	const char *field;
} zero_size;

static bool get_size(parser *p, const tok *t, const char *elem, const char *field, double *out,
                     zero_size *zero)
{
	double v;
	if (!p->strict && !memchr(t->s, ',', t->len) && num_parse(t->s, t->len, &v) == NUM_OK &&
	    v == 0) {
		if (!zero->t)
			*zero = (zero_size){t, field};
		*out = 0;
		return true;
	}
	return get_num(p, t, elem, field, &R_POS, out);
}

/* Keys, validation, then the object joins the scene (unless it has a zero
 * size, see get_size). */
static bool add_object(parser *p, const elem_def *e, object *o, const zero_size *zero)
{
	if (!parse_keys(p, e, o))
		return false;
	if (zero && zero->t) {
		rt_warn(p->warn, p->name, p->line, zero->t->col,
		        "%s %s \"%s\" is zero: the %s has no volume and is left out", e->name,
		        zero->field, quoted(p, zero->t), e->name);
		return true;
	}
	rt_error verr;
	rt_error_clear(&verr);
	if (!object_rules(o, &verr)) /* the editor's rules too */
		return fail(p, p->toks[0].col, "%s: %s", e->name, verr.msg);
	if (!scene_add_object(p->s, o, &verr)) /* too many objects for the memory */
		return fail(p, p->toks[0].col, "%s", verr.msg);
	return true;
}

/* DIFFUSE SPECULAR SHININESS REFLECTIVE from toks[first..first+3]. */
static bool get_material(parser *p, const elem_def *e, size_t first, material *m)
{
	const tok *t = &p->toks[first];
	return get_num(p, &t[0], e->name, "diffuse", &R_RATIO, &m->diffuse) &&
	       get_num(p, &t[1], e->name, "specular", &R_RATIO, &m->specular) &&
	       get_num(p, &t[2], e->name, "shininess", &R_SHINE, &m->shininess) &&
	       get_num(p, &t[3], e->name, "reflective", &R_RATIO, &m->reflective);
}

/* The material group is all four fields or none. */
static bool group_ok(parser *p, const elem_def *e, size_t first)
{
	if (p->np > first && p->np < first + 4)
		return fail(p, p->toks[first + 1].col,
		            "%s: %zu of the 4 material fields; expected DIFFUSE SPECULAR SHININESS "
		            "REFLECTIVE together or none of them",
		            e->name, p->np - first);
	return true;
}

/* ID POS ROT SCALE R,G,B [DIFFUSE SPECULAR SHININESS REFLECTIVE [SHEAR]] */
static bool parse_extended(parser *p, const elem_def *e)
{
	if (p->strict)
		return fail(p, p->toks[0].col,
		            "%s: the extended form is not allowed in strict mode; expected %s", e->name,
		            e->usage42);
	if (!count_ok(p, e, 4, 9, e->usage) || !group_ok(p, e, 4))
		return false;
	const tok *t = p->toks;
	vec3 pos, dir, scale, color;
	if (!get_vec(p, &t[1], e->name, "position", &R_ANY, &pos) ||
	    !get_dir(p, &t[2], e->name, "rotation", &dir) ||
	    !get_vec(p, &t[3], e->name, "scaling", &R_SCALE, &scale) ||
	    !get_color(p, &t[4], e->name, "colour", &color))
		return false;
	object o = object_make((obj_kind)e->kind, color);
	o.pos = pos;
	o.dir = dir;
	o.scale = scale;
	if (p->np >= 8 && !get_material(p, e, 5, &o.mat))
		return false;
	if (p->np == 9 && !get_tuple(p, &t[9], e->name, "shear", 6, "XY,XZ,YX,YZ,ZX,ZY", &R_ANY,
	                             o.shear))
		return false;
	return add_object(p, e, &o, NULL);
}

/* A 42-form object: the kind's defaults, then the fields the caller sets. */
static object short_object(const elem_def *e, vec3 pos, vec3 dir, vec3 scale, vec3 color)
{
	object o = object_make((obj_kind)e->kind, color);
	o.pos = pos;
	o.dir = dir;
	o.twist = 0;
	o.scale = scale;
	memset(o.shear, 0, sizeof o.shear);
	o.mat = material_default(color);
	return o;
}

static bool plain_number(const tok *t) { return !memchr(t->s, ',', t->len); }

/* The short form of e->form: its fields (shape.h), then R,G,B; the
 * extended form instead when the form has one and the line is not short:
 * when the first size field is missing or not a plain number, or (no size
 * field) when there are more fields than the short form's. */
static bool parse_form(parser *p, const elem_def *e)
{
	const shape_form *f = e->form;
	size_t nf = (size_t)f->nfields;
	if (f->extended) {
		const char *sz = strchr(f->types, 's');
		size_t k = sz ? (size_t)(sz - f->types) + 1 : 0;
		if (k ? p->np < k || !plain_number(&p->toks[k]) : p->np > nf + 1)
			return parse_extended(p, e);
	}
	if (!count_ok(p, e, nf + 1, nf + 1 + (f->material ? 4 : 0), usage_of(p, e)) ||
	    !group_ok(p, e, nf + 1))
		return false;
	vec3 pos = v3(0, 0, 0), dir = v3(0, 1, 0), color;
	double sizes[4] = {0, 0, 0, 0};
	size_t ns = 0;
	zero_size zero = {0};
	for (size_t i = 0; i < nf; i++) {
		const tok *t = &p->toks[1 + i];
		bool ok = f->types[i] == 'p'   ? get_vec(p, t, e->name, f->fields[i], &R_ANY, &pos)
		          : f->types[i] == 'd' ? get_dir(p, t, e->name, f->fields[i], &dir)
		                               : get_size(p, t, e->name, f->fields[i], &sizes[ns++], &zero);
		if (!ok)
			return false;
	}
	if (!get_color(p, &p->toks[nf + 1], e->name, "colour", &color))
		return false;
	object o = short_object(e, pos, dir, v3_splat(1), color);
	if (p->np == nf + 5 && !get_material(p, e, nf + 2, &o.mat))
		return false;
	if (!zero.t)
		f->read(&o, sizes);
	return add_object(p, e, &o, &zero);
}

static bool parse_triangle(parser *p, const elem_def *e)
{
	const char *const *names = e->form->fields;
	vec3 v[3], color;
	if (!count_ok(p, e, 4, 8, e->usage) || !group_ok(p, e, 4))
		return false;
	for (int k = 0; k < 3; k++)
		if (!get_vec(p, &p->toks[1 + k], e->name, names[k], &R_ANY, &v[k]))
			return false;
	if (!get_color(p, &p->toks[4], e->name, "colour", &color))
		return false;
	object o = object_make((obj_kind)e->kind, color);
	if (p->np == 8 && !get_material(p, e, 5, &o.mat))
		return false;
	vec3 n = v3_cross(v3_sub(v[1], v[0]), v3_sub(v[2], v[0]));
	if (n.x == 0 && n.y == 0 && n.z == 0)
		return fail(p, p->toks[1].col,
		            "triangle: the three points are on one line; expected the corners of a "
		            "triangle of non-zero area");
	memcpy(o.tri, v, sizeof v);
	return add_object(p, e, &o, NULL);
}

#define EXT_TAIL " POS ROT SCALE R,G,B [DIFFUSE SPECULAR SHININESS REFLECTIVE [SHEAR]]"

/* mesh FILE POS DIR SIZE [R,G,B [DIFFUSE SPECULAR SHININESS REFLECTIVE]] */
static bool parse_mesh(parser *p, const elem_def *e)
{
	if (p->strict)
		return fail(p, p->toks[0].col, "%s: not allowed in strict mode; expected the 42 elements",
		            e->name);
	if (!count_ok(p, e, 4, 9, e->usage) || !group_ok(p, e, 5))
		return false;
	const tok *t = p->toks;
	object o = object_make(OBJ_MESH, v3(255, 255, 255));
	if (!get_file(p, &t[1], t[1].s, t[1].len, NULL, &o.file) ||
	    !get_vec(p, &t[2], e->name, "position", &R_ANY, &o.pos) ||
	    !get_dir(p, &t[3], e->name, "direction", &o.dir))
		return false;
	if (plain_number(&t[4])) {
		double sz;
		if (!get_num(p, &t[4], e->name, "size", &R_POS, &sz))
			return false;
		o.scale = v3_splat(sz);
	} else if (!get_vec(p, &t[4], e->name, "size", &R_SCALE, &o.scale)) {
		return false;
	}
	o.file_colors = p->np < 5;
	if (p->np >= 5 && !get_color(p, &t[5], e->name, "colour", &o.mat.color))
		return false;
	if (p->np >= 9 && !get_material(p, e, 6, &o.mat))
		return false;
	if (!parse_keys(p, e, &o))
		return false;
	/* load it now (it stays cached for the render), so that a bad model
	 * is reported with this line */
	rt_error merr;
	rt_error_clear(&merr);
	mesh *m = mesh_cache_get_node(o.file, o.node, o.smooth != 0, o.crease, p->cancel, &merr);
	if (!m) {
		char msg[RT_ERROR_MSG_MAX];
		rt_error_format(&merr, msg, sizeof msg);
		return fail(p, t[1].col, "mesh file \"%s\": %s", quoted(p, &t[1]), msg);
	}
	/* the reader's warning (a missing mtllib, say) with this line; the
	 * model viewer's own scene (named after the model) says it itself */
	if (m->warning && strcmp(p->name, o.file) != 0)
		rt_warn(p->warn, p->name, p->line, t[1].col, "mesh file \"%s\": %s", quoted(p, &t[1]), m->warning);
	/* its own images too: a missing one failed every render after the
	 * load (the shell's load and add took the scene without a word) */
	bool images = mesh_images_ok(o.file, m, &merr);
	mesh_cache_put(m);
	if (!images) {
		char msg[RT_ERROR_MSG_MAX];
		rt_error_format(&merr, msg, sizeof msg);
		return fail(p, t[1].col, "mesh file \"%s\": %s", quoted(p, &t[1]), msg);
	}
	return add_object(p, e, &o, NULL);
}

/* The elements before the objects and after them; the objects' come from
 * the shape kinds (shape.h, kinds.def), in the order of the kinds, each
 * kind's own identifier and then its alias. */
static const elem_def elements_head[] = {
	{"A", "ambient", -1, true, parse_ambient, "A RATIO R,G,B", NULL, NULL},
	{"C", "camera", -1, true, parse_camera, "C POSITION DIRECTION FOV [vertical=1] [ortho=HALF_HEIGHT] [roll=DEG]", "C POSITION DIRECTION FOV", NULL},
	{"c", "camera", -1, false, parse_camera, "c POSITION DIRECTION FOV [vertical=1] [ortho=HALF_HEIGHT] [roll=DEG]", NULL, NULL},
	{"L", "light", -1, true, parse_light, "L POSITION RATIO [R,G,B] [cd=CANDELA [dir=X,Y,Z cone=INNER,OUTER] [range=R] | lux=LUX dir=X,Y,Z]", "L POSITION RATIO R,G,B", NULL},
	{"l", "light", -1, false, parse_light, "l POSITION RATIO [R,G,B] [cd=CANDELA [dir=X,Y,Z cone=INNER,OUTER] [range=R] | lux=LUX dir=X,Y,Z]", NULL, NULL},
	{"R", "resolution", -1, false, parse_resolution, "R WIDTH HEIGHT", NULL, NULL},
};
static const elem_def elements_tail[] = {
	{"mesh", "mesh", OBJ_MESH, false, parse_mesh,
	 "mesh FILE POSITION DIRECTION SIZE [R,G,B [DIFFUSE SPECULAR SHININESS REFLECTIVE]]", NULL, NULL},
	{"sky", "sky", -1, false, parse_sky,
	 "sky ZENITH_R,G,B HORIZON_R,G,B [STRENGTH] or sky FILE.hdr [STRENGTH [ROTATION]]", NULL, NULL},
	{"set", "set", -1, false, parse_set, "set NAME VALUE", NULL, NULL},
};
#define NHEAD (sizeof elements_head / sizeof elements_head[0])
#define NTAIL (sizeof elements_tail / sizeof elements_tail[0])

/* The element of an object's form, its usage lines written into p. */
static elem_def object_element(parser *p, obj_kind k, const shape_form *f)
{
	char *u = p->usage, *u42 = p->usage42;
	size_t n = sizeof p->usage;
	int used = 0;
	if (p->usage_form != f) {
		p->usage_form = f;
		if (f->nfields)
			used = snprintf(u, n, "%s %s R,G,B%s", f->id, f->usage,
			                f->material ? " [DIFFUSE SPECULAR SHININESS REFLECTIVE]" : "");
		if (f->extended)
			snprintf(u + used, n - (size_t)used, "%s%s" EXT_TAIL, used ? " or " : "", f->id);
		if (f->strict && f->nfields)
			snprintf(u42, sizeof p->usage42, "%s %s R,G,B", f->id, f->usage);
	}
	bool (*parse)(parser *, const elem_def *) =
	    obj_kind_flags(k) & KIND_VERTICES ? parse_triangle : f->nfields ? parse_form : parse_extended;
	return (elem_def){f->id, f->name, (int)k, f->strict, parse, u, f->strict && f->nfields ? u42 : NULL,
	                  f};
}

const char *rt_element(size_t i, const char **usage)
{
	if (i < NHEAD) {
		*usage = elements_head[i].usage;
		return elements_head[i].id;
	}
	i -= NHEAD;
	/* one parser's usage buffers per call: static, so one caller at a time */
	static parser p;
	for (int k = 0; k < OBJ_KIND_COUNT; k++) {
		const shape_kind *d = shape_kinds[k];
		for (int a = 0; a < 2; a++) {
			const shape_form *f = a ? &d->alias : &d->form;
			if (!f->id)
				continue;
			if (i-- == 0) {
				elem_def e = object_element(&p, (obj_kind)k, f);
				*usage = e.usage;
				return e.id;
			}
		}
	}
	if (i < NTAIL) {
		*usage = elements_tail[i].usage;
		return elements_tail[i].id;
	}
	return NULL;
}

/* Every element identifier, in order, for messages (strict: only those
 * strict mode allows). */
static void element_list(const parser *p, char *list, size_t size)
{
	size_t used = 0;
	list[0] = '\0';
#define ADD(id, ok) \
	if (!p->strict || (ok)) \
		used += (size_t)snprintf(list + used, used < size ? size - used : 0, " %s", id)
	for (size_t i = 0; i < NHEAD; i++)
		ADD(elements_head[i].id, elements_head[i].strict);
	for (int k = 0; k < OBJ_KIND_COUNT; k++) {
		const shape_kind *d = shape_kinds[k];
		if (d->form.id)
			ADD(d->form.id, d->form.strict);
		if (d->alias.id)
			ADD(d->alias.id, d->alias.strict);
	}
	for (size_t i = 0; i < NTAIL; i++)
		ADD(elements_tail[i].id, elements_tail[i].strict);
#undef ADD
}

/* Parses the tokens of one line (at least one). */
static bool parse_tokens(parser *p)
{
	const tok *id = &p->toks[0];
	const elem_def *e = NULL;
	elem_def obj;
	/* the first letters compared before the names (a line of a million) */
	for (size_t i = 0; i < NHEAD && !e; i++)
		if (elements_head[i].id[0] == id->s[0] && strcmp(elements_head[i].id, id->s) == 0)
			e = &elements_head[i];
	for (size_t i = 0; i < NTAIL && !e; i++)
		if (elements_tail[i].id[0] == id->s[0] && strcmp(elements_tail[i].id, id->s) == 0)
			e = &elements_tail[i];
	obj_kind k;
	const shape_form *f;
	if (!e && shape_kind_find(id->s, &k, &f)) {
		obj = object_element(p, k, f);
		e = &obj;
	}
	if (!e || (p->strict && !e->strict)) {
		char list[256];
		element_list(p, list, sizeof list);
		return fail(p, id->col, "%s element \"%s\"; expected one of%s%s",
		            e ? "strict mode does not allow the" : "unknown", quoted(p, id), list,
		            p->strict ? " (strict mode)" : "");
	}
	p->np = p->ntoks - 1;
	for (size_t i = 1; i < p->ntoks; i++) /* a quoted file name with '=' in it is no key */
		if (!p->toks[i].quoted && memchr(p->toks[i].s, '=', p->toks[i].len)) {
			p->np = i - 1;
			break;
		}
	p->nelems++;
	return e->parse(p, e);
}

static bool parse_line(parser *p, const char *s, size_t len)
{
	if (!lex_line(p, s, len))
		return false;
	return p->ntoks == 0 || parse_tokens(p);
}

static bool parse_text(parser *p, const char *text, size_t len)
{
	size_t i = 0;
	p->line = 1;
	while (i < len) {
		/* the line ends at the first '\n' or '\r' */
		const char *nl = memchr(text + i, '\n', len - i);
		size_t j = nl ? (size_t)(nl - text) : len;
		const char *cr = memchr(text + i, '\r', j - i);
		if (cr)
			j = (size_t)(cr - text);
		if ((p->line & 4095) == 0 && p->cancel && atomic_load(p->cancel))
			return fail(p, 0, "stopped");
		if (!parse_line(p, text + i, j - i))
			return false;
		if (j + 1 < len && text[j] == '\r' && text[j + 1] == '\n')
			j++;
		i = j + 1;
		p->line++;
	}
	return true;
}

/* The whole-file rules, once every line is read. */
static bool finish(parser *p)
{
	scene *s = p->s;
	p->line = 0;
	if (p->nelems == 0)
		return fail(p, 0, "no elements; expected a scene with at least a C line");
	if (p->strict) {
		if (!p->line_a)
			return fail(p, 0, "no ambient light; expected an A line (strict mode)");
		if (!p->line_c)
			return fail(p, 0, "no camera; expected a C line");
		if (!p->line_l)
			return fail(p, 0, "no light; expected an L line (strict mode)");
	}
	if (s->ncams == 0) {
		camera c = scene_camera(s);
		rt_warn(p->warn, p->name, 0, 0,
		        "no camera; expected a C line (using the default camera at %g,%g,%g looking "
		        "along %g,%g,%g)",
		        c.pos.x, c.pos.y, c.pos.z, c.dir.x, c.dir.y, c.dir.z);
		if (!scene_add_camera(s, &c, p->err))
			return false;
	}
	s->cam = 0;
	return true;
}

static void parser_init(parser *p, scene *s, const char *name, const rt_load_opts *opts,
                        rt_error *err)
{
	memset(p, 0, sizeof *p);
	p->s = s;
	p->name = name ? name : "";
	p->strict = opts && opts->strict;
	p->warn = opts ? opts->warn : NULL;
	p->cancel = opts ? opts->cancel : NULL;
	p->err = err;
	/* model and texture names are relative to the .rt file's folder */
	const char *slash = strrchr(p->name, '/');
	if (slash) {
		size_t n = slash == p->name ? 1 : (size_t)(slash - p->name);
		p->dir = malloc(n + 1);
		if (p->dir) {
			memcpy(p->dir, p->name, n);
			p->dir[n] = '\0';
		}
	}
}

static void parser_done(parser *p)
{
	free(p->dir);
	free(p->toks);
	free(p->text);
}

bool rt_name_is_rt(const char *name)
{
	size_t n = strlen(name);
	return n >= 3 && strcmp(name + n - 3, ".rt") == 0;
}

scene *rt_load_string(const char *text, size_t len, const char *name, const rt_load_opts *opts,
                      rt_error *err)
{
	scene *s = scene_new();
	if (!s) {
		rt_error_set(err, "out of memory");
		return NULL;
	}
	parser p;
	parser_init(&p, s, name, opts, err);
	bool ok;
	if (p.strict && !rt_name_is_rt(p.name)) {
		ok = fail(&p, 0, "the file name does not end in .rt; expected a .rt file (strict mode)");
	} else {
		rt_numloc loc;
		rt_numloc_enter(&loc);
		ok = parse_text(&p, text, len) && finish(&p);
		rt_numloc_leave(&loc);
	}
	parser_done(&p);
	if (!ok) {
		scene_free(s);
		return NULL;
	}
	return s;
}

/* The whole file in a new buffer; NULL with err set on failure. */
static char *read_file(void *ctx, const char *path, size_t *len, rt_error *err)
{
	(void)ctx;
	struct stat st;
	if (!path[0]) { /* rtsh "": the message would name no file */
		rt_error_set(err, "the scene's file name is empty; expected a .rt file");
		return NULL;
	}
	if (stat(path, &st) == 0 && S_ISDIR(st.st_mode)) {
		rt_error_at(err, path, 0, 0, "is a directory; expected a .rt file");
		return NULL;
	}
	/* A FIFO or a device is refused before it is opened (issue 31): opening
	 * a FIFO waits for a writer, a device may never end. */
	const char *kind;
	FILE *f = rt_file_open_regular(path, &kind);
	if (!f) {
		if (kind)
			rt_error_at(err, path, 0, 0, "is %s; expected a regular .rt file", kind);
		else
			rt_error_at(err, path, 0, 0, "cannot open: %s; expected a readable .rt file",
			            strerror(errno));
		return NULL;
	}
	size_t cap = 1 << 16;
	if (fstat(fileno(f), &st) == 0) {
		if (S_ISREG(st.st_mode) && (unsigned long long)st.st_size > RT_FILE_MAX) {
			fclose(f);
			rt_error_at(err, path, 0, 0,
			            "the file is larger than 1 GiB; expected a scene of at most 1 GiB");
			return NULL;
		}
		if (S_ISREG(st.st_mode))
			cap = (size_t)st.st_size + 1;
	}
	char *buf = NULL;
	size_t n = 0;
	for (;;) {
		if (n == cap || !buf) {
			size_t ncap = buf ? cap * 2 : cap;
			if (ncap > RT_FILE_MAX + 1)
				ncap = RT_FILE_MAX + 1;
			char *nb = realloc(buf, ncap);
			if (!nb) {
				rt_error_at(err, path, 0, 0, "out of memory reading the file");
				goto fail;
			}
			buf = nb;
			cap = ncap;
		}
		size_t want = cap - n;
		size_t got = fread(buf + n, 1, want, f);
		n += got;
		if (n > RT_FILE_MAX) {
			rt_error_at(err, path, 0, 0,
			            "the file is larger than 1 GiB; expected a scene of at most 1 GiB");
			goto fail;
		}
		if (got < want) {
			if (ferror(f)) {
				rt_error_at(err, path, 0, 0, "cannot read: %s", strerror(errno));
				goto fail;
			}
			break;
		}
	}
	fclose(f);
	buf[n] = '\0';
	*len = n;
	return buf;
fail:
	free(buf);
	fclose(f);
	return NULL;
}

char *rt_read_file(const char *path, const rt_load_opts *opts, size_t *len, rt_error *err)
{
	if (opts && opts->read)
		return opts->read(opts->read_ctx, path, len, err);
	return read_file(NULL, path, len, err);
}

bool rt_parse_line(scene *s, const char *line, const char *name, int lineno,
                   const rt_load_opts *opts, rt_error *err)
{
	parser p;
	parser_init(&p, s, name, opts, err);
	p.single = true;
	p.line = lineno;
	rt_numloc loc;
	rt_numloc_enter(&loc);
	bool ok = lex_line(&p, line, strlen(line));
	if (ok && p.ntoks == 0)
		ok = fail(&p, 0, "no element; expected an element line such as sp 0,0,0 1 255,0,0");
	if (ok)
		ok = parse_tokens(&p);
	rt_numloc_leave(&loc);
	parser_done(&p);
	return ok;
}
