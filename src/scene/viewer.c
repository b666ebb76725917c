/* rtsh — the model viewer's scene (rtfile.h, rt_load_file on a model).
 *
 * `rtsh model.obj` opens a scene made for the model: the model standing on
 * a ground plane (its bounding box centred over the origin, longest side 2
 * units, +Y up), a camera that frames its bounding sphere from the front,
 * a little above and to the right, a key light above the camera's left
 * shoulder, a soft ambient and a sky. The model keeps its own materials. `save x.rt` writes it out with a mesh
 * line that references the model.
 *
 * Two rules for models that do not say everything (rtsh(1), "The model
 * viewer"): the front is the file's +Z side (glTF's convention, and
 * Blender's OBJ export), except that a model deeper than wide whose top
 * leans clearly to -Z (an animal with its head at -Z, such as Spot) is
 * turned to face the camera (twist=180); and a model with texture
 * coordinates but no materials takes as its colour texture the one image
 * beside it whose name starts with the model's stem (spot_texture.png for
 * spot_triangulated.obj), which the status line names.
 */
#include <dirent.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "rtsh/filesrc.h"
#include "rtsh/gltf.h"
#include "rtsh/mesh.h"
#include "rtsh/rtfile.h"
#include "rtsh/texture.h"
#include "rtsh/world.h"

/* --- glTF 2.0 scenes --- */

static bool has_ext(const char *path, const char *ext)
{
	const char *slash = strrchr(path, '/'), *dot = strrchr(slash ? slash : path, '.');
	return dot && strcasecmp(dot + 1, ext) == 0;
}

/* Appends to the scene text; false when it would not fit. */
static bool put(char *text, size_t size, size_t *n, const char *fmt, ...) __attribute__((format(printf, 4, 5)));
static bool put(char *text, size_t size, size_t *n, const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	int k = vsnprintf(text + *n, size - *n, fmt, ap);
	va_end(ap);
	if (k < 0 || (size_t)k >= size - *n)
		return false;
	*n += (size_t)k;
	return true;
}

/* A number as the scene text writes it: within 1e-9 of a whole number (a
 * colour of 254.99999999999997 from the sRGB encoding of 1, a direction's
 * 2e-16 from a quaternion, -0) the whole number. */
static double tidy(double x)
{
	double r = round(x);
	return fabs(x - r) < 1e-9 ? r + 0.0 : x;
}

static vec3 tidy3(vec3 v)
{
	return v3(tidy(v.x), tidy(v.y), tidy(v.z));
}

/* `rtsh scene.glb`: the file as a scene (rtsh(5), "glTF scenes"). Its
 * triangles are one mesh line placed so that the file's coordinates are the
 * scene's (the box centred where it is, its longest side its own size);
 * every camera the nodes place (the first is used) and every
 * KHR_lights_punctual light, in physical units. A file without a camera is
 * framed as the model viewer frames a model; one with neither lights nor
 * emissive materials gets the viewer's stage lighting, and its status line
 * says so; otherwise it is lit by what it holds, on black, in path mode. */
/* A file with from 2 to NODE_OBJECTS nodes with meshes is read as one
 * object a node (`mesh FILE ... node=K`, so that the shell's edit commands
 * move them one by one), when reading the file once a node stays within
 * NODE_BYTES; otherwise as one object. */
#define NODE_OBJECTS 64
#define NODE_BYTES (256.0 * 1024 * 1024)

/* The bounds of each node's triangles (nb[k] for gi->mesh_nodes[k]) and
 * their union, or false when a node cannot be read alone (then the file is
 * one object). */
static bool node_bounds(const char *path, const gltf_info *gi, const rt_load_opts *opts, box *nb, box *all)
{
	struct stat st;
	if (gi->nmesh_nodes < 2 || gi->nmesh_nodes > NODE_OBJECTS || rt_file_stat(path, &st) != 0 ||
	    (double)st.st_size * (double)gi->nmesh_nodes > NODE_BYTES)
		return false;
	for (size_t k = 0; k < gi->nmesh_nodes; k++) {
		rt_error e = {0};
		mesh *m = mesh_cache_get_node(path, gi->mesh_nodes[k], true, 60, opts ? opts->cancel : NULL, &e);
		if (!m)
			return false;
		nb[k] = m->bounds;
		mesh_cache_put(m);
		*all = k == 0 ? nb[k] : box_union(*all, nb[k]);
	}
	return true;
}

