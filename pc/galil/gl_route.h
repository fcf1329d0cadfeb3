/*
 * gl_route.h - the kernel's minimum retransmission time (rto_min) on the
 * route to the controller (Linux rtnetlink; docs/link.md).
 *
 * Why: Linux TCP resends a lost segment no sooner than rto_min, 200 ms by
 * default, which is past the supervisor's 125 ms reply-age limit, so one
 * lost frame would trip WATCHDOG. The installer sets a lower rto_min on the
 * route ("ip route replace ADDR/32 dev IF rto_min 20ms"); roboelf checks it
 * at start-up with gl_route_rto_min_ms(). The answer is parsed from a
 * buffer by gl_route_parse() (testable without a kernel). Nothing prints.
 */
#ifndef GL_ROUTE_H
#define GL_ROUTE_H

#include <stddef.h>

/* Linux's default minimum retransmission timeout (TCP_RTO_MIN), ms. */
#define GL_ROUTE_DEFAULT_RTO_MIN_MS 200

/* What the kernel's route to the controller says. */
struct gl_route_info {
	int rto_min_ms;	 /* 0: the route sets none */
	int gateway;	 /* 1: through a gateway (not a direct link) */
	int oif;	 /* the interface's index, 0: not given */
	char ifname[16]; /* its name ("eth1"), "" when not known */
};

/*
 * gl_route_get() - the route the kernel uses to reach the peer of the
 * connected socket @fd: rto_min, whether it goes through a gateway (the
 * one supported network is a direct link: docs/technician.md), and the
 * interface. As gl_route_rto_min_ms() otherwise.
 */
int gl_route_get(int fd, int timeout_ms, struct gl_route_info *out);

/*
 * gl_route_parse_info() - gl_route_parse() with the gateway and the
 * interface index (the name is left "").
 */
int gl_route_parse_info(const void *buf, size_t len, struct gl_route_info *out);

/*
 * gl_route_rto_min_ms() - the rto_min of the route the kernel uses to reach
 * the peer of the connected socket @fd (IPv4 or IPv6): one RTM_GETROUTE
 * request on a NETLINK_ROUTE socket, answered within @timeout_ms.
 * @rto_min_ms: [out] the route's rto_min in ms, or 0 when the route sets
 *              none (the kernel's GL_ROUTE_DEFAULT_RTO_MIN_MS applies);
 *              must not be NULL.
 * Return: GL_OK; GL_ERR_ARG (@fd not a connected IPv4/IPv6 socket);
 *         GL_ERR_SYS (errno kept, also for a netlink error answer);
 *         GL_ERR_TIMEOUT; GL_ERR_PROTO (an answer gl_route_parse() refuses).
 */
int gl_route_rto_min_ms(int fd, int timeout_ms, int *rto_min_ms);

/*
 * gl_route_peer_loopback() - whether the peer of the connected socket @fd
 * is a loopback address (127.0.0.0/8, ::1, ::ffff:127.x): no cable, no
 * loss, nothing to check.
 * Return: 1 loopback, 0 not, GL_ERR_ARG (@fd not a connected IP socket).
 */
int gl_route_peer_loopback(int fd);

/*
 * gl_route_rto_limit_ms() - the largest rto_min with which two losses of
 * the same frame in a row (resent after rto_min, then twice that) still
 * answer within the critical reply-age limit: (@crit_ms - @period_ms) / 3,
 * rounded down; 25 ms at the defaults (125 and 50 ms). docs/link.md.
 * Return: the limit in ms, 0 when @crit_ms <= @period_ms.
 */
int gl_route_rto_limit_ms(int crit_ms, int period_ms);

/*
 * gl_route_parse() - the rto_min from the kernel's answer to RTM_GETROUTE:
 * the first RTM_NEWROUTE message of @buf (@len bytes), its RTA_METRICS
 * attribute, the RTAX_RTO_MIN metric in it.
 * @rto_min_ms: [out] the metric (ms), 0 when absent; must not be NULL.
 * Return: GL_OK; GL_ERR_SYS with errno set from an NLMSG_ERROR answer;
 *         GL_ERR_PROTO for a truncated or malformed answer or one without
 *         a route.
 */
int gl_route_parse(const void *buf, size_t len, int *rto_min_ms);

#endif /* GL_ROUTE_H */
