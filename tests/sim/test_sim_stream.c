/*
 * test_sim_stream.c - galil-sim's UDP command port and the DR record
 * stream over real sockets ($ROBOELF_BIN/galil-sim --udp-port 0): the
 * ready line's " udp <port>", a datagram opening a UDP handle and its
 * reply in one datagram, records arriving every n0 samples in real time,
 * the link faults on the stream side and on the TCP side separately (stall:
 * records lost; delay; drop: the UDP handle closed), and
 * IHT=>-1 closing the UDP handle (the stream stops).
 *
 * Every wait polls with a deadline; the process is signalled by pid only.
 */
#include <netinet/in.h>
#include <poll.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>
#include <arpa/inet.h>

#include <cmocka.h>

#include "proc.h"

#define START_MS 5000 /* ready line deadline */
#define REPLY_MS 2000 /* generous reply deadline */
#define QUIET_MS 300  /* "nothing arrives" is judged over this */
#define REC_LEN	 190  /* a DMC-4030 record: header, 3 axes */

struct fx {
	struct proc_sim sim;
	int ctl; /* control connection */
	int udp; /* our UDP socket, connected to galil-sim's UDP port */
	char resp[65536];
};

static int teardown(void **state);

static int setup(void **state)
{
	static char *const extra[] = {(char *)"--udp-port", (char *)"0", NULL};
	const char *bin = getenv("ROBOELF_BIN");
	struct fx *f = calloc(1, sizeof(*f));
	struct sockaddr_in sa = {.sin_family = AF_INET};

	if (!f)
		return -1;
	*state = f;
	f->ctl = f->udp = -1;
	if (!bin || proc_sim_start(&f->sim, bin, NULL, extra, START_MS) < 0) {
		fprintf(stderr, "galil-sim did not start (ROBOELF_BIN?)\n");
		teardown(state);
		return -1;
	}
	f->ctl = proc_ctl_connect(f->sim.ctl_port, REPLY_MS);
	f->udp = socket(AF_INET, SOCK_DGRAM, 0);
	sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
	sa.sin_port = htons((uint16_t)f->sim.udp_port);
	if (f->ctl < 0 || f->udp < 0 || f->sim.udp_port <= 0 ||
	    connect(f->udp, (struct sockaddr *)&sa, sizeof(sa)) < 0) {
		teardown(state);
		return -1;
	}
	return 0;
}

static int teardown(void **state)
{
	struct fx *f = *state;

	if (f->ctl >= 0)
		close(f->ctl);
	if (f->udp >= 0)
		close(f->udp);
	proc_kill(&f->sim.p);
	free(f);
	return 0;
}

static const char *ctl(struct fx *f, const char *req)
{
	if (proc_ctl_request(f->ctl, req, f->resp, sizeof(f->resp), REPLY_MS) <
	    0)
		fail_msg("no answer to '%s'", req);
	return f->resp;
}

static const char *events(struct fx *f)
{
	if (proc_ctl_request_multi(f->ctl, "events", f->resp, sizeof(f->resp),
				   REPLY_MS) < 0)
		fail_msg("no answer to 'events'");
	return f->resp;
}

/* One datagram within @ms; return its length, -1 when none came. */
static int recv_dgram(int fd, uint8_t *buf, size_t cap, int ms)
{
	struct pollfd p = {fd, POLLIN, 0};
	ssize_t r;

	if (poll(&p, 1, ms) != 1)
		return -1;
	r = recv(fd, buf, cap, 0);
	return (int)r;
}

/* Discard every datagram waiting now. */
static void drain(int fd)
{
	uint8_t buf[2048];

	while (recv_dgram(fd, buf, sizeof(buf), 0) >= 0)
		;
}

/* Send one datagram; the next datagram that is not a record is its
 * reply, which must be @want exactly. Records met on the way are
 * skipped. */
static void udp_exchange(struct fx *f, const char *cmd, const char *want,
			 int ms)
{
	long long end = proc_now_ms() + ms;
	uint8_t buf[2048];
	int n;

	assert_int_equal(send(f->udp, cmd, strlen(cmd), 0), strlen(cmd));
	do {
		n = recv_dgram(f->udp, buf, sizeof(buf) - 1,
			       (int)(end - proc_now_ms()));
		if (n < 0)
			fail_msg("no reply to '%s'", cmd);
	} while (n == REC_LEN && buf[0] == 0x87);
	buf[n] = '\0';
	assert_string_equal((char *)buf, want);
}

