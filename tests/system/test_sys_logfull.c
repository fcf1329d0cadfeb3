/*
 * test_sys_logfull.c - a full log disk (docs/safety.md H11, D30), on the
 * whole system: galil-sim running dmc/ (downloaded by galil-load), roboelf
 * supervising it through the virtual relay. A failed log write is shown
 * and retried once a second, never silent, and the FAULT line of a fault
 * found meanwhile is shown all the same and in time; once space is freed
 * the log is written again with the FAULT entry in it.
 *
 * One full calibration for the binary (group setup), then the case on a
 * fresh galil-sim with `--calibration file`. It mounts a tmpfs for the log
 * when run as root (else the log is /dev/full). It asserts the outcome,
 * the exact texts (sys_exact_h.h) and the reaction time against the
 * deadlines of docs/safety.md section 3 plus SX_SLACK_MS; the group
 * teardown prints the summary table.
 *
 * Environment: ROBOELF_SYS_FILTER=PATTERN runs only the matching cases;
 * ROBOELF_KEEP=1 keeps the temporary directory; ROBOELF_SYS_CAL=FILE
 * reuses a calibration (development).
 */
#include <errno.h>
#include <math.h>
#include <poll.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <fcntl.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <cmocka.h>

#include "sys_exact_h.h"

static struct sys_env env;
static struct sx_fixture fx;
static struct sys_case cs; /* the first roboelf and its controller */
static char log_mnt[SYS_PATH_MAX + 8]; /* a tmpfs mounted here, or "" */

static int group_setup(void **state)
{
	(void)state;
	return sx_group_setup(&fx, &env);
}

static int group_teardown(void **state)
{
	(void)state;
	return sx_group_teardown(&fx, 0);
}

static void unmount_log(void)
{
	if (!log_mnt[0])
		return;
	if (umount2(log_mnt, MNT_DETACH) < 0)
		print_message("[   WARN   ] cannot unmount '%s': %s\n", log_mnt,
			      strerror(errno));
	rmdir(log_mnt);
	log_mnt[0] = '\0';
}

static int case_teardown(void **state)
{
	(void)state;
	sys_case_stop(&cs);
	unmount_log();
	return 0;
}

/* ---- root cause: a full disk --------------------------------------------- */

/* A tiny tmpfs for the log (root only). Return: 0 mounted, -1 not. */
static int mount_logfs(void)
{
	snprintf(log_mnt, sizeof(log_mnt), "%s/logfs", env.dir);
	if (geteuid() != 0 || mkdir(log_mnt, 0700) < 0)
		goto not_mounted;
	if (mount("tmpfs", log_mnt, "tmpfs", MS_NOSUID | MS_NODEV,
		  "size=256k,mode=0700") == 0)
		return 0;
	rmdir(log_mnt);
not_mounted:
	log_mnt[0] = '\0';
	return -1;
}

/* Append @n bytes to @path: a line of '#' ending in a newline. */
static void pad_log(const char *path, size_t n)
{
	char buf[8192];
	int fd = open(path, O_WRONLY | O_APPEND | O_CLOEXEC);

	if (fd < 0 || n == 0 || n > sizeof(buf))
		fail_msg("cannot pad '%s' by %zu bytes", path, n);
	memset(buf, '#', n);
	buf[n - 1] = '\n';
	if (write(fd, buf, n) != (ssize_t)n)
		fail_msg("cannot pad '%s': %s", path, strerror(errno));
	close(fd);
}

/* Write @fd full until the filesystem refuses (ENOSPC). */
static void fill_fd(int fd)
{
	static char chunk[65536];
	size_t sz = sizeof(chunk);

	while (sz >= 1) {
		ssize_t n = write(fd, chunk, sz);

		if (n < 0 && errno != ENOSPC)
			fail_msg("filling the disk: %s", strerror(errno));
		if (n <= 0)
			sz /= 2;
	}
}

/*
 * Fill the log's filesystem so that every write to the log fails: the
 * log's last block padded to its end (a write into it would still
 * succeed), then every free block taken by @filler. Checked: no block
 * free, the log ending on a block boundary (roboelf may write a line
 * meanwhile: then padded again).
 */
static void fill_disk(const char *log, const char *filler)
{
	struct statvfs vfs;
	struct stat st;
	int fd = open(filler, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);

	if (fd < 0 || statvfs(log, &vfs) < 0)
		fail_msg("cannot fill '%s': %s", filler, strerror(errno));
	for (int k = 0; k < 3; k++) {
		if (stat(log, &st) < 0)
			fail_msg("stat '%s': %s", log, strerror(errno));
		if (st.st_size % (off_t)vfs.f_bsize != 0)
			pad_log(log,
				vfs.f_bsize -
				    (size_t)(st.st_size % (off_t)vfs.f_bsize));
		fill_fd(fd);
		if (stat(log, &st) == 0 && st.st_size % (off_t)vfs.f_bsize == 0)
			break;
	}
	close(fd);
	if (statvfs(log, &vfs) < 0 || vfs.f_bavail != 0 ||
	    st.st_size % (off_t)vfs.f_bsize != 0)
		fail_msg("the disk is not full: %lu blocks free, log %lld "
			 "bytes",
			 (unsigned long)vfs.f_bavail, (long long)st.st_size);
}

/* Does the file @path hold a line containing @a? */
static int file_has(const char *path, const char *a)
{
	char line[4096];
	FILE *f = fopen(path, "r");
	int found = 0;

	while (f && !found && fgets(line, sizeof(line), f))
		found = strstr(line, a) != NULL;
	if (f)
		fclose(f);
	return found;
}

