/* rtsh — the packets' walk of a mesh's tree (mesh_intersect_world_packet,
 * mesh_occluded_world_packet), written once and included by mesh_trace.c
 * for each vector unit that has it: PK(name) names its functions,
 * PK_TARGET is their target attribute (AVX2, or AVX2 given AVX-512's 32
 * vector registers, as the single walk's copies). Both do the same float
 * operations in the same order, so both find the same hits. */

/* The rays (a bit each) whose own slab test, the single walk's floats,
 * lets them into column k of node p. */
static PK_TARGET inline unsigned PK(rays_in)(const mesh_packet *s, const mesh_node *p, uint32_t k, float box_tmin, size_t rn0,
                                       size_t rn1, size_t rn2)
{
#define ROW(n, off) ((const float *)((const char *)(n)->b + (off)))
	const __m256 nx = _mm256_set1_ps(ROW(p, rn0)[k]), ny = _mm256_set1_ps(ROW(p, rn1)[k]),
		     nz = _mm256_set1_ps(ROW(p, rn2)[k]);
	const __m256 gx = _mm256_set1_ps(ROW(p, rn0 ^ MESH_ROW)[k]), gy = _mm256_set1_ps(ROW(p, rn1 ^ MESH_ROW)[k]),
		     gz = _mm256_set1_ps(ROW(p, rn2 ^ MESH_ROW)[k]);
#undef ROW
	unsigned m = 0;
	for (int h = 0; h < MESH_PACKET_MAX; h += 8) {
		__m256 ox = _mm256_load_ps(&s->ox[h]), oy = _mm256_load_ps(&s->oy[h]), oz = _mm256_load_ps(&s->oz[h]);
		__m256 t0 = _mm256_max_ps(_mm256_mul_ps(_mm256_sub_ps(nx, ox), _mm256_load_ps(&s->ix[h])),
					  _mm256_set1_ps(box_tmin));
		__m256 t1 = _mm256_min_ps(_mm256_mul_ps(_mm256_sub_ps(gx, ox), _mm256_load_ps(&s->fx[h])),
					  _mm256_load_ps(&s->bs[h]));
		t0 = _mm256_max_ps(_mm256_mul_ps(_mm256_sub_ps(ny, oy), _mm256_load_ps(&s->iy[h])), t0);
		t1 = _mm256_min_ps(_mm256_mul_ps(_mm256_sub_ps(gy, oy), _mm256_load_ps(&s->fy[h])), t1);
		t0 = _mm256_max_ps(_mm256_mul_ps(_mm256_sub_ps(nz, oz), _mm256_load_ps(&s->iz[h])), t0);
		t1 = _mm256_min_ps(_mm256_mul_ps(_mm256_sub_ps(gz, oz), _mm256_load_ps(&s->fz[h])), t1);
		m |= (unsigned)_mm256_movemask_ps(_mm256_cmp_ps(t0, t1, _CMP_LE_OQ)) << h;
	}
	return m;
}

/* Every ray's triangle set-up and tmin by component, as ray_leaf_setup
 * and the single walk's first leaf make them (the same selections and the
 * same operations, eight rays at a time): the origin on the axes kx, ky,
 * kz, the shear constants, the axes themselves. */
