/* rtsh — the physically based family of materials (rtsh(5), "Materials"):
 * glTF 2.0's metallic-roughness BSDF (the specification's Appendix B) and
 * the KHR_materials_transmission, _ior, _volume, _clearcoat and _specular
 * extensions.
 *
 *   material = coat over mix(dielectric, metal, metallic)
 *   metal      GGX specular x Schlick's Fresnel with F0 = base colour
 *   dielectric mix(plastic, glass, transmission)
 *   plastic    GGX specular x F + Lambert(base colour) x what the specular
 *              lets through (see pbr_make); F Schlick's with f0 =
 *              min(F0(ior) x specular_color, 1) x specular_factor and f90 =
 *              specular_factor (KHR_materials_specular)
 *   glass      a rough dielectric interface (Walter, Marschner, Li &
 *              Torrance, "Microfacet models for refraction through rough
 *              surfaces", EGSR 2007) with the exact Fresnel reflectance;
 *              the refracted light tinted by the base colour. Thin-walled:
 *              the light goes through without bending (the reflection
 *              mirrored below the surface)
 *   coat       a colourless GGX layer, ior 1.5 (Schlick, F0 = 0.04), of
 *              weight clearcoat; what it lets through, (1 - cc Fc(cos)) at
 *              both ends, lights the rest
 *
 * Every GGX lobe (Trowbridge & Reitz 1975; Walter et al. 2007) has alpha =
 * roughness^2 and the height-correlated Smith masking-shadowing G2 = 1 /
 * (1 + Lambda(o) + Lambda(i)) (Heitz, "Understanding the masking-shadowing
 * function in microfacet-based BRDFs", JCGT 2014), and is sampled by its
 * visible normals (Heitz, "Sampling the GGX distribution of visible
 * normals", JCGT 2018). Lobes whose alpha is below DELTA_ALPHA are perfect
 * mirrors / interfaces. The single-scattering GGX loses energy at high
 * roughness; the metal and the plastic's specular are compensated by
 * Turquin's factor 1 + F0 (1 / E(cos_o) - 1), E the lobe's directional
 * albedo with F = 1 (Turquin, "Practical multiple scattering compensation
 * for microfacet models", 2019), unless multiscatter=0.
 *
 * The sampling picks a lobe in proportion to its estimated albedo, then a
 * direction from it; the weight of a non-delta direction is the whole
 * BSDF's f cos over the whole mixture's pdf (one-sample MIS), so sampling,
 * evaluation and pdf agree by construction. */
#include "integrators.h"
#include "warp.h"


/* Lobes with alpha below this are perfect (roughness < 0.0316). */
#define DELTA_ALPHA 1e-3
/* Whitted mode follows mirror and refracted rays below this roughness. */
#define WHITTED_MIRROR_ROUGHNESS 0.2

enum { L_COAT, L_METAL, L_SPEC, L_DIFF, L_GLASS, L_COUNT };

static double avg3(vec3 v)
{
	return (v.x + v.y + v.z) * (1.0 / 3.0);
}

static double pow5(double x)
{
	double x2 = x * x;
	return x2 * x2 * x;
}

/* Schlick's Fresnel for a colour F0 and f90. */
static vec3 schlick3(vec3 f0, double f90, double c)
{
	double k = pow5(1.0 - (c < 1.0 ? c : 1.0));
	return v3_add(f0, v3_scale(v3_sub(v3_splat(f90), f0), k));
}

static double schlick1(double f0, double c)
{
	return f0 + (1.0 - f0) * pow5(1.0 - (c < 1.0 ? c : 1.0));
}

/* --- GGX ----------------------------------------------------------------- */

/* The distribution of normals h (local, z up), a2 = alpha^2. */
static double ggx_d(double a2, double hz)
{
	double k = hz * hz * (a2 - 1.0) + 1.0;
	return a2 / (RT_PI * k * k);
}

/* Smith's Lambda for a direction of cosine z (either side). */
static double ggx_lambda(double a2, double z)
{
	double z2 = z * z;
	if (z2 >= 1.0)
		return 0.0;
	return 0.5 * (sqrt(1.0 + a2 * (1.0 - z2) / z2) - 1.0);
}

/* A visible normal for wo (local, wo.z > 0), Heitz 2018: the hemisphere
 * configuration stretched to alpha 1, a uniform disc point projected onto
 * the visible half of it, stretched back. */
static vec3 ggx_sample_vndf(double a, vec3 wo, double u1, double u2)
{
	vec3 vh = v3_norm(v3(a * wo.x, a * wo.y, wo.z));
	double l2 = vh.x * vh.x + vh.y * vh.y;
	vec3 t1 = l2 > 0.0 ? v3_scale(v3(-vh.y, vh.x, 0.0), 1.0 / sqrt(l2)) : v3(1, 0, 0);
	vec3 t2 = v3_cross(vh, t1);
	double p1, p2;
	warp_disc(u1, u2, &p1, &p2);
	double s = 0.5 * (1.0 + vh.z);
	p2 = (1.0 - s) * sqrt(pos(1.0 - p1 * p1)) + s * p2;
	vec3 nh = v3_add(v3_add(v3_scale(t1, p1), v3_scale(t2, p2)), v3_scale(vh, sqrt(pos(1.0 - p1 * p1 - p2 * p2))));
	return v3_norm(v3(a * nh.x, a * nh.y, pos(nh.z)));
}

/* --- the directional albedo E(cos, alpha) with F = 1 ----------------------- */

/* E(alpha, cos) = the integral of D G2 / (4 cos_o cos_i) cos_i over the
 * hemisphere, i.e. the mean of G2 / G1(o) over visible normals whose
 * reflection stays above the surface, at alpha = i / 31 (from 0.001) and
 * cos = j / 31 (from 0.02). Computed once with this file's own
 * ggx_sample_vndf, a jittered 400 x 400 grid of (u1, u2) per entry (error
 * about 1e-4); tests/unit/test_pbr.c checks it against its own quadrature.
 * A coarse grid is not enough: the reflections lost below the horizon come
 * from a thin ring at the rim of the sampling disc. */
