/*
 * re_dmcif.c - the program's ZA fields, fault codes and stop codes. See
 * re_dmcif.h and docs/dmc-interface.md.
 */
#include "re_dmcif.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "gl_err.h"

/* ---- data record ---------------------------------------------------------*/

int re_za_decode(int32_t zaa, int32_t zab, int32_t zac, struct re_za *out)
{
	struct re_za z;

	if (!out)
		return GL_ERR_ARG;
	if (zaa < 0 || zaa > 999999 || zab < 0 || zac < 0)
		return GL_ERR_RANGE;
	z.hbdmc = zaa;
	z.state = zab % RE_ZAB_FCODE;
	z.fcode = (zab / RE_ZAB_FCODE) % 100;
	z.faxis = (zab / RE_ZAB_FAXIS) % 10;
	z.hb_echo = zab / RE_ZAB_ECHO;
	z.jraw = zac % RE_ZAC_JCMD;
	z.jcmd = (zac / RE_ZAC_JCMD) % 8 - 1;
	z.mcmd = (zac / RE_ZAC_MCMD) % 8;
	z.mneut = zac / RE_ZAC_MNEUT;
	if (z.state > RE_DMC_SERVICE || z.fcode > RE_DMC_F_MAX || z.faxis > 3 ||
	    z.hb_echo >= RE_HB_ECHO_MOD || z.mcmd > 6 || z.jcmd > 6 ||
	    z.mneut > 1)
		return GL_ERR_RANGE;
	*out = z;
	return GL_OK;
}

int re_hb_echo(long hbpc)
{
	return hbpc < 0 ? -1 : (int)(hbpc % RE_HB_ECHO_MOD);
}

const char *re_stop_reason(int stop_code)
{
	switch (stop_code) {
	case 0: return "still running";
	case 1: return "stopped at the commanded position";
	case 2: return "forward limit";
	case 3: return "reverse limit";
	case 4: return "stop command";
	case 6: return "abort input";
	case 7: return "abort command";
	case 8: return "position error above the limit";
	case 9: return "stopped after find edge";
	case 10: return "stopped after homing";
	case 11: return "selective abort input";
	case 12: return "encoder failure";
	case 15: return "amplifier fault";
	case 99: return "MC timeout";
	default: return "unexpected stop";
	}
}

/* Axis index from the program's faxis (1..3), -1 when none. */
static int re_faxis(int faxis)
{
	return faxis >= 1 && faxis <= 3 ? faxis - 1 : -1;
}

static enum re_fault_id re_ctrl_fault_id(int fcode)
{
	switch (fcode) {
	case RE_DMC_F_PARAM: return RE_F_CTRL_PARAM;
	case RE_DMC_F_WATCHDOG: return RE_F_CTRL_WATCHDOG;
	case RE_DMC_F_INPUT: return RE_F_CTRL_INPUT;
	case RE_DMC_F_POSERR: return RE_F_CTRL_POSERR;
	case RE_DMC_F_LIMIT: return RE_F_CTRL_LIMIT;
	case RE_DMC_F_CMDERR: return RE_F_CTRL_CMDERR;
	case RE_DMC_F_TCPERR: return RE_F_CTRL_TCPERR;
	case RE_DMC_F_AMPERR: return RE_F_CTRL_AMPERR;
	case RE_DMC_F_ENCODER: return RE_F_CTRL_ENCODER;
	case RE_DMC_F_MOTOROFF: return RE_F_CTRL_MOTOROFF;
	case RE_DMC_F_THREAD: return RE_F_CTRL_THREAD;
	case RE_DMC_F_SUPERVISOR: return RE_F_CTRL_SUPERVISOR;
	case RE_DMC_F_UNCMD: return RE_F_CTRL_UNCMD;
	case RE_DMC_F_FOREIGN: return RE_F_CTRL_FOREIGN_SET;
	case RE_DMC_F_SVCMOVE: return RE_F_CTRL_SVCMOVE;
	case RE_DMC_F_POTRANGE: return RE_F_CTRL_POTRANGE;
	case RE_DMC_F_SEAL: return RE_F_CTRL_SEAL;
	default: return RE_F_CTRL_UNKNOWN;
	}
}

int re_fault_is_ctrl(enum re_fault_id id)
{
	/* derived from the mapping, so that a new program fault code cannot
	 * be missing here */
	for (int code = 0; code < 100; code++)
		if (re_ctrl_fault_id(code) == id)
			return 1;
	return id == RE_F_CTRL_POWER || id == RE_F_CTRL_SAFE_ON ||
	       id == RE_F_CTRL_FOREIGN_HB;
}

/* Fault 15's detail (docs/dmc-interface.md, #MVGO and #MVSUP). */
static const char *re_svc_reason(long long det)
{
	static const char *const why[] = {
	    "the reason is not known",
	    "the axis was already moving",
	    "the requested speed is above the limit",
	    "the requested distance is above the limit",
	    "the requested time limit is out of range",
	    "a fast move toward a limit switch the potentiometer says is near",
	    "the move did not end within its time limit",
	    "it moved fast near a limit switch",
	};

	return det >= 1 && det <= 7 ? why[det] : why[0];
}