static PK_TARGET inline void PK(ready)(mesh_packet *s)
{
	const __m256 mag = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff)), zero = _mm256_setzero_ps();
	const __m256i i0 = _mm256_setzero_si256(), i1 = _mm256_set1_epi32(1), i2 = _mm256_set1_epi32(2);
	for (int h = 0; h < MESH_PACKET_MAX; h += 8) {
		__m256 dx = _mm256_load_ps(&s->dx[h]), dy = _mm256_load_ps(&s->dy[h]), dz = _mm256_load_ps(&s->dz[h]);
		__m256 ax = _mm256_and_ps(dx, mag), ay = _mm256_and_ps(dy, mag), az = _mm256_and_ps(dz, mag);
		/* kz: 2 when !(max(ax, ay) > az), else 1 when !(ax > ay), else 0 */
		__m256i kxy = _mm256_castps_si256(_mm256_cmp_ps(ax, ay, _CMP_NGT_UQ)); /* all ones: kz 1 */
		__m256i zbig = _mm256_castps_si256(_mm256_cmp_ps(_mm256_max_ps(ax, ay), az, _CMP_NGT_UQ));
		__m256i kz = _mm256_blendv_epi8(_mm256_blendv_epi8(i0, i1, kxy), i2, zbig);
		/* kx = next[kz], ky = next[kx] (next: 1, 2, 0), swapped when
		 * d[kz] < 0 */
		__m256i kz0 = _mm256_cmpeq_epi32(kz, i0), kz1 = _mm256_cmpeq_epi32(kz, i1);
		__m256i kx = _mm256_blendv_epi8(_mm256_blendv_epi8(i0, i2, kz1), i1, kz0);
		__m256i ky = _mm256_blendv_epi8(_mm256_blendv_epi8(i1, i0, kz1), i2, kz0);
		__m256 dkz = _mm256_blendv_ps(_mm256_blendv_ps(dz, dy, _mm256_castsi256_ps(kz1)), dx,
					      _mm256_castsi256_ps(kz0));
		__m256i neg = _mm256_castps_si256(_mm256_cmp_ps(dkz, zero, _CMP_LT_OQ));
		__m256i kx2 = _mm256_blendv_epi8(kx, ky, neg), ky2 = _mm256_blendv_epi8(ky, kx, neg);
		/* a component by axis k: x, y or z of each lane */
#define PICK(k, vx, vy, vz)                                                                                            \
	_mm256_blendv_ps(_mm256_blendv_ps(vz, vy, _mm256_castsi256_ps(_mm256_cmpeq_epi32(k, i1))), vx,                 \
			 _mm256_castsi256_ps(_mm256_cmpeq_epi32(k, i0)))
		__m256 ox = _mm256_load_ps(&s->ox[h]), oy = _mm256_load_ps(&s->oy[h]), oz = _mm256_load_ps(&s->oz[h]);
		__m256 sz = PICK(kz, _mm256_load_ps(&s->ix[h]), _mm256_load_ps(&s->iy[h]), _mm256_load_ps(&s->iz[h]));
		_mm256_store_ps(&s->ksz[h], sz);
		_mm256_store_ps(&s->ksx[h], _mm256_mul_ps(PICK(kx2, dx, dy, dz), sz));
		_mm256_store_ps(&s->ksy[h], _mm256_mul_ps(PICK(ky2, dx, dy, dz), sz));
		_mm256_store_ps(&s->kox[h], PICK(kx2, ox, oy, oz));
		_mm256_store_ps(&s->koy[h], PICK(ky2, ox, oy, oz));
		_mm256_store_ps(&s->koz[h], PICK(kz, ox, oy, oz));
#undef PICK
		__m256i axes = _mm256_or_si256(_mm256_or_si256(kx2, _mm256_slli_epi32(ky2, 2)), _mm256_slli_epi32(kz, 4));
		_mm256_store_si256((__m256i *)&s->axes[h], axes);
		/* tmin raised to eps / |d| (tm > g ? tm : g, as maxps) */
		__m256 tm = _mm256_set1_ps(s->tmin0);
		if (s->eps > 0.0f) {
			__m256 dd = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)), _mm256_mul_ps(dz, dz));
			tm = _mm256_max_ps(tm, _mm256_div_ps(_mm256_set1_ps(s->eps), _mm256_sqrt_ps(dd)));
		}
		_mm256_store_ps(&s->tmin[h], tm);
	}
	s->ready = 1;
}


/* Ray i meets the blocks of leaf `ref`, with the single ray's block test
 * (its bound the next float above its best, so that a triangle at exactly
 * that distance is seen). */
static PK_TARGET inline void PK(leaf)(const mesh *m, mesh_packet *s, int i, uint32_t ref)
{
	uint32_t first = ref & (MESH_MAX_BLOCKS - 1), nb = ((ref & ~MESH_LEAF) >> MESH_LEAF_SHIFT) + 1;
	mesh_ray r;
	r.o[0] = s->ox[i];
	r.o[1] = s->oy[i];
	r.o[2] = s->oz[i];
	r.kx = s->axes[i] & 3;
	r.ky = s->axes[i] >> 2 & 3;
	r.kz = s->axes[i] >> 4;
	r.sx = s->ksx[i];
	r.sy = s->ksy[i];
	r.sz = s->ksz[i];
	ray4 rq;
	ray4_make(&r, &rq);
	for (uint32_t k = 0; k < nb; k++) {
		float bt = s->bt[i], bb[3];
		int l = block_sse(m, first + k, &m->blk[first + k], &r, &rq, s->tmin[i], &bt, bb);
		if (l >= 0)
			pk_take(s, i, 4 * (first + k) + (uint32_t)l, bt, bb[0], bb[1], bb[2]);
	}
}

/* The rays `in` (ready, with the same axes kx, ky, kz) meet the blocks of
 * leaf `ref` eight at a time: each triangle of a block against eight rays
 * in one register, block_sse's operations in its order lane by lane (the
 * lanes are rays here, not triangles), and per ray the block's pick as
 * block_sse makes it: the nearest of the triangles with tmin < t < bt, the
 * first on a tie. No cut-outs here (PK(leaf) has them). */
