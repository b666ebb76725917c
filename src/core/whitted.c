/* rtsh — the Whitted integrator: ambient + direct light per point light,
 * hard shadows, recursive mirror reflection and refraction (Whitted, "An
 * improved illumination model for shaded display", 1980). Each material
 * family shades its own hits (mat_family.whitted): Phong for the seeds'
 * materials (bsdf_phong.c), the same BRDF as in path mode for PBR ones
 * (bsdf_pbr.c).
 *
 * Lights have no distance fall-off, as in miniRT: a light of ratio r and
 * colour c lights a surface facing it with r * c. */
#include "integrators.h"
#include "rtsh/packet.h"

static vec3 trace(const world *w, ray r, int depth);

static vec3 shade(const world *w, ray r, int depth, bool found, const hit *h)
{
	if (!found)
		return world_background(w, r.d, MODE_WHITTED);
	const mat_lin *m = &w->mats[h->mat];
	return mat_families[m->family]->whitted(w, m, h, r, depth, trace);
}

/* first: r is a camera ray (world_intersect_coherent) */
static vec3 trace_at(const world *w, ray r, int depth, bool first)
{
	hit h;
	bool found = (first ? world_intersect_coherent : world_intersect)(w, &r, 0.0, INFINITY, &h);
	return shade(w, r, depth, found, &h);
}

static vec3 trace(const world *w, ray r, int depth)
{
	return trace_at(w, r, depth, false);
}

vec3 whitted_radiance(const world *w, const render_settings *s, ray r)
{
	return trace_at(w, r, s->depth, true);
}

/* What this thread's last whitted_shadow_packets made its rays from, ray i
 * of its n (pre_hits: its h) in pre[i]. */
static _Thread_local struct {
	const hit *hits;
	int n;
	whitted_pre pre[PACKET_MAX];
} pre_cache;

vec3 whitted_radiance_first(const world *w, const render_settings *s, ray r, bool found, const hit *h,
                            uint32_t known, uint32_t blocked)
{
	const whitted_pre *pre = NULL;
	if (known >> WHITTED_KNOWN_PRE & 1u) {
		/* h is one of the last call's hits (integrators.h) */
		uintptr_t off = (uintptr_t)h - (uintptr_t)pre_cache.hits;
		if (off % sizeof *h == 0 && off / sizeof *h < (size_t)pre_cache.n)
			pre = &pre_cache.pre[off / sizeof *h];
	}
	whitted_shadow_hint = (whitted_shadows){h, known & ~(1u << WHITTED_KNOWN_PRE), blocked, pre};
	vec3 c = shade(w, r, s->depth, found, h);
	whitted_shadow_hint = (whitted_shadows){NULL, 0, 0, NULL};
	return c;
}

void whitted_shadow_packets(const world *w, int n, const hit *h, const bool *found, uint32_t *known,
                            uint32_t *blocked)
{
	whitted_pre *pre = pre_cache.pre;
	bool phong[PACKET_MAX];
	pre_cache.hits = h;
	pre_cache.n = n;
	for (int i = 0; i < n; i++) {
		known[i] = blocked[i] = 0;
		phong[i] = found[i] && w->mats[h[i].mat].family == MAT_PHONG;
		if (phong[i]) {
			phong_whitted_frame(w, &h[i], &pre[i].n, &pre[i].p);
			pre[i].lit = 0;
			known[i] = 1u << WHITTED_KNOWN_PRE;
		}
	}
	for (size_t l = 0; l < w->nlights && l < WHITTED_PACKET_LIGHTS; l++) {
		ray sr[PACKET_MAX];
		double dist[PACKET_MAX];
		int who[PACKET_MAX], m = 0;
		for (int i = 0; i < n; i++) {
			vec3 lr;
			double ndl;
			if (phong[i] && phong_light_ray(w, l, pre[i].p, pre[i].n, &sr[m], &dist[m], &lr, &ndl)) {
				if (l < WHITTED_PRE_LIGHTS) {
					pre[i].lit |= 1u << l;
					pre[i].lr[l] = lr;
					pre[i].ld[l] = sr[m].d;
					pre[i].ndl[l] = ndl;
				}
				who[m++] = i;
			}
		}
		bool occ[PACKET_MAX];
		world_occluded_packet(w, m, sr, 0.0, dist, occ);
		for (int k = 0; k < m; k++) {
			known[who[k]] |= 1u << l;
			blocked[who[k]] |= (uint32_t)occ[k] << l;
		}
	}
}

static vec3 whitted_camera(const world *w, const render_settings *s, ray r, sampler *g)
{
	(void)g;
	return whitted_radiance(w, s, r);
}

static vec3 whitted_camera_first(const world *w, const render_settings *s, ray r, sampler *g, bool found,
                                 const hit *h, uint32_t known, uint32_t blocked)
{
	(void)g;
	return whitted_radiance_first(w, s, r, found, h, known, blocked);
}

/* Whitted draws no random numbers: one sample is the pixel's centre. */
const integrator whitted_integrator = {whitted_camera, whitted_camera_first, whitted_shadow_packets, false, false};
