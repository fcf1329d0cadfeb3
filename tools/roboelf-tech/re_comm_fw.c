/*
 * re_comm_fw.c - commissioning steps 2 and 3: the controller's identity,
 * and the firmware behaviour dmc/ and the supervisor rely on, each checked
 * by a probe whose expected answer is quoted from the DMC-4000 command
 * reference (the page is named in the item). Motor power stays off; every
 * setting a probe changes is put back.
 *
 * The identity step also measures the link as the supervisor will use it:
 * the command handle's reply time and the controller's record stream (DR
 * to a UDP handle of this PC, opened and closed again): the interval is
 * the commissioning's measure of the real controller (docs/link.md).
 *
 * A probe FAILs when our programs or the supervisor would not work or not
 * be safe with the answer seen; it is a NOTE when the answer differs from
 * the reference (or the reference is silent) and our programs are safe
 * on either reading (docs/dmc-interface.md, "Controller behaviour the
 * program relies on"). Behaviour only a running program can show is
 * listed as a NOTE naming why the programs are safe on both readings.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gl_err.h"
#include "re_comm.h"
#include "re_comm_steps.h"
#include "re_comm_util.h"
#include "re_ctl.h"
#include "re_dmcif.h"
#include "re_linkmeas.h"
#include "re_plan.h"

#define STEP "firmware"

/* Text of a reply for the report: control bytes as '.', no line ends. */
static void clean(char *s)
{
	size_t n = strlen(s);

	while (n && (s[n - 1] == '\r' || s[n - 1] == '\n' || s[n - 1] == ' '))
		s[--n] = '\0';
	for (; *s; s++)
		if ((unsigned char)*s < 0x20 || (unsigned char)*s > 0x7e)
			*s = (*s == '\r' || *s == '\n') ? '|' : '.';
}

/* Keep the lines of a multi-line reply (ID, TH) for the report: CR
 * dropped, other control bytes as '.'. */
static void clean_lines(char *s)
{
	char *start = s, *o = s;

	for (; *s; s++)
		if (*s != '\r')
			*o++ = (*s == '\n' || (*s >= 0x20 && *s <= 0x7e)) ? *s
									  : '.';
	while (o > start && o[-1] == '\n')
		o--;
	*o = '\0';
}

/* A command whose reply (or refusal) goes into @out for the report. */
static int ask(struct re_comm *c, const char *cmd, char *out, size_t cap)
{
	int code = 0, rc = rc_cmd(c, cmd, out, cap);

	if (rc == GL_ERR_CTRL) {
		const char *tc = rc_tc(c, &code);

		snprintf(out, cap, "? (TC1 '%d %s')", code, tc);
		return rc;
	}
	if (rc == GL_ERR_OVERFLOW)
		rc = (int)strlen(out);
	if (rc >= 0)
		clean(out);
	return rc;
}

/* As ask(), keeping the reply's lines. */
static int ask_lines(struct re_comm *c, const char *cmd, char *out, size_t cap)
{
	int code = 0, rc = rc_cmd(c, cmd, out, cap);

	if (rc == GL_ERR_CTRL) {
		const char *tc = rc_tc(c, &code);

		snprintf(out, cap, "refused: ? (TC1 '%d %s')", code, tc);
		return rc;
	}
	if (rc >= 0 || rc == GL_ERR_OVERFLOW)
		clean_lines(out);
	return rc == GL_ERR_OVERFLOW ? (int)strlen(out) : rc;
}

#define DR_REF_MIN 8 /* the command reference's shortest DR interval */

/* A refused "DR @n0": whether the command reference's DR_REF_MIN samples
 * are accepted instead (opened and closed again at once), in @out. */
