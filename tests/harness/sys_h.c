/*
 * sys_h.c - system-test fixture: galil-sim + galil-load + roboelf on one
 * machine, fault injection through the control port. See sys_h.h.
 */
#include "sys_h.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <arpa/inet.h>

#include "re_config.h"

#define READY_LINE	"RoboELF Ready for Use"
#define CTL_TIMEOUT_MS	2000
#define EVT_BUF		(512 * 1024)
#define POLL_MS		10
#define LOAD_TIMEOUT_MS 60000

static void seterr(char *err, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

static void seterr(char *err, const char *fmt, ...)
{
	va_list ap;

	va_start(ap, fmt);
	vsnprintf(err, SYS_ERR_MAX, fmt, ap);
	va_end(ap);
}

/* The last @n bytes of a stream, for messages. */
static const char *tail(const struct proc *p, enum proc_stream s, size_t n)
{
	const char *t = proc_output(p, s);
	size_t len = strlen(t);

	return len > n ? t + len - n : t;
}

static void sleep_ms(int ms)
{
	poll(NULL, 0, ms);
}

/* ---- environment -------------------------------------------------------- */

static void env_paths(struct sys_env *e)
{
	const char *bin = getenv("ROBOELF_BIN");
	const char *top = getenv("ROBOELF_TOP");
	const char *build = getenv("BUILD");

	if (bin && *bin)
		snprintf(e->bin, sizeof(e->bin), "%s", bin);
	else
		snprintf(e->bin, sizeof(e->bin), "%s/bin",
			 build && *build ? build : "build");
	snprintf(e->top, sizeof(e->top), "%s", top && *top ? top : ".");
	e->keep = getenv("ROBOELF_KEEP") && *getenv("ROBOELF_KEEP") &&
		  strcmp(getenv("ROBOELF_KEEP"), "0");
}

static int read_file(const char *path, char **out, size_t *len)
{
	FILE *f = fopen(path, "rb");
	size_t cap = 65536, n = 0;
	char *buf;

	if (!f)
		return -1;
	buf = malloc(cap);
	while (buf) {
		size_t got = fread(buf + n, 1, cap - n - 1, f);

		n += got;
		if (n + 1 < cap)
			break;
		cap *= 2;
		char *nb = realloc(buf, cap);

		if (!nb) {
			free(buf);
			buf = NULL;
		}
		buf = nb;
	}
	fclose(f);
	if (!buf)
		return -1;
	buf[n] = '\0';
	*out = buf;
	*len = n;
	return 0;
}

/* Does @line (indentation, optional "- ") start with "@key:"? */
static int line_has_key(const char *line, size_t len, const char *key,
			size_t *indent)
{
	size_t i = 0, k = strlen(key);

	while (i < len && line[i] == ' ')
		i++;
	if (i + 1 < len && line[i] == '-' && line[i + 1] == ' ')
		i += 2;
	*indent = i;
	return len - i > k && !memcmp(line + i, key, k) && line[i + k] == ':';
}

/* Is @key among the keys of @s (NULL-key ended, may be NULL)? */
static int has_key(const struct sys_subst *s, const char *key)
{
	for (int i = 0; s && s[i].key; i++)
		if (!strcmp(s[i].key, key))
			return 1;
	return 0;
}

/* Write @src to @f with @var applied, then @base for keys @var lacks. */
static int subst_write(FILE *f, const char *src, const struct sys_subst *base,
		       const struct sys_subst *var, char *err)
{
	const struct sys_subst *s[2] = {var, base};
	int done[2][SYS_SUBST_MAX + 4] = {{0}};
	const char *p = src;

	for (int i = 0; base[i].key; i++)
		done[1][i] = has_key(var, base[i].key);
	while (*p) {
		const char *nl = strchr(p, '\n');
		size_t len = nl ? (size_t)(nl - p) : strlen(p), ind = 0;
		int hit = 0;

		for (int l = 0; l < 2 && !hit; l++)
			for (int i = 0; s[l] && s[l][i].key && !hit; i++) {
				if (done[l][i] || *p == '#' ||
				    !line_has_key(p, len, s[l][i].key, &ind))
					continue;
				fprintf(f, "%.*s%s: %s\n", (int)ind, p,
					s[l][i].key, s[l][i].value);
				done[l][i] = hit = 1;
			}
		if (!hit)
			fprintf(f, "%.*s\n", (int)len, p);
		p += len + (nl ? 1 : 0);
	}
	for (int l = 0; l < 2; l++)
		for (int i = 0; s[l] && s[l][i].key; i++)
			if (!done[l][i]) {
				seterr(err,
				       "config/roboelf.yaml has no key "
				       "'%s' to replace",
				       s[l][i].key);
				return -1;
			}
	return 0;
}

const char *sys_record(void)
{
	const char *v = getenv("ROBOELF_SYS_RECORD");

	return v && *v ? v : NULL;
}

enum re_fault_id sys_stall_fault(void)
{
	const char *r = sys_record();

	return r && !strcmp(r, "stream") ? RE_F_WDOG_STREAM : RE_F_WDOG_REPLY;
}

int sys_env_write_config(struct sys_env *e, const struct sys_subst *subst,
			 const char *path)
{
	char src_path[SYS_PATH_MAX + 32], cal[SYS_PATH_MAX + 8],
	    log[SYS_PATH_MAX + 16], ics[SYS_PATH_MAX + 16];
	const char *rec = sys_record();
	struct sys_subst base[] = {
	    {"file", cal},
	    {"path", log},
	    {"icstation_state", ics},
	    {rec ? "record" : NULL, rec},
	    {NULL, NULL},
	};
	char *src;
	size_t len;
	FILE *f;
	int rc;

	snprintf(src_path, sizeof(src_path), "%s/config/roboelf.yaml", e->top);
	snprintf(cal, sizeof(cal), "\"%s\"", e->cal);
	snprintf(log, sizeof(log), "\"%s/roboelf.log\"", e->dir);
	snprintf(ics, sizeof(ics), "\"%s/icstation.state\"", e->dir);
	if (read_file(src_path, &src, &len) < 0) {
		seterr(e->err, "cannot read '%s': %s", src_path,
		       strerror(errno));
		return -1;
	}
	f = fopen(path, "w");
	if (!f) {
		seterr(e->err, "cannot write '%s': %s", path, strerror(errno));
		free(src);
		return -1;
	}
	rc = subst_write(f, src, base, subst, e->err);
	if (fclose(f) != 0 && rc == 0) {
		seterr(e->err, "cannot write '%s'", path);
		rc = -1;
	}
	free(src);
	return rc;
}

static int env_figures(struct sys_env *e)
{
	struct re_config *cfg = calloc(1, sizeof(*cfg));
	char err[RE_CONFIG_ERR_MAX];
	const struct re_config_axis *a;

	if (!cfg)
		return -1;
	if (re_config_load_file(e->cfg, cfg, err, sizeof(err)) != 0) {
		seterr(e->err, "test configuration refused: %s", err);
		free(cfg);
		return -1;
	}
	a = &cfg->axes[0];
	e->period_ms = cfg->period_ms;
	e->noncrit_factor = cfg->watchdog.noncritical_factor;
	e->crit_factor = cfg->watchdog.critical_factor;
	e->wdto_ms = cfg->watchdog.controller_timeout_ms;
	e->jto_ms = cfg->joystick.invalid_timeout_ms;
	e->persistence = a->persistence_cycles;
	e->allowed_error = a->allowed_error;
	e->vmin_cps = a->vmin_cps;
	e->vmax_cps = a->vmax_cps;
	e->step_counts = a->step_counts;
	e->er_counts = a->position_error_limit_counts;
	for (int i = 0; i < 3; i++) {
		e->per_unit[i] = cfg->axes[i].counts_per_unit;
		snprintf(e->unit[i], sizeof(e->unit[i]), "%s",
			 re_unit_name(cfg->axes[i].unit));
	}
	e->readback_timeout_ms =
	    cfg->relay.readback ? cfg->relay.readback_timeout_ms : 0;
	free(cfg);
	return 0;
}

int sys_counts_tpl(const struct sys_env *e, int axis, char *buf, size_t cap)
{
	if (e->per_unit[axis] > 0) {
		snprintf(buf, cap, "{n} counts ({n} %s)", e->unit[axis]);
		return 2;
	}
	snprintf(buf, cap, "{n} counts");
	return 1;
}

void sys_counts_text(const struct sys_env *e, int axis, long counts, char *buf,
		     size_t cap)
{
	double v = e->per_unit[axis] > 0 ? counts / e->per_unit[axis] : 0;

	if (e->per_unit[axis] > 0)
		snprintf(buf, cap, "%ld counts (%.2f %s)", counts,
			 v > -0.005 && v < 0 ? 0.0 : v, e->unit[axis]);
	else
		snprintf(buf, cap, "%ld counts", counts);
}

int sys_env_init(struct sys_env *e)
{
	memset(e, 0, sizeof(*e));
	env_paths(e);
	snprintf(e->dir, sizeof(e->dir), "/tmp/roboelf-sys-XXXXXX");
	if (!mkdtemp(e->dir)) {
		seterr(e->err, "cannot make a temporary directory: %s",
		       strerror(errno));
		e->dir[0] = '\0';
		return -1;
	}
	snprintf(e->cfg, sizeof(e->cfg), "%s/roboelf.yaml", e->dir);
	snprintf(e->cal, sizeof(e->cal), "%s/roboelf.cal", e->dir);
	if (sys_env_write_config(e, NULL, e->cfg) < 0)
		return -1;
	return env_figures(e);
}

/* ROBOELF_SYS_CAL=FILE: reuse a calibration made earlier (development). */
static int reuse_calibration(struct sys_env *e, const char *from)
{
	char *buf;
	size_t len;
	FILE *f;
	int ok;

	if (read_file(from, &buf, &len) < 0) {
		seterr(e->err, "cannot read '%s': %s", from, strerror(errno));
		return -1;
	}
	f = fopen(e->cal, "w");
	ok = f && fwrite(buf, 1, len, f) == len;
	if (f && fclose(f) != 0)
		ok = 0;
	free(buf);
	if (!ok)
		seterr(e->err, "cannot write '%s'", e->cal);
	return ok ? 0 : -1;
}

/* One full calibration with `--calibration full`. */
static int calibrate_full(struct sys_env *e, int timeout_ms)
{
	struct sys_opts o = {.calibration = "full",
			     .ready_timeout_ms = timeout_ms};
	struct sys_case c;
	struct stat st;
	int rc = -1, status;

	if (sys_case_start(&c, e, &o) < 0) {
		snprintf(e->err, sizeof(e->err), "%s", c.err);
		return -1;
	}
	e->calib_s = c.ready_wall_s;
	proc_signal(&c.re, SIGTERM);
	if (proc_wait_exit(&c.re, 10000, &status) < 0)
		seterr(e->err, "roboelf did not exit within 10 s of SIGTERM "
			       "after calibrating");
	else if (proc_exit_code(&c.re) != 0)
		seterr(e->err, "roboelf exited with %d after calibrating: %s",
		       proc_exit_code(&c.re), tail(&c.re, PROC_STDERR, 800));
	else if (stat(e->cal, &st) < 0 || !S_ISREG(st.st_mode))
		seterr(e->err,
		       "no calibration file '%s' after a full "
		       "calibration",
		       e->cal);
	else
		rc = 0;
	sys_case_stop(&c);
	return rc;
}

/* The key of @e's configuration: FNV-1a of its text with the temporary
 * directory taken out (the only thing that differs between programs that
 * use the same configuration). 0 if it cannot be read. */
static uint64_t config_key(const struct sys_env *e)
{
	uint64_t h = 14695981039346656037ULL;
	size_t len, dlen = strlen(e->dir);
	char *buf;

	if (read_file(e->cfg, &buf, &len) < 0)
		return 0;
	for (size_t i = 0; i < len; i++) {
		if (dlen && !strncmp(buf + i, e->dir, dlen)) {
			i += dlen - 1;
			continue;
		}
		h = (h ^ (unsigned char)buf[i]) * 1099511628211ULL;
	}
	free(buf);
	return h;
}

/* Copy @from to @to whole or not at all (a temporary file renamed). */
static int copy_whole(const char *from, const char *to)
{
	char tmp[SYS_PATH_MAX + 80], *buf;
	size_t len;
	FILE *f;
	int ok;

	if (read_file(from, &buf, &len) < 0)
		return -1;
	snprintf(tmp, sizeof(tmp), "%s.%ld.tmp", to, (long)getpid());
	f = fopen(tmp, "w");
	ok = f && fwrite(buf, 1, len, f) == len;
	if (f && fclose(f) != 0)
		ok = 0;
	free(buf);
	if (ok && rename(tmp, to) == 0)
		return 0;
	unlink(tmp);
	return -1;
}

/* Take the lock @fd within @timeout_ms (polled: flock has no deadline). */
static int lock_within(int fd, int timeout_ms)
{
	long long end = proc_now_ms() + timeout_ms;

	while (flock(fd, LOCK_EX | LOCK_NB) < 0) {
		if (errno != EWOULDBLOCK || proc_now_ms() > end)
			return -1;
		poll(NULL, 0, 50);
	}
	return 0;
}

/* ROBOELF_SYS_CAL_SHARE=DIR: the first program of the run with this
 * configuration calibrates and keeps a copy in DIR; the others wait for
 * it (a lock) and copy it into their own directory. */
static int shared_calibration(struct sys_env *e, const char *share,
			      int timeout_ms)
{
	char copy[SYS_PATH_MAX + 64], lock[SYS_PATH_MAX + 80];
	uint64_t key = config_key(e);
	int fd, rc;

	if (!key)
		return calibrate_full(e, timeout_ms);
	snprintf(copy, sizeof(copy), "%s/calibration-%016llx.cal", share,
		 (unsigned long long)key);
	snprintf(lock, sizeof(lock), "%s.lock", copy);
	fd = open(lock, O_CREAT | O_RDWR | O_CLOEXEC, 0600);
	if (fd < 0 || lock_within(fd, timeout_ms + 30000) < 0) {
		seterr(e->err, "cannot lock '%s' within %d ms: %s", lock,
		       timeout_ms + 30000, strerror(errno));
		if (fd >= 0)
			close(fd);
		return -1;
	}
	if (access(copy, R_OK) == 0) {
		rc = reuse_calibration(e, copy);
		if (!rc)
			snprintf(e->cal_from, sizeof(e->cal_from), "%s", copy);
	} else {
		rc = calibrate_full(e, timeout_ms);
		if (!rc && copy_whole(e->cal, copy) < 0)
			seterr(e->err, "cannot keep a copy in '%s'", copy);
	}
	close(fd); /* the lock goes with it */
	return rc;
}

int sys_env_calibrate(struct sys_env *e, int timeout_ms)
{
	const char *reuse = getenv("ROBOELF_SYS_CAL");
	const char *share = getenv("ROBOELF_SYS_CAL_SHARE");

	if (reuse && *reuse)
		return reuse_calibration(e, reuse);
	if (share && *share)
		return shared_calibration(e, share, timeout_ms);
	return calibrate_full(e, timeout_ms);
}

const char *sys_env_cal_text(const struct sys_env *e, char *buf, size_t cap)
{
	if (e->cal_from[0])
		snprintf(buf, cap, "full calibration shared: copied from %s "
			 "(made once in this run by the first program with "
			 "this configuration)", e->cal_from);
	else
		snprintf(buf, cap, "full calibration done in %.1f s",
			 e->calib_s);
	return buf;
}

void sys_env_cleanup(struct sys_env *e)
{
	DIR *d;
	struct dirent *de;
	char path[SYS_PATH_MAX + 300];

	if (!e->dir[0] || e->keep)
		return;
	d = opendir(e->dir);
	while (d && (de = readdir(d))) {
		if (!strcmp(de->d_name, ".") || !strcmp(de->d_name, ".."))
			continue;
		snprintf(path, sizeof(path), "%s/%s", e->dir, de->d_name);
		unlink(path);
	}
	if (d)
		closedir(d);
	rmdir(e->dir);
	e->dir[0] = '\0';
}

int sys_env_ready(struct sys_env *e)
{
	int ok = sys_env_init(e) == 0 && sys_env_calibrate(e, 150000) == 0;
	char text[SYS_PATH_MAX + 320];

	if (ok)
		printf("[   INFO   ] %s (P %d ms, %s)\n",
		       sys_env_cal_text(e, text, sizeof(text)), e->period_ms,
		       e->dir);
	else
		printf("[   INFO   ] full calibration FAILED (P %d ms, %s): %s\n",
		       e->period_ms, e->dir, e->err);
	fflush(stdout);
	return ok;
}

void sys_env_done(struct sys_env *e, int ready)
{
	if (!ready)
		e->keep = 1;
	sys_env_cleanup(e);
}

/* ---- one case: start and stop ------------------------------------------- */

static int run_load(struct sys_case *c)
{
	struct sys_env *e = c->env;
	char bin[SYS_PATH_MAX + 16], addr[32], dmc[SYS_PATH_MAX + 8];
	char *argv[] = {
	    bin,    (char *)"-a", addr, (char *)"--start", (char *)"--config",
	    c->cfg, dmc,	  NULL};
	struct proc p;
	int status, rc = -1;

	snprintf(bin, sizeof(bin), "%s/galil-load", e->bin);
	snprintf(addr, sizeof(addr), "%s:%d", c->sim_addr, c->sim.port);
	snprintf(dmc, sizeof(dmc), "%s/dmc", e->top);
	if (proc_spawn(&p, argv, NULL) < 0) {
		seterr(c->err, "cannot start '%s': %s", bin, strerror(errno));
		return -1;
	}
	if (proc_wait_exit(&p, LOAD_TIMEOUT_MS, &status) < 0)
		seterr(c->err, "galil-load did not finish within %d ms",
		       LOAD_TIMEOUT_MS);
	else if (proc_exit_code(&p) != 0)
		seterr(c->err, "galil-load exited with %d: %s",
		       proc_exit_code(&p), tail(&p, PROC_STDERR, 800));
	else
		rc = 0;
	proc_kill(&p);
	return rc;
}

static int start_roboelf(struct sys_case *c, const struct sys_opts *o)
{
	struct sys_env *e = c->env;
	char bin[SYS_PATH_MAX + 16], addr[32], period[16];
	char *argv[48];
	int n = 0;

	snprintf(bin, sizeof(bin), "%s/%s", e->bin,
		 o->tech ? "roboelf-tech" : "roboelf");
	snprintf(addr, sizeof(addr), "%s:%d", c->sim_addr, c->sim.port);
	for (int i = 0; o->re_wrap && o->re_wrap[i] && n < 12; i++)
		argv[n++] = o->re_wrap[i];
	argv[n++] = bin;
	argv[n++] = (char *)"-c";
	argv[n++] = c->cfg;
	argv[n++] = (char *)"--galil";
	argv[n++] = addr;
	argv[n++] = (char *)"--relay";
	argv[n++] = c->relay_link;
	if (!o->tech) {
		argv[n++] = (char *)"--calibration";
		argv[n++] = (char *)(o->calibration ? o->calibration : "file");
	}
	argv[n++] = (char *)"--log";
	argv[n++] = c->log;
	if (o->period_ms > 0 && !o->tech) {
		snprintf(period, sizeof(period), "%d", o->period_ms);
		argv[n++] = (char *)"--period";
		argv[n++] = period;
	}
	for (int i = 0; o->re_args && o->re_args[i] && n < 46; i++)
		argv[n++] = o->re_args[i];
	argv[n] = NULL;
	if (proc_spawn(&c->re, argv, o->re_env) < 0) {
		seterr(c->err, "cannot start '%s': %s", bin, strerror(errno));
		return -1;
	}
	c->re_up = 1;
	return 0;
}

/* Ready, or a FAULT line / exit first (then fail at once). */
static int wait_ready(struct sys_case *c, const struct sys_opts *o)
{
	int full = o->calibration && !strcmp(o->calibration, "full");
	int timeout = o->ready_timeout_ms ? o->ready_timeout_ms
		      : full		  ? 150000
					  : 20000;
	long long t0 = proc_now_ms(), deadline = t0 + timeout;
	const char *why = "timeout";

	for (;;) {
		if (proc_wait_line(&c->re, PROC_STDOUT, READY_LINE, 20, NULL,
				   0) == 0) {
			c->ready_wall_s = (double)(proc_now_ms() - t0) / 1e3;
			return 0;
		}
		if (proc_find_line(&c->re, PROC_STDOUT, "FAULT ", NULL, 0) ==
		    0) {
			why = "FAULT line";
			break;
		}
		if (c->re.out[PROC_STDOUT].fd < 0) {
			why = "exit";
			break;
		}
		if (proc_now_ms() > deadline)
			break;
	}
	proc_wait_exit(&c->re, 300, NULL);
	seterr(c->err,
	       "no '%s' from roboelf after %lld ms (%s, exit %d)"
	       "\n--- stdout:\n%s\n--- stderr:\n%s",
	       READY_LINE, proc_now_ms() - t0, why, proc_exit_code(&c->re),
	       tail(&c->re, PROC_STDOUT, 1500), tail(&c->re, PROC_STDERR, 800));
	return -1;
}

/* At Ready: motor power on, every motor on, nothing moving. */
static int check_armed(struct sys_case *c)
{
	char st[2048];

	if (sys_state(c, st, sizeof(st)) < 0)
		return -1;
	if (!strstr(st, " relay=on ") || !strstr(st, " A.mo=0 ") ||
	    !strstr(st, " B.mo=0 ") || !strstr(st, " C.mo=0 ")) {
		seterr(c->err,
		       "at Ready the robot is not armed with power "
		       "on: %s",
		       st);
		return -1;
	}
	return 0;
}

/* galil-sim with @o's arguments and always a UDP port (--udp-port 0: the
 * record stream's, any free one), read from its ready line. */
static int start_sim(struct sys_case *c, const struct sys_opts *o)
{
	char *args[SYS_SIM_ARGS_MAX + 3];
	int n = 0;

	for (int i = 0; o->sim_args && o->sim_args[i]; i++) {
		if (n == SYS_SIM_ARGS_MAX) {
			seterr(c->err, "more than %d galil-sim arguments",
			       SYS_SIM_ARGS_MAX);
			return -1;
		}
		args[n++] = o->sim_args[i];
	}
	args[n++] = (char *)"--udp-port";
	args[n++] = (char *)"0";
	args[n] = NULL;
	if (proc_sim_start_wrapped(&c->sim, o->sim_wrap, c->env->bin,
				   c->relay_link,
				   o->sim_wrap ? "0.0.0.0" : NULL, args,
				   10000) < 0) {
		seterr(c->err, "galil-sim did not start ('%s/galil-sim')",
		       c->env->bin);
		return -1;
	}
	return 0;
}

/* The case's own configuration: @o's variant, and controller.udp_port
 * galil-sim's (unless the variant sets it). */
static int case_config(struct sys_case *c, const struct sys_opts *o)
{
	struct sys_subst all[SYS_SUBST_MAX + 2];
	char udp[16];
	int n = 0;

	for (int i = 0; o->subst && o->subst[i].key && n < SYS_SUBST_MAX; i++)
		all[n++] = o->subst[i];
	all[n] = (struct sys_subst){NULL, NULL};
	snprintf(udp, sizeof(udp), "%d", c->sim.udp_port);
	if (!has_key(all, "udp_port")) {
		all[n++] = (struct sys_subst){"udp_port", udp};
		all[n] = (struct sys_subst){NULL, NULL};
	}
	if (sys_env_write_config(c->env, all, c->cfg) < 0) {
		seterr(c->err, "%s", c->env->err);
		return -1;
	}
	return 0;
}

int sys_case_start(struct sys_case *c, struct sys_env *e,
		   const struct sys_opts *o)
{
	static const struct sys_opts none;

	memset(c, 0, sizeof(*c));
	c->ctl = -1;
	c->env = e;
	c->id = ++e->ncase;
	o = o ? o : &none;
	snprintf(c->relay_link, sizeof(c->relay_link), "%s/relay-%d", e->dir,
		 c->id);
	snprintf(c->log, sizeof(c->log), "%s/case-%d.log", e->dir, c->id);
	snprintf(c->cfg, sizeof(c->cfg), "%s/case-%d.yaml", e->dir, c->id);
	c->bufcap = EVT_BUF;
	c->buf = malloc(c->bufcap);
	if (!c->buf) {
		seterr(c->err, "out of memory");
		return -1;
	}
	snprintf(c->sim_addr, sizeof(c->sim_addr), "%s",
		 o->sim_addr ? o->sim_addr : "127.0.0.1");
	if (start_sim(c, o) < 0)
		goto fail;
	c->sim_up = 1;
	if (case_config(c, o) < 0)
		goto fail;
	c->ctl =
	    proc_ctl_connect_at(o->ctl_addr, c->sim.ctl_port, CTL_TIMEOUT_MS);
	if (c->ctl < 0) {
		seterr(c->err, "cannot connect to the control port %d",
		       c->sim.ctl_port);
		goto fail;
	}
	if ((!o->no_load && run_load(c) < 0) || start_roboelf(c, o) < 0)
		goto fail;
	if (o->no_ready)
		return 0;
	if (wait_ready(c, o) < 0)
		goto fail;
	c->t_ready_ms = sys_sim_time(c);
	if (c->t_ready_ms < 0 || sys_events(c) < 0 || check_armed(c) < 0)
		goto fail;
	return 0;
fail : {
	char keep[SYS_ERR_MAX];

	snprintf(keep, sizeof(keep), "%s", c->err);
	sys_case_stop(c);
	snprintf(c->err, sizeof(c->err), "%s", keep);
}
	return -1;
}

/* Keep the events beside the log, for a person reading a failure. */
static void dump_events(struct sys_case *c)
{
	char path[SYS_PATH_MAX + 16];
	FILE *f;

	if (c->ctl >= 0)
		sys_events(c);
	snprintf(path, sizeof(path), "%s/case-%d.events", c->env->dir, c->id);
	f = fopen(path, "w");
	for (size_t i = 0; f && i < c->nev; i++)
		fprintf(f, "%.0f %s\n", c->ev[i].t_ms, c->ev[i].text);
	if (f)
		fclose(f);
}

void sys_case_stop(struct sys_case *c)
{
	if (!c->env)
		return;
	if (c->buf)
		dump_events(c);
	if (c->re_up)
		proc_kill(&c->re);
	c->re_up = 0;
	if (c->ctl >= 0) {
		char r[64];

		proc_ctl_request(c->ctl, "quit", r, sizeof(r), 500);
		close(c->ctl);
	}
	c->ctl = -1;
	if (c->sim_up) {
		proc_wait_exit(&c->sim.p, 1000, NULL);
		proc_kill(&c->sim.p);
	}
	c->sim_up = 0;
	free(c->ev);
	c->ev = NULL;
	c->nev = c->capev = 0;
	free(c->buf);
	c->buf = NULL;
	if (c->relay_link[0])
		unlink(c->relay_link); /* galil-sim's, if it was killed */
	c->env = NULL;
}

/* ---- control port ------------------------------------------------------- */

int sys_ctl_ask(struct sys_case *c, const char *req, char *resp, size_t cap)
{
	int n = proc_ctl_request(c->ctl, req, resp, cap, CTL_TIMEOUT_MS);

	if (n < 0)
		seterr(c->err, "control request '%s': no answer", req);
	return n;
}

int sys_no_fault(struct sys_case *c, const char *when)
{
	char line[SYS_ERR_MAX / 2];

	proc_pump(&c->re, 0);
	if (proc_find_line(&c->re, PROC_STDOUT, "FAULT ", line, sizeof(line)) ==
	    0) {
		seterr(c->err, "%s: roboelf tripped (a false trip): %s", when,
		       line);
		return -1;
	}
	if (c->re.out[PROC_STDOUT].fd < 0) {
		seterr(c->err, "%s: roboelf exited:\n%s", when,
		       tail(&c->re, PROC_STDERR, SYS_ERR_MAX / 2));
		return -1;
	}
	return 0;
}

int sys_still_armed(struct sys_case *c, const char *when)
{
	char st[2048];

	if (sys_no_fault(c, when) < 0 || sys_state(c, st, sizeof(st)) < 0)
		return -1;
	if (!strstr(st, " relay=on ") || sys_state_num(st, "A.mo") != 0 ||
	    sys_state_num(st, "B.mo") != 0 || sys_state_num(st, "C.mo") != 0 ||
	    sys_state_num(st, "var.state") != 1) {
		seterr(c->err, "%s: the robot is no longer armed: %s", when,
		       st);
		return -1;
	}
	return 0;
}

int sys_ctl(struct sys_case *c, const char *fmt, ...)
{
	char req[256], resp[256];
	va_list ap;

	va_start(ap, fmt);
	vsnprintf(req, sizeof(req), fmt, ap);
	va_end(ap);
	if (sys_ctl_ask(c, req, resp, sizeof(resp)) < 0)
		return -1;
	if (strcmp(resp, "ok")) {
		seterr(c->err, "control request '%s': %s", req, resp);
		return -1;
	}
	return 0;
}

double sys_sim_time(struct sys_case *c)
{
	char resp[64], *end;
	double t;

	if (sys_ctl_ask(c, "time", resp, sizeof(resp)) < 0)
		return -1;
	t = strtod(resp, &end);
	if (end == resp) {
		seterr(c->err, "control request 'time': %s", resp);
		return -1;
	}
	return t;
}

int sys_state(struct sys_case *c, char *buf, size_t cap)
{
	if (sys_ctl_ask(c, "state", buf, cap) < 0)
		return -1;
	if (strncmp(buf, "time=", 5)) {
		seterr(c->err, "control request 'state': %s", buf);
		return -1;
	}
	return 0;
}

double sys_state_num(const char *state, const char *key)
{
	char val[64], *end;
	double v;

	if (proc_ctl_state_get(state, key, val, sizeof(val)) < 0)
		return NAN;
	v = strtod(val, &end);
	return end == val ? NAN : v;
}

/* ---- events ------------------------------------------------------------- */

static int evt_add(struct sys_case *c, double t, const char *text)
{
	if (c->nev == c->capev) {
		size_t cap = c->capev ? c->capev * 2 : 1024;
		struct sys_evt *n = realloc(c->ev, cap * sizeof(*n));

		if (!n)
			return -1;
		c->ev = n;
		c->capev = cap;
	}
	c->ev[c->nev].t_ms = t;
	snprintf(c->ev[c->nev].text, SYS_EVT_TEXT, "%s", text);
	c->nev++;
	return 0;
}

int sys_events(struct sys_case *c)
{
	char *p, *end;
	int n;

	n = proc_ctl_request_multi(c->ctl, "events", c->buf, c->bufcap,
				   CTL_TIMEOUT_MS);
	if (n < 0) {
		seterr(c->err, "control request 'events': no answer");
		return -1;
	}
	for (p = c->buf; *p; p = end) {
		char *nl = strchr(p, '\n'), *text;
		double t;

		end = nl ? nl + 1 : p + strlen(p);
		if (nl)
			*nl = '\0';
		t = strtod(p, &text);
		if (text == p || *text != ' ') {
			seterr(c->err, "bad event line '%s'", p);
			return -1;
		}
		if (evt_add(c, t, text + 1) < 0) {
			seterr(c->err, "out of memory");
			return -1;
		}
	}
	return (int)c->nev;
}

int sys_event_find(const struct sys_case *c, const char *prefix,
		   double after_ms)
{
	size_t k = strlen(prefix);

	for (size_t i = 0; i < c->nev; i++)
		if (c->ev[i].t_ms >= after_ms &&
		    !strncmp(c->ev[i].text, prefix, k))
			return (int)i;
	return -1;
}

int sys_wait_event(struct sys_case *c, const char *prefix, double after_ms,
		   int timeout_ms, double *t_ms)
{
	long long deadline = proc_now_ms() + timeout_ms;

	for (;;) {
		int i = sys_event_find(c, prefix, after_ms);

		if (i >= 0) {
			if (t_ms)
				*t_ms = c->ev[i].t_ms;
			return 0;
		}
		if (proc_now_ms() > deadline) {
			seterr(c->err,
			       "no event '%s...' after %.0f ms within "
			       "%d ms",
			       prefix, after_ms, timeout_ms);
			return -1;
		}
		if (c->re_up)
			proc_pump(&c->re, 0);
		sleep_ms(15);
		if (sys_events(c) < 0)
			return -1;
	}
}

int sys_wait_sim(struct sys_case *c, double t_ms, int timeout_ms)
{
	long long deadline = proc_now_ms() + timeout_ms;

	for (;;) {
		double now = sys_sim_time(c);

		if (now < 0)
			return -1;
		if (now >= t_ms)
			return 0;
		if (proc_now_ms() > deadline) {
			seterr(c->err,
			       "simulated time %.0f ms not reached "
			       "within %d ms (now %.0f)",
			       t_ms, timeout_ms, now);
			return -1;
		}
		if (c->re_up)
			proc_pump(&c->re, 0);
		sleep_ms(POLL_MS);
	}
}

int sys_wait_state(struct sys_case *c, const char *key, const char *value,
		   int timeout_ms)
{
	long long deadline = proc_now_ms() + timeout_ms;
	char st[2048], want[128];

	snprintf(want, sizeof(want), " %s=%s ", key, value);
	for (;;) {
		if (sys_state(c, st, sizeof(st) - 1) < 0)
			return -1;
		strcat(st, " ");
		if (strstr(st, want))
			return 0;
		if (proc_now_ms() > deadline) {
			seterr(c->err,
			       "state never showed %s=%s within %d ms:"
			       " %s",
			       key, value, timeout_ms, st);
			return -1;
		}
		if (c->re_up)
			proc_pump(&c->re, 0);
		sleep_ms(POLL_MS);
	}
}

int sys_wait_moving(struct sys_case *c, char axis, double counts,
		    int timeout_ms)
{
	long long deadline = proc_now_ms() + timeout_ms;
	char st[2048], key[8];
	double x0 = NAN;

	snprintf(key, sizeof(key), "%c.act", axis);
	for (;;) {
		double x;

		if (sys_state(c, st, sizeof(st)) < 0)
			return -1;
		x = sys_state_num(st, key);
		if (isnan(x0))
			x0 = x;
		if (fabs(x - x0) >= counts)
			return 0;
		if (proc_now_ms() > deadline) {
			seterr(c->err,
			       "axis %c moved %.0f counts, not %.0f, "
			       "within %d ms: %s",
			       axis, fabs(x - x0), counts, timeout_ms, st);
			return -1;
		}
		if (c->re_up)
			proc_pump(&c->re, 0);
		sleep_ms(POLL_MS);
	}
}

int sys_wait_stopped(struct sys_case *c, char axis, int timeout_ms,
		     double *t_ms)
{
	long long deadline = proc_now_ms() + timeout_ms;
	char st[2048], kref[8], kvel[8];
	double ref0 = NAN, t0 = -1;

	snprintf(kref, sizeof(kref), "%c.ref", axis);
	snprintf(kvel, sizeof(kvel), "%c.vel", axis);
	for (;;) {
		double ref, vel;

		if (sys_state(c, st, sizeof(st)) < 0)
			return -1;
		ref = sys_state_num(st, kref);
		vel = sys_state_num(st, kvel);
		if (ref == ref0 && fabs(vel) < SYS_STILL_CPS) {
			*t_ms = t0;
			return 0;
		}
		ref0 = ref;
		t0 = sys_state_num(st, "time");
		if (proc_now_ms() > deadline) {
			seterr(c->err, "axis %c still moving after %d ms: %s",
			       axis, timeout_ms, st);
			return -1;
		}
		if (c->re_up)
			proc_pump(&c->re, 0);
		sleep_ms(POLL_MS);
	}
}

/* The first "axis X motor off" (controller) or "X motor off" (as
 * docs/galil-sim.md words it) event of axis @a at or after @after_ms. */
static int motor_off_event(const struct sys_case *c, int a, double after_ms)
{
	char p1[32], p2[32];
	int i, j;

	snprintf(p1, sizeof(p1), "axis %c motor off", 'A' + a);
	snprintf(p2, sizeof(p2), "%c motor off", 'A' + a);
	i = sys_event_find(c, p1, after_ms);
	j = sys_event_find(c, p2, after_ms);
	return i < 0 ? j : j < 0 ? i : i < j ? i : j;
}

double sys_motors_off_time(const struct sys_case *c, double after_ms)
{
	double last = -1;

	for (int a = 0; a < 3; a++) {
		int i = motor_off_event(c, a, after_ms);

		if (i < 0)
			return -1;
		if (c->ev[i].t_ms > last)
			last = c->ev[i].t_ms;
	}
	return last;
}

/* ---- safe state --------------------------------------------------------- */

static int safe_now(struct sys_case *c, const char *st, int relay_may_be_on)
{
	if (!relay_may_be_on &&
	    (!strstr(st, " relay=off ") || !strstr(st, " power=0 "))) {
		seterr(c->err, "motor power is not cut: %s", st);
		return -1;
	}
	for (int a = 0; a < 3; a++) {
		char key[16];

		snprintf(key, sizeof(key), "%c.mo", 'A' + a);
		if (sys_state_num(st, key) != 1) {
			seterr(c->err, "motor %c is not off: %s", 'A' + a, st);
			return -1;
		}
	}
	return 0;
}

int sys_check_safe(struct sys_case *c, int relay_may_be_on, int hold_ms)
{
	char st0[2048], st1[2048];
	double t0;

	if (sys_state(c, st0, sizeof(st0)) < 0 ||
	    safe_now(c, st0, relay_may_be_on) < 0)
		return -1;
	t0 = sys_state_num(st0, "time");
	if (sys_wait_sim(c, t0 + hold_ms, hold_ms + 5000) < 0 ||
	    sys_state(c, st1, sizeof(st1)) < 0 ||
	    safe_now(c, st1, relay_may_be_on) < 0)
		return -1;
	for (int a = 0; a < 3; a++) {
		char key[16];
		double x0, x1;

		snprintf(key, sizeof(key), "%c.act", 'A' + a);
		x0 = sys_state_num(st0, key);
		x1 = sys_state_num(st1, key);
		if (isnan(x0) || x0 != x1) {
			seterr(c->err,
			       "axis %c moved from %.1f to %.1f "
			       "counts within %d ms after the safe state:\n"
			       "%s\n%s",
			       'A' + a, x0, x1, hold_ms, st0, st1);
			return -1;
		}
	}
	return 0;
}

/* ---- roboelf's output and log ------------------------------------------- */

int sys_wait_fault(struct sys_case *c, int timeout_ms, char *line, size_t cap)
{
	if (proc_wait_line(&c->re, PROC_STDOUT, "FAULT ", timeout_ms, line,
			   cap) == 0)
		return 0;
	seterr(c->err,
	       "no FAULT line from roboelf within %d ms\n--- "
	       "stdout:\n%s\n--- stderr:\n%s",
	       timeout_ms, tail(&c->re, PROC_STDOUT, 1200),
	       tail(&c->re, PROC_STDERR, 600));
	return -1;
}

int sys_fault_expect(enum re_fault_id id, int axis, char *prefix, size_t pcap,
		     char *recovery, size_t rcap)
{
	struct re_fault f;
	const char *cls;
	char line[512], *rec;

	re_fault_set(&f, id, axis);
	snprintf(f.s, sizeof(f.s), "x");
	if (re_fault_format(&f, NULL, line, sizeof(line)) < 0)
		return -1;
	cls = re_fault_class_name(re_fault_class(id));
	snprintf(prefix, pcap, "FAULT %s: ", cls);
	rec = strstr(line, ". Recovery: ");
	if (!rec)
		return -1;
	snprintf(recovery, rcap, "%s", rec);
	return 0;
}

enum re_fault_id sys_fault_match(const char *line, int axis,
				 const enum re_fault_id *ids)
{
	for (int i = 0; ids[i] != RE_F_NONE; i++) {
		char prefix[64], rec[512];
		size_t ll = strlen(line), rl;

		if (sys_fault_expect(ids[i], axis, prefix, sizeof(prefix), rec,
				     sizeof(rec)) < 0)
			continue;
		rl = strlen(rec);
		if (!strncmp(line, prefix, strlen(prefix)) && ll >= rl &&
		    !strcmp(line + ll - rl, rec))
			return ids[i];
	}
	return RE_F_NONE;
}

int sys_log_find(struct sys_case *c, const char *a, const char *b, char *line,
		 size_t cap)
{
	char *buf, *p;
	size_t len;
	int rc = -1;

	if (read_file(c->log, &buf, &len) < 0) {
		seterr(c->err, "cannot read the log '%s': %s", c->log,
		       strerror(errno));
		return -1;
	}
	for (p = buf; *p && rc < 0;) {
		char *nl = strchr(p, '\n');

		if (nl)
			*nl = '\0';
		if (strstr(p, a) && (!b || strstr(p, b))) {
			if (line)
				snprintf(line, cap, "%s", p);
			rc = 0;
		}
		p = nl ? nl + 1 : p + strlen(p);
	}
	if (rc < 0)
		seterr(c->err, "no line with '%s'%s%s%s in the log '%s'", a,
		       b ? " and '" : "", b ? b : "", b ? "'" : "", c->log);
	free(buf);
	return rc;
}

double sys_wall_ms(void)
{
	struct timespec ts;

	clock_gettime(CLOCK_REALTIME, &ts);
	return (double)ts.tv_sec * 1000.0 + (double)(ts.tv_nsec / 1000000);
}

long sys_wd_warnings(struct sys_case *c, long *full, long *sums)
{
	char *buf, *p, *w;
	long n = 0, k, nf = 0, ns = 0;
	int end;
	size_t len;

	if (read_file(c->log, &buf, &len) < 0) {
		seterr(c->err, "cannot read the log '%s': %s", c->log,
		       strerror(errno));
		return -1;
	}
	for (p = buf; *p;) {
		char *nl = strchr(p, '\n');

		if (nl)
			*nl = '\0';
		w = strstr(p, " WARN watchdog: ");
		end = 0;
		if (w && sscanf(w, " WARN watchdog: %ld more late %n", &k,
				&end) == 1 &&
		    end > 0 && k > 0) {
			n += k;
			ns++;
		} else if (w && strstr(w, " (non-critical limit ")) {
			n++;
			nf++;
		}
		p = nl ? nl + 1 : p + strlen(p);
	}
	free(buf);
	if (full)
		*full = nf;
	if (sums)
		*sums = ns;
	return n;
}

long sys_wd_counter(struct sys_case *c)
{
	char line[2048];
	const char *p;
	long n;

	if (sys_log_find(c, "stats: cycles=", NULL, line, sizeof(line)) < 0)
		return -1;
	p = strstr(line, " watchdog warnings=");
	if (!p || sscanf(p, " watchdog warnings=%ld", &n) != 1) {
		seterr(c->err, "no 'watchdog warnings=' in '%s'", line);
		return -1;
	}
	return n;
}

int sys_log_time_ms(struct sys_case *c, const char *a, double *ms)
{
	char line[4096];
	struct tm tm;
	int msec;

	if (sys_log_find(c, a, NULL, line, sizeof(line)) < 0)
		return -1;
	memset(&tm, 0, sizeof(tm));
	if (sscanf(line, "%4d-%2d-%2dT%2d:%2d:%2d.%3dZ", &tm.tm_year,
		   &tm.tm_mon, &tm.tm_mday, &tm.tm_hour, &tm.tm_min, &tm.tm_sec,
		   &msec) != 7) {
		seterr(c->err, "no time stamp in the log line '%s'", line);
		return -1;
	}
	tm.tm_year -= 1900;
	tm.tm_mon -= 1;
	*ms = (double)timegm(&tm) * 1000.0 + msec;
	return 0;
}

/* ---- a second host on the command port ---------------------------------- */

int sys_cmd_open(struct sys_case *c)
{
	int fd = proc_ctl_connect_at(c->sim_addr, c->sim.port, CTL_TIMEOUT_MS);

	if (fd < 0)
		seterr(c->err, "cannot connect to the controller port %d",
		       c->sim.port);
	return fd;
}

int sys_cmd(int fd, const char *cmd, int timeout_ms)
{
	long long deadline = proc_now_ms() + timeout_ms;
	char buf[256];
	int len = snprintf(buf, sizeof(buf), "%s\r", cmd);

	if (send(fd, buf, (size_t)len, MSG_NOSIGNAL) != len)
		return -1;
	for (;;) {
		struct pollfd pfd = {.fd = fd, .events = POLLIN};
		long long left = deadline - proc_now_ms();
		char ch;

		if (left <= 0 || poll(&pfd, 1, (int)left) <= 0)
			return -1;
		if (recv(fd, &ch, 1, 0) != 1)
			return -1;
		if (ch == ':')
			return 0;
		if (ch == '?')
			return 1;
	}
}
