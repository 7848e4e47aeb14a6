/* The files a run wrote, from its manifest; see cli_wrote.h. */
#define _POSIX_C_SOURCE 200809L

#include "cli/cli_wrote.h"

#include <stdio.h>
#include <string.h>

#include "cli/cli_common.h"
#include "store/outdir.h"

/* Files by name (below any subdirectory, as compare's sides). */
static const struct {
	const char *name, *what;
} known[] = {
        {"summary.json", "per group: counts, p_traverse, 95% interval"},
        {"trials.csv", "one row per trial: outcome, type, ledger"},
        {"trajectories.csv", "the kept trajectories, group by group"},
        {"survival.csv", "per group: Kaplan-Meier survival in the gate"},
        {"horizon.csv", "per group: the outcomes by each time h, with intervals"},
        {"run.json", "the command and its inputs, for beamsim regress"},
        {"lattice_map.csv", "each gate's place and beam stiffnesses"},
        {"final_locations.csv", "per group: where the trials ended"},
        {"transitions.csv", "per group: gate-to-gate steps counted"},
        {"gate_entries.csv", "every gate entry of every trial"},
        {"beam_peaks.csv", "each beam's largest deflection per trial"},
        {"trajectory.csv", "the trial's state over time"},
        {"ledger.csv", "the trial's energy ledger over time"},
        {"report.md", "the comparison, to read"},
        {"report.json", "the comparison's numbers"},
        {"pairs.csv", "one row per trial: both sides' outcomes"},
        {"regress.md", "the regression check, to read"},
        {"regress.json", "the regression check's numbers"},
        {"landscape.csv", "the energy landscape on its grid"},
        {"landscape.json", "the grid, the start and every pass"},
        {"kramers.csv", "escape rates against barrier and noise"},
        {"kramers.json", "the Kramers fit"},
        {"accuracy.csv", "error and cost of each backend setting"},
        {"accuracy.md", "the accuracy tables, to read"},
        {"equal_error.csv", "cost at equal error per backend"},
        {"sensitivity.csv", "the sensitivity of each essay parameter"},
        {"essay.csv", "each essay figure's value beside beamsim's"},
        {"essay.md", "the essay check, to read"},
        {"prediction.csv", "every final location's probability"},
        {"prediction_gates.csv", "the distribution of gates visited"},
        {"validate.json", "the chain against simulation: TV, cost"},
        {"validate.csv", "per group: every location, simulated and chained"},
        {"gates.csv", "per group: gates visited, simulated and chained"},
        {"markov.json", "the settings the maps were built with"},
        {"index.html", "every figure with a caption, for a browser"},
};

static int ends_with(const char *s, const char *tail)
{
	size_t n = strlen(s), m = strlen(tail);
	return n >= m && strcmp(s + n - m, tail) == 0;
}

const char *cli_wrote_what(const char *path)
{
	const char *base = strrchr(path, '/');
	base = base ? base + 1 : path;
	if (strncmp(path, "inputs/", 7) == 0 || strstr(path, "/inputs/"))
		return "a copy of an input, for beamsim regress";
	for (size_t i = 0; i < sizeof known / sizeof known[0]; i++)
		if (strcmp(base, known[i].name) == 0)
			return known[i].what;
	if (ends_with(base, ".png") || ends_with(base, ".svg"))
		return "a figure";
	if (ends_with(base, ".gp"))
		return "the figure's gnuplot script";
	if (ends_with(base, ".dat"))
		return "the figure's data";
	if (strncmp(base, "map_", 4) == 0 && ends_with(base, ".exits.csv"))
		return "every single gate's entry and exit state (--entries self)";
	if (strncmp(base, "map_", 4) == 0 && ends_with(base, ".csv"))
		return "a single-gate map: entry bin, exit bin, count";
	if (strncmp(base, "map_", 4) == 0 && ends_with(base, ".key"))
		return "everything that map depends on";
	if (strncmp(base, "map_", 4) == 0 && ends_with(base, ".cost"))
		return "the CPU time that map took";
	if (ends_with(base, ".mp4"))
		return "the video";
	return "";
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
		char buf[160];
		const char *what = ends_with(paths[i], ".mat")
		                           ? mat_what(paths[i], paths, n, buf, sizeof buf)
		                           : cli_wrote_what(paths[i]);
		if (what[0])
			fprintf(f, "  %-*s  %s\n", w, cli_path(paths[i]), what);
		else
			fprintf(f, "  %s\n", cli_path(paths[i]));
	}
	bsim_outdir_files_free(paths, n);
}
