/* DIR/viewer_data.js and DIR/viewer.js, the trajectory player of
 * index.html (store/viewer_data.h).
 *
 * viewer_data.js assigns one object, window.beamsimViewerData:
 *
 *   format      "beamsim-viewer-1"
 *   caps        {trajectories, frames, values}: viewer_data.h's caps
 *   kept        the trajectories the first side's file holds
 *   scenes      [{name, grid, body: {shape, radius, length, semi_axes,
 *               heading (rad), rotates, start}, beams: [{pivot, length,
 *               rest (rad, the rest direction's angle from +x), sign (+1 if a
 *               forward swing turns the beam counter-clockwise), stiffness}],
 *               side_x, success_y, f_prop, along ("y" or "heading"), rm}]
 *   landscapes  [{file, x0, dx, nx, y0, dy, ny, e_min, e_max, e}]: E_total as
 *               the landscape figure draws it (its .surface.dat's fourth
 *               column), e[j nx + i] at (x0 + i dx, y0 + j dy), J
 *   trials      [{group, trial, label, scene, landscape}]: scene and
 *               landscape index the lists above (landscape -1: none)
 *   sides       [{label, file, columns, trajectories: [{group, trial, rows,
 *               every, frames}]}]: a frame is [row, t, x, y, (heading),
 *               (f_rand), theta1..N, contact1..N] as columns names them,
 *               row the data row of file it is (0 the row after the header);
 *               every k-th row of the trajectory's `rows` and its last.
 *
 * Numbers are the files' own, read back and written as the shortest text
 * that reads back the same (util/json.h), so the player draws exactly the
 * state the files hold. */
#define _POSIX_C_SOURCE 200809L
#include "store/viewer_data.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "beamsim/compare_dir.h"
#include "beamsim/experiment.h"
#include "beamsim/limits.h"
#include "store/stored_run.h"
#include "util/atomic_file.h"
#include "util/csv_stream.h"
#include "util/csv_table.h"
#include "util/json.h"
#include "util/yaml_doc.h"
#include "viewer_js.h" /* bsim_viewer_js: src/store/viewer.js (cmake/embed_text.cmake) */

#define VIEWER_SIDES BSIM_COMPARE_SIDES_MAX

/* The landscape figure's grid is 51 points across (figures_paths.c); a
 * surface file of more points than this is not one of its. */
#define VIEWER_LANDSCAPE_POINTS 250000

typedef struct vside {
	char label[128];
	char rel[BSIM_PATH_MAX];    /* the trajectories' file as the page names it */
	char path[BSIM_PATH_MAX];   /* where it is read */
	char folder[BSIM_NAME_MAX]; /* "" or the side's folder with its '/' */
} vside;

typedef struct vtraj {
	long group, trial;
	int scene;
	long rows[VIEWER_SIDES]; /* in each side's file; 0: not kept there */
	int written;             /* by the side being written */
} vtraj;

typedef struct vland {
	char rel[BSIM_PATH_MAX];
	double x0, dx, y0, dy, e_min, e_max;
	int nx, ny;
	double *e;
} vland;

typedef struct viewer {
	const char *stage, *dir;
	int add;
	int is_run;
	bsim_run_scene run; /* a run's scene and record */
	bsim_experiment e;  /* a sweep's or comparison's experiment */
	int has_e;
	int n_sides;
	vside side[VIEWER_SIDES];
	int n;
	vtraj traj[BSIM_VIEWER_TRAJECTORIES];
	long kept;
	int n_scenes;
	long scene_group[BSIM_VIEWER_TRAJECTORIES];
	bsim_scene scenes[BSIM_VIEWER_TRAJECTORIES];
	int scene_land[BSIM_VIEWER_TRAJECTORIES];
	int n_lands;
	vland lands[BSIM_VIEWER_TRAJECTORIES];
} viewer;

