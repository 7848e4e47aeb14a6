#include "beamsim/error.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "util/text_check.h"

int bsim_error_set(bsim_error *err, int code, const char *fmt, ...)
{
	if (err) {
		va_list ap;
		va_start(ap, fmt);
		vsnprintf(err->msg, sizeof err->msg, fmt, ap);
		va_end(ap);
		bsim_text_escape(err->msg, sizeof err->msg);
		err->code = code;
	}
	return code;
}

void bsim_error_clear(bsim_error *err)
{
	if (err) {
		err->code = BSIM_OK;
		err->msg[0] = '\0';
	}
}

int bsim_error_nul_check(const char *what, const char *s, size_t len, bsim_error *err)
{
	if (!memchr(s, '\0', len))
		return BSIM_OK;
	/* The text as far as it fits, each NUL written \x00 here (the message
	 * could not hold it), what else is not printable by bsim_error_set. */
	char shown[256];
	size_t j = 0, i = 0;
	for (; i < len && j + 8 < sizeof shown; i++) {
		if (s[i] == '\0') {
			memcpy(shown + j, "\\x00", 4);
			j += 4;
		} else {
			shown[j++] = s[i];
		}
	}
	if (i < len)
		j += (size_t)snprintf(shown + j, sizeof shown - j, "...");
	shown[j] = '\0';
	return bsim_error_set(err, BSIM_EINPUT,
	                      "%s \"%s\": expected text without NUL bytes (the library would "
	                      "read it only up to the first)",
	                      what, shown);
}

static bsim_note_fn note_fn;
static void *note_user;

void bsim_note_set_handler(bsim_note_fn fn, void *user)
{
	note_fn = fn;
	note_user = user;
}

void bsim_note(const char *fmt, ...)
{
	char text[BSIM_ERROR_MSG_MAX];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(text, sizeof text, fmt, ap);
	va_end(ap);
	if (note_fn)
		note_fn(note_user, text);
	else
		fprintf(stderr, "beamsim: %s\n", text);
}
