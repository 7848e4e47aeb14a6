/* The processes of an MPI job; see cli_mpi.h. */
#define _XOPEN_SOURCE 700

#include "cli/cli_mpi.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <dirent.h>
#include <errno.h>
#include <sys/stat.h>

#include "cli/cli_common.h"
#include "cli/cli_options.h"

/* The job size the launcher gives, 0 if not launched as part of a job:
 * OpenMPI's mpirun, and the PMI of SLURM's srun and MPICH. */
static long launcher_size(void)
{
	const char *names[] = {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"};
	for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
		const char *v = getenv(names[i]);
		if (v && *v)
			return strtol(v, NULL, 10);
	}
	return getenv("PMIX_RANK") ? 1 : 0;
}

void cli_merge_apply(const cli_merge *m, struct cli_common *c)
{
	c->out = m->out;
	c->threads = m->threads;
	c->quiet = m->quiet;
	c->resume = 0;
	c->overwrite = m->overwrite;
}

int cli_shard_parse(const char *cmd, const char *value, int *index, int *count)
{
	char *end = NULL, *end2 = NULL;
	long k = strtol(value, &end, 10), n = 0;
	if (end != value && *end == '/')
		n = strtol(end + 1, &end2, 10);
	if (end == value || *end != '/' || !end2 || end2 == end + 1 || *end2 || n < 1 ||
	    n > 1000000 || k < 1 || k > n)
		return cli_usage(cmd, "--shard %s: expected I/N with 1 <= I <= N <= 1000000",
		                 value);
	*index = (int)k;
	*count = (int)n;
	return CLI_OK;
}

char **cli_stored_argv(int argc, char **argv, const char *pos)
{
	return cli_stored_argv_paths(argc, argv, &pos, 1);
}

char **cli_stored_argv_paths(int argc, char **argv, const char *const *pos, int n_pos)
{
	char **copy = calloc((size_t)argc + 1, sizeof *copy);
	for (int i = 0; copy && i < argc; i++) {
		copy[i] = argv[i];
		for (int k = 0; k < n_pos; k++) {
			/* the path as its own word (--map DIR) or after the option's
			 * '=' (--map=DIR) */
			const size_t len = strlen(argv[i]);
			const int own = pos[k] && argv[i] == pos[k];
			const int joined = pos[k] && pos[k] > argv[i] && pos[k] <= argv[i] + len &&
			                   pos[k][-1] == '=';
			char *abs = own || joined ? realpath(pos[k], NULL) : NULL;
			if (abs && joined) {
				const size_t head = (size_t)(pos[k] - argv[i]);
				char *word = malloc(head + strlen(abs) + 1);
				if (word) {
					memcpy(word, argv[i], head);
					strcpy(word + head, abs);
				}
				free(abs);
				abs = word;
			}
			if (abs) {
				copy[i] = abs;
				break;
			}
		}
	}
	return copy;
}

void cli_stored_argv_free(char **stored, int argc, char **argv)
{
	for (int i = 0; stored && i < argc; i++)
		if (stored[i] != argv[i])
			free(stored[i]);
	free(stored);
}

int cli_spread_end(const char *cmd, int rc, bsim_error *err, const char *journal, int argc,
                   char **argv, int shard, int shards, const char *out, int quiet)
{
	int rank = cli_mpi_rank();
	if (rc == BSIM_ESTOPPED && rank > 0)
		return rc; /* stopped by the job's signal: rank 0 says so, and how to resume */
	if (rc != BSIM_OK) {
		if (rank > 0)
			cli_error("rank %d of %d: %s", rank, cli_mpi_size(), err->msg);
		else
			cli_report(rc, err);
		rc = rank > 0 ? rc : cli_run_end(rc, journal, argc, argv);
		cli_mpi_abort(rc);
		return rc;
	}
	if (shards > 0 && !quiet)
		printf("part %d of %d of the %s in %s; beamsim merge joins the %d parts' "
		       "directories\n",
		       shard, shards, cmd, out, shards);
	return CLI_OK;
}

#ifndef BSIM_HAVE_MPI

