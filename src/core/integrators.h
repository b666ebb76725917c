/* rtsh — private interface between the renderer and its integrators. */
#ifndef RTSH_INTEGRATORS_H
#define RTSH_INTEGRATORS_H

#include "rtsh/render.h"
#include "sampler.h"

/* The camera ray of sample `sample` of pixel (px, py) of an fw x fh image,
 * and in *sp the sampler the integrator goes on with (camera.c); sampled:
 * the integrator draws numbers (integrator.sampled). */
ray camera_sample_ray(const world *w, const render_settings *s, bool sampled, int px, int py, int fw, int fh,
                      int sample, sampler *sp);
/* camera_sample_ray of every pixel of the block [x0, x1) x [y0, y1), row
 * by row, into r[i] and sp[i]: the same rays to the bit (camera.c). */
void camera_block_rays(const world *w, const render_settings *s, bool sampled, int x0, int y0, int x1, int y1,
                       int fw, int fh, int sample, ray *r, sampler *sp);

/* One integrator (integrators.def names it, its file defines it). */
typedef struct integrator {
	/* The radiance arriving along the camera ray r (unit direction); g:
	 * the camera sample's sampler, from dimension g->dim on. */
	vec3 (*radiance)(const world *w, const render_settings *s, ray r, sampler *g);
	/* The same when r's first hit is known (packets, render.c): found, h,
	 * and the answers of the shadow packets for it (known, blocked; 0 and 0
	 * without shadow_packets). */
	vec3 (*radiance_first)(const world *w, const render_settings *s, ray r, sampler *g, bool found, const hit *h,
	                       uint32_t known, uint32_t blocked);
	/* The shadow rays of a packet's first hits traced as packets (or NULL):
	 * whitted_shadow_packets below. */
	void (*shadow_packets)(const world *w, int n, const hit *h, const bool *found, uint32_t *known,
	                       uint32_t *blocked);
	/* It draws sampler numbers: each camera ray gets its pixel's sampler
	 * even at one sample per pixel (else a single sample is the pixel's
	 * centre). */
	bool sampled;
	/* It gives the denoiser its features (denoise.h): `denoise` applies. */
	bool features;
} integrator;

#define RT_INTEGRATOR(e, name, desc) extern const integrator desc;
#include "rtsh/integrators.def"
#undef RT_INTEGRATOR

/* The integrator of mode m (the first for an unknown m). */
const integrator *integrator_of(render_mode m);

/* Radiance arriving along r (unit direction) by ambient + Phong + hard
 * shadows + mirror reflection / refraction up to s->depth (whitted.c). */
vec3 whitted_radiance(const world *w, const render_settings *s, ray r);
/* A Monte-Carlo estimate of the radiance along r (path.c); g gives the
 * camera sample's numbers, from dimension g->dim on. */
vec3 path_radiance(const world *w, const render_settings *s, ray r, sampler *g);
/* The same two with the camera ray's first hit already traced (a packet,
 * packet.h): found says whether r hit anything, *h what (unread when not);
 * Whitted's with the answers of its shadow rays toward the lights of
 * `known` too (whitted_shadow_packets). */
vec3 whitted_radiance_first(const world *w, const render_settings *s, ray r, bool found, const hit *h,
                            uint32_t known, uint32_t blocked);
/* Whitted's shadow rays from the first hits of a packet's camera rays,
 * traced as packets, one per light (whitted.c): bit l of known[i] says
 * that ray i's shading will ask about light l (l < WHITTED_PACKET_LIGHTS,
 * a Phong surface), bit l of blocked[i] the answer world_occluded would
 * give. Bit WHITTED_KNOWN_PRE of known[i]: what the rays were made from is
 * kept too (whitted_pre, this thread's, until its next call), for the
 * whitted_radiance_first of h[i] that follows. */
void whitted_shadow_packets(const world *w, int n, const hit *h, const bool *found, uint32_t *known,
                            uint32_t *blocked);
