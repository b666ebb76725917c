/* rtsh — the one table of the objects' key=value fields (rtfile_priv.h),
 * which the reader, the writer, the editor's rules, `help` and completion
 * read. A new material key is a line of rt_keys (and its field in
 * scene.h's material, and a paragraph in rtsh(5)). */
#include <math.h>
#include <pthread.h>
#include <stddef.h>
#include <string.h>

#include "rtsh/rtfile.h"
#include "scene/rtfile_priv.h"

static bool ior_rule(double v) { return v == 0.0 || v >= 1.0; }
static bool positive(double v) { return v > 0.0; }

#define PBR(f) (RT_KEY_PBR | offsetof(material_pbr, f))

/* name, field, int, on triangles, kinds, in the short form, min, max, default, rule,
 * expected, help */
const rt_key rt_keys[] = {
	{"twist", offsetof(object, twist), false, false, 0, false, -RT_NUM_MAX, RT_NUM_MAX, 0, NULL,
	 "twist in degrees", "turn about the object's own axis, degrees", RT_KEY_NUM, false},
	{"fuzz", offsetof(object, mat.fuzz), false, true, 0, false, 0, 1, 0, NULL, "fuzz in [0,1]",
	 "roughness of the mirror lobe (0 sharp, 1 broad)", RT_KEY_NUM, false},
	{"metal", offsetof(object, mat.metal), false, true, 0, false, 0, 1, 0, NULL, "metal in [0,1]",
	 "how much reflections take the object's colour", RT_KEY_NUM, false},
	{"ior", offsetof(object, mat.ior), false, true, 0, false, 0, 10, 0, ior_rule,
	 "ior 0 (opaque) or a refractive index in [1,10]", "glass: refractive index (0 opaque)", RT_KEY_NUM,
	 false},
	{"emit", offsetof(object, mat.emission), false, true, 0, false, 0, 1e6, 0, NULL,
	 "emit in [0,1e6]", "emitted radiance, times the colour (path mode)", RT_KEY_NUM, false},
	{"checker", offsetof(object, mat.checker), true, true, 0, false, 0, 1000, 0, NULL,
	 "checker a whole number in [0,1000]", "checker texture: squares per unit (0 none)", RT_KEY_NUM,
	 false},
	{"tube", offsetof(object, tube), false, false, KIND_TUBE, true, 0, 100, 0.5, positive,
	 "tube a ratio in (0,100]", "torus: tube diameter / ring diameter", RT_KEY_NUM, false},
	{"texture", offsetof(object, mat.texture), false, true, 0, false, 0, 0, 0, NULL,
	 "texture=FILE, a PNG, JPEG, BMP, TGA, HDR, PPM, PFM or XPM image", "colour texture image file",
	 RT_KEY_FILE, false},
	{"normalmap", offsetof(object, mat.normalmap), false, true, 0, false, 0, 0, 0, NULL,
	 "normalmap=FILE, a tangent-space normal map image", "tangent-space normal map image file",
	 RT_KEY_FILE, false},
	{"bump", offsetof(object, mat.bump), false, true, 0, false, 0, 0, 0, NULL,
	 "bump=FILE, a height map image", "height map image file", RT_KEY_FILE, false},
	{"bumpscale", offsetof(object, mat.bumpscale), false, true, 0, false, -1e6, 1e6, 1, NULL,
	 "bumpscale in [-1e6,1e6]", "height of the bump map", RT_KEY_NUM, false},
	{"uvscale", offsetof(object, mat.uvscale), false, true, 0, false, -1e6, 1e6, 1, NULL,
	 "uvscale=U,V, two numbers in [-1e6,1e6], not 0", "texture repeats along U,V", RT_KEY_PAIR, false},
	{"uvoffset", offsetof(object, mat.uvoffset), false, true, 0, false, -1e6, 1e6, 0, NULL,
	 "uvoffset=U,V, two numbers in [-1e6,1e6]", "texture shift along U,V", RT_KEY_PAIR, false},
	/* the physically based family (scene.h, rtsh(5) "Materials") */
	{"roughness", PBR(roughness), false, true, 0, false, 0, 1, -1, NULL,
	 "roughness in [0,1]", "PBR: microfacet roughness, GGX alpha = roughness^2", RT_KEY_NUM, false},
	{"metallic", PBR(metallic), false, true, 0, false, 0, 1, 0, NULL, "metallic in [0,1]",
	 "PBR: conductor (1) with F0 = colour, or dielectric (0)", RT_KEY_NUM, false},
	{"transmission", PBR(transmission), false, true, 0, false, 0, 1, 0, NULL,
	 "transmission in [0,1]", "PBR: share of the dielectric that refracts (glass)", RT_KEY_NUM, false},
	{"thin", PBR(thin), true, true, 0, false, 0, 1, 0, NULL, "thin 0 (a volume) or 1",
	 "PBR: thin-walled transmission (1), no bending", RT_KEY_NUM, false},
	{"att_color", PBR(att_color), false, true, 0, false, 0, 255, 255, NULL,
	 "att_color=R,G,B, each in [0,255]", "PBR: colour after att_dist inside the volume", RT_KEY_RGB, false},
	{"att_dist", PBR(att_dist), false, true, 0, false, 0, 1e6, 0, NULL,
	 "att_dist in [0,1e6] (0 infinite)", "PBR: distance for att_color (0 infinite)", RT_KEY_NUM, false},
	{"clearcoat", PBR(clearcoat), false, true, 0, false, 0, 1, 0, NULL,
	 "clearcoat in [0,1]", "PBR: weight of a clear varnish coat", RT_KEY_NUM, false},
	{"clearcoat_roughness", PBR(clearcoat_roughness), false, true, 0, false, 0, 1, 0, NULL,
	 "clearcoat_roughness in [0,1]", "PBR: roughness of the coat", RT_KEY_NUM, false},
	{"specular_factor", PBR(specular_factor), false, true, 0, false, 0, 1, 1, NULL,
	 "specular_factor in [0,1]", "PBR: strength of the dielectric's reflection", RT_KEY_NUM, false},
	{"specular_color", PBR(specular_color), false, true, 0, false, 0, 255, 255, NULL,
	 "specular_color=R,G,B, each in [0,255]", "PBR: tint of the dielectric's reflection", RT_KEY_RGB,
	 false},
	{"emit_color", PBR(emit_color), false, true, 0, false, 0, 255, -1, NULL,
	 "emit_color=R,G,B, each in [0,255]", "emission colour (else the colour), times emit", RT_KEY_RGB,
	 false},
	{"multiscatter", PBR(multiscatter), true, true, 0, false, 0, 1, 1, NULL, "multiscatter 0 or 1",
	 "PBR: give back the energy single-scattering GGX loses (1) or not (0)", RT_KEY_NUM, false},
	{"smooth", offsetof(object, smooth), true, false, 0, false, 0, 1, 1, NULL,
	 "smooth 0 (flat faces) or 1 (smooth normals)", "mesh: smooth normals (1) or flat faces (0)",
	 RT_KEY_NUM, true},
	{"crease", offsetof(object, crease), false, false, 0, false, 0, 180, 60, NULL,
	 "crease in degrees, [0,180]", "mesh: edges sharper than this stay sharp, degrees", RT_KEY_NUM, true},
	{"node", offsetof(object, node), true, false, 0, false, 0, 16777215, -1, NULL,
	 "node an index into the glTF file's nodes", "mesh: one node of a glTF file alone (its index)", RT_KEY_NUM,
	 true},
};
const size_t rt_nkeys = sizeof rt_keys / sizeof rt_keys[0];

