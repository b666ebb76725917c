/* rtsh — the emissive surfaces the path tracer samples directly (path.c
 * weighs them against its own paths). Each shape kind says how its objects
 * are sampled (shape.h, shape_light_ops; src/core/shapes/); this file only
 * collects them. */
#include "emitters.h"

#include <stdlib.h>

#include "warp.h"

bool emitters_build(world *w, const scene *s, rt_error *err)
{
	w->emitters = NULL;
	w->nemitters = 0;
	size_t n = 0;
	for (size_t pass = 0; pass < 2; pass++) {
		for (size_t i = 0; i < s->nobjs; i++) {
			const object *o = &s->objs[i];
			if (!(max3(w->mats[i].emission) > 0.0))
				continue;
			const shape_kind *k = shape_kind_of(o->kind);
			emitter e = {.object = (uint32_t)i, .kind = (uint32_t)o->kind};
			if (!k || !k->light.make || !k->light.make(o, &e.l))
				continue; /* found by the paths only */
			if (pass == 1) {
				w->mats[i].light = (int32_t)w->nemitters;
				w->emitters[w->nemitters++] = e;
			} else {
				n++;
			}
		}
		if (pass == 0) {
			if (n == 0)
				return true;
			w->emitters = calloc(n, sizeof *w->emitters);
			if (!w->emitters)
				return rt_error_set(err, "out of memory preparing the scene");
		}
	}
	return true;
}
