/* rtsh — the walk of a mesh's tree, written once and included by
 * mesh_trace.c for each vector unit: WALK names the function, WALK_ISA is
 * 0 (scalar), 1 (SSE2) or 2 (AVX2), WALK_TARGET its target attribute.
 *
 * WALK(m, r, leaf_ready, tmin, guard, tmax, tri, b, any): the nearest hit
 * in (tmin, *tmax) (any = false: sets *tmax, *tri and b) or whether there
 * is any (any = true). r holds the ray's box part (ray_node_setup); its
 * triangle part (ray_leaf_setup) too when leaf_ready, else the walk makes
 * it at the first leaf, and tests the triangles from tmin raised to
 * guard / |d| (guard 0: tmin itself). Every unit runs the same float operations in the same order, so
 * each finds the same hits.
 */

static inline __attribute__((always_inline)) WALK_TARGET bool WALK(const mesh *m, mesh_ray *r, bool leaf_ready,
                                                                   float box_tmin, float guard, float *tmax,
                                                                   uint32_t *tri, float b[3], bool any,
                                                                   const size_t rn0, const size_t rn1,
                                                                   const size_t rn2)
{
	const mesh_node *nodes = m->nodes;
	/* rn0..rn2: byte offsets in a node of the near rows of each axis (the
	 * far rows one bit away); the ray's slab constants in registers of
	 * their own (GCC keeps arrays of vectors on the stack) */
#define rf0 (rn0 ^ MESH_ROW)
#define rf1 (rn1 ^ MESH_ROW)
#define rf2 (rn2 ^ MESH_ROW)
	float best = *tmax;
#define ROW(n, off) ((const float *)((const char *)(n)->b + (off)))
#if WALK_ISA >= 2
	__m256 ox = _mm256_set1_ps(r->o[0]), oy = _mm256_set1_ps(r->o[1]), oz = _mm256_set1_ps(r->o[2]);
	__m256 ix = _mm256_set1_ps(r->inv[0]), iy = _mm256_set1_ps(r->inv[1]), iz = _mm256_set1_ps(r->inv[2]);
	/* The far distances widened by BVH_SLAB_SLACK (Ize) through the
	 * reciprocal, fx = inv * S, not each distance, so that no multiply is
	 * left between a node's far planes and its test. As safe: inv is
	 * common to both sides, so a near distance (b - o) * inv is at most
	 * exact * (1 + eps)^2 and a far one at least exact * S * (1 - eps)^3
	 * (the difference, inv * S, the product), and S = 1 + 2 gamma(3)
	 * exceeds (1 + eps)^2 / (1 - eps)^3 = 1 + 5 eps + O(eps^2). The
	 * nearest hit, where the walk prunes, is widened once per leaf. Every
	 * unit does the same: the same boxes, the same hits. */
	const __m256 slack8 = _mm256_set1_ps(BVH_SLAB_SLACK);
	__m256 fx = _mm256_mul_ps(ix, slack8), fy = _mm256_mul_ps(iy, slack8), fz = _mm256_mul_ps(iz, slack8);
	__m256 t0_8 = _mm256_set1_ps(box_tmin);
	__m256 best8 = _mm256_set1_ps(best * BVH_SLAB_SLACK);
#elif WALK_ISA == 1
	const __m128 ox = _mm_set1_ps(r->o[0]), oy = _mm_set1_ps(r->o[1]), oz = _mm_set1_ps(r->o[2]);
	const __m128 ix = _mm_set1_ps(r->inv[0]), iy = _mm_set1_ps(r->inv[1]), iz = _mm_set1_ps(r->inv[2]);
	const __m128 slack4 = _mm_set1_ps(BVH_SLAB_SLACK);
	const __m128 fx = _mm_mul_ps(ix, slack4), fy = _mm_mul_ps(iy, slack4), fz = _mm_mul_ps(iz, slack4);
	const __m128 t0_4 = _mm_set1_ps(box_tmin);
	__m128 best4 = _mm_set1_ps(best * BVH_SLAB_SLACK);
#else
	const float invf[3] = {r->inv[0] * BVH_SLAB_SLACK, r->inv[1] * BVH_SLAB_SLACK, r->inv[2] * BVH_SLAB_SLACK};
#endif
	float tmin = box_tmin; /* the triangles' (raised at the first leaf) */
#if WALK_ISA >= 1
	ray4 rq = {_mm_setzero_ps(), _mm_setzero_ps(), _mm_setzero_ps(), _mm_setzero_ps(), _mm_setzero_ps(),
	           _mm_setzero_ps()};
	if (leaf_ready)
		ray4_make(r, &rq);
#endif
	entry stack[MESH_STACK];
	int sp = 0;
	bool found = false;
	uint32_t ref = 0; /* the root node */
	for (;;) {
		while (!(ref & MESH_LEAF)) {
			const mesh_node *n = (const mesh_node *)((const char *)nodes + ref);
			_Alignas(32) float tn[MESH_WIDTH];
#ifdef MESH_STATS
			mesh_stat_nodes++;
#endif
			unsigned hm;
#if WALK_ISA >= 2
			{
				/* max(x, acc) and min(x, acc) return acc when x is NaN */
				__m256 t0 = _mm256_max_ps(_mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(ROW(n, rn0)), ox), ix), t0_8);
				__m256 t1 = _mm256_min_ps(_mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(ROW(n, rf0)), ox), fx), best8);
				t0 = _mm256_max_ps(_mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(ROW(n, rn1)), oy), iy), t0);
				t1 = _mm256_min_ps(_mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(ROW(n, rf1)), oy), fy), t1);
				t0 = _mm256_max_ps(_mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(ROW(n, rn2)), oz), iz), t0);
				t1 = _mm256_min_ps(_mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(ROW(n, rf2)), oz), fz), t1);
				_mm256_store_ps(tn, t0);
				hm = (unsigned)_mm256_movemask_ps(_mm256_cmp_ps(t0, t1, _CMP_LE_OQ));
			}