int cli_mpi_init(int *argc, char ***argv)
{
	(void)argc;
	(void)argv;
	long n = launcher_size();
	if (n > 1) {
		cli_error("started as one of %ld processes of an MPI job, but this beamsim is "
		          "built without MPI: each process would run the whole command; build "
		          "it with MPI (libopenmpi-dev, docs/cluster.md) or split the work with "
		          "--shard I/N",
		          n);
		return CLI_USAGE;
	}
	return CLI_OK;
}

void cli_mpi_finish(void)
{
}

int cli_mpi_rank(void)
{
	return 0;
}

int cli_mpi_size(void)
{
	return 1;
}

void cli_mpi_spread(int *spread, bsim_sweep_part *part, cli_mpi_agree_fn *agree, size_t record_size,
                    const volatile sig_atomic_t *stop)
{
	(void)spread;
	(void)part;
	(void)agree;
	(void)record_size;
	(void)stop;
}

void cli_mpi_abort(int rc)
{
	(void)rc;
}

int cli_mpi_gather_dir(const char *mine, char **dirs)
{
	dirs[0] = strdup(mine);
	return dirs[0] ? CLI_OK : CLI_FAIL;
}

int cli_mpi_pass_exchange(void *user, void *const *runs, size_t bytes, const int *owner, int n,
                          bsim_error *err)
{
	(void)user;
	(void)runs;
	(void)bytes;
	(void)owner;
	(void)n;
	(void)err;
	return BSIM_OK;
}

#else

#include <mpi.h>
#include <pthread.h>

#include "beamsim/sweep.h"

enum { TAG_RECORDS = 1, TAG_DONE = 2 };

static int mpi_on, mpi_rank, mpi_size = 1;

int cli_mpi_init(int *argc, char ***argv)
{
	if (launcher_size() < 1)
		return CLI_OK; /* not under mpirun: one process, MPI not started */
	int provided = 0;
	if (MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS) {
		cli_error("MPI_Init_thread failed");
		return CLI_FAIL;
	}
	mpi_on = 1;
	MPI_Comm_rank(MPI_COMM_WORLD, &mpi_rank);
	MPI_Comm_size(MPI_COMM_WORLD, &mpi_size);
	if (provided < MPI_THREAD_FUNNELED) {
		cli_error("the MPI library does not allow threads (MPI_THREAD_FUNNELED)");
		cli_mpi_abort(CLI_FAIL);
	}
	return CLI_OK;
}

/* Waits for req, looking every millisecond: OpenMPI's own waits spin,
 * which takes a core from the ranks still computing. */
static void idle_wait(MPI_Request *req)
{
	const struct timespec ms = {0, 1000000};
	int flag = 0;
	MPI_Test(req, &flag, MPI_STATUS_IGNORE);
	while (!flag) {
		nanosleep(&ms, NULL);
		MPI_Test(req, &flag, MPI_STATUS_IGNORE);
	}
}

void cli_mpi_finish(void)
{
	if (!mpi_on)
		return;
	/* a rank done early waits here idle, not in MPI_Finalize's spin */
	MPI_Request req;
	if (mpi_size > 1 && MPI_Ibarrier(MPI_COMM_WORLD, &req) == MPI_SUCCESS)
		idle_wait(&req);
	MPI_Finalize();
	mpi_on = 0;
}

int cli_mpi_rank(void)
{
	return mpi_rank;
}

int cli_mpi_size(void)
{
	return mpi_size;
}

void cli_mpi_abort(int rc)
{
	if (mpi_on && mpi_size > 1) {
		fflush(stdout);
		fflush(stderr);
		MPI_Abort(MPI_COMM_WORLD, rc);
	}
}

/* A rank's queue of records not yet sent: each an 8-byte index and the
 * record; filled by any thread, sent by the main thread. */
typedef struct mpi_queue {
	pthread_mutex_t lock;
	unsigned char *buf;
	size_t used, cap, record_size;
} mpi_queue;

static mpi_queue queue = {PTHREAD_MUTEX_INITIALIZER, NULL, 0, 0, 0};

