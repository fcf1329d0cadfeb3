/*
 * re_comm_report.c - the commissioning report and its plots
 * (re_comm_report.h). The plots go through gnuplot (the PNG terminal)
 * into "NAME.png.tmp", renamed when gnuplot succeeded.
 */
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "base_durable.h"
#include "gl_err.h"
#include "re_comm_report.h"

#define REPORT_MAX (64 * 1024)

struct buf {
	char *p;
	size_t n, cap;
};

static void put(struct buf *b, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

static void put(struct buf *b, const char *fmt, ...)
{
	va_list ap;
	int k;

	if (b->n >= b->cap)
		return;
	va_start(ap, fmt);
	k = vsnprintf(b->p + b->n, b->cap - b->n, fmt, ap);
	va_end(ap);
	b->n = k < 0 ? b->cap : b->n + (size_t)k;
}

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

/* Run gnuplot with @script and inline data; the PNG renamed into place. */
static int gnuplot_png(const char *png, const char *script, const char *data)
{
	char tmp[1200];
	FILE *gp;

	snprintf(tmp, sizeof(tmp), "%s.tmp", png);
	gp = popen("gnuplot 2>/dev/null", "w");
	if (!gp)
		return -1;
	fprintf(gp, "set terminal png size 900,600\nset output '%s'\n", tmp);
	fputs(script, gp);
	fputs(data, gp);
	fprintf(gp, "unset multiplot\nset output\n");
	if (pclose(gp) != 0) {
		unlink(tmp);
		return -1;
	}
	return rename(tmp, png) == 0 ? 0 : -1;
}

static int plot_noise(const struct re_comm *c, const char *dir)
{
	static char data[RE_AXES * RE_COMM_NOISE_N * 32];
	char script[512], png[1024];
	struct buf d = {data, 0, sizeof(data)};

	if (c->noise_n < 2)
		return 0;
	for (int ax = 0; ax < RE_AXES; ax++) {
		double mean = 0;

		for (int i = 0; i < c->noise_n; i++)
			mean += c->noise_v[ax][i] / c->noise_n;
		for (int i = 0; i < c->noise_n; i++)
			put(&d, "%d %.3f\n", i,
			    (c->noise_v[ax][i] - mean) * 1e3);
		put(&d, "e\n");
	}
	snprintf(script, sizeof(script),
		 "set title 'potentiometers at rest, motor power off: "
		 "reading minus its mean'\nset xlabel 'sample (10 ms apart "
		 "plus the reply time)'\n"
		 "set ylabel 'mV'\nplot '-' w lp t '%s', '-' w lp t '%s', "
		 "'-' w lp t '%s'\n",
		 c->cfg->axes[0].name, c->cfg->axes[1].name,
		 c->cfg->axes[2].name);
	snprintf(png, sizeof(png), "%s/pots-at-rest.png", dir);
	return gnuplot_png(png, script, data) == 0 ? 1 : -1;
}

static void put_trace(struct buf *d, const struct re_comm_trace *t, int pot)
{
	for (int i = 0; i < t->n; i++)
		put(d, "%.1f %.4f\n", t->t_ms[i],
		    pot ? t->pot_v[i] : t->enc[i]);
	put(d, "e\n");
}

static int plot_move(const struct re_comm *c, int ax, const char *dir)
{
	static char data[2 * RE_COMM_TRACE_N * 40 + 1024];
	const struct re_comm_trace *t = &c->trace[ax];
	char png[1024];
	struct buf d = {data, 0, sizeof(data)};

	if (t->n < 2)
		return 0;
	put(&d,
	    "set multiplot layout 2,1 title 'axis %s: the small move "
	    "(encoder against motor, potentiometer against encoder)'\n"
	    "set xlabel 'ms after BG'\nset ylabel 'encoder, counts'\n"
	    "plot '-' w l t 'encoder'\n",
	    c->cfg->axes[ax].name);
	put_trace(&d, t, 0);
	put(&d,
	    "set ylabel 'potentiometer, V'\nplot '-' w l t 'analog input "
	    "%d'\n",
	    c->cfg->axes[ax].analog.input);
	put_trace(&d, t, 1);
	snprintf(png, sizeof(png), "%s/move-%s.png", dir,
		 c->cfg->axes[ax].name);
	return gnuplot_png(png, "", data) == 0 ? 1 : -1;
}

static void put_lines(struct buf *b, const char *text)
{
	while (*text) {
		size_t n = strcspn(text, "\n");

		put(b, "    %.*s\n", (int)n, text);
		text += n + (text[n] == '\n');
	}
}

static void put_items(const struct re_comm *c, struct buf *b)
{
	const char *step = "";

	for (int i = 0; i < c->n && i < RE_COMM_ITEMS; i++) {
		const struct re_comm_item *it = &c->item[i];

		if (strcmp(step, it->step))
			put(b, "\n== %s\n", step = it->step);
		put(b, "%s  %-16s %s\n", re_comm_res_name(it->res), it->name,
		    it->text);
		if (it->res == RE_COMM_FAIL && it->fix[0])
			put(b, "      fix: %s\n", it->fix);
	}
}

int re_comm_report(const struct re_comm *c, const struct re_comm_where *w,
		   const char *dir, int *plots, char *err, size_t errlen)
{
	static char text[REPORT_MAX];
	struct buf b = {text, 0, sizeof(text)};
	char path[1024], line[1024];
	int np = 0, bad = 0, r;

	if (mkdir(dir, 0755) != 0 && errno != EEXIST) {
		snprintf(err, errlen, "cannot create '%s': %s", dir,
			 strerror(errno));
		return GL_ERR_SYS;
	}
	r = plot_noise(c, dir);
	np += r > 0;
	bad += r < 0;
	for (int ax = 0; ax < RE_AXES; ax++) {
		r = plot_move(c, ax, dir);
		np += r > 0;
		bad += r < 0;
	}
	re_comm_summary(c, line, sizeof(line));
	put(&b, "RoboELF commissioning report\n\ndate: %s\n", w->date);
	put(&b, "controller: %s, serial %ld, at %s\nconfiguration: %s\n",
	    c->model, c->serial, w->address, w->config);
	put(&b, "motor power switched on during the run: %s\n",
	    c->power_on_seen ? "yes (relay and motion steps)" : "never");
	put(&b, "result: %s\n", line);
	put_items(c, &b);
	put(&b, "\n== the controller reports of itself\nID:\n");
	put_lines(&b, c->id_text);
	put(&b, "TH:\n");
	put_lines(&b, c->th_text);
	put(&b, "\nplots: %d PNG file(s) in %s%s\n", np, dir,
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
