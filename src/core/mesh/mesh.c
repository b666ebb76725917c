/* rtsh — meshes: the builder the readers share, welding, normals, the tree
 * (mesh.h); mesh_load.c reads them by format and caches them. */
#include "rtsh/mesh.h"

#include <ctype.h>
#include <errno.h>
#include <float.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/readhelp.h"
#include "core/bvh/bvh.h"
#include "rtsh/memory.h"
#include "rtsh/texture.h"

/* --- the builder --- */

/* mem_grow, for a builder's array: the builder's bytes after the growth are
 * checked against the memory limit first. */
static bool bgrow(mesh_builder *b, void **a, size_t *cap, size_t need, size_t size)
{
	if (need <= *cap)
		return true;
	size_t c = *cap ? *cap : 64;
	while (c < need && c <= SIZE_MAX / 2 / size)
		c *= 2;
	double after = (double)b->bytes + (double)(c - *cap) * (double)size;
	char what[300];
	snprintf(what, sizeof what, "the model %s", b->name ? b->name : "");
	if (!mem_check(after, what, &b->limit)) {
		b->over = true;
		return false;
	}
	size_t old = *cap;
	if (!mem_grow(a, cap, need, size))
		return false;
	b->bytes += (*cap - old) * size;
	return true;
}

const char *mb_failure(const mesh_builder *b)
{
	return read_cancelled() ? "stopped" : b->over ? b->limit.msg : "out of memory";
}

bool mb_vertex(mesh_builder *b, const float p[3])
{
	if (read_poll() || !bgrow(b, (void **)&b->v, &b->cv, b->nv + 1, sizeof *b->v))
		return false;
	memcpy(b->v[b->nv++], p, sizeof *b->v);
	return true;
}

bool mb_uv(mesh_builder *b, const float t[2])
{
	if (read_poll() || !bgrow(b, (void **)&b->vt, &b->cvt, b->nvt + 1, sizeof *b->vt))
		return false;
	memcpy(b->vt[b->nvt++], t, sizeof *b->vt);
	return true;
}

bool mb_normal(mesh_builder *b, const float n[3])
{
	if (read_poll() || !bgrow(b, (void **)&b->vn, &b->cvn, b->nvn + 1, sizeof *b->vn))
		return false;
	memcpy(b->vn[b->nvn++], n, sizeof *b->vn);
	return true;
}

static bool recent_copy(mesh_builder *b, int32_t c[3][3], uint64_t *hash);

bool mb_triangle(mesh_builder *b, int32_t c[3][3])
{
	uint64_t h;
	if (recent_copy(b, c, &h)) {
		b->ndup++;
		return !read_poll();
	}
	if (read_poll() || !bgrow(b, (void **)&b->c, &b->cc, b->nc + 3, sizeof *b->c) ||
	    !bgrow(b, (void **)&b->fm, &b->cf, b->nf + 1, sizeof *b->fm) ||
	    !bgrow(b, (void **)&b->th, &b->cth, b->nf + 1, sizeof *b->th))
		return false;
	b->th[b->nf] = h;
	memcpy(b->c[b->nc], c, 3 * sizeof *b->c);
	b->nc += 3;
	b->fm[b->nf++] = b->cur_mat;
	return true;
}

bool mb_texture(mesh_builder *b, texture *t)
{
	if (!mem_grow((void **)&b->texs, &b->ctexs, b->ntexs + 1, sizeof *b->texs)) {
		texture_free(t);
		return false;
	}
	b->texs[b->ntexs++] = t;
	return true;
}

/* The embedded textures are the mesh's (texs), not the material's. */
static void mat_free(mesh_mat *m)
{
	mem_free_all(m->name, m->map_kd, m->map_bump, m->map_norm, m->map_mr, m->map_emit, m->alpha_map);
}

/* The materials and embedded textures a builder, then its mesh, holds. */
static void mats_texs_free(mesh_mat *mats, size_t nmats, texture **texs, size_t ntexs)
{
	for (size_t i = 0; i < nmats; i++)
		mat_free(&mats[i]);
	free(mats);
	for (size_t i = 0; i < ntexs; i++)
		texture_free(texs[i]);
	free(texs);
}

void mb_free(mesh_builder *b)
{
	mats_texs_free(b->mats, b->nmats, b->texs, b->ntexs);
	mem_free_all(b->v, b->vt, b->vn, b->c, b->fm, b->th, b->warning);
	memset(b, 0, sizeof *b);
}

static uint64_t hash3(const int32_t k[3])
{
	uint64_t h = (uint32_t)k[0] * 0x9E3779B97F4A7C15ull;
	h ^= ((uint64_t)(uint32_t)k[1] + 0x632BE59BD9B4E019ull) * 0xC2B2AE3D27D4EB4Full;
	h ^= ((uint64_t)(uint32_t)k[2] + 0x85EBCA77C2B2AE63ull) * 0x165667B19E3779F9ull;
	/* the whole word into the low bits the table uses (splitmix64's
	 * finaliser): keys that step together, as an STL's corners (k, -1, k)
	 * do, made runs of neighbouring slots and long probes */
	h ^= h >> 30;
	h *= 0xBF58476D1CE4E5B9ull;
	h ^= h >> 27;
	h *= 0x94D049BB133111EBull;
	return h ^ (h >> 31);
}

