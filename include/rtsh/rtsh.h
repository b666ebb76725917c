/* rtsh — the public face of the render core (librtsh.a): load a scene, edit
 * it, render a rectangle of its picture and read the pixels, through two
 * opaque handles. This header includes no other; a program that embeds rtsh
 * (a file-manager previewer, a binding) needs only it and the library:
 *
 *     cc -Iinclude prog.c build/librtsh.a -lpng -lassimp -lcjson -lXpm -lstb -lm -pthread
 *
 * examples/embed.c is such a program, built and run by `make test`.
 * Errors: a function that fails returns NULL or false and, where it takes
 * one, fills the scene's error text (rtsh_error), "FILE:LINE: what is
 * wrong, what was expected" as the shell says it. Not thread-safe on one
 * handle; separate handles may be used from separate threads.
 * Implemented in src/scene/rtsh.c (the scene-files layer: it uses the reader,
 * the editor, the settings table and the renderer). */
#ifndef RTSH_RTSH_H
#define RTSH_RTSH_H

#include <stdbool.h>
#include <stddef.h>

typedef struct rtsh_scene rtsh_scene; /* a scene, its edits and its settings */
typedef struct rtsh_image rtsh_image; /* a rendered rectangle, linear RGB */

/* Loads a .rt scene (or a model file: .obj .ply .gltf .glb .stl, framed as
 * the model viewer does). NULL on failure, with the message in err (size
 * bytes, may be 0). The scene's own resolution and settings lines apply. */
rtsh_scene *rtsh_load(const char *path, char *err, size_t size);
/* The same from .rt text; `name` is what messages call it. */
rtsh_scene *rtsh_load_text(const char *text, const char *name, char *err, size_t size);
void rtsh_free(rtsh_scene *sc);
/* The last failure's message on this scene ("" when none). */
const char *rtsh_error(const rtsh_scene *sc);

/* A setting by the shell's `set` name (samples, resolution, mode, depth,
 * seed, exposure, threads...) and its value as text ("16", "320x240",
 * "path"). */
bool rtsh_set(rtsh_scene *sc, const char *name, const char *value);
/* The picture's size (the resolution setting). */
void rtsh_size(const rtsh_scene *sc, int *width, int *height);

/* Edits, each one step of undo. Objects are numbered from 0 in file order. */
size_t rtsh_object_count(const rtsh_scene *sc);
bool rtsh_object_move(rtsh_scene *sc, size_t i, double dx, double dy, double dz);
/* An sRGB colour, 0..255 a channel, as in .rt files. */
bool rtsh_object_color(rtsh_scene *sc, size_t i, double r, double g, double b);
/* A key=value field of the object ("reflective=0.5", "texture=wood.png"). */
bool rtsh_object_set(rtsh_scene *sc, size_t i, const char *assignment);
/* Adds one .rt line ("sp 0,0,5 2 255,0,0"), as the shell's `add` does. */
bool rtsh_add(rtsh_scene *sc, const char *line);
bool rtsh_undo(rtsh_scene *sc);

/* Renders the pixels x0 <= x < x1, y0 <= y < y1 of the picture, all its
 * samples: the same values, bit for bit, as the whole picture's render
 * gives those pixels (a rectangle on the calling thread; the whole picture
 * on the `threads` setting's threads, and denoised as `rtsh -o` writes it
 * when `denoise` is on in path mode). NULL on failure (rtsh_error says why). */
rtsh_image *rtsh_render(rtsh_scene *sc, int x0, int y0, int x1, int y1);
void rtsh_image_free(rtsh_image *im);
int rtsh_image_width(const rtsh_image *im);
int rtsh_image_height(const rtsh_image *im);
/* width x height pixels, rows top first, 3 linear-light floats each. */
const float *rtsh_image_pixels(const rtsh_image *im);
/* The same as 8-bit sRGB, into out (width x height x 3 bytes). */
void rtsh_image_srgb8(const rtsh_image *im, unsigned char *out);

#endif
