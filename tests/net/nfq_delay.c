/*
 * nfq_delay.c - nfq-delay: hold every packet of one NFQUEUE queue for a
 * fixed time, then accept it, in arrival order: a one-way delay for kernels
 * without the netem qdisc (tests/net/netns_rig.sh, docs/link.md).
 *
 * Usage: nfq-delay QUEUE DELAY_MS. Prints "nfq-delay: ready" once bound,
 * runs until SIGTERM/SIGINT, then accepts what it still holds. Packets
 * beyond HOLD_MAX waiting are accepted at once (counted, printed at exit
 * on stderr). A test tool: not installed, not part of roboelf.
 */
#include <errno.h>
#include <poll.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <arpa/inet.h>
#include <linux/netfilter.h>
#include <libnetfilter_queue/libnetfilter_queue.h>

#define HOLD_MAX 8192

struct held {
	uint32_t id;
	long long due_us;
};

static struct held ring[HOLD_MAX];
static size_t head, count;
static long long delay_us;
static unsigned long overflow;
static volatile sig_atomic_t stop;

static void on_signal(int sig)
{
	(void)sig;
	stop = 1;
}

static long long now_us(void)
{
	struct timespec ts;

	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (long long)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

static int on_packet(struct nfq_q_handle *qh, struct nfgenmsg *msg,
		     struct nfq_data *nfa, void *data)
{
	struct nfqnl_msg_packet_hdr *ph = nfq_get_msg_packet_hdr(nfa);
	uint32_t id;

	(void)msg;
	(void)data;
	if (!ph)
		return 0;
	id = ntohl(ph->packet_id);
	if (count == HOLD_MAX) {
		overflow++;
		return nfq_set_verdict(qh, id, NF_ACCEPT, 0, NULL);
	}
	ring[(head + count) % HOLD_MAX] =
	    (struct held){.id = id, .due_us = now_us() + delay_us};
	count++;
	return 0;
}

/* Accept every held packet that is due (all of them with @all). */
static void release(struct nfq_q_handle *qh, int all)
{
	long long t = now_us();

	while (count && (all || ring[head].due_us <= t)) {
		nfq_set_verdict(qh, ring[head].id, NF_ACCEPT, 0, NULL);
		head = (head + 1) % HOLD_MAX;
		count--;
	}
}

static int wait_ms(void)
{
	long long d;

	if (!count)
		return 100;
	d = ring[head].due_us - now_us();
	return d <= 0 ? 0 : (int)((d + 999) / 1000);
}

static int run(struct nfq_handle *h, struct nfq_q_handle *qh)
{
	char buf[65536] __attribute__((aligned));
	struct pollfd pfd = {.fd = nfq_fd(h), .events = POLLIN};

	while (!stop) {
		int n = poll(&pfd, 1, wait_ms());

		if (n < 0 && errno != EINTR)
			return -1;
		if (n > 0) {
			ssize_t len = recv(pfd.fd, buf, sizeof(buf), 0);

			if (len > 0)
				nfq_handle_packet(h, buf, (int)len);
			else if (len < 0 && errno != EINTR && errno != ENOBUFS)
				return -1;
		}
		release(qh, 0);
	}
	release(qh, 1);
	return 0;
}

int main(int argc, char **argv)
{
	struct nfq_handle *h;
	struct nfq_q_handle *qh;
	int rc;

	if (argc != 3) {
		fprintf(stderr, "usage: nfq-delay QUEUE DELAY_MS\n");
		return 2;
	}
	delay_us = atoll(argv[2]) * 1000;
	signal(SIGTERM, on_signal);
	signal(SIGINT, on_signal);
	h = nfq_open();
	if (!h || nfq_bind_pf(h, AF_INET) < 0) {
		fprintf(stderr, "nfq-delay: cannot open nfqueue: %s\n",
			strerror(errno));
		return 1;
	}
	qh = nfq_create_queue(h, (uint16_t)atoi(argv[1]), on_packet, NULL);
	if (!qh || nfq_set_mode(qh, NFQNL_COPY_META, 0) < 0) {
		fprintf(stderr, "nfq-delay: cannot bind queue %s: %s\n",
			argv[1], strerror(errno));
		nfq_close(h);
		return 1;
	}
	nfq_set_queue_maxlen(qh, HOLD_MAX);
	printf("nfq-delay: ready\n");
	fflush(stdout);
	rc = run(h, qh);
	if (overflow)
		fprintf(stderr, "nfq-delay: %lu packets not delayed\n",
			overflow);
	nfq_destroy_queue(qh);
	nfq_close(h);
	return rc < 0 ? 1 : 0;
}
