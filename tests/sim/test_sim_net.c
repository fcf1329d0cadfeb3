/*
 * test_sim_net.c - the galil-sim program ($ROBOELF_BIN/galil-sim) over its
 * real ports: the ready line, the control port, the command port and its
 * link faults (drop, stall, delay), the relay pty behind its link, quit and
 * SIGTERM (clean exit, link removed), and start-up errors.
 *
 * Every wait polls with a deadline; processes are signalled by pid only.
 */
#include <errno.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>
#include <arpa/inet.h>

#include <cmocka.h>

#include "proc.h"

#define START_MS 5000 /* ready line deadline */
#define REPLY_MS 2000 /* generous reply deadline */
#define QUIET_MS 300  /* "no reply" is judged over this */

struct fx {
	struct proc_sim sim;
	char dir[64];
	char link[128];
	int ctl; /* control connection */
	char resp[65536];
};

static const char *bin_dir(void)
{
	const char *b = getenv("ROBOELF_BIN");

	if (!b)
		fail_msg(
		    "ROBOELF_BIN is not set (run through tests/run-all.sh)");
	return b;
}

static int teardown(void **state);

/* On any failure here the fixture is undone at once: cmocka does not call
 * teardown after a failed setup. */
static int setup(void **state)
{
	const char *bin = getenv("ROBOELF_BIN");
	struct fx *f = calloc(1, sizeof(*f));

	if (!f)
		return -1;
	*state = f;
	f->ctl = -1;
	snprintf(f->dir, sizeof(f->dir), "/tmp/test_sim_net.XXXXXX");
	if (!mkdtemp(f->dir)) {
		free(f);
		return -1;
	}
	snprintf(f->link, sizeof(f->link), "%s/relay", f->dir);
	if (!bin) {
		fprintf(stderr, "ROBOELF_BIN is not set (run through "
				"tests/run-all.sh)\n");
	} else if (proc_sim_start(&f->sim, bin, f->link, NULL, START_MS) < 0) {
		fprintf(stderr, "galil-sim did not start\n");
	} else {
		f->ctl = proc_ctl_connect(f->sim.ctl_port, REPLY_MS);
		if (f->ctl >= 0)
			return 0;
	}
	teardown(state);
	return -1;
}

