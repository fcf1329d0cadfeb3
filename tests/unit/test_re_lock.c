/*
 * test_re_lock.c - one supervisor per controller and per relay (re_lock).
 *
 * Every test points ROBOELF_LOCK_DIR (or re_lock_dir_pick's places) at a
 * temporary directory: no system directory is touched. Other holders are
 * forked children that report over a pipe and hold the lock until the
 * parent says so (or kills them); every wait has a deadline (poll on the
 * pipe, poll on a pidfd for the child's death), none sleeps and hopes.
 *
 * Covered: two processes on one key (the refusal names the holder's pid,
 * program and start time), one process twice, a link and its target,
 * equal spellings of an address, different keys side by side, the lock
 * free at once after its holder is SIGKILLed, ROBOELF_LOCK_DIR, an
 * unwritable or missing directory, the fall-back order of the lock
 * directory and its modes, long keys, bad arguments.
 */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <grp.h>
#include <poll.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cmocka.h>

#include "gl_err.h"
#include "re_lock.h"

#define WAIT_MS 2000	       /* deadline of every wait */
#define PROG	"test_re_lock" /* this program's name (/proc/self/comm) */

struct fix {
	char dir[64];	/* the test's temporary directory */
	char locks[96]; /* ROBOELF_LOCK_DIR */
	char err[RE_LOCK_ERR_MAX];
	char want[RE_LOCK_ERR_MAX];
};

static void rm_tree(const char *dir)
{
	char cmd[160];

	snprintf(cmd, sizeof(cmd), "chmod -R u+rwx '%s'; rm -rf '%s'", dir,
		 dir);
	assert_int_equal(system(cmd), 0);
}

static int setup(void **state)
{
	struct fix *f = calloc(1, sizeof(*f));

	assert_non_null(f);
	strcpy(f->dir, "/tmp/h4lock.XXXXXX");
	assert_non_null(mkdtemp(f->dir));
	snprintf(f->locks, sizeof(f->locks), "%s/locks", f->dir);
	assert_int_equal(mkdir(f->locks, 0755), 0);
	assert_int_equal(setenv(RE_LOCK_DIR_ENV, f->locks, 1), 0);
	*state = f;
	return 0;
}

static int teardown(void **state)
{
	struct fix *f = *state;

	unsetenv(RE_LOCK_DIR_ENV);
	rm_tree(f->dir);
	free(f);
	return 0;
}

/* ---- children that hold locks ---- */

struct child {
	pid_t pid;
	int report; /* child -> parent: one line per event */
	int ctl;    /* parent -> child: a byte = release and exit */
};

/* In the child: "<rc> <message>\n", then wait for the parent's byte,
 * release, report "released\n" and exit. Never returns. */
static void child_main(const char *kind, const char *key, int report, int ctl)
{
	struct re_lock lk;
	char err[RE_LOCK_ERR_MAX], line[RE_LOCK_ERR_MAX + 16], b;
	int rc, n;

	re_lock_init(&lk);
	rc = re_lock_acquire(&lk, kind, key, err, sizeof(err));
	n = snprintf(line, sizeof(line), "%d %s\n", rc, err);
	if (write(report, line, (size_t)n) != n)
		_exit(2);
	if (read(ctl, &b, 1) != 1)
		_exit(3);
	re_lock_release(&lk);
	if (write(report, "released\n", 9) != 9)
		_exit(4);
	_exit(0);
}

/* Read one line from @fd within WAIT_MS. */
static void read_line(int fd, char *buf, size_t cap)
{
	struct pollfd p = {.fd = fd, .events = POLLIN};
	size_t n = 0;

	while (n + 1 < cap) {
		if (poll(&p, 1, WAIT_MS) != 1)
			fail_msg("no line from the child within %d ms",
				 WAIT_MS);
		if (read(fd, buf + n, 1) != 1)
			fail_msg("the child closed its pipe");
		if (buf[n++] == '\n')
			break;
	}
	buf[n] = '\0';
}

