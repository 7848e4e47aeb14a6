/* Text a YAML parser may be given; see text_check.h. */
#include "util/text_check.h"

#include <stdarg.h>
#include <stdint.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>

/* The length of the UTF-8 sequence at s (at most n bytes) and its code
 * point, or 0 if it is not well-formed (Unicode 15, Table 3-7: no overlong
 * forms, no surrogates, nothing above U+10FFFF). glibc's iconv accepts
 * sequences above U+10FFFF, on which libfyaml hangs, so this is checked
 * here by the table itself. */
static int utf8_sequence(const unsigned char *s, size_t n, uint32_t *cp)
{
	unsigned char c = s[0];
	if (c < 0x80) {
		*cp = c;
		return 1;
	}
	int len;
	unsigned char lo = 0x80, hi = 0xBF; /* range of the second byte */
	if (c >= 0xC2 && c <= 0xDF) {
		len = 2;
	} else if (c >= 0xE0 && c <= 0xEF) {
		len = 3;
		lo = c == 0xE0 ? 0xA0 : 0x80;
		hi = c == 0xED ? 0x9F : 0xBF;
	} else if (c >= 0xF0 && c <= 0xF4) {
		len = 4;
		lo = c == 0xF0 ? 0x90 : 0x80;
		hi = c == 0xF4 ? 0x8F : 0xBF;
	} else {
		return 0;
	}
	if ((size_t)len > n || s[1] < lo || s[1] > hi)
		return 0;
	uint32_t v = c & (0x7Fu >> len);
	for (int i = 1; i < len; i++) {
		if (i > 1 && (s[i] & 0xC0) != 0x80)
			return 0;
		v = v << 6 | (s[i] & 0x3Fu);
	}
	*cp = v;
	return len;
}

static int fault_at(text_fault *f, int line, int col, const char *fmt, ...)
        __attribute__((format(printf, 4, 5)));

static int fault_at(text_fault *f, int line, int col, const char *fmt, ...)
{
	va_list ap;
	f->line = line;
	f->col = col;
	va_start(ap, fmt);
	vsnprintf(f->what, sizeof f->what, fmt, ap);
	va_end(ap);
	return 0;
}

int bsim_text_check(const char *buf, size_t len, text_fault *fault)
{
	const unsigned char *s = (const unsigned char *)buf;
	int line = 1, col = 1, quotes = 0;
	for (size_t i = 0; i < len;) {
		uint32_t cp = 0;
		int k = utf8_sequence(s + i, len - i, &cp);
		if (k == 0)
			return fault_at(fault, line, col,
			                "byte 0x%02X, which is not UTF-8 (save the file as UTF-8)",
			                s[i]);
		if (cp == 0)
			return fault_at(fault, line, col, "a NUL byte");
		if (cp == '\t')
			return fault_at(fault, line, col,
			                "a tab character (indent and separate with spaces)");
		if (cp == '\r' && !(i + 1 < len && s[i + 1] == '\n'))
			return fault_at(fault, line, col, "a carriage return without a line feed");
		if (col == 1 && cp == '%')
			return fault_at(fault, line, col,
			                "a YAML directive (%%...), which beamsim files do not "
			                "take");
		/* Two escaped quotes in a row inside a single-quoted string make
		 * libfyaml 0.7.12 grow a buffer it never frees (fy_atom_iter). */
		quotes = cp == '\'' ? quotes + 1 : 0;
		if (quotes == 4)
			return fault_at(fault, line, col - 3,
			                "four apostrophes in a row (write the string in double "
			                "quotes)");
		int control = (cp < 0x20 && cp != '\n' && cp != '\r') || cp == 0x7F ||
		              (cp >= 0x80 && cp <= 0x9F) || cp == 0x2028 || cp == 0x2029;
		if (control)
			return fault_at(fault, line, col, "the control character U+%04X", cp);
		i += (size_t)k;
		if (cp == '\n') {
			line++;
			col = 1;
		} else if (cp != '\r') {
			col++;
		}
	}
	return 1;
}

size_t bsim_text_strip_cr(char *buf, size_t len)
{
	size_t out = 0;
	for (size_t i = 0; i < len; i++)
		if (!(buf[i] == '\r' && i + 1 < len && buf[i + 1] == '\n'))
			buf[out++] = buf[i];
	return out;
}

void bsim_text_escape(char *buf, size_t size)
{
	size_t len = strlen(buf), clean = 0;
	uint32_t cp;
	int k;
	/* Most messages are clean: find the first byte that is not. */
	while (clean < len &&
	       (k = utf8_sequence((const unsigned char *)buf + clean, len - clean, &cp)) > 0 &&
	       cp >= 0x20 && cp != 0x7F && !(cp >= 0x80 && cp <= 0x9F))
		clean += (size_t)k;
	if (clean == len || size < 2)
		return;
	char *copy = malloc(len + 1);
	if (!copy) {
		buf[clean] = '\0';
		return;
	}
	memcpy(copy, buf, len + 1);
	size_t out = clean, in = clean;
	while (in < len) {
		const unsigned char *s = (const unsigned char *)copy + in;
		k = utf8_sequence(s, len - in, &cp);
		int bad = k == 0 || cp < 0x20 || cp == 0x7F || (cp >= 0x80 && cp <= 0x9F);
		size_t need = bad ? 4 : (size_t)k;
		if (out + need >= size)
			break;
		if (bad) {
			snprintf(buf + out, 5, "\\x%02X", *s);
			in += 1;
		} else {
			memcpy(buf + out, s, (size_t)k);
			in += (size_t)k;
		}
		out += need;
	}
	buf[out] = '\0';
	free(copy);
}

void bsim_text_shell_word(FILE *f, const char *s)
{
	if (*s && strspn(s, "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789"
	                    "_-+=.,/:@%") == strlen(s)) {
		fputs(s, f);
		return;
	}
	fputc('\'', f);
	for (; *s; s++)
		if (*s == '\'')
			fputs("'\\''", f);
		else
			fputc(*s, f);
	fputc('\'', f);
}
