/*
 * re_dmcif.h - the DMC contract, the PC's side: the program's ZA record
 * fields (state, fault code, axis), its fault codes and details, and the
 * controller's stop codes, turned into the supervisor's faults. The DMC
 * side is the dmc/ programs (docs/dmc-interface.md, "Fault codes");
 * tests/unit/test_re_dmcif.c holds the two to each other.
 *
 * Not the cycle's checks (re_check). Pure: no I/O, no printing.
 */
#ifndef RE_DMCIF_H
#define RE_DMCIF_H

#include <stdint.h>

#include "re_fault.h"

/* The program's axes and joystick switch inputs (dmc/roboelf.dmc). */
#define RE_AXES	      3	 /* A, B (rotary), C (linear) */
#define RE_JOY_INPUTS 12 /* 6 commands x 2 redundant switches */

/* ---- data record: the program's ZA fields and the axes ------------------- */

enum re_dmc_state {
	RE_DMC_UNARMED = 0, /* safe: motors off */
	RE_DMC_ARMED = 1,
	RE_DMC_FAULT = 2,
	RE_DMC_SERVICE = 3, /* supervised automatic moves (calibration) */
};

/* Controller fault codes (docs/dmc-interface.md "Fault codes"). */
enum re_dmc_fcode {
	RE_DMC_F_NONE = 0,
	RE_DMC_F_PARAM = 1,
	RE_DMC_F_WATCHDOG = 2,
	RE_DMC_F_INPUT = 3,
	RE_DMC_F_POSERR = 4,
	RE_DMC_F_LIMIT = 5,
	RE_DMC_F_CMDERR = 6,
	RE_DMC_F_TCPERR = 7,
	RE_DMC_F_AMPERR = 8,
	RE_DMC_F_ENCODER = 9,
	RE_DMC_F_MOTOROFF = 10,
	RE_DMC_F_THREAD = 11,
	RE_DMC_F_SUPERVISOR = 12,
	RE_DMC_F_UNCMD = 13,	/* motion the program did not command */
	RE_DMC_F_FOREIGN = 14,	/* heartbeat out of sequence, settings */
	RE_DMC_F_SVCMOVE = 15,	/* a service move out of its bounds */
	RE_DMC_F_POTRANGE = 16, /* potentiometer outside its range */
	RE_DMC_F_SEAL = 17,	/* a sealed value changed (re_seal.h) */
	RE_DMC_F_MAX = 17,
};

/* ZAB = state + RE_ZAB_FCODE * fcode + RE_ZAB_FAXIS * faxis
 *       + RE_ZAB_ECHO * hb_echo (dmc/roboelf.dmc #MAIN, dmc-interface.md;
 * the echo since program 2.23: the DMC's hbemul, its modulus hbemod is
 * RE_HB_ECHO_MOD) */
#define RE_ZAB_FCODE   10L
#define RE_ZAB_FAXIS   1000L
#define RE_ZAB_ECHO    10000L
#define RE_HB_ECHO_MOD 10000L
/* The largest ZAB the program publishes (state 3, fcode 17, faxis 3, echo
 * 9999): 99 993 173, a 4-byte record field. */
#define RE_ZAB_MAX                                                             \
	(RE_DMC_SERVICE + RE_ZAB_FCODE * RE_DMC_F_MAX + RE_ZAB_FAXIS * 3 +     \
	 RE_ZAB_ECHO * (RE_HB_ECHO_MOD - 1))

/* ZAC = jraw + RE_ZAC_JCMD * (jcmd + 1) + RE_ZAC_MCMD * mcmd
 *       + RE_ZAC_MNEUT * mneut (dmc/roboelf.dmc #MAIN, dmc-interface.md) */
#define RE_ZAC_JCMD  4096L
#define RE_ZAC_MCMD  32768L
#define RE_ZAC_MNEUT 262144L
/* The largest ZAC the program publishes (jraw 4095, jcmd 6, mcmd 6,
 * mneut 1): the commissioning run checks that ZA and the record carry it. */
#define RE_ZAC_MAX                                                             \
	(RE_ZAC_JCMD - 1 + RE_ZAC_JCMD * 7 + RE_ZAC_MCMD * 6 + RE_ZAC_MNEUT)

