/* 64-bit FNV-1a (util/hash.h). */
#include "util/hash.h"

/* FNV's 64-bit prime, 2^40 + 2^8 + 0xb3. */
#define FNV1A64_PRIME 0x100000001b3ULL

uint64_t bsim_hash_fnv1a64(const void *p, size_t n, uint64_t seed)
{
	const unsigned char *b = p;
	uint64_t h = seed;
	for (size_t i = 0; i < n; i++) {
		h ^= b[i];
		h *= FNV1A64_PRIME;
	}
	return h;
}
