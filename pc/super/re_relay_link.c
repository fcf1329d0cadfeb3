/*
 * re_relay_link.c - is the relay link still sound? The descriptor, a
 * hang-up or error, the device node behind the path (stat()ed after an
 * inotify event of its watch, re_pathwatch.h, and at least once a second)
 * and the read-back step; never a state byte written (the decisions:
 * re_relay.c's header).
 */
#include <errno.h>
#include <poll.h>
#include <stdbool.h>
#include <stdint.h>
#include <string.h>
#include <sys/stat.h>

#include "base_clock.h"
#include "gl_err.h"
#include "re_pathwatch.h"
#include "re_relay_int.h"

#define FULL_CHECK_NS BASE_NS_PER_S /* stat() the port at least this often */

/* The device node by stat(): after a watch event, once a second, and in
 * every call while it fails. */
static int node_check(struct re_relay *r, int events)
{
	int64_t now = base_now_ns();
	struct stat st;

	if (!(events && re_pathwatch_changed(&r->pw)) && !r->node_suspect &&
	    now < r->next_full_ns)
		return GL_OK;
	r->next_full_ns = now + FULL_CHECK_NS;
	r->node_suspect = true;
	if (stat(r->cfg.port, &st) < 0)
		return re_relay_set_err(r, GL_ERR_RELAY,
					"device node is gone: %s",
					strerror(errno));
	if (!re_relay_same_node(r, &st))
		return re_relay_set_err(r, GL_ERR_RELAY,
					"the port now names another device");
	r->node_suspect = false;
	return GL_OK;
}

/* Descriptor, hang-up and device node from a poll() of the descriptor
 * and the path's watch; no byte written. */
static int link_seen(struct re_relay *r, short fd_ev, short watch_ev)
{
	if (fd_ev & POLLNVAL)
		return re_relay_set_err(r, GL_ERR_RELAY, "descriptor lost: %s",
					strerror(EBADF));
	if (fd_ev & POLLHUP)
		return re_relay_set_err(r, GL_ERR_RELAY, "link lost (hang-up)");
	if (fd_ev & POLLERR)
		return re_relay_set_err(r, GL_ERR_RELAY, "link error");
	/* no watch: re_pathwatch_changed() answers 1 (stat every call) */
	return node_check(r, r->pw.fd < 0 || watch_ev != 0);
}

/* Is the port open with a descriptor? GL_OK or GL_ERR_RELAY. */
static int link_open_fd(struct re_relay *r, int *fd)
{
	if (!r->linked)
		return re_relay_set_err(r, GL_ERR_RELAY, "port not open");
	*fd = r->ops->fd(&r->io);
	if (*fd < 0)
		return re_relay_set_err(r, GL_ERR_RELAY, "descriptor lost: %s",
					strerror(EBADF));
	return GL_OK;
}

/* One poll() with timeout 0 looks at the descriptor (POLLNVAL: it is
 * gone) and at the inotify watch of the path together (one
 * system call per cycle when nothing happened). */
int re_relay_link_check(struct re_relay *r)
{
	struct pollfd p[2] = {{.events = 0}, {.events = POLLIN}};
	int np;

	if (link_open_fd(r, &p[0].fd))
		return GL_ERR_RELAY;
	p[1].fd = r->pw.fd;
	np = r->pw.fd >= 0 ? 2 : 1;
	if (poll(p, (nfds_t)np, 0) < 0 && errno != EINTR)
		return re_relay_set_err(r, GL_ERR_RELAY, "poll failed: %s",
					strerror(errno));
	return link_seen(r, p[0].revents, np == 2 ? p[1].revents : 0);
}

int re_relay_check(re_relay *r)
{
	int rc;

	if (!r)
		return GL_ERR_ARG;
	rc = re_relay_link_check(r);
	if (!rc)
		rc = re_relay_readback_step(r);
	return rc;
}

void re_relay_fds(const re_relay *r, int *fd, int *watch_fd)
{
	*fd = r && r->linked ? r->ops->fd(&r->io) : -1;
	*watch_fd = *fd >= 0 ? r->pw.fd : -1;
}

int re_relay_check_seen(re_relay *r, short fd_revents, short watch_revents)
{
	int fd, rc;

	if (!r)
		return GL_ERR_ARG;
	rc = link_open_fd(r, &fd);
	if (!rc)
		rc = link_seen(r, fd_revents, watch_revents);
	if (!rc)
		rc = re_relay_readback_step(r);
	return rc;
}