static void dr_ref_try(struct re_comm *c, const struct re_plan *p, unsigned n0,
		       char *out, size_t cap)
{
	int udp = c->cfg->controller.udp_port;
	double ms = 4.0 * DR_REF_MIN * (double)p->ctl_sample_ns / 1e6;

	out[0] = '\0';
	if (n0 >= DR_REF_MIN)
		return;
	if (gl_link_stream_open(c->link, udp, DR_REF_MIN, p->ctl_sample_ns,
				RE_LINKMEAS_OPEN_MS, NULL) != GL_OK) {
		snprintf(out, cap, "; DR %d refused too", DR_REF_MIN);
		return;
	}
	gl_link_stream_close(c->link, 0);
	snprintf(out, cap,
		 "; DR %d accepted: the stream needs period_ms >= %.0f "
		 "(a quarter of it >= %d samples)",
		 DR_REF_MIN, ms + 0.5, DR_REF_MIN);
}

/* The stream opened, its records timed, closed; on failure its item
 * (FAIL with controller.record: stream, else a NOTE) and GL_ERR_AGAIN. */
static int stream_timing(struct re_comm *c, const struct re_plan *p,
			 struct re_linkmeas *m)
{
	const struct re_config_controller *cc = &c->cfg->controller;
	char why[GL_ERRTEXT_LEN] = "", more[160] = "";
	double rec_ms = p->stream_n0 * (double)p->ctl_sample_ns / 1e6;
	int dl_ms = (int)(3 * RE_LINKMEAS_RECORDS * rec_ms) + 500, code = 0;
	int rc =
	    gl_link_stream_open(c->link, cc->udp_port, p->stream_n0,
				p->ctl_sample_ns, RE_LINKMEAS_OPEN_MS, why);
	enum re_comm_res res =
	    cc->record == RE_RECORD_STREAM ? RE_COMM_FAIL : RE_COMM_NOTE;

	if (rc == GL_ERR_CTRL) {
		const char *tc = gl_link_ctrl_error(c->link, &code);

		snprintf(more, sizeof(more), " (TC1 '%d %s')", code, tc);
		dr_ref_try(c, p, p->stream_n0, more + strlen(more),
			   sizeof(more) - strlen(more));
	}
	if (rc == GL_OK) {
		rc = re_linkmeas_records(c->link, RE_LINKMEAS_RECORDS,
					 p->ctl_sample_ns, dl_ms, m);
		gl_link_stream_close(c->link, 0);
		if (rc == GL_ERR_TIMEOUT)
			snprintf(why, sizeof(why),
				 "only %d of %d records within %d ms",
				 m->records, RE_LINKMEAS_RECORDS, dl_ms);
		else if (rc != GL_OK)
			snprintf(why, sizeof(why), "%s", gl_strerror(rc));
	}
	if (rc == GL_OK)
		return GL_OK;
	re_comm_add(c, "identity", "record-stream", res,
		    res == RE_COMM_FAIL
			? "set controller.record: poll, or make the stream "
			  "work: controller.udp_port, UDP between controller "
			  "and PC, a period_ms the controller's DR accepts "
			  "(docs/link.md)"
			: NULL,
		    "DR %u (every %.1f ms) to a UDP handle, port %d: %s%s; "
		    "controller.record is %s",
		    p->stream_n0, rec_ms, cc->udp_port,
		    why[0] ? why : gl_strerror(rc), more,
		    re_record_name(cc->record));
	return GL_ERR_AGAIN;
}

/* The link measured: the reply time, the record stream's interval. */
static int link_timing(struct re_comm *c)
{
	struct re_linkmeas m = {0};
	struct gl_record rec;
	struct re_plan p;
	char line[400];
	const char *reply;
	int rc;

	if (!c->link)
		return GL_OK;
	re_plan_make(c->cfg, 0, &p);
	rc = re_linkmeas_reply(c->link, RE_LINKMEAS_REPLIES,
			       c->cfg->controller.timeout_ms, &m);
	if (rc < 0)
		return rc;
	/* a record that does not decode is the firmware step's finding
	 * (qr-record): the stream would only fail for the same reason */
	rc = c->io->ops->record(c->io->ud, NULL, &rec, 0);
	if (rc == GL_ERR_RECORD)
		re_comm_add(c, "identity", "record-stream", RE_COMM_NOTE, NULL,
			    "not measured: the controller's data record does "
			    "not decode (the firmware step's qr-record)");
	else if (rc < 0)
		return rc;
	else
		rc = stream_timing(c, &p, &m);
	re_linkmeas_line(&m, line, sizeof(line));
	reply = strstr(line, "command reply");
	/* no stream measured: the reply time alone ("record polled" would
	 * say what the configuration does, not what was measured) */
	re_comm_add(c, "identity", "link", RE_COMM_PASS, NULL, "%s",
		    rc == GL_OK || !reply ? line : reply);
	if (rc == GL_OK || rc == GL_ERR_RECORD ||
	    c->cfg->controller.record != RE_RECORD_STREAM)
		return GL_OK;
	return GL_ERR_MISMATCH;
}

