/* trials.csv's columns, described once (beamsim/trial_fields.h). */
#include "beamsim/trial_fields.h"

#include <math.h>
#include <pthread.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/lattice_outcome.h"
#include "store/survival_files.h"

static const char *const outcome_words[] = {"traversed", "side_exit", "stuck", "unstable"};
static const char *const type_words[] = {"none", "left", "right"};

/* One getter a column: the row's value. */
#define GETTER(fn, expr)                                                                           \
	static double fn(const bsim_trial_row *row)                                                \
	{                                                                                          \
		const bsim_trial_result *x = row->r;                                               \
		const bsim_ledger *l = &x->ledger;                                                 \
		(void)x;                                                                           \
		(void)l;                                                                           \
		return (expr);                                                                     \
	}

double bsim_survival_exit_time(const bsim_trial_result *r)
{
	return r->outcome == BSIM_TRAVERSED || r->outcome == BSIM_SIDE_EXIT ? r->t_end : NAN;
}

/* the row's indices, for a row of any of the tables below (no result) */
static double f_group(const bsim_trial_row *row)
{
	return row->group;
}

static double f_trial(const bsim_trial_row *row)
{
	return row->trial;
}

GETTER(f_outcome, x->outcome)
GETTER(f_type, x->type)
GETTER(f_steps, x->steps)
GETTER(f_t_end, x->t_end)
GETTER(f_x_end, x->x_end)
GETTER(f_y_end, x->y_end)
GETTER(f_vx_end, x->vx_end)
GETTER(f_max_theta1, x->max_theta[0])
GETTER(f_max_theta2, x->max_theta[1])
GETTER(f_e_start, l->e_start)
GETTER(f_e_end, l->e_end)
GETTER(f_work_in, l->w_prop + l->w_rand)
/* sleeping's and the essay protocol's resets too, so that e_end - e_start
 * = work_in - losses + residual */
GETTER(f_losses, l->damper + l->impact + l->contact + l->correction + l->sleep + l->reset)
GETTER(f_residual, l->residual)
GETTER(f_overlap_max, x->overlap_max)
GETTER(f_final_ix, x->final_ix)
GETTER(f_final_iy, x->final_iy)
GETTER(f_iteration_limits, (double)x->solver.iteration_limit)
GETTER(f_clamps, (double)x->solver.clamped)
GETTER(f_t_exit, bsim_survival_exit_time(x))
GETTER(f_heading_end, x->heading_end)
GETTER(f_angular_velocity_end, x->angular_velocity_end)
GETTER(f_turn_end, x->turn_end)
GETTER(f_turn_max, x->turn_max)

static void t_location(FILE *out, const bsim_trial_row *row)
{
	char label[48];
	bsim_lattice_location_label(bsim_lattice_location_of(row->r), label, sizeof label);
	fputs(label, out);
}

/* The gates entered in order, "ix:iy ix:iy ..."; a trial without its path
 * (taken from a resumed run's journal, which lattices never are) stayed
 * in one gate. */
static void t_path(FILE *out, const bsim_trial_row *row)
{
	const bsim_trial_log *tl = row->log;
	for (int j = 0; tl && j < tl->n_entries; j++)
		fprintf(out, "%s%d:%d", j ? " " : "", tl->entries[j].ix, tl->entries[j].iy);
	if (!tl || tl->n_entries == 0)
		fprintf(out, "%d:%d", row->r->final_ix, row->r->final_iy);
}

#define NUMBER(name, kind, unit, help, fn)                                                         \
	{                                                                                          \
		name, kind, unit, help, 0, fn, NULL, 0, NULL, 0, 0                                 \
	}
/* a number read back into member m of the result */
#define READ(name, kind, unit, help, fn, m)                                                        \
	{                                                                                          \
		name, kind, unit, help, 0, fn, NULL, 0, NULL, offsetof(bsim_trial_result, m),      \
		        sizeof(((bsim_trial_result *)0)->m)                                        \
	}

