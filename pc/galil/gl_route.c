/*
 * gl_route.c - rto_min of the route to the controller (see gl_route.h).
 *
 * One request, one answer: RTM_GETROUTE for the peer address of the link's
 * socket, the same lookup the kernel does for the connection, so the answer
 * is the route (and metric) the TCP stack uses. `ip route get ADDR` shows
 * the same ("rto_min lock 20ms"). The metric is kept in ms by the kernel.
 */
#include <errno.h>
#include <poll.h>
#include <stdint.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>
#include <arpa/inet.h>
#include <net/if.h>
#include <stdio.h>
#include <linux/netlink.h>
#include <linux/rtnetlink.h>
#include <netinet/in.h>

#include "gl_err.h"
#include "gl_route.h"

#define ANSWER_MAX 8192

/* The RTAX_RTO_MIN metric inside an RTA_METRICS attribute (@m, @len). */
static int metric_rto_min(const struct rtattr *m, int len, int *out)
{
	uint32_t v;

	for (; RTA_OK(m, len); m = RTA_NEXT(m, len)) {
		if (m->rta_type != RTAX_RTO_MIN)
			continue;
		if (RTA_PAYLOAD(m) < sizeof(uint32_t))
			return GL_ERR_PROTO;
		memcpy(&v, RTA_DATA(m), sizeof(v));
		*out = v > 60000 ? 60000 : (int)v;
		return GL_OK;
	}
	return len == 0 ? GL_OK : GL_ERR_PROTO;
}

static int parse_route(const struct nlmsghdr *h, struct gl_route_info *out)
{
	const struct rtmsg *rt = NLMSG_DATA(h);
	const struct rtattr *a;
	int len = (int)h->nlmsg_len - (int)NLMSG_LENGTH(sizeof(*rt)), rc;
	uint32_t oif;

	if (len < 0)
		return GL_ERR_PROTO;
	a = (const struct rtattr *)((const char *)rt +
				    NLMSG_ALIGN(sizeof(*rt)));
	for (; RTA_OK(a, len); a = RTA_NEXT(a, len)) {
		if (a->rta_type == RTA_METRICS) {
			rc = metric_rto_min(RTA_DATA(a), (int)RTA_PAYLOAD(a),
					    &out->rto_min_ms);
			if (rc != GL_OK)
				return rc;
		} else if (a->rta_type == RTA_GATEWAY) {
			out->gateway = 1;
		} else if (a->rta_type == RTA_OIF &&
			   RTA_PAYLOAD(a) >= sizeof(oif)) {
			memcpy(&oif, RTA_DATA(a), sizeof(oif));
			out->oif = (int)oif;
		}
	}
	return len == 0 ? GL_OK : GL_ERR_PROTO;
}

int gl_route_parse(const void *buf, size_t len, int *rto_min_ms)
{
	struct gl_route_info info;
	int rc = gl_route_parse_info(buf, len, &info);

	*rto_min_ms = info.rto_min_ms;
	return rc;
}

int gl_route_parse_info(const void *buf, size_t len, struct gl_route_info *out)
{
	const struct nlmsghdr *h = buf;
	unsigned int left = len > ANSWER_MAX ? ANSWER_MAX : (unsigned int)len;

	memset(out, 0, sizeof(*out));
	for (; NLMSG_OK(h, left); h = NLMSG_NEXT(h, left)) {
		if (h->nlmsg_type == NLMSG_ERROR) {
			const struct nlmsgerr *e = NLMSG_DATA(h);

			if (h->nlmsg_len < NLMSG_LENGTH(sizeof(*e)))
				return GL_ERR_PROTO;
			errno = e->error ? -e->error : EPROTO;
			return GL_ERR_SYS;
		}
		if (h->nlmsg_type == RTM_NEWROUTE)
			return parse_route(h, out);
	}
	return GL_ERR_PROTO;
}

struct route_req {
	struct nlmsghdr h;
	struct rtmsg rt;
	char attrs[64];
};

