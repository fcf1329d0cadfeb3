/*
 * sys_exact_h.c - the fixture of the exact-text system tests (see
 * sys_exact_h.h).
 */
#include <errno.h>
#include <math.h>
#include <poll.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <arpa/inet.h>
#include <netinet/in.h>

#include <cmocka.h>

#include "sys_exact_h.h"

/* ---- the summary table ---------------------------------------------------
 */

#define MAX_ROWS 40

static struct sx_row rows[MAX_ROWS];
static int nrows;

struct sx_row *sx_row_begin(const char *name)
{
	static struct sx_row spare;
	struct sx_row *r = nrows < MAX_ROWS ? &rows[nrows++] : &spare;

	memset(r, 0, sizeof(*r));
	snprintf(r->name, sizeof(r->name), "%s", name);
	snprintf(r->outcome, sizeof(r->outcome), "FAILED (see above)");
	snprintf(r->reaction, sizeof(r->reaction), "-");
	return r;
}

static void row_set(char *dst, size_t cap, const char *fmt, va_list ap)
{
	vsnprintf(dst, cap, fmt, ap);
}

void sx_row_reaction(struct sx_row *r, const char *fmt, ...)
{
	va_list ap;

	va_start(ap, fmt);
	row_set(r->reaction, sizeof(r->reaction), fmt, ap);
	va_end(ap);
	print_message("[ MEASURE  ] %s: %s\n", r->name, r->reaction);
}

void sx_row_text(struct sx_row *r, const char *text)
{
	snprintf(r->text, sizeof(r->text), "%s", text);
}

void sx_row_pass(struct sx_row *r, const char *fmt, ...)
{
	va_list ap;

	va_start(ap, fmt);
	row_set(r->outcome, sizeof(r->outcome), fmt, ap);
	va_end(ap);
}

/* The summary table, at the group's tear-down. */
static void print_table(void)

{
	print_message("[ SUMMARY  ] case | outcome | reaction | exact FAULT "
		      "line or message\n");
	for (int i = 0; i < nrows; i++)
		print_message("[ SUMMARY  ] %s | %s | %s | %s\n", rows[i].name,
			      rows[i].outcome, rows[i].reaction,
			      rows[i].text[0] ? rows[i].text : "-");
}

/* ---- exact texts -----------------------------------------------------------
 */

/* One number: -?digits[.digits]. Return: its length, 0 when none. */
static size_t number_len(const char *s)
{
	size_t n = *s == '-' ? 1 : 0, d = n;

	while (s[n] >= '0' && s[n] <= '9')
		n++;
	if (n == d)
		return 0;
	if (s[n] == '.' && s[n + 1] >= '0' && s[n + 1] <= '9')
		for (n++; s[n] >= '0' && s[n] <= '9'; n++)
			;
	return n;
}

/* "YYYY-MM-DD HH:MM:SS": 1 when @s starts with one. */
static int is_time(const char *s)
{
	static const char shape[] = "dddd-dd-dd dd:dd:dd";

	for (size_t i = 0; shape[i]; i++)
		if (shape[i] == 'd' ? s[i] < '0' || s[i] > '9'
				    : s[i] != shape[i])
			return 0;
	return 1;
}

/*
 * tpl_match() - does @s match @tpl exactly? "{n}" in @tpl stands for one
 * number (its value goes to @num, up to @max), "{t}" for a local time,
 * "{s}" for a non-empty text (the shortest that lets the rest match).
 * @k: numbers matched so far (0 at the top).
 * @at: [in,out] the furthest offset of @s matched (for the message).
 * Return: the count of numbers, or -1.
 */
static int tpl_match(const char *tpl, const char *s, const char *s0,
		     double *num, int max, int k, size_t *at)
{
	while (*tpl) {
		size_t n;

		if ((size_t)(s - s0) > *at)
			*at = (size_t)(s - s0);
		if (!strncmp(tpl, "{s}", 3)) {
			for (n = 1; n <= strlen(s); n++) {
				int r = tpl_match(tpl + 3, s + n, s0, num, max,
						  k, at);

				if (r >= 0)
					return r;
			}
			return -1;
		}
		if (!strncmp(tpl, "{n}", 3) && (n = number_len(s)) > 0) {
			if (k < max)
				num[k] = strtod(s, NULL);
			k++;
			s += n;
			tpl += 3;
		} else if (!strncmp(tpl, "{t}", 3) && is_time(s)) {
			s += 19;
			tpl += 3;
		} else if (*tpl == *s) {
			tpl++;
			s++;
		} else {
			return -1;
		}
	}
	return *s ? -1 : k;
}

int sx_expect_text(const char *what, const char *tpl, const char *line,
		   double *num, int max)
{
	size_t at = 0;
	int k = tpl_match(tpl, line, line, num, max, 0, &at);

	if (k < 0)
		fail_msg("%s: not the exact text\n  got:      %s\n  expected: "
			 "%s\n  they part at offset %zu: '%.40s'",
			 what, line, tpl, at, line + at);
	return k;
}

