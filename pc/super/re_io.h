/*
 * re_io.h - the supervisor's outside world behind one table of functions:
 * the controller link, the E-stop relay, the failure log and the clock.
 *
 * The cycle (re_super) and the calibration procedure (re_calib) talk to the
 * world only through struct re_io, so that unit tests can run them against a
 * fake controller and a fake clock (tests/unit/test_re_super.c) while
 * roboelf binds the real gl_link, re_relay and re_log (re_io_bind()).
 * Nothing here prints. The real binding allocates nothing per call.
 */
#ifndef RE_IO_H
#define RE_IO_H

#include <stddef.h>
#include <stdint.h>

#include "gl_link.h"
#include "gl_record.h"
#include "gl_stream.h"
#include "re_log.h"

#include <time.h>
#include "re_relay.h"

/*
 * The one command that stops every axis and switches the motors off: AB 1
 * aborts the motion only (a bare AB would abort the program too), and MO is
 * refused while an axis still decelerates (so not "ST ABC;MO ABC").
 */
#define RE_STOP_ALL "AB 1;MO ABC"

/* The PC heartbeat hbpc counts 0 .. RE_HBPC_WRAP - 1 (the DMC's hbpcwr):
 * a session starts at a random value and adds 1 per write, so a value
 * from another writer is out of sequence (dmc-interface.md, #HBCHK). */
#define RE_HBPC_WRAP 1000000000L

struct re_io_ops {
	/* gl_link_record(): one "[prefix;]QR" round trip. */
	int (*record)(void *ud, const char *prefix, struct gl_record *rec,
		      int timeout_ms);
	/* gl_link_record_text(): the same with data-answering commands in
	 * the prefix (the seal's read-back), their text in @text. Optional:
	 * NULL when the back-end cannot (no read-back then). */
	int (*record_text)(void *ud, const char *prefix, struct gl_record *rec,
			   char *text, size_t cap, int timeout_ms);
	/* gl_link_command(): one command line and its reply. */
	int (*command)(void *ud, const char *cmd, char *resp, size_t cap,
		       int timeout_ms);
	/* gl_link_ctrl_error(): the TC1 text (and code, @code may be NULL)
	 * after GL_ERR_CTRL; never NULL. */
	const char *(*ctrl_error)(void *ud, int *code);
	/* gl_link_message(): one unsolicited line; GL_ERR_AGAIN if none. */
	int (*message)(void *ud, char *line, size_t cap);
	/* re_relay_check(): GL_OK or GL_ERR_RELAY with @why filled. */
	int (*relay_check)(void *ud, char *why, size_t cap);
	/* re_relay_off(): start and confirm within relay.off_deadline_ms.
	 * GL_OK; GL_ERR_TIMEOUT (not confirmed by then); GL_ERR_RELAY. */
	int (*relay_off)(void *ud);
	/* re_relay_off_start(): hand "off" to the driver without waiting,
	 * so that the controller can be stopped while the bytes travel.
	 * GL_OK, or GL_ERR_RELAY (relay_off_finish reopens and retries);
	 * relay_off_finish must follow. */
	int (*relay_off_start)(void *ud);
	/* re_relay_off_finish(): confirm that "off" within @deadline_ms
	 * (from the call). Return: as relay_off. */
	int (*relay_off_finish)(void *ud, int deadline_ms);
	/* Optional (NULL: not attempted). Deliver one command line over a new
	 * connection to the controller (the old one is out of step or gone),
	 * connect and reply within @deadline_ms in all (a refused connect is
	 * tried again every 10 ms within it); on success the new connection
	 * replaces the command link. Return: as command(). */
	int (*stop_fresh)(void *ud, const char *cmd, char *resp, size_t cap,
			  int deadline_ms);
	/* re_relay_state(): what was last confirmed written. */
	enum re_relay_state (*relay_state)(void *ud);
	/* re_log: one event; RE_LOG_FAULT is on disk (fsync) on return. */
	int (*log)(void *ud, enum re_log_level lvl, const char *text);
	/* The stream design (re_super_cfg.stream); NULL when the back-end
	 * has none. gl_link_post(): send a line, its reply comes later. */
	int (*post)(void *ud, const char *line);
	/* gl_link_collect(): the posted line's reply if all there, without
	 * waiting: its text length, GL_ERR_AGAIN, or an error. */
	int (*collect)(void *ud, char *text, size_t cap);
	/* gl_link_stream_read(): 1 and the newest record in @rec, 0 none
	 * new, or an error; @now_ns is the time of reception. */
	int (*stream)(void *ud, struct gl_record *rec, int64_t now_ns);
	/* Optional (NULL: none shown). gl_link_stream_stats(): the records
	 * the stream's reader accepted and counted lost so far; 0, or -1
	 * when no stream is open. No I/O. */
	int (*stream_counts)(void *ud, uint64_t *records, uint64_t *lost);
	/* CLOCK_MONOTONIC, ns. */
	int64_t (*now_ns)(void *ud);
	/* Sleep until the absolute monotonic time @t_ns. */
	void (*sleep_until)(void *ud, int64_t t_ns);
};

