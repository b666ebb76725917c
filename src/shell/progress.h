/* rtsh — the text of a full render's progress: the bar, the percentage,
 * the samples per pixel done (on average: a full render traces every sample
 * of a tile at once, so it is the fraction of the work times the target),
 * the time so far and the estimate of the time left, and the speed in
 * millions of camera rays (one per sample) per second. */
#ifndef RTSH_PROGRESS_H
#define RTSH_PROGRESS_H

#include <stddef.h>
#include <stdio.h>

typedef struct progress_state {
	int w, h;        /* the image */
	int samples;     /* per pixel, the target */
	long done, total;/* units of work (tiles) */
	double elapsed;  /* seconds since the start */
} progress_state;

/* "[#####.......] 42% 27/64 spp 2.3 s, 3.1 s left 12.5 Mrays/s", with a bar
 * of `bar` characters (0: none). */
void progress_text(const progress_state *p, int bar, char *buf, size_t size);
/* "950 ms", "12 s", "2m05s": a duration for the status line. */
void progress_duration(double seconds, char *buf, size_t size);

/* The same text on a terminal's standard error, for batch mode (main.c)
 * and rtsh-mpi's rank 0 (farm.c): "\r", the text with a bar of 30, padded
 * with blanks over a longer line before it. The shell's status line is the
 * third output (shell.c). */
void progress_print(FILE *f, const progress_state *p);

#endif
