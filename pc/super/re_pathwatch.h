/*
 * re_pathwatch.h - notice cheaply that a path may now name another file.
 *
 * re_relay_check() runs every cycle and must notice when the relay's port
 * path stops naming the device node that was opened: the node removed, a
 * symbolic link retargeted (a pty number reused, a re-plugged adapter), the
 * node's mode or owner changed. A stat() of the path in every cycle walks
 * the whole path each time; this module asks inotify for the events that
 * can change the answer, so that the cycle reads one non-blocking
 * descriptor and the caller stat()s only after such an event.
 *
 * Watched, for the path and every symbolic link it resolves through: the
 * entry's name in its directory (created, deleted, renamed to or from,
 * attributes changed) and that directory itself (deleted, moved); and the
 * final node (attributes changed, deleted, moved). Not watched: directories
 * further up (an ancestor renamed or mounted over), so callers still stat()
 * now and then (re_relay_link.c: at least once a second).
 *
 * Nothing here prints or allocates; the descriptor is non-blocking and
 * close-on-exec.
 */
#ifndef RE_PATHWATCH_H
#define RE_PATHWATCH_H

#define RE_PATHWATCH_LINKS    8	  /* symbolic links followed, at most */
#define RE_PATHWATCH_NAME_MAX 256 /* bytes of one name, with the NUL */

struct re_pathwatch {
	int fd; /* inotify descriptor; -1 when not watching */
	int n;	/* entries of w[] in use */
	struct {
		int wd;				  /* inotify watch */
		char name[RE_PATHWATCH_NAME_MAX]; /* entry in that directory;
						   * "" = the watched object
						   * itself */
	} w[RE_PATHWATCH_LINKS + 2];
};

/* re_pathwatch_init() - a watch that watches nothing (fd -1). */
void re_pathwatch_init(struct re_pathwatch *pw);

/*
 * re_pathwatch_open() - start watching @path (closes an earlier watch).
 * @pw: [out] must not be NULL; initialised (re_pathwatch_init) or open.
 * @path: [in] the path as the user gave it (may be relative or a link).
 * Return: GL_OK; GL_ERR_SYS (inotify unavailable, no such file, too many
 *         watches; errno kept); GL_ERR_OVERFLOW (more than
 *         RE_PATHWATCH_LINKS links, or a name or path too long). On
 *         failure @pw watches nothing and re_pathwatch_changed() answers 1.
 */
int re_pathwatch_open(struct re_pathwatch *pw, const char *path);

/*
 * re_pathwatch_changed() - did anything that may change what the path
 * names happen since the last call? Never blocks: reads every pending event.
 * Return: 1 (an event concerning the path, lost events, or not watching),
 *         0 (nothing).
 */
int re_pathwatch_changed(struct re_pathwatch *pw);

/*
 * re_pathwatch_stop() - remove every watch but keep the descriptor, so that
 * a re_pathwatch_close() some milliseconds later does not wait for the
 * kernel to free them (closing an inotify descriptor that still has
 * watches waits for an RCU grace period: 7 to 15 ms measured on a loaded
 * 2-core machine). re_pathwatch_changed() then answers 0 until it is
 * opened again. No return value; cannot fail.
 */
void re_pathwatch_stop(struct re_pathwatch *pw);

/* re_pathwatch_close() - stop watching; @pw is then as after init. */
void re_pathwatch_close(struct re_pathwatch *pw);

#endif /* RE_PATHWATCH_H */
