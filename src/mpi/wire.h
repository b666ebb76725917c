/* rtsh-mpi — what rank 0 tells every rank before the render, encoded field
 * by field (not as a struct's bytes): fixed-width little-endian integers,
 * doubles as their IEEE 754 bits, after a magic word and a version. Ranks
 * built by another compiler, for another byte order, or from another
 * version of rtsh-mpi read the same values or refuse with a message; no
 * padding, pointer or struct layout is ever sent.
 *
 * Layout (version 5; version 4's, the farm's messages since changed:
 * farm.h), WIRE_CONFIG_SIZE bytes, zeros after the fields:
 *   "RTSHMPI\0"  u32 version  u32 length of what follows
 *   i32 status verbose progress strict tile prefetch delay_us
 *   render_settings: every row of the settings table (settings.h) but the
 *                    terminal's choices (SETTING_TERMINAL: pixels,
 *                    symbols; the receiver has their defaults), in its
 *                    order, by its type: i32 for a whole number or a
 *                    choice, u64, f64, or i32 W and H for a resolution
 *                    (today: width height samples depth mode threads
 *                    seed exposure denoise)
 *   u64 files (bytes of the packed file set)
 */
#ifndef RTSH_MPI_WIRE_H
#define RTSH_MPI_WIRE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rtsh/render.h"

#define WIRE_VERSION 5
/* Every rank receives this many bytes: more than version 1 needs, so that a
 * newer version can add fields and still be told apart. */
#define WIRE_CONFIG_SIZE 256

typedef struct job_config {
	int32_t status;   /* -1: render; else every rank exits with it */
	int32_t verbose, progress, strict;
	int32_t tile, prefetch, delay_us;
	render_settings set;
	uint64_t files;   /* bytes of the packed file set */
} job_config;

/* Encodes c into buf (WIRE_CONFIG_SIZE bytes). */
void wire_put_config(const job_config *c, unsigned char buf[WIRE_CONFIG_SIZE]);
/* Decodes buf into *c; false, with why (what is wrong, what was expected),
 * when it is not a configuration of this WIRE_VERSION or a value is out of
 * range. */
bool wire_get_config(job_config *c, const unsigned char buf[WIRE_CONFIG_SIZE], char *why,
                     size_t whylen);

#endif
