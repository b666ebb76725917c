/* rtsh — packets of coherent rays through the world's object tree
 * (rtsh/packet.h).
 *
 * One walk of the 4-wide tree (bvh.h) for up to PACKET_MAX rays whose
 * directions share each axis's sign:
 *   - the node test is the single ray's slab test (world.c) done on
 *     intervals: per axis, the lowest near-plane origin and inverse
 *     directions of the packet give a distance no greater than any ray's
 *     own float distance, and the highest far ones one no smaller
 *     (rounding to nearest is monotonic, so the bounds hold for the
 *     rounded values too). A child that no ray of the packet could enter
 *     by its own test is skipped; one that some ray might enter is visited
 *     by all. So the packet visits at least every leaf a ray alone would
 *     visit, and never misses what a single ray finds.
 *   - at a leaf every ray whose nearest hit so far could still be beaten
 *     meets every primitive with the single ray's own test (prim_hit.h);
 *     spheres, the common case, first as a vector pre-test of their
 *     discriminant, two rays per SSE2 register, with the same operations
 *     in the same order as sphere_hit, then sphere_hit itself for the rays
 *     that pass.
 * The nearest distance does not depend on the order of the walk; which of
 * two primitives at the same distance wins does (the single ray keeps the
 * first it meets). Each ray therefore also accepts a primitive at exactly
 * its current distance, and notes the tie: a ray with a tie at the end is
 * traced again alone. The same for the planes beside the tree: they are
 * tested first, in the same order, with the same strict test. */
#include "rtsh/packet.h"

#include <string.h>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "core/bvh/bvh.h"
#include "core/prim_hit.h"
#include "core/surface.h"
#include "rtsh/mesh.h"

/* The state of a packet's walk: the rays by component (for the vector
 * sphere pre-test, padded to an even count) and each ray's best hit. */
typedef struct pk_state {
	int n;
	_Alignas(16) double ox[PACKET_MAX], oy[PACKET_MAX], oz[PACKET_MAX];
	_Alignas(16) double dx[PACKET_MAX], dy[PACKET_MAX], dz[PACKET_MAX];
	_Alignas(16) double dd[PACKET_MAX];   /* d . d, as sphere_hit computes it */
	_Alignas(16) double tmax[PACKET_MAX]; /* the nearest hit so far (or the query's tmax) */
	const prim *best[PACKET_MAX];
	vec3 nl[PACKET_MAX];
	/* bit i for ray i: a primitive is its best (best[i] set), that
	 * primitive is a sphere, it has a tie; the planes beside the tree gave
	 * its tmax (packet_planes) */
	unsigned got, sph, tie, plane;
	bool one_o; /* every ray's origin is ray 0's, bit for bit (camera rays) */
} pk_state;

/* The interval form of bvh_ray: per axis, the near- and far-plane origins
 * that give the lowest near and highest far distances of any ray, the
 * inverse directions' range, and the rows of the node's boxes to read. */
typedef struct pk_ray {
	__m128 on[3], of[3], ilo[3], ihi[3];
	int near[3], far[3];
	bool one_o; /* every ray's origin equals ray 0's (as doubles: a zero of either sign) */
} pk_ray;

/* The smallest double above t >= 0 (+inf stays): a primitive at exactly
 * the distance found so far is still reported (offer). */
static inline double next_up(double t)
{
	if (!(t < INFINITY))
		return t;
	uint64_t u;
	memcpy(&u, &t, sizeof u);
	u = t > 0.0 ? u + 1 : 1;
	memcpy(&t, &u, sizeof t);
	return t;
}

/* The bound to give a model's walk (mesh_trace.c) for a ray whose nearest
 * hit so far is at t: that walk tests its float distances strictly against
 * its bound rounded to a float, so next_up(t) rounds back to t where t is a
 * float (another model's distance, or a sphere's that is one) and a
 * triangle at exactly t is not seen. t (1 + 2^-23) is not: for a normal
 * float F <= t, F 2^-23 is at least F's step to the next float, so the
 * bound, rounded to a float or not, lies above every float <= t (exact
 * when t is a float; rounding is monotonic otherwise). What else it lets
 * through, beyond t, offer drops. (+inf stays +inf.) */
static inline double model_bound(double t)
{
	return t * (1.0 + 0x1p-23);
}

/* One axis's components d of two rays into the packet's lowest, highest,
 * all its bits ANDed and ORed (packet_prepare). */
static inline void axis_extremes(__m128d d, __m128d *lo, __m128d *hi, __m128d *all, __m128d *any)
{
	*lo = _mm_min_pd(*lo, d);
	*hi = _mm_max_pd(*hi, d);
	*all = _mm_and_pd(*all, d);
	*any = _mm_or_pd(*any, d);
}

/* Loads rays r[0..n) (2 <= n <= PACKET_MAX) into s and fills q; false
 * when the packet is not coherent enough for the interval test: a direction component of another
 * sign than the first ray's, a zero or NaN component, an inverse or origin
 * that is not finite. Each ray's origin and inverse direction are rounded
 * as world.c's bvh_ray_prepare rounds them (on and of bracket the origin so
 * that the near plane's distance can only come down and the far plane's go
 * up), three axes in one register, and the packet keeps their lowest and
 * highest.
 *
 * The inverses are not computed ray by ray: for directions of one sign,
 * 1/d falls as d rises, and both the double division and the rounding to
 * float are monotonic, so the lowest rounded inverse is that of the highest
 * direction component and the highest that of the lowest: the same floats
 * from two divisions a packet instead of one a ray. Every ray's inverse
 * lies between those two (of one sign), so they are finite and not zero
 * exactly when all the rays' are. When every origin equals the first
 * ray's as doubles (camera rays; a zero of either sign gives the same
 * floats here), the first ray's bracket is the packet's.
 *
 * s gets the rays by component and d . d as sphere_hit computes it, two
 * rays per register; an odd count is padded with ray 0, which the vector
 * tests read and nothing offers (nor changes an extreme here). Each double
 * is read alone: the caller has usually just written the rays a component
 * at a time (cam_block_rays), and a 16-byte load of two such stores waits
 * for both to leave the store buffer instead of being forwarded; the pairs
 * are stored whole, so that the vector tests' loads are forwarded. */
