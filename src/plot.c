/* Raster drawing, a PNG encoder with stored deflate blocks, and log-log
 * plots (see beamsim/plot.h).
 *
 * CRC-32: polynomial 0xEDB88320 (reflected), initial and final XOR ~0.
 * Adler-32: a = 1 + sum b_i, b = sum a_i, both mod 65521; value b << 16 | a.
 * Lines: a disc of the line's width stamped every half pixel along it.
 * Log axes: u = (log10 v - log10 lo) / (log10 hi - log10 lo) in [0, 1]. */
#include "beamsim/plot.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "beamsim/atomic_file.h"

int bsim_image_alloc(bsim_image *im, int w, int h, bsim_error *err)
{
	im->w = w;
	im->h = h;
	im->rgb = malloc((size_t)w * (size_t)h * 3);
	if (!im->rgb)
		return bsim_error_set(err, BSIM_EFAIL, "out of memory for a %d x %d image", w, h);
	memset(im->rgb, 255, (size_t)w * (size_t)h * 3);
	return BSIM_OK;
}

void bsim_image_free(bsim_image *im)
{
	free(im->rgb);
	im->rgb = NULL;
}

void bsim_image_pixel(bsim_image *im, int x, int y, uint32_t color)
{
	if (x < 0 || y < 0 || x >= im->w || y >= im->h)
		return;
	unsigned char *p = im->rgb + ((size_t)y * (size_t)im->w + (size_t)x) * 3;
	p[0] = (unsigned char)(color >> 16);
	p[1] = (unsigned char)(color >> 8);
	p[2] = (unsigned char)color;
}

void bsim_image_rect(bsim_image *im, int x0, int y0, int x1, int y1, uint32_t color)
{
	for (int y = y0; y <= y1; y++)
		for (int x = x0; x <= x1; x++)
			bsim_image_pixel(im, x, y, color);
}

static void image_disc(bsim_image *im, double cx, double cy, double r, uint32_t color)
{
	int x0 = (int)floor(cx - r), x1 = (int)ceil(cx + r);
	int y0 = (int)floor(cy - r), y1 = (int)ceil(cy + r);
	for (int y = y0; y <= y1; y++)
		for (int x = x0; x <= x1; x++)
			if ((x - cx) * (x - cx) + (y - cy) * (y - cy) <= r * r + 0.25)
				bsim_image_pixel(im, x, y, color);
}

void bsim_image_line(bsim_image *im, double x0, double y0, double x1, double y1, int width,
                     uint32_t color)
{
	double len = hypot(x1 - x0, y1 - y0);
	int n = (int)ceil(len * 2.0) + 1;
	double r = 0.5 * (width - 1);
	for (int i = 0; i <= n; i++) {
		double u = (double)i / n;
		double x = x0 + u * (x1 - x0), y = y0 + u * (y1 - y0);
		if (width <= 1)
			bsim_image_pixel(im, (int)lround(x), (int)lround(y), color);
		else
			image_disc(im, x, y, r, color);
	}
}

void bsim_image_marker(bsim_image *im, int x, int y, int shape, int size, uint32_t color)
{
	int r = size / 2;
	switch (shape) {
	case 0:
		bsim_image_rect(im, x - r, y - r, x + r, y + r, color);
		break;
	case 1:
		image_disc(im, x, y, r, color);
		break;
	case 2: /* apex up: half-width grows from 0 at the top to r at the base */
		for (int dy = -r; dy <= r; dy++) {
			int half = (dy + r) / 2;
			for (int dx = -half; dx <= half; dx++)
				bsim_image_pixel(im, x + dx, y + dy, color);
		}
		break;
	default:
		bsim_image_line(im, x - r, y - r, x + r, y + r, 2, color);
		bsim_image_line(im, x - r, y + r, x + r, y - r, 2, color);
		break;
	}
}

/* The 5 x 7 font: 35 characters a glyph, row by row, '#' set. Lower case
 * is drawn as upper case. */
typedef struct font_glyph {
	char c;
	const char *rows;
} font_glyph;

