/* gload_dl.c - galil-load's controller steps; see gload_dl.h. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "base_clock.h"
#include "gl_err.h"
#include "gl_ident.h"
#include "gload_dl.h"

#define REPLY_CAP 256

int gload_exit_for(int err)
{
	if (err >= 0)
		return GLOAD_EXIT_OK;
	if (err == GL_ERR_ARG)
		return GLOAD_EXIT_USAGE;
	if (err == GL_ERR_CTRL || err == GL_ERR_MISMATCH)
		return GLOAD_EXIT_CTRL;
	return GLOAD_EXIT_CONN;
}

int gload_query_number(gl_link *l, const char *cmd, double *v, int timeout_ms)
{
	char resp[REPLY_CAP], *end;
	int rc = gl_link_command(l, cmd, resp, sizeof(resp), timeout_ms);

	if (rc < 0)
		return rc;
	errno = 0;
	*v = strtod(resp, &end);
	while (*end == ' ' || *end == '\r' || *end == '\n')
		end++;
	if (end == resp || *end || errno)
		return GL_ERR_PROTO;
	return GL_OK;
}

static int send_simple(gl_link *l, const char *cmd, int timeout_ms)
{
	char resp[REPLY_CAP];
	int rc = gl_link_command(l, cmd, resp, sizeof(resp), timeout_ms);

	return rc < 0 ? rc : GL_OK;
}

int gload_dl_busy(gl_link *l, int watch_ms, int *state, int timeout_ms)
{
	double xq = -1, st = -1, hb0 = 0, hb1 = 0;

	*state = -1;
	if (gload_query_number(l, "MG _XQ0", &xq, timeout_ms) != GL_OK ||
	    xq < 0)
		return 0;
	if (gload_query_number(l, "MG state", &st, timeout_ms) != GL_OK ||
	    (st != 1 && st != 3))
		return 0;
	if (gload_query_number(l, "MG hbpc", &hb0, timeout_ms) != GL_OK)
		return 0;
	base_sleep_ms(watch_ms);
	if (gload_query_number(l, "MG hbpc", &hb1, timeout_ms) != GL_OK ||
	    hb1 == hb0)
		return 0;
	*state = (int)st;
	return 1;
}

/* Every profiler stopped (_BGx = 0), waited for at most @stop_ms; on
 * GL_ERR_TIMEOUT @failed names the first axis still moving ("MG _BGB"). */
static int wait_stopped(gl_link *l, int axes, int stop_ms,
			char failed[GLOAD_CMD_LEN], int timeout_ms)
{
	long long end = base_now_ms() + stop_ms;
	double bg;
	int i, rc, moving;

	do {
		moving = -1;
		for (i = 0; i < axes; i++) {
			char cmd[GLOAD_CMD_LEN];

			snprintf(cmd, sizeof(cmd), "MG _BG%c", 'A' + i);
			rc = gload_query_number(l, cmd, &bg, timeout_ms);
			if (rc) {
				memcpy(failed, cmd, sizeof(cmd));
				return rc;
			}
			if (bg != 0 && moving < 0) {
				moving = i;
				memcpy(failed, cmd, sizeof(cmd));
			}
		}
		if (moving >= 0)
			base_sleep_ms(10);
	} while (moving >= 0 && base_now_ms() < end);
	return moving >= 0 ? GL_ERR_TIMEOUT : GL_OK;
}

/* An axis still moves @stop_ms after ST: AB 1 ends the motion at once (the
 * program threads are already halted), then wait again for the profilers.
 * @failed keeps the axis that did not stop. */
static int abort_motion(gl_link *l, int axes, int stop_ms,
			char failed[GLOAD_CMD_LEN], int timeout_ms)
{
	char axis[GLOAD_CMD_LEN];
	int rc;

	memcpy(axis, failed, sizeof(axis));
	snprintf(failed, GLOAD_CMD_LEN, "AB 1");
	rc = send_simple(l, failed, timeout_ms);
	if (!rc)
		rc = wait_stopped(l, axes, stop_ms, failed, timeout_ms);
	if (!rc)
		memcpy(failed, axis, sizeof(axis));
	return rc;
}

/* Motors off (MO: never while a profiler runs) and read back off. */
static int motors_off(gl_link *l, int axes, int *running,
		      char failed[GLOAD_CMD_LEN], int timeout_ms)
{
	double mo;
	int i, rc;

	snprintf(failed, GLOAD_CMD_LEN, "MO");
	rc = send_simple(l, failed, timeout_ms);
	for (i = 0; !rc && i < axes; i++) {
		snprintf(failed, GLOAD_CMD_LEN, "MG _MO%c", 'A' + i);
		rc = gload_query_number(l, failed, &mo, timeout_ms);
		if (!rc && mo != 1) {
			*running = -1;
			rc = GL_ERR_MISMATCH;
		}
	}
	return rc;
}