static bool packet_prepare(pk_state *s, const ray *r, int n, pk_ray *q)
{
	s->n = n;
	const __m128d one = _mm_set1_pd(1.0);
	const __m128 sign = _mm_set1_ps(-0.0f), ulp = _mm_set1_ps(0x1p-23f), tiny = _mm_set1_ps(0x1p-149f);
	const __m128 big = _mm_set1_ps(FLT_MAX);
	/* per axis the directions' lowest and highest and their bits ANDed
	 * and ORed (the sign bits: all negative, any negative), two lanes
	 * each; any NaN among directions and origins; whether every origin
	 * is the first ray's */
	__m128d lx = _mm_set1_pd(r[0].d.x), ly = _mm_set1_pd(r[0].d.y), lz = _mm_set1_pd(r[0].d.z);
	__m128d hx = lx, hy = ly, hz = lz, ax = lx, ay = ly, az = lz, bx = lx, by = ly, bz = lz;
	const __m128d o0x = _mm_set1_pd(r[0].o.x), o0y = _mm_set1_pd(r[0].o.y), o0z = _mm_set1_pd(r[0].o.z);
	__m128d nan = _mm_setzero_pd(), same = _mm_cmpeq_pd(o0x, o0x);
	for (int i = 0; i < n; i += 2) {
		const ray *ra = &r[i], *rb = i + 1 < n ? &r[i + 1] : &r[0];
		__m128d dx = _mm_loadh_pd(_mm_load_sd(&ra->d.x), &rb->d.x);
		__m128d dy = _mm_loadh_pd(_mm_load_sd(&ra->d.y), &rb->d.y);
		__m128d dz = _mm_loadh_pd(_mm_load_sd(&ra->d.z), &rb->d.z);
		__m128d ox = _mm_loadh_pd(_mm_load_sd(&ra->o.x), &rb->o.x);
		__m128d oy = _mm_loadh_pd(_mm_load_sd(&ra->o.y), &rb->o.y);
		__m128d oz = _mm_loadh_pd(_mm_load_sd(&ra->o.z), &rb->o.z);
		_mm_store_pd(&s->ox[i], ox);
		_mm_store_pd(&s->oy[i], oy);
		_mm_store_pd(&s->oz[i], oz);
		_mm_store_pd(&s->dx[i], dx);
		_mm_store_pd(&s->dy[i], dy);
		_mm_store_pd(&s->dz[i], dz);
		_mm_store_pd(&s->dd[i], _mm_add_pd(_mm_add_pd(_mm_mul_pd(dx, dx), _mm_mul_pd(dy, dy)), _mm_mul_pd(dz, dz)));
		nan = _mm_or_pd(nan, _mm_or_pd(_mm_cmpunord_pd(dx, dy), _mm_cmpunord_pd(dz, ox)));
		nan = _mm_or_pd(nan, _mm_cmpunord_pd(oy, oz));
		same = _mm_and_pd(same, _mm_and_pd(_mm_cmpeq_pd(ox, o0x), _mm_and_pd(_mm_cmpeq_pd(oy, o0y), _mm_cmpeq_pd(oz, o0z))));
		axis_extremes(dx, &lx, &hx, &ax, &bx);
		axis_extremes(dy, &ly, &hy, &ay, &by);
		axis_extremes(dz, &lz, &hz, &az, &bz);
	}
	int neg_and = (_mm_movemask_pd(ax) == 3) | (_mm_movemask_pd(ay) == 3) << 1 | (_mm_movemask_pd(az) == 3) << 2;
	int neg_or = (_mm_movemask_pd(bx) != 0) | (_mm_movemask_pd(by) != 0) << 1 | (_mm_movemask_pd(bz) != 0) << 2;
	if (_mm_movemask_pd(nan) || neg_and != neg_or)
		return false;
	/* (the extremes of values of one sign, no NaN, are the same whatever
	 * the order they are taken in) */
	__m128d dlo = _mm_unpacklo_pd(_mm_min_pd(lx, _mm_unpackhi_pd(lx, lx)), _mm_min_pd(ly, _mm_unpackhi_pd(ly, ly)));
	__m128d dhi = _mm_unpacklo_pd(_mm_max_pd(hx, _mm_unpackhi_pd(hx, hx)), _mm_max_pd(hy, _mm_unpackhi_pd(hy, hy)));
	__m128d dlo_z = _mm_min_pd(lz, _mm_unpackhi_pd(lz, lz)), dhi_z = _mm_max_pd(hz, _mm_unpackhi_pd(hz, hz));
	/* the inverses' signs are the directions' (every ray's the first's) */
	const __m128 isign = _mm_and_ps(
		_mm_movelh_ps(_mm_cvtpd_ps(_mm_set_pd(r[0].d.y, r[0].d.x)), _mm_cvtpd_ps(_mm_set_sd(r[0].d.z))), sign);
	bool one_o = _mm_movemask_pd(same) == 3;
	__m128 on_lo = _mm_set1_ps(INFINITY), on_hi = _mm_set1_ps(-INFINITY), of_lo = on_lo, of_hi = on_hi;
	__m128 bad = _mm_setzero_ps();
	for (int i = 0; i < (one_o ? 1 : n); i++) {
		__m128 f = _mm_movelh_ps(_mm_cvtpd_ps(_mm_set_pd(r[i].o.y, r[i].o.x)), _mm_cvtpd_ps(_mm_set_sd(r[i].o.z)));
		__m128 e = _mm_add_ps(_mm_mul_ps(_mm_andnot_ps(sign, f), ulp), tiny);
		__m128 es = _mm_xor_ps(e, isign);
		__m128 on = _mm_add_ps(f, es), of = _mm_sub_ps(f, es);
		/* |x| <= FLT_MAX fails for infinities and NaN */
		bad = _mm_or_ps(bad, _mm_cmpnle_ps(_mm_andnot_ps(sign, on), big));
		bad = _mm_or_ps(bad, _mm_cmpnle_ps(_mm_andnot_ps(sign, of), big));
		on_lo = _mm_min_ps(on_lo, on);
		on_hi = _mm_max_ps(on_hi, on);
		of_lo = _mm_min_ps(of_lo, of);
		of_hi = _mm_max_ps(of_hi, of);
	}
	__m128 ilo = _mm_movelh_ps(_mm_cvtpd_ps(_mm_div_pd(one, dhi)), _mm_cvtpd_ps(_mm_div_sd(one, dhi_z)));
	__m128 ihi = _mm_movelh_ps(_mm_cvtpd_ps(_mm_div_pd(one, dlo)), _mm_cvtpd_ps(_mm_div_sd(one, dlo_z)));
	/* the inverses must be finite and not zero (a zero direction
	 * component, of either sign, is the lowest in magnitude of its axis:
	 * its infinite inverse is ilo's or ihi's) */
	bad = _mm_or_ps(bad, _mm_cmpnle_ps(_mm_andnot_ps(sign, ilo), big));
	bad = _mm_or_ps(bad, _mm_cmpnle_ps(_mm_andnot_ps(sign, ihi), big));
	bad = _mm_or_ps(bad, _mm_cmpeq_ps(_mm_andnot_ps(sign, ilo), _mm_setzero_ps()));
	bad = _mm_or_ps(bad, _mm_cmpeq_ps(_mm_andnot_ps(sign, ihi), _mm_setzero_ps()));
	if (_mm_movemask_ps(bad) & 7)
		return false;
	q->one_o = one_o;
	float a_on_lo[4], a_on_hi[4], a_of_lo[4], a_of_hi[4], a_ilo[4], a_ihi[4];
	_mm_storeu_ps(a_on_lo, on_lo);
	_mm_storeu_ps(a_on_hi, on_hi);
	_mm_storeu_ps(a_of_lo, of_lo);
	_mm_storeu_ps(a_of_hi, of_hi);
	_mm_storeu_ps(a_ilo, ilo);
	_mm_storeu_ps(a_ihi, ihi);
	for (int a = 0; a < 3; a++) {
		bool neg = neg_and >> a & 1;
		/* near distance (b - o) inv: lowest with the origin farthest
		 * along the direction; far distance: highest with it farthest back */
		q->on[a] = _mm_set1_ps(neg ? a_on_lo[a] : a_on_hi[a]);
		q->of[a] = _mm_set1_ps(neg ? a_of_hi[a] : a_of_lo[a]);
		q->ilo[a] = _mm_set1_ps(a_ilo[a]);
		q->ihi[a] = _mm_set1_ps(a_ihi[a]);
		q->near[a] = a + (neg ? BVH_HI_X : BVH_LO_X);
		q->far[a] = a + (neg ? BVH_LO_X : BVH_HI_X);
	}
	return true;
}

