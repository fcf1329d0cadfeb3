/*
 * test_sys_basic.c - roboelf against the real binaries: galil-sim (a robot
 * with a short travel so that a full calibration takes seconds), dmc/
 * loaded with galil-load, the virtual relay. Covers start-up to "RoboELF
 * Ready for Use", a clean quit (exit 0, relay off, motors off), each fault
 * class injected through galil-sim's control port (the FAULT line on
 * stdout, relay off, motors off, the log entry, exit 4), and the start-up
 * refusals (no terminal, no relay, no controller, no stamped program).
 *
 * Needs ROBOELF_BIN (the binaries) and runs from the repository root.
 */
#include <errno.h>
#include <poll.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmocka.h>

#include "base_version.h"
#include "proc.h"
#include "sys_h.h"

#define START_MS 10000 /* galil-sim, galil-load */
#define READY_MS 60000 /* roboelf to "RoboELF Ready for Use" */
#define FAULT_MS 3000  /* an injected fault to its FAULT line */
#define EXIT_MS	 5000

static char bin[512];
static char tmp[256];
static char cal_file[300];

struct rig {
	struct proc_sim sim;
	struct proc rob;
	int ctl;
	char cfg[300];
	char log[300];
	char relay[300];
};

static struct rig rig;

/* ---- helpers ---------------------------------------------------------------
 */

static void path(char *out, size_t cap, const char *name)
{
	snprintf(out, cap, "%s/%s", tmp, name);
}

static int write_file(const char *p, const char *text)
{
	FILE *f = fopen(p, "w");

	if (!f)
		return -1;
	fputs(text, f);
	return fclose(f);
}

static int slurp(const char *p, char *buf, size_t cap)
{
	FILE *f = fopen(p, "r");
	size_t n;

	if (!f)
		return -1;
	n = fread(buf, 1, cap - 1, f);
	buf[n] = '\0';
	fclose(f);
	return (int)n;
}

/* A config for galil-sim's short robot (travel 20000 / 16000 counts). */
static int write_config(struct rig *r, int port, const char *relay,
			const char *calfile)
{
	/* ER 800 < step 1000 (the program's arm check 7); OT 1000 samples so
	 * that a jam at jog speed trips the position error (0.4 s at the
	 * 2000 counts/s start velocity) before the encoder-failure check */
	static const char axis_fmt[] =
	    "  - {name: %s, travel_counts: %d, position_error_limit_counts:"
	    " 800, step_counts: 1000,\n"
	    "     encoder_failure: {time_samples: 1000}}\n";
	const char *rec = sys_record();
	char text[4096], udp[32] = "";
	int n;

	/* galil-sim's UDP port (the record stream's), when it runs */
	if (r->sim.udp_port > 0)
		snprintf(udp, sizeof(udp), ", udp_port: %d", r->sim.udp_port);
	n = snprintf(text, sizeof(text),
		     "mode: development\nperiod_ms: 50\n"
		     "controller: {address: \"127.0.0.1:%d\"%s%s%s}\n"
		     "relay: {port_development: \"%s\", readback: true}\n"
		     "calibration: {file: \"%s\", near_margin_counts: 500}\n"
		     "log: {path: \"%s\"}\naxes:\n",
		     port, udp, rec ? ", record: " : "", rec ? rec : "", relay,
		     calfile, r->log);
	n += snprintf(text + n, sizeof(text) - (size_t)n, axis_fmt, "A", 20000);
	n += snprintf(text + n, sizeof(text) - (size_t)n, axis_fmt, "B", 20000);
	snprintf(text + n, sizeof(text) - (size_t)n, axis_fmt, "C", 16000);
	return write_file(r->cfg, text);
}

static int sim_start(struct rig *r)
{
	char plant[300];
	char *extra[] = {(char *)"--plant", plant, (char *)"--udp-port",
			 (char *)"0", NULL};

	path(plant, sizeof(plant), "plant.yaml");
	path(r->relay, sizeof(r->relay), "relay");
	path(r->cfg, sizeof(r->cfg), "roboelf.yaml");
	path(r->log, sizeof(r->log), "roboelf.log");
	unlink(r->log);
	if (proc_sim_start(&r->sim, bin, r->relay, extra, START_MS) < 0)
		return -1;
	r->ctl = proc_ctl_connect(r->sim.ctl_port, START_MS);
	return r->ctl < 0 ? -1 : 0;
}

