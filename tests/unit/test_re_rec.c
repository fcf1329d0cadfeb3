/*
 * test_re_rec.c - the flight recorder's pieces that need no supervisor
 * (pc/rec/re_rec.c; the cycle itself is tested in test_re_super.c):
 * the ring's size and its refusals; no system call in the cycle's copy
 * nor in a fault's note (a seccomp filter); the dump written atomically: a
 * child that writes a 3 MB trace over and over is SIGKILLed at 40 pseudo-random
 * moments (within three times one write's duration, measured first;
 * every other one as soon as NAME.tmp exists, i.e. inside a write); after each
 * kill the trace under its final name parses as complete and is never older
 * than the one seen before, and a left NAME.tmp either parses as complete
 * (killed between the write and the rename) or is refused - never a partial
 * file accepted.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <linux/filter.h>
#include <linux/seccomp.h>
#include <sys/prctl.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#include <cmocka.h>

#include "base_clock.h"
#include "base_file.h"
#include "gl_err.h"
#include "re_rec.h"
#include "re_trace.h"

#define BIG 8000 /* records: about 3 MB of text */

static struct re_trace_rec recs[BIG];

static void hdr(struct re_trace_hdr *h)
{
	memset(h, 0, sizeof(*h));
	snprintf(h->created, sizeof(h->created), "2026-11-25T08:50:48Z");
	snprintf(h->reason, sizeof(h->reason), "request");
	snprintf(h->serial, sizeof(h->serial), "1");
	h->period_ms = 2;
	h->n_axes = 3;
	for (int a = 0; a < 3; a++)
		snprintf(h->axis[a], RE_TRACE_NAME, "%c", 'A' + a);
}

/* The ring: (seconds + after) / period records; bad sizes refused. */
static void test_rec_sizes(void **state)
{
	static struct re_rec r;
	struct re_rec_cfg c = {.seconds = 30,
			       .after_fault_s = 2,
			       .period_ms = 10,
			       .n_axes = 3,
			       .axis_names = {"A", "B", "C"}};

	(void)state;
	assert_int_equal(re_rec_init(&r, &c), GL_OK);
	assert_int_equal(r.cap, 3200);
	assert_int_equal(r.count, 0);
	assert_true(r.text_cap >= re_trace_max_bytes(3200, 3));
	re_rec_finish(&r);
	assert_int_equal(re_rec_done(&r, NULL, 0, NULL, 0, NULL, NULL), 0);
	re_rec_free(&r);
	c.axis_names[1] = "B C";
	assert_int_equal(re_rec_init(&r, &c), GL_ERR_ARG);
	c.axis_names[1] = "B";
	c.period_ms = 50;
	c.min_period_ms = 10; /* calibration's samples: 3200 again */
	assert_int_equal(re_rec_init(&r, &c), GL_OK);
	assert_int_equal(r.cap, 3200);
	re_rec_free(&r);
	c.min_period_ms = 60; /* above the period */
	assert_int_equal(re_rec_init(&r, &c), GL_ERR_ARG);
	c.min_period_ms = 0;
	c.period_ms = 0;
	assert_int_equal(re_rec_init(&r, &c), GL_ERR_ARG);
	c.period_ms = 0.001; /* 32e6 records */
	assert_int_equal(re_rec_init(&r, &c), GL_ERR_ARG);
}

static void writer_child(const char *path, char *text, size_t cap, int32_t base)
{
	struct re_trace_hdr h;

	hdr(&h);
	for (int32_t gen = base + 1;; gen++) {
		recs[0].cycle = (int32_t)gen; /* which write this is */
		if (re_rec_dump_to(path, &h, recs, BIG, text, cap) != GL_OK)
			_exit(3);
	}
}

static int parse_file(const char *path, int32_t *gen, char *err, size_t cap)
{
	struct re_trace_hdr h;
	struct re_trace_rec *r = NULL;
	char *buf;
	size_t len;
	int rc = base_file_read(path, RE_TRACE_MAX_BYTES, &buf, &len);

	if (rc < 0)
		return rc;
	rc = re_trace_parse(buf, len, &h, &r, err, cap);
	free(buf);
	if (rc == GL_OK) {
		assert_int_equal(h.n_records, BIG);
		*gen = r[0].cycle;
	}
	free(r);
	return rc;
}

