/* What the MEX functions share; see bsim_mex.h. */
#include "bsim_mex.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

char *bmx_pool_take(bmx_pool *p, char *s)
{
	if (!s)
		return NULL;
	if (p->n == p->cap) {
		int cap = p->cap ? 2 * p->cap : 16;
		char **more = realloc(p->s, (size_t)cap * sizeof *more);
		if (!more) {
			free(s);
			return NULL;
		}
		p->s = more;
		p->cap = cap;
	}
	p->s[p->n++] = s;
	return s;
}

void bmx_pool_free(bmx_pool *p)
{
	for (int i = 0; i < p->n; i++)
		free(p->s[i]);
	free(p->s);
	memset(p, 0, sizeof *p);
}

static char *dup_text(const char *s)
{
	size_t n = strlen(s) + 1;
	char *d = malloc(n);
	if (d)
		memcpy(d, s, n);
	return d;
}

/* A character array's elements as UTF-8 with its NUL characters kept,
 * for a message about them: Octave's mxChar is a byte of UTF-8 already,
 * MATLAB's a UTF-16 unit (one of a surrogate pair shown as '?'). *len its
 * bytes; malloc'd, NULL if out of memory. */
static char *char_bytes(const mxArray *a, size_t *len)
{
	size_t n = mxGetNumberOfElements(a), j = 0;
	const mxChar *c = mxGetChars(a);
	char *s = malloc(3 * n + 1);
	for (size_t i = 0; s && i < n; i++) {
		unsigned u = sizeof *c == 1 ? (unsigned char)c[i] : (unsigned)c[i];
		if (sizeof *c == 1 || u < 0x80) {
			s[j++] = (char)u;
		} else if (u < 0x800) {
			s[j++] = (char)(0xC0 | u >> 6);
			s[j++] = (char)(0x80 | (u & 0x3F));
		} else if (u >= 0xD800 && u < 0xE000) {
			s[j++] = '?';
		} else {
			s[j++] = (char)(0xE0 | u >> 12);
			s[j++] = (char)(0x80 | ((u >> 6) & 0x3F));
			s[j++] = (char)(0x80 | (u & 0x3F));
		}
	}
	*len = j;
	return s;
}

/* A character row's text in the pool: *out NULL if a is no character
 * row; BSIM_EINPUT naming what if it holds a NUL character, at which
 * mxArrayToString, and the library after it, would end the text. */
static int char_text(const char *what, const mxArray *a, bmx_pool *p, const char **out,
                     bsim_error *err)
{
	*out = NULL;
	if (!mxIsChar(a) || mxGetM(a) > 1)
		return BSIM_OK;
	const mxChar *c = mxGetChars(a);
	size_t n = mxGetNumberOfElements(a), i = 0;
	while (i < n && c[i] != 0)
		i++;
	if (i < n) {
		size_t len;
		char *bytes = char_bytes(a, &len);
		if (!bytes)
			return bsim_error_set(err, BSIM_EFAIL, "out of memory");
		bsim_error_nul_check(what, bytes, len, err);
		free(bytes);
		return BSIM_EINPUT;
	}
	char *m = mxArrayToString(a);
	if (!m)
		return BSIM_OK;
	*out = bmx_pool_take(p, dup_text(m));
	mxFree(m);
	return *out ? BSIM_OK : bsim_error_set(err, BSIM_EFAIL, "out of memory");
}

static int strcasesame(const char *a, const char *b)
{
	for (; *a && *b; a++, b++)
		if (tolower((unsigned char)*a) != tolower((unsigned char)*b))
			return 0;
	return *a == *b;
}

