/*
 * re_lock.h - one supervisor per controller and per relay.
 *
 * Two supervisors driving one controller, or switching one relay, would
 * fight: each arms, disarms and switches power on its own view. Before
 * touching either, a supervisor takes an exclusive lock named after it:
 *
 *   re_lock_acquire(&lk, "controller", "192.168.42.7", err, sizeof(err));
 *   re_lock_acquire(&lk, "relay", "/dev/serial/by-id/usb-...", err, ...);
 *
 * The lock is flock(LOCK_EX | LOCK_NB) on a file in the lock directory
 * (re_lock_dir()). The kernel drops it when the holder closes the file or
 * dies, however it dies (SIGKILL included): there are no stale locks and
 * the files are never deleted (deleting a lock file lets two processes hold
 * "the" lock on two different files). The holder writes its pid, program
 * and start time into the file, so that a refused caller can say who holds
 * it:
 *   "controller 127.0.0.1:23023 is already supervised by roboelf
 *    (pid 1234, since 2026-11-25 10:02:03)"
 *
 * Keys name the thing, not the spelling: a controller address is
 * normalised to "host:port" as gl_link_open() parses it (default port 23,
 * the host in lower case; "[v6]:port" for IPv6; host names are not
 * resolved, so "localhost" and "127.0.0.1" are two keys); a relay port is
 * resolved with realpath(), so a link and its target are one key.
 *
 * The descriptor is close-on-exec: a child that exec()s does not inherit
 * the lock (a forked child that does not exec holds it with the parent).
 * Nothing here prints; only re_lock_acquire() writes files.
 */
#ifndef RE_LOCK_H
#define RE_LOCK_H

#include <stddef.h>

#define RE_LOCK_DIR_ENV	 "ROBOELF_LOCK_DIR"
#define RE_LOCK_RUN_DIR	 "/run/lock/roboelf" /* shared by every user */
#define RE_LOCK_PATH_MAX 4096		     /* bytes, with the NUL */
#define RE_LOCK_KEY_MAX	 4096		     /* bytes, with the NUL */
#define RE_LOCK_ERR_MAX	 512		     /* bytes of a message */

/* A lock held (fd >= 0) or not (fd -1); re_lock_init() before use. */
struct re_lock {
	int fd;			     /* the lock file, locked; -1 */
	char path[RE_LOCK_PATH_MAX]; /* the lock file; "" when not held */
};

/* Where the lock directory may be; re_lock_dir() fills it in. */
struct re_lock_places {
	const char *env_dir; /* $ROBOELF_LOCK_DIR, or NULL/"" */
	const char *run_dir; /* RE_LOCK_RUN_DIR */
	const char *xdg_dir; /* $XDG_RUNTIME_DIR, or NULL/"" */
	const char *tmp_dir; /* "/tmp" */
};

/* re_lock_init() - a lock not held. */
void re_lock_init(struct re_lock *lk);

/*
 * re_lock_acquire() - take the lock on @kind @key, never waiting.
 * @lk: [in,out] initialised and not held; must not be NULL.
 * @kind: "controller" (key: an address, normalised with
 *        re_lock_controller_key()), "relay" (key: a port path, resolved
 *        with re_lock_relay_key()), or another lower-case word (key used
 *        as given).
 * @key: [in] what is locked; must not be NULL or empty.
 * @err: [out] optional buffer for the reason of a failure, e.g.
 *       "controller 127.0.0.1:23023 is already supervised by roboelf (pid
 *       1234, since 2026-11-25 10:02:03)",
 *       "cannot create lock file '/run/lock/roboelf/relay-...lock':
 *       Permission denied"; "" on success.
 * @errlen: size of @err (RE_LOCK_ERR_MAX is enough).
 * The lock file is "<kind>-<key, percent-encoded>.lock" in re_lock_dir()
 * (a long key is cut and followed by its FNV-1a hash). After locking, the
 * file holds one line "pid=<pid> program=<name> since=<local time>".
 * Return: GL_OK (held); GL_ERR_BUSY (another open file holds it, in this
 *         process or another); GL_ERR_ARG (NULL, a held @lk, a bad @kind,
 *         an address gl_link_open() would refuse); GL_ERR_SYS (the lock
 *         directory or file cannot be made or opened, the relay path cannot
 *         be resolved; errno kept).
 */
int re_lock_acquire(struct re_lock *lk, const char *kind, const char *key,
		    char *err, size_t errlen);

/*
 * re_lock_release() - empty the description and drop the lock (the file
 * stays). A lock not held, or NULL, is a no-op.
 */
void re_lock_release(struct re_lock *lk);

/*
 * re_lock_controller_key() - @addr as "host:port": split like
 * gl_link_open() (gl_link_addr_split), default port 23, the port without
 * leading zeros, the host in lower case, IPv6 in brackets.
 * E.g. "10.0.0.2" -> "10.0.0.2:23", "[FE80::1]:023023" -> "[fe80::1]:23023".
 * Return: GL_OK; GL_ERR_ARG (an address gl_link_open() refuses);
 *         GL_ERR_OVERFLOW (@cap too small).
 */
int re_lock_controller_key(const char *addr, char *key, size_t cap);

/*
 * re_lock_relay_key() - @path resolved with realpath() (links followed,
 * "." and ".." removed): every name of one device node gives one key.
 * Return: GL_OK; GL_ERR_SYS (the path cannot be resolved, e.g. ENOENT;
 *         errno kept); GL_ERR_OVERFLOW (@cap too small).
 */
int re_lock_relay_key(const char *path, char *key, size_t cap);

/*
 * re_lock_dir_pick() - the lock directory among @pl, made if needed:
 * 1. @pl->env_dir when set: used as it is (it must exist);
 * 2. @pl->run_dir when it exists, or when it can be created (mode 01777,
 *    like /run/lock: every user's supervisors meet there);
 * 3. "<xdg_dir>/roboelf" (mode 0700) when @pl->xdg_dir is set;
 * 4. "<tmp_dir>/roboelf-locks-<uid>" (mode 0700; refused unless it is a
 *    directory of this user that nobody else can write).
 * 3 and 4 are per user: they exclude only this user's supervisors.
 * @dir: [out] the directory; @cap bytes.
 * @err: [out] optional reason of a failure.
 * Return: GL_OK; GL_ERR_SYS (errno kept); GL_ERR_OVERFLOW.
 */
int re_lock_dir_pick(const struct re_lock_places *pl, char *dir, size_t cap,
		     char *err, size_t errlen);

/*
 * re_lock_dir() - re_lock_dir_pick() with $ROBOELF_LOCK_DIR,
 * RE_LOCK_RUN_DIR, $XDG_RUNTIME_DIR and /tmp. Return: as that.
 */
int re_lock_dir(char *dir, size_t cap, char *err, size_t errlen);

#endif /* RE_LOCK_H */
