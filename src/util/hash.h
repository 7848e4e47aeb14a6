/* Internal: the one hash of beamsim's content keys, 64-bit FNV-1a
 * (Fowler, Noll, Vo). It names what a result depends on, not a secret: a
 * Markov map's file is map_HASH of its key text, and observed gate entries
 * are identified by the hash of their values. The values are part of the
 * file names of existing caches, so they never change. */
#ifndef BSIM_UTIL_HASH_H
#define BSIM_UTIL_HASH_H

#include <stddef.h>
#include <stdint.h>

/* FNV-1a's offset basis: the seed of a hash of nothing yet. */
#define HASH_FNV1A64_SEED 0xcbf29ce484222325ULL

/* The hash of n bytes at p continuing from seed (HASH_FNV1A64_SEED to
 * start, a previous result to hash more bytes after those):
 *   h = seed;  for each byte c:  h = (h XOR c) * 0x100000001b3  (mod 2^64) */
uint64_t bsim_hash_fnv1a64(const void *p, size_t n, uint64_t seed);

#endif
