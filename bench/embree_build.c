/* rtsh — Embree 3's build of the spheres of bench.c's spheres-N rows (built
 * with embree_primary, only when embree3/rtcore.h is installed).
 *
 *   embree_build N
 *
 * Generates the scene of the spheres-N rows (scene_generate(N, 1) with
 * spheres only: N spheres and a ground plane), gives the spheres to Embree
 * as RTC_GEOMETRY_TYPE_SPHERE_POINT and the plane as one quad (as
 * embree_primary does), at the build quality Embree uses for a static
 * scene unless told otherwise (RTC_BUILD_QUALITY_MEDIUM, the default), on
 * one thread, and prints
 *   build S bytes B
 * S: the median of three builds in wall-clock seconds, from the new scene to
 * the end of rtcCommitScene, the geometry buffers filled from the model in
 * between (world_build's work too: the model in, a tree out); B: what Embree
 * allocated for the scene (its memory monitor).
 */
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include <embree3/rtcore.h>

#include "rtsh/generate.h"
#include "rtsh/scene.h"

static double now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static atomic_llong bytes;

static bool monitor(void *ptr, ssize_t n, bool post)
{
	(void)ptr;
	(void)post;
	atomic_fetch_add(&bytes, (long long)n);
	return true;
}

static RTCScene build(RTCDevice dev, const scene *s, size_t nsph)
{
	RTCScene sc = rtcNewScene(dev);
	RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_SPHERE_POINT);
	float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), nsph);
	size_t k = 0;
	for (size_t i = 0; i < s->nobjs; i++) {
		const object *o = &s->objs[i];
		if (o->kind != OBJ_SPHERE)
			continue;
		v[4 * k] = (float)o->pos.x;
		v[4 * k + 1] = (float)o->pos.y;
		v[4 * k + 2] = (float)o->pos.z;
		v[4 * k + 3] = (float)(o->scale.x * 0.5);
		k++;
	}
	rtcCommitGeometry(g);
	rtcAttachGeometry(sc, g);
	rtcReleaseGeometry(g);
	for (size_t i = 0; i < s->nobjs; i++) {
		const object *o = &s->objs[i];
		if (o->kind != OBJ_PLANE)
			continue;
		vec3 n = v3_norm(o->dir);
		vec3 t = v3_norm(v3_cross(fabs(n.y) < 0.9 ? v3(0, 1, 0) : v3(1, 0, 0), n));
		vec3 b = v3_cross(n, t);
		RTCGeometry q = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_QUAD);
		float *qv = rtcSetNewGeometryBuffer(q, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 4);
		unsigned *ix = rtcSetNewGeometryBuffer(q, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT4, 4 * sizeof(unsigned), 1);
		static const double corner[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
		for (int c = 0; c < 4; c++) {
			vec3 p = v3_add(o->pos, v3_add(v3_scale(t, corner[c][0] * 5e4), v3_scale(b, corner[c][1] * 5e4)));
			qv[3 * c] = (float)p.x;
			qv[3 * c + 1] = (float)p.y;
			qv[3 * c + 2] = (float)p.z;
			ix[c] = (unsigned)c;
		}
		rtcCommitGeometry(q);
		rtcAttachGeometry(sc, q);
		rtcReleaseGeometry(q);
	}
	rtcCommitScene(sc);
	return sc;
}

int main(int argc, char **argv)
{
	if (argc != 2 && argc != 3) {
		fputs("usage: embree_build N [THREADS]\n", stderr);
		return 2;
	}
	size_t n = strtoul(argv[1], NULL, 10);
	int threads = argc == 3 ? atoi(argv[2]) : 1;
	if (threads < 1 || threads > 64) {
		fprintf(stderr, "embree_build: %s threads; expected 1..64\n", argv[2]);
		return 2;
	}
	gen_opts o = {.spheres_only = true};
	rt_error err;
	scene *s = scene_generate(n, 1, &o, &err);
	if (!s) {
		fprintf(stderr, "embree_build: %s\n", err.msg);
		return 1;
	}
	size_t nsph = 0;
	for (size_t i = 0; i < s->nobjs; i++)
		nsph += s->objs[i].kind == OBJ_SPHERE;
	char config[32];
	snprintf(config, sizeof config, "threads=%d", threads);
	RTCDevice dev = rtcNewDevice(config);
	rtcSetDeviceMemoryMonitorFunction(dev, monitor, NULL);
	double t[3];
	long long scene_bytes = 0;
	for (int pass = 0; pass < 3; pass++) {
		long long before = atomic_load(&bytes);
		double t0 = now();
		RTCScene sc = build(dev, s, nsph);
		t[pass] = now() - t0;
		scene_bytes = atomic_load(&bytes) - before;
		rtcReleaseScene(sc);
	}
	double a = t[0], b = t[1], c = t[2];
	double med = a < b ? (b < c ? b : a < c ? c : a) : (a < c ? a : b < c ? c : b);
	printf("build %.6f bytes %lld\n", med, scene_bytes);
	rtcReleaseDevice(dev);
	scene_free(s);
	return 0;
}
