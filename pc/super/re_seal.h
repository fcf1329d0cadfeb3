/*
 * re_seal.h - the sealed values: every value that decides how the robot
 * moves or is stopped, fixed before motion and held to a reference nobody
 * can rewrite without being caught (docs/dmc-interface.md, "The seal";
 * docs/safety.md, H12).
 *
 * The seal is a table of items, each a DMC reference and what it must hold:
 *  - the program's constants (dmc/constants.dmc #CONSTS) and parameters
 *    (vmax[], jin[], wdto, ...): literals in the program text, written by
 *    galil-load from the configuration, covered by the identity stamp. The
 *    program sets the parameters itself (#SEALIN, from #INIT);
 *  - the controller settings they rely on (KP KI KD TL ER OE OA OT OV LD
 *    MT CE per axis, CN, TM): literals too, within the controller's
 *    resolution;
 *  - the session's values (soft limits srev/sfwd and FL/BL, AC and DC, the
 *    speed limits vla vlb vlc the program guards): copied at service and
 *    arm entry (#SEALS, into ssn[]);
 *  - the thread set (thread 1 only inside its code while armed, threads
 *    2..7 never) and the program's running mark prun.
 * The program checks a slice of the table every main pass (#SEAL, all of it
 * within RE_SEAL_SLICES passes) and all of it at service and arm entry
 * (#SEALA); a difference stops the robot and latches fault 17 with the
 * item's number, its axis and the value found. The supervisor checks the
 * same table from its own plan (re_seal_expect) by its own read-back.
 *
 * re_seal_make() (re_sealmake.h, from the configuration) builds the table,
 * re_seal_emit() the DMC text galil-load
 * appends to the program; roboelf regenerates it and compares it with what
 * the controller holds. Pure (no I/O, no printing, no allocation) but
 * re_seal_read_fault(), which reads two values through a struct re_io.
 */
#ifndef RE_SEAL_H
#define RE_SEAL_H

#include <stddef.h>

#include "re_fault.h"
#include "re_io.h"

#define RE_SEAL_MAX	 200   /* items */
#define RE_SEAL_REF_MAX	 16    /* "vmax[0]", "_KPA", bytes incl. NUL */
#define RE_SEAL_LIT_MAX	 24    /* a literal, bytes incl. NUL */
#define RE_SEAL_SLICES	 9     /* main passes for the whole table */
#define RE_SEAL_SHADOWS	 21    /* ssn[]: srev sfwd FL BL AC DC vl x 3 */
#define RE_SEAL_TEXT_MAX 32768 /* the emitted program part, bytes */
/* The first line of the emitted part: roboelf finds the seal by it. */
#define RE_SEAL_FIRST "#SEALIN"

enum re_seal_kind {
	RE_SEAL_CONST = 0, /* a program constant, set by #CONSTS */
	RE_SEAL_PARAM,	   /* a parameter, set by #SEALIN */
	RE_SEAL_SETTING,   /* a controller setting, an operand */
	RE_SEAL_SESSION,   /* taken at service and arm entry into ssn[] */
	RE_SEAL_THREAD,	   /* a program thread that must not run there */
	RE_SEAL_RUNNING,   /* prun: 1 while the program runs */
};

struct re_seal_item {
	enum re_seal_kind kind;
	char ref[RE_SEAL_REF_MAX]; /* what the program reads */
	char lit[RE_SEAL_LIT_MAX]; /* the literal (CONST, PARAM, SETTING) */
	double value;		   /* the literal's value */
	double tol;		   /* SETTING: |found - value| allowed; < 0:
				    * found may be at most value - tol (TL:
				    * less torque is the safe side) */
	int axis;		   /* 0..2, or -1 */
	int shadow;		   /* SESSION: its ssn[] element, else -1 */
	const char *what;	   /* "maximum joystick velocity" */
};

/* A controller setting the seal holds per axis (re_seal_setting_at). */
struct re_seal_setting {
	const char *cmd; /* "KP": the operand is _KPA, _KPB, _KPC */
	double tol;	 /* the controller's resolution, 0: exact, < 0:
			  * an upper bound (re_seal_item.tol) */
	const char *what;
};

struct re_seal {
	int n;
	struct re_seal_item item[RE_SEAL_MAX];
	int t1_first, t1_last; /* program lines thread 1 may be on (armed) */
	int body_lines;	       /* lines of the program before the seal part */
};

/*
 * re_seal_start(), re_seal_add(), re_seal_end() - the same table built by
 * hand (the DMC tests seal their own parameters): start reads @body's
 * constants and thread 1's lines; add appends a RE_SEAL_PARAM or
 * RE_SEAL_SETTING item (@ref as the program reads it, @axis 0..2 or -1,
 * @tol for a setting's resolution, @what static text); end appends the
 * session items, the thread set and prun.
 * Return: GL_OK, GL_ERR_FORMAT (start), GL_ERR_OVERFLOW, GL_ERR_ARG.
 */
int re_seal_start(const char *body, size_t len, struct re_seal *out, char *err,
		  size_t errlen);
int re_seal_add(struct re_seal *s, enum re_seal_kind kind, const char *ref,
		int axis, double value, double tol, const char *what);
int re_seal_end(struct re_seal *s);

/*
 * re_seal_setting_at() - the per-axis setting @k (0-based) of the seal, in
 * the order re_seal_make() adds them, or NULL past the last one.
 * re_seal_add_fixed() - append the settings that are not per axis and never
 * configured (CN -1, TM 1000), as re_seal_make() does after the others.
 */