#define E_N 32
static const float e_table[E_N][E_N] = {
	{0.99866f, 0.99946f, 0.99985f, 0.99995f, 0.99997f, 0.99999f, 0.99998f, 0.99999f,
	 0.99999f, 1.00000f, 0.99999f, 0.99999f, 1.00000f, 1.00000f, 1.00000f, 1.00000f,
	 1.00000f, 0.99999f, 0.99999f, 0.99999f, 1.00000f, 1.00000f, 1.00000f, 0.99999f,
	 1.00000f, 1.00000f, 1.00000f, 1.00000f, 0.99999f, 0.99999f, 1.00000f, 1.00000f},
	{0.90712f, 0.89120f, 0.91272f, 0.94373f, 0.96385f, 0.97547f, 0.98255f, 0.98712f,
	 0.99017f, 0.99219f, 0.99361f, 0.99462f, 0.99536f, 0.99610f, 0.99650f, 0.99698f,
	 0.99729f, 0.99748f, 0.99773f, 0.99785f, 0.99803f, 0.99806f, 0.99837f, 0.99852f,
	 0.99847f, 0.99856f, 0.99860f, 0.99868f, 0.99870f, 0.99890f, 0.99873f, 0.99891f},
	{0.94056f, 0.91598f, 0.88845f, 0.89378f, 0.90971f, 0.92682f, 0.94111f, 0.95255f,
	 0.96142f, 0.96821f, 0.97328f, 0.97742f, 0.98048f, 0.98287f, 0.98526f, 0.98683f,
	 0.98812f, 0.98929f, 0.99049f, 0.99104f, 0.99199f, 0.99219f, 0.99279f, 0.99328f,
	 0.99361f, 0.99397f, 0.99431f, 0.99472f, 0.99496f, 0.99512f, 0.99530f, 0.99535f},
	{0.95531f, 0.93391f, 0.89732f, 0.88398f, 0.88531f, 0.89385f, 0.90517f, 0.91664f,
	 0.92742f, 0.93678f, 0.94486f, 0.95163f, 0.95741f, 0.96219f, 0.96625f, 0.96969f,
	 0.97247f, 0.97493f, 0.97713f, 0.97893f, 0.98055f, 0.98180f, 0.98297f, 0.98404f,
	 0.98501f, 0.98568f, 0.98649f, 0.98708f, 0.98770f, 0.98821f, 0.98868f, 0.98910f},
	{0.96240f, 0.94383f, 0.90715f, 0.88636f, 0.87782f, 0.87756f, 0.88246f, 0.88998f,
	 0.89853f, 0.90733f, 0.91579f, 0.92364f, 0.93065f, 0.93705f, 0.94258f, 0.94742f,
	 0.95181f, 0.95562f, 0.95902f, 0.96188f, 0.96445f, 0.96681f, 0.96884f, 0.97063f,
	 0.97212f, 0.97369f, 0.97498f, 0.97609f, 0.97712f, 0.97804f, 0.97894f, 0.97973f},
	{0.96598f, 0.94908f, 0.91383f, 0.89029f, 0.87632f, 0.86997f, 0.86903f, 0.87176f,
	 0.87675f, 0.88317f, 0.89012f, 0.89719f, 0.90425f, 0.91079f, 0.91703f, 0.92276f,
	 0.92799f, 0.93282f, 0.93704f, 0.94111f, 0.94465f, 0.94774f, 0.95064f, 0.95323f,
	 0.95561f, 0.95777f, 0.95980f, 0.96148f, 0.96318f, 0.96440f, 0.96588f, 0.96709f},
	{0.96742f, 0.95162f, 0.91763f, 0.89296f, 0.87616f, 0.86576f, 0.86054f, 0.85905f,
	 0.86056f, 0.86392f, 0.86853f, 0.87402f, 0.87979f, 0.88578f, 0.89177f, 0.89749f,
	 0.90296f, 0.90820f, 0.91302f, 0.91752f, 0.92180f, 0.92570f, 0.92930f, 0.93259f,
	 0.93563f, 0.93849f, 0.94108f, 0.94347f, 0.94566f, 0.94765f, 0.94949f, 0.95123f},
	{0.96789f, 0.95251f, 0.91919f, 0.89409f, 0.87543f, 0.86249f, 0.85411f, 0.84940f,
	 0.84766f, 0.84819f, 0.85035f, 0.85371f, 0.85792f, 0.86268f, 0.86764f, 0.87279f,
	 0.87798f, 0.88301f, 0.88791f, 0.89269f, 0.89722f, 0.90147f, 0.90554f, 0.90927f,
	 0.91285f, 0.91621f, 0.91935f, 0.92225f, 0.92501f, 0.92751f, 0.92991f, 0.93213f},
	{0.96766f, 0.95226f, 0.91915f, 0.89360f, 0.87382f, 0.85898f, 0.84834f, 0.84110f,
	 0.83675f, 0.83477f, 0.83462f, 0.83582f, 0.83820f, 0.84130f, 0.84509f, 0.84917f,
	 0.85353f, 0.85809f, 0.86265f, 0.86712f, 0.87159f, 0.87595f, 0.88011f, 0.88412f,
	 0.88794f, 0.89163f, 0.89520f, 0.89851f, 0.90165f, 0.90453f, 0.90737f, 0.91001f},
	{0.96670f, 0.95132f, 0.91799f, 0.89185f, 0.87114f, 0.85493f, 0.84250f, 0.83327f,
	 0.82683f, 0.82261f, 0.82036f, 0.81962f, 0.82010f, 0.82158f, 0.82392f, 0.82679f,
	 0.83013f, 0.83377f, 0.83758f, 0.84158f, 0.84561f, 0.84966f, 0.85377f, 0.85770f,
	 0.86157f, 0.86537f, 0.86899f, 0.87251f, 0.87593f, 0.87916f, 0.88225f, 0.88527f},
	{0.96552f, 0.94974f, 0.91582f, 0.88909f, 0.86753f, 0.85014f, 0.83628f, 0.82548f,
	 0.81720f, 0.81121f, 0.80708f, 0.80452f, 0.80324f, 0.80313f, 0.80395f, 0.80544f,
	 0.80755f, 0.81016f, 0.81309f, 0.81634f, 0.81972f, 0.82327f, 0.82689f, 0.83053f,
	 0.83424f, 0.83785f, 0.84143f, 0.84491f, 0.84843f, 0.85178f, 0.85506f, 0.85822f},
	{0.96422f, 0.94788f, 0.91304f, 0.88554f, 0.86304f, 0.84467f, 0.82960f, 0.81734f,
	 0.80765f, 0.80001f, 0.79427f, 0.79007f, 0.78726f, 0.78561f, 0.78493f, 0.78505f,
	 0.78592f, 0.78733f, 0.78922f, 0.79152f, 0.79415f, 0.79692f, 0.79993f, 0.80309f,
	 0.80632f, 0.80962f, 0.81293f, 0.81627f, 0.81962f, 0.82287f, 0.82609f, 0.82929f},
	{0.96255f, 0.94570f, 0.90974f, 0.88126f, 0.85793f, 0.83852f, 0.82233f, 0.80893f,
	 0.79788f, 0.78887f, 0.78171f, 0.77603f, 0.77178f, 0.76867f, 0.76659f, 0.76541f,
	 0.76502f, 0.76527f, 0.76604f, 0.76727f, 0.76892f, 0.77089f, 0.77314f, 0.77564f,
	 0.77821f, 0.78103f, 0.78391f, 0.78690f, 0.78984f, 0.79292f, 0.79598f, 0.79902f},
	{0.96067f, 0.94325f, 0.90602f, 0.87653f, 0.85219f, 0.83181f, 0.81458f, 0.80009f,
	 0.78789f, 0.77763f, 0.76912f, 0.76220f, 0.75662f, 0.75220f, 0.74885f, 0.74635f,
	 0.74473f, 0.74375f, 0.74342f, 0.74361f, 0.74426f, 0.74533f, 0.74669f, 0.74838f,
	 0.75029f, 0.75242f, 0.75470f, 0.75711f, 0.75966f, 0.76230f, 0.76495f, 0.76769f},
	{0.95877f, 0.94067f, 0.90196f, 0.87135f, 0.84600f, 0.82463f, 0.80642f, 0.79088f,
	 0.77756f, 0.76623f, 0.75659f, 0.74844f, 0.74166f, 0.73603f, 0.73143f, 0.72778f,
	 0.72497f, 0.72284f, 0.72142f, 0.72053f, 0.72015f, 0.72021f, 0.72068f, 0.72152f,
	 0.72262f, 0.72395f, 0.72558f, 0.72735f, 0.72929f, 0.73135f, 0.73357f, 0.73587f},
	{0.95679f, 0.93782f, 0.89767f, 0.86585f, 0.83948f, 0.81710f, 0.79790f, 0.78135f,
	 0.76703f, 0.75465f, 0.74396f, 0.73470f, 0.72679f, 0.72005f, 0.71432f, 0.70956f,
	 0.70562f, 0.70243f, 0.69993f, 0.69799f, 0.69659f, 0.69571f, 0.69524f, 0.69511f,
	 0.69535f, 0.69591f, 0.69674f, 0.69778f, 0.69907f, 0.70051f, 0.70211f, 0.70381f},
	{0.95469f, 0.93504f, 0.89323f, 0.86015f, 0.83263f, 0.80926f, 0.78907f, 0.77157f,
	 0.75628f, 0.74292f, 0.73120f, 0.72096f, 0.71202f, 0.70424f, 0.69749f, 0.69166f,
	 0.68670f, 0.68249f, 0.67894f, 0.67602f, 0.67362f, 0.67178f, 0.67034f, 0.66936f,
	 0.66870f, 0.66842f, 0.66841f, 0.66868f, 0.66919f, 0.66993f, 0.67085f, 0.67195f},
	{0.95256f, 0.93215f, 0.88858f, 0.85415f, 0.82555f, 0.80112f, 0.77999f, 0.76156f,
	 0.74531f, 0.73101f, 0.71840f, 0.70722f, 0.69732f, 0.68857f, 0.68085f, 0.67406f,
	 0.66811f, 0.66292f, 0.65841f, 0.65453f, 0.65121f, 0.64841f, 0.64610f, 0.64421f,
	 0.64267f, 0.64153f, 0.64068f, 0.64014f, 0.63989f, 0.63985f, 0.64008f, 0.64048f},
	{0.95043f, 0.92904f, 0.88383f, 0.84807f, 0.81829f, 0.79284f, 0.77075f, 0.75135f,
	 0.73421f, 0.71905f, 0.70552f, 0.69345f, 0.68267f, 0.67302f, 0.66440f, 0.65672f,
	 0.64989f, 0.64376f, 0.63837f, 0.63359f, 0.62937f, 0.62569f, 0.62247f, 0.61969f,
	 0.61733f, 0.61534f, 0.61371f, 0.61235f, 0.61131f, 0.61052f, 0.60996f, 0.60962f},
	{0.94824f, 0.92609f, 0.87895f, 0.84182f, 0.81086f, 0.78435f, 0.76129f, 0.74102f,
	 0.72303f, 0.70699f, 0.69261f, 0.67971f, 0.66810f, 0.65762f, 0.64818f, 0.63966f,
	 0.63197f, 0.62502f, 0.61874f, 0.61313f, 0.60810f, 0.60356f, 0.59952f, 0.59592f,
	 0.59275f, 0.58996f, 0.58749f, 0.58535f, 0.58353f, 0.58198f, 0.58067f, 0.57965f},
	{0.94609f, 0.92287f, 0.87406f, 0.83547f, 0.80336f, 0.77580f, 0.75180f, 0.73060f,
	 0.71176f, 0.69491f, 0.67974f, 0.66603f, 0.65362f, 0.64237f, 0.63213f, 0.62282f,
	 0.61436f, 0.60663f, 0.59958f, 0.59319f, 0.58735f, 0.58205f, 0.57723f, 0.57286f,
	 0.56893f, 0.56534f, 0.56214f, 0.55925f, 0.55668f, 0.55440f, 0.55237f, 0.55061f},
	{0.94384f, 0.91979f, 0.86907f, 0.82909f, 0.79576f, 0.76717f, 0.74221f, 0.72013f,
	 0.70047f, 0.68280f, 0.66687f, 0.65240f, 0.63925f, 0.62727f, 0.61631f, 0.60626f,
	 0.59705f, 0.58863f, 0.58086f, 0.57372f, 0.56717f, 0.56116f, 0.55561f, 0.55053f,
	 0.54585f, 0.54158f, 0.53764f, 0.53407f, 0.53079f, 0.52782f, 0.52509f, 0.52262f},
	{0.94166f, 0.91661f, 0.86415f, 0.82267f, 0.78812f, 0.75849f, 0.73259f, 0.70967f,
	 0.68917f, 0.67073f, 0.65404f, 0.63886f, 0.62503f, 0.61234f, 0.60070f, 0.58998f,
	 0.58010f, 0.57099f, 0.56257f, 0.55478f, 0.54757f, 0.54089f, 0.53467f, 0.52893f,
	 0.52360f, 0.51866f, 0.51410f, 0.50985f, 0.50591f, 0.50227f, 0.49890f, 0.49581f},
	{0.93937f, 0.91343f, 0.85907f, 0.81620f, 0.78050f, 0.74982f, 0.72299f, 0.69917f,
	 0.67791f, 0.65874f, 0.64131f, 0.62546f, 0.61094f, 0.59763f, 0.58532f, 0.57400f,
	 0.56350f, 0.55376f, 0.54475f, 0.53634f, 0.52852f, 0.52122f, 0.51443f, 0.50806f,
	 0.50213f, 0.49659f, 0.49141f, 0.48658f, 0.48205f, 0.47781f, 0.47385f, 0.47015f},
	{0.93707f, 0.91020f, 0.85406f, 0.80975f, 0.77283f, 0.74110f, 0.71333f, 0.68873f,
	 0.66669f, 0.64680f, 0.62869f, 0.61219f, 0.59705f, 0.58311f, 0.57022f, 0.55831f,
	 0.54724f, 0.53696f, 0.52734f, 0.51838f, 0.51001f, 0.50216f, 0.49483f, 0.48794f,
	 0.48147f, 0.47538f, 0.46966f, 0.46427f, 0.45921f, 0.45443f, 0.44992f, 0.44569f},
	{0.93479f, 0.90715f, 0.84902f, 0.80328f, 0.76514f, 0.73244f, 0.70379f, 0.67835f,
	 0.65557f, 0.63493f, 0.61622f, 0.59907f, 0.58334f, 0.56883f, 0.55539f, 0.54292f,
	 0.53133f, 0.52054f, 0.51043f, 0.50096f, 0.49208f, 0.48378f, 0.47591f, 0.46854f,
	 0.46159f, 0.45502f, 0.44882f, 0.44294f, 0.43740f, 0.43214f, 0.42716f, 0.42245f},
	{0.93258f, 0.90390f, 0.84396f, 0.79687f, 0.75755f, 0.72381f, 0.69425f, 0.66800f,
	 0.64450f, 0.62323f, 0.60386f, 0.58614f, 0.56983f, 0.55478f, 0.54085f, 0.52788f,
	 0.51581f, 0.50453f, 0.49394f, 0.48403f, 0.47472f, 0.46593f, 0.45767f, 0.44986f,
	 0.44247f, 0.43547f, 0.42884f, 0.42255f, 0.41659f, 0.41093f, 0.40553f, 0.40039f},
	{0.93034f, 0.90072f, 0.83896f, 0.79043f, 0.74995f, 0.71521f, 0.68482f, 0.65779f,
	 0.63359f, 0.61165f, 0.59169f, 0.57342f, 0.55655f, 0.54100f, 0.52659f, 0.51316f,
	 0.50063f, 0.48892f, 0.47794f, 0.46762f, 0.45789f, 0.44873f, 0.44007f, 0.43187f,
	 0.42411f, 0.41674f, 0.40975f, 0.40311f, 0.39678f, 0.39075f, 0.38499f, 0.37951f},
	{0.92812f, 0.89764f, 0.83398f, 0.78404f, 0.74241f, 0.70670f, 0.67544f, 0.64770f,
	 0.62276f, 0.60021f, 0.57970f, 0.56086f, 0.54354f, 0.52751f, 0.51265f, 0.49882f,
	 0.48587f, 0.47375f, 0.46240f, 0.45171f, 0.44163f, 0.43211f, 0.42312f, 0.41459f,
	 0.40650f, 0.39882f, 0.39152f, 0.38456f, 0.37792f, 0.37160f, 0.36553f, 0.35976f},
	{0.92589f, 0.89445f, 0.82899f, 0.77766f, 0.73495f, 0.69824f, 0.66615f, 0.63765f,
	 0.61208f, 0.58896f, 0.56788f, 0.54854f, 0.53076f, 0.51429f, 0.49902f, 0.48476f,
	 0.47147f, 0.45902f, 0.44732f, 0.43629f, 0.42590f, 0.41609f, 0.40680f, 0.39799f,
	 0.38964f, 0.38167f, 0.37410f, 0.36687f, 0.35999f, 0.35341f, 0.34711f, 0.34108f},
	{0.92360f, 0.89133f, 0.82404f, 0.77134f, 0.72752f, 0.68991f, 0.65699f, 0.62776f,
	 0.60159f, 0.57786f, 0.55625f, 0.53645f, 0.51823f, 0.50136f, 0.48568f, 0.47108f,
	 0.45747f, 0.44469f, 0.43268f, 0.42139f, 0.41072f, 0.40063f, 0.39111f, 0.38204f,
	 0.37345f, 0.36528f, 0.35749f, 0.35007f, 0.34298f, 0.33619f, 0.32969f, 0.32347f},
	{0.92136f, 0.88814f, 0.81913f, 0.76504f, 0.72012f, 0.68162f, 0.64793f, 0.61802f,
	 0.59118f, 0.56694f, 0.54484f, 0.52460f, 0.50595f, 0.48871f, 0.47270f, 0.45777f,
	 0.44384f, 0.43079f, 0.41851f, 0.40698f, 0.39608f, 0.38576f, 0.37602f, 0.36676f,
	 0.35798f, 0.34961f, 0.34165f, 0.33406f, 0.32679f, 0.31986f, 0.31322f, 0.30685f}
};

