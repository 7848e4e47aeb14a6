/* What the library is and what built it; see beamsim/version.h. The Box2D
 * version is its CMake package's (BSIM_BOX2D_VERSION, set by CMakeLists.txt):
 * Debian's 2.4.1 still says 2.4.0 in its b2_version. Chipmunk's is its
 * header's (BSIM_CHIPMUNK_VERSION, read by CMakeLists.txt). */
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

const char *bsim_version_box2d(void)
{
	return BSIM_BOX2D_VERSION;
}

const char *bsim_version_chipmunk(void)
{
	return BSIM_CHIPMUNK_VERSION;
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