/* SIGKILL at 40 moments while a big trace is rewritten in a loop. */
static void test_rec_kill_while_writing(void **state)
{
	char dir[] = "/tmp/test_re_rec.XXXXXX", path[128], tmp[140], err[256];
	size_t cap = re_trace_max_bytes(BIG, 3);
	char *text = malloc(cap);
	int32_t last = 0, gen;
	int partial = 0, complete_tmp = 0, no_tmp = 0;
	long dump_ms;
	uint64_t seed = 88172645463325252ULL;

	(void)state;
	assert_non_null(text);
	assert_non_null(mkdtemp(dir));
	snprintf(path, sizeof(path), "%s/roboelf-trace-x.csv", dir);
	snprintf(tmp, sizeof(tmp), "%s.tmp", path);
	for (int i = 0; i < BIG; i++) {
		recs[i].t_s = i * 0.002;
		recs[i].cycle = i;
		recs[i].axis[0].pot_v = 2.5 + 1e-4 * i;
	}
	/* one write here first: the kills land within 3 of its durations,
	 * so that some fall inside a write also when it is slow (ASan) */
	{
		struct re_trace_hdr h;
		struct timespec t0, t1;

		hdr(&h);
		clock_gettime(CLOCK_MONOTONIC, &t0);
		assert_int_equal(re_rec_dump_to(path, &h, recs, BIG, text, cap),
				 GL_OK);
		clock_gettime(CLOCK_MONOTONIC, &t1);
		dump_ms = (t1.tv_sec - t0.tv_sec) * 1000 +
			  (t1.tv_nsec - t0.tv_nsec) / 1000000;
		unlink(path);
	}
	for (int k = 0; k < 40; k++) {
		pid_t pid = fork();
		struct timespec ts = {0, 0};
		int st;

		assert_true(pid >= 0);
		if (pid == 0)
			writer_child(path, text, cap, 1000 * k);
		seed ^= seed << 13;
		seed ^= seed >> 7;
		seed ^= seed << 17;
		ts.tv_sec = (time_t)(seed % (uint64_t)(3 * dump_ms + 1)) / 1000;
		ts.tv_nsec = (long)(seed % (uint64_t)(3 * dump_ms + 1)) % 1000 *
			     1000000L;
		nanosleep(&ts, NULL);
		/* every other kill waits for NAME.tmp: inside a write */
		while (k % 2 && access(tmp, F_OK) != 0)
			;
		kill(pid, SIGKILL);
		waitpid(pid, &st, 0);
		assert_true(WIFSIGNALED(st));
		if (access(path, F_OK) == 0) {
			if (parse_file(path, &gen, err, sizeof(err)) != GL_OK)
				fail_msg("kill %d: '%s' refused: %s", k, path,
					 err);
			assert_true(gen >= last); /* never an older one */
			last = gen;
		}
		if (access(tmp, F_OK) != 0)
			no_tmp++;
		else if (parse_file(tmp, &gen, err, sizeof(err)) == GL_OK)
			complete_tmp++;
		else
			partial++;
		unlink(tmp); /* the next wait is for the next write's */
	}
	print_message("[ MEASURE  ] one write %ld ms; 40 kills: %d left a "
		      "partial NAME.tmp "
		      "(refused), %d a complete one, %d none; the trace always "
		      "complete (last write %d)\n",
		      dump_ms, partial, complete_tmp, no_tmp, (int)last);
	/* the 20 kills aimed at a write find NAME.tmp (a partial
	 * one, or a complete one not yet renamed) */
	assert_true(partial + complete_tmp >= 15);
	unlink(tmp);
	unlink(path);
	rmdir(dir);
	free(text);
}

static int64_t f_now(void *ud)
{
	(void)ud;
	return base_now_ns(); /* clock_gettime: the vDSO, no system call */
}

static enum re_relay_state f_relay(void *ud)
{
	(void)ud;
	return RE_RELAY_ON;
}

static const struct re_io_ops f_ops = {.now_ns = f_now, .relay_state = f_relay};

/* From here on, any system call but exit kills the process (SIGSYS). A
 * seccomp filter, not SECCOMP_MODE_STRICT: on some kernels (seen on a
 * 6.18 Firecracker guest) strict mode also forbids the time-stamp counter
 * that the vDSO's clock_gettime() reads, so the clock itself faulted
 * (SIGSEGV) although it makes no system call. */