const struct re_seal_setting *re_seal_setting_at(int k);
int re_seal_add_fixed(struct re_seal *s);

/*
 * re_seal_const() - the value of the program constant @name in @s.
 * Return: GL_OK, or GL_ERR_NOENT.
 */
int re_seal_const(const struct re_seal *s, const char *name, double *value);

/*
 * re_seal_emit() - the program part that holds the seal: #SEALIN, #SEALS,
 * #SEAL, #SEALA and their slices, #SLF (which item, then fault 17) and
 * #SLW (where a thread other than 0 that reaches #SLF waits to be found).
 * The line numbers in #SLF's own test follow @s->body_lines.
 * Lines of at most 80 characters, already in galil-load's preprocessed
 * form, each ending with LF; the first line is RE_SEAL_FIRST.
 * @out: [out] NUL-terminated.
 * Return: the length, or GL_ERR_OVERFLOW when @cap is too small.
 */
int re_seal_emit(const struct re_seal *s, char *out, size_t cap);

/*
 * re_seal_describe() - "vmax[0] (maximum joystick velocity, axis A)" for
 * item @number (1-based, as the program reports it), or "an unknown
 * sealed value (N)" when @number is not an item of @s.
 */
void re_seal_describe(const struct re_seal *s, int number, char *buf,
		      size_t cap);

/*
 * re_seal_fault() - fill a RE_F_CTRL_SEAL fault whose i[0] is the item's
 * number (1-based, the program's fdet): its axis, s its description, f0
 * @found (the program's sfv), f1 the sealed value (@sealed for a session
 * item, whose value the program took at entry; NAN: not known).
 */
void re_seal_fault(const struct re_seal *s, double found, double sealed,
		   struct re_fault *f);

/*
 * re_seal_read_fault() - for a RE_F_CTRL_SEAL fault (i[0] the item): read
 * over @io the value the program found (sfv) and, for a session item, the
 * value it sealed at entry (ssn[k]), then re_seal_fault(). Values that
 * cannot be read are NAN ("unknown" in the FAULT line). Other faults, or
 * @s NULL: nothing.
 */
void re_seal_read_fault(const struct re_seal *s, const struct re_io *io,
			int timeout_ms, struct re_fault *f);

/*
 * re_seal_compare() - the program text @have (the seal part the controller
 * holds) against @want (what this configuration gives, re_seal_emit()):
 * GL_OK when equal; else GL_ERR_MISMATCH and @err names the first sealed
 * value that differs, with both values: "... sealed with other values than
 * this configuration gives: vmax[0] (maximum joystick velocity, axis A) is
 * 8000 in the controller's program, 6000 here".
 */
int re_seal_compare(const struct re_seal *s, const char *have, size_t hlen,
		    const char *want, size_t wlen, char *err, size_t errlen);

/*
 * re_seal_expect() - what the supervisor expects every item to read, from
 * its own configuration (the table's literals) and, for the session items,
 * its own plan for @state (1 armed, 3 service): the soft limits srev/sfwd
 * and FL/BL from @soft_rev/@soft_fwd (counts, per axis; NULL: wide open,
 * as before calibration), AC and DC = acfact x the speed limit rounded
 * down to 1024, the speed limits vmax (armed) or svmax (service). Never
 * the controller's copy (ssn[]).
 * @out: [out] @s->n values; a thread item: -1, and for _XQ1 when armed
 *       the first line of thread 1's code (re_seal_judge() knows).
 */
void re_seal_expect(const struct re_seal *s, int state, const double *soft_rev,
		    const double *soft_fwd, double *out);

/*
 * re_seal_judge() - compare what the controller answered to "MG r1,...,rn"
 * for items @first .. @first + @count - 1 with @expect (re_seal_expect()).
 * @text: [in] the MG reply text, @len bytes (numbers separated by blanks).
 * @session_ok: judge the session items too (the program has been in the
 *              state @expect was made for); else they are skipped.
 * @state: the program's state in the same reply (for _XQ1).
 * @bad: [out] on RE_FAULT: the item's number (1-based); @found its value.
 * Return: RE_OK, RE_FAULT, or GL_ERR_PROTO when @text does not hold
 *         @count numbers.
 */
int re_seal_judge(const struct re_seal *s, const double *expect, int first,
		  int count, const char *text, size_t len, int session_ok,
		  int state, int *bad, double *found);

/*
 * re_seal_chunks() - split the table into MG requests that fit the
 * controller's line after the heartbeat: "MG r1,r2,..." of at most
 * @max_chars characters each.
 * @first, @count: [out] per chunk, the first item (0-based) and how many.
 * Return: the number of chunks (<= @cap), or GL_ERR_OVERFLOW.
 */
int re_seal_chunks(const struct re_seal *s, size_t max_chars, int *first,
		   int *count, int cap);

/*
 * re_seal_chunk_text() - "MG r1,...,rn" for items @first .. + @count.
 * Return: its length, or GL_ERR_OVERFLOW.
 */
int re_seal_chunk_text(const struct re_seal *s, int first, int count, char *buf,
		       size_t cap);

/*
 * re_seal_split() - where the seal part starts in a program text (the body
 * before it, the seal from it): the offset of the line RE_SEAL_FIRST.
 * Return: the offset, or -1 when the text holds no seal.
 */
long re_seal_split(const char *text, size_t len);

#endif /* RE_SEAL_H */
