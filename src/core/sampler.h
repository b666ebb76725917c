/* rtsh — counter-based random numbers and pixel sample positions.
 *
 * Every random number rtsh uses is a pure function of (seed, pixel, sample,
 * dimension): a path's generator is seeded by hashing those, so no state is
 * shared between threads and the image never depends on the thread count or
 * the order in which tiles are rendered.
 */
#ifndef RTSH_SAMPLER_H
#define RTSH_SAMPLER_H

#include <stdint.h>

/* The splitmix64 finaliser (Steele, Lea & Flood 2014): a bijective mix. */
static inline uint64_t hash64(uint64_t z)
{
	z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
	z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
	return z ^ (z >> 31);
}

typedef struct rng {
	uint64_t s;
} rng;

/* The stream of one camera sample. */
static inline rng rng_for(uint64_t seed, uint64_t pixel, uint64_t sample)
{
	uint64_t h = hash64(seed ^ 0x243f6a8885a308d3ULL);
	h = hash64(h ^ pixel);
	h = hash64(h ^ (sample * 0x9e3779b97f4a7c15ULL));
	return (rng){h};
}

/* splitmix64 as a generator: uniform 64-bit values. */
static inline uint64_t rng_u64(rng *r)
{
	r->s += 0x9e3779b97f4a7c15ULL;
	return hash64(r->s);
}

/* Uniform in [0, 1). */
static inline double rng_next(rng *r)
{
	return (double)(rng_u64(r) >> 11) * 0x1.0p-53;
}

/* The first two dimensions of the Sobol sequence (the van der Corput
 * sequence and its companion), a (0,2)-sequence: every power-of-two prefix
 * is stratified. scramble: a random digital shift per pixel. */
static inline uint32_t bit_reverse32(uint32_t v)
{
	v = ((v >> 1) & 0x55555555u) | ((v & 0x55555555u) << 1);
	v = ((v >> 2) & 0x33333333u) | ((v & 0x33333333u) << 2);
	v = ((v >> 4) & 0x0f0f0f0fu) | ((v & 0x0f0f0f0fu) << 4);
	v = ((v >> 8) & 0x00ff00ffu) | ((v & 0x00ff00ffu) << 8);
	return (v >> 16) | (v << 16);
}

static inline uint32_t sobol_dim1(uint32_t i)
{
	uint32_t r = 0;
	for (uint32_t v = 1u << 31; i; i >>= 1, v ^= v >> 1)
		if (i & 1)
			r ^= v;
	return r;
}

/* Sample i's offset inside its pixel, both coordinates in [0,1). */
static inline void pixel_offset(uint32_t i, uint64_t scramble, double *u, double *v)
{
	*u = (double)(bit_reverse32(i) ^ (uint32_t)scramble) * 0x1.0p-32;
	*v = (double)(sobol_dim1(i) ^ (uint32_t)(scramble >> 32)) * 0x1.0p-32;
}

#endif
