/*
 * ctrl.h - the simulated DMC-4030 controller: DMC interpreter (threads,
 * variables, arrays, automatic subroutines), motion (profiler, PT, limits,
 * OE/OA), and the host protocol of each Ethernet handle (framing, TC codes,
 * DL/UL, QR, CF/CW unsolicited output).
 *
 * It knows nothing about sockets or the robot: the plant (sim_plant.h) is
 * sampled through struct ctrl_sense / struct ctrl_drive once per servo
 * sample, and host bytes go in and out through ctrl_input()/ctrl_output().
 * Single-threaded; the caller serialises all calls.
 */
#ifndef SIM_CTRL_H
#define SIM_CTRL_H

#include <stddef.h>
#include <stdint.h>

#define CTRL_AXES    3 /* DMC-4030: A, B, C */
#define CTRL_HANDLES 8 /* Ethernet handles A..H */
#define CTRL_THREADS 8
#define CTRL_INPUTS  32 /* digital inputs 1..32 (bit n-1) */
#define CTRL_ANALOG  8	/* analog inputs 1..8 */

struct ctrl;

struct ctrl_cfg {
	const char *model; /* ^R^V text, e.g. "DMC4030 Rev 1.2h-sim" */
	long serial;	   /* MG _BN */
	int sample_us;	   /* TM, servo sample period in us (1000) */
	/* called for each event (motor off and why, limit reached, thread
	 * stopped, program error ...): one line, no CR LF. May be NULL. */
	void (*event)(void *ud, const char *line);
	void *event_ud;
	/* CTRL_DEV_* bits: answer differently from the command reference on
	 * purpose (galil-sim --deviate, docs/galil-sim.md); 0 = faithful */
	unsigned deviate;
};

/* Deliberate deviations from the reference (struct ctrl_cfg.deviate). */
#define CTRL_DEV_MG_JOIN   0x01u /* MG of several values: '-1.0000-2.0000' */
#define CTRL_DEV_DM_EXISTS 0x02u /* DM of an existing array re-dimensions */
#define CTRL_DEV_QR_HEADER 0x04u /* QR header byte 1 reads 0x03, not 0x07 */
#define CTRL_DEV_UL_TRIM   0x08u /* UL drops trailing spaces of each line */
#define CTRL_DEV_MO_MOVING 0x10u /* MO accepted while an axis profiles */
#define CTRL_DEV_ZA_16BIT  0x20u /* the record's ZA keeps 16 bits only */

/* What the plant reports to the controller each sample. */
struct ctrl_sense {
	double enc[CTRL_AXES];	  /* main encoder, counts */
	int fwd_limit[CTRL_AXES]; /* 1 = forward limit switch active */
	int rev_limit[CTRL_AXES]; /* 1 = reverse limit switch active */
	int home[CTRL_AXES];	  /* 1 = home input grounded (active) */
	double an_v[CTRL_ANALOG]; /* analog inputs 1..8, volts */
	uint32_t inputs; /* digital inputs, bit n-1 = input n, 1 = high */
	int amp_power;	 /* 1 = motor power present (E-stop relay on) */
};

/* What the controller commands each sample. */
struct ctrl_drive {
	double ref[CTRL_AXES];	    /* profiler reference position, counts */
	int motor_on[CTRL_AXES];    /* 1 = servo enabled (SH), 0 = MO */
	double torque_v[CTRL_AXES]; /* servo output, volts (+-TL) */
	uint32_t outputs;	    /* digital outputs, bit n-1 = output n */
};

/* Snapshot of one axis for tests and the control port. */
struct ctrl_axis_info {
	double ref, enc, vel; /* counts, counts, counts/s (profiler) */
	int motor_off, moving, stop_code;
	int fwd_limit, rev_limit; /* switch active */
};

/*
 * ctrl_new() - a controller in its power-up state (no program, motors off).
 * @cfg is copied (NULL: defaults). The caller owns the result and frees it
 * with ctrl_free() (NULL is ignored).
 * Return: NULL on allocation failure.
 */
struct ctrl *ctrl_new(const struct ctrl_cfg *cfg);
void ctrl_free(struct ctrl *c);

/* ctrl_handle_open/close() - a host connects to / leaves handle h (0..7). */
void ctrl_handle_open(struct ctrl *c, int h);
/* ctrl_handle_open_udp() - a UDP peer takes handle h (0..7): _IHh2 = 1, and
 * the handle may receive the DR record stream. */
void ctrl_handle_open_udp(struct ctrl *c, int h);
void ctrl_handle_close(struct ctrl *c, int h);

/*
 * ctrl_input() - bytes received from the host on handle h. Complete command
 * lines are executed at once (as the command interpreter does between
 * samples); replies are queued for ctrl_output().
 * Return: 0, or GL_ERR_ARG for a bad handle.
 */
int ctrl_input(struct ctrl *c, int h, const uint8_t *buf, size_t len);

/*
 * ctrl_output() - take up to @cap pending bytes for handle h: replies, and
 * unsolicited output when CF points at h (high bit set under CW1).
 * Return: the number of bytes copied.
 */
