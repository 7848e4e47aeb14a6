/* Part directories of a sweep split into processes; see part_dir.h. */
#define _POSIX_C_SOURCE 200809L

#include "store/part_dir.h"

#include <errno.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/limits.h"
#include "beamsim/output.h"
#include "beamsim/sweep_dir.h"
#include "beamsim/trial_fields.h"
#include "store/session.h"
#include "util/hash.h"
#include "util/json.h"
#include "util/yaml_doc.h"

void bsim_part_dir_run_id(const char *inputs, char out[17])
{
	snprintf(out, 17, "%016" PRIx64,
	         bsim_hash_fnv1a64(inputs, strlen(inputs), HASH_FNV1A64_SEED));
}

int bsim_part_dir_write(const char *stage, const char *command, int index, int count,
                        const char *run, long total, long records, int argc, char *const *argv,
                        bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	if (bsim_session_path(path, sizeof path, stage, "part.json", err))
		return BSIM_EFAIL;
	FILE *f = fopen(path, "w");
	if (!f)
		return bsim_error_set(err, BSIM_EFAIL, "%s: cannot write (%s)", path,
		                      strerror(errno));
	fputs("{\n  \"command\": ", f);
	bsim_json_string(f, command);
	fprintf(f, ",\n  \"part\": %d,\n  \"parts\": %d,\n  \"run\": \"%s\",\n", index, count, run);
	fprintf(f, "  \"trials\": %ld,\n  \"records\": %ld,\n  \"argv\": [", total, records);
	for (int i = 0; i < argc; i++) {
		fputs(i ? ", " : "", f);
		bsim_json_string(f, argv[i]);
	}
	fputs("]\n}\n", f);
	int bad = ferror(f);
	if (fclose(f) != 0 || bad)
		return bsim_error_set(err, BSIM_EFAIL, "%s: cannot write (%s)", path,
		                      strerror(errno));
	return BSIM_OK;
}

void bsim_sweep_dir_part_free(bsim_sweep_dir_part *p)
{
	for (int i = 0; p->argv && i < p->argc; i++)
		free(p->argv[i]);
	free(p->argv);
	memset(p, 0, sizeof *p);
}

static int part_text(const ydoc *d, struct fy_node *root, const char *field, char *buf, size_t size,
                     bsim_error *err)
{
	struct fy_node *n = bsim_ydoc_lookup(root, field);
	size_t len;
	const char *t = n && fy_node_is_scalar(n) ? fy_node_get_scalar(n, &len) : NULL;
	if (!t || len == 0 || len >= size)
		return bsim_ydoc_expected(d, n, NULL, field, "a string", err);
	memcpy(buf, t, len);
	buf[len] = '\0';
	return BSIM_OK;
}

static int part_long(const ydoc *d, struct fy_node *root, const char *field, long lo, long *out,
                     bsim_error *err)
{
	struct fy_node *n = bsim_ydoc_lookup(root, field);
	double x;
	if (!n || bsim_ydoc_number(n, &x) != YDOC_NUM_OK || x < lo || x > 1e15 || x != (long)x)
		return bsim_ydoc_expected(d, n, NULL, field, lo ? "a whole number >= 1" : "a count",
		                          err);
	*out = (long)x;
	return BSIM_OK;
}

int bsim_sweep_dir_part_read(const char *dir, bsim_sweep_dir_part *p, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	ydoc d;
	memset(p, 0, sizeof *p);
	if (bsim_session_path(path, sizeof path, dir, "part.json", err))
		return BSIM_EINPUT;
	if (bsim_ydoc_load_own(&d, path, err) != BSIM_OK) {
		char msg[sizeof err->msg];
		snprintf(msg, sizeof msg, "%s", err->msg);
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s (is %s the --out directory of sweep --shard I/N?)", msg,
		                      dir);
	}
	struct fy_node *root = fy_document_root(d.fyd);
	long index = 0, count = 0;
	int rc = part_text(&d, root, "command", p->command, sizeof p->command, err);
	if (!rc)
		rc = part_long(&d, root, "part", 1, &index, err);
	if (!rc)
		rc = part_long(&d, root, "parts", 1, &count, err);
	if (!rc && (index > count || count > 1000000))
		rc = bsim_ydoc_expected(&d, bsim_ydoc_lookup(root, "part"), NULL, "part",
		                        "a part from 1 to parts", err);
	if (!rc)
		rc = part_text(&d, root, "run", p->run, sizeof p->run, err);
	if (!rc)
		rc = part_long(&d, root, "records", 0, &p->records, err);
	struct fy_node *av = bsim_ydoc_lookup(root, "argv");
	if (!rc && (!av || !fy_node_is_sequence(av) || fy_node_sequence_item_count(av) < 1))
		rc = bsim_ydoc_expected(&d, av, NULL, "argv", "the command line, a list of strings",
		                        err);
	if (!rc) {
		int n = fy_node_sequence_item_count(av);
		p->argv = calloc((size_t)n + 1, sizeof *p->argv);
		if (!p->argv)
			rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
		for (int i = 0; !rc && i < n; i++) {
			struct fy_node *a = fy_node_sequence_get_by_index(av, i);
			size_t len;
			const char *t =
			        a && fy_node_is_scalar(a) ? fy_node_get_scalar(a, &len) : NULL;
			if (!t) {
				rc = bsim_ydoc_expected(&d, a, NULL, "argv", "a list of strings",
				                        err);
				break;
			}
			p->argv[i] = strndup(t, len);
			if (!p->argv[i])
				rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
			p->argc = i + 1;
		}
	}
	bsim_ydoc_free(&d);
	p->index = (int)index;
	p->count = (int)count;
	if (rc != BSIM_OK)
		bsim_sweep_dir_part_free(p);
	return rc;
}