/* Is the triangle of positions a, b, c of non-zero area? */
static bool tri_ok(const float *a, const float *b, const float *c)
{
	double e1[3], e2[3];
	for (int i = 0; i < 3; i++) {
		e1[i] = (double)b[i] - a[i];
		e2[i] = (double)c[i] - a[i];
	}
	double x = e1[1] * e2[2] - e1[2] * e2[1], y = e1[2] * e2[0] - e1[0] * e2[2],
	       z = e1[0] * e2[1] - e1[1] * e2[0];
	return x * x + y * y + z * z > 0.0;
}

/* --- exact duplicates --- */

/* The corners as the builder holds them: index triples (position, uv,
 * normal) into its arrays; uv and normals count only when every corner
 * has them (has_uv, has_n), as the welding below decides. */
typedef struct corners {
	const mesh_builder *b;
	bool uv, n;
} corners;

/* Two corners with the same position, uv and normal, bit for bit. */
static bool corner_eq(const corners *k, const int32_t *ca, const int32_t *cb)
{
	const mesh_builder *b = k->b;
	return (ca[0] == cb[0] || memcmp(b->v[ca[0]], b->v[cb[0]], sizeof *b->v) == 0) &&
	       (!k->uv || ca[1] == cb[1] || memcmp(b->vt[ca[1]], b->vt[cb[1]], sizeof *b->vt) == 0) &&
	       (!k->n || ca[2] == cb[2] || memcmp(b->vn[ca[2]], b->vn[cb[2]], sizeof *b->vn) == 0);
}

static uint64_t bits2(const float *a, const float *b)
{
	uint32_t x, y;
	memcpy(&x, a, 4);
	memcpy(&y, b, 4);
	return (uint64_t)x | (uint64_t)y << 32;
}

static uint64_t fold(uint64_t h)
{
	h ^= h >> 31;
	h *= 0xBF58476D1CE4E5B9ull;
	return h ^ h >> 29;
}

/* A corner's hash, from its position's values (two corners at the same
 * place, as an STL's are, hash alike; uv and normals are compared, not
 * hashed: a copy has them equal, and a triangle seldom differs from
 * another in them alone). */
static uint64_t corner_hash(const corners *k, const int32_t *c)
{
	const float *p = k->b->v[c[0]];
	uint32_t z;
	memcpy(&z, p + 2, 4);
	uint64_t h = bits2(p, p + 1) * 0x9E3779B97F4A7C15ull + (uint64_t)z * 0xC2B2AE3D27D4EB4Full;
	return h ^ h >> 32;
}

/* A triangle's hash: the sum over its three directed edges of a hash of
 * the edge's two corners' hashes, the same from any corner, another for
 * the mirror-image winding. */
static uint64_t tri_hash(const corners *k, int32_t (*c)[3], uint16_t mat)
{
	uint64_t a = corner_hash(k, c[0]), b = corner_hash(k, c[1]), d = corner_hash(k, c[2]);
	uint64_t e = (a + (b << 17 | b >> 47)) * 0x9E3779B97F4A7C15ull + (b + (d << 17 | d >> 47)) * 0x9E3779B97F4A7C15ull +
	             (d + (a << 17 | a >> 47)) * 0x9E3779B97F4A7C15ull;
	return fold(e + mat);
}

/* Drops the triangles equal to an earlier one: the same three corners
 * (position, uv and normal) in the same turn, from any corner, and the
 * same material. A ray meets a duplicate at the same distance as the one
 * kept, with the same surface, so the picture cannot change; N copies of
 * one face would otherwise make every ray that passes test all N (no tree
 * separates them). A mirror-image winding is another triangle. Done on the
 * builder's corners (ntri triangles, b->c and b->fm compacted), before
 * they are welded, so that the copies cost no vertices. One pass with a
 * hash table (1.5 to 3 slots a triangle, each its index and 32 bits of its
 * hash, so that only a matching hash compares corners), the slots fetched
 * ahead. Returns how many were dropped; none when the memory cannot be
 * had. */
static size_t drop_duplicates(mesh_builder *b, size_t ntri, bool has_uv, bool has_n)
{
	size_t cap = 16;
	if (ntri < 2)
		return 0;
	while (cap < ntri + ntri / 2)
		cap *= 2;
	uint64_t *slot = malloc(cap * sizeof *slot);
	if (!slot)
		return 0;
	memset(slot, 0xff, cap * sizeof *slot);
	const corners k = {b, has_uv, has_n};
	enum { AHEAD = 16 };
	size_t kept = 0;
	for (size_t t = 0; t < ntri; t++) {
		/* the hash mb_triangle made (positions and material: equal
		 * triangles hash alike whatever has_uv and has_n say) */
		uint64_t ht = b->th[t];
		if (t + AHEAD < ntri) /* not moved yet: only up to t are */
			__builtin_prefetch(&slot[b->th[t + AHEAD] & (cap - 1)]);
		int32_t(*tt)[3] = &b->c[3 * t];
		uint32_t tag = (uint32_t)(ht >> 32);
		size_t h = (size_t)ht & (cap - 1);
		bool dup = false;
		while (slot[h] != UINT64_MAX && !dup) {
			uint32_t o = (uint32_t)slot[h];
			if ((uint32_t)(slot[h] >> 32) == tag && b->fm[o] == b->fm[t]) {
				int32_t(*ot)[3] = &b->c[3 * (size_t)o];
				for (int j = 0; j < 3 && !dup; j++)
					dup = corner_eq(&k, tt[0], ot[j]) && corner_eq(&k, tt[1], ot[(j + 1) % 3]) &&
					      corner_eq(&k, tt[2], ot[(j + 2) % 3]);
			}
			if (!dup)
				h = (h + 1) & (cap - 1);
		}
		if (dup)
			continue;
		/* kept: moved down to its place, and found there from now on */
		if (kept != t) {
			memmove(&b->c[3 * kept], tt, 3 * sizeof *tt);
			b->fm[kept] = b->fm[t];
			b->th[kept] = b->th[t];
		}
		slot[h] = (uint64_t)tag << 32 | kept++;
	}
	free(slot);
	return ntri - kept;
}