/* Fork a child that takes @kind @key; return once it has reported. */
static void child_start(struct child *c, const char *kind, const char *key,
			char *line, size_t cap)
{
	int rep[2], ctl[2];

	assert_int_equal(pipe(rep), 0);
	assert_int_equal(pipe(ctl), 0);
	c->pid = fork();
	assert_true(c->pid >= 0);
	if (c->pid == 0) {
		close(rep[0]);
		close(ctl[1]);
		child_main(kind, key, rep[1], ctl[0]);
	}
	close(rep[1]);
	close(ctl[0]);
	c->report = rep[0];
	c->ctl = ctl[1];
	read_line(c->report, line, cap);
}

/* Wait (deadline WAIT_MS) for the child's death, reap it; exit status. */
static int child_reap(struct child *c)
{
	int pfd = (int)syscall(SYS_pidfd_open, c->pid, 0), status = -1;
	struct pollfd p = {.fd = pfd, .events = POLLIN};

	assert_true(pfd >= 0);
	if (poll(&p, 1, WAIT_MS) != 1)
		fail_msg("child %d still alive after %d ms", (int)c->pid,
			 WAIT_MS);
	close(pfd);
	assert_int_equal(waitpid(c->pid, &status, 0), c->pid);
	close(c->report);
	if (c->ctl >= 0)
		close(c->ctl);
	return status;
}

/* ---- helpers ---- */

static time_t parse_local(const char *s)
{
	struct tm tm;

	memset(&tm, 0, sizeof(tm));
	if (sscanf(s, "%4d-%2d-%2d %2d:%2d:%2d", &tm.tm_year, &tm.tm_mon,
		   &tm.tm_mday, &tm.tm_hour, &tm.tm_min, &tm.tm_sec) != 6)
		fail_msg("not a local time: '%s'", s);
	tm.tm_year -= 1900;
	tm.tm_mon -= 1;
	tm.tm_isdst = -1;
	return mktime(&tm);
}

/*
 * @msg must be exactly "<what> is already supervised by test_re_lock (pid
 * <pid>, since YYYY-MM-DD HH:MM:SS)" with the time in [@t0, @t1].
 */
static void refused_by(const char *msg, const char *what, long pid, time_t t0,
		       time_t t1)
{
	char prefix[RE_LOCK_ERR_MAX];
	size_t n;
	time_t t;

	n = (size_t)snprintf(
	    prefix, sizeof(prefix),
	    "%s is already supervised by " PROG " (pid %ld, since ", what, pid);
	if (strncmp(msg, prefix, n))
		fail_msg("message '%s', expected it to start '%s'", msg,
			 prefix);
	assert_int_equal(strlen(msg), n + 19 + 1);
	assert_int_equal(msg[n + 19], ')');
	t = parse_local(msg + n);
	assert_true(t >= t0 && t <= t1);
}

/* The lock file's one line: "pid=<pid> program=test_re_lock since=...". */
static void described(const char *path, long pid)
{
	char line[256], want[64];
	FILE *fp = fopen(path, "r");
	size_t n;

	assert_non_null(fp);
	assert_non_null(fgets(line, sizeof(line), fp));
	fclose(fp);
	n = (size_t)snprintf(want, sizeof(want),
			     "pid=%ld program=" PROG " since=", pid);
	assert_memory_equal(line, want, n);
	assert_int_equal(strlen(line), n + 19 + 1);
	(void)parse_local(line + n);
}

static void lock_ok(struct fix *f, struct re_lock *lk, const char *kind,
		    const char *key)
{
	re_lock_init(lk);
	if (re_lock_acquire(lk, kind, key, f->err, sizeof(f->err)) != GL_OK)
		fail_msg("re_lock_acquire(%s, %s): %s", kind, key, f->err);
	assert_string_equal(f->err, "");
	assert_true(lk->fd >= 0);
}

/* ---- tests ---- */

/* One key, two processes: the second is refused and told the holder's
 * pid, program and start time; free again once the holder releases. */
