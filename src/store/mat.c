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

/* A char row vector holding s (matio copies the bytes). */
static matvar_t *var_string(const char *name, const char *s)
{
	size_t dims[2] = {1, strlen(s)};
	return Mat_VarCreate(name, MAT_C_CHAR, MAT_T_UTF8, 2, dims, (void *)s, 0);
}

static matvar_t *var_build(const bsim_mat_field *f);

static matvar_t *var_cell(const bsim_mat_field *f)
{
	size_t dims[2] = {f->rows, 1};
	matvar_t *cell = Mat_VarCreate(f->name, MAT_C_CELL, MAT_T_CELL, 2, dims, NULL, 0);
	if (!cell)
		return NULL;
	for (size_t i = 0; i < f->rows; i++) {
		matvar_t *s = var_string(NULL, f->strings[i] ? f->strings[i] : "");
		if (!s) {
			Mat_VarFree(cell);
			return NULL;
		}
		Mat_VarSetCell(cell, (int)i, s); /* the cell owns s now */
	}
	return cell;
}

static matvar_t *var_struct(const bsim_mat_field *f)
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
		matvar_t *v = var_build(&f->fields[i]);
		if (!v) {
			Mat_VarFree(st);
			return NULL;
		}
		Mat_VarSetStructFieldByIndex(st, (size_t)i, 0, v); /* owned by st */
	}
	return st;
}

static matvar_t *var_build(const bsim_mat_field *f)
{
	switch (f->kind) {
	case BSIM_MAT_DOUBLE: {
		size_t dims[2] = {f->rows, f->cols};
		static const double empty = 0.0;
		const double *d = f->data && f->rows > 0 && f->cols > 0 ? f->data : &empty;
		return Mat_VarCreate(f->name, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, (void *)d, 0);
	}
	case BSIM_MAT_STRINGS:
		return var_cell(f);
	case BSIM_MAT_STRING:
		return var_string(f->name, f->strings && f->strings[0] ? f->strings[0] : "");
	case BSIM_MAT_STRUCT:
		return var_struct(f);
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
		matvar_t *v = var_build(&vars[i]);
		ok = v && Mat_VarWrite(mat, v, MAT_COMPRESSION_ZLIB) == 0;
		Mat_VarFree(v);
	}
	ok = Mat_Close(mat) == 0 && ok;
	if (ok && sync_path(tmp) == 0 && rename(tmp, path) == 0)
		return BSIM_OK;
	int e = errno;
	unlink(tmp);
	return bsim_error_set(err, BSIM_EFAIL, "%s: cannot write the MATLAB file (%s)", path,
	                      ok ? strerror(e) : "libmatio failed");
}