/* @n records in a row, each within the deadline; their sample numbers. */
static void recv_records(struct fx *f, uint16_t *sample, int n)
{
	uint8_t buf[2048];

	for (int i = 0; i < n; i++) {
		int len = recv_dgram(f->udp, buf, sizeof(buf), REPLY_MS);

		assert_int_equal(len, REC_LEN);
		assert_int_equal(buf[0], 0x87);
		assert_int_equal(buf[2] | buf[3] << 8, REC_LEN);
		sample[i] = (uint16_t)(buf[4] | buf[5] << 8);
	}
}

static int tcp_connect(struct fx *f)
{
	int fd = proc_ctl_connect(f->sim.port, REPLY_MS);

	assert_true(fd >= 0);
	return fd;
}

/* A TCP reply ending in ':' within @ms; -1 when none came. */
static int tcp_reply(int fd, char *buf, size_t cap, int ms)
{
	long long end = proc_now_ms() + ms;
	size_t n = 0;

	while (n + 1 < cap) {
		struct pollfd p = {fd, POLLIN, 0};
		long long left = end - proc_now_ms();
		ssize_t r;

		if (left <= 0 || poll(&p, 1, (int)left) != 1)
			return -1;
		if ((r = recv(fd, buf + n, cap - n - 1, 0)) <= 0)
			return -1;
		n += (size_t)r;
		buf[n] = '\0';
		if (buf[n - 1] == ':' || buf[n - 1] == '?')
			return (int)n;
	}
	return -1;
}

static void tcp_send(int fd, const char *cmd)
{
	assert_int_equal(send(fd, cmd, strlen(cmd), MSG_NOSIGNAL), strlen(cmd));
}

/* ---- tests ------------------------------------------------------------- */

/* The ready line ends with " udp <port>"; a datagram opens handle A (UDP),
 * each datagram is answered in one datagram, a TCP host then gets B. */
static void test_udp_commands(void **state)
{
	struct fx *f = *state;
	char line[512], want[64], buf[256];
	int tcp;

	assert_int_equal(proc_find_line(&f->sim.p, PROC_STDOUT,
					"galil-sim:", line, sizeof(line)),
			 0);
	snprintf(want, sizeof(want), " udp %d", f->sim.udp_port);
	assert_non_null(strstr(line, want));
	udp_exchange(f, "WH\r", "IHA\r\n:", REPLY_MS);
	udp_exchange(f, "MG _IHA2;MG 7", " 1.0000\r\n: 7.0000\r\n:", REPLY_MS);
	udp_exchange(f, "DR 10,1\r", "?", REPLY_MS); /* B is no UDP handle */
	udp_exchange(f, "TC1\r", " 133 Handle must be UDP\r\n:", REPLY_MS);
	tcp = tcp_connect(f);
	tcp_send(tcp, "WH;MG _IHA2\r");
	assert_true(tcp_reply(tcp, buf, sizeof(buf), REPLY_MS) > 0);
	assert_string_equal(buf, "IHB\r\n: 1.0000\r\n:");
	assert_non_null(strstr(events(f), "handle A opened from 127.0.0.1:"));
	assert_non_null(strstr(f->resp, " (UDP)"));
	close(tcp);
}

/* DR 20,0: records, one per datagram, 20 samples apart, in real time. */
static void test_stream_real_time(void **state)
{
	struct fx *f = *state;
	uint16_t s[10];
	long long t0;

	udp_exchange(f, "DR 20,0\r", ":", REPLY_MS);
	t0 = proc_now_ms();
	recv_records(f, s, 10);
	for (int i = 1; i < 10; i++)
		assert_int_equal((uint16_t)(s[i] - s[i - 1]), 20);
	/* 10 records at 20 ms: about 200 ms of wall clock (loose: a busy
	 * machine catches up in bursts) */
	assert_true(proc_now_ms() - t0 >= 150);
	udp_exchange(f, "DR 0\r", ":", REPLY_MS);
	drain(f->udp);
	assert_int_equal(recv_dgram(f->udp, (uint8_t[256]){0}, 256, QUIET_MS),
			 -1);
}

/* "link stall stream" loses the records but not the TCP replies; "link
 * stall tcp" the TCP replies but not the records; "link delay MS stream"
 * holds the UDP replies back. */