#define WHITTED_PACKET_LIGHTS 31
#define WHITTED_KNOWN_PRE 31
/* What whitted_shadow_packets worked out for a first hit on the way to its
 * shadow rays: the shading frame (phong_whitted_frame: n, p) and, for the
 * lights l < WHITTED_PRE_LIGHTS, whether phong_light_ray gave a ray (bit l
 * of lit), and then the radiance lr arriving, the direction ld and n . l.
 * The Phong family's Whitted shading takes them instead of working them
 * out again: the same doubles (the same functions of the same values),
 * without light_at's square root and division a second time. */
#define WHITTED_PRE_LIGHTS 4
typedef struct whitted_pre {
	vec3 n, p;
	uint32_t lit;
	vec3 lr[WHITTED_PRE_LIGHTS], ld[WHITTED_PRE_LIGHTS];
	double ndl[WHITTED_PRE_LIGHTS];
} whitted_pre;
/* What the Phong family's Whitted shading (bsdf_phong.c) is told of its
 * shadow rays: when `h` is the hit it shades, the answers for the lights of
 * `known` (whitted_shadow_packets), and pre (or NULL) what they were made
 * from. Set by whitted_radiance_first around the first hit's shading only;
 * per thread (defined in bsdf_phong.c). */
typedef struct whitted_shadows {
	const hit *h;
	uint32_t known, blocked;
	const whitted_pre *pre;
} whitted_shadows;
extern _Thread_local whitted_shadows whitted_shadow_hint;
vec3 path_radiance_first(const world *w, const render_settings *s, ray r, sampler *g, bool found, const hit *h);

/* The scattering at one path vertex: the material family's lobes
 * (material.c; the seeds' Phong family in bsdf_phong.c, the physically
 * based one in bsdf_pbr.c), in the frame of the side the ray arrived on.
 * The integrators call bsdf_make / _eval / _pdf / _sample_u and never look
 * at a family's fields. */
typedef struct bsdf {
	vec3 n;        /* unit normal, flipped onto the side of wo */
	vec3 wo;       /* unit direction back along the arriving ray */
	double cos_o;  /* n . wo, >= 0 */
	bool front;    /* wo is on the outward side (glass: entering) */
	uint8_t family; /* MAT_PHONG or MAT_PBR (world.h) */
	bool smooth;   /* some non-delta lobe: point lights are seen through it */
	bool through;  /* a non-delta lobe also transmits: lights below the surface count */
	vec3 sigma_in; /* absorption per unit inside the volume below (Beer-Lambert), or 0 */
	/* The Phong family (bsdf_phong.c): */
	vec3 kd;       /* Lambert: share x albedo */
	vec3 ks;       /* normalised Phong about the mirror direction: share */
	double ns;     /* its exponent (shininess) */
	vec3 km;       /* mirror / metal: share x tint (Schlick) */
	double nm;     /* its Phong exponent (from fuzz); < 0 for a perfect mirror */
	vec3 kt;       /* glass transmission tint (reflection is white) */
	double wg;     /* glass share */
	double ior;    /* glass refractive index (PBR: the dielectric's) */
	double p[4];   /* lobe choice probabilities: d, s, m, g (sum 1, or all 0) */
	double total;  /* sum of the lobes' choice weights (0: absorbs everything) */
	/* The PBR family (bsdf_pbr.c): */
	struct bsdf_pbr {
		vec3 t, b;        /* tangents: (t, b, n) a right-handed frame */
		vec3 base;        /* base colour */
		double a, ac;     /* GGX alpha of the base and of the coat */
		double wm, wp, wt; /* metal, opaque dielectric (plastic), transmission weights */
		double cc;        /* clearcoat weight */
		vec3 f0;          /* the plastic's F0 (KHR_materials_specular), f90 = sf */
		double sf;        /* its specularFactor */
		double cc_o;      /* 1 - cc Fc(cos_o): what the coat lets through toward wo */
		double pl[6];     /* lobe choice: coat, metal, plastic spec, diffuse, glass, (unused) */
		bool delta, cdelta; /* the base's / the coat's specular lobes are perfect */
		bool thin, ms;    /* thin-walled; energy compensation (Turquin 2019) */
		vec3 kms_m, kms_p; /* Turquin's factors of the metal and the plastic's specular */
		double kdiff;     /* the plastic's Lambert: (1 - Es(cos_o)) / (1 - Es_avg) */
	} pb;
} bsdf;

