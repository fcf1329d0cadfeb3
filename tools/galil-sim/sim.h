/*
 * sim.h - galil-sim as a library: the controller (ctrl.h) and the robot
 * (sim_plant.h) stepped together, in virtual time for tests or against the
 * wall clock for the TCP servers (sim_net.h).
 *
 * The DMC tests (tests/dmc) and galil-sim's main use only this API.
 * Single-threaded: the caller serialises every call on one struct sim.
 *
 * Motor power: the virtual E-stop relay starts OFF (power cut), as the real
 * one does at start-up. An in-process test that wants the motors to move
 * switches it on with sim_control(s, "relay on", ...) (or through the relay
 * pty after sim_attach_relay()).
 */
#ifndef SIM_H
#define SIM_H

#include <stddef.h>
#include <stdint.h>

#include "ctrl.h"

struct sim;
struct sim_plant;
struct sim_relay;

#define SIM_EVENT_LEN	160  /* bytes per event text, NUL included */
#define SIM_EVENTS_MAX	2048 /* events kept until read; older are dropped */
#define SIM_REQUEST_MAX 256  /* bytes per control request */
#define SIM_WATCH_MAX	16   /* variables in the state line */
/* a response buffer this large holds any control answer */
#define SIM_RESPONSE_MAX (SIM_EVENTS_MAX * (SIM_EVENT_LEN + 24) + 64)

/* Link faults injected on the command port (sim_net.h applies them). */
enum sim_link {
	SIM_LINK_OK,
	SIM_LINK_DROP,	/* close every command connection, refuse new */
	SIM_LINK_STALL, /* sockets stay open, nothing flows */
	SIM_LINK_DELAY, /* replies held back by delay_ms */
};

/*
 * Faults of one command line on the command port (net/ applies them; the
 * control port's "link once" and "link first" inject them; the vocabulary
 * is in docs/galil-sim.md, "Line faults"). @arg of struct sim_line_fault:
 * ms for DELAY and EXTRA, the download line (1-based) for DLREJECT.
 */
enum sim_line_kind {
	SIM_LINE_NONE,
	SIM_LINE_DELAY,	   /* the line's reply held back arg ms */
	SIM_LINE_QMARK,	   /* first command corrupted: '?', TC 1 */
	SIM_LINE_SPLIT,	   /* reply sent byte by byte, 1 ms apart */
	SIM_LINE_CHUNKS,   /* reply sent in 1..8-byte pieces, 0..2 ms apart */
	SIM_LINE_GARBAGE,  /* reply replaced by control bytes and "garbage" */
	SIM_LINE_UNSOL,	   /* an unsolicited line in the middle of the reply */
	SIM_LINE_UNSOLPRE, /* an unsolicited line before a final QR's record */
	SIM_LINE_EXTRA,	   /* one ':' more, arg ms later (0: same write) */
	SIM_LINE_DROP,	   /* the connection closed, the line not run */
	SIM_LINE_SILENT,   /* the connection answers nothing from then on */
	SIM_LINE_DLREJECT, /* line arg of the next DL corrupted: '?', TC 60 */
	SIM_LINE_BADHDR,   /* a QR record's header announces 4 axes */
};

struct sim_line_fault {
	enum sim_line_kind kind;
	int arg;
};

/*
 * sim_line_fault_parse() / sim_line_fault_name() - a line fault from its
 * control-port words (@word: "delay", "qmark", "split", "chunks",
 * "garbage", "unsol", "unsolpre", "extra", "drop", "silent", "dlreject",
 * "badhdr"; @arg: its argument or NULL) into @out, and the word of @kind
 * (a static string; "?" out of range).
 * Return (parse): 0, or GL_ERR_ARG with @why (static text) set to the
 * reason (unknown word, missing, extra or bad argument); @out untouched.
 */
int sim_line_fault_parse(const char *word, const char *arg,
			 struct sim_line_fault *out, const char **why);
const char *sim_line_fault_name(enum sim_line_kind kind);

/*
 * sim_new() / sim_free() - a simulator with the plant from @plant_file
 * (YAML), or the built-in default robot when @plant_file is NULL; the
 * relay off, no pty; and its release (controller, plant, relay, pty and
 * link; NULL is a no-op).
 * @out: [out] the simulator, owned by the caller (sim_free()); NULL on
 *       failure.
 * @err: [out] "FILE:LINE:COLUMN: message" on a bad plant file; @errlen its
 *       size.
 * Return: 0, GL_ERR_CONFIG, GL_ERR_NOMEM.
 */
int sim_new(struct sim **out, const char *plant_file, char *err, size_t errlen);
/*
 * sim_new_serial() - sim_new() with the controller's serial number (MG
 * _BN) @serial instead of the default 403001 (@serial <= 0: the default).
 */
int sim_new_serial(struct sim **out, const char *plant_file, long serial,
		   char *err, size_t errlen);
void sim_free(struct sim *s);

/*
 * sim_model() - the controller's model and firmware text, the answer to
 * ^R^V without CR LF ':' ("DMC4030 Rev 1.2h-sim"); a static string.
 */
const char *sim_model(const struct sim *s);

/* sim_ctrl() - the controller inside, for ctrl_* calls (owned by @s). */
struct ctrl *sim_ctrl(struct sim *s);

