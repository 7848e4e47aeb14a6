/* The output primitives every file goes through: JSON numbers that read
 * back to the same double, escaped strings, and atomic files that appear
 * whole or not at all. */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "util/atomic_file.h"
#include "util/json.h"
#include "support.h"

/* The JSON text of x (static storage). */
static const char *json_of_number(double x)
{
	static char buf[64];
	memset(buf, 0, sizeof buf);
	FILE *f = fmemopen(buf, sizeof buf - 1, "w");
	bsim_json_number(f, x);
	fclose(f);
	return buf;
}

static void test_json_numbers_round_trip(void **state)
{
	(void)state;
	const double xs[] = {0.42,      0.1 + 0.2,          1.0 / 3.0,
	                     -2.5e-300, 4.9e-324,           1.7976931348623157e308,
	                     12,        0.03699349820698568};
	for (size_t i = 0; i < sizeof xs / sizeof xs[0]; i++)
		assert_true(strtod(json_of_number(xs[i]), NULL) == xs[i]);
	assert_string_equal(json_of_number(0.42), "0.42"); /* the shortest form */
	assert_string_equal(json_of_number(NAN), "null");
	assert_string_equal(json_of_number(INFINITY), "null");
}

static void test_json_string_escapes(void **state)
{
	(void)state;
	char buf[128] = {0};
	FILE *f = fmemopen(buf, sizeof buf - 1, "w");
	bsim_json_string(f, "a\"b\\c\nd\te");
	fclose(f);
	assert_string_equal(buf, "\"a\\\"b\\\\c\\nd\\te\"");
}

static void test_atomic_file(void **state)
{
	(void)state;
	const char *dir = bsim_test_dir("atomic");
	char path[1100];
	snprintf(path, sizeof path, "%s/out.txt", dir);
	bsim_atomic_file a;
	bsim_error err;
	assert_int_equal(bsim_atomic_file_open(&a, path, &err), BSIM_OK);
	fputs("half", a.f);
	assert_int_not_equal(access(path, F_OK), 0); /* nothing visible before commit */
	bsim_atomic_file_abort(&a);
	assert_int_not_equal(access(path, F_OK), 0);
	assert_int_not_equal(access(a.tmp, F_OK), 0); /* no temporary left behind */

	assert_int_equal(bsim_atomic_file_open(&a, path, &err), BSIM_OK);
	fputs("whole", a.f);
	assert_int_equal(bsim_atomic_file_commit(&a, &err), BSIM_OK);
	char *text = bsim_test_read(path);
	assert_string_equal(text, "whole");
	free(text);

	char bad[1100];
	snprintf(bad, sizeof bad, "%s/missing/out.txt", dir);
	assert_int_not_equal(bsim_atomic_file_open(&a, bad, &err), BSIM_OK);
	assert_non_null(strstr(err.msg, "missing/out.txt"));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_json_numbers_round_trip),
	        cmocka_unit_test(test_json_string_escapes),
	        cmocka_unit_test(test_atomic_file),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
