/* rtsh — the turntable in batch (turntable.h). */
#include "shell/turntable.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "rtsh/gif.h"
#include "rtsh/image.h"
#include "rtsh/orbit.h"
#include "rtsh/render.h"
#include "rtsh/rtfile.h"
#include "rtsh/settings.h"
#include "rtsh/world.h"
#include "shell/args.h"

static int report(const rt_error *err)
{
	char msg[RT_ERROR_MSG_MAX + RT_ERROR_FILE_MAX + 32];
	rt_error_format(err, msg, sizeof msg);
	fprintf(stderr, "%s\n", msg);
	return 1;
}

int turntable_batch(const rtsh_options *o)
{
	int frames = o->turntable_frames;
	bool gif = turntable_is_gif(o->output);
	char name[4096];
	if (!o->scene) {
		fprintf(stderr, "rtsh: --turntable needs a scene file\nTry 'rtsh --help' for more information.\n");
		return 2;
	}
	if (!turntable_output_ok(o->output)) {
		char exts[128];
		image_extensions(exts, sizeof exts, false);
		fprintf(stderr,
		        "rtsh: --turntable: output \"%s\" is neither a .gif nor a numbered image name; expected "
		        "spin.gif or a name with one %%d such as frame%%03d.png (%s)\n"
		        "Try 'rtsh --help' for more information.\n",
		        o->output, exts);
		return 2;
	}
	rt_error err;
	rt_load_opts lo = {.strict = o->strict};
	scene *s = rt_load_file(o->scene, &lo, &err);
	if (!s)
		return report(&err);
	render_settings set = render_settings_default();
	render_settings_apply_hints(&set, &s->hints);
	options_apply_settings(o, &set);
	camera c0 = scene_camera(s);
	vec3 pivot = orbit_scene_centre(s);
	world *w = world_build(s, &err);
	scene_free(s);
	if (!w)
		return report(&err);
	int delay = TURNTABLE_TURN_CS / frames;
	if (delay < TURNTABLE_MIN_CS)
		delay = TURNTABLE_MIN_CS;
	gif_anim *g = gif ? gif_new(set.width, set.height, delay) : NULL;
	int rc = 0;
	if (gif && !g) {
		fprintf(stderr, "rtsh: out of memory for a %dx%d GIF\n", set.width, set.height);
		rc = 1;
	}
	bool tty = !o->quiet && isatty(STDERR_FILENO);
	/* One render job a frame; the world's camera turned between them. */
	for (int k = 0; rc == 0 && k < frames; k++) {
		camera c = orbit_turntable(c0, pivot, k, frames);
		w->cam = cam_view_make(&c);
		framebuffer *fb = render_image(w, &set, NULL, NULL, NULL, &err);
		if (!fb) {
			rc = report(&err);
			break;
		}
		if (gif) {
			if (!gif_add_linear(g, fb->rgb, set.exposure)) {
				fprintf(stderr, "rtsh: out of memory for the GIF\n");
				rc = 1;
			}
		} else {
			turntable_name(o->output, k, name, sizeof name);
			if (!image_write(name, fb, set.exposure, &err))
				rc = report(&err);
		}
		fb_free(fb);
		if (tty)
			fprintf(stderr, "\rframe %d/%d", k + 1, frames);
	}
	if (tty)
		fputc('\n', stderr);
	if (rc == 0 && gif && !gif_save(g, o->output, &err))
		rc = report(&err);
	if (rc == 0 && tty)
		fprintf(stderr, "wrote %s: %d frames of %dx%d, a full turn (%d samples, %s)\n", gif ? o->output : "the frames",
		        frames, set.width, set.height, set.samples, render_mode_name(set.mode));
	gif_free(g);
	world_free(w);
	return rc;
}
