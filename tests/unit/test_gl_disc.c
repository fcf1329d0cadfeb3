/*
 * test_gl_disc.c - controller discovery (pc/galil/gl_disc): the probe
 * bytes, the reply parser and the BOOT-P parser on buffers, and
 * gl_disc_probe() against a listener of this test on 127.0.0.1 that
 * answers like a controller (twice, plus a datagram that is not a revision
 * report, both of which must be ignored).
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <pthread.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cmocka.h>

#include "gl_disc.h"
#include "gl_err.h"

#define WINDOW_MS 300 /* the probe's listening window in these tests */

static int parse(const char *s, struct gl_disc_ctrl *c)
{
	memset(c, 0, sizeof(*c));
	return gl_disc_parse_reply(s, strlen(s), c);
}

/* The probe is ^R^V CR. */
static void test_request(void **state)
{
	char b[8];

	(void)state;
	assert_int_equal(gl_disc_request(b, sizeof(b)), 3);
	assert_memory_equal(b, "\x12\x16\r", 3);
	assert_int_equal(gl_disc_request(b, 2), GL_ERR_OVERFLOW);
}

/* Revision reports as ^R^V answers them (command reference example). */
static void test_reply_ok(void **state)
{
	struct gl_disc_ctrl c;

	(void)state;
	assert_int_equal(parse("DMC4030 Rev 1.2h\r\n:", &c), GL_OK);
	assert_string_equal(c.model, "DMC4030");
	assert_string_equal(c.rev, "1.2h");
	assert_int_equal(c.serial, -1);
	assert_int_equal(parse(" DMC4143 Rev 1.1a1", &c), GL_OK);
	assert_string_equal(c.model, "DMC4143");
	assert_string_equal(c.rev, "1.1a1");
	assert_int_equal(parse("RIO47102 Rev 1.1j\r\n", &c), GL_OK);
	assert_string_equal(c.model, "RIO47102");
}

/* Anything else is not a controller's reply (untouched output). */
static void test_reply_bad(void **state)
{
	static const char *const bad[] = {
	    "",
	    ":",
	    "?",
	    "DMC4030",
	    "DMC4030 Rev ",
	    "DMC4030 rev 1.2h",
	    "4030 Rev 1.2h",
	    "DMC4030 Rev 1.2h x",
	    "DMC-4030 Rev 1.2h",
	    "DMC4030 Rev 1.2h\r\n:junk",
	};
	struct gl_disc_ctrl c;
	size_t i;

	(void)state;
	for (i = 0; i < sizeof(bad) / sizeof(bad[0]); i++) {
		memset(&c, 0x5a, sizeof(c));
		assert_int_equal(
		    gl_disc_parse_reply(bad[i], strlen(bad[i]), &c),
		    GL_ERR_FORMAT);
		assert_int_equal((unsigned char)c.model[0], 0x5a);
	}
}

/* A BOOT-P request with Galil's OUI 00:50:4C, model byte 8, serial 0x1234. */
static void bootp(unsigned char *b, size_t n)
{
	memset(b, 0, n);
	b[0] = 1, b[1] = 1, b[2] = 6;
	b[28] = 0x00, b[29] = 0x50, b[30] = 0x4c, b[31] = 8;
	b[32] = 0x12, b[33] = 0x34;
	b[236] = 0x63, b[237] = 0x82, b[238] = 0x53, b[239] = 0x63;
}

static void test_bootp(void **state)
{
	unsigned char b[300];
	struct gl_disc_ctrl c;

	(void)state;
	bootp(b, sizeof(b));
	assert_int_equal(gl_disc_parse_bootp(b, sizeof(b), &c), GL_OK);
	assert_string_equal(c.addr, "00:50:4C:08:12:34");
	assert_string_equal(c.model, "code 8");
	assert_int_equal(c.serial, 0x1234);
	assert_int_equal(gl_disc_parse_bootp(b, 239, &c), GL_ERR_FORMAT);
	b[29] = 0x51; /* another vendor */
	assert_int_equal(gl_disc_parse_bootp(b, sizeof(b), &c), GL_ERR_FORMAT);
	bootp(b, sizeof(b));
	b[0] = 2; /* a reply, not a request */
	assert_int_equal(gl_disc_parse_bootp(b, sizeof(b), &c), GL_ERR_FORMAT);
	bootp(b, sizeof(b));
	b[239] = 0; /* no magic cookie */
	assert_int_equal(gl_disc_parse_bootp(b, sizeof(b), &c), GL_ERR_FORMAT);
}

/* The listener: one probe, answered by junk and twice by a report. */
struct lsn {
	int fd, port;
	pthread_t th;
	char probe[16];
	ssize_t probe_len;
};

static void *lsn_main(void *arg)
{
	static const char *const answers[] = {
	    "hello", "DMC4030 Rev 1.2h\r\n:", "DMC4030 Rev 1.2h\r\n:"};
	struct lsn *s = arg;
	struct sockaddr_in from;
	socklen_t flen = sizeof(from);
	struct pollfd pfd = {.fd = s->fd, .events = POLLIN};
	size_t i;

	if (poll(&pfd, 1, 5000) != 1) /* the test's own deadline */
		return NULL;
	s->probe_len = recvfrom(s->fd, s->probe, sizeof(s->probe), 0,
				(struct sockaddr *)&from, &flen);
	for (i = 0; i < sizeof(answers) / sizeof(answers[0]); i++)
		sendto(s->fd, answers[i], strlen(answers[i]), 0,
		       (struct sockaddr *)&from, flen);
	return NULL;
}

static void test_probe_loopback(void **state)
{
	struct sockaddr_in a = {.sin_family = AF_INET};
	struct gl_disc_ctrl list[4];
	socklen_t len = sizeof(a);
	struct lsn s = {0};
	int n;

	(void)state;
	s.fd = socket(AF_INET, SOCK_DGRAM, 0);
	a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
	assert_true(s.fd >= 0);
	assert_int_equal(bind(s.fd, (struct sockaddr *)&a, sizeof(a)), 0);
	assert_int_equal(getsockname(s.fd, (struct sockaddr *)&a, &len), 0);
	s.port = ntohs(a.sin_port);
	assert_int_equal(pthread_create(&s.th, NULL, lsn_main, &s), 0);
	n = gl_disc_probe("127.0.0.1", (unsigned)s.port, WINDOW_MS, list, 4,
			  NULL);
	pthread_join(s.th, NULL);
	close(s.fd);
	assert_int_equal(s.probe_len, 3);
	assert_memory_equal(s.probe, "\x12\x16\r", 3);
	assert_int_equal(n, 1);
	assert_string_equal(list[0].addr, "127.0.0.1");
	assert_string_equal(list[0].model, "DMC4030");
	assert_string_equal(list[0].rev, "1.2h");
}

static void test_probe_args(void **state)
{
	struct gl_disc_ctrl list[1];

	(void)state;
	assert_int_equal(gl_disc_probe("not-an-ip", 50000, 10, list, 1, NULL),
			 GL_ERR_ARG);
	assert_int_equal(gl_disc_probe("127.0.0.1", 0, 10, list, 1, NULL),
			 GL_ERR_ARG);
	assert_int_equal(gl_disc_probe("127.0.0.1", 50000, 10, list, 0, NULL),
			 GL_ERR_ARG);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_request),
	    cmocka_unit_test(test_reply_ok),
	    cmocka_unit_test(test_reply_bad),
	    cmocka_unit_test(test_bootp),
	    cmocka_unit_test(test_probe_loopback),
	    cmocka_unit_test(test_probe_args),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
