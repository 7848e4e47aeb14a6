/* Output directories with their journals; see session.h. */
#define _POSIX_C_SOURCE 200809L

#include "store/session.h"
#include "beamsim/trial_fields.h"
#include "store/index_html.h"
#include "util/file_read.h"

#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

int bsim_session_path(char *buf, size_t size, const char *dir, const char *name, bsim_error *err)
{
	int n = snprintf(buf, size, "%s/%s", dir, name);
	if (n < 0 || (size_t)n >= size)
		return bsim_error_set(err, BSIM_EFAIL, "%s/%s: path too long", dir, name);
	return BSIM_OK;
}

int bsim_session_open(bsim_session *s, const char *dir, bsim_outdir_mode mode, const char *command,
                      const bsim_outdir_spelling *spelling, const char *inputs, size_t record_size,
                      bsim_error *err)
{
	const char *opt = bsim_outdir_resume_option(spelling);
	struct stat st;
	memset(s, 0, sizeof *s);
	s->dir = dir;
	s->add = mode == BSIM_OUTDIR_ADD;
	if (bsim_outdir_open(&s->od, dir, mode, command, spelling, err) != BSIM_OK)
		return err->code;
	s->stage = bsim_outdir_stage(s->od);
	if (!inputs)
		return BSIM_OK;
	int rc = bsim_session_path(s->journal_path, sizeof s->journal_path, bsim_outdir_work(s->od),
	                           "journal", err);
	if (rc != BSIM_OK) {
		bsim_session_close(s, BSIM_EINPUT, NULL, NULL, err);
		return BSIM_EINPUT;
	}
	const int resume = mode == BSIM_OUTDIR_RESUME;
	int have = lstat(s->journal_path, &st) == 0;
	if (have && !S_ISREG(st.st_mode)) {
		/* The journal is opened for reading and writing: a FIFO in its
		 * place would block the first read for ever. */
		rc = bsim_error_set(err, BSIM_EINPUT,
		                    "%s: expected the journal of a stopped run, got %s",
		                    s->journal_path, bsim_file_kind(&st));
	} else if (resume && !have) {
		int finished = 0;
		bsim_error ignore;
		bsim_outdir_verify(dir, &finished, &ignore);
		rc = finished
		             ? bsim_error_set(err, BSIM_EINPUT,
		                              "%s: %s holds a finished run, nothing to resume (use "
		                              "%s instead to replace it)",
		                              opt, dir, bsim_outdir_overwrite_option(spelling))
		             : bsim_error_set(
		                       err, BSIM_EINPUT,
		                       "%s: %s holds no stopped run to resume (run without %s)",
		                       opt, dir, opt);
	} else if (resume) {
		rc = bsim_journal_resume(&s->journal, s->journal_path, bsim_trial_record_fields(),
		                         inputs, record_size, err);
		if (rc != BSIM_OK) {
			char msg[sizeof err->msg];
			snprintf(msg, sizeof msg, "%s", err->msg);
			bsim_error_set(err, rc, "%s: %s: %s", opt, dir, msg);
		}
	} else {
		/* a stopped run's journal is there only if the user asked to
		 * replace it (bsim_outdir_open refuses it otherwise) */
		rc = bsim_journal_create(&s->journal, s->journal_path, bsim_trial_record_fields(),
		                         inputs, record_size, err);
	}
	if (rc != BSIM_OK) {
		/* The refused journal is another run's: it stays. */
		s->journal_path[0] = '\0';
		bsim_session_close(s, rc, NULL, NULL, err);
	}
	return rc;
}

int bsim_session_defer(bsim_session *s, int rc, int deferrable, const bsim_error *err)
{
	if (rc == BSIM_OK || !deferrable)
		return rc;
	if (s->n_deferred++ == 0 && err)
		s->deferred = *err;
	s->deferred.code = rc;
	return BSIM_OK;
}

int bsim_session_close(bsim_session *s, int rc, const char *command, int *kept, bsim_error *err)
{
	bsim_error e;
	int keep = 0;
	if (rc == BSIM_OK && s->od) {
		/* a directory with figures gets its page, committed with them */
		int crc = bsim_index_html_write(s->stage, s->dir, s->add, command, &e);
		if (crc == BSIM_OK)
			crc = s->add ? bsim_outdir_add(s->od, command, &e)
			             : bsim_outdir_commit(s->od, command, &e);
		if (crc != BSIM_OK) {
			*err = e;
			rc = BSIM_EFAIL;
			keep = 1; /* the trials are done: a resumed run writes the files again */
		} else if (s->n_deferred > 0) {
			/* committed as a result; the run still failed */
			*err = s->deferred;
			rc = s->deferred.code;
			if (s->n_deferred > 1) {
				size_t used = strlen(err->msg);
				snprintf(err->msg + used, sizeof err->msg - used,
				         " (and %d more failures like it)", s->n_deferred - 1);
			}
		}
	} else if (rc == BSIM_ESTOPPED || s->done ||
	           (s->journal && bsim_journal_failed(s->journal))) {
		keep = 1;
	}
	/* A journal this session did not open (another run's, refused) is never
	 * touched; this session's is kept only to be resumed. */
	int ours = s->journal != NULL;
	if (s->journal && bsim_journal_close(s->journal, &e) != BSIM_OK && rc == BSIM_OK) {
		*err = e;
		rc = BSIM_EFAIL;
	}
	s->journal = NULL;
	if (ours && !keep)
		unlink(s->journal_path);
	if (kept)
		*kept = ours && keep;
	if (rc != BSIM_OK)
		bsim_outdir_explain(s->od, err->msg, sizeof err->msg);
	bsim_outdir_close(s->od);
	s->od = NULL;
	return rc;
}
