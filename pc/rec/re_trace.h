/*
 * re_trace.h - the flight recorder's trace format (docs/trace-format.md):
 * a versioned, self-describing CSV text. Pure: buffers in, buffers out; no
 * files, no clock, nothing printed.
 *
 *   # roboelf-trace 1                        magic and format version
 *   # key value                              header lines (see below)
 *   # units s,1,...                          one unit per column
 *   t_s,cycle,...                            the column names
 *   0.010000,1,...                           one row per supervisor cycle
 *   # end 3000 records crc32 1a2b3c4d        count and CRC-32 of every byte
 *                                            before this line
 *
 * gnuplot, Python (csv, numpy, pandas) and spreadsheets read it as a CSV
 * whose '#' lines are comments. re_trace_parse() is strict: a file without
 * its end line (truncated), with another version, another column list, a
 * bad number, a wrong count or checksum, or beyond the size limits is
 * refused with a message naming the line.
 */
#ifndef RE_TRACE_H
#define RE_TRACE_H

#include <stddef.h>
#include <stdint.h>

#define RE_TRACE_VERSION     1
#define RE_TRACE_MAGIC	     "# roboelf-trace"
#define RE_TRACE_AXES	     3	     /* axes per record, at most */
#define RE_TRACE_NAME	     16	     /* axis name incl. NUL */
#define RE_TRACE_TEXT	     512     /* fault text incl. NUL */
#define RE_TRACE_MAX_RECORDS 2000000 /* refused beyond (reader and writer) */
#define RE_TRACE_MAX_BYTES   (1024u * 1024u * 1024u) /* file size, refused */
#define RE_TRACE_LINE_MAX    4096 /* longest line the reader accepts */

/* The phase column: what the supervisor expected in the cycle. */
enum re_trace_phase {
	RE_TPH_IDLE = 0,    /* nothing powered expected (start-up) */
	RE_TPH_SERVICE = 1, /* service state: calibration, centring */
	RE_TPH_ARMED = 2,   /* ready for use, joystick moves */
	RE_TPH_FAULT = 3,   /* latched: only polling */
};

/* One axis of one cycle. Integers are what the controller reported. */
struct re_trace_axis {
	int32_t enc_counts; /* _TP, counts */
	int32_t ref_counts; /* _RP: the commanded position, counts */
	double pot_v;	    /* measured potentiometer, V */
	double pot_exp_v;   /* expected from the table, V; NAN: no table */
	double tol_v;	    /* tolerance, V; NAN: no table */
	double margin_v;    /* tol - |pot - expected|, V; < 0 outside */
	double vcmd_cps;    /* commanded velocity (d _RP / dt), counts/s */
	double vel_cps;	    /* actual velocity (_TV), counts/s */
	int32_t motor_off;  /* 1: motor off */
	int32_t moving;	    /* 1: profiler running */
	int32_t fwd_lim;    /* 1: forward limit switch active */
	int32_t rev_lim;    /* 1: reverse limit switch active */
	int32_t stop_code;  /* _SC */
};

/* One supervisor cycle. */
struct re_trace_rec {
	double t_s;	   /* supervisor clock, s since the recorder started */
	int32_t cycle;	   /* supervisor cycle number */
	int32_t phase;	   /* enum re_trace_phase */
	int32_t fault;	   /* latched fault id (re_fault.h), 0: none */
	int32_t relay;	   /* enum re_relay_state (2: on) */
	int32_t link_ok;   /* 1: the round trip of this cycle succeeded */
	double age_ms;	   /* reply age at the last good reply, ms */
	double late_ms;	   /* wake-up lateness of this cycle, ms */
	int32_t hbpc;	   /* heartbeat written to the controller */
	int32_t hbdmc;	   /* the program's heartbeat (ZAA) */
	int32_t sample;	   /* the record's sample number (controller time) */
	int32_t joy_raw;   /* joystick raw input word (ZAC % 4096) */
	int32_t jcmd;	   /* decoded joystick command, -1 invalid */
	int32_t mcmd;	   /* the program's motion command */
	int32_t dmc_state; /* program state (ZAB % 10) */
	int32_t fcode;	   /* program fault code */
	struct re_trace_axis axis[RE_TRACE_AXES];
};