int rc_step_identity(struct re_comm *c)
{
	char wh[64], qz[96];
	double tm = 0;
	int rc;

	if (!strstr(c->model, c->cfg->controller.model)) {
		re_comm_add(c, "identity", "model", RE_COMM_FAIL,
			    "connect the robot to the configured model, or "
			    "correct controller.model in the configuration",
			    "^R^V answered '%s'; the configuration expects "
			    "'%s'",
			    c->model, c->cfg->controller.model);
		return GL_ERR_MISMATCH;
	}
	re_comm_add(c, "identity", "model", RE_COMM_PASS, NULL,
		    "^R^V: '%s' (expected to contain '%s'); serial (MG _BN) "
		    "%ld",
		    c->model, c->cfg->controller.model, c->serial);
	if ((rc = ask_lines(c, "ID", c->id_text, sizeof(c->id_text))) < 0 &&
	    rc != GL_ERR_CTRL)
		return rc;
	re_comm_add(c, "identity", "ID", rc < 0 ? RE_COMM_NOTE : RE_COMM_PASS,
		    NULL, "ID (the hardware the controller reports): %s",
		    rc < 0 ? c->id_text : "answered, at the end of the report");
	if ((rc = ask_lines(c, "TH", c->th_text, sizeof(c->th_text))) < 0 &&
	    rc != GL_ERR_CTRL)
		return rc;
	re_comm_add(c, "identity", "TH", rc < 0 ? RE_COMM_NOTE : RE_COMM_PASS,
		    NULL, "TH (its address and handles): %s",
		    rc < 0 ? c->th_text : "answered, at the end of the report");
	rc = ask(c, "WH", wh, sizeof(wh));
	if (rc >= 0 || rc == GL_ERR_CTRL)
		rc = ask(c, "QZ", qz, sizeof(qz));
	if (rc == GL_ERR_BROKEN || rc == GL_ERR_TIMEOUT || rc == GL_ERR_CLOSED)
		return rc;
	rc = rc_num(c, "_TM", &tm);
	re_comm_add(c, "identity", "handle", RE_COMM_PASS, NULL,
		    "WH (this connection): %s; QZ: %s; servo sample TM: "
		    "%.0f us",
		    wh, qz, rc == GL_OK ? tm : -1.0);
	return link_timing(c);
}

/* ---- the probes ---------------------------------------------------------- */

static int probe_unknown(struct re_comm *c)
{
	int code = 0, rc = rc_cmd(c, "ZZ", NULL, 0);
	const char *tc = rc == GL_ERR_CTRL ? rc_tc(c, &code) : "";

	if (rc == GL_ERR_CTRL && code == 1) {
		re_comm_add(c, STEP, "unknown-command", RE_COMM_PASS, NULL,
			    "sent 'ZZ'; reference (TC): an unrecognised "
			    "command answers '?' and TC1 '1 Unrecognized "
			    "command'; seen: ?, TC1 '%d %s'",
			    code, tc);
		return GL_OK;
	}
	if (rc != GL_ERR_CTRL && rc < 0)
		return rc;
	re_comm_add(c, STEP, "unknown-command", RE_COMM_FAIL,
		    "do not use this controller: galil-load and roboelf "
		    "detect every refused command by the '?' and TC1",
		    "sent 'ZZ'; reference (TC): '?' and TC1 '1 Unrecognized "
		    "command'; seen: %s%d %s",
		    rc == GL_ERR_CTRL ? "?, TC1 " : "accepted, ", code, tc);
	return GL_OK;
}