int bmx_pairs(int nrhs, const mxArray *prhs[], int first, const char *const *names, int n_names,
              const mxArray **values, bsim_error *err)
{
	char known[512] = "";
	for (int i = 0; i < n_names; i++) {
		values[i] = NULL;
		size_t len = strlen(known);
		snprintf(known + len, sizeof known - len, "%s'%s'", i ? ", " : "", names[i]);
	}
	if ((nrhs - first) % 2 != 0)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "expected name-value pairs after the first argument, got "
		                      "an odd number of arguments (names: %s)",
		                      known);
	for (int k = first; k < nrhs; k += 2) {
		char name[64] = "", what[48];
		snprintf(what, sizeof what, "argument %d", k + 1);
		bmx_pool none = {0};
		const char *text;
		/* (a name holding a NUL would match the name before it) */
		int bad = char_text(what, prhs[k], &none, &text, err), is_text = text != NULL;
		bmx_pool_free(&none);
		if (bad)
			return err->code;
		if (!is_text || mxGetString(prhs[k], name, sizeof name) != 0)
			return bsim_error_set(err, BSIM_EINPUT,
			                      "argument %d: expected the name of an argument (%s)",
			                      k + 1, known);
		int i = 0;
		while (i < n_names && !strcasesame(name, names[i]))
			i++;
		if (i == n_names)
			return bsim_error_set(err, BSIM_EINPUT,
			                      "unknown argument '%s' (expected %s)", name, known);
		values[i] = prhs[k + 1];
	}
	return BSIM_OK;
}

int bmx_text(const char *name, const mxArray *a, bmx_pool *p, const char **out, bsim_error *err)
{
	char what[80];
	snprintf(what, sizeof what, "'%s'", name);
	if (char_text(what, a, p, out, err) != BSIM_OK)
		return err->code;
	if (!*out)
		return bsim_error_set(err, BSIM_EINPUT, "'%s': expected text (a character row)",
		                      name);
	return BSIM_OK;
}

/* The one real number of a numeric or logical scalar. */
static int real_scalar(const mxArray *a, double *x)
{
	if (!(mxIsNumeric(a) || mxIsLogical(a)) || mxIsComplex(a) || mxGetNumberOfElements(a) != 1)
		return -1;
	*x = mxGetScalar(a);
	return 0;
}

int bmx_long(const char *name, const mxArray *a, long lo, long hi, long *out, bsim_error *err)
{
	double x;
	if (real_scalar(a, &x) != 0 || !(x >= (double)lo && x <= (double)hi) || x != floor(x))
		return bsim_error_set(err, BSIM_EINPUT, "'%s': expected an integer from %ld to %ld",
		                      name, lo, hi);
	*out = (long)x;
	return BSIM_OK;
}

int bmx_seed(const char *name, const mxArray *a, uint64_t *out, bsim_error *err)
{
	if (mxIsUint64(a) && mxGetNumberOfElements(a) == 1) {
		*out = *(const uint64_t *)mxGetData(a);
		return BSIM_OK;
	}
	double x;
	if (real_scalar(a, &x) != 0 || !(x >= 0 && x <= 9007199254740992.0) || x != floor(x))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "'%s': expected an integer >= 0 (beyond 2^53 as uint64)",
		                      name);
	*out = (uint64_t)x;
	return BSIM_OK;
}

int bmx_flag(const char *name, const mxArray *a, int *out, bsim_error *err)
{
	double x;
	if (real_scalar(a, &x) != 0 || !(x == 0 || x == 1))
		return bsim_error_set(err, BSIM_EINPUT, "'%s': expected true or false", name);
	*out = x == 1;
	return BSIM_OK;
}

int bmx_double(const char *name, const mxArray *a, double *out, bsim_error *err)
{
	if (real_scalar(a, out) != 0 || !isfinite(*out))
		return bsim_error_set(err, BSIM_EINPUT, "'%s': expected a finite number", name);
	return BSIM_OK;
}

/* The shortest text of x that reads back to x; integers without a point;
 * YAML's words for the non-finite. */
static void number_text(double x, char *buf, size_t size)
{
	if (isnan(x)) {
		snprintf(buf, size, ".nan");
	} else if (isinf(x)) {
		snprintf(buf, size, x > 0 ? ".inf" : "-.inf");
	} else if (x == floor(x) && fabs(x) <= 9007199254740992.0) {
		snprintf(buf, size, "%.0f", x);
	} else {
		for (int digits = 1; digits <= 17; digits++) {
			snprintf(buf, size, "%.*g", digits, x);
			if (strtod(buf, NULL) == x)
				break;
		}
	}
}

