/*
 * test_gload_cli.c - the galil-load binary as a child process, with no
 * controller or with a fake one made of a bare socket in this test: help
 * and usage errors (exit 2), the offline check (exit 1, exact messages on
 * stderr, nothing sent), the sizes printed, -o, a refused connection and a
 * controller that never answers (exit 3 after the timeout).
 *
 * Needs $ROBOELF_BIN/galil-load (tests/run-all.sh sets ROBOELF_BIN).
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
#include <sys/socket.h>
#include <unistd.h>

#include <cmocka.h>

#include "base_version.h"
#include "load_h.h"
#include "proc.h"

#define BAD		"tests/data/dmc_bad/"
#define GOOD		"tests/data/dmc_good/"
#define RUN_DEADLINE_MS 20000

static char bin[512];

static int setup(void **state)
{
	const char *dir = getenv("ROBOELF_BIN");

	(void)state;
	if (!dir || !*dir) {
		fprintf(stderr,
			"test_gload_cli: ROBOELF_BIN is not set "
			"(run through tests/run-all.sh or make check)\n");
		return -1;
	}
	snprintf(bin, sizeof(bin), "%s/galil-load", dir);
	if (access(bin, X_OK) != 0) {
		fprintf(stderr, "test_gload_cli: '%s' is missing\n", bin);
		return -1;
	}
	return 0;
}

/* Run galil-load with @args (NULL-terminated); return its exit code. */
static int run(struct proc *p, const char *const *args)
{
	int rc = load_h_run(p, bin, NULL, args, RUN_DEADLINE_MS);

	if (rc == -2)
		fail_msg("galil-load did not exit within %d ms",
			 RUN_DEADLINE_MS);
	assert_true(rc >= 0);
	return rc;
}

/* A listening socket on 127.0.0.1 that never answers; returns its port. */
static int silent_server(int *fd)
{
	struct sockaddr_in a = {.sin_family = AF_INET};
	socklen_t len = sizeof(a);

	*fd = socket(AF_INET, SOCK_STREAM, 0);
	assert_true(*fd >= 0);
	a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
	assert_int_equal(bind(*fd, (struct sockaddr *)&a, sizeof(a)), 0);
	assert_int_equal(listen(*fd, 4), 0);
	assert_int_equal(getsockname(*fd, (struct sockaddr *)&a, &len), 0);
	return ntohs(a.sin_port);
}

/* A port nobody listens on (bound, then closed). */
static int closed_port(void)
{
	int fd, port = silent_server(&fd);

	close(fd);
	return port;
}

static void test_help(void **state)
{
	static const char *const args[] = {"--help", NULL};
	static const char first[] = "usage: galil-load [-a HOST[:PORT]] "
				    "[options] FILE.dmc...|DIR\n";
	struct proc p;

	(void)state;
	assert_int_equal(run(&p, args), 0);
	assert_true(
	    strncmp(proc_output(&p, PROC_STDOUT), first, strlen(first)) == 0);
	assert_string_equal(proc_output(&p, PROC_STDERR), "");
	proc_kill(&p);
}

struct usage_case {
	const char *args[8];
	const char *first_line; /* of stderr */
};

