/* Several sweeps as one job with one journal; see sweep_batch.h. */
#define _POSIX_C_SOURCE 200809L

#include "store/sweep_batch.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "beamsim/backend_registry.h"
#include "beamsim/run_record.h"
#include "beamsim/trial_fields.h"
#include "store/part_dir.h"
#include "util/journal.h"

/* Every sweep's inputs, one after another (malloc'd; NULL and err). */
static char *batch_inputs(const char *command, const bsim_experiment *const *e,
                          const bsim_sweep_config *cfg, int n, bsim_error *err)
{
	char *text = NULL;
	size_t len = 0;
	FILE *f = open_memstream(&text, &len);
	if (!f) {
		bsim_error_set(err, BSIM_EFAIL, "out of memory");
		return NULL;
	}
	fprintf(f, "%s: %d sweeps\n", command, n);
	int rc = BSIM_OK;
	for (int s = 0; s < n && rc == BSIM_OK; s++) {
		const bsim_backend *b = cfg[s].backend ? cfg[s].backend : bsim_backend_default();
		bsim_options none = {0};
		const bsim_options *opts = cfg[s].opts ? cfg[s].opts : &none;
		bsim_run_record rec;
		bsim_run_record_fill(&rec, command, e[s], 1, &b, &opts, NULL, NULL);
		char *one = bsim_run_record_inputs(&rec, e[s], cfg[s].extra, cfg[s].n_extra, err);
		if (!one) {
			rc = err->code;
			break;
		}
		fprintf(f, "=== sweep %d\n%s", s, one);
		free(one);
	}
	if (fclose(f) != 0 && rc == BSIM_OK)
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	if (rc != BSIM_OK) {
		free(text);
		return NULL;
	}
	return text;
}

/* ---- a complete journal read once ----------------------------------------
 *
 * After a merge or an MPI job's parts the journal holds every trial, in the
 * order the parts sent them. Read once, its records go to a file at their
 * index's place (unlinked at once: nothing is left behind); each sweep then
 * gets a journal of its own records only, so the sweeps do not each read
 * the whole journal. */
typedef struct batch_spill {
	int fd;
	size_t size;
	long total;
	unsigned char *have; /* a bit per journal index */
	int failed;          /* errno of a failed write */
} batch_spill;

static int spill_take(void *user, uint64_t index, const void *payload)
{
	batch_spill *sp = user;
	if (index >= (uint64_t)sp->total)
		return 1;
	if (pwrite(sp->fd, payload, sp->size, (off_t)(index * sp->size)) != (ssize_t)sp->size) {
		sp->failed = errno ? errno : EIO;
		return 1;
	}
	sp->have[index / 8] |= (unsigned char)(1u << (index % 8));
	return 0;
}