static int teardown(void **state)
{
	struct fx *f = *state;

	if (f->ctl >= 0)
		close(f->ctl);
	proc_kill(&f->sim.p);
	unlink(f->link);
	rmdir(f->dir);
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

static long state_long(struct fx *f, const char *key)
{
	char val[64];

	if (proc_ctl_state_get(ctl(f, "state"), key, val, sizeof(val)) < 0)
		fail_msg("no '%s' in the state line", key);
	return strtol(val, NULL, 10);
}

static int cmd_connect(struct fx *f)
{
	int fd = proc_ctl_connect(f->sim.port, REPLY_MS);

	assert_true(fd >= 0);
	return fd;
}

/* Read until ':' or '?' ends a reply; return bytes, -1 on timeout, 0 on
 * close. */
static int read_reply(int fd, char *buf, size_t cap, int timeout_ms)
{
	long long end = proc_now_ms() + timeout_ms;
	size_t n = 0;

	while (n + 1 < cap) {
		struct pollfd p = {fd, POLLIN, 0};
		long long left = end - proc_now_ms();
		ssize_t r;

		if (left <= 0 || poll(&p, 1, (int)left) <= 0)
			return -1;
		r = recv(fd, buf + n, cap - n - 1, 0);
		if (r <= 0)
			return 0;
		n += (size_t)r;
		buf[n] = '\0';
		if (buf[n - 1] == ':' || buf[n - 1] == '?')
			return (int)n;
	}
	return (int)n;
}

static void send_cmd(int fd, const char *cmd)
{
	assert_int_equal(send(fd, cmd, strlen(cmd), MSG_NOSIGNAL),
			 (ssize_t)strlen(cmd));
}

/* "MG 1" answered: the value then ':'. */
static void expect_mg1(int fd)
{
	char buf[128];

	send_cmd(fd, "MG 1\r");
	assert_true(read_reply(fd, buf, sizeof(buf), REPLY_MS) > 0);
	assert_non_null(strstr(buf, "1.0000"));
	assert_int_equal(buf[strlen(buf) - 1], ':');
}

/* The peer closes @fd within the deadline. */
static void expect_closed(int fd)
{
	char buf[64];
	struct pollfd p = {fd, POLLIN, 0};

	assert_int_equal(poll(&p, 1, REPLY_MS), 1);
	assert_int_equal(recv(fd, buf, sizeof(buf), 0), 0);
}

/* Poll the control port until @req answers @want (deadline). */
static void wait_answer(struct fx *f, const char *req, const char *want)
{
	long long end = proc_now_ms() + REPLY_MS;

	while (strcmp(ctl(f, req), want)) {
		if (proc_now_ms() > end)
			fail_msg("'%s' still '%s', want '%s'", req, f->resp,
				 want);
		poll(NULL, 0, 5);
	}
}

/* ---- start-up ----------------------------------------------------------- */

/* The ready line names the ports and the pty; the link points at it. */
static void test_ready_line_and_link(void **state)
{
	struct fx *f = *state;
	char line[512], want[512], target[256];
	ssize_t n;

	assert_int_equal(proc_find_line(&f->sim.p, PROC_STDOUT,
					"galil-sim:", line, sizeof(line)),
			 0);
	snprintf(want, sizeof(want),
		 "galil-sim: listening on 127.0.0.1:%d "
		 "control %d relay %s",
		 f->sim.port, f->sim.ctl_port, f->sim.relay);
	assert_string_equal(line, want);
	assert_memory_equal(f->sim.relay, "/dev/pts/", 9);
	n = readlink(f->link, target, sizeof(target) - 1);
	assert_true(n > 0);
	target[n] = '\0';
	assert_string_equal(target, f->sim.relay);
	/* exactly one line on stdout */
	assert_int_equal(strchr(proc_output(&f->sim.p, PROC_STDOUT), '\n') -
			     proc_output(&f->sim.p, PROC_STDOUT),
			 (long)strlen(line));
	assert_string_equal(ctl(f, "relay"), "off");
}

/* Simulated time follows the wall clock. */
static void test_real_time(void **state)
{
	struct fx *f = *state;
	long long w0 = proc_now_ms(), w1;
	long t0 = strtol(ctl(f, "time"), NULL, 10), t1;

	do {
		poll(NULL, 0, 20);
		w1 = proc_now_ms();
	} while (w1 - w0 < 500);
	t1 = strtol(ctl(f, "time"), NULL, 10);
	w1 = proc_now_ms() - w0;
	/* the loop catches up when late: simulated time never runs ahead,
	 * and lags by at most its 100-sample catch-up (the reaction times of
	 * docs/safety.md are measured in simulated ms) */
	assert_true(t1 - t0 <= w1 + 20);
	assert_true(t1 - t0 >= w1 - 100);
}

/* ---- command port and link faults -------------------------------------- */

static void test_command_port_and_delay(void **state)
{
	struct fx *f = *state;
	int fd = cmd_connect(f);
	long long t;
	char buf[128];

	expect_mg1(fd);
	assert_string_equal(ctl(f, "link delay 300"), "ok");
	t = proc_now_ms();
	expect_mg1(fd);
	assert_true(proc_now_ms() - t >= 290);
	ctl(f, "link ok");
	send_cmd(fd, "bogus\r");
	assert_true(read_reply(fd, buf, sizeof(buf), REPLY_MS) > 0);
	assert_string_equal(buf, "?");
	close(fd);
}

/* Stall: the socket stays open and nothing comes back; what is sent
 * meanwhile is lost. After "link ok" the link works again. */
static void test_link_stall(void **state)
{
	struct fx *f = *state;
	int fd = cmd_connect(f);
	char buf[128];

	expect_mg1(fd);
	ctl(f, "link stall");
	send_cmd(fd, "MG 1\r");
	assert_int_equal(read_reply(fd, buf, sizeof(buf), QUIET_MS), -1);
	ctl(f, "link ok");
	expect_mg1(fd);
	assert_int_equal(read_reply(fd, buf, sizeof(buf), QUIET_MS), -1);
	close(fd);
}

/* Drop: every command connection is closed and new ones are refused until
 * "link ok". */
static void test_link_drop(void **state)
{
	struct fx *f = *state;
	int a = cmd_connect(f), b = cmd_connect(f), c;

	expect_mg1(a);
	expect_mg1(b);
	ctl(f, "link drop");
	expect_closed(a);
	expect_closed(b);
	c = cmd_connect(f);
	expect_closed(c);
	close(c);
	ctl(f, "link ok");
	c = cmd_connect(f);
	expect_mg1(c);
	close(a);
	close(b);
	close(c);
}

/* Eight handles: a ninth connection is closed at once. */
static void test_eight_handles(void **state)
{
	struct fx *f = *state;
	int fd[9];

	for (int i = 0; i < 8; i++) {
		fd[i] = cmd_connect(f);
		expect_mg1(fd[i]);
	}
	fd[8] = cmd_connect(f);
	expect_closed(fd[8]);
	close(fd[0]);
	fd[0] = cmd_connect(f);
	expect_mg1(fd[0]);
	for (int i = 0; i < 9; i++)
		close(fd[i]);
}

/* A power cycle closes the command connections. */
static void test_power_cycle_closes(void **state)
{
	struct fx *f = *state;
	int fd = cmd_connect(f);

	expect_mg1(fd);
	ctl(f, "power-cycle");
	expect_closed(fd);
	close(fd);
	fd = cmd_connect(f);
	expect_mg1(fd);
	close(fd);
}

/* ---- IH closing and connection events ---------------------------------- */

/* The events since the last call, into f->resp, each line ending with a
 * newline (so that " text\n" matches a whole event text). */
static const char *events(struct fx *f)
{
	int n = proc_ctl_request_multi(f->ctl, "events", f->resp,
				       sizeof(f->resp) - 1, REPLY_MS);

	if (n < 0)
		fail_msg("no answer to 'events'");
	if (n > 0)
		strcat(f->resp, "\n");
	return f->resp;
}

/* " handle A opened from 127.0.0.1:<local port of fd>\n" is in @ev. */
static void expect_opened(const char *ev, char handle, int fd)
{
	struct sockaddr_in sa;
	socklen_t len = sizeof(sa);
	char want[64];

	assert_int_equal(getsockname(fd, (struct sockaddr *)&sa, &len), 0);
	snprintf(want, sizeof(want), " handle %c opened from 127.0.0.1:%d\n",
		 handle, ntohs(sa.sin_port));
	if (!strstr(ev, want))
		fail_msg("no '%s' in the events:\n%s", want, ev);
}

/* "cmd\r" on @fd answers exactly @want (the reply up to ':' or '?'). */
static void expect_reply(int fd, const char *cmd, const char *want)
{
	char buf[256], line[64];

	snprintf(line, sizeof(line), "%s\r", cmd);
	send_cmd(fd, line);
	assert_true(read_reply(fd, buf, sizeof(buf), REPLY_MS) > 0);
	assert_string_equal(buf, want);
}

/* IHT=>-3 from handle B closes handle A (EOF), B goes on; the handle is
 * free again (_IHA2 = 0) and the next connection takes it. */
static void test_iht_closes_others(void **state)
{
	struct fx *f = *state;
	int a = cmd_connect(f), b;
	const char *ev;

	expect_mg1(a); /* a is handle A */
	b = cmd_connect(f);
	expect_mg1(b); /* b is handle B */
	expect_reply(b, "WH", "IHB\r\n:");
	expect_reply(b, "MG _IHA2,_IHB2", " 2.0000 2.0000\r\n:");
	expect_reply(b, "IHT=>-3", ":");
	expect_closed(a);
	expect_mg1(b);
	expect_reply(b, "MG _IHA2,_IHB2", " 0.0000 2.0000\r\n:");
	ev = events(f);
	expect_opened(ev, 'A', a);
	expect_opened(ev, 'B', b);
	assert_non_null(strstr(ev, " handle A closed by IHT from handle B\n"));
	assert_null(strstr(ev, "handle B closed"));
	close(a);
	a = cmd_connect(f);
	expect_reply(a, "WH", "IHA\r\n:");
	expect_opened(events(f), 'A', a);
	close(a);
	close(b);
}

/* Wait until the events include " @text\n" (deadline). */
static void wait_event(struct fx *f, const char *text)
{
	long long end = proc_now_ms() + REPLY_MS;
	char want[128];

	snprintf(want, sizeof(want), " %s\n", text);
	while (!strstr(events(f), want)) {
		if (proc_now_ms() > end)
			fail_msg("no event '%s'", text);
		poll(NULL, 0, 5);
	}
}

/* IHS=>-2 closes the sender after its reply; IHA=>-2 closes handle A; a
 * client that leaves is "closed (peer)". */
static void test_ihs_and_iha(void **state)
{
	struct fx *f = *state;
	int a = cmd_connect(f), b, c;
	const char *ev;

	expect_mg1(a);
	b = cmd_connect(f);
	expect_mg1(b);
	expect_reply(b, "IHA=>-2", ":");
	expect_closed(a);
	expect_reply(b, "IHS=>-2", ":");
	expect_closed(b);
	c = cmd_connect(f);
	expect_reply(c, "WH", "IHA\r\n:");
	expect_reply(c, "MG _IHA2,_IHB2", " 2.0000 0.0000\r\n:");
	ev = events(f);
	assert_non_null(strstr(ev, " handle A closed by IHA from handle B\n"));
	assert_non_null(strstr(ev, " handle B closed by IHS from handle B\n"));
	close(c);
	wait_event(f, "handle A closed (peer)");
	close(a);
	close(b);
}

/* The close waits for the IH reply: with replies held back 300 ms, handle
 * A stays open until handle B has its ':'. */
static void test_ih_close_after_reply(void **state)
{
	struct fx *f = *state;
	int a = cmd_connect(f), b;
	struct pollfd p;
	char buf[16];

	expect_mg1(a);
	b = cmd_connect(f);
	expect_mg1(b);
	assert_string_equal(ctl(f, "link delay 300"), "ok");
	send_cmd(b, "IHT=>-3\r");
	p = (struct pollfd){a, POLLIN, 0};
	assert_int_equal(poll(&p, 1, 200), 0); /* still open, nothing sent */
	assert_true(read_reply(b, buf, sizeof(buf), REPLY_MS) > 0);
	assert_string_equal(buf, ":");
	expect_closed(a);
	close(a);
	close(b);
}

/* ---- the relay behind its link ----------------------------------------- */

static int open_relay(const char *path)
{
	struct termios tio;
	int fd = open(path, O_RDWR | O_NOCTTY | O_CLOEXEC);

	if (fd < 0)
		return -1;
	tcgetattr(fd, &tio);
	cfmakeraw(&tio);
	tcsetattr(fd, TCSANOW, &tio);
	return fd;
}

static void test_relay_over_pty(void **state)
{
	struct fx *f = *state;
	int fd = open_relay(f->link);
	struct pollfd p;
	uint8_t b = 0xAA;
	struct stat st;

	assert_true(fd >= 0);
	assert_int_equal(write(fd, "\x65", 1), 1);
	wait_answer(f, "relay", "on");
	assert_int_equal(state_long(f, "power"), 1);
	assert_int_equal(write(fd, "\x5b", 1), 1);
	p = (struct pollfd){fd, POLLIN, 0};
	assert_int_equal(poll(&p, 1, REPLY_MS), 1);
	assert_int_equal(read(fd, &b, 1), 1);
	assert_int_equal(b, 0x01);
	assert_int_equal(write(fd, "\x6f", 1), 1);
	wait_answer(f, "relay", "off");

	ctl(f, "relayfault unplug");
	errno = 0;
	assert_int_equal(write(fd, "\x65", 1), -1);
	assert_int_equal(errno, EIO);
	assert_int_equal(lstat(f->link, &st), -1);
	assert_int_equal(stat(f->sim.relay, &st), -1);
	close(fd);
	ctl(f, "relayfault ok");
	fd = open_relay(f->link);
	assert_true(fd >= 0);
	assert_int_equal(write(fd, "\x65", 1), 1);
	wait_answer(f, "relay", "on");
	close(fd);
	proc_ctl_request_multi(f->ctl, "events", f->resp, sizeof(f->resp),
			       REPLY_MS);
	assert_non_null(strstr(f->resp, " relay on (byte 0x65)\n"));
	assert_non_null(strstr(f->resp, " inject: relayfault unplug\n"));
	assert_non_null(strstr(f->resp, " relay plugged in at /dev/pts/"));
}

#define WEDGE_HOLD_MS 200 /* a wedge is judged over this */

/*
 * relayfault wedge: the board stops reading its pty. A host (raw termios,
 * O_NONBLOCK) writes "relay off": for WEDGE_HOLD_MS the relay still
 * answers on and the state says power=1; "relay off" from the control port
 * is refused; the host's writes end up refused (EAGAIN). relayfault ok:
 * the queue is discarded unread, the relay is off, the board obeys again.
 */
static void test_relay_wedge(void **state)
{
	struct fx *f = *state;
	int fd = open_relay(f->link);
	long long end;
	uint8_t chunk[256];
	long total = 1;
	ssize_t w;

	assert_true(fd >= 0);
	assert_int_equal(fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK),
			 0);
	assert_int_equal(write(fd, "\x65", 1), 1);
	wait_answer(f, "relay", "on");
	assert_string_equal(ctl(f, "relayfault wedge"), "ok");
	assert_int_equal(write(fd, "\x6f", 1), 1);
	end = proc_now_ms() + WEDGE_HOLD_MS;
	while (proc_now_ms() < end) {
		assert_string_equal(ctl(f, "relay"), "on");
		assert_int_equal(state_long(f, "power"), 1);
		poll(NULL, 0, 10);
	}
	assert_string_equal(ctl(f, "relay off"), "error: relay is wedged");
	memset(chunk, 0x65, sizeof(chunk));
	while ((w = write(fd, chunk, sizeof(chunk))) > 0 && total < (1L << 20))
		total += w;
	assert_int_equal(w, -1);
	assert_true(errno == EAGAIN || errno == EWOULDBLOCK);
	assert_string_equal(ctl(f, "relay"), "on");
	assert_string_equal(ctl(f, "relayfault ok"), "ok");
	assert_string_equal(ctl(f, "relay"), "off");
	wait_event(f, "relay obeys again (relays off)");
	/* all logged before "relayfault ok" answered: one answer has them */
	assert_non_null(strstr(f->resp, " relay wedged (bytes not read)\n"));
	assert_non_null(
	    strstr(f->resp, " relay off (board reset after wedge)\n"));
	assert_null(strstr(f->resp, "(byte 0x6f)"));
	assert_int_equal(write(fd, "\x65", 1), 1);
	wait_answer(f, "relay", "on");
	close(fd);
}