static const struct usage_case usages[] = {
    /* no files: ./dmc of the source tree the tests run in (the default
     * DMC directory, tests/checks/install.sh tests the installed one) */
    {{NULL},
     "galil-load: no controller address (-a HOST); use --check to check "
     "offline\n"},
    {{"--check", "--dmc", "dmc", GOOD "clean.dmc", NULL},
     "galil-load: --dmc DIR and program files: give one or the other\n"},
    {{GOOD "clean.dmc", NULL},
     "galil-load: no controller address (-a HOST); use --check to check "
     "offline\n"},
    {{"--check", "-m", "9999", GOOD "clean.dmc", NULL},
     "galil-load: unknown model '9999' (40x0, 41x3, 21x3, 30010)\n"},
    {{"--check", "--start", GOOD "clean.dmc", NULL},
     "galil-load: --check does not talk to a controller; drop -c, --burn "
     "and --start\n"},
    {{"-a", "127.0.0.1", "-c", "TP", "--burn", NULL},
     "galil-load: --burn, --start and -o need program files (only a "
     "checked program is burned or started)\n"},
    {{"-a", "127.0.0.1", "-c", "DL", NULL},
     "galil-load: 'DL' cannot be sent with -c (give program files to "
     "download)\n"},
    {{"-a", "127.0.0.1", "--start=1AB", GOOD "clean.dmc", NULL},
     "galil-load: invalid label '1AB' for --start\n"},
    {{"-a", "127.0.0.1", "-t", "0", "-c", "TP", NULL},
     "galil-load: invalid timeout '0' (1..600000 ms)\n"},
    {{"--bogus", NULL}, "galil-load: invalid or incomplete option '--bogus'\n"},
    /* --verify never writes: nothing that would may come with it */
    {{"-a", "127.0.0.1", "--verify", "-f", GOOD "clean.dmc", NULL},
     "galil-load: --verify only reads the controller's program; drop "
     "--check, -f, --burn, --start, -c and --find\n"},
    {{"-a", "127.0.0.1", "--verify", "--burn", GOOD "clean.dmc", NULL},
     "galil-load: --verify only reads the controller's program; drop "
     "--check, -f, --burn, --start, -c and --find\n"},
    {{"-a", "127.0.0.1", "--verify", "--start", GOOD "clean.dmc", NULL},
     "galil-load: --verify only reads the controller's program; drop "
     "--check, -f, --burn, --start, -c and --find\n"},
    {{"-a", "127.0.0.1", "--verify", "-c", "MG 1", GOOD "clean.dmc", NULL},
     "galil-load: --verify only reads the controller's program; drop "
     "--check, -f, --burn, --start, -c and --find\n"},
    {{"--verify", "--check", GOOD "clean.dmc", NULL},
     "galil-load: --verify only reads the controller's program; drop "
     "--check, -f, --burn, --start, -c and --find\n"},
    {{"--verify", GOOD "clean.dmc", NULL},
     "galil-load: no controller address (-a HOST); use --check to check "
     "offline\n"},
};

/* Usage errors: exit 2, the reason first, then the usage text. */
static void test_usage_errors(void **state)
{
	size_t i, n;
	struct proc p;

	(void)state;
	for (i = 0; i < sizeof(usages) / sizeof(usages[0]); i++) {
		const char *err;

		assert_int_equal(run(&p, usages[i].args), 2);
		err = proc_output(&p, PROC_STDERR);
		n = strlen(usages[i].first_line);
		if (strncmp(err, usages[i].first_line, n) ||
		    strncmp(err + n, "usage: galil-load", 17))
			fail_msg("case %zu: stderr '%s'", i, err);
		proc_kill(&p);
	}
}

/* --start names a label the program lacks: refused before connecting. */
static void test_start_label_missing(void **state)
{
	const char *args[] = {"-a", "127.0.0.1:1", "--start=NOPE",
			      GOOD "clean.dmc", NULL};
	struct proc p;

	(void)state;
	assert_int_equal(run(&p, args), 2);
	assert_non_null(strstr(proc_output(&p, PROC_STDERR),
			       "galil-load: --start: the program has no label "
			       "'#NOPE'\n"));
	proc_kill(&p);
}

/* --check of a bad file: exit 1, exactly these lines on stderr. */
static void test_check_fails(void **state)
{
	static const char *const args[] = {"--check", BAD "label_undefined.dmc",
					   NULL};
	struct proc p;

	(void)state;
	assert_int_equal(run(&p, args), 1);
	assert_string_equal(proc_output(&p, PROC_STDERR), BAD
			    "label_undefined.dmc:7: label-undefined: undefined "
			    "label '#NOWHERE' in 'JP'\n" BAD
			    "label_undefined.dmc:8: label-undefined: undefined "
			    "label '#SUB' in 'JS'\n" BAD
			    "label_undefined.dmc:9: label-undefined: undefined "
			    "label '#THR' in 'XQ'\n"
			    "galil-load: check failed (3 problems); nothing "
			    "was sent to the controller\n");
	assert_string_equal(proc_output(&p, PROC_STDOUT), "");
	proc_kill(&p);
}