/* galil-load of the DMC programs in @dir, sealed with the rig's
 * configuration (written here first; the case may write it again with
 * other paths, which the seal does not hold). */
static int galil_load_dir(struct rig *r, const char *dir)
{
	char exe[600], addr[64];
	char *argv[] = {exe,	(char *)"-a", addr, (char *)"--config",
			r->cfg, (char *)dir,  NULL};
	struct proc p;
	int code;

	if (write_config(r, r->sim.port, r->relay, cal_file) < 0)
		return -1;
	snprintf(exe, sizeof(exe), "%s/galil-load", bin);
	snprintf(addr, sizeof(addr), "127.0.0.1:%d", r->sim.port);
	if (proc_spawn(&p, argv, NULL) < 0)
		return -1;
	if (proc_wait_exit(&p, START_MS, NULL) < 0)
		code = -1;
	else
		code = proc_exit_code(&p);
	if (code != 0)
		fprintf(stderr, "galil-load: %s%s", proc_output(&p, 0),
			proc_output(&p, 1));
	proc_kill(&p);
	return code;
}

static int galil_load(struct rig *r)
{
	return galil_load_dir(r, "dmc/");
}

static int rob_start(struct rig *r, const char *calib)
{
	char exe[600];
	char *argv[] = {exe,	       (char *)"-c",
			r->cfg,	       (char *)"--calibration",
			(char *)calib, NULL};

	snprintf(exe, sizeof(exe), "%s/roboelf", bin);
	return proc_spawn(&r->rob, argv, NULL);
}

static void ctl(const char *req, char *resp, size_t cap)
{
	assert_true(proc_ctl_request(rig.ctl, req, resp, cap, 2000) >= 0);
}

static void ctl_ok(const char *req)
{
	char resp[256];

	ctl(req, resp, sizeof(resp));
	assert_string_equal(resp, "ok");
}

/* Wait until "state" shows every motor off (the DMC may be the one that
 * switches them off, a little after the supervisor cut the relay). */
static int motors_off(int timeout_ms)
{
	long long deadline = proc_now_ms() + timeout_ms;
	char st[2048], v[16];

	do {
		int off = 0;

		ctl("state", st, sizeof(st));
		for (const char *k = "ABC"; *k; k++) {
			char key[8];

			snprintf(key, sizeof(key), "%c.mo", *k);
			if (!proc_ctl_state_get(st, key, v, sizeof(v)) &&
			    !strcmp(v, "1"))
				off++;
		}
		if (off == 3)
			return 1;
		poll(NULL, 0, 20);
	} while (proc_now_ms() < deadline);
	fprintf(stderr, "state: %s\n", st);
	return 0;
}

/* Wait until axis @axis's encoder ("<axis>.pos") is @counts away from
 * where it was at the call. */
static int axis_moved(char axis, long counts, int timeout_ms)
{
	long long deadline = proc_now_ms() + timeout_ms;
	char st[2048], v[32], key[8];
	long p0;

	snprintf(key, sizeof(key), "%c.pos", axis);
	ctl("state", st, sizeof(st));
	if (proc_ctl_state_get(st, key, v, sizeof(v)))
		return 0;
	p0 = strtol(v, NULL, 10);
	do {
		poll(NULL, 0, 20);
		ctl("state", st, sizeof(st));
		if (!proc_ctl_state_get(st, key, v, sizeof(v)) &&
		    labs(strtol(v, NULL, 10) - p0) >= counts)
			return 1;
	} while (proc_now_ms() < deadline);
	fprintf(stderr, "state: %s\n", st);
	return 0;
}

static void assert_relay_off(void)
{
	char resp[64];

	ctl("relay", resp, sizeof(resp));
	assert_string_equal(resp, "off");
}

