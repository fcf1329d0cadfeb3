/*
 * sim_int.h - the inside of struct sim, shared by sim.c (stepping, events)
 * and sim_control.c (the control-port requests). Not a public header.
 */
#ifndef SIM_INT_H
#define SIM_INT_H

#include <stdint.h>

#include "ctrl.h"
#include "sim.h"

#define SIM_MODEL     "DMC4030 Rev 1.2h-sim"
#define SIM_SERIAL    403001L
#define SIM_SAMPLE_US 1000
#define SIM_WATCH_LEN 32

struct sim_evt {
	int64_t t_us;
	char text[SIM_EVENT_LEN];
};

struct sim {
	struct ctrl *ctrl;
	struct sim_plant *plant;
	struct sim_relay *relay;
	struct ctrl_sense sense;
	struct ctrl_drive drive;
	int64_t time_us;

	struct sim_evt *ev; /* ring of SIM_EVENTS_MAX */
	unsigned ev_head, ev_count;
	unsigned long ev_lost;
	void (*hook)(void *ud, double t_ms, const char *text);
	void *hook_ud;

	char watch[SIM_WATCH_MAX][SIM_WATCH_LEN];
	int nwatch;

	enum sim_link link;
	double link_delay_ms;
	enum sim_link_scope link_scope;	  /* which side the link fault hits */
	struct sim_line_fault line_once;  /* "link once": the next line */
	struct sim_line_fault line_first; /* "link first": new connections */
	void (*disconnect)(void *ud);
	void *disconnect_ud;
	int quit;

	/* limit switches at the previous sample, to log changes */
	int prev_lf[CTRL_AXES], prev_lr[CTRL_AXES];
	/* motor power and the power output at the previous sample */
	int prev_power, prev_pout;
};

/*
 * sim_fmt_ms() - simulated time @t_us (microseconds) as milliseconds for
 * messages, "1234" or "1234.5", into @buf of @cap bytes (NUL-terminated,
 * cut to fit).
 */
void sim_fmt_ms(char *buf, size_t cap, int64_t t_us);

#endif /* SIM_INT_H */
