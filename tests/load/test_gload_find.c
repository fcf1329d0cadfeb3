/*
 * test_gload_find.c - galil-load's controller discovery (child process)
 * against a listener of this test on 127.0.0.1 that answers the probe like
 * a controller ("DMC4030 Rev 1.2h" CR LF ':'): --find lists it exactly;
 * when -a does not answer, galil-load lists it on stderr and, stdin not
 * being a terminal, exits 3 without connecting anywhere else. And against
 * galil-sim --disc-port 0, the simulator a technician practises on: --find
 * lists it with the model text it answers to ^R^V.
 *
 * Needs $ROBOELF_BIN/galil-load and $ROBOELF_BIN/galil-sim.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <pthread.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cmocka.h>

#include "load_h.h"
#include "proc.h"

#define RUN_DEADLINE_MS 10000
#define LISTEN_MS	8000 /* the listener gives up after this */

#define SIM_START_MS 5000 /* galil-sim's ready line */

static char load_bin[512];

struct lsn {
	int fd, port;
	pthread_t th;
	int probes; /* probes answered */
};

static struct lsn lsn;

/* Answer every probe (^R^V CR) until LISTEN_MS passes without one. */
static void *lsn_main(void *arg)
{
	static const char reply[] = "DMC4030 Rev 1.2h\r\n:";
	struct lsn *s = arg;
	struct pollfd pfd = {.fd = s->fd, .events = POLLIN};
	struct sockaddr_in from;
	socklen_t flen;
	char b[64];
	ssize_t n;

	while (poll(&pfd, 1, LISTEN_MS) == 1) {
		flen = sizeof(from);
		n = recvfrom(s->fd, b, sizeof(b), 0, (struct sockaddr *)&from,
			     &flen);
		if (n <= 0)
			break; /* shut down by lsn_stop() */
		if (n == 3 && !memcmp(b, "\x12\x16\r", 3)) {
			s->probes++;
			sendto(s->fd, reply, strlen(reply), 0,
			       (struct sockaddr *)&from, flen);
		}
	}
	return NULL;
}

static int lsn_start(void **state)
{
	struct sockaddr_in a = {.sin_family = AF_INET};
	socklen_t len = sizeof(a);

	(void)state;
	memset(&lsn, 0, sizeof(lsn));
	lsn.fd = socket(AF_INET, SOCK_DGRAM, 0);
	a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
	if (lsn.fd < 0 || bind(lsn.fd, (struct sockaddr *)&a, sizeof(a)) ||
	    getsockname(lsn.fd, (struct sockaddr *)&a, &len))
		return -1;
	lsn.port = ntohs(a.sin_port);
	return pthread_create(&lsn.th, NULL, lsn_main, &lsn);
}

static int lsn_stop(void **state)
{
	(void)state;
	shutdown(lsn.fd, SHUT_RDWR); /* wakes the poll (Linux) */
	pthread_join(lsn.th, NULL);
	close(lsn.fd);
	return 0;
}

static int setup_group(void **state)
{
	const char *bin_dir = getenv("ROBOELF_BIN");

	(void)state;
	if (!bin_dir || !*bin_dir) {
		fprintf(stderr, "test_gload_find: ROBOELF_BIN is not set\n");
		return -1;
	}
	snprintf(load_bin, sizeof(load_bin), "%s/galil-load", bin_dir);
	return access(load_bin, X_OK);
}

static int run(struct proc *p, const char *addr, const char *const *args)
{
	int rc = load_h_run(p, load_bin, addr, args, RUN_DEADLINE_MS);

	if (rc == -2)
		fail_msg("galil-load did not exit within %d ms",
			 RUN_DEADLINE_MS);
	assert_true(rc >= 0);
	return rc;
}

/* --find lists the one controller, exactly. */
static void test_find(void **state)
{
	char port[16];
	const char *args[] = {"--find",	     "--find-addr", "127.0.0.1",
			      "--find-port", port,	    "-t",
			      "300",	     NULL};
	struct proc p;

	(void)state;
	snprintf(port, sizeof(port), "%d", lsn.port);
	assert_int_equal(run(&p, NULL, args), 0);
	assert_string_equal(proc_output(&p, PROC_STDOUT),
			    "  1  127.0.0.1        DMC4030 Rev 1.2h\n");
	assert_string_equal(proc_output(&p, PROC_STDERR), "");
	assert_int_equal(lsn.probes, 1);
	proc_kill(&p);
}