static const bsim_trial_field fields[] = {
        {"group", BSIM_FIELD_INT, "", "the group, 0-based", 1, f_group, NULL, 0, NULL, 0, 0},
        {"trial", BSIM_FIELD_INT, "", "the trial within its group, 0-based", 1, f_trial, NULL, 0,
         NULL, 0, 0},
        {"outcome", BSIM_FIELD_WORD, "", "traversed, side_exit, stuck or unstable", 0, f_outcome,
         outcome_words, 4, NULL, 0, 0},
        {"type", BSIM_FIELD_WORD, "", "the beam a traversal went over: left, right or none", 0,
         f_type, type_words, 3, NULL, 0, 0},
        READ("steps", BSIM_FIELD_INT, "", "steps to the outcome", f_steps, steps),
        READ("t_end", BSIM_FIELD_REAL, "s", "time to the outcome", f_t_end, t_end),
        READ("x_end", BSIM_FIELD_REAL, "m", "the end position's x", f_x_end, x_end),
        READ("y_end", BSIM_FIELD_REAL, "m", "the end position's y", f_y_end, y_end),
        READ("vx_end", BSIM_FIELD_REAL, "m/s", "the end velocity's x", f_vx_end, vx_end),
        READ("max_theta1", BSIM_FIELD_REAL, "rad", "beam 1's peak angle", f_max_theta1,
             max_theta[0]),
        READ("max_theta2", BSIM_FIELD_REAL, "rad", "beam 2's peak angle", f_max_theta2,
             max_theta[1]),
        READ("e_start", BSIM_FIELD_REAL, "J", "the energy at the start", f_e_start, ledger.e_start),
        READ("e_end", BSIM_FIELD_REAL, "J", "the energy at the end", f_e_end, ledger.e_end),
        READ("work_in", BSIM_FIELD_REAL, "J", "the forces' work", f_work_in, ledger.w_prop),
        READ("losses", BSIM_FIELD_REAL, "J", "what dissipation took", f_losses, ledger.damper),
        READ("residual", BSIM_FIELD_REAL, "J", "the ledger's residual", f_residual,
             ledger.residual),
        NUMBER("overlap_max", BSIM_FIELD_MEASURED, "m", "the deepest overlap of body and beams",
               f_overlap_max),
        READ("final_ix", BSIM_FIELD_INT, "", "the final gate's column", f_final_ix, final_ix),
        READ("final_iy", BSIM_FIELD_INT, "", "the final gate's row", f_final_iy, final_iy),
        {"location", BSIM_FIELD_TEXT, "", "where it ended: end:ix, side:iy or stuck:ix:iy", 0, NULL,
         NULL, 0, t_location, 0, 0},
        {"path", BSIM_FIELD_TEXT, "", "the gates entered, ix:iy separated by spaces", 0, NULL, NULL,
         0, t_path, 0, 0},
        READ("iteration_limits", BSIM_FIELD_INT, "", "solves that stopped at their limit",
             f_iteration_limits, solver.iteration_limit),
        READ("clamps", BSIM_FIELD_INT, "", "(sub)steps whose motion the solver clamped", f_clamps,
             solver.clamped),
        NUMBER("t_exit", BSIM_FIELD_MEASURED, "s", "when the trial left the gate or the field",
               f_t_exit),
        READ("heading_end", BSIM_FIELD_REAL, "rad", "the body's heading at the end", f_heading_end,
             heading_end),
        READ("angular_velocity_end", BSIM_FIELD_REAL, "rad/s",
             "the body's angular velocity at the end", f_angular_velocity_end,
             angular_velocity_end),
        READ("turn_end", BSIM_FIELD_REAL, "rad", "how far the body turned", f_turn_end, turn_end),
        READ("turn_max", BSIM_FIELD_REAL, "rad", "the largest turn on the way", f_turn_max,
             turn_max),
};

const bsim_trial_field *bsim_trial_fields(int *n)
{
	*n = (int)(sizeof fields / sizeof fields[0]);
	return fields;
}

const bsim_trial_field *bsim_trial_field_find(const char *name)
{
	for (size_t i = 0; i < sizeof fields / sizeof fields[0]; i++)
		if (!strcmp(fields[i].name, name))
			return &fields[i];
	return NULL;
}