static int is_file(const char *path)
{
	struct stat st;
	return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

/* The set's file rel: in stage, else (adding to dir) in dir. 1 and its
 * path, or 0 if the set has none. */
static int find(const viewer *v, const char *rel, char *path, size_t size)
{
	if (snprintf(path, size, "%s/%s", v->stage, rel) < (int)size && is_file(path))
		return 1;
	return v->add && snprintf(path, size, "%s/%s", v->dir, rel) < (int)size && is_file(path);
}

/* The directory whose run.json is the set's (stage's, else dir's), or NULL. */
static const char *record_root(const viewer *v)
{
	char path[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/run.json", v->stage);
	if (is_file(path))
		return v->stage;
	snprintf(path, sizeof path, "%s/run.json", v->dir);
	return v->add && is_file(path) ? v->dir : NULL;
}

/* run.json's "command" into buf (16 bytes), and for a sweep or comparison
 * the label of each side ("backends": [{"label"}], docs/files.md) into
 * labels, *n of them. The record is read here rather than by
 * bsim_run_record_read, which comes with the stored runs' writers: the
 * page is written at the end of one of them (store/session.h). */
static int record_read(const char *root, char *buf, char labels[][128], int *n, bsim_error *err)
{
	char path[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/run.json", root);
	ydoc d;
	int rc = bsim_ydoc_load_own(&d, path, err);
	if (rc)
		return rc;
	struct fy_node *top = fy_document_root(d.fyd);
	struct fy_node *c = bsim_ydoc_lookup(top, "command");
	size_t len = 0;
	const char *t = c && fy_node_is_scalar(c) ? fy_node_get_scalar(c, &len) : "";
	snprintf(buf, 16, "%.*s", (int)(len < 15 ? len : 15), t ? t : "");
	*n = 0;
	struct fy_node *sides = bsim_ydoc_lookup(top, "backends");
	int count = sides && fy_node_is_sequence(sides) ? fy_node_sequence_item_count(sides) : 0;
	for (int i = 0; i < count && i < VIEWER_SIDES && !rc; i++) {
		char at[32];
		snprintf(at, sizeof at, "%d.label", i);
		struct fy_node *l = bsim_ydoc_lookup(sides, at);
		t = l && fy_node_is_scalar(l) ? fy_node_get_scalar(l, &len) : NULL;
		if (!t || len == 0 || len >= sizeof labels[0])
			rc = bsim_ydoc_expected(&d, l, sides, "backends", "a label of each side",
			                        err);
		else
			snprintf(labels[(*n)++], sizeof labels[0], "%.*s", (int)len, t);
	}
	bsim_ydoc_free(&d);
	return rc;
}

static void add_side(viewer *v, const char *label, const char *folder)
{
	vside *s = &v->side[v->n_sides];
	snprintf(s->label, sizeof s->label, "%.127s", label);
	snprintf(s->folder, sizeof s->folder, "%s", folder);
	snprintf(s->rel, sizeof s->rel, "%s%s", folder,
	         v->is_run ? "trajectory.csv" : "trajectories.csv");
	if (find(v, s->rel, s->path, sizeof s->path))
		v->n_sides++;
}

/* What the set holds to play: its sides and what their scenes come from.
 * Nothing (n_sides 0) for a set that is no run, sweep or comparison or
 * kept no trajectory. */
static int open_set(viewer *v, bsim_error *err)
{
	const char *root = record_root(v);
	char command[16] = "", labels[VIEWER_SIDES][128];
	int n_labels = 0;
	if (!root)
		return BSIM_OK;
	int rc = record_read(root, command, labels, &n_labels, err);
	if (rc)
		return rc;
	if (strcmp(command, "run") == 0) {
		v->is_run = 1;
		int found = 0;
		char path[BSIM_PATH_MAX];
		if (!find(v, "trajectory.csv", path, sizeof path))
			return BSIM_OK;
		rc = bsim_run_scene_load(root, &v->run, &found, err);
		if (rc || !found)
			return rc;
		add_side(v, v->run.backend, "");
		return BSIM_OK;
	}
	if (strcmp(command, "sweep") != 0 && strcmp(command, "compare") != 0)
		return BSIM_OK;
	for (int i = 0; i < n_labels; i++) {
		char folder[BSIM_NAME_MAX] = "";
		if (n_labels > 1) {
			bsim_compare_dir_label(labels[i], folder, sizeof folder - 1);
			strcat(folder, "/");
		}
		add_side(v, labels[i], folder);
	}
	if (v->n_sides == 0)
		return BSIM_OK;
	char path[BSIM_PATH_MAX];
	snprintf(path, sizeof path, "%s/inputs/experiment.yaml", root);
	rc = bsim_experiment_load(path, NULL, 0, &v->e, err);
	v->has_e = rc == BSIM_OK;
	return rc;
}

/* ---- the trajectories' files ---------------------------------------------------------- */

typedef struct vcols {
	int group, trial, t, x, y, heading, f_rand;
	int n_beams;
	int *theta, *contact; /* n_beams each */
} vcols;

static void vcols_free(vcols *c)
{
	free(c->theta);
	free(c->contact);
	c->theta = c->contact = NULL;
}

static int col_of(const csv_stream *cs, const char *name)
{
	for (int i = 0; i < cs->n_cols; i++)
		if (strcmp(cs->names[i], name) == 0)
			return i;
	return -1;
}

/* The columns of a trajectories file: t, x, y, theta1..N and contact1..N
 * (N from the header), group and trial (a sweep's), heading and f_rand
 * where there are. */
static int vcols_find(const viewer *v, const csv_stream *cs, vcols *c, bsim_error *err)
{
	memset(c, 0, sizeof *c);
	c->group = col_of(cs, "group");
	c->trial = col_of(cs, "trial");
	c->t = col_of(cs, "t");
	c->x = col_of(cs, "x");
	c->y = col_of(cs, "y");
	c->heading = col_of(cs, "heading");
	c->f_rand = col_of(cs, "f_rand");
	char name[32];
	for (;;) {
		snprintf(name, sizeof name, "theta%d", c->n_beams + 1);
		if (col_of(cs, name) < 0)
			break;
		c->n_beams++;
	}
	const char *missing = c->t < 0 ? "t" : c->x < 0 ? "x" : c->y < 0 ? "y" : NULL;
	if (!missing && !v->is_run)
		missing = c->group < 0 ? "group" : c->trial < 0 ? "trial" : NULL;
	if (missing)
		return bsim_error_set(err, BSIM_EINPUT, "%s: expected a column %s", cs->path,
		                      missing);
	c->theta = calloc((size_t)c->n_beams + 1, sizeof *c->theta);
	c->contact = calloc((size_t)c->n_beams + 1, sizeof *c->contact);
	if (!c->theta || !c->contact) {
		vcols_free(c);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	}
	for (int i = 0; i < c->n_beams; i++) {
		snprintf(name, sizeof name, "theta%d", i + 1);
		c->theta[i] = col_of(cs, name);
		snprintf(name, sizeof name, "contact%d", i + 1);
		c->contact[i] = col_of(cs, name);
		if (c->contact[i] < 0) {
			vcols_free(c);
			return bsim_error_set(err, BSIM_EINPUT,
			                      "%s: expected a column contact%d beside theta%d",
			                      cs->path, i + 1, i + 1);
		}
	}
	return BSIM_OK;
}

/* The cell of column col as a number, or BSIM_EINPUT naming file, line and
 * column. */
static int cell_number(const csv_stream *cs, int col, double *out, bsim_error *err)
{
	if (bsim_csv_number(cs->cells[col], out) != 0)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s:%ld: %s: expected a number, got \"%.40s\"", cs->path,
		                      cs->line, cs->names[col], cs->cells[col]);
	return BSIM_OK;
}

/* The row's group and trial (a run's from its record). */
static int row_key(const viewer *v, const csv_stream *cs, const vcols *c, long *g, long *t,
                   bsim_error *err)
{
	if (v->is_run) {
		*g = v->run.group;
		*t = v->run.trial;
		return BSIM_OK;
	}
	double dg, dt;
	int rc = cell_number(cs, c->group, &dg, err);
	if (!rc)
		rc = cell_number(cs, c->trial, &dt, err);
	if (rc)
		return rc;
	if (dg != floor(dg) || dg < 0 || dg >= v->e.n_groups)
		return bsim_error_set(err, BSIM_EINPUT, "%s:%ld: group: expected 0 to %d, got %s",
		                      cs->path, cs->line, v->e.n_groups - 1, cs->cells[c->group]);
	if (dt != floor(dt) || dt < 0 || dt > 2147483647.0)
		return bsim_error_set(err, BSIM_EINPUT,
		                      "%s:%ld: trial: expected an integer >= 0, got %s", cs->path,
		                      cs->line, cs->cells[c->trial]);
	*g = (long)dg;
	*t = (long)dt;
	return BSIM_OK;
}

static int traj_index(const viewer *v, long g, long t)
{
	for (int i = 0; i < v->n; i++)
		if (v->traj[i].group == g && v->traj[i].trial == t)
			return i;
	return -1;
}

/* Pass one over side s's file: the first side's first trajectories join
 * the list; every side counts the rows of those in the list. */
static int count_rows(viewer *v, int s, bsim_error *err)
{
	csv_stream cs;
	vcols c;
	int rc = bsim_csv_stream_open(v->side[s].path, &cs, err);
	if (rc)
		return rc;
	cs.path = v->side[s].path;
	rc = vcols_find(v, &cs, &c, err);
	if (rc) {
		bsim_csv_stream_close(&cs);
		return rc;
	}
	long pg = -1, pt = -1;
	int idx = -1, r;
	while (!rc && (r = bsim_csv_stream_next(&cs, err)) == 1) {
		long g, t;
		if ((rc = row_key(v, &cs, &c, &g, &t, err)))
			break;
		if (g != pg || t != pt) {
			idx = traj_index(v, g, t);
			if (idx < 0 && s == 0) {
				v->kept++;
				if (v->n < BSIM_VIEWER_TRAJECTORIES) {
					idx = v->n++;
					v->traj[idx] = (vtraj){.group = g, .trial = t};
				}
			}
			pg = g;
			pt = t;
		}
		if (idx >= 0)
			v->traj[idx].rows[s]++;
	}
	if (!rc && r < 0)
		rc = err->code;
	vcols_free(&c);
	bsim_csv_stream_close(&cs);
	return rc;
}

/* The frames of a trajectory of n columns a frame: at most the caps. */
static long frame_cap(int columns)
{
	long cap = BSIM_VIEWER_VALUES / (columns > 0 ? columns : 1);
	cap = cap < BSIM_VIEWER_FRAMES ? cap : BSIM_VIEWER_FRAMES;
	return cap < 3 ? 3 : cap;
}

/* Every k-th row of rows, and the last, is at most cap frames. */
static long row_step(long rows, long cap)
{
	return rows <= cap ? 1 : (rows - 1 + cap - 3) / (cap - 2);
}

/* Pass two: side s as its object of sides (the format above). */
static int write_side(viewer *v, int s, FILE *f, bsim_viewer_summary *sum, bsim_error *err)
{
	const vside *sd = &v->side[s];
	csv_stream cs;
	vcols c;
	int rc = bsim_csv_stream_open(sd->path, &cs, err);
	if (rc)
		return rc;
	cs.path = sd->path;
	rc = vcols_find(v, &cs, &c, err);
	if (rc) {
		bsim_csv_stream_close(&cs);
		return rc;
	}
	for (int i = 0; i < v->n && !rc; i++) {
		const bsim_scene *sc = &v->scenes[v->traj[i].scene];
		v->traj[i].written = 0;
		if (v->traj[i].rows[s] > 0 && sc->n_beams != c.n_beams)
			rc = bsim_error_set(
			        err, BSIM_EINPUT,
			        "%s: %d theta columns for a scene of %d beams (group %ld)",
			        sd->path, c.n_beams, sc->n_beams, v->traj[i].group);
	}
	const int columns = 4 + (c.heading >= 0) + (c.f_rand >= 0) + 2 * c.n_beams;
	const long cap = frame_cap(columns);
	fputs("{\"label\": ", f);
	bsim_json_string(f, sd->label);
	fputs(", \"file\": ", f);
	bsim_json_string(f, sd->rel);
	fputs(", \"columns\": [\"row\", \"t\", \"x\", \"y\"", f);
	if (c.heading >= 0)
		fputs(", \"heading\"", f);
	if (c.f_rand >= 0)
		fputs(", \"f_rand\"", f);
	for (int k = 0; k < 2; k++)
		for (int i = 0; i < c.n_beams; i++)
			fprintf(f, ", \"%s%d\"", k ? "contact" : "theta", i + 1);
	fputs("],\n \"trajectories\": [", f);
	long pg = -1, pt = -1, row = -1, k = 0, every = 1, rows = 0, written = 0, frames = 0;
	int idx = -1, open = 0, r = 0, left = 0; /* left: trajectories of the list still to come */
	for (int i = 0; i < v->n; i++)
		left += v->traj[i].rows[s] > 0;
	while (!rc && (r = bsim_csv_stream_next(&cs, err)) == 1) {
		long g, t;
		row++;
		if ((rc = row_key(v, &cs, &c, &g, &t, err)))
			break;
		if (g != pg || t != pt) {
			if (open)
				fputs("]}", f);
			open = 0;
			if (left == 0)
				break; /* the rest of the file is not played */
			idx = traj_index(v, g, t);
			pg = g;
			pt = t;
			if (idx >= 0 && v->traj[idx].written) {
				rc = bsim_error_set(
				        err, BSIM_EINPUT,
				        "%s:%ld: expected the rows of group %ld, trial %ld "
				        "together, got more after another trial's",
				        sd->path, cs.line, g, t);
				break;
			}
			if (idx >= 0) {
				v->traj[idx].written = open = 1;
				left--;
				rows = v->traj[idx].rows[s];
				every = row_step(rows, cap);
				k = frames = 0;
				fprintf(f,
				        "%s\n  {\"group\": %ld, \"trial\": %ld, \"rows\": %ld, "
				        "\"every\": %ld, \"frames\": [",
				        written++ ? "," : "", g, t, rows, every);
				if (rows > sum->most_rows)
					sum->most_rows = rows;
				if (every > sum->most_every)
					sum->most_every = (int)every;
			}
		}
		if (!open)
			continue;
		long here = k++;
		if (here % every != 0 && here != rows - 1)
			continue;
		int cols[4 + 2] = {c.t, c.x, c.y, c.heading, c.f_rand};
		fprintf(f, "%s\n   [%ld", frames++ ? "," : "", row);
		for (int j = 0; j < 5 && !rc; j++) {
			double x;
			if (cols[j] < 0)
				continue;
			rc = cell_number(&cs, cols[j], &x, err);
			fputc(',', f);
			bsim_json_number(f, x);
		}
		for (int j = 0; j < c.n_beams && !rc; j++) {
			double x;
			rc = cell_number(&cs, c.theta[j], &x, err);
			fputc(',', f);
			bsim_json_number(f, x);
		}
		for (int j = 0; j < c.n_beams && !rc; j++) {
			double x;
			rc = cell_number(&cs, c.contact[j], &x, err);
			fprintf(f, ",%d", isfinite(x) ? (int)x : 0);
		}
		fputc(']', f);
	}
	if (!rc && r < 0)
		rc = err->code;
	if (open)
		fputs("]}", f);
	fputs("]}", f);
	vcols_free(&c);
	bsim_csv_stream_close(&cs);
	return rc;
}

/* ---- scenes and landscapes ------------------------------------------------------------ */

/* The surface of a landscape figure (figures_paths.c): rows "x y E_total
 * E_drawn E_3d", one block of equal y per row of the grid. */
static int land_read(const char *path, vland *l, bsim_error *err)
{
	FILE *in = fopen(path, "r");
	if (!in)
		return bsim_error_set(err, BSIM_EINPUT, "%s: cannot be read", path);
	char line[512];
	long ln = 0, cap = 0, n = 0;
	int rc = BSIM_OK, in_block = 0, block_n = 0;
	double first_x = NAN, last_x = NAN, first_y = NAN, last_y = NAN;
	l->nx = 0;
	l->ny = 0;
	while (!rc && fgets(line, sizeof line, in)) {
		ln++;
		if (line[0] == '#')
			continue;
		double x, y, e_total, e_drawn;
		if (strspn(line, " \t\r\n") == strlen(line)) {
			if (in_block && l->ny == 1)
				l->nx = block_n;
			else if (in_block && block_n != l->nx)
				rc = bsim_error_set(
				        err, BSIM_EINPUT,
				        "%s:%ld: expected %d points in each row of the grid, "
				        "got %d",
				        path, ln, l->nx, block_n);
			in_block = 0;
			continue;
		}
		if (sscanf(line, "%lf %lf %lf %lf", &x, &y, &e_total, &e_drawn) != 4 ||
		    !isfinite(x) || !isfinite(y) || !isfinite(e_drawn)) {
			rc = bsim_error_set(err, BSIM_EINPUT,
			                    "%s:%ld: expected x y E_total E_drawn, finite numbers",
			                    path, ln);
			break;
		}
		if (!in_block) {
			in_block = 1;
			block_n = 0;
			l->ny++;
		}
		if (n == cap) {
			if (cap >= VIEWER_LANDSCAPE_POINTS) {
				rc = bsim_error_set(err, BSIM_EINPUT,
				                    "%s:%ld: expected at most %d points", path, ln,
				                    VIEWER_LANDSCAPE_POINTS);
				break;
			}
			cap = cap ? 2 * cap : 4096;
			double *e = realloc(l->e, (size_t)cap * sizeof *e);
			if (!e) {
				rc = bsim_error_set(err, BSIM_EFAIL, "out of memory");
				break;
			}
			l->e = e;
		}
		l->e[n++] = e_drawn;
		block_n++;
		if (n == 1)
			first_x = x, first_y = y;
		if (l->ny == 1)
			last_x = x;
		last_y = y;
	}
	fclose(in);
	if (!rc && in_block) {
		if (l->ny == 1)
			l->nx = block_n;
		else if (block_n != l->nx)
			rc = bsim_error_set(
			        err, BSIM_EINPUT,
			        "%s:%ld: expected %d points in each row of the grid, got %d", path,
			        ln, l->nx, block_n);
	}
	if (!rc && (l->nx < 2 || l->ny < 2))
		rc = bsim_error_set(err, BSIM_EINPUT,
		                    "%s: expected a grid of at least 2 x 2 points, got %d x %d",
		                    path, l->nx, l->ny);
	if (rc) {
		free(l->e);
		l->e = NULL;
		return rc;
	}
	l->x0 = first_x;
	l->y0 = first_y;
	l->dx = (last_x - first_x) / (l->nx - 1);
	l->dy = (last_y - first_y) / (l->ny - 1);
	l->e_min = INFINITY;
	l->e_max = -INFINITY;
	for (long i = 0; i < n; i++) {
		l->e_min = fmin(l->e_min, l->e[i]);
		l->e_max = fmax(l->e_max, l->e[i]);
	}
	return BSIM_OK;
}

/* The landscape of group g, or of the run: the figure's surface in the
 * set (a comparison's, of the first side that drew it); -1 if none. */
static int land_of(viewer *v, long g, int *out, bsim_error *err)
{
	*out = -1;
	char rel[BSIM_PATH_MAX], path[BSIM_PATH_MAX];
	for (int s = 0; s < v->n_sides; s++) {
		if (v->is_run)
			snprintf(rel, sizeof rel, "landscape_path.surface.dat");
		else
			snprintf(rel, sizeof rel, "%slandscape_g%03ld.surface.dat",
			         v->side[s].folder, g);
		if (!find(v, rel, path, sizeof path))
			continue;
		vland *l = &v->lands[v->n_lands];
		memset(l, 0, sizeof *l);
		snprintf(l->rel, sizeof l->rel, "%s", rel);
		int rc = land_read(path, l, err);
		if (rc)
			return rc;
		*out = v->n_lands++;
		return BSIM_OK;
	}
	return BSIM_OK;
}

/* Each trajectory's scene (one a group), and its landscape. */
static int scenes_make(viewer *v, bsim_error *err)
{
	for (int i = 0; i < v->n; i++) {
		int k = 0;
		while (k < v->n_scenes && v->scene_group[k] != v->traj[i].group)
			k++;
		v->traj[i].scene = k;
		if (k < v->n_scenes)
			continue;
		int rc = v->is_run ? bsim_scene_copy(&v->scenes[k], &v->run.scene)
		                   : bsim_experiment_group_scene(&v->e, (int)v->traj[i].group, NULL,
		                                                 0, &v->scenes[k], err);
		if (rc)
			return v->is_run ? bsim_error_set(err, BSIM_EFAIL, "out of memory") : rc;
		v->scene_group[k] = v->traj[i].group;
		v->n_scenes++;
		if ((rc = land_of(v, v->traj[i].group, &v->scene_land[k], err)))
			return rc;
	}
	return BSIM_OK;
}

/* "k=v, ..." of the group's grid values, or of the run's --set. */
static void grid_text(const viewer *v, long g, char *buf, size_t size)
{
	size_t len = 0;
	buf[0] = '\0';
	if (v->is_run) {
		for (int i = 0; i < v->run.n_sets && len < size; i++) {
			int w = snprintf(buf + len, size - len, "%s%s=%s", i ? ", " : "",
			                 v->run.keys[i], v->run.values[i]);
			len += w > 0 ? (size_t)w : 0;
		}
		return;
	}
	int idx[64] = {0};
	if (v->e.n_axes > 64)
		return;
	bsim_experiment_group_index(&v->e, (int)g, idx);
	for (int a = 0; a < v->e.n_axes && len < size; a++) {
		int w = snprintf(buf + len, size - len, "%s%s=%s", a ? ", " : "", v->e.axes[a].key,
		                 v->e.axes[a].values[idx[a]]);
		len += w > 0 ? (size_t)w : 0;
	}
}

static void scene_json(FILE *f, const viewer *v, int k)
{
	static const char *const shapes[] = {"disk", "capsule", "ellipse"};
	const bsim_scene *s = &v->scenes[k];
	const bsim_body_def *b = &s->body;
	char grid[1024];
	grid_text(v, v->scene_group[k], grid, sizeof grid);
	fputs("{\"name\": ", f);
	bsim_json_string(f, s->name);
	fputs(", \"grid\": ", f);
	bsim_json_string(f, grid);
	fprintf(f, ",\n  \"body\": {\"shape\": \"%s\", \"radius\": ",
	        shapes[b->shape >= 0 && b->shape <= 2 ? b->shape : 0]);
	bsim_json_number(f, b->radius);
	fputs(", \"length\": ", f);
	bsim_json_number(f, b->length);
	fputs(", \"semi_axes\": ", f);
	bsim_json_pair(f, b->semi_axes);
	fputs(", \"heading\": ", f);
	bsim_json_number(f, bsim_body_heading(b));
	fprintf(f, ", \"rotates\": %d, \"start\": ", b->rotates);
	bsim_json_pair(f, b->start);
	fputs("},\n  \"beams\": [", f);
	for (int i = 0; i < s->n_beams; i++) {
		const bsim_beam_def *bm = &s->beams[i];
		double u0[2];
		bsim_scene_beam_rest_direction(bm, u0);
		fputs(i ? ",\n   {\"pivot\": " : "\n   {\"pivot\": ", f);
		bsim_json_pair(f, bm->pivot);
		fputs(", \"length\": ", f);
		bsim_json_number(f, bm->length);
		fputs(", \"rest\": ", f);
		bsim_json_number(f, atan2(u0[1], u0[0]));
		fprintf(f, ", \"sign\": %d, \"stiffness\": ",
		        bsim_scene_beam_forward_sign(bm) > 0 ? 1 : -1);
		bsim_json_number(f, bm->stiffness);
		fputc('}', f);
	}
	fputs("],\n  \"side_x\": ", f);
	bsim_json_number(f, s->side_x);
	fputs(", \"success_y\": ", f);
	bsim_json_number(f, s->success_y);
	fputs(", \"f_prop\": ", f);
	bsim_json_number(f, s->effects.has_propulsion ? s->effects.propulsion_force : 0.0);
	fprintf(f, ", \"along\": \"%s\", \"rm\": ",
	        s->effects.propulsion_along == BSIM_ALONG_HEADING ? "heading" : "y");
	bsim_json_number(f, s->effects.has_random_force ? s->effects.random_magnitude : 0.0);
	fputc('}', f);
}

static void land_json(FILE *f, const vland *l)
{
	fputs("{\"file\": ", f);
	bsim_json_string(f, l->rel);
	fprintf(f, ", \"nx\": %d, \"ny\": %d, \"x0\": ", l->nx, l->ny);
	bsim_json_number(f, l->x0);
	fputs(", \"dx\": ", f);
	bsim_json_number(f, l->dx);
	fputs(", \"y0\": ", f);
	bsim_json_number(f, l->y0);
	fputs(", \"dy\": ", f);
	bsim_json_number(f, l->dy);
	fputs(", \"e_min\": ", f);
	bsim_json_number(f, l->e_min);
	fputs(", \"e_max\": ", f);
	bsim_json_number(f, l->e_max);
	fputs(",\n  \"e\": [", f);
	for (long i = 0; i < (long)l->nx * l->ny; i++)
		fprintf(f, "%s%.6g", i ? (i % 16 ? "," : ",\n   ") : "", l->e[i]);
	fputs("]}", f);
}

static int write_data(viewer *v, const char *path, bsim_viewer_summary *sum, bsim_error *err)
{
	bsim_atomic_file o;
	int rc = bsim_atomic_file_open(&o, path, err);
	if (rc)
		return rc;
	FILE *f = o.f;
	fprintf(f,
	        "/* The trajectories index.html plays (viewer.js), written by beamsim. */\n"
	        "window.beamsimViewerData = {\"format\": \"beamsim-viewer-1\",\n"
	        "\"caps\": {\"trajectories\": %d, \"frames\": %d, \"values\": %d},\n"
	        "\"kept\": %ld,\n\"scenes\": [",
	        BSIM_VIEWER_TRAJECTORIES, BSIM_VIEWER_FRAMES, BSIM_VIEWER_VALUES, v->kept);
	for (int k = 0; k < v->n_scenes; k++) {
		fputs(k ? ",\n " : "\n ", f);
		scene_json(f, v, k);
	}
	fputs("],\n\"landscapes\": [", f);
	for (int k = 0; k < v->n_lands; k++) {
		fputs(k ? ",\n " : "\n ", f);
		land_json(f, &v->lands[k]);
	}
	fputs("],\n\"trials\": [", f);
	for (int i = 0; i < v->n; i++) {
		const vtraj *t = &v->traj[i];
		char label[1200], grid[1024];
		grid_text(v, t->group, grid, sizeof grid);
		if (v->is_run)
			snprintf(label, sizeof label, "trial %ld of group %ld%s%s%s%s", t->trial,
			         t->group, *v->run.outcome ? ": " : "", v->run.outcome,
			         *grid ? "; " : "", grid);
		else
			snprintf(label, sizeof label, "group %ld, trial %ld%s%s", t->group,
			         t->trial, *grid ? ": " : "", grid);
		fprintf(f,
		        "%s\n {\"group\": %ld, \"trial\": %ld, \"scene\": %d, \"landscape\": %d, "
		        "\"label\": ",
		        i ? "," : "", t->group, t->trial, t->scene, v->scene_land[t->scene]);
		bsim_json_string(f, label);
		fputc('}', f);
	}
	fputs("],\n\"sides\": [", f);
	for (int s = 0; s < v->n_sides && !rc; s++) {
		fputs(s ? ",\n" : "\n", f);
		rc = write_side(v, s, f, sum, err);
	}
	fputs("]};\n", f);
	if (rc) {
		bsim_atomic_file_abort(&o);
		return rc;
	}
	return bsim_atomic_file_commit(&o, err);
}

static int write_player(const char *path, bsim_error *err)
{
	bsim_atomic_file o;
	int rc = bsim_atomic_file_open(&o, path, err);
	if (rc)
		return rc;
	fputs(bsim_viewer_js, o.f);
	return bsim_atomic_file_commit(&o, err);
}

int bsim_viewer_write(const char *stage, const char *dir, int add, bsim_viewer_summary *sum,
                      bsim_error *err)
{
	memset(sum, 0, sizeof *sum);
	viewer *v = calloc(1, sizeof *v);
	if (!v)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory");
	v->stage = stage;
	v->dir = dir;
	v->add = add;
	int rc = open_set(v, err);
	for (int s = 0; !rc && s < v->n_sides; s++)
		rc = count_rows(v, s, err);
	if (!rc && v->n > 0)
		rc = scenes_make(v, err);
	if (!rc && v->n > 0) {
		char path[BSIM_PATH_MAX];
		sum->sides = v->n_sides;
		sum->shown = v->n;
		sum->kept = v->kept;
		sum->landscapes = v->n_lands;
		sum->most_every = 1;
		snprintf(path, sizeof path, "%s/viewer_data.js", stage);
		rc = write_data(v, path, sum, err);
		snprintf(path, sizeof path, "%s/viewer.js", stage);
		if (!rc)
			rc = write_player(path, err);
		if (rc)
			sum->shown = 0;
	}
	for (int k = 0; k < v->n_scenes; k++)
		bsim_scene_free(&v->scenes[k]);
	for (int k = 0; k < v->n_lands; k++)
		free(v->lands[k].e);
	if (v->is_run)
		bsim_run_scene_free(&v->run);
	if (v->has_e)
		bsim_experiment_free(&v->e);
	free(v);
	return rc;
}