static const font_glyph font[] = {
        {'A', ".###.#...##...#######...##...##...#"}, {'B', "####.#...##...#####.#...##...#####."},
        {'C', ".###.#...##....#....#....#...#.###."}, {'D', "####.#...##...##...##...##...#####."},
        {'E', "######....#....####.#....#....#####"}, {'F', "######....#....####.#....#....#...."},
        {'G', ".###.#...##....#.####...##...#.####"}, {'H', "#...##...##...#######...##...##...#"},
        {'I', ".###...#....#....#....#....#...###."}, {'J', "..###...#....#....#....##..#..##..."},
        {'K', "#...##..#.#.#..##...#.#..#..#.#...#"}, {'L', "#....#....#....#....#....#....#####"},
        {'M', "#...###.###.#.##.#.##...##...##...#"}, {'N', "#...##...###..##.#.##..###...##...#"},
        {'O', ".###.#...##...##...##...##...#.###."}, {'P', "####.#...##...#####.#....#....#...."},
        {'Q', ".###.#...##...##...##.#.##..#..##.#"}, {'R', "####.#...##...#####.#.#..#..#.#...#"},
        {'S', ".#####....#.....###.....#....#####."}, {'T', "#####..#....#....#....#....#....#.."},
        {'U', "#...##...##...##...##...##...#.###."}, {'V', "#...##...##...##...##...#.#.#...#.."},
        {'W', "#...##...##...##.#.##.#.##.#.#.#.#."}, {'X', "#...##...#.#.#...#...#.#.#...##...#"},
        {'Y', "#...##...#.#.#...#....#....#....#.."}, {'Z', "#####....#...#...#...#...#....#####"},
        {'0', ".###.#...##..###.#.###..##...#.###."}, {'1', "..#...##....#....#....#....#...###."},
        {'2', ".###.#...#....#...#...#...#...#####"}, {'3', "#####...#...#.....#.....##...#.###."},
        {'4', "...#...##..#.#.#..#.#####...#....#."}, {'5', "######....####.....#....##...#.###."},
        {'6', "..##..#...#....####.#...##...#.###."}, {'7', "#####....#...#...#...#....#....#..."},
        {'8', ".###.#...##...#.###.#...##...#.###."}, {'9', ".###.#...##...#.####....#...#..##.."},
        {'.', "..........................##...##.."}, {'-', "...............#####..............."},
        {'+', ".......#....#..#####..#....#......."}, {'=', "..........#####.....#####.........."},
        {'/', ".........#...#...#...#...#........."}, {'(', "...#...#...#....#....#.....#.....#."},
        {')', ".#.....#.....#....#....#...#...#..."}, {':', "......##...##........##...##......."},
        {',', "....................##....#...#...."}, {'_', "..............................#####"},
        {'%', "##...##..#...#...#...#...#..##...##"}, {'|', "..#....#....#....#....#....#....#.."},
        {'*', ".......#..#.#.#.###.#.#.#..#......."}, {'^', "..#...#.#.#...#...................."},
};

#define FONT_W 5
#define FONT_H 7

static const char *font_find(char c)
{
	if (c >= 'a' && c <= 'z')
		c = (char)(c - 'a' + 'A');
	for (size_t i = 0; i < sizeof font / sizeof font[0]; i++)
		if (font[i].c == c)
			return font[i].rows;
	return NULL; /* a space, or a character the font lacks: blank */
}

int bsim_text_width(const char *s, int scale)
{
	int n = (int)strlen(s);
	return n ? (n * (FONT_W + 1) - 1) * scale : 0;
}

