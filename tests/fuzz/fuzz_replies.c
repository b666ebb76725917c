/* rtsh — libFuzzer target: the terminal's answers (term/out.c).
 *
 * DSR, DA1, DECRQSS and XTGETTCAP answers arrive on the terminal's input,
 * mixed with the keys typed, from outside rtsh (a hostile or garbled
 * terminal, a man in the middle of a serial line). A scheduler that has
 * sent its start-up questions reads the input in pieces (cut where the
 * input's first bytes say) at times that advance by the next byte, pumped
 * in between. Besides crashes, leaks and UB, the target checks that
 * answers can only take bytes away: the keys given back are a subsequence
 * of the input, so nothing a terminal answers can type a command that was
 * not typed.
 */
#include <fcntl.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base/abuf.h"
#include "term/out.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* True when k[0..kn) is a subsequence of s[0..sn). */
static int subsequence(const char *k, size_t kn, const uint8_t *s, size_t sn)
{
	size_t i = 0;
	for (size_t j = 0; j < sn && i < kn; j++)
		if ((uint8_t)k[i] == s[j])
			i++;
	return i == kn;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	static int null = -1;
	if (null < 0)
		null = open("/dev/null", O_WRONLY);
	if (size < 2)
		return 0;
	uint8_t cut = data[0], step = data[1];
	data += 2;
	size -= 2;
	termout *o = termout_new(null);
	if (!o)
		return 0;
	double now = 1.0;
	termout_probe(o, cut & 1, now);
	abuf keys;
	abuf_init(&keys);
	size_t piece = (size_t)(cut >> 1) + 1;
	for (size_t at = 0; at < size; at += piece) {
		size_t n = size - at < piece ? size - at : piece;
		termout_input(o, (const char *)data + at, n, now, &keys);
		now += step / 64.0; /* up to 4 s between pieces: time-outs fire */
		termout_pump(o, now, &keys);
		(void)termout_wait(o, now);
	}
	termout_pump(o, now + 10, &keys);
	(void)termout_notice(o);
	(void)termout_truecolor(o);
	(void)termout_get_stats(o);
	if (!keys.failed && !subsequence(keys.b, keys.len, data, size))
		abort(); /* an answer made up keys */
	abuf_free(&keys);
	termout_free(o);
	return 0;
}
