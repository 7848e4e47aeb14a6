/* A table read row by row (beamsim/table.h): the public face of the
 * streamed reader the .mat twins use (util/csv_stream.h). */
#include "beamsim/table.h"

#include <stdlib.h>

#include "util/csv_stream.h"

struct bsim_table_reader {
	csv_stream s;
};

int bsim_table_open(const char *path, bsim_table_reader **out, bsim_error *err)
{
	*out = NULL;
	bsim_table_reader *t = malloc(sizeof *t);
	if (!t)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory reading %s", path);
	int rc = bsim_csv_stream_open(path, &t->s, err);
	if (rc != BSIM_OK) {
		free(t);
		return rc;
	}
	*out = t;
	return BSIM_OK;
}

int bsim_table_columns(const bsim_table_reader *t)
{
	return t->s.n_cols;
}

const char *bsim_table_column(const bsim_table_reader *t, int c)
{
	return c >= 0 && c < t->s.n_cols ? t->s.names[c] : NULL;
}

int bsim_table_next(bsim_table_reader *t, const char *const **cells, bsim_error *err)
{
	int got = bsim_csv_stream_next(&t->s, err);
	*cells = got == 1 ? (const char *const *)t->s.cells : NULL;
	return got;
}

long bsim_table_line(const bsim_table_reader *t)
{
	return t->s.line;
}

void bsim_table_close(bsim_table_reader *t)
{
	if (!t)
		return;
	bsim_csv_stream_close(&t->s);
	free(t);
}

double bsim_table_count_rows(const char *path)
{
	double lines = bsim_csv_count_lines(path);
	return lines < 0 ? -1 : lines > 0 ? lines - 1 : 0;
}