/* Is triangle c a copy of one of the last triangles kept (b->recent), in
 * the current material? Corners compare by value; a uv or a normal only
 * when both corners have one (the finish compares more loosely, when the
 * mesh keeps none). Else c becomes the one its hash's slot remembers. */
static bool recent_copy(mesh_builder *b, int32_t c[3][3], uint64_t *hash)
{
	*hash = 0; /* out-of-range indices: one hash, the finish compares */
	for (int k = 0; k < 3; k++)
		if (c[k][0] < 0 || (size_t)c[k][0] >= b->nv || c[k][1] >= (int32_t)b->nvt || c[k][2] >= (int32_t)b->nvn)
			return false; /* the reader checks its indices; nothing is assumed here */
	const corners k = {b, false, false};
	uint64_t h = tri_hash(&k, c, b->cur_mat);
	*hash = h;
	uint64_t *slot = &b->recent[h & (sizeof b->recent / sizeof b->recent[0] - 1)];
	uint32_t tag = (uint32_t)(h >> 32);
	if (*slot && (uint32_t)(*slot >> 32) == tag) {
		size_t o = (uint32_t)*slot - 1;
		int32_t(*ot)[3] = &b->c[3 * o];
		if (b->fm[o] == b->cur_mat)
			for (int j = 0; j < 3; j++) {
				bool same = true;
				for (int i = 0; i < 3 && same; i++) {
					const int32_t *x = c[i], *y = ot[(j + i) % 3];
					same = (x[0] == y[0] || memcmp(b->v[x[0]], b->v[y[0]], sizeof *b->v) == 0) &&
					       (x[1] == y[1] || (x[1] >= 0 && y[1] >= 0 && memcmp(b->vt[x[1]], b->vt[y[1]], sizeof *b->vt) == 0)) &&
					       (x[2] == y[2] || (x[2] >= 0 && y[2] >= 0 && memcmp(b->vn[x[2]], b->vn[y[2]], sizeof *b->vn) == 0));
				}
				if (same)
					return true;
			}
	}
	if (b->nf < UINT32_MAX - 1)
		*slot = (uint64_t)tag << 32 | (b->nf + 1);
	return false;
}

