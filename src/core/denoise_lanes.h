/* rtsh — the denoiser's regression and choice, VL neighbouring pixels at a
 * time, one in each lane of GCC's and Clang's vectors. denoise.c includes
 * this file once for each lane count it builds (8 with AVX2, 4 for any
 * processor), after defining VL, LANES(name) (the copy's name of a
 * function or type), LANES_TARGET (the copy's processor) and the job;
 * every lane does its pixel's operations in its pixel's order, so the
 * copies' results are the same bits. Defines LANES(regression_rows) and
 * LANES(pick_rows). */

#define vf LANES(vf)
#define vi LANES(vi)
#define vll LANES(vll)
#define vf_splat LANES(vf_splat)
#define vi_splat LANES(vi_splat)
#define vi_lanes LANES(vi_lanes)
#define vf_load LANES(vf_load)
#define vf_any LANES(vf_any)
#define vf_exp_fast LANES(vf_exp_fast)
#define normal_rows LANES(normal_rows)
#define solve_lanes LANES(solve_lanes)
#define regression_body LANES(regression_body)
#define pick_body LANES(pick_body)
#define feat_dist2 LANES(feat_dist2)
#define LANES_INLINE static inline __attribute__((always_inline))

/* VL floats in one SIMD value, VL ints (the lanes' masks: all bits set
 * where true), VL / 2 long longs (a mask's test). */
typedef float vf __attribute__((vector_size(VL * 4)));
typedef int vi __attribute__((vector_size(VL * 4)));
typedef long long vll __attribute__((vector_size(VL * 4)));

LANES_INLINE vf vf_splat(float x)
{
	vf v = {0};
	for (int l = 0; l < VL; l++)
		v[l] = x;
	return v;
}

LANES_INLINE vi vi_splat(int x)
{
	vi v = {0};
	for (int l = 0; l < VL; l++)
		v[l] = x;
	return v;
}

/* x, x + 1, ..., x + VL - 1: the lanes' columns */
LANES_INLINE vi vi_lanes(int x)
{
	vi v = {0};
	for (int l = 0; l < VL; l++)
		v[l] = x + l;
	return v;
}

LANES_INLINE vf vf_load(const float *p)
{
	vf v;
	memcpy(&v, p, sizeof v);
	return v;
}

/* x where m is set, else +0. (These three are macros and the others take
 * pointers: no vector is passed by value, the ABI of which GCC notes
 * changes with AVX.) */
#define vf_and(x, m) ((vf)((vi)(x) & (m)))
#define vf_abs(x) vf_and(x, vi_splat(0x7fffffff))

/* The squared distance, lane by lane, of the six features at offset q of
 * the planes pf from the centre pixels' gf. */
LANES_INLINE vf feat_dist2(const vf *gf, const float *const *pf, ptrdiff_t q)
{
	vf e = vf_splat(0.0f);
#pragma GCC unroll 6
	for (int k = 0; k < 6; k++) {
		vf d = gf[k] - vf_load(pf[k] + q);
		e += d * d;
	}
	return e;
}

/* Whether some lane of the mask *m is set. */
LANES_INLINE bool vf_any(const vi *m)
{
	vll t = (vll)*m;
	long long any = 0;
	for (int l = 0; l < VL / 2; l++)
		any |= t[l];
	return any != 0;
}

/* exp(-x) for x >= 0 as (1 - x/16)^16 (its limit definition), 0 from
 * x = 16 on: within 0.03 of it everywhere, four multiplications; of VL
 * values. */
LANES_INLINE vf vf_exp_fast(const vf *x)
{
	vf t = vf_splat(1.0f) - *x * vf_splat(1.0f / 16);
	t = vf_and(t, t > vf_splat(0.0f));
	t *= t;
	t *= t;
	t *= t;
	return t * t;
}

/* Rows [r0, r1) of the normal equations' lower triangle in a: each sum
 * over the taps in their order, a few rows at a time so that their sums
 * stay in registers. */
LANES_INLINE void normal_rows(vf *a, int nt, const vf *tw, vf (*tv)[NU], int r0, int r1)
{
	vf s[NU * 2];
	int n = TRI(r1, 0) - TRI(r0, 0);
#pragma GCC unroll 16
	for (int k = 0; k < n; k++)
		s[k] = a[TRI(r0, 0) + k];
	for (int t = 0; t < nt; t++) {
#pragma GCC unroll 8
		for (int r = r0; r < r1; r++) {
			/* regressor 0 is 1: times it, a product is itself exactly */
			vf wv = r == 0 ? tw[t] : tw[t] * tv[t][r];
			s[TRI(r, 0) - TRI(r0, 0)] += wv;
#pragma GCC unroll 8
			for (int c = 1; c <= r; c++)
				s[TRI(r, c) - TRI(r0, 0)] += wv * tv[t][c];
		}
	}
#pragma GCC unroll 16
	for (int k = 0; k < n; k++)
		a[TRI(r0, 0) + k] = s[k];
}