static int probe_tm(struct re_comm *c)
{
	double tm = 0;
	int rc = rc_num(c, "_TM", &tm);

	if (rc != GL_OK)
		return rc;
	re_comm_add(c, STEP, "tm-1000",
		    tm == 1000 ? RE_COMM_PASS : RE_COMM_FAIL,
		    "set the servo sample time with 'TM 1000' and burn it "
		    "('BN'); every time in dmc/ assumes 1 ms",
		    "MG _TM; dmc/ needs 1000 (us; TM: the default sample "
		    "time); seen %.0f",
		    tm);
	return GL_OK;
}

/* MG of two values must give two white-space separated numbers. */
static int probe_mg(struct re_comm *c)
{
	char resp[96], tok[2][32] = {"", ""};
	int rc = rc_cmd(c, "MG -1,-2", resp, sizeof(resp));
	int n;

	if (rc < 0)
		return rc;
	n = sscanf(resp, "%31s %31s", tok[0], tok[1]);
	clean(resp);
	re_comm_add(c, STEP, "mg-separate",
		    n == 2 && atof(tok[0]) == -1 && atof(tok[1]) == -2
			? RE_COMM_PASS
			: RE_COMM_NOTE,
		    NULL,
		    "sent 'MG -1,-2'; reference (MG): each number keeps its "
		    "sign position (' -1.0000 -2.0000'); seen '%s'%s",
		    resp,
		    n == 2 ? ""
			   : " (roboelf and galil-load read one value per MG: "
			     "safe)");
	return GL_OK;
}

/* Write @set to a setting, read it back, put the old value back. */
static int probe_round(struct re_comm *c, const char *name, const char *op,
		       double set, double want, const char *ref)
{
	char cmd[48], expr[16];
	double old = 0, got = 0;
	int rc;

	snprintf(expr, sizeof(expr), "_%sA", op);
	if ((rc = rc_num(c, expr, &old)) != GL_OK)
		return rc;
	snprintf(cmd, sizeof(cmd), "%sA=%.0f", op, set);
	if ((rc = rc_cmd(c, cmd, NULL, 0)) < 0 ||
	    (rc = rc_num(c, expr, &got)) != GL_OK)
		return rc;
	snprintf(cmd, sizeof(cmd), "%sA=%.0f", op, old);
	if ((rc = rc_cmd(c, cmd, NULL, 0)) < 0)
		return rc;
	re_comm_add(c, STEP, name, got == want ? RE_COMM_PASS : RE_COMM_NOTE,
		    NULL,
		    "%sA=%.0f, then MG %s; reference (%s); expected %.0f, "
		    "seen %.0f%s (put back to %.0f)",
		    op, set, expr, ref, want, got,
		    got == want ? ""
				: "; the supervisor's read-back tolerance "
				  "covers either",
		    old);
	return GL_OK;
}

/* DM of an array that exists: UNCONFIRMED; #INIT deallocates first. */
static int probe_dm(struct re_comm *c)
{
	char r1[96] = "", r2[96] = "";
	int rc;

	rc_cmd(c, "DA cmqz[]", NULL, 0); /* refused when absent: fine */
	if ((rc = ask(c, "DM cmqz[4]", r1, sizeof(r1))) < 0 &&
	    rc != GL_ERR_CTRL)
		return rc;
	if ((rc = ask(c, "DM cmqz[4]", r2, sizeof(r2))) < 0 &&
	    rc != GL_ERR_CTRL)
		return rc;
	rc_cmd(c, "DA cmqz[]", NULL, 0);
	re_comm_add(c, STEP, "dm-exists", RE_COMM_NOTE, NULL,
		    "DM cmqz[4] twice; reference (DM): silent on an array "
		    "that exists (UNCONFIRMED); first '%s', second '%s'; "
		    "dmc/ deallocates every array first (DA *[]): safe on "
		    "either",
		    r1[0] ? r1 : ":", r2[0] ? r2 : ":");
	return GL_OK;
}