#elif WALK_ISA == 1
			hm = 0;
			for (int h = 0; h < 2; h++) {
				__m128 t0 = _mm_max_ps(_mm_mul_ps(_mm_sub_ps(_mm_load_ps(ROW(n, rn0) + 4 * h), ox), ix), t0_4);
				__m128 t1 = _mm_min_ps(_mm_mul_ps(_mm_sub_ps(_mm_load_ps(ROW(n, rf0) + 4 * h), ox), fx), best4);
				t0 = _mm_max_ps(_mm_mul_ps(_mm_sub_ps(_mm_load_ps(ROW(n, rn1) + 4 * h), oy), iy), t0);
				t1 = _mm_min_ps(_mm_mul_ps(_mm_sub_ps(_mm_load_ps(ROW(n, rf1) + 4 * h), oy), fy), t1);
				t0 = _mm_max_ps(_mm_mul_ps(_mm_sub_ps(_mm_load_ps(ROW(n, rn2) + 4 * h), oz), iz), t0);
				t1 = _mm_min_ps(_mm_mul_ps(_mm_sub_ps(_mm_load_ps(ROW(n, rf2) + 4 * h), oz), fz), t1);
				_mm_store_ps(&tn[4 * h], t0);
				hm |= (unsigned)_mm_movemask_ps(_mm_cmple_ps(t0, t1)) << (4 * h);
			}
#else
			hm = 0;
			const float best_far = best * BVH_SLAB_SLACK;
			for (int k = 0; k < MESH_WIDTH; k++) {
				float t0 = box_tmin, t1 = best_far;
				const size_t rn[3] = {rn0, rn1, rn2}, rf[3] = {rf0, rf1, rf2};
				for (int a = 0; a < 3; a++) {
					float tnear = (ROW(n, rn[a])[k] - r->o[a]) * r->inv[a];
					float tfar = (ROW(n, rf[a])[k] - r->o[a]) * invf[a];
					t0 = tnear > t0 ? tnear : t0;
					t1 = tfar < t1 ? tfar : t1;
				}
				tn[k] = t0;
				hm |= (unsigned)(t0 <= t1) << k;
			}
