/*
 * ctrl_axcmd.h - the axis commands (ctrl_axcmd.c); internal to the simulated
 * controller (ctrl/), not part of its API (ctrl.h).
 * It does not move the axes itself (ctrl_motion.h).
 */
#ifndef SIM_CTRL_AXCMD_H
#define SIM_CTRL_AXCMD_H

#include "ctrl_int.h"

/*
 * ctrl_axis_cmd() - the axis commands @name (parameters, PA PR JG PT DP ZA
 * BG ST AB SH MO, reports TP TE TD RP TV TT TS SC) with argument text @a;
 * replies go to the statement output. Return: 0 or a TC code.
 */
int ctrl_axis_cmd(struct ctrl_xc *x, const char *name, const char *a);

#endif /* SIM_CTRL_AXCMD_H */