typedef struct bsdf_sample {
	vec3 wi;       /* the new direction (unit) */
	vec3 weight;   /* f cos / pdf, the lobe choice included (energy) */
	double radiance_scale; /* (eta_i / eta_t)^2 on refraction, else 1 */
	bool transmit; /* wi goes through the surface */
	bool delta;    /* from a perfect mirror or glass lobe */
	double pdf;    /* bsdf_pdf(wi) when the family knows it already, else < 0 */
} bsdf_sample;

/* The bsdf of material m at hit h seen from wo (unit, pointing away). */
void bsdf_make(bsdf *b, const mat_lin *m, const hit *h, vec3 wo);
/* The BSDF value f(wi, wo) of the non-delta lobes (per steradian). */
vec3 bsdf_eval(const bsdf *b, vec3 wi);
/* Samples a lobe and a direction from three uniform numbers: u[0] picks
 * the lobe (and, rescaled, glass's reflection or refraction), u[1], u[2]
 * the direction; false when the path is absorbed. */
bool bsdf_sample_u(const bsdf *b, const double u[3], bsdf_sample *out);
/* The same with three numbers from g. */
bool bsdf_sample_dir(const bsdf *b, rng *g, bsdf_sample *out);
/* The mixed density with which bsdf_sample_dir picks the direction wi
 * through a smooth lobe (per steradian; delta lobes are left out). */
double bsdf_pdf(const bsdf *b, vec3 wi);
/* True when u[0] matters to bsdf_sample_u (more than one lobe to pick). */
bool bsdf_has_choice(const bsdf *b);
/* The denoiser's features (denoise.c): the surface's albedo (what a white
 * light would come back as, roughly), and 0; or, for a surface that is
 * mostly a perfect mirror, a narrow glossy metal lobe or glass, 1 (look
 * along the mirror reflection) or 2
 * (along the refraction *dir) with the tint that gives. */
int bsdf_features(const bsdf *b, vec3 *albedo, vec3 *tint, vec3 *dir);
/* The Phong exponent of a mirror lobe of roughness fuzz in (0,1]. */
double fuzz_exponent(double fuzz);

/* Whitted's recursive ray (whitted.c): the radiance along r, followed to
 * depth more bounces; weight as in mat_family.whitted. */
typedef vec3 (*whitted_trace_fn)(const world *w, ray r, int depth, vec3 weight);

/* One material family (material.c's table, indexed by mat_lin.family). */
typedef struct mat_family {
	const char *name;
	void (*make)(bsdf *b, const mat_lin *m, vec3 albedo);
	vec3 (*eval)(const bsdf *b, vec3 wi);
	double (*pdf)(const bsdf *b, vec3 wi);
	bool (*sample)(const bsdf *b, const double u[3], bsdf_sample *out);
	bool (*has_choice)(const bsdf *b);
	int (*features)(const bsdf *b, vec3 *albedo, vec3 *tint, vec3 *dir);
	/* Whitted shading (whitted.c): what the material sends back along r
	 * at h from the point lights and ambient, and the mirror / glass rays
	 * it follows (trace), up to depth. weight is what r's radiance is
	 * multiplied by on its way to the camera (1,1,1 for a camera ray); a
	 * ray the material follows is given weight times its own factor
	 * (kr, kt, reflective...), and trace does not follow it when that is
	 * negligible (whitted.c, WHITTED_MIN_WEIGHT). */
	vec3 (*whitted)(const world *w, const mat_lin *m, const hit *h, ray r, int depth, vec3 weight,
	                whitted_trace_fn trace);
} mat_family;
extern const mat_family mat_phong_family, mat_pbr_family;
/* By mat_lin.family (material.c). */
extern const mat_family *const mat_families[MAT_FAMILY_COUNT];

/* Reflectance of a smooth dielectric for unpolarised light (Born & Wolf
 * 1.5.2; pbrt 4th ed. 9.3.2). cos_i > 0 on the incident side; eta = eta_t /
 * eta_i. Sets *cos_t for the refracted ray; 1 on total internal reflection. */
