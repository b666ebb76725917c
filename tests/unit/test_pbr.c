/* rtsh — tests of the physically based materials (bsdf_pbr.c). Every
 * expected value is computed here, independently of the code under test:
 *   - the directional albedo of each lobe, by the test's own quadrature of
 *     f |cos| over the sphere of directions (a midpoint rule in cos theta and
 *     phi), against the mean sampled weight and against the white furnace (a
 *     sphere under a uniform sky of radiance 1 at depth 1 shows the albedo);
 *   - with energy compensation, a conductor with F0 = 1 reflects everything;
 *     a white glass sphere in the furnace neither gains nor loses energy;
 *   - reciprocity: f(o, i) = f(i, o) for reflection, and for refraction
 *     f(o, i) / eta_i^2 ... in Veach's form f_front(o, i) = f_back(i, o) / eta^2;
 *   - energy conservation: no combination's albedo above 1;
 *   - a chi-square test of the sampled directions against the pdf (binned
 *     over the sphere, expected counts by integrating the pdf per bin, as
 *     Mitsuba's test suite does), and the pdf integrating to the share of
 *     samples not absorbed. */
#include "testutil.h"

#include "core/integrators.h"
#include "rtsh/render.h"
#include "rtsh/scene.h"
#include "rtsh/world.h"

typedef struct pbr_args {
	vec3 base;
	double rough, metallic, trans, cc, ccr;
	bool thin, ms;
} pbr_args;

static mat_lin pbr_mat(pbr_args a)
{
	mat_lin m = {0};
	m.family = MAT_PBR;
	m.albedo = a.base;
	m.ior = 1.5;
	m.light = -1;
	m.thin = a.thin;
	m.pbr.roughness = (float)a.rough;
	m.pbr.metallic = (float)a.metallic;
	m.pbr.transmission = (float)a.trans;
	m.pbr.clearcoat = (float)a.cc;
	m.pbr.clearcoat_roughness = (float)a.ccr;
	m.pbr.specular_factor = 1;
	m.pbr.specular_color[0] = m.pbr.specular_color[1] = m.pbr.specular_color[2] = 1;
	m.pbr.single = !a.ms;
	return m;
}

/* The bsdf at the origin, normal +Z, seen from wo = (sin, 0, cos = c);
 * front: from outside (the outward normal is +Z), else from inside. */
static bsdf bsdf_at(const mat_lin *m, double c, bool front)
{
	hit h = {.t = 1, .p = v3(0, 0, 0), .n = v3(0, 0, front ? 1 : -1), .front = front};
	bsdf b;
	bsdf_make(&b, m, &h, v3(sqrt(1 - c * c), 0, c));
	return b;
}

/* The test's own quadrature of f |cos| over the sphere: the midpoint rule
 * in t and phi (2n x 2n cells), with theta = pi/2 (1 -
 * cos(pi t)) so that the cells crowd both poles, where the sharp lobes of
 * normal incidence sit: d omega = sin theta (dtheta / dt) dt dphi. */
static vec3 albedo_quad_split(const bsdf *b, int n, vec3 *trans)
{
	vec3 sum = v3(0, 0, 0), below = v3(0, 0, 0);
	double dt = 1.0 / (2 * n), dp = RT_PI / n;
	for (int i = 0; i < 2 * n; i++) {
		double t = (i + 0.5) * dt, th = 0.5 * RT_PI * (1 - cos(RT_PI * t));
		double jac = sin(th) * 0.5 * RT_PI * RT_PI * sin(RT_PI * t);
		double z = cos(th), s = sin(th);
		for (int j = 0; j < 2 * n; j++) {
			double phi = (j + 0.5) * dp;
			vec3 wi = v3(s * cos(phi), s * sin(phi), z);
			vec3 v = v3_scale(bsdf_eval(b, wi), fabs(z) * jac);
			if (z > 0)
				sum = v3_add(sum, v);
			else
				below = v3_add(below, v);
		}
	}
	*trans = v3_scale(below, dt * dp);
	return v3_scale(sum, dt * dp);
}

/* The radiance albedo: reflection plus transmission. */
static vec3 albedo_quad(const bsdf *b, int n)
{
	vec3 t, r = albedo_quad_split(b, n, &t);
	return v3_add(r, t);
}

/* The energy albedo: the transmitted radiance was scaled by 1 / eta^2
 * crossing into a volume of relative index eta (Veach 1997, 5.2); the
 * energy is not. */