#endif
			if (!hm)
				goto pop;
			if (!(hm & (hm - 1))) {
				ref = n->child[__builtin_ctz(hm)];
				continue;
			}
			if (any) {
				/* any hit will do: no sorting, the first child now */
				int k = __builtin_ctz(hm);
				for (unsigned rest = hm & (hm - 1); rest; rest &= rest - 1) {
					int j = __builtin_ctz(rest);
					stack[sp++] = (entry){n->child[j], tn[j]};
				}
				ref = n->child[k];
				continue;
			}
			ref = push_sorted(n, hm, tn, stack, &sp);
			prefetch_ref(m, stack[sp - 1].ref);
		}
		{
			/* a leaf: its blocks */
			if (!leaf_ready) {
				ray_leaf_setup(r);
				if (guard > 0.0f) {
					float g = guard / sqrtf(r->d[0] * r->d[0] + r->d[1] * r->d[1] + r->d[2] * r->d[2]);
					tmin = tmin > g ? tmin : g;
				}
#if WALK_ISA >= 1
				ray4_make(r, &rq);
#endif
				leaf_ready = true;
			}
			uint32_t first = ref & (MESH_MAX_BLOCKS - 1), nb = ((ref & ~MESH_LEAF) >> MESH_LEAF_SHIFT) + 1;
#ifdef MESH_STATS
			mesh_stat_leaves++;
#endif
			for (uint32_t k = 0; k < nb; k++) {
				const mesh_tri4 *blk = &m->blk[first + k];
#ifdef MESH_STATS
				mesh_stat_blocks++;
#endif
#if WALK_ISA >= 1
				int l = block_sse(m, first + k, blk, r, &rq, tmin, &best, b);
#else
				int l = block_scalar(m, first + k, blk, r, tmin, &best, b);
#endif
				if (l >= 0) {
					*tri = 4 * (first + k) + (uint32_t)l;
					found = true;
					if (any)
						goto done;
				}
			}
#if WALK_ISA >= 2
			/* the node tests' ray made again from memory (one broadcast
			 * each): dead through the leaf's blocks, whose tests then
			 * have the registers to themselves, instead of stored and
			 * loaded around them (the empty asm: the compiler may not
			 * keep the old values for them) */
			__asm__("" : "+m"(*r));
			ox = _mm256_set1_ps(r->o[0]);
			oy = _mm256_set1_ps(r->o[1]);
			oz = _mm256_set1_ps(r->o[2]);
			ix = _mm256_set1_ps(r->inv[0]);
			iy = _mm256_set1_ps(r->inv[1]);
			iz = _mm256_set1_ps(r->inv[2]);
			fx = _mm256_mul_ps(ix, slack8);
			fy = _mm256_mul_ps(iy, slack8);
			fz = _mm256_mul_ps(iz, slack8);
			t0_8 = _mm256_set1_ps(box_tmin);
			best8 = _mm256_set1_ps(best * BVH_SLAB_SLACK);
#elif WALK_ISA == 1
			if (found)
				best4 = _mm_set1_ps(best * BVH_SLAB_SLACK);
#endif
		}
	pop:
		if (!any)
			while (sp > 0 && stack[sp - 1].t > BVH_SLAB_SLACK * best)
				sp--;
		if (sp == 0)
			break;
		ref = stack[--sp].ref;
	}
done:
	/* every hit found was nearer than the last, so b holds the best's */
	if (found)
		*tmax = best;
	return found;
}

#undef ROW
#undef rf0
#undef rf1
#undef rf2
#undef WALK
#undef WALK_ISA
#undef WALK_TARGET
