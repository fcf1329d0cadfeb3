/*
 * test_gload_sim.c - galil-load (child process) against galil-sim, which
 * really runs the DMC: a clean program loaded, verified, started and
 * running (the variable its #AUTO sets); the identity stamp read back and
 * verified as roboelf does at start-up; a second load found unchanged and
 * the program left running; a running program halted before a forced
 * reload; --verify equal and different, halting and writing nothing; --burn
 * then a power cycle runs #AUTO (and without --burn the power cycle leaves
 * nothing); -c round trips and a rejected command; ^R^V through -c; a load
 * while an axis jogs.
 *
 * Needs $ROBOELF_BIN/galil-sim and galil-load. One simulator per test,
 * started with --port 0 --control-port 0, killed by pid.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "gl_err.h"
#include "gl_ident.h"
#include "gl_link.h"
#include "load_h.h"
#include "proc.h"

#define GOOD		"tests/data/dmc_good/"
#define RUN_DEADLINE_MS 30000
#define READY_MS	10000
#define CLEAN_ID	0x32DC74A870EEBF04ULL

static char load_bin[512];
static const char *bin_dir;

static int setup_group(void **state)
{
	char sim[512];

	(void)state;
	bin_dir = getenv("ROBOELF_BIN");
	if (!bin_dir || !*bin_dir) {
		fprintf(stderr, "test_gload_sim: ROBOELF_BIN is not set (run "
				"through tests/run-all.sh or make check)\n");
		return -1;
	}
	snprintf(load_bin, sizeof(load_bin), "%s/galil-load", bin_dir);
	snprintf(sim, sizeof(sim), "%s/galil-sim", bin_dir);
	if (access(load_bin, X_OK) != 0 || access(sim, X_OK) != 0) {
		fprintf(stderr, "test_gload_sim: '%s' or '%s' is missing\n",
			load_bin, sim);
		return -1;
	}
	return 0;
}

struct simctx {
	struct proc_sim s;
	char addr[32];
	int ctl; /* control-port socket */
};

static void sim_start(struct simctx *c)
{
	memset(c, 0, sizeof(*c));
	if (proc_sim_start(&c->s, bin_dir, NULL, NULL, READY_MS) != 0)
		fail_msg("galil-sim did not print its ready line within %d ms",
			 READY_MS);
	snprintf(c->addr, sizeof(c->addr), "127.0.0.1:%d", c->s.port);
	c->ctl = proc_ctl_connect(c->s.ctl_port, 2000);
	if (c->ctl < 0) {
		proc_kill(&c->s.p);
		fail_msg("cannot connect to galil-sim's control port %d",
			 c->s.ctl_port);
	}
}

static void sim_stop(struct simctx *c)
{
	if (c->ctl >= 0)
		close(c->ctl);
	proc_kill(&c->s.p);
}

static int run(struct proc *p, const struct simctx *c, const char *const *args)
{
	int rc = load_h_run(p, load_bin, c->addr, args, RUN_DEADLINE_MS);

	if (rc == -2)
		fail_msg("galil-load did not exit within %d ms",
			 RUN_DEADLINE_MS);
	assert_true(rc >= 0);
	return rc;
}

/* run() that must exit 0; otherwise the failure shows galil-load's
 * own words. */
static void run_ok(struct proc *p, const struct simctx *c,
		   const char *const *args)
{
	int rc = run(p, c, args);

	if (rc != 0)
		fail_msg("galil-load exited %d: %s%s", rc,
			 proc_output(p, PROC_STDOUT),
			 proc_output(p, PROC_STDERR));
}

static gl_link *sim_link(const struct simctx *c)
{
	char err[GL_ERRTEXT_LEN];
	gl_link *l = NULL;

	if (gl_link_open(&l, c->addr, 2000, err) != GL_OK)
		fail_msg("%s", err);
	return l;
}

/* "MG @name" on a new connection: GL_OK and the value, or the error. */
static int sim_query(const struct simctx *c, const char *cmd, double *v)
{
	gl_link *l = sim_link(c);
	char resp[128];
	int rc = gl_link_command(l, cmd, resp, sizeof(resp), 2000);

	gl_link_close(l);
	if (rc >= 0)
		*v = strtod(resp, NULL);
	return rc < 0 ? rc : GL_OK;
}

