/*
 * re_lock.c - one supervisor per controller and per relay: flock() on a
 * file named after the thing supervised. See re_lock.h.
 *
 * Decisions:
 * - flock(), not fcntl() record locks: an flock lock belongs to the open
 *   file description, so two opens in one process also exclude each other
 *   (a second supervisor object in the same process is refused too), and
 *   closing an unrelated descriptor of the same file does not drop it.
 * - The file is opened without O_CREAT first and created with O_EXCL only
 *   when missing: in a sticky, world-writable directory (/run/lock) Linux
 *   refuses O_CREAT on another user's file (fs.protected_regular), and
 *   O_NOFOLLOW refuses a link planted in its place. Files are made 0666
 *   so that every user's supervisor can open and lock them; only the
 *   holder writes the description, and nothing reads it but the message.
 * - The description is written over the old one from offset 0 and then
 *   truncated to its length, so that a reader sees a whole line (old or
 *   new) except in a window of two system calls; a reader that finds no
 *   line says "another process".
 * - Lock files are never deleted (see re_lock.h).
 */
#include "re_lock.h"

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "gl_err.h"
#include "gl_hash.h"
#include "gl_link.h"

#define KIND_MAX  32  /* bytes of a kind, without the NUL */
#define NAME_KEEP 160 /* encoded key bytes kept in a file name */
#define NAME_CAP  256 /* a file name, with the NUL (NAME_MAX 255) */
#define DESC_MAX  256 /* bytes of the holder's description */
#define PROG_MAX  64  /* bytes of the program name, with the NUL */