/* Draws s; (ux, uy) is the direction of the text, (vx, vy) of its rows. */
static void text_draw(bsim_image *im, int x, int y, const char *s, int scale, uint32_t color,
                      int ux, int uy, int vx, int vy)
{
	for (int k = 0; s[k]; k++) {
		const char *g = font_find(s[k]);
		if (!g)
			continue;
		int ox = k * (FONT_W + 1) * scale;
		for (int r = 0; r < FONT_H; r++)
			for (int c = 0; c < FONT_W; c++) {
				if (g[r * FONT_W + c] != '#')
					continue;
				for (int dy = 0; dy < scale; dy++)
					for (int dx = 0; dx < scale; dx++) {
						int a = ox + c * scale + dx, b = r * scale + dy;
						bsim_image_pixel(im, x + a * ux + b * vx,
						                 y + a * uy + b * vy, color);
					}
			}
	}
}

void bsim_image_text(bsim_image *im, int x, int y, const char *s, int scale, uint32_t color)
{
	text_draw(im, x, y, s, scale, color, 1, 0, 0, 1);
}

void bsim_image_text_up(bsim_image *im, int x, int y, const char *s, int scale, uint32_t color)
{
	text_draw(im, x, y, s, scale, color, 0, -1, 1, 0);
}

uint32_t bsim_crc32(uint32_t crc, const unsigned char *p, size_t n)
{
	static uint32_t table[256];
	static int ready;
	if (!ready) { /* idempotent, so a race between threads is harmless */
		for (uint32_t i = 0; i < 256; i++) {
			uint32_t c = i;
			for (int k = 0; k < 8; k++)
				c = c & 1 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
			table[i] = c;
		}
		ready = 1;
	}
	crc = ~crc;
	for (size_t i = 0; i < n; i++)
		crc = table[(crc ^ p[i]) & 0xFF] ^ (crc >> 8);
	return ~crc;
}

uint32_t bsim_adler32(const unsigned char *p, size_t n)
{
	uint32_t a = 1, b = 0;
	for (size_t i = 0; i < n; i++) {
		a = (a + p[i]) % 65521u;
		b = (b + a) % 65521u;
	}
	return b << 16 | a;
}

typedef struct png_buf {
	unsigned char *p;
	size_t n;
} png_buf;

static void put32(png_buf *b, uint32_t v)
{
	b->p[b->n++] = (unsigned char)(v >> 24);
	b->p[b->n++] = (unsigned char)(v >> 16);
	b->p[b->n++] = (unsigned char)(v >> 8);
	b->p[b->n++] = (unsigned char)v;
}

/* A chunk: length, type, data, CRC over type and data. */
static void put_chunk(png_buf *b, const char *type, const unsigned char *data, size_t n)
{
	put32(b, (uint32_t)n);
	size_t start = b->n;
	memcpy(b->p + b->n, type, 4);
	b->n += 4;
	if (n)
		memcpy(b->p + b->n, data, n);
	b->n += n;
	put32(b, bsim_crc32(0, b->p + start, n + 4));
}

