/*
 * test_sim_disc.c - galil-sim's answer to the controller discovery probe:
 * the probe and reply bytes (sim_disc.h, pure), the model text against the
 * controller's own ^R^V answer (in-process), and the galil-sim program
 * ($ROBOELF_BIN/galil-sim --disc-port 0) over UDP: a probe is answered
 * from the discovery port with exactly the bytes ^R^V answers on the
 * command port; malformed datagrams get nothing, each is an event, and
 * the simulator keeps serving; a burst larger than one pass's bound is
 * answered whole; a discovery port in use is exit 1.
 *
 * Every wait has a deadline; "nothing was sent" is judged after the
 * simulator has logged the datagram, never by waiting for silence.
 */
#include <arpa/inet.h>
#include <errno.h>
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

#include <cmocka.h>

#include "ctrl.h"
#include "gl_err.h"
#include "proc.h"
#include "sim.h"
#include "sim_disc.h"

#define START_MS 5000 /* ready line deadline */
#define REPLY_MS 2000 /* generous reply deadline */
#define MODEL	 "DMC4030 Rev 1.2h-sim"
#define REPLY	 MODEL "\r\n:"
#define PROBE	 "\x12\x16\r"

/* ---- the bytes (pure) -------------------------------------------------- */

static int probe(const char *b, size_t len)
{
	return sim_disc_is_probe((const uint8_t *)b, len);
}

static void test_probe_bytes(void **state)
{
	uint8_t big[SIM_DISC_READ_MAX] = {0x12, 0x16, '\r'};

	(void)state;
	assert_int_equal(probe(PROBE, 3), 1);
	assert_int_equal(probe("\x12\x16\r\n", 4), 1);
	assert_int_equal(probe("", 0), 0);
	assert_int_equal(probe("\x12\x16", 2), 0);	/* no CR */
	assert_int_equal(probe("\x12\x16\n", 3), 0);	/* LF, not CR */
	assert_int_equal(probe("\x12\x16\r\r", 4), 0);	/* a second CR */
	assert_int_equal(probe("\x12\x16\r\nX", 5), 0); /* more after it */
	assert_int_equal(probe("\x16\x12\r", 3), 0);	/* swapped */
	assert_int_equal(probe("MG _BN\r", 7), 0);
	assert_int_equal(sim_disc_is_probe(NULL, 3), 0);
	/* the whole length counts, not the bytes read */
	assert_int_equal(sim_disc_is_probe(big, 600), 0);
}

static void test_reply_bytes(void **state)
{
	char buf[SIM_DISC_REPLY_MAX];

	(void)state;
	assert_int_equal(sim_disc_reply(MODEL, buf, sizeof(buf)), 23);
	assert_memory_equal(buf, REPLY, 23);
	assert_int_equal(sim_disc_reply(MODEL, buf, 23), 23);
	assert_int_equal(sim_disc_reply(MODEL, buf, 22), GL_ERR_OVERFLOW);
	assert_int_equal(sim_disc_reply(NULL, buf, sizeof(buf)),
			 GL_ERR_OVERFLOW);
}

/* The text the responder is given is what the controller answers to ^R^V,
 * and the serial (not in the reply) stays the documented 403001. */
static void test_model_is_rv_answer(void **state)
{
	struct sim *s;
	char err[256], resp[128];

	(void)state;
	assert_int_equal(sim_new(&s, NULL, err, sizeof(err)), 0);
	assert_string_equal(sim_model(s), MODEL);
	assert_int_equal(
	    ctrl_command(sim_ctrl(s), "\x12\x16", resp, sizeof(resp)), 0);
	assert_string_equal(resp, MODEL "\r\n");
	assert_int_equal(
	    ctrl_command(sim_ctrl(s), "MG _BN", resp, sizeof(resp)), 0);
	assert_string_equal(resp, " 403001.0000\r\n");
	sim_free(s);
}

/* ---- galil-sim over UDP ------------------------------------------------ */

struct fx {
	struct proc_sim sim;
	int disc; /* the discovery port from the ready line */
	int udp;  /* this test's UDP socket on 127.0.0.1 */
	int ctl;  /* control connection */
	char resp[65536];
	char ev[8192]; /* the "discovery:" events read so far */
	size_t ev_len;
};

static int fx_free(struct fx *f)
{
	if (f->udp >= 0)
		close(f->udp);
	if (f->ctl >= 0)
		close(f->ctl);
	proc_kill(&f->sim.p);
	free(f);
	return -1;
}

static int udp_open(void)
{
	struct sockaddr_in a = {.sin_family = AF_INET};
	int fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);

	a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
	if (fd >= 0 && bind(fd, (struct sockaddr *)&a, sizeof(a)) < 0) {
		close(fd);
		return -1;
	}
	return fd;
}

