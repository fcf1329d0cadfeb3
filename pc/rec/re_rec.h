/*
 * re_rec.h - the flight recorder: every supervisor cycle is
 * copied into a ring buffer allocated at start-up; after a fault (once
 * after_fault_s more has been recorded) and on request the ring is written
 * to a trace file (docs/trace-format.md) next to the log.
 *
 * In the cycle (re_rec_take(), through re_super_recorder()): one struct
 * copied into the ring; no allocation, no system call, no file I/O. When a
 * fault latches (re_rec_fault_note(), also in the cycle): the trace's name
 * is chosen, for the FAULT log entry. Outside the cycle (re_rec_poll(),
 * from the run loop): a due dump copies the ring into a second buffer
 * allocated at start-up and hands it to the recorder's writer thread,
 * which converts it to text and writes it with base_durable_write()
 * (temporary file, fsync, rename): a crash never leaves a partial trace
 * under the final name. Nothing here prints; results are fetched with
 * re_rec_done().
 */
#ifndef RE_REC_H
#define RE_REC_H

#include <pthread.h>
#include <stddef.h>
#include <stdint.h>

#include "re_super.h"
#include "re_trace.h"

#define RE_REC_PATH 1024 /* a trace's path incl. NUL */
#define RE_REC_ERR  256

struct re_rec_cfg {
	double seconds;	      /* history before a fault, s */
	double after_fault_s; /* and after it, s */
	double period_ms;     /* the supervisor period (the header's) */
	double min_period_ms; /* the shortest period it runs at, which
			       * sizes the ring (calibration samples faster
			       * than the configured period); 0: period_ms */
	const char *dir;      /* directory of the traces, "" or NULL: "." */
	int n_axes;	      /* 1..RE_TRACE_AXES */
	const char *axis_names[RE_TRACE_AXES];
	uint64_t config_hash;
};

struct re_rec {
	/* the ring, written by the cycle */
	struct re_trace_rec *ring;
	size_t cap, head, count; /* head: the next slot */
	int64_t t0_ns;		 /* t_s = 0 */
	int64_t prev_ns;	 /* the previous record's time */
	uint16_t prev_sample;	 /* and its sample number (vcmd) */
	int32_t prev_ref[RE_TRACE_AXES];
	int have_prev;
	struct re_trace_hdr hdr; /* the header's fixed part */
	char dir[RE_REC_PATH / 2];
	int64_t after_ns;
	double span_s; /* a trace covers at most seconds + after_fault_s */
	/* a fault whose trace is due (set in the cycle, dumped outside it) */
	int fault_pending;
	int64_t fault_ns, due_ns;
	char fault_text[RE_SUPER_LINE];
	char fault_path[RE_REC_PATH];
	char note[RE_REC_PATH + 16];
	char last_stamp[32]; /* the name stamp last used, for -2, -3 ... */
	int stamp_seq;
	/* the writer thread and its job */
	pthread_t th;
	int th_up;
	pthread_mutex_t mu;
	pthread_cond_t cv;
	int job;  /* 1: queued or being written */
	int stop; /* the thread ends */
	struct re_trace_rec *snap;
	size_t snap_n;
	struct re_trace_hdr job_hdr;
	char job_path[RE_REC_PATH];
	char *text;
	size_t text_cap;
	/* results, for re_rec_done() */
	int done; /* results not yet fetched */
	int done_rc;
	char done_path[RE_REC_PATH];
	char done_err[RE_REC_ERR];
	size_t done_records;
	double done_ms; /* conversion and write, wall ms */
	uint64_t written;
};

/*
 * re_rec_init() - allocate the ring ((seconds + after_fault_s) x 1000 /
 * min_period_ms records, at least 2), the dump buffer and its text buffer,
 * and start the writer thread. A trace holds the cycles of the last
 * seconds + after_fault_s (fewer records when the period is longer).
 * @r: [out]; @cfg: [in] copied (the names too).
 * Return: GL_OK; GL_ERR_ARG (bad sizes, axes, names, too many records);
 *         GL_ERR_NOMEM; GL_ERR_SYS (the thread could not start).
 */
int re_rec_init(struct re_rec *r, const struct re_rec_cfg *cfg);

/*
 * re_rec_begin() - the trace's time zero (the supervisor's clock, @v's
 * io) unless already set, and the controller's @serial (NULL or "":
 * unchanged), without hooking into a supervisor (re_rec_attach() does
 * both; tests drive re_rec_take() by hand with a view).
 */
void re_rec_begin(struct re_rec *r, const struct re_super_view *v,
		  const char *serial);

/*
 * re_rec_attach() - record @s's cycles from now (re_super_recorder()) and
 * name controller @serial (NULL or "": "-") in the traces. t_s counts from
 * the first attach.
 */
void re_rec_attach(struct re_rec *r, struct re_super *s, const char *serial);

/*
 * re_rec_take() - the cycle hook: copy @s's last cycle into the ring.
 * No allocation, no system call (the time is the supervisor's own clock).
 */
void re_rec_take(struct re_rec *r, const struct re_super_view *s);

/*
 * re_rec_fault_note() - the fault hook: the fault's trace is due
 * after_fault_s from now; its path is chosen now (UTC stamp).
 * Return: "trace PATH (written after_fault_s after the fault)", or NULL when
 *         a fault is already pending.
 */
const char *re_rec_fault_note(struct re_rec *r, const struct re_super_view *s);

/*
 * re_rec_request() - a trace of the ring as it is now (SIGUSR1, a key),
 * outside the cycle: the ring is copied and handed to the writer at once.
 * Return: GL_OK, GL_ERR_BUSY when the writer is busy (try again later).
 */
int re_rec_request(struct re_rec *r);

/*
 * re_rec_poll() - outside the cycle: a fault's trace whose after_fault_s
 * has passed at @now_ns (or any pending one when @now_ns is INT64_MAX) is
 * copied and handed to the writer.
 * Return: 1 when a dump was queued, 0 otherwise.
 */
int re_rec_poll(struct re_rec *r, int64_t now_ns);

/*
 * re_rec_done() - the result of a finished dump, once.
 * @path: [out] the trace's path; @err: [out] why it failed ("" on success).
 * Return: 0 nothing new; 1 a trace was written (@records, @ms filled); -1 a
 *         dump failed.
 */
int re_rec_done(struct re_rec *r, char *path, size_t cap, char *err,
		size_t errlen, size_t *records, double *ms);

/*
 * re_rec_finish() - quitting: a pending fault trace is dumped now, and the
 * writer finishes what it has (waits for it). Call re_rec_done() after.
 */
void re_rec_finish(struct re_rec *r);

/* re_rec_free() - stop the thread (after re_rec_finish()), free buffers. */
void re_rec_free(struct re_rec *r);

/*
 * re_rec_dump_to() - the writer's work, synchronously (also for tests and
 * make bench): @n records of @recs under @h written to @path through
 * @text (@cap bytes) with base_durable_write().
 * Return: GL_OK; GL_ERR_OVERFLOW, GL_ERR_ARG (re_trace_write()); GL_ERR_SYS
 *         with errno set when the file cannot be written.
 */
int re_rec_dump_to(const char *path, const struct re_trace_hdr *h,
		   const struct re_trace_rec *recs, size_t n, char *text,
		   size_t cap);

#endif /* RE_REC_H */
