/*
 * test_gload_dl.c - galil-load's download sequence, run as a child process
 * against a scripted controller in this test (a thread on 127.0.0.1), whose
 * faults are exact: reject DL line n, close the connection when DL line n
 * arrives, change one byte of the read-back, keep a thread running after
 * HX, refuse BP, fail to start a thread. The fake logs every command it
 * receives, so each test asserts the exact protocol sequence and the
 * program left on the controller (empty after every failure).
 *
 * Why not galil-stub: the stub does not answer "MG _XQn" (galil-load's
 * proof that HX halted every thread) and has no read-back or mid-download
 * faults; test_gload_stub.c uses it for what it offers.
 *
 * How the fake differs from a DMC-4030: one connection at a time; it knows
 * only ^R^V, MG _BN, QZ, MG _XQn, MG _BGx, MG _MOx, HXn, ST, AB 1, MO (refused
 * with TC 7 while an axis moves), DL, UL, BP, XQ #L,0, TC1, "x=n"/"MG x"
 * for one variable, any other "name=n" (accepted, forgotten), and MG state
 * / MG hbpc when a supervisor is simulated (hbpc advancing); a rejected DL
 * line gets '?' at once, the download then ends with one ':' (two
 * terminators), and the lines before the bad one stay stored (the worst
 * case: a partial program).
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

#define GOOD		"tests/data/dmc_good/"
#define RUN_DEADLINE_MS 30000
#define PROG_CAP	(64 * 1024)
#define LOG_CAP		(64 * 1024)
#define CLEAN_ID	"32DC74A870EEBF04"

struct fake {
	int lfd, port;
	pthread_t th;
	pthread_mutex_t mu;
	volatile int stop;
	/* faults, set before galil-load runs */
	int reject_dl_line; /* '?' (TC 60) to this DL line */
	int drop_dl_line;   /* close the connection when it arrives */
	int corrupt_ul;	    /* the first UL after a DL differs */
	int stuck_thread;   /* this thread ignores HX (-1: none) */
	int reject_bp;
	int xq_no_run;	  /* XQ answers ':' but the thread stays off */
	int supervised;	  /* the RoboELF program runs armed, hbpc advancing */
	int moving_polls; /* after ST, MG _BGA answers 1 this many times */
	int jogging;	  /* axis A moves until ST */
	int st_ignored;	  /* ST does not stop axis A (AB 1 does) */
	/* state */
	char prog[PROG_CAP]; /* lines, each ending in '\n' */
	size_t prog_len;
	char burned[PROG_CAP];
	int running[8];
	int tc;
	const char *tc_text;
	double var_x;
	int motors_on, hbpc;
	int connections;
	int downloads;
	char log[LOG_CAP]; /* one command per line; DL lines as "> ..." */
	size_t log_len;
	/* connection */
	int dl, dl_line, dl_bad;
	char cur[256];
	size_t cur_len;
	char dl_buf[PROG_CAP];
	size_t dl_len;
};

static struct fake fk;
static char bin[512];

/* Append "@prefix@s\n" to the protocol log. */
static void fk_log(const char *prefix, const char *s)
{
	int n = snprintf(fk.log + fk.log_len, LOG_CAP - fk.log_len, "%s%s\n",
			 prefix, s);

	if (n > 0 && fk.log_len + (size_t)n < LOG_CAP)
		fk.log_len += (size_t)n;
}

static void fk_send(int fd, const char *s)
{
	send(fd, s, strlen(s), MSG_NOSIGNAL);
}

static void fk_reject(int fd, int tc, const char *text)
{
	fk.tc = tc;
	fk.tc_text = text;
	fk_send(fd, "?");
}

static void fk_number(int fd, double v)
{
	char s[64];

	snprintf(s, sizeof(s), "% .4f\r\n:", v);
	fk_send(fd, s);
}

static void fk_upload(int fd)
{
	size_t i;
	char c[2] = "";

	for (i = 0; i < fk.prog_len; i++) {
		c[0] = fk.prog[i];
		if (c[0] == '\n')
			fk_send(fd, "\r\n");
		else if (fk.corrupt_ul && i == 0)
			fk_send(fd, "#"); /* the first byte changed */
		else
			fk_send(fd, c);
	}
	if (fk.prog_len > 0)
		fk.corrupt_ul = 0;
	fk_send(fd, "\x1a:");
}

static int fk_has_label(const char *label)
{
	char want[32];
	const char *p;
	size_t n = (size_t)snprintf(want, sizeof(want), "%s\n", label);

	for (p = fk.prog; p && *p; p = strchr(p, '\n'), p = p ? p + 1 : p)
		if (!strncmp(p, want, n))
			return 1;
	return 0;
}

