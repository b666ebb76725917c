/* rtsh — libraries opened on first use (dlopen), so that a start-up that
 * never reads a model or an XPM image does not map and relocate them:
 * assimp alone brought libstdc++, libdraco, libminizip and libgcc_s, and
 * libXpm five X11 libraries (issue 29: the process's serial time). */
#ifndef RTSH_DYNLIB_H
#define RTSH_DYNLIB_H

#include <pthread.h>
#include <stdbool.h>
#include <stddef.h>

/* One function of a library: its name and where its address goes (the
 * address of a function pointer of the right type). */
typedef struct dynlib_fn {
	const char *name;
	void *fnp;
} dynlib_fn;

/* Opens the library `soname` (kept open for the process's life) and fills
 * every fns[i].fnp. False, with why ("NAME: dlerror's reason"), when the
 * library or one of its functions is missing; the pointers are then left
 * unusable. Not thread-safe by itself: call it under pthread_once. */
bool dynlib_open(const char *soname, const dynlib_fn *fns, size_t n, char *why, size_t wsize);

/* A library's state in the reader that opens it on first use: once runs
 * the reader's opener (which sets ok and why by dynlib_open); static,
 * initialised with DYNLIB_LAZY. */
typedef struct dynlib_lazy {
	pthread_once_t once;
	bool ok;
	char why[256];
} dynlib_lazy;
#define DYNLIB_LAZY {PTHREAD_ONCE_INIT, false, ""}

#endif
