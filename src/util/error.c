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
