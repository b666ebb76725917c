/* rtsh — Embree 3's packet calls on camera rays, for bench/embree_primary.c
 * and bench/embree_mesh.c (only built where embree3/rtcore.h is installed).
 *
 * embree_packet_rows traces the camera rays of a w x h image (rtsh's
 * cam_ray through each pixel centre, made a tile at a time as rtsh's render
 * and packet rows make them, cam_block_rays, and converted to float) in tiles of
 * 2x2 pixels with rtcIntersect4, 2x4 (2 wide, 4 tall) with rtcIntersect8
 * and 4x4 with rtcIntersect16, the context flagged coherent, on the calling
 * thread; a tile at the image's edge leaves its missing lanes invalid. It
 * prints, for the fastest of three passes after one that warms the caches
 * (timed on clk: the clock of the harness's rtcIntersect1 row),
 *   packet N mrays M seconds S hits H
 * and then the fastest of three passes that make and store the 16-ray
 * packets without tracing them (what the 16-ray pass spends around the call):
 *   packet-fill 16 seconds S
 */
#ifndef RTSH_BENCH_EMBREE_PACKETS_H
#define RTSH_BENCH_EMBREE_PACKETS_H

#include <math.h>
#include <stdio.h>
#include <time.h>

#include <embree3/rtcore.h>

#include "rtsh/world.h"

static double packet_clock(clockid_t clk)
{
	struct timespec ts;
	clock_gettime(clk, &ts);
	return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* One pass of N-ray packets over tiles tw x th; the hits counted. The
 * structure of RTCRayHit4/8/16 is the same but for the array length, so one
 * macro makes the three. */
#define EMBREE_PACKET_PASS(NAME, N, TYPE, CALL)                                                        \
	static long packet_pass_##NAME(RTCScene sc, const cam_view *cv, int w, int h, int tw, int th)          \
	{                                                                                              \
		struct RTCIntersectContext ctx;                                                        \
		rtcInitIntersectContext(&ctx);                                                         \
		ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;                                       \
		_Alignas(64) struct TYPE rh;                                                           \
		_Alignas(64) int valid[N];                                                             \
		ray tile[N];                                                                           \
		long hits = 0;                                                                         \
		for (int y0 = 0; y0 < h; y0 += th)                                                     \
			for (int x0 = 0; x0 < w; x0 += tw) {                                           \
				int x1 = x0 + tw < w ? x0 + tw : w, y1 = y0 + th < h ? y0 + th : h;    \
				cam_block_rays(cv, x0, y0, x1, y1, w, h, tile);                        \
				for (int k = 0; k < N; k++) {                                          \
					int x = x0 + k % tw, y = y0 + k / tw;                          \
					valid[k] = x < x1 && y < y1 ? -1 : 0;                          \
					ray r = tile[valid[k] ? (y - y0) * (x1 - x0) + x - x0 : 0];    \
					rh.ray.org_x[k] = (float)r.o.x;                                \
					rh.ray.org_y[k] = (float)r.o.y;                                \
					rh.ray.org_z[k] = (float)r.o.z;                                \
					rh.ray.dir_x[k] = (float)r.d.x;                                \
					rh.ray.dir_y[k] = (float)r.d.y;                                \
					rh.ray.dir_z[k] = (float)r.d.z;                                \
					rh.ray.tnear[k] = 0.0f;                                        \
					rh.ray.tfar[k] = INFINITY;                                     \
					rh.ray.time[k] = 0.0f;                                         \
					rh.ray.mask[k] = 0xffffffffu;                                  \
					rh.ray.id[k] = (unsigned)k;                                    \
					rh.ray.flags[k] = 0;                                           \
					rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;                    \
					rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;                 \
				}                                                                      \
				CALL(valid, sc, &ctx, &rh);                                            \
				for (int k = 0; k < N; k++)                                            \
					hits += valid[k] && rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID; \
			}                                                                              \
		return hits;                                                                           \
	}

/* The fill pass's "call": the packet's stores made visible, nothing traced. */
#define EMBREE_FILL_ONLY(valid, sc, ctx, rh) __asm__ volatile("" : : "r"(valid), "r"(sc), "r"(ctx), "r"(rh) : "memory")

EMBREE_PACKET_PASS(4, 4, RTCRayHit4, rtcIntersect4)
EMBREE_PACKET_PASS(8, 8, RTCRayHit8, rtcIntersect8)
EMBREE_PACKET_PASS(16, 16, RTCRayHit16, rtcIntersect16)
EMBREE_PACKET_PASS(fill16, 16, RTCRayHit16, EMBREE_FILL_ONLY)

static void embree_packet_rows(RTCScene sc, const cam_view *cv, int w, int h, clockid_t clk)
{
	for (int n = 4; n <= 16; n *= 2) {
		double best = -1;
		long hits = 0;
		for (int pass = 0; pass < 4; pass++) {
			double t0 = packet_clock(clk);
			hits = n == 4 ? packet_pass_4(sc, cv, w, h, 2, 2)
			     : n == 8 ? packet_pass_8(sc, cv, w, h, 2, 4)
			              : packet_pass_16(sc, cv, w, h, 4, 4);
			double t = packet_clock(clk) - t0;
			if (pass > 0 && (best < 0 || t < best))
				best = t;
		}
		printf("packet %d mrays %.4f seconds %.6f hits %ld\n", n, (double)w * h / best * 1e-6, best, hits);
	}
	/* what the 16-ray pass spends outside rtcIntersect16: the same tiles'
	 * rays made and stored into the packet, the hits counted, no call */
	double best = -1;
	for (int pass = 0; pass < 4; pass++) {
		double t0 = packet_clock(clk);
		(void)packet_pass_fill16(sc, cv, w, h, 4, 4);
		double t = packet_clock(clk) - t0;
		if (pass > 0 && (best < 0 || t < best))
			best = t;
	}
	printf("packet-fill 16 seconds %.6f\n", best);
}

#endif
