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

/* Adaptive tree depth control (Hall and Greenberg, "A testbed for
 * realistic image synthesis", 1983): a mirror or glass ray is not traced
 * when the weight it carries to the pixel (the product of the kr, kt,
 * reflective... along its way), its largest channel, is below this. Without
 * it glass traces two rays at every hit, each to depth - 1, and rays caught
 * among glass spheres branch 2^depth (scenes/final.rt's depth 50: minutes).
 * The bound: what is left out is the branch's weight times the radiance L
 * it would bring back (L can pass 1: bright lights, emission). A pixel is
 * the mean of its samples times the camera's gain, sRGB-encoded, whose
 * steepest slope is 12.92 x 255 = 3295 codes per unit (near black), so one
 * left-out branch moves a pixel by less than 3295 x 2^-24 x gain x L =
 * 0.0002 x gain x L codes: a code only for L in the thousands, and below
 * that only a pixel within that distance of a rounding edge can flip. 2^-16
 * and 2^-20 flipped 10 and 1 pixels of final.rt at 320x180 by a code (24
 * and 1 of materials.rt); 2^-24 none there, in scenes/ or in 166 files of
 * scenes-wild, and costs final.rt no more rays than 2^-16 to speak of. */
#define WHITTED_MIN_WEIGHT (1.0 / (1 << 24))
/* ...and a hard bound for files made to defeat the weight rule (glass of
 * ior 5.8 reflects half and passes half, so a full tree 24 levels deep,
 * 2^25 rays, stays above it; a hit's weights sum to at most 1 in both
 * families, so the rule alone bounds a level to 2^24 rays, no more): a
 * camera ray traces at most this many mirror and glass rays, so at most
 * 1 + 4096 rays and their shadow rays in all; past it, none more (they
 * bring back black, in the order they come: such a file's picture is cut,
 * its time bounded). It is above what a chain of depth 1000 mirrors (the
 * setting's largest depth) traces, so no weight-1 chain is ever cut, and
 * no scene of scenes/ or scenes-wild reaches it. */
#define WHITTED_MAX_RAYS 4096

static _Thread_local int rays_left; /* of this camera ray's WHITTED_MAX_RAYS */

static vec3 trace(const world *w, ray r, int depth, vec3 weight);

static vec3 shade(const world *w, ray r, int depth, vec3 weight, bool found, const hit *h)
{
	if (!found)
		return world_background(w, r.d, MODE_WHITTED);
	const mat_lin *m = &w->mats[h->mat];
	return mat_families[m->family]->whitted(w, m, h, r, depth, weight, trace);
}

/* first: r is a camera ray (world_intersect_coherent) */
static vec3 trace_at(const world *w, ray r, int depth, vec3 weight, bool first)
{
	hit h;
	bool found = (first ? world_intersect_coherent : world_intersect)(w, &r, 0.0, INFINITY, &h);
	return shade(w, r, depth, weight, found, &h);
}

static vec3 trace(const world *w, ray r, int depth, vec3 weight)
{
	if (fmax(weight.x, fmax(weight.y, weight.z)) < WHITTED_MIN_WEIGHT || rays_left <= 0)
		return v3(0, 0, 0);
	rays_left--;
	return trace_at(w, r, depth, weight, false);
}

vec3 whitted_radiance(const world *w, const render_settings *s, ray r)
{
	rays_left = WHITTED_MAX_RAYS;
	return trace_at(w, r, s->depth, v3(1, 1, 1), true);
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
	rays_left = WHITTED_MAX_RAYS;
	vec3 c = shade(w, r, s->depth, v3(1, 1, 1), found, h);
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