/* Each lane's solve of the regression's normal equations (lower triangle
 * a, TRI) with their ridge, M z = (1, 0, ..., 0): solve's operations for
 * n = NU and that one right-hand side, in its order, lane by lane, so that
 * every lane's z is the bits solve gives its pixel. Returns the lanes whose
 * system was positive definite (z is +0 in the others). */
LANES_INLINE vi solve_lanes(const vf *a, vf zv[NU])
{
	vf m[NU][NU];
#pragma GCC unroll 8
	for (int r = 0; r < NU; r++)
#pragma GCC unroll 8
		for (int c = 0; c <= r; c++)
			m[r][c] = a[TRI(r, c)];
	vf ridge = m[0][0] * vf_splat(RIDGE);
#pragma GCC unroll 8
	for (int r = 1; r < NU; r++)
		m[r][r] += ridge;
	vi ok = vi_splat(-1);
	vf inv[NU];
#pragma GCC unroll 8
	for (int c = 0; c < NU; c++) {
		vf d = m[c][c];
#pragma GCC unroll 8
		for (int k = 0; k < c; k++)
			d -= m[c][k] * m[c][k];
		ok &= d > vf_splat(1e-12f);
		/* a failed lane goes on with 1 (its z is dropped) */
		d = vf_and(d, ok) + vf_and(vf_splat(1.0f), ~ok);
		for (int l = 0; l < VL; l++)
			d[l] = sqrtf(d[l]);
		m[c][c] = d;
		inv[c] = vf_splat(1.0f) / d;
#pragma GCC unroll 8
		for (int r = c + 1; r < NU; r++) {
			vf v = m[r][c];
#pragma GCC unroll 8
			for (int k = 0; k < c; k++)
				v -= m[r][k] * m[c][k];
			m[r][c] = v * inv[c];
		}
	}
	vf z[NU];
#pragma GCC unroll 8
	for (int r = 0; r < NU; r++) {
		vf v = vf_splat(r == 0 ? 1.0f : 0.0f);
#pragma GCC unroll 8
		for (int k = 0; k < r; k++)
			v -= m[r][k] * z[k];
		z[r] = v * inv[r];
	}
#pragma GCC unroll 8
	for (int r = NU - 1; r >= 0; r--) {
		vf v = z[r];
#pragma GCC unroll 8
		for (int k = r + 1; k < NU; k++)
			v -= m[k][r] * zv[k];
		zv[r] = v * inv[r];
	}
#pragma GCC unroll 8
	for (int r = 0; r < NU; r++)
		zv[r] = vf_and(zv[r], ok);
	return ok;
}

/* Weighted first-order regression (NFOR, Bitterli et al. 2016, without its
 * colour weights) of the radiance over albedo on the screen position, the
 * normal and the depth, over the window around each pixel of rows
 * [y0, y1), evaluated at the pixel. The taps are weighted by how alike
 * their features are (albedo, normal, depth off the pixel's plane, direct
 * light: DIRECT_W) and by nothing else: no weight depends on the noise,
 * so the fit of each half's brightness depends on that half's samples
 * only, and cross_error estimates the fit's error honestly.
 *
 * VL neighbouring pixels of a row at a time, one in each SIMD lane
 * (their planes: one load for them all): each lane does the one pixel's
 * operations in the one pixel's order, so the results are those of a
 * pixel alone to the bit. A tap that is outside the image or has no
 * weight for a lane adds +0 to that lane's sums (masked), which leaves
 * them as they were, as if it had been skipped. */
