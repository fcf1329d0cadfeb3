/*
 * re_pathwatch.c - inotify watches on a path, its links and its node.
 * See re_pathwatch.h.
 *
 * inotify reports events on an inode, and in a watched directory the name
 * of the entry concerned; a watch on the path's directory with the entry's
 * name filters out the traffic of unrelated files (/tmp is busy). A lost
 * event (queue overflow) or a watch that went away (IN_IGNORED: the
 * directory was deleted) counts as a change: the caller then stat()s.
 */
#include "re_pathwatch.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <string.h>
#include <sys/inotify.h>
#include <unistd.h>

#include "gl_err.h"

/* In a directory: what happens to one entry, or to the directory. */
#define DIR_EVENTS                                                             \
	(IN_CREATE | IN_DELETE | IN_MOVED_FROM | IN_MOVED_TO | IN_ATTRIB |     \
	 IN_DELETE_SELF | IN_MOVE_SELF)
/* On the node: mode, owner, link count (IN_ATTRIB), removal, rename. */
#define NODE_EVENTS (IN_ATTRIB | IN_DELETE_SELF | IN_MOVE_SELF)

void re_pathwatch_init(struct re_pathwatch *pw)
{
	pw->fd = -1;
	pw->n = 0;
}

void re_pathwatch_stop(struct re_pathwatch *pw)
{
	for (int i = 0; i < pw->n; i++)
		if (pw->fd >= 0 && pw->w[i].wd >= 0)
			inotify_rm_watch(pw->fd, pw->w[i].wd);
	pw->n = 0;
}

void re_pathwatch_close(struct re_pathwatch *pw)
{
	if (pw->fd >= 0)
		close(pw->fd);
	re_pathwatch_init(pw);
}

static int add(struct re_pathwatch *pw, const char *what, unsigned int mask,
	       const char *name)
{
	int wd;

	if (pw->n >= (int)(sizeof(pw->w) / sizeof(pw->w[0])) ||
	    strlen(name) >= sizeof(pw->w[0].name))
		return GL_ERR_OVERFLOW;
	wd = inotify_add_watch(pw->fd, what, mask);
	if (wd < 0)
		return GL_ERR_SYS;
	pw->w[pw->n].wd = wd;
	snprintf(pw->w[pw->n].name, sizeof(pw->w[0].name), "%s", name);
	pw->n++;
	return GL_OK;
}

/* Watch @path's entry in its directory ("." for a bare name). */
static int add_entry(struct re_pathwatch *pw, const char *path)
{
	char dir[PATH_MAX];
	const char *slash = strrchr(path, '/');
	size_t dl;

	if (!slash)
		return add(pw, ".", DIR_EVENTS, path);
	dl = slash == path ? 1 : (size_t)(slash - path);
	if (dl >= sizeof(dir) || !slash[1])
		return GL_ERR_OVERFLOW;
	memcpy(dir, path, dl);
	dir[dl] = '\0';
	return add(pw, dir, DIR_EVENTS, slash + 1);
}

/* The next path in the chain of links: @cur's target, relative to @cur's
 * directory. Return 1 (followed), 0 (@cur is no link) or a gl_err. */
static int follow(char *cur, size_t cap)
{
	char target[PATH_MAX];
	const char *slash;
	ssize_t n = readlink(cur, target, sizeof(target) - 1);
	int len;

	if (n < 0)
		return errno == EINVAL ? 0 : GL_ERR_SYS;
	target[n] = '\0';
	slash = strrchr(cur, '/');
	if (target[0] == '/' || !slash)
		len = snprintf(cur, cap, "%s", target);
	else
		len = snprintf(cur + (slash - cur) + 1,
			       cap - (size_t)(slash - cur) - 1, "%s", target);
	return len < 0 || (size_t)len >= cap ? GL_ERR_OVERFLOW : 1;
}

int re_pathwatch_open(struct re_pathwatch *pw, const char *path)
{
	char cur[PATH_MAX];
	int rc, hops;

	re_pathwatch_close(pw);
	if (snprintf(cur, sizeof(cur), "%s", path) >= (int)sizeof(cur))
		return GL_ERR_OVERFLOW;
	pw->fd = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
	if (pw->fd < 0)
		return GL_ERR_SYS;
	for (hops = 0;; hops++) {
		rc = add_entry(pw, cur);
		if (rc == GL_OK)
			rc = follow(cur, sizeof(cur));
		if (rc == 0)
			break;
		if (rc == 1 && hops >= RE_PATHWATCH_LINKS)
			rc = GL_ERR_OVERFLOW;
		if (rc < 0)
			goto out_close;
	}
	rc = add(pw, cur, NODE_EVENTS, "");
	if (rc == GL_OK)
		return GL_OK;
out_close:
	re_pathwatch_close(pw);
	return rc;
}

/* Does @ev concern a watched entry, node or directory? */
static int concerns(const struct re_pathwatch *pw,
		    const struct inotify_event *ev)
{
	int i;

	if (ev->mask & IN_Q_OVERFLOW)
		return 1;
	for (i = 0; i < pw->n; i++) {
		if (pw->w[i].wd != ev->wd)
			continue;
		if (!pw->w[i].name[0] || !ev->len ||
		    !strcmp(ev->name, pw->w[i].name))
			return 1;
	}
	return 0;
}

int re_pathwatch_changed(struct re_pathwatch *pw)
{
	_Alignas(struct inotify_event) char buf[4096];
	const struct inotify_event *ev;
	int hit = 0;
	ssize_t n;
	char *p;

	if (pw->fd < 0)
		return 1;
	for (;;) {
		n = read(pw->fd, buf, sizeof(buf));
		if (n < 0 && errno == EINTR)
			continue;
		if (n <= 0)
			break;
		for (p = buf; p < buf + n; p += sizeof(*ev) + ev->len) {
			ev = (const struct inotify_event *)(void *)p;
			hit |= concerns(pw, ev);
		}
	}
	if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK)
		hit = 1;
	return hit;
}