/* The interval slab test of node n's four children: bit k set when some
 * ray of the packet may enter child k within [tmin, tmax]; tn[k] no more
 * than where any of them enters it. */
static inline unsigned packet_slab4(const bvh_node *n, const pk_ray *q, float tmin, float tmax, float tn[4])
{
	__m128 t0 = _mm_set1_ps(tmin), t1 = _mm_set1_ps(tmax);
	for (int a = 0; a < 3; a++) {
		__m128 x = _mm_sub_ps(_mm_load_ps(n->b[q->near[a]]), q->on[a]);
		__m128 y = _mm_sub_ps(_mm_load_ps(n->b[q->far[a]]), q->of[a]);
		__m128 lo = _mm_min_ps(_mm_mul_ps(x, q->ilo[a]), _mm_mul_ps(x, q->ihi[a]));
		__m128 hi = _mm_max_ps(_mm_mul_ps(y, q->ilo[a]), _mm_mul_ps(y, q->ihi[a]));
		t0 = _mm_max_ps(lo, t0);
		t1 = _mm_min_ps(hi, t1);
	}
	_mm_storeu_ps(tn, t0);
	return (unsigned)_mm_movemask_ps(_mm_cmple_ps(t0, _mm_mul_ps(t1, _mm_set1_ps(BVH_SLAB_SLACK))));
}

/* Ray i meets primitive p (a sphere or not): a nearer hit replaces its
 * best, one at the same distance from another primitive is a tie. */
static inline void offer(pk_state *s, int i, const prim *p, double t, vec3 nl, bool sphere)
{
	unsigned bit = 1u << i;
	if (t < s->tmax[i]) {
		s->tmax[i] = t;
		s->best[i] = p;
		s->nl[i] = nl;
		s->got |= bit;
		s->tie &= ~bit;
		s->sph = sphere ? s->sph | bit : s->sph & ~bit;
	} else if (t == s->tmax[i] && (s->got & bit) && p != s->best[i]) {
		/* (at the distance of a plane or of the query's tmax, a single
		 * ray keeps the plane or nothing: not a tie) */
		s->tie |= bit;
	}
}

#if defined(__SSE2__)
/* A sphere in SSE2 registers, both lanes: its centre and squared radius. */
typedef struct pk_sphere {
	__m128d cx, cy, cz, rr;
} pk_sphere;

static inline pk_sphere pk_sphere_of(const prim *p)
{
	return (pk_sphere){_mm_set1_pd(p->u.sph.c.x), _mm_set1_pd(p->u.sph.c.y), _mm_set1_pd(p->u.sph.c.z),
	                   _mm_set1_pd(p->u.sph.r * p->u.sph.r)};
}

/* Rays i and i + 1 (bits 0 and 1) whose discriminant against the sphere is
 * not negative: sphere_hit's, term by term; NaN passes on to sphere_hit,
 * as there (leaf_spheres and leaf_occluded). */
static inline unsigned sphere_disc2(const pk_state *s, int i, const pk_sphere *sp)
{
	__m128d ocx = _mm_sub_pd(_mm_load_pd(&s->ox[i]), sp->cx);
	__m128d ocy = _mm_sub_pd(_mm_load_pd(&s->oy[i]), sp->cy);
	__m128d ocz = _mm_sub_pd(_mm_load_pd(&s->oz[i]), sp->cz);
	__m128d dx = _mm_load_pd(&s->dx[i]), dy = _mm_load_pd(&s->dy[i]), dz = _mm_load_pd(&s->dz[i]);
	__m128d b = _mm_add_pd(_mm_add_pd(_mm_mul_pd(ocx, dx), _mm_mul_pd(ocy, dy)), _mm_mul_pd(ocz, dz));
	__m128d c = _mm_sub_pd(_mm_add_pd(_mm_add_pd(_mm_mul_pd(ocx, ocx), _mm_mul_pd(ocy, ocy)), _mm_mul_pd(ocz, ocz)),
	                       sp->rr);
	__m128d disc = _mm_sub_pd(_mm_mul_pd(b, b), _mm_mul_pd(_mm_load_pd(&s->dd[i]), c));
	return (unsigned)_mm_movemask_pd(_mm_cmpnlt_pd(disc, _mm_setzero_pd()));
}

/* sphere_disc2 for rays of one origin: oc and c, computed once by
 * sphere_disc2's own operations on that origin, are every ray's, and so
 * is the discriminant. (Origins equal as doubles may differ in the sign
 * of a zero; that can change the sign of a zero in oc and b but not b * b
 * or oc . oc, so not the discriminant.) */
static inline unsigned sphere_disc2_o(const pk_state *s, int i, __m128d ocx, __m128d ocy, __m128d ocz, __m128d c)
{
	__m128d dx = _mm_load_pd(&s->dx[i]), dy = _mm_load_pd(&s->dy[i]), dz = _mm_load_pd(&s->dz[i]);
	__m128d b = _mm_add_pd(_mm_add_pd(_mm_mul_pd(ocx, dx), _mm_mul_pd(ocy, dy)), _mm_mul_pd(ocz, dz));
	__m128d disc = _mm_sub_pd(_mm_mul_pd(b, b), _mm_mul_pd(_mm_load_pd(&s->dd[i]), c));
	return (unsigned)_mm_movemask_pd(_mm_cmpnlt_pd(disc, _mm_setzero_pd()));
}
#endif

/* next_up of both lanes: the smallest double above t >= 0, +inf and NaN
 * kept, the smallest denormal for t <= 0 (next_up's integer steps). */
static inline __m128d next_up2(__m128d t)
{
	__m128d fin = _mm_cmplt_pd(t, _mm_set1_pd(INFINITY)), pos = _mm_cmpgt_pd(t, _mm_setzero_pd());
	__m128i one = _mm_set1_epi64x(1);
	__m128d up = _mm_castsi128_pd(_mm_add_epi64(_mm_castpd_si128(t), one));
	__m128d u = _mm_or_pd(_mm_and_pd(pos, up), _mm_andnot_pd(pos, _mm_castsi128_pd(one)));
	return _mm_or_pd(_mm_and_pd(fin, u), _mm_andnot_pd(fin, t));
}

/* The rays of s meet sphere p: first the discriminants of all the pairs
 * (sphere_disc2), then for the pairs where one is not negative sphere_hit's
 * remaining steps on both lanes, each lane its operations in its order: q
 * = -(b + copysign(sqrt(disc), b)), t0 = q / a, t1 = c / q (t0 when q is
 * 0), the two in order, the nearer above tmin, and its test against tmin
 * and the next double above the ray's nearest so far (offer). A lane
 * whose discriminant is negative is dropped, as sphere_hit returns there. */