mesh *mb_finish(mesh_builder *b, rt_error *err)
{
	mesh *m = calloc(1, sizeof *m);
	size_t ntri = b->nc / 3;
	uint32_t *slot = NULL;
	if (!m)
		goto oom;
	if (ntri > UINT32_MAX / 4 || b->nv > UINT32_MAX / 4) {
		rt_error_set(err, "%s: %zu triangles, %zu vertices: too many (at most %u)", b->name, ntri,
		             b->nv, UINT32_MAX / 4);
		goto fail;
	}
	/* keep the triangles of non-zero area */
	size_t kept = 0;
	for (size_t t = 0; t < ntri; t++) {
		int32_t(*c)[3] = &b->c[3 * t];
		if (!tri_ok(b->v[c[0][0]], b->v[c[1][0]], b->v[c[2][0]]))
			continue;
		memmove(&b->c[3 * kept], c, 3 * sizeof *c);
		b->th[kept] = b->th[t];
		b->fm[kept++] = b->fm[t];
	}
	ntri = kept;
	if (ntri == 0) {
		rt_error_set(err, "%s: the model has no triangle of non-zero area; expected at least one face",
		             b->name);
		goto fail;
	}
	bool plain = true, has_uv = b->nvt > 0, has_n = b->nvn > 0;
	for (size_t i = 0; i < 3 * ntri; i++) {
		if (b->c[i][1] < 0)
			has_uv = false;
		if (b->c[i][2] < 0)
			has_n = false;
	}
	plain = !has_uv && !has_n;
	size_t dups = drop_duplicates(b, ntri, has_uv, has_n), dropped = b->ndup + dups;
	ntri -= dups;
	m->ntris = (uint32_t)ntri;
	m->tri = malloc(ntri * sizeof *m->tri);
	if (!m->tri)
		goto oom;
	if (plain) {
		/* the positions are the vertices */
		m->nverts = (uint32_t)b->nv;
		m->p = b->v;
		b->v = NULL;
		for (size_t t = 0; t < ntri; t++)
			for (int k = 0; k < 3; k++)
				m->tri[t][k] = (uint32_t)b->c[3 * t + k][0];
	} else {
		/* weld equal (position, uv, normal) triples into one vertex */
		size_t cap = 16;
		while (cap < 4 * ntri)
			cap *= 2;
		slot = malloc(cap * sizeof *slot);
		m->p = malloc(3 * ntri * sizeof *m->p);
		if (has_uv)
			m->uv = malloc(3 * ntri * sizeof *m->uv);
		if (has_n)
			m->n = malloc(3 * ntri * sizeof *m->n);
		if (!slot || !m->p || (has_uv && !m->uv) || (has_n && !m->n))
			goto oom;
		memset(slot, 0xff, cap * sizeof *slot);
		uint32_t nv = 0;
		/* the slot of the corner WELD_AHEAD on is fetched now: the table
		 * (4 to 8 slots a triangle) outgrows the caches, and the walk
		 * would otherwise wait on memory at every corner */
		enum { WELD_AHEAD = 32 };
		for (size_t i = 0; i < 3 * ntri; i++) {
			if (i + WELD_AHEAD < 3 * ntri) {
				const int32_t *a = b->c[i + WELD_AHEAD];
				int32_t ka[3] = {a[0], has_uv ? a[1] : -1, has_n ? a[2] : -1};
				__builtin_prefetch(&slot[(size_t)hash3(ka) & (cap - 1)]);
			}
			int32_t key[3] = {b->c[i][0], has_uv ? b->c[i][1] : -1, has_n ? b->c[i][2] : -1};
			size_t h = (size_t)hash3(key) & (cap - 1);
			uint32_t found = UINT32_MAX;
			while (slot[h] != UINT32_MAX) {
				uint32_t s = slot[h];
				const int32_t *o = b->c[s];
				if (o[0] == key[0] && (!has_uv || o[1] == key[1]) && (!has_n || o[2] == key[2])) {
					found = m->tri[s / 3][s % 3];
					break;
				}
				h = (h + 1) & (cap - 1);
			}
			if (found == UINT32_MAX) {
				slot[h] = (uint32_t)i;
				found = nv++;
				memcpy(m->p[found], b->v[key[0]], sizeof *m->p);
				if (has_uv)
					memcpy(m->uv[found], b->vt[key[1]], sizeof *m->uv);
				if (has_n) {
					const float *n = b->vn[key[2]];
					double l = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
					for (int k = 0; k < 3; k++)
						m->n[found][k] = l > 0 ? (float)(n[k] / l) : 0.0f;
				}
			}
			m->tri[i / 3][i % 3] = found;
		}
		m->nverts = nv;
		free(slot);
		slot = NULL;
	}
	if (dropped && !b->warning) {
		char msg[RT_ERROR_FILE_MAX + 128];
		snprintf(msg, sizeof msg, "%s: %zu duplicate triangle%s dropped (the same corners and material as another)",
		         b->name, dropped, dropped == 1 ? "" : "s");
		b->warning = strdup(msg); /* NULL: not said, no harm */
	}
	m->nmats = (uint32_t)b->nmats;
	m->mats = b->mats;
	b->mats = NULL;
	b->nmats = 0;
	m->ntexs = (uint32_t)b->ntexs;
	m->texs = b->texs;
	b->texs = NULL;
	b->ntexs = 0;
	m->warning = b->warning;
	b->warning = NULL;
	if (m->nmats > 1) {
		m->tmat = b->fm;
		b->fm = NULL;
	}
	/* Model files are right-handed (OBJ, PLY, glTF and STL alike); the scene
	 * frame is left-handed (looking down +Z, +X is on the right). Mirroring X
	 * makes a model look as it does in the tools that made it; swapping two
	 * corners keeps each face's geometric normal on the side it faced. */
	for (uint32_t i = 0; i < m->nverts; i++) {
		m->p[i][0] = -m->p[i][0];
		if (m->n)
			m->n[i][0] = -m->n[i][0];
	}
	for (uint32_t t = 0; t < m->ntris; t++) {
		uint32_t k = m->tri[t][1];
		m->tri[t][1] = m->tri[t][2];
		m->tri[t][2] = k;
	}
	m->bounds = box_empty();
	for (uint32_t i = 0; i < m->nverts; i++)
		m->bounds = box_add(m->bounds, v3(m->p[i][0], m->p[i][1], m->p[i][2]));
	mb_free(b);
	return m;
oom:
	rt_error_set(err, "%s: out of memory reading the model", b->name);
fail:
	free(slot);
	mb_free(b);
	mesh_free(m);
	return NULL;
}

void mesh_free(mesh *m)
{
	if (!m)
		return;
	mats_texs_free(m->mats, m->nmats, m->texs, m->ntexs);
	mem_free_all(m->path, m->p, m->n, m->uv, m->tri, m->tmat, m->warning, m->nodes, m->blk, m->btri, m);
}

static size_t tex_bytes(const texture *t)
{
	size_t n = 0;
	for (int l = 0; t && l < t->nlevels; l++)
		n += (size_t)t->level[l].w * (size_t)t->level[l].h * 3 * sizeof(float);
	return n;
}