static void assert_ready(void)
{
	if (proc_wait_line(&rig.rob, PROC_STDOUT, "RoboELF Ready for Use",
			   READY_MS, NULL, 0) < 0) {
		fprintf(stderr, "roboelf stdout:\n%s\nstderr:\n%s\n",
			proc_output(&rig.rob, 0), proc_output(&rig.rob, 1));
		fail_msg("no 'RoboELF Ready for Use'");
	}
}

static int quit_rob(int sig)
{
	assert_int_equal(proc_signal(&rig.rob, sig), 0);
	assert_int_equal(proc_wait_exit(&rig.rob, EXIT_MS, NULL), 0);
	return proc_exit_code(&rig.rob);
}

/* The FAULT line on stdout, then the same line in the log, relay off,
 * motors off; SIGTERM then exits 4. */
static void expect_fault(const char *prefix)
{
	char line[512], logbuf[65536];

	if (proc_wait_line(&rig.rob, PROC_STDOUT, prefix, FAULT_MS, line,
			   sizeof(line)) < 0) {
		fprintf(stderr, "roboelf stdout:\n%s\n",
			proc_output(&rig.rob, 0));
		fail_msg("no '%s' line", prefix);
	}
	assert_non_null(strstr(line, ". Recovery: "));
	assert_relay_off();
	assert_true(motors_off(2000));
	assert_true(slurp(rig.log, logbuf, sizeof(logbuf)) > 0);
	assert_non_null(strstr(logbuf, line));
	assert_int_equal(quit_rob(SIGTERM), 4);
}

/* ---- fixtures --------------------------------------------------------------
 */

static int group_setup(void **state)
{
	const char *b = getenv("ROBOELF_BIN");
	char plant[300];

	(void)state;
	if (!b || !*b) {
		fprintf(stderr, "ROBOELF_BIN is not set\n");
		return -1;
	}
	snprintf(bin, sizeof(bin), "%s", b);
	snprintf(tmp, sizeof(tmp), "/tmp/roboelf-basic-XXXXXX");
	if (!mkdtemp(tmp))
		return -1;
	path(plant, sizeof(plant), "plant.yaml");
	path(cal_file, sizeof(cal_file), "calibration.txt");
	return write_file(plant, "axes:\n"
				 "  A: {rev_limit: -10000, fwd_limit: 10000}\n"
				 "  B: {rev_limit: -10000, fwd_limit: 10000}\n"
				 "  C: {rev_limit: -8000, fwd_limit: 8000}\n");
}

static int group_teardown(void **state)
{
	char cmd[400];

	(void)state;
	snprintf(cmd, sizeof(cmd), "rm -rf '%s'", tmp);
	return system(cmd) == 0 ? 0 : -1;
}

/* Sim + program + roboelf started with @calib, up to Ready. */
static int setup_calib(const char *calib)
{
	memset(&rig, 0, sizeof(rig));
	rig.ctl = -1;
	if (sim_start(&rig) < 0 || galil_load(&rig) != 0 ||
	    write_config(&rig, rig.sim.port, rig.relay, cal_file) < 0 ||
	    rob_start(&rig, calib) < 0)
		return -1;
	return 0;
}

static int setup_file(void **state)
{
	(void)state;
	return setup_calib("file");
}

static int setup_full(void **state)
{
	(void)state;
	return setup_calib("full");
}

static int setup_sim_only(void **state)
{
	(void)state;
	memset(&rig, 0, sizeof(rig));
	rig.ctl = -1;
	return sim_start(&rig);
}

static int teardown(void **state)
{
	char resp[64];

	(void)state;
	proc_kill(&rig.rob);
	if (rig.ctl >= 0) {
		proc_ctl_request(rig.ctl, "quit", resp, sizeof(resp), 1000);
		close(rig.ctl);
	}
	proc_wait_exit(&rig.sim.p, 2000, NULL);
	proc_kill(&rig.sim.p);
	return 0;
}

/* ---- tests -----------------------------------------------------------------
 */