static void fk_xq(int fd, const char *cmd)
{
	char label[32];

	if (sscanf(cmd, "XQ %31[^,],0", label) != 1 || !fk_has_label(label)) {
		fk_reject(fd, 11, "Invalid label or line number");
		return;
	}
	if (!fk.xq_no_run)
		fk.running[0] = 1;
	fk_send(fd, ":");
}

static void fk_halt(int fd, int n)
{
	if (n >= 0 && n < 8 && n != fk.stuck_thread)
		fk.running[n] = 0;
	fk_send(fd, ":");
}

/* One command line (no DL in progress). */
static void fk_command(int fd, const char *cmd)
{
	char c;
	int n;

	fk_log("", cmd[0] == 0x12 ? "^R^V" : cmd);
	if (!strcmp(cmd, "\x12\x16"))
		fk_send(fd, "DMC4030 Rev 1.2h-fake\r\n:");
	else if (!strcmp(cmd, "MG _BN"))
		fk_number(fd, 4242);
	else if (sscanf(cmd, "MG _XQ%d", &n) == 1 && n >= 0 && n < 8)
		fk_number(fd, fk.running[n] ? 5 : -1);
	else if (sscanf(cmd, "HX%d", &n) == 1)
		fk_halt(fd, n);
	else if (!strcmp(cmd, "QZ"))
		fk_send(fd, " 3, 52, 26, 36\r\n:");
	else if (!strcmp(cmd, "ST"))
		fk.jogging = fk.jogging && fk.st_ignored, fk_send(fd, ":");
	else if (!strcmp(cmd, "AB 1"))
		fk.jogging = 0, fk_send(fd, ":");
	else if (sscanf(cmd, "MG _BG%c", &c) == 1 && c >= 'A' && c <= 'C')
		fk_number(fd,
			  c == 'A' && (fk.jogging || fk.moving_polls-- > 0));
	else if (!strcmp(cmd, "MO") && (fk.jogging || fk.moving_polls > 0))
		fk_reject(fd, 7, "Command not valid while running");
	else if (!strcmp(cmd, "MO"))
		fk.motors_on = 0, fk_send(fd, ":");
	else if (sscanf(cmd, "MG _MO%c", &c) == 1 && c >= 'A' && c <= 'C')
		fk_number(fd, !fk.motors_on);
	else if (!strcmp(cmd, "MG state") && fk.supervised)
		fk_number(fd, 1);
	else if (!strcmp(cmd, "MG hbpc") && fk.supervised)
		fk_number(fd, fk.hbpc += 3);
	else if (!strcmp(cmd, "UL"))
		fk_upload(fd);
	else if (!strcmp(cmd, "DL"))
		fk.dl = 1, fk.dl_line = 0, fk.dl_bad = 0, fk.dl_len = 0;
	else if (!strcmp(cmd, "BP") && fk.reject_bp)
		fk_reject(fd, 15, "EEPROM write error");
	else if (!strcmp(cmd, "BP"))
		memcpy(fk.burned, fk.prog, PROG_CAP), fk_send(fd, ":");
	else if (!strncmp(cmd, "XQ ", 3))
		fk_xq(fd, cmd);
	else if (!strcmp(cmd, "TC1")) {
		char s[128];

		snprintf(s, sizeof(s), "%d %s\r\n:", fk.tc, fk.tc_text);
		fk_send(fd, s);
	} else if (sscanf(cmd, "x=%d", &n) == 1)
		fk.var_x = n, fk_send(fd, ":");
	else if (!strcmp(cmd, "MG x"))
		fk_number(fd, fk.var_x);
	else if (strchr(cmd, '=') && cmd[0] >= 'a' && cmd[0] <= 'z')
		fk_send(fd, ":"); /* a variable: made, and forgotten */
	else
		fk_reject(fd, 1, "Unrecognized command");
}

/* A DL line arrived; return -1 to drop the connection. */
static int fk_dl_line(int fd, const char *line)
{
	size_t n = strlen(line);

	fk.dl_line++;
	fk_log("> ", line);
	if (fk.dl_line == fk.drop_dl_line)
		return -1;
	if (fk.dl_bad)
		return 0;
	if (fk.dl_line == fk.reject_dl_line) {
		fk.dl_bad = 1;
		fk_reject(fd, 60,
			  "Download error - line too long or too many "
			  "lines");
		return 0;
	}
	memcpy(fk.prog + fk.prog_len, line, n); /* partial, on purpose */
	fk.prog_len += n;
	fk.prog[fk.prog_len++] = '\n';
	fk.prog[fk.prog_len] = '\0';
	return 0;
}

