/* rtsh — the text of a full render's progress (progress.h). */
#include "shell/progress.h"

#include <math.h>
#include <stdio.h>

void progress_duration(double s, char *buf, size_t size)
{
	if (!(s >= 0))
		s = 0;
	if (s < 1)
		snprintf(buf, size, "%.0f ms", s * 1000);
	else if (s < 10)
		snprintf(buf, size, "%.1f s", s);
	else if (s < 60)
		snprintf(buf, size, "%.0f s", s);
	else
		snprintf(buf, size, "%.0fm%02.0fs", floor(s / 60), floor(fmod(s, 60)));
}

void progress_text(const progress_state *p, int bar, char *buf, size_t size)
{
	double frac = p->total > 0 ? (double)p->done / (double)p->total : 1.0;
	if (frac > 1)
		frac = 1;
	char bars[64] = "";
	if (bar > 0) {
		if (bar > 60)
			bar = 60;
		int fill = (int)(frac * bar + 0.5);
		bars[0] = '[';
		for (int i = 0; i < bar; i++)
			bars[1 + i] = i < fill ? '#' : '.';
		bars[bar + 1] = ']';
		bars[bar + 2] = ' ';
		bars[bar + 3] = '\0';
	}
	char el[32], left[48] = "", speed[32] = "";
	progress_duration(p->elapsed, el, sizeof el);
	if (p->done > 0 && p->done < p->total) {
		char t[32];
		progress_duration(p->elapsed / frac - p->elapsed, t, sizeof t);
		snprintf(left, sizeof left, ", %s left", t);
	}
	double rays = frac * (double)p->w * (double)p->h * (double)p->samples;
	if (p->done > 0 && p->elapsed > 0)
		snprintf(speed, sizeof speed, " %.1f Mrays/s", rays / p->elapsed / 1e6);
	/* Samples per pixel done, on average: whole numbers while counting. */
	double spp = frac * p->samples;
	snprintf(buf, size, "%s%d%% %d/%d spp %s%s%s", bars, (int)(frac * 100), (int)spp, p->samples, el, left,
	         speed);
}

void progress_print(FILE *f, const progress_state *p)
{
	char line[160];
	progress_text(p, 30, line, sizeof line);
	fprintf(f, "\r%-78s", line);
	fflush(f);
}