/* Element i of a numeric or logical array as text. */
static void element_text(const mxArray *a, size_t i, char *buf, size_t size)
{
	if (mxIsLogical(a)) {
		snprintf(buf, size, "%s", mxGetLogicals(a)[i] ? "true" : "false");
		return;
	}
	double x;
	switch (mxGetClassID(a)) {
	case mxDOUBLE_CLASS:
		x = ((const double *)mxGetData(a))[i];
		break;
	case mxSINGLE_CLASS:
		x = ((const float *)mxGetData(a))[i];
		break;
	case mxINT8_CLASS:
		x = ((const int8_T *)mxGetData(a))[i];
		break;
	case mxUINT8_CLASS:
		x = ((const uint8_T *)mxGetData(a))[i];
		break;
	case mxINT16_CLASS:
		x = ((const int16_T *)mxGetData(a))[i];
		break;
	case mxUINT16_CLASS:
		x = ((const uint16_T *)mxGetData(a))[i];
		break;
	case mxINT32_CLASS:
		x = ((const int32_T *)mxGetData(a))[i];
		break;
	case mxUINT32_CLASS:
		x = ((const uint32_T *)mxGetData(a))[i];
		break;
	case mxINT64_CLASS:
		x = (double)((const int64_T *)mxGetData(a))[i];
		break;
	case mxUINT64_CLASS:
		x = (double)((const uint64_T *)mxGetData(a))[i];
		break;
	default:
		x = NAN;
		break;
	}
	number_text(x, buf, size);
}

int bmx_value_text(const char *name, const mxArray *a, bmx_pool *p, const char **out,
                   bsim_error *err)
{
	if (mxIsChar(a)) {
		char what[160];
		snprintf(what, sizeof what, "'%s': the value", name);
		if (char_text(what, a, p, out, err) != BSIM_OK)
			return err->code;
		if (!*out)
			return bsim_error_set(err, BSIM_EINPUT, "'%s': expected one row of text",
			                      name);
		return BSIM_OK;
	}
	if (!(mxIsNumeric(a) || mxIsLogical(a)) || mxIsComplex(a))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "'%s': expected a value: a real number, a vector, true or "
		                      "false, or text",
		                      name);
	size_t n = mxGetNumberOfElements(a);
	char *s = malloc(32 * (n + 1) + 8);
	if (!s)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	if (n == 1) {
		element_text(a, 0, s, 32);
	} else {
		size_t len = 0;
		s[len++] = '[';
		for (size_t i = 0; i < n; i++) {
			char one[32];
			element_text(a, i, one, sizeof one);
			len += (size_t)sprintf(s + len, "%s%s", i ? ", " : "", one);
		}
		s[len++] = ']';
		s[len] = '\0';
	}
	if (!(*out = bmx_pool_take(p, s)))
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	return BSIM_OK;
}

/* A cell of an even number of elements, keys at odd places (1-based). */
static int key_value_cell(const char *name, const mxArray *a, bsim_error *err)
{
	if (!mxIsCell(a) || mxGetNumberOfElements(a) % 2 != 0)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "'%s': expected a cell {KEY, VALUE, KEY, VALUE, ...}", name);
	return BSIM_OK;
}