/* A byte of a connection; return -1 to drop it. */
static int fk_byte(int fd, char c)
{
	if (fk.dl && c == '\\') {
		fk_log("> ", "\\");
		fk.dl = 0;
		fk.downloads++;
		fk_send(fd, fk.dl_bad ? ":" : "::");
		return 0;
	}
	if (c == '\n')
		return 0;
	if (c != '\r') {
		if (fk.cur_len < sizeof(fk.cur) - 1)
			fk.cur[fk.cur_len++] = c;
		return 0;
	}
	fk.cur[fk.cur_len] = '\0';
	fk.cur_len = 0;
	if (fk.dl)
		return fk_dl_line(fd, fk.cur);
	fk_command(fd, fk.cur);
	if (fk.dl) { /* a new download replaces the program */
		fk.prog_len = 0;
		fk.prog[0] = '\0';
	}
	return 0;
}

static void fk_serve(int fd)
{
	char buf[4096];
	ssize_t n, i;

	fk.dl = 0;
	fk.cur_len = 0;
	while ((n = recv(fd, buf, sizeof(buf), 0)) > 0) {
		pthread_mutex_lock(&fk.mu);
		for (i = 0; i < n; i++)
			if (fk_byte(fd, buf[i]) < 0)
				break;
		pthread_mutex_unlock(&fk.mu);
		if (i < n)
			break;
	}
	close(fd);
}

static void *fk_main(void *arg)
{
	struct pollfd p = {.fd = fk.lfd, .events = POLLIN};
	int fd;

	(void)arg;
	while (!fk.stop) {
		if (poll(&p, 1, 20) <= 0)
			continue;
		fd = accept(fk.lfd, NULL, NULL);
		if (fd < 0)
			continue;
		pthread_mutex_lock(&fk.mu);
		fk.connections++;
		pthread_mutex_unlock(&fk.mu);
		fk_serve(fd);
	}
	return NULL;
}

static int fk_start(void **state)
{
	struct sockaddr_in a = {.sin_family = AF_INET};
	socklen_t len = sizeof(a);

	(void)state;
	memset(&fk, 0, sizeof(fk));
	fk.stuck_thread = -1;
	pthread_mutex_init(&fk.mu, NULL);
	fk.lfd = socket(AF_INET, SOCK_STREAM, 0);
	a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
	if (fk.lfd < 0 || bind(fk.lfd, (struct sockaddr *)&a, sizeof(a)) ||
	    listen(fk.lfd, 4) ||
	    getsockname(fk.lfd, (struct sockaddr *)&a, &len))
		return -1;
	fk.port = ntohs(a.sin_port);
	return pthread_create(&fk.th, NULL, fk_main, NULL) ? -1 : 0;
}

static int fk_stop(void **state)
{
	(void)state;
	fk.stop = 1;
	pthread_join(fk.th, NULL);
	close(fk.lfd);
	pthread_mutex_destroy(&fk.mu);
	return 0;
}

static int setup_group(void **state)
{
	const char *dir = getenv("ROBOELF_BIN");

	(void)state;
	if (!dir || !*dir) {
		fprintf(stderr, "test_gload_dl: ROBOELF_BIN is not set (run "
				"through tests/run-all.sh or make check)\n");
		return -1;
	}
	snprintf(bin, sizeof(bin), "%s/galil-load", dir);
	if (access(bin, X_OK) != 0) {
		fprintf(stderr, "test_gload_dl: '%s' is missing\n", bin);
		return -1;
	}
	return 0;
}

/* Run galil-load -a <fake> @args...; return the exit code. */
static int run(struct proc *p, const char *const *args)
{
	char addr[32];

	snprintf(addr, sizeof(addr), "127.0.0.1:%d", fk.port);
	int rc = load_h_run(p, bin, addr, args, RUN_DEADLINE_MS);

	if (rc == -2)
		fail_msg("galil-load did not exit within %d ms",
			 RUN_DEADLINE_MS);
	assert_true(rc >= 0);
	return rc;
}

static char *clean_program(void)
{
	FILE *f = fopen(GOOD "clean.expected", "rb");
	char *buf = calloc(1, PROG_CAP);
	size_t n;

	assert_non_null(f);
	assert_non_null(buf);
	n = fread(buf, 1, PROG_CAP - 64, f);
	fclose(f);
	strcpy(buf + n, "NO ID " CLEAN_ID "\n");
	return buf;
}

/* "> line" for every line of @prog, then "> \". */
static void dl_lines(char *out, size_t cap, const char *prog)
{
	const char *p, *e;
	size_t o = 0;

	for (p = prog; *p; p = e + 1) {
		e = strchr(p, '\n');
		o += (size_t)snprintf(out + o, cap - o, "> %.*s\n",
				      (int)(e - p), p);
	}
	snprintf(out + o, cap - o, "> \\\n");
}

/* The halt: prun=0, every thread, ST, every axis stopped, MO, every motor
 * read back off, no thread running (the axes from QZ). */