static void test_lock_two_processes(void **state)
{
	struct fix *f = *state;
	struct child c;
	struct re_lock lk;
	char line[RE_LOCK_ERR_MAX + 16];
	time_t t0 = time(NULL), t1;

	child_start(&c, "controller", "127.0.0.1:23023", line, sizeof(line));
	assert_string_equal(line, "0 \n");
	t1 = time(NULL);
	re_lock_init(&lk);
	assert_int_equal(re_lock_acquire(&lk, "controller", "127.0.0.1:23023",
					 f->err, sizeof(f->err)),
			 GL_ERR_BUSY);
	refused_by(f->err, "controller 127.0.0.1:23023", (long)c.pid, t0, t1);
	assert_int_equal(lk.fd, -1);
	assert_string_equal(lk.path, "");
	/* Another spelling of the same address (leading zeros). */
	assert_int_equal(re_lock_acquire(&lk, "controller", "127.0.0.1:023023",
					 f->err, sizeof(f->err)),
			 GL_ERR_BUSY);
	refused_by(f->err, "controller 127.0.0.1:23023", (long)c.pid, t0, t1);
	assert_int_equal(write(c.ctl, "r", 1), 1);
	read_line(c.report, line, sizeof(line));
	assert_string_equal(line, "released\n");
	lock_ok(f, &lk, "controller", "127.0.0.1:23023");
	described(lk.path, (long)getpid());
	assert_int_equal(child_reap(&c), 0);
	re_lock_release(&lk);
}

/* One process twice (two open files): refused with its own pid; a held
 * handle cannot acquire again; release, then acquire again. */
static void test_lock_same_process(void **state)
{
	struct fix *f = *state;
	struct re_lock a, b;
	time_t t0 = time(NULL);

	lock_ok(f, &a, "controller", "10.0.0.2");
	re_lock_init(&b);
	assert_int_equal(re_lock_acquire(&b, "controller", "10.0.0.2:23",
					 f->err, sizeof(f->err)),
			 GL_ERR_BUSY);
	refused_by(f->err, "controller 10.0.0.2:23", (long)getpid(), t0,
		   time(NULL));
	assert_int_equal(re_lock_acquire(&a, "controller", "10.0.0.9", f->err,
					 sizeof(f->err)),
			 GL_ERR_ARG);
	assert_string_equal(f->err, "cannot lock: invalid arguments");
	re_lock_release(&a);
	assert_int_equal(a.fd, -1);
	re_lock_release(&a); /* no-op */
	re_lock_release(NULL);
	lock_ok(f, &b, "controller", "10.0.0.2");
	re_lock_release(&b);
}

/* A symbolic link and its target (and "." in the path) are one relay. */
static void test_lock_link_and_target(void **state)
{
	struct fix *f = *state;
	struct re_lock a, b;
	char dev[128], link[128], dotted[128], real[256], what[300];
	time_t t0 = time(NULL);
	int fd;

	snprintf(dev, sizeof(dev), "%s/dev", f->dir);
	snprintf(link, sizeof(link), "%s/link", f->dir);
	snprintf(dotted, sizeof(dotted), "%s/./dev", f->dir);
	fd = open(dev, O_WRONLY | O_CREAT, 0644);
	assert_true(fd >= 0);
	close(fd);
	assert_int_equal(symlink("dev", link), 0);
	assert_non_null(realpath(dev, real));
	snprintf(what, sizeof(what), "relay %s", real);
	lock_ok(f, &a, "relay", link);
	re_lock_init(&b);
	assert_int_equal(
	    re_lock_acquire(&b, "relay", dev, f->err, sizeof(f->err)),
	    GL_ERR_BUSY);
	refused_by(f->err, what, (long)getpid(), t0, time(NULL));
	assert_int_equal(
	    re_lock_acquire(&b, "relay", dotted, f->err, sizeof(f->err)),
	    GL_ERR_BUSY);
	re_lock_release(&a);
	lock_ok(f, &b, "relay", dev);
	re_lock_release(&b);
}

/* A holder that has not written its description yet (it locks first):
 * the refusal says "another process". */