/* ---- motor power options ------------------------------------------------ */

/* --no-amp-undervoltage --power-output 2: the state line shows the output,
 * SB 2 / CB 2 over the command port switch motor power (events), and the
 * controller sees no under-voltage when power goes. */
static void test_power_options(void **state)
{
	static char *const extra[] = {(char *)"--no-amp-undervoltage",
				      (char *)"--power-output", (char *)"2",
				      NULL};
	struct fx *f = *state;
	int fd;

	proc_kill(&f->sim.p);
	close(f->ctl);
	f->ctl = -1;
	assert_int_equal(
	    proc_sim_start(&f->sim, bin_dir(), NULL, extra, START_MS), 0);
	f->ctl = proc_ctl_connect(f->sim.ctl_port, REPLY_MS);
	assert_true(f->ctl >= 0);
	fd = cmd_connect(f);
	assert_string_equal(ctl(f, "relay on"), "ok");
	assert_int_equal(state_long(f, "pout"), 0);
	assert_int_equal(state_long(f, "power"), 0);
	expect_reply(fd, "SB 2", ":");
	wait_event(f, "power output 2 set");
	assert_int_equal(state_long(f, "pout"), 1);
	assert_int_equal(state_long(f, "power"), 1);
	expect_reply(fd, "CB 2", ":");
	wait_event(f, "power output 2 cleared (motor power cut by the "
		      "controller)");
	assert_int_equal(state_long(f, "power"), 0);
	events(f); /* drop what came so far */
	expect_reply(fd, "SB 2", ":");
	wait_event(f, "power output 2 set");
	assert_string_equal(ctl(f, "relay off"), "ok");
	wait_event(f, "motor power lost (amplifiers report nothing: "
		      "under-voltage model off)");
	expect_reply(fd, "MG _TA0", " 0.0000\r\n:");
	close(fd);
}