/* Wait (deadline @ms) until "MG @var" answers @want. */
static int wait_value(const struct simctx *c, const char *cmd, double want,
		      int ms)
{
	long long end = proc_now_ms() + ms;
	double v;

	do {
		if (sim_query(c, cmd, &v) == GL_OK && v == want)
			return 0;
		usleep(20 * 1000); /* poll interval */
	} while (proc_now_ms() < end);
	return -1;
}

static int has(const struct proc *p, enum proc_stream s, const char *text)
{
	return strstr(proc_output(p, s), text) != NULL;
}

/* Load, verify and start; #AUTO runs; the stamp verifies as in roboelf. */
static void test_clean_start(void **state)
{
	static const char *const args[] = {"--start", GOOD "clean.dmc", NULL};
	char prog[8192];
	struct simctx c;
	struct proc p;
	uint64_t id = 0;
	gl_link *l;
	double v;
	int n;

	(void)state;
	sim_start(&c);
	run_ok(&p, &c, args);
	assert_true(has(&p, PROC_STDOUT,
			"verified: the read-back matches, "
			"identity 32DC74A870EEBF04\n"));
	assert_true(has(&p, PROC_STDOUT, "started: #AUTO in thread 0"));
	assert_string_equal(proc_output(&p, PROC_STDERR), "");
	proc_kill(&p);
	assert_int_equal(wait_value(&c, "MG booted", 1, 2000), 0);
	assert_int_equal(sim_query(&c, "MG sum", &v), GL_OK);
	assert_true(v == 5); /* JS #add(2,3) */
	assert_int_equal(sim_query(&c, "MG _XQ0", &v), GL_OK);
	assert_true(v >= 0);
	l = sim_link(&c);
	n = gl_link_upload(l, prog, sizeof(prog), 5000);
	gl_link_close(l);
	assert_true(n > 0);
	assert_int_equal(gl_ident_verify(prog, (size_t)n, &id), GL_OK);
	assert_true(id == CLEAN_ID);
	sim_stop(&c);
}

/* Switch motor A on (SH A): a halt would switch it off (MO), so a motor
 * still on afterwards shows that nothing was halted. */
static void motor_on(const struct simctx *c)
{
	gl_link *l = sim_link(c);
	char resp[64];

	assert_true(gl_link_command(l, "SH A", resp, sizeof(resp), 2000) >= 0);
	gl_link_close(l);
}

/* The running program untouched: thread 0 still runs, motor A still on,
 * and the controller still holds the program stamped @id. */
static void assert_untouched(const struct simctx *c, uint64_t id)
{
	char prog[8192];
	uint64_t held = 0;
	gl_link *l;
	double v;
	int n;

	assert_int_equal(sim_query(c, "MG _XQ0", &v), GL_OK);
	assert_true(v >= 0);
	assert_int_equal(sim_query(c, "MG _MOA", &v), GL_OK);
	assert_true(v == 0);
	l = sim_link(c);
	n = gl_link_upload(l, prog, sizeof(prog), 5000);
	gl_link_close(l);
	assert_true(n > 0);
	assert_int_equal(gl_ident_verify(prog, (size_t)n, &held), GL_OK);
	assert_true(held == id);
}

/* A second load of the same program is compared before anything is
 * halted: the running program keeps running and nothing is downloaded;
 * --start finds thread 0 running and leaves it; a forced load halts the
 * running program first (DL is refused while it runs). */