static void test_lock_holder_unknown(void **state)
{
	struct fix *f = *state;
	struct re_lock lk;
	char path[RE_LOCK_PATH_MAX];
	int fd;

	lock_ok(f, &lk, "controller", "10.0.0.2");
	memcpy(path, lk.path, sizeof(path));
	re_lock_release(&lk);
	fd = open(path, O_RDWR);
	assert_true(fd >= 0);
	assert_int_equal(flock(fd, LOCK_EX | LOCK_NB), 0);
	assert_int_equal(re_lock_acquire(&lk, "controller", "10.0.0.2", f->err,
					 sizeof(f->err)),
			 GL_ERR_BUSY);
	assert_string_equal(f->err, "controller 10.0.0.2:23 is already "
				    "supervised by another process");
	close(fd);
	lock_ok(f, &lk, "controller", "10.0.0.2");
	re_lock_release(&lk);
}

/* Different keys and kinds side by side; the file names. */
static void test_lock_keys_coexist(void **state)
{
	struct fix *f = *state;
	struct re_lock lk[5];
	char path[256];
	struct stat st;
	int i;

	lock_ok(f, &lk[0], "controller", "10.0.0.2");
	lock_ok(f, &lk[1], "controller", "10.0.0.3");
	lock_ok(f, &lk[2], "controller", "10.0.0.2:24");
	lock_ok(f, &lk[3], "controller", "[FE80::1]");
	lock_ok(f, &lk[4], "other", "10.0.0.2:23");
	snprintf(path, sizeof(path), "%s/controller-10.0.0.2%%3A23.lock",
		 f->locks);
	assert_string_equal(lk[0].path, path);
	snprintf(path, sizeof(path),
		 "%s/controller-%%5Bfe80%%3A%%3A1%%5D%%3A23.lock", f->locks);
	assert_string_equal(lk[3].path, path);
	snprintf(path, sizeof(path), "%s/other-10.0.0.2%%3A23.lock", f->locks);
	assert_string_equal(lk[4].path, path);
	for (i = 0; i < 5; i++) {
		assert_int_equal(stat(lk[i].path, &st), 0);
		assert_int_equal(st.st_mode & 0777, 0666);
		described(lk[i].path, (long)getpid());
		re_lock_release(&lk[i]);
	}
}

/* The holder is SIGKILLed: the kernel drops its lock; the next acquire
 * succeeds at once (no stale lock) and overwrites the description. */
