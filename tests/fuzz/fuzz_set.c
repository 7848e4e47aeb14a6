/* Fuzz target: `--set KEY=VALUE` overrides on the essay's gate, one per
 * line of the input (split at the first '=', as the program splits its
 * argument), applied in order; an accepted scene then runs briefly. */
#include "fuzz_common.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_SETS 8

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	char *text = malloc(size + 1);
	if (!text)
		return 0;
	memcpy(text, data, size);
	text[size] = '\0';
	/* Arguments are C strings: a NUL ends the text, as it would argv. */
	bsim_override ov[MAX_SETS];
	int n = 0;
	for (char *line = text; line && n < MAX_SETS;) {
		char *next = strchr(line, '\n');
		if (next)
			*next++ = '\0';
		char *eq = strchr(line, '=');
		if (eq && eq != line) {
			*eq = '\0';
			ov[n] = (bsim_override){line, eq + 1, NULL};
			n++;
		}
		line = next;
	}
	char path[300];
	snprintf(path, sizeof path, "%s/gate.yaml", fuzz_dir());
	fuzz_load_and_run(path, ov, n);
	free(text);
	return 0;
}