#define HALT_CMDS                                                              \
	"QZ\nprun=0\nHX0\nHX1\nHX2\nHX3\nHX4\nHX5\nHX6\nHX7\nST\n"             \
	"MG _BGA\nMG _BGB\nMG _BGC\nMO\nMG _MOA\nMG _MOB\nMG _MOC\n"           \
	"MG _XQ0\nMG _XQ1\nMG _XQ2\nMG _XQ3\nMG _XQ4\nMG _XQ5\nMG _XQ6\n"      \
	"MG _XQ7\n"

/* Identify; the busy check before anything else (no program running:
 * one question; a program but no RoboELF state: refused, TC1 read); then
 * the controller's program read (UL) before anything is halted: a program
 * it already holds is left running. */
#define IDENT	       "^R^V\nMG _BN\n"
#define BUSY_IDLE      "MG _XQ0\n"
#define BUSY_NOSTATE   "MG _XQ0\nMG state\nTC1\n"
#define IDENT_UL       IDENT BUSY_IDLE "UL\n"
#define IDENT_RUN_UL   IDENT BUSY_NOSTATE "UL\n"

/* Identify, the busy check, UL, the halt. */
static const char halt_log[] = IDENT_UL HALT_CMDS;

static void assert_log(const char *want)
{
	pthread_mutex_lock(&fk.mu);
	if (strcmp(fk.log, want))
		fail_msg("protocol log:\n%s\nwant:\n%s", fk.log, want);
	pthread_mutex_unlock(&fk.mu);
}

static int has(const struct proc *p, enum proc_stream s, const char *text)
{
	return strstr(proc_output(p, s), text) != NULL;
}

/* A clean program: upload, halt, download, read back; exact sequence. */
static void test_load_clean(void **state)
{
	static const char *const args[] = {GOOD "clean.dmc", NULL};
	char *prog = clean_program(), want[LOG_CAP];
	struct proc p;
	int n;

	(void)state;
	assert_int_equal(run(&p, args), 0);
	n = snprintf(want, sizeof(want), "%sDL\n", halt_log);
	dl_lines(want + n, sizeof(want) - (size_t)n, prog);
	strcat(want, "UL\n");
	assert_log(want);
	assert_string_equal(fk.prog, prog);
	assert_true(has(&p, PROC_STDOUT,
			"controller: DMC4030 Rev 1.2h-fake, "
			"serial 4242\n"));
	assert_true(has(&p, PROC_STDOUT,
			"verified: the read-back matches, "
			"identity " CLEAN_ID "\n"));
	assert_string_equal(proc_output(&p, PROC_STDERR), "");
	assert_int_equal(fk.running[0], 0); /* not started by default */
	proc_kill(&p);
	free(prog);
}

/* The same program again: read, nothing halted or written (the running
 * thread keeps running); --force halts and downloads anyway. */
static void test_unchanged(void **state)
{
	static const char *const args[] = {GOOD "clean.dmc", NULL};
	static const char *const force[] = {"-f", GOOD "clean.dmc", NULL};
	char *prog = clean_program();
	struct proc p;

	(void)state;
	strcpy(fk.prog, prog);
	fk.prog_len = strlen(prog);
	fk.running[0] = 1;
	fk.motors_on = 1;
	assert_int_equal(run(&p, args), 0);
	assert_log(IDENT_RUN_UL);
	assert_true(has(&p, PROC_STDOUT,
			"unchanged: the controller already "
			"holds this program (identity " CLEAN_ID "); not "
			"downloaded\n"
			"left running: nothing halted, nothing written\n"));
	assert_string_equal(proc_output(&p, PROC_STDERR), "");
	assert_int_equal(fk.downloads, 0);
	assert_int_equal(fk.running[0], 1);
	assert_int_equal(fk.motors_on, 1);
	proc_kill(&p);
	assert_int_equal(run(&p, force), 0);
	assert_int_equal(fk.downloads, 1);
	assert_int_equal(fk.running[0], 0);
	assert_string_equal(fk.prog, prog);
	proc_kill(&p);
	free(prog);
}

/* --verify, the same program: UL only (the protocol log holds nothing
 * else), exit 0, the running thread and the motors untouched. */
static void test_verify_equal(void **state)
{
	static const char *const args[] = {"--verify", GOOD "clean.dmc", NULL};
	char *prog = clean_program();
	struct proc p;

	(void)state;
	strcpy(fk.prog, prog);
	fk.prog_len = strlen(prog);
	fk.running[0] = 1;
	fk.motors_on = 1;
	assert_int_equal(run(&p, args), 0);
	assert_log(IDENT_RUN_UL);
	assert_true(has(&p, PROC_STDOUT,
			"controller: DMC4030 Rev 1.2h-fake, serial 4242\n"
			"verified: the controller holds this program, "
			"identity " CLEAN_ID "\n"));
	assert_string_equal(proc_output(&p, PROC_STDERR), "");
	assert_int_equal(fk.downloads, 0);
	assert_int_equal(fk.running[0], 1);
	assert_int_equal(fk.motors_on, 1);
	assert_string_equal(fk.prog, prog);
	proc_kill(&p);
	free(prog);
}