int bmx_overrides(const char *name, const mxArray *a, bmx_pool *p, bsim_override **ov, int *n,
                  bsim_error *err)
{
	*ov = NULL;
	*n = 0;
	if (!a)
		return BSIM_OK;
	if (key_value_cell(name, a, err) != BSIM_OK)
		return BSIM_EINPUT;
	int pairs = (int)(mxGetNumberOfElements(a) / 2);
	/* The array is a string of the pool too: freed with it. */
	*ov = (bsim_override *)bmx_pool_take(p, calloc((size_t)pairs + 1, sizeof **ov));
	if (!*ov)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	for (int i = 0; i < pairs; i++) {
		const mxArray *k = mxGetCell(a, (mwIndex)(2 * i));
		const mxArray *v = mxGetCell(a, (mwIndex)(2 * i + 1));
		char what[80];
		snprintf(what, sizeof what, "'%s': the key", name);
		const char *key = NULL;
		if (k && char_text(what, k, p, &key, err) != BSIM_OK)
			return err->code;
		if (!key)
			return bsim_error_set(err, BSIM_EINPUT,
			                      "'%s': element %d: expected a key (text), e.g. "
			                      "'body.mass'",
			                      name, 2 * i + 1);
		if (!v)
			return bsim_error_set(err, BSIM_EINPUT, "'%s' %s: expected a value", name,
			                      key);
		const char *value;
		if (bmx_value_text(key, v, p, &value, err) != BSIM_OK)
			return err->code;
		/* the origin the command line gives it, "--set KEY=VALUE", so
		 * that its messages are the program's */
		size_t size = strlen(key) + strlen(value) + sizeof "--set =";
		char *origin = bmx_pool_take(p, malloc(size));
		if (!origin)
			return bsim_error_set(err, BSIM_EFAIL, "out of memory");
		snprintf(origin, size, "--set %s=%s", key, value);
		(*ov)[i] = (bsim_override){key, value, origin};
	}
	*n = pairs;
	return BSIM_OK;
}

void bmx_grid_free(bsim_grid_axis *axes, int n)
{
	for (int i = 0; axes && i < n; i++)
		free(axes[i].values);
	free(axes);
}

/* The values of one axis: a numeric or logical vector, a cell of values,
 * or one text. */
static int axis_values(const char *key, const mxArray *v, bmx_pool *p, bsim_grid_axis *ax,
                       bsim_error *err)
{
	size_t n = mxIsChar(v) ? 1 : mxGetNumberOfElements(v);
	if (n == 0 || !(mxIsChar(v) || mxIsCell(v) || mxIsNumeric(v) || mxIsLogical(v)))
		return bsim_error_set(err, BSIM_EINPUT,
		                      "'grid' %s: expected one or more values (a vector or a "
		                      "cell)",
		                      key);
	ax->values = calloc(n, sizeof *ax->values);
	if (!ax->values)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	for (size_t i = 0; i < n; i++) {
		const char *text = NULL;
		if (mxIsChar(v)) {
			if (bmx_value_text(key, v, p, &text, err) != BSIM_OK)
				return err->code;
		} else if (mxIsCell(v)) {
			const mxArray *c = mxGetCell(v, (mwIndex)i);
			if (!c || bmx_value_text(key, c, p, &text, err) != BSIM_OK)
				return c ? err->code
				         : bsim_error_set(err, BSIM_EINPUT,
				                          "'grid' %s: empty value", key);
		} else {
			char one[32];
			element_text(v, i, one, sizeof one);
			if (!(text = bmx_pool_take(p, dup_text(one))))
				return bsim_error_set(err, BSIM_EFAIL, "out of memory");
		}
		ax->values[i] = (char *)text;
	}
	ax->n_values = (int)n;
	/* The axis's origin is the command line's "--grid KEY", one for all its
	 * values: the library names a value "--grid KEY=VALUE". */
	size_t len = strlen(key) + sizeof "--grid ";
	char *origin = bmx_pool_take(p, malloc(len));
	if (!origin)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	snprintf(origin, len, "--grid %s", key);
	ax->origin = origin;
	return BSIM_OK;
}

int bmx_grid(const char *name, const mxArray *a, bmx_pool *p, bsim_grid_axis **axes, int *n,
             bsim_error *err)
{
	*axes = NULL;
	*n = 0;
	if (!a)
		return BSIM_OK;
	if (key_value_cell(name, a, err) != BSIM_OK)
		return BSIM_EINPUT;
	int pairs = (int)(mxGetNumberOfElements(a) / 2);
	*axes = calloc((size_t)pairs + 1, sizeof **axes);
	if (!*axes)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	*n = pairs;
	for (int i = 0; i < pairs; i++) {
		const mxArray *k = mxGetCell(a, (mwIndex)(2 * i));
		const mxArray *v = mxGetCell(a, (mwIndex)(2 * i + 1));
		const char *key = NULL;
		if (k && char_text("'grid': the key", k, p, &key, err) != BSIM_OK)
			return err->code;
		if (!key)
			return bsim_error_set(err, BSIM_EINPUT,
			                      "'grid': element %d: expected a key (text), e.g. "
			                      "'beams.0.stiffness'",
			                      2 * i + 1);
		(*axes)[i].key = (char *)key;
		if (!v)
			return bsim_error_set(err, BSIM_EINPUT, "'grid' %s: expected values", key);
		if (axis_values(key, v, p, &(*axes)[i], err) != BSIM_OK)
			return err->code;
	}
	return BSIM_OK;
}

