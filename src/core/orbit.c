/* rtsh — orbiting a camera (rtsh/orbit.h). */
#include "rtsh/orbit.h"

#include <math.h>

#include "rtsh/shape.h"

box orbit_scene_bounds(const scene *s)
{
	box b = box_empty();
	for (size_t i = 0; i < s->nobjs; i++) {
		if (s->objs[i].kind == OBJ_PLANE)
			continue;
		box o = object_bounds(&s->objs[i]);
		if (!box_is_empty(o) && v3_finite(o.lo) && v3_finite(o.hi))
			b = box_union(b, o);
	}
	return b;
}

vec3 orbit_scene_centre(const scene *s)
{
	box b = orbit_scene_bounds(s);
	if (!box_is_empty(b))
		return box_center(b);
	camera c = scene_camera(s);
	return v3_add(c.pos, v3_norm(c.dir));
}

/* Spherical angles of a direction: azimuth about +Y from +Z towards +X,
 * elevation from the horizon (radians). */
static void angles(vec3 d, double *az, double *el)
{
	double len = v3_len(d);
	*el = len > 0 ? asin(clampd(d.y / len, -1.0, 1.0)) : 0.0;
	*az = atan2(d.x, d.z);
}

static vec3 from_angles(double az, double el, double len)
{
	return v3(len * cos(el) * sin(az), len * sin(el), len * cos(el) * cos(az));
}

camera orbit_camera(camera c, vec3 pivot, double yaw_deg, double pitch_deg)
{
	if (!isfinite(yaw_deg) || !isfinite(pitch_deg))
		return c;
	double lim = deg_to_rad(ORBIT_PITCH_LIMIT);
	vec3 off = v3_sub(c.pos, pivot);
	double r = v3_len(off), az, el;
	angles(off, &az, &el);
	/* The camera's right is (cos az_d, 0, -sin az_d) for a heading az_d;
	 * facing the pivot its heading is az + pi, so going right lowers az. */
	double yaw = deg_to_rad(yaw_deg), pitch = deg_to_rad(pitch_deg);
	double ne = clampd(el + pitch, -lim, lim);
	if (fabs(el) > lim) /* loaded beyond the limit: may only come back */
		ne = el + pitch > el ? fmin(el + pitch, fmax(el, lim)) : fmax(el + pitch, fmin(el, -lim));
	double dp = ne - el;
	if (r > 0)
		c.pos = v3_add(pivot, from_angles(az - yaw, ne, r));
	/* The direction turns with the position: its heading by -yaw, its
	 * elevation by -dp (looking at the pivot, it is the offset reversed). */
	double daz, del;
	angles(c.dir, &daz, &del);
	double nd = clampd(del - dp, -lim, lim);
	if (fabs(del) > lim)
		nd = del; /* straight up or down stays */
	c.dir = from_angles(daz - yaw, nd, 1.0);
	return c;
}

camera orbit_dolly(camera c, vec3 pivot, double factor)
{
	if (!isfinite(factor))
		return c;
	double keep = clampd(1.0 - factor, 0.001, 1000.0);
	if (c.ortho > 0) {
		/* an orthographic view does not grow nearer: it shows less */
		double h = c.ortho * keep;
		if (h >= 1e-9 && h <= 1e9)
			c.ortho = h;
		return c;
	}
	vec3 off = v3_sub(c.pos, pivot);
	c.pos = v3_add(pivot, v3_scale(off, keep));
	return c;
}

camera orbit_frame(camera c, box b, double aspect)
{
	if (box_is_empty(b) || !v3_finite(b.lo) || !v3_finite(b.hi) || !(aspect > 0))
		return c;
	vec3 centre = box_center(b);
	double radius = 0.5 * v3_len(v3_sub(b.hi, b.lo));
	if (!(radius > 0))
		radius = 0.5;
	vec3 d = v3_norm(c.dir);
	c.dir = d;
	if (c.ortho > 0) {
		/* the sphere within the rectangle, h high and h x aspect wide
		 * either side, from in front of it */
		c.ortho = radius / fmin(1.0, aspect);
		c.pos = v3_sub(centre, v3_scale(d, 2 * radius));
		return c;
	}
	/* the half angles' tangents; vertical=1 (glTF's yfov) gives the height's */
	double t = tan(deg_to_rad(c.fov) * 0.5);
	double th = c.vertical ? t * aspect : t, tv = c.vertical ? t : t / aspect;
	double half = atan(fmin(th, tv));
	double dist = radius / sin(half);
	c.pos = v3_sub(centre, v3_scale(d, dist));
	return c;
}

camera orbit_turntable(camera c, vec3 pivot, int frame, int frames)
{
	if (frames <= 0 || frame % frames == 0)
		return c;
	return orbit_camera(c, pivot, 360.0 * frame / frames, 0.0);
}