static PK_TARGET inline void PK(leaf_rays)(const mesh *m, mesh_packet *s, unsigned in, uint32_t ref, int kx, int ky, int kz)
{
	uint32_t first = ref & (MESH_MAX_BLOCKS - 1), nb = ((ref & ~MESH_LEAF) >> MESH_LEAF_SHIFT) + 1;
	const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f), inf = _mm256_set1_ps(INFINITY);
	const __m256i bits = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
	for (int h = 0; h < MESH_PACKET_MAX; h += 8) {
		unsigned hm = in >> h & 0xffu;
		if (!hm)
			continue;
		const __m256 act = _mm256_castsi256_ps(
			_mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32((int)hm), bits), bits));
		const __m256 ox = _mm256_load_ps(&s->kox[h]), oy = _mm256_load_ps(&s->koy[h]), oz = _mm256_load_ps(&s->koz[h]);
		const __m256 sx = _mm256_load_ps(&s->ksx[h]), sy = _mm256_load_ps(&s->ksy[h]), sz = _mm256_load_ps(&s->ksz[h]);
		const __m256 tmin = _mm256_load_ps(&s->tmin[h]);
		for (uint32_t k = 0; k < nb; k++) {
			const mesh_tri4 *q = &m->blk[first + k];
			const __m256 bt = _mm256_load_ps(&s->bt[h]);
			__m256 pick = inf, pu = zero, pv = zero, pw = zero;
			__m256i pl = _mm256_set1_epi32(-1);
			for (int l = 0; l < 4; l++) {
				__m256 az = _mm256_sub_ps(_mm256_set1_ps(q->v[kz][l]), oz);
				__m256 bz = _mm256_sub_ps(_mm256_set1_ps(q->v[3 + kz][l]), oz);
				__m256 cz = _mm256_sub_ps(_mm256_set1_ps(q->v[6 + kz][l]), oz);
				__m256 ax = _mm256_sub_ps(_mm256_sub_ps(_mm256_set1_ps(q->v[kx][l]), ox), _mm256_mul_ps(sx, az));
				__m256 ay = _mm256_sub_ps(_mm256_sub_ps(_mm256_set1_ps(q->v[ky][l]), oy), _mm256_mul_ps(sy, az));
				__m256 bx = _mm256_sub_ps(_mm256_sub_ps(_mm256_set1_ps(q->v[3 + kx][l]), ox), _mm256_mul_ps(sx, bz));
				__m256 by = _mm256_sub_ps(_mm256_sub_ps(_mm256_set1_ps(q->v[3 + ky][l]), oy), _mm256_mul_ps(sy, bz));
				__m256 cx = _mm256_sub_ps(_mm256_sub_ps(_mm256_set1_ps(q->v[6 + kx][l]), ox), _mm256_mul_ps(sx, cz));
				__m256 cy = _mm256_sub_ps(_mm256_sub_ps(_mm256_set1_ps(q->v[6 + ky][l]), oy), _mm256_mul_ps(sy, cz));
				__m256 u = _mm256_sub_ps(_mm256_mul_ps(cx, by), _mm256_mul_ps(cy, bx));
				__m256 v = _mm256_sub_ps(_mm256_mul_ps(ax, cy), _mm256_mul_ps(ay, cx));
				__m256 w = _mm256_sub_ps(_mm256_mul_ps(bx, ay), _mm256_mul_ps(by, ax));
				__m256 lo = _mm256_min_ps(_mm256_min_ps(u, v), w), hi = _mm256_max_ps(_mm256_max_ps(u, v), w);
				unsigned zm = (unsigned)_mm256_movemask_ps(
						      _mm256_or_ps(_mm256_cmp_ps(lo, zero, _CMP_EQ_OQ), _mm256_cmp_ps(hi, zero, _CMP_EQ_OQ))) &
					      hm;
				if (zm) {
					/* an edge function at zero: in double, as wt_test */
					EDGES_IN_DOUBLE(8, __m256, _mm256_store_ps, _mm256_load_ps, _mm256_min_ps, _mm256_max_ps);
				}
				__m256 out = _mm256_and_ps(_mm256_cmp_ps(lo, zero, _CMP_LT_OQ), _mm256_cmp_ps(hi, zero, _CMP_GT_OQ));
				/* no ray of the eight meets it: the next (coherent rays
				 * mostly agree; a NaN lane goes on, to fail on its
				 * distance) */
				if (!_mm256_movemask_ps(_mm256_andnot_ps(out, act)))
					continue;
				__m256 det = _mm256_add_ps(_mm256_add_ps(u, v), w);
				__m256 tt = _mm256_mul_ps(
					_mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(u, az), _mm256_mul_ps(v, bz)), _mm256_mul_ps(w, cz)), sz);
				__m256 inv = _mm256_div_ps(one, det);
				__m256 th = _mm256_mul_ps(tt, inv);
				__m256 ok = _mm256_andnot_ps(out, _mm256_and_ps(_mm256_cmp_ps(th, tmin, _CMP_GT_OQ),
										_mm256_cmp_ps(th, bt, _CMP_LT_OQ)));
				/* the nearest so far in the block, the first on a tie */
				__m256 better = _mm256_and_ps(_mm256_and_ps(ok, act), _mm256_cmp_ps(th, pick, _CMP_LT_OQ));
				if (!_mm256_movemask_ps(better))
					continue;
				pick = _mm256_blendv_ps(pick, th, better);
				pl = _mm256_castps_si256(
					_mm256_blendv_ps(_mm256_castsi256_ps(pl), _mm256_castsi256_ps(_mm256_set1_epi32(l)), better));
				pu = _mm256_blendv_ps(pu, _mm256_mul_ps(u, inv), better);
				pv = _mm256_blendv_ps(pv, _mm256_mul_ps(v, inv), better);
				pw = _mm256_blendv_ps(pw, _mm256_mul_ps(w, inv), better);
			}
			unsigned got = ~(unsigned)_mm256_movemask_ps(_mm256_castsi256_ps(pl)) & hm;
			if (!got)
				continue;
			_Alignas(32) float fp[8], fu[8], fv[8], fw[8];
			_Alignas(32) int32_t fl[8];
			_mm256_store_ps(fp, pick);
			_mm256_store_ps(fu, pu);
			_mm256_store_ps(fv, pv);
			_mm256_store_ps(fw, pw);
			_mm256_store_si256((__m256i *)fl, pl);
			for (; got; got &= got - 1) {
				int j = __builtin_ctz(got);
				pk_take(s, h + j, 4 * (first + k) + (uint32_t)fl[j], fp[j], fu[j], fv[j], fw[j]);
			}
		}
	}
}