int bmx_backend(const char *name, const bsim_override *kv, int n_kv, const bsim_backend **b,
                bsim_options *opts, bsim_error *err)
{
	memset(opts, 0, sizeof *opts);
	*b = name ? bsim_backend_find(name, err) : bsim_backend_default();
	if (!*b)
		return BSIM_EINPUT;
	for (int i = 0; i < n_kv; i++) {
		char text[128];
		int len = snprintf(text, sizeof text, "%s=%s", kv[i].key, kv[i].value);
		if (len < 0 || (size_t)len >= sizeof text)
			return bsim_error_set(err, BSIM_EINPUT, "'backend_opt' %s: value too long",
			                      kv[i].key);
		if (bsim_options_add(opts, text, err) != BSIM_OK)
			return BSIM_EINPUT;
	}
	return bsim_options_check(opts, (*b)->knobs, (*b)->n_knobs, (*b)->name, err);
}

int bmx_from_one(bsim_error *err)
{
	static const char *const names[] = {"group", "trial"};
	for (int i = 0; i < 2; i++) {
		char head[64];
		long given, last;
		int used = 0;
		snprintf(head, sizeof head, "--%s %%ld: expected 0 to %%ld%%n", names[i]);
		if (sscanf(err->msg, head, &given, &last, &used) == 2 && used > 0) {
			char rest[BSIM_ERROR_MSG_MAX];
			snprintf(rest, sizeof rest, "%s", err->msg + used);
			return bsim_error_set(err, err->code, "'%s' %ld: expected 1 to %ld%s",
			                      names[i], given + 1, last + 1, rest);
		}
	}
	return err->code ? err->code : BSIM_EINPUT;
}

int bmx_trial_open(const mxArray *path, const mxArray *const *v, bmx_pool *pool, bmx_trial *t,
                   bsim_error *err)
{
	memset(t, 0, sizeof *t);
	bsim_replay_def def = bsim_replay_def_default();
	long group = 1, trial = 1;
	const char *backend = NULL;
	bsim_override *kv = NULL;
	int n_kv = 0;
	if (bmx_text("path", path, pool, &def.path, err) ||
	    (v[BMX_TRIAL_GROUP] &&
	     bmx_long("group", v[BMX_TRIAL_GROUP], 1, INT32_MAX, &group, err)) ||
	    (v[BMX_TRIAL_TRIAL] &&
	     bmx_long("trial", v[BMX_TRIAL_TRIAL], 1, INT32_MAX, &trial, err)) ||
	    (v[BMX_TRIAL_SEED] && bmx_seed("seed", v[BMX_TRIAL_SEED], &def.seed, err)) ||
	    (v[BMX_TRIAL_BACKEND] &&
	     bmx_text("backend", v[BMX_TRIAL_BACKEND], pool, &backend, err)) ||
	    bmx_overrides("backend_opt", v[BMX_TRIAL_BACKEND_OPT], pool, &kv, &n_kv, err) ||
	    bmx_overrides("set", v[BMX_TRIAL_SET], pool, (bsim_override **)&def.sets, &def.n_sets,
	                  err) ||
	    bmx_grid("grid", v[BMX_TRIAL_GRID], pool, &t->grid, &t->n_grid, err))
		return err->code;
	def.group = group - 1;
	def.trial = trial - 1;
	def.has_seed = v[BMX_TRIAL_SEED] != NULL;
	def.grid = t->grid;
	def.n_grid = t->n_grid;
	if (bsim_replay_is_dir(def.path)) {
		/* a stored run names its own backend: 'backend' is a side's label */
		def.side = backend;
		def.has_backend_opts = n_kv > 0;
	}
	if (bsim_replay_open(&def, &t->rp, err) != BSIM_OK)
		return bmx_from_one(err);
	t->backend = t->rp->backend;
	t->opts = t->rp->opts;
	if (!t->backend && bmx_backend(backend, kv, n_kv, &t->backend, &t->opts, err) != BSIM_OK)
		return BSIM_EINPUT;
	return BSIM_OK;
}