size_t ctrl_output(struct ctrl *c, int h, uint8_t *buf, size_t cap);

/* ctrl_output_pending() - bytes ctrl_output() would give for handle h. */
size_t ctrl_output_pending(const struct ctrl *c, int h);

/*
 * ctrl_step() - one servo sample: read @in, update profilers, servo and
 * protection (limits, OE, OA, amplifier), run the program threads for one
 * sample, and write @out.
 */
void ctrl_step(struct ctrl *c, const struct ctrl_sense *in,
	       struct ctrl_drive *out);

/* ctrl_sample_ms() - the servo sample period in ms (TM / 1000). */
double ctrl_sample_ms(const struct ctrl *c);

/*
 * ctrl_command() - run one command line as if sent by a host on a private
 * handle; @resp gets the reply text without the final ':' (or "?").
 * Return: 0 on ':', GL_ERR_CTRL on '?' (TC holds the code).
 */
int ctrl_command(struct ctrl *c, const char *line, char *resp, size_t cap);

/*
 * ctrl_download() - DL a program text directly (as a completed download).
 * @bad_line: [out] optional, 1-based line of the first rejected line.
 * Return: 0 or GL_ERR_CTRL.
 */
int ctrl_download(struct ctrl *c, const char *text, size_t len, int *bad_line);

/*
 * ctrl_get_var() / ctrl_set_var() - a program variable or array element
 * ("name" or "name[i]"). Return: 0 or GL_ERR_NOENT.
 */
int ctrl_get_var(const struct ctrl *c, const char *name, double *v);
int ctrl_set_var(struct ctrl *c, const char *name, double v);

/* ctrl_axis_info() - state of axis 0..2. Return 0 or GL_ERR_ARG. */
int ctrl_axis_info(const struct ctrl *c, int axis, struct ctrl_axis_info *out);

/* ctrl_outputs() - the digital outputs now, bit n-1 = output n (SB, CB,
 * OB, OP, also between samples). */
uint32_t ctrl_outputs(const struct ctrl *c);

/* ctrl_threads() - bit n = thread n running. */
unsigned ctrl_threads(const struct ctrl *c);

/*
 * ctrl_power_cycle() - lose RAM (program, variables, arrays, settings,
 * positions) but keep what BP/BN/BV burned; run #AUTO if the burned program
 * has one.
 */
void ctrl_power_cycle(struct ctrl *c);

/*
 * ctrl_handle_close_wanted() - 1 when the controller wants the connection
 * on handle @h closed (IHS=>-3, IHT=>-3, IHB=>-2 ..., or a power cycle):
 * the network layer closes the socket and calls ctrl_handle_close(), which
 * records the event "handle A closed by IHT from handle B".
 */
int ctrl_handle_close_wanted(const struct ctrl *c, int h);

/*
 * ctrl_handle_close_by() - for a handle whose close is wanted: the handle
 * (0..7, or 8 for ctrl_command()'s private port) whose IH command asked
 * for it. The close is due once that handle's reply has been sent (IHS:
 * the handle's own reply). Return: the handle, or -1 when there is no
 * reply to wait for (a program's IH, a power cycle, no close wanted).
 */
int ctrl_handle_close_by(const struct ctrl *c, int h);

/*
 * ctrl_handle_lost() - the TCP connection of handle @h failed (peer gone
 * while output was pending, ...): the handle is closed, TC 123, _IA4 = h,
 * and #TCPERR runs if the program has it.
 */
void ctrl_handle_lost(struct ctrl *c, int h);

/*
 * ctrl_stream_take() - the oldest data record the DR stream queued (one
 * whole record, the QR bytes, for one datagram) into @buf.
 * @h: [out] optional, the handle (0..7) it is for.
 * Return: its length, or 0 when none is queued or @cap is too small.
 */
size_t ctrl_stream_take(struct ctrl *c, int *h, uint8_t *buf, size_t cap);

/* ctrl_stream_lost() - records dropped because nobody took them in time
 * (more than 64 waiting). */
uint64_t ctrl_stream_lost(const struct ctrl *c);

/* ctrl_handle_peer() - optional: ports and peer address, for TH and _IH. */
void ctrl_handle_peer(struct ctrl *c, int h, int local_port, uint32_t peer_ip,
		      int peer_port);

/*
 * ctrl_serial_output() - take up to @cap bytes of the unsolicited output
 * routed to the serial port (CF S, the power-up default), which the
 * simulator does not have. Return: bytes copied.
 */
size_t ctrl_serial_output(struct ctrl *c, uint8_t *buf, size_t cap);

/*
 * ctrl_set_line_budget() - program lines all threads together may run per
 * servo sample (default 16; see docs/galil-sim-controller.md).
 */
void ctrl_set_line_budget(struct ctrl *c, int lines_per_sample);

/*
 * ctrl_set_deviate() - replace the deliberate deviations from the command
 * reference (CTRL_DEV_* bits, as struct ctrl_cfg.deviate); 0 = faithful.
 * Unknown bits are ignored.
 */
void ctrl_set_deviate(struct ctrl *c, unsigned dev_bits);

#endif /* SIM_CTRL_H */