/* The rays `in` meet the blocks of leaf `ref`: eight at a time when they
 * share their axes and the model has no cut-outs, else one by one. */
static PK_TARGET inline void PK(leaf_all)(const mesh *m, mesh_packet *s, unsigned in, uint32_t ref)
{
	if (!s->ready)
		PK(ready)(s);
	/* the rays whose axes are the first's, in vector registers (the
	 * axes were just stored as vectors: a scalar load would wait) */
	int i0 = __builtin_ctz(in);
	__m256i a0 = _mm256_load_si256((const __m256i *)&s->axes[0]), a1 = _mm256_load_si256((const __m256i *)&s->axes[8]);
	__m256i first = _mm256_permutevar8x32_epi32(i0 < 8 ? a0 : a1, _mm256_set1_epi32(i0 & 7));
	unsigned same = (unsigned)_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(a0, first))) |
			(unsigned)_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(a1, first))) << 8;
	if (!m->cuts && (in & (in - 1)) && !(in & ~same)) {
		int ax = _mm256_cvtsi256_si32(first);
		PK(leaf_rays)(m, s, in, ref, ax & 3, ax >> 2 & 3, ax >> 4);
		return;
	}
	for (; in; in &= in - 1)
		PK(leaf)(m, s, __builtin_ctz(in), ref);
}

/* The highest of the rays' bs: where the packet prunes. */
static PK_TARGET inline float PK(far)(const mesh_packet *s)
{
	__m256 a = _mm256_max_ps(_mm256_load_ps(&s->bs[0]), _mm256_load_ps(&s->bs[8]));
	__m128 b = _mm_max_ps(_mm256_castps256_ps128(a), _mm256_extractf128_ps(a, 1));
	b = _mm_max_ps(b, _mm_movehl_ps(b, b));
	b = _mm_max_ss(b, _mm_shuffle_ps(b, b, 1));
	return _mm_cvtss_f32(b);
}

/* The lowest and highest of eight floats (no NaN among them). */
static PK_TARGET inline float PK(hmin)(__m256 a)
{
	__m128 b = _mm_min_ps(_mm256_castps256_ps128(a), _mm256_extractf128_ps(a, 1));
	b = _mm_min_ps(b, _mm_movehl_ps(b, b));
	return _mm_cvtss_f32(_mm_min_ss(b, _mm_shuffle_ps(b, b, 1)));
}

static PK_TARGET inline float PK(hmax)(__m256 a)
{
	__m128 b = _mm_max_ps(_mm256_castps256_ps128(a), _mm256_extractf128_ps(a, 1));
	b = _mm_max_ps(b, _mm_movehl_ps(b, b));
	return _mm_cvtss_f32(_mm_max_ss(b, _mm_shuffle_ps(b, b, 1)));
}

