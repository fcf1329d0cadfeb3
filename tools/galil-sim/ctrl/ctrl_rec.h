/*
 * ctrl_rec.h - the QR data record (ctrl_rec.c); internal to the simulated
 * controller (ctrl/), not part of its API (ctrl.h).
 * It does not define the record layout (gl_record.h).
 */
#ifndef SIM_CTRL_REC_H
#define SIM_CTRL_REC_H

#include "ctrl_int.h"

/*
 * ctrl_record() - the QR data record of @c encoded into @buf (@cap bytes).
 * Return: its length, or a negative gl_err (GL_ERR_OVERFLOW: @cap too
 * small).
 */
int ctrl_record(struct ctrl *c, uint8_t *buf, size_t cap);

#endif /* SIM_CTRL_REC_H */
