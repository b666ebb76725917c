/* rtsh — the scene model: what a .rt file says, as the user wrote it.
 *
 * The model keeps user-facing values (sRGB colours 0..255, directions as
 * written, degrees, diameters) so that load -> save -> load is exact. The
 * render core derives everything else (unit vectors, linear colours,
 * matrices) when it prepares a world (world.h) from a scene.
 *
 * Ownership: a scene owns its arrays; scene_free releases everything.
 */
#ifndef RTSH_SCENE_H
#define RTSH_SCENE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rtsh/error.h"
#include "rtsh/math.h"

/* What the model needs to know about a kind (kinds.def). */
enum {
	KIND_UNBOUNDED = 1, /* no size: scale is unused (the plane) */
	KIND_VERTICES = 2,  /* three world-space vertices in tri[], no transform (the triangle) */
	KIND_TUBE = 4,      /* uses object.tube (the torus) */
	KIND_MODEL = 8,     /* a model file placed like a unit shape: file, file_colors, smooth,
	                     * crease (the mesh; its triangles are the world's instances, mesh.h) */
};

typedef enum obj_kind {
#define RT_KIND(e, id, name, desc, flags) OBJ_##e,
#include "rtsh/kinds.def"
#undef RT_KIND
	OBJ_KIND_COUNT
} obj_kind;

/* The KIND_* flags of a kind (kinds.def). */
unsigned obj_kind_flags(obj_kind k);

/* One shared copy of the string s[0..n) that lives as long as the process:
 * equal strings give the same pointer, so objects holding file names stay
 * plain values (copied, compared and undone like numbers). NULL when out
 * of memory. */
const char *rt_intern(const char *s, size_t n);

/* The .rt identifier ("sp", "pl", ...) and the English name of a kind. */
const char *obj_kind_id(obj_kind k);
const char *obj_kind_name(obj_kind k);
/* Kind from its identifier ("sp", "tr", ...); -1 if none. (The short-form
 * aliases such as "sq" are the reader's: shape.h.) */
int obj_kind_from_id(const char *id);

typedef struct material {
	vec3 color;        /* sRGB, 0..255 per channel, as written */
	double diffuse;    /* [0,1] scale of the Lambertian albedo */
	double specular;   /* [0,1] Phong specular weight */
	double shininess;  /* [1,500] Phong exponent */
	double reflective; /* [0,1] mirror weight */
	/* Extensions, written as trailing key=value fields; the defaults
	 * below mean "absent" and are not written back. */
	double fuzz;     /* fuzz=   [0,1] roughness of the mirror lobe (0) */
	double metal;    /* metal=  [0,1] tint reflections by colour (0) */
	double ior;      /* ior=    0 opaque, else refractive index >= 1 (0) */
	double emission; /* emit=   emitted radiance = emit x colour (0); with emit_color=,
	                  * emit x that colour (glTF: emissiveFactor x emissive_strength) */
	int checker;     /* checker= 0 none, else squares per unit (0) */
	/* Textures (rt_intern'ed paths, NULL = none; see rtsh(5), "Textures"). */
	const char *texture;   /* texture=   colour image, sRGB */
	const char *normalmap; /* normalmap= tangent-space normal map, linear */
	const char *bump;      /* bump=      height map */
	double bumpscale;      /* bumpscale= height of white in scene units (1) */
	double uvscale[2];     /* uvscale=U,V (1,1) */
	double uvoffset[2];    /* uvoffset=U,V (0,0) */
	/* The physically based family, or NULL for the seeds' Phong family
	 * (see material_pbr): a shared block that lives as long as the
	 * process (material_pbr_intern), so that a material stays a plain
	 * value and the 200000-object scenes of the seeds' family pay 8 bytes. */
	const struct material_pbr *pbr;
} material;

/* The physically based family (rtsh(5), "Materials"; glTF 2.0's
 * metallic-roughness model, its Appendix B, and the KHR_materials_*
 * extensions). A material belongs to it when any of these keys is given;
 * it then ignores diffuse, specular, shininess, reflective, fuzz and
 * metal. The material's `color` is the base colour, its `ior` the
 * dielectric's index (0 = 1.5), its emission emit x (emit_color or
 * colour). The defaults mean "absent" and are not written back. */