/* ---- ending ------------------------------------------------------------- */

static void test_quit(void **state)
{
	struct fx *f = *state;
	int st;
	struct stat sb;

	assert_string_equal(ctl(f, "quit"), "ok");
	assert_int_equal(proc_wait_exit(&f->sim.p, REPLY_MS, &st), 0);
	assert_int_equal(proc_exit_code(&f->sim.p), 0);
	assert_int_equal(lstat(f->link, &sb), -1);
}

static void test_sigterm(void **state)
{
	struct fx *f = *state;
	int st;
	struct stat sb;

	assert_int_equal(lstat(f->link, &sb), 0);
	assert_int_equal(proc_signal(&f->sim.p, SIGTERM), 0);
	assert_int_equal(proc_wait_exit(&f->sim.p, REPLY_MS, &st), 0);
	assert_int_equal(proc_exit_code(&f->sim.p), 0);
	assert_int_equal(lstat(f->link, &sb), -1);
	assert_string_equal(proc_output(&f->sim.p, PROC_STDERR), "");
}

/* ---- start-up errors (no fixture) -------------------------------------- */

/* Run galil-sim with @args; its exit code (or -1) and stderr in @err. */
static int run_galil_sim(char *const *args, char *err, size_t cap)
{
	char bin[512], *argv[16];
	struct proc p;
	int n = 0, st, code = -1;

	snprintf(bin, sizeof(bin), "%s/galil-sim", bin_dir());
	argv[n++] = bin;
	for (int i = 0; args[i]; i++)
		argv[n++] = args[i];
	argv[n] = NULL;
	err[0] = '\0';
	if (proc_spawn(&p, argv, NULL) < 0)
		return -1;
	if (proc_wait_exit(&p, START_MS, &st) == 0 &&
	    proc_output(&p, PROC_STDOUT)[0] == '\0') {
		code = proc_exit_code(&p);
		snprintf(err, cap, "%s", proc_output(&p, PROC_STDERR));
	}
	proc_kill(&p);
	return code;
}