static PK_TARGET __attribute__((noinline)) bool PK(walk)(const mesh *m, const double (*M)[4], int n, const ray *wr,
                                                       double tmin, double tmax1, const double *tmax, double *t,
                                                       uint32_t *slot, float (*b)[3], unsigned *found, unsigned *tie,
                                                       bool any)
{
	_Alignas(32) mesh_packet s;
	s.any = any;
	float box_tmin = (float)tmin;
	/* the rays in the model's floats by component, as the single walk
	 * makes them (world_ray_floats: its operations in its order, four rays
	 * at a time), the lanes past n ray 0 again */
	const bool up = upright(M);
	int i = 0;
	{
		_Static_assert(sizeof(ray) == 6 * sizeof(double) && offsetof(ray, d) == 3 * sizeof(double),
			       "ray: six doubles o, d");
		const __m256d m00 = _mm256_set1_pd(M[0][0]), m01 = _mm256_set1_pd(M[0][1]), m02 = _mm256_set1_pd(M[0][2]),
			      m03 = _mm256_set1_pd(M[0][3]);
		const __m256d m10 = _mm256_set1_pd(M[1][0]), m11 = _mm256_set1_pd(M[1][1]), m12 = _mm256_set1_pd(M[1][2]),
			      m13 = _mm256_set1_pd(M[1][3]);
		const __m256d m20 = _mm256_set1_pd(M[2][0]), m21 = _mm256_set1_pd(M[2][1]), m22 = _mm256_set1_pd(M[2][2]),
			      m23 = _mm256_set1_pd(M[2][3]);
		const __m256d huge = _mm256_set1_pd(3e38);
		const __m256i pick = _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6);
		for (; i + 4 <= n; i += 4) {
			/* the four rays' 24 doubles turned into six registers of
			 * one component each (loads and shuffles: gathers are slow) */
			const ray *q4 = &wr[i];
			__m256d a0 = _mm256_loadu_pd(&q4[0].o.x), a1 = _mm256_loadu_pd(&q4[1].o.x);
			__m256d a2 = _mm256_loadu_pd(&q4[2].o.x), a3 = _mm256_loadu_pd(&q4[3].o.x);
			/* a_k: o.x o.y o.z d.x of ray k; c_k: d.y d.z of ray k */
			__m128d c0 = _mm_loadu_pd(&q4[0].d.y), c1 = _mm_loadu_pd(&q4[1].d.y);
			__m128d c2 = _mm_loadu_pd(&q4[2].d.y), c3 = _mm_loadu_pd(&q4[3].d.y);
			__m256d t0 = _mm256_unpacklo_pd(a0, a1); /* ox0 ox1 oz0 oz1 */
			__m256d t1 = _mm256_unpackhi_pd(a0, a1); /* oy0 oy1 dx0 dx1 */
			__m256d t2 = _mm256_unpacklo_pd(a2, a3); /* ox2 ox3 oz2 oz3 */
			__m256d t3 = _mm256_unpackhi_pd(a2, a3); /* oy2 oy3 dx2 dx3 */
			__m256d px = _mm256_permute2f128_pd(t0, t2, 0x20), pz = _mm256_permute2f128_pd(t0, t2, 0x31);
			__m256d py = _mm256_permute2f128_pd(t1, t3, 0x20), vx = _mm256_permute2f128_pd(t1, t3, 0x31);
			__m256d c01 = _mm256_set_m128d(c1, c0), c23 = _mm256_set_m128d(c3, c2); /* dy0 dz0 dy1 dz1 */
			__m256d u0 = _mm256_unpacklo_pd(c01, c23), u1 = _mm256_unpackhi_pd(c01, c23); /* dy0 dy2 dy1 dy3 */
			__m256d vy = _mm256_permute4x64_pd(u0, 0xd8), vz = _mm256_permute4x64_pd(u1, 0xd8);
			__m256d a, bq, c, e, f, g;
			if (up) {
				a = _mm256_add_pd(_mm256_mul_pd(m00, px), m03);
				bq = _mm256_add_pd(_mm256_mul_pd(m11, py), m13);
				c = _mm256_add_pd(_mm256_mul_pd(m22, pz), m23);
				e = _mm256_mul_pd(m00, vx);
				f = _mm256_mul_pd(m11, vy);
				g = _mm256_mul_pd(m22, vz);
			} else {
				a = _mm256_add_pd(_mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(m00, px), _mm256_mul_pd(m01, py)),
								_mm256_mul_pd(m02, pz)),
						  m03);
				bq = _mm256_add_pd(_mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(m10, px), _mm256_mul_pd(m11, py)),
								 _mm256_mul_pd(m12, pz)),
						   m13);
				c = _mm256_add_pd(_mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(m20, px), _mm256_mul_pd(m21, py)),
								_mm256_mul_pd(m22, pz)),
						  m23);
				e = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(m00, vx), _mm256_mul_pd(m01, vy)),
						  _mm256_mul_pd(m02, vz));
				f = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(m10, vx), _mm256_mul_pd(m11, vy)),
						  _mm256_mul_pd(m12, vz));
				g = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(m20, vx), _mm256_mul_pd(m21, vy)),
						  _mm256_mul_pd(m22, vz));
			}
			_mm_store_ps(&s.ox[i], _mm256_cvtpd_ps(a));
			_mm_store_ps(&s.oy[i], _mm256_cvtpd_ps(bq));
			_mm_store_ps(&s.oz[i], _mm256_cvtpd_ps(c));
			_mm_store_ps(&s.dx[i], _mm256_cvtpd_ps(e));
			_mm_store_ps(&s.dy[i], _mm256_cvtpd_ps(f));
			_mm_store_ps(&s.dz[i], _mm256_cvtpd_ps(g));
			if (tmax) {
				/* best: tmax < 3e38 ? (float)tmax : inf */
				__m256d tm = _mm256_loadu_pd(&tmax[i]);
				__m128 lt = _mm256_castps256_ps128(_mm256_permutevar8x32_ps(
					_mm256_castpd_ps(_mm256_cmp_pd(tm, huge, _CMP_LT_OQ)), pick));
				_mm_storeu_ps(&s.best[i], _mm_blendv_ps(_mm_set1_ps(INFINITY), _mm256_cvtpd_ps(tm), lt));
			}
		}
	}
	for (; i < n; i++) {
		float o[3], d[3];
		world_ray_floats(M, up, &wr[i], o, d);
		s.ox[i] = o[0];
		s.oy[i] = o[1];
		s.oz[i] = o[2];
		s.dx[i] = d[0];
		s.dy[i] = d[1];
		s.dz[i] = d[2];
		if (tmax)
			s.best[i] = tmax[i] < 3e38 ? (float)tmax[i] : INFINITY;
	}
	if (tmax) {
		for (i = 0; i < n; i++) {
			s.bt[i] = next_upf(s.best[i]);
			s.bs[i] = s.bt[i] * BVH_SLAB_SLACK;
		}
	} else {
		/* one tmax for all */
		float b1 = tmax1 < 3e38 ? (float)tmax1 : INFINITY, t1 = next_upf(b1);
		const __m256 vb = _mm256_set1_ps(b1), vt = _mm256_set1_ps(t1), vs = _mm256_set1_ps(t1 * BVH_SLAB_SLACK);
		for (i = 0; i < MESH_PACKET_MAX; i += 8) {
			_mm256_store_ps(&s.best[i], vb);
			_mm256_store_ps(&s.bt[i], vt);
			_mm256_store_ps(&s.bs[i], vs);
		}
	}
	for (i = n; i < MESH_PACKET_MAX; i++) {
		s.ox[i] = s.ox[0];
		s.oy[i] = s.oy[0];
		s.oz[i] = s.oz[0];
		s.dx[i] = s.dx[0];
		s.dy[i] = s.dy[0];
		s.dz[i] = s.dz[0];
		s.bs[i] = -INFINITY; /* never enters a leaf, never raises PK(far) */
		s.bt[i] = 0.0f;      /* (read by PK(leaf_rays), never used) */
	}
	/* Camera packets beside the model (most of a view's, where the model
	 * does not fill it): no ray's line passes the model's box, so none can
	 * hit; known before the set-up of the walk (its divisions and the
	 * root's test). A line o + t d misses the box (centre c, half sides
	 * e) when, for some axis k, the component k of q = (c - o) x d
	 * exceeds what the box spans across it: |q_x| > e_y |d_z| + e_z |d_y|
	 * and so on (the separating axes of a line and a box, each axis
	 * crossed with d). The test is made generous: the half sides raised
	 * by 1%, and 1e-5 of the two products that make q_k added, far more
	 * than the floats' roundings of q_k (a few parts in 1e7 of them) and
	 * of a hit; a NaN culls nothing. The answer is the walk's: no hit, no
	 * tie. */
	if (!any) {
		const vec3 bc = box_center(m->bounds), be = v3_scale(v3_sub(m->bounds.hi, m->bounds.lo), 0.505);
		const __m256 cx = _mm256_set1_ps((float)bc.x), cy = _mm256_set1_ps((float)bc.y), cz = _mm256_set1_ps((float)bc.z);
		const __m256 ex = _mm256_set1_ps((float)be.x), ey = _mm256_set1_ps((float)be.y), ez = _mm256_set1_ps((float)be.z);
		const __m256 rel = _mm256_set1_ps(1e-5f), mag = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
		unsigned out = 0;
		for (int h = 0; h < MESH_PACKET_MAX; h += 8) {
			__m256 dx = _mm256_load_ps(&s.dx[h]), dy = _mm256_load_ps(&s.dy[h]), dz = _mm256_load_ps(&s.dz[h]);
			__m256 px = _mm256_sub_ps(cx, _mm256_load_ps(&s.ox[h])), py = _mm256_sub_ps(cy, _mm256_load_ps(&s.oy[h])),
			       pz = _mm256_sub_ps(cz, _mm256_load_ps(&s.oz[h]));
			__m256 yz = _mm256_mul_ps(py, dz), zy = _mm256_mul_ps(pz, dy), zx = _mm256_mul_ps(pz, dx),
			       xz = _mm256_mul_ps(px, dz), xy = _mm256_mul_ps(px, dy), yx = _mm256_mul_ps(py, dx);
			__m256 ax = _mm256_and_ps(dx, mag), ay = _mm256_and_ps(dy, mag), az = _mm256_and_ps(dz, mag);
			/* |q_k| against the box's span, the margin added */
#define SEP(a, b, sa, sb)                                                                                              \
	_mm256_cmp_ps(_mm256_and_ps(_mm256_sub_ps(a, b), mag),                                                         \
		      _mm256_add_ps(_mm256_add_ps(sa, sb),                                                             \
				    _mm256_mul_ps(rel, _mm256_add_ps(_mm256_and_ps(a, mag), _mm256_and_ps(b, mag)))),  \
		      _CMP_GT_OQ)
			__m256 sep = _mm256_or_ps(_mm256_or_ps(SEP(yz, zy, _mm256_mul_ps(ey, az), _mm256_mul_ps(ez, ay)),
							       SEP(zx, xz, _mm256_mul_ps(ez, ax), _mm256_mul_ps(ex, az))),
						  SEP(xy, yx, _mm256_mul_ps(ex, ay), _mm256_mul_ps(ey, ax)));
#undef SEP
			out |= (unsigned)_mm256_movemask_ps(sep) << h;
		}
		if (out == 0xffffu) {
			*found = *tie = 0;
			return true;
		}
	}
	/* the inverses (1 / d, correctly rounded as ray_node_setup's), the far
	 * ones inv S; the signs each axis shares; per axis the origin to
	 * subtract from the near planes (the farthest along the direction) and
	 * from the far ones (the farthest back), the inverses' and the far
	 * inverses' ranges. The bounds need finite origins and finite, non-zero
	 * inverses (a NaN fails too). Of one sign, the inverses' extremes are
	 * the largest and smallest in magnitude, so an infinite or zero one is
	 * among them; and inv S is monotonic in inv, so the far inverses' range
	 * is the extremes' times S, the same floats as the rays' own. */
	const __m256 one = _mm256_set1_ps(1.0f), slack = _mm256_set1_ps(BVH_SLAB_SLACK), big = _mm256_set1_ps(FLT_MAX);
	const __m256 mag = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
	float *oa[3] = {s.ox, s.oy, s.oz}, *da[3] = {s.dx, s.dy, s.dz}, *ia[3] = {s.ix, s.iy, s.iz},
	      *fa[3] = {s.fx, s.fy, s.fz};
	__m256 on[3], of[3], ilo[3], ihi[3], flo[3], fhi[3];
	size_t rn[3];
	__m256 bad = _mm256_setzero_ps();
	for (int a = 0; a < 3; a++) {
		__m256 olo = _mm256_load_ps(oa[a]), ohi = olo, il = _mm256_set1_ps(INFINITY), ih = _mm256_set1_ps(-INFINITY);
		unsigned negs = 0;
		for (int h = 0; h < MESH_PACKET_MAX; h += 8) {
			__m256 o = _mm256_load_ps(oa[a] + h), inv = _mm256_div_ps(one, _mm256_load_ps(da[a] + h));
			_mm256_store_ps(ia[a] + h, inv);
			_mm256_store_ps(fa[a] + h, _mm256_mul_ps(inv, slack));
			bad = _mm256_or_ps(bad, _mm256_cmp_ps(_mm256_and_ps(o, mag), big, _CMP_NLE_UQ));
			bad = _mm256_or_ps(bad, _mm256_cmp_ps(inv, inv, _CMP_UNORD_Q));
			negs |= (unsigned)_mm256_movemask_ps(inv) << h;
			olo = _mm256_min_ps(olo, o);
			ohi = _mm256_max_ps(ohi, o);
			il = _mm256_min_ps(il, inv);
			ih = _mm256_max_ps(ih, inv);
		}
		if (negs != 0 && negs != 0xffffu)
			return false;
		bool neg = negs != 0;
		float l = PK(hmin)(il), hh = PK(hmax)(ih), fl = l * BVH_SLAB_SLACK, fh = hh * BVH_SLAB_SLACK;
		if (!(fabsf(l) <= FLT_MAX && fabsf(hh) <= FLT_MAX && l != 0.0f && hh != 0.0f && fabsf(fl) <= FLT_MAX &&
		      fabsf(fh) <= FLT_MAX))
			return false;
		on[a] = _mm256_set1_ps(neg ? PK(hmin)(olo) : PK(hmax)(ohi));
		of[a] = _mm256_set1_ps(neg ? PK(hmax)(ohi) : PK(hmin)(olo));
		ilo[a] = _mm256_set1_ps(l);
		ihi[a] = _mm256_set1_ps(hh);
		flo[a] = _mm256_set1_ps(fl);
		fhi[a] = _mm256_set1_ps(fh);
		rn[a] = (size_t)(MESH_LO(a) + neg) * MESH_ROW;
	}
	if (_mm256_movemask_ps(bad))
		return false;
	s.ready = false;
	s.tmin0 = box_tmin;
	s.eps = m->eps;
	const size_t rn0 = rn[0], rn1 = rn[1], rn2 = rn[2];
	s.found = s.tie = 0;
	const __m256 t0_8 = _mm256_set1_ps(box_tmin);
	float far = PK(far)(&s);
	pk_entry stack[MESH_STACK];
	int sp = 0;
	pk_entry cur = {0, 0.0f, 0, 0}; /* the root node */
	const mesh_node *nodes = m->nodes;
	for (;;) {
		if (!(cur.ref & MESH_LEAF)) {
			const mesh_node *nd = (const mesh_node *)((const char *)nodes + cur.ref);
			__m256 t0 = t0_8, t1 = _mm256_set1_ps(far);
			for (int a = 0; a < 3; a++) {
				size_t r0 = rn[a];
				__m256 x = _mm256_sub_ps(_mm256_load_ps((const float *)((const char *)nd->b + r0)), on[a]);
				__m256 y = _mm256_sub_ps(_mm256_load_ps((const float *)((const char *)nd->b + (r0 ^ MESH_ROW))),
							 of[a]);
				t0 = _mm256_max_ps(_mm256_min_ps(_mm256_mul_ps(x, ilo[a]), _mm256_mul_ps(x, ihi[a])), t0);
				t1 = _mm256_min_ps(_mm256_max_ps(_mm256_mul_ps(y, flo[a]), _mm256_mul_ps(y, fhi[a])), t1);
			}
			_Alignas(32) float tn[MESH_WIDTH];
			_mm256_store_ps(tn, t0);
			unsigned hm = (unsigned)_mm256_movemask_ps(_mm256_cmp_ps(t0, t1, _CMP_LE_OQ));
			if (hm) {
				uint32_t parent = cur.ref;
				if (!(hm & (hm - 1))) { /* one child: on to it */
					uint32_t k = (uint32_t)__builtin_ctz(hm);
					cur = (pk_entry){nd->child[k], tn[k], parent, k};
					continue;
				}
				/* the children, farthest first, so the nearest is on
				 * top: on to it, the others wait */
				int base = sp;
				for (; hm; hm &= hm - 1) {
					uint32_t k = (uint32_t)__builtin_ctz(hm);
					pk_entry e = {nd->child[k], tn[k], parent, k};
					int j = sp++;
					while (j > base && stack[j - 1].t < e.t) {
						stack[j] = stack[j - 1];
						j--;
					}
					stack[j] = e;
				}
				cur = stack[--sp];
				continue;
			}
		} else {
			unsigned in = PK(rays_in)(&s, (const mesh_node *)((const char *)nodes + cur.parent), cur.k, box_tmin,
						 rn0, rn1, rn2);
			if (in)
				PK(leaf_all)(m, &s, in, cur.ref);
			far = PK(far)(&s);
		}
		/* the next entry the packet may still need */
		while (sp > 0 && stack[sp - 1].t > far)
			sp--;
		if (sp == 0)
			break;
		cur = stack[--sp];
	}
	for (unsigned f = s.found; f; f &= f - 1) {
		int j = __builtin_ctz(f);
		t[j] = s.best[j];
		slot[j] = s.slot[j];
		b[j][0] = s.b[j][0];
		b[j][1] = s.b[j][1];
		b[j][2] = s.b[j][2];
		if (!((double)s.best[j] < (tmax ? tmax[j] : tmax1)))
			s.found &= ~(1u << j);
	}
	*found = s.found;
	*tie = s.tie & s.found;
	return true;
}

#undef PK
#undef PK_TARGET
