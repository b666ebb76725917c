/* rtsh — counter-based sample values: Owen-scrambled Sobol points.
 *
 * Every number a path uses is a pure function of (seed, pixel, sample index,
 * dimension): no state is shared between threads, so the image never depends
 * on the thread count, the order of the tiles, the passes or the machines a
 * render is split across, and a progressive pass continues the sequence of
 * the one before.
 *
 * The sample values are the first two dimensions of the Sobol sequence (a
 * (0,2)-sequence: every power-of-two prefix of the points is stratified in
 * every elementary interval), Owen-scrambled by a hash and padded to any
 * number of dimensions by shuffling the sample index with another Owen
 * scramble (Burley, "Practical Hash-based Owen Scrambling", JCGT 2020, with
 * the permutation of Laine & Karras, "Stratified sampling for stochastic
 * transparency", 2011). Each pixel and each dimension draws its own
 * scrambles from a hash of (seed, pixel, dimension), which decorrelates the
 * pixels (no visible pattern) while each pixel's N = 2^k samples stay
 * stratified. A path asks for its numbers one or two at a time (samp_1d,
 * samp_2d); the dimension counts up. Past SAMPLER_DIMS dimensions (deep
 * bounces, whose light is small) the numbers are plain hashed random values.
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

static inline uint32_t bit_reverse32(uint32_t v)
{
	v = ((v >> 1) & 0x55555555u) | ((v & 0x55555555u) << 1);
	v = ((v >> 2) & 0x33333333u) | ((v & 0x33333333u) << 2);
	v = ((v >> 4) & 0x0f0f0f0fu) | ((v & 0x0f0f0f0fu) << 4);
	v = ((v >> 8) & 0x00ff00ffu) | ((v & 0x00ff00ffu) << 8);
	return (v >> 16) | (v << 16);
}

/* A random permutation of 32-bit words in which bit i of the result depends
 * only on bits 0..i of x: on bit-reversed values it is a nested uniform
 * (Owen) scramble. Burley's (2020) improvement of Laine & Karras's hash. */
static inline uint32_t owen_permute_rev(uint32_t x, uint32_t seed)
{
	x ^= x * 0x3d20adeau;
	x += seed;
	x *= (seed >> 16) | 1u;
	x ^= x * 0x05526c56u;
	x ^= x * 0x53a22864u;
	return x;
}

/* Owen scrambling of the binary fraction x / 2^32 (most significant digit
 * first). */
static inline uint32_t owen_scramble(uint32_t x, uint32_t seed)
{
	return bit_reverse32(owen_permute_rev(bit_reverse32(x), seed));
}

/* Sobol's second dimension of index i, bit-reversed (bit k is the k-th
 * binary digit after the point). Its generator matrix is Pascal's triangle
 * mod 2: digit k = XOR of the index bits j with k a submask of j (Lucas's
 * theorem), a superset sum done in five steps. */
static inline uint32_t sobol1_rev(uint32_t i)
{
	i ^= (i >> 1) & 0x55555555u;
	i ^= (i >> 2) & 0x33333333u;
	i ^= (i >> 4) & 0x0f0f0f0fu;
	i ^= (i >> 8) & 0x00ff00ffu;
	i ^= i >> 16;
	return i;
}

/* Sobol's second dimension of index i as a binary fraction x / 2^32 (the
 * textbook construction, one direction number per index bit). */
static inline uint32_t sobol_dim1(uint32_t i)
{
	return bit_reverse32(sobol1_rev(i));
}

/* Dimensions drawn from the scrambled Sobol points; later ones are hashed
 * random numbers. */
#define SAMPLER_DIMS 64u

/* One camera sample's source of numbers. */
typedef struct sampler {
	uint64_t key;    /* hash of (seed, pixel) */
	uint32_t index;  /* the sample's number in its pixel */
	uint32_t rindex; /* the same, bits reversed */
	uint32_t dim;    /* the next dimension */
} sampler;

static inline sampler sampler_for(uint64_t seed, uint64_t pixel, uint32_t sample)
{
	uint64_t h = hash64(seed ^ 0x243f6a8885a308d3ULL);
	return (sampler){hash64(h ^ pixel), sample, bit_reverse32(sample), 0};
}

/* The scrambles of dimension d: 64 hashed bits. */
static inline uint64_t sampler_dim_key(const sampler *s, uint32_t d)
{
	return hash64(s->key + (uint64_t)(d + 1) * 0x9e3779b97f4a7c15ULL);
}

static inline double u32_unit(uint32_t x)
{
	return (double)x * 0x1.0p-32;
}

/* A hashed random value of dimension d, beyond the table. */
static inline double sampler_hashed(const sampler *s, uint32_t d)
{
	uint64_t h = hash64(sampler_dim_key(s, d) ^ ((uint64_t)s->index * 0xd1b54a32d192ed03ULL));
	return (double)(h >> 11) * 0x1.0p-53;
}

/* The next number, uniform in [0, 1): the van der Corput (base 2) point
 * of the shuffled index, Owen-scrambled. */
static inline double samp_1d(sampler *s)
{
	uint32_t d = s->dim++;
	if (d >= SAMPLER_DIMS)
		return sampler_hashed(s, d);
	uint64_t k = sampler_dim_key(s, d);
	/* the shuffled index i = Owen(index): bit j of i depends on the bits
	 * j.. of index, so the first 2^m indices map to an aligned block */
	uint32_t i = bit_reverse32(owen_permute_rev(s->rindex, (uint32_t)k));
	/* the point reverse(i), Owen-scrambled: reverse(permute(i)) */
	return u32_unit(bit_reverse32(owen_permute_rev(i, (uint32_t)(k >> 32))));
}

/* The next two numbers: a 2-D point of the (0,2)-sequence, both dimensions
 * Owen-scrambled, its index shuffled for this pair of dimensions. */
static inline void samp_2d(sampler *s, double *u, double *v)
{
	uint32_t d = s->dim;
	s->dim += 2;
	if (d >= SAMPLER_DIMS) {
		*u = sampler_hashed(s, d);
		*v = sampler_hashed(s, d + 1);
		return;
	}
	uint64_t k = sampler_dim_key(s, d), k2 = (k * 0xd1b54a32d192ed03ULL) >> 32;
	uint32_t i = bit_reverse32(owen_permute_rev(s->rindex, (uint32_t)k)); /* shuffled */
	*u = u32_unit(bit_reverse32(owen_permute_rev(i, (uint32_t)(k >> 32))));
	*v = u32_unit(bit_reverse32(owen_permute_rev(sobol1_rev(i), (uint32_t)k2)));
}

/* Sample `sample`'s offset inside pixel `pixel`, both coordinates in
 * [0,1): the first two dimensions of its sampler (render_sample). */
static inline void pixel_offset(uint64_t seed, uint64_t pixel, uint32_t sample, double *u,
                                double *v)
{
	sampler s = sampler_for(seed, pixel, sample);
	samp_2d(&s, u, v);
}

#endif
