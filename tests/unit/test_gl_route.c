/*
 * test_gl_route.c - gl_route: the rto_min metric, the gateway and the
 * interface parsed from hand-built rtnetlink answers (present, absent, an
 * error answer, truncated, no route), and live lookups of the loopback
 * route (no rto_min: 0; a direct link on "lo").
 */
#include <errno.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>
#include <arpa/inet.h>
#include <linux/netlink.h>
#include <linux/rtnetlink.h>
#include <netinet/in.h>

#include <cmocka.h>

#include "gl_err.h"
#include "gl_route.h"

struct answer {
	struct nlmsghdr h;
	struct rtmsg rt;
	char attrs[128];
} __attribute__((aligned(4)));

/* An RTM_NEWROUTE answer; @rto_ms < 0: no RTA_METRICS at all, 0: metrics
 * without RTAX_RTO_MIN (only RTAX_MTU). */
static size_t build(struct answer *a, int rto_ms)
{
	struct rtattr *dst, *met, *m;
	uint32_t v = 1500, addr = htonl(0x0a000002);
	size_t len;

	memset(a, 0, sizeof(*a));
	a->h.nlmsg_type = RTM_NEWROUTE;
	a->rt.rtm_family = AF_INET;
	dst = (struct rtattr *)a->attrs;
	dst->rta_type = RTA_DST;
	dst->rta_len = RTA_LENGTH(4);
	memcpy(RTA_DATA(dst), &addr, 4);
	len = RTA_SPACE(4);
	if (rto_ms >= 0) {
		met = (struct rtattr *)(a->attrs + len);
		met->rta_type = RTA_METRICS;
		m = (struct rtattr *)RTA_DATA(met);
		m->rta_type = RTAX_MTU;
		m->rta_len = RTA_LENGTH(4);
		memcpy(RTA_DATA(m), &v, 4);
		met->rta_len = RTA_LENGTH(RTA_SPACE(4));
		if (rto_ms > 0) {
			v = (uint32_t)rto_ms;
			m = (struct rtattr *)((char *)m + RTA_SPACE(4));
			m->rta_type = RTAX_RTO_MIN;
			m->rta_len = RTA_LENGTH(4);
			memcpy(RTA_DATA(m), &v, 4);
			met->rta_len = RTA_LENGTH(2 * RTA_SPACE(4));
		}
		len += RTA_ALIGN(met->rta_len);
	}
	a->h.nlmsg_len = NLMSG_LENGTH(sizeof(a->rt)) + (unsigned)len;
	return a->h.nlmsg_len;
}

/* rto_min 20 ms on the route: 20. */
static void test_parse_rto_min(void **state)
{
	struct answer a;
	int ms = -1;

	(void)state;
	assert_int_equal(gl_route_parse(&a, build(&a, 20), &ms), GL_OK);
	assert_int_equal(ms, 20);
}

/* Metrics without rto_min, and no metrics at all: 0 (kernel default). */
static void test_parse_absent(void **state)
{
	struct answer a;
	int ms = -1;

	(void)state;
	assert_int_equal(gl_route_parse(&a, build(&a, 0), &ms), GL_OK);
	assert_int_equal(ms, 0);
	ms = -1;
	assert_int_equal(gl_route_parse(&a, build(&a, -1), &ms), GL_OK);
	assert_int_equal(ms, 0);
}

/* NLMSG_ERROR (no route to the host): GL_ERR_SYS with its errno. */
static void test_parse_error_answer(void **state)
{
	struct {
		struct nlmsghdr h;
		struct nlmsgerr e;
	} m;
	int ms = -1;

	(void)state;
	memset(&m, 0, sizeof(m));
	m.h.nlmsg_type = NLMSG_ERROR;
	m.h.nlmsg_len = NLMSG_LENGTH(sizeof(m.e));
	m.e.error = -ENETUNREACH;
	errno = 0;
	assert_int_equal(gl_route_parse(&m, sizeof(m), &ms), GL_ERR_SYS);
	assert_int_equal(errno, ENETUNREACH);
	assert_int_equal(ms, 0);
}

/* Truncated, an attribute longer than the message, no message. */
static void test_parse_malformed(void **state)
{
	struct answer a;
	size_t n = build(&a, 20);
	int ms = -1;

	(void)state;
	assert_int_equal(gl_route_parse(&a, n - 6, &ms), GL_ERR_PROTO);
	build(&a, 20);
	((struct rtattr *)a.attrs)->rta_len = 200;
	assert_int_equal(gl_route_parse(&a, n, &ms), GL_ERR_PROTO);
	assert_int_equal(gl_route_parse(&a, 0, &ms), GL_ERR_PROTO);
	a.h.nlmsg_type = NLMSG_DONE;
	a.h.nlmsg_len = NLMSG_LENGTH(0);
	assert_int_equal(gl_route_parse(&a, NLMSG_LENGTH(0), &ms),
			 GL_ERR_PROTO);
}