static void test_unchanged_and_forced(void **state)
{
	static const char *const start[] = {"--start", GOOD "clean.dmc", NULL};
	static const char *const again[] = {GOOD "clean.dmc", NULL};
	static const char *const force[] = {"-f", GOOD "clean.dmc", NULL};
	struct simctx c;
	struct proc p;
	double v;

	(void)state;
	sim_start(&c);
	run_ok(&p, &c, start);
	proc_kill(&p);
	assert_int_equal(wait_value(&c, "MG booted", 1, 2000), 0);
	motor_on(&c);
	run_ok(&p, &c, again);
	assert_true(has(&p, PROC_STDOUT,
			"unchanged: the controller already holds this program "
			"(identity 32DC74A870EEBF04); not downloaded\n"
			"left running: nothing halted, nothing written\n"));
	assert_false(has(&p, PROC_STDOUT, "halted:"));
	assert_false(has(&p, PROC_STDOUT, "downloading"));
	assert_string_equal(proc_output(&p, PROC_STDERR), "");
	proc_kill(&p);
	assert_untouched(&c, CLEAN_ID);
	run_ok(&p, &c, start);
	assert_true(has(&p, PROC_STDOUT,
			"running: thread 0 already runs it "
			"(at line "));
	assert_true(has(&p, PROC_STDOUT,
			"); not restarted (--force halts, reloads and "
			"restarts it)\n"
			"left running: nothing halted, nothing written\n"));
	proc_kill(&p);
	assert_untouched(&c, CLEAN_ID);
	run_ok(&p, &c, force);
	assert_true(has(&p, PROC_STDOUT, "halted: threads stopped"));
	assert_true(has(&p, PROC_STDOUT, "verified: the read-back matches"));
	proc_kill(&p);
	assert_int_equal(sim_query(&c, "MG _XQ0", &v), GL_OK);
	assert_true(v == -1);
	assert_int_equal(sim_query(&c, "MG _MOA", &v), GL_OK);
	assert_true(v == 1);
	sim_stop(&c);
}

/* clean.dmc with its 'WT 10' (program line 13, file line 19) made 'WT 20',
 * written to @path (PATH_MAX) in a new temporary directory. */
static void write_variant(char *path, size_t cap)
{
	static const char from[] = "\tWT 10";
	char src[4096], dir[] = "/tmp/gload_verify.XXXXXX";
	FILE *f = fopen(GOOD "clean.dmc", "rb");
	char *at;
	size_t n;

	assert_non_null(f);
	n = fread(src, 1, sizeof(src) - 1, f);
	fclose(f);
	src[n] = 0;
	at = strstr(src, from);
	assert_non_null(at);
	at[5] = '2';
	assert_non_null(mkdtemp(dir));
	snprintf(path, cap, "%s/variant.dmc", dir);
	f = fopen(path, "wb");
	assert_non_null(f);
	assert_int_equal(fwrite(src, 1, n, f), n);
	assert_int_equal(fclose(f), 0);
}

static void remove_variant(const char *path)
{
	char dir[512];

	snprintf(dir, sizeof(dir), "%s", path);
	unlink(path);
	*strrchr(dir, '/') = 0;
	rmdir(dir);
}

/* --verify against the program that runs: equal (exit 0) and different
 * (exit 6, the first differing line); neither halts nor writes. */
static void test_verify(void **state)
{
	char var[512], want[1024];
	const char *const same[] = {"--verify", var, NULL};
	const char *const other[] = {"--verify", GOOD "clean.dmc", NULL};
	const char *const start[] = {"--start", var, NULL};
	unsigned long long id = 0;
	struct simctx c;
	struct proc p;
	const char *s;

	(void)state;
	write_variant(var, sizeof(var));
	sim_start(&c);
	run_ok(&p, &c, start);
	s = strstr(proc_output(&p, PROC_STDOUT),
		   "read-back matches, identity ");
	assert_non_null(s);
	assert_int_equal(sscanf(s, "read-back matches, identity %llX", &id), 1);
	proc_kill(&p);
	assert_int_equal(wait_value(&c, "MG booted", 1, 2000), 0);
	motor_on(&c);
	assert_int_equal(run(&p, &c, other), 6);
	snprintf(want, sizeof(want),
		 "galil-load: verify: the controller's program differs from "
		 "these files (identity 32DC74A870EEBF04)\n"
		 "galil-load: the controller holds identity %016llX\n"
		 "tests/data/dmc_good/clean.dmc:19: first difference: program "
		 "line 13 'WT 10'\n"
		 "galil-load: nothing was halted or written; to load these "
		 "files run galil-load without --verify (that halts the "
		 "program)\n",
		 id);
	assert_string_equal(proc_output(&p, PROC_STDERR), want);
	assert_false(has(&p, PROC_STDOUT, "verified"));
	proc_kill(&p);
	assert_untouched(&c, id);
	run_ok(&p, &c, same);
	snprintf(want, sizeof(want),
		 "verified: the controller holds this program, identity "
		 "%016llX\n",
		 id);
	assert_true(has(&p, PROC_STDOUT, want));
	assert_false(has(&p, PROC_STDOUT, "halted:"));
	assert_string_equal(proc_output(&p, PROC_STDERR), "");
	proc_kill(&p);
	assert_untouched(&c, id);
	sim_stop(&c);
	remove_variant(var);
}

