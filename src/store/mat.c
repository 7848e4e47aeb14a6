/* MATLAB files written with libmatio (mat.h). */
#define _POSIX_C_SOURCE 200809L
#include "store/mat.h"

#include <errno.h>
#include <fcntl.h>
#include <matio.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "beamsim/version.h"
#include "beamsim/limits.h"

bsim_mat_field bsim_mat_column(const char *name, const double *data, size_t rows)
{
	return bsim_mat_matrix(name, data, rows, 1);
}

bsim_mat_field bsim_mat_matrix(const char *name, const double *data, size_t rows, size_t cols)
{
	bsim_mat_field f = {
	        .name = name, .kind = BSIM_MAT_DOUBLE, .rows = rows, .cols = cols, .data = data};
	return f;
}

bsim_mat_field bsim_mat_strings(const char *name, const char *const *strings, size_t rows)
{
	bsim_mat_field f = {.name = name,
	                    .kind = BSIM_MAT_STRINGS,
	                    .rows = rows,
	                    .cols = 1,
	                    .strings = strings};
	return f;
}

bsim_mat_field bsim_mat_string(const char *name, const char *const *string)
{
	bsim_mat_field f = {
	        .name = name, .kind = BSIM_MAT_STRING, .rows = 1, .cols = 1, .strings = string};
	return f;
}

bsim_mat_field bsim_mat_struct(const char *name, const bsim_mat_field *fields, int n_fields)
{
	bsim_mat_field f = {.name = name,
	                    .kind = BSIM_MAT_STRUCT,
	                    .rows = 1,
	                    .cols = 1,
	                    .fields = fields,
	                    .n_fields = n_fields};
	return f;
}

void bsim_mat_name(const char *key, char *out, size_t size)
{
	size_t n = 0;
	if (size < 2) {
		if (size)
			out[0] = '\0';
		return;
	}
	size_t max = size - 1 < 63 ? size - 1 : 63;
	int alpha = (*key >= 'a' && *key <= 'z') || (*key >= 'A' && *key <= 'Z');
	if (!alpha)
		out[n++] = 'x';
	for (; *key && n < max; key++) {
		char c = *key;
		int ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
		         (c >= '0' && c <= '9') || c == '_';
		out[n++] = ok ? c : '_';
	}
	out[n] = '\0';
}

/* What a write lends matio (MAT_F_DONT_COPY_DATA: matio neither copies nor
 * frees it) beside the caller's arrays: each cell array's elements, and
 * one char variable per distinct string, shared by every element that
 * holds it. Freed after Mat_VarFree of the variable. */
typedef struct lent {
	matvar_t **cells;    /* a cell array's rows elements */
	matvar_t **distinct; /* its n_distinct strings */
	size_t n_distinct;
	struct lent *next;
} lent;

static void lent_free(lent *l)
{
	while (l) {
		lent *next = l->next;
		for (size_t i = 0; i < l->n_distinct; i++)
			Mat_VarFree(l->distinct[i]);
		free(l->distinct);
		free(l->cells);
		free(l);
		l = next;
	}
}

/* A char row vector holding s, lent to matio (s outlives the write). */
static matvar_t *var_string(const char *name, const char *s)
{
	size_t dims[2] = {1, strlen(s)};
	return Mat_VarCreate(name, MAT_C_CHAR, MAT_T_UTF8, 2, dims, (void *)s,
	                     MAT_F_DONT_COPY_DATA);
}

static matvar_t *var_build(const bsim_mat_field *f, lent **lent);

static size_t str_hash(const char *s)
{
	size_t h = 1469598103934665603u; /* FNV-1a */
	for (; *s; s++)
		h = (h ^ (unsigned char)*s) * 1099511628211u;
	return h;
}

/* A cell array of f->rows strings. matio writes each element in full, so
 * elements with equal text may be one variable: the file is the same, and
 * a column of a few distinct words (a trial's outcome) costs a pointer a
 * row instead of a variable (about 250 bytes) a row. */
