/* gl_hash.c - FNV-1a 64-bit (http://www.isthe.com/chongo/tech/comp/fnv/). */
#include "gl_hash.h"

#define FNV64_PRIME 0x100000001b3ULL

uint64_t gl_fnv1a64(uint64_t h, const void *buf, size_t len)
{
	const unsigned char *p = buf;

	while (len--) {
		h ^= *p++;
		h *= FNV64_PRIME;
	}
	return h;
}
