/* rtsh — the Embree 3 comparison for `make bench` (optional: built only when
 * embree3/rtcore.h is installed, see the Makefile).
 *
 *   embree_primary SCENE.rt W H
 *
 * Loads the scene with rtsh's own parser, gives its spheres to Embree as
 * RTC_GEOMETRY_TYPE_SPHERE_POINT and its planes as one large quad each
 * (100 km a side: at the grid's view no camera ray reaches the edge), then
 * traces the same camera rays as bench.c's primary-ray row (one through each
 * pixel centre, rtsh's cam_ray, converted to float) with rtcIntersect1 on
 * one thread, and prints
 *   mrays M seconds S hits H
 * for the fastest of three passes (the first warms the caches); then the same
 * rays in packets, rtcIntersect4 on 2x2-pixel tiles, rtcIntersect8 on 2x4
 * (2 wide, 4 tall) and rtcIntersect16 on 4x4, with the coherent flag
 * (RTC_INTERSECT_CONTEXT_FLAG_COHERENT), one line each:
 *   packet N mrays M seconds S hits H
 * Then, when the scene has a light, shadow rays toward its first light from
 * rtsh's own camera hits (world_intersect_packet on 4x4 blocks; the origin
 * moved 1e-7 along the normal, as bench.c's packet rows make them; the
 * same doubles, converted to float, with tnear 1e-4 so that float rounding
 * does not find the ray's own sphere), made beforehand and only the
 * queries timed: rtcOccluded1 on each, then rtcOccluded16 on each block's
 * (coherent flag), fastest of three passes after one that warms the caches:
 *   shadow mrays M seconds S blocked B
 *   shadow-packet 16 mrays M seconds S blocked B
 * Other shapes are not translated: the program says so and fails.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <embree3/rtcore.h>

#include "rtsh/packet.h"
#include "rtsh/rtfile.h"
#include "rtsh/world.h"
#include "embree_packets.h"

static double now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static void add_plane(RTCDevice dev, RTCScene sc, const object *o)
{
	vec3 n = v3_norm(o->dir);
	vec3 t = v3_norm(v3_cross(fabs(n.y) < 0.9 ? v3(0, 1, 0) : v3(1, 0, 0), n));
	vec3 b = v3_cross(n, t);
	const double e = 5e4;
	RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_QUAD);
	float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 4);
	unsigned *idx = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT4, 4 * sizeof(unsigned), 1);
	static const double corner[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
	for (int i = 0; i < 4; i++) {
		vec3 p = v3_add(o->pos, v3_add(v3_scale(t, corner[i][0] * e), v3_scale(b, corner[i][1] * e)));
		v[3 * i] = (float)p.x;
		v[3 * i + 1] = (float)p.y;
		v[3 * i + 2] = (float)p.z;
		idx[i] = (unsigned)i;
	}
	rtcCommitGeometry(g);
	rtcAttachGeometry(sc, g);
	rtcReleaseGeometry(g);
}

/* The shadow rows (see the top): false when memory runs out. */
static bool shadow_rows(RTCScene sc, const world *wd, int w, int h)
{
	size_t nblk = (size_t)((w + 3) / 4) * (size_t)((h + 3) / 4);
	float(*q)[7] = malloc(nblk * PACKET_MAX * sizeof *q); /* origin, direction, tfar */
	int *cnt = malloc(nblk * sizeof *cnt);
	if (!q || !cnt) {
		free(q);
		free(cnt);
		return false;
	}
	vec3 lamp = wd->lights[0].pos;
	size_t b = 0, total = 0;
	for (int y0 = 0; y0 < h; y0 += 4)
		for (int x0 = 0; x0 < w; x0 += 4, b++) {
			int x1 = x0 + 4 < w ? x0 + 4 : w, y1 = y0 + 4 < h ? y0 + 4 : h, n = (x1 - x0) * (y1 - y0), m = 0;
			ray r[PACKET_MAX];
			hit hh[PACKET_MAX];
			bool found[PACKET_MAX];
			cam_block_rays(&wd->cam, x0, y0, x1, y1, w, h, r);
			world_intersect_packet(wd, n, r, 0.0, INFINITY, hh, found);
			for (int i = 0; i < n; i++)
				if (found[i]) {
					vec3 p = v3_madd(hh[i].p, hh[i].n, 1e-7), to = v3_sub(lamp, p);
					double d = v3_len(to);
					vec3 dir = v3_scale(to, 1.0 / d);
					float *f = q[b * PACKET_MAX + (size_t)m++];
					f[0] = (float)p.x, f[1] = (float)p.y, f[2] = (float)p.z;
					f[3] = (float)dir.x, f[4] = (float)dir.y, f[5] = (float)dir.z;
					f[6] = (float)d;
				}
			cnt[b] = m;
			total += (size_t)m;
		}
	struct RTCIntersectContext ctx;
	rtcInitIntersectContext(&ctx);
	double best = -1;
	long blocked = 0;
	for (int pass = 0; pass < 4; pass++) {
		long nb = 0;
		double t0 = now();
		for (size_t k = 0; k < nblk; k++)
			for (int i = 0; i < cnt[k]; i++) {
				const float *f = q[k * PACKET_MAX + (size_t)i];
				struct RTCRay ry = {f[0], f[1], f[2], 1e-4f, f[3], f[4], f[5], 0.0f, f[6], 0xffffffffu, 0, 0};
				rtcOccluded1(sc, &ctx, &ry);
				nb += ry.tfar < 0.0f; /* Embree sets tfar to -inf when blocked */
			}
		double t = now() - t0;
		if (pass > 0 && (best < 0 || t < best))
			best = t;
		blocked = nb;
	}
	printf("shadow mrays %.4f seconds %.6f blocked %ld\n", (double)total / best * 1e-6, best, blocked);
	ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
	best = -1;
	for (int pass = 0; pass < 4; pass++) {
		long nb = 0;
		double t0 = now();
		for (size_t k = 0; k < nblk; k++) {
			_Alignas(64) struct RTCRay16 ry;
			_Alignas(64) int valid[16];
			for (int i = 0; i < 16; i++) {
				const float *f = q[k * PACKET_MAX + (size_t)(i < cnt[k] ? i : 0)];
				valid[i] = i < cnt[k] ? -1 : 0;
				ry.org_x[i] = f[0], ry.org_y[i] = f[1], ry.org_z[i] = f[2];
				ry.dir_x[i] = f[3], ry.dir_y[i] = f[4], ry.dir_z[i] = f[5];
				ry.tnear[i] = 1e-4f;
				ry.tfar[i] = f[6];
				ry.time[i] = 0.0f;
				ry.mask[i] = 0xffffffffu;
				ry.id[i] = (unsigned)i;
				ry.flags[i] = 0;
			}
			if (cnt[k])
				rtcOccluded16(valid, sc, &ctx, &ry);
			for (int i = 0; i < cnt[k]; i++)
				nb += ry.tfar[i] < 0.0f;
		}
		double t = now() - t0;
		if (pass > 0 && (best < 0 || t < best))
			best = t;
		blocked = nb;
	}
	printf("shadow-packet 16 mrays %.4f seconds %.6f blocked %ld\n", (double)total / best * 1e-6, best, blocked);
	free(q);
	free(cnt);
	return true;
}