/* --verify, no program on the controller: exit 6, what differs and what
 * to do; UL only, nothing halted or written. */
static void test_verify_empty(void **state)
{
	static const char *const args[] = {"--verify", GOOD "clean.dmc", NULL};
	struct proc p;

	(void)state;
	fk.running[0] = 1;
	fk.motors_on = 1;
	assert_int_equal(run(&p, args), 6);
	assert_log(IDENT_RUN_UL);
	assert_string_equal(
	    proc_output(&p, PROC_STDERR),
	    "galil-load: verify: the controller's program differs from "
	    "these files (identity " CLEAN_ID ")\n"
	    "galil-load: the controller holds no program\n"
	    "galil-load: nothing was halted or written; to load these files "
	    "run galil-load without --verify (that halts the program)\n");
	assert_false(has(&p, PROC_STDOUT, "verified"));
	assert_int_equal(fk.downloads, 0);
	assert_int_equal(fk.running[0], 1);
	assert_int_equal(fk.motors_on, 1);
	proc_kill(&p);
}

/*
 * Which line was rejected: the link reports the last line it had sent when
 * it saw the '?', so it is @bad or a later one; or, when the '?' came after
 * the whole program, it is not known.
 */
static void assert_rejected_line(const struct proc *p, int bad)
{
	const char *err = proc_output(p, PROC_STDERR);
	const char *s = strstr(err, ": the controller rejected program line ");
	int line = 0;

	if (!s) {
		if (!strstr(err, "galil-load: the controller did not say "
				 "which line it rejected\n"))
			fail_msg("no rejected line named; galil-load said:\n%s",
				 err);
		return;
	}
	assert_int_equal(
	    sscanf(s, ": the controller rejected program line %d", &line), 1);
	assert_true(line >= bad);
}

/* The controller rejects a line: exit 4, TC1 text, erased, halted. */
static void test_reject_line(void **state)
{
	static const char *const args[] = {GOOD "clean.dmc", NULL};
	struct proc p;

	(void)state;
	fk.reject_dl_line = 5;
	assert_int_equal(run(&p, args), 4);
	assert_true(has(&p, PROC_STDERR,
			"galil-load: controller rejected the "
			"download (DL): 60 Download error - line too long or "
			"too many lines\n"));
	assert_rejected_line(&p, 5);
	assert_true(has(&p, PROC_STDERR,
			"galil-load: the controller is halted "
			"and its program erased\n"));
	assert_int_equal(fk.downloads, 2); /* the program, then empty */
	assert_string_equal(fk.prog, "");
	assert_int_equal(fk.running[0], 0);
	/* the erase: an empty DL confirmed by UL, on the same connection */
	assert_non_null(strstr(fk.log, "DL\n> \\\nUL\n"));
	assert_int_equal(fk.connections, 1);
	proc_kill(&p);
}

/* The connection drops in the middle of the download: exit 3; galil-load
 * reconnects, halts and erases the partial program. */
static void test_drop_mid_download(void **state)
{
	static const char *const args[] = {GOOD "clean.dmc", NULL};
	char want[LOG_CAP];
	struct proc p;

	(void)state;
	fk.drop_dl_line = 6;
	assert_int_equal(run(&p, args), 3);
	assert_true(has(&p, PROC_STDERR,
			"galil-load: the download (DL) "
			"failed: "));
	assert_true(has(&p, PROC_STDERR,
			"galil-load: the controller is halted "
			"and its program erased\n"));
	assert_int_equal(fk.connections, 2);
	assert_string_equal(fk.prog, "");
	snprintf(want, sizeof(want), "> #LOOP\n%s", HALT_CMDS);
	pthread_mutex_lock(&fk.mu);
	assert_non_null(strstr(fk.log, want)); /* line 6 arrived, then anew */
	assert_non_null(strstr(fk.log, "MG _XQ7\nDL\n> \\\nUL\n"));
	pthread_mutex_unlock(&fk.mu);
	proc_kill(&p);
}

/* The read-back differs: exit 4, the line named, erased. */
static void test_verify_mismatch(void **state)
{
	static const char *const args[] = {"--burn", "--start",
					   GOOD "clean.dmc", NULL};
	struct proc p;

	(void)state;
	fk.corrupt_ul = 1;
	fk.prog_len = 0;
	assert_int_equal(run(&p, args), 4);
	assert_true(has(&p, PROC_STDERR,
			"galil-load: verify failed: the "
			"program read back (UL) differs at line 1\n"));
	assert_true(has(&p, PROC_STDERR,
			"galil-load: the controller is halted "
			"and its program erased\n"));
	assert_string_equal(fk.prog, "");
	assert_null(strstr(fk.log, "BP"));   /* never burned */
	assert_null(strstr(fk.log, "XQ #")); /* never started */
	assert_int_equal(fk.running[0], 0);
	proc_kill(&p);
}