int bsim_png_encode(const bsim_image *im, unsigned char **out, size_t *n, bsim_error *err)
{
	const size_t row = (size_t)im->w * 3 + 1; /* filter byte 0, then RGB */
	const size_t raw_n = row * (size_t)im->h;
	const size_t blocks = raw_n / 65535 + 1;
	const size_t z_n = 2 + raw_n + 5 * blocks + 4;
	unsigned char *raw = malloc(raw_n), *z = malloc(z_n);
	unsigned char *png = malloc(8 + 25 + 12 + z_n + 12);
	if (!raw || !z || !png) {
		free(raw);
		free(z);
		free(png);
		return bsim_error_set(err, BSIM_EFAIL, "out of memory encoding a PNG");
	}
	for (int y = 0; y < im->h; y++) {
		raw[(size_t)y * row] = 0;
		memcpy(raw + (size_t)y * row + 1, im->rgb + (size_t)y * (size_t)im->w * 3, row - 1);
	}
	/* zlib: CMF 0x78 (deflate, 32 KiB window), FLG 0x01 ((0x7801) % 31 == 0). */
	size_t k = 0;
	z[k++] = 0x78;
	z[k++] = 0x01;
	size_t off = 0;
	do {
		size_t len = raw_n - off < 65535 ? raw_n - off : 65535;
		int last = off + len == raw_n;
		z[k++] = (unsigned char)last; /* BFINAL, BTYPE 00: stored */
		z[k++] = (unsigned char)(len & 0xFF);
		z[k++] = (unsigned char)(len >> 8);
		z[k++] = (unsigned char)(~len & 0xFF);
		z[k++] = (unsigned char)((~len >> 8) & 0xFF);
		memcpy(z + k, raw + off, len);
		k += len;
		off += len;
	} while (off < raw_n);
	uint32_t adler = bsim_adler32(raw, raw_n);
	z[k++] = (unsigned char)(adler >> 24);
	z[k++] = (unsigned char)(adler >> 16);
	z[k++] = (unsigned char)(adler >> 8);
	z[k++] = (unsigned char)adler;

	png_buf b = {png, 0};
	static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
	memcpy(b.p, sig, 8);
	b.n = 8;
	unsigned char ihdr[13];
	png_buf hb = {ihdr, 0};
	put32(&hb, (uint32_t)im->w);
	put32(&hb, (uint32_t)im->h);
	ihdr[8] = 8;  /* bit depth */
	ihdr[9] = 2;  /* colour type: RGB */
	ihdr[10] = 0; /* compression: deflate */
	ihdr[11] = 0; /* filter method 0 */
	ihdr[12] = 0; /* no interlace */
	put_chunk(&b, "IHDR", ihdr, 13);
	put_chunk(&b, "IDAT", z, k);
	put_chunk(&b, "IEND", NULL, 0);
	free(raw);
	free(z);
	*out = png;
	*n = b.n;
	return BSIM_OK;
}

int bsim_png_write(const char *path, const bsim_image *im, bsim_error *err)
{
	unsigned char *png;
	size_t n;
	int rc = bsim_png_encode(im, &png, &n, err);
	if (rc)
		return rc;
	bsim_atomic_file o;
	rc = bsim_atomic_file_open(&o, path, err);
	if (rc == BSIM_OK) {
		fwrite(png, 1, n, o.f);
		rc = bsim_atomic_file_commit(&o, err);
	}
	free(png);
	return rc;
}

/* Axis range as whole decades around the finite positive values. */
static void plot_range(const bsim_plot_series *s, int n_series, int axis, double *lo, double *hi)
{
	double a = INFINITY, b = -INFINITY;
	for (int i = 0; i < n_series; i++)
		for (int k = 0; k < s[i].n; k++) {
			double v = axis ? s[i].y[k] : s[i].x[k];
			if (isfinite(v) && v > 0) {
				a = fmin(a, v);
				b = fmax(b, v);
			}
		}
	if (!isfinite(a)) {
		a = 1;
		b = 10;
	}
	*lo = floor(log10(a));
	*hi = ceil(log10(b));
	if (*hi <= *lo)
		*hi = *lo + 1;
}

#define PLOT_GREY 0xDDDDDDu
#define PLOT_INK  0x000000u