/* galil-sim with --disc-port 0; the port is the ready line's " disc N". */
static int setup(void **state)
{
	char *const extra[] = {(char *)"--disc-port", (char *)"0", NULL};
	const char *bin = getenv("ROBOELF_BIN");
	struct fx *f = calloc(1, sizeof(*f));
	char line[512];
	const char *d;

	if (!f)
		return -1;
	f->udp = f->ctl = -1;
	if (!bin || proc_sim_start(&f->sim, bin, NULL, extra, START_MS) < 0) {
		fprintf(stderr, "galil-sim did not start (ROBOELF_BIN?)\n");
		return fx_free(f);
	}
	if (proc_find_line(&f->sim.p, PROC_STDOUT, "galil-sim: listening on ",
			   line, sizeof(line)) < 0 ||
	    !(d = strstr(line, " disc ")) ||
	    sscanf(d, " disc %d", &f->disc) != 1)
		return fx_free(f);
	f->udp = udp_open();
	f->ctl = proc_ctl_connect(f->sim.ctl_port, REPLY_MS);
	if (f->udp < 0 || f->ctl < 0)
		return fx_free(f);
	*state = f;
	return 0;
}

static int teardown(void **state)
{
	fx_free(*state);
	return 0;
}

static void send_to(int fd, int port, const void *b, size_t len)
{
	struct sockaddr_in to = {.sin_family = AF_INET};

	to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
	to.sin_port = htons((uint16_t)port);
	assert_int_equal(
	    sendto(fd, b, len, 0, (struct sockaddr *)&to, sizeof(to)),
	    (ssize_t)len);
}

/* One datagram within REPLY_MS: its length, @from its source. */
static ssize_t recv_one(int fd, char *b, size_t cap, struct sockaddr_in *from)
{
	struct pollfd pfd = {.fd = fd, .events = POLLIN};
	socklen_t flen = sizeof(*from);

	assert_int_equal(poll(&pfd, 1, REPLY_MS), 1);
	return recvfrom(fd, b, cap, 0, (struct sockaddr *)from, &flen);
}

static int local_port(int fd)
{
	struct sockaddr_in a;
	socklen_t len = sizeof(a);

	assert_int_equal(getsockname(fd, (struct sockaddr *)&a, &len), 0);
	return ntohs(a.sin_port);
}

/* Read the events; keep the "discovery:" ones, without their times, one
 * per line, in f->ev (reading events consumes them). */
static void read_events(struct fx *f)
{
	char *line, *save = NULL;

	assert_true(proc_ctl_request_multi(f->ctl, "events", f->resp,
					   sizeof(f->resp), REPLY_MS) >= 0);
	for (line = strtok_r(f->resp, "\n", &save); line;
	     line = strtok_r(NULL, "\n", &save)) {
		const char *t = strstr(line, " discovery: ");

		if (!t)
			continue;
		assert_true(f->ev_len + strlen(t) + 1 < sizeof(f->ev));
		f->ev_len +=
		    (size_t)snprintf(f->ev + f->ev_len,
				     sizeof(f->ev) - f->ev_len, "%s\n", t + 1);
	}
}

/* The "discovery:" events, once @last (a whole line) is among them. */
static const char *disc_events(struct fx *f, const char *last)
{
	long long deadline = proc_now_ms() + REPLY_MS;

	for (read_events(f); !strstr(f->ev, last); read_events(f)) {
		if (proc_now_ms() > deadline)
			fail_msg("no event '%s' within %d ms; got:\n%s", last,
				 REPLY_MS, f->ev);
		poll(NULL, 0, 2); /* between requests, not instead of a wait */
	}
	return f->ev;
}

/* ^R^V over the command port: what the controller answers there. */
static void rv_over_tcp(struct fx *f, char *b, size_t cap)
{
	int fd = proc_ctl_connect(f->sim.port, REPLY_MS);
	size_t n = 0;
	ssize_t r;

	assert_true(fd >= 0);
	assert_int_equal(write(fd, PROBE, 3), 3);
	while (n == 0 || b[n - 1] != ':') {
		struct pollfd pfd = {.fd = fd, .events = POLLIN};

		assert_int_equal(poll(&pfd, 1, REPLY_MS), 1);
		r = read(fd, b + n, cap - 1 - n);
		assert_true(r > 0);
		n += (size_t)r;
	}
	b[n] = '\0';
	close(fd);
}

/* A probe is answered from the discovery port with the ^R^V answer. */
static void test_probe_answered(void **state)
{
	struct fx *f = *state;
	struct sockaddr_in from;
	char b[128], tcp[128], want[128];

	send_to(f->udp, f->disc, PROBE, 3);
	assert_int_equal(recv_one(f->udp, b, sizeof(b), &from), 23);
	assert_memory_equal(b, REPLY, 23);
	assert_int_equal(ntohs(from.sin_port), f->disc);
	assert_int_equal(ntohl(from.sin_addr.s_addr), INADDR_LOOPBACK);
	rv_over_tcp(f, tcp, sizeof(tcp));
	assert_string_equal(tcp, REPLY);
	snprintf(want, sizeof(want), "discovery: answered 127.0.0.1:%d\n",
		 local_port(f->udp));
	assert_string_equal(disc_events(f, want), want);
}