/*
 * 7. A full disk. As root: the log on a 256 KiB tmpfs, filled after Ready
 * (fill_disk()); otherwise the log is a symbolic link to /dev/full (every
 * write fails from the start). Then a fault the PC finds at rest (pot A
 * offset 0.5 V, deadline (2 + k) P, D1 of docs/safety.md). The FAULT line
 * is shown all the same and in time; the screen says the log cannot be
 * written, once a second; on the tmpfs, once space is freed, it says the
 * log is written again and the FAULT entry is in the log.
 */
#define RETRY_MS 1000 /* roboelf retries the log once a second */

static void test_log_full(void **state)
{
	struct sx_row *r = sx_row_begin("7 full disk");
	char log[SYS_PATH_MAX + 32], filler[SYS_PATH_MAX + 32];
	char logopt[SYS_PATH_MAX + 40], warn[SYS_PATH_MAX + 160];
	char line[SX_TEXT_MAX], msg[SX_TEXT_MAX], tpl[1024], how[64];
	char *args[] = {(char *)"--log", logopt, NULL};
	struct sys_opts o = {.re_args = args};
	double t, t_relay, t_mo, num[7],
	    d = (2.0 + env.persistence) * sx_p(&env);
	long long w1, w2;
	int k;
	int i, tmpfs = mount_logfs() == 0;

	(void)state;
	if (tmpfs) {
		snprintf(log, sizeof(log), "%s/roboelf.log", log_mnt);
		snprintf(filler, sizeof(filler), "%s/filler", log_mnt);
		snprintf(how, sizeof(how), "tmpfs filled after Ready");
	} else {
		snprintf(log, sizeof(log), "%s/full.log", env.dir);
		unlink(log);
		if (symlink("/dev/full", log) < 0)
			fail_msg("symlink '%s': %s", log, strerror(errno));
		snprintf(how, sizeof(how), "log -> /dev/full (not root)");
	}
	snprintf(logopt, sizeof(logopt), "%s", log);
	sx_start_with(&cs, &fx, &o);
	if (tmpfs)
		fill_disk(log, filler);
	t = sx_inject(&cs, "inject: ", "pot A offset 0.5");
	if (sys_wait_fault(&cs, SX_FAULT_WAIT_MS, line, sizeof(line)) < 0)
		fail_msg("%s", cs.err);
	sx_row_text(r, line);
	i = sx_wait_event(&cs, "relay off", NULL, t, 3000);
	t_relay = cs.ev[i].t_ms - t;
	t_mo = sx_wait_motors_off(&cs, t, 3000) - t;
	snprintf(warn, sizeof(warn),
		 "roboelf: WARNING: cannot write the log '%s' (No space left "
		 "on device): the last entry is not on disk; retrying",
		 log);
	if (proc_wait_line(&cs.re, PROC_STDOUT, "roboelf: WARNING: ",
			   2 * RETRY_MS, msg, sizeof(msg)) < 0)
		fail_msg("no 'cannot write the log' message after the "
			 "fault\n--- stdout:\n%s",
			 proc_output(&cs.re, PROC_STDOUT));
	w1 = proc_now_ms();
	sx_expect_text("the log message", warn, msg, NULL, 0);
	if (proc_wait_line(&cs.re, PROC_STDOUT, "roboelf: WARNING: ",
			   2 * RETRY_MS, msg, sizeof(msg)) < 0)
		fail_msg("the log was not retried within %d ms", 2 * RETRY_MS);
	w2 = proc_now_ms();
	sx_expect_text("the repeated log message", warn, msg, NULL, 0);
	sx_row_reaction(r,
			"%s: relay off %.0f ms (deadline %.0f), motors off "
			"%.0f ms (deadline %.0f); log retried after %lld ms",
			how, t_relay, d, t_mo, d + SYS_MAINMS, w2 - w1);
	k = sx_tpl_encpot(&env, tpl, sizeof(tpl), 0);
	sx_not_own_request(line);
	sx_expect_text("the FAULT line", tpl, line, num, 7);
	sx_check_encpot_units(&env, num, k, 0, line);
	if (t_relay > d + SX_SLACK_MS || t_mo > d + SYS_MAINMS + SX_SLACK_MS)
		fail_msg("too late: relay off %.0f ms, motors off %.0f ms",
			 t_relay, t_mo);
	if (w2 - w1 < RETRY_MS / 2 || w2 - w1 > RETRY_MS * 3 / 2 + SX_SLACK_MS)
		fail_msg("retried after %lld ms, not once a second", w2 - w1);
	if (tmpfs) {
		snprintf(warn, sizeof(warn),
			 "roboelf: the log '%s' is written again", log);
		unlink(filler);
		if (proc_wait_line(&cs.re, PROC_STDOUT, "roboelf: the log ",
				   2 * RETRY_MS, msg, sizeof(msg)) < 0)
			fail_msg("the log was not written again within %d ms "
				 "of freeing the disk",
				 2 * RETRY_MS);
		sx_expect_text("the log message", warn, msg, NULL, 0);
		if (!file_has(log, line))
			fail_msg("the FAULT entry is not in the log after the "
				 "disk was freed");
	}
	sx_row_pass(r, "%s: FAULT shown, log retried%s", how,
		    tmpfs ? ", written once freed" : "");
}

#define T(f) cmocka_unit_test_teardown(f, case_teardown)

int main(void)
{
	const struct CMUnitTest tests[] = {
	    T(test_log_full),
	};
	const char *filter = getenv("ROBOELF_SYS_FILTER");

	if (filter && *filter)
		cmocka_set_test_filter(filter);
	return cmocka_run_group_tests(tests, group_setup, group_teardown);
}