struct re_io {
	const struct re_io_ops *ops;
	void *ud;
};

#define RE_IO_LOGQ     16  /* log events queued between two flushes */
#define RE_IO_LOGQ_LEN 512 /* longer queued texts are cut */

/* One INFO/WARN event queued inside a cycle (no file write in
 * the cycle), with the times it happened at. */
struct re_io_logq_ent {
	enum re_log_level lvl;
	struct timespec wall; /* CLOCK_REALTIME (vDSO: no system call) */
	int64_t mono_ns;
	char text[RE_IO_LOGQ_LEN];
};

/* The descriptors of the cycle's one look. */
enum re_io_look_fd {
	RE_LOOK_CMD,   /* the command socket: stray bytes before a request */
	RE_LOOK_MSG,   /* the message socket */
	RE_LOOK_RELAY, /* the relay port: error, hang-up (events 0) */
	RE_LOOK_WATCH, /* the relay path's inotify watch */
	RE_LOOK_KEY,   /* the keyboard (key_fd, when watch_key) */
	RE_LOOK_N
};

/*
 * What the wait before a cycle saw (one look per cycle). The
 * wait (ops->sleep_until) is a ppoll() over every descriptor the cycle
 * reads; a descriptor that shows an event is noted and left out for the
 * rest of the wait. Each reader then takes its entry once, and skips its
 * own look (a recv, poll or read that would find nothing) when the entry
 * shows no event: fd[i] is the descriptor seen (-1: not looked at, or
 * taken), so a reader whose descriptor changed since looks itself.
 */
struct re_io_look {
	int fd[RE_LOOK_N];
	short revents[RE_LOOK_N];
};

/* The real world: any member may be NULL (then its calls fail safely). */
struct re_io_real {
	gl_link *link;
	re_relay *relay;
	struct re_log *log;
	const char *address; /* the controller, for stop_fresh; NULL: none */
	int cmd_timeout_ms;  /* the command link's default reply deadline */
	/* the record stream's counters of a link the stop over a new
	 * connection replaced (have_stream_was: 1 when kept) */
	struct gl_stream_stats stream_was;
	int have_stream_was;
	/* CLOCK_MONOTONIC ns at the start and the end of the last record or
	 * command: a moment this process is known to have run (roboelf's
	 * SIGCONT handler reads it to measure a stop) */
	volatile int64_t last_run_ns;
	/* defer_log: INFO/WARN events are queued (FAULT ones flush the queue
	 * and go to disk at once) until re_io_flush_log() */
	int defer_log;
	unsigned logq_n;
	unsigned long logq_dropped;
	struct re_io_logq_ent logq[RE_IO_LOGQ];
	/* the keyboard, looked at in the wait when watch_key is set */
	int key_fd;
	int watch_key;
	struct re_io_look look; /* set by the wait; see re_io_look */
};

/*
 * re_io_bind() - point @io at the real link, relay, log and clock in @real.
 * @real must outlive @io. Calls on a NULL link return GL_ERR_CLOSED, on a
 * NULL relay GL_ERR_RELAY; log calls on a NULL or closed log do nothing.
 */
void re_io_bind(struct re_io *io, struct re_io_real *real);

/*
 * re_io_flush_log() - write the INFO/WARN events queued while
 * @real->defer_log was set, in order, with the times they happened at;
 * then, if the queue overflowed, one WARN saying how many were dropped.
 * Called between cycles (after the cycle's work), never inside one.
 * Return: GL_OK, or the first error of re_log_write_at().
 */
int re_io_flush_log(struct re_io_real *real);

/*
 * re_io_key_look() - what the wait before this cycle saw of the keyboard
 * (@real->key_fd, when @real->watch_key); its entry is then taken.
 * No system call. Return: 1 input (or end of it) is waiting, 0 none,
 * -1 not looked at (read it at the caller's own rate).
 */
int re_io_key_look(struct re_io_real *real);

/* re_io_now_ns() - CLOCK_MONOTONIC in ns (for callers without an io). */
int64_t re_io_now_ns(void);

/*
 * re_io_logf() - printf-style log event through @io (INFO, WARN or FAULT).
 * Formats into a stack buffer; no allocation. Return: as ops->log.
 */
int re_io_logf(const struct re_io *io, enum re_log_level lvl, const char *fmt,
	       ...) __attribute__((format(printf, 3, 4)));

/*
 * re_io_read() - "MG <expr>" through @io and parse the one number.
 * @timeout_ms: 0 = the link default.
 * Return: GL_OK; an error of ops->command; GL_ERR_PROTO when the reply is
 *         not exactly one number.
 */
int re_io_read(const struct re_io *io, const char *expr, double *v,
	       int timeout_ms);

#endif /* RE_IO_H */
