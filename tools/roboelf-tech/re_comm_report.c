/*
 * re_comm_report.c - the commissioning report and its plots
 * (re_comm_report.h; the plots: re_comm_plot.h).
 */
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "base_durable.h"
#include "re_comm_util.h"
#include "gl_err.h"
#include "re_comm_plot.h"
#include "re_comm_report.h"

#define REPORT_MAX (64 * 1024)

void re_comm_summary(const struct re_comm *c, char *buf, size_t cap)
{
	int notes = 0;

	for (int i = 0; i < c->n && i < RE_COMM_ITEMS; i++) {
		const struct re_comm_item *it = &c->item[i];

		if (it->res == RE_COMM_FAIL) {
			snprintf(buf, cap,
				 "FAILED at step %s (%s): %s - fix: %s",
				 it->step, it->name, it->text, it->fix);
			return;
		}
		notes += it->res == RE_COMM_NOTE;
	}
	snprintf(buf, cap,
		 "PASSED: every step passed (%d checks, %d notes on behaviour "
		 "the programs are safe with either way)",
		 c->n, notes);
}

static void put_lines(struct rc_text *b, const char *text)
{
	while (*text) {
		size_t n = strcspn(text, "\n");

		rc_text_put(b, "    %.*s\n", (int)n, text);
		text += n + (text[n] == '\n');
	}
}

static void put_items(const struct re_comm *c, struct rc_text *b)
{
	const char *step = "";

	for (int i = 0; i < c->n && i < RE_COMM_ITEMS; i++) {
		const struct re_comm_item *it = &c->item[i];

		if (strcmp(step, it->step))
			rc_text_put(b, "\n== %s\n", step = it->step);
		rc_text_put(b, "%s  %-16s %s\n", re_comm_res_name(it->res),
			    it->name, it->text);
		if (it->res == RE_COMM_FAIL && it->fix[0])
			rc_text_put(b, "      fix: %s\n", it->fix);
	}
}

int re_comm_report(const struct re_comm *c, const struct re_comm_where *w,
		   const char *dir, int *plots, char *err, size_t errlen)
{
	static char text[REPORT_MAX];
	struct rc_text b = {text, 0, sizeof(text)};
	char path[1024], line[1024];
	int np = 0, bad = 0, r;

	if (mkdir(dir, 0755) != 0 && errno != EEXIST) {
		snprintf(err, errlen, "cannot create '%s': %s", dir,
			 strerror(errno));
		return GL_ERR_SYS;
	}
	re_comm_plots(c, dir, &np, &bad);
	re_comm_summary(c, line, sizeof(line));
	rc_text_put(&b, "RoboELF commissioning report\n\ndate: %s\n", w->date);
	rc_text_put(&b,
		    "controller: %s, serial %ld, at %s\nconfiguration: %s\n",
		    c->model, c->serial, w->address, w->config);
	rc_text_put(&b, "motor power switched on during the run: %s\n",
		    c->power_on_seen ? "yes (relay and motion steps)"
				     : "never");
	rc_text_put(&b, "result: %s\n", line);
	put_items(c, &b);
	rc_text_put(&b, "\n== the controller reports of itself\nID:\n");
	put_lines(&b, c->id_text);
	rc_text_put(&b, "TH:\n");
	put_lines(&b, c->th_text);
	rc_text_put(
	    &b,
	    "\nplots: %d PNG file(s) in %s, each drawn from its gnuplot "
	    "script (NAME.gp)%s\n",
	    np, dir,
	    bad ? " (gnuplot missing or failed for some: not drawn)" : "");
	if (b.n >= b.cap) {
		snprintf(err, errlen, "the report is longer than %d bytes",
			 REPORT_MAX);
		return GL_ERR_OVERFLOW;
	}
	snprintf(path, sizeof(path), "%s/%s", dir, RE_COMM_REPORT_NAME);
	r = base_durable_write(path, text, b.n, 0644);
	if (r != 0) {
		errno = -r;
		snprintf(err, errlen, "cannot write '%s': %s", path,
			 strerror(-r));
		return GL_ERR_SYS;
	}
	if (plots)
		*plots = np;
	return GL_OK;
}
