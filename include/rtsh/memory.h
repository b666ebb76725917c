/* rtsh — memory estimates: refuse a request before starting it.
 *
 * A request that needs more memory than the machine has would either fail
 * half way (malloc returns NULL after minutes of work) or, worse, push the
 * machine into swap and the OOM killer. So the big requests (a generated
 * scene, a loaded scene, a framebuffer) estimate what they need first and
 * are refused with a message when it is more than the process may use: the
 * smaller of the physical memory (sysconf _SC_PHYS_PAGES x _SC_PAGE_SIZE),
 * RLIMIT_AS and RLIMIT_DATA, and a limit set by mem_set_limit (tests and
 * fuzzers).
 */
#ifndef RTSH_MEMORY_H
#define RTSH_MEMORY_H

#include <stdbool.h>
#include <stddef.h>

#include "rtsh/error.h"

/* Bytes one scene object costs from loading to rendering: the scene model,
 * the undo copy of the editor, the world's object and the BVH (measured:
 * bench/README.md, "memory per object"). */
#define MEM_PER_OBJECT 1024.0
/* Bytes one pixel of a full-resolution image costs: the framebuffer's linear
 * RGB floats, its running sums (doubles) and the 8-bit copy written out. */
#define MEM_PER_PIXEL 40.0

/* Memory already held that a new request comes on top of: the scenes the
 * editors keep (each editor's current scene and the whole scenes its undo
 * and redo history holds after `load` and `generate`, edit.c), as bytes and
 * a count of scenes. mem_hold adds (or with negative deltas removes). */
void mem_hold(double bytes, long scenes);
double mem_held(long *scenes);

/* Asks the kernel to back the 2 MB-aligned pages of [p, p + bytes) with huge
 * pages (madvise MADV_HUGEPAGE, where transparent huge pages are "madvise"):
 * a million-object world's tree, primitives and materials are walked at
 * random, and with 4 KB pages most node visits also miss the TLB. Call it
 * before the memory is first written; a no-op below 4 MB or where the call
 * is refused. */
void mem_huge_pages(void *p, size_t bytes);
/* bytes (at least 1) for an array walked at random, 64-byte aligned; from
 * 4 MB on, 2 MB-aligned and a whole number of 2 MB pages long, with
 * mem_huge_pages, so that every page of it can be a huge one (an array
 * placed at random leaves up to its first and last 2 MB in 4 KB pages).
 * Freed with free; NULL when out of memory. */
void *mem_alloc_huge(size_t bytes);
/* Makes the pages of [p, p + bytes) at once (madvise MADV_POPULATE_WRITE,
 * Linux 5.14) rather than at a fault each on first write: for a large
 * array about to be written whole (world_build's materials, references and
 * order: the same 40000 pages for a million objects without a trap each,
 * about 8% of the build's thread time, bench/README.md's build5 section). A no-op below 4 MB or
 * where the call is refused; the memory's contents are not changed. */
void mem_prefault(void *p, size_t bytes);

/* The most bytes this process may use, and what sets that figure ("physical
 * memory", "RLIMIT_AS", "RLIMIT_DATA" or "the set limit"). */
double mem_limit(const char **why);
/* Caps the limit at `bytes` (0: no cap beyond the machine's). */
void mem_set_limit(size_t bytes);
/* True when `bytes`, on top of what is held (mem_held), fits in the limit;
 * else sets err to "WHAT needs about X of memory; expected at most Y (WHY)"
 * (naming what is held when the request alone would fit) and returns
 * false. */
bool mem_check(double bytes, const char *what, rt_error *err);

/* Makes room for `need` elements of `size` bytes in the array *a of
 * capacity *cap, doubling from 64; false (nothing changed) on overflow or
 * when out of memory. */
bool mem_grow(void **a, size_t *cap, size_t need, size_t size);

/* A copy of the n bytes at p with a NUL after them (they may hold NULs:
 * file contents), or NULL when out of memory. */
char *mem_dupz(const void *p, size_t n);

/* Frees each pointer named, in order (NULLs are skipped, as free does): a
 * destructor still names every field its struct owns, in one line,
 * mem_free_all(fb->rgb, fb->sum, fb). Only for plain heap blocks; a field
 * with its own destructor is freed by that. */
#define mem_free_all(...) \
	mem_free_list((void *[]){__VA_ARGS__}, sizeof((void *[]){__VA_ARGS__}) / sizeof(void *))
void mem_free_list(void *const *p, size_t n);

#endif