size_t mesh_memory(const mesh *m)
{
	size_t n = sizeof *m;
	if (m->tri)
		n += (size_t)m->ntris * sizeof *m->tri;
	if (m->p)
		n += (size_t)m->nverts * sizeof *m->p;
	if (m->n)
		n += (size_t)m->nverts * sizeof *m->n;
	if (m->uv)
		n += (size_t)m->nverts * sizeof *m->uv;
	if (m->tmat)
		n += (size_t)m->ntris * sizeof *m->tmat;
	n += (size_t)m->nnodes * sizeof *m->nodes;
	n += (size_t)m->nblk * (sizeof *m->blk + sizeof *m->btri);
	for (uint32_t i = 0; i < m->ntexs; i++)
		n += tex_bytes(m->texs[i]);
	for (uint32_t i = 0; i < m->nmats; i++)
		if (m->mats[i].alpha_map)
			n += (size_t)m->mats[i].alpha_w * (size_t)m->mats[i].alpha_h;
	return n;
}

/* --- normals --- */

static vec3 vtx(const mesh *m, uint32_t i)
{
	return v3(m->p[i][0], m->p[i][1], m->p[i][2]);
}

/* The slot of (vertex v, normal n) in the open-addressed table slot[cap]
 * of corner numbers: the corner there has this vertex and normal, or the
 * slot is free (UINT32_MAX). */
static size_t normal_slot(const uint32_t *slot, size_t cap, const mesh *m, const float (*nn)[3], uint32_t v,
                          const float n[3])
{
	uint32_t bits[3];
	memcpy(bits, n, sizeof bits);
	int32_t key[3] = {(int32_t)(v ^ bits[2] * 0x9E3779B1u), (int32_t)bits[0], (int32_t)bits[1]};
	size_t h = (size_t)hash3(key) & (cap - 1);
	while (slot[h] != UINT32_MAX &&
	       !(m->tri[slot[h] / 3][slot[h] % 3] == v && memcmp(nn[slot[h]], n, sizeof *nn) == 0))
		h = (h + 1) & (cap - 1);
	return h;
}

/* Smooth normals weighted by corner angle (Thürmer & Wüthrich, "Computing
 * vertex normals from polygonal facets", 1998), a face contributing to a
 * corner only when it meets the corner's face at no more than the crease
 * angle; corners of one position with different normals become different
 * vertices.
 *
 * Linear in the corners (issue 31): each corner's angle is computed once; a
 * vertex of more than CREASE_DEG_MAX faces ignores the crease, so its sum
 * is one sum for all its corners; a vertex of fewer compares each corner's
 * face with the others, at most CREASE_DEG_MAX comparisons a corner; and
 * corners of equal vertex and normal find each other through a hash table,
 * not by comparing every pair. */