/* --check of a good file: sizes before and after, limits used. */
static void test_check_ok(void **state)
{
	static const char *const args[] = {"--check", GOOD "clean.dmc", NULL};
	struct proc p;

	(void)state;
	assert_int_equal(run(&p, args), 0);
	assert_string_equal(proc_output(&p, PROC_STDOUT),
			    "source: 1 file, 26 lines, 685 bytes\n"
			    "program: 19 lines, 186 bytes with the identity "
			    "line 'NO ID 32DC74A870EEBF04'\n"
			    "check: ok (DMC-40x0: 19/4000 lines, 3/510 labels, "
			    "3/510 variables)\n");
	assert_string_equal(proc_output(&p, PROC_STDERR), "");
	proc_kill(&p);
}

static char *slurp(const char *path, size_t *len)
{
	FILE *f = fopen(path, "rb");
	char *buf;

	if (!f)
		return NULL;
	buf = calloc(1, 65536);
	assert_non_null(buf);
	*len = fread(buf, 1, 65535, f);
	fclose(f);
	return buf;
}

/* -o writes the stamped program; a failed check writes nothing. */
static void test_output_file(void **state)
{
	char out[] = "/tmp/gload_outXXXXXX";
	const char *args[] = {"--check", "-o", out, GOOD "clean.dmc", NULL};
	const char *bad[] = {"--check", "-o", out, BAD "backslash.dmc", NULL};
	size_t len, elen;
	char *got, *want;
	struct proc p;
	int fd = mkstemp(out);

	(void)state;
	assert_true(fd >= 0);
	close(fd);
	unlink(out);
	assert_int_equal(run(&p, args), 0);
	proc_kill(&p);
	got = slurp(out, &len);
	want = slurp(GOOD "clean.expected", &elen);
	assert_non_null(got);
	assert_int_equal(len, elen + strlen("NO ID 32DC74A870EEBF04\n"));
	assert_memory_equal(got, want, elen);
	assert_string_equal(got + elen, "NO ID 32DC74A870EEBF04\n");
	free(got);
	free(want);
	unlink(out);
	assert_int_equal(run(&p, bad), 1);
	proc_kill(&p);
	assert_int_equal(access(out, F_OK), -1);
}

/* A failing check never connects: the server sees no connection. */
static void test_check_before_connect(void **state)
{
	char addr[32];
	const char *args[] = {"-a", addr, BAD "backslash.dmc", NULL};
	struct pollfd pfd;
	struct proc p;
	int fd, port = silent_server(&fd);

	(void)state;
	snprintf(addr, sizeof(addr), "127.0.0.1:%d", port);
	assert_int_equal(run(&p, args), 1);
	proc_kill(&p);
	pfd.fd = fd;
	pfd.events = POLLIN;
	assert_int_equal(poll(&pfd, 1, 0), 0); /* no pending connection */
	close(fd);
}

/* The project's own programs (dmc/, through dmc/MANIFEST) pass the check
 * for the DMC-4030. */
static void test_project_dmc(void **state)
{
	static const char *const args[] = {"--check", "dmc", NULL};
	struct proc p;

	(void)state;
	if (run(&p, args) != 0)
		fail_msg("galil-load --check dmc failed:\n%s",
			 proc_output(&p, PROC_STDERR));
	assert_string_equal(proc_output(&p, PROC_STDERR), "");
	assert_non_null(strstr(proc_output(&p, PROC_STDOUT), "check: ok "));
	proc_kill(&p);
}

/* The identity line galil-load printed for a check ("" when absent). */
static void identity_of(const char *out, char id[32])
{
	const char *at = strstr(out, "identity line 'NO ID ");

	id[0] = '\0';
	if (at)
		snprintf(id, 32, "%.22s", at + strlen("identity line '"));
}

/* No files: --check takes ./dmc (here the source tree's) and says so;
 * --version names the same programs and the identity --check dmc
 * stamps, with the release and the interface of base_version.h. */