double pbr_ggx_albedo(double alpha, double cos_o);
/* E(cos_o, alpha), bilinear in the table. */
double pbr_ggx_albedo(double alpha, double cos_o)
{
	double x = clampd(alpha, 0.0, 1.0) * (E_N - 1), y = clampd(cos_o, 0.0, 1.0) * (E_N - 1);
	int i = (int)x, j = (int)y;
	i = i < E_N - 2 ? i : E_N - 2;
	j = j < E_N - 2 ? j : E_N - 2;
	double fx = x - i, fy = y - j;
	double e0 = e_table[i][j] + (e_table[i][j + 1] - e_table[i][j]) * fy;
	double e1 = e_table[i + 1][j] + (e_table[i + 1][j + 1] - e_table[i + 1][j]) * fy;
	return e0 + (e1 - e0) * fx;
}

/* --- the bsdf -------------------------------------------------------------- */

static vec3 to_local(const bsdf *b, vec3 v)
{
	return v3(v3_dot(v, b->pb.t), v3_dot(v, b->pb.b), v3_dot(v, b->n));
}

static vec3 to_world(const bsdf *b, vec3 v)
{
	return v3_add(v3_add(v3_scale(b->pb.t, v.x), v3_scale(b->pb.b, v.y)), v3_scale(b->n, v.z));
}