static inline double fresnel_dielectric(double cos_i, double eta, double *cos_t)
{
	double sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
	if (sin2_t >= 1.0) {
		*cos_t = 0.0;
		return 1.0;
	}
	double ct = sqrt(1.0 - sin2_t);
	double rs = (cos_i - eta * ct) / (cos_i + eta * ct);
	double rp = (eta * cos_i - ct) / (eta * cos_i + ct);
	*cos_t = ct;
	return 0.5 * (rs * rs + rp * rp);
}

/* What a ray that leaves the scene sees: the sky if the scene has one, else
 * black (whitted) or the ambient colour as a uniform sky (path). */
vec3 world_background(const world *w, vec3 dir, render_mode mode);

/* The surface colour at a hit (the checker texture applied). */
vec3 hit_albedo(const mat_lin *m, const hit *h);
/* The material at a hit: m, or *tmp holding m with its textures of
 * parameters applied (glTF's metallic-roughness texture: roughness x G,
 * metallic x B). */
const mat_lin *hit_material(const mat_lin *m, const hit *h, mat_lin *tmp);
/* The emitted radiance at a hit: the emission, times glTF's emissive
 * texture there when the material has one. */
vec3 hit_emission(const mat_lin *m, const hit *h);

/* A point just off the surface on the side of n, for spawning rays. */
static inline vec3 offset_point(const world *w, vec3 p, vec3 n)
{
	double ax = fabs(p.x), ay = fabs(p.y), az = fabs(p.z); /* not fmax: a library call */
	double m = ax > ay ? ax : ay;
	double e = w->eps + 1e-12 * (m > az ? m : az);
	return v3_madd(p, n, e);
}

/* Whether adding the Phong highlight lr (s rv^e) to c (rv > 0) leaves every
 * component of c as it is, told without pow: only when it does. With
 * 0 < rv <= 0.5 and e >= 64, or rv <= 0.8 and e >= 200, rv^e <= 2^-64 (pow
 * is within an ulp of it); then each product the shading rounds is below
 * c_k 2^-54 when lr_k s <= 512 c_k (three roundings and pow's error fit in
 * the spare factor 2), and a c_k > 0 is moved by nothing below half its
 * ulp, which is above c_k 2^-54. NaN and infinite lr or c fail a test. */
static inline bool phong_specular_negligible(vec3 c, vec3 lr, double s, double rv, double e)
{
	if (!(rv <= 0.5 ? e >= 64.0 : rv <= 0.8 && e >= 200.0))
		return false;
	return c.x > 0.0 && c.y > 0.0 && c.z > 0.0 && c.x < INFINITY && c.y < INFINITY && c.z < INFINITY &&
	       fabs(lr.x * s) <= 512.0 * c.x && fabs(lr.y * s) <= 512.0 * c.y && fabs(lr.z * s) <= 512.0 * c.z;
}

/* The shading point and normal of the Phong family's Whitted shading at
 * h, and the shadow ray toward light l from there: false when the light
 * sends nothing to p or is behind the surface (no ray is traced); else *sr,
 * its length *dist, the radiance *lr arriving and n . l (*ndl). Whitted's
 * shadow packets make the same rays with it. */
static inline void phong_whitted_frame(const world *w, const hit *h, vec3 *n, vec3 *p)
{
	*n = h->front ? h->n : v3_neg(h->n);
	*p = offset_point(w, h->p, *n);
}

static inline bool phong_light_ray(const world *w, size_t l, vec3 p, vec3 n, ray *sr, double *dist, vec3 *lr,
                                   double *ndl)
{
	vec3 ld;
	*lr = light_at(&w->lights[l], p, &ld, dist); /* physical lights fall off */
	if (!(lr->x > 0.0 || lr->y > 0.0 || lr->z > 0.0))
		return false;
	*ndl = v3_dot(n, ld);
	if (*ndl <= 0.0)
		return false;
	*sr = (ray){p, ld};
	return true;
}

#endif