/* The request for the route to @peer. */
static int build_req(struct route_req *r, const struct sockaddr_storage *peer)
{
	const void *addr;
	size_t alen;
	struct rtattr *a;

	memset(r, 0, sizeof(*r));
	if (peer->ss_family == AF_INET) {
		addr = &((const struct sockaddr_in *)peer)->sin_addr;
		alen = 4;
	} else if (peer->ss_family == AF_INET6) {
		addr = &((const struct sockaddr_in6 *)peer)->sin6_addr;
		alen = 16;
	} else {
		return GL_ERR_ARG;
	}
	r->h.nlmsg_type = RTM_GETROUTE;
	r->h.nlmsg_flags = NLM_F_REQUEST;
	r->h.nlmsg_seq = 1;
	r->rt.rtm_family = (unsigned char)peer->ss_family;
	r->rt.rtm_dst_len = (unsigned char)(alen * 8);
	a = (struct rtattr *)r->attrs;
	a->rta_type = RTA_DST;
	a->rta_len = (unsigned short)RTA_LENGTH(alen);
	memcpy(RTA_DATA(a), addr, alen);
	r->h.nlmsg_len = NLMSG_LENGTH(sizeof(r->rt)) + RTA_SPACE(alen);
	return GL_OK;
}

static int ask(const struct route_req *r, int timeout_ms,
	       struct gl_route_info *out)
{
	char buf[ANSWER_MAX] __attribute__((aligned(NLMSG_ALIGNTO)));
	struct sockaddr_nl kernel = {.nl_family = AF_NETLINK};
	struct pollfd pfd = {.events = POLLIN};
	ssize_t n;
	int rc = GL_ERR_SYS;

	pfd.fd = socket(AF_NETLINK, SOCK_RAW | SOCK_CLOEXEC, NETLINK_ROUTE);
	if (pfd.fd < 0)
		return GL_ERR_SYS;
	if (sendto(pfd.fd, r, r->h.nlmsg_len, 0, (struct sockaddr *)&kernel,
		   sizeof(kernel)) < 0)
		goto out_close;
	n = poll(&pfd, 1, timeout_ms);
	if (n == 0)
		rc = GL_ERR_TIMEOUT;
	if (n <= 0)
		goto out_close;
	n = recv(pfd.fd, buf, sizeof(buf), 0);
	if (n > 0)
		rc = gl_route_parse_info(buf, (size_t)n, out);
out_close : {
	int keep = errno;

	close(pfd.fd);
	errno = keep;
}
	return rc;
}

int gl_route_peer_loopback(int fd)
{
	struct sockaddr_storage peer;
	socklen_t plen = sizeof(peer);
	const unsigned char *b;

	if (getpeername(fd, (struct sockaddr *)&peer, &plen) < 0)
		return GL_ERR_ARG;
	if (peer.ss_family == AF_INET) {
		b = (const unsigned char *)&((struct sockaddr_in *)&peer)
			->sin_addr;
		return b[0] == 127;
	}
	if (peer.ss_family != AF_INET6)
		return GL_ERR_ARG;
	b = ((struct sockaddr_in6 *)&peer)->sin6_addr.s6_addr;
	if (IN6_IS_ADDR_LOOPBACK((const struct in6_addr *)b))
		return 1;
	return IN6_IS_ADDR_V4MAPPED((const struct in6_addr *)b) && b[12] == 127;
}

int gl_route_rto_limit_ms(int crit_ms, int period_ms)
{
	return crit_ms > period_ms ? (crit_ms - period_ms) / 3 : 0;
}

int gl_route_get(int fd, int timeout_ms, struct gl_route_info *out)
{
	struct sockaddr_storage peer;
	socklen_t plen = sizeof(peer);
	struct route_req r;
	int rc;

	memset(out, 0, sizeof(*out));
	if (getpeername(fd, (struct sockaddr *)&peer, &plen) < 0)
		return GL_ERR_ARG;
	if (build_req(&r, &peer) != GL_OK)
		return GL_ERR_ARG;
	rc = ask(&r, timeout_ms, out);
	if (rc == GL_OK && out->oif > 0 &&
	    !if_indextoname((unsigned)out->oif, out->ifname))
		snprintf(out->ifname, sizeof(out->ifname), "#%d", out->oif);
	return rc;
}

int gl_route_rto_min_ms(int fd, int timeout_ms, int *rto_min_ms)
{
	struct gl_route_info info;
	int rc = gl_route_get(fd, timeout_ms, &info);

	*rto_min_ms = info.rto_min_ms;
	return rc;
}
