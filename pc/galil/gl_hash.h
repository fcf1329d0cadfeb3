/*
 * gl_hash.h - FNV-1a 64-bit hash, used for the DMC program identity stamp
 * (docs/dmc-interface.md) and the configuration hash in calibration files.
 * An identity check against accidental change, not a security measure.
 */
#ifndef GL_HASH_H
#define GL_HASH_H

#include <stddef.h>
#include <stdint.h>

#define GL_FNV64_INIT 0xcbf29ce484222325ULL

/*
 * gl_fnv1a64() - continue a hash over @len bytes of @buf.
 * @h: GL_FNV64_INIT for a new hash, or a previous result.
 * Return: the updated hash.
 */
uint64_t gl_fnv1a64(uint64_t h, const void *buf, size_t len);

#endif /* GL_HASH_H */