/* ---- a lattice's gate_entries.csv and beam_peaks.csv -------------------- */

/* One getter a column of gate entry row->seq of the row's log. */
#define ENTRY_GETTER(fn, expr)                                                                     \
	static double fn(const bsim_trial_row *row)                                                \
	{                                                                                          \
		const bsim_gate_entry *e = &row->log->entries[row->seq];                           \
		return (expr);                                                                     \
	}

static double e_seq(const bsim_trial_row *row)
{
	return row->seq;
}

ENTRY_GETTER(e_ix, e->ix)
ENTRY_GETTER(e_iy, e->iy)
ENTRY_GETTER(e_step, e->step)
ENTRY_GETTER(e_t, e->t)
ENTRY_GETTER(e_pos, e->pos)
ENTRY_GETTER(e_x, e->x[0])
ENTRY_GETTER(e_y, e->x[1])
ENTRY_GETTER(e_vx, e->v[0])
ENTRY_GETTER(e_vy, e->v[1])
ENTRY_GETTER(e_theta_left, e->theta[0])
ENTRY_GETTER(e_omega_left, e->omega[0])
ENTRY_GETTER(e_theta_right, e->theta[1])
ENTRY_GETTER(e_omega_right, e->omega[1])

static void t_edge(FILE *out, const bsim_trial_row *row)
{
	fputs(bsim_trial_edge_name(row->log->entries[row->seq].edge), out);
}

static const bsim_trial_field entry_fields[] = {
        {"group", BSIM_FIELD_INT, "", "the group, 0-based", 1, f_group, NULL, 0, NULL, 0, 0},
        {"trial", BSIM_FIELD_INT, "", "the trial within its group, 0-based", 1, f_trial, NULL, 0,
         NULL, 0, 0},
        {"seq", BSIM_FIELD_INT, "", "the entry's place in the trial's path, 0-based", 1, e_seq,
         NULL, 0, NULL, 0, 0},
        NUMBER("ix", BSIM_FIELD_INT, "", "the entered gate's column", e_ix),
        NUMBER("iy", BSIM_FIELD_INT, "", "the entered gate's row", e_iy),
        {"edge", BSIM_FIELD_TEXT, "", "the edge crossed: start, bottom, left, right or top", 0,
         NULL, NULL, 0, t_edge, 0, 0},
        NUMBER("step", BSIM_FIELD_INT, "", "the step at whose end the body was inside", e_step),
        NUMBER("t", BSIM_FIELD_FIXED, "s", "the time of that step's end", e_t),
        NUMBER("pos", BSIM_FIELD_REAL, "m", "where the path crossed the edge, gate frame", e_pos),
        NUMBER("x", BSIM_FIELD_REAL, "m", "the body's x, gate frame", e_x),
        NUMBER("y", BSIM_FIELD_REAL, "m", "the body's y, gate frame", e_y),
        NUMBER("vx", BSIM_FIELD_REAL, "m/s", "the body's velocity, x", e_vx),
        NUMBER("vy", BSIM_FIELD_REAL, "m/s", "the body's velocity, y", e_vy),
        NUMBER("theta_left", BSIM_FIELD_REAL, "rad", "the gate's left beam's angle", e_theta_left),
        NUMBER("omega_left", BSIM_FIELD_REAL, "rad/s", "its angular velocity", e_omega_left),
        NUMBER("theta_right", BSIM_FIELD_REAL, "rad", "the gate's right beam's angle",
               e_theta_right),
        NUMBER("omega_right", BSIM_FIELD_REAL, "rad/s", "its angular velocity", e_omega_right),
};

/* The gate of peak row->seq's beam: ix, iy or side (0 left, 1 right). */
static double peak_gate(const bsim_trial_row *row, int which)
{
	int g[3];
	bsim_lattice_beam_gate(row->def, row->log->peaks[row->seq].beam, &g[0], &g[1], &g[2]);
	return g[which];
}