int bsim_plot_loglog(const char *path, int w, int h, const char *title, const char *xlabel,
                     const char *ylabel, const bsim_plot_series *s, int n_series, bsim_error *err)
{
	bsim_image im;
	int rc = bsim_image_alloc(&im, w, h, err);
	if (rc)
		return rc;
	int legend_w = 0;
	for (int i = 0; i < n_series; i++) {
		int tw = bsim_text_width(s[i].label, 1);
		legend_w = tw > legend_w ? tw : legend_w;
	}
	legend_w += 40;
	const int left = 80, top = 40, bottom = 60, right = legend_w + 20;
	const int x0 = left, x1 = w - right, y0 = top, y1 = h - bottom; /* plot box */
	double xlo, xhi, ylo, yhi;
	plot_range(s, n_series, 0, &xlo, &xhi);
	plot_range(s, n_series, 1, &ylo, &yhi);
#define PX(v) (x0 + (log10(v) - xlo) / (xhi - xlo) * (x1 - x0))
#define PY(v) (y1 - (log10(v) - ylo) / (yhi - ylo) * (y1 - y0))
	char buf[32];
	/* Grid and tick labels at each decade, minor ticks at 2..9. */
	for (int e = (int)xlo; e <= (int)xhi; e++) {
		double px = PX(pow(10, e));
		bsim_image_line(&im, px, y0, px, y1, 1, PLOT_GREY);
		snprintf(buf, sizeof buf, "1e%d", e);
		bsim_image_text(&im, (int)px - bsim_text_width(buf, 1) / 2, y1 + 8, buf, 1,
		                PLOT_INK);
		for (int m = 2; m < 10 && e < (int)xhi; m++) {
			double q = PX(m * pow(10, e));
			bsim_image_line(&im, q, y1, q, y1 - 4, 1, PLOT_INK);
		}
	}
	for (int e = (int)ylo; e <= (int)yhi; e++) {
		double py = PY(pow(10, e));
		bsim_image_line(&im, x0, py, x1, py, 1, PLOT_GREY);
		snprintf(buf, sizeof buf, "1e%d", e);
		bsim_image_text(&im, x0 - 8 - bsim_text_width(buf, 1), (int)py - 3, buf, 1,
		                PLOT_INK);
		for (int m = 2; m < 10 && e < (int)yhi; m++) {
			double q = PY(m * pow(10, e));
			bsim_image_line(&im, x0, q, x0 + 4, q, 1, PLOT_INK);
		}
	}
	bsim_image_line(&im, x0, y0, x1, y0, 1, PLOT_INK);
	bsim_image_line(&im, x0, y1, x1, y1, 1, PLOT_INK);
	bsim_image_line(&im, x0, y0, x0, y1, 1, PLOT_INK);
	bsim_image_line(&im, x1, y0, x1, y1, 1, PLOT_INK);
	bsim_image_text(&im, (x0 + x1 - bsim_text_width(xlabel, 1)) / 2, y1 + 28, xlabel, 1,
	                PLOT_INK);
	bsim_image_text_up(&im, 20, (y0 + y1 + bsim_text_width(ylabel, 1)) / 2, ylabel, 1,
	                   PLOT_INK);
	bsim_image_text(&im, (x0 + x1 - bsim_text_width(title, 2)) / 2, 12, title, 2, PLOT_INK);

	/* Curves: segments between successive drawable points, then markers. */
	for (int i = 0; i < n_series; i++) {
		int have = 0;
		double px = 0, py = 0;
		for (int k = 0; k < s[i].n; k++) {
			double x = s[i].x[k], y = s[i].y[k];
			if (!(isfinite(x) && isfinite(y) && x > 0 && y > 0))
				continue;
			double qx = PX(x), qy = PY(y);
			if (have && !s[i].dashed)
				bsim_image_line(&im, px, py, qx, qy, 2, s[i].color);
			else if (have) { /* dashes of 6 px, gaps of 4 px */
				double len = hypot(qx - px, qy - py);
				for (double d = 0; d < len; d += 10) {
					double e2 = fmin(d + 6, len);
					bsim_image_line(&im, px + (qx - px) * d / len,
					                py + (qy - py) * d / len,
					                px + (qx - px) * e2 / len,
					                py + (qy - py) * e2 / len, 2, s[i].color);
				}
			}
			bsim_image_marker(&im, (int)lround(qx), (int)lround(qy), s[i].marker, 7,
			                  s[i].color);
			have = 1;
			px = qx;
			py = qy;
		}
	}
#undef PX
#undef PY
	/* Legend. */
	for (int i = 0; i < n_series; i++) {
		int ly = y0 + 6 + i * 14;
		int lx = x1 + 12;
		bsim_image_line(&im, lx, ly + 3, lx + 22, ly + 3, 2, s[i].color);
		bsim_image_marker(&im, lx + 11, ly + 3, s[i].marker, 7, s[i].color);
		bsim_image_text(&im, lx + 30, ly, s[i].label, 1, PLOT_INK);
	}
	rc = bsim_png_write(path, &im, err);
	bsim_image_free(&im);
	return rc;
}
