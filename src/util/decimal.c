/* Spellings of numbers that look like another base; see util/decimal.h. */
#include "util/decimal.h"

#include <ctype.h>
#include <string.h>

int decimal_other_base(const char *t)
{
	while (isspace((unsigned char)*t))
		t++;
	if (*t == '+' || *t == '-')
		t++;
	return t[0] == '0' &&
	       ((strchr("xXoObB", t[1]) && t[1] != '\0') || isdigit((unsigned char)t[1]));
}