const char *rt_key_info(size_t i, const char **help)
{
	if (i >= rt_nkeys)
		return NULL;
	*help = rt_keys[i].help;
	return rt_keys[i].name;
}

bool rt_key_applies(const rt_key *k, obj_kind kind)
{
	unsigned f = obj_kind_flags(kind);
	if (k->mesh_only && !(f & KIND_MODEL))
		return false;
	if ((f & KIND_VERTICES) && !k->triangles)
		return false;
	return !k->needs || (f & k->needs);
}

/* The absent PBR block, made once: rt_key_get reads it for every PBR key of
 * every object without one (the rules of a million loaded spheres). */
static material_pbr absent_pbr;
static pthread_once_t absent_once = PTHREAD_ONCE_INIT;

static void absent_init(void)
{
	absent_pbr = material_pbr_absent();
}

/* Where key k's value is in o: in the object, or in o's PBR block (the
 * absent one when o has none). */
static const char *key_src(const rt_key *k, const object *o)
{
	if (!(k->offset & RT_KEY_PBR))
		return (const char *)o + k->offset;
	const material_pbr *pb = o->mat.pbr;
	if (!pb) {
		pthread_once(&absent_once, absent_init);
		pb = &absent_pbr;
	}
	return (const char *)pb + (k->offset & ~RT_KEY_PBR);
}

double rt_key_get(const rt_key *k, const object *o)
{
	const char *base = key_src(k, o);
	if (k->is_int)
		return *(const int *)(const void *)base;
	return *(const double *)(const void *)base;
}

void rt_key_get_n(const rt_key *k, const object *o, double *v, int n)
{
	memcpy(v, key_src(k, o), (size_t)n * sizeof *v);
}

/* Writes n doubles (or one int) into o's field of key k. */
static bool key_store(const rt_key *k, object *o, const double *v, int n)
{
	if (!(k->offset & RT_KEY_PBR)) {
		char *base = (char *)o + k->offset;
		if (k->is_int)
			*(int *)(void *)base = (int)v[0];
		else
			memcpy(base, v, (size_t)n * sizeof *v);
		return true;
	}
	material_pbr p = o->mat.pbr ? *o->mat.pbr : material_pbr_absent();
	char *base = (char *)&p + (k->offset & ~RT_KEY_PBR);
	if (k->is_int)
		*(int *)(void *)base = (int)v[0];
	else
		memcpy(base, v, (size_t)n * sizeof *v);
	bool oom = false;
	const material_pbr *q = material_pbr_intern(&p, &oom);
	if (oom)
		return false;
	o->mat.pbr = q;
	return true;
}

bool rt_key_set(const rt_key *k, object *o, double v)
{
	return key_store(k, o, &v, 1);
}

bool rt_key_set_n(const rt_key *k, object *o, const double *v, int n)
{
	return key_store(k, o, v, n);
}