/* ---- fixtures ----------------------------------------------------------- */

/* Remove the files of a one-level directory, then the directory. */
static void remove_dir(const char *path)
{
	char cmd[SYS_PATH_MAX * 2];

	if (!path[0] || access(path, F_OK) < 0)
		return;
	snprintf(cmd, sizeof(cmd), "rm -rf -- '%s'", path);
	if (system(cmd) != 0)
		print_message("[   WARN   ] cannot remove '%s'\n", path);
}

/* The FAULT line of the last case's log (up to the " | " of the log's
 * details), or "". */
static void cal_fault_line(const struct sys_env *env, char *out, size_t cap)
{
	char path[SYS_PATH_MAX + 32], buf[8192];
	FILE *f;

	out[0] = '\0';
	snprintf(path, sizeof(path), "%s/case-%d.log", env->dir, env->ncase);
	f = fopen(path, "r");
	while (f && fgets(buf, sizeof(buf), f)) {
		char *p = strstr(buf, " FAULT FAULT "), *end;

		if (!p)
			continue;
		p += 7;
		end = strstr(p, " | ");
		snprintf(out, cap, "%.*s",
			 end ? (int)(end - p) : (int)strlen(p), p);
		break;
	}
	if (f)
		fclose(f);
}

/*
 * One full calibration for every case. A calibration is a supervised phase
 * like any other: when the first one fails, that is a failure (reported by
 * test_full_calibration, or by the group's tear-down), and a second one
 * gives the other cases their file.
 */
static void calibrate_env(struct sx_fixture *fx)
{
	struct sys_env *env = fx->env;

	if (sys_env_calibrate(env, 150000) == 0) {
		fx->ok = 1;
		return;
	}
	snprintf(fx->cal_fail, sizeof(fx->cal_fail), "%s", env->err);
	cal_fault_line(env, fx->cal_line, sizeof(fx->cal_line));
	print_message("[   WARN   ] the full calibration failed; once more "
		      "for the other cases:\n%s\n",
		      fx->cal_fail);
	fx->ok = sys_env_calibrate(env, 150000) == 0;
}

int sx_group_setup(struct sx_fixture *fx, struct sys_env *env)
{
	char text[SYS_PATH_MAX + 320];

	memset(fx, 0, sizeof(*fx));
	fx->env = env;
	fx->re_env[0] = fx->lock_env;
	if (sys_env_init(env) == 0) {
		snprintf(fx->lock_dir, sizeof(fx->lock_dir), "%s/locks",
			 env->dir);
		snprintf(fx->lock_dir2, sizeof(fx->lock_dir2),
			 "%s/locks-other-host", env->dir);
		snprintf(fx->lock_env, sizeof(fx->lock_env),
			 "ROBOELF_LOCK_DIR=%s", fx->lock_dir);
		snprintf(fx->lock_env2, sizeof(fx->lock_env2),
			 "ROBOELF_LOCK_DIR=%s", fx->lock_dir2);
		/* the calibration's roboelf inherits it */
		if (mkdir(fx->lock_dir, 0700) == 0 &&
		    mkdir(fx->lock_dir2, 0700) == 0 &&
		    setenv("ROBOELF_LOCK_DIR", fx->lock_dir, 1) == 0)
			calibrate_env(fx);
	}
	if (fx->ok)
		print_message("[   INFO   ] %s (P %d ms, %s)\n",
			      sys_env_cal_text(env, text, sizeof(text)),
			      env->period_ms, env->dir);
	else
		print_message("[   INFO   ] full calibration FAILED (P %d ms, "
			      "%s): %s\n",
			      env->period_ms, env->dir, env->err);
	return 0;
}

int sx_group_teardown(struct sx_fixture *fx, int first_cal_tested)
{
	struct sys_env *env = fx->env;

	print_table();
	if (!fx->ok)
		env->keep = 1;
	if (!env->keep) {
		remove_dir(fx->lock_dir);
		remove_dir(fx->lock_dir2);
	}
	sys_env_cleanup(env);
	if (fx->cal_fail[0] && !first_cal_tested) {
		print_message("[  FAILS   ] the full calibration failed on its "
			      "first try: %s\n%s\n",
			      fx->cal_line, fx->cal_fail);
		return -1;
	}
	return 0;
}

void sx_start_with(struct sys_case *c, struct sx_fixture *fx,
		   struct sys_opts *o)
{
	if (!fx->ok)
		fail_msg("no calibrated environment: %s", fx->env->err);
	o->re_env = fx->re_env;
	if (sys_case_start(c, fx->env, o) < 0)
		fail_msg("%s", c->err);
}