static double energy_quad(const bsdf *b, int n, bool volume)
{
	vec3 t, r = albedo_quad_split(b, n, &t);
	double eta = b->front ? 1.5 : 1 / 1.5;
	return v3_max_comp(v3_add(r, v3_scale(t, volume ? eta * eta : 1.0)));
}

typedef struct estimate {
	vec3 mean;
	double sd;
} estimate;

static estimate albedo_sampled(const bsdf *b, int n, rng *r)
{
	vec3 sum = v3(0, 0, 0), sq = v3(0, 0, 0);
	for (int i = 0; i < n; i++) {
		bsdf_sample smp;
		if (!bsdf_sample_dir(b, r, &smp))
			continue;
		vec3 w = v3_scale(smp.weight, smp.radiance_scale);
		sum = v3_add(sum, w);
		sq = v3_add(sq, v3_mul(w, w));
	}
	estimate e;
	e.mean = v3_scale(sum, 1.0 / n);
	vec3 var = v3_sub(v3_scale(sq, 1.0 / n), v3_mul(e.mean, e.mean));
	e.sd = sqrt(fmax(0.0, v3_max_comp(var)) / n);
	return e;
}

static const pbr_args lobes[] = {
	/* base, roughness, metallic, transmission, coat, coat roughness, thin, ms */
	{{1, 1, 1}, 0.3, 1, 0, 0, 0, false, false},         /* white conductor */
	{{0.95, 0.64, 0.54}, 0.6, 1, 0, 0, 0, false, false}, /* copper */
	{{1, 1, 1}, 1.0, 1, 0, 0, 0, false, false},
	{{0.8, 0.1, 0.1}, 0.4, 0, 0, 0, 0, false, false},   /* red plastic */
	{{0.9, 0.9, 0.9}, 0.5, 0, 1, 0, 0, true, false},    /* thin rough glass */
	{{0.9, 0.9, 0.9}, 0.3, 0, 1, 0, 0, false, false},   /* rough glass volume */
	{{0.9, 0.9, 0.9}, 0.6, 0, 1, 0, 0, false, false},
	{{0.2, 0.3, 0.8}, 0.7, 0, 0, 1, 0.3, false, false}, /* coated plastic */
	{{0.95, 0.64, 0.54}, 0.5, 1, 0, 0, 0, false, true}, /* compensated copper */
};
#define NLOBES (int)(sizeof lobes / sizeof lobes[0])

/* Per lobe, from outside and (glass) inside, at four angles: the mean
 * sampled weight equals the quadrature of f |cos|, and neither is above 1. */
static void test_albedo_sample_vs_quadrature(void **state)
{
	(void)state;
	rng r = {4242};
	const double cosv[] = {1.0, 0.7, 0.35, 0.1};
	for (int k = 0; k < NLOBES; k++) {
		mat_lin m = pbr_mat(lobes[k]);
		for (int side = 0; side < (lobes[k].trans > 0 ? 2 : 1); side++)
			for (int a = 0; a < 4; a++) {
				bsdf b = bsdf_at(&m, cosv[a], side == 0);
				vec3 q = albedo_quad(&b, 400);
				estimate e = albedo_sampled(&b, 200000, &r);
				/* the quadrature's own error: a few 1e-3 at the sharpest lobe */
				double tol = 5 * e.sd + 0.006;
				if (fabs(q.x - e.mean.x) > tol || fabs(q.y - e.mean.y) > tol || fabs(q.z - e.mean.z) > tol)
					fail_msg("lobe %d side %d cos %g: quadrature %.4f %.4f %.4f, sampled %.4f %.4f %.4f "
					         "(sd %.4f)",
					         k, side, cosv[a], q.x, q.y, q.z, e.mean.x, e.mean.y, e.mean.z, e.sd);
				double en = energy_quad(&b, 400, lobes[k].trans > 0 && !lobes[k].thin);
				if (en > 1.0 + 0.006)
					fail_msg("lobe %d side %d cos %g: energy albedo %.4f above 1", k, side, cosv[a], en);
				if (a == 0 || a == 3)
					print_message("lobe %d side %d cos %.2f: albedo %.4f (sampled %.4f +- %.4f)\n", k, side,
					              cosv[a], q.x, e.mean.x, e.sd);
			}
	}
}