static int mpi_record(void *user, long index, const void *payload, bsim_error *err)
{
	(void)user;
	size_t n = 8 + queue.record_size;
	int64_t i = index;
	pthread_mutex_lock(&queue.lock);
	if (queue.used + n > queue.cap) {
		size_t cap = queue.cap ? 2 * queue.cap : 64 * n;
		unsigned char *more = realloc(queue.buf, cap);
		if (!more) {
			pthread_mutex_unlock(&queue.lock);
			return bsim_error_set(err, BSIM_EFAIL, "out of memory for records to send");
		}
		queue.buf = more;
		queue.cap = cap;
	}
	memcpy(queue.buf + queue.used, &i, 8);
	memcpy(queue.buf + queue.used + 8, payload, queue.record_size);
	queue.used += n;
	pthread_mutex_unlock(&queue.lock);
	return BSIM_OK;
}

/* Batches on their way to rank 0 (sent without waiting: rank 0 takes
 * them between its own trials), freed once sent. */
#define PENDING_MAX 64
static MPI_Request pending_req[PENDING_MAX];
static unsigned char *pending_buf[PENDING_MAX];
static int n_pending;

/* Frees the batches sent; with all, waits for every one. */
static void pending_reap(int all)
{
	for (int i = 0; i < n_pending;) {
		int flag = 0;
		if (all)
			idle_wait(&pending_req[i]);
		else
			MPI_Test(&pending_req[i], &flag, MPI_STATUS_IGNORE);
		if (all || flag) {
			free(pending_buf[i]);
			pending_req[i] = pending_req[--n_pending];
			pending_buf[i] = pending_buf[n_pending];
		} else {
			i++;
		}
	}
}

/* The queue sent to rank 0 (main thread only). */
static void send_queue(void)
{
	pending_reap(0);
	if (n_pending == PENDING_MAX) {
		idle_wait(&pending_req[0]);
		pending_reap(0);
	}
	pthread_mutex_lock(&queue.lock);
	size_t used = queue.used;
	unsigned char *buf = NULL;
	if (used > 0) {
		buf = queue.buf;
		queue.buf = NULL;
		queue.used = queue.cap = 0;
	}
	pthread_mutex_unlock(&queue.lock);
	if (!buf)
		return;
	MPI_Isend(buf, (int)used, MPI_BYTE, 0, TAG_RECORDS, MPI_COMM_WORLD,
	          &pending_req[n_pending]);
	pending_buf[n_pending++] = buf;
}

/* Rank 0: every message waiting, records to accept; *ended counts the
 * ranks done. */
static int receive(bsim_sweep_accept_fn accept, void *ctx, int *ended, bsim_error *err)
{
	for (;;) {
		int flag = 0, bytes = 0;
		MPI_Status st;
		MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &st);
		if (!flag)
			return BSIM_OK;
		MPI_Get_count(&st, MPI_BYTE, &bytes);
		unsigned char *buf = malloc(bytes > 0 ? (size_t)bytes : 1);
		if (!buf)
			return bsim_error_set(err, BSIM_EFAIL,
			                      "out of memory for %d bytes of records", bytes);
		MPI_Recv(buf, bytes, MPI_BYTE, st.MPI_SOURCE, st.MPI_TAG, MPI_COMM_WORLD,
		         MPI_STATUS_IGNORE);
		int rc = BSIM_OK;
		size_t n = 8 + queue.record_size;
		if (st.MPI_TAG == TAG_DONE)
			++*ended;
		else if ((size_t)bytes % n != 0)
			rc = bsim_error_set(err, BSIM_EFAIL,
			                    "rank %d sent %d bytes, not records of %zu",
			                    st.MPI_SOURCE, bytes, n);
		for (size_t off = 0;
		     rc == BSIM_OK && st.MPI_TAG == TAG_RECORDS && off < (size_t)bytes; off += n) {
			int64_t index;
			memcpy(&index, buf + off, 8);
			rc = accept(ctx, (long)index, buf + off + 8, err);
		}
		free(buf);
		if (rc != BSIM_OK)
			return rc;
	}
}

typedef struct mpi_part {
	const volatile sig_atomic_t *stop;
	int ended;
} mpi_part;

static mpi_part part_state;