/* A thread that survives HX: exit 4 before anything is downloaded. */
static void test_thread_stuck(void **state)
{
	static const char *const args[] = {GOOD "clean.dmc", NULL};
	struct proc p;

	(void)state;
	fk.stuck_thread = 3;
	fk.running[3] = 1;
	assert_int_equal(run(&p, args), 4);
	assert_true(has(&p, PROC_STDERR,
			"galil-load: thread 3 still runs "
			"after HX3\n"));
	assert_int_equal(fk.downloads, 0);
	assert_null(strstr(fk.log, "MG _XQ4"));
	proc_kill(&p);
}

/* --burn --start: BP after the read-back, then XQ and the check. */
static void test_burn_and_start(void **state)
{
	static const char *const args[] = {"--burn", "--start",
					   GOOD "clean.dmc", NULL};
	char *prog = clean_program();
	struct proc p;
	const char *tail;

	(void)state;
	assert_int_equal(run(&p, args), 0);
	tail = fk.log + fk.log_len - strlen("UL\nBP\nXQ #AUTO,0\nMG _XQ0\n");
	assert_string_equal(tail, "UL\nBP\nXQ #AUTO,0\nMG _XQ0\n");
	assert_string_equal(fk.burned, prog);
	assert_int_equal(fk.running[0], 1);
	assert_true(has(&p, PROC_STDOUT, "burned: #AUTO runs at power-up\n"));
	assert_true(has(&p, PROC_STDOUT,
			"started: #AUTO in thread 0 (at line "
			"5)\n"));
	proc_kill(&p);
	free(prog);
}

/* The same program with --burn --start: BP is refused while a program
 * runs, so the running thread is halted (after the busy check), then the
 * program burned and started; nothing is downloaded. */
static void test_unchanged_burn_start(void **state)
{
	static const char *const args[] = {"--burn", "--start",
					   GOOD "clean.dmc", NULL};
	char *prog = clean_program();
	struct proc p;

	(void)state;
	strcpy(fk.prog, prog);
	fk.prog_len = strlen(prog);
	fk.running[0] = 1;
	assert_int_equal(run(&p, args), 0);
	/* thread 0 runs: the busy check asks the state (no RoboELF
	 * program here: refused, TC1 read) */
	assert_log(IDENT_RUN_UL HALT_CMDS
			    "BP\nXQ #AUTO,0\nMG _XQ0\n");
	assert_true(has(&p, PROC_STDOUT,
			"unchanged: the controller already holds this program "
			"(identity " CLEAN_ID "); not downloaded\n"
			"halted: threads stopped, axes stopped, motors off\n"
			"burned: #AUTO runs at power-up\n"
			"started: #AUTO in thread 0 (at line 5)\n"));
	assert_int_equal(fk.downloads, 0);
	assert_string_equal(fk.burned, prog);
	assert_int_equal(fk.running[0], 1);
	proc_kill(&p);
	free(prog);
}

/* --start=LABEL that does not run; BP refused. Both exit 4. */
static void test_start_and_burn_fail(void **state)
{
	static const char *const start[] = {"--start=LOOP", GOOD "clean.dmc",
					    NULL};
	static const char *const burn[] = {"-f", "--burn", GOOD "clean.dmc",
					   NULL};
	struct proc p;

	(void)state;
	fk.xq_no_run = 1;
	assert_int_equal(run(&p, start), 4);
	assert_true(has(&p, PROC_STDERR,
			"galil-load: thread 0 is not running "
			"after 'XQ #LOOP,0' (_XQ0 = -1)\n"));
	proc_kill(&p);
	fk.reject_bp = 1;
	assert_int_equal(run(&p, burn), 4);
	assert_true(has(&p, PROC_STDERR,
			"galil-load: controller rejected the "
			"burn (BP): 15 EEPROM write error\n"));
	proc_kill(&p);
}

/* -c: replies printed in order; a rejected command exits 4 with TC1. */
static void test_commands(void **state)
{
	static const char *const ok[] = {"-c", "x=17",	 "-c", "MG x",
					 "-c", "MG _BN", NULL};
	static const char *const bad[] = {"-c", "MG x",	  "-c", "FOO",
					  "-c", "MG _BN", NULL};
	struct proc p;

	(void)state;
	assert_int_equal(run(&p, ok), 0);
	assert_string_equal(proc_output(&p, PROC_STDOUT),
			    " 17.0000\n 4242.0000\n");
	/* a write is preceded by the look at the program (none runs) */
	assert_string_equal(fk.log, "MG _XQ0\nx=17\nMG x\nMG _BN\n");
	proc_kill(&p);
	assert_int_equal(run(&p, bad), 4);
	assert_string_equal(proc_output(&p, PROC_STDOUT), " 17.0000\n");
	assert_string_equal(proc_output(&p, PROC_STDERR),
			    "galil-load: controller rejected 'FOO': 1 "
			    "Unrecognized command\n");
	proc_kill(&p);
}

