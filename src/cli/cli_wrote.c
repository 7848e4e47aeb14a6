/* The files a run wrote, from its manifest; see cli_wrote.h. */
#define _POSIX_C_SOURCE 200809L

#include "cli/cli_wrote.h"

#include <stdio.h>
#include <string.h>

#include "cli/cli_common.h"
#include "store/index_html.h"
#include "store/outdir.h"

static int ends_with(const char *s, const char *tail)
{
	size_t n = strlen(s), m = strlen(tail);
	return n >= m && strcmp(s + n - m, tail) == 0;
}

const char *cli_wrote_what(const char *path, char *buf, size_t size)
{
	const char *base = strrchr(path, '/');
	base = base ? base + 1 : path;
	if (strncmp(path, "inputs/", 7) == 0 || strstr(path, "/inputs/"))
		return "a copy of an input, for beamsim regress";
	/* a figure's own caption would make a long line: index.html has it */
	if (ends_with(base, ".png") || ends_with(base, ".svg"))
		return "a figure";
	bsim_index_caption(base, buf, size);
	return buf;
}

/* A .mat's words: the twin of the .csv or .json of its name among paths,
 * in buf. */
static const char *mat_what(const char *mat, char **paths, size_t n, char *buf, size_t size)
{
	size_t stem = strlen(mat) - 4;
	for (size_t i = 0; i < n; i++)
		if (strncmp(paths[i], mat, stem) == 0 && (strcmp(paths[i] + stem, ".csv") == 0 ||
		                                          strcmp(paths[i] + stem, ".json") == 0)) {
			const char *base = strrchr(paths[i], '/');
			snprintf(buf, size, "%s for MATLAB", base ? base + 1 : paths[i]);
			return buf;
		}
	return "MATLAB data";
}

void cli_wrote(FILE *f, const char *dir)
{
	char **paths;
	size_t n;
	bsim_error err;
	fprintf(f, "wrote %s/ (manifest.json lists these):\n", cli_path(dir));
	if (bsim_outdir_files(dir, &paths, &n, &err) != BSIM_OK)
		return;
	int w = 0;
	for (size_t i = 0; i < n; i++) {
		int len = (int)strlen(paths[i]);
		w = len > w && len <= 40 ? len : w;
	}
	for (size_t i = 0; i < n; i++) {
		char buf[512];
		const char *what = ends_with(paths[i], ".mat")
		                           ? mat_what(paths[i], paths, n, buf, sizeof buf)
		                           : cli_wrote_what(paths[i], buf, sizeof buf);
		if (what[0])
			fprintf(f, "  %-*s  %s\n", w, cli_path(paths[i]), what);
		else
			fprintf(f, "  %s\n", cli_path(paths[i]));
	}
	bsim_outdir_files_free(paths, n);
}