/* The eta of the side below over the side of wo. */
static double eta_of(const bsdf *b)
{
	return b->front ? b->ior : 1.0 / b->ior;
}

static double coat_through(const bsdf *b, double c)
{
	return 1.0 - b->pb.cc * schlick1(0.04, c);
}

/* The share of light the plastic's specular layer reflects from a
 * direction of cosine mu: F(mu) E(mu) (plus what Turquin's factor gives
 * back, f0 (1 - E)); exactly F(mu) for a perfect one. */
static double spec_albedo(const struct bsdf_pbr *p, double mu)
{
	double f = max3(schlick3(p->f0, p->sf, mu));
	if (p->delta)
		return f;
	double e = pbr_ggx_albedo(p->a, mu);
	return f * e + (p->ms ? max3(p->f0) * (1.0 - e) : 0.0);
}

static void pbr_make(bsdf *b, const mat_lin *m, vec3 albedo)
{
	struct bsdf_pbr *p = &b->pb;
	basis(b->n, &p->t, &p->b);
	p->base = albedo;
	double r = clampd(m->pbr.roughness, 0.0, 1.0), rc = clampd(m->pbr.clearcoat_roughness, 0.0, 1.0);
	p->a = r * r;
	p->ac = rc * rc;
	p->delta = p->a < DELTA_ALPHA;
	p->cdelta = p->ac < DELTA_ALPHA;
	double metallic = clampd(m->pbr.metallic, 0.0, 1.0), tr = clampd(m->pbr.transmission, 0.0, 1.0);
	p->wm = metallic;
	p->wp = (1.0 - metallic) * (1.0 - tr);
	p->wt = (1.0 - metallic) * tr;
	p->cc = clampd(m->pbr.clearcoat, 0.0, 1.0);
	b->ior = m->ior >= 1.0 ? m->ior : 1.5;
	p->thin = m->thin;
	p->ms = !m->pbr.single;
	double f0 = (b->ior - 1.0) / (b->ior + 1.0);
	f0 *= f0;
	p->sf = clampd(m->pbr.specular_factor, 0.0, 1.0);
	vec3 sc = v3(m->pbr.specular_color[0], m->pbr.specular_color[1], m->pbr.specular_color[2]);
	vec3 f0c = v3_scale(sc, f0);
	p->f0 = v3_scale(v3(f0c.x < 1 ? f0c.x : 1, f0c.y < 1 ? f0c.y : 1, f0c.z < 1 ? f0c.z : 1), p->sf);
	p->kms_m = v3_splat(1.0);
	p->kms_p = v3_splat(1.0);
	if (p->ms && !p->delta) {
		double e = pbr_ggx_albedo(p->a, b->cos_o), k = e > 0.0 ? 1.0 / e - 1.0 : 0.0;
		p->kms_m = v3_add(v3_splat(1.0), v3_scale(albedo, k));
		p->kms_p = v3_add(v3_splat(1.0), v3_scale(p->f0, k));
	}
	/* The plastic's Lambert base gets what the specular layer lets
	 * through, (1 - Es(o)) (1 - Es(i)) / (1 - Es_avg): reciprocal, and
	 * energy is conserved exactly (Kulla & Conty, "Revisiting physically
	 * based shading at Imageworks", 2017, the albedo scaling of layers;
	 * glTF's (1 - F(v.h)) gains up to 6% at grazing angles). Es_avg = 2
	 * int Es(mu) mu dmu by the midpoint rule. */
	p->kdiff = 0.0;
	if (p->wp > 0.0) {
		double avg = 0.0;
		for (int i = 0; i < 16; i++) {
			double mu = (i + 0.5) / 16.0;
			avg += spec_albedo(p, mu) * mu;
		}
		avg *= 2.0 / 16.0;
		p->kdiff = avg < 1.0 ? (1.0 - spec_albedo(p, b->cos_o)) / (1.0 - avg) : 0.0;
	}
	/* lobe choice in proportion to what each sends back from cos_o */
	double co = b->cos_o;
	double pc = p->cc * schlick1(0.04, co), rest = 1.0 - pc;
	vec3 fd = schlick3(p->f0, p->sf, co);
	double w[L_COUNT];
	w[L_COAT] = pc;
	w[L_METAL] = rest * p->wm * avg3(schlick3(albedo, 1.0, co));
	w[L_SPEC] = rest * p->wp * avg3(fd);
	w[L_DIFF] = rest * p->wp * (1.0 - spec_albedo(p, co)) * avg3(albedo);
	w[L_GLASS] = rest * p->wt * (avg3(albedo) > 0.1 ? avg3(albedo) : 0.1);
	double total = 0.0;
	for (int i = 0; i < L_COUNT; i++)
		total += w[i];
	b->total = total;
	for (int i = 0; i < L_COUNT; i++)
		p->pl[i] = total > 0.0 ? w[i] / total : 0.0;
	bool nd_base = !p->delta && (w[L_METAL] > 0.0 || w[L_SPEC] > 0.0 || w[L_GLASS] > 0.0);
	b->smooth = w[L_DIFF] > 0.0 || (w[L_COAT] > 0.0 && !p->cdelta) || nd_base;
	b->through = !p->delta && p->wt > 0.0;
	if (!p->thin)
		b->sigma_in = v3(m->pbr.sigma_a[0], m->pbr.sigma_a[1], m->pbr.sigma_a[2]);
}