static void log_clear(void)
{
	pthread_mutex_lock(&fk.mu);
	fk.log_len = 0;
	fk.log[0] = '\0';
	pthread_mutex_unlock(&fk.mu);
}

/* -c on an armed program: reads pass; a write is refused with exit 5 and
 * why, and not sent; with --force it is sent, with what follows said. */
static void test_commands_armed(void **state)
{
	static const char *const reads[] = {"-c", "MG x", "-c",	    "x=?", "-c",
					    "x=", "-c",	  "MG _BN", NULL};
	static const char *const write[] = {"-c", "MG x",   "-c", "x=17",
					    "-c", "MG _BN", NULL};
	static const char *const force[] = {"--force", "-c", "x=17", NULL};
	struct proc p;

	(void)state;
	fk.running[0] = fk.running[1] = 1;
	fk.supervised = 1;
	fk.var_x = 5;
	run(&p, reads);
	assert_log("MG x\nx=?\nx=\nMG _BN\n");
	proc_kill(&p);
	log_clear();
	assert_int_equal(run(&p, write), 5);
	assert_log("MG x\nMG _XQ0\nMG state\n");
	assert_string_equal(
	    proc_output(&p, PROC_STDERR),
	    "galil-load: 'x=17' writes to the controller, and its program is "
	    "armed: a write could change how the robot moves or is stopped. "
	    "Refused (reads such as MG, TP and 'KP ?,?' are allowed); quit "
	    "roboelf first, or give --force to send it anyway (the program "
	    "latches a fault if it changes a sealed value)\n");
	assert_int_equal(fk.var_x, 5);
	proc_kill(&p);
	assert_int_equal(run(&p, force), 0);
	assert_true(
	    has(&p, PROC_STDOUT,
		"warning: --force: sending 'x=17' to a program that is "
		"armed: if it changes a sealed value, the program stops "
		"the robot and latches fault 17, and roboelf cuts motor "
		"power\n"));
	assert_int_equal(fk.var_x, 17);
	proc_kill(&p);
}

/* roboelf drives the robot (the program armed, its heartbeat advancing):
 * refused with exit 5 and why, nothing halted or sent after the busy
 * check; with --force it is halted and loaded, with a warning. */
static void test_busy_refused(void **state)
{
	static const char *const args[] = {GOOD "clean.dmc", NULL};
	static const char *const force[] = {"--force", GOOD "clean.dmc", NULL};
	struct proc p;

	(void)state;
	fk.running[0] = fk.running[1] = 1;
	fk.supervised = 1;
	fk.motors_on = 1;
	assert_int_equal(run(&p, args), 5);
	/* refused before the program is read */
	assert_log(IDENT "MG _XQ0\nMG state\nMG hbpc\nMG hbpc\n");
	assert_true(has(&p, PROC_STDERR,
			"galil-load: the controller's program is armed and "
			"its supervisor's heartbeat is advancing: roboelf is "
			"driving the robot. Loading halts the program: every "
			"axis stops, every motor is switched off and roboelf "
			"latches a fault. Quit roboelf first, or give --force "
			"to do exactly that\n"));
	assert_int_equal(fk.running[0], 1);
	assert_int_equal(fk.motors_on, 1);
	assert_int_equal(fk.downloads, 0);
	proc_kill(&p);
	assert_int_equal(run(&p, force), 0);
	assert_true(has(&p, PROC_STDOUT,
			"warning: --force: halting a program "
			"that roboelf drives (armed)"));
	assert_int_equal(fk.running[0], 0);
	assert_int_equal(fk.motors_on, 0);
	assert_int_equal(fk.downloads, 1);
	proc_kill(&p);
}

/* --verify while roboelf drives the robot: refused with exit 5 before the
 * program is read (the upload would delay its cycle); nothing else sent. */
static void test_verify_busy(void **state)
{
	static const char *const args[] = {"--verify", GOOD "clean.dmc", NULL};
	struct proc p;

	(void)state;
	fk.running[0] = fk.running[1] = 1;
	fk.supervised = 1;
	fk.motors_on = 1;
	assert_int_equal(run(&p, args), 5);
	assert_log(IDENT "MG _XQ0\nMG state\nMG hbpc\nMG hbpc\n");
	assert_string_equal(proc_output(&p, PROC_STDERR),
			    "galil-load: the controller's program is armed and "
			    "its supervisor's heartbeat is advancing: roboelf "
			    "is driving the robot. --verify reads the whole "
			    "program (UL), which would delay roboelf's cycle; "
			    "nothing was read. Verify when roboelf has quit\n");
	assert_int_equal(fk.running[0], 1);
	assert_int_equal(fk.motors_on, 1);
	proc_kill(&p);
}

