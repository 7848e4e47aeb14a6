#include "beamsim/error.h"

#include <stdarg.h>
#include <stdio.h>

#include "util/text_check.h"

int bsim_error_set(bsim_error *err, int code, const char *fmt, ...)
{
	if (err) {
		va_list ap;
		va_start(ap, fmt);
		vsnprintf(err->msg, sizeof err->msg, fmt, ap);
		va_end(ap);
		text_escape(err->msg, sizeof err->msg);
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