/* Full calibration to Ready (saves the file the other tests load), status
 * lines, then SIGTERM: exit 0, relay off, motors off, logged. */
static void test_sys_full_calibration_ready_quit(void **state)
{
	char logbuf[65536], line[512];
	const char *p;
	int points = 0;

	(void)state;
	assert_ready();
	assert_int_equal(proc_wait_line(&rig.rob, PROC_STDOUT, "status ", 3000,
					line, sizeof(line)),
			 0);
	assert_non_null(strstr(line, "relay=on"));
	assert_non_null(strstr(line, "ctrl=\"armed\""));
	assert_int_equal(quit_rob(SIGTERM), 0);
	assert_relay_off();
	assert_true(motors_off(1000));
	assert_int_equal(
	    proc_find_line(&rig.rob, PROC_STDOUT, "FAULT", NULL, 0), -1);
	assert_true(slurp(rig.log, logbuf, sizeof(logbuf)) > 0);
	assert_non_null(strstr(logbuf, "INFO RoboELF Ready for Use"));
	p = strstr(logbuf, "calibration (full) axis A: ");
	assert_non_null(p);
	assert_int_equal(
	    sscanf(p, "calibration (full) axis A: %d points", &points), 1);
	assert_true(points >= 19 && points <= 20); /* 19000 counts */
	assert_non_null(strstr(logbuf, "INFO stop: SIGTERM"));
	assert_true(access(cal_file, R_OK) == 0);
}

/* Ctrl-C quits the same way. */
static void test_sys_file_calibration_sigint(void **state)
{
	(void)state;
	assert_ready();
	assert_int_equal(quit_rob(SIGINT), 0);
	assert_relay_off();
	assert_true(motors_off(1000));
}

/* Potentiometer offset: ENCODER. */
static void test_sys_fault_encoder(void **state)
{
	(void)state;
	assert_ready();
	ctl_ok("pot B offset 0.5");
	expect_fault("FAULT ENCODER: axis B");
}

/* Replies later than the critical limit: WATCHDOG. */
static void test_sys_fault_watchdog(void **state)
{
	(void)state;
	assert_ready();
	ctl_ok("link delay 300");
	expect_fault("FAULT WATCHDOG: ");
}

/* The connection dropped: COMM. */
static void test_sys_fault_comm(void **state)
{
	(void)state;
	assert_ready();
	ctl_ok("link drop");
	expect_fault("FAULT COMM: ");
}

/* The relay unplugged: ESTOP, motors off through the controller. */
static void test_sys_fault_estop(void **state)
{
	(void)state;
	assert_ready();
	ctl_ok("relayfault unplug");
	expect_fault("FAULT ESTOP: ");
}

/* Jammed axis while jogging: the controller's position error, MOTION. */
static void test_sys_fault_motion(void **state)
{
	(void)state;
	assert_ready();
	ctl_ok("joy A fwd");
	assert_true(axis_moved('A', 300, 3000)); /* jam it while it moves */
	ctl_ok("block A 1");
	expect_fault("FAULT MOTION: axis A");
}

/* One joystick channel held past the invalid-input timeout: INPUT. */
static void test_sys_fault_input(void **state)
{
	(void)state;
	assert_ready();
	ctl_ok("joy B fwd a");
	expect_fault("FAULT INPUT: ");
}

/* No terminal and no --calibration: exit 2 before touching anything. */
static void test_sys_no_terminal(void **state)
{
	char exe[600], cfg[300];
	char *argv[] = {exe, (char *)"-c", cfg, NULL};
	struct proc p;

	(void)state;
	memset(&rig, 0, sizeof(rig));
	path(rig.log, sizeof(rig.log), "roboelf.log");
	path(rig.cfg, sizeof(rig.cfg), "roboelf.yaml");
	snprintf(cfg, sizeof(cfg), "%s", rig.cfg);
	assert_int_equal(write_config(&rig, 1, "/nonexistent/relay", cal_file),
			 0);
	snprintf(exe, sizeof(exe), "%s/roboelf", bin);
	assert_int_equal(proc_spawn(&p, argv, NULL), 0);
	assert_int_equal(proc_wait_exit(&p, EXIT_MS, NULL), 0);
	assert_int_equal(proc_exit_code(&p), 2);
	assert_non_null(
	    strstr(proc_output(&p, PROC_STDERR), "no terminal to ask"));
	proc_kill(&p);
}

