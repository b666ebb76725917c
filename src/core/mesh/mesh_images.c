/* rtsh — a model's own image files, looked up before a load is taken. */
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "rtsh/filesrc.h"
#include "rtsh/mesh.h"

/* The model's own image files (an MTL's maps, a glTF's images beside it)
 * are there, as a .rt's texture= is checked (src/scene/rtfile_read.c): a
 * missing one makes the load fail with the model's name, the material's
 * and the image's, rather than every render after it (rtsh(5), "Meshes").
 * Only looked up (stat), not decoded: a scene of a hundred images is not
 * read twice; a corrupt one is the render's error, in the same words
 * (surface.c). */
bool mesh_images_ok(const char *path, const mesh *m, rt_error *err)
{
	for (uint32_t k = 0; k < m->nmats; k++) {
		const mesh_mat *mm = &m->mats[k];
		const struct {
			const char *file, *what;
		} f[] = {{mm->map_kd, "colour texture"},
		         {mm->map_norm, "normal map"},
		         {mm->map_bump, "bump map"},
		         {mm->gltf ? mm->map_mr : NULL, "metallic-roughness texture"},
		         {mm->gltf ? mm->map_emit : NULL, "emissive texture"}};
		for (size_t i = 0; i < sizeof f / sizeof f[0]; i++) {
			struct stat st;
			if (!f[i].file)
				continue;
			const char *why = NULL, *kind = NULL;
			if (rt_file_stat(f[i].file, &st) != 0)
				why = strerror(errno);
			else if ((kind = rt_file_kind(st.st_mode)) != NULL)
				why = "not a regular file";
			if (!why)
				continue;
			char mat[96];
			if (mm->name && mm->name[0])
				snprintf(mat, sizeof mat, "\"%.80s\"", mm->name);
			else
				snprintf(mat, sizeof mat, "%u", k + 1);
			return rt_error_set(err, "%s: the %s of material %s: %s: cannot read the image: %s%s%s", path,
			                    f[i].what, mat, f[i].file, why, kind ? " but " : "", kind ? kind : "");
		}
	}
	return true;
}