static int mpi_collect(void *user, int wait, bsim_sweep_accept_fn accept, void *ctx,
                       bsim_error *err)
{
	mpi_part *p = user;
	if (mpi_rank != 0) {
		send_queue();
		if (wait) {
			pending_reap(1);
			MPI_Request req;
			MPI_Isend(NULL, 0, MPI_BYTE, 0, TAG_DONE, MPI_COMM_WORLD, &req);
			idle_wait(&req);
		}
		return BSIM_OK;
	}
	int rc = receive(accept, ctx, &p->ended, err);
	/* Waiting for the others: a millisecond's sleep between looks leaves
	 * the cores to the ranks still running. */
	while (rc == BSIM_OK && wait && p->ended < mpi_size - 1) {
		if (p->stop && *p->stop)
			return bsim_error_set(err, BSIM_ESTOPPED,
			                      "stopped while %d of %d ranks were running",
			                      mpi_size - 1 - p->ended, mpi_size);
		struct timespec ms = {0, 1000000};
		nanosleep(&ms, NULL);
		rc = receive(accept, ctx, &p->ended, err);
	}
	return rc;
}

/* FNV-1a: the ranks compare their inputs by it. */
static uint64_t text_hash(const char *s)
{
	uint64_t h = 0xcbf29ce484222325ULL;
	for (; *s; s++)
		h = (h ^ (unsigned char)*s) * 0x100000001b3ULL;
	return h;
}

static int mpi_agree(void *user, const char *inputs, unsigned char *done, size_t bytes,
                     bsim_error *err)
{
	(void)user;
	uint64_t h = text_hash(inputs), lo = 0, hi = 0;
	MPI_Allreduce(&h, &lo, 1, MPI_UINT64_T, MPI_MIN, MPI_COMM_WORLD);
	MPI_Allreduce(&h, &hi, 1, MPI_UINT64_T, MPI_MAX, MPI_COMM_WORLD);
	if (lo != hi)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "the ranks read different inputs (an experiment, scene or "
		                      "stiffness file differs between nodes, or another "
		                      "beamsim build): rank %d's differ from another's",
		                      mpi_rank);
	/* in pieces: MPI counts are ints */
	for (size_t off = 0; off < bytes; off += 1u << 30) {
		size_t n = bytes - off < (1u << 30) ? bytes - off : (1u << 30);
		MPI_Bcast(done + off, (int)n, MPI_BYTE, 0, MPI_COMM_WORLD);
	}
	return BSIM_OK;
}

/* The records' size, once the run knows it (bsim_sweep_part.sized): a
 * lattice sweep's hold its gate paths. */
static void mpi_sized(void *user, size_t record_size)
{
	(void)user;
	queue.record_size = record_size;
}

void cli_mpi_spread(int *spread, bsim_sweep_part *part, cli_mpi_agree_fn *agree, size_t record_size,
                    const volatile sig_atomic_t *stop)
{
	if (mpi_size < 2)
		return;
	queue.record_size = record_size;
	part_state.stop = stop;
	*spread = mpi_rank == 0 ? BSIM_SPREAD_GATHER : BSIM_SPREAD_SEND;
	*part = (bsim_sweep_part){.index = mpi_rank,
	                          .count = mpi_size,
	                          .record = mpi_rank ? mpi_record : NULL,
	                          .collect = mpi_collect,
	                          .user = &part_state,
	                          .sized = mpi_sized};
	*agree = mpi_agree;
}

#endif

#ifdef BSIM_HAVE_MPI

enum { TAG_FILE = 3 };

/* Sends buf to rank 0, waiting idle (idle_wait) while rank 0 computes. */
static void send_idle(const void *buf, int n, MPI_Datatype type)
{
	MPI_Request req;
	MPI_Isend(buf, n, type, 0, TAG_FILE, MPI_COMM_WORLD, &req);
	idle_wait(&req);
}

/* This rank's files of dir, each its name's length, name, size, bytes;
 * an empty name ends them. */