/* With energy compensation, a conductor of F0 = 1 reflects all the light
 * at every angle and roughness; without it, the loss grows with roughness. */
static void test_compensated_conductor(void **state)
{
	(void)state;
	rng r = {7};
	const double rough[] = {0.2, 0.5, 0.8, 1.0}, cosv[] = {1.0, 0.5, 0.15};
	for (int i = 0; i < 4; i++)
		for (int a = 0; a < 3; a++) {
			pbr_args on = {{1, 1, 1}, rough[i], 1, 0, 0, 0, false, true}, off = on;
			off.ms = false;
			mat_lin mon = pbr_mat(on), moff = pbr_mat(off);
			bsdf bon = bsdf_at(&mon, cosv[a], true), boff = bsdf_at(&moff, cosv[a], true);
			estimate e = albedo_sampled(&bon, 100000, &r);
			vec3 q = albedo_quad(&bon, 300), qoff = albedo_quad(&boff, 300);
			/* the table of E is interpolated: 1.5% */
			if (fabs(e.mean.x - 1.0) > 5 * e.sd + 0.015 || fabs(q.x - 1.0) > 0.015)
				fail_msg("roughness %g cos %g: sampled %.4f +- %.4f, quadrature %.4f", rough[i], cosv[a], e.mean.x,
				         e.sd, q.x);
			if (a == 0)
				print_message("conductor F0=1 roughness %.1f cos 1: %.4f with compensation, %.4f without\n",
				              rough[i], q.x, qoff.x);
		}
}

/* Helmholtz reciprocity of the reflection, and Veach's adjoint relation of
 * the refraction: f_front(o, i) = f_back(i, o) / eta^2 (eta = 1.5). */
static void test_reciprocity(void **state)
{
	(void)state;
	test_rng t = {11};
	int checked = 0;
	for (int k = 0; k < NLOBES; k++) {
		if (lobes[k].ms)
			continue; /* Turquin's factor depends on cos_o alone: not reciprocal (rtsh(5)) */
		mat_lin m = pbr_mat(lobes[k]);
		for (int n = 0; n < 300; n++) {
			vec3 o = tdir(&t), i = tdir(&t);
			if (o.z < 0)
				o.z = -o.z;
			if (fabs(o.z) < 0.05 || fabs(i.z) < 0.05)
				continue;
			hit h = {.t = 1, .n = v3(0, 0, 1), .front = true};
			bsdf bo;
			bsdf_make(&bo, &m, &h, o);
			vec3 f1 = bsdf_eval(&bo, i);
			bsdf bi;
			hit hi = {.t = 1, .n = v3(0, 0, 1), .front = i.z > 0};
			bsdf_make(&bi, &m, &hi, i);
			vec3 f2 = bsdf_eval(&bi, o);
			if (i.z < 0 && !lobes[k].thin)
				f2 = v3_scale(f2, 1.0 / 2.25);
			double tol = 1e-9 * (1 + v3_max_comp(f1));
			assert_near(f1.x, f2.x, tol);
			assert_near(f1.y, f2.y, tol);
			assert_near(f1.z, f2.z, tol);
			checked++;
		}
	}
	print_message("%d direction pairs reciprocal\n", checked);
}

/* Energy: over a grid of parameters and angles, the quadrature of f |cos|
 * never passes 1. */
static void test_energy_bound(void **state)
{
	(void)state;
	const double rough[] = {0.3, 0.6, 1.0}, met[] = {0, 0.5, 1}, tr[] = {0, 1}, cc[] = {0, 1};
	const double cosv[] = {1.0, 0.4, 0.08};
	double worst = 0;
	int n = 0;
	for (int ms = 0; ms < 2; ms++)
		for (int a = 0; a < 3; a++)
			for (int b = 0; b < 3; b++)
				for (int c = 0; c < 2; c++)
					for (int d = 0; d < 2; d++)
						for (int e = 0; e < 3; e++)
							for (int side = 0; side < 2; side++) {
								pbr_args p = {{1, 1, 1}, rough[a], met[b], tr[c], cc[d], 0.2, false, ms};
								mat_lin m = pbr_mat(p);
								bsdf bs = bsdf_at(&m, cosv[e], side == 0);
								double v = energy_quad(&bs, 300, tr[c] > 0);
								worst = fmax(worst, v);
								if (v > 1.01)
									fail_msg("rough %g metal %g trans %g coat %g ms %d cos %g side %d: albedo %.4f",
									         rough[a], met[b], tr[c], cc[d], ms, cosv[e], side, v);
								n++;
							}
	print_message("%d combinations: largest albedo %.4f\n", n, worst);
}

