/*
 * gl_err.h - the one error enum of the RoboELF code base.
 *
 * Every module returns GL_OK (0) or a negative gl_err code; functions that
 * return a count return >= 0 on success. GL_ERR_SYS leaves errno intact for
 * the caller. No module prints: callers turn codes into text with
 * gl_strerror() and add context of their own.
 */
#ifndef GL_ERR_H
#define GL_ERR_H

enum gl_err {
	GL_OK = 0,
	GL_ERR_ARG = -1,       /* invalid argument (caller bug or bad input) */
	GL_ERR_SYS = -2,       /* system call failed; errno is kept */
	GL_ERR_TIMEOUT = -3,   /* no complete reply before the deadline */
	GL_ERR_PROTO = -4,     /* reply does not follow the Galil framing */
	GL_ERR_CTRL = -5,      /* controller answered '?'; see TC1 text */
	GL_ERR_CONFIG = -6,    /* configuration invalid */
	GL_ERR_NOMEM = -7,     /* allocation failed (start-up only) */
	GL_ERR_CLOSED = -8,    /* peer closed the connection */
	GL_ERR_BROKEN = -9,    /* link out of step; must be reopened */
	GL_ERR_AGAIN = -10,    /* nothing available yet (non-blocking) */
	GL_ERR_RECORD = -11,   /* data record header/length disagree */
	GL_ERR_RANGE = -12,    /* value outside its allowed range */
	GL_ERR_FORMAT = -13,   /* file or text format invalid */
	GL_ERR_CRC = -14,      /* checksum mismatch */
	GL_ERR_MISMATCH = -15, /* read-back or verify differs */
	GL_ERR_RELAY = -16,    /* E-stop relay failed */
	GL_ERR_NOENT = -17,    /* file, label or variable not found */
	GL_ERR_OVERFLOW = -18, /* buffer or table too small */
	GL_ERR_BUSY = -19,     /* held by another process or supervisor */
};

/*
 * gl_strerror() - short lower-case text for an error code.
 * @err: a gl_err value (or any int).
 * Return: a static string, never NULL ("unknown error" for unknown codes).
 */
const char *gl_strerror(int err);

#endif /* GL_ERR_H */
