/* rtsh — libFuzzer target: the .rt reader, and the save -> reload round trip.
 *
 * Any input the reader accepts must save to text that the reader accepts
 * again, and saving that second scene must give the same bytes: whatever
 * loads, saves and reloads, which is what `save x.rt` promises. And the
 * keeping writer (rtkeep.h) must give back the very bytes it was given when
 * nothing was edited. A reader
 * crash, a leak, undefined behaviour, or a saved scene that does not reload
 * or reloads to something else stops the fuzzer (abort).
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rtsh/rtfile.h"
#include "rtsh/rtkeep.h"
#include "rtsh/scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* The scene as .rt text (malloc'ed, *len bytes); aborts if the writer fails. */
static char *save_text(const scene *s, size_t *len)
{
	char *buf = NULL;
	FILE *f = open_memstream(&buf, len);
	rt_error err;
	if (!f)
		abort();
	if (!rt_write(s, f, &err)) {
		fprintf(stderr, "round trip: the writer failed: %s\n", err.msg);
		abort();
	}
	fclose(f);
	return buf;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	/* Both dialects: the first byte chooses --strict for half the inputs. */
	rt_load_opts opts = {.strict = size > 0 && (data[0] & 1) && (data[0] & 0x80)};
	rt_error err;
	scene *s = rt_load_string((const char *)data, size, "fuzz.rt", &opts, &err);
	if (!s)
		return 0;
	/* Saving with no edit keeps the file byte for byte (rtkeep.h), unless
	 * the keeping writer gave up (NULL: it writes from scratch then). */
	size_t klen;
	char *kept = rt_keep_text(s, (const char *)data, size, &klen);
	if (kept && (klen != size || memcmp(kept, data, size) != 0)) {
		fprintf(stderr, "keeping writer: an unedited scene saves to other bytes\n--- saved:\n%.*s\n", (int)klen,
		        kept);
		abort();
	}
	free(kept);
	size_t alen, blen;
	char *a = save_text(s, &alen);
	rt_load_opts plain = {0};
	scene *s2 = rt_load_string(a, alen, "saved.rt", &plain, &err);
	if (!s2) {
		fprintf(stderr, "round trip: the saved scene does not load: %s:%d:%d: %s\n--- saved:\n%s",
		        err.file, err.line, err.col, err.msg, a);
		abort();
	}
	char *b = save_text(s2, &blen);
	if (alen != blen || memcmp(a, b, alen) != 0) {
		fprintf(stderr, "round trip: saving the reloaded scene gives other bytes\n--- first:\n%s--- second:\n%s",
		        a, b);
		abort();
	}
	free(a);
	free(b);
	scene_free(s2);
	scene_free(s);
	return 0;
}