static void leaf_spheres(pk_state *s, const prim *p, double tmin)
{
	const vec3 zero = {0, 0, 0};
	const pk_sphere sph = pk_sphere_of(p);
	const __m128d sign = _mm_set1_pd(-0.0), t0v = _mm_set1_pd(tmin);
	__m128d ocx = _mm_setzero_pd(), ocy = ocx, ocz = ocx, c1 = ocx;
	if (s->one_o) {
		ocx = _mm_sub_pd(_mm_load_pd(&s->ox[0]), sph.cx);
		ocy = _mm_sub_pd(_mm_load_pd(&s->oy[0]), sph.cy);
		ocz = _mm_sub_pd(_mm_load_pd(&s->oz[0]), sph.cz);
		c1 = _mm_sub_pd(_mm_add_pd(_mm_add_pd(_mm_mul_pd(ocx, ocx), _mm_mul_pd(ocy, ocy)), _mm_mul_pd(ocz, ocz)),
		                sph.rr);
	}
	unsigned pass = 0;
	for (int i = 0; i < s->n; i += 2)
		pass |= (s->one_o ? sphere_disc2_o(s, i, ocx, ocy, ocz, c1) : sphere_disc2(s, i, &sph)) << i;
	pass &= (1u << s->n) - 1; /* (not the pad) */
	for (unsigned pairs = (pass | pass >> 1) & 0x5555u; pairs; pairs &= pairs - 1) {
		int i = __builtin_ctz(pairs);
		__m128d dx = _mm_load_pd(&s->dx[i]), dy = _mm_load_pd(&s->dy[i]), dz = _mm_load_pd(&s->dz[i]);
		__m128d ox = ocx, oy = ocy, oz = ocz, c = c1;
		if (!s->one_o) {
			ox = _mm_sub_pd(_mm_load_pd(&s->ox[i]), sph.cx);
			oy = _mm_sub_pd(_mm_load_pd(&s->oy[i]), sph.cy);
			oz = _mm_sub_pd(_mm_load_pd(&s->oz[i]), sph.cz);
			c = _mm_sub_pd(_mm_add_pd(_mm_add_pd(_mm_mul_pd(ox, ox), _mm_mul_pd(oy, oy)), _mm_mul_pd(oz, oz)), sph.rr);
		}
		__m128d a = _mm_load_pd(&s->dd[i]);
		__m128d b = _mm_add_pd(_mm_add_pd(_mm_mul_pd(ox, dx), _mm_mul_pd(oy, dy)), _mm_mul_pd(oz, dz));
		if (s->one_o && _mm_movemask_pd(_mm_cmpeq_pd(b, _mm_setzero_pd()))) {
			/* b is a zero: its sign, which q takes, is that of the
			 * ray's own o - c (origins equal as doubles may differ in
			 * the sign of a zero; c and the discriminant do not) */
			ox = _mm_sub_pd(_mm_load_pd(&s->ox[i]), sph.cx);
			oy = _mm_sub_pd(_mm_load_pd(&s->oy[i]), sph.cy);
			oz = _mm_sub_pd(_mm_load_pd(&s->oz[i]), sph.cz);
			b = _mm_add_pd(_mm_add_pd(_mm_mul_pd(ox, dx), _mm_mul_pd(oy, dy)), _mm_mul_pd(oz, dz));
		}
		__m128d disc = _mm_sub_pd(_mm_mul_pd(b, b), _mm_mul_pd(a, c));
		__m128d sq = _mm_sqrt_pd(disc);
		__m128d q = _mm_xor_pd(_mm_add_pd(b, _mm_or_pd(_mm_andnot_pd(sign, sq), _mm_and_pd(sign, b))), sign);
		__m128d t0 = _mm_div_pd(q, a), t1 = _mm_div_pd(c, q);
		__m128d qz = _mm_cmpneq_pd(q, _mm_setzero_pd());
		t1 = _mm_or_pd(_mm_and_pd(qz, t1), _mm_andnot_pd(qz, t0));
		__m128d gt = _mm_cmpgt_pd(t0, t1);
		__m128d lo = _mm_or_pd(_mm_and_pd(gt, t1), _mm_andnot_pd(gt, t0));
		__m128d hi = _mm_or_pd(_mm_and_pd(gt, t0), _mm_andnot_pd(gt, t1));
		__m128d above = _mm_cmpgt_pd(lo, t0v);
		__m128d tt = _mm_or_pd(_mm_and_pd(above, lo), _mm_andnot_pd(above, hi));
		__m128d ok = _mm_and_pd(_mm_cmpgt_pd(tt, t0v), _mm_cmplt_pd(tt, next_up2(_mm_load_pd(&s->tmax[i]))));
		unsigned m = (unsigned)_mm_movemask_pd(ok) & pass >> i & 3u;
		if (!m)
			continue;
		double t[2];
		_mm_storeu_pd(t, tt);
		if (m & 1)
			offer(s, i, p, t[0], zero, true);
		if (m & 2)
			offer(s, i + 1, p, t[1], zero, true);
	}
}

/* The rays of s meet a model among the objects (a mesh instance in a leaf)
 * as a packet through its own triangle tree: each ray to model_bound of its
 * nearest so far, so that offer sees a triangle at exactly that distance,
 * and a ray the model's packet found a tie for meets it again alone. False
 * when the model's packet is not traced (the caller tests ray by ray). */
static bool leaf_mesh(const world *w, pk_state *s, const prim *p, const ray *r, double tmin)
{
	const prim_inst *in = &w->insts[p->u.index];
	double tm[PACKET_MAX], t[PACKET_MAX];
	uint32_t slot[PACKET_MAX];
	float b[PACKET_MAX][3];
	unsigned got, tie;
	for (int i = 0; i < s->n; i++)
		tm[i] = model_bound(s->tmax[i]);
	if (!mesh_intersect_world_packet(in->mesh, in->inv, s->n, r, tmin, 0.0, tm, t, slot, b, &got, &tie))
		return false;
	for (unsigned g = got & ~tie; g; g &= g - 1) {
		int i = __builtin_ctz(g);
		offer(s, i, p, t[i], v3((double)slot[i], b[i][1], b[i][2]), false);
	}
	for (; tie; tie &= tie - 1) {
		int i = __builtin_ctz(tie);
		double tt;
		vec3 nl;
		if (world_prim_hit(w, p, &r[i], tmin, tm[i], &tt, &nl, true))
			offer(s, i, p, tt, nl, false);
	}
	return true;
}

/* The farthest of the rays' nearest hits so far. */
static inline double packet_far(const pk_state *s)
{
	/* (two at a time, lanes 0 and 1: the maximum of numbers, no NaN among
	 * the nearest hits, does not depend on the order) */
	__m128d m = _mm_set1_pd(s->tmax[0]);
	int i = 0;
	for (; i + 2 <= s->n; i += 2)
		m = _mm_max_pd(_mm_set_pd(s->tmax[i + 1], s->tmax[i]), m);
	if (i < s->n)
		m = _mm_max_pd(_mm_set1_pd(s->tmax[i]), m);
	return _mm_cvtsd_f64(_mm_max_sd(_mm_unpackhi_pd(m, m), m));
}

