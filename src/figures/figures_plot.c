/* The figures of a directory drawn into a directory (beamsim plot DIR); see
 * beamsim/figures.h. A reader of DIR: a mix of two runs' files is refused.
 * The figures are written into a staging area and join the directory's
 * set at the end: into DIR itself, beside its files; into another
 * directory, replacing what a previous plot left there. */
#include "beamsim/figures.h"

#include <stdlib.h>
#include <string.h>

#include "store/outdir.h"
#include "store/session.h"

int bsim_figures_plot(const char *dir, const bsim_figures_def *def, bsim_figures_result *out,
                      bsim_error *err)
{
	int has_manifest = 0;
	memset(out, 0, sizeof *out);
	if (bsim_outdir_verify(dir, &has_manifest, err) != BSIM_OK)
		return BSIM_EINPUT;
	const char *to = def->out ? def->out : dir;
	bsim_session ss;
	/* Into DIR the figures join its result; into another directory they
	 * are a result of their own. */
	bsim_outdir_mode mode = def->out ? bsim_session_mode(0, def->overwrite) : BSIM_OUTDIR_ADD;
	int rc = bsim_session_open(&ss, to, mode, "plot", NULL, NULL, 0, err);
	if (rc != BSIM_OK)
		return rc;
	bsim_figures_def d = *def;
	d.out = ss.stage;
	rc = bsim_figures_draw(dir, &d, out, err);
	/* the figures drawn and those gnuplot failed on are committed */
	rc = bsim_session_defer(&ss, rc, out->failed > 0, err);
	/* Paths and notes name the figures where they will be. */
	size_t stage_len = strlen(ss.stage), to_len = strlen(to);
	for (int i = 0; rc == BSIM_OK && i < out->n; i++) {
		const char *name = out->paths[i];
		if (strncmp(name, ss.stage, stage_len) != 0)
			continue;
		char *p = malloc(to_len + strlen(name + stage_len) + 1);
		if (!p) {
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
			break;
		}
		memcpy(p, to, to_len);
		strcpy(p + to_len, name + stage_len);
		free(out->paths[i]);
		out->paths[i] = p;
	}
	for (int i = 0; rc == BSIM_OK && i < out->n_notes; i++)
		bsim_outdir_explain(ss.od, out->notes[i], strlen(out->notes[i]) + 1);
	rc = bsim_session_close(&ss, rc, "plot", NULL, err);
	if (rc != BSIM_OK)
		bsim_figures_result_free(out);
	return rc;
}
