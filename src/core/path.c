/* rtsh — the path-tracing integrator: Lambertian diffuse with cosine-weighted
 * sampling, mirror reflection, next-event estimation toward the point lights,
 * emission, the sky, and Russian roulette.
 *
 * Point lights follow the Whitted convention (no fall-off): a light of
 * radiance-ratio L gives a white Lambertian surface facing it the outgoing
 * radiance L, i.e. irradiance pi * L * cos(theta). */
#include "integrators.h"

/* A cosine-weighted direction about the unit normal n (Malley's method). */
static vec3 sample_cosine(vec3 n, double u1, double u2)
{
	double r = sqrt(u1), phi = 2.0 * RT_PI * u2;
	double x = r * cos(phi), y = r * sin(phi), z = sqrt(fmax(0.0, 1.0 - u1));
	/* An orthonormal basis around n (Duff et al., "Building an orthonormal
	 * basis, revisited", 2017). */
	double sign = copysign(1.0, n.z);
	double a = -1.0 / (sign + n.z), b = n.x * n.y * a;
	vec3 t = v3(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
	vec3 bt = v3(b, sign + n.y * n.y * a, -n.y);
	return v3_add(v3_add(v3_scale(t, x), v3_scale(bt, y)), v3_scale(n, z));
}

vec3 path_radiance(const world *w, const render_settings *s, ray r, rng *g)
{
	vec3 radiance = v3(0, 0, 0), thr = v3(1, 1, 1);
	for (int bounce = 0;; bounce++) {
		hit h;
		if (!world_intersect(w, &r, 0.0, INFINITY, &h)) {
			radiance = v3_add(radiance, v3_mul(thr, world_background(w, r.d, MODE_PATH)));
			break;
		}
		const mat_lin *m = &w->mats[h.object];
		radiance = v3_add(radiance, v3_mul(thr, m->emission));
		if (bounce >= s->depth)
			break;
		vec3 n = h.front ? h.n : v3_neg(h.n);
		vec3 albedo = hit_albedo(m, &h);
		vec3 p = offset_point(w, h.p, n);

		/* Choose the mirror lobe with probability `reflective`. */
		if (m->reflective > 0.0 && rng_next(g) < m->reflective) {
			vec3 tint = v3_lerp(v3(1, 1, 1), albedo, m->metal);
			thr = v3_mul(thr, tint);
			r = (ray){p, v3_reflect(r.d, n)};
		} else {
			vec3 kd = v3_scale(albedo, m->diffuse);
			for (size_t i = 0; i < w->nlights; i++) {
				const light_lin *l = &w->lights[i];
				vec3 to = v3_sub(l->pos, p);
				double dist = v3_len(to);
				if (!(dist > 0.0))
					continue;
				vec3 ld = v3_scale(to, 1.0 / dist);
				double ndl = v3_dot(n, ld);
				if (ndl <= 0.0)
					continue;
				ray sr = {p, ld};
				if (!world_occluded(w, &sr, 0.0, dist))
					radiance = v3_add(radiance, v3_mul(thr, v3_mul(kd, v3_scale(l->radiance, ndl))));
			}
			double u1 = rng_next(g), u2 = rng_next(g);
			r = (ray){p, sample_cosine(n, u1, u2)};
			thr = v3_mul(thr, kd); /* f cos / pdf = (kd / pi) cos / (cos / pi) */
		}
		/* Russian roulette after three bounces keeps the estimate unbiased. */
		if (bounce >= 3) {
			double q = fmin(0.95, v3_max_comp(thr));
			if (!(q > 0.0) || rng_next(g) >= q)
				break;
			thr = v3_scale(thr, 1.0 / q);
		}
	}
	return radiance;
}