/* Run galil-sim with @args; expect exit @code and @err on stderr. */
static void run_expect(char *const *args, int code, const char *err)
{
	char got[1024];

	assert_int_equal(run_galil_sim(args, got, sizeof(got)), code);
	if (strcmp(got, err))
		fail_msg("stderr '%s', want '%s'", got, err);
}

static void test_bad_plant_file(void **state)
{
	char dir[] = "/tmp/test_sim_net.XXXXXX", path[96], want[256];
	char got[1024];
	FILE *fp;
	int code;

	(void)state;
	assert_non_null(mkdtemp(dir));
	snprintf(path, sizeof(path), "%s/plant.yaml", dir);
	fp = fopen(path, "w");
	assert_non_null(fp);
	fputs("axes:\n  A:\n    fwd_limit: 1\n    lag: 2\n", fp);
	fclose(fp);
	snprintf(want, sizeof(want), "%s:4:5: unknown key 'lag' in axes.A\n",
		 path);
	code = run_galil_sim((char *const[]){(char *)"--plant", path,
					     (char *)"--no-relay-link", NULL},
			     got, sizeof(got));
	unlink(path);
	rmdir(dir);
	assert_int_equal(code, 2);
	assert_string_equal(got, want);
}

static void test_usage_errors(void **state)
{
	(void)state;
	run_expect(
	    (char *const[]){(char *)"--relay-protocol", (char *)"numato", NULL},
	    2,
	    "galil-sim: unknown relay protocol 'numato' (devantech, "
	    "icstation, lcus, kmtronic)\n");
	run_expect((char *const[]){(char *)"--port", (char *)"70000", NULL}, 2,
		   "galil-sim: bad port '70000'\ntry 'galil-sim --help'\n");
	run_expect((char *const[]){(char *)"extra", NULL}, 2,
		   "galil-sim: unexpected argument 'extra'\n");
	run_expect(
	    (char *const[]){(char *)"--power-output", (char *)"9", NULL}, 2,
	    "galil-sim: bad power output '9' (0..8)\ntry 'galil-sim --help'\n");
	run_expect(
	    (char *const[]){(char *)"--miswire", (char *)"encoder-reversed:D",
			    NULL},
	    2,
	    "galil-sim: bad miswiring 'encoder-reversed:D' "
	    "(encoder-reversed:AXIS, limits-swapped:AXIS, relay-unwired, "
	    "pot-reversed:AXIS, joystick-swap:N,M, dead-input:N, "
	    "joystick-polarity; AXIS A..C, inputs 1..32)\n"
	    "try 'galil-sim --help'\n");
	run_expect((char *const[]){(char *)"--deviate", (char *)"mg", NULL}, 2,
		   "galil-sim: unknown deviation 'mg' (mg-join, dm-exists, "
		   "qr-header, ul-trim, mo-moving, za-16bit)\ntry 'galil-sim "
		   "--help'\n");
}