static void test_lock_free_after_sigkill(void **state)
{
	struct fix *f = *state;
	struct child c;
	struct re_lock lk;
	char line[RE_LOCK_ERR_MAX + 16], path[256], real[128], *p;
	size_t n;
	int status;

	child_start(&c, "relay", f->locks, line, sizeof(line));
	assert_string_equal(line, "0 \n");
	/* <locks>/relay-<realpath of locks, '/' as %2F>.lock */
	assert_non_null(realpath(f->locks, real));
	n = (size_t)snprintf(path, sizeof(path), "%s/relay-", f->locks);
	for (p = real; *p; p++)
		n += (size_t)snprintf(path + n, sizeof(path) - n,
				      *p == '/' ? "%%2F" : "%c", *p);
	snprintf(path + n, sizeof(path) - n, ".lock");
	described(path, (long)c.pid);
	assert_int_equal(kill(c.pid, SIGKILL), 0);
	status = child_reap(&c);
	assert_true(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
	described(path, (long)c.pid); /* stale text, but no lock */
	lock_ok(f, &lk, "relay", f->locks);
	assert_string_equal(lk.path, path);
	described(path, (long)getpid());
	re_lock_release(&lk);
}

/* ROBOELF_LOCK_DIR is where the file goes; release empties it and
 * leaves it (lock files are never deleted). */
static void test_lock_env_dir(void **state)
{
	struct fix *f = *state;
	struct re_lock lk;
	char path[256], dir[RE_LOCK_PATH_MAX];
	struct stat st;

	assert_int_equal(re_lock_dir(dir, sizeof(dir), f->err, sizeof(f->err)),
			 GL_OK);
	assert_string_equal(dir, f->locks);
	lock_ok(f, &lk, "controller", "127.0.0.1:23023");
	snprintf(path, sizeof(path), "%s/controller-127.0.0.1%%3A23023.lock",
		 f->locks);
	assert_string_equal(lk.path, path);
	described(path, (long)getpid());
	re_lock_release(&lk);
	assert_int_equal(stat(path, &st), 0);
	assert_int_equal(st.st_size, 0);
	assert_string_equal(lk.path, "");
}

/* In the child: drop root (to nobody) if root, try the lock, report. */
static void unprivileged_try(const char *dir, int report)
{
	struct re_lock lk;
	char err[RE_LOCK_ERR_MAX], line[RE_LOCK_ERR_MAX + 16];
	int rc, n;

	if (getuid() == 0 &&
	    (setgroups(0, NULL) || setgid(65534) || setuid(65534)))
		_exit(5);
	setenv(RE_LOCK_DIR_ENV, dir, 1);
	re_lock_init(&lk);
	rc = re_lock_acquire(&lk, "controller", "127.0.0.1:23023", err,
			     sizeof(err));
	n = snprintf(line, sizeof(line), "%d %s\n", rc, err);
	_exit(write(report, line, (size_t)n) == n ? 0 : 6);
}

/* A lock directory the caller cannot write: a clear error, as an
 * unprivileged user (a root test run forks one); a missing directory and
 * a file in its place. */
static void test_lock_dir_unusable(void **state)
{
	struct fix *f = *state;
	struct child c = {0};
	struct re_lock lk;
	char ro[128], line[RE_LOCK_ERR_MAX + 16], want[RE_LOCK_ERR_MAX + 16];
	int rep[2], fd;

	snprintf(ro, sizeof(ro), "%s/ro", f->dir);
	assert_int_equal(mkdir(ro, 0555), 0);
	assert_int_equal(chmod(ro, 0555), 0);
	assert_int_equal(chmod(f->dir, 0711), 0);
	assert_int_equal(pipe(rep), 0);
	c.pid = fork();
	assert_true(c.pid >= 0);
	if (c.pid == 0)
		unprivileged_try(ro, rep[1]);
	close(rep[1]);
	c.report = rep[0];
	c.ctl = -1;
	read_line(c.report, line, sizeof(line));
	snprintf(want, sizeof(want),
		 "%d cannot create lock file '%s/controller-127.0.0.1%%3A23023"
		 ".lock': Permission denied\n",
		 GL_ERR_SYS, ro);
	assert_string_equal(line, want);
	assert_int_equal(child_reap(&c), 0);
	snprintf(ro, sizeof(ro), "%s/none", f->dir);
	setenv(RE_LOCK_DIR_ENV, ro, 1);
	re_lock_init(&lk);
	assert_int_equal(re_lock_acquire(&lk, "controller", "10.0.0.2", f->err,
					 sizeof(f->err)),
			 GL_ERR_SYS);
	snprintf(f->want, sizeof(f->want),
		 "lock directory '%s' (ROBOELF_LOCK_DIR): No such file or "
		 "directory",
		 ro);
	assert_string_equal(f->err, f->want);
	fd = open(ro, O_WRONLY | O_CREAT, 0644);
	assert_true(fd >= 0);
	close(fd);
	assert_int_equal(re_lock_acquire(&lk, "controller", "10.0.0.2", f->err,
					 sizeof(f->err)),
			 GL_ERR_SYS);
	snprintf(f->want, sizeof(f->want),
		 "lock directory '%s' (ROBOELF_LOCK_DIR): Not a directory", ro);
	assert_string_equal(f->err, f->want);
}

static mode_t mode_of(const char *path)
{
	struct stat st;

	assert_int_equal(lstat(path, &st), 0);
	return st.st_mode & 07777;
}

/* The fall-back order of the lock directory, and the modes it makes. */
static void test_lock_dir_order(void **state)
{
	struct fix *f = *state;
	char run[128], xdg[128], tmp[128], got[RE_LOCK_PATH_MAX];
	char want[256], nope[128];
	struct re_lock_places pl = {0};
	mode_t old;
	int rc;

	snprintf(run, sizeof(run), "%s/run", f->dir);
	snprintf(nope, sizeof(nope), "%s/nope/run", f->dir);
	snprintf(xdg, sizeof(xdg), "%s/xdg", f->dir);
	snprintf(tmp, sizeof(tmp), "%s/tmp", f->dir);
	assert_int_equal(mkdir(xdg, 0700), 0);
	assert_int_equal(mkdir(tmp, 01777), 0);
	/* 1. the environment first */
	pl = (struct re_lock_places){f->locks, run, xdg, tmp};
	assert_int_equal(re_lock_dir_pick(&pl, got, sizeof(got), NULL, 0),
			 GL_OK);
	assert_string_equal(got, f->locks);
	/* 2. the shared directory, created 01777 whatever the umask */
	pl.env_dir = "";
	old = umask(077);
	rc = re_lock_dir_pick(&pl, got, sizeof(got), NULL, 0);
	umask(old);
	assert_int_equal(rc, GL_OK);
	assert_string_equal(got, run);
	assert_int_equal(mode_of(run), 01777);
	assert_int_equal(re_lock_dir_pick(&pl, got, sizeof(got), NULL, 0),
			 GL_OK); /* exists: used */
	assert_string_equal(got, run);
	/* 3. cannot be created: XDG_RUNTIME_DIR/roboelf, 0700 */
	pl.run_dir = nope;
	assert_int_equal(re_lock_dir_pick(&pl, got, sizeof(got), NULL, 0),
			 GL_OK);
	snprintf(want, sizeof(want), "%s/roboelf", xdg);
	assert_string_equal(got, want);
	assert_int_equal(mode_of(want), 0700);
	/* 4. no XDG_RUNTIME_DIR: <tmp>/roboelf-locks-<uid>, 0700 */
	pl.xdg_dir = NULL;
	assert_int_equal(re_lock_dir_pick(&pl, got, sizeof(got), NULL, 0),
			 GL_OK);
	snprintf(want, sizeof(want), "%s/roboelf-locks-%lu", tmp,
		 (unsigned long)getuid());
	assert_string_equal(got, want);
	assert_int_equal(mode_of(want), 0700);
	/* ... refused when others can write it, or when it is a link */
	assert_int_equal(chmod(want, 0777), 0);
	assert_int_equal(
	    re_lock_dir_pick(&pl, got, sizeof(got), f->err, sizeof(f->err)),
	    GL_ERR_SYS);
	snprintf(f->want, sizeof(f->want),
		 "lock directory '%s' is not a private directory of this user",
		 want);
	assert_string_equal(f->err, f->want);
	assert_int_equal(rmdir(want), 0);
	assert_int_equal(symlink(xdg, want), 0);
	assert_int_equal(
	    re_lock_dir_pick(&pl, got, sizeof(got), f->err, sizeof(f->err)),
	    GL_ERR_SYS);
	assert_string_equal(f->err, f->want);
	/* a file where the shared directory should be: said, no fall-back */
	assert_int_equal(rmdir(run), 0);
	assert_int_equal(close(open(run, O_WRONLY | O_CREAT, 0644)), 0);
	pl.run_dir = run;
	assert_int_equal(
	    re_lock_dir_pick(&pl, got, sizeof(got), f->err, sizeof(f->err)),
	    GL_ERR_SYS);
	snprintf(f->want, sizeof(f->want),
		 "lock directory '%s' is not a directory", run);
	assert_string_equal(f->err, f->want);
}

/* Controller addresses as gl_link_open() parses them; relay paths. */
static void test_lock_keys(void **state)
{
	static const struct {
		const char *addr, *key;
	} ok[] = {
	    {"127.0.0.1:23023", "127.0.0.1:23023"},
	    {"10.0.0.2", "10.0.0.2:23"},
	    {"Galil.Example:0023", "galil.example:23"},
	    {"[::1]", "[::1]:23"},
	    {"[FE80::1%eth0]:65535", "[fe80::1%eth0]:65535"},
	};
	static const char *const bad[] = {
	    "",		  "::1",     "host:", "host:0",
	    "host:65536", "host:2x", "[::1",  "[::1]x",
	};
	char key[64];
	size_t i;

	(void)state;
	for (i = 0; i < sizeof(ok) / sizeof(ok[0]); i++) {
		assert_int_equal(
		    re_lock_controller_key(ok[i].addr, key, sizeof(key)),
		    GL_OK);
		assert_string_equal(key, ok[i].key);
	}
	for (i = 0; i < sizeof(bad) / sizeof(bad[0]); i++)
		assert_int_equal(
		    re_lock_controller_key(bad[i], key, sizeof(key)),
		    GL_ERR_ARG);
	assert_int_equal(re_lock_controller_key("10.0.0.2", key, 11),
			 GL_ERR_OVERFLOW);
	assert_int_equal(re_lock_relay_key("/tmp/../tmp/.", key, sizeof(key)),
			 GL_OK);
	assert_string_equal(key, "/tmp");
	errno = 0;
	assert_int_equal(
	    re_lock_relay_key("/nonexistent/relay", key, sizeof(key)),
	    GL_ERR_SYS);
	assert_int_equal(errno, ENOENT);
}

/* Bad arguments; a relay that does not exist; an address refused. */
static void test_lock_bad_arguments(void **state)
{
	struct fix *f = *state;
	struct re_lock lk;
	static const char *const kinds[] = {"", "Controller", "relay-2", "a_b"};
	size_t i;

	re_lock_init(&lk);
	assert_int_equal(re_lock_acquire(NULL, "relay", "/x", NULL, 0),
			 GL_ERR_ARG);
	assert_int_equal(re_lock_acquire(&lk, "relay", "", NULL, 0),
			 GL_ERR_ARG);
	assert_int_equal(re_lock_acquire(&lk, "relay", NULL, NULL, 0),
			 GL_ERR_ARG);
	for (i = 0; i < sizeof(kinds) / sizeof(kinds[0]); i++)
		assert_int_equal(
		    re_lock_acquire(&lk, kinds[i], "k", f->err, sizeof(f->err)),
		    GL_ERR_ARG);
	assert_int_equal(
	    re_lock_acquire(&lk, "controller", "::1", f->err, sizeof(f->err)),
	    GL_ERR_ARG);
	assert_string_equal(f->err,
			    "cannot lock controller: invalid address '::1'");
	assert_int_equal(re_lock_acquire(&lk, "relay", "/nonexistent/relay",
					 f->err, sizeof(f->err)),
			 GL_ERR_SYS);
	assert_string_equal(f->err, "cannot lock relay '/nonexistent/relay': "
				    "No such file or directory");
	assert_int_equal(lk.fd, -1);
}

/* Keys too long for a file name: cut and hashed; keys that differ only
 * after the cut are still two locks. */
static void test_lock_long_keys(void **state)
{
	struct fix *f = *state;
	struct re_lock a, b;
	char k1[400], k2[400], *base;

	memset(k1, 'x', sizeof(k1) - 1);
	k1[sizeof(k1) - 1] = '\0';
	memcpy(k2, k1, sizeof(k1));
	k2[sizeof(k2) - 2] = 'y';
	lock_ok(f, &a, "other", k1);
	lock_ok(f, &b, "other", k2);
	assert_string_not_equal(a.path, b.path);
	base = strrchr(a.path, '/') + 1;
	assert_int_equal(strlen(base), 6 + 160 + 17 + 5);
	assert_int_equal(strncmp(base, "other-xxxx", 10), 0);
	re_lock_release(&a);
	re_lock_release(&b);
}

#define T(fn) cmocka_unit_test_setup_teardown(fn, setup, teardown)

int main(void)
{
	static const struct CMUnitTest tests[] = {
	    T(test_lock_two_processes),	  T(test_lock_same_process),
	    T(test_lock_link_and_target), T(test_lock_keys_coexist),
	    T(test_lock_holder_unknown),  T(test_lock_free_after_sigkill),
	    T(test_lock_env_dir),	  T(test_lock_dir_unusable),
	    T(test_lock_dir_order),	  T(test_lock_keys),
	    T(test_lock_bad_arguments),	  T(test_lock_long_keys),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
