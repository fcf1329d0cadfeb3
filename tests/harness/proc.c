/*
 * proc.c - spawn, watch and reap test processes; galil-sim start-up and its
 * control-port client. See proc.h.
 */
#include "proc.h"

#include <errno.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <arpa/inet.h>

#include "base_clock.h"

#define PROC_BUF_INIT 4096

long long proc_now_ms(void)
{
	return (long long)base_now_ms();
}

static int remaining_ms(long long deadline_ms)
{
	long long left = deadline_ms - proc_now_ms();

	return left < 0 ? 0 : (int)left;
}

static int buf_init(struct proc_buf *b, int fd)
{
	b->data = malloc(PROC_BUF_INIT);
	if (!b->data)
		return -1;
	b->data[0] = '\0';
	b->len = 0;
	b->cap = PROC_BUF_INIT;
	b->cursor = 0;
	b->fd = fd;
	return 0;
}

static int buf_reserve(struct proc_buf *b, size_t more)
{
	char *n;
	size_t cap = b->cap;

	if (b->len + more + 1 <= cap)
		return 0;
	if (cap == 0)
		return -1;
	while (b->len + more + 1 > cap)
		cap *= 2;
	n = realloc(b->data, cap);
	if (!n)
		return -1;
	b->data = n;
	b->cap = cap;
	return 0;
}

/* Read once from a readable pipe; mark EOF. */
static void buf_read(struct proc_buf *b)
{
	ssize_t n;

	if (buf_reserve(b, 4096) < 0)
		return;
	n = read(b->fd, b->data + b->len, b->cap - b->len - 1);
	if (n > 0) {
		b->len += (size_t)n;
		b->data[b->len] = '\0';
	} else if (n == 0 || (errno != EINTR && errno != EAGAIN)) {
		close(b->fd);
		b->fd = -1;
	}
}

static void child_exec(char *const argv[], char *const env[], int in[2],
		       int out[2], int err[2])
{
	dup2(in[0], 0);
	dup2(out[1], 1);
	dup2(err[1], 2);
	close(in[0]);
	close(in[1]);
	close(out[0]);
	close(out[1]);
	close(err[0]);
	close(err[1]);
	for (int i = 0; env && env[i]; i++)
		putenv(env[i]);
	execv(argv[0], argv);
	fprintf(stderr, "proc: cannot run '%s': %s\n", argv[0],
		strerror(errno));
	_exit(127);
}

static void close_pair(int fd[2])
{
	if (fd[0] >= 0)
		close(fd[0]);
	if (fd[1] >= 0)
		close(fd[1]);
}

int proc_spawn(struct proc *p, char *const argv[], char *const env[])
{
	int in[2] = {-1, -1}, out[2] = {-1, -1}, err[2] = {-1, -1};

	memset(p, 0, sizeof(*p));
	p->stdin_fd = p->out[0].fd = p->out[1].fd = -1;
	if (pipe(in) < 0 || pipe(out) < 0 || pipe(err) < 0)
		goto out_close;
	if (buf_init(&p->out[0], out[0]) < 0 ||
	    buf_init(&p->out[1], err[0]) < 0)
		goto out_close;
	p->pid = fork();
	if (p->pid < 0)
		goto out_close;
	if (p->pid == 0)
		child_exec(argv, env, in, out, err);
	close(in[0]);
	close(out[1]);
	close(err[1]);
	p->stdin_fd = in[1];
	fcntl(out[0], F_SETFD, FD_CLOEXEC);
	fcntl(err[0], F_SETFD, FD_CLOEXEC);
	fcntl(in[1], F_SETFD, FD_CLOEXEC);
	signal(SIGPIPE, SIG_IGN);
	return 0;

out_close:
	close_pair(in);
	close_pair(out);
	close_pair(err);
	p->out[0].fd = p->out[1].fd = -1;
	p->pid = 0;
	return -1;
}

int proc_pump(struct proc *p, int timeout_ms)
{
	struct pollfd pfd[2];
	int n = 0, map[2];

	for (int i = 0; i < 2; i++) {
		if (!p->out[i].data || p->out[i].fd < 0)
			continue; /* never spawned, or at EOF */
		pfd[n].fd = p->out[i].fd;
		pfd[n].events = POLLIN;
		map[n++] = i;
	}
	if (n == 0)
		return -1;
	if (poll(pfd, (nfds_t)n, timeout_ms) <= 0)
		return 0;
	for (int i = 0; i < n; i++)
		if (pfd[i].revents & (POLLIN | POLLHUP | POLLERR))
			buf_read(&p->out[map[i]]);
	return 0;
}

/* Search complete lines of @b from @from for @prefix; return the offset. */
static long find_line(const struct proc_buf *b, size_t from, const char *prefix,
		      size_t *end)
{
	size_t plen = strlen(prefix);
	size_t pos = from;

	while (pos < b->len) {
		const char *nl = memchr(b->data + pos, '\n', b->len - pos);

		if (!nl)
			return -1;
		size_t e = (size_t)(nl - b->data);
		if (e - pos >= plen && !memcmp(b->data + pos, prefix, plen)) {
			*end = e;
			return (long)pos;
		}
		pos = e + 1;
	}
	return -1;
}

