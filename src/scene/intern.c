/* rtsh — interned strings (scene.h, rt_intern): file names in objects.
 *
 * A hash set of strings that are never freed, guarded by a mutex: the few
 * model and texture names a session sees cost a few bytes each, and in
 * exchange an object with a file name is still a plain value. */
#include <pthread.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "rtsh/memory.h"
#include "rtsh/scene.h"

static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static char **set;
static size_t nset, cap; /* cap a power of two, at most half full */

static uint64_t hash(const char *s, size_t n)
{
	uint64_t h = 1469598103934665603ull; /* FNV-1a */
	for (size_t i = 0; i < n; i++)
		h = (h ^ (unsigned char)s[i]) * 1099511628211ull;
	return h;
}

static bool insert(char **tab, size_t c, char *s)
{
	size_t i = (size_t)hash(s, strlen(s)) & (c - 1);
	while (tab[i])
		i = (i + 1) & (c - 1);
	tab[i] = s;
	return true;
}

const char *rt_intern(const char *s, size_t n)
{
	if (memchr(s, '\0', n))
		n = strlen(s);
	pthread_mutex_lock(&lock);
	const char *out = NULL;
	if (cap) {
		size_t i = (size_t)hash(s, n) & (cap - 1);
		while (set[i]) {
			if (strlen(set[i]) == n && memcmp(set[i], s, n) == 0) {
				out = set[i];
				break;
			}
			i = (i + 1) & (cap - 1);
		}
	}
	if (!out && 2 * (nset + 1) > cap) {
		size_t c = cap ? 2 * cap : 64;
		char **t = calloc(c, sizeof *t);
		if (t) {
			for (size_t i = 0; i < cap; i++)
				if (set[i])
					insert(t, c, set[i]);
			free(set);
			set = t;
			cap = c;
		}
	}
	if (!out && 2 * (nset + 1) <= cap) {
		char *d = mem_dupz(s, n);
		if (d) {
			insert(set, cap, d);
			nset++;
			out = d;
		}
	}
	pthread_mutex_unlock(&lock);
	return out;
}

/* The PBR blocks of materials (scene.h): the same idea for a fixed-size
 * record, compared by its bytes (every -0 made +0 first). */
static pthread_mutex_t pbr_lock = PTHREAD_MUTEX_INITIALIZER;
static material_pbr **pbr_set;
static size_t pbr_n, pbr_cap;

static uint64_t pbr_hash(const material_pbr *p)
{
	return hash((const char *)p, sizeof *p);
}

static void pbr_insert(material_pbr **tab, size_t c, material_pbr *p)
{
	size_t i = (size_t)pbr_hash(p) & (c - 1);
	while (tab[i])
		i = (i + 1) & (c - 1);
	tab[i] = p;
}

const material_pbr *material_pbr_intern(const material_pbr *in, bool *oom)
{
	/* a copy with no padding garbage and no negative zeros */
	material_pbr p;
	memset(&p, 0, sizeof p);
	p.roughness = in->roughness + 0.0;
	p.metallic = in->metallic + 0.0;
	p.transmission = in->transmission + 0.0;
	p.thin = in->thin;
	p.att_color = v3(in->att_color.x + 0.0, in->att_color.y + 0.0, in->att_color.z + 0.0);
	p.att_dist = in->att_dist + 0.0;
	p.clearcoat = in->clearcoat + 0.0;
	p.clearcoat_roughness = in->clearcoat_roughness + 0.0;
	p.specular_factor = in->specular_factor + 0.0;
	p.specular_color = v3(in->specular_color.x + 0.0, in->specular_color.y + 0.0, in->specular_color.z + 0.0);
	p.emit_color = v3(in->emit_color.x + 0.0, in->emit_color.y + 0.0, in->emit_color.z + 0.0);
	p.multiscatter = in->multiscatter;
	material_pbr absent;
	memset(&absent, 0, sizeof absent);
	material_pbr a = material_pbr_absent();
	absent.roughness = a.roughness;
	absent.att_color = a.att_color;
	absent.specular_factor = a.specular_factor;
	absent.specular_color = a.specular_color;
	absent.emit_color = a.emit_color;
	absent.multiscatter = a.multiscatter;
	if (memcmp(&p, &absent, sizeof p) == 0)
		return NULL;
	pthread_mutex_lock(&pbr_lock);
	const material_pbr *out = NULL;
	if (pbr_cap) {
		size_t i = (size_t)pbr_hash(&p) & (pbr_cap - 1);
		while (pbr_set[i]) {
			if (memcmp(pbr_set[i], &p, sizeof p) == 0) {
				out = pbr_set[i];
				break;
			}
			i = (i + 1) & (pbr_cap - 1);
		}
	}
	if (!out && 2 * (pbr_n + 1) > pbr_cap) {
		size_t c = pbr_cap ? 2 * pbr_cap : 64;
		material_pbr **t = calloc(c, sizeof *t);
		if (t) {
			for (size_t i = 0; i < pbr_cap; i++)
				if (pbr_set[i])
					pbr_insert(t, c, pbr_set[i]);
			free(pbr_set);
			pbr_set = t;
			pbr_cap = c;
		}
	}
	if (!out && 2 * (pbr_n + 1) <= pbr_cap) {
		material_pbr *d = malloc(sizeof *d);
		if (d) {
			*d = p;
			pbr_insert(pbr_set, pbr_cap, d);
			pbr_n++;
			out = d;
		}
	}
	pthread_mutex_unlock(&pbr_lock);
	if (!out && oom)
		*oom = true;
	return out;
}