static void packet_walk(const world *w, pk_state *s, const ray *r, const pk_ray *q, double tmin)
{
	const bvh *tree = w->tree;
	const bvh_node *nodes = tree->nodes;
	double far = packet_far(s);
	float ftmin = to_float_down(tmin), ftmax = to_float_up(far);
	bvh_entry stack[BVH_STACK];
	int sp = 0;
	uint32_t child = tree->root, meta = tree->root_meta;
	for (;;) {
		if (meta) {
			const prim *p = &w->prims[child];
			uint32_t count = meta & ~BVH_LEAF;
			for (uint32_t k = 0; k < count; k++) {
				if (p[k].tag == PRIM_SPHERE) {
					leaf_spheres(s, &p[k], tmin);
					continue;
				}
				if (p[k].tag == PRIM_MESH && leaf_mesh(w, s, &p[k], r, tmin))
					continue;
				for (int i = 0; i < s->n; i++) {
					double t;
					vec3 nl = {0, 0, 0};
					double tm = p[k].tag == PRIM_MESH ? model_bound(s->tmax[i]) : next_up(s->tmax[i]);
					if (world_prim_hit(w, &p[k], &r[i], tmin, tm, &t, &nl, true))
						offer(s, i, &p[k], t, nl, false);
				}
			}
			far = packet_far(s);
			ftmax = to_float_up(far);
		} else {
			const bvh_node *n = &nodes[child];
			float tn[BVH_WIDTH];
			unsigned m = packet_slab4(n, q, ftmin, ftmax, tn);
			if (m) {
				/* the nearest now, the others later */
				sp = bvh_enter_sorted(n, m, tn, stack, sp, &child, &meta);
				continue;
			}
		}
		/* the single walk's own test, in double, against the farthest ray */
		while (sp > 0 && (double)stack[sp - 1].t > (double)BVH_SLAB_SLACK * far)
			sp--;
		if (sp == 0)
			break;
		sp--;
		child = stack[sp].child;
		meta = stack[sp].meta;
	}
}

/* A lone model (the model viewer's world, trace's own case in world.c): the
 * planes first for each ray, as there, then the packet through the model's
 * triangle tree (mesh_intersect_world_packet). False when that packet is
 * not traced: the caller traces each ray alone. */
static bool model_packet(const world *w, int n, const ray *r, double tmin, double tmax, trace_hit *th, bool *found)
{
	const prim *p = &w->prims[0];
	const prim_inst *in = &w->insts[p->u.index];
	double tm[PACKET_MAX], t[PACKET_MAX];
	const prim_plane *best_plane[PACKET_MAX] = {NULL};
	uint32_t slot[PACKET_MAX];
	float b[PACKET_MAX][3];
	if (w->nplanes) {
		for (int i = 0; i < n; i++)
			tm[i] = tmax;
		for (size_t k = 0; k < w->nplanes; k++)
			for (int i = 0; i < n; i++) {
				double tp;
				if (plane_hit(&w->planes[k], &r[i], tmin, tm[i], &tp)) {
					tm[i] = tp;
					best_plane[i] = &w->planes[k];
				}
			}
	}
	unsigned got, tie;
	if (!mesh_intersect_world_packet(in->mesh, in->inv, n, r, tmin, tmax, w->nplanes ? tm : NULL, t, slot, b, &got,
	                                 &tie))
		return false;
	world_rays_count(n);
	if (w->nplanes) {
		for (int i = 0; i < n; i++) {
			found[i] = best_plane[i] != NULL;
			if (found[i] && !(got >> i & 1u))
				th[i] = (trace_hit){tm[i], NULL, best_plane[i], {0, 0, 0}};
		}
	} else {
		memset(found, 0, (size_t)n * sizeof *found);
	}
	for (unsigned g = got; g; g &= g - 1) {
		int i = __builtin_ctz(g);
		th[i] = (trace_hit){t[i], p, NULL, {(double)slot[i], b[i][1], b[i][2]}};
		found[i] = true;
	}
	for (; tie; tie &= tie - 1) {
		int i = __builtin_ctz(tie);
		world_rays_count(-1);
		found[i] = world_trace_coherent(w, &r[i], tmin, tmax, &th[i]);
	}
	return true;
}

/* plane_hit_o for rays i and i + 1 of s, each lane its operations in its
 * order: the slope dy = h . d, the distance *tt = -oy / dy, and the lanes
 * where dy is not 0 and tmin < *tt < tmax (NaN fails every compare, as
 * there). oy: the origins' height over the plane, plane_oy's operations
 * on each lane's origin, or *oy1 when given (rays of one origin). */
static inline __m128d plane_hit2(const prim_plane *pl, const pk_state *s, int i, const __m128d *oy1, double tmin,
                                 __m128d tmax, __m128d *tt)
{
	const __m128d h0 = _mm_set1_pd(pl->h[0]), h1 = _mm_set1_pd(pl->h[1]), h2 = _mm_set1_pd(pl->h[2]);
	__m128d oy = oy1 ? *oy1
	                 : _mm_add_pd(_mm_add_pd(_mm_add_pd(_mm_mul_pd(h0, _mm_load_pd(&s->ox[i])),
	                                                    _mm_mul_pd(h1, _mm_load_pd(&s->oy[i]))),
	                                         _mm_mul_pd(h2, _mm_load_pd(&s->oz[i]))),
	                              _mm_set1_pd(pl->h[3]));
	__m128d dy = _mm_add_pd(_mm_add_pd(_mm_mul_pd(h0, _mm_load_pd(&s->dx[i])), _mm_mul_pd(h1, _mm_load_pd(&s->dy[i]))),
	                        _mm_mul_pd(h2, _mm_load_pd(&s->dz[i])));
	*tt = _mm_div_pd(_mm_xor_pd(oy, _mm_set1_pd(-0.0)), dy);
	return _mm_and_pd(_mm_cmpneq_pd(dy, _mm_setzero_pd()),
	                  _mm_and_pd(_mm_cmpgt_pd(*tt, _mm_set1_pd(tmin)), _mm_cmplt_pd(*tt, tmax)));
}

/* The planes beside the tree for the rays of s, as trace tests them (the
 * nearest in the planes' order, each with plane_hit's test): s->tmax[i]
 * from tmax down to the nearest plane's distance, best_plane[i] that plane
 * or NULL. Two rays per SSE2 register, each lane plane_hit_o's operations
 * in its order: dy = h . d, -oy / dy, the strict test against tmin and the
 * nearest so far (dy == 0 fails as there; a NaN fails every compare, as
 * there). Rays of one origin share its height over each plane (plane_oy,
 * once a plane: see world_trace_packet); others each compute their own,
 * plane_oy's operations in its order. */
