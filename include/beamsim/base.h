/* What every public header needs first: BSIM_API, the mark of a function or
 * object libbeamsim.so exports. The library is compiled with hidden
 * visibility (CMakeLists.txt, bsim_layer), so what carries the mark is the
 * whole ABI and nothing else is: the ABI is the API of include/beamsim/.
 * On Windows the mark exports from the DLL while it is built (BSIM_BUILDING)
 * and imports into the programs that use it. */
#ifndef BSIM_BASE_H
#define BSIM_BASE_H

#if defined(_WIN32)
#if defined(BSIM_BUILDING)
#define BSIM_API __declspec(dllexport)
#else
#define BSIM_API __declspec(dllimport)
#endif
#elif defined(__GNUC__)
#define BSIM_API __attribute__((visibility("default")))
#else
#define BSIM_API
#endif

#endif