/* The scene made for a model is written as .rt lines, which cannot hold a
 * line break: the rest of such a name became lines of their own (its
 * comment's), and its mesh line an unclosed quote. */
static bool name_fits_a_line(const char *path, rt_error *err)
{
	if (!strpbrk(path, "\n\r"))
		return true;
	return rt_error_set(err, "%s: the file name has a line break, which a scene line cannot hold; expected a "
	                         "name without one (rename the file)", path);
}

static char *gltf_text(const char *path, const rt_load_opts *opts, size_t *len, bool *stage_lit, rt_error *err)
{
	if (!name_fits_a_line(path, err))
		return NULL;
	gltf_info gi;
	if (!gltf_read_info(path, &gi, err))
		return NULL;
	box bb = {v3(0, 0, 0), v3(0, 0, 0)};
	box *nb = gi.nmesh_nodes ? malloc(gi.nmesh_nodes * sizeof *nb) : NULL;
	bool split = nb && node_bounds(path, &gi, opts, nb, &bb);
	if (!split) {
		mesh *m = mesh_cache_get(path, true, 60, opts ? opts->cancel : NULL, err);
		if (!m) {
			free(nb);
			gltf_info_free(&gi);
			return NULL;
		}
		bb = m->bounds;
		if (m->warning) /* duplicate triangles dropped, say */
			rt_warn(opts ? opts->warn : NULL, NULL, 0, 0, "%s", m->warning);
		bool images = mesh_images_ok(path, m, err);
		mesh_cache_put(m);
		if (!images) {
			free(nb);
			gltf_info_free(&gi);
			return NULL;
		}
	} else {
		/* a node's mesh holds all the file's materials */
		mesh *m = mesh_cache_get_node(path, gi.mesh_nodes[0], true, 60, opts ? opts->cancel : NULL, err);
		bool images = m && mesh_images_ok(path, m, err);
		mesh_cache_put(m);
		if (!images) {
			free(nb);
			gltf_info_free(&gi);
			return NULL;
		}
	}
	vec3 ext = v3_sub(bb.hi, bb.lo), mid = box_center(bb);
	double longest = v3_max_comp(ext);
	if (!(longest > 0))
		longest = 1;
	const char *slash = strrchr(path, '/');
	const char *base = slash ? slash + 1 : path;
	bool quote = strpbrk(base, " \t,#\"=") != NULL; /* = : not a key */
	bool stage = gi.nlights == 0 && !gi.emissive;
	*stage_lit = stage;
	size_t size = 4096 + 256 * (gi.ncams + gi.nlights) + (split ? (160 + strlen(base)) * gi.nmesh_nodes : 0), n = 0;
	char *text = malloc(size);
	if (!text) {
		rt_error_set(err, "%s: out of memory", path);
		goto done;
	}
	bool ok = put(text, size, &n, "# the glTF scene %s\n", base);
	if (!split)
		ok = ok && put(text, size, &n, "mesh %s%s%s %.17g,%.17g,%.17g 0,1,0 %.17g\n", quote ? "\"" : "", base,
		               quote ? "\"" : "", mid.x, mid.y, mid.z, longest);
	/* a node: its triangles' box centred where it is, its longest side its
	 * own size (surface.c places a model so) */
	for (size_t k = 0; split && ok && k < gi.nmesh_nodes; k++) {
		vec3 c = box_center(nb[k]);
		double l = v3_max_comp(v3_sub(nb[k].hi, nb[k].lo));
		ok = put(text, size, &n, "mesh %s%s%s %.17g,%.17g,%.17g 0,1,0 %.17g node=%ld\n", quote ? "\"" : "", base,
		         quote ? "\"" : "", c.x, c.y, c.z, l > 0 ? l : 1, gi.mesh_nodes[k]);
	}
	/* the viewer's framing: the bounding sphere from the front, a little
	 * above and to the right, 50 degrees across a 16:9 image */
	double radius = 0.5 * v3_len(ext), fov = 50, vhalf = atan(tan(fov * M_PI / 360) * 9.0 / 16.0);
	double dist = 0.85 * (radius > 0 ? radius : 1) / sin(vhalf);
	vec3 vdir = v3_norm(v3(0.45, -0.35, -1));
	if (gi.ncams == 0) {
		vec3 cam = v3_sub(mid, v3_scale(vdir, dist));
		ok = ok && put(text, size, &n, "C %.17g,%.17g,%.17g %.17g,%.17g,%.17g %g\n", cam.x, cam.y, cam.z, vdir.x,
		               vdir.y, vdir.z, fov);
	}
	for (size_t i = 0; ok && i < gi.ncams; i++) {
		gltf_camera cc = gi.cams[i];
		cc.pos = tidy3(cc.pos);
		cc.fwd = tidy3(cc.fwd);
		const gltf_camera *c = &cc;
		/* the camera's roll: the angle from rtsh's upright up (camera.c)
		 * to the file's, towards the camera's right */
		vec3 up_ref = fabs(c->fwd.y) > 0.999999 ? v3(0, 0, 1) : v3(0, 1, 0);
		vec3 right = v3_norm(v3_cross(up_ref, c->fwd)), up = v3_cross(c->fwd, right);
		double roll = atan2(v3_dot(c->up, right), v3_dot(c->up, up)) * 180 / M_PI;
		if (fabs(roll) < 1e-9)
			roll = 0;
		if (c->ortho)
			ok = put(text, size, &n, "%c %.17g,%.17g,%.17g %.17g,%.17g,%.17g 60 ortho=%.17g", i ? 'c' : 'C',
			         c->pos.x, c->pos.y, c->pos.z, c->fwd.x, c->fwd.y, c->fwd.z, c->ymag);
		else
			ok = put(text, size, &n, "%c %.17g,%.17g,%.17g %.17g,%.17g,%.17g %.17g vertical=1", i ? 'c' : 'C',
			         c->pos.x, c->pos.y, c->pos.z, c->fwd.x, c->fwd.y, c->fwd.z, c->yfov * 180 / M_PI);
		if (ok && roll != 0)
			ok = put(text, size, &n, " roll=%.17g", roll);
		ok = ok && put(text, size, &n, "\n");
	}
	/* the first camera's shape, when the file gives it */
	double aspect = gi.ncams == 0 ? 0 : gi.cams[0].ortho ? (gi.cams[0].ymag > 0 ? gi.cams[0].xmag / gi.cams[0].ymag : 0)
	                                                     : gi.cams[0].aspect;
	if (ok && aspect > 0.05 && aspect < 20)
		ok = put(text, size, &n, "R 1280 %d\n", (int)fmax(1, round(1280 / aspect)));
	for (size_t i = 0; ok && i < gi.nlights; i++) {
		gltf_light ll = gi.lights[i];
		ll.pos = tidy3(ll.pos);
		ll.dir = tidy3(ll.dir);
		const gltf_light *l = &ll;
		vec3 c = linear_to_srgb255(v3(l->color[0], l->color[1], l->color[2]));
		/* a colour brighter than white: the excess goes into the intensity */
		double top = v3_max_comp(c), k = 1;
		if (top > 255) {
			k = v3_max_comp(v3(l->color[0], l->color[1], l->color[2]));
			c = linear_to_srgb255(v3(l->color[0] / k, l->color[1] / k, l->color[2] / k));
		}
		c = tidy3(c);
		ok = put(text, size, &n, "L %.17g,%.17g,%.17g 1 %.17g,%.17g,%.17g %s=%.17g", l->pos.x, l->pos.y, l->pos.z,
		         c.x, c.y, c.z, l->type == GLTF_DIRECTIONAL ? "lux" : "cd", l->intensity * k);
		if (ok && l->type != GLTF_POINT)
			ok = put(text, size, &n, " dir=%.17g,%.17g,%.17g", l->dir.x, l->dir.y, l->dir.z);
		if (ok && l->type == GLTF_SPOT)
			ok = put(text, size, &n, " cone=%.17g,%.17g", l->inner * 180 / M_PI, l->outer * 180 / M_PI);
		if (ok && l->type != GLTF_DIRECTIONAL && l->range > 0)
			ok = put(text, size, &n, " range=%.17g", l->range);
		ok = ok && put(text, size, &n, "\n");
	}
	if (ok && stage) {
		/* the viewer's stage: ambient, a key light above the camera's left
		 * shoulder, a sky and a floor under the model */
		vec3 target = mid;
		double d = gi.ncams > 0 ? v3_len(v3_sub(mid, gi.cams[0].pos)) : dist;
		vec3 lamp = v3_add(target, v3(1.2 * d, 2.0 * d, 1.5 * d));
		ok = put(text, size, &n,
		         "A 0.25 255,255,255\nL %.17g,%.17g,%.17g 0.8 255,250,240\nsky 110,150,210 235,235,240 1\n"
		         "pl 0,%.17g,0 0,1,0 180,180,180\nset samples 4\n",
		         lamp.x, lamp.y, lamp.z, bb.lo.y);
	} else if (ok) {
		ok = put(text, size, &n, "set mode path\nset samples 64\n");
	}
	if (!ok) {
		rt_error_set(err, "%s: the file name is too long", path);
		free(text);
		text = NULL;
		goto done;
	}
	*len = n;
	if (stage)
		rt_warn(opts ? opts->warn : NULL, path, 0, 0,
		        "no lights and no emissive materials: lit by the model viewer's stage lighting");
done:
	free(nb);
	gltf_info_free(&gi);
	return text;
}