static int send_dir(const char *dir)
{
	DIR *d = opendir(dir);
	if (!d) {
		cli_error("%s: cannot read: %s", dir, strerror(errno));
		return CLI_FAIL;
	}
	int rc = CLI_OK;
	struct dirent *e;
	while (rc == CLI_OK && (e = readdir(d)) != NULL) {
		char path[4096];
		struct stat st;
		snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
		if (lstat(path, &st) != 0 || !S_ISREG(st.st_mode))
			continue; /* ., .. and the session's .beamsim */
		FILE *f = fopen(path, "rb");
		long n = st.st_size;
		char *b = f && n < INT32_MAX ? malloc((size_t)n + 1) : NULL;
		if (!b || fread(b, 1, (size_t)n, f) != (size_t)n) {
			cli_error("%s: cannot read: %s", path, strerror(errno));
			rc = CLI_FAIL;
		} else {
			int len = (int)strlen(e->d_name);
			int size = (int)n;
			send_idle(&len, 1, MPI_INT);
			send_idle(e->d_name, len, MPI_CHAR);
			send_idle(&size, 1, MPI_INT);
			send_idle(b, size, MPI_BYTE);
		}
		free(b);
		if (f)
			fclose(f);
	}
	closedir(d);
	int end = 0;
	if (rc == CLI_OK)
		send_idle(&end, 1, MPI_INT);
	return rc;
}

/* Rank from's files into the new directory dir. */
static int receive_dir(int from, const char *dir)
{
	for (;;) {
		int len = 0, size = 0;
		char name[256];
		MPI_Recv(&len, 1, MPI_INT, from, TAG_FILE, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
		if (len <= 0)
			return CLI_OK;
		if (len >= (int)sizeof name) {
			cli_error("rank %d: a file name of %d bytes", from, len);
			return CLI_FAIL;
		}
		MPI_Recv(name, len, MPI_CHAR, from, TAG_FILE, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
		name[len] = '\0';
		MPI_Recv(&size, 1, MPI_INT, from, TAG_FILE, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
		char *b = malloc((size_t)size + 1);
		if (!b) {
			cli_error("out of memory");
			return CLI_FAIL;
		}
		MPI_Recv(b, size, MPI_BYTE, from, TAG_FILE, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
		size_t n = strlen(dir) + (size_t)len + 2;
		char *path = strchr(name, '/') ? NULL : malloc(n);
		if (path)
			snprintf(path, n, "%s/%s", dir, name);
		FILE *f = path ? fopen(path, "wb") : NULL;
		int ok = f && fwrite(b, 1, (size_t)size, f) == (size_t)size;
		if (f && fclose(f) != 0)
			ok = 0;
		free(b);
		if (!ok)
			cli_error("%s/%s: cannot write: %s", dir, name, strerror(errno));
		free(path);
		if (!ok)
			return CLI_FAIL;
	}
}

int cli_mpi_pass_exchange(void *user, void *const *runs, size_t bytes, const int *owner, int n,
                          bsim_error *err)
{
	(void)user;
	if (!mpi_on || mpi_size < 2)
		return BSIM_OK;
	/* in pieces of at most 1 GiB: MPI counts in int */
	const size_t piece = (size_t)1 << 30;
	for (int i = 0; i < n; i++)
		for (size_t at = 0; at < bytes; at += piece) {
			int count = (int)(bytes - at < piece ? bytes - at : piece);
			MPI_Request req;
			if (MPI_Ibcast((char *)runs[i] + at, count, MPI_BYTE, owner[i],
			               MPI_COMM_WORLD, &req) != MPI_SUCCESS)
				return bsim_error_set(
				        err, BSIM_EFAIL,
				        "MPI_Ibcast of map %d's pass from rank %d failed", i,
				        owner[i]);
			idle_wait(&req);
		}
	return BSIM_OK;
}

int cli_mpi_gather_dir(const char *mine, char **dirs)
{
	if (!mpi_on || mpi_size < 2) {
		dirs[0] = strdup(mine);
		return dirs[0] ? CLI_OK : CLI_FAIL;
	}
	if (mpi_rank > 0)
		return send_dir(mine);
	int rc = (dirs[0] = strdup(mine)) ? CLI_OK : CLI_FAIL;
	for (int r = 1; r < mpi_size && rc == CLI_OK; r++) {
		char tmpl[4096];
		/* unique: one left by a killed job is not in the way */
		snprintf(tmpl, sizeof tmpl, "%s.rank%d-XXXXXX", mine, r);
		if (!mkdtemp(tmpl)) {
			cli_error("%s: cannot create: %s", tmpl, strerror(errno));
			rc = CLI_FAIL;
		} else if ((dirs[r] = strdup(tmpl)) == NULL)
			rc = CLI_FAIL;
		else
			rc = receive_dir(r, tmpl);
	}
	return rc;
}

#endif