static void power_cycle(struct simctx *c)
{
	char resp[128];

	assert_true(proc_ctl_request(c->ctl, "power-cycle", resp, sizeof(resp),
				     5000) >= 0);
	assert_string_equal(resp, "ok");
}

/* Without --burn a power cycle loses the program; with it #AUTO runs. */
static void test_burn_power_cycle(void **state)
{
	static const char *const plain[] = {GOOD "clean.dmc", NULL};
	static const char *const burn[] = {"-f", "--burn", GOOD "clean.dmc",
					   NULL};
	char prog[8192];
	struct simctx c;
	struct proc p;
	gl_link *l;
	double v;

	(void)state;
	sim_start(&c);
	run_ok(&p, &c, plain);
	proc_kill(&p);
	power_cycle(&c);
	l = sim_link(&c);
	assert_int_equal(gl_link_upload(l, prog, sizeof(prog), 5000), 0);
	gl_link_close(l);
	assert_int_equal(sim_query(&c, "MG _XQ0", &v), GL_OK);
	assert_true(v == -1);
	run_ok(&p, &c, burn);
	assert_true(has(&p, PROC_STDOUT, "burned: #AUTO runs at power-up\n"));
	proc_kill(&p);
	assert_int_equal(sim_query(&c, "MG _XQ0", &v), GL_OK);
	assert_true(v == -1); /* loaded, not started */
	power_cycle(&c);
	assert_int_equal(wait_value(&c, "MG booted", 1, 3000), 0);
	assert_int_equal(sim_query(&c, "MG _XQ0", &v), GL_OK);
	assert_true(v >= 0);
	sim_stop(&c);
}

/* -c: left-to-right arithmetic and a variable; a rejected command. */
static void test_commands(void **state)
{
	static const char *const ok[] = {"-c", "abc=6",	 "-c", "MG 1+2*3",
					 "-c", "MG abc", NULL};
	static const char *const bad[] = {"-c", "bg A", NULL};
	struct simctx c;
	struct proc p;
	double a, b;

	(void)state;
	sim_start(&c);
	run_ok(&p, &c, ok);
	assert_int_equal(
	    sscanf(proc_output(&p, PROC_STDOUT), "%lf\n%lf", &a, &b), 2);
	assert_true(a == 9);
	assert_true(b == 6);
	proc_kill(&p);
	assert_int_equal(run(&p, &c, bad), 4);
	assert_string_equal(proc_output(&p, PROC_STDERR),
			    "galil-load: controller rejected 'bg A': 1 "
			    "Unrecognized command\n");
	proc_kill(&p);
	sim_stop(&c);
}

/* The firmware revision request ^R^V (0x12 0x16, command reference ^R^V)
 * goes through -c and prints the reply exactly; ^R^S (master reset) and
 * other control bytes are refused before anything is sent (exit 2). */
static void test_ctrl_requests(void **state)
{
	static const char *const rv[] = {"-c", "\x12\x16", NULL};
	static const char *const rs[] = {"-c", "\x12\x13", NULL};
	static const char *const other[] = {"-c", "MG 1\x01", NULL};
	struct simctx c;
	struct proc p;

	(void)state;
	sim_start(&c);
	run_ok(&p, &c, rv);
	assert_string_equal(proc_output(&p, PROC_STDOUT),
			    "DMC4030 Rev 1.2h-sim\n");
	assert_string_equal(proc_output(&p, PROC_STDERR), "");
	proc_kill(&p);
	assert_int_equal(run(&p, &c, rs), 2);
	assert_true(has(&p, PROC_STDERR,
			"galil-load: '^R^S' (master reset: erases the "
			"controller's EEPROM and its IP address) is not sent "
			"by galil-load\n"));
	proc_kill(&p);
	assert_int_equal(run(&p, &c, other), 2);
	assert_true(
	    has(&p, PROC_STDERR,
		"galil-load: 'MG 1^A' holds a control character: only "
		"the requests ^R^V and '^L^K ?' may be sent with -c\n"));
	proc_kill(&p);
	sim_stop(&c);
}