/* A live lookup: the loopback route sets no rto_min; an unconnected socket
 * is refused. */
static void test_live_loopback(void **state)
{
	struct sockaddr_in sa = {.sin_family = AF_INET};
	socklen_t len = sizeof(sa);
	int lfd = socket(AF_INET, SOCK_STREAM, 0);
	int fd = socket(AF_INET, SOCK_STREAM, 0), ms = -1;

	(void)state;
	sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
	assert_true(lfd >= 0 && fd >= 0);
	assert_int_equal(gl_route_rto_min_ms(fd, 1000, &ms), GL_ERR_ARG);
	assert_int_equal(bind(lfd, (struct sockaddr *)&sa, sizeof(sa)), 0);
	assert_int_equal(listen(lfd, 1), 0);
	assert_int_equal(getsockname(lfd, (struct sockaddr *)&sa, &len), 0);
	assert_int_equal(connect(fd, (struct sockaddr *)&sa, sizeof(sa)), 0);
	assert_int_equal(gl_route_rto_min_ms(fd, 1000, &ms), GL_OK);
	assert_int_equal(ms, 0);
	close(fd);
	close(lfd);
}

/* Append a 4-byte attribute to answer @a (built by build()). */
static void add_u32(struct answer *a, unsigned short type, uint32_t v)
{
	struct rtattr *r =
	    (struct rtattr *)((char *)a + NLMSG_ALIGN(a->h.nlmsg_len));

	r->rta_type = type;
	r->rta_len = RTA_LENGTH(4);
	memcpy(RTA_DATA(r), &v, 4);
	a->h.nlmsg_len = NLMSG_ALIGN(a->h.nlmsg_len) + RTA_SPACE(4);
}

/* A route through a gateway on interface 3; a direct one on interface 2;
 * neither attribute: no gateway, interface 0. */
static void test_parse_gateway(void **state)
{
	struct answer a;
	struct gl_route_info ri;

	(void)state;
	build(&a, 20);
	add_u32(&a, RTA_GATEWAY, htonl(0x0a000001));
	add_u32(&a, RTA_OIF, 3);
	assert_int_equal(gl_route_parse_info(&a, a.h.nlmsg_len, &ri), GL_OK);
	assert_int_equal(ri.gateway, 1);
	assert_int_equal(ri.oif, 3);
	assert_int_equal(ri.rto_min_ms, 20);
	assert_string_equal(ri.ifname, "");
	build(&a, 0);
	add_u32(&a, RTA_OIF, 2);
	assert_int_equal(gl_route_parse_info(&a, a.h.nlmsg_len, &ri), GL_OK);
	assert_int_equal(ri.gateway, 0);
	assert_int_equal(ri.oif, 2);
	build(&a, -1);
	assert_int_equal(gl_route_parse_info(&a, a.h.nlmsg_len, &ri), GL_OK);
	assert_int_equal(ri.gateway, 0);
	assert_int_equal(ri.oif, 0);
}

/* A live lookup: to 127.0.0.1 the route is a direct link on "lo". */
static void test_live_direct(void **state)
{
	struct sockaddr_in sa = {.sin_family = AF_INET};
	socklen_t len = sizeof(sa);
	int lfd = socket(AF_INET, SOCK_STREAM, 0);
	int fd = socket(AF_INET, SOCK_STREAM, 0);
	struct gl_route_info ri;

	(void)state;
	sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
	assert_true(lfd >= 0 && fd >= 0);
	assert_int_equal(bind(lfd, (struct sockaddr *)&sa, sizeof(sa)), 0);
	assert_int_equal(listen(lfd, 1), 0);
	assert_int_equal(getsockname(lfd, (struct sockaddr *)&sa, &len), 0);
	assert_int_equal(connect(fd, (struct sockaddr *)&sa, sizeof(sa)), 0);
	assert_int_equal(gl_route_get(fd, 1000, &ri), GL_OK);
	assert_int_equal(ri.gateway, 0);
	assert_string_equal(ri.ifname, "lo");
	close(fd);
	close(lfd);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
	    cmocka_unit_test(test_parse_rto_min),
	    cmocka_unit_test(test_parse_absent),
	    cmocka_unit_test(test_parse_error_answer),
	    cmocka_unit_test(test_parse_gateway),
	    cmocka_unit_test(test_live_direct),
	    cmocka_unit_test(test_parse_malformed),
	    cmocka_unit_test(test_live_loopback),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
