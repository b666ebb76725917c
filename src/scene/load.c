/* rtsh — a scene from a file by its format (rtfile.h): a .rt file through
 * the reader (rtfile_read.c), a model through the model viewer's scene
 * (viewer.c). */
#include <stdlib.h>

#include "rtsh/mesh.h"
#include "rtsh/rtfile.h"
#include "scene/rtfile_priv.h"

scene *rt_load_file(const char *path, const rt_load_opts *opts, rt_error *err)
{
	if (mesh_format_known(path) && !(opts && opts->strict))
		return rt_load_model(path, opts, err);
	if (opts && opts->strict && !rt_name_is_rt(path)) {
		rt_error_at(err, path, 0, 0,
		            "the file name does not end in .rt; expected a .rt file (strict mode)");
		return NULL;
	}
	size_t len = 0;
	char *text = rt_read_file(path, opts, &len, err);
	if (!text)
		return NULL;
	scene *s = rt_load_string(text, len, path, opts, err);
	free(text);
	return s;
}