/*
 * sim_get_plant() / sim_get_relay() - the robot and the relay inside, for
 * sim_plant_* and sim_relay_* calls (owned by @s).
 */
struct sim_plant *sim_get_plant(struct sim *s);
struct sim_relay *sim_get_relay(struct sim *s);

/*
 * sim_deviation_bit() - the CTRL_DEV_* bit (ctrl.h) of a deviation name of
 * galil-sim --deviate: "mg-join", "dm-exists", "qr-header", "ul-trim",
 * "mo-moving" (docs/galil-sim.md, "Firmware deviations").
 * Return: the bit, or 0 for an unknown name.
 */
unsigned sim_deviation_bit(const char *name);

/* sim_seed() - restart the potentiometer noise generator from @seed. */
void sim_seed(struct sim *s, unsigned long seed);

/*
 * sim_attach_relay() - give the virtual relay a pseudo-terminal speaking
 * @protocol ("devantech", "icstation", "lcus", "kmtronic") and optionally a
 * symbolic link @link_path to it (NULL or "" for none). The relay is off.
 * @err: [out] the reason on failure.
 * Return: 0, GL_ERR_ARG (unknown protocol, link refused), GL_ERR_SYS.
 */
int sim_attach_relay(struct sim *s, const char *protocol, const char *link_path,
		     char *err, size_t errlen);

/*
 * sim_step() - one servo sample: plant sensors -> ctrl_step -> plant
 * motion; simulated time advances by ctrl_sample_ms().
 */
void sim_step(struct sim *s);

/*
 * sim_advance_ms() - run the controller and the plant for @ms milliseconds
 * of simulated time, one servo sample at a time. The relay pty is not
 * serviced here (sim_net does it in real time).
 */
void sim_advance_ms(struct sim *s, double ms);

/* sim_time_ms() - simulated time since sim_new(), ms. */
double sim_time_ms(const struct sim *s);

/*
 * sim_power_cycle() - switch the controller off and on: every command
 * connection is closed, the encoder counters restart at 0 where the motors
 * are, the controller loses RAM and runs a burned #AUTO (ctrl_power_cycle).
 * The robot and the relay are not affected.
 */
void sim_power_cycle(struct sim *s);

/*
 * sim_power() - 1 when motor power is on: relay energised on a working
 * board and, when the plant has a power_output, that controller output set.
 */
int sim_power(const struct sim *s);

/*
 * sim_control() - one request of the control-port text protocol
 * ("joy A fwd", "pot B offset 0.3", "state", "events", ...), without the
 * newline. @resp gets "ok", a value, or "error: <reason>"; the answer to
 * "events" is several lines separated by '\n', the last one "end" (no
 * final newline). docs/galil-sim.md lists the requests.
 * Return: 0, or GL_ERR_ARG when @resp starts with "error:".
 */
int sim_control(struct sim *s, const char *req, char *resp, size_t cap);

/*
 * sim_event() - record an event line at the current simulated time (used by
 * the controller's event callback and the fault injections).
 */
void sim_event(struct sim *s, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/*
 * sim_set_event_hook() - also pass every event to @fn (e.g. galil-sim
 * --verbose prints them). @fn gets the simulated time and the text.
 */
void sim_set_event_hook(struct sim *s,
			void (*fn)(void *ud, double t_ms, const char *text),
			void *ud);

/*
 * sim_link() - the link fault injected now; @delay_ms: [out] optional
 * (NULL), its reply delay in ms (SIM_LINK_DELAY).
 */
enum sim_link sim_link(const struct sim *s, double *delay_ms);

/* Where a link fault applies ("link stall tcp", "link delay 50 stream"). */
enum sim_link_scope {
	SIM_SCOPE_ALL,	  /* the TCP command port and the UDP port */
	SIM_SCOPE_TCP,	  /* the TCP command port only */
	SIM_SCOPE_STREAM, /* the UDP port only: records and UDP replies */
};

/*
 * sim_link_on() - the link fault as one side of the command port sees it:
 * @stream 1 for the UDP port (the DR record stream and the replies to UDP
 * handles), 0 for the TCP connections. SIM_LINK_OK when the fault injected
 * is scoped to the other side. @delay_ms: as sim_link().
 */
enum sim_link sim_link_on(const struct sim *s, int stream, double *delay_ms);

/*
 * sim_line_fault() - a line fault injected and not yet used: @first 0 for
 * "link once" (the next command line any host begins), 1 for "link first"
 * (the first command line of every new connection).
 * @out: [out] the fault; kind SIM_LINE_NONE when none.
 * Return: 1 when one is armed, else 0.
 */
int sim_line_fault(const struct sim *s, int first, struct sim_line_fault *out);

/* sim_line_fault_used() - the "link once" fault met its line: disarm it. */
void sim_line_fault_used(struct sim *s);

/*
 * sim_set_disconnect() - @fn(@ud) is called to close every command
 * connection (link drop, power cycle) before the controller state changes.
 * One callback at a time; NULL removes it. @ud is not owned.
 */
void sim_set_disconnect(struct sim *s, void (*fn)(void *ud), void *ud);

/* sim_quit_requested() - 1 after the "quit" request, else 0. */
int sim_quit_requested(const struct sim *s);

#endif /* SIM_H */