/* --miswire and --deviate reach the robot and the controller; TH shows
 * this connection's real peer (reference TH layout). */
static void test_miswire_deviate_options(void **state)
{
	static char *const extra[] = {(char *)"--miswire",
				      (char *)"relay-unwired",
				      (char *)"--miswire",
				      (char *)"joystick-swap:1,3",
				      (char *)"--deviate",
				      (char *)"mg-join",
				      NULL};
	struct fx *f = *state;
	struct sockaddr_in me;
	socklen_t len = sizeof(me);
	char buf[1024], want[96];
	int fd;

	proc_kill(&f->sim.p);
	close(f->ctl);
	f->ctl = -1;
	assert_int_equal(
	    proc_sim_start(&f->sim, bin_dir(), NULL, extra, START_MS), 0);
	f->ctl = proc_ctl_connect(f->sim.ctl_port, REPLY_MS);
	assert_true(f->ctl >= 0);
	fd = cmd_connect(f);
	assert_int_equal(state_long(f, "power"), 1); /* relay off */
	expect_reply(fd, "MG -1,-2", "-1.0000-2.0000\r\n:");
	expect_reply(fd, "MG _TA0", " 0.0000\r\n:");
	assert_string_equal(ctl(f, "joy A fwd a"), "ok");
	for (long long end = proc_now_ms() + REPLY_MS;; poll(NULL, 0, 5)) {
		send_cmd(fd, "MG @IN[1],@IN[3]\r");
		assert_true(read_reply(fd, buf, sizeof(buf), REPLY_MS) > 0);
		if (!strcmp(buf, " 0.0000 1.0000\r\n:"))
			break; /* switch A fwd a is wired to input 3 */
		if (proc_now_ms() > end)
			fail_msg("MG @IN[1],@IN[3] still '%s'", buf);
	}
	assert_int_equal(getsockname(fd, (struct sockaddr *)&me, &len), 0);
	send_cmd(fd, "TH\r");
	assert_true(read_reply(fd, buf, sizeof(buf), REPLY_MS) > 0);
	snprintf(want, sizeof(want),
		 "\r\nIHA TCP PORT %d TO IP ADDRESS 127,0,0,1 PORT %d\r\n",
		 f->sim.port, ntohs(me.sin_port));
	if (!strstr(buf, want))
		fail_msg("TH '%s' lacks '%s'", buf, want);
	close(fd);
}

/* A relay link path holding a regular file is refused: exit 1, the file
 * left alone. */
static void test_link_not_symlink(void **state)
{
	char dir[] = "/tmp/test_sim_net.XXXXXX", path[96], want[256];
	char got[1024];
	struct stat st;
	FILE *fp;
	int code, regular;

	(void)state;
	assert_non_null(mkdtemp(dir));
	snprintf(path, sizeof(path), "%s/relay", dir);
	fp = fopen(path, "w");
	assert_non_null(fp);
	fclose(fp);
	snprintf(want, sizeof(want),
		 "galil-sim: refusing to replace '%s': not a symbolic link\n",
		 path);
	code =
	    run_galil_sim((char *const[]){(char *)"--port", (char *)"0",
					  (char *)"--control-port", (char *)"0",
					  (char *)"--relay-link", path, NULL},
			  got, sizeof(got));
	regular = stat(path, &st) == 0 && S_ISREG(st.st_mode);
	unlink(path);
	rmdir(dir);
	assert_int_equal(code, 1);
	assert_string_equal(got, want);
	assert_true(regular);
}