/* An axis jogs when galil-load comes (galil-sim refuses MO while its
 * profiler runs, TC 7, as the command reference MO says): galil-load
 * stops it, waits, switches the motors off and loads; afterwards the axis
 * is at rest, every motor off, the program verified. */
static void test_load_while_jogging(void **state)
{
	static const char *const args[] = {GOOD "clean.dmc", NULL};
	struct simctx c;
	struct proc p;
	gl_link *l;
	char resp[64];
	double v;

	(void)state;
	sim_start(&c);
	l = sim_link(&c);
	assert_true(gl_link_command(l, "SH ABC", resp, sizeof(resp), 2000) >=
		    0);
	assert_true(gl_link_command(l, "JG 20000", resp, sizeof(resp), 2000) >=
		    0);
	assert_true(gl_link_command(l, "BG A", resp, sizeof(resp), 2000) >= 0);
	/* the simulator's MO refusal this test relies on */
	assert_int_equal(gl_link_command(l, "MO", resp, sizeof(resp), 2000),
			 GL_ERR_CTRL);
	assert_string_equal(gl_link_ctrl_error(l, NULL),
			    "Command not valid while running");
	gl_link_close(l);
	assert_int_equal(sim_query(&c, "MG _BGA", &v), GL_OK);
	assert_true(v == 1);
	run_ok(&p, &c, args);
	assert_true(has(&p, PROC_STDOUT,
			"halted: threads stopped, axes stopped, motors off\n"
			"downloading 19 lines to "));
	assert_true(has(&p, PROC_STDOUT,
			"verified: the read-back matches, "
			"identity 32DC74A870EEBF04\n"));
	assert_string_equal(proc_output(&p, PROC_STDERR), "");
	proc_kill(&p);
	assert_int_equal(sim_query(&c, "MG _BGA", &v), GL_OK);
	assert_true(v == 0);
	assert_int_equal(sim_query(&c, "MG _TVA", &v), GL_OK);
	assert_true(v == 0);
	assert_int_equal(sim_query(&c, "MG _MOA+_MOB+_MOC", &v), GL_OK);
	assert_true(v == 3);
	sim_stop(&c);
}

/* A controller that stops answering (control port "link stall"): exit 3
 * after the command timeout; answering again ("link ok"): exit 0. */
static void test_stalled(void **state)
{
	static const char *const args[] = {"-t", "300", "-c", "MG 2", NULL};
	char resp[128];
	struct simctx c;
	struct proc p;

	(void)state;
	sim_start(&c);
	assert_true(proc_ctl_request(c.ctl, "link stall", resp, sizeof(resp),
				     2000) >= 0);
	assert_string_equal(resp, "ok");
	assert_int_equal(run(&p, &c, args), 3);
	assert_string_equal(proc_output(&p, PROC_STDERR),
			    "galil-load: no reply to 'MG 2' within 300 ms\n");
	proc_kill(&p);
	assert_true(
	    proc_ctl_request(c.ctl, "link ok", resp, sizeof(resp), 2000) >= 0);
	assert_string_equal(resp, "ok");
	run_ok(&p, &c, args);
	proc_kill(&p);
	sim_stop(&c);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_clean_start),
	    cmocka_unit_test(test_unchanged_and_forced),
	    cmocka_unit_test(test_verify),
	    cmocka_unit_test(test_burn_power_cycle),
	    cmocka_unit_test(test_commands),
	    cmocka_unit_test(test_stalled),
	    cmocka_unit_test(test_ctrl_requests),
	    cmocka_unit_test(test_load_while_jogging),
	};

	return cmocka_run_group_tests(tests, setup_group, NULL);
}