/* One part's journal being read into the whole's. */
typedef struct join_ctx {
	const char *dir;
	int index, count; /* 0-based */
	long total, distinct;
	unsigned char *seen; /* a bit per trial */
	bsim_journal *j;
	bsim_error *err;
	int failed;
} join_ctx;

static int join_take(void *user, uint64_t index, const void *payload)
{
	join_ctx *c = user;
	if (index >= (uint64_t)c->total || (long)(index % (uint64_t)c->count) != c->index) {
		c->failed = bsim_error_set(c->err, BSIM_EINPUT,
		                           "%s/part.journal: holds trial %" PRIu64
		                           ", which is not one of part %d of %d's",
		                           c->dir, index, c->index + 1, c->count);
		return 1;
	}
	if (bsim_journal_append(c->j, index, payload, c->err) != BSIM_OK) {
		c->failed = BSIM_EFAIL;
		return 1;
	}
	unsigned char bit = (unsigned char)(1u << (index % 8));
	c->distinct += !(c->seen[index / 8] & bit);
	c->seen[index / 8] |= bit;
	return 0;
}

int bsim_part_dir_check(const char *const *dirs, int n, const char *command, const char *run,
                        bsim_sweep_dir_part *parts, bsim_error *err)
{
	int rc = BSIM_OK;
	/* The run the caller gives is the one the first part's command line
	 * makes of the inputs now; the first part is checked against it, the
	 * others against the first. */
	const char *given = run;
	for (int k = 0; rc == BSIM_OK && k < n; k++) {
		bsim_sweep_dir_part *p = &parts[k];
		rc = bsim_sweep_dir_part_read(dirs[k], p, err);
		if (rc != BSIM_OK)
			break;
		if (!run)
			run = parts[0].run;
		if (strcmp(p->command, command) != 0)
			rc = bsim_error_set(err, BSIM_EINPUT, "%s: a part of a %s, not of a %s",
			                    dirs[k], p->command, command);
		else if (strcmp(p->run, run) != 0 && k == 0 && given)
			rc = bsim_error_set(err, BSIM_EINPUT,
			                    "%s/part.json says part %d of %d of run %s, but its "
			                    "command line gives run %s of the inputs as they are "
			                    "now: the file was edited, or the inputs (experiment, "
			                    "scene) changed since the part ran",
			                    dirs[k], p->index, p->count, p->run, run);
		else if (strcmp(p->run, run) != 0)
			rc = bsim_error_set(err, BSIM_EINPUT,
			                    "%s is part %d of %d of run %s, not of run %s (%s's): "
			                    "parts of different runs",
			                    dirs[k], p->index, p->count, p->run, run, dirs[0]);
		else if (p->count != parts[0].count)
			rc = bsim_error_set(
			        err, BSIM_EINPUT, "%s is part %d of %d, %s part %d of %d", dirs[k],
			        p->index, p->count, dirs[0], parts[0].index, parts[0].count);
		for (int q = 0; rc == BSIM_OK && q < k; q++)
			if (parts[q].index == p->index)
				rc = bsim_error_set(err, BSIM_EINPUT,
				                    "%s and %s are both part %d of %d", dirs[q],
				                    dirs[k], p->index, p->count);
	}
	int count = rc == BSIM_OK ? parts[0].count : 0;
	if (rc == BSIM_OK && n != count) {
		/* the first missing part, and how many are */
		int first = 0, missing = 0;
		for (int i = count; i >= 1; i--) {
			int have = 0;
			for (int k = 0; k < n; k++)
				have |= parts[k].index == i;
			if (!have) {
				first = i;
				missing++;
			}
		}
		rc = bsim_error_set(err, BSIM_EINPUT,
		                    "part %d of %d is missing (%d of the %d parts of run %s are "
		                    "missing; each part's directory is needed once)",
		                    first, count, missing, count, run);
	}
	return rc;
}