/* A port in use: exit 1 with the reason. */
static void test_port_in_use(void **state)
{
	struct sockaddr_in sa = {.sin_family = AF_INET};
	socklen_t len = sizeof(sa);
	int fd = socket(AF_INET, SOCK_STREAM, 0);
	char port[16], want[128];

	(void)state;
	sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
	assert_int_equal(bind(fd, (struct sockaddr *)&sa, sizeof(sa)), 0);
	assert_int_equal(listen(fd, 1), 0);
	getsockname(fd, (struct sockaddr *)&sa, &len);
	snprintf(port, sizeof(port), "%d", ntohs(sa.sin_port));
	snprintf(want, sizeof(want),
		 "galil-sim: cannot listen on "
		 "127.0.0.1:%s: Address already in use\n",
		 port);
	run_expect((char *const[]){(char *)"--port", port,
				   (char *)"--control-port", (char *)"0",
				   (char *)"--no-relay-link", NULL},
		   1, want);
	close(fd);
}

#define T(name) cmocka_unit_test_setup_teardown(name, setup, teardown)

/* ---- line faults --------------------------------------------------------- */

/* Read exactly @n bytes (deadline REPLY_MS); return the count read. */
static size_t read_n(int fd, unsigned char *buf, size_t n)
{
	long long end = proc_now_ms() + REPLY_MS;
	size_t got = 0;

	while (got < n) {
		struct pollfd p = {fd, POLLIN, 0};
		long long left = end - proc_now_ms();
		ssize_t r;

		if (left <= 0 || poll(&p, 1, (int)left) <= 0)
			break;
		r = recv(fd, buf + got, n - got, 0);
		if (r <= 0)
			break;
		got += (size_t)r;
	}
	return got;
}

/* Nothing arrives on @fd for QUIET_MS. */
static void expect_quiet(int fd)
{
	struct pollfd p = {fd, POLLIN, 0};

	assert_int_equal(poll(&p, 1, QUIET_MS), 0);
}

/* "link once": the next line only; each fault as docs/galil-sim.md says. */
static void test_line_fault_replies(void **state)
{
	static const unsigned char garbage[] = "\x01\x02garbage\x00\x1f:";
	struct fx *f = *state;
	int fd = cmd_connect(f);
	unsigned char buf[256];
	long long t;

	assert_string_equal(ctl(f, "link once qmark"), "ok");
	send_cmd(fd, "MG 1;MG 2\r");
	assert_int_equal(read_n(fd, buf, 11), 11);
	assert_memory_equal(buf, "? 2.0000\r\n:", 11);
	expect_reply(fd, "TC1", " 1 Unrecognized command\r\n:");
	send_cmd(fd, "MG 1;MG 2\r");
	assert_int_equal(read_n(fd, buf, 20), 20);
	assert_memory_equal(buf, " 1.0000\r\n: 2.0000\r\n:", 20);
	assert_string_equal(ctl(f, "link once garbage"), "ok");
	send_cmd(fd, "MG 1\r");
	assert_int_equal(read_n(fd, buf, sizeof(garbage) - 1),
			 sizeof(garbage) - 1);
	assert_memory_equal(buf, garbage, sizeof(garbage) - 1);
	assert_string_equal(ctl(f, "link once unsol"), "ok");
	send_cmd(fd, "MG 12345\r");
	assert_int_equal(read_n(fd, buf, 14 + 16), 14 + 16);
	assert_memory_equal(buf, " 12345.", 7);
	assert_int_equal(buf[7], 'U' | 0x80);
	assert_int_equal(buf[7 + 15], '\n' | 0x80);
	assert_memory_equal(buf + 23, "0000\r\n:", 7);
	assert_string_equal(ctl(f, "link once extra"), "ok");
	send_cmd(fd, "MG 1\r");
	assert_int_equal(read_n(fd, buf, 11), 11);
	assert_memory_equal(buf, " 1.0000\r\n::", 11);
	assert_string_equal(ctl(f, "link once extra 200"), "ok");
	expect_reply(fd, "MG 1", " 1.0000\r\n:");
	t = proc_now_ms();
	assert_int_equal(read_n(fd, buf, 1), 1);
	assert_int_equal(buf[0], ':');
	assert_true(proc_now_ms() - t >= 150);
	assert_string_equal(ctl(f, "link once split"), "ok");
	t = proc_now_ms();
	expect_reply(fd, "MG 1", " 1.0000\r\n:");
	assert_true(proc_now_ms() - t >= 9); /* 10 bytes, 1 ms apart */
	assert_string_equal(ctl(f, "link once chunks"), "ok");
	expect_reply(fd, "MG 1", " 1.0000\r\n:");
	assert_string_equal(ctl(f, "link once delay 300"), "ok");
	t = proc_now_ms();
	expect_reply(fd, "MG 1", " 1.0000\r\n:");
	assert_true(proc_now_ms() - t >= 290);
	expect_reply(fd, "MG 2", " 2.0000\r\n:");
	assert_non_null(strstr(events(f), " handle A: line fault delay\n"));
	close(fd);
}