int main(int argc, char **argv)
{
	if (argc != 4) {
		fputs("usage: embree_primary SCENE.rt W H\n", stderr);
		return 2;
	}
	int w = atoi(argv[2]), h = atoi(argv[3]);
	rt_error err;
	scene *s = rt_load_file(argv[1], NULL, &err);
	if (!s || w < 1 || h < 1) {
		fprintf(stderr, "embree_primary: %s\n", s ? "bad size" : err.msg);
		return 1;
	}
	world *wd = world_build(s, &err); /* for the camera: the same rays as rtsh */
	if (!wd) {
		fprintf(stderr, "embree_primary: %s\n", err.msg);
		return 1;
	}
	RTCDevice dev = rtcNewDevice("threads=1");
	RTCScene sc = rtcNewScene(dev);
	size_t nsph = 0;
	for (size_t i = 0; i < s->nobjs; i++)
		nsph += s->objs[i].kind == OBJ_SPHERE;
	if (nsph) {
		RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_SPHERE_POINT);
		float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), nsph);
		size_t k = 0;
		for (size_t i = 0; i < s->nobjs; i++) {
			const object *o = &s->objs[i];
			if (o->kind != OBJ_SPHERE)
				continue;
			if (o->scale.x != o->scale.y || o->scale.y != o->scale.z) {
				fprintf(stderr, "embree_primary: object %zu is an ellipsoid; only spheres and planes\n", i + 1);
				return 1;
			}
			v[4 * k] = (float)o->pos.x;
			v[4 * k + 1] = (float)o->pos.y;
			v[4 * k + 2] = (float)o->pos.z;
			v[4 * k + 3] = (float)(o->scale.x * 0.5);
			k++;
		}
		rtcCommitGeometry(g);
		rtcAttachGeometry(sc, g);
		rtcReleaseGeometry(g);
	}
	for (size_t i = 0; i < s->nobjs; i++) {
		const object *o = &s->objs[i];
		if (o->kind == OBJ_PLANE) {
			add_plane(dev, sc, o);
		} else if (o->kind != OBJ_SPHERE) {
			fprintf(stderr, "embree_primary: object %zu is a %s; only spheres and planes\n", i + 1,
			        obj_kind_name(o->kind));
			return 1;
		}
	}
	rtcCommitScene(sc);

	struct RTCIntersectContext ctx;
	rtcInitIntersectContext(&ctx);
	double best = -1;
	long hits = 0;
	for (int pass = 0; pass < 3; pass++) {
		long nh = 0;
		double t0 = now();
		for (int y = 0; y < h; y++)
			for (int x = 0; x < w; x++) {
				ray r = cam_ray(&wd->cam, x + 0.5, y + 0.5, w, h);
				struct RTCRayHit rh;
				rh.ray.org_x = (float)r.o.x;
				rh.ray.org_y = (float)r.o.y;
				rh.ray.org_z = (float)r.o.z;
				rh.ray.dir_x = (float)r.d.x;
				rh.ray.dir_y = (float)r.d.y;
				rh.ray.dir_z = (float)r.d.z;
				rh.ray.tnear = 0.0f;
				rh.ray.tfar = INFINITY;
				rh.ray.time = 0.0f;
				rh.ray.mask = 0xffffffffu;
				rh.ray.id = 0;
				rh.ray.flags = 0;
				rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
				rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
				rtcIntersect1(sc, &ctx, &rh);
				nh += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
			}
		double t = now() - t0;
		if (pass > 0 && (best < 0 || t < best))
			best = t;
		hits = nh;
	}
	printf("mrays %.4f seconds %.6f hits %ld\n", (double)w * h / best * 1e-6, best, hits);
	embree_packet_rows(sc, &wd->cam, w, h, CLOCK_MONOTONIC);
	if (wd->nlights && !shadow_rows(sc, wd, w, h)) {
		fputs("embree_primary: out of memory\n", stderr);
		return 1;
	}
	rtcReleaseScene(sc);
	rtcReleaseDevice(dev);
	world_free(wd);
	scene_free(s);
	return 0;
}
