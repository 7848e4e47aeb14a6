/* Raster images, PNG files and log-log plots with no dependency beyond libc.
 *
 * An image is w x h RGB pixels, 8 bits a channel, row 0 at the top. A PNG
 * (ISO/IEC 15948) is the 8-byte signature and chunks length | type | data |
 * CRC-32(type | data); IDAT holds a zlib stream (RFC 1950) whose deflate
 * data (RFC 1951) are stored blocks: no compression, at most 65535 bytes a
 * block, followed by the Adler-32 of the uncompressed scanlines (each a
 * filter byte 0 and the row). Text is drawn with a built-in 5 x 7 bitmap
 * font (upper case, digits and common punctuation). */
#ifndef BEAMSIM_PLOT_H
#define BEAMSIM_PLOT_H

#include <stddef.h>
#include <stdint.h>

#include "beamsim/error.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct bsim_image {
	int w, h;
	unsigned char *rgb; /* w * h * 3 bytes, row-major from the top */
} bsim_image;

/* A w x h image filled with white. BSIM_EFAIL if out of memory. */
int bsim_image_alloc(bsim_image *im, int w, int h, bsim_error *err);
void bsim_image_free(bsim_image *im);

/* Drawing, clipped to the image. Colours are 0xRRGGBB. */
void bsim_image_pixel(bsim_image *im, int x, int y, uint32_t color);
void bsim_image_rect(bsim_image *im, int x0, int y0, int x1, int y1, uint32_t color);
/* A line of the given width in pixels (>= 1), end points in pixels. */
void bsim_image_line(bsim_image *im, double x0, double y0, double x1, double y1, int width,
                     uint32_t color);
/* A marker centred on (x, y): shape 0 square, 1 circle, 2 triangle, 3 cross. */
void bsim_image_marker(bsim_image *im, int x, int y, int shape, int size, uint32_t color);
/* Text with its top-left corner at (x, y), each font pixel scale x scale. */
void bsim_image_text(bsim_image *im, int x, int y, const char *s, int scale, uint32_t color);
/* Text drawn upwards (rotated 90 degrees counter-clockwise), for a y label;
 * (x, y) is the bottom-left corner. */
void bsim_image_text_up(bsim_image *im, int x, int y, const char *s, int scale, uint32_t color);
/* Width in pixels of s at the given scale. */
int bsim_text_width(const char *s, int scale);

/* CRC-32 (ISO 3309, as PNG uses it) of n bytes continuing crc (0 to start). */
uint32_t bsim_crc32(uint32_t crc, const unsigned char *p, size_t n);
/* Adler-32 (RFC 1950) of n bytes. */
uint32_t bsim_adler32(const unsigned char *p, size_t n);

/* The PNG file of im in a malloc'd buffer. BSIM_EFAIL if out of memory. */
int bsim_png_encode(const bsim_image *im, unsigned char **out, size_t *n, bsim_error *err);
/* Writes im as a PNG file (atomically). BSIM_EFAIL naming path on error. */
int bsim_png_write(const char *path, const bsim_image *im, bsim_error *err);

/* One curve of a plot: n points (x[i], y[i]); non-positive or non-finite
 * points are left out (a log axis has no place for them). */
typedef struct bsim_plot_series {
	const char *label;
	int n;
	const double *x, *y;
	uint32_t color;
	int marker; /* as bsim_image_marker */
	int dashed; /* 1: a dashed line */
} bsim_plot_series;

/* A log-log plot with ticks at powers of ten, axis labels, a title and a
 * legend right of the axes, written as a PNG file of w x h pixels. */
int bsim_plot_loglog(const char *path, int w, int h, const char *title, const char *xlabel,
                     const char *ylabel, const bsim_plot_series *s, int n_series, bsim_error *err);

#ifdef __cplusplus
}
#endif
#endif
