/* rtsh — Embree 3 on a triangle model, for the triangle rows of `make bench`
 * (built with embree_primary, only when embree3/rtcore.h is installed).
 *
 *   embree_mesh MODEL W H
 *
 * Reads the model with rtsh's reader, gives its triangles to Embree
 * (RTC_GEOMETRY_TYPE_TRIANGLE, RTC_BUILD_QUALITY_HIGH, one thread), and
 * prints the median of three passes of each, in process CPU time (as
 * bench.c times rtsh's side, so that other jobs on the machine slow
 * neither):
 *   build S bytes B primary M hits H secondary M2
 * build: rtcCommitScene in seconds; bytes: what Embree allocated for the
 * scene (its memory monitor); primary and secondary: Mrays/s of
 * rtcIntersect1 on the rays of mesh_rays.h. Then the camera rays in packets
 * of 4, 8 and 16 with the coherent flag (embree_packets.h), a line each:
 *   packet N mrays M seconds S hits H
 */
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <embree3/rtcore.h>

#include "embree_packets.h"
#include "mesh_rays.h"
#include "rtsh/mesh.h"

static double now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
	return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static double median3(const double t[3])
{
	double a = t[0], b = t[1], c = t[2];
	return a < b ? (b < c ? b : a < c ? c : a) : (a < c ? a : b < c ? c : b);
}

static atomic_llong bytes;

static bool monitor(void *ptr, ssize_t n, bool post)
{
	(void)ptr;
	(void)post;
	atomic_fetch_add(&bytes, (long long)n);
	return true;
}

/* coherent: camera rays in pixel order, given Embree's hint for them as
 * rtsh's are given its own (world_trace_coherent) */
static bool trace(RTCScene sc, vec3 o, vec3 d, float *t, vec3 *ng, bool coherent)
{
	struct RTCIntersectContext ctx;
	rtcInitIntersectContext(&ctx);
	if (coherent)
		ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
	struct RTCRayHit rh;
	rh.ray.org_x = (float)o.x;
	rh.ray.org_y = (float)o.y;
	rh.ray.org_z = (float)o.z;
	rh.ray.dir_x = (float)d.x;
	rh.ray.dir_y = (float)d.y;
	rh.ray.dir_z = (float)d.z;
	rh.ray.tnear = 0;
	rh.ray.tfar = INFINITY;
	rh.ray.mask = 0xFFFFFFFF;
	rh.ray.flags = 0;
	rh.ray.time = 0;
	rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
	rtcIntersect1(sc, &ctx, &rh);
	if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
		return false;
	*t = rh.ray.tfar;
	*ng = v3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);
	return true;
}

int main(int argc, char **argv)
{
	if (argc != 4) {
		fputs("usage: embree_mesh MODEL W H\n", stderr);
		return 2;
	}
	int w = atoi(argv[2]), h = atoi(argv[3]);
	rt_error err = {0};
	mesh *m = mesh_load(argv[1], &err);
	if (!m || w < 1 || h < 1) {
		fprintf(stderr, "embree_mesh: %s\n", m ? "bad size" : err.msg);
		return 1;
	}
	RTCDevice dev = rtcNewDevice("threads=1");
	rtcSetDeviceMemoryMonitorFunction(dev, monitor, NULL);
	double tbuild[3];
	RTCScene sc = NULL;
	long long scene_bytes = 0;
	for (int pass = 0; pass < 3; pass++) {
		if (sc)
			rtcReleaseScene(sc);
		long long before = atomic_load(&bytes);
		double t0 = now();
		sc = rtcNewScene(dev);
		rtcSetSceneBuildQuality(sc, RTC_BUILD_QUALITY_HIGH);
		RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
		rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_HIGH);
		float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), m->nverts);
		unsigned *ix = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), m->ntris);
		memcpy(v, m->p, (size_t)m->nverts * 3 * sizeof(float));
		memcpy(ix, m->tri, (size_t)m->ntris * 3 * sizeof(unsigned));
		rtcCommitGeometry(g);
		rtcAttachGeometry(sc, g);
		rtcReleaseGeometry(g);
		rtcCommitScene(sc);
		double t = now() - t0;
		tbuild[pass] = t;
		scene_bytes = atomic_load(&bytes) - before;
	}
	camera c = bench_mesh_camera(m->bounds);
	cam_view cv = cam_view_make(&c);
	double eps = 1e-4 * v3_len(v3_sub(m->bounds.hi, m->bounds.lo));
	double tprim[3], tsec[3];
	long hits = 0, sec_rays = 0;
	for (int pass = 0; pass < 3; pass++) {
		double t0 = now();
		hits = 0;
		for (int y = 0; y < h; y++)
			for (int x = 0; x < w; x++) {
				ray r = cam_ray(&cv, x + 0.5, y + 0.5, w, h);
				float t;
				vec3 ng;
				hits += trace(sc, r.o, r.d, &t, &ng, true);
			}
		double tp = now() - t0;
		tprim[pass] = tp;
		/* secondary rays: made first from this pass's hits, then timed */
		ray *sr = malloc((size_t)w * h * sizeof *sr);
		sec_rays = 0;
		for (int y = 0; y < h; y++)
			for (int x = 0; x < w; x++) {
				ray r = cam_ray(&cv, x + 0.5, y + 0.5, w, h);
				float t;
				vec3 ng;
				if (!trace(sc, r.o, r.d, &t, &ng, true))
					continue;
				vec3 n = v3_norm(ng);
				if (v3_dot(n, r.d) > 0)
					n = v3_neg(n);
				sr[sec_rays++] = (ray){v3_madd(ray_at(r, t), n, eps),
				                       bench_diffuse_dir(n, (uint64_t)y * (uint64_t)w + (uint64_t)x)};
			}
		double t1 = now();
		for (long i = 0; i < sec_rays; i++) {
			float t;
			vec3 ng;
			trace(sc, sr[i].o, sr[i].d, &t, &ng, false);
		}
		double ts = now() - t1;
		free(sr);
		tsec[pass] = ts;
	}
	printf("build %.6f bytes %lld primary %.4f hits %ld secondary %.4f\n", median3(tbuild), scene_bytes,
	       (double)w * h / median3(tprim) * 1e-6, hits, (double)sec_rays / median3(tsec) * 1e-6);
	embree_packet_rows(sc, &cv, w, h, CLOCK_PROCESS_CPUTIME_ID);
	rtcReleaseScene(sc);
	rtcReleaseDevice(dev);
	mesh_free(m);
	return 0;
}