/* galil-sim answers the probe: listed with its ^R^V text, exactly. */
static void test_find_sim(void **state)
{
	char *const extra[] = {(char *)"--disc-port", (char *)"0", NULL};
	char port[16], line[512];
	const char *args[] = {"--find",	     "--find-addr", "127.0.0.1",
			      "--find-port", port,	    "-t",
			      "500",	     NULL};
	struct proc_sim sim;
	struct proc p;
	const char *d;
	int disc = 0;

	(void)state;
	assert_int_equal(proc_sim_start(&sim, getenv("ROBOELF_BIN"), NULL,
					extra, SIM_START_MS),
			 0);
	assert_int_equal(proc_find_line(&sim.p, PROC_STDOUT,
					"galil-sim: listening on ", line,
					sizeof(line)),
			 0);
	d = strstr(line, " disc ");
	assert_non_null(d);
	assert_int_equal(sscanf(d, " disc %d", &disc), 1);
	snprintf(port, sizeof(port), "%d", disc);
	assert_int_equal(run(&p, NULL, args), 0);
	assert_string_equal(proc_output(&p, PROC_STDOUT),
			    "  1  127.0.0.1        DMC4030 Rev 1.2h-sim\n");
	assert_string_equal(proc_output(&p, PROC_STDERR), "");
	proc_kill(&p);
	proc_kill(&sim.p);
}

/* Nothing answers at another port: exit 3 and says so. */
static void test_find_none(void **state)
{
	char port[16];
	const char *args[] = {"--find",	     "--find-addr", "127.0.0.1",
			      "--find-port", port,	    "-t",
			      "200",	     NULL};
	struct proc p;

	(void)state;
	snprintf(port, sizeof(port), "%d",
		 lsn.port == 65535 ? 1 : lsn.port + 1);
	assert_int_equal(run(&p, NULL, args), 3);
	assert_string_equal(proc_output(&p, PROC_STDOUT), "");
	assert_true(strstr(proc_output(&p, PROC_STDERR),
			   "galil-load: no Galil controller answered the "
			   "discovery probe (UDP 127.0.0.1:") != NULL);
	proc_kill(&p);
}

/* -a refuses the connection: the list on stderr, exit 3, stdin is no
 * terminal so nothing is chosen and nothing else is connected to. */
static void test_unreachable_lists(void **state)
{
	struct sockaddr_in a = {.sin_family = AF_INET};
	socklen_t len = sizeof(a);
	char port[16], addr[32], want[256];
	const char *args[] = {"--find-addr", "127.0.0.1", "--find-port", port,
			      "-c",	     "MG 1",	  NULL};
	struct proc p;
	int fd = socket(AF_INET, SOCK_STREAM, 0); /* bound, not listening */

	(void)state;
	a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
	assert_true(fd >= 0);
	assert_int_equal(bind(fd, (struct sockaddr *)&a, sizeof(a)), 0);
	assert_int_equal(getsockname(fd, (struct sockaddr *)&a, &len), 0);
	snprintf(addr, sizeof(addr), "127.0.0.1:%d", ntohs(a.sin_port));
	snprintf(port, sizeof(port), "%d", lsn.port);
	assert_int_equal(run(&p, addr, args), 3);
	close(fd);
	snprintf(want, sizeof(want),
		 "galil-load: cannot connect to '%s': Connection refused\n"
		 "galil-load: Galil controllers that answer on this network:\n"
		 "  1  127.0.0.1        DMC4030 Rev 1.2h\n",
		 addr);
	assert_string_equal(proc_output(&p, PROC_STDERR), want);
	assert_string_equal(proc_output(&p, PROC_STDOUT), "");
	proc_kill(&p);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test_setup_teardown(test_find, lsn_start, lsn_stop),
	    cmocka_unit_test(test_find_sim),
	    cmocka_unit_test_setup_teardown(test_find_none, lsn_start,
					    lsn_stop),
	    cmocka_unit_test_setup_teardown(test_unreachable_lists, lsn_start,
					    lsn_stop),
	};

	return cmocka_run_group_tests(tests, setup_group, NULL);
}