/* unsolpre goes before a final QR's record; badhdr changes its header. */
static void test_line_fault_records(void **state)
{
	struct fx *f = *state;
	int fd = cmd_connect(f);
	unsigned char buf[512];

	assert_string_equal(ctl(f, "link once unsolpre"), "ok");
	send_cmd(fd, "x=1;QR\r");
	assert_int_equal(read_n(fd, buf, 1 + 16 + 190 + 1), 1 + 16 + 190 + 1);
	assert_int_equal(buf[0], ':');
	assert_int_equal(buf[1], 'U' | 0x80);
	assert_int_equal(buf[17] & 0x80, 0x80); /* the record's header */
	assert_int_equal(buf[19], 190);
	assert_int_equal(buf[1 + 16 + 190], ':');
	assert_string_equal(ctl(f, "link once badhdr"), "ok");
	send_cmd(fd, "QR\r");
	assert_int_equal(read_n(fd, buf, 191), 191);
	assert_int_equal(buf[1], 0x0F);
	send_cmd(fd, "QR\r");
	assert_int_equal(read_n(fd, buf, 191), 191);
	assert_int_not_equal(buf[1], 0x0F);
	close(fd);
}

/* drop, silent; "link first" meets every new connection; "link ok" ends
 * it; bad requests. */
static void test_line_fault_connection(void **state)
{
	struct fx *f = *state;
	int fd, i;

	fd = cmd_connect(f);
	assert_string_equal(ctl(f, "link once drop"), "ok");
	send_cmd(fd, "MG 1\r");
	expect_closed(fd);
	close(fd);
	fd = cmd_connect(f);
	expect_mg1(fd);
	assert_string_equal(ctl(f, "link once silent"), "ok");
	send_cmd(fd, "MG 1\r");
	expect_quiet(fd);
	send_cmd(fd, "MG 1\r");
	expect_quiet(fd);
	close(fd);
	assert_string_equal(ctl(f, "link first qmark"), "ok");
	for (i = 0; i < 2; i++) {
		fd = cmd_connect(f);
		expect_reply(fd, "MG 1", "?");
		expect_mg1(fd);
		close(fd);
	}
	assert_string_equal(ctl(f, "link ok"), "ok");
	fd = cmd_connect(f);
	expect_mg1(fd);
	close(fd);
	assert_string_equal(ctl(f, "link once fly"),
			    "error: line fault 'fly': unknown");
	assert_string_equal(ctl(f, "link first delay"),
			    "error: line fault 'delay': needs an argument");
	assert_string_equal(ctl(f, "link once qmark 1"),
			    "error: line fault 'qmark': takes no argument");
	assert_string_equal(ctl(f, "link once dlreject 0"),
			    "error: line fault 'dlreject': bad line number "
			    "(1..4000)");
	assert_memory_equal(ctl(f, "link once"),
			    "error: usage: link <once|first> ", 32);
}

/* dlreject N: '?' as line N of the next download arrives, TC 60, the
 * download refused; the lines before are not. */
static void test_line_fault_dlreject(void **state)
{
	struct fx *f = *state;
	int fd = cmd_connect(f);
	unsigned char buf[64];

	assert_string_equal(ctl(f, "link once dlreject 3"), "ok");
	expect_mg1(fd);
	send_cmd(fd, "DL\r#A\rx=1\r");
	expect_quiet(fd);
	send_cmd(fd, "x=2\r");
	assert_int_equal(read_n(fd, buf, 1), 1);
	assert_int_equal(buf[0], '?');
	send_cmd(fd, "EN\r\\");
	assert_int_equal(read_n(fd, buf, 2), 2);
	assert_memory_equal(buf, ":?", 2);
	expect_reply(fd, "TC1",
		     " 60 Download error - line too long or too many "
		     "lines\r\n:");
	/* the next download is not touched */
	send_cmd(fd, "DL\r#A\rx=1\rx=2\rEN\r\\");
	assert_int_equal(read_n(fd, buf, 2), 2);
	assert_memory_equal(buf, "::", 2);
	close(fd);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    T(test_ready_line_and_link),
	    T(test_real_time),
	    T(test_command_port_and_delay),
	    T(test_link_stall),
	    T(test_link_drop),
	    T(test_eight_handles),
	    T(test_power_cycle_closes),
	    T(test_iht_closes_others),
	    T(test_ihs_and_iha),
	    T(test_ih_close_after_reply),
	    T(test_relay_over_pty),
	    T(test_relay_wedge),
	    T(test_power_options),
	    T(test_line_fault_replies),
	    T(test_line_fault_records),
	    T(test_line_fault_connection),
	    T(test_line_fault_dlreject),
	    T(test_quit),
	    T(test_sigterm),
	    cmocka_unit_test(test_bad_plant_file),
	    cmocka_unit_test(test_usage_errors),
	    cmocka_unit_test_setup_teardown(test_miswire_deviate_options, setup,
					    teardown),
	    cmocka_unit_test(test_link_not_symlink),
	    cmocka_unit_test(test_port_in_use),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