static void test_stream_faults(void **state)
{
	struct fx *f = *state;
	uint8_t rec[2048];
	uint16_t s[3];
	char buf[256];
	long long t0;
	int tcp;

	udp_exchange(f, "DR 10,0\r", ":", REPLY_MS);
	tcp = tcp_connect(f);
	recv_records(f, s, 3);
	assert_string_equal(ctl(f, "link stall stream"), "ok");
	drain(f->udp);
	assert_int_equal(recv_dgram(f->udp, rec, sizeof(rec), QUIET_MS), -1);
	tcp_send(tcp, "MG 1\r");
	assert_true(tcp_reply(tcp, buf, sizeof(buf), REPLY_MS) > 0);
	assert_string_equal(buf, " 1.0000\r\n:");
	assert_string_equal(ctl(f, "link stall tcp"), "ok");
	recv_records(f, s, 3);
	tcp_send(tcp, "MG 2\r");
	assert_int_equal(tcp_reply(tcp, buf, sizeof(buf), QUIET_MS), -1);
	assert_string_equal(ctl(f, "link ok"), "ok");
	recv_records(f, s, 3);
	assert_string_equal(ctl(f, "link delay 400 stream"), "ok");
	udp_exchange(f, "DR 0\r", ":", REPLY_MS);
	drain(f->udp);
	t0 = proc_now_ms();
	udp_exchange(f, "MG 3\r", " 3.0000\r\n:", REPLY_MS);
	assert_true(proc_now_ms() - t0 >= 350);
	t0 = proc_now_ms();
	tcp_send(tcp, "MG 4\r");
	assert_true(tcp_reply(tcp, buf, sizeof(buf), REPLY_MS) > 0);
	assert_true(proc_now_ms() - t0 < 350);
	assert_non_null(strstr(events(f), "inject: link stall stream\n"));
	assert_non_null(strstr(f->resp, "inject: link delay 400 stream"));
	close(tcp);
}

/* "link drop stream" closes the UDP handle only and refuses new peers;
 * the TCP host keeps its handle. */
static void test_stream_drop(void **state)
{
	struct fx *f = *state;
	uint8_t rec[2048];
	char buf[256];
	int tcp;

	udp_exchange(f, "DR 10,0\r", ":", REPLY_MS);
	tcp = tcp_connect(f);
	assert_string_equal(ctl(f, "link drop stream"), "ok");
	tcp_send(tcp, "MG _IHA2, _IHB2, _DR0\r");
	assert_true(tcp_reply(tcp, buf, sizeof(buf), REPLY_MS) > 0);
	assert_string_equal(buf, " 0.0000 2.0000 0.0000\r\n:");
	drain(f->udp);
	assert_int_equal(send(f->udp, "WH\r", 3, 0), 3);
	assert_int_equal(recv_dgram(f->udp, rec, sizeof(rec), QUIET_MS), -1);
	events(f);
	assert_non_null(strstr(f->resp, "handle A closed (link drop)"));
	assert_non_null(strstr(f->resp, "refused (link drop)"));
	assert_null(strstr(f->resp, "handle B closed"));
	assert_string_equal(ctl(f, "link ok"), "ok");
	udp_exchange(f, "WH\r", "IHA\r\n:", REPLY_MS);
	close(tcp);
}

/* IHT=>-1 from a TCP host closes the UDP handle after its reply: the
 * stream stops; the next datagram opens the handle again. */
static void test_ih_closes_udp(void **state)
{
	struct fx *f = *state;
	uint8_t rec[2048];
	uint16_t s[2];
	char buf[256];
	int tcp;

	udp_exchange(f, "DR 10,0\r", ":", REPLY_MS);
	recv_records(f, s, 2);
	tcp = tcp_connect(f);
	tcp_send(tcp, "IHT=>-1\r");
	assert_true(tcp_reply(tcp, buf, sizeof(buf), REPLY_MS) > 0);
	assert_string_equal(buf, ":");
	tcp_send(tcp, "MG _IHA2, _DR0\r");
	assert_true(tcp_reply(tcp, buf, sizeof(buf), REPLY_MS) > 0);
	assert_string_equal(buf, " 0.0000 0.0000\r\n:");
	drain(f->udp);
	assert_int_equal(recv_dgram(f->udp, rec, sizeof(rec), QUIET_MS), -1);
	assert_non_null(
	    strstr(events(f), "handle A closed by IHT from handle B"));
	udp_exchange(f, "WH\r", "IHA\r\n:", REPLY_MS);
	close(tcp);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test_setup_teardown(test_udp_commands, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_stream_real_time, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_stream_faults, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_stream_drop, setup, teardown),
	    cmocka_unit_test_setup_teardown(test_ih_closes_udp, setup,
					    teardown),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