#define CREASE_DEG_MAX 256
static bool smooth_normals(mesh *m, double crease_deg, const atomic_bool *cancel, rt_error *err)
{
	uint32_t nv = m->nverts, nt = m->ntris;
	size_t cap = 16;
	while (cap < 6 * (size_t)nt)
		cap *= 2;
	vec3 *fn = malloc((size_t)nt * sizeof *fn);
	uint32_t *start = calloc((size_t)nv + 1, sizeof *start);
	uint32_t *list = malloc((size_t)nt * 3 * sizeof *list);
	uint32_t *newid = malloc((size_t)nt * 3 * sizeof *newid);
	double *ang = malloc((size_t)nt * 3 * sizeof *ang);
	uint32_t *slot = malloc(cap * sizeof *slot);
	float(*nn)[3] = malloc((size_t)nt * 3 * sizeof *nn);
	bool stopped = false;
	if (!fn || !start || !list || !newid || !ang || !slot || !nn)
		goto fail;
	memset(slot, 0xff, cap * sizeof *slot);
	for (uint32_t t = 0; t < nt; t++) {
		vec3 a = vtx(m, m->tri[t][0]), b = vtx(m, m->tri[t][1]), c = vtx(m, m->tri[t][2]);
		vec3 n = v3_cross(v3_sub(b, a), v3_sub(c, a));
		double l = v3_len(n);
		fn[t] = l > 0 ? v3_scale(n, 1.0 / l) : v3(0, 0, 0);
		for (int k = 0; k < 3; k++) {
			start[m->tri[t][k] + 1]++;
			/* the corner's angle */
			vec3 p = vtx(m, m->tri[t][k]);
			vec3 e1 = v3_sub(vtx(m, m->tri[t][(k + 1) % 3]), p);
			vec3 e2 = v3_sub(vtx(m, m->tri[t][(k + 2) % 3]), p);
			double la = v3_len(e1), lb = v3_len(e2);
			ang[3 * t + k] = la > 0 && lb > 0 ? acos(clampd(v3_dot(e1, e2) / (la * lb), -1, 1)) : 0;
		}
	}
	for (uint32_t v = 0; v < nv; v++)
		start[v + 1] += start[v];
	{
		uint32_t *fill = malloc((size_t)nv * sizeof *fill);
		if (!fill)
			goto fail;
		memcpy(fill, start, (size_t)nv * sizeof *fill);
		for (uint32_t t = 0; t < nt; t++)
			for (uint32_t k = 0; k < 3; k++)
				list[fill[m->tri[t][k]]++] = 3 * t + k;
		free(fill);
	}
	double cosc = cos(crease_deg * M_PI / 180.0) - 1e-9;
	uint32_t next = nv;
	for (uint32_t v = 0; v < nv; v++) {
		uint32_t s = start[v], e = start[v + 1], deg = e - s;
		if ((v & 0xffff) == 0 && cancel && atomic_load_explicit(cancel, memory_order_relaxed)) {
			stopped = true;
			goto fail;
		}
		vec3 all = v3(0, 0, 0); /* the sum of every face, when the crease is ignored */
		if (deg > CREASE_DEG_MAX)
			for (uint32_t j = s; j < e; j++)
				all = v3_madd(all, fn[list[j] / 3], ang[list[j]]);
		for (uint32_t i = s; i < e; i++) {
			uint32_t ci = list[i], ti = ci / 3;
			vec3 sum = all;
			if (deg <= CREASE_DEG_MAX)
				for (uint32_t j = s; j < e; j++) {
					uint32_t cj = list[j], tj = cj / 3;
					if (v3_dot(fn[ti], fn[tj]) >= cosc)
						sum = v3_madd(sum, fn[tj], ang[cj]);
				}
			double l = v3_len(sum);
			vec3 n = l > 0 ? v3_scale(sum, 1.0 / l) : fn[ti];
			nn[ci][0] = (float)n.x;
			nn[ci][1] = (float)n.y;
			nn[ci][2] = (float)n.z;
			/* the same vertex as an earlier corner with this normal */
			size_t h = normal_slot(slot, cap, m, (const float(*)[3])nn, v, nn[ci]);
			if (slot[h] != UINT32_MAX) {
				newid[ci] = newid[slot[h]];
			} else {
				slot[h] = ci;
				newid[ci] = i == s ? v : next++;
			}
		}
	}
	free(slot);
	slot = NULL;
	free(ang);
	ang = NULL;
	float(*p)[3] = malloc((size_t)next * sizeof *p);
	float(*n)[3] = malloc((size_t)next * sizeof *n);
	float(*uv)[2] = m->uv ? malloc((size_t)next * sizeof *uv) : NULL;
	if (!p || !n || (m->uv && !uv)) {
		free(p);
		free(n);
		free(uv);
		goto fail;
	}
	for (uint32_t v = 0; v < nv; v++) {
		memcpy(p[v], m->p[v], sizeof *p);
		memset(n[v], 0, sizeof *n);
		if (uv)
			memcpy(uv[v], m->uv[v], sizeof *uv);
	}
	for (uint32_t c = 0; c < 3 * nt; c++) {
		uint32_t old = m->tri[c / 3][c % 3], id = newid[c];
		memcpy(p[id], m->p[old], sizeof *p);
		memcpy(n[id], nn[c], sizeof *n);
		if (uv)
			memcpy(uv[id], m->uv[old], sizeof *uv);
		m->tri[c / 3][c % 3] = id;
	}
	free(m->p);
	free(m->uv);
	m->p = p;
	m->n = n;
	m->uv = uv;
	m->nverts = next;
	mem_free_all(fn, start, list, newid, nn);
	return true;
fail:
	mem_free_all(fn, start, list, newid, ang, slot, nn);
	if (stopped)
		return rt_error_set(err, "stopped");
	return rt_error_set(err, "%s: out of memory computing normals", m->path ? m->path : "mesh");
}

bool mesh_prepare(mesh *m, bool smooth, double crease_deg, rt_error *err)
{
	return mesh_prepare_cancel(m, smooth, crease_deg, NULL, err);
}

/* Numbers the n items that the count indices in idx name in the order the
 * indices first use them, the unused ones after in their own order; idx is
 * rewritten to the new numbers, and the arrays *a and *b (n items of asize
 * and bsize bytes; either may be NULL) are permuted to match. With memory
 * short nothing changes (the order is only for speed). */
static void renumber_by_first_use(uint32_t *idx, size_t count, uint32_t n, void **a, size_t asize, void **b,
                                  size_t bsize)
{
	uint32_t *new_of = malloc((size_t)n * sizeof *new_of);
	char *na = *a ? malloc((size_t)n * asize) : NULL, *nb = *b ? malloc((size_t)n * bsize) : NULL;
	if (!new_of || (*a && !na) || (*b && !nb)) {
		free(new_of);
		free(na);
		free(nb);
		return;
	}
	memset(new_of, 0xff, (size_t)n * sizeof *new_of);
	uint32_t next = 0;
	for (size_t j = 0; j < count; j++) {
		uint32_t v = idx[j];
		if (new_of[v] == UINT32_MAX)
			new_of[v] = next++;
		idx[j] = new_of[v];
	}
	for (uint32_t v = 0; v < n; v++) {
		if (new_of[v] == UINT32_MAX)
			new_of[v] = next++; /* triangles: in no leaf (none is); vertices: unused */
		if (na)
			memcpy(na + (size_t)new_of[v] * asize, (const char *)*a + (size_t)v * asize, asize);
		if (nb)
			memcpy(nb + (size_t)new_of[v] * bsize, (const char *)*b + (size_t)v * bsize, bsize);
	}
	free(*a);
	free(*b);
	*a = na;
	*b = nb;
	free(new_of);
}