static int spill_fill(batch_spill *sp, const char *journal, const char *inputs, bsim_error *err)
{
	char path[BSIM_PATH_MAX + 16];
	snprintf(path, sizeof path, "%s.byindex", journal);
	sp->fd = open(path, O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
	if (sp->fd < 0)
		return bsim_error_set(err, BSIM_EFAIL, "%s: cannot create (%s)", path,
		                      strerror(errno));
	unlink(path);
	sp->have = calloc((size_t)sp->total / 8 + 1, 1);
	if (!sp->have)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	long n = 0, cut = 0;
	int rc = bsim_journal_read(journal, bsim_trial_record_fields(), inputs, sp->size,
	                           spill_take, sp, &n, &cut, err);
	if (rc == BSIM_OK && sp->failed)
		rc = bsim_error_set(err, BSIM_EFAIL, "%s: cannot write (%s)", path,
		                    strerror(sp->failed));
	return rc;
}

/* The records first .. end - 1 as a journal at path, opened to be replayed. */
static int spill_journal(const batch_spill *sp, const char *path, const char *inputs, long first,
                         long end, bsim_journal **out, bsim_error *err)
{
	bsim_journal *j = NULL;
	*out = NULL;
	unsigned char *buf = malloc(sp->size);
	int rc = buf ? bsim_journal_create(&j, path, bsim_trial_record_fields(), inputs, sp->size,
	                                   err)
	             : bsim_error_set(err, BSIM_EFAIL, "out of memory");
	for (long i = first; rc == BSIM_OK && i < end; i++) {
		if (!(sp->have[i / 8] & (1u << (i % 8))))
			continue;
		if (pread(sp->fd, buf, sp->size, (off_t)((size_t)i * sp->size)) !=
		    (ssize_t)sp->size)
			rc = bsim_error_set(err, BSIM_EFAIL,
			                    "cannot read back the journal's trial %ld (%s)", i,
			                    strerror(errno));
		else
			rc = bsim_journal_append(j, (uint64_t)i, buf, err);
	}
	free(buf);
	bsim_error ignore;
	int closed = bsim_journal_close(j, rc == BSIM_OK ? err : &ignore);
	if (rc == BSIM_OK)
		rc = closed;
	if (rc == BSIM_OK)
		rc = bsim_journal_resume(out, path, bsim_trial_record_fields(), inputs, sp->size,
		                         err);
	return rc;
}

/* Progress over every sweep: the sweeps before this one counted whole. */
typedef struct batch_ctx {
	sweep_batch *b;
	const bsim_experiment *const *e;
	const bsim_sweep_config *cfg;
	int n;
	const long *first; /* each sweep's first journal index */
	long total;        /* trials of every sweep */
	bsim_journal *journal;
	const bsim_sweep_part *real; /* the part this process runs */
	int last;                    /* running the last sweep */
	long sweep_total;            /* what the sweep's progress counts up to */
	double *cpu;                 /* NULL, or per sweep */
} batch_ctx;

static void batch_progress(void *user, long done, long total)
{
	batch_ctx *c = user;
	c->sweep_total = total;
	long d = c->b->done_before + done;
	if (c->b->progress)
		c->b->progress(c->b->progress_user, d < c->b->total ? d : c->b->total, c->b->total);
}

/* Sweep s's configuration: the batch's journal index, journal and
 * progress. */
static bsim_sweep_config batch_cfg(batch_ctx *c, int s, bsim_journal *journal)
{
	bsim_sweep_config k = c->cfg[s];
	k.journal = journal;
	k.journal_first = c->first[s];
	k.journal_total = c->total;
	k.results_only = 1;
	k.progress = batch_progress;
	k.progress_user = c;
	k.stop = c->b->stop;
	k.sink = NULL;
	k.keep = 0;
	return k;
}

static int batch_record(void *user, long index, const void *payload, bsim_error *err)
{
	batch_ctx *c = user;
	return c->real->record(c->real->user, index, payload, err);
}

/* The parts wait for each other once, after the last sweep: between
 * sweeps a part only hands on what it has. */
static int batch_collect(void *user, int wait, bsim_sweep_accept_fn accept, void *ctx,
                         bsim_error *err)
{
	batch_ctx *c = user;
	return c->real->collect(c->real->user, wait && c->last, accept, ctx, err);
}

/* This process's part of every sweep (part_dir_run_fn). */
static int batch_parts(void *user, const bsim_sweep_part *part, bsim_error *err)
{
	batch_ctx *c = user;
	c->real = part;
	bsim_sweep_part p = *part;
	p.record = part->record ? batch_record : NULL;
	p.collect = part->collect ? batch_collect : NULL;
	p.user = c;
	/* progress: this part's trials, or with collect every part's */
	sweep_batch *b = c->b;
	b->done_before = 0;
	b->total = 0;
	for (long j = 0; j < c->total; j++) {
		int done = part->done && (part->done[j / 8] & (1u << (j % 8)));
		b->total += part->collect ? 1 : j % part->count == part->index && !done;
	}
	int rc = BSIM_OK;
	for (int s = 0; s < c->n && rc == BSIM_OK; s++) {
		bsim_sweep_config k = batch_cfg(c, s, c->journal);
		c->last = s == c->n - 1;
		c->sweep_total = 0;
		clock_t c0 = clock();
		rc = bsim_sweep_run_part(c->e[s], &k, &p, err);
		if (c->cpu)
			c->cpu[s] += (double)(clock() - c0) / CLOCKS_PER_SEC;
		b->done_before += c->sweep_total;
	}
	return rc;
}

int bsim_sweep_batch_run(sweep_batch *b, const bsim_experiment *const *e,
                         const bsim_sweep_config *cfg, int n, bsim_sweep_result *res,
                         bsim_error *err)
{
	return bsim_sweep_batch_run_cpu(b, e, cfg, n, res, NULL, err);
}

int bsim_sweep_batch_run_cpu(sweep_batch *b, const bsim_experiment *const *e,
                             const bsim_sweep_config *cfg, int n, bsim_sweep_result *res,
                             double *cpu, bsim_error *err)
{
	b->open = b->writes = 0;
	b->journal[0] = '\0';
	memset(res, 0, (size_t)n * sizeof *res);
	long *first = calloc((size_t)n + 1, sizeof *first);
	if (!first)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	for (int s = 0; s < n; s++)
		first[s + 1] = first[s] + (long)e[s]->n_groups * e[s]->trials;
	for (int s = 0; cpu && s < n; s++)
		cpu[s] = 0.0;
	batch_ctx c = {b, e, cfg, n, first, first[n], NULL, NULL, 0, 0, cpu};
	const bsim_sweep_spread *sp = b->spread;
	int merge = sp && sp->n_merge > 0;
	int spread = sp && !merge ? sp->spread : BSIM_SPREAD_NONE;
	const size_t size = bsim_sweep_record_size(0);
	char *inputs = NULL;
	int rc = BSIM_OK;
	if (b->out || spread != BSIM_SPREAD_NONE) {
		inputs = batch_inputs(b->command, e, cfg, n, err);
		rc = inputs ? BSIM_OK : err->code;
	}
	if (rc == BSIM_OK && merge && b->resume)
		rc = bsim_error_set(err, BSIM_EINPUT, "merge: --resume does not apply");
	part_dir_spread pds = {
	        spread,  sp ? &sp->part : NULL, sp ? sp->agree : NULL, b->command, size,
	        c.total, sp ? sp->argc : 0,     sp ? sp->argv : NULL};
	if (rc == BSIM_OK && spread == BSIM_SPREAD_SEND) {
		/* another rank's part: its records go to rank 0, no directory */
		rc = bsim_part_dir_spread_run(&pds, inputs, NULL, batch_parts, &c, err);
		free(inputs);
		free(first);
		return rc;
	}
	if (rc == BSIM_OK && b->out) {
		rc = bsim_session_open(&b->ss, b->out, bsim_session_mode(b->resume, b->overwrite),
		                       b->command, b->spelling, inputs, size, err);
		b->open = rc == BSIM_OK;
		c.journal = b->open ? b->ss.journal : NULL;
	}
	if (rc == BSIM_OK && merge) {
		char run[17];
		bsim_part_dir_run_id(inputs, run);
		rc = bsim_part_dir_join(sp->merge, sp->n_merge, b->command, run, inputs, size,
		                        c.total, b->ss.journal, err);
		if (rc == BSIM_OK)
			rc = bsim_part_dir_journal_reopen(&b->ss, inputs, size, err);
	} else if (rc == BSIM_OK && spread != BSIM_SPREAD_NONE) {
		rc = bsim_part_dir_spread_run(&pds, inputs, &b->ss, batch_parts, &c, err);
		if (spread == BSIM_SPREAD_SHARD) {
			/* the part directory is written: the caller commits it */
			free(inputs);
			free(first);
			return rc;
		}
		if (rc == BSIM_OK)
			rc = bsim_part_dir_journal_reopen(&b->ss, inputs, size, err);
	}
	/* Every sweep from the journal, the trials it lacks run here. A new
	 * journal holds no record of a sweep before it runs; a resumed one is
	 * read from its start for each sweep; a complete one (a merge's, an
	 * MPI job's) once, each sweep then reading its own records only. */
	const int complete = b->open && (merge || spread == BSIM_SPREAD_GATHER);
	batch_spill spill = {-1, size, c.total, NULL, 0};
	char own_path[BSIM_PATH_MAX + 16] = "";
	if (rc == BSIM_OK && complete) {
		snprintf(own_path, sizeof own_path, "%s.sweep", b->ss.journal_path);
		rc = spill_fill(&spill, b->ss.journal_path, inputs, err);
	}
	b->done_before = 0;
	b->total = c.total;
	for (int s = 0; s < n && rc == BSIM_OK; s++) {
		bsim_journal *own = NULL;
		clock_t c0 = clock();
		if (complete)
			rc = spill_journal(&spill, own_path, inputs, first[s], first[s + 1], &own,
			                   err);
		else if (s > 0 && b->open && b->resume)
			rc = bsim_part_dir_journal_reopen(&b->ss, inputs, size, err);
		bsim_sweep_config k = batch_cfg(&c, s, own ? own : b->open ? b->ss.journal : NULL);
		c.sweep_total = 0;
		if (rc == BSIM_OK)
			rc = bsim_sweep_run(e[s], &k, &res[s], err);
		if (own) {
			bsim_error ignore;
			bsim_journal_close(own, &ignore);
			unlink(own_path);
		}
		if (cpu)
			cpu[s] += (double)(clock() - c0) / CLOCKS_PER_SEC;
		b->done_before += first[s + 1] - first[s];
	}
	if (spill.fd >= 0)
		close(spill.fd);
	free(spill.have);
	if (rc == BSIM_OK) {
		b->ss.done = 1;
		b->writes = 1;
	} else {
		for (int s = 0; s < n; s++)
			bsim_sweep_result_free(&res[s]);
	}
	free(inputs);
	free(first);
	return rc;
}

int bsim_sweep_batch_end(sweep_batch *b, int rc, bsim_error *err)
{
	if (!b->open)
		return rc;
	int kept = 0;
	rc = bsim_session_close(&b->ss, rc, b->command, &kept, err);
	b->open = 0;
	if (kept)
		snprintf(b->journal, sizeof b->journal, "%s", b->ss.journal_path);
	return rc;
}