typedef struct material_pbr {
	double roughness;    /* roughness= [0,1], perceptual: GGX alpha = roughness^2
	                      * (-1 = absent; a PBR material without it has 1, glTF's default) */
	double metallic;     /* metallic= [0,1]: conductor with F0 = colour (1) or
	                      * dielectric over Lambert / transmission (0) (0) */
	double transmission; /* transmission= [0,1]: share of the dielectric base that
	                      * refracts instead of Lambert (KHR_materials_transmission) (0) */
	int thin;            /* thin= 1: thin-walled, no bending, no volume (glTF without
	                      * KHR_materials_volume); 0: a refracting volume (0) */
	vec3 att_color;      /* att_color=R,G,B sRGB 0..255: colour white light has after
	                      * att_dist inside the volume (KHR_materials_volume) (255,255,255) */
	double att_dist;     /* att_dist= > 0: that distance, scene units; 0 = infinite (0) */
	double clearcoat;    /* clearcoat= [0,1]: weight of a colourless GGX coat, ior 1.5 (0) */
	double clearcoat_roughness; /* clearcoat_roughness= [0,1] (0) */
	double specular_factor;     /* specular_factor= [0,1]: KHR_materials_specular's
	                             * specularFactor, scales the dielectric's F (1) */
	vec3 specular_color;        /* specular_color=R,G,B sRGB 0..255: its specularColorFactor,
	                             * tints the dielectric's F0 (255,255,255) */
	vec3 emit_color;            /* emit_color=R,G,B sRGB 0..255: emission colour instead of
	                             * the base colour (-1,-1,-1 = absent) */
	int multiscatter;           /* multiscatter= 1: the GGX lobes' energy lost to single
	                             * scattering is given back (Turquin 2019); 0: not (1) */
} material_pbr;

/* Every key absent. */
material_pbr material_pbr_absent(void);
/* The shared copy of p (equal blocks give the same pointer, so materials
 * compare by pointer); NULL when p is all absent, or out of memory (*oom
 * set then, when oom is not NULL). */
const material_pbr *material_pbr_intern(const material_pbr *p, bool *oom);

/* The default material of a 42-format object: diffuse 0.9, specular 0.9,
 * shininess 200, reflective 0, no extensions. */
material material_default(vec3 color);

/* An object. The writer uses the short 42 form (sp c d rgb, pl p n rgb,
 * cy/co c axis d h rgb, sq, tr) whenever it loses nothing, and the extended
 * form otherwise. */
typedef struct object {
	obj_kind kind;
	vec3 pos;         /* centre (sphere, cube, cylinder, cone, disc, rect) or point (plane) */
	vec3 dir;         /* where the local +Y axis points, as written; never zero */
	double twist;     /* degrees about dir (twist=) */
	vec3 scale;       /* extents on the local axes, all > 0 (see rtsh(5)) */
	double shear[6];  /* xy xz yx yz zx zy; all zero = none */
	vec3 tri[3];      /* KIND_VERTICES: the vertices (pos/dir/scale unused) */
	double tube;      /* the torus: tube-to-ring diameter ratio (tube=), > 0; 0.5 by default */
	material mat;
	/* KIND_MODEL: the model file (rt_intern'ed, as the reader resolved it:
	 * relative to the .rt file's folder, or absolute), whether the colour
	 * was left out (the model's own materials are used), and the normals. */
	const char *file;
	bool file_colors;
	int smooth;       /* smooth= 0 flat faces, 1 smooth normals (1) */
	double crease;    /* crease= degrees beyond which an edge stays sharp (60) */
	int node;         /* node= a glTF file's node alone (its index), -1 the whole file */
} object;

/* The kinds of light: the miniRT light (no fall-off, `ratio` x colour),
 * and the physical lights of glTF's KHR_lights_punctual (rtsh(5),
 * "Lights"): a point or a spot of `intensity` candela, with
 * inverse-square fall-off, or a sun of `intensity` lux shining along dir;
 * their brightness is ratio x intensity x colour (linear). */
enum { LIGHT_MINIRT, LIGHT_POINT, LIGHT_SPOT, LIGHT_SUN };

typedef struct light {
	vec3 pos;
	double ratio; /* brightness [0,1] */
	vec3 color;   /* sRGB 0..255 */
	/* physical lights (L ... cd= or lux=): kind != LIGHT_MINIRT */
	int kind;
	double intensity; /* cd= candela (point, spot) or lux= (sun), >= 0 */
	vec3 dir;         /* dir= where a spot or the sun shines; never zero for them */
	double inner, outer; /* cone=INNER,OUTER: a spot's cone half-angles, degrees */
	double range;     /* range= distance where a point or spot ends (glTF's
	                   * window), 0 = none */
} light;

typedef struct camera {
	vec3 pos;
	vec3 dir;   /* as written; never zero */
	double fov; /* horizontal, degrees, (0,180); vertical when `vertical` */
	bool vertical; /* vertical=1: fov is the vertical angle (glTF's yfov) */
	double ortho;  /* ortho=H > 0: an orthographic view H high above and below
	                * the centre (glTF's ymag); 0: perspective */
	double roll;   /* roll=DEG: the camera turned about its axis, its up
	                * towards its right (glTF cameras); 0: upright */
} camera;

