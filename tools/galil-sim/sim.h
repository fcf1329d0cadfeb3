/*
 * sim.h - galil-sim as a library: the controller (ctrl.h) and the robot
 * (sim_plant.h) stepped together, in virtual time for tests or against the
 * wall clock for the TCP servers (sim_net.h).
 *
 * The DMC tests (tests/dmc) and galil-sim's main use only this API.
 */
#ifndef SIM_H
#define SIM_H

#include <stddef.h>

#include "ctrl.h"

struct sim;

/*
 * sim_new() - a simulator with the plant from @plant_file (YAML), or the
 * built-in default robot when @plant_file is NULL.
 * @err: [out] "FILE:LINE:COLUMN: message" on a bad plant file.
 * Return: 0, GL_ERR_CONFIG, GL_ERR_NOMEM.
 */
int sim_new(struct sim **out, const char *plant_file, char *err, size_t errlen);
void sim_free(struct sim *s);

/* sim_ctrl() - the controller inside, for ctrl_* calls. */
struct ctrl *sim_ctrl(struct sim *s);

/*
 * sim_advance_ms() - run the controller and the plant for @ms milliseconds
 * of simulated time, one servo sample at a time.
 */
void sim_advance_ms(struct sim *s, double ms);

/* sim_time_ms() - simulated time since sim_new(), ms. */
double sim_time_ms(const struct sim *s);

/*
 * sim_control() - one request of the control-port text protocol
 * ("joy A fwd", "pot B offset 0.3", "state", "events", ...), without the
 * newline. @resp gets "ok", a value, or "error: <reason>".
 * Return: 0, or GL_ERR_ARG when @resp starts with "error:".
 */
int sim_control(struct sim *s, const char *req, char *resp, size_t cap);

/*
 * sim_event() - record an event line at the current simulated time (used by
 * the controller's event callback and the fault injections).
 */
void sim_event(struct sim *s, const char *fmt, ...)
	__attribute__((format(printf, 2, 3)));

#endif /* SIM_H */
