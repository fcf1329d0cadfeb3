/*
 * gl_disc.h - finding Galil controllers on the local network, the way
 * Galil's own tools do (docs/galil-load.md "Finding the controller").
 *
 * Galil's GDK firewall page lists the traffic of its discovery: a
 * "Controller discovery request" sent to UDP port 50000 and a "Controller
 * discovery reply" from UDP port 50000; gclib's GAddresses() lists each
 * Ethernet controller as "address, revision report" (e.g. "DMC4040 Rev
 * 1.2f"). The bytes of the request and reply are not published: we send the
 * revision request ^R^V (0x12 0x16, command reference ^R^V) and take a reply
 * that reads like a revision report (UNCONFIRMED on hardware). Controllers
 * without an IP address send BOOT-P requests (UDP 68 -> 67) whose hardware
 * address carries Galil's OUI 00:50:4C, a model byte and the serial number
 * (Galil's Linux driver, FillBootpRep); gl_disc_parse_bootp() reads them
 * (listening on port 67 needs root, so no tool here does).
 *
 * Parsers take buffers and are pure; gl_disc_probe() is the only function
 * that touches a socket. Nothing here prints. roboelf never uses this
 * module (it must never connect anywhere but its configured address).
 */
#ifndef GL_DISC_H
#define GL_DISC_H

#include <stddef.h>

#include "gl_link.h"

#define GL_DISC_PORT	  50000 /* Galil GDK firewall page */
#define GL_DISC_BCAST	  "255.255.255.255"
#define GL_DISC_REPLY_MAX 512 /* bytes of one reply datagram read */

/* One controller that answered. */
struct gl_disc_ctrl {
	char addr[48];	/* the reply's source address, e.g. "192.168.1.40" */
	char model[32]; /* e.g. "DMC4030" */
	char rev[32];	/* firmware revision, e.g. "1.2h" */
	long serial;	/* serial number, -1 when not known */
};

/*
 * gl_disc_request() - the probe datagram: ^R^V CR (3 bytes).
 * @buf: [out] at least @cap bytes. Return: the length, or GL_ERR_OVERFLOW.
 */
int gl_disc_request(char *buf, size_t cap);

/*
 * gl_disc_parse_reply() - parse one reply datagram (pure).
 * @buf, @len: the datagram: a revision report "MODEL Rev REVISION",
 *       optionally with leading spaces and followed by CR, LF and ':'.
 *       MODEL is letters and digits starting with a letter (e.g.
 *       "DMC4030", "RIO47102"); REVISION is printable, without spaces.
 * @out: [out] model and rev filled, addr left untouched, serial -1.
 * Return: GL_OK, or GL_ERR_FORMAT (not a revision report; @out untouched).
 */
int gl_disc_parse_reply(const char *buf, size_t len, struct gl_disc_ctrl *out);

/*
 * gl_disc_parse_bootp() - read a BOOT-P/DHCP request of a Galil controller
 * (pure): op 1, hardware address starting with 00:50:4C, the magic cookie
 * 0x63825363 at byte 236.
 * @out: [out] addr is the MAC "00:50:4C:xx:xx:xx", model the model byte as
 *       "code N", serial from bytes 32-33 (big-endian); rev empty.
 * Return: GL_OK, or GL_ERR_FORMAT (shorter than 240 bytes, not a request,
 *         not from a Galil controller).
 */
int gl_disc_parse_bootp(const unsigned char *buf, size_t len,
			struct gl_disc_ctrl *out);

/*
 * gl_disc_probe() - send the probe to @bcast:@port (broadcast allowed) and
 * collect the replies for @window_ms, then return (a deadline, not a count).
 * Replies that do not parse are ignored; one entry per source address.
 * @bcast: IPv4 address, e.g. GL_DISC_BCAST or "127.0.0.1".
 * @list: [out] up to @max controllers, in the order they answered.
 * @err: [out] optional GL_ERRTEXT_LEN bytes, e.g. "cannot send the
 *       discovery probe to '255.255.255.255:50000': Network is unreachable".
 * Return: the number found (>= 0), GL_ERR_ARG, GL_ERR_SYS.
 */
int gl_disc_probe(const char *bcast, unsigned port, int window_ms,
		  struct gl_disc_ctrl *list, int max, char err[GL_ERRTEXT_LEN]);

#endif /* GL_DISC_H */
