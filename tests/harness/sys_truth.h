/*
 * sys_truth.h - the system tests' truth check: every fact roboelf states
 * about a fault, against what galil-sim recorded.
 *
 * galil-sim's event log (the control port's `events`: "<sim ms> <text>"
 * lines) is the ground truth: which motor went off when and why (a host
 * handle's command or the controller itself), when the relay opened and
 * the amplifiers lost power, which handle's stop (AB, MO) arrived, which
 * fault was injected on which axis. roboelf's FAULT line and its FAULT log
 * entry state the same facts: the fault's class and axis, a consequence
 * ("Then: axis X: ..."), motor power off (relay open) confirmed, the stop
 * command delivered or not, motors off confirmed, the stop's round trip.
 *
 * The parsers take buffers (unit-tested on recorded text in
 * tests/unit/test_sys_truth.c); sys_truth_check() applies them to a running
 * case. A fact one side does not state is not compared: "not confirmed"
 * states nothing about the relay, only that roboelf does not know.
 */
#ifndef SYS_TRUTH_H
#define SYS_TRUTH_H

#include <stddef.h>

struct sys_case;

/* A yes/no fact; SYS_UNKNOWN when not stated (or not recorded). */
enum sys_tri { SYS_UNKNOWN = 0, SYS_NO, SYS_YES };

#define SYS_TRUTH_TEXT 200

struct sys_facts {
	char cls[16];	/* "ENCODER"; "" not stated */
	char axis;	/* the first cause's axis 'A'..'H'; 0 none stated */
	char then_axis; /* a consequence on this axis; 0 none */
	enum sys_tri delivered;	 /* the stop command reached the controller */
	enum sys_tri relay_open; /* the relay opened */
	enum sys_tri power_off;	 /* the amplifiers have no motor power */
	enum sys_tri motors_off; /* every motor off */
	double stop_ms;		 /* the stop's round trip; < 0 unknown */
	/* said: the axis a status line after the FAULT line gives the
	 * controller's fault (ctrl="FAULT MOTOR OFF axis A (code 10)"), 0
	 * none; and that line's ctrl text */
	char ctrl_axis;
	char ctrl_text[64];
	char self_off[8];	      /* truth: axes the controller switched off
					 by itself (not a host's command) */
	char stop_ev[SYS_TRUTH_TEXT]; /* truth: the event that shows the
					 stop arrived, or "" */
	char first_ev[SYS_TRUTH_TEXT]; /* truth: the injection */
};

/*
 * sys_truth_said() - what roboelf stated: @line its FAULT line, @log_entry
 * its FAULT log entry (the line followed by "| relay off: ... |
 * controller stop: ... |"), or NULL.
 * @out: [out] the facts; unknown where nothing is said.
 * Return: 0, or -1 when @line is not a FAULT line.
 */
int sys_truth_said(const char *line, const char *log_entry,
		   struct sys_facts *out);

/*
 * sys_truth_said_status() - add to @out what the status lines roboelf
 * printed after its FAULT line (@stdout_text, its whole output so far) say
 * of the controller's latched fault: the first naming an axis, else the
 * last one's text.
 */
void sys_truth_said_status(const char *stdout_text, struct sys_facts *out);

/*
 * sys_truth_true() - what galil-sim recorded: @events its event lines
 * ("<sim ms> <text>\n" ...), the whole log of the case. Facts are read
 * from the events at or after @after_ms (the injection) and up to
 * @until_ms (< 0: all): the injection's axis and class, the stop's arrival
 * (a host handle's AB or MO, not one of @foreign, a bit mask 1 = handle A),
 * the axes the controller switched off itself; and the state at @until_ms:
 * relay, amplifier power, every motor.
 * @out: [out] the facts.
 * Return: 0, or -1 on a line that is not "<number> <text>".
 */
int sys_truth_true(const char *events, double after_ms, double until_ms,
		   unsigned foreign, struct sys_facts *out);

/*
 * sys_truth_compare() - every fact both sides state, said against true.
 * @buf: [out] "" when they agree, else one line per mismatch: "<fact>:
 * roboelf printed <x>, galil-sim recorded <y> (<event>)".
 * Return: the number of mismatches.
 */
int sys_truth_compare(const struct sys_facts *said,
		      const struct sys_facts *truth, char *buf, size_t cap);

/*
 * sys_truth_check() - the check on a running case, right after the fault
 * (before roboelf is told to quit): @line the FAULT line seen on stdout,
 * its log entry read from the case's log, the status lines printed after
 * it so far (one a second: one not there yet is not waited for),
 * galil-sim's events from
 * @after_ms (the injection's simulated time) to now. A fact roboelf states
 * as done that the log does not show yet is waited for (events fetched
 * every 15 ms, at most 1000 ms); nothing else waits.
 * @foreign: handles that are not roboelf's (1 = handle A), or 0; those
 * opened after Ready (when the case saw it) and before @after_ms are
 * counted in too.
 * Return: 0 when every stated fact is true, -1 with c->err naming each
 * false one, the line and the events.
 */
int sys_truth_check(struct sys_case *c, const char *line, double after_ms,
		    unsigned foreign);

/*
 * sys_truth_events() - the events @c holds as galil-sim gave them, "<sim
 * ms> <text>\n" each, for sys_truth_true().
 * Return: a buffer to free(), or NULL (out of memory).
 */
char *sys_truth_events(const struct sys_case *c);

/*
 * sys_truth_foreign() - the handles opened on galil-sim between @from_ms
 * and @to_ms (simulated; the events held by @c): the test's own clients
 * opened before the fault.
 * Return: the mask (1 = handle A).
 */
unsigned sys_truth_foreign(const struct sys_case *c, double from_ms,
			   double to_ms);

#endif /* SYS_TRUTH_H */