typedef struct ambient {
	double ratio; /* [0,1] */
	vec3 color;   /* sRGB 0..255 */
} ambient;

/* The path tracer's sky: a gradient from horizon to zenith. */
typedef struct sky {
	vec3 zenith;     /* sRGB 0..255 */
	vec3 horizon;    /* sRGB 0..255 */
	double strength; /* radiance scale, >= 0 */
	const char *file; /* sky FILE [STRENGTH [ROTATION]]: an HDR image (rt_intern'ed), or NULL */
	double rotation;  /* degrees about +Y */
} sky;

/* The most rows of the settings table (settings.h; checked there), and the
 * longest text of a kept setting's value with its terminating zero (a
 * 64-bit whole number, a double in the fewest digits: "-0.00012345678901234567").
 * 16 x 24 keeps scene_hints no larger than an object, the largest member of
 * the editor's undo records. */
#define SCENE_KEPT_MAX 16
#define SCENE_KEPT_LEN 24

/* Per-scene render hints from the file (`R`, `set` lines). scene_new sets
 * them all to "unset": width, height and samples 0, depth and mode -1, the
 * kept values "". */
typedef struct scene_hints {
	int width, height; /* R w h, or set resolution WxH */
	int samples;       /* set samples N */
	int depth;         /* set depth N (0 is a valid depth) */
	int mode;          /* set mode whitted|path: -1 unset, else render_mode */
	/* Every other setting kept with the scene (a SETTING_SCENE row of the
	 * settings table: seed, exposure, denoise, ...), by its row number:
	 * `set NAME VALUE`'s value as the row formats it (settings_scene_value),
	 * zero-padded; "" = unset. The four above keep their own fields (the R
	 * line and their long-standing messages), and their slots stay "". */
	char kept[SCENE_KEPT_MAX][SCENE_KEPT_LEN];
} scene_hints;

typedef struct scene {
	bool has_ambient;
	ambient amb;
	camera *cams; /* at least one in a loaded scene */
	size_t ncams, cap_cams;
	size_t cam; /* the active camera */
	light *lights;
	size_t nlights, cap_lights;
	object *objs;
	size_t nobjs, cap_objs;
	bool has_sky;
	sky sky;
	scene_hints hints;
	/* What the status line says about the scene beside its name (the glTF
	 * loader: "stage lighting" for a file with no light of its own);
	 * rt_intern'ed, NULL = nothing. Not saved. */
	const char *note;
} scene;

scene *scene_new(void);
void scene_free(scene *s);
/* The bytes the scene's model takes: the struct and its three arrays at
 * their capacity (mesh and texture files are the world's, not counted). */
size_t scene_bytes(const scene *s);
/* A deep copy; NULL when out of memory. */
scene *scene_clone(const scene *s);
/* True when a and b describe the identical scene, value for value. */
bool scene_equal(const scene *a, const scene *b);
bool object_equal(const object *a, const object *b);

/* Appending copies the element; false (err set) when out of memory. */
bool scene_add_object(scene *s, const object *o, rt_error *err);
bool scene_add_light(scene *s, const light *l, rt_error *err);
bool scene_add_camera(scene *s, const camera *c, rt_error *err);
/* Removes element i (0-based), keeping the order of the others. */
void scene_remove_object(scene *s, size_t i);
void scene_remove_light(scene *s, size_t i);
/* Inserts a copy of o so that it becomes element i (0-based). */
bool scene_insert_object(scene *s, size_t i, const object *o, rt_error *err);
bool scene_insert_light(scene *s, size_t i, const light *l, rt_error *err);
/* The active camera; a scene without one gets the default camera. */
camera scene_camera(const scene *s);

/* A unit-size object of kind k at the origin with the default material. */
object object_make(obj_kind k, vec3 color);
/* Checks the object can be rendered: finite numbers, non-zero dir, positive
 * scale, an invertible shear, a non-degenerate triangle. */
bool object_validate(const object *o, rt_error *err);
/* Local-to-world transform: T(pos) * R(dir, twist) * Shear * S(scale / 2),
 * mapping the unit shape (extent [-1,1], see shape.h) to the object.
 * Triangles: identity. False if not invertible. */
bool object_xform(const object *o, xform *out);
/* Centre of an object (triangles: the centroid). */
vec3 object_center(const object *o);
/* Edits in world space: move by d; rotate by Euler angles (degrees, applied
 * about X, then Y, then Z) about the object's centre; multiply the scale.
 * Rotation updates dir and twist so that the result saves exactly. */
void object_move(object *o, vec3 d);
bool object_rotate(object *o, vec3 deg, rt_error *err);
bool object_scale(object *o, vec3 factor, rt_error *err);

#endif