/* _IHh2 of our own handle is non-zero (#FORGN counts open handles). */
static int probe_handle(struct re_comm *c)
{
	char wh[32], expr[16];
	double v = 0;
	int rc = ask(c, "WH", wh, sizeof(wh));
	const char *h = strstr(wh, "IH");

	if (rc < 0)
		return rc;
	if (!h || h[2] < 'A' || h[2] > 'H') {
		re_comm_add(c, STEP, "handle-open", RE_COMM_FAIL,
			    "check the model: dmc/ (#FORGN) needs WH and "
			    "_IHh2",
			    "WH; reference (WH): 'IHA'..'IHH' for an "
			    "Ethernet handle; seen '%s'",
			    wh);
		return GL_OK;
	}
	snprintf(expr, sizeof(expr), "_IH%c2", h[2]);
	if ((rc = rc_num(c, expr, &v)) != GL_OK)
		return rc;
	re_comm_add(c, STEP, "handle-open",
		    v != 0 ? RE_COMM_PASS : RE_COMM_FAIL,
		    "do not use this firmware: #FORGN would not see a second "
		    "connection",
		    "MG %s of this connection (%c); reference (IH): 2 TCP "
		    "slave, -2 TCP master, 0 free; seen %.0f",
		    expr, h[2], v);
	return GL_OK;
}

/* CN: limit switches active low (-1), which dmc/ reads (_LFx 0 active). */
static int probe_cn(struct re_comm *c)
{
	double v = 0;
	int rc = rc_num(c, "_CN0", &v);

	if (rc != GL_OK)
		return rc;
	re_comm_add(c, STEP, "cn-limits", v == -1 ? RE_COMM_PASS : RE_COMM_FAIL,
		    "send 'CN -1' and burn it ('BN'): dmc/ and the supervisor "
		    "read a limit switch as active when _LFx / _LRx is 0",
		    "MG _CN0; reference (CN): -1 = limit switches active "
		    "low (the default); seen %.0f",
		    v);
	return GL_OK;
}

/* @IN[9]: inputs 9-16 exist only on 5-8 axis controllers. */
static int probe_in9(struct re_comm *c)
{
	char r[96];
	int rc = ask(c, "MG @IN[9]", r, sizeof(r));

	if (rc < 0 && rc != GL_ERR_CTRL)
		return rc;
	re_comm_add(c, STEP, "in-9-16", RE_COMM_NOTE, NULL,
		    "MG @IN[9]; reference (@IN): 'Inputs 9-16 only valid for "
		    "5-8 axis controller'; seen '%s'; the configuration and "
		    "dmc/ (check 10) refuse inputs 9-16: safe on either",
		    r);
	return GL_OK;
}

/* The data record the supervisor reads every cycle decodes. */
static int probe_record(struct re_comm *c)
{
	struct gl_record rec;
	int rc = c->io->ops->record(c->io->ud, NULL, &rec, 0);

	if (rc == GL_OK) {
		re_comm_add(c, STEP, "qr-record", RE_COMM_PASS, NULL,
			    "QR; reference (QR, QZ): header byte 0 bit 7 set, "
			    "the axes A-C present, the length QZ announces; "
			    "decoded, sample %u",
			    (unsigned)rec.sample);
		return GL_OK;
	}
	if (rc != GL_ERR_RECORD)
		return rc;
	re_comm_add(c, STEP, "qr-record", RE_COMM_FAIL,
		    "the supervisor cannot read this controller's data "
		    "record: report the model and firmware (identity) to the "
		    "developers",
		    "QR; reference (QR, QZ): a record of the announced "
		    "length whose header names axes A-C; the record did not "
		    "decode (%s)",
		    gl_strerror(rc));
	return GL_OK;
}

/* ZAC carries the program's largest value whole, in MG _ZAC and in the
 * record (ZA: a 4-byte signed field of the record, galil-notes 2); the
 * program is halted here, so nothing else writes ZA. */