static void test_default_dmc(void **state)
{
	static const char *const given[] = {"--check", "dmc", NULL};
	static const char *const none[] = {"--check", NULL};
	static const char *const version[] = {"--version", NULL};
	char want_id[32], id[32], want[256];
	struct proc p;

	(void)state;
	assert_int_equal(run(&p, given), 0);
	identity_of(proc_output(&p, PROC_STDOUT), want_id);
	assert_int_equal(strlen(want_id), 22); /* NO ID + 16 hex digits */
	proc_kill(&p);

	assert_int_equal(run(&p, none), 0);
	assert_string_equal(proc_output(&p, PROC_STDERR), "");
	assert_true(
	    strncmp(proc_output(&p, PROC_STDOUT),
		    "DMC programs: dmc (no files given)\nsealed: ", 43) == 0);
	assert_non_null(strstr(proc_output(&p, PROC_STDOUT),
			       " values from config/roboelf.yaml\nsource: 2 "
			       "files and the seal, "));
	identity_of(proc_output(&p, PROC_STDOUT), id);
	assert_string_equal(id, want_id);
	proc_kill(&p);

	assert_int_equal(run(&p, version), 0);
	snprintf(want, sizeof(want),
		 "galil-load " ROBOELF_VERSION " (controller program "
		 "interface " ROBOELF_DMC_VERSION ", dmc/constants.dmc "
		 "vers)\nDMC programs: dmc, identity '%s'\n",
		 want_id);
	assert_string_equal(proc_output(&p, PROC_STDOUT), want);
	assert_string_equal(proc_output(&p, PROC_STDERR), "");
	proc_kill(&p);
}

/* Nobody listening: exit 3 with the reason, and the (here empty) list of
 * controllers that answer the discovery probe, sent to loopback. */
static void test_connection_refused(void **state)
{
	char addr[32], port[16], want[512];
	const char *args[] = {"-a",	   addr,	  "--find-addr",
			      "127.0.0.1", "--find-port", port,
			      "-c",	   "MG 1",	  NULL};
	struct proc p;

	(void)state;
	snprintf(addr, sizeof(addr), "127.0.0.1:%d", closed_port());
	snprintf(port, sizeof(port), "%d", closed_port());
	snprintf(want, sizeof(want),
		 "galil-load: cannot connect to '%s': Connection refused\n"
		 "galil-load: Galil controllers that answer on this network:\n"
		 "galil-load: no Galil controller answered the discovery "
		 "probe (UDP 127.0.0.1:%s) within 1000 ms\n",
		 addr, port);
	assert_int_equal(run(&p, args), 3);
	assert_string_equal(proc_output(&p, PROC_STDERR), want);
	proc_kill(&p);
}

/* A controller that never answers: exit 3 after the command timeout. */
static void test_no_answer(void **state)
{
	char addr[32];
	const char *args[] = {"-a", addr, "-t", "300", "-c", "MG 1", NULL};
	struct proc p;
	long long t0;
	int fd, port = silent_server(&fd), code;

	(void)state;
	snprintf(addr, sizeof(addr), "127.0.0.1:%d", port);
	t0 = proc_now_ms();
	code = run(&p, args);
	assert_int_equal(code, 3);
	assert_true(proc_now_ms() - t0 >= 300 - 10);
	assert_true(proc_now_ms() - t0 < 5000);
	assert_string_equal(proc_output(&p, PROC_STDERR),
			    "galil-load: no reply to 'MG 1' within 300 ms\n");
	proc_kill(&p);
	close(fd);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_help),
	    cmocka_unit_test(test_usage_errors),
	    cmocka_unit_test(test_start_label_missing),
	    cmocka_unit_test(test_check_fails),
	    cmocka_unit_test(test_check_ok),
	    cmocka_unit_test(test_output_file),
	    cmocka_unit_test(test_check_before_connect),
	    cmocka_unit_test(test_default_dmc),
	    cmocka_unit_test(test_project_dmc),
	    cmocka_unit_test(test_connection_refused),
	    cmocka_unit_test(test_no_answer),
	};

	return cmocka_run_group_tests(tests, setup, NULL);
}