/* The front rule: true when the model is deeper (Z) than wide (X) and the
 * corners in the highest tenth of its height lie on average more than a
 * quarter of its half-depth behind the box's centre (-Z): the model then
 * faces -Z, and the viewer turns it about +Y. */
static bool faces_back(const mesh *m)
{
	box bb = m->bounds;
	vec3 ext = v3_sub(bb.hi, bb.lo);
	if (!(ext.z > ext.x) || !(ext.y > 0))
		return false;
	double band = bb.hi.y - 0.1 * ext.y, sum = 0;
	size_t n = 0;
	for (uint32_t slot = 0; slot < 4 * m->nblk; slot++) {
		vec3 c[3];
		mesh_corners(m, slot, c);
		for (int k = 0; k < 3; k++)
			if (c[k].y >= band) {
				sum += c[k].z;
				n++;
			}
	}
	double mid = 0.5 * (bb.lo.z + bb.hi.z);
	return n > 0 && sum / (double)n < mid - 0.25 * 0.5 * ext.z;
}

/* The texture rule: for a model with texture coordinates and no materials,
 * the one image in its folder whose name starts with the model's stem (its
 * name up to the first '_', '-', '.' or blank) followed by one of those
 * characters. Writes its name (no folder) to out; false when there is none,
 * or several (said as a warning). */