/* No relay, no start: exit 3 with the relay's reason. */
static void test_sys_no_relay(void **state)
{
	(void)state;
	memset(&rig, 0, sizeof(rig));
	rig.ctl = -1;
	path(rig.log, sizeof(rig.log), "roboelf.log");
	path(rig.cfg, sizeof(rig.cfg), "roboelf.yaml");
	assert_int_equal(
	    write_config(&rig, 1, "/tmp/roboelf-no-such-relay", cal_file), 0);
	assert_int_equal(rob_start(&rig, "file"), 0);
	assert_int_equal(proc_wait_exit(&rig.rob, EXIT_MS, NULL), 0);
	assert_int_equal(proc_exit_code(&rig.rob), 3);
	assert_non_null(
	    strstr(proc_output(&rig.rob, PROC_STDOUT), "roboelf: error: "));
	assert_non_null(strstr(proc_output(&rig.rob, PROC_STDOUT),
			       "roboelf-no-such-relay"));
}

/* A controller holding no stamped program: refused, exit 3, "galil-load"
 * named, motor power cut again. */
static void test_sys_no_program(void **state)
{
	(void)state;
	assert_int_equal(write_config(&rig, rig.sim.port, rig.relay, cal_file),
			 0);
	assert_int_equal(rob_start(&rig, "file"), 0);
	assert_int_equal(proc_wait_exit(&rig.rob, EXIT_MS, NULL), 0);
	assert_int_equal(proc_exit_code(&rig.rob), 3);
	assert_non_null(
	    strstr(proc_output(&rig.rob, PROC_STDOUT), "galil-load"));
	assert_relay_off();
}

/* A whole, stamped program of another release (vers 2.00, whose record
 * has no mneut): refused before motor power, exit 3, the versions named. */
static void test_sys_old_program(void **state)
{
	static char text[65536];
	char dir[300], p[400];
	const char *names[] = {"MANIFEST", "constants.dmc", "roboelf.dmc"};
	char *v;

	(void)state;
	path(dir, sizeof(dir), "olddmc");
	assert_int_equal(mkdir(dir, 0700), 0);
	for (int i = 0; i < 3; i++) {
		snprintf(p, sizeof(p), "dmc/%s", names[i]);
		assert_true(slurp(p, text, sizeof(text)) > 0);
		v = strstr(text, "\nvers=" ROBOELF_DMC_VERSION "\n");
		if (i == 1) {
			assert_non_null(v);
			memcpy(v, "\nvers=2.00\n", 11);
		}
		snprintf(p, sizeof(p), "%s/%s", dir, names[i]);
		assert_int_equal(write_file(p, text), 0);
	}
	assert_int_equal(galil_load_dir(&rig, dir), 0);
	assert_int_equal(write_config(&rig, rig.sim.port, rig.relay, cal_file),
			 0);
	assert_int_equal(rob_start(&rig, "file"), 0);
	assert_int_equal(proc_wait_exit(&rig.rob, EXIT_MS, NULL), 0);
	assert_int_equal(proc_exit_code(&rig.rob), 3);
	assert_non_null(strstr(proc_output(&rig.rob, PROC_STDOUT),
			       "the controller's program is version 2.00 and "
			       "this roboelf needs version " ROBOELF_DMC_VERSION
			       ": load this release's dmc/ with galil-load "
			       "(docs/technician.md)"));
	assert_relay_off();
	assert_true(motors_off(1000));
}

/* The joystick held from before start-up: at arming the operator is told
 * to release it, nothing moves and "Ready" waits; released, "Ready", and
 * then a command moves its axis. */