/* Malformed datagrams: no answer, one event each, in order; the probe
 * after them is answered and its reply is the only datagram that came
 * back (counted once its event says every datagram has been handled). */
static void test_malformed_ignored(void **state)
{
	struct fx *f = *state;
	static const char *const bad[] = {"", "\x12\x16", "MG _BN\r",
					  "\x12\x16\r\r"};
	static const size_t bad_len[] = {0, 2, 7, 4};
	char big[600], b[128], want[1024], last[128], st[32];
	struct sockaddr_in from;
	int me = local_port(f->udp), n = 0;

	memset(big, 'x', sizeof(big));
	memcpy(big, PROBE, 3); /* begins like a probe, 600 bytes long */
	for (size_t i = 0; i < 4; i++)
		send_to(f->udp, f->disc, bad[i], bad_len[i]);
	send_to(f->udp, f->disc, big, sizeof(big));
	send_to(f->udp, f->disc, PROBE, 3);
	snprintf(last, sizeof(last), "discovery: answered 127.0.0.1:%d\n", me);
	(void)disc_events(f, last); /* every reply has been sent by now */
	assert_int_equal(recv_one(f->udp, b, sizeof(b), &from), 23);
	assert_memory_equal(b, REPLY, 23);
	assert_int_equal(recv(f->udp, b, sizeof(b), MSG_DONTWAIT), -1);
	assert_true(errno == EAGAIN || errno == EWOULDBLOCK);
	for (size_t i = 0; i < 5; i++)
		n += snprintf(want + n, sizeof(want) - (size_t)n,
			      "discovery: ignored %zu bytes from 127.0.0.1:%d "
			      "(not ^R^V CR)\n",
			      i < 4 ? bad_len[i] : sizeof(big), me);
	snprintf(want + n, sizeof(want) - (size_t)n, "%s", last);
	assert_string_equal(f->ev, want);
	/* still serving: the control port and the command port */
	assert_true(proc_ctl_request(f->ctl, "time", st, sizeof(st), REPLY_MS) >
		    0);
	rv_over_tcp(f, b, sizeof(b));
	assert_string_equal(b, REPLY);
}

/* More probes at once than one pass handles (SIM_DISC_BURST): every one
 * is answered, in later passes. */
static void test_burst_answered(void **state)
{
	struct fx *f = *state;
	enum { N = 3 * SIM_DISC_BURST + 1 };
	struct sockaddr_in from;
	char b[128];

	for (int i = 0; i < N; i++)
		send_to(f->udp, f->disc, PROBE, 3);
	for (int i = 0; i < N; i++) {
		assert_int_equal(recv_one(f->udp, b, sizeof(b), &from), 23);
		assert_memory_equal(b, REPLY, 23);
	}
}

/* A second galil-sim on the same discovery port: exit 1, the reason. */
static void test_port_in_use(void **state)
{
	struct fx *f = *state;
	char bin[512], port[16], want[256];
	char *argv[] = {bin,
			(char *)"--port",
			(char *)"0",
			(char *)"--control-port",
			(char *)"0",
			(char *)"--no-relay-link",
			(char *)"--disc-port",
			port,
			NULL};
	struct proc p;
	int st;

	snprintf(bin, sizeof(bin), "%s/galil-sim", getenv("ROBOELF_BIN"));
	snprintf(port, sizeof(port), "%d", f->disc);
	assert_int_equal(proc_spawn(&p, argv, NULL), 0);
	assert_int_equal(proc_wait_exit(&p, START_MS, &st), 0);
	assert_int_equal(proc_exit_code(&p), 1);
	snprintf(want, sizeof(want),
		 "galil-sim: cannot bind the discovery port 127.0.0.1:%d: "
		 "Address already in use\n",
		 f->disc);
	assert_string_equal(proc_output(&p, PROC_STDERR), want);
	assert_string_equal(proc_output(&p, PROC_STDOUT), "");
	proc_kill(&p);
}

/* Without --disc-port nothing is bound and the ready line is unchanged. */
static void test_off_by_default(void **state)
{
	struct proc_sim s;
	char line[512], want[512];

	(void)state;
	assert_int_equal(
	    proc_sim_start(&s, getenv("ROBOELF_BIN"), NULL, NULL, START_MS), 0);
	assert_int_equal(proc_find_line(&s.p, PROC_STDOUT,
					"galil-sim: listening on ", line,
					sizeof(line)),
			 0);
	snprintf(want, sizeof(want),
		 "galil-sim: listening on 127.0.0.1:%d control %d relay %s",
		 s.port, s.ctl_port, s.relay);
	assert_string_equal(line, want);
	proc_kill(&s.p);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_probe_bytes),
	    cmocka_unit_test(test_reply_bytes),
	    cmocka_unit_test(test_model_is_rv_answer),
	    cmocka_unit_test_setup_teardown(test_probe_answered, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_malformed_ignored, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_burst_answered, setup,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_port_in_use, setup, teardown),
	    cmocka_unit_test(test_off_by_default),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