/* The regularised lower incomplete gamma P(s, x) by its series (x < s + 1)
 * or continued fraction (Abramowitz & Stegun 6.5.29, 6.5.31). */
static double gamma_p(double s, double x)
{
	if (x <= 0)
		return 0;
	double lg = lgamma(s);
	if (x < s + 1) {
		double term = 1 / s, sum = term;
		for (int n = 1; n < 1000; n++) {
			term *= x / (s + n);
			sum += term;
			if (term < sum * 1e-15)
				break;
		}
		return sum * exp(-x + s * log(x) - lg);
	}
	/* Lentz's method for the continued fraction of Q */
	double b = x + 1 - s, c = 1e300, d = 1 / b, h = d;
	for (int i = 1; i < 1000; i++) {
		double an = -i * (i - s);
		b += 2;
		d = an * d + b;
		if (fabs(d) < 1e-300)
			d = 1e-300;
		c = b + an / c;
		if (fabs(c) < 1e-300)
			c = 1e-300;
		d = 1 / d;
		double del = d * c;
		h *= del;
		if (fabs(del - 1) < 1e-15)
			break;
	}
	return 1 - exp(-x + s * log(x) - lg) * h;
}

/* Chi-square of sampled directions against the pdf, over NZ x NP bins of
 * equal solid angle on the whole sphere; bins expecting fewer than 5 are
 * pooled. Also checks the pdf integrates to the share of samples kept. */
static void test_chi2(void **state)
{
	(void)state;
	enum { NZ = 20, NP = 40, SUB = 12, N = 400000 };
	static double expect[NZ * NP];
	static int count[NZ * NP];
	rng r = {31337};
	const double cosv[] = {0.9, 0.4};
	int tests = 0;
	for (int k = 0; k < NLOBES; k++)
		for (int side = 0; side < (lobes[k].trans > 0 ? 2 : 1); side++)
			for (int a = 0; a < 2; a++) {
				mat_lin m = pbr_mat(lobes[k]);
				bsdf b = bsdf_at(&m, cosv[a], side == 0);
				double total = 0;
				for (int i = 0; i < NZ; i++)
					for (int j = 0; j < NP; j++) {
						double s = 0;
						for (int u = 0; u < SUB; u++)
							for (int v = 0; v < SUB; v++) {
								double z = -1 + 2.0 * (i + (u + 0.5) / SUB) / NZ;
								double phi = 2 * RT_PI * (j + (v + 0.5) / SUB) / NP;
								double sn = sqrt(1 - z * z);
								s += bsdf_pdf(&b, v3(sn * cos(phi), sn * sin(phi), z));
							}
						expect[i * NP + j] = s * (2.0 / NZ) * (2 * RT_PI / NP) / (SUB * SUB);
						total += expect[i * NP + j];
					}
				memset(count, 0, sizeof count);
				int kept = 0;
				for (int n = 0; n < N; n++) {
					bsdf_sample smp;
					if (!bsdf_sample_dir(&b, &r, &smp) || smp.delta)
						continue;
					kept++;
					double z = clampd(smp.wi.z, -1, 1), phi = atan2(smp.wi.y, smp.wi.x);
					if (phi < 0)
						phi += 2 * RT_PI;
					int i = (int)((z + 1) / 2 * NZ), j = (int)(phi / (2 * RT_PI) * NP);
					i = i < NZ ? i : NZ - 1;
					j = j < NP ? j : NP - 1;
					count[i * NP + j]++;
				}
				/* the pdf's integral is the chance a sample is kept */
				double share = (double)kept / N;
				if (fabs(total - share) > 0.01 + 4 * sqrt(share * (1 - share) / N))
					fail_msg("lobe %d side %d cos %g: the pdf integrates to %.4f, %.4f of the samples kept", k,
					         side, cosv[a], total, share);
				double chi2 = 0, pe = 0;
				int po = 0, dof = 0;
				for (int c = 0; c < NZ * NP; c++) {
					pe += expect[c] * N;
					po += count[c];
					if (pe >= 5) {
						chi2 += (po - pe) * (po - pe) / pe;
						dof++;
						pe = 0;
						po = 0;
					}
				}
				if (pe > 0)
					chi2 += (po - pe) * (po - pe) / (pe > 1 ? pe : 1);
				double pval = 1 - gamma_p((dof - 1) / 2.0, chi2 / 2);
				tests++;
				print_message("lobe %d side %d cos %.1f: chi2 %.1f over %d bins, p %.3f\n", k, side, cosv[a], chi2,
				              dof, pval);
				/* Mitsuba's rule: reject at 1% over all the tests (Sidak) */
				if (pval < 1 - pow(1 - 0.01, 1.0 / 30))
					fail_msg("lobe %d side %d cos %g: chi2 %.1f, %d dof, p %.2g", k, side, cosv[a], chi2, dof - 1,
					         pval);
			}
	print_message("%d chi-square tests\n", tests);
}