static int probe_za(struct re_comm *c)
{
	char cmd[32], r[96] = "";
	struct gl_record rec;
	double mg = -1;
	long qr = -1;
	int rc, ok;

	snprintf(cmd, sizeof(cmd), "ZA ,,%ld", RE_ZAC_MAX);
	rc = ask(c, cmd, r, sizeof(r));
	if (rc < 0 && rc != GL_ERR_CTRL)
		return rc;
	/* MG _ZAC refused (GL_ERR_CTRL): mg stays -1, a FAIL below */
	if (rc >= 0 && (rc = rc_num(c, "_ZAC", &mg)) != GL_OK &&
	    rc != GL_ERR_CTRL)
		return rc;
	if (mg >= 0) {
		rc = c->io->ops->record(c->io->ud, NULL, &rec, 0);
		if (rc != GL_OK && rc != GL_ERR_RECORD)
			return rc;
		if (rc == GL_OK && rec.n_axes >= 3)
			qr = rec.axis[2].za;
	}
	if ((rc = rc_cmd(c, "ZA ,,0", NULL, 0)) < 0 && rc != GL_ERR_CTRL)
		return rc;
	ok = mg == RE_ZAC_MAX && qr == RE_ZAC_MAX;
	re_comm_add(c, STEP, "za-range", ok ? RE_COMM_PASS : RE_COMM_FAIL,
		    ok ? NULL
		       : "roboelf cannot read the program's joystick and "
			 "motion field from this controller: report the "
			 "model and firmware (identity) to the developers",
		    "%s%s, then MG _ZAC and QR; reference (ZA; the record's "
		    "user field, 4 bytes signed): %ld in both; seen %.0f and "
		    "%ld (put back to 0)",
		    cmd, r[0] == '?' ? r : "", RE_ZAC_MAX, mg, qr);
	return GL_OK;
}

/* What only a running program shows: why dmc/ is safe on both readings. */
static const struct {
	const char *name, *text;
} unprobed[] = {
    {"at-negvar", "AT -var with a negated variable (UNCONFIRMED): dmc/ does "
		  "not use it; it waits with the documented literal AT -10"},
    {"re1", "the automatic subroutines return with RE1 (reference: RE): "
	    "tests/dmc on galil-sim; every routine makes safe before it "
	    "returns"},
    {"poserr-oa", "an encoder failure (OA, stop code 12) may not run "
		  "#POSERR (UNCONFIRMED): #GUARD finds the motor off within "
		  "mainms"},
    {"auto-subs", "#LIMSWI, #POSERR, #AMPERR run with no code in thread 0 "
		  "(reference): prun=0 makes them only make safe and EN"},
    {"en-cmderr", "EN inside #CMDERR returns to where thread 0 left off "
		  "(reference): #CMDERR ends with ZS and JP, never EN"},
    {"ot-ki", "OT needs a non-zero KI (reference: OT 'necessary'): the "
	      "configuration refuses encoder_failure with ki 0"},
};

int rc_step_firmware(struct re_comm *c)
{
	int (*const probe[])(struct re_comm *) = {
	    probe_unknown, probe_tm,  probe_mg,	    probe_dm, probe_handle,
	    probe_cn,	   probe_in9, probe_record, probe_za,
	};
	int rc;

	for (size_t i = 0; i < sizeof(probe) / sizeof(probe[0]); i++)
		if ((rc = probe[i](c)) != GL_OK)
			return rc;
	if ((rc = probe_round(c, "sp-resolution", "SP", 1001, 1000,
			      "SP: resolution 2 counts/s")) != GL_OK ||
	    (rc = probe_round(c, "ac-resolution", "AC", 2000, 1024,
			      "AC: resolution 1024 counts/s2")) != GL_OK)
		return rc;
	for (size_t i = 0; i < sizeof(unprobed) / sizeof(unprobed[0]); i++)
		re_comm_add(c, STEP, unprobed[i].name, RE_COMM_NOTE, NULL,
			    "not probed with direct commands: %s",
			    unprobed[i].text);
	return GL_OK;
}
