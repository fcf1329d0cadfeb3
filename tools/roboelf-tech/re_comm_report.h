/*
 * re_comm_report.h - the commissioning run's report: a text file
 * DIR/commissioning.txt (every step, probe and check with its result, the
 * controller's identity, the fix of the failed step) and the plots
 * (re_comm_plot.h: DIR/pots-at-rest.gp and .png, DIR/move-A.gp and .png
 * ...).
 *
 * Every file is written whole or not at all (a temporary file renamed;
 * the text through base_durable_write()). A missing gnuplot leaves the
 * plots out and says so in the report. Nothing here prints.
 */
#ifndef RE_COMM_REPORT_H
#define RE_COMM_REPORT_H

#include <stddef.h>

#include "re_comm.h"

#define RE_COMM_REPORT_NAME "commissioning.txt"

struct re_comm_where {
	const char *address; /* the controller's address */
	const char *config;  /* the configuration file */
	const char *date;    /* e.g. "2026-11-25 08:30:00 UTC" */
};

/*
 * re_comm_report() - write the report of run @c into directory @dir
 * (created if missing, mode 0755).
 * @plots: [out] how many PNG files were written (may be NULL).
 * @err: [out] the reason on failure ("cannot write 'DIR/...': ...").
 * Return: GL_OK; GL_ERR_SYS (errno kept), GL_ERR_OVERFLOW.
 */
int re_comm_report(const struct re_comm *c, const struct re_comm_where *w,
		   const char *dir, int *plots, char *err, size_t errlen);

/*
 * re_comm_summary() - one line for the console: "PASSED: ..." or
 * "FAILED at step X: <text> - fix: <fix>", into @buf (@cap bytes).
 */
void re_comm_summary(const struct re_comm *c, char *buf, size_t cap);

#endif /* RE_COMM_REPORT_H */
