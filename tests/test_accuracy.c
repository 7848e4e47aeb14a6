/* beamsim accuracy: (a) the PNG writer gives a valid file (signature,
 * IHDR, chunk CRCs and the zlib Adler-32 checked by code written here, not
 * the writer's); (b) the consistency error of the thesis backend falls at
 * order 2 for implicit midpoint and order 1 for semi-implicit Euler in
 * smooth motion (two beams in free damped vibration, no impacts):
 * e(h) / e(h/2) ~ 2^q; (c) the command runs (--quick) and writes a CSV row
 * per (backend, setting, h) of finite numbers; (d) the errors do not
 * depend on the number of threads. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "beamsim/accuracy.h"
#include "beamsim/plot.h"
#include "support.h"

/* Bit-by-bit CRC-32 (reflected 0xEDB88320), independent of the writer's table. */
static uint32_t crc_bitwise(const unsigned char *p, size_t n)
{
	uint32_t c = 0xFFFFFFFFu;
	for (size_t i = 0; i < n; i++) {
		c ^= p[i];
		for (int k = 0; k < 8; k++)
			c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
	}
	return ~c;
}

static uint32_t be32(const unsigned char *p)
{
	return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

static void test_checksums_known(void **state)
{
	(void)state;
	const unsigned char *w = (const unsigned char *)"Wikipedia";
	assert_int_equal(bsim_adler32(w, 9), 0x11E60398u);
	/* CRC-32 check value of "123456789" (ISO 3309). */
	const unsigned char *d = (const unsigned char *)"123456789";
	assert_int_equal(bsim_crc32(0, d, 9), 0xCBF43926u);
	assert_int_equal(bsim_crc32(bsim_crc32(0, d, 4), d + 4, 5), 0xCBF43926u);
}

/* Encodes an image larger than one stored block and checks every byte of
 * the format that a reader relies on. */
static void test_png_valid(void **state)
{
	(void)state;
	bsim_image im;
	assert_int_equal(bsim_image_alloc(&im, 150, 200, NULL), BSIM_OK); /* 90200 raw bytes */
	bsim_image_line(&im, 0, 0, 149, 199, 2, 0xFF0000u);
	bsim_image_text(&im, 5, 5, "1E-3 SPEED", 1, 0x000000u);
	bsim_image_marker(&im, 50, 50, 2, 7, 0x00FF00u);
	unsigned char *png;
	size_t n;
	assert_int_equal(bsim_png_encode(&im, &png, &n, NULL), BSIM_OK);
	static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
	assert_memory_equal(png, sig, 8);
	size_t k = 8;
	int chunks = 0, saw_ihdr = 0, saw_iend = 0;
	unsigned char *z = malloc(n);
	size_t zn = 0;
	while (k + 12 <= n) {
		uint32_t len = be32(png + k);
		assert_true(k + 12 + len <= n);
		const unsigned char *type = png + k + 4;
		assert_int_equal(be32(png + k + 8 + len), crc_bitwise(type, len + 4));
		if (chunks == 0) {
			assert_memory_equal(type, "IHDR", 4);
			assert_int_equal(len, 13);
			assert_int_equal(be32(type + 4), 150);
			assert_int_equal(be32(type + 8), 200);
			assert_int_equal(type[12], 8); /* bit depth */
			assert_int_equal(type[13], 2); /* RGB */
			assert_int_equal(type[14] | type[15] | type[16], 0);
			saw_ihdr = 1;
		}
		if (memcmp(type, "IDAT", 4) == 0) {
			memcpy(z + zn, type + 4, len);
			zn += len;
		}
		if (memcmp(type, "IEND", 4) == 0)
			saw_iend = 1;
		chunks++;
		k += 12 + len;
	}
	assert_true(saw_ihdr && saw_iend);
	assert_int_equal(k, n);
	/* zlib header, stored blocks, Adler-32 of the filtered scanlines. */
	assert_int_equal((z[0] << 8 | z[1]) % 31, 0);
	assert_int_equal(z[0] & 0x0F, 8);
	size_t raw_n = (150 * 3 + 1) * 200, r = 0, p = 2;
	unsigned char *raw = malloc(raw_n);
	int last = 0, blocks = 0;
	while (!last) {
		last = z[p] & 1;
		assert_int_equal(z[p] >> 1, 0); /* BTYPE 00 */
		unsigned len = z[p + 1] | z[p + 2] << 8, nlen = z[p + 3] | z[p + 4] << 8;
		assert_int_equal(len ^ 0xFFFFu, nlen);
		assert_true(r + len <= raw_n);
		memcpy(raw + r, z + p + 5, len);
		r += len;
		p += 5 + len;
		blocks++;
	}
	assert_true(blocks >= 2);
	assert_int_equal(r, raw_n);
	assert_int_equal(p + 4, zn);
	uint32_t a = 1, b = 0;
	for (size_t i = 0; i < raw_n; i++) {
		a = (a + raw[i]) % 65521;
		b = (b + a) % 65521;
	}
	assert_int_equal(be32(z + p), b << 16 | a);
	/* Row 0 filter 0, then the first pixel (red line from the corner). */
	assert_int_equal(raw[0], 0);
	assert_int_equal(raw[1], 0xFF);
	assert_int_equal(raw[2], 0);
	free(raw);
	free(z);
	free(png);
	bsim_image_free(&im);
}

/* Two beams of the essay's gate released from 0.3 and -0.2 rad, the body
 * at rest out of reach: smooth motion, no impacts. */
static double vibration_consistency(const char *integrator, double h,
                                    const bsim_accuracy_reference *ref)
{
	bsim_scene s;
	bsim_scene_init_gate(&s, 0.0, 0.0);
	s.beams[0].initial_theta = 0.3;
	s.beams[1].initial_theta = -0.2;
	s.dt = h;
	s.max_steps = (int)lround(2.0 / h);
	bsim_options o = {0};
	char kv[64];
	snprintf(kv, sizeof kv, "integrator=%s", integrator);
	assert_int_equal(bsim_options_add(&o, kv, NULL), BSIM_OK);
	double mean, max;
	bsim_error err;
	int rc = bsim_accuracy_consistency(ref, &s, &bsim_backend_thesis, &o, 1, 0.064, 8, &mean,
	                                   &max, &err);
	if (rc)
		print_error("%s\n", err.msg);
	assert_int_equal(rc, BSIM_OK);
	bsim_scene_free(&s);
	return mean;
}

static void test_consistency_order(void **state)
{
	(void)state;
	bsim_scene s;
	bsim_scene_init_gate(&s, 0.0, 0.0);
	s.beams[0].initial_theta = 0.3;
	s.beams[1].initial_theta = -0.2;
	s.dt = 0.000125;
	s.max_steps = 16000; /* 2 s */
	bsim_accuracy_reference ref;
	bsim_error err;
	assert_int_equal(
	        bsim_accuracy_reference_run(&ref, &s, &bsim_backend_thesis, NULL, 1, 0.016, &err),
	        BSIM_OK);
	assert_true(ref.n > 100);
	double m2 = vibration_consistency("midpoint", 0.002, &ref);
	double m1 = vibration_consistency("midpoint", 0.001, &ref);
	double e2 = vibration_consistency("euler", 0.002, &ref);
	double e1 = vibration_consistency("euler", 0.001, &ref);
	print_message("midpoint %.3g -> %.3g (ratio %.2f), euler %.3g -> %.3g (ratio %.2f)\n", m2,
	              m1, m2 / m1, e2, e1, e2 / e1);
	assert_true(m1 > 0 && e1 > 0);
	assert_true(m2 / m1 > 2.5);                  /* order 2: 4 */
	assert_true(e2 / e1 > 1.6 && e2 / e1 < 2.5); /* order 1: 2 */
	assert_true(m1 < e1);
	bsim_accuracy_reference_free(&ref);
	bsim_scene_free(&s);
}

/* Counts CSV fields that are not finite numbers in columns 3.. of a row. */
static int csv_check_row(char *line, int *fields)
{
	int bad = 0, i = 0;
	char *save = NULL;
	for (char *t = strtok_r(line, ",", &save); t; t = strtok_r(NULL, ",", &save), i++) {
		if (i < 2)
			continue;
		char *end;
		double v = strtod(t, &end);
		bad += end == t || (*end && *end != '\n') || !isfinite(v);
	}
	*fields = i;
	return bad;
}

static char *run_quick(const char *name, const char *backends, const char *threads)
{
	char dir[1024];
	snprintf(dir, sizeof dir, "%s", bsim_test_dir(name));
	char scene[1024];
	snprintf(scene, sizeof scene, "%s", bsim_test_src("configs/thesis/gate.yaml"));
	const char *argv[] = {"accuracy",   "--quick",
	                      "--out",      dir,
	                      "--scene",    scene,
	                      "--set",      "effects.propulsion.force=9",
	                      "--set",      "effects.random_force.magnitude=20",
	                      "--backends", backends,
	                      "--threads",  threads,
	                      NULL};
	char *err = NULL;
	int status = bsim_test_cli(argv, NULL, &err);
	if (status != 0)
		print_error("%s\n", err ? err : "");
	free(err);
	assert_int_equal(status, 0);
	char path[1100];
	snprintf(path, sizeof path, "%s/accuracy.png", dir);
	char *png = bsim_test_read(path);
	assert_non_null(png);
	assert_memory_equal(png, "\x89PNG\r\n\x1a\n", 8);
	free(png);
	snprintf(path, sizeof path, "%s/accuracy.md", dir);
	char *md = bsim_test_read(path);
	assert_non_null(md);
	assert_non_null(strstr(md, "| backend |"));
	free(md);
	snprintf(path, sizeof path, "%s/accuracy.csv", dir);
	char *csv = bsim_test_read(path);
	assert_non_null(csv);
	return csv;
}

static void test_cli_quick(void **state)
{
	(void)state;
	char *csv = run_quick("quick", "thesis,box2d", "2");
	int rows = 0, thesis = 0, box2d = 0;
	char *save = NULL;
	char *line = strtok_r(csv, "\n", &save);
	assert_non_null(strstr(line, "err_mean_m"));
	while ((line = strtok_r(NULL, "\n", &save))) {
		thesis += strncmp(line, "thesis,", 7) == 0;
		box2d += strncmp(line, "box2d,", 6) == 0;
		int fields;
		char copy[512];
		snprintf(copy, sizeof copy, "%s", line);
		assert_int_equal(csv_check_row(copy, &fields), 0);
		assert_int_equal(fields, 15);
		rows++;
	}
	/* 6 steps (0.016 .. 0.0005 s) x 4 thesis and 12 box2d settings. */
	assert_int_equal(thesis, 4 * 6);
	assert_int_equal(box2d, 12 * 6);
	assert_int_equal(rows, 96);
	free(csv);
}

/* Each row up to p_err (its first 10 columns): timings differ run to run. */
static char *without_timings(const char *csv)
{
	char *out = malloc(strlen(csv) + 1);
	size_t k = 0;
	int commas = 0;
	for (const char *c = csv; *c; c++) {
		if (*c == '\n') {
			commas = 0;
			out[k++] = '\n';
			continue;
		}
		commas += *c == ',';
		if (commas < 10)
			out[k++] = *c;
	}
	out[k] = '\0';
	return out;
}

static void test_threads_independent(void **state)
{
	(void)state;
	char *one = run_quick("threads1", "thesis", "1");
	char *two = run_quick("threads2", "thesis", "2");
	char *a = without_timings(one), *b = without_timings(two);
	assert_string_equal(a, b);
	free(a);
	free(b);
	free(one);
	free(two);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	        cmocka_unit_test(test_checksums_known),     cmocka_unit_test(test_png_valid),
	        cmocka_unit_test(test_consistency_order),   cmocka_unit_test(test_cli_quick),
	        cmocka_unit_test(test_threads_independent),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