LANES_INLINE void regression_body(job *j, int y0, int y1)
{
	int w = j->fb->w, h = j->fb->h;
	const float *pf[6], *pdata[5];
	for (int k = 0; k < 6; k++)
		pf[k] = plane(j, PL_F0 + k);
	for (int k = 0; k < 5; k++)
		pdata[k] = plane(j, PL_DATA + k);
	const float *pz = plane(j, PL_Z), *pd = plane(j, PL_D), *pgx = plane(j, PL_GX), *pgy = plane(j, PL_GY);
	float *perr[NCAND];
	for (int c = 0; c < NCAND; c++)
		perr[c] = plane(j, PL_ERR + c);
	/* the taps' offsets, and over WIN (the regressors), in every lane */
	vf off[2 * WIN + 1], offw[2 * WIN + 1];
	for (int d = -WIN; d <= WIN; d++) {
		off[d + WIN] = vf_splat((float)d);
		offw[d + WIN] = vf_splat((float)d * (1.0f / WIN));
	}
	for (int y = y0; y < y1; y++)
		for (int x = 0; x < w; x += VL) {
			ptrdiff_t i = (ptrdiff_t)y * w + x;
			vf gf[6];
			for (int k = 0; k < 6; k++)
				gf[k] = vf_load(pf[k] + i);
			vf gz = vf_load(pz + i), gd = vf_load(pd + i), ggx = vf_load(pgx + i), ggy = vf_load(pgy + i);
			vf inv_z = vf_splat(1.0f) / (vf_splat(SIGMA_Z) * gz + vf_splat(1e-6f));
			/* the direct light's slope, in shares of its value */
			vf dscale = vf_splat(1.0f) / (vf_splat(0.5f) * vf_abs(gd) + vf_splat(0.05f));
			vi lane = vi_lanes(x);
			/* The taps with a weight in some lane: the weights (0 where
			 * none), regressors, masks and where the tap's data are. */
			vf tw[TAPS], tv[TAPS][NU];
			vi tm[TAPS];
			ptrdiff_t tq[TAPS];
			/* The normal equations' lower triangle (what solve reads). */
			vf a[NTRI] = {{0}};
			int nt = 0;
			for (int dy = -WIN; dy <= WIN; dy++) {
				int qy = y + dy;
				if (qy < 0 || qy >= h)
					continue;
				for (int dx = -WIN; dx <= WIN; dx++) {
					/* no lane's tap inside the image: only +0 to add */
					if (x + dx + VL - 1 < 0 || x + dx >= w)
						continue;
					vi qx = lane + vi_splat(dx);
					vi in = (qx >= vi_splat(0)) & (qx < vi_splat(w));
					ptrdiff_t q = (ptrdiff_t)qy * w + x + dx;
					vf e = feat_dist2(gf, pf, q);
					vf qz = vf_load(pz + q);
					e += vf_abs(qz - (gz + ggx * off[dx + WIN] + ggy * off[dy + WIN])) * inv_z;
					vf dd = (vf_load(pd + q) - gd) * dscale;
					e += vf_splat(DIRECT_W) * dd * dd;
					vf wt = vf_exp_fast(&e);
					vi m = in & (wt > vf_splat(0.0f));
					if (!vf_any(&m))
						continue;
					vf tww = vf_and(wt, m);
					vf *v = tv[nt];
					v[0] = vf_splat(1.0f);
					v[1] = offw[dx + WIN];
					v[2] = offw[dy + WIN];
					for (int k = 3; k < 6; k++)
						v[k] = vf_and(vf_load(pf[k] + q) - gf[k], m);
					v[6] = vf_and((qz - gz) * inv_z, m);
					v[7] = vf_and(dd, m);
					tw[nt] = tww;
					tm[nt] = m;
					tq[nt] = q;
					nt++;
				}
			}
			normal_rows(a, nt, tw, tv, 0, 4);
			normal_rows(a, nt, tw, tv, 4, 6);
			normal_rows(a, nt, tw, tv, 6, 7);
			normal_rows(a, nt, tw, tv, 7, 8);
			/* Each lane's solve: the fit at the pixel is sum_t h_t y_t,
			 * with h_t the tap's weight times z . (its regressors),
			 * M z = (1, 0, ..., 0): one solve for all the right-hand
			 * sides. */
			vf zv[NU];
			vi ok = solve_lanes(a, zv);
			int lanes = w - x < VL ? w - x : VL;
			/* The direct light's fit: the normal equations of the
			 * constant and regressor 7 are the sub-matrix of the whole
			 * one's, solved in closed form, all lanes at once: with
			 * M = (m00 m70; m70 m77), z = (m77, -m70) / det. With a
			 * ridge (so where the taps' direct light is all alike, the
			 * taps' weighted mean); a lane without weight is left out. */
			vf m00 = a[TRI(0, 0)], m70 = a[TRI(7, 0)];
			vf m77 = a[TRI(7, 7)] + m00 * vf_splat(DIRECT_RIDGE);
			vf det = m00 * m77 - m70 * m70;
			vi okd = (m00 > vf_splat(0.0f)) & (det > vf_splat(1e-6f) * m00 * m77);
			vf safe = vf_and(det, okd) + vf_and(vf_splat(1.0f), ~okd);
			vf zd0 = vf_and(m77 / safe, okd), zd7 = vf_and(-m70 / safe, okd);
			vf fo[5] = {{0}}, fd[5] = {{0}};
			for (int t = 0; t < nt; t++) {
				const vf *v = tv[t];
				vf p0 = zv[0] * v[0] + zv[4] * v[4], p1 = zv[1] * v[1] + zv[5] * v[5];
				vf p2 = zv[2] * v[2] + zv[6] * v[6], p3 = zv[3] * v[3] + zv[7] * v[7];
				vf hv = tw[t] * (p0 + p1 + p2 + p3);
				vf hd = tw[t] * (zd0 + zd7 * v[7]);
#pragma GCC unroll 5
				for (int c = 0; c < 5; c++) {
					vf yv = vf_load(pdata[c] + tq[t]);
					fo[c] += vf_and(hv * yv, tm[t]);
					fd[c] += vf_and(hd * yv, tm[t]);
				}
			}
			for (int l = 0; l < lanes; l++) {
				size_t pi = (size_t)i + (size_t)l;
				const chan *r0 = j->t[pi].h;
				float am = lum(j->am + pi * 3), am2 = am * am;
				float *fit = j->fit + pi * 3 * NFIT, *fitd = fit + 3;
				if (!ok[l]) {
					memcpy(fit, r0[CH_ALL].c, sizeof r0[CH_ALL].c);
					memcpy(fitd, r0[CH_ALL].c, sizeof r0[CH_ALL].c);
					perr[CAND_RAW][pi] = 0.0f; /* the raw pixel */
					perr[CAND_FIT][pi] = INFINITY;
					perr[CAND_DIRECT][pi] = INFINITY;
					continue;
				}
				for (int k = 0; k < 3; k++) {
					fit[k] = fo[k][l];
					fitd[k] = okd[l] ? fd[k][l] : r0[CH_ALL].c[k];
				}
				if (!j->halves) {
					/* One sample: no halves, no error estimate; the fit. */
					perr[CAND_RAW][pi] = INFINITY;
					perr[CAND_FIT][pi] = 0.0f;
					perr[CAND_DIRECT][pi] = INFINITY;
					continue;
				}
				float nc[NCH];
				chain_n(pixel_spp(j->fb, pi), nc);
				float na = nc[CH_A], nb = nc[CH_B];
				/* The raw pixel estimated the same way as the fits, so
				 * that the estimates share their noise. */
				perr[CAND_RAW][pi] = cross_error(r0, na, nb, lum(r0[CH_A].c), lum(r0[CH_B].c)) * am2;
				perr[CAND_FIT][pi] = cross_error(r0, na, nb, fo[3][l], fo[4][l]) * am2;
				perr[CAND_DIRECT][pi] = okd[l] ? cross_error(r0, na, nb, fd[3][l], fd[4][l]) * am2 : INFINITY;
			}
		}
}

