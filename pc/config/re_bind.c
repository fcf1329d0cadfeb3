/*
 * re_bind.c - the E-stop relay bound to this robot by its USB serial
 * number: the serial number's rule, the choice of the board, the udev
 * rule's text, the start-up's comparison. See re_bind.h.
 */
#include "re_bind.h"

#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include "gl_err.h"

#define FIX "(docs/technician.md, section 10)"

/* The message of a refusal into @err (optional); returns @rc. */
static int say(int rc, char *err, size_t errlen, const char *fmt, ...)
{
	va_list ap;

	if (err && errlen) {
		va_start(ap, fmt);
		vsnprintf(err, errlen, fmt, ap);
		va_end(ap);
	}
	return rc;
}

char *re_bind_shown(const char *s, char *buf, size_t cap)
{
	size_t i;

	if (!cap)
		return buf;
	for (i = 0; s && s[i] && i + 1 < cap; i++)
		buf[i] = s[i] >= 0x20 && s[i] < 0x7f ? s[i] : '?';
	buf[i] = '\0';
	return buf;
}

static bool serial_char(char c)
{
	return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') ||
	       (c >= '0' && c <= '9') || c == '.' || c == '_' || c == '-' ||
	       c == ':';
}

int re_bind_serial_check(const char *serial, char *err, size_t errlen)
{
	char shown[RE_BIND_SERIAL_LEN + 2];
	size_t i, len = serial ? strlen(serial) : 0;

	if (!len)
		return say(GL_ERR_FORMAT, err, errlen,
			   "the serial number is empty");
	re_bind_shown(serial, shown, sizeof(shown));
	if (len > RE_BIND_SERIAL_LEN)
		return say(GL_ERR_FORMAT, err, errlen,
			   "serial number '%.*s...' is longer than %d "
			   "characters",
			   RE_BIND_SERIAL_LEN, shown, RE_BIND_SERIAL_LEN);
	for (i = 0; i < len; i++) {
		unsigned char c = (unsigned char)serial[i];

		if (serial_char(serial[i]))
			continue;
		if (c >= 0x20 && c < 0x7f)
			return say(GL_ERR_FORMAT, err, errlen,
				   "serial number '%s' has a character not "
				   "allowed in a udev rule ('%c' at position "
				   "%zu): only letters, digits, '.', '_', '-' "
				   "and ':'",
				   shown, c, i + 1);
		return say(GL_ERR_FORMAT, err, errlen,
			   "serial number '%s' has a character not allowed "
			   "in a udev rule (byte 0x%02x at position %zu): only "
			   "letters, digits, '.', '_', '-' and ':'",
			   shown, c, i + 1);
	}
	return GL_OK;
}

/* With @want: the one port of that serial number. */
static int choose_wanted(const struct re_bind_port *ports, size_t n,
			 const char *want, size_t *chosen, char *err,
			 size_t errlen)
{
	size_t i, found = 0;

	for (i = 0; i < n; i++) {
		if (strcmp(ports[i].serial, want))
			continue;
		if (!found++)
			*chosen = i;
	}
	if (found > 1)
		return say(GL_ERR_ARG, err, errlen,
			   "%zu USB serial ports have the serial number '%s': "
			   "a rule by serial number cannot tell them apart; "
			   "unplug every board but the relay",
			   found, want);
	if (!found)
		return say(GL_ERR_NOENT, err, errlen,
			   "no USB serial port has the serial number '%s' "
			   "(%zu found): plug in that relay board and run "
			   "again",
			   want, n);
	return GL_OK;
}