static void packet_planes(const world *w, pk_state *s, double tmin, double tmax, const prim_plane **best_plane)
{
	int n = s->n, even = (n + 1) & ~1;
	for (int i = 0; i < even; i += 2) {
		_mm_store_pd(&s->tmax[i], _mm_set1_pd(tmax)); /* (whole: the loads below are forwarded) */
		best_plane[i] = best_plane[i + 1] = NULL;
	}
	unsigned any = 0;
	/* Origins equal as doubles may differ in the sign of a zero, and so
	 * may oy, only when it is zero: then -oy / dy is a zero (or NaN) that
	 * no tmin >= 0 lets through either way. */
	bool one = s->one_o && tmin >= 0.0;
	for (size_t k = 0; k < w->nplanes; k++) {
		const prim_plane *pl = &w->planes[k];
		const __m128d oy1 = _mm_set1_pd(one ? plane_oy(pl, (vec3){s->ox[0], s->oy[0], s->oz[0]}) : 0.0);
		for (int i = 0; i < n; i += 2) {
			__m128d tt, t = _mm_load_pd(&s->tmax[i]);
			__m128d m = plane_hit2(pl, s, i, one ? &oy1 : NULL, tmin, t, &tt);
			_mm_store_pd(&s->tmax[i], _mm_or_pd(_mm_and_pd(m, tt), _mm_andnot_pd(m, t)));
			/* (without branches: which rays meet a plane first follows the
			 * picture, not a pattern the branch predictor learns) */
			int bits = _mm_movemask_pd(m);
			best_plane[i] = bits & 1 ? pl : best_plane[i];
			best_plane[i + 1] = bits & 2 ? pl : best_plane[i + 1]; /* (the pad's entry exists: even <= PACKET_MAX) */
			any |= (unsigned)bits << i;
		}
	}
	s->plane = any & ((1u << n) - 1);
}

/* The packet's walk of rays r[0..n) (n <= PACKET_MAX) into s, the planes'
 * nearest into best_plane: false when the rays are not traced as a packet
 * (too few, not coherent, an empty tree), to be traced alone. */
static bool packet_trace(const world *w, int n, const ray *r, double tmin, double tmax, pk_state *s,
                         const prim_plane **best_plane)
{
	pk_ray q;
	if (n < 2 || !w->nprims)
		return false;
	if (!packet_prepare(s, r, n, &q))
		return false;
	world_rays_count(n);
	s->one_o = q.one_o;
	s->got = s->sph = s->tie = 0;
	packet_planes(w, s, tmin, tmax, best_plane);
	packet_walk(w, s, r, &q, tmin);
	return true;
}

static bool lone_model(const world *w)
{
	return w->nprims == 1 && w->prims[0].tag == PRIM_MESH;
}

void world_trace_packet(const world *w, int n, const ray *r, double tmin, double tmax, trace_hit *th, bool *found)
{
	pk_state s;
	const prim_plane *best_plane[PACKET_MAX];
	bool lone = lone_model(w);
	if (lone && n >= 2 && n <= PACKET_MAX && model_packet(w, n, r, tmin, tmax, th, found))
		return;
	if (n > PACKET_MAX || lone || !packet_trace(w, n, r, tmin, tmax, &s, best_plane)) {
		for (int i = 0; i < n; i++)
			found[i] = world_trace_coherent(w, &r[i], tmin, tmax, &th[i]);
		return;
	}
	for (int i = 0; i < n; i++) {
		if (s.tie >> i & 1) {
			world_rays_count(-1);
			found[i] = world_trace_coherent(w, &r[i], tmin, tmax, &th[i]);
			continue;
		}
		bool got = s.got >> i & 1;
		th[i].t = s.tmax[i];
		th[i].prim = got ? s.best[i] : NULL;
		th[i].plane = got ? NULL : best_plane[i];
		th[i].nl = got ? s.nl[i] : (vec3){0, 0, 0};
		found[i] = got || best_plane[i];
	}
}

/* Rays a and b of s (lanes 0 and 1) on a point of their hit: o + d t, as
 * ray_at. */
static inline void pk_point2(const pk_state *s, int a, int b, __m128d *px, __m128d *py, __m128d *pz)
{
	__m128d t = _mm_set_pd(s->tmax[b], s->tmax[a]);
	*px = _mm_add_pd(_mm_set_pd(s->ox[b], s->ox[a]), _mm_mul_pd(_mm_set_pd(s->dx[b], s->dx[a]), t));
	*py = _mm_add_pd(_mm_set_pd(s->oy[b], s->oy[a]), _mm_mul_pd(_mm_set_pd(s->dy[b], s->dy[a]), t));
	*pz = _mm_add_pd(_mm_set_pd(s->oz[b], s->oz[a]), _mm_mul_pd(_mm_set_pd(s->dz[b], s->dz[a]), t));
}

/* Whether n . d < 0 for rays a and b (bits 0 and 1), as v3_dot(n, d) < 0.0
 * computes it, n given by component for each lane. */
static inline int pk_front2(const pk_state *s, int a, int b, __m128d nx, __m128d ny, __m128d nz)
{
	__m128d dot = _mm_add_pd(_mm_add_pd(_mm_mul_pd(nx, _mm_set_pd(s->dx[b], s->dx[a])),
	                                    _mm_mul_pd(ny, _mm_set_pd(s->dy[b], s->dy[a]))),
	                         _mm_mul_pd(nz, _mm_set_pd(s->dz[b], s->dz[a])));
	return _mm_movemask_pd(_mm_cmplt_pd(dot, _mm_setzero_pd()));
}

static inline void store2(__m128d v, double *a, double *b)
{
	_mm_storel_pd(a, v);
	_mm_storeh_pd(b, v);
}

/* The hit records of the rays of s on plane pl (bits on): world_finish's
 * (finish_plane, surf_shape_uv), two rays at a time, each lane its
 * operations in its order; an odd one out through world_finish itself. */
