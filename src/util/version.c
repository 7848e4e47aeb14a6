/* What the library is and what built it; see beamsim/version.h. (What
 * each backend is built on is in its table, bsim_backend.engine and
 * version.) */
#include "beamsim/version.h"

#include "build_info.h"

const char *bsim_version(void)
{
	return BSIM_VERSION;
}

const char *bsim_version_commit(void)
{
	return BSIM_BUILD_COMMIT;
}

#define TEXT_OF(x) #x
#define TEXT(x)    TEXT_OF(x)

const char *bsim_version_compiler(void)
{
#if defined(__clang__)
	return "clang " TEXT(__clang_major__) "." TEXT(__clang_minor__) "." TEXT(
	        __clang_patchlevel__);
#elif defined(__GNUC__)
	return "gcc " TEXT(__GNUC__) "." TEXT(__GNUC_MINOR__) "." TEXT(__GNUC_PATCHLEVEL__);
#else
	return "an unknown C compiler";
#endif
}