void sx_start(struct sys_case *c, struct sx_fixture *fx)
{
	struct sys_opts o = {0};

	sx_start_with(c, fx, &o);
	if (sys_ctl(c, "watch state") < 0 || sys_ctl(c, "watch fcode") < 0 ||
	    sys_ctl(c, "watch fdet") < 0 || sys_ctl(c, "watch hbpc") < 0)
		fail_msg("%s", c->err);
}

/* ---- deadlines (docs/safety.md, section 3) --------------------------------
 */

double sx_p(const struct sys_env *env)
{
	return env->period_ms;
}

double sx_d_ctrl_to_relay(const struct sys_env *env)
{
	return SYS_MAINMS + 2.0 * sx_p(env);
}

/* ---- events and the state line ---------------------------------------------
 */

int sx_wait_event(struct sys_case *c, const char *prefix, const char *sub,
		  double after, int timeout_ms)
{
	long long deadline = proc_now_ms() + timeout_ms;
	size_t k = strlen(prefix);

	for (;;) {
		for (size_t i = 0; i < c->nev; i++)
			if (c->ev[i].t_ms >= after &&
			    !strncmp(c->ev[i].text, prefix, k) &&
			    (!sub || strstr(c->ev[i].text, sub)))
				return (int)i;
		if (proc_now_ms() > deadline)
			fail_msg("no event '%s...%s' after %.0f ms within %d "
				 "ms",
				 prefix, sub ? sub : "", after, timeout_ms);
		if (c->re_up)
			proc_pump(&c->re, 0);
		poll(NULL, 0, 15);
		if (sys_events(c) < 0)
			fail_msg("%s", c->err);
	}
}

double sx_wait_motors_off(struct sys_case *c, double after, int ms)
{
	long long deadline = proc_now_ms() + ms;

	for (;;) {
		double t = sys_motors_off_time(c, after);

		if (t >= 0)
			return t;
		if (proc_now_ms() > deadline)
			fail_msg("not every motor was switched off after %.0f "
				 "ms (no 'axis <X> motor off' event for each "
				 "axis within %d ms)",
				 after, ms);
		poll(NULL, 0, 15);
		if (sys_events(c) < 0)
			fail_msg("%s", c->err);
	}
}

double sx_state_num(struct sys_case *c, const char *key)
{
	char st[SX_TEXT_MAX];
	double v;

	if (sys_state(c, st, sizeof(st)) < 0)
		fail_msg("%s", c->err);
	v = sys_state_num(st, key);
	if (isnan(v))
		fail_msg("no '%s' in the state line: %s", key, st);
	return v;
}

char sx_handle_of(struct sys_case *c, int fd, double after, double *t)
{
	struct sockaddr_in sa;
	socklen_t len = sizeof(sa);
	char from[48];
	int i;

	if (getsockname(fd, (struct sockaddr *)&sa, &len) < 0)
		fail_msg("getsockname: %s", strerror(errno));
	snprintf(from, sizeof(from), " opened from 127.0.0.1:%u",
		 (unsigned)ntohs(sa.sin_port));
	i = sx_wait_event(c, "handle ", from, after, 3000);
	*t = c->ev[i].t_ms;
	return c->ev[i].text[7];
}

double sx_inject(struct sys_case *c, const char *evt, const char *req)
{
	char want[300];
	double before = sys_sim_time(c);
	int i;

	if (before < 0 || sys_ctl(c, "%s", req) < 0)
		fail_msg("%s", c->err);
	snprintf(want, sizeof(want), "%s%s", evt, req);
	i = sx_wait_event(c, want, NULL, before, 2000);
	return c->ev[i].t_ms;
}

void sx_not_own_request(const char *line)
{
	if (strstr(line, "Then: the controller latched the supervisor's "
			 "fault request"))
		fail_msg("the FAULT line names the supervisor's own fault "
			 "request (pcflt=1, fault 12) as a consequence:\n  %s",
			 line);
}

int sx_tpl_encpot(const struct sys_env *env, char *tpl, size_t cap, int axis)
{
	char pos[48];
	int k = sys_counts_tpl(env, axis, pos, sizeof(pos));

	snprintf(tpl, cap,
		 "FAULT ENCODER: axis %c: potentiometer reads {n} V "
		 "but {n} V is expected at encoder position %s; "
		 "they differ by {n} V, more than the {n} V allowed, "
		 "for {n} cycles." SX_SAFE_OK " Recovery: press the E-stop "
		 "and keep it pressed, check the encoder and potentiometer "
		 "cables "
		 "of axis %c, restart roboelf and recalibrate",
		 'A' + axis, pos, 'A' + axis);
	return k;
}

void sx_check_encpot_units(const struct sys_env *env, const double *num, int k,
			   int axis, const char *line)
{
	if (k == 2 && fabs(num[3] - num[2] / env->per_unit[axis]) > 0.0051)
		fail_msg("the position in %s (%.2f) is not %.0f counts: %s",
			 env->unit[axis], num[3], num[2], line);
}