static void finish_planes(const world *w, const pk_state *s, const ray *r, const prim_plane *pl, unsigned on, hit *h)
{
	const prim_shape *sh = &w->shapes[pl->shape];
	const double(*m)[4] = sh->inv;
	const __m128d m00 = _mm_set1_pd(m[0][0]), m01 = _mm_set1_pd(m[0][1]), m02 = _mm_set1_pd(m[0][2]);
	const __m128d m03 = _mm_set1_pd(m[0][3]), m10 = _mm_set1_pd(m[1][0]), m11 = _mm_set1_pd(m[1][1]);
	const __m128d m12 = _mm_set1_pd(m[1][2]), m13 = _mm_set1_pd(m[1][3]), m20 = _mm_set1_pd(m[2][0]);
	const __m128d m21 = _mm_set1_pd(m[2][1]), m22 = _mm_set1_pd(m[2][2]), m23 = _mm_set1_pd(m[2][3]);
	const __m128d nx = _mm_set1_pd(pl->n.x), ny = _mm_set1_pd(pl->n.y), nz = _mm_set1_pd(pl->n.z);
	const bool uv = surf_wants_uv(w, pl->object);
	while (on & (on - 1)) {
		int a = __builtin_ctz(on);
		on &= on - 1;
		int b = __builtin_ctz(on);
		on &= on - 1;
		__m128d px, py, pz;
		pk_point2(s, a, b, &px, &py, &pz);
		int front = pk_front2(s, a, b, nx, ny, nz);
		/* m[k][0] x + m[k][1] y + m[k][2] z + m[k][3], in that order */
		__m128d lx = _mm_add_pd(_mm_add_pd(_mm_add_pd(_mm_mul_pd(m00, px), _mm_mul_pd(m01, py)), _mm_mul_pd(m02, pz)), m03);
		__m128d ly = _mm_add_pd(_mm_add_pd(_mm_add_pd(_mm_mul_pd(m10, px), _mm_mul_pd(m11, py)), _mm_mul_pd(m12, pz)), m13);
		__m128d lz = _mm_add_pd(_mm_add_pd(_mm_add_pd(_mm_mul_pd(m20, px), _mm_mul_pd(m21, py)), _mm_mul_pd(m22, pz)), m23);
		hit *ha = &h[a], *hb = &h[b];
		ha->t = s->tmax[a];
		hb->t = s->tmax[b];
		store2(px, &ha->p.x, &hb->p.x);
		store2(py, &ha->p.y, &hb->p.y);
		store2(pz, &ha->p.z, &hb->p.z);
		store2(lx, &ha->local.x, &hb->local.x);
		store2(ly, &ha->local.y, &hb->local.y);
		store2(lz, &ha->local.z, &hb->local.z);
		ha->n = hb->n = pl->n;
		ha->object = hb->object = pl->object;
		ha->front = front & 1;
		hb->front = front >> 1 & 1;
		if (uv) {
			surf_shape_uv(w, sh, pl->n, ha);
			surf_shape_uv(w, sh, pl->n, hb);
		} else {
			ha->mat = hb->mat = pl->object;
			ha->has_uv = hb->has_uv = false;
		}
	}
	if (on) {
		int a = __builtin_ctz(on);
		trace_hit th = {s->tmax[a], NULL, pl, {0, 0, 0}};
		world_finish(w, &r[a], &th, &h[a]);
	}
}

/* The hit records of rays a and b of s on spheres pa and pb: finish_hit's
 * for a sphere, each lane its operations in its order (the normal
 * v3_norm(p - c): the squared length, its sqrt, 1 / that, the products). */
static void finish_sphere2(const pk_state *s, const prim *pa, const prim *pb, int a, int b, hit *h)
{
	__m128d px, py, pz;
	pk_point2(s, a, b, &px, &py, &pz);
	__m128d vx = _mm_sub_pd(px, _mm_set_pd(pb->u.sph.c.x, pa->u.sph.c.x));
	__m128d vy = _mm_sub_pd(py, _mm_set_pd(pb->u.sph.c.y, pa->u.sph.c.y));
	__m128d vz = _mm_sub_pd(pz, _mm_set_pd(pb->u.sph.c.z, pa->u.sph.c.z));
	__m128d len = _mm_sqrt_pd(_mm_add_pd(_mm_add_pd(_mm_mul_pd(vx, vx), _mm_mul_pd(vy, vy)), _mm_mul_pd(vz, vz)));
	__m128d inv = _mm_div_pd(_mm_set1_pd(1.0), len);
	__m128d nx = _mm_mul_pd(vx, inv), ny = _mm_mul_pd(vy, inv), nz = _mm_mul_pd(vz, inv);
	int front = pk_front2(s, a, b, nx, ny, nz);
	const prim *p[2] = {pa, pb};
	int idx[2] = {a, b};
	for (int k = 0; k < 2; k++) {
		hit *o = &h[idx[k]];
		o->t = s->tmax[idx[k]];
		o->object = p[k]->object;
		o->mat = p[k]->object;
		o->has_uv = false;
		o->front = front >> k & 1;
	}
	store2(px, &h[a].p.x, &h[b].p.x);
	store2(py, &h[a].p.y, &h[b].p.y);
	store2(pz, &h[a].p.z, &h[b].p.z);
	/* (local = n: stored from the registers, not copied from the record,
	 * whose halves, just stored one by one, a 16-byte load would wait for) */
	store2(nx, &h[a].n.x, &h[b].n.x);
	store2(ny, &h[a].n.y, &h[b].n.y);
	store2(nz, &h[a].n.z, &h[b].n.z);
	store2(nx, &h[a].local.x, &h[b].local.x);
	store2(ny, &h[a].local.y, &h[b].local.y);
	store2(nz, &h[a].local.z, &h[b].local.z);
}

void world_intersect_packet(const world *w, int n, const ray *r, double tmin, double tmax, hit *h, bool *found)
{
	pk_state s;
	const prim_plane *best_plane[PACKET_MAX];
	bool lone = lone_model(w);
	if (lone || n > PACKET_MAX || !packet_trace(w, n, r, tmin, tmax, &s, best_plane)) {
		trace_hit th[PACKET_MAX];
		if (!lone || n > PACKET_MAX) {
			for (int i = 0; i < n; i++)
				found[i] = world_intersect_coherent(w, &r[i], tmin, tmax, &h[i]);
			return;
		}
		world_trace_packet(w, n, r, tmin, tmax, th, found);
		for (int i = 0; i < n; i++)
			if (found[i])
				world_finish(w, &r[i], &th[i], &h[i]);
		return;
	}
	/* the hit records: rays on one plane by pairs, rays on spheres by
	 * pairs, the rest (ties, other primitives) one by one as world_finish
	 * makes them; sorted by the walk's bits, not by branches on each ray
	 * (which rays end on a sphere and which on the plane follows the
	 * picture: a branch on it is mispredicted often) */
	unsigned tie = s.tie;
	unsigned sph = s.got & s.sph & ~tie, pln = s.plane & ~s.got & ~tie, alone = tie | (s.got & ~s.sph);
	unsigned hit_any = s.got | s.plane;
	for (int i = 0; i < n; i++)
		found[i] = hit_any >> i & 1;
	for (; alone; alone &= alone - 1) {
		int i = __builtin_ctz(alone);
		if (tie >> i & 1) {
			world_rays_count(-1);
			found[i] = world_intersect_coherent(w, &r[i], tmin, tmax, &h[i]);
		} else {
			trace_hit th = {s.tmax[i], s.best[i], NULL, s.nl[i]};
			world_finish(w, &r[i], &th, &h[i]);
		}
	}
	while (pln) {
		/* the rays on the first ray's plane, then those on the next */
		const prim_plane *pl = best_plane[__builtin_ctz(pln)];
		unsigned on = w->nplanes == 1 ? pln : 0;
		for (unsigned m = on ? 0 : pln; m; m &= m - 1) {
			int i = __builtin_ctz(m);
			on |= (unsigned)(best_plane[i] == pl) << i;
		}
		pln &= ~on;
		finish_planes(w, &s, r, pl, on, h);
	}
	while (sph & (sph - 1)) {
		int a = __builtin_ctz(sph);
		sph &= sph - 1;
		int b = __builtin_ctz(sph);
		sph &= sph - 1;
		finish_sphere2(&s, s.best[a], s.best[b], a, b, h);
	}
	if (sph) {
		int a = __builtin_ctz(sph);
		trace_hit th = {s.tmax[a], s.best[a], NULL, s.nl[a]};
		world_finish(w, &r[a], &th, &h[a]);
	}
}

/* --- any hit: shadow rays --- */