int re_bind_choose(const struct re_bind_port *ports, size_t n, const char *want,
		   size_t *chosen, char *err, size_t errlen)
{
	char shown[RE_BIND_NAME_MAX];

	if (want && re_bind_serial_check(want, err, errlen))
		return GL_ERR_FORMAT;
	if (!n)
		return say(GL_ERR_NOENT, err, errlen,
			   "no USB serial port found: plug in the relay board "
			   "and run again");
	if (want)
		return choose_wanted(ports, n, want, chosen, err, errlen);
	if (n > 1)
		return say(GL_ERR_ARG, err, errlen,
			   "%zu USB serial ports found: unplug every one but "
			   "the relay board and run again, or name it with "
			   "--serial SERIAL",
			   n);
	re_bind_shown(ports[0].name, shown, sizeof(shown));
	if (!ports[0].serial[0])
		return say(GL_ERR_NOENT, err, errlen,
			   "the one USB serial port, '%s', has no USB serial "
			   "number: it cannot be bound; use a relay board "
			   "that has one " FIX,
			   shown);
	if (re_bind_serial_check(ports[0].serial, err, errlen))
		return GL_ERR_FORMAT;
	*chosen = 0;
	return GL_OK;
}

int re_bind_rule(const struct re_bind_port *p, char *buf, size_t cap, char *err,
		 size_t errlen)
{
	int n;

	if (re_bind_serial_check(p->serial, err, errlen))
		return GL_ERR_FORMAT;
	if (p->vid < 0 || p->vid > 0xffff || p->pid < 0 || p->pid > 0xffff)
		return say(GL_ERR_RANGE, err, errlen,
			   "USB id %x:%x is not two 16-bit numbers", p->vid,
			   p->pid);
	n = snprintf(
	    buf, cap,
	    "# 60-roboelf-relay.rules - the E-stop relay of this robot, "
	    "bound by its USB\n"
	    "# serial number (written by 'roboelf-tech bind-relay'; "
	    "docs/technician.md,\n"
	    "# section 10): the name /dev/" RE_BIND_SYMLINK " for this one "
	    "board only, and\n"
	    "# read and write access for the group " RE_BIND_GROUP ". It "
	    "masks the package's rule\n"
	    "# of the same name in /lib/udev/rules.d, which names no board. "
	    "To bind\n"
	    "# another board, run 'roboelf-tech bind-relay' again.\n"
	    "SUBSYSTEM==\"tty\", ATTRS{idVendor}==\"%04x\", "
	    "ATTRS{idProduct}==\"%04x\", ATTRS{serial}==\"%s\", "
	    "SYMLINK+=\"" RE_BIND_SYMLINK "\", GROUP=\"" RE_BIND_GROUP
	    "\", MODE=\"" RE_BIND_MODE "\"\n",
	    (unsigned)p->vid, (unsigned)p->pid, p->serial);
	if (n < 0 || (size_t)n >= cap)
		return say(GL_ERR_OVERFLOW, err, errlen,
			   "the rule does not fit %zu bytes", cap);
	return n;
}

int re_bind_verify(const char *port, const char *read, const char *configured,
		   char *err, size_t errlen)
{
	char shown[RE_BIND_SERIAL_MAX];

	if (!configured || !configured[0])
		return say(GL_ERR_CONFIG, err, errlen,
			   "the E-stop relay '%s' is not bound to this robot: "
			   "relay.serial is not set; bind the board with "
			   "'roboelf-tech bind-relay' and set relay.serial to "
			   "the serial number it prints " FIX,
			   port);
	if (!read || !read[0])
		return say(GL_ERR_NOENT, err, errlen,
			   "the E-stop relay '%s' has no USB serial number "
			   "(relay.serial is '%s'): clinical mode needs the "
			   "board bound to this robot by its serial number; "
			   "plug in the board bound with 'roboelf-tech "
			   "bind-relay' " FIX,
			   port, configured);
	if (strcmp(read, configured))
		return say(GL_ERR_MISMATCH, err, errlen,
			   "the E-stop relay '%s' is not the board bound to "
			   "this robot: its USB serial number is '%s', "
			   "relay.serial is '%s'; plug in the bound board, or "
			   "bind this one with 'roboelf-tech bind-relay' and "
			   "set relay.serial to its serial number " FIX,
			   port, re_bind_shown(read, shown, sizeof(shown)),
			   configured);
	return GL_OK;
}