static bool beside_texture(const char *path, const mesh *m, const rt_load_opts *opts, char *out, size_t size)
{
	if (!m->uv || m->nmats > 0)
		return false;
	const char *slash = strrchr(path, '/');
	const char *base = slash ? slash + 1 : path;
	size_t stem = strcspn(base, "_-. ");
	if (stem == 0 || stem == strlen(base))
		return false;
	char dir[4096];
	int dn = slash ? snprintf(dir, sizeof dir, "%.*s", (int)(slash - path + 1), path) : snprintf(dir, sizeof dir, "./");
	if (dn < 0 || (size_t)dn >= sizeof dir)
		return false;
	DIR *d = opendir(dir);
	if (!d)
		return false;
	int found = 0;
	struct dirent *e;
	while ((e = readdir(d)) != NULL) {
		const char *nm = e->d_name;
		if (strncmp(nm, base, stem) != 0 || !nm[stem] || !strchr("_-. ", nm[stem]) || !image_format_known(nm))
			continue;
		char full[8192];
		struct stat st;
		int fn = snprintf(full, sizeof full, "%s%s", dir, nm);
		if (fn < 0 || (size_t)fn >= sizeof full || stat(full, &st) != 0 || !S_ISREG(st.st_mode))
			continue;
		if (found++ == 0 && strlen(nm) < size)
			memcpy(out, nm, strlen(nm) + 1);
		else if (found == 1)
			found = 2; /* too long a name: not taken */
	}
	closedir(d);
	if (found > 1)
		rt_warn(opts ? opts->warn : NULL, NULL, 0, 0,
		        "%s: %d images beside it start with \"%.*s\": none taken as its texture (use texture=)", base, found,
		        (int)stem, base);
	return found == 1;
}

