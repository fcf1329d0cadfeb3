/*
 * re_comm_steps.h - the commissioning run's steps, in the order re_comm_run()
 * runs them (re_comm.h): re_comm_fw.c (identity, firmware), re_comm_wire.c
 * (joystick, pots, limits), re_comm_move.c (relay, motion). Not for use
 * outside the re_comm modules.
 */
#ifndef RE_COMM_STEPS_H
#define RE_COMM_STEPS_H

#include "re_comm.h"

/*
 * The steps (re_comm.h). Each returns GL_OK when it passed (notes allowed),
 * GL_ERR_MISMATCH after recording its FAIL item, or a link error.
 */
int rc_step_identity(struct re_comm *c);
int rc_step_firmware(struct re_comm *c);
int rc_step_joystick(struct re_comm *c);
int rc_step_pots(struct re_comm *c);
int rc_step_limits(struct re_comm *c);
int rc_step_relay(struct re_comm *c);
int rc_step_motion(struct re_comm *c);

#endif /* RE_COMM_STEPS_H */
