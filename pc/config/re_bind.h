/*
 * re_bind.h - the E-stop relay bound to this robot by its USB serial
 * number: the rule a serial number must follow, the choice of the relay
 * board among the USB serial ports found, the udev rule that names that
 * one board /dev/roboelf-relay, and the start-up's comparison of the
 * board's serial number with relay.serial (docs/technician.md, section 10;
 * docs/safety.md).
 *
 * Why a binding: the package's own udev rule matches no board (any FTDI
 * cable plugged into the PC would otherwise become "the E-stop relay").
 * `roboelf-tech bind-relay` writes /etc/udev/rules.d/60-roboelf-relay.rules
 * for the board's serial number, which masks the package's rule of the
 * same name in /lib/udev/rules.d; in clinical mode roboelf refuses a relay
 * whose USB serial number is not relay.serial.
 *
 * Pure: buffers in, text out; no I/O, no printing, no allocation. The ports
 * are listed by the caller (roboelf-tech, with libserialport), the serial
 * number of the configured port read by re_relay_usb_serial().
 */
#ifndef RE_BIND_H
#define RE_BIND_H

#include <stddef.h>

#define RE_BIND_SERIAL_MAX 128	/* bytes with the NUL (libserialport: 127) */
#define RE_BIND_NAME_MAX   256	/* a port's name, bytes with the NUL */
#define RE_BIND_DESC_MAX   128	/* a port's description, bytes with the NUL */
#define RE_BIND_SERIAL_LEN 64	/* longest serial number bound, characters */
#define RE_BIND_RULE_MAX   1024 /* the rules file, bytes with the NUL */
#define RE_BIND_ERR_MAX	   512	/* a message, bytes with the NUL */

/* The link udev makes, its group (the operators', which the package's
 * postinst creates) and mode: only root and that group use the relay. */
#define RE_BIND_SYMLINK "roboelf-relay"
#define RE_BIND_GROUP	"roboelf"
#define RE_BIND_MODE	"0660"

/* One USB serial port, as the caller's listing found it. */
struct re_bind_port {
	char name[RE_BIND_NAME_MAX];	 /* e.g. "/dev/ttyUSB0" */
	char desc[RE_BIND_DESC_MAX];	 /* e.g. "FT232R USB UART" */
	char serial[RE_BIND_SERIAL_MAX]; /* USB serial number; "": none */
	int vid, pid;			 /* USB vendor and product id */
};

/*
 * re_bind_serial_check() - may @serial stand in a udev rule's value?
 * 1..RE_BIND_SERIAL_LEN characters, each a letter, a digit, '.', '_', '-'
 * or ':' (no quote, backslash, space or control character, which would end
 * or change the value, and no '*', '?', '[' or '|', which udev takes as a
 * pattern matching other boards too).
 * @err: [out] optional; on refusal, e.g. "serial number 'A1\"B' has a
 *       character not allowed in a udev rule ('\"' at position 3): only
 *       letters, digits, '.', '_', '-' and ':'".
 * Return: GL_OK; GL_ERR_FORMAT (refused).
 */
int re_bind_serial_check(const char *serial, char *err, size_t errlen);

/*
 * re_bind_choose() - the relay board among the @n USB serial ports @ports.
 * @want: [in] the serial number asked for (--serial), or NULL: then the
 *        one port there is.
 * @chosen: [out] its index in @ports, on success.
 * @err: [out] optional; the refusal with what to do, e.g. "2 USB serial
 *       ports found: unplug every one but the relay board and run again,
 *       or name it with --serial SERIAL".
 * Refused: @want or the chosen port's serial number not allowed
 * (re_bind_serial_check()); no port; with @want, no port of that serial
 * number; without, more than one port, or one with no serial number.
 * Return: GL_OK; GL_ERR_FORMAT (a serial number refused); GL_ERR_NOENT
 *         (no port, or none of that serial number, or none with a serial
 *         number); GL_ERR_ARG (several ports and no @want).
 */
int re_bind_choose(const struct re_bind_port *ports, size_t n, const char *want,
		   size_t *chosen, char *err, size_t errlen);

/*
 * re_bind_rule() - the whole rules file that names the board @p (its
 * vendor and product ids and serial number) /dev/roboelf-relay, group
 * roboelf, mode 0660: a comment, then the rule on its own line:
 *   SUBSYSTEM=="tty", ATTRS{idVendor}=="0403", ATTRS{idProduct}=="6001",
 *   ATTRS{serial}=="A10KXYZ9", SYMLINK+="roboelf-relay", GROUP="roboelf",
 *   MODE="0660"
 * Nothing the device reports is written but its ids and checked serial.
 * @buf: [out] NUL-terminated; @cap: its size (RE_BIND_RULE_MAX is enough).
 * @err: [out] optional, on refusal.
 * Return: the length written (> 0); GL_ERR_FORMAT (serial number refused);
 *         GL_ERR_RANGE (an id outside 0..0xffff); GL_ERR_OVERFLOW.
 */
int re_bind_rule(const struct re_bind_port *p, char *buf, size_t cap, char *err,
		 size_t errlen);

/*
 * re_bind_verify() - is the relay at @port the board bound to this robot?
 * Clinical start-up: @read is the USB serial number read from the port
 * (re_relay_usb_serial(), "" when it has none), @configured relay.serial.
 * Equal and not empty: bound.
 * @err: [out] optional; on refusal a message naming the port, both values
 *       and the fix ('roboelf-tech bind-relay'); characters of @read that
 *       are not printable ASCII are shown as '?'.
 * Return: GL_OK; GL_ERR_CONFIG (relay.serial empty); GL_ERR_NOENT (the
 *         port has no USB serial number); GL_ERR_MISMATCH (different).
 */
int re_bind_verify(const char *port, const char *read, const char *configured,
		   char *err, size_t errlen);

/*
 * re_bind_shown() - @s for a terminal or a log: every byte that is not
 * printable ASCII replaced by '?', cut to @cap - 1 bytes.
 * Return: @buf.
 */
char *re_bind_shown(const char *s, char *buf, size_t cap);

#endif /* RE_BIND_H */
