/* rtsh — glTF 2.0 files as scenes: what a .gltf or .glb holds beside its
 * triangles (those are mesh.h's, mesh_read_gltf).
 *
 * gltf_read_info reads the file's JSON (not its buffers) and walks the
 * node hierarchy of its scene as mesh_read_gltf does, and gives every
 * camera and every KHR_lights_punctual light placed by a node, in the
 * mesh's coordinates (the file's, with X mirrored as every model's is:
 * mesh.h), and whether a material the scene's meshes use emits light.
 * Errors are worded as the mesh reader's: the file, the JSON path or byte
 * offset, what was expected.
 */
#ifndef RTSH_GLTF_H
#define RTSH_GLTF_H

#include <stdbool.h>
#include <stddef.h>

#include "rtsh/error.h"
#include "rtsh/math.h"

typedef struct gltf_camera {
	vec3 pos, fwd, up;  /* unit fwd and up, mirrored like the mesh */
	bool ortho;
	double yfov;        /* perspective: vertical field of view, radians */
	double aspect;      /* perspective: width / height, 0 when not given */
	double xmag, ymag;  /* orthographic: half width and half height */
	int index;          /* in the file's cameras[] */
} gltf_camera;

enum { GLTF_POINT, GLTF_SPOT, GLTF_DIRECTIONAL };

typedef struct gltf_light {
	int type;           /* GLTF_POINT, GLTF_SPOT, GLTF_DIRECTIONAL */
	vec3 pos, dir;      /* dir: where it shines (spot, directional), unit */
	double color[3];    /* linear RGB */
	double intensity;   /* candela (point, spot) or lux (directional) */
	double range;       /* 0: unlimited */
	double inner, outer; /* spot cone angles, radians */
} gltf_light;

typedef struct gltf_info {
	gltf_camera *cams;
	size_t ncams;
	gltf_light *lights;
	size_t nlights;
	bool emissive;      /* a material of a mesh the scene places emits */
	long *mesh_nodes;   /* the nodes with a mesh the scene places, in walk order */
	size_t nmesh_nodes;
} gltf_info;

/* Reads the cameras and lights of a .gltf or .glb; false (err set) when the
 * file cannot be read or is not glTF 2.0. gltf_info_free releases them. */
bool gltf_read_info(const char *path, gltf_info *out, rt_error *err);
/* The same from bytes (tests, fuzzing). */
bool gltf_parse_info(const char *name, const char *buf, size_t len, gltf_info *out, rt_error *err);
void gltf_info_free(gltf_info *g);

#endif