/* What the header says. */
struct re_trace_hdr {
	int version;	      /* RE_TRACE_VERSION */
	char created[32];     /* UTC, "YYYY-MM-DDTHH:MM:SSZ" */
	char reason[16];      /* "fault" or "request" */
	uint64_t config_hash; /* re_config_hash() */
	char serial[32];      /* controller serial number, "-" unknown */
	double period_ms;     /* supervisor period */
	int n_axes;	      /* 1..RE_TRACE_AXES */
	char axis[RE_TRACE_AXES][RE_TRACE_NAME];
	int have_fault;	  /* 1: fault_t_s and fault_text are set */
	double fault_t_s; /* the fault instant on the t_s axis */
	char fault_text[RE_TRACE_TEXT]; /* the FAULT line, one line */
	uint32_t n_records;		/* set by the writer / the reader */
};

/*
 * re_trace_max_bytes() - an upper bound of the text re_trace_write() makes
 * for @n_records records of @n_axes axes (for a buffer allocated once).
 * Return: bytes, or 0 when @n_axes or @n_records is out of range.
 */
size_t re_trace_max_bytes(size_t n_records, int n_axes);

/*
 * re_trace_write() - serialise @n records of the ring @ring (capacity
 * @ring_cap), starting at index @first and wrapping, after the header @h
 * (n_records is taken from @n), into @buf.
 * @len: [out] the bytes written (no NUL counted; one is appended if room).
 * Return: GL_OK; GL_ERR_ARG (NULL, n_axes out of range, @first >=
 *         @ring_cap, @n > @ring_cap or > RE_TRACE_MAX_RECORDS, an axis name
 *         or text that is empty or holds ',', space or a control character
 *         where not allowed); GL_ERR_OVERFLOW when @cap is too small.
 */
int re_trace_write(const struct re_trace_hdr *h,
		   const struct re_trace_rec *ring, size_t ring_cap,
		   size_t first, size_t n, char *buf, size_t cap, size_t *len);

/*
 * re_trace_parse() - read a whole trace from @buf (@len bytes, NUL not
 * needed), strictly.
 * @h: [out] the header.
 * @recs: [out] the records, allocated with malloc() (NULL when there are
 *        none); the caller frees them. NULL on error.
 * @err: [out] why the file was refused: "line N: ..." or "byte N: ...".
 * Return: GL_OK; GL_ERR_ARG (NULL); GL_ERR_RANGE (larger than
 *         RE_TRACE_MAX_BYTES or RE_TRACE_MAX_RECORDS, a line longer than
 *         RE_TRACE_LINE_MAX); GL_ERR_FORMAT (not a trace, another version,
 *         a bad header, column list or value, truncated: no end line, or
 *         data after it); GL_ERR_CRC (content changed); GL_ERR_NOMEM.
 */
int re_trace_parse(const char *buf, size_t len, struct re_trace_hdr *h,
		   struct re_trace_rec **recs, char *err, size_t errlen);

/*
 * re_trace_columns() - the number of columns of a trace of @n_axes axes.
 * Return: the count, or 0 for @n_axes out of 1..RE_TRACE_AXES.
 */
int re_trace_columns(int n_axes);

/*
 * re_trace_column_name() - the name of column @i (0-based) of a trace with
 * the axis names @axis (@n_axes of them), e.g. "t_s" or "B_pot_v", into
 * @buf; its unit ("s", "V", "counts/s", "ms", "1") into @unit (may be NULL).
 * Return: GL_OK, or GL_ERR_ARG for @i out of range.
 */
int re_trace_column_name(int i, int n_axes, const char (*axis)[RE_TRACE_NAME],
			 char *buf, size_t cap, char *unit, size_t ucap);

#endif /* RE_TRACE_H */