static matvar_t *var_cell(const bsim_mat_field *f, lent **lentp)
{
	lent *l = calloc(1, sizeof *l);
	if (!l)
		return NULL;
	l->next = *lentp;
	*lentp = l;
	size_t n_slots = 64, cap = 0;
	size_t *slot = calloc(n_slots, sizeof *slot); /* index + 1 into distinct, 0 free */
	l->cells = malloc((f->rows ? f->rows : 1) * sizeof *l->cells);
	int ok = slot && l->cells;
	for (size_t i = 0; ok && i < f->rows; i++) {
		const char *s = f->strings[i] ? f->strings[i] : "";
		if (i > 0 && s == f->strings[i - 1]) {
			l->cells[i] = l->cells[i - 1];
			continue;
		}
		size_t j = str_hash(s) & (n_slots - 1);
		while (slot[j] && strcmp((const char *)l->distinct[slot[j] - 1]->data, s) != 0)
			j = (j + 1) & (n_slots - 1);
		if (slot[j]) {
			l->cells[i] = l->distinct[slot[j] - 1];
			continue;
		}
		if (l->n_distinct == cap) {
			cap = cap ? 2 * cap : 16;
			matvar_t **d = realloc(l->distinct, cap * sizeof *d);
			if (!(ok = d != NULL))
				break;
			l->distinct = d;
		}
		matvar_t *v = var_string(NULL, s);
		if (!(ok = v != NULL))
			break;
		l->distinct[l->n_distinct++] = v;
		slot[j] = l->n_distinct;
		l->cells[i] = v;
		if (2 * l->n_distinct > n_slots) { /* rehash at half full */
			size_t n = 2 * n_slots;
			size_t *grown = calloc(n, sizeof *grown);
			if (!(ok = grown != NULL))
				break;
			for (size_t k = 0; k < l->n_distinct; k++) {
				size_t m = str_hash((const char *)l->distinct[k]->data) & (n - 1);
				while (grown[m])
					m = (m + 1) & (n - 1);
				grown[m] = k + 1;
			}
			free(slot);
			slot = grown;
			n_slots = n;
		}
	}
	free(slot);
	if (!ok)
		return NULL;
	size_t dims[2] = {f->rows, 1};
	return Mat_VarCreate(f->name, MAT_C_CELL, MAT_T_CELL, 2, dims, f->rows ? l->cells : NULL,
	                     f->rows ? MAT_F_DONT_COPY_DATA : 0);
}

static matvar_t *var_struct(const bsim_mat_field *f, lent **lentp)
{
	const char **names = calloc((size_t)f->n_fields + 1, sizeof *names);
	if (!names)
		return NULL;
	for (int i = 0; i < f->n_fields; i++)
		names[i] = f->fields[i].name;
	size_t dims[2] = {1, 1};
	matvar_t *st = Mat_VarCreateStruct2(f->name, 2, dims, names);
	free(names);
	if (!st)
		return NULL;
	for (int i = 0; i < f->n_fields; i++) {
		matvar_t *v = var_build(&f->fields[i], lentp);
		if (!v) {
			Mat_VarFree(st);
			return NULL;
		}
		Mat_VarSetStructFieldByIndex(st, (size_t)i, 0, v); /* owned by st */
	}
	return st;
}

/* f as a matio variable whose data are f's arrays, lent (they outlive the
 * write); what else it needs goes to *lentp. */
static matvar_t *var_build(const bsim_mat_field *f, lent **lentp)
{
	switch (f->kind) {
	case BSIM_MAT_DOUBLE: {
		size_t dims[2] = {f->rows, f->cols};
		static const double empty = 0.0;
		const double *d = f->data && f->rows > 0 && f->cols > 0 ? f->data : &empty;
		return Mat_VarCreate(f->name, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, (void *)d,
		                     MAT_F_DONT_COPY_DATA);
	}
	case BSIM_MAT_STRINGS:
		return var_cell(f, lentp);
	case BSIM_MAT_STRING:
		return var_string(f->name, f->strings && f->strings[0] ? f->strings[0] : "");
	case BSIM_MAT_STRUCT:
		return var_struct(f, lentp);
	}
	return NULL;
}

/* matio keeps its file name to itself, so the temporary file is synced by
 * name before the rename: a crash leaves the old file or the new one. */
static int sync_path(const char *path)
{
	int fd = open(path, O_RDONLY);
	if (fd < 0)
		return -1;
	int rc = fsync(fd);
	return close(fd) || rc ? -1 : 0;
}

int bsim_mat_write(const char *path, const bsim_mat_field *vars, int n_vars, bsim_error *err)
{
	char tmp[BSIM_PATH_MAX];
	if (snprintf(tmp, sizeof tmp, "%s.tmp.%ld", path, (long)getpid()) >= (int)sizeof tmp)
		return bsim_error_set(err, BSIM_EFAIL, "%s: path too long", path);
	char header[116];
	snprintf(header, sizeof header, "MATLAB 5.0 MAT-file, written by beamsim %s", BSIM_VERSION);
	mat_t *mat = Mat_CreateVer(tmp, header, MAT_FT_MAT5);
	if (!mat)
		return bsim_error_set(err, BSIM_EFAIL, "%s: cannot create (%s)", path,
		                      strerror(errno));
	int ok = 1;
	for (int i = 0; i < n_vars && ok; i++) {
		lent *l = NULL;
		matvar_t *v = var_build(&vars[i], &l);
		ok = v && Mat_VarWrite(mat, v, MAT_COMPRESSION_ZLIB) == 0;
		Mat_VarFree(v);
		lent_free(l);
	}
	ok = Mat_Close(mat) == 0 && ok;
	if (ok && sync_path(tmp) == 0 && rename(tmp, path) == 0)
		return BSIM_OK;
	int e = errno;
	unlink(tmp);
	return bsim_error_set(err, BSIM_EFAIL, "%s: cannot write the MATLAB file (%s)", path,
	                      ok ? strerror(e) : "libmatio failed");
}
