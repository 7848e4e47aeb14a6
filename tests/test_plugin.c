/* A backend from outside the tree (beamsim/backend_plugin.h): the example
 * plug-in (examples/plugin_gate_euler.c) loaded by the library, by
 * BEAMSIM_PLUGINS and by --backend plugin:PATH, found by its name, recorded
 * with its library so that regress loads it again; and the libraries a
 * loader must refuse (tests/plugins/plugin_faulty.c), each with the file and
 * the reason. Its physics is the per-backend tests' (docs/tests.md, "Every
 * backend"), which run it beside the built-in backends. */
#define _POSIX_C_SOURCE 200809L

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "support.h"

#include "beamsim/backend_plugin.h"
#include "beamsim/backend_registry.h"

/* The path of faulty plug-in k (tests/CMakeLists.txt). */
static const char *faulty(int k)
{
	static char path[1024];
	snprintf(path, sizeof path, "%s%d.so", BSIM_TEST_PLUGIN_FAULTY, k);
	return path;
}

/* Loaded once, the same table by every route; listed after the built-in
 * backends, with the absolute path of its library. */
static void test_load_and_find(void **state)
{
	(void)state;
	const bsim_backend *const *list = bsim_backend_list();
	int built_in = 0;
	while (list[built_in])
		built_in++;
	for (int i = 0; i < built_in; i++)
		assert_null(bsim_backend_plugin_path(list[i]));
	bsim_error err;
	const bsim_backend *b = bsim_backend_load(BSIM_TEST_PLUGIN, &err);
	assert_non_null(b);
	assert_string_equal(b->name, "gate_euler");
	assert_ptr_equal(bsim_backend_load(BSIM_TEST_PLUGIN, &err), b);
	assert_ptr_equal(bsim_backend_find("gate_euler", &err), b);
	char spec[1100];
	snprintf(spec, sizeof spec, "plugin:%s", BSIM_TEST_PLUGIN);
	assert_ptr_equal(bsim_backend_find(spec, &err), b);
	assert_int_equal(bsim_backend_spec_name("plugin:/a/b.so:iterations=3"),
	                 strlen("plugin:/a/b.so"));
	assert_int_equal(bsim_backend_spec_name("thesis:slop=1e-6"), strlen("thesis"));
	list = bsim_backend_list();
	assert_ptr_equal(list[built_in], b);
	assert_null(list[built_in + 1]);
	const char *path = bsim_backend_plugin_path(b);
	assert_non_null(path);
	assert_true(path[0] == '/');
	assert_non_null(strstr(path, "libgate_euler.so"));
	assert_int_equal(bsim_backend_plugins_status(&err), BSIM_OK);
}

/* Each faulty library refused with its path and the reason; nothing
 * registered. */
static void test_refused(void **state)
{
	(void)state;
	static const char *const why[] = {"", "a backend named thesis is registered already",
	                                  "field advance is empty",
	                                  "the backend's name \"bad name\" has a character",
	                                  "built against backend interface"};
	const bsim_backend *const *list = bsim_backend_list();
	int before = 0;
	while (list[before])
		before++;
	for (int k = 1; k <= 4; k++) {
		bsim_error err;
		assert_null(bsim_backend_load(faulty(k), &err));
		print_message("refused: %s\n", err.msg);
		assert_int_equal(err.code, BSIM_EINPUT);
		assert_non_null(strstr(err.msg, faulty(k)));
		assert_non_null(strstr(err.msg, why[k]));
	}
	/* not a library; a library that is not a plug-in */
	bsim_error err;
	assert_null(bsim_backend_load(bsim_test_src("README.md"), &err));
	assert_non_null(strstr(err.msg, "cannot be loaded"));
	assert_null(bsim_backend_load(BSIM_TEST_LIBBEAMSIM, &err));
	assert_non_null(strstr(err.msg, "exports no bsim_plugin"));
	int after = 0;
	while (list[after])
		after++;
	assert_int_equal(after, before);
	assert_null(bsim_backend_find("plugin:/nonexistent/lib.so", &err));
	assert_non_null(strstr(err.msg, "--backend plugin:/nonexistent/lib.so"));
}

/* BEAMSIM_PLUGINS: the commands list the plug-in by its name; one that
 * fails to load stops every command with exit status 2, naming the
 * variable, the file and the reason. */