static void copy_line(const struct proc_buf *b, size_t start, size_t end,
		      char *line, size_t cap)
{
	size_t n = end - start;

	if (!line || cap == 0)
		return;
	if (n >= cap)
		n = cap - 1;
	memcpy(line, b->data + start, n);
	line[n] = '\0';
	if (n > 0 && line[n - 1] == '\r')
		line[n - 1] = '\0';
}

int proc_wait_line(struct proc *p, enum proc_stream s, const char *prefix,
		   int timeout_ms, char *line, size_t cap)
{
	long long deadline = proc_now_ms() + timeout_ms;
	struct proc_buf *b = &p->out[s];

	if (!b->data)
		return -1;
	for (;;) {
		size_t end;
		long at = find_line(b, b->cursor, prefix, &end);

		if (at >= 0) {
			copy_line(b, (size_t)at, end, line, cap);
			b->cursor = end + 1;
			return 0;
		}
		if (b->fd < 0 || remaining_ms(deadline) == 0)
			return -1;
		proc_pump(p, remaining_ms(deadline) < 20
				 ? remaining_ms(deadline)
				 : 20);
	}
}

int proc_find_line(const struct proc *p, enum proc_stream s, const char *prefix,
		   char *line, size_t cap)
{
	size_t end;
	long at = find_line(&p->out[s], 0, prefix, &end);

	if (at < 0)
		return -1;
	copy_line(&p->out[s], (size_t)at, end, line, cap);
	return 0;
}

const char *proc_output(const struct proc *p, enum proc_stream s)
{
	return p->out[s].data ? p->out[s].data : "";
}

int proc_signal(struct proc *p, int sig)
{
	if (p->pid <= 0 || p->reaped)
		return -1;
	return kill(p->pid, sig);
}

int proc_write(struct proc *p, const char *text)
{
	size_t len = strlen(text);

	if (p->stdin_fd < 0)
		return -1;
	return write(p->stdin_fd, text, len) == (ssize_t)len ? 0 : -1;
}

int proc_wait_exit(struct proc *p, int timeout_ms, int *status)
{
	long long deadline = proc_now_ms() + timeout_ms;

	while (!p->reaped && p->pid > 0) {
		pid_t r = waitpid(p->pid, &p->status, WNOHANG);

		if (r == p->pid) {
			p->reaped = 1;
			break;
		}
		if (r < 0 && errno != EINTR)
			return -1;
		if (remaining_ms(deadline) == 0)
			return -1;
		if (proc_pump(p, 10) < 0)
			poll(NULL, 0, 5); /* pipes closed: wait for exit */
	}
	/* the pipes' last bytes, until EOF or the deadline */
	while (remaining_ms(deadline) > 0 && proc_pump(p, 10) == 0)
		;
	if (status)
		*status = p->status;
	return p->reaped ? 0 : -1;
}

int proc_exit_code(const struct proc *p)
{
	if (!p->reaped || !WIFEXITED(p->status))
		return -1;
	return WEXITSTATUS(p->status);
}

void proc_kill(struct proc *p)
{
	if (p->pid > 0 && !p->reaped) {
		kill(p->pid, SIGKILL);
		while (waitpid(p->pid, &p->status, 0) < 0 && errno == EINTR)
			;
		p->reaped = 1;
	}
	for (int i = 0; i < 2; i++) {
		/* a zeroed struct has fd 0 but no buffer: not ours to close */
		if (p->out[i].data && p->out[i].fd >= 0)
			close(p->out[i].fd);
		p->out[i].fd = -1;
		free(p->out[i].data);
		p->out[i].data = NULL;
		p->out[i].len = p->out[i].cap = 0;
	}
	if (p->stdin_fd > 0)
		close(p->stdin_fd);
	p->stdin_fd = -1;
}

/* ---- galil-sim --------------------------------------------------------- */

static int sim_parse_ready(struct proc_sim *s, const char *line)
{
	char relay[256] = "";
	const char *udp;

	if (sscanf(line,
		   "galil-sim: listening on %*[0-9.]:%d control %d "
		   "relay %255s",
		   &s->port, &s->ctl_port, relay) < 2)
		return -1;
	snprintf(s->relay, sizeof(s->relay), "%s", relay);
	/* " udp <port>" follows the relay (and " disc <port>") when on */
	udp = strstr(line, " udp ");
	if (udp && sscanf(udp, " udp %d", &s->udp_port) != 1)
		return -1;
	return 0;
}

int proc_sim_start(struct proc_sim *s, const char *bin_dir,
		   const char *relay_link, char *const extra[], int timeout_ms)
{
	return proc_sim_start_wrapped(s, NULL, bin_dir, relay_link, NULL, extra,
				      timeout_ms);
}