/* The whole non-delta BSDF value at local wo, wi. */
static vec3 pbr_f(const bsdf *b, vec3 wo, vec3 wi)
{
	const struct bsdf_pbr *p = &b->pb;
	double co = wo.z, ci = wi.z;
	vec3 f = v3(0, 0, 0);
	if (co <= 0.0 || ci == 0.0)
		return f;
	double att = (1.0 - p->cc * schlick1(0.04, co)) * (1.0 - p->cc * schlick1(0.04, fabs(ci)));
	double a2 = p->a * p->a;
	if (ci > 0.0) {
		vec3 h = v3_norm(v3_add(wo, wi));
		double oh = v3_dot(wo, h);
		if (p->wp > 0.0) {
			vec3 fd = schlick3(p->f0, p->sf, oh);
			f = v3_madd(f, p->base, p->wp * p->kdiff * (1.0 - spec_albedo(p, ci)) * (1.0 / RT_PI));
			if (!p->delta) {
				double spec = ggx_d(a2, h.z) / (4.0 * co * ci * (1.0 + ggx_lambda(a2, co) + ggx_lambda(a2, ci)));
				f = v3_add(f, v3_scale(v3_mul(fd, p->kms_p), p->wp * spec));
			}
		}
		if (!p->delta && (p->wm > 0.0 || p->wt > 0.0)) {
			double spec = ggx_d(a2, h.z) / (4.0 * co * ci * (1.0 + ggx_lambda(a2, co) + ggx_lambda(a2, ci)));
			if (p->wm > 0.0)
				f = v3_add(f, v3_scale(v3_mul(schlick3(p->base, 1.0, oh), p->kms_m), p->wm * spec));
			if (p->wt > 0.0) {
				double ct;
				f = v3_add(f, v3_splat(p->wt * spec * fresnel_dielectric(oh, p->thin ? b->ior : eta_of(b), &ct)));
			}
		}
		f = v3_scale(f, att);
		if (p->cc > 0.0 && !p->cdelta) {
			double ac2 = p->ac * p->ac;
			double spec = ggx_d(ac2, h.z) / (4.0 * co * ci * (1.0 + ggx_lambda(ac2, co) + ggx_lambda(ac2, ci)));
			f = v3_add(f, v3_splat(p->cc * schlick1(0.04, oh) * spec));
		}
		return f;
	}
	if (p->delta || p->wt <= 0.0)
		return f;
	double aci = -ci, ct;
	if (p->thin) {
		/* the reflection mirrored below: wr = (wi.x, wi.y, -wi.z) */
		vec3 h = v3_norm(v3_add(wo, v3(wi.x, wi.y, aci)));
		double oh = v3_dot(wo, h);
		double spec = ggx_d(a2, h.z) / (4.0 * co * aci * (1.0 + ggx_lambda(a2, co) + ggx_lambda(a2, aci)));
		double tf = 1.0 - fresnel_dielectric(oh, b->ior, &ct);
		return v3_scale(p->base, att * p->wt * tf * spec);
	}
	/* Walter et al. 2007, eq. 21, in pbrt 4th ed.'s form (9.7.5) */
	double eta = eta_of(b);
	vec3 h = v3_add(v3_scale(wi, eta), wo);
	double hl = v3_len(h);
	if (!(hl > 0.0))
		return f;
	h = v3_scale(h, 1.0 / hl);
	if (h.z < 0.0)
		h = v3_neg(h);
	double ih = v3_dot(wi, h), oh = v3_dot(wo, h);
	if (ih >= 0.0 || oh <= 0.0)
		return f; /* a microfacet seen from behind */
	double F = fresnel_dielectric(oh, eta, &ct);
	double den = ih + oh / eta;
	double t = ggx_d(a2, h.z) / (1.0 + ggx_lambda(a2, co) + ggx_lambda(a2, aci)) * fabs(ih * oh) /
	           (den * den * aci * co);
	/* radiance: compressed by 1 / eta^2 going through */
	return v3_scale(p->base, att * p->wt * (1.0 - F) * t / (eta * eta));
}