void bmx_trial_free(bmx_trial *t)
{
	bsim_replay_free(t->rp);
	bmx_grid_free(t->grid, t->n_grid);
	memset(t, 0, sizeof *t);
}

/* ---- what the functions return ---------------------------------------- */

void bmx_set(mxArray *s, mwIndex i, const char *field, mxArray *v)
{
	if (mxGetFieldNumber(s, field) < 0)
		mxAddField(s, field);
	mxSetField(s, i, field, v);
}

mxArray *bmx_scalar(double x)
{
	return mxCreateDoubleScalar(x);
}

mxArray *bmx_string(const char *text)
{
	return mxCreateString(text);
}

mxArray *bmx_u64(uint64_t x)
{
	mxArray *a = mxCreateNumericMatrix(1, 1, mxUINT64_CLASS, mxREAL);
	*(uint64_t *)mxGetData(a) = x;
	return a;
}

mxArray *bmx_row(const double *x, int n)
{
	mxArray *a = mxCreateDoubleMatrix(1, (mwSize)n, mxREAL);
	double *d = mxGetPr(a);
	for (int i = 0; i < n; i++)
		d[i] = x[i];
	return a;
}

mxArray *bmx_column(size_t n, double **data)
{
	mxArray *a = mxCreateDoubleMatrix((mwSize)n, 1, mxREAL);
	*data = mxGetPr(a);
	return a;
}

static size_t text_hash(const char *s)
{
	size_t h = 1469598103934665603u; /* FNV-1a */
	for (; *s; s++)
		h = (h ^ (unsigned char)*s) * 1099511628211u;
	return h;
}

long bmx_labels_code(bmx_labels *l, const char *text)
{
	if (2 * (l->n + 1) > l->n_slots) {
		size_t size = l->n_slots ? 2 * l->n_slots : 64;
		size_t *slot = calloc(size, sizeof *slot);
		if (!slot)
			return -1;
		for (size_t i = 0; i < l->n; i++) {
			size_t k = text_hash(l->text[i]);
			while (slot[k & (size - 1)])
				k++;
			slot[k & (size - 1)] = i + 1;
		}
		free(l->slot);
		l->slot = slot;
		l->n_slots = size;
	}
	for (size_t k = text_hash(text);; k++) {
		size_t *at = &l->slot[k & (l->n_slots - 1)];
		if (*at && strcmp(l->text[*at - 1], text) == 0)
			return (long)*at;
		if (*at)
			continue;
		if (l->n == l->cap) {
			size_t cap = l->cap ? 2 * l->cap : 16;
			char **t = realloc(l->text, cap * sizeof *t);
			if (!t)
				return -1;
			l->text = t;
			l->cap = cap;
		}
		if (!(l->text[l->n] = dup_text(text)))
			return -1;
		*at = ++l->n;
		return (long)l->n;
	}
}

mxArray *bmx_labels_cell(const bmx_labels *l)
{
	return bmx_cellstr((const char *const *)l->text, (int)l->n);
}

void bmx_labels_free(bmx_labels *l)
{
	for (size_t i = 0; i < l->n; i++)
		free(l->text[i]);
	free(l->text);
	free(l->slot);
	memset(l, 0, sizeof *l);
}

mxArray *bmx_cellstr(const char *const *texts, int n)
{
	mxArray *c = mxCreateCellMatrix((mwSize)n, 1);
	for (int i = 0; i < n; i++)
		mxSetCell(c, (mwIndex)i, bmx_string(texts[i]));
	return c;
}

