/* rtsh — libraries opened on first use (dynlib.h). */
#include "base/dynlib.h"

#include <dlfcn.h>
#include <stdio.h>
#include <string.h>

bool dynlib_open(const char *soname, const dynlib_fn *fns, size_t n, char *why, size_t wsize)
{
	void *h = dlopen(soname, RTLD_NOW | RTLD_LOCAL);
	if (!h) {
		const char *e = dlerror();
		snprintf(why, wsize, "%s", e ? e : soname);
		return false;
	}
	for (size_t i = 0; i < n; i++) {
		dlerror();
		void *s = dlsym(h, fns[i].name);
		if (!s) {
			const char *e = dlerror();
			snprintf(why, wsize, "%s: %s", soname, e ? e : fns[i].name);
			return false;
		}
		/* POSIX: a function's address fits a void * and back */
		memcpy(fns[i].fnp, &s, sizeof s);
	}
	why[0] = '\0';
	return true;
}
