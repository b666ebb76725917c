/* rtsh — memory estimates, and growing arrays (memory.h). */
#include "rtsh/memory.h"

#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>

static _Atomic size_t set_limit;
/* What the editors hold (mem_hold): bytes and scenes. */
static _Atomic long long held_bytes;
static _Atomic long held_scenes;

void mem_hold(double bytes, long scenes)
{
	atomic_fetch_add(&held_bytes, (long long)bytes);
	atomic_fetch_add(&held_scenes, scenes);
}

double mem_held(long *scenes)
{
	if (scenes)
		*scenes = atomic_load(&held_scenes);
	long long b = atomic_load(&held_bytes);
	return b > 0 ? (double)b : 0;
}

void mem_set_limit(size_t bytes)
{
	atomic_store(&set_limit, bytes);
}

double mem_limit(const char **why)
{
	double best = 1e300;
	const char *by = "no limit";
	long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
	if (pages > 0 && page > 0) {
		best = (double)pages * (double)page;
		by = "physical memory";
	}
	static const struct {
		int res;
		const char *name;
	} limits[] = {{RLIMIT_AS, "RLIMIT_AS"}, {RLIMIT_DATA, "RLIMIT_DATA"}};
	for (size_t i = 0; i < sizeof limits / sizeof limits[0]; i++) {
		struct rlimit rl;
		if (getrlimit(limits[i].res, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY &&
		    (double)rl.rlim_cur < best) {
			best = (double)rl.rlim_cur;
			by = limits[i].name;
		}
	}
	size_t cap = atomic_load(&set_limit);
	if (cap && (double)cap < best) {
		best = (double)cap;
		by = "the set limit";
	}
	if (why)
		*why = by;
	return best;
}

/* "1.5 GiB", "300 MiB", "12 KiB". */
static void human(double bytes, char *buf, size_t size)
{
	static const char *unit[] = {"bytes", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
	int u = 0;
	while (bytes >= 1024 && u < 6) {
		bytes /= 1024;
		u++;
	}
	snprintf(buf, size, u && bytes < 10 ? "%.1f %s" : "%.0f %s", bytes, unit[u]);
}

bool mem_check(double bytes, const char *what, rt_error *err)
{
	const char *why;
	double limit = mem_limit(&why);
	long scenes;
	double held = mem_held(&scenes);
	if (!(bytes + held > limit))
		return true;
	char need[32], have[32], kept[32];
	human(bytes, need, sizeof need);
	human(limit, have, sizeof have);
	/* What is held is named only when it is why the request is refused. */
	if (held <= 0 || bytes > limit)
		return rt_error_set(err, "%s needs about %s of memory; expected at most %s (%s)", what, need, have, why);
	human(held, kept, sizeof kept);
	return rt_error_set(err,
	                    "%s needs about %s of memory on top of the %s held by %ld scene%s (the current one and "
	                    "those kept for undo); expected at most %s in all (%s)",
	                    what, need, kept, scenes, scenes == 1 ? "" : "s", have, why);
}

bool mem_grow(void **a, size_t *cap, size_t need, size_t size)
{
	if (need <= *cap)
		return true;
	size_t c = *cap ? *cap : 64;
	while (c < need) {
		if (c > SIZE_MAX / 2 / size)
			return false;
		c *= 2;
	}
	void *p = realloc(*a, c * size);
	if (!p)
		return false;
	*a = p;
	*cap = c;
	return true;
}

void mem_huge_pages(void *p, size_t bytes)
{
#ifdef MADV_HUGEPAGE
	const uintptr_t huge = (uintptr_t)2 << 20;
	if (!p || bytes < 2 * huge)
		return;
	uintptr_t lo = ((uintptr_t)p + huge - 1) & ~(huge - 1), hi = ((uintptr_t)p + bytes) & ~(huge - 1);
	if (hi > lo)
		(void)madvise((void *)lo, hi - lo, MADV_HUGEPAGE);
#else
	(void)p;
	(void)bytes;
#endif
}

void *mem_alloc_huge(size_t bytes)
{
	const size_t huge = (size_t)2 << 20;
	if (bytes > SIZE_MAX - huge)
		return NULL;
	if (bytes < 2 * huge)
		return aligned_alloc(64, bytes ? (bytes + 63) & ~(size_t)63 : 64);
	size_t whole = (bytes + huge - 1) & ~(huge - 1);
	void *p = aligned_alloc(huge, whole);
	mem_huge_pages(p, whole);
	return p;
}

void mem_prefault(void *p, size_t bytes)
{
#ifdef MADV_POPULATE_WRITE
	const uintptr_t page = 4096;
	if (!p || bytes < ((size_t)4 << 20))
		return;
	uintptr_t lo = ((uintptr_t)p + page - 1) & ~(page - 1), hi = ((uintptr_t)p + bytes) & ~(page - 1);
	if (hi > lo)
		(void)madvise((void *)lo, hi - lo, MADV_POPULATE_WRITE);
#else
	(void)p;
	(void)bytes;
#endif
}

char *mem_dupz(const void *p, size_t n)
{
	char *d = malloc(n + 1);
	if (d) {
		memcpy(d, p, n);
		d[n] = '\0';
	}
	return d;
}

void mem_free_list(void *const *p, size_t n)
{
	for (size_t i = 0; i < n; i++)
		free(p[i]);
}