/* --- the white furnace, rendered -------------------------------------------- */

/* A sphere of material p filling the middle of the image under a uniform
 * sky of radiance 1; the centre pixels see it head-on (cos_o ~ 1). */
static double furnace_centre(const material_pbr *p, vec3 color, int depth, int spp)
{
	scene *s = scene_new();
	assert_non_null(s);
	camera c = {.pos = v3(0, 0, -10), .dir = v3(0, 0, 1), .fov = 4};
	assert_true(scene_add_camera(s, &c, NULL));
	s->has_ambient = true;
	s->amb = (ambient){1, v3(255, 255, 255)};
	object o = object_make(OBJ_SPHERE, color);
	o.scale = v3(2, 2, 2);
	o.mat.pbr = material_pbr_intern(p, NULL);
	assert_non_null(o.mat.pbr);
	assert_true(scene_add_object(s, &o, NULL));
	world *w = world_build(s, NULL);
	assert_non_null(w);
	render_settings set = render_settings_default();
	set.width = set.height = 8;
	set.samples = spp;
	set.depth = depth;
	set.threads = 2;
	set.mode = MODE_PATH;
	set.denoise = 2;
	framebuffer *fb = render_image(w, &set, NULL, NULL, NULL, NULL);
	assert_non_null(fb);
	double sum = 0;
	for (int y = 3; y < 5; y++)
		for (int x = 3; x < 5; x++)
			sum += fb->rgb[(y * 8 + x) * 3];
	fb_free(fb);
	world_free(w);
	scene_free(s);
	return sum / 4;
}

static void test_furnace(void **state)
{
	(void)state;
	material_pbr metal = material_pbr_absent();
	metal.roughness = 0.8;
	metal.metallic = 1;
	/* compensated conductor of F0 = 1: exactly 1 */
	assert_near(furnace_centre(&metal, v3(255, 255, 255), 1, 4000), 1.0, 0.015);
	/* without: the albedo of the quadrature at cos_o = 1 */
	metal.multiscatter = 0;
	mat_lin m = pbr_mat((pbr_args){{1, 1, 1}, 0.8, 1, 0, 0, 0, false, false});
	bsdf b = bsdf_at(&m, 1.0, true);
	double q = albedo_quad(&b, 400).x;
	double v = furnace_centre(&metal, v3(255, 255, 255), 1, 4000);
	print_message("furnace F0=1 roughness 0.8, single scattering: %.4f, quadrature %.4f\n", v, q);
	assert_near(v, q, 0.015);
	/* A smooth white glass sphere, thin or not, gives back 1; a rough one
	 * loses what single-scattering GGX loses (not compensated for
	 * dielectrics: rtsh(5)), a few per cent, and never gains. */
	const double rough[] = {0, 0.4};
	for (int i = 0; i < 2; i++)
		for (int thin = 0; thin < 2; thin++) {
			material_pbr g = material_pbr_absent();
			g.roughness = rough[i];
			g.transmission = 1;
			g.thin = thin;
			double gv = furnace_centre(&g, v3(255, 255, 255), 64, 2000);
			print_message("furnace white glass roughness %.1f thin %d: %.4f\n", rough[i], thin, gv);
			if (rough[i] == 0)
				assert_near(gv, 1.0, 0.01);
			else
				assert_true(gv > 0.9 && gv < 1.01);
		}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_albedo_sample_vs_quadrature),
		cmocka_unit_test(test_compensated_conductor),
		cmocka_unit_test(test_reciprocity),
		cmocka_unit_test(test_energy_bound),
		cmocka_unit_test(test_chi2),
		cmocka_unit_test(test_furnace),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