struct re_za {
	int32_t hbdmc; /* ZAA */
	int state;     /* ZAB % 10 */
	int fcode;     /* (ZAB / 10) % 100 */
	int faxis;     /* (ZAB / 1000) % 10: 1..3 = A..C, 0 none */
	int jraw;      /* ZAC % 4096 */
	int jcmd;      /* (ZAC / 4096) % 8 - 1: -1 invalid, 0, 1..6 */
	int mcmd;      /* (ZAC / 32768) % 8: 0..6 */
	int mneut;     /* ZAC / 262144: 1 once the joystick was seen neutral
			* since arming (program 2.10) */
	/* ZAB / 10000 (program 2.23): the last hbpc the program accepted as
	 * the supervisor's heartbeat, mod RE_HB_ECHO_MOD, as the program's
	 * last #MAIN pass before the record left it: in the safe state
	 * (and its requests) every change of hbpc (no sequence is judged),
	 * armed and in service only a change 1..hbmaxd steps after the last
	 * one seen (one out of sequence is fault 14, not echoed); 0 before
	 * any was accepted since XQ #AUTO (also the echo of an hbpc that is
	 * 0 mod RE_HB_ECHO_MOD); frozen while a fault is latched (state 2
	 * follows no heartbeat). re_hb_echo() gives the echo of a value. */
	int hb_echo;
};

/*
 * re_za_decode() - decode ZAA, ZAB, ZAC (axes A, B, C's user fields).
 * @out: [out] filled only on success.
 * Return: GL_OK; GL_ERR_RANGE when a field is negative or a decoded value is
 *         outside its range (state > 3, fcode > 17, faxis > 3, hb_echo >
 *         9999, jcmd > 6, mcmd > 6, mneut > 1, hbdmc > 999999); GL_ERR_ARG
 *         on NULL.
 */
int re_za_decode(int32_t zaa, int32_t zab, int32_t zac, struct re_za *out);

/*
 * re_hb_echo() - the echo (struct re_za hb_echo) the program publishes
 * once it accepted the heartbeat @hbpc (0 .. RE_HBPC_WRAP - 1, as the
 * supervisor writes it): @hbpc mod RE_HB_ECHO_MOD.
 * Return: 0 .. RE_HB_ECHO_MOD - 1; -1 when @hbpc is negative.
 */
int re_hb_echo(long hbpc);

/*
 * re_stop_reason() - text for a stop code: 8 "position error above the
 * limit", 12 "encoder failure", 15 "amplifier fault", 2 "forward limit", 3
 * "reverse limit", 4 "stop command", 7 "abort command", 6 "abort input", ...
 * Return: a static string, never NULL ("unexpected stop" for others).
 */
const char *re_stop_reason(int stop_code);

/*
 * re_dmc_fcode_name() - the controller fault @code's name in the contract
 * (docs/dmc-interface.md "Fault codes", the legend of dmc/roboelf.dmc):
 * "PARAM" .. "SEAL"; "none" for 0.
 * re_dmc_fcode_words() - the same fault in the operator's words, for the
 * status board: "PARAMETER", "JAM", "MOTOR OFF" ...
 * Return: static text; NULL for a code outside 0..RE_DMC_F_MAX.
 */
const char *re_dmc_fcode_name(int code);
const char *re_dmc_fcode_words(int code);

/*
 * re_fault_is_ctrl() - @id is a fault the controller program latched (one
 * that re_ctrl_fault() produces).
 * Return: 1 or 0.
 */
int re_fault_is_ctrl(enum re_fault_id id);

/*
 * re_ctrl_fault() - turn a latched controller fault (state 2) into a fault.
 * @za: [in] decoded fields; fcode, faxis used.
 * @fdet: the detail (MG fdet), or RE_VAL_UNKNOWN when not read.
 * @fault: [out] the matching RE_F_CTRL_* (RE_F_CTRL_UNKNOWN for code 0 or an
 *         unknown code); axis = faxis - 1.
 * Return: GL_OK, GL_ERR_ARG on NULL.
 */
int re_ctrl_fault(const struct re_za *za, long long fdet,
		  struct re_fault *fault);

#endif /* RE_DMCIF_H */