static int forbid_syscalls(void)
{
	struct sock_filter f[] = {
	    BPF_STMT(BPF_LD | BPF_W | BPF_ABS,
		     offsetof(struct seccomp_data, nr)),
	    BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, SYS_exit, 0, 1),
	    BPF_STMT(BPF_RET | BPF_K, SECCOMP_RET_ALLOW),
	    BPF_STMT(BPF_RET | BPF_K, SECCOMP_RET_KILL_PROCESS),
	};
	struct sock_fprog prog = {.len = sizeof(f) / sizeof(f[0]), .filter = f};

	if (prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0)
		return -1;
	return prctl(PR_SET_SECCOMP, SECCOMP_MODE_FILTER, &prog);
}

/* In a child where any system call but exit kills it: 100000 cycles copied
 * into the ring and a fault's note made. The child exiting by itself with
 * 0 is the proof that neither makes a system call. */
static void test_rec_no_syscall(void **state)
{
	static struct re_super_view s;
	static struct re_rec r;
	struct re_rec_cfg c = {.seconds = 30,
			       .after_fault_s = 2,
			       .period_ms = 10,
			       .dir = "/tmp",
			       .n_axes = 3,
			       .axis_names = {"A", "B", "C"}};
	pid_t pid;
	int st;

	(void)state;
	memset(&s, 0, sizeof(s));
	s.io.ops = &f_ops;
	s.cfg.n_axes = 3;
	s.have_record = s.have_za = s.link_ok = 1;
	for (int i = 0; i < 3; i++)
		s.have_encres[i] = 1;
	snprintf(s.fault_line, sizeof(s.fault_line), "FAULT X: test");
	assert_int_equal(re_rec_init(&r, &c), GL_OK);
	re_rec_begin(&r, &s, "1");
	pid = fork();
	assert_true(pid >= 0);
	if (pid == 0) {
		const char *note;

		if (forbid_syscalls() != 0)
			syscall(SYS_exit, 2);
		for (long i = 0; i < 100000; i++) {
			s.cycles++;
			s.rec.axis[0].ref_pos += 10;
			re_rec_take(&r, &s);
		}
		s.latched = 1;
		note = re_rec_fault_note(&r, &s);
		syscall(SYS_exit, note && r.count == r.cap &&
					  !strncmp(note, "trace /tmp/", 11)
				      ? 0
				      : 3);
	}
	assert_int_equal(waitpid(pid, &st, 0), pid);
	if (WIFSIGNALED(st))
		fail_msg("the child was killed by signal %d: a system call",
			 WTERMSIG(st));
	assert_true(WIFEXITED(st));
	assert_int_equal(WEXITSTATUS(st), 0);
	re_rec_free(&r);
}

/* The commanded velocity is the change of _RP over the controller's time
 * (its 16-bit sample counter, 1 ms per sample), whatever the PC's clock
 * did between the cycles: 10 counts per sample is 10000 counts/s with
 * records 9, 10, 11 samples apart, across the counter's wrap; the same
 * record twice gives no figure (NAN). */
static void test_rec_vcmd_controller_time(void **state)
{
	static struct re_super_view s;
	static struct re_rec r;
	struct re_rec_cfg c = {.seconds = 2,
			       .after_fault_s = 1,
			       .period_ms = 10,
			       .dir = "/tmp",
			       .n_axes = 3,
			       .axis_names = {"A", "B", "C"}};
	static const int gap[] = {10, 9, 11, 10, 0};

	(void)state;
	memset(&s, 0, sizeof(s));
	s.io.ops = &f_ops;
	s.cfg.n_axes = 3;
	s.have_record = s.have_za = s.link_ok = 1;
	s.rec.sample = 65520; /* wraps after the second record */
	assert_int_equal(re_rec_init(&r, &c), GL_OK);
	re_rec_begin(&r, &s, "1");
	re_rec_take(&r, &s);
	assert_true(isnan(r.ring[0].axis[0].vcmd_cps)); /* no previous */
	for (int k = 0; k < 5; k++) {
		s.cycles++;
		s.rec.sample = (uint16_t)(s.rec.sample + gap[k]);
		s.rec.axis[0].ref_pos += 10 * gap[k];
		re_rec_take(&r, &s);
		if (gap[k])
			assert_float_equal(r.ring[k + 1].axis[0].vcmd_cps,
					   10000.0, 1e-6);
		else
			assert_true(isnan(r.ring[k + 1].axis[0].vcmd_cps));
		assert_float_equal(r.ring[k + 1].axis[1].vcmd_cps, 0, 0);
	}
	re_rec_free(&r);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_rec_sizes),
	    cmocka_unit_test(test_rec_vcmd_controller_time),
	    cmocka_unit_test(test_rec_no_syscall),
	    cmocka_unit_test(test_rec_kill_while_writing),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