/* Chooses per pixel the candidate whose estimated error, averaged over
 * (2 PICK_R + 1)^2 pixels, is the least (NFOR filters its errors before
 * choosing too: one pixel's estimate is as noisy as the pixel), or where
 * both regressions are estimated to beat the raw pixel their blend by
 * those estimates; times the albedo again, into the all-samples chain
 * (radiance, and the noise variance of the mean's brightness). The
 * average is weighted by how alike the pixels' albedo, normal and direct
 * light are (exp(-PICK_SCALE d^2), d their distance as the regression's
 * weights measure it, but for the depth), so that the estimates of another surface (a highlight's, a
 * wall's behind an edge) count less than the pixel's own surface's. The
 * sums are left undivided by the weights' sum: it is the same for every
 * candidate of the pixel, and neither the choice nor the blend's shares
 * change with it. A pixel of DENOISE_OWN_TIMES the mean samples or
 * more chooses by its own estimates alone (its halves are long enough:
 * the window's pixels have far fewer samples and their estimates favour
 * fits that are biased there, a glossy highlight's). */
LANES_INLINE void pick_body(job *j, int y0, int y1)
{
	int w = j->fb->w, h = j->fb->h;
	const float *perr[NCAND], *pf[6];
	for (int c = 0; c < NCAND; c++)
		perr[c] = plane(j, PL_ERR + c);
	for (int k = 0; k < 6; k++)
		pf[k] = plane(j, PL_F0 + k);
	const float *pd = plane(j, PL_D);
	for (int y = y0; y < y1; y++)
		for (int x0 = 0; x0 < w; x0 += VL) {
			/* VL pixels' sums, one in each lane, each over its window
			 * in the one pixel's order; a tap outside the image or of no
			 * weight adds +0 (masked), as if skipped. */
			vi lane = vi_lanes(x0);
			vi in[2 * PICK_R + 1];
			for (int dx = -PICK_R; dx <= PICK_R; dx++) {
				vi qx = lane + vi_splat(dx);
				in[dx + PICK_R] = (qx >= vi_splat(0)) & (qx < vi_splat(w));
			}
			vf gf[6];
			for (int k = 0; k < 6; k++)
				gf[k] = vf_load(pf[k] + (ptrdiff_t)y * w + x0);
			vf gd = vf_load(pd + (ptrdiff_t)y * w + x0);
			vf dscale = vf_splat(1.0f) / (vf_splat(0.5f) * vf_abs(gd) + vf_splat(0.05f));
			vf sv[NCAND] = {{0}};
			for (int qy = y - PICK_R; qy <= y + PICK_R; qy++) {
				if (qy < 0 || qy >= h)
					continue;
#pragma GCC unroll 9
				for (int dx = -PICK_R; dx <= PICK_R; dx++) {
					ptrdiff_t q = (ptrdiff_t)qy * w + x0 + dx;
					vf e = feat_dist2(gf, pf, q);
					vf dd = (vf_load(pd + q) - gd) * dscale;
					e += vf_splat(DIRECT_W) * dd * dd;
					e *= vf_splat(PICK_SCALE);
					vf wt = vf_exp_fast(&e);
					/* no weight: skipped (an infinite estimate times 0
					 * would be a NaN) */
					vi m = in[dx + PICK_R] & (wt > vf_splat(0.0f));
#pragma GCC unroll 3
					for (int c = 0; c < NCAND; c++)
						sv[c] += vf_and(wt * vf_load(perr[c] + q), m);
				}
			}
			int lanes = w - x0 < VL ? w - x0 : VL;
			for (int ln = 0; ln < lanes; ln++) {
				size_t i = (size_t)y * w + (size_t)(x0 + ln);
				float s[NCAND];
				for (int c = 0; c < NCAND; c++)
					s[c] = sv[c][ln];
				if (trusts_own(j->fb, i))
					for (int c = 0; c < NCAND; c++)
						s[c] = perr[c][i];
				int best = CAND_RAW;
				for (int c = 1; c < NCAND; c++)
					if (s[c] < s[best])
						best = c;
				chan *o = &j->t[i].h[CH_ALL];
				const float *am = j->am + i * 3, *c = best == CAND_RAW ? o->c : j->fit + (i * NFIT + (size_t)(best - CAND_FIT)) * 3;
				float l = lum(am);
				float mix[3];
				if (s[CAND_FIT] < s[CAND_RAW] && s[CAND_DIRECT] < s[CAND_RAW]) {
					/* Both fits beat the raw pixel: their blend, each
					 * weighted by how much it is estimated to gain on
					 * the raw pixel (a choice between two estimates
					 * that close is as noisy as they are). */
					const float *f1 = j->fit + i * NFIT * 3, *f2 = f1 + 3;
					float g1 = s[CAND_RAW] - s[CAND_FIT], g2 = s[CAND_RAW] - s[CAND_DIRECT];
					float w1 = g1 / (g1 + g2);
					for (int k = 0; k < 3; k++)
						mix[k] = w1 * f1[k] + (1.0f - w1) * f2[k];
					c = mix;
				}
				for (int k = 0; k < 3; k++) {
					float v = c[k] * am[k];
					o->c[k] = v > 0 ? v : 0;
				}
				float nc[NCH];
				chain_n(pixel_spp(j->fb, i), nc);
				o->v = o->v / nc[CH_ALL] * l * l;
			}
		}
}

LANES_TARGET static void LANES(regression_rows)(job *j, int y0, int y1)
{
	regression_body(j, y0, y1);
}

LANES_TARGET static void LANES(pick_rows)(job *j, int y0, int y1)
{
	pick_body(j, y0, y1);
}

#undef LANES_INLINE
#undef vf
#undef vi
#undef vll
#undef vf_splat
#undef vi_splat
#undef vi_lanes
#undef vf_load
#undef vf_and
#undef vf_any
#undef vf_abs
#undef vf_exp_fast
#undef normal_rows
#undef solve_lanes
#undef regression_body
#undef pick_body
#undef feat_dist2