int proc_sim_start_wrapped(struct proc_sim *s, char *const wrap[],
			   const char *bin_dir, const char *relay_link,
			   const char *listen, char *const extra[],
			   int timeout_ms)
{
	char bin[512], line[512];
	char *argv[48];
	int n = 0;

	memset(s, 0, sizeof(*s));
	snprintf(bin, sizeof(bin), "%s/galil-sim", bin_dir);
	for (int i = 0; wrap && wrap[i] && n < 12; i++)
		argv[n++] = wrap[i];
	argv[n++] = bin;
	if (listen) {
		argv[n++] = (char *)"--listen";
		argv[n++] = (char *)listen;
	}
	argv[n++] = (char *)"--port";
	argv[n++] = (char *)"0";
	argv[n++] = (char *)"--control-port";
	argv[n++] = (char *)"0";
	if (relay_link) {
		argv[n++] = (char *)"--relay-link";
		argv[n++] = (char *)relay_link;
	} else {
		/* never the shared default /tmp/roboelf-relay: tests and a
		 * running demo must not meet there */
		argv[n++] = (char *)"--no-relay-link";
	}
	for (int i = 0; extra && extra[i] && n < 47; i++)
		argv[n++] = extra[i];
	argv[n] = NULL;
	if (proc_spawn(&s->p, argv, NULL) < 0)
		return -1;
	if (proc_wait_line(&s->p, PROC_STDOUT, "galil-sim: listening on ",
			   timeout_ms, line, sizeof(line)) < 0 ||
	    sim_parse_ready(s, line) < 0) {
		proc_kill(&s->p);
		return -1;
	}
	return 0;
}

/* ---- control port ------------------------------------------------------ */

int proc_ctl_connect(int port, int timeout_ms)
{
	return proc_ctl_connect_at(NULL, port, timeout_ms);
}

int proc_ctl_connect_at(const char *addr, int port, int timeout_ms)
{
	long long deadline = proc_now_ms() + timeout_ms;
	struct sockaddr_in sa;

	memset(&sa, 0, sizeof(sa));
	sa.sin_family = AF_INET;
	sa.sin_port = htons((uint16_t)port);
	if (inet_pton(AF_INET, addr && *addr ? addr : "127.0.0.1",
		      &sa.sin_addr) != 1)
		return -1;
	for (;;) {
		int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
		int one = 1;

		if (fd < 0)
			return -1;
		setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof(one));
		if (connect(fd, (struct sockaddr *)&sa, sizeof(sa)) == 0)
			return fd;
		close(fd);
		if (remaining_ms(deadline) == 0)
			return -1;
		poll(NULL, 0, 10);
	}
}

/* Read one line (up to '\n') from @fd into @line, CR stripped. */
static int read_line(int fd, char *line, size_t cap, long long deadline)
{
	size_t n = 0;

	for (;;) {
		struct pollfd pfd = {.fd = fd, .events = POLLIN};
		char c;

		if (poll(&pfd, 1, remaining_ms(deadline)) <= 0)
			return -1;
		if (read(fd, &c, 1) != 1)
			return -1;
		if (c == '\n')
			break;
		if (c == '\r')
			continue;
		if (n + 1 >= cap)
			return -1;
		line[n++] = c;
	}
	line[n] = '\0';
	return (int)n;
}

static int send_req(int fd, const char *req)
{
	char buf[512];
	int len = snprintf(buf, sizeof(buf), "%s\n", req);

	if (len < 0 || (size_t)len >= sizeof(buf))
		return -1;
	return send(fd, buf, (size_t)len, MSG_NOSIGNAL) == len ? 0 : -1;
}

int proc_ctl_request(int fd, const char *req, char *resp, size_t cap,
		     int timeout_ms)
{
	if (send_req(fd, req) < 0)
		return -1;
	return read_line(fd, resp, cap, proc_now_ms() + timeout_ms);
}

int proc_ctl_request_multi(int fd, const char *req, char *resp, size_t cap,
			   int timeout_ms)
{
	long long deadline = proc_now_ms() + timeout_ms;
	size_t len = 0;
	char line[1024];

	if (cap == 0 || send_req(fd, req) < 0)
		return -1;
	resp[0] = '\0';
	for (;;) {
		int n = read_line(fd, line, sizeof(line), deadline);

		if (n < 0)
			return -1;
		if (!strcmp(line, "end"))
			return (int)len;
		if (len + (size_t)n + 2 > cap)
			return -1;
		if (len > 0)
			resp[len++] = '\n';
		memcpy(resp + len, line, (size_t)n + 1);
		len += (size_t)n;
		if (!strncmp(line, "error:", 6) && len == (size_t)n)
			return (int)len;
	}
}

int proc_ctl_state_get(const char *state, const char *key, char *val,
		       size_t cap)
{
	size_t klen = strlen(key);
	const char *p = state;

	while (p && *p) {
		while (*p == ' ')
			p++;
		if (!strncmp(p, key, klen) && p[klen] == '=') {
			const char *v = p + klen + 1;
			size_t n = strcspn(v, " \n");

			if (n >= cap)
				n = cap - 1;
			memcpy(val, v, n);
			val[n] = '\0';
			return 0;
		}
		p = strchr(p, ' ');
	}
	return -1;
}