/* Fault 14's detail: 1 the heartbeat, 3 wdto or jto, 4 OE, 5 the
 * program's state set from outside. */
static void re_foreign(long long det, struct re_fault *f)
{
	if (det == 1) {
		f->id = RE_F_CTRL_FOREIGN_HB;
		return;
	}
	snprintf(f->s, sizeof(f->s), "%s",
		 det == 3   ? "the watchdog or the joystick timeout"
		 : det == 4 ? "off-on-error switched off"
		 : det == 5 ? "the program's state, set to a value it never "
			      "sets itself"
			    : "which one is not known");
}

/* The text and values of the version 2.00 faults 13..16. */
static void re_ctrl_fault_v2(long long fdet, struct re_fault *f)
{
	switch (f->id) {
	case RE_F_CTRL_UNCMD:
		if (fdet == 3) {
			re_fault_set(f, RE_F_CTRL_SAFE_ON, -1);
			break;
		}
		snprintf(f->s, sizeof(f->s), "%s",
			 fdet == 1   ? "a move started by another program"
			 : fdet == 2 ? "faster than allowed"
				     : "reason unknown");
		break;
	case RE_F_CTRL_FOREIGN_SET: re_foreign(fdet, f); break;
	case RE_F_CTRL_SVCMOVE:
		snprintf(f->s, sizeof(f->s), "%s", re_svc_reason(fdet));
		break;
	case RE_F_CTRL_POTRANGE:
		f->f[0] = fdet == RE_VAL_UNKNOWN ? NAN : (double)fdet / 1000.0;
		break;
	default: break;
	}
}

int re_ctrl_fault(const struct re_za *za, long long fdet,
		  struct re_fault *fault)
{
	enum re_fault_id id;

	if (!za || !fault)
		return GL_ERR_ARG;
	id = re_ctrl_fault_id(za->fcode);
	/* AMPERR on no single axis: every amplifier lost power at once. */
	if (id == RE_F_CTRL_AMPERR && re_faxis(za->faxis) < 0)
		id = RE_F_CTRL_POWER;
	re_fault_set(fault, id, re_faxis(za->faxis));
	fault->i[0] = fdet;
	if (id == RE_F_CTRL_UNKNOWN) {
		fault->i[0] = za->fcode;
		fault->i[1] = za->faxis;
		fault->i[2] = fdet;
	} else if (id == RE_F_CTRL_LIMIT) {
		snprintf(fault->s, sizeof(fault->s), "%s",
			 fdet == 2   ? "forward"
			 : fdet == 3 ? "reverse"
				     : "forward or reverse");
	} else if (id == RE_F_CTRL_MOTOROFF) {
		snprintf(fault->s, sizeof(fault->s), "%s",
			 fdet == RE_VAL_UNKNOWN ? "reason unknown"
						: re_stop_reason((int)fdet));
	} else {
		re_ctrl_fault_v2(fdet, fault);
	}
	return GL_OK;
}

/* One row per controller fault code: the contract's name, the words. */
static const struct {
	const char *name, *words;
} FCODES[RE_DMC_F_MAX + 1] = {
    [RE_DMC_F_NONE] = {"none", "none"},
    [RE_DMC_F_PARAM] = {"PARAM", "PARAMETER"},
    [RE_DMC_F_WATCHDOG] = {"WATCHDOG", "WATCHDOG"},
    [RE_DMC_F_INPUT] = {"INPUT", "INPUT"},
    [RE_DMC_F_POSERR] = {"POSERR", "JAM"},
    [RE_DMC_F_LIMIT] = {"LIMIT", "LIMIT"},
    [RE_DMC_F_CMDERR] = {"CMDERR", "COMMAND"},
    [RE_DMC_F_TCPERR] = {"TCPERR", "TCP"},
    [RE_DMC_F_AMPERR] = {"AMPERR", "AMPLIFIER"},
    [RE_DMC_F_ENCODER] = {"ENCODER", "ENCODER"},
    [RE_DMC_F_MOTOROFF] = {"MOTOROFF", "MOTOR OFF"},
    [RE_DMC_F_THREAD] = {"THREAD", "THREAD"},
    [RE_DMC_F_SUPERVISOR] = {"SUPERVISOR", "SUPERVISOR"},
    [RE_DMC_F_UNCMD] = {"UNCMD", "UNCOMMANDED MOTION"},
    [RE_DMC_F_FOREIGN] = {"FOREIGN", "SETTINGS"},
    [RE_DMC_F_SVCMOVE] = {"SVCMOVE", "SERVICE MOVE"},
    [RE_DMC_F_POTRANGE] = {"POTRANGE", "POT RANGE"},
    [RE_DMC_F_SEAL] = {"SEAL", "SEALED VALUE CHANGED"},
};

const char *re_dmc_fcode_name(int code)
{
	return code >= 0 && code <= RE_DMC_F_MAX ? FCODES[code].name : NULL;
}

const char *re_dmc_fcode_words(int code)
{
	return code >= 0 && code <= RE_DMC_F_MAX ? FCODES[code].words : NULL;
}