/* The mixture density of the non-delta lobes at local wi. */
static double pbr_pdf_local(const bsdf *b, vec3 wo, vec3 wi)
{
	const struct bsdf_pbr *p = &b->pb;
	double co = wo.z, ci = wi.z, pdf = 0.0;
	if (co <= 0.0 || ci == 0.0)
		return 0.0;
	double a2 = p->a * p->a;
	if (ci > 0.0) {
		vec3 h = v3_norm(v3_add(wo, wi));
		pdf += p->pl[L_DIFF] * ci / RT_PI;
		double base_p = p->pl[L_METAL] + p->pl[L_SPEC];
		if (!p->delta && (base_p > 0.0 || p->pl[L_GLASS] > 0.0)) {
			/* the visible normals' density / (4 o.h) = G1(o) D / (4 cos_o) */
			double r = ggx_d(a2, h.z) / (4.0 * co * (1.0 + ggx_lambda(a2, co)));
			double ct, oh = v3_dot(wo, h);
			double fr = p->pl[L_GLASS] > 0.0 ? fresnel_dielectric(oh, p->thin ? b->ior : eta_of(b), &ct) : 0.0;
			pdf += (base_p + p->pl[L_GLASS] * fr) * r;
		}
		if (p->pl[L_COAT] > 0.0 && !p->cdelta) {
			double ac2 = p->ac * p->ac;
			pdf += p->pl[L_COAT] * ggx_d(ac2, h.z) / (4.0 * co * (1.0 + ggx_lambda(ac2, co)));
		}
		return pdf;
	}
	if (p->delta || p->pl[L_GLASS] <= 0.0)
		return 0.0;
	double aci = -ci, ct;
	if (p->thin) {
		vec3 h = v3_norm(v3_add(wo, v3(wi.x, wi.y, aci)));
		double oh = v3_dot(wo, h);
		double r = ggx_d(a2, h.z) / (4.0 * co * (1.0 + ggx_lambda(a2, co)));
		return p->pl[L_GLASS] * (1.0 - fresnel_dielectric(oh, b->ior, &ct)) * r;
	}
	double eta = eta_of(b);
	vec3 h = v3_add(v3_scale(wi, eta), wo);
	double hl = v3_len(h);
	if (!(hl > 0.0))
		return 0.0;
	h = v3_scale(h, 1.0 / hl);
	if (h.z < 0.0)
		h = v3_neg(h);
	double ih = v3_dot(wi, h), oh = v3_dot(wo, h);
	if (ih >= 0.0 || oh <= 0.0)
		return 0.0;
	double F = fresnel_dielectric(oh, eta, &ct);
	double den = ih + oh / eta;
	/* visible normals' density x |dh / dwi| = |i.h| / (i.h + o.h / eta)^2 */
	double dv = ggx_d(a2, h.z) * oh / (co * (1.0 + ggx_lambda(a2, co)));
	return p->pl[L_GLASS] * (1.0 - F) * dv * fabs(ih) / (den * den);
}

