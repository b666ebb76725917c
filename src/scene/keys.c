/* rtsh — the one table of the objects' key=value fields (rtfile_priv.h),
 * which the reader, the writer, the editor's rules, `help` and completion
 * read. A new material key is a line of rt_keys (and its field in
 * scene.h's material, and a paragraph in rtsh(5)). */
#include <math.h>
#include <stddef.h>

#include "rtsh/rtfile.h"
#include "scene/rtfile_priv.h"

static bool ior_rule(double v) { return v == 0.0 || v >= 1.0; }
static bool positive(double v) { return v > 0.0; }

/* name, field, int, on triangles, kinds, in the short form, min, max, default, rule,
 * expected, help */
const rt_key rt_keys[] = {
	{"twist", offsetof(object, twist), false, false, 0, false, -RT_NUM_MAX, RT_NUM_MAX, 0, NULL,
	 "twist in degrees", "turn about the object's own axis, degrees"},
	{"fuzz", offsetof(object, mat.fuzz), false, true, 0, false, 0, 1, 0, NULL, "fuzz in [0,1]",
	 "roughness of the mirror lobe (0 sharp, 1 broad)"},
	{"metal", offsetof(object, mat.metal), false, true, 0, false, 0, 1, 0, NULL, "metal in [0,1]",
	 "how much reflections take the object's colour"},
	{"ior", offsetof(object, mat.ior), false, true, 0, false, 0, 10, 0, ior_rule,
	 "ior 0 (opaque) or a refractive index in [1,10]", "glass: refractive index (0 opaque)"},
	{"emit", offsetof(object, mat.emission), false, true, 0, false, 0, 1e6, 0, NULL,
	 "emit in [0,1e6]", "emitted radiance, times the colour (path mode)"},
	{"checker", offsetof(object, mat.checker), true, true, 0, false, 0, 1000, 0, NULL,
	 "checker a whole number in [0,1000]", "checker texture: squares per unit (0 none)"},
	{"tube", offsetof(object, tube), false, false, KIND_TUBE, true, 0, 100, 0.5, positive,
	 "tube a ratio in (0,100]", "torus: tube diameter / ring diameter"},
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
	if ((f & KIND_VERTICES) && !k->triangles)
		return false;
	return !k->needs || (f & k->needs);
}

double rt_key_get(const rt_key *k, const object *o)
{
	const char *base = (const char *)o + k->offset;
	if (k->is_int)
		return *(const int *)(const void *)base;
	return *(const double *)(const void *)base;
}

void rt_key_set(const rt_key *k, object *o, double v)
{
	char *base = (char *)o + k->offset;
	if (k->is_int)
		*(int *)(void *)base = (int)v;
	else
		*(double *)(void *)base = v;
}