static double p_beam(const bsim_trial_row *row)
{
	return row->log->peaks[row->seq].beam;
}

static double p_ix(const bsim_trial_row *row)
{
	return peak_gate(row, 0);
}

static double p_iy(const bsim_trial_row *row)
{
	return peak_gate(row, 1);
}

static double p_side(const bsim_trial_row *row)
{
	return peak_gate(row, 2) != 0;
}

static double p_peak(const bsim_trial_row *row)
{
	return row->log->peaks[row->seq].peak;
}

static const char *const side_words[] = {"left", "right"};

static const bsim_trial_field peak_fields[] = {
        {"group", BSIM_FIELD_INT, "", "the group, 0-based", 1, f_group, NULL, 0, NULL, 0, 0},
        {"trial", BSIM_FIELD_INT, "", "the trial within its group, 0-based", 1, f_trial, NULL, 0,
         NULL, 0, 0},
        {"beam", BSIM_FIELD_INT, "", "the beam, the scene's, 0-based", 1, p_beam, NULL, 0, NULL, 0,
         0},
        NUMBER("ix", BSIM_FIELD_INT, "", "its gate's column", p_ix),
        NUMBER("iy", BSIM_FIELD_INT, "", "its gate's row", p_iy),
        {"side", BSIM_FIELD_WORD, "", "its side of the gate: left or right", 0, p_side, side_words,
         2, NULL, 0, 0},
        NUMBER("max_theta", BSIM_FIELD_REAL, "rad", "its peak angle over the trial", p_peak),
};

const bsim_trial_field *bsim_gate_entry_fields(int *n)
{
	*n = (int)(sizeof entry_fields / sizeof entry_fields[0]);
	return entry_fields;
}

const bsim_trial_field *bsim_beam_peak_fields(int *n)
{
	*n = (int)(sizeof peak_fields / sizeof peak_fields[0]);
	return peak_fields;
}

double bsim_trial_field_number(const bsim_trial_field *f, const bsim_trial_row *row)
{
	double x = f->value(row);
	if (f->kind == BSIM_FIELD_INT)
		return (double)(long long)x;
	if (f->kind == BSIM_FIELD_MEASURED && isnan(x))
		return NAN;
	char text[400]; /* "%.6f" of the largest double: 316 characters */
	snprintf(text, sizeof text, f->kind == BSIM_FIELD_FIXED ? "%.6f" : "%.10g", x);
	return strtod(text, NULL);
}

void bsim_trial_field_write(FILE *out, const bsim_trial_field *f, const bsim_trial_row *row)
{
	switch (f->kind) {
	case BSIM_FIELD_INT:
		fprintf(out, "%lld", (long long)f->value(row));
		return;
	case BSIM_FIELD_REAL:
		fprintf(out, "%.10g", f->value(row));
		return;
	case BSIM_FIELD_MEASURED: {
		double x = f->value(row);
		if (!isnan(x))
			fprintf(out, "%.10g", x);
		return;
	}
	case BSIM_FIELD_WORD: {
		int k = (int)f->value(row);
		fputs(k >= 0 && k < f->n_words ? f->words[k] : "?", out);
		return;
	}
	case BSIM_FIELD_TEXT:
		f->text(out, row);
		return;
	case BSIM_FIELD_FIXED:
		fprintf(out, "%.6f", f->value(row));
		return;
	}
}

void bsim_trial_fields_header(FILE *out, const bsim_trial_field *f, int n)
{
	for (int c = 0; c < n; c++)
		fprintf(out, "%s%s", c ? "," : "", f[c].name);
	fputc('\n', out);
}

void bsim_trial_fields_line(FILE *out, const bsim_trial_field *f, int n, const bsim_trial_row *row)
{
	for (int c = 0; c < n; c++) {
		if (c)
			fputc(',', out);
		bsim_trial_field_write(out, &f[c], row);
	}
	fputc('\n', out);
}

/* ---- the result as it lies in memory (a journal's record) --------------- */

/* Every member of each struct: the result's as beamsim/trial.h lists
 * them (a nested struct's by their path), a gate entry's and a beam
 * peak's here. A member of a struct left out leaves a gap that
 * test_journal finds. */