static vec3 pbr_eval(const bsdf *b, vec3 wi)
{
	return pbr_f(b, to_local(b, b->wo), to_local(b, wi));
}

static double pbr_pdf(const bsdf *b, vec3 wi)
{
	return pbr_pdf_local(b, to_local(b, b->wo), to_local(b, wi));
}

static bool pbr_has_choice(const bsdf *b)
{
	(void)b;
	return true;
}

/* A perfect lobe's sample: its value over its choice probability. */
static bool delta_out(bsdf_sample *out, vec3 wi, vec3 weight)
{
	out->wi = wi;
	out->weight = weight;
	out->delta = true;
	return true;
}

static bool pbr_sample(const bsdf *b, const double u[3], bsdf_sample *out)
{
	const struct bsdf_pbr *p = &b->pb;
	if (!(b->total > 0.0) || b->cos_o <= 0.0)
		return false;
	int lobe = 0;
	double below = 0.0, acc = p->pl[0];
	while (lobe < L_COUNT - 1 && (u[0] >= acc || p->pl[lobe] == 0.0)) {
		below = acc;
		acc += p->pl[++lobe];
	}
	while (lobe > 0 && p->pl[lobe] == 0.0)
		below -= p->pl[--lobe];
	double pk = p->pl[lobe], ur = clampd((u[0] - below) / pk, 0.0, 0.999999999);
	out->radiance_scale = 1.0;
	out->transmit = false;
	out->delta = false;
	vec3 wo = to_local(b, b->wo);
	double co = wo.z;
	vec3 mirror = v3_sub(v3_scale(b->n, 2.0 * co), b->wo);
	double att_r = coat_through(b, co) * coat_through(b, co);
	vec3 wi;
	switch (lobe) {
	case L_COAT:
		if (p->cdelta)
			return delta_out(out, mirror, v3_splat(p->cc * schlick1(0.04, co) / pk));
		{
			vec3 h = ggx_sample_vndf(p->ac, wo, u[1], u[2]);
			wi = v3_sub(v3_scale(h, 2.0 * v3_dot(wo, h)), wo);
		}
		break;
	case L_METAL:
	case L_SPEC:
		if (p->delta) {
			vec3 F = lobe == L_METAL ? v3_scale(schlick3(p->base, 1.0, co), p->wm)
			                         : v3_scale(schlick3(p->f0, p->sf, co), p->wp);
			return delta_out(out, mirror, v3_scale(F, att_r / pk));
		}
		{
			vec3 h = ggx_sample_vndf(p->a, wo, u[1], u[2]);
			wi = v3_sub(v3_scale(h, 2.0 * v3_dot(wo, h)), wo);
		}
		break;
	case L_DIFF:
		wi = warp_cosine(v3(0, 0, 1), u[1], u[2]);
		break;
	default: { /* glass: reflect with probability F, else go through */
		double eta = p->thin ? b->ior : eta_of(b), ct;
		if (p->delta) {
			double F = fresnel_dielectric(co, eta, &ct);
			if (ur < F)
				return delta_out(out, mirror, v3_splat(p->wt * att_r / pk));
			if (p->thin) {
				out->transmit = true;
				return delta_out(out, v3_neg(b->wo), v3_scale(p->base, p->wt * att_r / pk));
			}
			vec3 t = v3_add(v3_scale(b->wo, -1.0 / eta), v3_scale(b->n, co / eta - ct));
			out->transmit = true;
			out->radiance_scale = 1.0 / (eta * eta);
			double att = coat_through(b, co) * coat_through(b, ct);
			return delta_out(out, v3_norm(t), v3_scale(p->base, p->wt * att / pk));
		}
		vec3 h = ggx_sample_vndf(p->a, wo, u[1], u[2]);
		double oh = v3_dot(wo, h);
		double F = fresnel_dielectric(oh, eta, &ct);
		vec3 wr = v3_sub(v3_scale(h, 2.0 * oh), wo);
		if (ur < F) {
			wi = wr;
		} else if (p->thin) {
			wi = v3(wr.x, wr.y, -wr.z);
			out->transmit = true;
		} else {
			wi = v3_add(v3_scale(wo, -1.0 / eta), v3_scale(h, oh / eta - ct));
			out->transmit = true;
			out->radiance_scale = 1.0 / (eta * eta);
		}
		break;
	}
	}
	if (out->transmit ? wi.z >= 0.0 : wi.z <= 0.0)
		return false; /* below the surface: the lobe's lost energy */
	double pdf = pbr_pdf_local(b, wo, wi);
	if (!(pdf > 0.0))
		return false;
	vec3 f = pbr_f(b, wo, wi);
	out->wi = to_world(b, v3_norm(wi));
	/* radiance_scale is applied by the caller: take it out of f */
	out->weight = v3_scale(f, fabs(wi.z) / (pdf * out->radiance_scale));
	return true;
}