/* An axis jogs when galil-load comes: ST, then it waits for the profiler
 * to end before MO (which the controller refuses while an axis moves). */
static void test_load_while_jogging(void **state)
{
	static const char *const args[] = {GOOD "clean.dmc", NULL};
	struct proc p;

	(void)state;
	fk.jogging = 1;
	fk.moving_polls = 3; /* still decelerating for three polls */
	fk.motors_on = 1;
	assert_int_equal(run(&p, args), 0);
	pthread_mutex_lock(&fk.mu);
	/* three rounds still moving, the fourth stopped, then MO */
	assert_non_null(strstr(fk.log, "ST\n"
				       "MG _BGA\nMG _BGB\nMG _BGC\n"
				       "MG _BGA\nMG _BGB\nMG _BGC\n"
				       "MG _BGA\nMG _BGB\nMG _BGC\n"
				       "MG _BGA\nMG _BGB\nMG _BGC\nMO\n"
				       "MG _MOA\n"));
	assert_null(strstr(fk.log, "TC1"));
	pthread_mutex_unlock(&fk.mu);
	assert_int_equal(fk.motors_on, 0);
	assert_int_equal(fk.downloads, 1);
	proc_kill(&p);
}

/* Axis A keeps moving after ST (st_ignored) past --stop-wait: galil-load
 * aborts it (AB 1), switches the motors off, names the axis, exits 4 and
 * downloads nothing. */
static void test_axis_not_stopping(void **state)
{
	static const char *const args[] = {"--stop-wait", "200",
					   GOOD "clean.dmc", NULL};
	struct proc p;

	(void)state;
	fk.jogging = 1;
	fk.st_ignored = 1;
	fk.motors_on = 1;
	assert_int_equal(run(&p, args), 4);
	assert_string_equal(proc_output(&p, PROC_STDERR),
			    "galil-load: axis A still moving 200 ms after "
			    "'ST': aborted it (AB 1) and switched the motors "
			    "off; nothing downloaded (see --stop-wait)\n");
	pthread_mutex_lock(&fk.mu);
	assert_non_null(strstr(fk.log, "MG _BGC\nAB 1\nMG _BGA\nMG _BGB\n"
				       "MG _BGC\nMO\nMG _MOA\n"));
	assert_null(strstr(fk.log, "DL\n"));
	/* the one UL is the comparison, before the halt */
	assert_int_equal(strncmp(fk.log, IDENT_UL, strlen(IDENT_UL)), 0);
	assert_null(strstr(fk.log + strlen(IDENT_UL), "UL\n"));
	pthread_mutex_unlock(&fk.mu);
	assert_int_equal(fk.motors_on, 0);
	assert_int_equal(fk.downloads, 0);
	proc_kill(&p);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test_setup_teardown(test_load_clean, fk_start, fk_stop),
	    cmocka_unit_test_setup_teardown(test_unchanged, fk_start, fk_stop),
	    cmocka_unit_test_setup_teardown(test_verify_equal, fk_start,
					    fk_stop),
	    cmocka_unit_test_setup_teardown(test_verify_empty, fk_start,
					    fk_stop),
	    cmocka_unit_test_setup_teardown(test_reject_line, fk_start,
					    fk_stop),
	    cmocka_unit_test_setup_teardown(test_drop_mid_download, fk_start,
					    fk_stop),
	    cmocka_unit_test_setup_teardown(test_verify_mismatch, fk_start,
					    fk_stop),
	    cmocka_unit_test_setup_teardown(test_thread_stuck, fk_start,
					    fk_stop),
	    cmocka_unit_test_setup_teardown(test_burn_and_start, fk_start,
					    fk_stop),
	    cmocka_unit_test_setup_teardown(test_unchanged_burn_start, fk_start,
					    fk_stop),
	    cmocka_unit_test_setup_teardown(test_start_and_burn_fail, fk_start,
					    fk_stop),
	    cmocka_unit_test_setup_teardown(test_commands, fk_start, fk_stop),
	    cmocka_unit_test_setup_teardown(test_commands_armed, fk_start,
					    fk_stop),
	    cmocka_unit_test_setup_teardown(test_busy_refused, fk_start,
					    fk_stop),
	    cmocka_unit_test_setup_teardown(test_verify_busy, fk_start,
					    fk_stop),
	    cmocka_unit_test_setup_teardown(test_load_while_jogging, fk_start,
					    fk_stop),
	    cmocka_unit_test_setup_teardown(test_axis_not_stopping, fk_start,
					    fk_stop),
	};

	return cmocka_run_group_tests(tests, setup_group, NULL);
}