bool mesh_prepare_cancel(mesh *m, bool smooth, double crease_deg, const atomic_bool *cancel, rt_error *err)
{
	char what[300];
	snprintf(what, sizeof what, "the model %s (%u triangles)", m->path ? m->path : "", m->ntris);
	if (!mem_check((double)m->ntris * MESH_PREPARE_BYTES, what, err))
		return false;
	if (!smooth) {
		free(m->n);
		m->n = NULL;
	} else if (!m->n && !smooth_normals(m, crease_deg, cancel, err)) {
		return false;
	}
	if (!mesh_build_tree(m, cancel, err))
		return false;
	/* triangles, then vertices, in the order the blocks first use them, so
	 * that shading a leaf's triangles finds their data close together */
	if (m->nblk)
		renumber_by_first_use(&m->btri[0][0], (size_t)m->nblk * 4, m->ntris, (void **)&m->tri, sizeof *m->tri,
		                      (void **)&m->tmat, sizeof *m->tmat);
	renumber_by_first_use(&m->tri[0][0], (size_t)m->ntris * 3, m->nverts, (void **)&m->n, sizeof *m->n,
	                      (void **)&m->uv, sizeof *m->uv);
	/* the blocks hold the positions from now on, and the corners' indices
	 * serve only to interpolate normals and uv */
	free(m->p);
	m->p = NULL;
	if (!m->n && !m->uv) {
		free(m->tri);
		m->tri = NULL;
	}
	double ext = fmax(v3_max_abs(m->bounds.lo), v3_max_abs(m->bounds.hi));
	m->eps = (float)(ext * 0x1p-19);
	return true;
}

/* --- surface --- */

void mesh_surface(const mesh *m, uint32_t slot, const float b[3], mesh_surf *s)
{
	vec3 pc[3];
	mesh_corners(m, slot, pc);
	vec3 e1 = v3_sub(pc[1], pc[0]), e2 = v3_sub(pc[2], pc[0]);
	s->ng = v3_cross(e1, e2);
	s->ns = s->ng;
	s->u = s->v = 0;
	s->dpdu = s->dpdv = s->shift = v3(0, 0, 0);
	uint32_t t = mesh_slot_tri(m, slot);
	s->mat = m->nmats == 0 ? -1 : m->tmat ? m->tmat[t] : 0;
	if (!m->tri)
		return; /* neither normals nor uv */
	const uint32_t *i = m->tri[t];
	if (m->n) {
		vec3 n = v3(0, 0, 0);
		for (int k = 0; k < 3; k++)
			n = v3_madd(n, v3(m->n[i[k]][0], m->n[i[k]][1], m->n[i[k]][2]), b[k]);
		/* a normal on the far side of the face would shade it black */
		if (v3_dot(n, n) > 0)
			s->ns = v3_dot(n, s->ng) >= 0 ? n : v3_neg(n);
		/* the shadow terminator (mesh_surf.shift): p' = p + sum_k b_k
		 * max(0, -(p - p_k).n_k) n_k, each corner's normal on the side of
		 * the face the interpolated one is on */
		vec3 p = v3(0, 0, 0);
		for (int k = 0; k < 3; k++)
			p = v3_madd(p, pc[k], b[k]);
		for (int k = 0; k < 3; k++) {
			vec3 nk = v3(m->n[i[k]][0], m->n[i[k]][1], m->n[i[k]][2]);
			double l = v3_len(nk);
			if (!(l > 0))
				continue;
			nk = v3_scale(nk, (v3_dot(nk, s->ns) >= 0 ? 1.0 : -1.0) / l);
			double d = v3_dot(v3_sub(p, pc[k]), nk);
			if (d < 0)
				s->shift = v3_madd(s->shift, nk, -d * b[k]);
		}
	}
	if (m->uv) {
		const float *a = m->uv[i[0]], *bb = m->uv[i[1]], *c = m->uv[i[2]];
		s->u = b[0] * a[0] + b[1] * bb[0] + b[2] * c[0];
		s->v = b[0] * a[1] + b[1] * bb[1] + b[2] * c[1];
		double du1 = bb[0] - a[0], dv1 = bb[1] - a[1], du2 = c[0] - a[0], dv2 = c[1] - a[1];
		double det = du1 * dv2 - dv1 * du2;
		if (det != 0.0) {
			s->dpdu = v3_scale(v3_sub(v3_scale(e1, dv2), v3_scale(e2, dv1)), 1.0 / det);
			s->dpdv = v3_scale(v3_sub(v3_scale(e2, du1), v3_scale(e1, du2)), 1.0 / det);
		}
	}
}

/* --- alpha coverage (glTF alphaMode MASK) --- */

/* Texel index i of n along an axis, by the sampler's wrap mode. */
static long wrap_texel(long i, long n, int mode)
{
	if (mode == MESH_WRAP_CLAMP)
		return i < 0 ? 0 : i >= n ? n - 1 : i;
	if (mode == MESH_WRAP_MIRROR) {
		long k = i % (2 * n);
		k = k < 0 ? k + 2 * n : k;
		return k < n ? k : 2 * n - 1 - k;
	}
	long k = i % n;
	return k < 0 ? k + n : k;
}