/* rt_model_text, with the name of the texture the texture rule took in tex
 * ("" when none). */
static char *model_text(const char *path, const rt_load_opts *opts, size_t *len, char *tex, size_t tex_size,
                        rt_error *err)
{
	if (!name_fits_a_line(path, err))
		return NULL;
	bool stage;
	if (has_ext(path, "gltf") || has_ext(path, "glb"))
		return gltf_text(path, opts, len, &stage, err);
	mesh *m = mesh_cache_get(path, true, 60, opts ? opts->cancel : NULL, err);
	if (!m)
		return NULL;
	if (m->warning) /* a missing material library, say */
		rt_warn(opts ? opts->warn : NULL, NULL, 0, 0, "%s", m->warning);
	if (!mesh_images_ok(path, m, err)) {
		mesh_cache_put(m);
		return NULL;
	}
	vec3 ext = v3_sub(m->bounds.hi, m->bounds.lo);
	bool turned = faces_back(m);
	bool textured = beside_texture(path, m, opts, tex, tex_size);
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
	bool quote = strpbrk(base, " \t,#\"=") != NULL; /* = : not a key */
	bool tquote = textured && strpbrk(tex, " \t,#\"=") != NULL;
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
	                 "mesh %s%s%s 0,%.6g,0 0,1,0 2%s%s%s%s%s\n"
	                 "set samples 4\n",
	                 base, cam.x, cam.y, cam.z, dir.x, dir.y, dir.z, fov, lamp.x, lamp.y, lamp.z,
	                 quote ? "\"" : "", base, quote ? "\"" : "", e.y / 2, turned ? " twist=180" : "",
	                 textured ? " texture=" : "", tquote ? "\"" : "", textured ? tex : "", tquote ? "\"" : "");
	if (n < 0 || n >= 8192) {
		free(text);
		rt_error_set(err, "%s: the file name is too long", path);
		return NULL;
	}
	*len = (size_t)n;
	return text;
}

char *rt_model_text(const char *path, const rt_load_opts *opts, size_t *len, rt_error *err)
{
	char tex[1024] = "";
	return model_text(path, opts, len, tex, sizeof tex, err);
}

scene *rt_load_model(const char *path, const rt_load_opts *opts, rt_error *err)
{
	size_t n;
	bool gltf = has_ext(path, "gltf") || has_ext(path, "glb"), stage = false;
	char tex[1024] = "";
	char *text = gltf ? gltf_text(path, opts, &n, &stage, err) : model_text(path, opts, &n, tex, sizeof tex, err);
	if (!text)
		return NULL;
	scene *s = rt_load_string(text, n, path, opts, err);
	free(text);
	if (s && stage) /* the status line says so */
		s->note = rt_intern("stage lighting", strlen("stage lighting"));
	if (s && tex[0]) { /* the texture rule's image, named in the status line */
		char note[1100];
		int k = snprintf(note, sizeof note, "texture %s", tex);
		s->note = rt_intern(note, (size_t)k < sizeof note ? (size_t)k : sizeof note - 1);
	}
	return s;
}
