/* Recording a trial (docs/files.md "`run`"): the layout of the trajectory
 * and ledger CSVs (trial.h gives their columns), their rows, and the row
 * every sink of a recorder receives. */
#include "run/trial_record.h"

#include <string.h>

#include "beamsim/landscape.h"
#include "run/trial_ledger.h"

int bsim_trial_body_columns(const bsim_scene *scene)
{
	return scene->body.rotates || scene->body.shape != BSIM_SHAPE_DISK;
}

void bsim_trial_trajectory_header_body(FILE *f, int n_beams, int body_columns)
{
	fputs("t,x,y,vx,vy", f);
	for (int i = 1; i <= n_beams; i++)
		fprintf(f, ",theta%d,omega%d", i, i);
	fputs(",f_rand", f);
	for (int i = 1; i <= n_beams; i++)
		fprintf(f, ",contact%d", i);
	fputs(body_columns ? ",e_kin,e_beam,e_prop,heading,angular_velocity\n"
	                   : ",e_kin,e_beam,e_prop\n",
	      f);
}

void bsim_trial_trajectory_header(FILE *f, int n_beams)
{
	bsim_trial_trajectory_header_body(f, n_beams, 0);
}

void bsim_trial_ledger_header(FILE *f)
{
	fputs("t,e_kin,e_beam,e_mech,w_prop,w_rand,damper,impact,contact,correction,residual,sleep,"
	      "reset\n",
	      f);
}

void bsim_trial_trajectory_row(void *file, const bsim_record_row *row)
{
	FILE *f = file;
	const bsim_state *s = row->state;
	fprintf(f, "%.6f,%.10g,%.10g,%.10g,%.10g", row->t, s->x[0], s->x[1], s->v[0], s->v[1]);
	for (int i = 0; i < s->n_beams; i++)
		fprintf(f, ",%.10g,%.10g", s->theta[i], s->omega[i]);
	fprintf(f, ",%.10g", row->f_rand);
	for (int i = 0; i < s->n_beams; i++)
		fprintf(f, ",%d", s->contact[i]);
	if (row->body_columns)
		fprintf(f, ",%.10g,%.10g,%.10g,%.10g,%.10g\n", row->e_kin, row->e_beam, row->e_prop,
		        s->heading, s->angular_velocity);
	else
		fprintf(f, ",%.10g,%.10g,%.10g\n", row->e_kin, row->e_beam, row->e_prop);
}

static void ledger_row(FILE *f, const bsim_record_row *row)
{
	const bsim_ledger *l = row->ledger;
	fprintf(f, "%.6f,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g\n",
	        row->t, row->e_kin, row->e_beam, row->e_kin + row->e_beam, l->w_prop, l->w_rand,
	        l->damper, l->impact, l->contact, l->correction, l->residual, l->sleep, l->reset);
}

void bsim_trial_record_row(const bsim_recorder *rec, const bsim_scene *sc, const bsim_state *s,
                           long step, double f_rand, const bsim_ledger *ledger)
{
	bsim_record_row row = {
	        .step = step,
	        .t = (double)step * sc->dt,
	        .state = s,
	        .f_rand = f_rand,
	        .ledger = ledger,
	        .e_kin = energy_kinetic(sc, s),
	        .e_beam = energy_springs(sc, s),
	        .e_prop = bsim_landscape_e_prop(sc, s->x[1]),
	        .body_columns = bsim_trial_body_columns(sc),
	};
	if (rec->csv)
		bsim_trial_trajectory_row(rec->csv, &row);
	if (rec->ledger)
		ledger_row(rec->ledger, &row);
	if (rec->record)
		rec->record(rec->record_user, &row);
}

/* The essay's world holds two beams: the whole state takes those listed
 * active, where the map puts them. */
const bsim_state *bsim_trial_record_state(bsim_state *whole, const int *map, const bsim_state *s)
{
	if (!map)
		return s;
	int local[2];
	for (int k = 0; k < s->n_active && k < 2; k++)
		local[k] = map[s->active[k]];
	bsim_state_set_active(whole, local, s->n_active < 2 ? s->n_active : 2);
	memcpy(whole->x, s->x, sizeof whole->x);
	memcpy(whole->v, s->v, sizeof whole->v);
	whole->heading = s->heading;
	whole->angular_velocity = s->angular_velocity;
	for (int k = 0; k < s->n_active && k < 2; k++) {
		int i = s->active[k];
		whole->theta[map[i]] = s->theta[i];
		whole->omega[map[i]] = s->omega[i];
		whole->contact[map[i]] = s->contact[i];
	}
	whole->energy = s->energy;
	whole->impacts = s->impacts;
	return whole;
}