/* A texel coordinate (texel centres at integers) brought near the image,
 * where floor() and the wrap are exact: by the wrap's period, or clamped. */
static double wrap_coord(double x, long n, int mode)
{
	if (mode == MESH_WRAP_CLAMP)
		return x < -1.0 ? -1.0 : x > (double)n ? (double)n : x;
	return fmod(x, mode == MESH_WRAP_MIRROR ? 2.0 * (double)n : (double)n);
}

/* The bilinear alpha of the map at (u, v), v up (texture.c's texel
 * centres: x = u w - 1/2, y = (1 - v) h - 1/2). */
static double alpha_at(const mesh_mat *mm, double u, double v)
{
	long w = mm->alpha_w, h = mm->alpha_h;
	double x = u * (double)w - 0.5, y = (1.0 - v) * (double)h - 0.5;
	if (!isfinite(x) || !isfinite(y))
		return 0.0;
	x = wrap_coord(x, w, mm->alpha_wrap[0]);
	y = wrap_coord(y, h, mm->alpha_wrap[1]);
	double fx = floor(x), fy = floor(y), ax = x - fx, ay = y - fy;
	long x0 = wrap_texel((long)fx, w, mm->alpha_wrap[0]), x1 = wrap_texel((long)fx + 1, w, mm->alpha_wrap[0]);
	long y0 = wrap_texel((long)fy, h, mm->alpha_wrap[1]), y1 = wrap_texel((long)fy + 1, h, mm->alpha_wrap[1]);
	const unsigned char *a = mm->alpha_map;
	double a00 = a[(size_t)y0 * (size_t)w + (size_t)x0], a10 = a[(size_t)y0 * (size_t)w + (size_t)x1];
	double a01 = a[(size_t)y1 * (size_t)w + (size_t)x0], a11 = a[(size_t)y1 * (size_t)w + (size_t)x1];
	return ((1 - ay) * ((1 - ax) * a00 + ax * a10) + ay * ((1 - ax) * a01 + ax * a11)) / 255.0;
}

static _Thread_local bool alpha_hashed;

void mesh_alpha_hashed(bool on)
{
	alpha_hashed = on;
}

/* A number in [0, 1) of the hit (its triangle, not its slot: a leaf's
 * lanes that repeat a triangle must draw the same, and the bits of its
 * barycentrics): as good as random from one ray to the next, the same for
 * the same point (splitmix64's finaliser). */
static double hit_hash(uint32_t tri, const float b[3])
{
	uint32_t x, y, z;
	memcpy(&x, &b[0], 4);
	memcpy(&y, &b[1], 4);
	memcpy(&z, &b[2], 4);
	uint64_t h = ((uint64_t)x << 32 | y) ^ ((uint64_t)z << 32 | tri) * 0x9E3779B97F4A7C15ull;
	h = (h ^ (h >> 30)) * 0xBF58476D1CE4E5B9ull;
	h = (h ^ (h >> 27)) * 0x94D049BB133111EBull;
	h ^= h >> 31;
	return (double)(h >> 11) * 0x1p-53;
}

bool mesh_cut_hole(const mesh *m, uint32_t slot, const float b[3])
{
	if (m->nmats == 0)
		return false;
	uint32_t t = mesh_slot_tri(m, slot);
	const mesh_mat *mm = &m->mats[m->tmat ? m->tmat[t] : 0];
	if (mm->alpha_mode == MESH_ALPHA_OPAQUE)
		return false;
	double a = mm->alpha;
	if (mm->alpha_map) {
		/* the hit's uv as mesh_surface interpolates it (none: 0, 0), then
		 * the base colour texture's KHR_texture_transform (surface.c) */
		double u = 0, v = 0;
		if (m->tri && m->uv) {
			const uint32_t *i = m->tri[t];
			const float *pa = m->uv[i[0]], *pb = m->uv[i[1]], *pc = m->uv[i[2]];
			u = b[0] * pa[0] + b[1] * pb[0] + b[2] * pc[0];
			v = b[0] * pa[1] + b[1] * pb[1] + b[2] * pc[1];
		}
		double tu = u * mm->uvs[0] + mm->uvo[0] + v * mm->uvx[0];
		double tv = v * mm->uvs[1] + mm->uvo[1] + u * mm->uvx[1];
		a *= alpha_at(mm, tu, tv);
	}
	if (mm->alpha_mode == MESH_ALPHA_BLEND) /* see through by alpha, or MASK at 0.5 */
		return a < (alpha_hashed ? hit_hash(t, b) : 0.5);
	return a < mm->alpha_cutoff;
}

unsigned mesh_cut_lanes(const mesh *m, uint32_t blk, unsigned lanes, const float u[4], const float v[4],
                        const float w[4], const float inv[4])
{
	for (unsigned rest = lanes; rest; rest &= rest - 1) {
		int l = __builtin_ctz(rest);
		float b[3] = {u[l] * inv[l], v[l] * inv[l], w[l] * inv[l]};
		if (mesh_cut_hole(m, 4 * blk + (uint32_t)l, b))
			lanes &= ~(1u << l);
	}
	return lanes;
}
