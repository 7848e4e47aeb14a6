/* Display names of scene keys (beamsim/key_names.h), against the scene
 * schema itself: every key a grid or --set can give a number has a name
 * and a unit, so no figure falls back to a YAML path. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/key_names.h"
#include "model/scene_internal.h"

/* Walks a schema table; each numeric key (numbers, integers, pairs, and the
 * lattice's own numeric keys read later) must be found. Beam keys are tried
 * as beams.0 and beams.1. */
static int walk(const scene_table *t, const char *prefix, char *missing, size_t size)
{
	int n = 0;
	for (int i = 0; i < t->n_fields; i++) {
		const scene_field *f = &t->fields[i];
		char key[160];
		snprintf(key, sizeof key, "%s%s", prefix, f->key);
		if (f->kind == SK_BLOCK || f->kind == SK_LATTICE) {
			char p[200];
			snprintf(p, sizeof p, "%s.", key);
			n += walk(f->sub, p, missing, size);
			continue;
		}
		if (f->kind == SK_BEAMS) {
			n += walk(f->sub, "beams.0.", missing, size);
			n += walk(f->sub, "beams.1.", missing, size);
			continue;
		}
		if (f->kind == SK_NAME || strcmp(key, "lattice.stiffness_file") == 0 ||
		    strcmp(key, "lattice.protocol") == 0 ||
		    strcmp(key, "effects.random_force.model") == 0) /* words, not numbers */
			continue;
		bsim_key_name k;
		if (!bsim_key_name_find(key, &k)) {
			size_t used = strlen(missing);
			snprintf(missing + used, size - used, " %s", key);
			n++;
		}
	}
	return n;
}

static void every_numeric_key_has_a_name(void **state)
{
	(void)state;
	char missing[2000] = "";
	int n = walk(&bsim_scene_top_table, "", missing, sizeof missing);
	if (n)
		fail_msg("%d keys without a display name:%s", n, missing);
}

static void labels_read_as_the_essay_writes_them(void **state)
{
	(void)state;
	char buf[200];
	bsim_key_label("effects.propulsion.force", 0, buf, sizeof buf);
	assert_string_equal(buf, "propulsive force F_prop (N)");
	bsim_key_label("effects.random_force.magnitude", 1, buf, sizeof buf);
	assert_string_equal(buf, "random force magnitude R_{m} (N)");
	bsim_key_label("beams.0.stiffness", 0, buf, sizeof buf);
	assert_string_equal(buf, "left beam stiffness k_1 (N m/rad)");
	bsim_key_label("beams.1.stiffness", 0, buf, sizeof buf);
	assert_string_equal(buf, "right beam stiffness k_2 (N m/rad)");
	bsim_key_label("beams.4.damping", 1, buf, sizeof buf);
	assert_string_equal(buf, "beam 5 damping c_{5} (N m s/rad)");
	bsim_key_label("contact.restitution", 0, buf, sizeof buf);
	assert_string_equal(buf, "restitution e");
	bsim_key_value("effects.random_force.magnitude", "30", 0, buf, sizeof buf);
	assert_string_equal(buf, "R_m = 30 N");
}

/* A key outside the table reads as itself; drawn in gnuplot's enhanced
 * text its underscores must stay underscores, not subscripts. */
static void an_unknown_key_reads_as_itself(void **state)
{
	(void)state;
	bsim_key_name k;
	assert_int_equal(bsim_key_name_find("beams.x.stiffness", &k), 0);
	assert_int_equal(bsim_key_name_find("beams.0.stiff", &k), 0);
	assert_int_equal(bsim_key_name_find("body.rest_mass", &k), 0);
	assert_string_equal(k.name, "body.rest_mass");
	assert_string_equal(k.symbol_gp, "body.rest\\_mass");
	assert_string_equal(k.unit, "");
	char buf[100];
	bsim_key_label("body.rest_mass", 1, buf, sizeof buf);
	assert_string_equal(buf, "body.rest\\_mass");
	bsim_key_label("body.rest_mass", 0, buf, sizeof buf);
	assert_string_equal(buf, "body.rest_mass");
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(every_numeric_key_has_a_name),
	        cmocka_unit_test(labels_read_as_the_essay_writes_them),
	        cmocka_unit_test(an_unknown_key_reads_as_itself),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