/* The denoiser's view: a perfect mirror metal or perfect glass is looked
 * through; anything else shows its base colour. */
static int pbr_features(const bsdf *b, vec3 *albedo, vec3 *tint, vec3 *dir)
{
	const struct bsdf_pbr *p = &b->pb;
	*albedo = p->base;
	if (!p->delta)
		return 0;
	if (p->wm >= 0.5) {
		*tint = schlick3(p->base, 1.0, b->cos_o);
		return 1;
	}
	if (p->wt >= 0.5) {
		*tint = p->base;
		if (p->thin) {
			*dir = v3_neg(b->wo);
			return 2;
		}
		double eta = eta_of(b), ct;
		if (fresnel_dielectric(b->cos_o, eta, &ct) >= 1.0)
			return 1;
		*dir = v3_add(v3_scale(b->wo, -1.0 / eta), v3_scale(b->n, b->cos_o / eta - ct));
		return 2;
	}
	return 0;
}

/* Whitted: ambient x base colour, the point lights through the same BRDF
 * as in path mode, and below WHITTED_MIRROR_ROUGHNESS the mirror (and
 * refracted) rays weighted by the lobes' Fresnel at cos_o. */
static vec3 pbr_whitted(const world *w, const mat_lin *m, const hit *h, ray r, int depth,
                        vec3 (*trace)(const world *w, ray r, int depth))
{
	bsdf b; /* bsdf_make's work for this family, without calling back up */
	bsdf_begin(&b, m, h, v3_neg(r.d));
	pbr_make(&b, m, hit_albedo(m, h));
	const struct bsdf_pbr *p = &b.pb;
	vec3 pt = offset_point(w, h->p, b.n);
	vec3 c = v3_add(v3_mul(w->ambient, p->base), m->emission);
	c = v3_add(c, whitted_lights(w, &b, pt, pbr_eval));
	if (depth <= 0)
		return c;
	double co = b.cos_o, ct;
	vec3 mirror = v3_sub(v3_scale(b.n, 2.0 * co), b.wo);
	vec3 kr = v3(0, 0, 0), kt = v3(0, 0, 0);
	vec3 tdir = v3(0, 0, 0);
	double att = coat_through(&b, co);
	if (clampd(m->pbr.roughness, 0, 1) < WHITTED_MIRROR_ROUGHNESS) {
		kr = v3_add(v3_scale(schlick3(p->base, 1.0, co), p->wm), v3_scale(schlick3(p->f0, p->sf, co), p->wp));
		if (p->wt > 0.0) {
			double eta = p->thin ? b.ior : eta_of(&b);
			double F = fresnel_dielectric(co, eta, &ct);
			kr = v3_add(kr, v3_splat(p->wt * F));
			kt = v3_scale(p->base, p->wt * (1.0 - F));
			tdir = p->thin ? v3_neg(b.wo)
			               : v3_norm(v3_add(v3_scale(b.wo, -1.0 / eta), v3_scale(b.n, co / eta - ct)));
		}
		kr = v3_scale(kr, att * att);
		kt = v3_scale(kt, att * att);
	}
	if (clampd(m->pbr.clearcoat_roughness, 0, 1) < WHITTED_MIRROR_ROUGHNESS)
		kr = v3_add(kr, v3_splat(p->cc * schlick1(0.04, co)));
	if (max3(kr) > 0.0)
		c = v3_add(c, v3_mul(kr, trace(w, (ray){pt, mirror}, depth - 1)));
	if (max3(kt) > 0.0)
		c = v3_add(c, v3_mul(kt, trace(w, (ray){offset_point(w, h->p, v3_neg(b.n)), tdir}, depth - 1)));
	return c;
}

const mat_family mat_pbr_family = {
	.name = "pbr",
	.make = pbr_make,
	.eval = pbr_eval,
	.pdf = pbr_pdf,
	.sample = pbr_sample,
	.has_choice = pbr_has_choice,
	.features = pbr_features,
	.whitted = pbr_whitted,
};
