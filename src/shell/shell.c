/* rtsh — placeholder until the shell lands (issue 3). */
#include <stdio.h>

#include "shell/options.h"

int shell_main(const rtsh_options *o)
{
	(void)o;
	fputs("rtsh: the interactive shell is not built yet; use rtsh SCENE.rt -o OUT\n", stderr);
	return 2;
}
