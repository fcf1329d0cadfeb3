/* gl_err.c - texts for the gl_err codes. */
#include "gl_err.h"

const char *gl_strerror(int err)
{
	switch (err) {
	case GL_OK: return "success";
	case GL_ERR_ARG: return "invalid argument";
	case GL_ERR_SYS: return "system error";
	case GL_ERR_TIMEOUT: return "timed out";
	case GL_ERR_PROTO: return "protocol error";
	case GL_ERR_CTRL: return "controller rejected the command";
	case GL_ERR_CONFIG: return "invalid configuration";
	case GL_ERR_NOMEM: return "out of memory";
	case GL_ERR_CLOSED: return "connection closed by peer";
	case GL_ERR_BROKEN: return "link out of step";
	case GL_ERR_AGAIN: return "no data yet";
	case GL_ERR_RECORD: return "malformed data record";
	case GL_ERR_RANGE: return "value out of range";
	case GL_ERR_FORMAT: return "invalid format";
	case GL_ERR_CRC: return "checksum mismatch";
	case GL_ERR_MISMATCH: return "read-back mismatch";
	case GL_ERR_RELAY: return "relay failure";
	case GL_ERR_NOENT: return "not found";
	case GL_ERR_OVERFLOW: return "buffer too small";
	case GL_ERR_BUSY: return "in use by another supervisor";
	}
	return "unknown error";
}