/* The rays of s not yet known to be blocked: bit i for ray i. */
static void leaf_occluded(const world *w, pk_state *s, unsigned *live, const prim *p, const ray *r, double tmin)
{
	/* (a model here is met ray by ray: shadow rays that reach a leaf of the
	 * object tree come from points far apart, and as one packet through
	 * the model's tree they made instances.rt 1.6x slower) */
	if (p->tag != PRIM_SPHERE) {
		for (unsigned m = *live; m; m &= m - 1) {
			int i = __builtin_ctz(m);
			if (world_prim_occluded(w, p, &r[i], tmin, s->tmax[i]))
				*live &= ~(1u << i);
		}
		return;
	}
	const pk_sphere sph = pk_sphere_of(p);
	for (int i = 0; i < s->n; i += 2) {
		if (!(*live >> i & 3u))
			continue;
		unsigned m = sphere_disc2(s, i, &sph) & (*live >> i);
		for (; m; m &= m - 1) {
			int j = i + __builtin_ctz(m);
			double t;
			if (sphere_hit(p, &r[j], tmin, s->tmax[j], &t))
				*live &= ~(1u << j);
		}
	}
}

/* Whether a plane of w blocks r between tmin and tmax (world_occluded's
 * planes, tested before its tree: model_occluded, world_occluded_packet). */
static bool planes_block(const world *w, const ray *r, double tmin, double tmax)
{
	double t;
	for (size_t k = 0; k < w->nplanes; k++)
		if (plane_hit(&w->planes[k], r, tmin, tmax, &t))
			return true;
	return false;
}

/* The rays of s (bits) that a plane blocks between tmin and tmax[i]:
 * planes_block's test (plane_hit) two rays per SSE2 register, each lane
 * its operations in its order (the origin's height h . o + h[3], the
 * slope h . d, -oy / dy, the strict tests; dy == 0 and NaN fail as
 * there). */
static unsigned packet_planes_block(const world *w, const pk_state *s, double tmin, const double *tmax)
{
	int n = s->n;
	unsigned blocked = 0;
	for (size_t k = 0; k < w->nplanes; k++) {
		const prim_plane *pl = &w->planes[k];
		for (int i = 0; i < n; i += 2) {
			__m128d tt, tm = _mm_set_pd(i + 1 < n ? tmax[i + 1] : tmax[i], tmax[i]);
			blocked |= (unsigned)_mm_movemask_pd(plane_hit2(pl, s, i, NULL, tmin, tm, &tt)) << i;
		}
	}
	return blocked & ((1u << n) - 1);
}

/* Shadow rays on a lone model: the planes first for each ray, as
 * world_occluded, then the rays they leave through the model's triangle
 * tree in one packet (mesh_occluded_world_packet). False when that packet
 * is not traced: the caller traces each ray alone. */
static bool model_occluded(const world *w, int n, const ray *r, double tmin, const double *tmax, bool *occ)
{
	const prim_inst *in = &w->insts[w->prims[0].u.index];
	ray rl[PACKET_MAX];
	double tl[PACKET_MAX];
	int at[PACKET_MAX], nl = 0;
	for (int i = 0; i < n; i++) {
		bool blocked = planes_block(w, &r[i], tmin, tmax[i]);
		occ[i] = blocked;
		if (!blocked) {
			rl[nl] = r[i];
			tl[nl] = tmax[i];
			at[nl++] = i;
		}
	}
	unsigned got = 0;
	if (nl > 0 && !mesh_occluded_world_packet(in->mesh, in->inv, nl, rl, tmin, tl, &got))
		return false;
	world_rays_count(n);
	for (int k = 0; k < nl; k++)
		occ[at[k]] = got >> k & 1u;
	return true;
}

void world_occluded_packet(const world *w, int n, const ray *r, double tmin, const double *tmax, bool *occ)
{
	pk_ray q;
	bool lone_model = w->nprims == 1 && w->prims[0].tag == PRIM_MESH;
	if (lone_model && n >= 2 && n <= PACKET_MAX && model_occluded(w, n, r, tmin, tmax, occ))
		return;
	pk_state s;
	if (n < 2 || n > PACKET_MAX || lone_model || !packet_prepare(&s, r, n, &q)) {
		for (int i = 0; i < n; i++)
			occ[i] = world_occluded(w, &r[i], tmin, tmax[i]);
		return;
	}
	world_rays_count(n);
	s.one_o = false;
	unsigned live = ((1u << n) - 1) & ~packet_planes_block(w, &s, tmin, tmax);
	for (int i = 0; i < n; i++) {
		occ[i] = !(live >> i & 1u);
		s.tmax[i] = tmax[i];
	}
	if (w->nprims && live) {
		const bvh_node *nodes = w->tree->nodes;
		float ftmin = to_float_down(tmin);
		double far = 0;
		for (int i = 0; i < n; i++)
			far = tmax[i] > far ? tmax[i] : far;
		float ftmax = to_float_up(far);
		/* each ray's own slab test, as the single walk does it: a node the
		 * packet's interval lets through is entered only when a ray still
		 * live enters it too (shadow rays from points far apart make a
		 * wide interval: with 1M small spheres it let through most of the
		 * tree). The rays are tried in turn until they cover what the
		 * interval let through, and a packet whose first 32 nodes culled
		 * nothing stops trying (the grid's packets are that tight). */
		bvh_ray one[PACKET_MAX];
		float ftmax1[PACKET_MAX];
		unsigned ready = 0; /* the rays whose one[] is filled */
		bool refine = true;
		int tried = 0, culled = 0;
		bvh_entry stack[BVH_STACK];
		int sp = 0;
		uint32_t child = w->tree->root, meta = w->tree->root_meta;
		for (;;) {
			if (meta) {
				const prim *p = &w->prims[child];
				uint32_t count = meta & ~BVH_LEAF;
				for (uint32_t k = 0; k < count && live; k++)
					leaf_occluded(w, &s, &live, &p[k], r, tmin);
				if (!live)
					break;
			} else {
				float tn[BVH_WIDTH];
				unsigned m = packet_slab4(&nodes[child], &q, ftmin, ftmax, tn);
				if (m && refine) {
					unsigned got = 0;
					float t1[BVH_WIDTH];
					for (unsigned lv = live; lv && (got & m) != m; lv &= lv - 1) {
						int i = __builtin_ctz(lv);
						if (!(ready >> i & 1u)) {
							bvh_ray_prepare(&r[i], &one[i]);
							ftmax1[i] = to_float_up(tmax[i]);
							ready |= 1u << i;
						}
						got |= bvh_slab4(&nodes[child], &one[i], ftmin, ftmax1[i], t1);
					}
					tried++;
					culled += (m & ~got) != 0;
					m &= got;
					/* a packet whose interval is tight wastes the rays'
					 * tests: after 32 nodes with nothing culled, stop */
					refine = culled > 0 || tried < 32;
				}
				if (m) {
					sp = bvh_enter_any(&nodes[child], m, tn, stack, sp, &child, &meta);
					continue;
				}
			}
			if (sp == 0)
				break;
			sp--;
			child = stack[sp].child;
			meta = stack[sp].meta;
		}
	}
	for (int i = 0; i < n; i++)
		occ[i] = occ[i] || !(live >> i & 1u);
}
