/*
 * sim_ctlport.c - galil-sim's control port line framing (see
 * sim_ctlport.h). The requests themselves are sim_control()'s.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "gl_err.h"
#include "sim.h"
#include "sim_ctlport.h"
#include "sim_sock.h"

void sim_ctlport_init(struct sim_ctlport *cp, struct sim *s)
{
	memset(cp, 0, sizeof(*cp));
	cp->sim = s;
	cp->lfd = -1;
	for (int i = 0; i < SIM_CTLPORT_CLIENTS; i++)
		cp->client[i].fd = -1;
}

int sim_ctlport_listen(struct sim_ctlport *cp, const char *addr, int port,
		       char *err, size_t errlen)
{
	cp->lfd = sim_sock_listen(addr, port, &cp->port, err, errlen);
	return cp->lfd < 0 ? GL_ERR_SYS : 0;
}

static void client_close(struct sim_ctlport_client *cl)
{
	if (cl->fd >= 0)
		close(cl->fd);
	cl->fd = -1;
	free(cl->out);
	cl->out = NULL;
}

void sim_ctlport_shutdown(struct sim_ctlport *cp)
{
	for (int i = 0; i < SIM_CTLPORT_CLIENTS; i++)
		client_close(&cp->client[i]);
	if (cp->lfd >= 0)
		close(cp->lfd);
	cp->lfd = -1;
}

int sim_ctlport_fd(const struct sim_ctlport *cp, int i)
{
	if (i < 0 || i >= SIM_CTLPORT_CLIENTS || cp->client[i].out_len)
		return -1;
	return cp->client[i].fd;
}

void sim_ctlport_accept(struct sim_ctlport *cp)
{
	int fd = accept(cp->lfd, NULL, NULL), i;

	if (fd < 0)
		return;
	for (i = 0; i < SIM_CTLPORT_CLIENTS && cp->client[i].fd >= 0; i++)
		;
	if (i == SIM_CTLPORT_CLIENTS) {
		static const char busy[] = "error: too many control clients\n";

		(void)!send(fd, busy, sizeof(busy) - 1, MSG_NOSIGNAL);
		close(fd);
		return;
	}
	memset(&cp->client[i], 0, sizeof(cp->client[i]));
	cp->client[i].out = malloc(SIM_RESPONSE_MAX + 1);
	if (!cp->client[i].out) {
		close(fd);
		cp->client[i].fd = -1;
		return;
	}
	sim_sock_nonblock(fd);
	cp->client[i].fd = fd;
}

static void client_answer(struct sim_ctlport *cp, struct sim_ctlport_client *cl,
			  char *line)
{
	size_t len = strlen(line);

	if (len && line[len - 1] == '\r')
		line[--len] = '\0';
	if (cl->discarding) {
		snprintf(cl->out, SIM_RESPONSE_MAX,
			 "error: request too long "
			 "(at most %d bytes)",
			 SIM_REQUEST_MAX - 1);
		cl->discarding = 0;
	} else {
		sim_control(cp->sim, line, cl->out, SIM_RESPONSE_MAX);
	}
	cl->out_len = strlen(cl->out);
	cl->out[cl->out_len++] = '\n';
	cl->out_sent = 0;
}

/* Answer the next complete line, if the previous answer has gone. */
static void client_process(struct sim_ctlport *cp,
			   struct sim_ctlport_client *cl)
{
	char *nl;
	size_t used;

	while (cl->fd >= 0 && cl->out_len == 0) {
		nl = memchr(cl->in, '\n', cl->in_len);
		if (!nl) {
			if (cl->in_len == sizeof(cl->in)) {
				cl->discarding = 1; /* keep the tail only */
				cl->in_len = 0;
			}
			return;
		}
		*nl = '\0';
		used = (size_t)(nl - cl->in) + 1;
		client_answer(cp, cl, cl->in);
		memmove(cl->in, cl->in + used, cl->in_len - used);
		cl->in_len -= used;
	}
}

void sim_ctlport_read(struct sim_ctlport *cp, int i)
{
	struct sim_ctlport_client *cl;
	ssize_t r;

	if (i < 0 || i >= SIM_CTLPORT_CLIENTS || cp->client[i].fd < 0)
		return;
	cl = &cp->client[i];
	r = recv(cl->fd, cl->in + cl->in_len, sizeof(cl->in) - cl->in_len, 0);
	if (r < 0 && sim_sock_again(errno))
		return;
	if (r <= 0) {
		client_close(cl);
		return;
	}
	cl->in_len += (size_t)r;
	client_process(cp, cl);
}

static void client_flush(struct sim_ctlport *cp, struct sim_ctlport_client *cl)
{
	ssize_t w;

	if (cl->fd < 0 || cl->out_sent == cl->out_len)
		return;
	w = send(cl->fd, cl->out + cl->out_sent, cl->out_len - cl->out_sent,
		 MSG_NOSIGNAL);
	if (w < 0 && sim_sock_again(errno))
		return;
	if (w < 0) {
		client_close(cl);
		return;
	}
	cl->out_sent += (size_t)w;
	if (cl->out_sent == cl->out_len) {
		cl->out_len = cl->out_sent = 0;
		client_process(cp, cl);
	}
}

void sim_ctlport_flush(struct sim_ctlport *cp)
{
	for (int i = 0; i < SIM_CTLPORT_CLIENTS; i++)
		client_flush(cp, &cp->client[i]);
}