int bsim_part_dir_join(const char *const *dirs, int n, const char *command, const char *run,
                       const char *inputs, size_t record_size, long total, bsim_journal *j,
                       bsim_error *err)
{
	bsim_sweep_dir_part *parts = calloc((size_t)n, sizeof *parts);
	if (!parts)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	int rc = bsim_part_dir_check(dirs, n, command, run, parts, err);
	int count = rc == BSIM_OK ? parts[0].count : 0;
	unsigned char *seen = rc == BSIM_OK ? calloc((size_t)total / 8 + 1, 1) : NULL;
	if (rc == BSIM_OK && !seen)
		rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
	for (int k = 0; rc == BSIM_OK && k < n; k++) {
		char path[BSIM_PATH_MAX];
		join_ctx c = {dirs[k], parts[k].index - 1, count, total, 0, seen, j, err, 0};
		long records = 0, cut = 0;
		if (bsim_session_path(path, sizeof path, dirs[k], "part.journal", err))
			rc = BSIM_EINPUT;
		if (rc == BSIM_OK)
			rc = bsim_journal_read(path, bsim_trial_record_fields(), inputs,
			                       record_size, join_take, &c, &records, &cut, err);
		if (rc == BSIM_OK && c.failed)
			rc = c.failed;
		else if (rc == BSIM_OK && (cut > 0 || c.distinct != parts[k].records))
			rc = bsim_error_set(err, BSIM_EINPUT,
			                    "%s: holds %ld of the %ld trials its part.json "
			                    "counts%s",
			                    path, c.distinct, parts[k].records,
			                    cut > 0 ? ", then a damaged record" : "");
	}
	free(seen);
	for (int k = 0; k < n; k++)
		bsim_sweep_dir_part_free(&parts[k]);
	free(parts);
	return rc;
}

/* A journal record marked in the done bits (bsim_journal_fn). */
static int mark_done(void *user, uint64_t index, const void *payload)
{
	(void)payload;
	unsigned char **bits = user;
	(*bits)[index / 8] |= (unsigned char)(1u << (index % 8));
	return 0;
}

int bsim_part_dir_spread_run(const part_dir_spread *sp, const char *inputs, bsim_session *ss,
                             part_dir_run_fn run, void *user, bsim_error *err)
{
	long total = sp->total;
	size_t bytes = (size_t)total / 8 + 1;
	unsigned char *done = calloc(bytes, 1);
	if (!done)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	long kept = 0, cut = 0;
	int rc = BSIM_OK;
	if (ss && ss->journal) {
		unsigned char *bits = done;
		rc = bsim_journal_replay(ss->journal, mark_done, &bits, &kept, &cut, err);
	}
	if (rc == BSIM_OK && sp->agree)
		rc = sp->agree(sp->part->user, inputs, done, bytes, err);
	bsim_sweep_part part = *sp->part;
	part.done = done;
	if (rc == BSIM_OK && part.sized)
		part.sized(part.user, sp->record_size);
	if (rc == BSIM_OK)
		rc = run(user, &part, err);
	if (rc == BSIM_OK && sp->spread == BSIM_SPREAD_SHARD) {
		long records = 0;
		char id[17], path[BSIM_PATH_MAX];
		bsim_part_dir_run_id(inputs, id);
		ss->done = 1;
		rc = bsim_journal_close(ss->journal, err);
		ss->journal = NULL;
		if (rc == BSIM_OK)
			rc = bsim_session_path(path, sizeof path, ss->stage, "part.journal", err);
		/* part.journal counts every trial it holds: count them again */
		unsigned char *bits = done;
		memset(done, 0, bytes);
		if (rc == BSIM_OK)
			rc = bsim_journal_read(ss->journal_path, bsim_trial_record_fields(), inputs,
			                       sp->record_size, mark_done, &bits, &kept, &cut, err);
		for (long i = 0; rc == BSIM_OK && i < total; i++)
			records += (done[i / 8] >> (i % 8)) & 1;
		if (rc == BSIM_OK && bsim_output_mkdir(ss->stage, err) != BSIM_OK)
			rc = BSIM_EFAIL;
		if (rc == BSIM_OK && rename(ss->journal_path, path) != 0)
			rc = bsim_error_set(err, BSIM_EFAIL, "%s: cannot move to %s (%s)",
			                    ss->journal_path, path, strerror(errno));
		if (rc == BSIM_OK) {
			ss->journal_path[0] = '\0';
			rc = bsim_part_dir_write(ss->stage, sp->command, sp->part->index + 1,
			                         sp->part->count, id, total, records, sp->argc,
			                         sp->argv, err);
		}
	}
	free(done);
	return rc;
}

int bsim_part_dir_journal_reopen(bsim_session *ss, const char *inputs, size_t record_size,
                                 bsim_error *err)
{
	int rc = bsim_journal_close(ss->journal, err);
	ss->journal = NULL;
	if (rc == BSIM_OK)
		rc = bsim_journal_resume(&ss->journal, ss->journal_path, bsim_trial_record_fields(),
		                         inputs, record_size, err);
	return rc;
}