static void test_sys_joystick_held(void **state)
{
	char logbuf[65536];

	(void)state;
	assert_int_equal(galil_load(&rig), 0);
	assert_int_equal(write_config(&rig, rig.sim.port, rig.relay, cal_file),
			 0);
	ctl_ok("joy A fwd");
	assert_int_equal(rob_start(&rig, "file"), 0);
	assert_int_equal(
	    proc_wait_line(&rig.rob, PROC_STDOUT,
			   "roboelf: the joystick is held (axis A forward) "
			   "since arming: release it to neutral; nothing moves "
			   "until the controller has seen it released",
			   READY_MS, NULL, 0),
	    0);
	assert_false(axis_moved('A', 50, 1000));
	assert_int_equal(proc_find_line(&rig.rob, PROC_STDOUT,
					"RoboELF Ready for Use", NULL, 0),
			 -1);
	ctl_ok("joy A neutral");
	assert_ready();
	ctl_ok("joy A fwd");
	assert_true(axis_moved('A', 300, 3000));
	ctl_ok("joy A neutral");
	assert_int_equal(quit_rob(SIGTERM), 0);
	assert_true(slurp(rig.log, logbuf, sizeof(logbuf)) > 0);
	assert_non_null(strstr(logbuf, "WARN arm: joystick held (axis A "
				       "forward) since arming; waiting for "
				       "neutral"));
	assert_non_null(strstr(logbuf, "INFO RoboELF Ready for Use"));
}

/* Nothing listening at the controller address: exit 3, relay off. */
static void test_sys_no_controller(void **state)
{
	(void)state;
	assert_int_equal(write_config(&rig, 1, rig.relay, cal_file), 0);
	assert_int_equal(rob_start(&rig, "file"), 0);
	assert_int_equal(proc_wait_exit(&rig.rob, EXIT_MS, NULL), 0);
	assert_int_equal(proc_exit_code(&rig.rob), 3);
	assert_non_null(
	    strstr(proc_output(&rig.rob, PROC_STDOUT), "cannot connect"));
	assert_relay_off();
}

/* A missing calibration file without a terminal: exit 2, relay off. */
static void test_sys_missing_calibration_file(void **state)
{
	char missing[300];

	(void)state;
	path(missing, sizeof(missing), "no-such-calibration.txt");
	assert_int_equal(galil_load(&rig), 0);
	assert_int_equal(write_config(&rig, rig.sim.port, rig.relay, missing),
			 0);
	assert_int_equal(rob_start(&rig, "file"), 0);
	assert_int_equal(proc_wait_exit(&rig.rob, READY_MS, NULL), 0);
	assert_int_equal(proc_exit_code(&rig.rob), 2);
	assert_non_null(strstr(proc_output(&rig.rob, PROC_STDOUT),
			       "no-such-calibration.txt"));
	assert_relay_off();
	assert_true(motors_off(1000));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test_setup_teardown(
		test_sys_full_calibration_ready_quit, setup_full, teardown),
	    cmocka_unit_test_setup_teardown(test_sys_file_calibration_sigint,
					    setup_file, teardown),
	    cmocka_unit_test_setup_teardown(test_sys_fault_encoder, setup_file,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_sys_fault_watchdog, setup_file,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_sys_fault_comm, setup_file,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_sys_fault_estop, setup_file,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_sys_fault_motion, setup_file,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_sys_fault_input, setup_file,
					    teardown),
	    cmocka_unit_test(test_sys_no_terminal),
	    cmocka_unit_test_teardown(test_sys_no_relay, teardown),
	    cmocka_unit_test_setup_teardown(test_sys_no_program, setup_sim_only,
					    teardown),
	    cmocka_unit_test_setup_teardown(test_sys_old_program,
					    setup_sim_only, teardown),
	    cmocka_unit_test_setup_teardown(test_sys_joystick_held,
					    setup_sim_only, teardown),
	    cmocka_unit_test_setup_teardown(test_sys_no_controller,
					    setup_sim_only, teardown),
	    cmocka_unit_test_setup_teardown(test_sys_missing_calibration_file,
					    setup_sim_only, teardown),
	};

	return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
