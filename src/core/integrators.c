/* rtsh — the integrators by render_mode (integrators.def, integrators.h):
 * the renderer and the camera ask here what an integrator traces and
 * needs; each integrator's file defines its row. */
#include "integrators.h"

/* The integrators by render_mode (integrators.def). */
static const integrator *const integrators[MODE_COUNT] = {
#define RT_INTEGRATOR(e, name, desc) [MODE_##e] = &desc,
#include "rtsh/integrators.def"
#undef RT_INTEGRATOR
};

const char *const render_mode_names[MODE_COUNT + 1] = {
#define RT_INTEGRATOR(e, name, desc) [MODE_##e] = name,
#include "rtsh/integrators.def"
#undef RT_INTEGRATOR
	NULL,
};

const char *render_mode_name(render_mode m)
{
	return (unsigned)m < MODE_COUNT ? render_mode_names[m] : render_mode_names[0];
}

const integrator *integrator_of(render_mode m)
{
	return integrators[(unsigned)m < MODE_COUNT ? m : 0];
}

bool render_mode_denoises(render_mode m)
{
	return integrator_of(m)->features;
}

ray render_sample_ray(const world *w, const render_settings *s, int px, int py, int fw, int fh, int sample)
{
	sampler sp;
	return camera_sample_ray(w, s, integrator_of(s->mode)->sampled, px, py, fw, fh, sample, &sp);
}
