/*
 * proc.h - test helpers for system tests: spawn a program with its stdout and
 * stderr on pipes, wait for a line with a deadline, send signals, reap it with
 * a deadline, kill it by pid on teardown; start galil-sim and read its ready
 * line; a tiny client for galil-sim's control port.
 *
 * Every wait has a deadline and polls file descriptors (no sleep-and-hope).
 * Processes are only ever signalled by their own pid, never by name.
 */
#ifndef TESTS_PROC_H
#define TESTS_PROC_H

#include <stddef.h>
#include <sys/types.h>

enum proc_stream {
	PROC_STDOUT = 0,
	PROC_STDERR = 1,
};

struct proc_buf {
	char *data; /* everything read so far, NUL-terminated */
	size_t len;
	size_t cap;
	size_t cursor; /* proc_wait_line() searches from here */
	int fd;	       /* read end of the pipe, -1 when at EOF */
};

struct proc {
	pid_t pid;  /* 0 when not running or already reaped */
	int status; /* waitpid() status once reaped */
	int reaped;
	int stdin_fd;		/* write end of the child's stdin, or -1 */
	struct proc_buf out[2]; /* PROC_STDOUT, PROC_STDERR */
};

/*
 * proc_spawn() - start @argv[0] with @argv, stdout/stderr on pipes, stdin on
 * a pipe (so the child is never on a terminal).
 * @p: [out] the process; call proc_kill() on it in every case.
 * @env: optional extra "NAME=value" strings (NULL-terminated), or NULL.
 * Return: 0, or -1 with errno set.
 */
int proc_spawn(struct proc *p, char *const argv[], char *const env[]);

/*
 * proc_pump() - read whatever is available on both pipes, waiting at most
 * @timeout_ms for the first byte. Return: 0, or -1 when both pipes are at EOF.
 */
int proc_pump(struct proc *p, int timeout_ms);

/*
 * proc_wait_line() - wait until a complete line starting with @prefix appears
 * on @s after the stream's cursor; the cursor moves past that line.
 * @line: [out] optional copy of the line without the newline.
 * Return: 0 when found; -1 on timeout or when the stream ended first.
 */
int proc_wait_line(struct proc *p, enum proc_stream s, const char *prefix,
		   int timeout_ms, char *line, size_t cap);

/*
 * proc_find_line() - like proc_wait_line() but over everything read so far,
 * without waiting and without moving the cursor.
 * Return: 0 when found, -1 otherwise.
 */
int proc_find_line(const struct proc *p, enum proc_stream s, const char *prefix,
		   char *line, size_t cap);

/* proc_output() - everything read from @s so far (NUL-terminated). */
const char *proc_output(const struct proc *p, enum proc_stream s);

/* proc_signal() - send @sig to the process by its pid. Return: 0 or -1. */
int proc_signal(struct proc *p, int sig);

/*
 * proc_write() - write @text to the child's stdin. Return: 0 or -1.
 */
int proc_write(struct proc *p, const char *text);

/*
 * proc_wait_exit() - reap the process within @timeout_ms, reading its output
 * meanwhile. @status: [out] the waitpid() status.
 * Return: 0 when reaped, -1 on timeout (the process is left running).
 */
int proc_wait_exit(struct proc *p, int timeout_ms, int *status);

/*
 * proc_exit_code() - the exit code of a reaped process, or -1 when it did
 * not exit normally (signal) or is not reaped.
 */
int proc_exit_code(const struct proc *p);

/*
 * proc_kill() - teardown: SIGKILL by pid if still running, reap, close the
 * pipes, free the buffers. Safe to call twice and on a zeroed struct.
 */
void proc_kill(struct proc *p);

/* ---- galil-sim --------------------------------------------------------- */

struct proc_sim {
	struct proc p;
	int port;	 /* controller TCP port */
	int ctl_port;	 /* control port */
	char relay[256]; /* relay pty path as printed */
	int udp_port;	 /* UDP command port (--udp-port), 0 = off */
};

/*
 * proc_sim_start() - start @bin_dir/galil-sim --port 0 --control-port 0
 * [--relay-link @relay_link, or --no-relay-link when NULL] [@extra...] and
 * wait (@timeout_ms) for its line
 * "galil-sim: listening on 127.0.0.1:<port> control <port> relay <path>"
 * (with " udp <port>" at its end when @extra asks for --udp-port).
 * @extra: optional NULL-terminated extra arguments, or NULL.
 * Return: 0, or -1 (the process is killed and reaped).
 */
int proc_sim_start(struct proc_sim *s, const char *bin_dir,
		   const char *relay_link, char *const extra[], int timeout_ms);

/*
 * proc_sim_start_wrapped() - proc_sim_start() with galil-sim run through
 * @wrap (a NULL-terminated argv prefix that ends by exec'ing its arguments,
 * e.g. {"ip", "netns", "exec", "NS", NULL}, so that the pid is galil-sim's),
 * or directly when @wrap is NULL; with @listen (an IPv4 address, or NULL for
 * 127.0.0.1) given as --listen.
 * Return: 0, or -1 (the process is killed and reaped).
 */
int proc_sim_start_wrapped(struct proc_sim *s, char *const wrap[],
			   const char *bin_dir, const char *relay_link,
			   const char *listen, char *const extra[],
			   int timeout_ms);

/* ---- galil-sim control port client ------------------------------------- */

/*
 * proc_ctl_connect() - connect to 127.0.0.1:@port within @timeout_ms.
 * Return: the socket, or -1.
 */
int proc_ctl_connect(int port, int timeout_ms);

/*
 * proc_ctl_connect_at() - connect to @addr (dotted IPv4; NULL or "": 127.0.0.1)
 * port @port within @timeout_ms. Return: the socket, or -1.
 */
int proc_ctl_connect_at(const char *addr, int port, int timeout_ms);

/*
 * proc_ctl_request() - send "@req\n" and read one answer line (without the
 * newline) into @resp.
 * Return: the length of @resp, or -1 on error or timeout.
 */
int proc_ctl_request(int fd, const char *req, char *resp, size_t cap,
		     int timeout_ms);

/*
 * proc_ctl_request_multi() - send "@req\n" and read lines until a line "end"
 * (not included); the lines are joined with '\n' into @resp.
 * Return: the length of @resp, or -1 on error, timeout or overflow.
 */
int proc_ctl_request_multi(int fd, const char *req, char *resp, size_t cap,
			   int timeout_ms);

/*
 * proc_ctl_state_get() - the value of "@key=" in a "state" answer line.
 * Return: 0 with @val filled, or -1 when the key is absent.
 */
int proc_ctl_state_get(const char *state, const char *key, char *val,
		       size_t cap);

/* proc_now_ms() - CLOCK_MONOTONIC in ms. */
long long proc_now_ms(void);

#endif /* TESTS_PROC_H */