mxArray *bmx_codes(const uint32_t *codes, size_t n, size_t n_labels)
{
	mxClassID id = n_labels <= UINT8_MAX    ? mxUINT8_CLASS
	               : n_labels <= UINT16_MAX ? mxUINT16_CLASS
	                                        : mxUINT32_CLASS;
	mxArray *a = mxCreateNumericMatrix((mwSize)n, 1, id, mxREAL);
	void *d = mxGetData(a);
	for (size_t k = 0; k < n; k++) {
		if (id == mxUINT8_CLASS)
			((uint8_t *)d)[k] = (uint8_t)codes[k];
		else if (id == mxUINT16_CLASS)
			((uint16_t *)d)[k] = (uint16_t)codes[k];
		else
			((uint32_t *)d)[k] = codes[k];
	}
	return a;
}

/* 1 if the function name exists here (MATLAB's exist). */
static int exists(const char *name)
{
	mxArray *in = bmx_string(name), *out = NULL;
	int yes = mexCallMATLAB(1, &out, 1, &in, "exist") == 0 && out && mxGetScalar(out) != 0;
	mxDestroyArray(in);
	if (out)
		mxDestroyArray(out);
	return yes;
}

void bmx_text_field(mxArray *t, mxArray *l, const char *name, mxArray *codes, mxArray *labels)
{
	bmx_set(l, 0, name, labels);
	if (!exists("categorical")) {
		bmx_set(t, 0, name, codes);
		return;
	}
	/* categorical(codes, 1:n, labels): the value set of the codes' class */
	size_t n = mxGetNumberOfElements(labels);
	mxArray *set = mxCreateNumericMatrix(1, (mwSize)n, mxGetClassID(codes), mxREAL);
	void *d = mxGetData(set);
	for (size_t i = 0; i < n; i++) {
		if (mxGetClassID(codes) == mxUINT8_CLASS)
			((uint8_t *)d)[i] = (uint8_t)(i + 1);
		else if (mxGetClassID(codes) == mxUINT16_CLASS)
			((uint16_t *)d)[i] = (uint16_t)(i + 1);
		else
			((uint32_t *)d)[i] = (uint32_t)(i + 1);
	}
	mxArray *in[3] = {codes, set, labels}, *cat = NULL;
	mexCallMATLAB(1, &cat, 3, in, "categorical");
	mxDestroyArray(set);
	mxDestroyArray(codes);
	bmx_set(t, 0, name, cat);
}

void bmx_field_name(const char *key, char *buf, size_t size)
{
	size_t j = 0;
	if (size == 0)
		return;
	if (!isalpha((unsigned char)key[0]) && j + 1 < size)
		buf[j++] = 'x';
	for (const char *c = key; *c && j + 1 < size; c++)
		buf[j++] = isalnum((unsigned char)*c) || *c == '_' ? *c : '_';
	buf[j] = '\0';
}

void bmx_fail(const bsim_error *err)
{
	const char *id = err->code == BSIM_EINPUT      ? "beamsim:input"
	                 : err->code == BSIM_EDISAGREE ? "beamsim:disagree"
	                 : err->code == BSIM_ESTOPPED  ? "beamsim:stopped"
	                                               : "beamsim:failed";
	mexErrMsgIdAndTxt(id, "%s", err->msg[0] ? err->msg : "failed");
}

mxArray *bmx_member_int(const void *v, size_t size)
{
	(void)size;
	return bmx_scalar(*(const int *)v);
}

mxArray *bmx_member_long(const void *v, size_t size)
{
	(void)size;
	return bmx_scalar((double)*(const long *)v);
}

mxArray *bmx_member_ulong(const void *v, size_t size)
{
	(void)size;
	return bmx_scalar((double)*(const unsigned long *)v);
}

mxArray *bmx_member_doubles(const void *v, size_t size)
{
	size_t n = size / sizeof(double);
	return n > 1 ? bmx_row(v, (int)n) : bmx_scalar(*(const double *)v);
}