int gload_dl_halt(gl_link *l, int threads, int axes, int stop_ms, int *running,
		  char failed[GLOAD_CMD_LEN], int timeout_ms)
{
	char axis[GLOAD_CMD_LEN];
	double xq;
	int i, rc, late = 0;

	/* a controller without the RoboELF program makes prun a variable */
	snprintf(failed, GLOAD_CMD_LEN, "prun=0");
	rc = send_simple(l, failed, timeout_ms);
	for (i = 0; !rc && i < threads; i++) {
		snprintf(failed, GLOAD_CMD_LEN, "HX%d", i);
		rc = send_simple(l, failed, timeout_ms);
	}
	/* bare ST: every axis, decelerating (and the threads once more) */
	if (!rc) {
		snprintf(failed, GLOAD_CMD_LEN, "ST");
		rc = send_simple(l, failed, timeout_ms);
	}
	if (!rc)
		rc = wait_stopped(l, axes, stop_ms, failed, timeout_ms);
	if (rc == GL_ERR_TIMEOUT) {
		rc = abort_motion(l, axes, stop_ms, failed, timeout_ms);
		late = rc == GL_OK;
		if (late)
			memcpy(axis, failed, sizeof(axis));
	}
	if (!rc)
		rc = motors_off(l, axes, running, failed, timeout_ms);
	for (i = 0; !rc && i < threads; i++) {
		snprintf(failed, GLOAD_CMD_LEN, "MG _XQ%d", i);
		rc = gload_query_number(l, failed, &xq, timeout_ms);
		if (!rc && xq != -1.0) {
			*running = i;
			rc = GL_ERR_MISMATCH;
		}
	}
	if (!rc && late) {
		/* halted, but an axis did not stop after ST in time */
		memcpy(failed, axis, sizeof(axis));
		*running = GLOAD_HALT_LATE;
		return GL_ERR_MISMATCH;
	}
	if (!rc)
		failed[0] = '\0';
	return rc;
}

/* Next line of a normal-form text from *@pos; 0 at the end. */
static int nf_line(const char *t, size_t len, size_t *pos, const char **s,
		   size_t *n)
{
	const char *e;

	if (*pos >= len)
		return 0;
	*s = t + *pos;
	e = memchr(*s, '\n', len - *pos);
	*n = e ? (size_t)(e - *s) : len - *pos;
	*pos += *n + 1;
	return 1;
}

int gload_dl_compare(const char *want, size_t wlen, const char *got,
		     size_t glen, int *line)
{
	char *a = malloc(wlen + 1), *b = malloc(glen + 1);
	const char *sa = NULL, *sb = NULL;
	size_t pa = 0, pb = 0, na = 0, nb = 0;
	int la, lb, more_a, more_b, n = 0, rc = GL_ERR_NOMEM;

	if (!a || !b)
		goto out_free;
	la = gl_ident_normalise(want, wlen, a, wlen + 1);
	lb = gl_ident_normalise(got, glen, b, glen + 1);
	if (la < 0 || lb < 0)
		goto out_free;
	rc = GL_OK;
	do {
		n++;
		more_a = nf_line(a, (size_t)la, &pa, &sa, &na);
		more_b = nf_line(b, (size_t)lb, &pb, &sb, &nb);
		if (more_a != more_b ||
		    (more_a && (na != nb || memcmp(sa, sb, na)))) {
			*line = n;
			rc = GL_ERR_MISMATCH;
		}
	} while (!rc && more_a && more_b);
out_free:
	free(a);
	free(b);
	return rc;
}

int gload_dl_upload(gl_link *l, char *buf, size_t cap, int timeout_ms)
{
	int rc;

	if (timeout_ms < GLOAD_SLOW_TIMEOUT_MS)
		timeout_ms = GLOAD_SLOW_TIMEOUT_MS;
	rc = gl_link_upload(l, buf, cap, timeout_ms);
	if (rc < 0)
		return rc;
	return gl_ident_normalise(buf, (size_t)rc, buf, cap);
}

int gload_dl_download(gl_link *l, const char *text, size_t len, int *bad_line,
		      int timeout_ms)
{
	if (timeout_ms < GLOAD_SLOW_TIMEOUT_MS)
		timeout_ms = GLOAD_SLOW_TIMEOUT_MS;
	*bad_line = 0;
	return gl_link_download(l, text, len, bad_line, timeout_ms);
}

int gload_dl_erase(gl_link *l, int timeout_ms)
{
	char buf[REPLY_CAP];
	int bad, rc;

	rc = gload_dl_download(l, "", 0, &bad, timeout_ms);
	if (rc)
		return rc;
	rc = gload_dl_upload(l, buf, sizeof(buf), timeout_ms);
	if (rc == GL_ERR_OVERFLOW)
		return GL_ERR_MISMATCH;
	if (rc < 0)
		return rc;
	return rc == 0 ? GL_OK : GL_ERR_MISMATCH;
}

int gload_dl_burn(gl_link *l, int timeout_ms)
{
	if (timeout_ms < GLOAD_SLOW_TIMEOUT_MS)
		timeout_ms = GLOAD_SLOW_TIMEOUT_MS;
	return send_simple(l, "BP", timeout_ms);
}

int gload_dl_start(gl_link *l, const char *label, double *xq0, int timeout_ms)
{
	char cmd[GL_LINE_MAX + 1];
	double v = -1;
	int rc;

	if (snprintf(cmd, sizeof(cmd), "XQ #%s,0", label) >= (int)sizeof(cmd))
		return GL_ERR_ARG;
	rc = send_simple(l, cmd, timeout_ms);
	if (!rc)
		rc = gload_query_number(l, "MG _XQ0", &v, timeout_ms);
	if (xq0)
		*xq0 = v;
	if (!rc && v == -1.0)
		rc = GL_ERR_MISMATCH;
	return rc;
}
