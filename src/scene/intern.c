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

/* A set of byte strings kept for ever: open addressing, its capacity a
 * power of two at most half full, guarded by its mutex. Each kept copy has
 * a NUL after its bytes; `fixed` is the size of every entry (records), or 0
 * for NUL-free strings, whose length is strlen's. */
typedef struct intern_set {
	pthread_mutex_t lock;
	char **tab;
	size_t n, cap;
	size_t fixed;
} intern_set;

static uint64_t hash(const char *s, size_t n)
{
	uint64_t h = 1469598103934665603ull; /* FNV-1a */
	for (size_t i = 0; i < n; i++)
		h = (h ^ (unsigned char)s[i]) * 1099511628211ull;
	return h;
}

static size_t entry_len(const intern_set *set, const char *e)
{
	return set->fixed ? set->fixed : strlen(e);
}

static void insert(const intern_set *set, char **tab, size_t c, char *e)
{
	size_t i = (size_t)hash(e, entry_len(set, e)) & (c - 1);
	while (tab[i])
		i = (i + 1) & (c - 1);
	tab[i] = e;
}

/* The kept copy of the n bytes at p (kept now when new), or NULL when out
 * of memory. */
static const char *set_intern(intern_set *set, const char *p, size_t n)
{
	pthread_mutex_lock(&set->lock);
	const char *out = NULL;
	if (set->cap) {
		size_t i = (size_t)hash(p, n) & (set->cap - 1);
		while (set->tab[i]) {
			if (entry_len(set, set->tab[i]) == n && memcmp(set->tab[i], p, n) == 0) {
				out = set->tab[i];
				break;
			}
			i = (i + 1) & (set->cap - 1);
		}
	}
	if (!out && 2 * (set->n + 1) > set->cap) {
		size_t c = set->cap ? 2 * set->cap : 64;
		char **t = calloc(c, sizeof *t);
		if (t) {
			for (size_t i = 0; i < set->cap; i++)
				if (set->tab[i])
					insert(set, t, c, set->tab[i]);
			free(set->tab);
			set->tab = t;
			set->cap = c;
		}
	}
	if (!out && 2 * (set->n + 1) <= set->cap) {
		char *d = mem_dupz(p, n);
		if (d) {
			insert(set, set->tab, set->cap, d);
			set->n++;
			out = d;
		}
	}
	pthread_mutex_unlock(&set->lock);
	return out;
}

static intern_set names = {PTHREAD_MUTEX_INITIALIZER, NULL, 0, 0, 0};

const char *rt_intern(const char *s, size_t n)
{
	if (memchr(s, '\0', n))
		n = strlen(s);
	return set_intern(&names, s, n);
}

/* The PBR blocks of materials (scene.h): the same idea for a fixed-size
 * record, compared by its bytes (every -0 made +0 first). */
static intern_set pbrs = {PTHREAD_MUTEX_INITIALIZER, NULL, 0, 0, sizeof(material_pbr)};

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
	const material_pbr *out = (const material_pbr *)(const void *)set_intern(&pbrs, (const char *)&p, sizeof p);
	if (!out && oom)
		*oom = true;
	return out;
}