static int fail(char *err, size_t errlen, int rc, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static int fail(char *err, size_t errlen, int rc, const char *fmt, ...)
{
	int saved = errno;
	va_list ap;

	if (err && errlen) {
		va_start(ap, fmt);
		vsnprintf(err, errlen, fmt, ap);
		va_end(ap);
	}
	errno = saved;
	return rc;
}

void re_lock_init(struct re_lock *lk)
{
	lk->fd = -1;
	lk->path[0] = '\0';
}

/* ---- keys ---- */

int re_lock_controller_key(const char *addr, char *key, size_t cap)
{
	char host[256], port[8];
	size_t i;
	int n;

	if (!addr || !key ||
	    gl_link_addr_split(addr, host, sizeof(host), port, sizeof(port)))
		return GL_ERR_ARG;
	/* Host names and IPv6 digits are case-blind; a zone (%eth0) not. */
	for (i = 0; host[i] && host[i] != '%'; i++)
		host[i] = (char)tolower((unsigned char)host[i]);
	n = snprintf(key, cap, strchr(host, ':') ? "[%s]:%ld" : "%s:%ld", host,
		     strtol(port, NULL, 10));
	return n < 0 || (size_t)n >= cap ? GL_ERR_OVERFLOW : GL_OK;
}

int re_lock_relay_key(const char *path, char *key, size_t cap)
{
	char real[PATH_MAX];

	if (!path || !key || !path[0]) {
		errno = ENOENT;
		return GL_ERR_SYS;
	}
	if (!realpath(path, real))
		return GL_ERR_SYS;
	if (strlen(real) >= cap)
		return GL_ERR_OVERFLOW;
	memcpy(key, real, strlen(real) + 1);
	return GL_OK;
}

/* The key of @kind: normalised as its kind asks. */
static int normalise(const char *kind, const char *key, char *norm, size_t cap,
		     char *err, size_t errlen)
{
	int rc;

	if (!strcmp(kind, "controller")) {
		rc = re_lock_controller_key(key, norm, cap);
		return rc ? fail(err, errlen, rc,
				 "cannot lock controller: "
				 "invalid address '%s'",
				 key)
			  : GL_OK;
	}
	if (!strcmp(kind, "relay")) {
		rc = re_lock_relay_key(key, norm, cap);
		return rc ? fail(err, errlen, rc, "cannot lock relay '%s': %s",
				 key,
				 rc == GL_ERR_SYS ? strerror(errno)
						  : "path too long")
			  : GL_OK;
	}
	if (strlen(key) >= cap)
		return fail(err, errlen, GL_ERR_ARG,
			    "cannot lock %s: key too "
			    "long",
			    kind);
	memcpy(norm, key, strlen(key) + 1);
	return GL_OK;
}

/* "<kind>-<key percent-encoded>.lock"; a long key is cut after NAME_KEEP
 * bytes and followed by "-<FNV-1a 64 of the whole key>". */
static void lock_name(const char *kind, const char *key, char *name)
{
	static const char hex[] = "0123456789ABCDEF";
	size_t n = (size_t)snprintf(name, NAME_CAP, "%s-", kind), start = n;
	const unsigned char *k = (const unsigned char *)key;
	bool plain;

	for (; *k; k++) {
		plain = isalnum(*k) || *k == '.' || *k == '-' || *k == '_';
		if (n - start + (plain ? 1 : 3) > NAME_KEEP)
			break;
		if (plain) {
			name[n++] = (char)*k;
			continue;
		}
		name[n++] = '%';
		name[n++] = hex[*k >> 4];
		name[n++] = hex[*k & 15];
	}
	if (*k)
		n += (size_t)snprintf(name + n, NAME_CAP - n, "-%016llx",
				      (unsigned long long)gl_fnv1a64(
					  GL_FNV64_INIT, key, strlen(key)));
	snprintf(name + n, NAME_CAP - n, ".lock");
}

static bool kind_ok(const char *kind)
{
	size_t n = strlen(kind);

	return n > 0 && n <= KIND_MAX &&
	       strspn(kind, "abcdefghijklmnopqrstuvwxyz") == n;
}

/* ---- the directory ---- */

/* An existing directory? If not, errno says why (ENOTDIR: no directory). */
static bool is_dir(const char *path)
{
	struct stat st;

	if (stat(path, &st) < 0)
		return false;
	if (S_ISDIR(st.st_mode))
		return true;
	errno = ENOTDIR;
	return false;
}

/* Make @dir with exactly @mode (umask aside) unless it exists: 0 or -1. */
static int make_dir(const char *dir, mode_t mode)
{
	if (!mkdir(dir, mode))
		return chmod(dir, mode);
	if (errno != EEXIST)
		return -1;
	if (is_dir(dir))
		return 0;
	if (errno == ENOTDIR)
		errno = EEXIST; /* something else is there */
	return -1;
}

/* The last resort: refused unless a directory of ours nobody else can
 * write (/tmp is shared: the name may have been taken). */
static int private_dir(const char *dir, char *err, size_t errlen)
{
	struct stat st;

	if (make_dir(dir, 0700) < 0 && errno != EEXIST)
		return fail(err, errlen, GL_ERR_SYS,
			    "cannot create lock directory '%s': %s", dir,
			    strerror(errno));
	if (lstat(dir, &st) < 0)
		return fail(err, errlen, GL_ERR_SYS, "lock directory '%s': %s",
			    dir, strerror(errno));
	if (!S_ISDIR(st.st_mode) || st.st_uid != getuid() ||
	    (st.st_mode & 022)) {
		errno = EPERM;
		return fail(err, errlen, GL_ERR_SYS,
			    "lock directory '%s' is not a private directory "
			    "of this user",
			    dir);
	}
	return GL_OK;
}

static int put_dir(char *dir, size_t cap, const char *path)
{
	if (snprintf(dir, cap, "%s", path) >= (int)cap)
		return GL_ERR_OVERFLOW;
	return GL_OK;
}

int re_lock_dir_pick(const struct re_lock_places *pl, char *dir, size_t cap,
		     char *err, size_t errlen)
{
	char path[RE_LOCK_PATH_MAX];

	if (pl->env_dir && pl->env_dir[0]) {
		if (!is_dir(pl->env_dir))
			return fail(err, errlen, GL_ERR_SYS,
				    "lock directory '%s' (" RE_LOCK_DIR_ENV
				    "): %s",
				    pl->env_dir, strerror(errno));
		return put_dir(dir, cap, pl->env_dir);
	}
	if (!make_dir(pl->run_dir, 01777))
		return put_dir(dir, cap, pl->run_dir);
	if (errno == EEXIST) /* something else is there: say so */
		return fail(err, errlen, GL_ERR_SYS,
			    "lock directory '%s' is not a directory",
			    pl->run_dir);
	if (pl->xdg_dir && pl->xdg_dir[0]) {
		snprintf(path, sizeof(path), "%s/roboelf", pl->xdg_dir);
		if (!make_dir(path, 0700))
			return put_dir(dir, cap, path);
	}
	snprintf(path, sizeof(path), "%s/roboelf-locks-%lu", pl->tmp_dir,
		 (unsigned long)getuid());
	if (private_dir(path, err, errlen))
		return GL_ERR_SYS;
	return put_dir(dir, cap, path);
}

int re_lock_dir(char *dir, size_t cap, char *err, size_t errlen)
{
	const struct re_lock_places pl = {
	    .env_dir = getenv(RE_LOCK_DIR_ENV),
	    .run_dir = RE_LOCK_RUN_DIR,
	    .xdg_dir = getenv("XDG_RUNTIME_DIR"),
	    .tmp_dir = "/tmp",
	};

	return re_lock_dir_pick(&pl, dir, cap, err, errlen);
}

/* ---- the file ---- */

/* Open the lock file, creating it (0666) when missing. */
static int open_file(const char *path, char *err, size_t errlen)
{
	int fd, tries;

	for (tries = 0; tries < 3; tries++) {
		fd = open(path, O_RDWR | O_CLOEXEC | O_NOFOLLOW);
		if (fd >= 0)
			return fd;
		if (errno != ENOENT)
			return fail(err, errlen, -1,
				    "cannot open lock file '%s': %s", path,
				    strerror(errno));
		fd = open(path, O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
		if (fd >= 0) {
			fchmod(fd, 0666);
			return fd;
		}
		if (errno != EEXIST)
			break;
	}
	return fail(err, errlen, -1, "cannot create lock file '%s': %s", path,
		    strerror(errno));
}

/* The program's name (/proc/self/comm), spaces made '_'. */
static void program_name(char *buf, size_t cap)
{
	FILE *f = fopen("/proc/self/comm", "re");
	size_t i;

	if (!f || !fgets(buf, (int)cap, f))
		snprintf(buf, cap, "unknown");
	if (f)
		fclose(f);
	buf[strcspn(buf, "\n")] = '\0';
	for (i = 0; buf[i]; i++)
		if (isspace((unsigned char)buf[i]))
			buf[i] = '_';
}

/* "pid=<pid> program=<name> since=<local time>" over the old line. */
static void describe(int fd)
{
	char line[DESC_MAX], prog[PROG_MAX], since[32];
	time_t now = time(NULL);
	struct tm tm;
	int n;

	program_name(prog, sizeof(prog));
	localtime_r(&now, &tm);
	strftime(since, sizeof(since), "%Y-%m-%d %H:%M:%S", &tm);
	n = snprintf(line, sizeof(line), "pid=%ld program=%s since=%s\n",
		     (long)getpid(), prog, since);
	if (pwrite(fd, line, (size_t)n, 0) == n && ftruncate(fd, n) == 0)
		return;
	/* Not fatal: the lock is held; a refused caller says "another
	 * process". */
}

/* Who holds the lock, from its description. */
static void holder(int fd, char *buf, size_t cap)
{
	char line[DESC_MAX], prog[PROG_MAX], since[32];
	ssize_t n = pread(fd, line, sizeof(line) - 1, 0);
	long pid;

	if (n > 0) {
		line[n] = '\0';
		if (sscanf(line, "pid=%ld program=%63s since=%31[^\n]", &pid,
			   prog, since) == 3) {
			snprintf(buf, cap, "%s (pid %ld, since %s)", prog, pid,
				 since);
			return;
		}
	}
	snprintf(buf, cap, "another process");
}

/* Lock @fd, never waiting; on failure close it and say why. */
static int take(int fd, const char *kind, const char *norm, const char *path,
		char *err, size_t errlen)
{
	char who[DESC_MAX];
	int e;

	if (!flock(fd, LOCK_EX | LOCK_NB))
		return GL_OK;
	e = errno;
	if (e == EWOULDBLOCK)
		holder(fd, who, sizeof(who));
	close(fd);
	errno = e;
	if (e == EWOULDBLOCK)
		return fail(err, errlen, GL_ERR_BUSY,
			    "%s %s is already supervised by %s", kind, norm,
			    who);
	return fail(err, errlen, GL_ERR_SYS, "cannot lock '%s': %s", path,
		    strerror(e));
}

int re_lock_acquire(struct re_lock *lk, const char *kind, const char *key,
		    char *err, size_t errlen)
{
	char norm[RE_LOCK_KEY_MAX], dir[RE_LOCK_PATH_MAX], name[NAME_CAP];
	int rc, fd;

	if (err && errlen)
		err[0] = '\0';
	if (!lk || !kind || !key || !key[0] || lk->fd >= 0 || !kind_ok(kind))
		return fail(err, errlen, GL_ERR_ARG,
			    "cannot lock: invalid arguments");
	rc = normalise(kind, key, norm, sizeof(norm), err, errlen);
	if (!rc)
		rc = re_lock_dir(dir, sizeof(dir), err, errlen);
	if (rc)
		return rc;
	lock_name(kind, norm, name);
	if (snprintf(lk->path, sizeof(lk->path), "%s/%s", dir, name) >=
	    (int)sizeof(lk->path))
		return fail(err, errlen, GL_ERR_ARG,
			    "cannot lock: lock directory path too long");
	fd = open_file(lk->path, err, errlen);
	if (fd < 0)
		rc = GL_ERR_SYS;
	else
		rc = take(fd, kind, norm, lk->path, err, errlen);
	if (rc) {
		lk->path[0] = '\0';
		return rc;
	}
	describe(fd);
	lk->fd = fd;
	return GL_OK;
}

void re_lock_release(struct re_lock *lk)
{
	if (!lk || lk->fd < 0)
		return;
	if (ftruncate(lk->fd, 0) < 0) {
		/* the description stays; the lock goes with close() */
	}
	close(lk->fd);
	re_lock_init(lk);
}
