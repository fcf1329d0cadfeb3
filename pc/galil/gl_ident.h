/*
 * gl_ident.h - the program identity stamp (docs/dmc-interface.md, "Program
 * identity"): galil-load appends the line
 *
 *	NO ID <16 hex digits>
 *
 * to the preprocessed DMC program; the digits are the FNV-1a 64-bit hash
 * (gl_hash.h) of the program text before that line, each line terminated by
 * one LF. The supervisor uploads the program at start-up and checks the stamp
 * with gl_ident_verify(), so it refuses a controller holding anything that
 * galil-load did not check and stamp. This guards against accidental change,
 * not against an attacker.
 *
 * Normal form (used for the stamp, for gl_ident_verify() and for galil-load's
 * byte-for-byte read-back comparison): the text is cut at the first 0x1A (the
 * end mark of UL); CR LF and lone CR become LF; empty lines at the end are
 * dropped; a non-empty text ends with exactly one LF. Nothing inside a line
 * changes (spaces, case).
 *
 * Pure functions over buffers; no allocation, nothing printed.
 */
#ifndef GL_IDENT_H
#define GL_IDENT_H

#include <stddef.h>
#include <stdint.h>

#define GL_IDENT_PREFIX "NO ID "
#define GL_IDENT_DIGITS 16
/* "NO ID " + 16 hex digits + NUL */
#define GL_IDENT_LINE_SIZE (sizeof(GL_IDENT_PREFIX) - 1 + GL_IDENT_DIGITS + 1)

/*
 * gl_ident_normalise() - put a program text in normal form (above).
 * @in: [in] the text, @len bytes (may contain NUL bytes; they are kept).
 * @out: [out] the normal form; may be the same buffer as @in (in place).
 *       Not NUL-terminated unless room is left (it is when @cap > result).
 * @cap: capacity of @out; @len + 1 is always enough.
 * Return: the length of the normal form (>= 0), or GL_ERR_OVERFLOW (nothing
 *         useful in @out) or GL_ERR_ARG (NULL pointer with @len > 0).
 */
int gl_ident_normalise(const char *in, size_t len, char *out, size_t cap);

/*
 * gl_ident_stamp() - the identity of a preprocessed program.
 * @text: [in] the program in normal form without the stamp line (each line
 *        terminated by one LF), @len bytes.
 * @line: [out] optional; the stamp line "NO ID 0123456789ABCDEF" (upper-case
 *        hex, NUL-terminated, no line end).
 * Return: the FNV-1a 64 hash of exactly the @len bytes of @text.
 */
uint64_t gl_ident_stamp(const char *text, size_t len,
			char line[GL_IDENT_LINE_SIZE]);

/*
 * gl_ident_parse() - read the identity out of one line.
 * @line: [in] the line, @len bytes, without its line end.
 * @id: [out] the identity on success; must not be NULL.
 * The line must be exactly "NO ID " and 16 hex digits (either case).
 * Return: GL_OK or GL_ERR_FORMAT.
 */
int gl_ident_parse(const char *line, size_t len, uint64_t *id);

/*
 * gl_ident_verify() - check an uploaded program's stamp.
 * @uploaded: [in] the program as uploaded (UL): CR LF, CR or LF line ends,
 *            optionally ending with 0x1A and anything after it.
 * @len: bytes in @uploaded.
 * @id: [out] optional; the identity written in the stamp line (set for
 *      GL_OK and GL_ERR_MISMATCH), 0 otherwise.
 * The stamp must be the last line of the normal form, and the hash of the
 * normal form before it must equal the stamp. No allocation.
 * Return: GL_OK; GL_ERR_MISMATCH (stamp present, text changed);
 *         GL_ERR_FORMAT (empty program, or the last line is not a stamp);
 *         GL_ERR_ARG (NULL @uploaded with @len > 0).
 */
int gl_ident_verify(const char *uploaded, size_t len, uint64_t *id);

#endif /* GL_IDENT_H */