#define ENTRY_MEMBERS(X) X(ix) X(iy) X(edge) X(step) X(t) X(pos) X(x) X(v) X(theta) X(omega)
#define PEAK_MEMBERS(X)  X(beam) X(peak)

/* A member's kind from its type, so that the table cannot misname it (an
 * enum is an unsigned int here; an array is its element's kind). A type
 * not listed does not compile. */
#define KIND_OF(e)                                                                                 \
	_Generic((e), int: "int", unsigned int: "uint", long: "long", unsigned long: "ulong",      \
	         double: "double", double *: "double")

#define MEMBER(T, name, m) {name, KIND_OF(((T *)0)->m), offsetof(T, m), sizeof(((T *)0)->m)},
#define RESULT_MEMBER(m)   MEMBER(bsim_trial_result, #m, m)
#define LEDGER_MEMBER(m)   MEMBER(bsim_trial_result, "ledger." #m, ledger.m)
#define SOLVER_MEMBER(m)   MEMBER(bsim_trial_result, "solver." #m, solver.m)
#define ENTRY_MEMBER(m)    MEMBER(bsim_gate_entry, "gate_entry." #m, m)
#define PEAK_MEMBER(m)     MEMBER(bsim_beam_peak, "beam_peak." #m, m)

/* clang-format off */
static const bsim_trial_member members[] = {
	BSIM_TRIAL_RESULT_PLAIN(RESULT_MEMBER)
	BSIM_TRIAL_RESULT_OTHER(RESULT_MEMBER)
	BSIM_LEDGER_SHOWN(LEDGER_MEMBER)
	BSIM_LEDGER_OTHER(LEDGER_MEMBER)
	BSIM_SOLVER_COUNTS(SOLVER_MEMBER)
	ENTRY_MEMBERS(ENTRY_MEMBER)
	PEAK_MEMBERS(PEAK_MEMBER)
};
/* clang-format on */

#define COUNT(LIST) (0 LIST(ONE))
#define ONE(m)      +1
enum {
	N_RESULT = COUNT(BSIM_TRIAL_RESULT_PLAIN) + COUNT(BSIM_TRIAL_RESULT_OTHER) +
	           COUNT(BSIM_LEDGER_SHOWN) + COUNT(BSIM_LEDGER_OTHER) + COUNT(BSIM_SOLVER_COUNTS),
	N_ENTRY = COUNT(ENTRY_MEMBERS),
	N_PEAK = COUNT(PEAK_MEMBERS),
};

const bsim_trial_member *bsim_trial_members(int *n)
{
	*n = (int)(sizeof members / sizeof members[0]);
	return members;
}

static char record_fields[4096];
static pthread_once_t record_fields_once = PTHREAD_ONCE_INIT;

static void record_fields_make(void)
{
	static const struct {
		const char *name;
		size_t size;
		int n;
	} structs[] = {{"bsim_trial_result", sizeof(bsim_trial_result), N_RESULT},
	               {"bsim_gate_entry", sizeof(bsim_gate_entry), N_ENTRY},
	               {"bsim_beam_peak", sizeof(bsim_beam_peak), N_PEAK}};
	size_t used = 0;
	const bsim_trial_member *m = members;
	for (int s = 0; s < 3; s++) {
		used += (size_t)snprintf(record_fields + used, sizeof record_fields - used,
		                         "%s %zu\n", structs[s].name, structs[s].size);
		for (int k = 0; k < structs[s].n; k++, m++) {
			const char *dot = strchr(m->name, '.');
			/* a gate entry's or peak's member by its own name */
			const char *name = s > 0 && dot ? dot + 1 : m->name;
			used += (size_t)snprintf(record_fields + used, sizeof record_fields - used,
			                         "%s %s %zu %zu\n", name, m->kind, m->offset,
			                         m->size);
		}
	}
}

const char *bsim_trial_record_fields(void)
{
	pthread_once(&record_fields_once, record_fields_make);
	return record_fields;
}