static void test_environment(void **state)
{
	(void)state;
	setenv(BSIM_PLUGINS_ENV, BSIM_TEST_PLUGIN, 1);
	const char *backends[] = {"backends", NULL};
	char *out = NULL, *err = NULL;
	assert_int_equal(bsim_test_cli(backends, &out, &err), 0);
	assert_non_null(strstr(out, "\ngate_euler\n"));
	free(out);
	free(err);
	char both[2100];
	snprintf(both, sizeof both, "%s:%s", BSIM_TEST_PLUGIN, faulty(2));
	setenv(BSIM_PLUGINS_ENV, both, 1);
	const char *needles[] = {BSIM_PLUGINS_ENV, faulty(2), "field advance is empty", NULL};
	bsim_test_expect_input_error(backends, needles);
	unsetenv(BSIM_PLUGINS_ENV);
}

/* --backend plugin:PATH[:K=V] on sweep and a side of a three-way compare:
 * run.json records the plug-in's name, its options and its library, and
 * regress runs the comparison again from that record alone (no
 * BEAMSIM_PLUGINS), every trial the same; a bad option is refused before
 * anything runs. */
static void test_command_line(void **state)
{
	(void)state;
	unsetenv(BSIM_PLUGINS_ENV);
	const char *dir = bsim_test_dir("plugin_cli");
	const char *exp = bsim_test_src("configs/thesis/h1_symmetric.yaml");
	char spec[1100], side[1200];
	snprintf(spec, sizeof spec, "plugin:%s:iterations=3", BSIM_TEST_PLUGIN);
	char sweep_dir[1024], cmp_dir[1024], again_dir[1024];
	snprintf(sweep_dir, sizeof sweep_dir, "%s", bsim_test_join(dir, "sweep"));
	snprintf(cmp_dir, sizeof cmp_dir, "%s", bsim_test_join(dir, "cmp"));
	snprintf(again_dir, sizeof again_dir, "%s", bsim_test_join(dir, "again"));
	const char *sweep[] = {"sweep", exp,     "--backend", spec, "--trials",
	                       "2",     "--out", sweep_dir,   NULL};
	assert_int_equal(bsim_test_cli(sweep, NULL, NULL), 0);
	char *run = bsim_test_read(bsim_test_join(sweep_dir, "run.json"));
	assert_non_null(run);
	assert_non_null(strstr(run, "\"name\": \"gate_euler\""));
	assert_non_null(strstr(run, "\"iterations\": 3"));
	char recorded[1200];
	snprintf(recorded, sizeof recorded, "\"plugin\": \"");
	assert_non_null(strstr(run, recorded));
	assert_non_null(strstr(run, "libgate_euler.so\""));
	free(run);

	snprintf(side, sizeof side, "thesis,chipmunk,plugin:%s", BSIM_TEST_PLUGIN);
	const char *compare[] = {"compare", exp,     "--backends", side, "--trials",
	                         "3",       "--out", cmp_dir,      NULL};
	char *out = NULL;
	assert_int_equal(bsim_test_cli(compare, &out, NULL), 0);
	assert_non_null(strstr(out, "thesis vs chipmunk vs gate_euler on "));
	free(out);
	assert_true(bsim_test_exists(bsim_test_join(cmp_dir, "gate_euler/trials.csv")));
	const char *regress[] = {"regress", cmp_dir, "--exact", "--out", again_dir, NULL};
	assert_int_equal(bsim_test_cli(regress, &out, NULL), 0);
	assert_non_null(strstr(out, "gate_euler: 0 of 90 trials changed"));
	free(out);

	snprintf(spec, sizeof spec, "plugin:%s:iterations=0", BSIM_TEST_PLUGIN);
	const char *bad[] = {"sweep",    exp, "--backend", spec,
	                     "--trials", "2", "--out",     bsim_test_join(dir, "bad"),
	                     NULL};
	const char *needles[] = {"iterations >= 1", NULL};
	bsim_test_expect_input_error(bad, needles);
	assert_false(bsim_test_exists(bsim_test_join(dir, "bad")));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_load_and_find),
	        cmocka_unit_test(test_refused),
	        cmocka_unit_test(test_environment),
	        cmocka_unit_test(test_command_line),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
