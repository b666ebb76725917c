/* rtsh — the model viewer's scene (rtfile.h, rt_load_file on a model).
 *
 * `rtsh model.obj` opens a scene made for the model: the model standing on
 * a ground plane (its bounding box centred over the origin, longest side 2
 * units, +Y up), a camera that frames its bounding sphere from the front,
 * a little above and to the right, a key light above the camera's left
 * shoulder, a soft ambient and a sky. The model keeps its own materials. `save x.rt` writes it out with a mesh
 * line that references the model.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rtsh/mesh.h"
#include "rtsh/rtfile.h"

char *rt_model_text(const char *path, const rt_load_opts *opts, size_t *len, rt_error *err)
{
	mesh *m = mesh_cache_get(path, true, 60, opts ? opts->cancel : NULL, err);
	if (!m)
		return NULL;
	if (m->warning) /* a missing material library, say */
		rt_warn(opts ? opts->warn : NULL, NULL, 0, 0, "%s", m->warning);
	vec3 ext = v3_sub(m->bounds.hi, m->bounds.lo);
	mesh_cache_put(m);
	double longest = v3_max_comp(ext);
	if (!(longest > 0))
		longest = 1;
	vec3 e = v3_scale(ext, 2.0 / longest); /* the placed model's box */
	double radius = 0.5 * v3_len(e);
	/* 50 degrees across a 16:9 image: the vertical half angle decides */
	double fov = 50, vhalf = atan(tan(fov * M_PI / 360) * 9.0 / 16.0);
	double dist = 0.85 * radius / sin(vhalf);
	vec3 target = v3(0, e.y / 2, 0);
	vec3 dir = v3_norm(v3(0.45, -0.35, -1)); /* from the camera to the model */
	vec3 cam = v3_sub(target, v3_scale(dir, dist));
	vec3 lamp = v3_add(target, v3(1.2 * dist, 2.0 * dist, 1.5 * dist));
	const char *slash = strrchr(path, '/');
	const char *base = slash ? slash + 1 : path;
	bool quote = strpbrk(base, " \t,#\"") != NULL;
	char *text = malloc(8192);
	if (!text) {
		rt_error_set(err, "out of memory");
		return NULL;
	}
	int n = snprintf(text, 8192,
	                 "# the model viewer's scene for %s\n"
	                 "A 0.25 255,255,255\n"
	                 "C %.6g,%.6g,%.6g %.6g,%.6g,%.6g %g\n"
	                 "L %.6g,%.6g,%.6g 0.8 255,250,240\n"
	                 "sky 110,150,210 235,235,240 1\n"
	                 "pl 0,0,0 0,1,0 180,180,180\n"
	                 "mesh %s%s%s 0,%.6g,0 0,1,0 2\n"
	                 "set samples 4\n",
	                 base, cam.x, cam.y, cam.z, dir.x, dir.y, dir.z, fov, lamp.x, lamp.y, lamp.z,
	                 quote ? "\"" : "", base, quote ? "\"" : "", e.y / 2);
	if (n < 0 || n >= 8192) {
		free(text);
		rt_error_set(err, "%s: the file name is too long", path);
		return NULL;
	}
	*len = (size_t)n;
	return text;
}

scene *rt_load_model(const char *path, const rt_load_opts *opts, rt_error *err)
{
	size_t n;
	char *text = rt_model_text(path, opts, &n, err);
	if (!text)
		return NULL;
	scene *s = rt_load_string(text, n, path, opts, err);
	free(text);
	return s;
}
